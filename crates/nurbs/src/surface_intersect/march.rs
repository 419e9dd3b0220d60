//! Newton refinement, tangent and curvature of the intersection curve, marching and the
//! assembly of branches (module docs, steps 2–5).

use nalgebra::{Matrix2, SMatrix, SVector, Vector2, Vector3};

use super::{IntersectError, Intersection, ParamBox, SsiOptions, MAX_TURN_RAD, TANGENT_SIN};
use crate::{NurbsCurve, NurbsSurface, SurfaceDerivs2};

/// Newton iterations of one refinement (linear convergence near tangency needs ~25 to reach
/// 1e-12 from a step-sized start; 60 leaves margin).
const NEWTON_ITERS: usize = 60;

/// Relative cut-off of singular values in the minimum-norm Newton step.
const SVD_RCOND: f64 = 1e-12;

/// Largest growth of the marching step from one point to the next (keeps the curvature
/// estimate local).
const STEP_GROWTH: f64 = 2.0;

/// One point of an intersection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntersectionPoint {
    /// The point (midpoint of `S_a(uv_a)` and `S_b(uv_b)`).
    pub point: Vector3<f64>,
    /// Parameters on surface a.
    pub uv_a: [f64; 2],
    /// Parameters on surface b.
    pub uv_b: [f64; 2],
    /// `|S_a(uv_a) − S_b(uv_b)|`.
    pub residual: f64,
    /// The surfaces touch here (`|n_a × n_b| <` [`TANGENT_SIN`]).
    pub tangential: bool,
}

/// How a branch ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchEnd {
    /// On a side of a parameter box (the point lies on it).
    Boundary,
    /// The branch is a closed loop (its last point repeats the first).
    Closed,
    /// The step fell below `min_step` (a singular point, e.g. where branches cross, or a cusp).
    StepFailure,
    /// `max_points` was reached.
    PointLimit,
}

/// One traced branch of an intersection.
#[derive(Debug, Clone)]
pub struct IntersectionBranch {
    /// Marched points in order.
    pub points: Vec<IntersectionPoint>,
    /// How the branch ends at its first and last point.
    pub ends: [BranchEnd; 2],
    /// Cubic NURBS curve through the points (domain [0, 1]).
    pub curve: NurbsCurve<3>,
    /// Largest distance of the curve from the points at their fit parameters.
    pub fit_error: f64,
}

impl IntersectionBranch {
    /// Whether the branch is a closed loop.
    pub fn is_closed(&self) -> bool {
        self.ends[0] == BranchEnd::Closed
    }
}

/// Internal point: parameters `(u_a, v_a, u_b, v_b)`, the mean point and the residual.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pt {
    pub x: [f64; 4],
    pub p: Vector3<f64>,
    pub residual: f64,
}

/// The extra (fourth) equation of a refinement.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Constraint {
    /// None: minimum-norm steps onto the curve.
    None,
    /// `(S_a − origin)·normal = 0`.
    Plane(Vector3<f64>, Vector3<f64>),
    /// Parameter `index` equals `value`.
    Param(usize, f64),
}

fn clamp_to_domains(a: &NurbsSurface, b: &NurbsSurface, x: &mut [f64; 4]) {
    let ((au0, au1), (av0, av1)) = a.domain();
    let ((bu0, bu1), (bv0, bv1)) = b.domain();
    x[0] = x[0].clamp(au0, au1);
    x[1] = x[1].clamp(av0, av1);
    x[2] = x[2].clamp(bu0, bu1);
    x[3] = x[3].clamp(bv0, bv1);
}

/// Gauss–Newton on `S_a − S_b = 0` plus `constraint`, minimum-norm SVD steps (rank-deficient
/// at tangency, where it converges linearly). Returns the point when `|S_a − S_b| ≤
/// point_tol` and the constraint holds to `point_tol`. O(NEWTON_ITERS) evaluations.
pub(crate) fn refine(
    a: &NurbsSurface,
    b: &NurbsSurface,
    start: [f64; 4],
    constraint: Constraint,
    opts: &SsiOptions,
) -> Option<Pt> {
    let mut x = start;
    clamp_to_domains(a, b, &mut x);
    let target = 0.01 * opts.point_tol;
    for _ in 0..NEWTON_ITERS {
        let da = a.derivs2(x[0], x[1]);
        let db = b.derivs2(x[2], x[3]);
        let f = da.p - db.p;
        let (g, grad) = match constraint {
            Constraint::None => (0.0, [0.0; 4]),
            Constraint::Plane(o, n) => {
                ((da.p - o).dot(&n), [da.su.dot(&n), da.sv.dot(&n), 0.0, 0.0])
            }
            Constraint::Param(k, val) => {
                let mut e = [0.0; 4];
                e[k] = 1.0;
                (x[k] - val, e)
            }
        };
        let res = f.norm();
        if res <= target && g.abs() <= target {
            return Some(Pt {
                x,
                p: 0.5 * (da.p + db.p),
                residual: res,
            });
        }
        let mut j = SMatrix::<f64, 4, 4>::zeros();
        for r in 0..3 {
            j[(r, 0)] = da.su[r];
            j[(r, 1)] = da.sv[r];
            j[(r, 2)] = -db.su[r];
            j[(r, 3)] = -db.sv[r];
        }
        let mut rhs = SVector::<f64, 4>::new(-f.x, -f.y, -f.z, -g);
        if matches!(constraint, Constraint::None) {
            rhs[3] = 0.0;
        } else {
            for c in 0..4 {
                j[(3, c)] = grad[c];
            }
        }
        let svd = j.svd(true, true);
        let smax = svd.singular_values.max();
        let dx = svd.solve(&rhs, SVD_RCOND * smax).ok()?;
        let mut step = 0.0f64;
        for k in 0..4 {
            x[k] += dx[k];
            step = step.max(dx[k].abs());
        }
        clamp_to_domains(a, b, &mut x);
        if !step.is_finite() {
            return None;
        }
        if step < 1e-16 {
            // Stalled: accept only if already within tolerance.
            let da = a.point(x[0], x[1]);
            let db = b.point(x[2], x[3]);
            let res = (da - db).norm();
            return (res <= opts.point_tol).then(|| Pt {
                x,
                p: 0.5 * (da + db),
                residual: res,
            });
        }
    }
    let pa = a.point(x[0], x[1]);
    let pb = b.point(x[2], x[3]);
    let res = (pa - pb).norm();
    let g_ok = match constraint {
        Constraint::None => true,
        Constraint::Plane(o, n) => (pa - o).dot(&n).abs() <= opts.point_tol,
        Constraint::Param(k, val) => (x[k] - val).abs() <= 1e-12,
    };
    (res <= opts.point_tol && g_ok).then(|| Pt {
        x,
        p: 0.5 * (pa + pb),
        residual: res,
    })
}

/// Parameter increments `(du, dv)` that move `S` by `w` to first order (least squares).
fn param_step(d: &SurfaceDerivs2, w: &Vector3<f64>) -> Vector2<f64> {
    let g = Matrix2::new(
        d.su.dot(&d.su),
        d.su.dot(&d.sv),
        d.su.dot(&d.sv),
        d.sv.dot(&d.sv),
    );
    let r = Vector2::new(d.su.dot(w), d.sv.dot(w));
    g.try_inverse().map_or(Vector2::zeros(), |gi| gi * r)
}

/// Second fundamental form of `d` along the tangent vector `w`, measured along `n`.
fn second_form(d: &SurfaceDerivs2, n: &Vector3<f64>, w: &Vector3<f64>) -> f64 {
    let s = param_step(d, w);
    n.dot(&(d.suu * s.x * s.x + d.suv * 2.0 * s.x * s.y + d.svv * s.y * s.y))
}

/// Local differential geometry of the intersection at a point.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Tangent {
    /// A regular (or tangential-but-curve) direction, unit, and the curve's curvature.
    Curve {
        t: Vector3<f64>,
        kappa: f64,
        tangential: bool,
    },
    /// The surfaces touch at an isolated point (elliptic contact) or are singular here.
    Isolated,
}

/// Tangent and curvature of the intersection curve at parameters `x`, the tangent oriented
/// along `prev` when given. Transversal: `t = n_a × n_b`, curvature vector `k = α n_a + β n_b`
/// from `k·n_a = κ_a(t)`, `k·n_b = κ_b(t)` (normal curvatures). Tangential: the null direction
/// of `II_a − II_b` in the common tangent plane (a hyperbolic difference has two; the one
/// nearest `prev` is taken), curvature bounded by the larger normal curvature.
pub(crate) fn tangent(
    a: &NurbsSurface,
    b: &NurbsSurface,
    x: &[f64; 4],
    prev: Option<Vector3<f64>>,
) -> Tangent {
    let da = a.derivs2(x[0], x[1]);
    let db = b.derivs2(x[2], x[3]);
    let (Some(na), Some(nb)) = (da.normal(), db.normal()) else {
        return Tangent::Isolated;
    };
    let orient = |t: Vector3<f64>| match prev {
        Some(p) if t.dot(&p) < 0.0 => -t,
        _ => t,
    };
    let c = na.cross(&nb);
    let s = c.norm();
    if s >= TANGENT_SIN {
        let t = orient(c / s);
        let ka = second_form(&da, &na, &t);
        let kb = second_form(&db, &nb, &t);
        let cos = na.dot(&nb);
        let det = 1.0 - cos * cos;
        let (al, be) = ((ka - cos * kb) / det, (kb - cos * ka) / det);
        let kappa = (al * al + be * be + 2.0 * al * be * cos).max(0.0).sqrt();
        return Tangent::Curve {
            t,
            kappa,
            tangential: false,
        };
    }
    // Tangential: common tangent plane of n = n_a.
    let n = na;
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = n.cross(&helper).normalize();
    let e2 = n.cross(&e1);
    let q = |w: &Vector3<f64>| second_form(&da, &n, w) - second_form(&db, &n, w);
    let q11 = q(&e1);
    let q22 = q(&e2);
    let q12 = 0.5 * (q(&(e1 + e2)) - q11 - q22);
    let m = nalgebra::Matrix2::new(q11, q12, q12, q22);
    let eig = m.symmetric_eigen();
    let (l1, l2) = (eig.eigenvalues[0], eig.eigenvalues[1]);
    let w1 = eig.eigenvectors.column(0);
    let w2 = eig.eigenvectors.column(1);
    let dir = |w: nalgebra::VectorView2<f64>| e1 * w[0] + e2 * w[1];
    let scale = l1.abs().max(l2.abs());
    let kmax = [&e1, &e2]
        .iter()
        .map(|w| {
            second_form(&da, &n, w)
                .abs()
                .max(second_form(&db, &n, w).abs())
        })
        .fold(0.0, f64::max);
    let mut cands: Vec<Vector3<f64>> = Vec::new();
    // Relative size under which an eigenvalue of II_a − II_b counts as zero.
    const NULL_REL: f64 = 1e-3;
    if scale <= 1e-12 * kmax.max(1e-300) {
        // Osculating to second order: any direction; keep the previous one.
        match prev {
            Some(p) => cands.push(p),
            None => return Tangent::Isolated,
        }
    } else if l1.abs() <= NULL_REL * scale {
        cands.push(dir(w1));
    } else if l2.abs() <= NULL_REL * scale {
        cands.push(dir(w2));
    } else if l1 * l2 < 0.0 {
        let th = (-l1 / l2).sqrt().atan();
        let (sn, cs) = th.sin_cos();
        cands.push(dir(w1) * cs + dir(w2) * sn);
        cands.push(dir(w1) * cs - dir(w2) * sn);
    } else {
        return Tangent::Isolated;
    }
    let t = match prev {
        Some(p) => cands
            .iter()
            .copied()
            .max_by(|x, y| x.dot(&p).abs().total_cmp(&y.dot(&p).abs()))
            .unwrap_or(cands[0]),
        None => cands[0],
    };
    Tangent::Curve {
        t: orient(t.normalize()),
        kappa: kmax,
        tangential: true,
    }
}

fn step_for(kappa: f64, opts: &SsiOptions) -> f64 {
    let h = if kappa > 0.0 {
        (8.0 * opts.chord_tol / kappa).sqrt()
    } else {
        opts.max_step
    };
    h.clamp(opts.min_step, opts.max_step)
}

/// Parameters predicted for a move by `w` from `x`.
fn predict(a: &NurbsSurface, b: &NurbsSurface, x: &[f64; 4], w: &Vector3<f64>) -> [f64; 4] {
    let da = a.derivs2(x[0], x[1]);
    let db = b.derivs2(x[2], x[3]);
    let sa = param_step(&da, w);
    let sb = param_step(&db, w);
    [x[0] + sa.x, x[1] + sa.y, x[2] + sb.x, x[3] + sb.y]
}

/// The point where the step from `cur` to `next` leaves a box: the smallest fraction of the
/// step (linear in parameters) at which a parameter crosses its bound, refined by Newton with
/// that parameter fixed at the bound.
fn boundary_point(
    a: &NurbsSurface,
    b: &NurbsSurface,
    ba: &ParamBox,
    bb: &ParamBox,
    cur: &Pt,
    next: &[f64; 4],
    opts: &SsiOptions,
) -> Option<Pt> {
    let bounds = [ba.u, ba.v, bb.u, bb.v];
    let mut best: Option<(f64, usize, f64)> = None;
    for k in 0..4 {
        let (lo, hi) = bounds[k];
        let (x0, x1) = (cur.x[k], next[k]);
        for bound in [lo, hi] {
            let crosses = (x0 - bound) * (x1 - bound) < 0.0 || (x1 - bound).abs() == 0.0;
            let outside = x1 < lo || x1 > hi;
            if crosses && outside && (x1 - x0).abs() > 0.0 {
                let f = ((bound - x0) / (x1 - x0)).clamp(0.0, 1.0);
                if best.is_none_or(|(bf, _, _)| f < bf) {
                    best = Some((f, k, bound));
                }
            }
        }
    }
    let (f, k, bound) = best?;
    let mut start = [0.0; 4];
    for i in 0..4 {
        start[i] = cur.x[i] + f * (next[i] - cur.x[i]);
    }
    start[k] = bound;
    let p = refine(a, b, start, Constraint::Param(k, bound), opts)?;
    (ba.contains(p.x[0], p.x[1]) && bb.contains(p.x[2], p.x[3])).then_some(p)
}

/// Marches from `start` along `dir` until a box side, loop closure, step failure or the point
/// limit; returns the points after `start` (tangential flags per point) and how it ended.
#[allow(clippy::too_many_arguments)]
fn march(
    a: &NurbsSurface,
    b: &NurbsSurface,
    ba: &ParamBox,
    bb: &ParamBox,
    opts: &SsiOptions,
    start: &Pt,
    dir: Vector3<f64>,
    kappa0: f64,
    allow_close: bool,
) -> (Vec<(Pt, bool)>, BranchEnd) {
    let mut out: Vec<(Pt, bool)> = Vec::new();
    let mut cur = *start;
    let mut t = dir;
    let mut h = step_for(kappa0, opts);
    let mut travelled = 0.0;
    loop {
        if out.len() + 1 >= opts.max_points {
            return (out, BranchEnd::PointLimit);
        }
        // Loop closure: the start lies within one step ahead.
        if allow_close && out.len() >= 3 && travelled > 2.0 * h {
            let to_start = start.p - cur.p;
            if to_start.norm() <= 1.2 * h && to_start.dot(&t) > 0.0 {
                out.push((*start, false));
                return (out, BranchEnd::Closed);
            }
        }
        let target = cur.p + t * h;
        let x0 = predict(a, b, &cur.x, &(t * h));
        let accepted = refine(a, b, x0, Constraint::Plane(target, t), opts).and_then(|p| {
            let d = (p.p - cur.p).norm();
            if d > 2.0 * h || d < 0.1 * h {
                return None;
            }
            match tangent(a, b, &p.x, Some(t)) {
                Tangent::Curve {
                    t: nt,
                    kappa,
                    tangential,
                } if nt.dot(&t) >= MAX_TURN_RAD.cos() => Some((p, nt, kappa, tangential)),
                _ => None,
            }
        });
        match accepted {
            Some((p, nt, kappa, tangential)) => {
                if !(ba.contains(p.x[0], p.x[1]) && bb.contains(p.x[2], p.x[3])) {
                    if let Some(q) = boundary_point(a, b, ba, bb, &cur, &p.x, opts) {
                        if (q.p - cur.p).norm() > 1e-12 {
                            out.push((q, is_tangential(a, b, &q)));
                        }
                        return (out, BranchEnd::Boundary);
                    }
                    if h * 0.5 >= opts.min_step {
                        h *= 0.5;
                        continue;
                    }
                    return (out, BranchEnd::Boundary);
                }
                travelled += (p.p - cur.p).norm();
                out.push((p, tangential));
                cur = p;
                t = nt;
                h = step_for(kappa, opts).min(STEP_GROWTH * h);
            }
            None => {
                // A step predicted outside a box: put the end on the box side.
                if !(ba.contains(x0[0], x0[1]) && bb.contains(x0[2], x0[3])) {
                    if let Some(q) = boundary_point(a, b, ba, bb, &cur, &x0, opts) {
                        if (q.p - cur.p).norm() <= 2.0 * h {
                            if (q.p - cur.p).norm() > 1e-12 {
                                out.push((q, is_tangential(a, b, &q)));
                            }
                            return (out, BranchEnd::Boundary);
                        }
                    }
                }
                // A failed step right at a box side ends the branch there.
                let on_side = {
                    let e = 1e-9;
                    let near = |x: f64, (lo, hi): (f64, f64)| {
                        (x - lo).abs() <= e * (hi - lo) || (x - hi).abs() <= e * (hi - lo)
                    };
                    near(cur.x[0], ba.u)
                        || near(cur.x[1], ba.v)
                        || near(cur.x[2], bb.u)
                        || near(cur.x[3], bb.v)
                };
                if h * 0.5 < opts.min_step {
                    let end = if on_side {
                        BranchEnd::Boundary
                    } else {
                        BranchEnd::StepFailure
                    };
                    return (out, end);
                }
                h *= 0.5;
            }
        }
    }
}

/// Whether the surfaces touch at `p` (`|n_a × n_b| <` [`TANGENT_SIN`]).
fn is_tangential(a: &NurbsSurface, b: &NurbsSurface, p: &Pt) -> bool {
    match (a.normal(p.x[0], p.x[1]), b.normal(p.x[2], p.x[3])) {
        (Some(na), Some(nb)) => na.cross(&nb).norm() < TANGENT_SIN,
        _ => true,
    }
}

/// Distance from `p` to the polyline `pts`.
fn polyline_distance(p: &Vector3<f64>, pts: &[IntersectionPoint]) -> f64 {
    if pts.len() == 1 {
        return (p - pts[0].point).norm();
    }
    pts.windows(2)
        .map(|w| {
            let (s, e) = (w[0].point, w[1].point);
            let d = e - s;
            let l2 = d.norm_squared();
            let f = if l2 > 0.0 {
                ((p - s).dot(&d) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p - (s + d * f)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

fn to_point(a: &NurbsSurface, b: &NurbsSurface, p: &Pt, tangential: bool) -> IntersectionPoint {
    let _ = (a, b);
    IntersectionPoint {
        point: p.p,
        uv_a: [p.x[0], p.x[1]],
        uv_b: [p.x[2], p.x[3]],
        residual: p.residual,
        tangential,
    }
}

/// Traces every branch through the seeds (skipping seeds already on a traced branch) and fits
/// the curves.
pub(crate) fn trace_all(
    a: &NurbsSurface,
    ba: ParamBox,
    b: &NurbsSurface,
    bb: ParamBox,
    opts: &SsiOptions,
    seeds: Vec<Pt>,
) -> Result<Intersection, IntersectError> {
    // A seed within this distance of a traced branch lies on it: a converged seed is on the
    // curve, whose distance to the marched polyline is at most the chord sagitta.
    let cover = 2.0 * opts.chord_tol + 10.0 * opts.point_tol;
    let mut traced: Vec<(Vec<IntersectionPoint>, [BranchEnd; 2])> = Vec::new();
    let mut touch: Vec<IntersectionPoint> = Vec::new();
    for s in &seeds {
        if traced
            .iter()
            .any(|(pts, _)| polyline_distance(&s.p, pts) <= cover)
            || touch.iter().any(|q| (q.point - s.p).norm() <= cover)
        {
            continue;
        }
        let (t0, k0, tan0) = match tangent(a, b, &s.x, None) {
            Tangent::Curve {
                t,
                kappa,
                tangential,
            } => (t, kappa, tangential),
            Tangent::Isolated => {
                touch.push(to_point(a, b, s, true));
                continue;
            }
        };
        let (fwd, end_f) = march(a, b, &ba, &bb, opts, s, t0, k0, true);
        let mut pts = Vec::new();
        let ends = if end_f == BranchEnd::Closed {
            pts.push(to_point(a, b, s, tan0));
            pts.extend(fwd.iter().map(|(p, tg)| to_point(a, b, p, *tg)));
            [BranchEnd::Closed, BranchEnd::Closed]
        } else {
            let (bwd, end_b) = march(a, b, &ba, &bb, opts, s, -t0, k0, false);
            pts.extend(bwd.iter().rev().map(|(p, tg)| to_point(a, b, p, *tg)));
            pts.push(to_point(a, b, s, tan0));
            pts.extend(fwd.iter().map(|(p, tg)| to_point(a, b, p, *tg)));
            [end_b, end_f]
        };
        if pts.len() == 1 {
            touch.push(pts[0]);
        } else {
            traced.push((pts, ends));
        }
    }
    let mut branches = Vec::with_capacity(traced.len());
    for (i, (points, ends)) in traced.into_iter().enumerate() {
        let data: Vec<Vector3<f64>> = points.iter().map(|p| p.point).collect();
        let fit = super::fit_dense(&data, opts.fit_tol)
            .map_err(|source| IntersectError::Fit { branch: i, source })?;
        branches.push(IntersectionBranch {
            points,
            ends,
            curve: fit.curve,
            fit_error: fit.max_error,
        });
    }
    Ok(Intersection {
        branches,
        touch_points: touch,
    })
}
