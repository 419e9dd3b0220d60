//! Bound-constrained Newton iteration for the squared distance `f(u,v) = ½|S(u,v) − q|²`
//! on a parameter box (projected Newton with an active set).
//!
//! Gradient `g = (r·S_u, r·S_v)` with `r = S − q`; Hessian
//! `H = [[S_u·S_u + r·S_uu, S_u·S_v + r·S_uv], [·, S_v·S_v + r·S_vv]]`. A variable sitting on
//! a bound with the gradient pushing outwards is fixed (the iteration then continues on that
//! edge, a 1D Newton in the other variable; both fixed = a corner). When `H` is not positive
//! definite the Gauss–Newton matrix `JᵀJ` is used instead; a backtracking step keeps `f`
//! decreasing. Quadratic convergence near a non-degenerate minimum.

use nalgebra::Vector3;

use crate::SurfaceDerivs2;

/// Largest number of Newton iterations (a well-started iteration needs 3–6).
pub(crate) const MAX_ITER: usize = 40;

/// Cosine of the angle between `S − q` and a tangent accepted as "orthogonal".
pub(crate) const ANGLE_TOL: f64 = 1e-11;

/// Length scale (mm) of the last Newton step taken without evaluating the surface.
///
/// Near a non-degenerate minimum Newton converges quadratically: after a step of length `s`
/// the iterate is within about `K s²` of the minimiser, where `1/K` is a length of the order
/// of the radius of curvature of the surface and of the distance function (metres to
/// millimetres on machined parts). A free step with `s² ≤ step_tol · TAYLOR_LENGTH` therefore
/// leaves an error below `step_tol` as long as `1/K ≥ TAYLOR_LENGTH` = 1 µm, and the
/// iteration stops after it. The new point and tangents are taken from the second-order
/// Taylor expansion at the current point, whose second-order term is required to be below
/// `step_tol` as well (the third-order remainder is smaller still), so the answer's point,
/// normal and distance agree with an evaluation at the new parameters to round-off. This
/// saves the last of the usual 3–5 evaluations of a warm query.
pub(crate) const TAYLOR_LENGTH: f64 = 1e-3;

/// Result of a bound-constrained Newton run.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Local {
    pub u: f64,
    pub v: f64,
    pub point: Vector3<f64>,
    /// The natural normal `S_u × S_v` (not normalised) at the point.
    pub normal: Vector3<f64>,
    /// Squared distance.
    pub d2: f64,
    /// Per variable: 0 = free (gradient ≈ 0), -1 = held at the lower bound, +1 = at the upper.
    pub active: [i8; 2],
    /// The iteration met its step tolerance (otherwise it stopped at MAX_ITER).
    pub converged: bool,
}

/// Round-off level of `|S − q|²` near `f`: evaluation errors of a few ulps of the
/// coordinates, `δ(|r|²) ≈ 2|r|·δp`. Steps that increase `f` by less are accepted, so the
/// iteration can finish converging where `f` itself no longer resolves the progress.
#[inline]
pub(crate) fn noise<const D: usize>(
    f: f64,
    p: &nalgebra::SVector<f64, D>,
    q: &nalgebra::SVector<f64, D>,
) -> f64 {
    let scale = p.amax().max(q.amax()) + 1e-300;
    2.0 * f.sqrt() * 64.0 * f64::EPSILON * scale + 1e-300
}

/// Minimises `½|S − q|²` over `[lo.0, hi.0] × [lo.1, hi.1]` from `(u, v)`.
/// `eval` gives the derivatives at a parameter pair; `step_tol` is the 3D step length (mm)
/// below which the iteration stops.
#[inline]
pub(crate) fn minimise<F: Fn(f64, f64) -> SurfaceDerivs2>(
    eval: F,
    q: &Vector3<f64>,
    lo: (f64, f64),
    hi: (f64, f64),
    start: (f64, f64),
    step_tol: f64,
) -> Local {
    let (mut u, mut v) = (start.0.clamp(lo.0, hi.0), start.1.clamp(lo.1, hi.1));
    let mut e = eval(u, v);
    let mut r = e.p - q;
    let mut f = r.norm_squared();
    let mut active = [0i8; 2];
    let mut converged = false;
    let taylor_tol2 = step_tol * TAYLOR_LENGTH;
    for _ in 0..MAX_ITER {
        let gu = r.dot(&e.su);
        let gv = r.dot(&e.sv);
        let fix_u = (u <= lo.0 && gu > 0.0) || (u >= hi.0 && gu < 0.0);
        let fix_v = (v <= lo.1 && gv > 0.0) || (v >= hi.1 && gv < 0.0);
        active = [
            if fix_u {
                if u <= lo.0 {
                    -1
                } else {
                    1
                }
            } else {
                0
            },
            if fix_v {
                if v <= lo.1 {
                    -1
                } else {
                    1
                }
            } else {
                0
            },
        ];
        let auu = e.su.norm_squared();
        let avv = e.sv.norm_squared();
        let auv = e.su.dot(&e.sv);
        let huu = auu + r.dot(&e.suu);
        let hvv = avv + r.dot(&e.svv);
        let huv = auv + r.dot(&e.suv);
        let (du, dv) = match (fix_u, fix_v) {
            (true, true) => {
                converged = true;
                break;
            }
            (false, true) => {
                let h = if huu > 0.0 { huu } else { auu };
                (if h > 0.0 { -gu / h } else { 0.0 }, 0.0)
            }
            (true, false) => {
                let h = if hvv > 0.0 { hvv } else { avv };
                (0.0, if h > 0.0 { -gv / h } else { 0.0 })
            }
            (false, false) => {
                let det = huu * hvv - huv * huv;
                if huu > 0.0 && det > 1e-12 * huu * hvv.abs() {
                    ((-gu * hvv + gv * huv) / det, (-gv * huu + gu * huv) / det)
                } else {
                    let det = auu * avv - auv * auv;
                    if det > 1e-14 * auu * avv {
                        ((-gu * avv + gv * auv) / det, (-gv * auu + gu * auv) / det)
                    } else {
                        let s = auu + avv;
                        if s > 0.0 {
                            (-gu / s, -gv / s)
                        } else {
                            (0.0, 0.0)
                        }
                    }
                }
            }
        };
        // Stop when the (projected) Newton step is below the tolerance: the iteration
        // converges quadratically, so the error left is far below `step_tol`.
        let pu = (u + du).clamp(lo.0, hi.0) - u;
        let pv = (v + dv).clamp(lo.1, hi.1) - v;
        let predicted = (e.su * pu + e.sv * pv).norm();
        if predicted <= step_tol {
            // Also require the angle condition (relative orthogonality) unless the step is
            // at round-off level: near-cusps make tiny steps with a sizeable angle left.
            let rn = f.sqrt();
            let cu = if fix_u {
                0.0
            } else {
                gu.abs() / (rn * auu.sqrt())
            };
            let cv = if fix_v {
                0.0
            } else {
                gv.abs() / (rn * avv.sqrt())
            };
            if !(cu > ANGLE_TOL || cv > ANGLE_TOL) || predicted <= 1e-3 * step_tol {
                converged = true;
                break;
            }
        }
        // A free step this short is applied through the second-order Taylor expansion of
        // `S` at the current point instead of a new evaluation (see [`TAYLOR_LENGTH`]).
        let inside = u + du >= lo.0 && u + du <= hi.0 && v + dv >= lo.1 && v + dv <= hi.1;
        if !fix_u && !fix_v && inside && predicted * predicted <= taylor_tol2 {
            let (du, dv) = (pu, pv);
            let half = 0.5 * (e.suu * (du * du) + e.suv * (2.0 * du * dv) + e.svv * (dv * dv));
            if half.norm() <= step_tol {
                let p = e.p + e.su * du + e.sv * dv + half;
                let rn = p - q;
                let fnew = rn.norm_squared();
                if fnew <= f + noise(f, &p, q) {
                    e = SurfaceDerivs2 {
                        p,
                        su: e.su + e.suu * du + e.suv * dv,
                        sv: e.sv + e.suv * du + e.svv * dv,
                        ..e
                    };
                    u += du;
                    v += dv;
                    r = rn;
                    f = fnew;
                    converged = true;
                    break;
                }
            }
        }
        // Backtracking on the projected step.
        let mut t = 1.0;
        let mut accepted = false;
        let (mut un, mut vn) = (u, v);
        let mut en = e;
        let mut fnew = f;
        for _ in 0..12 {
            un = (u + t * du).clamp(lo.0, hi.0);
            vn = (v + t * dv).clamp(lo.1, hi.1);
            en = eval(un, vn);
            fnew = (en.p - q).norm_squared();
            if fnew <= f + noise(f, &en.p, q) {
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        let step = (e.su * (un - u) + e.sv * (vn - v)).norm();
        if !accepted {
            // No decrease even for tiny steps. That is a minimum within round-off only if
            // S − q is already normal to the surface (the angle condition); otherwise the
            // line search failed at a non-stationary point, which is not convergence (a leaf
            // solved this way must not be taken as that leaf's minimum).
            let rn = f.sqrt();
            let cu = if fix_u {
                0.0
            } else {
                gu.abs() / (rn * auu.sqrt())
            };
            let cv = if fix_v {
                0.0
            } else {
                gv.abs() / (rn * avv.sqrt())
            };
            converged = !(cu > ANGLE_TOL || cv > ANGLE_TOL);
            break;
        }
        u = un;
        v = vn;
        e = en;
        r = e.p - q;
        f = fnew;
        if step <= step_tol {
            converged = true;
            break;
        }
    }
    // Refresh the active set at the final point.
    let gu = r.dot(&e.su);
    let gv = r.dot(&e.sv);
    if active[0] == 0 && ((u <= lo.0 && gu > 0.0) || (u >= hi.0 && gu < 0.0)) {
        active[0] = if u <= lo.0 { -1 } else { 1 };
    }
    if active[1] == 0 && ((v <= lo.1 && gv > 0.0) || (v >= hi.1 && gv < 0.0)) {
        active[1] = if v <= lo.1 { -1 } else { 1 };
    }
    Local {
        u,
        v,
        point: e.p,
        normal: e.su.cross(&e.sv),
        d2: f,
        active,
        converged,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::closest::wavy_test_surface;
    use std::cell::Cell;

    /// Newton runs that end with a step applied through the Taylor expansion answer the same
    /// point, normal and distance as an evaluation at the returned parameters (to round-off:
    /// 1e-12 mm, 1e-9 relative on the normal), and the returned point satisfies the angle
    /// condition; on these warm starts (0.1 mm from the answer) at least half of the runs
    /// end that way, one evaluation earlier.
    #[test]
    fn taylor_final_step_matches_an_evaluation() {
        // About 100 mm (step tolerance ≈ 1.4e-11 mm).
        let s = wavy_test_surface(14.0, 9.0, 19.0, 23.0);
        let step_tol = 1e-13 * (1.0 + 140.0);
        let mut taylor_ends = 0;
        let runs = 200;
        for k in 0..runs {
            let (u, v) = (0.1 + 0.004 * k as f64, 0.2 + 0.003 * k as f64);
            let d = s.derivs2(u, v);
            let n = d.su.cross(&d.sv).normalize();
            let q = d.p + n * (1.0 + 0.01 * k as f64);
            // Start ~0.1 mm (along the surface) away.
            let start = (u + 0.1 / d.su.norm(), v - 0.05 / d.sv.norm());
            let evals = Cell::new(0usize);
            let last = Cell::new((f64::NAN, f64::NAN));
            let l = minimise(
                |a, b| {
                    evals.set(evals.get() + 1);
                    last.set((a, b));
                    s.derivs2(a, b)
                },
                &q,
                (0.0, 0.0),
                (1.0, 1.0),
                start,
                step_tol,
            );
            assert!(l.converged, "run {k} did not converge");
            let e = s.derivs2(l.u, l.v);
            assert!(
                (l.point - e.p).norm() <= 1e-12,
                "run {k}: point off by {:e}",
                (l.point - e.p).norm()
            );
            let ne = e.su.cross(&e.sv);
            assert!(
                (l.normal - ne).norm() <= 1e-9 * ne.norm(),
                "run {k}: normal"
            );
            assert!(
                (l.d2.sqrt() - (e.p - q).norm()).abs() <= 1e-12,
                "run {k}: distance"
            );
            let r = e.p - q;
            let cu = r.dot(&e.su).abs() / (r.norm() * e.su.norm());
            let cv = r.dot(&e.sv).abs() / (r.norm() * e.sv.norm());
            assert!(cu <= 1e-10 && cv <= 1e-10, "run {k}: angle {cu:e} {cv:e}");
            if last.get() != (l.u, l.v) {
                taylor_ends += 1;
            }
        }
        assert!(
            taylor_ends * 2 >= runs,
            "only {taylor_ends} of {runs} runs ended by the Taylor step"
        );
    }
}
