//! The exact intersection of an axis-parallel ray with the solid a cutter sweeps over one
//! straight segment of pure translation (the tool axis does not turn).
//!
//! Let `C` be the convex cutting solid of [`crate::tool_solid`] (a stack of sphere slabs
//! and frustums; the bull-nose torus is not handled here) and `P` the translation. The
//! swept solid `S = C ⊕ [0, 1]·P = conv(C ∪ (C + P))` is convex, so a ray meets it in one
//! interval. Its boundary lies in `∂C ∪ ∂(C + P) ∪ {g + s·P : g ∈ Γ, s ∈ [0, 1]}` where `Γ`
//! (the contour generator) holds the points of `∂C` with a supporting plane parallel to
//! `P`. On a piece (a quadric cut by the slab `h₀ ≤ h ≤ h₁`) `Γ` consists of
//!
//! * **sphere** of centre `c`, radius `R`: the great circle normal to `P`; its sweep is the
//!   cylinder of radius `R` about the line `c + s·P`: a quadratic in the ray parameter λ;
//! * **frustum** `r(h) = r₀ + k·(h − h₀)`: the two generator lines at the angles `φ` from
//!   `P⊥` (the part of `P` normal to the axis) with `cos φ = k·(P·a)/|P⊥|` (outward normal
//!   `ρ̂ − k·a` normal to `P`); each sweeps a planar parallelogram: a linear equation;
//! * **rim circles** of the slab faces (radius `r(hⱼ) > 0`): their sweep is the oblique
//!   cylinder through the circle along `P`, a quadratic; when `P` is parallel to the face
//!   (`P·a = 0`) the face sweeps a planar stadium, met at one point.
//!
//! A rim between two pieces where the profile is tangent-continuous (ball to shank,
//! sphere to taper) carries no contour point of its own and is skipped. The ray interval is
//! the hull of the end intervals (closed form, [`RevolvedSolid::ray_hull`]) and of every
//! candidate above whose sweep fraction `s` lies in `[0, 1]` and whose generator lies in
//! its piece: each candidate is a point `g + s·P` with `g ∈ C`, so it lies in `S`
//! (the interval never exceeds the swept solid), and the entry and exit of the ray are
//! among them (the interval is exact). Candidates are accepted with a slack of
//! [`ACCEPT`] in `s` and in height (10⁻¹² relative), far below the removal's `f32` storage.
//!
//! Cost: two closed-form end intersections plus, per piece, one quadratic (sphere) or two
//! linear solves (frustum) and one quadratic per kept rim: O(pieces), no iteration, no
//! allocation.

use crate::tool_solid::{Piece, RayLocal, RevolvedSolid};

/// Relative slack of the candidate checks (`s ∈ [−ε, 1 + ε]`, heights within `ε·scale`).
const ACCEPT: f64 = 1e-12;

/// Most pieces and rims of a sweepable cutting part.
const MAX_PIECES: usize = 4;

/// A rim circle of the cutting part's profile that carries contour points: height and
/// radius.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rim {
    h: f64,
    r: f64,
}

/// A cutting solid prepared for [`SweptSolid::ray_interval`]: its pieces (sphere slabs and
/// frustums only) and the rims between non-tangent pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct SweptSolid {
    solid: RevolvedSolid,
    rims: [Rim; MAX_PIECES + 1],
    n_rims: usize,
}

#[inline]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
fn axpy(x: &[f64; 3], t: f64, y: &[f64; 3]) -> [f64; 3] {
    [x[0] + t * y[0], x[1] + t * y[1], x[2] + t * y[2]]
}

/// Slope `dr/dh` of a piece's profile at height `h`.
fn slope(p: &Piece, h: f64) -> f64 {
    match *p {
        Piece::Frustum { h0, h1, r0, r1 } => {
            if h1 > h0 {
                (r1 - r0) / (h1 - h0)
            } else {
                0.0
            }
        }
        Piece::Sphere { hc, .. } => {
            let r = p.radius_at(h);
            if r > 0.0 {
                -(h - hc) / r
            } else {
                f64::INFINITY
            }
        }
        Piece::Torus { .. } => f64::NAN,
    }
}

/// Roots of `a λ² + 2 b λ + c = 0` (none when `a` vanishes or the roots are complex).
#[inline]
fn roots(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a <= 1e-14 {
        return None;
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let q = -(b + b.signum() * sq);
    if q == 0.0 {
        return Some((-b / a, -b / a));
    }
    Some((q / a, c / q))
}

impl SweptSolid {
    /// The kernel of a cutting part; `None` when it has a torus piece (bull-nose corner)
    /// or more than [`MAX_PIECES`] pieces: such cutters keep the sampled path.
    pub fn new(solid: &RevolvedSolid) -> Option<Self> {
        let pieces = solid.pieces();
        if pieces.is_empty()
            || pieces.len() > MAX_PIECES
            || pieces.iter().any(|p| matches!(p, Piece::Torus { .. }))
        {
            return None;
        }
        let mut rims = [Rim { h: 0.0, r: 0.0 }; MAX_PIECES + 1];
        let mut n_rims = 0;
        let mut push = |h: f64, r: f64| {
            if r > 0.0 {
                rims[n_rims] = Rim { h, r };
                n_rims += 1;
            }
        };
        let first = pieces[0];
        push(first.heights().0, first.radius_at(first.heights().0));
        for w in pieces.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            let h = lo.heights().1;
            let (s0, s1) = (slope(&lo, h), slope(&hi, h));
            let (r0, r1) = (lo.radius_at(h), hi.radius_at(h));
            let smooth = (s0 - s1).abs() <= 1e-9 * (1.0 + s0.abs()) && (r0 - r1).abs() <= 1e-12;
            if !smooth {
                push(h, r0.max(r1));
            }
        }
        let last = pieces[pieces.len() - 1];
        push(last.heights().1, last.radius_at(last.heights().1));
        Some(Self {
            solid: solid.clone(),
            rims,
            n_rims,
        })
    }

    /// The swept cutting solid's interval on the ray along coordinate `d` through the point
    /// whose other two coordinates differ from the end tip's by `(du, dv)`, as λ measured
    /// from the end tip's coordinate along the ray. The solid (unit axis `axis`) is swept
    /// from the tip `−sweep` to the tip `0` (relative to the end tip), i.e. over the
    /// segment that ends at the placement. `None` when the ray misses.
    pub fn ray_interval(
        &self,
        d: usize,
        du: f64,
        dv: f64,
        axis: &[f64; 3],
        sweep: &[f64; 3],
    ) -> Option<(f64, f64)> {
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut take = |l: f64| {
            lo = lo.min(l);
            hi = hi.max(l);
        };
        // End positions: tip 0 and tip −sweep (λ' from the shifted tip: λ = λ' − sweep_d).
        if let Some((s, e)) = self.solid.ray_hull(&RayLocal::new(d, du, dv, axis)) {
            take(s);
            take(e);
        }
        let (pu, pv, pd) = (sweep[ua], sweep[va], sweep[d]);
        let len2 = pu * pu + pv * pv + pd * pd;
        let shifted = RayLocal::new(d, du + pu, dv + pv, axis);
        if let Some((s, e)) = self.solid.ray_hull(&shifted) {
            take(s - pd);
            take(e - pd);
        }
        if len2 > 1e-24 {
            // Local frame (u, v, d), end tip at the origin; positions at s·p, s ∈ [0, 1].
            let o = [du, dv, 0.0];
            let a = [axis[ua], axis[va], axis[d]];
            let p = [-pu, -pv, -pd];
            self.sides(&o, &a, &p, len2, &mut take);
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// Candidates of the swept sides (module docs) on the ray `o + λ·(0, 0, 1)`; `p` the
    /// translation of the positions (`|p|² = len2`), `a` the unit axis, all in the local
    /// frame.
    #[inline]
    fn sides(
        &self,
        o: &[f64; 3],
        a: &[f64; 3],
        p: &[f64; 3],
        len2: f64,
        take: &mut impl FnMut(f64),
    ) {
        let e = [0.0, 0.0, 1.0];
        let s_ok = |s: f64| (-ACCEPT..=1.0 + ACCEPT).contains(&s);
        let len = len2.sqrt();
        let pa = dot(p, a);
        for piece in self.solid.pieces() {
            let (h0, h1) = piece.heights();
            let hslack = ACCEPT * (1.0 + h1.abs() + len);
            match *piece {
                Piece::Sphere { hc, radius, .. } => {
                    // Cylinder of radius R about c + s·p.
                    let c = [hc * a[0], hc * a[1], hc * a[2]];
                    let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
                    let ph = [p[0] / len, p[1] / len, p[2] / len];
                    let g0 = axpy(&oc, -dot(&oc, &ph), &ph);
                    let g1 = axpy(&e, -ph[2], &ph);
                    if let Some((l1, l2)) = roots(
                        dot(&g1, &g1),
                        dot(&g0, &g1),
                        dot(&g0, &g0) - radius * radius,
                    ) {
                        for l in [l1, l2] {
                            let x = axpy(&oc, l, &e);
                            let s = dot(&x, p) / len2;
                            let h = hc + dot(&x, a) - s * pa;
                            if s_ok(s) && h >= h0 - hslack && h <= h1 + hslack {
                                take(l);
                            }
                        }
                    }
                }
                Piece::Frustum { r0, r1, .. } => {
                    let k = if h1 > h0 { (r1 - r0) / (h1 - h0) } else { 0.0 };
                    let perp = axpy(p, -pa, a);
                    let m = dot(&perp, &perp).sqrt();
                    if m <= 1e-12 * len {
                        continue;
                    }
                    let cos = k * pa / m;
                    if cos.abs() > 1.0 {
                        continue;
                    }
                    let u1 = [perp[0] / m, perp[1] / m, perp[2] / m];
                    let u2 = cross(a, &u1);
                    let sin = (1.0 - cos * cos).max(0.0).sqrt();
                    for sg in [1.0, -1.0] {
                        let rho = [
                            cos * u1[0] + sg * sin * u2[0],
                            cos * u1[1] + sg * sin * u2[1],
                            cos * u1[2] + sg * sin * u2[2],
                        ];
                        // Generator B + α·ℓ, α ∈ [0, h1 − h0], swept along p.
                        let b = axpy(&[h0 * a[0], h0 * a[1], h0 * a[2]], r0, &rho);
                        let l = axpy(a, k, &rho);
                        let n = cross(&l, p);
                        let nn = dot(&n, &n);
                        if n[2].abs() <= 1e-12 * nn.sqrt() {
                            continue;
                        }
                        let ob = [b[0] - o[0], b[1] - o[1], b[2] - o[2]];
                        let lam = dot(&n, &ob) / n[2];
                        let w = [-ob[0], -ob[1], -ob[2] + lam];
                        let (ll, lp, pp) = (dot(&l, &l), dot(&l, p), len2);
                        let (wl, wp) = (dot(&w, &l), dot(&w, p));
                        let det = ll * pp - lp * lp;
                        if det <= 0.0 {
                            continue;
                        }
                        let alpha = (wl * pp - wp * lp) / det;
                        let s = (wp * ll - wl * lp) / det;
                        if s_ok(s) && alpha >= -hslack && alpha <= h1 - h0 + hslack {
                            take(lam);
                        }
                    }
                }
                Piece::Torus { .. } => {}
            }
        }
        for rim in &self.rims[..self.n_rims] {
            let c = [rim.h * a[0], rim.h * a[1], rim.h * a[2]];
            let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
            let oca = dot(&oc, a);
            if pa.abs() > 1e-12 * len {
                // Oblique cylinder: y(λ) = x(λ) − t(λ)·p in the rim plane, |y| = r.
                let y0 = axpy(&oc, -oca / pa, p);
                let y1 = axpy(&e, -a[2] / pa, p);
                if let Some((l1, l2)) =
                    roots(dot(&y1, &y1), dot(&y0, &y1), dot(&y0, &y0) - rim.r * rim.r)
                {
                    for l in [l1, l2] {
                        if s_ok((oca + l * a[2]) / pa) {
                            take(l);
                        }
                    }
                }
            }
            if pa.abs() <= 1e-9 * len && a[2].abs() > 1e-12 {
                // The face sweeps a planar stadium: the ray crosses its plane once.
                let l = -oca / a[2];
                let x = axpy(&oc, l, &e);
                let s = (dot(&x, p) / len2).clamp(0.0, 1.0);
                let y = axpy(&x, -s, p);
                if dot(&y, &y) <= rim.r * rim.r {
                    take(l);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{Cutter, CutterShape};

    fn solid(shape: CutterShape) -> RevolvedSolid {
        RevolvedSolid::cutting_part(&Cutter::new("t", shape, 6.0, 2.0, 30.0).unwrap())
    }

    #[test]
    fn torus_cutters_are_not_swept() {
        let s = solid(CutterShape::BullNose {
            radius: 3.0,
            corner_radius: 1.0,
        });
        assert!(SweptSolid::new(&s).is_none());
    }

    #[test]
    fn smooth_junctions_carry_no_rim() {
        let ball = SweptSolid::new(&solid(CutterShape::BallEnd { radius: 1.5 })).unwrap();
        // Only the top face of the flutes.
        assert_eq!(ball.n_rims, 1, "{:?}", &ball.rims[..ball.n_rims]);
        let taper = SweptSolid::new(&solid(CutterShape::TaperedBallEnd {
            ball_radius: 1.0,
            half_angle: 0.05,
        }))
        .unwrap();
        assert_eq!(taper.n_rims, 1);
        let flat = SweptSolid::new(&solid(CutterShape::FlatEnd { radius: 2.0 })).unwrap();
        assert_eq!(flat.n_rims, 2);
    }

    #[test]
    fn capsule_matches_closed_form() {
        // A ball of radius 1.5 swept 4 mm along x with a vertical axis; the ray along z
        // through (2, 0.5) meets the capsule's lower half at z = 1.5 − √(1.5² − 0.5²).
        let s = solid(CutterShape::BallEnd { radius: 1.5 });
        let k = SweptSolid::new(&s).unwrap();
        let (lo, _) = k
            .ray_interval(2, -2.0, 0.5, &[0.0, 0.0, 1.0], &[4.0, 0.0, 0.0])
            .unwrap();
        let want = 1.5 - (1.5f64 * 1.5 - 0.25).sqrt();
        assert!((lo - want).abs() < 1e-12, "{lo} vs {want}");
    }
}
