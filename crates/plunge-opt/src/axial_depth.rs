//! Axial position of a flat-end plunge cutter: how far it may move along its axis before its
//! bottom touches a floor (the hub, or the shroud seen from outside for the start height).
//!
//! # Geometry (paper 000 §4, eqs. 2–9)
//! The cutter's bottom is a disk of radius `R` centred on the axis line `P + t·q` (`q` the
//! unit axis, tip → spindle). On a floor of hyperbolic points (hub and shroud of an impeller:
//! concave along the meridian, convex around the axis, seen from the cutter's side) the first
//! contact of a descending disk lies on its rim circle, and the rim is tangent to the floor
//! there. The contact `Q = S(u, v)` solves
//!
//! - `P + t·q + R·r = S(u, v)` (eq. 2), with `T·n = 0` (eq. 3),
//! - `T = q × n / |q × n|` (eq. 4), `r = q × T` (eq. 5): `r` is the rim direction opposite
//!   to the tangential part of the floor normal `n`, i.e. the rim point that meets the floor
//!   first; when `q ∥ n`, `T = q × PQ / |q × PQ|` (eq. 6) with `PQ = P − Q`, so `r` points
//!   from the axis toward the current contact estimate.
//!
//! Freezing `r` at the current estimate and linearising eq. 2 gives (eq. 7)
//! `q·Δt − S_u·Δu − S_v·Δv = S(u, v) − P − t·q − R·r`, a 3 × 3 linear system in
//! `(Δt, Δu, Δv)`. Paper eq. 8 solves it through its normal equations (dot products with `q`,
//! `S_u`, `S_v`); we solve the square system directly by LU with partial pivoting, which has
//! the same solution and a smaller condition number. Iterations stop when every increment is
//! below [`NEWTON_STEP_TOL`] (1e-9); the bottom centre is then `P + t·q` (eq. 9).
//!
//! With a corner radius `ρ` (bull nose) and an allowance `a`, the torus touches the floor
//! offset by `a` exactly when its centre circle (radius `R − ρ`, height `ρ` above the tip)
//! touches the floor offset by `ρ + a`: the same solve against the offset floor
//! ([`RevolvedFloor::offset`]), then the tip is `ρ` lower along the axis.
//!
//! The frozen-`r` iteration converges linearly with a factor of about `R·κ` (κ the floor's
//! curvature along the rim tangent) — below 0.2 for impeller hubs — so a solve takes 5–15
//! iterations; each costs one contour evaluation with first derivatives (closed form for a
//! surface of revolution). Cost O(iterations); no allocation.
//!
//! The seed is the lowest of [`SEED_RIM_SAMPLES`] rim points of the disk placed where its
//! centre meets the floor, so the iteration starts next to the global contact rather than the
//! opposite tangency of the rim (where `t` is a minimum, not a maximum, over the rim).
//!
//! # General route
//! For a floor that is not hyperbolic everywhere, [`depth_by_projection`] discretises the
//! whole bottom disk (rings × spokes), projects every point along the axis onto the floor and
//! keeps the highest touch (paper 000 Fig. 10), then refines the best rim angle by golden
//! section. On a surface of revolution both routes agree to 1e-6 mm (tests).

use cam_core::{Point3, Vector3};
use impeller_model::MeridionalCurve;
use nalgebra::{Matrix3, Vector2};

/// Increment size below which the Newton iteration of eqs. 7–8 stops (paper 000: "repeat
/// until Δt, Δu, Δv < ε"); in mm for `t`, in contour parameter / radians for `(u, v)`.
pub const NEWTON_STEP_TOL: f64 = 1e-9;
/// Iteration cap of the Newton solve: the linear rate above reaches 1e-9 in well under 60
/// steps; hitting the cap means the axis is (nearly) tangent to the floor.
pub const NEWTON_MAX_ITERATIONS: usize = 60;
/// `|q × n|` below which the axis counts as parallel to the floor normal (eq. 6 instead of
/// eq. 4): below it the direction of `q × n` is rounding noise.
pub const PARALLEL_TOL: f64 = 1e-12;
/// Rim points tried for the seed: 16 directions put a sample within 11.25° of the contact.
pub const SEED_RIM_SAMPLES: usize = 16;

/// Warm start of a contact solve: floor parameters `(u, v)` and axial position `t`.
pub type ContactSeed = ((f64, f64), f64);

/// A floor point with its first derivatives and unit normal toward the cutter's side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorPoint {
    /// `S(u, v)`.
    pub p: Vector3,
    /// `∂S/∂u`.
    pub su: Vector3,
    /// `∂S/∂v`.
    pub sv: Vector3,
    /// Unit normal pointing to the side where the cutter is.
    pub n: Vector3,
}

/// A floor the cutter's bottom descends onto.
pub trait Floor: Sync {
    /// Point, derivatives and normal at `(u, v)`.
    fn eval(&self, u: f64, v: f64) -> FloorPoint;
    /// Parameters of the closest floor point to `p`.
    fn closest_params(&self, p: &Vector3) -> (f64, f64);
    /// Signed distance of `p` (positive on the cutter's side).
    fn signed_distance(&self, p: &Vector3) -> f64;
}

/// A surface of revolution about +Z given by its meridional (z, r) contour, offset by a
/// constant along its normal, with the contour continued along its end tangents beyond both
/// ends (so a disk overhanging the outlet or inlet edge meets the continued floor: a plane
/// at a radial outlet, a cylinder at an axial inlet).
///
/// Parameters: `u` the contour parameter, `v` the polar angle (rad) — paper eq. 1,
/// `S(u, v) = B(v)·C(u)` with `B(v)` the rotation about Z. The normal toward the cutter is
/// the contour's channel-side normal (`MeridionalCurve::normal`): into the channel for the
/// hub, out of it for the shroud — the side the cutter is on when it plunges (hub) or
/// starts (above the shroud).
#[derive(Debug, Clone, Copy)]
pub struct RevolvedFloor<'a> {
    contour: &'a MeridionalCurve,
    offset: f64,
}

impl<'a> RevolvedFloor<'a> {
    /// The floor of `contour` itself.
    pub fn new(contour: &'a MeridionalCurve) -> Self {
        Self {
            contour,
            offset: 0.0,
        }
    }

    /// The floor offset by `d` (mm) toward the cutter's side.
    pub fn offset(contour: &'a MeridionalCurve, d: f64) -> Self {
        Self { contour, offset: d }
    }

    /// (z, r), first and second derivative at contour parameter `u`, continued linearly
    /// beyond the ends.
    fn contour_derivs(&self, u: f64) -> [Vector2<f64>; 3] {
        let (a, b) = self.contour.domain();
        let c = self.contour.curve();
        if u > b {
            let [p, d, _] = c.derivs2(b);
            [p + d * (u - b), d, Vector2::zeros()]
        } else if u < a {
            let [p, d, _] = c.derivs2(a);
            [p + d * (u - a), d, Vector2::zeros()]
        } else {
            c.derivs2(u)
        }
    }

    /// Closest point of the continued contour to `zr`: (parameter, signed distance along
    /// the channel-side normal).
    fn closest_zr(&self, zr: Vector2<f64>) -> (f64, f64) {
        let (a, b) = self.contour.domain();
        let (t, d) = self.contour.closest(zr);
        for end in [a, b] {
            if (t - end).abs() < 1e-12 {
                let [p, dp, _] = self.contour.curve().derivs2(end);
                let s = (zr - p).dot(&dp) / dp.norm_squared();
                let beyond = if end == b { s > 0.0 } else { s < 0.0 };
                if beyond {
                    let n = Vector2::new(dp[1], -dp[0]) / dp.norm();
                    return (end + s, (zr - p).dot(&n));
                }
            }
        }
        (t, d)
    }
}

impl Floor for RevolvedFloor<'_> {
    fn eval(&self, u: f64, v: f64) -> FloorPoint {
        let [c, d1, d2] = self.contour_derivs(u);
        // Channel-side normal N = (r', −z') / |C'| in (z, r) and its derivative along u.
        let big = Vector2::new(d1[1], -d1[0]);
        let len = big.norm().max(1e-300);
        let n2 = big / len;
        let big_u = Vector2::new(d2[1], -d2[0]);
        let n2_u = (big_u - n2 * n2.dot(&big_u)) / len;
        let d = self.offset;
        let (s, co) = v.sin_cos();
        let z = c[0] + d * n2[0];
        let r = c[1] + d * n2[1];
        let z_u = d1[0] + d * n2_u[0];
        let r_u = d1[1] + d * n2_u[1];
        FloorPoint {
            p: Vector3::new(r * co, r * s, z),
            su: Vector3::new(r_u * co, r_u * s, z_u),
            sv: Vector3::new(-r * s, r * co, 0.0),
            n: Vector3::new(n2[1] * co, n2[1] * s, n2[0]),
        }
    }

    fn closest_params(&self, p: &Vector3) -> (f64, f64) {
        let zr = Vector2::new(p.z, p.x.hypot(p.y));
        (self.closest_zr(zr).0, p.y.atan2(p.x))
    }

    fn signed_distance(&self, p: &Vector3) -> f64 {
        let zr = Vector2::new(p.z, p.x.hypot(p.y));
        self.closest_zr(zr).1 - self.offset
    }
}

/// The contact of a descending flat bottom with a floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Axial position: the bottom centre is `P + t·q` (eq. 9).
    pub t: f64,
    /// Floor parameters of the contact point.
    pub uv: (f64, f64),
    /// The contact point `Q` on the floor.
    pub point: Vector3,
    /// Unit floor normal at `Q` (toward the cutter).
    pub normal: Vector3,
    /// Newton iterations used.
    pub iterations: usize,
}

/// Why the depth solve failed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum DepthError {
    /// The linear system of eq. 7 is singular: the axis lies in the floor's tangent plane.
    #[error("the tool axis is tangent to the floor (singular contact system)")]
    Singular,
    /// No convergence within [`NEWTON_MAX_ITERATIONS`].
    #[error("the contact iteration did not converge in {0} steps")]
    NotConverged(usize),
    /// Non-finite input or iterate.
    #[error("non-finite axis point, axis or radius")]
    NonFinite,
}

/// The rim frame of eqs. 4–6: `(T, r)` for axis `q`, floor normal `n`, axis point `p` and
/// current contact estimate `q_pt`. Falls back to any direction perpendicular to `q` when
/// both `q × n` and `q × PQ` vanish (the estimate lies on the axis and the axis is normal).
pub fn rim_frame(q: &Vector3, n: &Vector3, p: &Vector3, q_pt: &Vector3) -> (Vector3, Vector3) {
    let c = q.cross(n);
    let t = if c.norm() > PARALLEL_TOL {
        c.normalize()
    } else {
        let c2 = q.cross(&(p - q_pt));
        if c2.norm() > PARALLEL_TOL * (p - q_pt).norm().max(1.0) {
            c2.normalize()
        } else {
            let helper = if q.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            q.cross(&helper).normalize()
        }
    };
    (t, q.cross(&t))
}

/// A unit vector perpendicular to `q` and a second one completing a right-handed frame.
pub fn perpendicular_frame(q: &Vector3) -> (Vector3, Vector3) {
    let helper = if q.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = q.cross(&helper).normalize();
    (e1, q.cross(&e1))
}

/// Axial position `t` where the point `x` moved along `q` meets the floor (signed distance
/// zero), by secant steps safeguarded with bisection on a bracket found by doubling steps.
/// Used by the general route and the seeds; tolerance 1e-12 mm on the signed distance.
pub fn project_along_axis<F: Floor + ?Sized>(floor: &F, x: &Vector3, q: &Vector3) -> Option<f64> {
    let g = |t: f64| floor.signed_distance(&(x + q * t));
    let g0 = g(0.0);
    if !g0.is_finite() {
        return None;
    }
    // The floor is below (g > 0): move down (t < 0); otherwise up.
    let dir = if g0 > 0.0 { -1.0 } else { 1.0 };
    let (mut a, mut ga) = (0.0, g0);
    let mut step = g0.abs().max(1e-3);
    let mut b = a + dir * step;
    let mut gb = g(b);
    let mut k = 0;
    while ga.signum() == gb.signum() {
        k += 1;
        if k > 60 || !gb.is_finite() {
            return None;
        }
        a = b;
        ga = gb;
        step *= 2.0;
        b = a + dir * step;
        gb = g(b);
    }
    for _ in 0..200 {
        let mut m = b - gb * (b - a) / (gb - ga);
        if !(m > a.min(b) && m < a.max(b)) {
            m = 0.5 * (a + b);
        }
        let gm = g(m);
        if gm.abs() < 1e-12 || (b - a).abs() < 1e-13 {
            return Some(m);
        }
        if gm.signum() == ga.signum() {
            a = m;
            ga = gm;
        } else {
            b = m;
            gb = gm;
        }
    }
    Some(0.5 * (a + b))
}

/// Solves eqs. 2–9 for the bottom circle of radius `radius` on the axis `p + t·q` touching
/// `floor` tangentially; `seed` (floor parameters, axial position) warm-starts the iteration
/// (e.g. from the previous plunge), otherwise the rim-sampling seed of the module docs.
///
/// Errors: [`DepthError`] on a singular system (axis tangent to the floor), no convergence or
/// non-finite input. O(iterations), no allocation.
pub fn solve_contact<F: Floor + ?Sized>(
    floor: &F,
    p: &Point3,
    q: &Vector3,
    radius: f64,
    seed: Option<((f64, f64), f64)>,
) -> Result<Contact, DepthError> {
    let pv = p.coords;
    let finite = pv.iter().all(|c| c.is_finite()) && q.iter().all(|c| c.is_finite());
    if !(finite && radius.is_finite() && radius >= 0.0) {
        return Err(DepthError::NonFinite);
    }
    let q = q.normalize();
    let ((mut u, mut v), mut t) = match seed {
        Some(s) => s,
        None => rim_seed(floor, &pv, &q, radius),
    };
    for it in 1..=NEWTON_MAX_ITERATIONS {
        let fp = floor.eval(u, v);
        let (_, r) = rim_frame(&q, &fp.n, &pv, &fp.p);
        let rhs = fp.p - pv - q * t - r * radius;
        let a = Matrix3::from_columns(&[q, -fp.su, -fp.sv]);
        let d = a.lu().solve(&rhs).ok_or(DepthError::Singular)?;
        if !d.iter().all(|c| c.is_finite()) {
            return Err(DepthError::Singular);
        }
        t += d[0];
        u += d[1];
        v += d[2];
        if d.iter().all(|c| c.abs() < NEWTON_STEP_TOL) {
            let fp = floor.eval(u, v);
            return Ok(Contact {
                t,
                uv: (u, v),
                point: fp.p,
                normal: fp.n,
                iterations: it,
            });
        }
    }
    Err(DepthError::NotConverged(NEWTON_MAX_ITERATIONS))
}

/// The seed of [`solve_contact`]: the disk is placed where its centre meets the floor along
/// the axis, and of [`SEED_RIM_SAMPLES`] rim points the one that meets the floor highest up
/// the axis gives `(u, v)` (its closest floor point) and `t`.
fn rim_seed<F: Floor + ?Sized>(
    floor: &F,
    p: &Vector3,
    q: &Vector3,
    radius: f64,
) -> ((f64, f64), f64) {
    let t0 = project_along_axis(floor, p, q).unwrap_or(0.0);
    let (e1, e2) = perpendicular_frame(q);
    let centre = p + q * t0;
    let mut best = (f64::NEG_INFINITY, centre);
    for k in 0..SEED_RIM_SAMPLES {
        let th = std::f64::consts::TAU * k as f64 / SEED_RIM_SAMPLES as f64;
        let x = centre + (e1 * th.cos() + e2 * th.sin()) * radius;
        if let Some(h) = project_along_axis(floor, &x, q) {
            if h > best.0 {
                best = (h, x + q * h);
            }
        }
    }
    let t = if best.0.is_finite() { t0 + best.0 } else { t0 };
    (floor.closest_params(&best.1), t)
}

/// General route (paper 000 Fig. 10): the axial position of the bottom disk of radius
/// `radius` on the axis `p + t·q` where it first touches `floor`, from `rings` concentric
/// rings (plus the centre) × `spokes` angles of disk points each projected along the axis
/// ([`project_along_axis`]); the highest touch wins, and the best rim angle is refined by
/// golden section over ±one spoke (to 1e-10 rad) because the rim is where contact happens on
/// hyperbolic floors. Works on any floor; cost O(rings · spokes) projections.
pub fn depth_by_projection<F: Floor + ?Sized>(
    floor: &F,
    p: &Point3,
    q: &Vector3,
    radius: f64,
    rings: usize,
    spokes: usize,
) -> Option<f64> {
    let q = q.normalize();
    let pv = p.coords;
    let (e1, e2) = perpendicular_frame(&q);
    let spokes = spokes.max(3);
    let rings = rings.max(1);
    let at = |rho: f64, th: f64| {
        project_along_axis(floor, &(pv + (e1 * th.cos() + e2 * th.sin()) * rho), &q)
    };
    let mut best = at(0.0, 0.0)?;
    let mut best_rim = (f64::NEG_INFINITY, 0.0);
    for i in 1..=rings {
        let rho = radius * i as f64 / rings as f64;
        for k in 0..spokes {
            let th = std::f64::consts::TAU * k as f64 / spokes as f64;
            let h = at(rho, th)?;
            best = best.max(h);
            if i == rings && h > best_rim.0 {
                best_rim = (h, th);
            }
        }
    }
    // Golden-section maximisation of the rim touch around the best spoke.
    let dth = std::f64::consts::TAU / spokes as f64;
    let (mut a, mut b) = (best_rim.1 - dth, best_rim.1 + dth);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let mut fc = at(radius, c)?;
    let mut fd = at(radius, d)?;
    while (b - a).abs() > 1e-10 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = at(radius, c)?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = at(radius, d)?;
        }
    }
    Some(best.max(fc.max(fd)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hub() -> MeridionalCurve {
        MeridionalCurve::quarter_ellipse([125.0, 40.0], [20.0, 200.0]).unwrap()
    }
    fn shroud() -> MeridionalCurve {
        MeridionalCurve::quarter_ellipse([125.0, 110.0], [55.0, 200.0]).unwrap()
    }

    /// Brute-force search along the axis: for each of `n` rim angles the exact touch height
    /// (root along the axis), maximised, then refined by golden section around the best
    /// angle — an answer independent of the Newton iteration.
    fn brute(floor: &dyn Floor, p: &Point3, q: &Vector3, r: f64) -> f64 {
        depth_by_projection(floor, p, q, r, 3, 180).unwrap()
    }

    fn check(floor: &dyn Floor, p: Point3, q: Vector3, r: f64) -> Contact {
        let c = solve_contact(floor, &p, &q, r, None).unwrap();
        let b = brute(floor, &p, &q, r);
        assert!((c.t - b).abs() < 1e-6, "newton {} vs brute {}", c.t, b);
        // Tangency: T·n = 0 at the contact, and the contact is on the rim.
        let qn = q.normalize();
        let centre = p.coords + qn * c.t;
        assert!(((c.point - centre).norm() - r).abs() < 1e-7);
        assert!((c.point - centre).dot(&qn).abs() < 1e-7);
        let (tt, _) = rim_frame(&qn, &c.normal, &p.coords, &c.point);
        assert!(tt.dot(&c.normal).abs() < 1e-9);
        c
    }

    #[test]
    fn newton_matches_brute_force_on_hub_and_shroud() {
        let h = hub();
        let s = shroud();
        let floor = RevolvedFloor::new(&h);
        for (m, phi, tilt) in [(0.3, 0.2, 0.1), (0.6, -0.4, -0.2), (0.9, 1.0, 0.25)] {
            let t = h.param_at_fraction(m);
            let fp = floor.eval(t, phi);
            let side = fp.sv.normalize();
            let q = (fp.n + fp.su.normalize() * tilt + side * 0.05).normalize();
            let p = Point3::from(fp.p + fp.n * 30.0);
            for r in [4.0, 8.0, 15.0] {
                check(&floor, p, q, r);
            }
        }
        // Shroud seen from outside (start height): the same solve.
        let floor = RevolvedFloor::new(&s);
        let t = s.param_at_fraction(0.5);
        let fp = floor.eval(t, 0.3);
        let q = (fp.n + fp.su.normalize() * 0.15).normalize();
        check(&floor, Point3::from(fp.p + fp.n * 40.0), q, 8.0);
    }

    #[test]
    fn axis_along_the_normal_is_solved() {
        // q ∥ n at the foot of P: the disk centred on a hub point with the axis along its
        // normal; the seed from the foot hits eq. 6 and its fallback.
        let h = hub();
        let floor = RevolvedFloor::new(&h);
        let t = h.param_at_fraction(0.5);
        let fp = floor.eval(t, 0.0);
        let p = Point3::from(fp.p + fp.n * 20.0);
        let c = check(&floor, p, fp.n, 15.0);
        // The hub is concave along the meridian: the rim touches above the centre's foot.
        assert!(c.t > -20.0);
        let warm = solve_contact(&floor, &p, &fp.n, 15.0, Some(((t, 0.0), -20.0))).unwrap();
        assert!((warm.t - c.t).abs() < 1e-6, "{} vs {}", warm.t, c.t);
        // The frame of eq. 6 when q ∥ n: r points from the axis toward the contact.
        let (_, r) = rim_frame(
            &Vector3::z(),
            &Vector3::z(),
            &Vector3::zeros(),
            &Vector3::new(3.0, 4.0, -1.0),
        );
        assert!((r - Vector3::new(0.6, 0.8, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn corner_radius_uses_the_offset_hub() {
        // Bull nose R = 8, ρ = 2, allowance 0.5: solve the centre circle (R − ρ) against
        // the hub offset by ρ + a; brute force: the torus's lowest distance to the hub is a.
        let h = hub();
        let (r, rho, a) = (8.0, 2.0, 0.5);
        let off = RevolvedFloor::offset(&h, rho + a);
        let base = RevolvedFloor::new(&h);
        let t = h.param_at_fraction(0.4);
        let fp = base.eval(t, 0.1);
        let q = (fp.n + fp.su.normalize() * 0.2).normalize();
        let p = Point3::from(fp.p + fp.n * 30.0);
        let c = check(&off, p, q, r - rho);
        let tip = p.coords + q * (c.t - rho);
        // Torus points: centre circle radius r − ρ at height ρ; tube radius ρ (lower half).
        let (e1, e2) = perpendicular_frame(&q);
        let mut min_d = f64::INFINITY;
        for i in 0..720 {
            let th = std::f64::consts::TAU * i as f64 / 720.0;
            let e = e1 * th.cos() + e2 * th.sin();
            for j in 0..=90 {
                let psi = std::f64::consts::FRAC_PI_2 * j as f64 / 90.0;
                let x = tip + q * rho + e * (r - rho) + (e * psi.sin() - q * psi.cos()) * rho;
                min_d = min_d.min(base.signed_distance(&x));
            }
        }
        assert!(min_d >= a - 1e-6, "torus gouges the allowance: {min_d}");
        assert!(min_d <= a + 1e-3, "torus does not touch: {min_d}");
    }
}
