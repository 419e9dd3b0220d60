//! Curve–curve intersection: every place where two NURBS curves meet (in a parameter plane,
//! `D = 2`) or come within a distance tolerance of each other (3-D closest approach,
//! `D = 3`), including tangencies and overlapping pieces; and the global closest approach of
//! two curves.
//!
//! # Method
//!
//! Both curves are split into Bézier segments; because every weight is positive, a segment
//! lies in the convex hull — hence in the axis-aligned box — of its control points (NURBS
//! Book §5.4, Sederberg's Bézier clipping bounds). Pairs of segments whose boxes are more than
//! `tol` apart are discarded; the rest are halved by de Casteljau subdivision (in homogeneous
//! coordinates for rational pieces), always the longer segment, until a pair is a *leaf*:
//!
//! * **transversal leaf**: both control polygons lie within [`FLAT_REL`] of their chords and
//!   the chords cross at an angle whose sine exceeds [`TRANSVERSAL_SIN`]: the pair holds at
//!   most one crossing, found by damped Gauss–Newton on `A(u) − B(v) = 0` (Newton's method in
//!   the plane) started from the chords' closest points;
//! * **parallel leaf**: the segments are shorter than a quarter of
//!   [`IntersectOptions::min_overlap_length`] (near-parallel pairs keep subdividing until
//!   then): Gauss–Newton for a touching point, and an overlap test projecting each segment's
//!   end points onto the other (1-D Gauss–Newton) — if two of them lie within `tol` and so
//!   does the midpoint between them, the leaf is an overlapping piece.
//!
//! Converged points farther apart than `tol` are dropped; overlapping leaf pieces that touch
//! in both parameters are chained into ranges; a chain shorter than `min_overlap_length` in
//! space is a tangency and reported as one point (its closest pair); points within
//! `min_overlap_length` of each other or inside an overlap are merged (the closest pair is
//! kept). Hence a tangency is reported once, crossings closer than `min_overlap_length` merge.
//!
//! Tolerances: `tol` is the distance under which the curves count as meeting; Gauss–Newton
//! stops at a parameter step below [`PARAM_EPS`] of the domain or a residual below
//! `tol · 1e-3`. Transversal crossings converge quadratically to rounding; tangencies
//! linearly, to about `√tol` in parameter, which the merging absorbs.
//!
//! Complexity: O((n_a + n_b)·log(1/ε)) leaf pairs for curves with isolated intersections,
//! plus `length / min_overlap_length` leaves per overlapping piece; each leaf costs a few
//! dozen curve evaluations. Allocations: the segment lists and a work stack.

use nalgebra::SVector;

use crate::{NurbsCurve, NurbsError};

/// Control polygons within this fraction of their chord length of the chord count as flat:
/// a Bézier piece that flat turns by < ~0.5°, so two flat pieces crossing at
/// [`TRANSVERSAL_SIN`] or more meet at most once and Newton from the chords converges.
pub const FLAT_REL: f64 = 1e-2;

/// Sine of the smallest chord angle treated as a transversal crossing (~5.7°). Flat pieces
/// closer to parallel are subdivided further and checked for tangency and overlap.
pub const TRANSVERSAL_SIN: f64 = 0.1;

/// Gauss–Newton parameter-step convergence threshold, relative to the domain length.
pub const PARAM_EPS: f64 = 1e-14;

/// Gauss–Newton iteration cap: quadratic convergence needs < 10 steps, linear convergence at
/// a tangency (halving per step) ~50 to reach [`PARAM_EPS`].
const MAX_NEWTON: usize = 60;

/// Subdivision depth cap per segment (2^-60 of a segment is far below rounding); guards the
/// recursion against degenerate (zero-length) segments.
const MAX_DEPTH: usize = 60;

/// Default [`IntersectOptions::min_overlap_length`] relative to the larger curve's bounding
/// box diagonal: pieces meeting within `tol` over less than 1e-3 of the curve's size are
/// tangencies (two circles of radius `r` touching within `tol = 1e-9 r` do so over ~1e-4 r).
pub const DEFAULT_OVERLAP_REL: f64 = 1e-3;

/// Options of [`intersect_curves`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntersectOptions {
    /// Distance (in the curves' units) under which the curves count as meeting.
    pub tol: f64,
    /// Shortest overlapping piece reported as a range; shorter ones are tangency points.
    /// `None`: [`DEFAULT_OVERLAP_REL`] times the larger bounding-box diagonal.
    pub min_overlap_length: Option<f64>,
}

impl Default for IntersectOptions {
    fn default() -> Self {
        Self {
            tol: 1e-9,
            min_overlap_length: None,
        }
    }
}

/// One isolated meeting point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntersectionPoint<const D: usize> {
    /// Parameter on the first curve.
    pub u: f64,
    /// Parameter on the second curve.
    pub v: f64,
    /// Midpoint of `A(u)` and `B(v)`.
    pub point: SVector<f64, D>,
    /// `|A(u) − B(v)|` (≤ tol).
    pub distance: f64,
}

/// A meeting of two curves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CurveIntersection<const D: usize> {
    /// Crossing or tangency point.
    Point(IntersectionPoint<D>),
    /// Overlapping piece: `A([u.0, u.1])` lies within `tol` of `B` between `v.0` and `v.1`
    /// (`v.0 > v.1` when the curves run in opposite directions there).
    Overlap {
        /// Parameter range on the first curve, increasing.
        u: (f64, f64),
        /// Matching parameter range on the second curve (`v.0` matches `u.0`).
        v: (f64, f64),
    },
}

/// A Bézier piece in homogeneous form: `hw[i] = w_i P_i`, weights `w[i]`, on `[t0, t1]`.
#[derive(Debug, Clone)]
struct Seg<const D: usize> {
    hw: Vec<SVector<f64, D>>,
    w: Vec<f64>,
    t0: f64,
    t1: f64,
    lo: SVector<f64, D>,
    hi: SVector<f64, D>,
    depth: usize,
}

impl<const D: usize> Seg<D> {
    fn new(hw: Vec<SVector<f64, D>>, w: Vec<f64>, t0: f64, t1: f64, depth: usize) -> Self {
        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for (p, &wi) in hw.iter().zip(&w) {
            let e = p / wi;
            lo = lo.inf(&e);
            hi = hi.sup(&e);
        }
        Self {
            hw,
            w,
            t0,
            t1,
            lo,
            hi,
            depth,
        }
    }

    fn euclid(&self, i: usize) -> SVector<f64, D> {
        self.hw[i] / self.w[i]
    }

    fn first(&self) -> SVector<f64, D> {
        self.euclid(0)
    }

    fn last(&self) -> SVector<f64, D> {
        self.euclid(self.hw.len() - 1)
    }

    fn diag(&self) -> f64 {
        (self.hi - self.lo).norm()
    }

    /// Largest distance of a control point from the chord (or from the first point when the
    /// chord degenerates).
    fn flatness(&self) -> f64 {
        let (a, b) = (self.first(), self.last());
        let d = b - a;
        let len = d.norm();
        (0..self.hw.len())
            .map(|i| {
                let q = self.euclid(i) - a;
                if len > 0.0 {
                    let t = q.dot(&d) / (len * len);
                    (q - d * t).norm()
                } else {
                    q.norm()
                }
            })
            .fold(0.0, f64::max)
    }

    /// de Casteljau halving in homogeneous space.
    fn split(&self) -> (Self, Self) {
        let n = self.hw.len();
        let mut hw = self.hw.clone();
        let mut w = self.w.clone();
        let mut left_h = Vec::with_capacity(n);
        let mut left_w = Vec::with_capacity(n);
        let mut right_h = vec![SVector::<f64, D>::zeros(); n];
        let mut right_w = vec![0.0; n];
        left_h.push(hw[0]);
        left_w.push(w[0]);
        right_h[n - 1] = hw[n - 1];
        right_w[n - 1] = w[n - 1];
        for r in 1..n {
            for i in 0..n - r {
                hw[i] = (hw[i] + hw[i + 1]) * 0.5;
                w[i] = 0.5 * (w[i] + w[i + 1]);
            }
            left_h.push(hw[0]);
            left_w.push(w[0]);
            right_h[n - 1 - r] = hw[n - 1 - r];
            right_w[n - 1 - r] = w[n - 1 - r];
        }
        let tm = 0.5 * (self.t0 + self.t1);
        (
            Seg::new(left_h, left_w, self.t0, tm, self.depth + 1),
            Seg::new(right_h, right_w, tm, self.t1, self.depth + 1),
        )
    }
}

fn box_gap<const D: usize>(a: &Seg<D>, b: &Seg<D>) -> f64 {
    let mut g2 = 0.0;
    for k in 0..D {
        let g = (a.lo[k] - b.hi[k]).max(b.lo[k] - a.hi[k]).max(0.0);
        g2 += g * g;
    }
    g2.sqrt()
}

fn segments<const D: usize>(c: &NurbsCurve<D>) -> Result<Vec<Seg<D>>, NurbsError> {
    let mut out = Vec::new();
    for s in c.bezier_segments()? {
        let (t0, t1) = s.domain();
        let w: Vec<f64> = match s.weights() {
            Some(w) => w.to_vec(),
            None => vec![1.0; s.control_points().len()],
        };
        if w.iter().any(|&x| !(x.is_finite() && x > 0.0)) {
            return Err(NurbsError::InvalidGeometry(
                "curve intersection needs positive weights (convex-hull bounds)".into(),
            ));
        }
        let hw = s
            .control_points()
            .iter()
            .zip(&w)
            .map(|(p, &wi)| p * wi)
            .collect();
        out.push(Seg::new(hw, w, t0, t1, 0));
    }
    Ok(out)
}

/// Damped Gauss–Newton on `A(u) − B(v)` from `(u, v)`, parameters kept in the two curves'
/// domains. Returns the final `(u, v, |A − B|)`.
fn gauss_newton<const D: usize>(
    a: &NurbsCurve<D>,
    b: &NurbsCurve<D>,
    mut u: f64,
    mut v: f64,
    tol: f64,
) -> (f64, f64, f64) {
    let (ua, ub) = a.domain();
    let (va, vb) = b.domain();
    let eps_u = PARAM_EPS * (ub - ua).max(1e-300);
    let eps_v = PARAM_EPS * (vb - va).max(1e-300);
    let mut best = (u, v, (a.point(u) - b.point(v)).norm());
    for _ in 0..MAX_NEWTON {
        let da = a.derivs2(u);
        let db = b.derivs2(v);
        let d = da[0] - db[0];
        let dist = d.norm();
        if dist < best.2 {
            best = (u, v, dist);
        }
        if dist <= tol * 1e-3 {
            break;
        }
        // Normal equations of J = [A', −B'] with the second-order terms of ½|d|² (true
        // Newton on the squared distance), damped when not positive definite.
        let h11 = da[1].dot(&da[1]) + da[2].dot(&d);
        let h22 = db[1].dot(&db[1]) - db[2].dot(&d);
        let h12 = -da[1].dot(&db[1]);
        let g1 = da[1].dot(&d);
        let g2 = -db[1].dot(&d);
        let scale = (h11.abs() + h22.abs()).max(1e-300);
        let mut mu = 0.0;
        let (mut du, mut dv) = (0.0, 0.0);
        for _ in 0..8 {
            let (a11, a22) = (h11 + mu, h22 + mu);
            let det = a11 * a22 - h12 * h12;
            if a11 > 0.0 && det > 1e-14 * scale * scale {
                du = -(a22 * g1 - h12 * g2) / det;
                dv = -(a11 * g2 - h12 * g1) / det;
                break;
            }
            mu = if mu == 0.0 { 1e-10 * scale } else { mu * 100.0 };
        }
        let nu = (u + du).clamp(ua, ub);
        let nv = (v + dv).clamp(va, vb);
        let step_small = (nu - u).abs() <= eps_u && (nv - v).abs() <= eps_v;
        // Halve the step while it does not decrease the distance (line search).
        let (mut su, mut sv) = (nu, nv);
        let mut accepted = false;
        for _ in 0..30 {
            if (a.point(su) - b.point(sv)).norm() <= dist {
                accepted = true;
                break;
            }
            su = 0.5 * (su + u);
            sv = 0.5 * (sv + v);
        }
        if !accepted || step_small {
            break;
        }
        u = su;
        v = sv;
    }
    let dist = (a.point(best.0) - b.point(best.1)).norm();
    (best.0, best.1, dist)
}

/// Closest point of `c` to `q` on `[t0, t1]` by 1-D Newton from the nearer end / middle.
fn project<const D: usize>(c: &NurbsCurve<D>, q: &SVector<f64, D>, t0: f64, t1: f64) -> (f64, f64) {
    let mut best = (t0, (c.point(t0) - q).norm());
    for t in [t1, 0.5 * (t0 + t1)] {
        let d = (c.point(t) - q).norm();
        if d < best.1 {
            best = (t, d);
        }
    }
    let mut t = best.0;
    let eps = PARAM_EPS * (t1 - t0).abs().max(1e-300);
    for _ in 0..MAX_NEWTON {
        let d = c.derivs2(t);
        let r = d[0] - q;
        let g = d[1].dot(&r);
        let h = d[1].dot(&d[1]) + d[2].dot(&r);
        let step = if h > 0.0 {
            -g / h
        } else {
            -g / d[1].dot(&d[1]).max(1e-300)
        };
        let nt = (t + step).clamp(t0.min(t1), t0.max(t1));
        let nd = (c.point(nt) - q).norm();
        if nd < best.1 {
            best = (nt, nd);
        }
        if (nt - t).abs() <= eps {
            break;
        }
        t = nt;
    }
    best
}

/// Overlap piece of a parallel leaf, if any: `(u0, u1, v0, v1)` with `u0 < u1`.
fn leaf_overlap<const D: usize>(
    a: &NurbsCurve<D>,
    b: &NurbsCurve<D>,
    sa: &Seg<D>,
    sb: &Seg<D>,
    tol: f64,
) -> Option<(f64, f64, f64, f64)> {
    // Pairs (u, v) of end points of one segment that lie on the other.
    let mut hits: Vec<(f64, f64)> = Vec::with_capacity(4);
    for u in [sa.t0, sa.t1] {
        let (v, d) = project(b, &a.point(u), sb.t0, sb.t1);
        if d <= tol {
            hits.push((u, v));
        }
    }
    for v in [sb.t0, sb.t1] {
        let (u, d) = project(a, &b.point(v), sa.t0, sa.t1);
        if d <= tol {
            hits.push((u, v));
        }
    }
    if hits.len() < 2 {
        return None;
    }
    hits.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (first, last) = (hits[0], hits[hits.len() - 1]);
    if last.0 - first.0 <= 0.0 {
        return None;
    }
    // The midpoint between them must lie on B too (rules out two crossings at the ends).
    let um = 0.5 * (first.0 + last.0);
    let (lo, hi) = (first.1.min(last.1), first.1.max(last.1));
    let (_, dm) = project(b, &a.point(um), lo, hi);
    (dm <= tol).then_some((first.0, last.0, first.1, last.1))
}

/// All intersections of two curves of the same dimension (see the module docs), sorted by
/// the first curve's parameter.
///
/// Errors: non-positive `tol`, or a curve with a non-positive weight.
pub fn intersect_curves<const D: usize>(
    a: &NurbsCurve<D>,
    b: &NurbsCurve<D>,
    opts: &IntersectOptions,
) -> Result<Vec<CurveIntersection<D>>, NurbsError> {
    let tol = opts.tol;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(NurbsError::InvalidGeometry(format!(
            "intersection tolerance {tol} must be finite and > 0"
        )));
    }
    let sa = segments(a)?;
    let sb = segments(b)?;
    let size = sa
        .iter()
        .chain(sb.iter().map(|s| s as &Seg<D>))
        .map(|s| s.diag())
        .fold(0.0, f64::max);
    let extent = {
        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for s in sa.iter().chain(sb.iter()) {
            lo = lo.inf(&s.lo);
            hi = hi.sup(&s.hi);
        }
        (hi - lo).norm().max(size)
    };
    let min_overlap = opts
        .min_overlap_length
        .unwrap_or(DEFAULT_OVERLAP_REL * extent)
        .max(4.0 * tol);
    let leaf_len = 0.25 * min_overlap;

    let mut points: Vec<IntersectionPoint<D>> = Vec::new();
    let mut pieces: Vec<(f64, f64, f64, f64)> = Vec::new();
    let mut stack: Vec<(Seg<D>, Seg<D>)> = Vec::new();
    for x in &sa {
        for y in &sb {
            if box_gap(x, y) <= tol {
                stack.push((x.clone(), y.clone()));
            }
        }
    }
    let push_point = |u: f64, v: f64, points: &mut Vec<IntersectionPoint<D>>| {
        let (u, v, d) = gauss_newton(a, b, u, v, tol);
        if d <= tol {
            points.push(IntersectionPoint {
                u,
                v,
                point: (a.point(u) + b.point(v)) * 0.5,
                distance: d,
            });
        }
    };
    while let Some((x, y)) = stack.pop() {
        let (lx, ly) = ((x.last() - x.first()).norm(), (y.last() - y.first()).norm());
        let flat_x = x.flatness() <= FLAT_REL * lx.max(tol);
        let flat_y = y.flatness() <= FLAT_REL * ly.max(tol);
        let deep = x.depth >= MAX_DEPTH && y.depth >= MAX_DEPTH;
        if flat_x && flat_y {
            let dx = x.last() - x.first();
            let dy = y.last() - y.first();
            let sin = if lx > 0.0 && ly > 0.0 {
                let c = dx.dot(&dy) / (lx * ly);
                (1.0 - c * c).max(0.0).sqrt()
            } else {
                0.0
            };
            if sin > TRANSVERSAL_SIN {
                let (u0, v0) = chord_params(&x, &y);
                push_point(u0, v0, &mut points);
                continue;
            }
            if (x.diag() <= leaf_len && y.diag() <= leaf_len) || deep {
                if let Some(p) = leaf_overlap(a, b, &x, &y, tol) {
                    pieces.push(p);
                }
                push_point(0.5 * (x.t0 + x.t1), 0.5 * (y.t0 + y.t1), &mut points);
                continue;
            }
        } else if deep {
            push_point(0.5 * (x.t0 + x.t1), 0.5 * (y.t0 + y.t1), &mut points);
            continue;
        }
        // Split the larger (or the non-flat) piece.
        let split_x = (x.diag() >= y.diag() && x.depth < MAX_DEPTH) || y.depth >= MAX_DEPTH;
        if split_x {
            let (l, r) = x.split();
            for h in [l, r] {
                if box_gap(&h, &y) <= tol {
                    stack.push((h, y.clone()));
                }
            }
        } else {
            let (l, r) = y.split();
            for h in [l, r] {
                if box_gap(&x, &h) <= tol {
                    stack.push((x.clone(), h));
                }
            }
        }
    }
    Ok(assemble(a, b, points, pieces, tol, min_overlap))
}

/// Parameters of the closest points of the two chords, mapped to the segments' ranges.
fn chord_params<const D: usize>(x: &Seg<D>, y: &Seg<D>) -> (f64, f64) {
    let (p, q) = (x.first(), y.first());
    let (d1, d2) = (x.last() - p, y.last() - q);
    let r = p - q;
    let (a, b, c) = (d1.dot(&d1), d1.dot(&d2), d2.dot(&d2));
    let (d, e) = (d1.dot(&r), d2.dot(&r));
    let den = a * c - b * b;
    let (s, t) = if den > 1e-300 {
        (
            ((b * e - c * d) / den).clamp(0.0, 1.0),
            ((a * e - b * d) / den).clamp(0.0, 1.0),
        )
    } else {
        (0.5, 0.5)
    };
    (x.t0 + s * (x.t1 - x.t0), y.t0 + t * (y.t1 - y.t0))
}

/// Chains overlap pieces, turns short chains into tangency points, merges duplicates.
fn assemble<const D: usize>(
    a: &NurbsCurve<D>,
    b: &NurbsCurve<D>,
    mut points: Vec<IntersectionPoint<D>>,
    mut pieces: Vec<(f64, f64, f64, f64)>,
    tol: f64,
    min_overlap: f64,
) -> Vec<CurveIntersection<D>> {
    let (ua, ub) = a.domain();
    let (va, vb) = b.domain();
    let join_u = 1e-9 * (ub - ua);
    let join_v = 1e-9 * (vb - va);
    pieces.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut chains: Vec<(f64, f64, f64, f64)> = Vec::new();
    for p in pieces {
        if let Some(c) = chains.last_mut() {
            let touches_u = p.0 <= c.1 + join_u;
            let touches_v = (p.2 - c.3).abs() <= join_v
                || (p.2.min(p.3) <= c.2.max(c.3) + join_v && p.2.max(p.3) + join_v >= c.2.min(c.3));
            if touches_u && touches_v {
                if p.1 > c.1 {
                    c.1 = p.1;
                    c.3 = p.3;
                }
                continue;
            }
        }
        chains.push(p);
    }
    let mut out: Vec<CurveIntersection<D>> = Vec::new();
    let mut overlaps: Vec<(f64, f64, f64, f64)> = Vec::new();
    for c in chains {
        let len = (a.point(c.1) - a.point(c.0)).norm();
        if len >= min_overlap {
            overlaps.push(c);
        } else {
            // A tangency seen as a short overlap: its closest pair.
            let (u, v, d) = gauss_newton(a, b, 0.5 * (c.0 + c.1), 0.5 * (c.2 + c.3), tol);
            if d <= tol {
                points.push(IntersectionPoint {
                    u,
                    v,
                    point: (a.point(u) + b.point(v)) * 0.5,
                    distance: d,
                });
            }
        }
    }
    // Drop points inside overlaps, then merge points closer than min_overlap (keep closest).
    points.retain(|p| {
        !overlaps
            .iter()
            .any(|o| p.u >= o.0 - join_u && p.u <= o.1 + join_u)
    });
    points.sort_by(|x, y| x.u.total_cmp(&y.u));
    let mut merged: Vec<IntersectionPoint<D>> = Vec::new();
    for p in points {
        if let Some(m) = merged
            .iter_mut()
            .find(|m| (m.point - p.point).norm() < min_overlap)
        {
            if p.distance < m.distance {
                *m = p;
            }
            continue;
        }
        merged.push(p);
    }
    out.extend(merged.into_iter().map(CurveIntersection::Point));
    out.extend(overlaps.into_iter().map(|o| CurveIntersection::Overlap {
        u: (o.0, o.1),
        v: (o.2, o.3),
    }));
    out.sort_by(|x, y| start_u(x).total_cmp(&start_u(y)));
    out
}

fn start_u<const D: usize>(x: &CurveIntersection<D>) -> f64 {
    match x {
        CurveIntersection::Point(p) => p.u,
        CurveIntersection::Overlap { u, .. } => u.0,
    }
}

/// Global closest approach of two curves: the pair `(u, v)` minimising `|A(u) − B(v)|`, by
/// branch and bound over Bézier segment pairs (a pair is discarded when its boxes' gap
/// exceeds the best distance found, minus `tol`), Gauss–Newton at flat leaves. The result is
/// within `tol` of the true minimum distance. Errors: non-positive `tol` or weights.
/// Complexity: as [`intersect_curves`] for isolated minima.
pub fn closest_approach<const D: usize>(
    a: &NurbsCurve<D>,
    b: &NurbsCurve<D>,
    tol: f64,
) -> Result<IntersectionPoint<D>, NurbsError> {
    if !(tol.is_finite() && tol > 0.0) {
        return Err(NurbsError::InvalidGeometry(format!(
            "closest-approach tolerance {tol} must be finite and > 0"
        )));
    }
    let sa = segments(a)?;
    let sb = segments(b)?;
    let (ua, ub) = a.domain();
    let (va, vb) = b.domain();
    let mut best = IntersectionPoint {
        u: ua,
        v: va,
        point: (a.point(ua) + b.point(va)) * 0.5,
        distance: (a.point(ua) - b.point(va)).norm(),
    };
    let consider = |u: f64, v: f64, best: &mut IntersectionPoint<D>| {
        let (u, v, d) = gauss_newton(a, b, u, v, tol);
        if d < best.distance {
            *best = IntersectionPoint {
                u,
                v,
                point: (a.point(u) + b.point(v)) * 0.5,
                distance: d,
            };
        }
    };
    for (u, v) in [(ua, vb), (ub, va), (ub, vb)] {
        consider(u, v, &mut best);
    }
    let mut stack: Vec<(Seg<D>, Seg<D>)> = Vec::new();
    for x in &sa {
        for y in &sb {
            stack.push((x.clone(), y.clone()));
        }
    }
    while let Some((x, y)) = stack.pop() {
        if box_gap(&x, &y) > best.distance - tol {
            continue;
        }
        let lx = (x.last() - x.first()).norm();
        let ly = (y.last() - y.first()).norm();
        let flat = x.flatness() <= FLAT_REL * lx.max(tol) && y.flatness() <= FLAT_REL * ly.max(tol);
        let deep = x.depth >= MAX_DEPTH && y.depth >= MAX_DEPTH;
        if flat || deep || (x.diag() <= tol && y.diag() <= tol) {
            // Two nearly straight pieces: one distance minimum, reached from the chords'.
            let (u0, v0) = chord_params(&x, &y);
            consider(u0, v0, &mut best);
            continue;
        }
        let split_x = (x.diag() >= y.diag() && x.depth < MAX_DEPTH) || y.depth >= MAX_DEPTH;
        if split_x {
            let (l, r) = x.split();
            stack.push((l, y.clone()));
            stack.push((r, y));
        } else {
            let (l, r) = y.split();
            stack.push((x.clone(), l));
            stack.push((x, r));
        }
    }
    Ok(best)
}
