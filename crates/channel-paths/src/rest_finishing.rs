//! Rest finishing (paper 003 §4, the "secondary cut" after verification): ball-end point
//! milling of only the places where the job's earlier operations left material above the
//! design, with a smaller tool.
//!
//! It lives beside hub and blade-root finishing because what it cuts is theirs: the corners
//! where hub, blade sides and fillets meet, which a larger ball cannot enter. It reads the
//! stock those operations leave ([`cam_plan::RemainingMaterial`]: the pipeline simulates their
//! cuts on the blank and measures the residual at the verifier's design samples).
//!
//! # Regions
//! On each surface's sample grid the samples whose residual exceeds `threshold_mm` are grouped
//! into *regions*, the connected components of the grid (8-neighbourhood). A region's
//! area is the sum of its samples' cells ([`cam_plan::RestGrid::cell_area_mm2`]).
//!
//! # Ball centres
//! Let `D(p)` be a lower bound of the distance of `p` to the design material, positive in the
//! air, exact on hub and blades (NURBS, [`cam_plan::DesignClearance`]) and away from the
//! blade-root fillets, conservative by the wedge bound near them (see below). A region's cut is made of *passes* along the
//! grid direction in which the region is longer, at most one step-over apart across it (the
//! exact circle–circle step-over of a flat surface, [`cam_core::ball_step_over`], for
//! `scallop_mm`), sampled at most `0.25·r` apart along. Each pass sample is a point `s` of the
//! grid (bilinear between the samples); its ball centre is `s` moved onto the offset surface
//! `D = r` by the fixed-point iteration `c ← c + (r − D(c))·∇D(c)` (central differences,
//! `|r − D(c)| ≤ 1e-7` mm, at most 60 steps). On a face this is `s + r·n`; in a concave corner it
//! converges to the ball that touches both walls nearest to `s` (in a corner of orthogonal
//! walls in two steps, geometrically in sharper ones), so a corner the ball cannot enter is
//! cut as deep as the ball reaches and no deeper. A sample whose iteration does not settle
//! is left out (its pass is split there).
//!
//! # Clearance, fillets included
//! The fillet's distance is defined only inside the arc's sector: a ball whose centre lies
//! outside every sector (beyond a fillet's end, where the fillet stops at the hub's rim) can
//! still reach into the fillet (a Ø1 ball beside the impeller-8+8 leading-edge roots cut
//! 0.025–0.15 mm into the fillet's end when judged on it). Clearance and the centres are
//! therefore judged on a margin that bounds the true distance from below everywhere: a
//! sphere of radius `ρ` about `p` is clear when `min(d_hub, d_blade) ≥ ρ` (sharp design) and,
//! for the fillets, `max(d_hub, d_blade) ≥ reach + ρ` (the fillet material lies within
//! [`ImpellerFillets::reach_mm`] of both walls) or, for every fillet near `p`, `p` lies in one
//! of its rolling balls (`R − d_spine ≥ ρ`: a rolling ball holds no material) or the lower
//! bound of its distance to the fillet's material is `≥ ρ`
//! ([`ImpellerFillets::material_bounds`]: the material lies section by section in the wedge
//! of the contact directions, sampled every 0.01 mm of spine, each sample's exact distance
//! less its neighbours' spread). The margin is 1-Lipschitz, so the motion certificates below
//! hold for it; `D(p)` above is the margin of the point `p` (ρ = 0).
//!
//! # Tool axis
//! Every cutter sample ([`cam_plan::DesignClearance::samples`]) above the ball centre keeps a
//! margin `≥ −tol/2`; shank and holder (the query's frusta against the design mesh) keep the
//! largest residual measured anywhere plus `tol` (they must not rub the stock that is still
//! there), along motions too ([`cam_plan::DesignClearance::segment_clearance`]). Axes are
//! searched in rings of `step_deg` around the *preferred axis* (the sum of the unit normals of
//! the walls within `r + tol` of the centre: the bisector of a corner) up to `max_tilt_deg`,
//! tried in order of their angle to the previous station's axis (the same axis wherever it is
//! clear, so the rotary axes move only where they must); the machine must reach the axis
//! ([`cam_plan::PlanContext::reaches`]). A station with no clear axis is skipped.
//!
//! Every motion between consecutive stations is certified: for each tool sample (the ball
//! included) the margin along the motion (centre linear, axis turned at constant rate) is a
//! Lipschitz function with constant `|Δc| + |h − r|·Δθ`, bisected until each interval's lower
//! bound `(f₀ + f₁)/2 − L·Δs/2` clears the floor (at most 2¹⁴ pieces). A motion that fails
//! splits the pass; passes are joined at feed where that motion certifies (a link at feed,
//! [`cam_core::MoveKind::Link`]), else linked over the safety surface
//! ([`cam_plan::PlanContext::link`]).
//!
//! Once a region's runs are placed, their axes are smoothed about the ball centres by the
//! shared step [`cam_plan::axis_smoothing`] (issue 37: the ring search picks neighbouring
//! axes that alternate, and the rotary axes would chatter inside the cut): a turned posture
//! keeps the floors above, and the motions touching it certify, or the planned posture
//! stays (`axis_reversals_*` and `axis_smoothing_*` metrics; a plot of the run with the most
//! direction changes).
//!
//! # Measured
//! `residual_before_max_mm`, `target_area_mm2`: from the stock read. `residual_after_max_mm`:
//! for every target sample, the height along its normal to the first ball station the normal
//! meets, as the verifier measures residual (an upper bound of what is left: the motions
//! between stations cut more). Targets still
//! above `threshold_mm` are *unreachable* with this plan (`unreachable_points`, with their
//! area): in a sharp concave corner of angle `β` a ball of radius `r` leaves
//! `r(1/sin(β/2) − 1)` at the corner line whatever its path. Of those, `corner_points` (and
//! `corner_area_mm2`) are proven out of reach of every ball of radius `r` or more: the ball
//! tangent at the sample (centre on its normal) overlaps the design by at least
//! `CORNER_OVERLAP_MM` (distances to points of the design's closed material: an upper bound
//! of the centre's distance), and where the surface is smooth a ball can touch a point only
//! from its normal; the rest could be touched by a ball and are left by this plan.
//! `max_overcut_mm`: the largest negative margin of a station's ball (≤ tol/2 by
//! construction).
//!
//! Cost: O(stations · iterations · design distance) for the centres, O(stations · axes tried
//! · tool samples · design distance) for the postures, O(motions · samples · bisections) for
//! the motions; regions run in parallel (rayon).

use cam_core::{CutterLocation, Move, ToolPath};
use cam_plan::{
    ClearanceOptions, DesignClearance, FilletMargin, Metrics, Operation, OperationSpec, PartSet,
    PlanContext, PlanError, PlannedOperation, Plot, PlotKind, PlotSeries, Point3, RestGrid,
};
use nalgebra::{UnitQuaternion, Vector3};
use rayon::prelude::*;
use serde::Deserialize;

use crate::accessibility::ball_radius;

/// Kind key of rest finishing in job files.
pub const REST_FINISHING: &str = "rest_finishing";

/// Approach length above a path's first point (mm).
const APPROACH_MM: f64 = 2.0;
/// Fixed-point steps of a ball centre onto the offset surface.
const SETTLE_STEPS: usize = 60;
/// Accepted offset error of a settled centre (mm).
const SETTLE_TOL_MM: f64 = 1e-7;
/// Central-difference step of the distance gradient (mm).
const GRAD_STEP_MM: f64 = 1e-5;
/// Queries allowed to certify the shank and holder along a motion.
const SHANK_QUERIES: usize = 64;
/// Deepest bisection of a motion's certificate (2¹⁴ pieces).
const MOTION_DEPTH: usize = 14;

fn default_threshold() -> f64 {
    0.1
}
fn default_scallop() -> f64 {
    0.01
}
fn default_max_tilt() -> f64 {
    75.0
}
fn default_step() -> f64 {
    5.0
}

/// The kind's own job keys.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Residual above which a sample is rest material (mm).
    #[serde(default = "default_threshold")]
    threshold_mm: f64,
    /// Scallop height between passes (mm).
    #[serde(default = "default_scallop")]
    scallop_mm: f64,
    /// Largest angle of the axis from the preferred axis (degrees).
    #[serde(default = "default_max_tilt")]
    max_tilt_deg: f64,
    /// Ring step of the axis search (degrees).
    #[serde(default = "default_step")]
    step_deg: f64,
}

/// Rest finishing, kind [`REST_FINISHING`].
#[derive(Debug, Clone)]
pub struct RestFinishing {
    name: String,
    tool: String,
    params: Params,
}

/// Builds a [`RestFinishing`] from its job table. Keys: `threshold_mm` (> 0, default 0.1),
/// `scallop_mm` (> 0, default 0.01), `max_tilt_deg` ([0, 89], default 75), `step_deg`
/// ((0, 15], default 5).
pub fn build_rest_finishing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let p: Params = cam_plan::params::parse(spec)?;
    let bad = |key: &str, why: String| Err(PlanError::param(&spec.name, key, why));
    if !(p.threshold_mm.is_finite() && p.threshold_mm > 0.0) {
        return bad(
            "threshold_mm",
            format!("{} must be finite and > 0", p.threshold_mm),
        );
    }
    if !(p.scallop_mm.is_finite() && p.scallop_mm > 0.0) {
        return bad(
            "scallop_mm",
            format!("{} must be finite and > 0", p.scallop_mm),
        );
    }
    if !(p.max_tilt_deg.is_finite() && (0.0..=89.0).contains(&p.max_tilt_deg)) {
        return bad(
            "max_tilt_deg",
            format!("{} must be in [0, 89]", p.max_tilt_deg),
        );
    }
    if !(p.step_deg.is_finite() && p.step_deg > 0.0 && p.step_deg <= 15.0) {
        return bad("step_deg", format!("{} must be in (0, 15]", p.step_deg));
    }
    Ok(Box::new(RestFinishing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params: p,
    }))
}

/// A region: the grid it lies on and its samples `(i, j)`.
#[derive(Debug, Clone)]
struct Region {
    grid: usize,
    cells: Vec<(usize, usize)>,
}

/// The connected components (8-neighbourhood) of the samples of `g` above `threshold`.
fn regions_of(g: &RestGrid, grid: usize, threshold: f64) -> Vec<Region> {
    let above = |i: usize, j: usize| g.residual(i, j).is_some_and(|r| r > threshold);
    let mut seen = vec![false; g.nu * g.nv];
    let mut out = Vec::new();
    for j0 in 0..g.nv {
        for i0 in 0..g.nu {
            if seen[j0 * g.nu + i0] || !above(i0, j0) {
                continue;
            }
            seen[j0 * g.nu + i0] = true;
            let mut stack = vec![(i0, j0)];
            let mut cells = Vec::new();
            while let Some((i, j)) = stack.pop() {
                cells.push((i, j));
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (ni, nj) = (i as i64 + di, j as i64 + dj);
                        if ni < 0 || nj < 0 || ni >= g.nu as i64 || nj >= g.nv as i64 {
                            continue;
                        }
                        let (ni, nj) = (ni as usize, nj as usize);
                        if !seen[nj * g.nu + ni] && above(ni, nj) {
                            seen[nj * g.nu + ni] = true;
                            stack.push((ni, nj));
                        }
                    }
                }
            }
            cells.sort_unstable_by_key(|&(i, j)| (j, i));
            out.push(Region { grid, cells });
        }
    }
    out
}

/// A ball station: centre, unit axis and the cutter location.
#[derive(Debug, Clone, Copy)]
struct Station {
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    cl: CutterLocation,
}

/// The planner of one operation: the design distance with fillets, the tool's samples and
/// the floors.
struct Planner<'a> {
    ctx: &'a PlanContext<'a>,
    material: DesignClearance<'a>,
    fillets: Option<FilletMargin>,
    r: f64,
    tol: f64,
    /// Cutter samples above the ball centre: (height above the tip, radius, floor).
    upper: Vec<(f64, f64, f64)>,
    /// Shank and holder against hub and blades (the cutter left out).
    shank: DesignClearance<'a>,
    /// What shank and holder keep from the design: the largest residual plus `tol`.
    stock_margin: f64,
    max_tilt: f64,
    step: f64,
}

/// Overlap with the design (mm) of the ball tangent at a sample left above the threshold
/// from which the sample counts as out of every ball's reach (`corner_points`): well above
/// the design distances' accuracy and the normal's (central differences; an error `α` moves
/// the tangent ball by `r·α²/2`).
const CORNER_OVERLAP_MM: f64 = 0.005;

/// The signed distance of one wall (hub, blades, fillets) where it is defined.
type WallDistance<'a> = dyn Fn(&Vector3<f64>) -> Option<f64> + 'a;

/// Per-region outcome.
#[derive(Debug, Default)]
struct RegionResult {
    runs: Vec<Vec<Station>>,
    passes: usize,
    skipped: usize,
    unsettled: usize,
    fillet_blocked: usize,
    split: usize,
    max_overcut: f64,
    /// The axis smoothing of the runs ([`cam_plan::axis_smoothing`]).
    smoothing: cam_plan::SmoothingSummary,
}

impl Planner<'_> {
    /// `D(p)`: the lower bound of the distance to hub, blades and fillets (module docs),
    /// [`Self::margin`] of a point.
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        self.margin(p, 0.0)
    }

    /// Clearance margin of the sphere of radius `rho` about `p` (≥ 0: clear of hub, blades
    /// and fillets): the sharp design's `min(d_hub, d_blade) − ρ`, and for the fillets
    /// `max(max(d_hub, d_blade) − reach − ρ, min_k(R − d_k − ρ))` with `d_k` the distance to
    /// fillet `k`'s spine (module docs). 1-Lipschitz in `p`.
    fn margin(&self, p: &Vector3<f64>, rho: f64) -> f64 {
        let q = Point3::from(*p);
        let hub = self.material.hub_signed_distance(&q);
        let blade = self.material.blade_signed_distance(&q).0;
        match &self.fillets {
            Some(f) => f.margin(p, rho, hub, blade),
            None => hub.min(blade) - rho,
        }
    }

    fn gradient(&self, p: &Vector3<f64>) -> Vector3<f64> {
        central_gradient(|q| self.distance(q), p)
    }

    /// The ball centre of pass sample `s` on the offset surface `D = r` (module docs).
    fn settle(&self, s: &Vector3<f64>) -> Option<Vector3<f64>> {
        let mut c = *s;
        for _ in 0..SETTLE_STEPS {
            let e = self.r - self.distance(&c);
            if e.abs() <= SETTLE_TOL_MM {
                return Some(c);
            }
            let g = self.gradient(&c).try_normalize(1e-9)?;
            c += g * e;
        }
        None
    }

    /// The outward unit normal at the design point `p` of the surface named `surface` (the
    /// verifier's names: `hub`, `<blade>_fillet_<side>`, blade sides and tips): the
    /// gradient of that part's distance (central differences).
    fn surface_normal(&self, surface: &str, p: &Vector3<f64>) -> Vector3<f64> {
        let part = |q: &Vector3<f64>| -> f64 {
            let pt = Point3::from(*q);
            if surface == "hub" {
                self.material.hub_signed_distance(&pt)
            } else if surface.contains("_fillet_") {
                self.fillets
                    .as_ref()
                    .and_then(|f| f.fillets().closest(q))
                    .map_or_else(|| self.distance(q), |(d, _)| d)
            } else {
                self.material.blade_signed_distance(&pt).0
            }
        };
        central_gradient(part, p)
            .try_normalize(1e-9)
            .unwrap_or_else(|| self.gradient(p).normalize())
    }

    /// How deep the ball of radius `r` tangent to the design at `p` (outward unit normal `n`;
    /// centre `p + r·n`) overlaps the design: `r` less an upper bound of the distance from the
    /// centre to the design, each term the distance to a point of the design's closed
    /// material (the exact hub and blade signed distances, the fillet's arc point where a
    /// fillet decides). Positive: that ball gouges. Where the surface is smooth at `p`, every
    /// ball whose sphere passes through `p` without entering the material has its centre on
    /// the normal, and a ball of radius `R ≥ r` tangent there holds this one: no ball of
    /// radius `r` or more reaches `p`. O(one design distance).
    fn tangent_ball_overlap(&self, p: &Vector3<f64>, n: &Vector3<f64>) -> f64 {
        let c = p + n * self.r;
        let q = Point3::from(c);
        let hub = self.material.hub_signed_distance(&q);
        let blade = self.material.blade_signed_distance(&q).0;
        let fillet = self
            .fillets
            .as_ref()
            .and_then(|f| f.fillets().closest(&c))
            .map_or(f64::INFINITY, |(d, _)| d);
        self.r - hub.min(blade).min(fillet)
    }

    /// The preferred axis at centre `c`: the sum of the unit normals of the walls (hub,
    /// blade, fillet) within `r + tol` of it.
    fn preferred_axis(&self, c: &Vector3<f64>) -> Vector3<f64> {
        let near = self.r + self.tol;
        let parts: [&WallDistance<'_>; 3] = [
            &|p| Some(self.material.hub_signed_distance(&Point3::from(*p))),
            &|p| Some(self.material.blade_signed_distance(&Point3::from(*p)).0),
            &|p| {
                self.fillets
                    .as_ref()
                    .and_then(|f| f.fillets().closest(p).map(|(d, _)| d))
            },
        ];
        let mut sum = Vector3::zeros();
        for f in parts {
            if !f(c).is_some_and(|d| d <= near) {
                continue;
            }
            // A wall defined on one side of `c` only has no gradient here (NaN): the design's.
            let g = central_gradient(|q| f(q).unwrap_or(f64::NAN), c);
            if !g.iter().all(|x| x.is_finite()) {
                return self.gradient(c).try_normalize(1e-9).unwrap_or(Vector3::z());
            }
            if let Some(u) = g.try_normalize(1e-9) {
                sum += u;
            }
        }
        sum.try_normalize(1e-9)
            .unwrap_or_else(|| self.gradient(c).try_normalize(1e-9).unwrap_or(Vector3::z()))
    }

    /// Smallest margin of the tool above the ball over its floors at `(c, axis)` (negative:
    /// not clear); stops below 0.
    fn posture_margin(&self, c: &Vector3<f64>, axis: &Vector3<f64>) -> f64 {
        let tip = c - axis * self.r;
        let mut best = f64::INFINITY;
        for &(h, rho, floor) in &self.upper {
            let m = self.margin(&(tip + axis * h), rho) - floor;
            best = best.min(m);
            if best < 0.0 {
                return best;
            }
        }
        match CutterLocation::new(Point3::from(tip), *axis) {
            Ok(cl) if self.shank.is_clear(&cl, self.stock_margin) => best,
            _ => -1.0,
        }
    }

    /// The axes tried at `c` (module docs), nearest to `prefer_near` first.
    fn candidate_axes(
        &self,
        c: &Vector3<f64>,
        prefer_near: Option<&Vector3<f64>>,
    ) -> Vec<Vector3<f64>> {
        let a0 = self.preferred_axis(c);
        let u = a0
            .cross(&Vector3::x())
            .try_normalize(1e-6)
            .unwrap_or_else(|| a0.cross(&Vector3::y()).normalize());
        let v = a0.cross(&u);
        let rings = (self.max_tilt / self.step).floor() as usize;
        let mut out = vec![a0];
        for k in 1..=rings {
            let th = k as f64 * self.step;
            let m = ((std::f64::consts::TAU * th.sin() / self.step).ceil() as usize).max(6);
            for q in 0..m {
                let ph = std::f64::consts::TAU * q as f64 / m as f64;
                out.push((a0 * th.cos() + (u * ph.cos() + v * ph.sin()) * th.sin()).normalize());
            }
        }
        let target = prefer_near.copied().unwrap_or(a0);
        out.sort_by(|a, b| b.dot(&target).total_cmp(&a.dot(&target)));
        if let Some(p) = prefer_near {
            if p.dot(&a0) >= self.max_tilt.cos() {
                out.insert(0, *p);
            }
        }
        out
    }

    /// A clear posture with its ball centre at `c` (None: none within the search).
    fn posture(&self, c: &Vector3<f64>, prev: Option<&Vector3<f64>>) -> Option<Station> {
        self.candidate_axes(c, prev).into_iter().find_map(|a| {
            if !self.ctx.reaches(&a) || self.posture_margin(c, &a) < 0.0 {
                return None;
            }
            let cl = CutterLocation::new(Point3::from(c - a * self.r), a).ok()?;
            Some(Station {
                centre: *c,
                axis: a,
                cl,
            })
        })
    }

    /// Whether the motion from `a` to `b` is certified clear (module docs).
    fn motion_clear(&self, a: &Station, b: &Station) -> bool {
        let turn = UnitQuaternion::rotation_between(&a.axis, &b.axis)
            .map(|q| q.scaled_axis())
            .unwrap_or_else(Vector3::zeros);
        let theta = turn.norm();
        let dc = (b.centre - a.centre).norm();
        let at = |s: f64, h: f64| -> Vector3<f64> {
            let axis = UnitQuaternion::from_scaled_axis(turn * s) * a.axis;
            let c = a.centre + (b.centre - a.centre) * s;
            c + axis * (h - self.r)
        };
        let ball = (self.r, self.r, -0.5 * self.tol);
        // Non-cutting parts keep their floor; the whole tool keeps `margin ≥ floor`.
        std::iter::once(ball)
            .chain(self.upper.iter().copied())
            .all(|(h, rho, floor)| {
                let f = |s: f64| self.margin(&at(s, h), rho);
                let lip = dc + (h - self.r).abs() * theta;
                certify(&f, lip, floor, (0.0, f(0.0)), (1.0, f(1.0)), 0)
            })
            && self
                .shank
                .segment_clearance(
                    &a.cl,
                    &b.cl,
                    self.stock_margin,
                    0.5 * self.tol,
                    SHANK_QUERIES,
                )
                .is_ok()
    }

    /// Plans the passes of `region` on `g`; `pass_done(k, n)` is called after the `k`-th of
    /// its `n` passes (progress).
    fn plan_region(
        &self,
        g: &RestGrid,
        region: &Region,
        step: f64,
        pass_done: &dyn Fn(usize, usize),
    ) -> RegionResult {
        let mut res = RegionResult::default();
        let (mut i0, mut i1, mut j0, mut j1) = (usize::MAX, 0, usize::MAX, 0);
        for &(i, j) in &region.cells {
            i0 = i0.min(i);
            i1 = i1.max(i);
            j0 = j0.min(j);
            j1 = j1.max(j);
        }
        // One cell around the region, inside the grid.
        let (i0, j0) = (i0.saturating_sub(1), j0.saturating_sub(1));
        let (i1, j1) = ((i1 + 1).min(g.nu - 1), (j1 + 1).min(g.nv - 1));
        let length = |along_i: bool, k: usize| -> f64 {
            let (lo, hi) = if along_i { (i0, i1) } else { (j0, j1) };
            (lo..hi)
                .filter_map(|a| {
                    let (p, q) = if along_i {
                        (g.point(a, k), g.point(a + 1, k))
                    } else {
                        (g.point(k, a), g.point(k, a + 1))
                    };
                    Some((Vector3::from(p?) - Vector3::from(q?)).norm())
                })
                .sum()
        };
        let len_i = (j0..=j1).map(|j| length(true, j)).fold(0.0, f64::max);
        let len_j = (i0..=i1).map(|i| length(false, i)).fold(0.0, f64::max);
        let along_i = len_i >= len_j;
        let (len_along, len_across) = if along_i {
            (len_i, len_j)
        } else {
            (len_j, len_i)
        };
        let n_across = ((len_across / step).ceil() as usize + 1).max(1);
        let n_along = ((len_along / (0.25 * self.r)).ceil() as usize + 1).max(2);
        let in_region = |fi: f64, fj: f64| {
            let (ci, cj) = (fi.round() as i64, fj.round() as i64);
            region
                .cells
                .iter()
                .any(|&(i, j)| (i as i64 - ci).abs() <= 1 && (j as i64 - cj).abs() <= 1)
        };
        let mut prev_axis: Option<Vector3<f64>> = None;
        for k in 0..n_across {
            let fk = if n_across == 1 {
                0.5
            } else {
                k as f64 / (n_across - 1) as f64
            };
            let mut run: Vec<Station> = Vec::new();
            let mut pass_runs = Vec::new();
            let order: Vec<usize> = if k % 2 == 0 {
                (0..n_along).collect()
            } else {
                (0..n_along).rev().collect()
            };
            for q in order {
                let fq = q as f64 / (n_along - 1) as f64;
                let (fi, fj) = if along_i {
                    (
                        i0 as f64 + fq * (i1 - i0) as f64,
                        j0 as f64 + fk * (j1 - j0) as f64,
                    )
                } else {
                    (
                        i0 as f64 + fk * (i1 - i0) as f64,
                        j0 as f64 + fq * (j1 - j0) as f64,
                    )
                };
                let station = in_region(fi, fj)
                    .then(|| bilinear(g, fi, fj))
                    .flatten()
                    .and_then(|s| {
                        let c = self.settle(&s);
                        if c.is_none() {
                            res.unsettled += 1;
                        }
                        c
                    })
                    .filter(|c| {
                        let clear = self.margin(c, self.r) >= -0.5 * self.tol;
                        if !clear {
                            res.fillet_blocked += 1;
                        }
                        clear
                    })
                    .and_then(|c| {
                        let st = self.posture(&c, prev_axis.as_ref());
                        if st.is_none() {
                            res.skipped += 1;
                        }
                        st
                    });
                let Some(st) = station else {
                    if !run.is_empty() {
                        pass_runs.push(std::mem::take(&mut run));
                    }
                    continue;
                };
                prev_axis = Some(st.axis);
                res.max_overcut = res.max_overcut.max(-self.margin(&st.centre, self.r));
                if let Some(last) = run.last() {
                    if (last.centre - st.centre).norm() < 1e-4 {
                        continue;
                    }
                    if !self.motion_clear(last, &st) {
                        res.split += 1;
                        pass_runs.push(std::mem::take(&mut run));
                    }
                }
                run.push(st);
            }
            if !run.is_empty() {
                pass_runs.push(run);
            }
            if !pass_runs.is_empty() {
                res.passes += 1;
            }
            res.runs.extend(pass_runs);
            pass_done(k + 1, n_across);
        }
        res.max_overcut = res.max_overcut.max(0.0);
        self.smooth_axes(&mut res);
        res
    }

    /// The shared axis smoothing ([`cam_plan::axis_smoothing`]) of every run: each posture
    /// turns about its ball centre (the ball, so every contact and the residual it leaves,
    /// stays where it was placed), a turned posture is kept only when the machine reaches its
    /// axis and the tool keeps this planner's floors ([`Self::posture_margin`]), and every
    /// motion touching one is certified as the planned ones are ([`Self::motion_clear`]).
    fn smooth_axes(&self, res: &mut RegionResult) {
        let opts = cam_plan::AxisSmoothing::ball_end(self.r);
        for run in &mut res.runs {
            let cls: Vec<CutterLocation> = run.iter().map(|s| s.cl).collect();
            let out = cam_plan::axis_smoothing::smooth_run(&cls, &opts, self);
            res.smoothing.add(&out);
            for (s, cl) in run.iter_mut().zip(out.postures) {
                s.axis = cl.axis.into_inner();
                s.cl = cl;
            }
        }
    }

    /// The runs of one region as a closed path: consecutive runs joined at feed where the
    /// motion certifies and is at most `near` long, else linked.
    fn path(
        &self,
        name: String,
        tool: &str,
        runs: &[Vec<Station>],
        near: f64,
    ) -> Result<(ToolPath, usize), PlanError> {
        let mut path = ToolPath::new(name, tool);
        let mut joined = 0;
        let mut last: Option<Station> = None;
        for run in runs {
            let Some(first) = run.first() else { continue };
            match last {
                None => path.moves.push(Move::feed(first.cl)),
                Some(l) => {
                    if (l.centre - first.centre).norm() <= near && self.motion_clear(&l, first) {
                        path.moves.push(Move::link(first.cl));
                        joined += 1;
                    } else {
                        path.moves
                            .extend(self.ctx.link(&l.cl, &first.cl, APPROACH_MM)?);
                    }
                }
            }
            path.moves
                .extend(run.iter().skip(1).map(|s| Move::feed(s.cl)));
            last = run.last().copied();
        }
        self.ctx.close(&mut path, APPROACH_MM)?;
        Ok((path, joined))
    }
}

/// Each point of `points` as a cross of half-width `d` for a line chart (strokes separated by
/// NaN, which lifts the pen): scattered samples drawn as markers, not joined.
fn crosses(points: &[[f64; 2]], d: f64) -> Vec<[f64; 2]> {
    let gap = [f64::NAN, f64::NAN];
    points
        .iter()
        .flat_map(|&[x, y]| [[x - d, y], [x + d, y], gap, [x, y - d], [x, y + d], gap])
        .collect()
}

/// The gradient of `f` at `p` by central differences of [`GRAD_STEP_MM`].
fn central_gradient(f: impl Fn(&Vector3<f64>) -> f64, p: &Vector3<f64>) -> Vector3<f64> {
    let h = GRAD_STEP_MM;
    let mut g = Vector3::zeros();
    for k in 0..3 {
        let mut e = Vector3::zeros();
        e[k] = h;
        g[k] = (f(&(p + e)) - f(&(p - e))) / (2.0 * h);
    }
    g
}

/// The residual the balls of radius `r` about `centres` leave above the design point `p` along
/// its normal `n`: the distance along the ray `p + t·n` (`t ≥ 0`) to the first ball it meets
/// (0 when `p` lies in one; infinite when it meets none). The verifier measures the residual
/// the same way, so this bounds what the stations leave from above (the motions between them
/// cut more). O(centres).
fn ray_entry(p: &Vector3<f64>, n: &Vector3<f64>, centres: &[Vector3<f64>], r: f64) -> f64 {
    centres
        .iter()
        .filter_map(|c| {
            let w = c - p;
            let b = w.dot(n);
            let disc = b * b - (w.norm_squared() - r * r);
            (disc >= 0.0).then(|| {
                let s = disc.sqrt();
                (b + s >= 0.0).then_some((b - s).max(0.0))
            })?
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether `f` (Lipschitz constant `lip` on `[a.0, b.0]`, values `a.1`, `b.1` at the ends)
/// stays at or above `floor` on the interval: the lower bound `(f(a) + f(b))/2 − lip·(b − a)/2`
/// of a Lipschitz function, bisected until it clears (at most [`MOTION_DEPTH`] levels).
fn certify(
    f: &dyn Fn(f64) -> f64,
    lip: f64,
    floor: f64,
    a: (f64, f64),
    b: (f64, f64),
    depth: usize,
) -> bool {
    if a.1 < floor || b.1 < floor {
        return false;
    }
    if 0.5 * (a.1 + b.1) - 0.5 * lip * (b.0 - a.0) >= floor {
        return true;
    }
    if depth >= MOTION_DEPTH {
        return false;
    }
    let m = 0.5 * (a.0 + b.0);
    let fm = (m, f(m));
    certify(f, lip, floor, a, fm, depth + 1) && certify(f, lip, floor, fm, b, depth + 1)
}

/// The grid point at fractional indices `(fi, fj)`: bilinear between its cell's four
/// samples, the weights of missing ones (under a fillet, inside a blade: the holes of a
/// surface's grid) shared by the others; `None` where all four are missing. A start point
/// only: the ball centre is settled on the design from it.
fn bilinear(g: &RestGrid, fi: f64, fj: f64) -> Option<Vector3<f64>> {
    let i = (fi.floor().max(0.0) as usize).min(g.nu.saturating_sub(2));
    let j = (fj.floor().max(0.0) as usize).min(g.nv.saturating_sub(2));
    let (a, b) = (
        (fi - i as f64).clamp(0.0, 1.0),
        (fj - j as f64).clamp(0.0, 1.0),
    );
    let p = |i: usize, j: usize| -> Option<Vector3<f64>> {
        g.residual(i, j)?;
        g.point(i, j).map(Vector3::from)
    };
    let corners = [
        (p(i, j), (1.0 - a) * (1.0 - b)),
        (p(i + 1, j), a * (1.0 - b)),
        (p(i, j + 1), (1.0 - a) * b),
        (p(i + 1, j + 1), a * b),
    ];
    let (sum, weight) = corners
        .iter()
        .filter_map(|(q, w)| q.map(|q| (q * *w, *w)))
        .fold((Vector3::zeros(), 0.0), |(s, t), (q, w)| (s + q, t + w));
    if corners.iter().all(|(q, _)| q.is_none()) {
        return None;
    }
    if weight > 1e-12 {
        return Some(sum / weight);
    }
    // The present samples carry no weight here (a corner of the cell): the nearest of them.
    corners.iter().filter_map(|(q, _)| *q).next()
}

impl cam_plan::PostureCheck for Planner<'_> {
    type Clear = ();
    fn posture_clear(&self, _: usize, cl: &CutterLocation) -> Option<()> {
        let axis = cl.axis.into_inner();
        let c = cl.tip.coords + axis * self.r;
        (self.ctx.reaches(&axis) && self.posture_margin(&c, &axis) >= 0.0).then_some(())
    }
    fn planned_clear(&self, _: usize, _: &CutterLocation) -> Option<()> {
        // Planned postures passed the same check when they were chosen.
        Some(())
    }
    fn motion_clear(
        &self,
        _: usize,
        (a, _): (&CutterLocation, &()),
        (b, _): (&CutterLocation, &()),
    ) -> bool {
        let station = |cl: &CutterLocation| Station {
            centre: cl.tip.coords + cl.axis.into_inner() * self.r,
            axis: cl.axis.into_inner(),
            cl: *cl,
        };
        self.motion_clear(&station(a), &station(b))
    }
}

impl Operation for RestFinishing {
    fn kind(&self) -> &'static str {
        REST_FINISHING
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn needs_remaining(&self) -> bool {
        true
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        let r = ball_radius(ctx, &self.name, "rest finishing")?;
        let remaining = ctx.remaining.ok_or_else(|| {
            PlanError::geometry(
                &self.name,
                "the stock",
                "rest finishing plans from the stock the earlier operations leave, and none was given (it needs earlier operations in the job)",
            )
        })?;
        if remaining.after.is_empty() {
            return Err(PlanError::geometry(
                &self.name,
                "the stock",
                "rest finishing machines what earlier operations leave, and none comes before it in the job",
            ));
        }
        let tol = ctx.tolerances.machining_tol;
        let fillets = FilletMargin::new(ctx.impeller)
            .map_err(|e| PlanError::geometry(&self.name, "blade-root fillets", e.to_string()))?;
        let stock_margin = remaining.max_residual_mm() + tol;
        let flutes = ctx.tool.cutter.flute_length;
        let upper = ctx
            .clearance
            .samples()
            .filter(|&(h, _)| h > r + 1e-9)
            .map(|(h, rho)| (h, rho, -0.5 * tol))
            .collect();
        let planner = Planner {
            ctx,
            material: ctx.clearance.with_options(ClearanceOptions {
                parts: PartSet::MATERIAL,
                ..ctx.clearance.options()
            }),
            fillets,
            r,
            tol,
            upper,
            shank: ctx.clearance.with_options(ClearanceOptions {
                parts: PartSet::MATERIAL,
                above_mm: flutes,
                ..ctx.clearance.options()
            }),
            stock_margin,
            max_tilt: self.params.max_tilt_deg.to_radians(),
            step: self.params.step_deg.to_radians(),
        };
        let step = cam_core::ball_step_over(r, 0.0, self.params.scallop_mm)
            .map_err(|e| PlanError::param(&self.name, "scallop_mm", e.to_string()))?;
        let threshold = self.params.threshold_mm;
        let regions: Vec<Region> = remaining
            .grids
            .iter()
            .enumerate()
            .flat_map(|(k, g)| regions_of(g, k, threshold))
            .collect();
        // Progress in residual samples above the threshold: a region's samples are credited
        // pass by pass (after pass k of n, ⌊cells·k/n⌋ of them), so a large region shows it
        // moves too.
        let total_cells: usize = regions.iter().map(|r| r.cells.len()).sum();
        let done_cells = std::sync::atomic::AtomicUsize::new(0);
        ctx.progress("samples above the threshold", 0, total_cells);
        let results: Vec<RegionResult> = regions
            .par_iter()
            .map(|reg| {
                let cells = reg.cells.len();
                let pass_done = |k: usize, n: usize| {
                    let share = |k: usize| cells * k / n.max(1);
                    let credit = share(k) - share(k - 1);
                    let done =
                        done_cells.fetch_add(credit, std::sync::atomic::Ordering::Relaxed) + credit;
                    ctx.progress("samples above the threshold", done, total_cells);
                };
                planner.plan_region(&remaining.grids[reg.grid], reg, step, &pass_done)
            })
            .collect();

        // What each target keeps: the nearest station's ball (an upper bound).
        let centres: Vec<Vector3<f64>> = results
            .iter()
            .flat_map(|res| res.runs.iter().flatten().map(|s| s.centre))
            .collect();
        let mut target_points = 0usize;
        let (mut area, mut unreachable_area, mut unreachable) = (0.0, 0.0, 0usize);
        // Of those left, the ones no ball of radius ≥ r reaches (CORNER_OVERLAP_MM).
        let (mut corner_area, mut corner) = (0.0, 0usize);
        let (mut before_max, mut after_max): (f64, f64) = (0.0, 0.0);
        let mut before_series = Vec::new();
        let mut after_series = Vec::new();
        let mut corner_series = Vec::new();
        for reg in &regions {
            let g = &remaining.grids[reg.grid];
            for &(i, j) in &reg.cells {
                let (Some(p), Some(before)) = (g.point(i, j), g.residual(i, j)) else {
                    continue;
                };
                let p = Vector3::from(p);
                let cell = g.cell_area_mm2(i, j);
                target_points += 1;
                area += cell;
                before_max = before_max.max(before);
                let n = planner.surface_normal(&g.surface, &p);
                let after = before.min(ray_entry(&p, &n, &centres, r));
                after_max = after_max.max(after);
                let rz = [p.x.hypot(p.y), p.z];
                before_series.push(rz);
                if after > threshold {
                    unreachable += 1;
                    unreachable_area += cell;
                    after_series.push(rz);
                    if planner.tangent_ball_overlap(&p, &n) >= CORNER_OVERLAP_MM {
                        corner += 1;
                        corner_area += cell;
                        corner_series.push(rz);
                    }
                }
            }
        }

        let mut paths = Vec::new();
        let mut joined = 0usize;
        let mut sum = RegionResult::default();
        let mut order: Vec<(f64, usize)> = results
            .iter()
            .enumerate()
            .filter_map(|(k, res)| {
                let c = res.runs.first()?.first()?.centre;
                Some((c.y.atan2(c.x), k))
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        for &(_, k) in &order {
            let res = &results[k];
            let surface = &remaining.grids[regions[k].grid].surface;
            let (path, j) = planner.path(
                format!("{} {surface} region {k}", self.name),
                &self.tool,
                &res.runs,
                2.0 * step + r,
            )?;
            joined += j;
            paths.push(path);
        }
        for res in &results {
            sum.passes += res.passes;
            sum.skipped += res.skipped;
            sum.unsettled += res.unsettled;
            sum.fillet_blocked += res.fillet_blocked;
            sum.split += res.split;
            sum.max_overcut = sum.max_overcut.max(res.max_overcut);
            sum.smoothing.merge(&res.smoothing);
        }
        let stations = centres.len();
        let mut metrics = Metrics::new();
        metrics
            .count("regions", regions.len())
            .count("target_points", target_points)
            .number("target_area_mm2", area)
            .number("threshold_mm", threshold)
            .number("residual_before_max_mm", before_max)
            .number("residual_after_max_mm", after_max)
            .count("unreachable_points", unreachable)
            .number("unreachable_area_mm2", unreachable_area)
            .count("corner_points", corner)
            .number("corner_area_mm2", corner_area)
            .count("passes", sum.passes)
            .count("stations", stations)
            .count("skipped_locations", sum.skipped)
            .count("unsettled_locations", sum.unsettled)
            .count("fillet_blocked_locations", sum.fillet_blocked)
            .count("split_motions", sum.split)
            .number("step_over_mm", step)
            .number("max_overcut_mm", sum.max_overcut);
        sum.smoothing.add_metrics(&mut metrics);
        let mut notes = vec![format!(
            "{} regions above {threshold} mm after {} ({target_points} samples, {area:.2} mm²; largest residual {before_max:.3} mm): {} passes, {stations} ball stations, {joined} pass-to-pass steps at feed; largest residual left at the stations {after_max:.3} mm",
            regions.len(),
            remaining.after.join(", "),
            sum.passes,
        )];
        if unreachable > 0 {
            let left = unreachable - corner;
            let left_area = (unreachable_area - corner_area).max(0.0);
            notes.push(format!(
                "{unreachable} samples ({unreachable_area:.2} mm²) stay above {threshold} mm: no station of the ball of radius {r} mm cuts them below it. {corner} of them ({corner_area:.2} mm²) no ball of radius {r} mm or more reaches: the ball tangent there overlaps the design by at least {CORNER_OVERLAP_MM} mm (corners sharper than the ball); {left} ({left_area:.2} mm²) a ball could touch but this plan leaves (locations left out: see below)"
            ));
        }
        if sum.skipped > 0 || sum.unsettled > 0 || sum.split > 0 || sum.fillet_blocked > 0 {
            notes.push(format!(
                "{} locations without a clear axis within {}° of the preferred one, {} whose ball centre did not settle, {} whose ball cannot be certified clear of a fillet (near both walls and outside every rolling ball: at a fillet's end), {} motions not clear as a whole (split there)",
                sum.skipped, self.params.max_tilt_deg, sum.unsettled, sum.fillet_blocked, sum.split
            ));
        }
        if sum.smoothing.runs > 0 {
            notes.push(sum.smoothing.note());
        }
        if regions.is_empty() {
            notes.push(format!(
                "nothing above {threshold} mm is left: no rest to machine"
            ));
        }
        let mut plots = vec![Plot {
            title: "Rest finishing, meridional view: targets, what is left, ball centres".into(),
            kind: PlotKind::Lines {
                x_label: "radius (mm)".into(),
                y_label: "z (mm)".into(),
                series: vec![
                    PlotSeries {
                        label: "above the threshold before".into(),
                        points: crosses(&before_series, 0.4),
                    },
                    PlotSeries {
                        label: "left above it by the stations".into(),
                        points: crosses(&after_series, 0.25),
                    },
                    PlotSeries {
                        label: "of those, out of every ball's reach".into(),
                        points: crosses(&corner_series, 0.15),
                    },
                    PlotSeries {
                        label: "ball centres".into(),
                        points: crosses(
                            &centres
                                .iter()
                                .map(|c| [c.x.hypot(c.y), c.z])
                                .collect::<Vec<_>>(),
                            0.1,
                        ),
                    },
                ],
                equal_aspect: true,
            },
        }];
        plots.extend(sum.smoothing.plot());
        Ok(PlannedOperation {
            paths,
            metrics,
            plots,
            notes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_are_the_connected_components_above_the_threshold() {
        let (nu, nv) = (6, 4);
        let mut residual = vec![Some(0.0); nu * nv];
        for (i, j) in [(0, 0), (1, 1), (4, 2), (5, 3), (5, 0)] {
            residual[j * nu + i] = Some(0.2);
        }
        residual[3] = None;
        let g = RestGrid {
            surface: "hub".into(),
            nu,
            nv,
            points: (0..nu * nv)
                .map(|k| [(k % nu) as f64, (k / nu) as f64, 0.0])
                .collect(),
            residual_mm: residual,
        };
        let regs = regions_of(&g, 0, 0.1);
        let mut sizes: Vec<usize> = regs.iter().map(|r| r.cells.len()).collect();
        sizes.sort_unstable();
        // (0,0)-(1,1) touch diagonally; (4,2)-(5,3) too; (5,0) stands alone.
        assert_eq!(sizes, vec![1, 2, 2]);
    }

    #[test]
    fn ray_entry_is_the_height_to_the_first_ball_along_the_normal() {
        let p = Vector3::zeros();
        let n = Vector3::z();
        // A ball of radius 1 centred 3 above p: entered at height 2; one beside the ray: missed.
        let cs = [Vector3::new(0.0, 0.0, 3.0), Vector3::new(5.0, 0.0, 1.0)];
        assert!((ray_entry(&p, &n, &cs, 1.0) - 2.0).abs() < 1e-12);
        // A ball holding p: nothing left; a ball below p only: none met.
        assert_eq!(ray_entry(&p, &n, &[Vector3::new(0.0, 0.2, 0.1)], 1.0), 0.0);
        assert!(ray_entry(&p, &n, &[Vector3::new(0.0, 0.0, -3.0)], 1.0).is_infinite());
    }

    #[test]
    fn certify_finds_a_dip_between_clear_ends() {
        // f(s) = |s − 0.5| − 0.01 dips below 0 at the middle; Lipschitz constant 1.
        let f = |s: f64| (s - 0.5).abs() - 0.01;
        assert!(!certify(&f, 1.0, 0.0, (0.0, f(0.0)), (1.0, f(1.0)), 0));
        // Lifted by 0.02 it stays above 0 everywhere and is certified.
        let g = |s: f64| (s - 0.5).abs() + 0.01;
        assert!(certify(&g, 1.0, 0.0, (0.0, g(0.0)), (1.0, g(1.0)), 0));
    }

    #[test]
    fn bilinear_interpolates_inside_and_shares_the_weight_of_missing_samples() {
        let g = RestGrid {
            surface: "s".into(),
            nu: 2,
            nv: 2,
            points: vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 2.0, 0.0],
                [2.0, 2.0, 4.0],
            ],
            residual_mm: vec![Some(0.0), Some(0.0), Some(0.0), Some(0.0)],
        };
        let p = bilinear(&g, 0.5, 0.5).unwrap();
        assert!((p - Vector3::new(1.0, 1.0, 1.0)).norm() < 1e-12);
        // Without (1, 1) the other three share its weight: their mean at the centre.
        let mut h = g.clone();
        h.residual_mm[3] = None;
        let q = bilinear(&h, 0.5, 0.5).unwrap();
        assert!((q - Vector3::new(2.0 / 3.0, 2.0 / 3.0, 0.0)).norm() < 1e-12);
        // At the missing corner itself, the nearest present one.
        assert!(bilinear(&h, 1.0, 1.0).is_some());
        h.residual_mm = vec![None; 4];
        assert!(bilinear(&h, 0.5, 0.5).is_none());
    }
}
