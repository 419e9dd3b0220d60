//! Global closest point on a NURBS curve (any dimension).
//!
//! **Degree ≤ 7 (every curve the project builds):** a certified search. The curve's Bézier
//! segments sit in a bounding-volume tree of their control-point boxes (positive weights: a
//! segment lies in the convex hull of its control points); the tree is walked best-first
//! and each segment whose box is nearer than the best distance is searched by root isolation
//! of the distance's derivative in the Bernstein basis, rational segments included (see
//! `curve_cert.rs`: `(C − q)·C' = N/W³` with `N` a Bernstein polynomial computed exactly from
//! the homogeneous control points). The answer's `certified` flag says the minimum is
//! proven global. The hint only seeds the upper bound.
//!
//! **Higher degrees:** the earlier method below, kept as the fallback.
//!
//! Same method as the surface projector, one dimension down: the curve is decomposed into
//! Bézier segments (split further where the tangent turns by more than ~35°); each piece
//! keeps the axis-aligned box of its control polygon (a lower bound of the distance to the
//! piece) and the cone of its hodograph (all tangents). A query first solves the piece with
//! the smallest lower bound (or runs Newton on the whole domain from a hint), then every
//! piece whose box is closer than the best distance and whose tangent cone does not prove
//! the distance monotone towards an interior C¹ end is minimised by bounded 1D Newton
//! (`g = (C−q)·C'`, `H = C'·C' + (C−q)·C''`, Gauss–Newton `C'·C'` when `H ≤ 0`, backtracking,
//! clamped to the piece). End points of the domain are exact constrained minima.
//!
//! Global optimality: each piece carries boxes of `C'` and `C''` (hodograph control vectors),
//! and a query checks by interval arithmetic that `H = |C'|² + (C − q)·C''` is positive on the
//! whole piece, so the distance is strictly convex there and Newton's answer is the piece's
//! minimum. Pieces that fail (queries beyond a centre of curvature) are searched by branch
//! and bound over de Casteljau halves (allocating). Rigorous for polynomial curves; rational
//! pieces use sampled derivative boxes widened by 25% (a heuristic). Newton stops at a
//! predicted step below `1e-13 × (1 + size)` with the angle condition met to `1e-11`.
//! Queries take `&self` and do not allocate.

use nalgebra::SVector;

use super::bezier::BezierSegment;
use crate::NurbsCurve;

/// The closest point found on a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint<const D: usize> {
    /// Parameter of the closest point (inside the domain).
    pub u: f64,
    /// `C(u)`.
    pub point: SVector<f64, D>,
    /// The tangent `C'(u)` (derivative in the curve's parameter), e.g. to sign the distance.
    pub tangent: SVector<f64, D>,
    /// Distance from the query point (mm).
    pub distance: f64,
    /// The answer is a domain end where the distance still decreases outwards.
    pub on_boundary: bool,
    /// Proven global: every part of the curve was shown to be no nearer (by the Bernstein
    /// root isolation of [`CurveProjector`]'s tree search). `false` only when an interval
    /// stayed ambiguous at the finest subdivision, or for curves of degree above 7 (searched
    /// by the sampled-bound method).
    pub certified: bool,
}

#[derive(Debug, Clone)]
struct Piece<const D: usize> {
    u0: f64,
    u1: f64,
    seg: usize,
    min: SVector<f64, D>,
    max: SVector<f64, D>,
    /// Tangent cone: unit axis and sine of half angle.
    cone: Option<(SVector<f64, D>, f64)>,
    /// May the piece be dropped when the distance decreases towards its start / end?
    exclude_towards: [bool; 2],
    samples: [(f64, SVector<f64, D>); 5],
    /// Boxes of `C'` and `C''` over the piece (convexity certificate).
    d1: (SVector<f64, D>, SVector<f64, D>),
    d2: (SVector<f64, D>, SVector<f64, D>),
}

/// Boxes `(min, max)` of `C'` and `C''` over a segment: hodograph control vectors for
/// polynomial pieces (rigorous), a 9-point sample widened by 25% for rational ones.
#[allow(clippy::type_complexity)]
fn derivative_boxes<const D: usize>(
    seg: &BezierSegment<D>,
) -> (
    (SVector<f64, D>, SVector<f64, D>),
    (SVector<f64, D>, SVector<f64, D>),
) {
    let boxed = |vs: &[SVector<f64, D>], widen: f64| {
        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for v in vs {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        if vs.is_empty() {
            return (SVector::zeros(), SVector::zeros());
        }
        let pad = SVector::<f64, D>::from_fn(|k, _| {
            widen * ((hi[k] - lo[k]) + lo[k].abs().max(hi[k].abs()))
        });
        (lo - pad, hi + pad)
    };
    let h = seg.u1 - seg.u0;
    if seg.rational {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for k in 0..=8 {
            let d = seg.derivs2(seg.u0 + h * k as f64 / 8.0);
            a.push(d[1]);
            b.push(d[2]);
        }
        return (boxed(&a, 0.25), boxed(&b, 0.25));
    }
    let pts: Vec<SVector<f64, D>> = seg.points().collect();
    let p = seg.p as f64;
    let d1: Vec<SVector<f64, D>> = pts.windows(2).map(|w| (w[1] - w[0]) * (p / h)).collect();
    let d2: Vec<SVector<f64, D>> = pts
        .windows(3)
        .map(|w| (w[2] - w[1] * 2.0 + w[0]) * (p * (p - 1.0) / (h * h)))
        .collect();
    (boxed(&d1, 1e-12), boxed(&d2, 1e-12))
}

/// Is `H = |C'|² + (C − q)·C''` positive on the whole piece (interval arithmetic over the
/// boxes of `C − q`, `C'`, `C''`)? Then the distance is strictly convex there.
#[allow(clippy::type_complexity)]
fn certified<const D: usize>(
    min: &SVector<f64, D>,
    max: &SVector<f64, D>,
    d1: &(SVector<f64, D>, SVector<f64, D>),
    d2: &(SVector<f64, D>, SVector<f64, D>),
    q: &SVector<f64, D>,
) -> bool {
    let mut lo = 0.0;
    for k in 0..D {
        let (a, b) = (d1.0[k], d1.1[k]);
        lo += if a <= 0.0 && b >= 0.0 {
            0.0
        } else {
            (a * a).min(b * b)
        };
        let (r0, r1) = (min[k] - q[k], max[k] - q[k]);
        let c = [r0 * d2.0[k], r0 * d2.1[k], r1 * d2.0[k], r1 * d2.1[k]];
        lo += c.iter().copied().fold(f64::INFINITY, f64::min);
    }
    lo > 0.0
}

/// Deepest query-time subdivision of an uncertified piece (the piece is depth 1, so the
/// finest pieces are 2⁻⁷ = 1/128 of it).
const MAX_BB_DEPTH: usize = 8;

/// Precomputed closest-point query structure for one curve. See the module docs.
#[derive(Debug, Clone)]
pub struct CurveProjector<const D: usize> {
    segs: Vec<BezierSegment<D>>,
    breaks: Vec<f64>,
    pieces: Vec<Piece<D>>,
    domain: (f64, f64),
    step_tol: f64,
    /// Bounding-volume tree over the Bézier segments (empty above degree 7).
    tree: Vec<super::curve_cert::Node<D>>,
    /// Per segment, the query-independent polynomials of the certified search (empty above
    /// degree 7).
    polys: Vec<super::curve_cert::PiecePolys<D>>,
}

struct Local1<const D: usize> {
    u: f64,
    point: SVector<f64, D>,
    d2: f64,
    active: i8,
}

impl<const D: usize> CurveProjector<D> {
    /// Builds the query structure. O(spans × p²).
    pub fn new(curve: &NurbsCurve<D>) -> Self {
        let (segs, breaks) = super::decompose_curve(curve);
        let p = curve.degree();
        let mut pieces = Vec::new();
        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for (k, seg) in segs.iter().enumerate() {
            for pt in seg.points() {
                lo = lo.inf(&pt);
                hi = hi.sup(&pt);
            }
            let n = split_count(seg);
            let c1_start = k > 0 && curve.knots().multiplicity(seg.u0) < p;
            let c1_end = k + 1 < segs.len() && curve.knots().multiplicity(seg.u1) < p;
            for i in 0..n {
                let a = lerp(seg.u0, seg.u1, i, n);
                let b = lerp(seg.u0, seg.u1, i + 1, n);
                let sub = if n == 1 {
                    seg.clone()
                } else {
                    seg.sub_segment(a, b)
                };
                let pts: Vec<SVector<f64, D>> = sub.points().collect();
                let mut min = SVector::<f64, D>::repeat(f64::INFINITY);
                let mut max = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
                for pt in &pts {
                    min = min.inf(pt);
                    max = max.sup(pt);
                }
                let pad = SVector::<f64, D>::from_fn(|d, _| 1e-12 * (min[d].abs() + max[d].abs()));
                min -= pad;
                max += pad;
                let cone = if curve.is_rational() {
                    None
                } else {
                    let diffs: Vec<SVector<f64, D>> = pts.windows(2).map(|w| w[1] - w[0]).collect();
                    cone_of(&diffs)
                };
                let mut samples = [(0.0, SVector::<f64, D>::zeros()); 5];
                for (s, slot) in samples.iter_mut().enumerate() {
                    let u = lerp(a, b, s, 4);
                    *slot = (u, seg.derivs2(u)[0]);
                }
                let (d1, d2) = derivative_boxes(&sub);
                pieces.push(Piece {
                    u0: a,
                    u1: b,
                    seg: k,
                    min,
                    max,
                    cone,
                    exclude_towards: [i > 0 || c1_start, i + 1 < n || c1_end],
                    samples,
                    d1,
                    d2,
                });
            }
        }
        let diag = (hi - lo).norm();
        let step_tol = 1e-13 * (1.0 + if diag.is_finite() { diag } else { 0.0 });
        let (tree, polys) = if p <= super::curve_cert::MAX_CERT_DEGREE {
            let boxes: Vec<_> = segs.iter().map(super::curve_cert::control_box).collect();
            (
                super::curve_cert::build_tree(&boxes),
                segs.iter()
                    .map(super::curve_cert::PiecePolys::new)
                    .collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        CurveProjector {
            segs,
            breaks,
            pieces,
            domain: curve.domain(),
            step_tol,
            tree,
            polys,
        }
    }

    #[inline]
    fn seg_index(&self, u: f64) -> usize {
        let n = self.breaks.len() - 1;
        self.breaks[1..n].partition_point(|&b| b <= u)
    }

    /// `[C, C', C'']` at `u` from the Bézier segments (no allocation; `u` outside the
    /// domain extrapolates the end segment).
    #[inline]
    pub fn derivs2(&self, u: f64) -> [SVector<f64, D>; 3] {
        self.segs[self.seg_index(u)].derivs2(u)
    }

    /// The global closest point of the curve to `q`.
    pub fn closest_point(&self, q: &SVector<f64, D>) -> CurvePoint<D> {
        self.closest_point_with_hint(q, None)
    }

    /// The global closest point to `q` when it lies within `max_dist` of `q`, `None` when
    /// every point of the curve is farther (a non-finite `q` or a NaN or negative `max_dist`
    /// gives `None`; an infinite one is the unbounded search).
    ///
    /// For degree ≤ 7 the certified search starts with `max_dist²` as its upper bound, so
    /// every Bézier segment whose control box lies farther is pruned before any root
    /// isolation: a query far from the curve costs a few box distances of the segment tree's
    /// top. The answer, when there is one, is the global closest point (as
    /// [`Self::closest_point`]: the pruned segments are farther than it). A closest point
    /// within the certification tolerance (10⁻¹⁰ mm) below `max_dist` may be reported as
    /// `None`: callers give a bound with that much margin. Higher degrees run the full
    /// search and compare.
    pub fn closest_point_within(
        &self,
        q: &SVector<f64, D>,
        max_dist: f64,
    ) -> Option<CurvePoint<D>> {
        if !(q.iter().all(|c| c.is_finite()) && max_dist >= 0.0) {
            return None;
        }
        if max_dist == f64::INFINITY {
            return Some(self.closest_point(q));
        }
        if self.tree.is_empty() {
            return Some(self.closest_point(q)).filter(|c| c.distance <= max_dist);
        }
        // A hair above the bound so that a point at exactly `max_dist` is found.
        let seed = max_dist * max_dist * (1.0 + 1e-12) + f64::MIN_POSITIVE;
        self.tree_search_below(q, None, seed)
    }

    /// The global closest point to `q`, starting Newton from parameter `hint` when given
    /// (the answer does not depend on it). A non-finite `q` gives a NaN distance.
    pub fn closest_point_with_hint(&self, q: &SVector<f64, D>, hint: Option<f64>) -> CurvePoint<D> {
        let (a, b) = self.domain;
        if !q.iter().all(|c| c.is_finite()) {
            // No point is closest to a non-finite query.
            let e = self.derivs2(a);
            return CurvePoint {
                u: a,
                point: e[0],
                tangent: e[1],
                distance: f64::NAN,
                on_boundary: false,
                certified: false,
            };
        }
        if !self.tree.is_empty() {
            return self.tree_search(q, hint);
        }
        let mut best: Option<Local1<D>> = None;
        if let Some(h) = hint.filter(|h| h.is_finite()) {
            best = Some(self.newton(q, a, b, h, None));
        }
        let lb = |pc: &Piece<D>| -> f64 {
            let mut s = 0.0;
            for d in 0..D {
                let x = (pc.min[d] - q[d]).max(q[d] - pc.max[d]).max(0.0);
                s += x * x;
            }
            s
        };
        if best.is_none() {
            let mut first = 0;
            let mut first_lb = f64::INFINITY;
            for (i, pc) in self.pieces.iter().enumerate() {
                let l = lb(pc);
                if l < first_lb {
                    first_lb = l;
                    first = i;
                }
            }
            best = Some(self.solve_piece(first, q));
        }
        for (i, pc) in self.pieces.iter().enumerate() {
            let bound = best.as_ref().map_or(f64::INFINITY, |b| b.d2);
            if lb(pc) >= bound {
                continue;
            }
            if let Some((axis, sin)) = &pc.cone {
                // (C − q)·t over the box and the cone.
                let mut min_dot = 0.0;
                let mut max_dot = 0.0;
                let mut max_w2 = 0.0;
                for d in 0..D {
                    let lo = pc.min[d] - q[d];
                    let hi = pc.max[d] - q[d];
                    min_dot += (axis[d] * lo).min(axis[d] * hi);
                    max_dot += (axis[d] * lo).max(axis[d] * hi);
                    max_w2 += lo.abs().max(hi.abs()).powi(2);
                }
                let margin = max_w2.sqrt() * sin;
                if (min_dot > margin && pc.exclude_towards[0])
                    || (max_dot < -margin && pc.exclude_towards[1])
                {
                    continue;
                }
            }
            let l = self.solve_piece(i, q);
            if l.d2 < bound {
                best = Some(l);
            }
        }
        match best {
            Some(l) => CurvePoint {
                u: l.u,
                point: l.point,
                tangent: self.derivs2(l.u)[1],
                distance: l.d2.sqrt(),
                on_boundary: l.active != 0,
                certified: false,
            },
            None => {
                let [c, t, _] = self.derivs2(a);
                CurvePoint {
                    u: a,
                    point: c,
                    tangent: t,
                    distance: (c - q).norm(),
                    on_boundary: true,
                    certified: false,
                }
            }
        }
    }

    /// Certified search: best-first walk of the segment tree, each segment searched by
    /// Bernstein root isolation ([`super::curve_cert`]). The hint only seeds the upper bound.
    fn tree_search(&self, q: &SVector<f64, D>, hint: Option<f64>) -> CurvePoint<D> {
        let found = self.tree_search_below(q, hint, f64::INFINITY);
        // With no bound every search finds a point (a segment's end at worst); the fallback
        // only keeps this total.
        found.unwrap_or_else(|| {
            let (a, _) = self.domain;
            let e = self.derivs2(a);
            CurvePoint {
                u: a,
                point: e[0],
                tangent: e[1],
                distance: (e[0] - q).norm(),
                on_boundary: false,
                certified: false,
            }
        })
    }

    /// The certified tree search for a point nearer than `sqrt(bound_d2)` (`None` when there
    /// is none), Newton seeded at `hint`.
    fn tree_search_below(
        &self,
        q: &SVector<f64, D>,
        hint: Option<f64>,
        bound_d2: f64,
    ) -> Option<CurvePoint<D>> {
        use super::curve_cert::{box_d2, search_piece, Best};
        let (a, b) = self.domain;
        // `piece` stays out of range until a segment search finds a point below the bound.
        let mut best = Best {
            t: 0.0,
            piece: usize::MAX,
            d2: bound_d2,
            certified: true,
        };
        if let Some(h) = hint.filter(|h| h.is_finite()) {
            let u = h.clamp(a, b);
            let k = self.seg_index(u);
            let sg = &self.segs[k];
            let d2 = (sg.derivs2(u)[0] - q).norm_squared();
            // Slightly above: the segment search must still run and return its own point.
            best.d2 = d2 * (1.0 + 1e-12) + f64::MIN_POSITIVE;
            best.piece = k;
            best.t = (u - sg.u0) / (sg.u1 - sg.u0);
        }
        // Stack of (node, lower bound); depth ≤ log2(segments) + 1 per level pushed.
        let mut stack = [(0usize, 0.0f64); 128];
        let mut top = 1;
        stack[0] = (0, box_d2(&self.tree[0].min, &self.tree[0].max, q));
        let mut walked_all = true;
        while top > 0 {
            top -= 1;
            let (id, lb) = stack[top];
            if lb >= best.d2 {
                continue;
            }
            let node = &self.tree[id];
            match node.kids {
                None => search_piece(&self.polys[node.lo], node.lo, q, &mut best),
                Some((l, r)) => {
                    if top + 2 > stack.len() {
                        walked_all = false;
                        continue;
                    }
                    let ll = box_d2(&self.tree[l].min, &self.tree[l].max, q);
                    let lr = box_d2(&self.tree[r].min, &self.tree[r].max, q);
                    // Nearer child on top.
                    let (far, near) = if ll <= lr {
                        ((r, lr), (l, ll))
                    } else {
                        ((l, ll), (r, lr))
                    };
                    stack[top] = far;
                    stack[top + 1] = near;
                    top += 2;
                }
            }
        }
        let sg = self.segs.get(best.piece)?;
        let u = (sg.u0 + best.t * (sg.u1 - sg.u0)).clamp(a, b);
        let e = sg.derivs2(u);
        let g = (e[0] - q).dot(&e[1]);
        Some(CurvePoint {
            u,
            point: e[0],
            tangent: e[1],
            distance: (e[0] - q).norm(),
            on_boundary: (u <= a && g > 0.0) || (u >= b && g < 0.0),
            certified: best.certified && walked_all,
        })
    }

    fn solve_piece(&self, i: usize, q: &SVector<f64, D>) -> Local1<D> {
        let pc = &self.pieces[i];
        let mut start = pc.samples[0].0;
        let mut ds = f64::INFINITY;
        for (u, p) in &pc.samples {
            let d = (p - q).norm_squared();
            if d < ds {
                ds = d;
                start = *u;
            }
        }
        let mut best = self.newton(q, pc.u0, pc.u1, start, Some(pc.seg));
        if !certified(&pc.min, &pc.max, &pc.d1, &pc.d2, q) {
            // Possibly several minima (query beyond a centre of curvature): branch and bound.
            let seg = &self.segs[pc.seg];
            let sub = seg.sub_segment(pc.u0, pc.u1);
            self.branch_and_bound(pc.seg, &sub, q, &mut best, 1);
        }
        best
    }

    /// Branch and bound over de Casteljau pieces: pruned by their control-polygon boxes,
    /// solved by Newton once certified convex (or at the depth limit), halved otherwise.
    fn branch_and_bound(
        &self,
        seg: usize,
        sub: &BezierSegment<D>,
        q: &SVector<f64, D>,
        best: &mut Local1<D>,
        depth: usize,
    ) {
        let mut min = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut max = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for p in sub.points() {
            min = min.inf(&p);
            max = max.sup(&p);
        }
        let mut lb = 0.0;
        for k in 0..D {
            let x = (min[k] - q[k]).max(q[k] - max[k]).max(0.0);
            lb += x * x;
        }
        if lb >= best.d2 {
            return;
        }
        let (d1, d2) = derivative_boxes(sub);
        if depth >= MAX_BB_DEPTH || certified(&min, &max, &d1, &d2, q) {
            let mid = 0.5 * (sub.u0 + sub.u1);
            let l = self.newton(q, sub.u0, sub.u1, mid, Some(seg));
            if l.d2 < best.d2 {
                *best = l;
            }
            return;
        }
        let mid = 0.5 * (sub.u0 + sub.u1);
        let halves = [sub.sub_segment(sub.u0, mid), sub.sub_segment(mid, sub.u1)];
        for h in &halves {
            self.branch_and_bound(seg, h, q, best, depth + 1);
        }
    }

    /// Bounded 1D Newton on `[lo, hi]` from `start`.
    fn newton(
        &self,
        q: &SVector<f64, D>,
        lo: f64,
        hi: f64,
        start: f64,
        seg: Option<usize>,
    ) -> Local1<D> {
        let ev = |u: f64| match seg {
            Some(s) => self.segs[s].derivs2(u),
            None => self.derivs2(u),
        };
        let mut u = start.clamp(lo, hi);
        let mut e = ev(u);
        let mut r = e[0] - q;
        let mut f = r.norm_squared();
        for _ in 0..super::newton::MAX_ITER {
            let g = r.dot(&e[1]);
            if (u <= lo && g > 0.0) || (u >= hi && g < 0.0) {
                break;
            }
            let a = e[1].norm_squared();
            let h = a + r.dot(&e[2]);
            let h = if h > 0.0 { h } else { a };
            if h <= 0.0 {
                break;
            }
            let du = -g / h;
            let predicted = (e[1] * ((u + du).clamp(lo, hi) - u)).norm();
            if predicted <= self.step_tol
                && (g.abs() <= super::newton::ANGLE_TOL * f.sqrt() * a.sqrt()
                    || predicted <= 1e-3 * self.step_tol)
            {
                break;
            }
            let mut t = 1.0;
            let mut accepted = None;
            for _ in 0..12 {
                let un = (u + t * du).clamp(lo, hi);
                let en = ev(un);
                let fnew = (en[0] - q).norm_squared();
                if fnew <= f + super::newton::noise(f, &en[0], q) {
                    accepted = Some((un, en, fnew));
                    break;
                }
                t *= 0.5;
            }
            let Some((un, en, fnew)) = accepted else {
                break;
            };
            let step = (e[1] * (un - u)).norm();
            u = un;
            e = en;
            r = e[0] - q;
            f = fnew;
            if step <= self.step_tol {
                break;
            }
        }
        let g = r.dot(&e[1]);
        let (a, b) = self.domain;
        let active = if u <= a && g > 0.0 {
            -1
        } else if u >= b && g < 0.0 {
            1
        } else {
            0
        };
        Local1 {
            u,
            point: e[0],
            d2: f,
            active,
        }
    }
}

/// Global closest point of `curve` to `q` (builds a [`CurveProjector`] for one query).
pub fn closest_point_on_curve<const D: usize>(
    curve: &NurbsCurve<D>,
    q: &SVector<f64, D>,
) -> CurvePoint<D> {
    CurveProjector::new(curve).closest_point(q)
}

fn lerp(a: f64, b: f64, i: usize, n: usize) -> f64 {
    if i == n {
        b
    } else {
        a + (b - a) * i as f64 / n as f64
    }
}

/// Pieces per segment so that the tangent turns by at most ~35° in each (sampled).
fn split_count<const D: usize>(seg: &BezierSegment<D>) -> usize {
    let mut n = 1;
    while n < 64 {
        let mut ok = true;
        for i in 0..n {
            let a = lerp(seg.u0, seg.u1, i, n);
            let b = lerp(seg.u0, seg.u1, i + 1, n);
            let Some(tc) = seg.derivs2(0.5 * (a + b))[1].try_normalize(0.0) else {
                continue;
            };
            for k in 0..=6 {
                if let Some(t) = seg.derivs2(lerp(a, b, k, 6))[1].try_normalize(0.0) {
                    if t.dot(&tc) < 0.82 {
                        ok = false;
                    }
                }
            }
        }
        if ok {
            break;
        }
        n *= 2;
    }
    n
}

fn cone_of<const D: usize>(dirs: &[SVector<f64, D>]) -> Option<(SVector<f64, D>, f64)> {
    let mut axis = SVector::<f64, D>::zeros();
    for d in dirs {
        let n = d.norm();
        if n > 0.0 {
            axis += d / n;
        }
    }
    let axis = axis.try_normalize(0.0)?;
    let mut sin_max: f64 = 0.0;
    for d in dirs {
        let n = d.norm();
        if n == 0.0 {
            continue;
        }
        let c = d.dot(&axis) / n;
        if c <= 1e-3 {
            return None;
        }
        sin_max = sin_max.max((1.0 - c * c).max(0.0).sqrt());
    }
    Some((axis, (sin_max * (1.0 + 1e-9) + 1e-12).min(1.0)))
}
