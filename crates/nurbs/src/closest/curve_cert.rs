//! Certified global closest point on a (rational) Bézier piece, by root isolation of the
//! distance's derivative in the Bernstein basis, and a bounding-volume tree over the pieces
//! of a curve.
//!
//! For a rational Bézier piece with homogeneous control points `(w_i P_i, w_i)` and a query
//! `q`, write `R(t) = Σ B_i^p(t) w_i (P_i − q)` and `W(t) = Σ B_i^p(t) w_i`, so that
//! `C(t) − q = R/W`. Then `|C − q|² = S/W²` with `S = R·R` (a Bernstein polynomial of degree
//! 2p, coefficients by the product rule of Bernstein polynomials, Farouki & Rajan 1988), and
//! `d/dt |C − q|² / 2 = (C − q)·C' = N / W³` with
//!
//! ```text
//! N = ½ W S' − W' S        (degree 3p − 1; N = ½ S' for a polynomial piece)
//! ```
//!
//! With positive weights `W > 0`, so the sign of the distance's derivative is the sign of
//! `N`, whose Bernstein coefficients are exact functions of the data. By the variation
//! diminishing property (Descartes' rule for the Bernstein basis) the number of roots of `N`
//! in an interval is at most the number of sign changes of its coefficients there:
//!
//! - no sign change: the distance is monotone, its minimum is at an interval end (the end
//!   values of `S` and `W` are their end coefficients, so the candidate costs nothing);
//! - one change from − to +: exactly one stationary point, a minimum: it is found by a
//!   bracketed Newton iteration on `N` (bisection safeguard) to 1e-15 of the parameter;
//! - one change from + to −: one maximum, the minimum is at an end;
//! - otherwise the interval is halved by de Casteljau's algorithm on the coefficients of `N`,
//!   `S` and `W` and each half is searched.
//!
//! Every interval is first pruned by the lower bound `min_k S_k / (max_k W_k)²` of the squared
//! distance (convex hull of the Bernstein coefficients) against the best distance found, and
//! settled by its nearer end when `max_k S_k / (min_k W_k)²` shows its distances span less
//! than [`CERT_TOL`] = 1e-10 mm: the answer is certified to be within 1e-10 mm of the global
//! minimum distance. An
//! identically zero `N` (the query at the centre of a circular arc) makes every point of the
//! interval a closest point. An interval still ambiguous at [`MAX_SPLIT_DEPTH`] halvings
//! (width 2⁻⁴⁰ of the piece: roots closer than that, i.e. a tangential double root within
//! round-off) is solved by the bracketed iteration and its ends, and the answer's
//! `certified` flag is cleared. Nothing allocates; degree ≤ [`MAX_CERT_DEGREE`].
//!
//! The products do not depend on the query but for `q` entering linearly: they are
//! precomputed per piece ([`PiecePolys`]), so a query forms `S` and `N` in O(D p); then
//! O(p²) per halving and a few Newton steps on `N` for the root. The tree visits the pieces
//! whose box is nearer than the best distance, O(log n) for a query near one piece.

use nalgebra::SVector;

use super::bezier::BezierSegment;

/// Largest degree handled (fixed-size coefficient arrays: `N` has 3p coefficients).
pub(crate) const MAX_CERT_DEGREE: usize = 7;
const NC: usize = 3 * MAX_CERT_DEGREE + 1;

/// Halvings of a piece's parameter interval before an ambiguous interval is solved without
/// a certificate: 2⁻⁴⁰ ≈ 1e-12 of the piece, below which two stationary points of the
/// distance cannot be told apart in double precision.
pub(crate) const MAX_SPLIT_DEPTH: usize = 40;

/// Relative size of `N`'s coefficients below which the distance is constant over an
/// interval (|N| ≤ 1e-13 × |S'|-scale: round-off of the products).
const FLAT_REL: f64 = 1e-13;

/// Root of `N` to this fraction of the interval: 1e-14 of a 100 mm piece is 1e-12 mm along
/// the curve, and the distance, stationary there, changes by its square.
const ROOT_TOL: f64 = 1e-14;

/// Distance tolerance of the certificate, mm: an interval is dropped when nothing in it can
/// be nearer than the best found by more than this, and settled by its nearer end when its
/// distances span less than this (this bounds the search near a centre of curvature, where
/// the distance is almost constant over a whole piece). Far below any machining tolerance
/// and above the round-off of the Bernstein products on parts of a few hundred mm.
pub(crate) const CERT_TOL: f64 = 1e-10;

/// Bracketed root iterations on `N` (each halves the bracket at least once per two steps).
const ROOT_ITER: usize = 80;

const fn binom_table() -> [[f64; NC + 1]; NC + 1] {
    let mut t = [[0.0; NC + 1]; NC + 1];
    let mut n = 0;
    while n <= NC {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    t
}

static BINOM: [[f64; NC + 1]; NC + 1] = binom_table();

/// `scale · Σ_k c_k B_{k,n}(t)` for `t ∈ [0, 1]` by Horner's scheme on `c_k C(n, k)` in the
/// ratio `t / (1 − t)` (for t ≤ ½) or `(1 − t) / t` (for t > ½), times the power of the
/// larger of `t`, `1 − t`: O(n), every ratio ≤ 1.
#[inline]
fn bernstein_horner(c: &[f64], n: usize, t: f64, scale: f64) -> f64 {
    let s = 1.0 - t;
    let binom = &BINOM[n];
    if t <= 0.5 {
        let r = t / s;
        let mut acc = c[n] * binom[n];
        for k in (0..n).rev() {
            acc = acc * r + c[k] * binom[k];
        }
        scale * acc * s.powi(n as i32)
    } else {
        let r = s / t;
        let mut acc = c[0] * binom[0];
        for k in 1..=n {
            acc = acc * r + c[k] * binom[k];
        }
        scale * acc * t.powi(n as i32)
    }
}

/// A Bernstein polynomial on a sub-interval, coefficients `c[0..=deg]`.
#[derive(Debug, Clone, Copy)]
struct Poly {
    c: [f64; NC],
    deg: usize,
}

impl Poly {
    fn zero(deg: usize) -> Self {
        Poly { c: [0.0; NC], deg }
    }

    /// Product in the Bernstein basis.
    fn mul(&self, o: &Poly) -> Poly {
        let (m, n) = (self.deg, o.deg);
        let mut r = Poly::zero(m + n);
        for i in 0..=m {
            let a = self.c[i] * BINOM[m][i];
            if a == 0.0 {
                continue;
            }
            for j in 0..=n {
                r.c[i + j] += a * o.c[j] * BINOM[n][j];
            }
        }
        for k in 0..=m + n {
            r.c[k] /= BINOM[m + n][k];
        }
        r
    }

    /// Derivative with respect to the local parameter of the current interval.
    fn deriv(&self) -> Poly {
        let n = self.deg;
        let mut r = Poly::zero(n.saturating_sub(1));
        for k in 0..n {
            r.c[k] = n as f64 * (self.c[k + 1] - self.c[k]);
        }
        r
    }

    fn sub(&self, o: &Poly) -> Poly {
        let mut r = *self;
        for k in 0..=self.deg {
            r.c[k] -= o.c[k];
        }
        r
    }

    fn scale(&self, s: f64) -> Poly {
        let mut r = *self;
        for k in 0..=self.deg {
            r.c[k] *= s;
        }
        r
    }

    /// Value at local t ∈ [0, 1]: Horner's scheme in `t / (1 − t)` (or `(1 − t) / t` for
    /// t > ½, so the ratio stays ≤ 1) on the scaled coefficients `c_k C(n, k)`. O(n), no
    /// copy of the coefficients.
    fn eval(&self, t: f64) -> f64 {
        bernstein_horner(&self.c[..=self.deg], self.deg, t, 1.0)
    }

    /// Value and derivative (in the local parameter) at t ∈ [0, 1], both by
    /// [`bernstein_horner`]: `f' = n Σ (c_{k+1} − c_k) B_{k,n−1}`.
    fn eval_with_deriv(&self, t: f64) -> (f64, f64) {
        let n = self.deg;
        if n == 0 {
            return (self.c[0], 0.0);
        }
        let mut d = [0.0; NC];
        for k in 0..n {
            d[k] = self.c[k + 1] - self.c[k];
        }
        (
            bernstein_horner(&self.c[..=n], n, t, 1.0),
            bernstein_horner(&d[..n], n - 1, t, n as f64),
        )
    }

    /// Halves at t = ½ (de Casteljau): (left, right).
    fn halves(&self) -> (Poly, Poly) {
        let n = self.deg;
        let mut l = Poly::zero(n);
        let mut r = Poly::zero(n);
        let mut b = self.c;
        l.c[0] = b[0];
        r.c[n] = b[n];
        for k in 1..=n {
            for i in 0..=n - k {
                b[i] = 0.5 * (b[i] + b[i + 1]);
            }
            l.c[k] = b[0];
            r.c[n - k] = b[n - k];
        }
        (l, r)
    }

    fn min(&self) -> f64 {
        self.c[..=self.deg]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    fn max(&self) -> f64 {
        self.c[..=self.deg]
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The best point of a search: local parameter on the piece, squared distance, certified.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Best {
    pub t: f64,
    pub piece: usize,
    pub d2: f64,
    pub certified: bool,
}

/// The query-independent Bernstein polynomials of one piece, so that a query only forms
/// linear combinations (no polynomial products per query). With the control points shifted
/// by the piece's centre `c` (homogeneous `X_d = w (P_d − c_d)`), `q' = q − c` and
/// `R_d = X_d − q'_d W`:
///
/// ```text
/// S = Σ R_d² = A − 2 Σ q'_d B_d + |q'|² C     A = Σ X_d²,  B_d = X_d W,  C = W²
/// N = ½ W S' − W' S = N(A) − 2 Σ q'_d N(B_d) + |q'|² N(C)     (N linear in S)
/// ```
///
/// Shifting by the centre keeps the terms of the sum of the order of the piece's size, so
/// the round-off of the expansion stays that of the direct products (within a small factor).
#[derive(Debug, Clone)]
pub(crate) struct PiecePolys<const D: usize> {
    centre: SVector<f64, D>,
    w: Poly,
    sa: Poly,
    sb: [Poly; D],
    sc: Poly,
    na: Poly,
    nb: [Poly; D],
    nc: Poly,
}

impl<const D: usize> PiecePolys<D> {
    /// Precomputes the polynomials of `seg` (degree ≤ [`MAX_CERT_DEGREE`]). O(D p²).
    pub(crate) fn new(seg: &BezierSegment<D>) -> Self {
        let p = seg.p;
        let mut centre = SVector::<f64, D>::zeros();
        let (mut lo, mut hi) = (
            SVector::<f64, D>::repeat(f64::INFINITY),
            SVector::<f64, D>::repeat(f64::NEG_INFINITY),
        );
        for pt in seg.points() {
            lo = lo.inf(&pt);
            hi = hi.sup(&pt);
        }
        if lo.iter().chain(hi.iter()).all(|x| x.is_finite()) {
            centre = (lo + hi) * 0.5;
        }
        let mut w = Poly::zero(p);
        for (i, (_, wi)) in seg.pw.iter().enumerate() {
            w.c[i] = *wi;
        }
        let x: [Poly; D] = std::array::from_fn(|d| {
            let mut x = Poly::zero(p);
            for (i, (pw, wi)) in seg.pw.iter().enumerate() {
                x.c[i] = pw[d] - centre[d] * wi;
            }
            x
        });
        let mut sa = Poly::zero(2 * p);
        for xd in &x {
            let sq = xd.mul(xd);
            for k in 0..=2 * p {
                sa.c[k] += sq.c[k];
            }
        }
        let sb: [Poly; D] = std::array::from_fn(|d| x[d].mul(&w));
        let sc = w.mul(&w);
        let rational = seg.rational;
        let nlin = |t: &Poly| -> Poly {
            if rational {
                w.mul(&t.deriv()).scale(0.5).sub(&w.deriv().mul(t))
            } else {
                t.deriv().scale(0.5)
            }
        };
        PiecePolys {
            centre,
            na: nlin(&sa),
            nb: std::array::from_fn(|d| nlin(&sb[d])),
            nc: nlin(&sc),
            w,
            sa,
            sb,
            sc,
        }
    }
}

/// Searches piece `piece` (precomputed polynomials `pre`) for a point nearer than `best`
/// (see module docs). O(D p) to form `S` and `N`, then the root isolation.
pub(crate) fn search_piece<const D: usize>(
    pre: &PiecePolys<D>,
    piece: usize,
    q: &SVector<f64, D>,
    best: &mut Best,
) {
    let qc = q - pre.centre;
    let q2 = qc.norm_squared();
    let mut s = pre.sa;
    for k in 0..=s.deg {
        let mut acc = s.c[k] + q2 * pre.sc.c[k];
        for d in 0..D {
            acc -= 2.0 * qc[d] * pre.sb[d].c[k];
        }
        s.c[k] = acc;
    }
    let mut n = pre.na;
    for k in 0..=n.deg {
        let mut acc = n.c[k] + q2 * pre.nc.c[k];
        for d in 0..D {
            acc -= 2.0 * qc[d] * pre.nb[d].c[k];
        }
        n.c[k] = acc;
    }
    let flat = FLAT_REL * (s.max().abs() * s.deg as f64).max(f64::MIN_POSITIVE);
    isolate(&n, &s, &pre.w, 0.0, 1.0, 0, flat, piece, best);
}

#[allow(clippy::too_many_arguments)]
fn isolate(
    n: &Poly,
    s: &Poly,
    w: &Poly,
    a: f64,
    b: f64,
    depth: usize,
    flat: f64,
    piece: usize,
    best: &mut Best,
) {
    let (wmin, wmax) = (w.min(), w.max());
    let lb = s.min().max(0.0) / (wmax * wmax);
    // Nothing here can be nearer than the best by more than the tolerance.
    if lb.sqrt() >= best.d2.sqrt() - CERT_TOL {
        return;
    }
    let consider = |t: f64, d2: f64, cert: bool, best: &mut Best| {
        if d2 < best.d2 {
            *best = Best {
                t,
                piece,
                d2,
                certified: best.certified && cert,
            };
        } else if !cert {
            best.certified = false;
        }
    };
    let end0 = s.c[0] / (w.c[0] * w.c[0]);
    let end1 = s.c[s.deg] / (w.c[w.deg] * w.c[w.deg]);
    // Every point of the interval is within the tolerance of the nearer end: done.
    let ub = s.max() / (wmin * wmin);
    if ub.sqrt() - lb.sqrt() <= CERT_TOL {
        let (t, d2) = if end0 <= end1 { (a, end0) } else { (b, end1) };
        consider(t, d2, true, best);
        return;
    }
    let (nmin, nmax) = (n.min(), n.max());
    if nmax.abs().max(nmin.abs()) <= flat {
        // Constant distance on the interval.
        consider(a, end0, true, best);
        return;
    }
    if nmin >= 0.0 {
        consider(a, end0, true, best);
        return;
    }
    if nmax <= 0.0 {
        consider(b, end1, true, best);
        return;
    }
    // Sign changes, zeros skipped.
    let mut changes = 0;
    let mut last = 0.0;
    let mut first_neg = false;
    for &c in &n.c[..=n.deg] {
        if c == 0.0 {
            continue;
        }
        if last == 0.0 {
            first_neg = c < 0.0;
        } else if (c < 0.0) != (last < 0.0) {
            changes += 1;
        }
        last = c;
    }
    if changes == 1 && !first_neg {
        // One maximum: the minimum is at an end.
        consider(a, end0, true, best);
        consider(b, end1, true, best);
        return;
    }
    if changes == 1 || depth >= MAX_SPLIT_DEPTH {
        let cert = changes == 1;
        if let Some(t) = root(n) {
            let d2 = s.eval(t) / w.eval(t).powi(2);
            consider(a + (b - a) * t, d2, cert, best);
        }
        consider(a, end0, cert, best);
        consider(b, end1, cert, best);
        return;
    }
    let (nl, nr) = n.halves();
    let (sl, sr) = s.halves();
    let (wl, wr) = w.halves();
    let m = 0.5 * (a + b);
    // Nearer half first (smaller lower bound), so the other is pruned more often.
    let lbl = sl.min() / wl.max().powi(2);
    let lbr = sr.min() / wr.max().powi(2);
    if lbl <= lbr {
        isolate(&nl, &sl, &wl, a, m, depth + 1, flat, piece, best);
        isolate(&nr, &sr, &wr, m, b, depth + 1, flat, piece, best);
    } else {
        isolate(&nr, &sr, &wr, m, b, depth + 1, flat, piece, best);
        isolate(&nl, &sl, &wl, a, m, depth + 1, flat, piece, best);
    }
}

/// A root of `n` on [0, 1] where it goes from negative to positive, by Newton steps kept
/// inside a shrinking bracket; a step that leaves the bracket is replaced by a false-position
/// step (every third such step by bisection, so the bracket shrinks geometrically). Starts at
/// the false-position point of the ends. Stops when the Newton correction or the bracket is
/// below [`ROOT_TOL`]. `None` when the ends do not go from − to +.
fn root(n: &Poly) -> Option<f64> {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let (mut flo, mut fhi) = (n.c[0], n.c[n.deg]);
    if flo > 0.0 || fhi < 0.0 {
        // The ends do not bracket (several roots): the interior minimum of the coefficients.
        return None;
    }
    if flo == 0.0 {
        return Some(0.0);
    }
    if fhi == 0.0 {
        return Some(1.0);
    }
    let mut t = flo / (flo - fhi);
    let mut fallbacks = 0usize;
    for _ in 0..ROOT_ITER {
        let (f, df) = n.eval_with_deriv(t);
        if f == 0.0 {
            return Some(t);
        }
        if f < 0.0 {
            lo = t;
            flo = f;
        } else {
            hi = t;
            fhi = f;
        }
        let step = f / df;
        if df > 0.0 && step.abs() <= ROOT_TOL {
            // Converged: the correction is below the tolerance (it may round to `t`).
            return Some((t - step).clamp(lo, hi));
        }
        let mut next = if df > 0.0 { t - step } else { f64::NAN };
        if !(next > lo && next < hi) {
            fallbacks += 1;
            next = if fallbacks.is_multiple_of(3) {
                0.5 * (lo + hi)
            } else {
                lo - flo * (hi - lo) / (fhi - flo)
            };
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
        }
        if hi - lo <= ROOT_TOL {
            return Some(next);
        }
        t = next;
    }
    Some(0.5 * (lo + hi))
}

/// Axis-aligned box of a piece's Euclidean control points (contains the piece: positive
/// weights make it a convex combination of them).
pub(crate) fn control_box<const D: usize>(
    seg: &BezierSegment<D>,
) -> (SVector<f64, D>, SVector<f64, D>) {
    let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
    let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
    for p in seg.points() {
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    let pad = SVector::<f64, D>::from_fn(|d, _| 1e-12 * (lo[d].abs() + hi[d].abs()));
    (lo - pad, hi + pad)
}

/// A node of the bounding-volume tree over a curve's pieces (pieces `lo..hi`, contiguous
/// along the curve, so the boxes of ranges stay tight).
#[derive(Debug, Clone)]
pub(crate) struct Node<const D: usize> {
    pub min: SVector<f64, D>,
    pub max: SVector<f64, D>,
    pub lo: usize,
    /// Children (node indices), none for a leaf (one piece).
    pub kids: Option<(usize, usize)>,
}

/// Builds the tree over piece boxes; node 0 is the root.
pub(crate) fn build_tree<const D: usize>(
    boxes: &[(SVector<f64, D>, SVector<f64, D>)],
) -> Vec<Node<D>> {
    let mut nodes = Vec::with_capacity(2 * boxes.len());
    fn rec<const D: usize>(
        boxes: &[(SVector<f64, D>, SVector<f64, D>)],
        lo: usize,
        hi: usize,
        nodes: &mut Vec<Node<D>>,
    ) -> usize {
        let mut min = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut max = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for b in &boxes[lo..hi] {
            min = min.inf(&b.0);
            max = max.sup(&b.1);
        }
        let id = nodes.len();
        nodes.push(Node {
            min,
            max,
            lo,
            kids: None,
        });
        if hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            let l = rec(boxes, lo, mid, nodes);
            let r = rec(boxes, mid, hi, nodes);
            nodes[id].kids = Some((l, r));
        }
        id
    }
    if !boxes.is_empty() {
        rec(boxes, 0, boxes.len(), &mut nodes);
    }
    nodes
}

/// Squared distance from `q` to a box (0 inside).
#[inline]
pub(crate) fn box_d2<const D: usize>(
    min: &SVector<f64, D>,
    max: &SVector<f64, D>,
    q: &SVector<f64, D>,
) -> f64 {
    let mut s = 0.0;
    for d in 0..D {
        let x = (min[d] - q[d]).max(q[d] - max[d]).max(0.0);
        s += x * x;
    }
    s
}
