//! The blade-root fillet as geometry: the rolling-ball blend of radius `R` between the hub
//! and each blade side.
//!
//! # Geometry
//! A ball of radius `R` rolling in the corner between the hub and a blade side, touching
//! both, sweeps the fillet. Its centre `c` lies on both offset surfaces (the *spine*):
//! `c = B(u, v) + R·n_b(u, v)` with `n_b` the side's outward unit normal, and
//! `d_hub(c) = R` with `d_hub` the hub's exact signed distance (channel side positive). Per
//! blade station `u` the spine point is the root of the scalar function
//! `g(v) = d_hub(B(u, v) + R·n_b(u, v)) − R` above the side's hub edge, found by a bracket
//! (first sign change among [`BRACKET_SAMPLES`] samples of `v`, − to +) and the Illinois
//! regula falsi ([`FilletSection::solve`], to `|g| < 1e-13` mm). The ball touches the side at
//! `B(u, v)` and the hub at `c − R·n_h` (`n_h` the hub normal at the foot of `c`). Both
//! contact points lie on the ball's characteristic circle (the spine's tangent is
//! perpendicular to both normals: it is tangent to both offset surfaces), so the fillet's
//! cross-section at `u` is the circular arc of radius `R` about `c` from the hub contact to
//! the blade contact, of angle `π − β` where `β` is the angle of the corner between hub and
//! side ([`FilletSection::arc`], exact rational quadratic NURBS).
//!
//! # The fillet of a blade side ([`BladeFillet`])
//! Sections at stations uniform in `u` form *pieces*: maximal runs of stations whose ball
//! fits, i.e. whose centre is `R` (within [`FIT_CHECK_MM`]) from the side by the global
//! closest point and no nearer to the other side; a station whose offset surfaces do not
//! meet, or whose ball would cross the blade (a concave region tighter than `R`, the nose of
//! a thin edge), ends a piece. Each piece's spine is the cubic B-spline interpolating its
//! centres with uniform parameters (NURBS Book A9.1; the stations are uniform in `u`, so the
//! curve parameter is affine in `u`), and the two contact normals are interpolated the same
//! way. The spine's error is measured against exact sections at every midpoint between
//! stations; the stations are doubled until it is at most the tolerance (default
//! [`DEFAULT_FILLET_TOL_MM`]) or [`MAX_STATIONS`] is reached ([`FilletPiece::fit_error_mm`]
//! says what was reached).
//!
//! # Distance ([`BladeFillet::signed_distance`])
//! The fillet material near a piece is the part of the corner outside the rolling balls. For
//! a point `p` whose nearest spine point `c(t)` (certified global curve projection) is
//! interior, whose direction from it lies in the wedge spanned by the two contact
//! directions `−n_h`, `−n_b` (the arc's sector) and which lies in the corner (on the air
//! side of the walls' tangent planes at the contacts, within [`CORNER_SLACK`]`·R`: the
//! sector goes on through hub and blade), the nearest fillet point is on that arc
//! along `p − c(t)`, and the signed distance (positive in the air, as every design distance
//! here) is `R − |p − c(t)|`. Elsewhere the fillet does not decide the distance (`None`):
//! the nearest design point is on the hub or the side, or beyond the piece's ends. The
//! design's distance with fillets is the minimum of the sharp design's signed distance and
//! this one (the fillet adds material to the corner). Stated error: the spine fit's error
//! (the distance is 1-Lipschitz in the spine's position), at most the tolerance.
//!
//! Cost: building a piece of `n` stations takes `O(n)` section solves (regula falsi, each
//! `O(iterations)` exact hub distances) and `2n` global blade projections, plus the
//! refinement's midpoint checks (in parallel); a distance is one certified curve
//! projection, O(log n). The refinement doubles the stations of the whole side; the spine's
//! interpolation is a banded solve (O(n) in `nurbs::fit::interpolate_curve`). On the NASA
//! HECC main blade with an assumed 1.5 mm fillet (release, 2 cores) the spine converges
//! slowly: 2049 stations leave 4.5e-3 / 7.3e-3 mm (pressure / suction side, 0.1-0.2 s),
//! 16 385 stations 7.3e-5 / 6.7e-5 mm in about 1 s per side (the dense solve took about
//! 40 s for 4097). A spine that still misses the tolerance at [`MAX_STATIONS`] is kept with
//! its error, which [`BladeFillet::fit_error_mm`] reports. Refining only where the midpoint
//! check fails would save the stations where the spine converges early.

use crate::blade::{Blade, Side};
use crate::channel::edge_v;
use crate::error::ModelError;
use crate::query::blade_side_distance;
use crate::revolved::RevolvedSurface;
use nalgebra::{SVector, Vector3};
use nurbs::closest::CurveProjector;
use nurbs::fit::{interpolate_curve, Parametrisation};
use nurbs::NurbsCurve;
use rayon::prelude::*;

/// Samples of `v` (hub edge to the side's top) searched for the first sign change of the
/// spine function.
pub const BRACKET_SAMPLES: usize = 64;

/// Iterations of the regula falsi of a section.
const ROOT_ITERS: usize = 200;

/// Default largest error of a fillet's spine (mm).
pub const DEFAULT_FILLET_TOL_MM: f64 = 1e-4;

/// Largest number of stations of a blade side's fillet (module docs: a real blade export
/// needs 16 385 for 1e-4 mm).
pub const MAX_STATIONS: usize = 32769;

/// How far behind a wall's tangent plane at the ball's contact a point may lie and still
/// count as in the corner (fraction of `R`): the walls curve away from their tangent planes
/// by about `R²/(2ρ)` across the fillet (`ρ` their radius of curvature, 0.014·R for a hub of
/// 35 mm at R = 1 mm).
pub const CORNER_SLACK: f64 = 0.1;

/// First number of stations of a blade side's fillet (then doubled while the fit is coarser
/// than the tolerance).
const FIRST_STATIONS: usize = 129;

/// How far a ball's centre may be from `R` of the blade side (global closest point) for its
/// section to count (mm): the sections solve to 1e-13 mm, so more means the nearest side
/// point is elsewhere (the ball crosses the blade).
pub const FIT_CHECK_MM: f64 = 1e-6;

/// One cross-section of the fillet: the rolling ball touching the hub and a blade side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilletSection {
    /// Station: the blade side's `u`.
    pub u: f64,
    /// The side's `v` of the blade contact.
    pub v: f64,
    /// Ball centre (spine point).
    pub centre: Vector3<f64>,
    /// Outward unit normal of the side at the blade contact.
    pub blade_normal: Vector3<f64>,
    /// Channel-side unit normal of the hub at the hub contact.
    pub hub_normal: Vector3<f64>,
    /// Ball (fillet) radius (mm).
    pub radius: f64,
}

impl FilletSection {
    /// The ball of radius `radius` touching the hub and `side` of `blade` at station `u`
    /// (module docs): `None` when the side's offset surface does not reach the hub's within
    /// the side's `v` range (no sign change of the spine function) or a normal is singular.
    /// Cost: up to [`BRACKET_SAMPLES`] + `ROOT_ITERS` exact hub distances.
    pub fn solve(
        hub: &RevolvedSurface,
        blade: &Blade,
        side: Side,
        u: f64,
        radius: f64,
    ) -> Option<Self> {
        let s = blade.side(side);
        let (_, (v0, v1)) = s.domain();
        let off = |v: f64| -> Option<(Vector3<f64>, Vector3<f64>)> {
            let n = blade.outward_normal(side, u, v)?;
            Some((s.point(u, v) + n * radius, n))
        };
        let g = |v: f64| off(v).map(|(c, _)| hub.signed_distance(&c) - radius);
        let v_root = edge_v(blade, side, hub, u).unwrap_or(v0);
        // Bracket: the first sign change of g above the hub edge.
        let mut a = v_root.max(v0);
        let mut ga = g(a)?;
        let mut bracket = None;
        for k in 1..=BRACKET_SAMPLES {
            let b = a + (v1 - v_root.max(v0)) * 1.0 / BRACKET_SAMPLES as f64;
            let b = b.min(v1);
            let gb = g(b)?;
            if ga <= 0.0 && gb > 0.0 {
                bracket = Some((a, b, ga, gb));
                break;
            }
            a = b;
            ga = gb;
            if k == BRACKET_SAMPLES || b >= v1 {
                break;
            }
        }
        let (lo, hi, flo, fhi) = bracket?;
        let v = crate::root::illinois(g, (lo, flo), (hi, fhi), 1e-13, ROOT_ITERS)?.x;
        let (centre, blade_normal) = off(v)?;
        let (t, phi, _) = hub.closest(&centre);
        Some(Self {
            u,
            v,
            centre,
            blade_normal,
            hub_normal: hub.normal(t, phi),
            radius,
        })
    }

    /// The ball's contact with the blade side.
    pub fn blade_foot(&self) -> Vector3<f64> {
        self.centre - self.blade_normal * self.radius
    }

    /// The ball's contact with the hub.
    pub fn hub_foot(&self) -> Vector3<f64> {
        self.centre - self.hub_normal * self.radius
    }

    /// Angle of the fillet's arc (rad): `π` less the corner's angle between hub and side.
    pub fn arc_angle(&self) -> f64 {
        self.hub_normal.angle(&self.blade_normal)
    }

    /// The point of the arc at fraction `t ∈ [0, 1]` of its angle, from the hub contact
    /// (`t = 0`) to the blade contact (`t = 1`); exactly `radius` from the centre.
    pub fn arc_point(&self, t: f64) -> Vector3<f64> {
        let (a, b) = (-self.hub_normal, -self.blade_normal);
        let w = self.arc_angle();
        let d = if w < 1e-12 {
            a
        } else {
            (a * ((1.0 - t) * w).sin() + b * (t * w).sin()) / w.sin()
        };
        self.centre + d.normalize() * self.radius
    }

    /// The arc as an exact rational quadratic NURBS curve (hub contact at 0, blade contact
    /// at 1). Errors when the contact directions are parallel (no corner).
    pub fn arc(&self) -> Result<NurbsCurve<3>, ModelError> {
        let a = -self.hub_normal;
        let b = -self.blade_normal;
        let y = b - a * a.dot(&b);
        if y.norm() < 1e-12 {
            return Err(ModelError::Geometry(format!(
                "fillet section at u = {:.6}: hub and blade normals are parallel",
                self.u
            )));
        }
        Ok(NurbsCurve::circle_arc(
            self.centre,
            a,
            y,
            self.radius,
            0.0,
            self.arc_angle(),
        )?)
    }
}

/// A run of fitting stations of a blade side's fillet with its fitted spine.
#[derive(Debug, Clone)]
pub struct FilletPiece {
    sections: Vec<FilletSection>,
    spine: NurbsCurve<3>,
    /// Hub normal (0..3) and blade normal (3..6) along the spine's parameter.
    normals: NurbsCurve<6>,
    projector: CurveProjector<3>,
    /// Farthest a point can lie from its nearest spine point where this piece decides the
    /// distance ([`FilletPiece::closest`]'s sector), with a margin (see [`sector_reach`]).
    sector_reach: f64,
    fit_error_mm: f64,
    /// The material's bounding wedges along the spine, built on first use
    /// ([`FilletPiece::material_distance_lower`]).
    wedges: std::sync::OnceLock<Wedges>,
}

/// Spine spacing of the material wedges (mm).
const WEDGE_SPACING_MM: f64 = 0.01;
/// Wedges per culling block.
const WEDGE_BLOCK: usize = 32;

/// The region of one section's fillet material: in the plane of the contact directions `a`
/// (to the hub contact) and `b` (to the blade contact) through the spine point `s`, the part
/// of the angle between `a` and `b` (angle `gamma`) outside the disc of radius `R` and on the
/// air side of both walls' tangent planes moved in by `CORNER_SLACK·R` (`w·a ≤ c`,
/// `w·b ≤ c`, `c = (1 + CORNER_SLACK)·R`): what [`FilletPiece::closest`] counts as material.
/// It lies in the annular sector from `R` to `r_out = c / cos(γ/2)` (the corner) and in the
/// quadrilateral of the spine point, the two moved contacts `c·a`, `c·b` and the corner.
/// `delta` bounds how far the wedge of any spine point up to the neighbouring samples lies
/// from this one or that one.
#[derive(Debug, Clone, Copy)]
struct Wedge {
    s: Vector3<f64>,
    a: Vector3<f64>,
    e: Vector3<f64>,
    n: Vector3<f64>,
    /// `cos γ`, `sin γ` of the sector's angle `γ` (< π).
    cos_g: f64,
    sin_g: f64,
    r_out: f64,
    /// `c = (1 + CORNER_SLACK)·R`: the moved tangent planes' distance from the spine point.
    c: f64,
    delta: f64,
}

/// A run of wedges (or of blocks) with a bounding sphere of everything they hold (`delta`
/// included) and the plane bounds of its wedges ([`PlaneBound`]).
#[derive(Debug, Clone, Copy)]
struct WedgeBlock {
    centre: Vector3<f64>,
    radius: f64,
    range: (usize, usize),
    /// Plane bounds from the run's first and last wedge, and the largest `delta` of its
    /// wedges.
    planes: [PlaneBound; 2],
    delta_max: f64,
}

/// How far the planes of a run of wedges lie from a point, from one reference wedge `r` of
/// the run: every wedge `k` lies in the plane through `s_k` of normal `n_k`, so its distance
/// from `p` is at least `|τ_k|`, `τ_k = (p − s_k)·n_k`, and
/// `τ_k = τ_r + (p − s_r)·(n_k − n_r) + (s_r − s_k)·n_k`, so that
/// `τ_r − |p − s_r|·turn + lo ≤ τ_k ≤ τ_r + |p − s_r|·turn + hi` with `turn = max_k |n_k − n_r|`,
/// `lo`/`hi` the least/largest `(s_r − s_k)·n_k` over the run. Where that interval excludes 0
/// its nearer end bounds `|τ_k|` from below for the whole run: a run lying along the spine
/// away from `p`'s cross-section is culled by it (its bounding sphere, as wide as the
/// wedges' outer radius, is not).
#[derive(Debug, Clone, Copy)]
struct PlaneBound {
    s: Vector3<f64>,
    n: Vector3<f64>,
    turn: f64,
    lo: f64,
    hi: f64,
}

impl PlaneBound {
    fn of(r: &Wedge, run: &[Wedge]) -> Self {
        let (mut turn, mut lo, mut hi) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
        for k in run {
            turn = turn.max((k.n - r.n).norm());
            let x = (r.s - k.s).dot(&k.n);
            lo = lo.min(x);
            hi = hi.max(x);
        }
        Self {
            s: r.s,
            n: r.n,
            turn,
            lo,
            hi,
        }
    }

    /// A lower bound of `|τ_k|` over the run (type docs), 0 where the interval holds 0.
    #[inline]
    fn lower(&self, p: &Vector3<f64>) -> f64 {
        let w = p - self.s;
        let tau = w.dot(&self.n);
        let slack = w.norm() * self.turn;
        // 10⁻¹² mm for the rounding of these products against the wedges' own.
        ((tau - slack + self.lo).max(-(tau + slack + self.hi)) - 1e-12).max(0.0)
    }
}

impl WedgeBlock {
    /// A lower bound of `distance − delta` over the run's wedges: the bounding sphere's and
    /// the plane bounds'.
    #[inline]
    fn lower(&self, p: &Vector3<f64>) -> f64 {
        let sphere = (p - self.centre).norm() - self.radius;
        let planes = self.planes[0].lower(p).max(self.planes[1].lower(p)) - self.delta_max;
        sphere.max(planes)
    }

    /// The run of `wedges` (non-empty) with its bounding sphere (centre: the mean of the
    /// items' centres; radius: the largest reach of an item's sphere from it), `range` the
    /// items' indices.
    fn of(
        wedges: &[Wedge],
        spheres: &[(Vector3<f64>, f64)],
        range: (usize, usize),
    ) -> Option<Self> {
        let (first, last) = (wedges.first()?, wedges.last()?);
        let centre = spheres.iter().map(|s| s.0).sum::<Vector3<f64>>() / spheres.len() as f64;
        let radius = spheres
            .iter()
            .map(|s| (s.0 - centre).norm() + s.1)
            .fold(0.0, f64::max);
        Some(WedgeBlock {
            centre,
            radius,
            range,
            planes: [PlaneBound::of(first, wedges), PlaneBound::of(last, wedges)],
            delta_max: wedges.iter().map(|w| w.delta).fold(0.0, f64::max),
        })
    }
}

/// Visits `items` nearest first by `lower` (a lower bound of what each can contribute), and
/// stops at the first whose bound reaches `*best` (the rest bound no lower). Up to 64 items
/// are ordered on the stack; longer lists are visited in their order, each skipped when its
/// bound reaches `*best`.
#[inline]
fn nearest_first<T>(
    items: &[T],
    lower: impl Fn(&T) -> f64,
    best: &mut f64,
    mut visit: impl FnMut(&T, &mut f64),
) {
    const N: usize = 64;
    if items.len() > N {
        for it in items {
            if lower(it) < *best {
                visit(it, best);
            }
        }
        return;
    }
    let mut order = [(0.0f64, 0usize); N];
    for (k, it) in items.iter().enumerate() {
        order[k] = (lower(it), k);
    }
    let order = &mut order[..items.len()];
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    for &(lb, k) in order.iter() {
        if lb >= *best {
            break;
        }
        visit(&items[k], best);
    }
}

/// Runs of [`WEDGE_BLOCK`] wedges ([`WedgeBlock::of`]), each wedge's sphere `(s, r_out +
/// delta)`.
fn wedge_blocks(wedges: &[Wedge]) -> Vec<WedgeBlock> {
    (0..wedges.len())
        .step_by(WEDGE_BLOCK)
        .filter_map(|lo| {
            let hi = (lo + WEDGE_BLOCK).min(wedges.len());
            let run = &wedges[lo..hi];
            let spheres: Vec<_> = run.iter().map(|w| (w.s, w.r_out + w.delta)).collect();
            WedgeBlock::of(run, &spheres, (lo, hi))
        })
        .collect()
}

/// Runs of [`WEDGE_BLOCK`] blocks: a group's sphere holds its blocks' spheres, its plane
/// bounds are those of all its wedges.
fn block_groups(wedges: &[Wedge], blocks: &[WedgeBlock]) -> Vec<WedgeBlock> {
    (0..blocks.len())
        .step_by(WEDGE_BLOCK)
        .filter_map(|lo| {
            let hi = (lo + WEDGE_BLOCK).min(blocks.len());
            let run = &blocks[lo..hi];
            let spheres: Vec<_> = run.iter().map(|b| (b.centre, b.radius)).collect();
            let (w0, w1) = (run.first()?.range.0, run.last()?.range.1);
            WedgeBlock::of(&wedges[w0..w1], &spheres, (lo, hi))
        })
        .collect()
}

/// The wedges, their blocks, and groups of [`WEDGE_BLOCK`] blocks (a two-level cull).
#[derive(Debug, Clone, Default)]
struct Wedges {
    wedges: Vec<Wedge>,
    blocks: Vec<WedgeBlock>,
    groups: Vec<WedgeBlock>,
}

/// 2-D distance from `(x, y)` to the segment from `(x0, y0)` to `(x1, y1)`.
#[inline]
fn segment_distance_2d(x: f64, y: f64, (x0, y0): (f64, f64), (x1, y1): (f64, f64)) -> f64 {
    let (dx, dy) = (x1 - x0, y1 - y0);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((x - x0) * dx + (y - y0) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (u, v) = (x - x0 - t * dx, y - y0 - t * dy);
    (u * u + v * v).sqrt()
}

impl Wedge {
    /// Distance from `p` to the wedge's region (type docs): the plane's normal offset and a
    /// lower bound of the 2-D distance to the region, the larger of the exact 2-D distances
    /// to the annular sector (angle below π) and to the quadrilateral, each of which holds
    /// it. The quadrilateral keeps the bound tight beside a wall above the fillet (a ball
    /// riding a blade side well above the hub), where the sector, as wide as the corner is
    /// far, reaches into the wall up to `r_out` from the spine.
    #[cfg(test)]
    fn distance(&self, p: &Vector3<f64>, inner: f64) -> f64 {
        self.distance_below(p, inner, f64::INFINITY)
    }

    /// [`Self::distance`] where only values below `limit` matter: the sector's alone when it
    /// already reaches `limit` (the quadrilateral could only raise it).
    #[inline]
    fn distance_below(&self, p: &Vector3<f64>, inner: f64, limit: f64) -> f64 {
        let w = p - self.s;
        let tau = w.dot(&self.n);
        let (x, y) = (w.dot(&self.a), w.dot(&self.e));
        let ds = self.sector_distance_2d(x, y, inner);
        let sector = (tau * tau + ds * ds).sqrt();
        if sector >= limit {
            return sector;
        }
        let d2 = ds.max(self.kite_distance_2d(x, y));
        (tau * tau + d2 * d2).sqrt()
    }

    /// 2-D distance from `(x, y)` (along `a`, `e`) to the quadrilateral of the spine point,
    /// `c·a`, the corner and `c·b` (convex: its angles at the contacts are right angles).
    #[inline]
    fn kite_distance_2d(&self, x: f64, y: f64) -> f64 {
        let c = self.c;
        let bx = (x * self.cos_g + y * self.sin_g) - c;
        if y >= 0.0 && x * self.sin_g - y * self.cos_g >= 0.0 && x <= c && bx <= 0.0 {
            return 0.0;
        }
        // The corner: on both moved tangent lines, `x = c` and `x cos γ + y sin γ = c`.
        let corner = (c, c * (1.0 - self.cos_g) / self.sin_g.max(1e-12));
        let (o, pa, pb) = ((0.0, 0.0), (c, 0.0), (c * self.cos_g, c * self.sin_g));
        segment_distance_2d(x, y, o, pa)
            .min(segment_distance_2d(x, y, pa, corner))
            .min(segment_distance_2d(x, y, corner, pb))
            .min(segment_distance_2d(x, y, pb, o))
    }

    /// 2-D distance from `(x, y)` to the annular sector between `a` and `b` from `inner` to
    /// `r_out` (exact; the angle is below π).
    #[inline]
    fn sector_distance_2d(&self, x: f64, y: f64, inner: f64) -> f64 {
        // Inside the sector's angle (below π): on the left of `a` and on the right of `b`.
        if y >= 0.0 && x * self.sin_g - y * self.cos_g >= 0.0 {
            let m = (x * x + y * y).sqrt();
            (inner - m).max(m - self.r_out).max(0.0)
        } else {
            let seg = |dx: f64, dy: f64| {
                let r = (x * dx + y * dy).clamp(inner, self.r_out);
                let (u, v) = (x - r * dx, y - r * dy);
                (u * u + v * v).sqrt()
            };
            seg(1.0, 0.0).min(seg(self.cos_g, self.sin_g))
        }
    }
}

impl FilletPiece {
    /// The exact sections at the piece's stations (u increasing).
    pub fn sections(&self) -> &[FilletSection] {
        &self.sections
    }

    /// The fitted spine (ball centres; parameter affine in the side's `u` over the piece).
    pub fn spine(&self) -> &NurbsCurve<3> {
        &self.spine
    }

    /// Largest distance found between the fitted spine and exact sections solved at every
    /// midpoint between stations (mm).
    pub fn fit_error_mm(&self) -> f64 {
        self.fit_error_mm
    }

    /// The side's `u` range the piece covers.
    pub fn u_range(&self) -> (f64, f64) {
        let n = self.sections.len();
        (self.sections[0].u, self.sections[n - 1].u)
    }

    /// The fitted section at side parameter `u` within [`Self::u_range`] (centre and normals
    /// from the fitted curves, normals renormalised). Its `v` is NaN: the fitted curves carry
    /// no side parameter (solve the exact section for it).
    pub fn section_at(&self, u: f64) -> FilletSection {
        let (u0, u1) = self.u_range();
        let t = ((u - u0) / (u1 - u0)).clamp(0.0, 1.0);
        let n = self.normals.point(t);
        let r = self.sections[0].radius;
        let (nh, nb) = (
            Vector3::new(n[0], n[1], n[2]).normalize(),
            Vector3::new(n[3], n[4], n[5]).normalize(),
        );
        FilletSection {
            u,
            v: f64::NAN,
            centre: self.spine.point(t),
            blade_normal: nb,
            hub_normal: nh,
            radius: r,
        }
    }

    /// A lower bound of the distance from `p` to this piece's fillet material (≤ 0 inside it),
    /// valid wherever `p` is: the material lies, section by section, in the wedge of the
    /// contact directions between radius `R` and the corner ([`FilletPiece::closest`]: the
    /// foot interior and perpendicular, the sector between the contacts, the slack-moved
    /// tangent planes). The wedges are sampled every [`WEDGE_SPACING_MM`] of spine; a
    /// sample's bound is its exact wedge distance less `delta`: the spine chord to the
    /// neighbouring samples plus the corner radius times the contact directions' turn
    /// (twice the half-interval bound, for the curvature between samples). 1-Lipschitz in `p`
    /// (a minimum of distances less constants). The wedges are searched in groups and blocks
    /// of [`WEDGE_BLOCK`], nearest first by a lower bound (a bounding sphere, and the
    /// distance to the wedges' planes, [`PlaneBound`]: what culls the blocks along the spine
    /// away from `p`'s cross-section); a block whose bound reaches the best value so far is
    /// skipped, so the result is that of every wedge. Cost: O(groups + blocks of the near
    /// groups + wedges of the blocks within the result of `p`'s cross-section); the wedges
    /// are built on first use, O(spine length / spacing). On impeller-5-freeform's whole
    /// plan the nearest-first planes took rest finishing's planning from 52.6 to 48.9 s.
    /// Values at or above `cap` are returned as some value `≥ cap` (the blocks that cannot go
    /// below it are not evaluated).
    pub fn material_distance_lower(&self, p: &Vector3<f64>, cap: f64) -> f64 {
        let w = self.wedges.get_or_init(|| self.build_wedges());
        let inner = self.sections[0].radius;
        let mut best = cap;
        nearest_first(
            &w.groups,
            |g| g.lower(p),
            &mut best,
            |g, best| {
                nearest_first(
                    &w.blocks[g.range.0..g.range.1],
                    |b| b.lower(p),
                    best,
                    |b, best| {
                        for k in &w.wedges[b.range.0..b.range.1] {
                            let d = k.distance_below(p, inner, *best + k.delta);
                            *best = best.min(d - k.delta);
                        }
                    },
                )
            },
        );
        best
    }

    /// [`Self::material_distance_lower`] without any culling: every wedge (what the culled
    /// search must return exactly; tests).
    #[cfg(test)]
    fn material_distance_lower_all(&self, p: &Vector3<f64>, cap: f64) -> f64 {
        let w = self.wedges.get_or_init(|| self.build_wedges());
        let inner = self.sections[0].radius;
        w.wedges
            .iter()
            .map(|k| k.distance(p, inner) - k.delta)
            .fold(cap, f64::min)
    }

    fn build_wedges(&self) -> Wedges {
        let r = self.sections[0].radius;
        let length: f64 = self
            .sections
            .windows(2)
            .map(|w| (w[1].centre - w[0].centre).norm())
            .sum();
        let n = ((length / WEDGE_SPACING_MM).ceil() as usize).max(2) + 1;
        let mut wedges: Vec<Wedge> = (0..n)
            .filter_map(|k| {
                let t = k as f64 / (n - 1) as f64;
                let (nh, nb) = contact_normals(&self.normals, t)?;
                let (a, b) = (-nh, -nb);
                let e = (b - a * a.dot(&b)).try_normalize(1e-12)?;
                let gamma = a.dot(&b).clamp(-1.0, 1.0).acos();
                Some(Wedge {
                    s: self.spine.point(t),
                    a,
                    e,
                    n: a.cross(&e),
                    cos_g: gamma.cos(),
                    sin_g: gamma.sin(),
                    r_out: (1.0 + CORNER_SLACK) * r / (0.5 * gamma).cos().max(1e-3),
                    c: (1.0 + CORNER_SLACK) * r,
                    delta: 0.0,
                })
            })
            .collect();
        let gaps: Vec<f64> = wedges
            .windows(2)
            .map(|w| {
                let turn = w[0].a.angle(&w[1].a).max(w[0].e.angle(&w[1].e));
                (w[1].s - w[0].s).norm() + w[0].r_out.max(w[1].r_out) * turn
            })
            .collect();
        for (k, wd) in wedges.iter_mut().enumerate() {
            let before = if k > 0 { gaps[k - 1] } else { 0.0 };
            wd.delta = before.max(gaps.get(k).copied().unwrap_or(0.0));
        }
        let blocks = wedge_blocks(&wedges);
        let groups = block_groups(&wedges, &blocks);
        Wedges {
            wedges,
            blocks,
            groups,
        }
    }

    /// Distance from `p` to the piece's spine (the curve of rolling-ball centres, its ends
    /// included): the global closest point of the certified projection. O(projection).
    pub fn spine_distance(&self, p: &Vector3<f64>) -> f64 {
        (p - self.projector.closest_point(p).point).norm()
    }

    /// Signed distance of `p` to the fillet material of this piece (module docs) and the
    /// nearest point of the fillet surface, `None` where the fillet does not decide it.
    fn closest(&self, p: &Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
        // Beyond the sector's reach from the whole spine nothing below can answer; the
        // bounded search proves that from the spine's segment boxes without isolating roots.
        let q = self.projector.closest_point_within(p, self.sector_reach)?;
        let d = p - q.point;
        let tangent = q.tangent.try_normalize(1e-12)?;
        if q.on_boundary || d.dot(&tangent).abs() > 1e-6 * (1.0 + d.norm()) {
            return None;
        }
        let (nh, nb) = contact_normals(&self.normals, q.u)?;
        let (a, b) = (-nh, -nb);
        // d = λ a + μ b (+ a tangent part): the arc's sector when λ, μ ≥ 0.
        let ab = a.dot(&b);
        let det = 1.0 - ab * ab;
        if det < 1e-12 {
            return None;
        }
        let (da, db) = (d.dot(&a), d.dot(&b));
        let lambda = (da - ab * db) / det;
        let mu = (db - ab * da) / det;
        let slack = -1e-9 * (1.0 + d.norm());
        // The corner: on the air side of both walls' tangent planes at the contacts (with
        // CORNER_SLACK·R for the walls' curvature); the sector continues through the hub
        // and the blade, where the fillet is not the nearest material.
        let r = self.sections[0].radius;
        let (hub_foot, blade_foot) = (q.point + a * r, q.point + b * r);
        let inside = -CORNER_SLACK * r;
        if (p - hub_foot).dot(&(-a)) < inside || (p - blade_foot).dot(&(-b)) < inside {
            return None;
        }
        let dn = d.norm();
        (lambda >= slack && mu >= slack && dn > 1e-12).then(|| (r - dn, q.point + d * (r / dn)))
    }
}

/// The fillet of one blade side with the hub (module docs).
#[derive(Debug, Clone)]
pub struct BladeFillet {
    side: Side,
    radius: f64,
    pieces: Vec<FilletPiece>,
    stations: usize,
}

impl BladeFillet {
    /// The fillet of radius `radius` between `hub` and `side` of `blade`, its spine within
    /// `tol_mm` where [`MAX_STATIONS`] allow (module docs). Errors: a radius that is not
    /// positive and finite, a tolerance that is not positive, a fit that fails.
    pub fn build(
        hub: &RevolvedSurface,
        blade: &Blade,
        side: Side,
        radius: f64,
        tol_mm: f64,
    ) -> Result<Self, ModelError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(ModelError::invalid("fillet radius", "must be > 0"));
        }
        if !(tol_mm.is_finite() && tol_mm > 0.0) {
            return Err(ModelError::invalid("fillet tolerance", "must be > 0"));
        }
        let ((u0, u1), _) = blade.side(side).domain();
        let mut n = FIRST_STATIONS;
        // Doubling keeps every station: station k of n is station 2k of 2n − 1 (the same u
        // to the bit, both quotients being of exact integers scaled by 2), so only the odd
        // ones are solved; stations are independent and solved in parallel.
        let mut stations: Vec<Option<FilletSection>> = Vec::new();
        loop {
            stations = (0..n)
                .into_par_iter()
                .map(|k| match (k % 2, stations.get(k / 2)) {
                    (0, Some(known)) => *known,
                    _ => {
                        let u = u0 + (u1 - u0) * k as f64 / (n - 1) as f64;
                        fitting_section(hub, blade, side, u, radius)
                    }
                })
                .collect();
            let mut pieces = Vec::new();
            let mut run: Vec<FilletSection> = Vec::new();
            for s in stations.iter().chain(std::iter::once(&None)) {
                match s {
                    Some(s) => run.push(*s),
                    None => {
                        if run.len() >= 4 {
                            pieces.push(fit_piece(hub, blade, side, std::mem::take(&mut run))?);
                        }
                        run.clear();
                    }
                }
            }
            let worst = pieces
                .iter()
                .map(FilletPiece::fit_error_mm)
                .fold(0.0, f64::max);
            if worst <= tol_mm || 2 * n - 1 > MAX_STATIONS {
                return Ok(Self {
                    side,
                    radius,
                    pieces,
                    stations: n,
                });
            }
            n = 2 * n - 1;
        }
    }

    /// The blade side.
    pub fn side(&self) -> Side {
        self.side
    }

    /// Fillet radius (mm).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Runs of stations where the ball fits, u increasing.
    pub fn pieces(&self) -> &[FilletPiece] {
        &self.pieces
    }

    /// Stations sampled along the side (uniform in `u`).
    pub fn stations(&self) -> usize {
        self.stations
    }

    /// Largest spine error of any piece (mm).
    pub fn fit_error_mm(&self) -> f64 {
        self.pieces
            .iter()
            .map(FilletPiece::fit_error_mm)
            .fold(0.0, f64::max)
    }

    /// Signed distance of `p` to the fillet material (positive in the air), where the fillet
    /// decides the design's distance (module docs); `None` elsewhere.
    pub fn signed_distance(&self, p: &Vector3<f64>) -> Option<f64> {
        self.closest(p).map(|(d, _)| d)
    }

    /// [`Self::signed_distance`] with the nearest point of the fillet surface (on the arc
    /// through `p`'s direction from the ball centre).
    pub fn closest(&self, p: &Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
        self.pieces
            .iter()
            .filter_map(|k| k.closest(p))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// How far the fillet reaches from the blade side and how high up it (mm), the largest
    /// over the sections: the hub contact's distance from the side's tangent plane at the
    /// blade contact, and the blade contact's height above the hub's tangent plane at the hub
    /// contact (`R·cot(β/2)` each in a planar corner of angle `β`).
    pub fn extent_mm(&self) -> (f64, f64) {
        self.pieces
            .iter()
            .flat_map(|k| k.sections.iter())
            .map(|s| {
                let (h, b) = (s.hub_foot(), s.blade_foot());
                ((h - b).dot(&s.blade_normal), (b - h).dot(&s.hub_normal))
            })
            .fold((0.0, 0.0), |a, e| (a.0.max(e.0), a.1.max(e.1)))
    }

    /// Largest distance from a ball centre to its corner over the sections,
    /// `R / sin(β/2)` (`β` the corner's angle), plus `R`: every point whose fillet distance
    /// can be below both its hub and its side distance lies within this of the hub and of
    /// the side (the arc's sector between the centre and the corner).
    pub fn reach_mm(&self) -> f64 {
        self.pieces
            .iter()
            .flat_map(|k| k.sections.iter())
            .map(|s| {
                let half = 0.5 * (std::f64::consts::PI - s.arc_angle());
                s.radius / half.sin().max(1e-3) + s.radius
            })
            .fold(0.0, f64::max)
    }
}

/// The fillets of every blade of an impeller: each row's reference blade's pressure and
/// suction fillets ([`BladeFillet`]) and every instance's rotation about +Z.
///
/// A query at `p` evaluates only the instances whose angular window holds `p`'s polar
/// angle: the polar angles of the row's fillet spine (reference blade, unwrapped), turned by
/// the instance's pitch, widened by `reach / r` (`reach` = [`BladeFillet::reach_mm`] + the
/// radius, `r` the smallest spine radius): a point outside every window is farther than the
/// reach from every fillet sector. Cost: O(blades) angle tests and two certified curve
/// projections per instance in the window.
#[derive(Debug, Clone)]
pub struct ImpellerFillets {
    radius: f64,
    reach: f64,
    /// Per row (main, splitter): the pressure and suction fillets and the angular window of
    /// the reference blade's fillets (rad, unwrapped).
    rows: Vec<([BladeFillet; 2], (f64, f64))>,
    /// Per blade in `+θ` order (main 0, splitter 0, main 1, ...): row and rotation.
    instances: Vec<(usize, nalgebra::Rotation3<f64>)>,
}

impl ImpellerFillets {
    /// The fillets of `impeller` (radius `Impeller::fillet_radius_mm`, spine within
    /// `tol_mm`), or `None` for a radius of 0.
    pub fn new(impeller: &crate::Impeller, tol_mm: f64) -> Result<Option<Self>, ModelError> {
        let radius = impeller.fillet_radius_mm();
        if radius <= 0.0 {
            return Ok(None);
        }
        let mut sets = vec![impeller.main()];
        sets.extend(impeller.splitter());
        let mut rows = Vec::with_capacity(sets.len());
        let mut reach: f64 = 0.0;
        for set in &sets {
            let blade = set.blade();
            let build = |side| BladeFillet::build(impeller.hub(), blade, side, radius, tol_mm);
            let (p, s) = rayon::join(|| build(Side::Pressure), || build(Side::Suction));
            let pair = [p?, s?];
            let mut phis: Vec<f64> = Vec::new();
            let mut r_min = f64::INFINITY;
            for f in &pair {
                reach = reach.max(f.reach_mm());
                for c in f.pieces().iter().flat_map(|k| k.sections().iter()) {
                    phis.push(c.centre.y.atan2(c.centre.x));
                    r_min = r_min.min(c.centre.x.hypot(c.centre.y));
                }
            }
            // Unwrapped about the first angle (a fillet spans far less than a turn).
            let base = phis.first().copied().unwrap_or(0.0);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for phi in phis {
                let d = (phi - base + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                lo = lo.min(base + d);
                hi = hi.max(base + d);
            }
            let margin = (reach + radius) / r_min.max(1e-6);
            rows.push((pair, (lo - margin, hi + margin)));
        }
        let mut instances = Vec::new();
        for k in 0..impeller.main().count() {
            for (row, set) in sets.iter().enumerate() {
                instances.push((row, set.rotation(k)));
            }
        }
        Ok(Some(Self {
            radius,
            reach,
            rows,
            instances,
        }))
    }

    /// Fillet radius (mm).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Largest spine error of any row's fillet (mm), [`BladeFillet::fit_error_mm`].
    pub fn fit_error_mm(&self) -> f64 {
        self.rows
            .iter()
            .flat_map(|r| r.0.iter())
            .map(BladeFillet::fit_error_mm)
            .fold(0.0, f64::max)
    }

    /// [`BladeFillet::reach_mm`] over every fillet.
    pub fn reach_mm(&self) -> f64 {
        self.reach
    }

    /// [`BladeFillet::extent_mm`] over every fillet: (from the side, up from the hub).
    pub fn extent_mm(&self) -> (f64, f64) {
        self.rows
            .iter()
            .flat_map(|r| r.0.iter())
            .map(BladeFillet::extent_mm)
            .fold((0.0, 0.0), |a, e| (a.0.max(e.0), a.1.max(e.1)))
    }

    /// Blades in `+θ` order.
    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// Row (0 main, 1 splitter) and rotation of blade instance `i`.
    pub fn instance(&self, i: usize) -> Option<(usize, &nalgebra::Rotation3<f64>)> {
        self.instances.get(i).map(|(row, rot)| (*row, rot))
    }

    /// The fillet of `side` of row `row`'s reference blade.
    pub fn fillet(&self, row: usize, side: Side) -> Option<&BladeFillet> {
        let k = match side {
            Side::Pressure => 0,
            Side::Suction => 1,
        };
        self.rows.get(row).map(|r| &r.0[k])
    }

    /// Calls `visit` with two bounds for each fillet of the instances whose window holds `p`
    /// (each side's pieces taken together, the smallest over them): the distance `d_spine`
    /// from `p` to the spine, and a lower bound `m` of the distance from `p` to the fillet
    /// material ([`FilletPiece::material_distance_lower`]). The ball of radius `R` about any
    /// spine point is free of design material (it touches hub and side and the fillet lies
    /// outside it), so a sphere about `p` of radius `ρ` is clear of that fillet when
    /// `R − d_spine ≥ ρ` or when `m ≥ ρ`, i.e. when `max(R − d_spine, m) ≥ ρ`; a fillet not
    /// visited is farther than [`Self::reach_mm`] from `p`. The spine distance is exact where
    /// it is below `R − m`, the only place it can decide that maximum, and passed as `+∞`
    /// elsewhere (the spine search is bounded there: most pieces are pruned by their boxes).
    /// Cost: the wedge bounds plus a bounded certified projection per piece.
    /// Material bounds at or above `cap` are passed as some value `≥ cap`.
    pub fn material_bounds(&self, p: &Vector3<f64>, cap: f64, mut visit: impl FnMut(f64, f64)) {
        self.near_instances(p, |pair, _, q| {
            for f in pair {
                if f.pieces.is_empty() {
                    continue;
                }
                let material = f
                    .pieces
                    .iter()
                    .map(|k| k.material_distance_lower(&q, cap))
                    .fold(f64::INFINITY, f64::min);
                // Only a spine nearer than R − material can decide; the bounded search
                // prunes the rest (10⁻⁹ mm above its certification tolerance).
                let within = f.radius - material + 1e-9;
                let spine = f
                    .pieces
                    .iter()
                    .filter_map(|k| k.projector.closest_point_within(&q, within))
                    .map(|c| c.distance)
                    .fold(f64::INFINITY, f64::min);
                visit(spine, material);
            }
        });
    }

    /// Calls `visit` with the fillet pair, the rotation and `p` in the reference blade's frame
    /// for every instance whose angular window holds `p`'s polar angle (unwrapped into it).
    fn near_instances(
        &self,
        p: &Vector3<f64>,
        mut visit: impl FnMut(&[BladeFillet; 2], &nalgebra::Rotation3<f64>, Vector3<f64>),
    ) {
        let phi = p.y.atan2(p.x);
        for (row, rot) in &self.instances {
            let (pair, (lo, hi)) = &self.rows[*row];
            let a = phi - rot.scaled_axis().z;
            let mid = 0.5 * (lo + hi);
            let a = mid
                + ((a - mid + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI);
            if a < *lo || a > *hi {
                continue;
            }
            visit(pair, rot, rot.inverse() * p);
        }
    }

    /// The fillet distance of `p` and the fillet surface point deciding it (the smallest
    /// over the instances whose window holds `p`), `None` where no fillet decides
    /// ([`BladeFillet::closest`]).
    pub fn closest(&self, p: &Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
        let mut best: Option<(f64, Vector3<f64>)> = None;
        self.near_instances(p, |pair, rot, q| {
            for f in pair {
                if let Some((d, foot)) = f.closest(&q) {
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, rot * foot));
                    }
                }
            }
        });
        best
    }
}

/// The section at `u` when its ball fits against the blade and the hub: it touches the hub
/// inside its contour (not at an end), its centre is `R` outside `side` by
/// the global closest point (within [`FIT_CHECK_MM`]) and at least `R` from the other side
/// (unsigned: the ball does not reach it).
fn fitting_section(
    hub: &RevolvedSurface,
    blade: &Blade,
    side: Side,
    u: f64,
    radius: f64,
) -> Option<FilletSection> {
    let s = FilletSection::solve(hub, blade, side, u, radius)?;
    // The ball must touch the hub surface, not roll over an end of its contour (the inlet
    // rim beside a leading edge standing at the hub's end).
    let (t, _) = hub
        .meridional()
        .closest(crate::MeridionalCurve::zr_of(&s.centre));
    let (t0, t1) = hub.meridional().domain();
    let end = 1e-9 * (t1 - t0);
    if t <= t0 + end || t >= t1 - end {
        return None;
    }
    let (own, d_own) = blade_side_distance(blade, side, &s.centre, Some((s.u, s.v)));
    let (other, _) = blade_side_distance(blade, side.other(), &s.centre, None);
    let fits = own.distance.is_finite()
        && (d_own - radius).abs() <= FIT_CHECK_MM
        && other.distance >= radius - FIT_CHECK_MM;
    fits.then_some(s)
}

/// The piece through `sections` (at least 4, uniform in `u`): spine and normals
/// interpolated (cubic, uniform parameters) and their error measured at every midpoint.
fn fit_piece(
    hub: &RevolvedSurface,
    blade: &Blade,
    side: Side,
    sections: Vec<FilletSection>,
) -> Result<FilletPiece, ModelError> {
    let fit_err = |e: nurbs::fit::FitError| ModelError::Geometry(format!("fillet spine: {e}"));
    let centres: Vec<SVector<f64, 3>> = sections.iter().map(|s| s.centre).collect();
    let normals: Vec<SVector<f64, 6>> = sections
        .iter()
        .map(|s| {
            let (h, b) = (s.hub_normal, s.blade_normal);
            SVector::<f64, 6>::from([h.x, h.y, h.z, b.x, b.y, b.z])
        })
        .collect();
    let spine = interpolate_curve(&centres, 3, Parametrisation::Uniform, None).map_err(fit_err)?;
    let normals =
        interpolate_curve(&normals, 3, Parametrisation::Uniform, None).map_err(fit_err)?;
    let n = sections.len();
    let radius = sections[0].radius;
    let fit_error_mm = (0..n - 1)
        .into_par_iter()
        .map(|k| {
            let um = 0.5 * (sections[k].u + sections[k + 1].u);
            let t = (k as f64 + 0.5) / (n - 1) as f64;
            FilletSection::solve(hub, blade, side, um, radius)
                .map_or(f64::INFINITY, |s| (spine.point(t) - s.centre).norm())
        })
        .reduce(|| 0.0, f64::max);
    let projector = CurveProjector::new(&spine);
    let sector_reach = sector_reach(&normals, sections.len(), radius);
    Ok(FilletPiece {
        sections,
        spine,
        normals,
        projector,
        sector_reach,
        fit_error_mm,
        wedges: std::sync::OnceLock::new(),
    })
}

/// The unit hub and blade normals (out of the material, toward the ball) of the
/// contact-normal curve at `t`, `None` where either vanishes.
fn contact_normals(normals: &NurbsCurve<6>, t: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let n = normals.point(t);
    Some((
        Vector3::new(n[0], n[1], n[2]).try_normalize(1e-12)?,
        Vector3::new(n[3], n[4], n[5]).try_normalize(1e-12)?,
    ))
}

/// Samples of the contact-normal curve per section interval in [`sector_reach`].
const REACH_SAMPLES_PER_SECTION: usize = 16;

/// Relative margin of [`sector_reach`] over its sampled value.
const REACH_MARGIN: f64 = 0.1;

/// How far from its spine point a point can lie where [`FilletPiece::closest`] answers.
/// There `d = p − c(t) = λ·a + μ·b` (up to a tangent part below 10⁻⁶·|d|) with `λ, μ ≥ 0`, and
/// `p` is on the air side of both walls' tangent planes moved in by `k·R` (`k` =
/// [`CORNER_SLACK`]): `d·a ≤ (1 + k)·R` and `d·b ≤ (1 + k)·R`. On that quadrilateral of the
/// `(a, b)` plane `|d|` is largest at the corner `d·a = d·b = (1 + k)·R`, where
/// `|d| = (1 + k)·R / cos(γ/2)` (`γ` the angle between `a` and `b`). The largest `γ` of the
/// contact-normal curve is taken over [`REACH_SAMPLES_PER_SECTION`] samples per section
/// interval, and the bound widened by [`REACH_MARGIN`] for the curve between samples and the
/// tangent part; a corner opening to within about 1° of flat (no bound worth the name) gives an
/// infinite reach (the unbounded search). O(sections) evaluations.
fn sector_reach(normals: &NurbsCurve<6>, sections: usize, radius: f64) -> f64 {
    let n = (sections.max(2) - 1) * REACH_SAMPLES_PER_SECTION + 1;
    let (t0, t1) = normals.domain();
    let mut half_cos = f64::INFINITY;
    for k in 0..n {
        let t = t0 + (t1 - t0) * k as f64 / (n - 1) as f64;
        let Some((a, b)) = contact_normals(normals, t) else {
            return f64::INFINITY;
        };
        let gamma = a.dot(&b).clamp(-1.0, 1.0).acos();
        half_cos = half_cos.min((0.5 * gamma).cos());
    }
    if half_cos.is_nan() || half_cos <= 0.01 {
        return f64::INFINITY;
    }
    (1.0 + REACH_MARGIN) * (1.0 + CORNER_SLACK) * radius / half_cos
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blade::BladeKind;
    use crate::meridional::MeridionalCurve;
    use nurbs::NurbsSurface;

    /// Both fillets of the default impeller's main blade.
    fn default_main_fillets() -> Vec<BladeFillet> {
        let imp = crate::fixtures::default_impeller().expect("fixture");
        [Side::Pressure, Side::Suction]
            .into_iter()
            .map(|side| {
                BladeFillet::build(
                    imp.hub(),
                    imp.main().blade(),
                    side,
                    imp.fillet_radius_mm(),
                    DEFAULT_FILLET_TOL_MM,
                )
                .expect("fillet")
            })
            .collect()
    }

    /// The culled wedge search (nearest first, spheres and plane bounds) returns what every
    /// wedge gives (to 1e-12 mm), with and without a cap, at points around the default
    /// impeller's fillets (near the material, inside the balls, beyond the piece's ends and
    /// far off); and the plane bounds cull (the point of them).
    #[test]
    fn culled_material_bound_is_the_bound_over_every_wedge() {
        let mut culled_blocks = 0usize;
        for f in default_main_fillets() {
            for piece in f.pieces() {
                let (u0, u1) = piece.u_range();
                for k in 0..600 {
                    let t = -0.05 + 1.1 * k as f64 / 599.0;
                    let s = piece.section_at((u0 + (u1 - u0) * t).clamp(u0, u1));
                    let scale = [0.5, 2.0, 8.0][k % 3];
                    let w = Vector3::new(
                        ((k * 37) % 101) as f64 / 50.0 - 1.0,
                        ((k * 61) % 103) as f64 / 51.5 - 1.0,
                        ((k * 13) % 107) as f64 / 53.5 - 1.0,
                    ) * scale;
                    let p = s.centre + w;
                    for cap in [f64::INFINITY, 1.0, 0.2] {
                        let a = piece.material_distance_lower(&p, cap);
                        let b = piece.material_distance_lower_all(&p, cap);
                        assert!((a - b).abs() < 1e-12, "{p:?} cap {cap}: {a} vs {b}");
                    }
                    let wd = piece.wedges.get().expect("built");
                    let best = piece.material_distance_lower_all(&p, f64::INFINITY);
                    culled_blocks += wd
                        .blocks
                        .iter()
                        .filter(|b| {
                            let sphere = (p - b.centre).norm() - b.radius;
                            sphere < best && b.lower(&p) >= best
                        })
                        .count();
                }
            }
        }
        assert!(
            culled_blocks > 3_000,
            "{culled_blocks} blocks culled by the planes"
        );
    }

    /// `material_bounds`' bounded spine distances decide the rolling-ball test exactly as the
    /// exact spine distances: `max(R − d_spine, m)` is the same (to 1e-9 mm) at points
    /// around every blade root of the default impeller (hub and side, near and beyond the
    /// rolling balls); and the bound prunes (some spines passed as +∞).
    #[test]
    fn bounded_spines_decide_the_material_test_as_exact_ones() {
        let imp = crate::fixtures::default_impeller().expect("fixture");
        let f = ImpellerFillets::new(&imp, DEFAULT_FILLET_TOL_MM)
            .expect("fillets")
            .expect("a fillet radius");
        let r = f.radius();
        let (mut visits, mut infinite) = (0, 0);
        for row in 0..2 {
            for side in [Side::Pressure, Side::Suction] {
                let bf = f.fillet(row, side).expect("row fillet");
                for piece in bf.pieces() {
                    let (u0, u1) = piece.u_range();
                    for k in 0..300 {
                        let s = piece.section_at(u0 + (u1 - u0) * k as f64 / 299.0);
                        let w = Vector3::new(
                            ((k * 37) % 101) as f64 / 25.0 - 2.0,
                            ((k * 61) % 103) as f64 / 25.75 - 2.0,
                            ((k * 13) % 107) as f64 / 26.75 - 2.0,
                        );
                        let p = s.centre + w;
                        let mut got = Vec::new();
                        f.material_bounds(&p, 10.0, |spine, m| got.push((spine, m)));
                        let mut want = Vec::new();
                        f.near_instances(&p, |pair, _, q| {
                            for bf in pair {
                                if bf.pieces.is_empty() {
                                    continue;
                                }
                                let spine = bf
                                    .pieces
                                    .iter()
                                    .map(|k| k.spine_distance(&q))
                                    .fold(f64::INFINITY, f64::min);
                                let m = bf
                                    .pieces
                                    .iter()
                                    .map(|k| k.material_distance_lower(&q, 10.0))
                                    .fold(f64::INFINITY, f64::min);
                                want.push((spine, m));
                            }
                        });
                        assert_eq!(got.len(), want.len(), "{p:?}");
                        for (g, w) in got.iter().zip(&want) {
                            visits += 1;
                            infinite += usize::from(g.0.is_infinite());
                            assert_eq!(g.1, w.1);
                            let (a, b) = ((r - g.0).max(g.1), (r - w.0).max(w.1));
                            assert!((a - b).abs() < 1e-9, "{p:?}: {g:?} vs {w:?}");
                        }
                    }
                }
            }
        }
        assert!(
            visits > 1000 && infinite > 100 && infinite < visits,
            "{visits} visits, {infinite} pruned"
        );
    }

    /// The bounded spine search answers exactly as the unbounded one: on the default
    /// impeller's fillets (both sides of the main blade), points around the spines with
    /// offsets up to 5 mm (inside and beyond the sector reach, the piece's ends included)
    /// get the same answer, `None` included, to 1e-9 mm; and the reach is finite and
    /// prunes (some points beyond it).
    #[test]
    fn the_sector_reach_changes_no_answer() {
        let mut pruned = 0;
        let mut answered = 0;
        for f in default_main_fillets() {
            for piece in f.pieces() {
                assert!(
                    piece.sector_reach.is_finite() && piece.sector_reach < 5.0,
                    "{}",
                    piece.sector_reach
                );
                let mut unbounded = piece.clone();
                unbounded.sector_reach = f64::INFINITY;
                let (u0, u1) = piece.u_range();
                for k in 0..2000 {
                    let t = -0.05 + 1.1 * k as f64 / 1999.0;
                    let s = piece.section_at((u0 + (u1 - u0) * t).clamp(u0, u1));
                    let w = Vector3::new(
                        ((k * 37) % 101) as f64 / 10.0 - 5.0,
                        ((k * 61) % 103) as f64 / 10.3 - 5.0,
                        ((k * 13) % 107) as f64 / 10.7 - 5.0,
                    );
                    // Even k: in the corner's sector, from inside the ball to beyond the
                    // corner; odd k: anywhere around.
                    let p = if k % 2 == 0 {
                        let (a, b) = (-s.hub_normal, -s.blade_normal);
                        let f = ((k * 7) % 11) as f64 / 10.0;
                        let rho = s.radius * (0.2 + 1.6 * ((k * 17) % 13) as f64 / 12.0);
                        s.centre + (a * (1.0 - f) + b * f).normalize() * rho
                    } else {
                        s.centre + w
                    };
                    let a = piece.closest(&p);
                    let b = unbounded.closest(&p);
                    match (a, b) {
                        (Some(a), Some(b)) => {
                            answered += 1;
                            assert!((a.0 - b.0).abs() < 1e-9, "{p:?}: {a:?} vs {b:?}");
                            assert!((a.1 - b.1).norm() < 1e-9, "{p:?}: {a:?} vs {b:?}");
                        }
                        (None, None) => {
                            if piece.projector.closest_point(&p).distance > piece.sector_reach {
                                pruned += 1;
                            }
                        }
                        _ => panic!("{p:?}: bounded {a:?}, unbounded {b:?}"),
                    }
                }
            }
        }
        assert!(
            answered > 500 && pruned > 500,
            "{answered} answered, {pruned} pruned"
        );
    }

    /// A plane patch through `o` spanned by `eu` (u, 0..1) and `ev` (v, 0..1), bilinear.
    fn plane(o: Vector3<f64>, eu: Vector3<f64>, ev: Vector3<f64>) -> NurbsSurface {
        let ctrl = vec![vec![o, o + ev], vec![o + eu, o + eu + ev]];
        NurbsSurface::new(
            1,
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
            ctrl,
            None,
        )
        .expect("plane")
    }

    /// The flat hub z = 0 from r = 5 to r = 80 (channel side +z).
    fn flat_hub() -> RevolvedSurface {
        let c = NurbsCurve::<2>::new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![SVector::from([0.0, 5.0]), SVector::from([0.0, 80.0])],
            None,
        )
        .expect("line");
        RevolvedSurface::new(MeridionalCurve::new(c).expect("contour")).expect("hub")
    }

    /// A radial blade at φ ≈ 0 whose pressure side (y = 0 at the hub, facing −y) leans by
    /// `lean` (rad) toward −y with height, the suction side 2 mm away in +y.
    fn leaning_blade(lean: f64) -> Blade {
        let up = Vector3::new(0.0, -lean.sin(), lean.cos()) * 40.0;
        let below = Vector3::new(0.0, lean.sin(), -lean.cos()) * 5.0;
        let eu = Vector3::new(40.0, 0.0, 0.0);
        let pressure = plane(Vector3::new(15.0, 0.0, 0.0) + below, eu, up);
        let suction = plane(Vector3::new(15.0, 2.0, 0.0) + below, eu, up);
        Blade::from_sides(BladeKind::Ruled, pressure, suction, None).expect("blade")
    }

    #[test]
    fn section_in_a_planar_corner_matches_the_closed_form() {
        let hub = flat_hub();
        for lean_deg in [0.0_f64, 20.0, -25.0] {
            let lean = lean_deg.to_radians();
            let blade = leaning_blade(lean);
            let r = 1.5;
            // Corner angle between the hub (+z) and the pressure side in the air (−y side):
            // β = 90° − lean (the side leans over the air). The ball centre is on the
            // bisector, r / sin(β/2) from the corner line (the x axis), r above the hub and r
            // from the side: c = (x, −r·(1 + sin(lean))/cos(lean), r).
            let beta = std::f64::consts::FRAC_PI_2 - lean;
            let s = FilletSection::solve(&hub, &blade, Side::Pressure, 0.5, r).expect("section");
            let cy = -r * (1.0 + lean.sin()) / lean.cos();
            assert!((s.centre.x - 35.0).abs() < 1e-9, "{s:?}");
            assert!(
                (s.centre.y - cy).abs() < 1e-9,
                "lean {lean_deg}: {s:?} vs {cy}"
            );
            assert!((s.centre.z - r).abs() < 1e-12, "{s:?}");
            let corner = Vector3::new(s.centre.x, 0.0, 0.0);
            assert!(((s.centre - corner).norm() - r / (0.5 * beta).sin()).abs() < 1e-9);
            // Contacts on the planes, the arc's angle π − β, every arc point r from c.
            assert!(s.hub_foot().z.abs() < 1e-12);
            let nb = blade
                .outward_normal(Side::Pressure, 0.5, 0.5)
                .expect("normal");
            assert!(
                (s.blade_foot() - Vector3::new(35.0, 0.0, 0.0))
                    .dot(&nb)
                    .abs()
                    < 1e-9
            );
            assert!((s.arc_angle() - (std::f64::consts::PI - beta)).abs() < 1e-12);
            let arc = s.arc().expect("arc");
            for k in 0..=16 {
                let t = k as f64 / 16.0;
                assert!(((arc.point(t) - s.centre).norm() - r).abs() < 1e-12);
                assert!(((s.arc_point(t) - s.centre).norm() - r).abs() < 1e-12);
            }
            assert!((arc.point(0.0) - s.hub_foot()).norm() < 1e-12);
            assert!((arc.point(1.0) - s.blade_foot()).norm() < 1e-12);
        }
    }

    #[test]
    fn planar_fillet_distance_is_the_rolling_balls() {
        let hub = flat_hub();
        let lean = 10.0_f64.to_radians();
        let blade = leaning_blade(lean);
        let r = 2.0;
        let f = BladeFillet::build(&hub, &blade, Side::Pressure, r, 1e-6).expect("fillet");
        assert_eq!(f.pieces().len(), 1);
        assert!(f.fit_error_mm() < 1e-9, "{}", f.fit_error_mm());
        let cy = -r * (1.0 + lean.sin()) / lean.cos();
        // In the corner's sector of the ball: R − |p − c|, inside the ball (air) and beyond
        // it (fillet material) alike.
        for (dy, dz) in [(0.3, -0.4), (0.5, -1.2), (0.4, -1.6), (0.8, -0.9)] {
            let p = Vector3::new(30.0, cy + dy, r + dz);
            let c = Vector3::new(30.0, cy, r);
            let want = r - (p - c).norm();
            let got = f.signed_distance(&p).expect("in the sector");
            assert!((got - want).abs() < 1e-9, "{p:?}: {got} vs {want}");
        }
        // Under the hub (the sector goes on through it), above the ball's centre (the side
        // is nearer) and away from the corner: not decided.
        assert!(f
            .signed_distance(&Vector3::new(30.0, cy + 0.1, -0.5))
            .is_none());
        assert!(f
            .signed_distance(&Vector3::new(30.0, cy - 1.0, r + 1.0))
            .is_none());
        assert!(f
            .signed_distance(&Vector3::new(30.0, cy - 5.0, 0.5))
            .is_none());
        // Beyond the blade's ends.
        assert!(f.signed_distance(&Vector3::new(60.0, cy, 0.5)).is_none());
    }

    #[test]
    fn no_section_where_the_offsets_do_not_meet() {
        let hub = flat_hub();
        let blade = leaning_blade(0.0);
        // A ball taller than the side (45 mm above the hub at most) never touches the hub
        // and the side at once.
        assert!(FilletSection::solve(&hub, &blade, Side::Pressure, 0.5, 60.0).is_none());
        assert!(BladeFillet::build(&hub, &blade, Side::Pressure, 0.0, 1e-4).is_err());
    }
}
