//! Sign certificates of the distance gradient on a (rational) Bézier leaf, from Bernstein
//! coefficients.
//!
//! For a leaf with homogeneous control points `(w P, w)`, shift the points by the leaf's
//! centre `c` (`X = w (P − c)`, `q' = q − c`), so that `S − q = (X − q' W) / W` with
//! `W = Σ B w > 0`. The tangent is `S_u = T_u / W²` with `T_u = X_u W − X W_u` (for a
//! polynomial leaf `W ≡ 1` and `T_u = X_u`). Hence
//!
//! ```text
//! sign (S − q)·S_u = sign [ X·T_u − q'·(W T_u) ] = sign [ A_u − q'·E_u ]
//! ```
//!
//! where `A_u = X·T_u` (scalar) and `E_u = W T_u` (vector) are tensor-product Bernstein
//! polynomials that do not depend on the query (degree `(2p − 1, 2q)` for a polynomial leaf,
//! `(3p − 1, 3q)` for a rational one; products by the Bernstein product rule, positive
//! constant factors dropped). A query forms the coefficients `A_u − q'·E_u` (3 multiply-adds
//! each); when all of them are positive (negative), `(S − q)·S_u` is positive (negative) on
//! the whole leaf by the convex-hull property of the Bernstein basis, so the distance is
//! strictly increasing (decreasing) in `u` across the leaf and its minimum lies on the edge
//! `u = u0` (`u = u1`). The same for `v`. This is exact at the resolution of the leaf (the
//! coefficients converge to the values quadratically under subdivision), far tighter than
//! the tangent-cone test, and rigorous for rational leaves with positive weights.
//!
//! A coefficient counts as signed only beyond a margin of `1e-12` of the magnitudes that
//! were summed (round-off of the products and of the query's combination).
//! Cost per leaf and direction: `(2p)(2q + 1)` (polynomial) coefficients of 4 flops each;
//! no allocation.

use nalgebra::Vector3;

use crate::closest::bezier::BezierPatch;

/// Relative margin of a coefficient's sign.
const SIGN_MARGIN: f64 = 1e-12;

/// The query-independent polynomials of one direction: `A − q'·E` coefficients.
#[derive(Debug, Clone)]
struct Direction {
    a: Vec<f64>,
    e: Vec<Vector3<f64>>,
    /// Largest `|A_k|` and `|E_k|`, for the round-off margin.
    a_max: f64,
    e_max: f64,
}

impl Direction {
    /// +1 if every coefficient of `A − q'·E` is positive, −1 if every one is negative, 0
    /// otherwise.
    #[inline]
    fn sign(&self, qc: &Vector3<f64>) -> i8 {
        let margin = SIGN_MARGIN * (self.a_max + qc.norm() * self.e_max);
        let (mut pos, mut neg) = (true, true);
        for (a, e) in self.a.iter().zip(&self.e) {
            let g = a - qc.dot(e);
            pos &= g > margin;
            neg &= g < -margin;
            if !pos && !neg {
                return 0;
            }
        }
        if pos {
            1
        } else if neg {
            -1
        } else {
            0
        }
    }
}

/// Gradient-sign certificate of one leaf (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct GradSigns {
    centre: Vector3<f64>,
    u: Direction,
    v: Direction,
}

/// A tensor-product Bernstein polynomial: degrees `(m, n)`, coefficients `c[i (n+1) + j]`.
#[derive(Debug, Clone)]
struct TP<T> {
    m: usize,
    n: usize,
    c: Vec<T>,
}

fn binom(n: usize, k: usize) -> f64 {
    let mut r = 1.0;
    for i in 0..k {
        r = r * (n - i) as f64 / (i + 1) as f64;
    }
    r
}

/// Binomial coefficients `C(n, k)`, `k = 0..=n`.
fn binom_row(n: usize) -> Vec<f64> {
    (0..=n).map(|k| binom(n, k)).collect()
}

/// Bernstein product `a ⊗ b` with the coefficient product `f` (scalar·vector, dot, ...).
/// O((a.m + 1)(a.n + 1)(b.m + 1)(b.n + 1)).
fn product<A: Copy, B: Copy, C: Copy + std::ops::AddAssign + std::ops::Mul<f64, Output = C>>(
    a: &TP<A>,
    b: &TP<B>,
    zero: C,
    f: impl Fn(A, B) -> C,
) -> TP<C> {
    let (m, n) = (a.m + b.m, a.n + b.n);
    let (bam, ban, bbm, bbn) = (
        binom_row(a.m),
        binom_row(a.n),
        binom_row(b.m),
        binom_row(b.n),
    );
    let (bm, bn) = (binom_row(m), binom_row(n));
    let mut c = vec![zero; (m + 1) * (n + 1)];
    for i1 in 0..=a.m {
        for j1 in 0..=a.n {
            let x = a.c[i1 * (a.n + 1) + j1];
            let s1 = bam[i1] * ban[j1];
            for i2 in 0..=b.m {
                for j2 in 0..=b.n {
                    let s = s1 * bbm[i2] * bbn[j2];
                    c[(i1 + i2) * (n + 1) + j1 + j2] += f(x, b.c[i2 * (b.n + 1) + j2]) * s;
                }
            }
        }
    }
    for k in 0..=m {
        for l in 0..=n {
            c[k * (n + 1) + l] = c[k * (n + 1) + l] * (1.0 / (bm[k] * bn[l]));
        }
    }
    TP { m, n, c }
}

/// Differences along u (`X_{i+1,j} − X_ij`, degree `(m − 1, n)`; the factor `m` dropped).
fn diff_u<T: Copy + std::ops::Sub<Output = T>>(x: &TP<T>) -> TP<T> {
    let mut c = Vec::with_capacity(x.m * (x.n + 1));
    for i in 0..x.m {
        for j in 0..=x.n {
            c.push(x.c[(i + 1) * (x.n + 1) + j] - x.c[i * (x.n + 1) + j]);
        }
    }
    TP {
        m: x.m - 1,
        n: x.n,
        c,
    }
}

fn swap_uv<T: Copy>(x: &TP<T>) -> TP<T> {
    let mut c = Vec::with_capacity(x.c.len());
    for j in 0..=x.n {
        for i in 0..=x.m {
            c.push(x.c[i * (x.n + 1) + j]);
        }
    }
    TP { m: x.n, n: x.m, c }
}

/// `T = X_u W − X W_u` of a rational net (`x` homogeneous vector part, `w` weights).
fn rational_tangent(x: &TP<Vector3<f64>>, w: &TP<f64>) -> TP<Vector3<f64>> {
    let t1 = product(&diff_u(x), w, Vector3::zeros(), |a, b| a * b);
    let t2 = product(x, &diff_u(w), Vector3::zeros(), |a, b| a * b);
    TP {
        m: t1.m,
        n: t1.n,
        c: t1.c.iter().zip(&t2.c).map(|(a, b)| a - b).collect(),
    }
}

/// The homogeneous net of a leaf as (vector part, weights), the vector part shifted by
/// `centre`.
fn nets(sub: &BezierPatch, centre: &Vector3<f64>) -> (TP<Vector3<f64>>, TP<f64>) {
    (
        TP {
            m: sub.p,
            n: sub.q,
            c: sub
                .pw
                .iter()
                .map(|c| Vector3::new(c[0], c[1], c[2]) - centre * c[3])
                .collect(),
        },
        TP {
            m: sub.p,
            n: sub.q,
            c: sub.pw.iter().map(|c| c[3]).collect(),
        },
    )
}

/// Bernstein coefficients of `X_u W − X W_u` and `X_v W − X W_v` of a rational leaf: every
/// tangent `S_u = (X_u W − X W_u) / W²` (resp. `S_v`) is a positive combination of them, so
/// a cone containing them contains every tangent direction of the leaf. Empty for degree 0.
pub(crate) fn rational_tangent_coefficients(
    sub: &BezierPatch,
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    if sub.p == 0 || sub.q == 0 {
        return (Vec::new(), Vec::new());
    }
    let (x, w) = nets(sub, &Vector3::zeros());
    (
        rational_tangent(&x, &w).c,
        swap_uv(&rational_tangent(&swap_uv(&x), &swap_uv(&w))).c,
    )
}

impl GradSigns {
    /// The certificate of leaf `sub` (degrees ≥ 1). O((p q)²) products for polynomial
    /// leaves, O((p q)² · 4) for rational ones.
    pub(crate) fn new(sub: &BezierPatch) -> Option<GradSigns> {
        if sub.p == 0 || sub.q == 0 {
            return None;
        }
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in sub.points() {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        let centre = (lo + hi) * 0.5;
        if !centre.iter().all(|c| c.is_finite()) {
            return None;
        }
        let (x, w) = nets(sub, &centre);
        let rational = sub.rational;
        let direction = |x: &TP<Vector3<f64>>, w: &TP<f64>| -> Direction {
            let (a, e) = if rational {
                // T = X_u W − X W_u, A = X·T, E = W T.
                let t = rational_tangent(x, w);
                (
                    product(x, &t, 0.0, |a, b| a.dot(&b)),
                    product(w, &t, Vector3::zeros(), |a, b| b * a),
                )
            } else {
                let t = diff_u(x);
                (
                    product(x, &t, 0.0, |a, b| a.dot(&b)),
                    product(w, &t, Vector3::zeros(), |a, b| b * a),
                )
            };
            Direction {
                a_max: a.c.iter().fold(0.0, |m, v| m.max(v.abs())),
                e_max: e.c.iter().fold(0.0, |m, v| m.max(v.norm())),
                a: a.c,
                e: e.c,
            }
        };
        let u = direction(&x, &w);
        // The v direction is the u direction of the transposed net.
        let v = direction(&swap_uv(&x), &swap_uv(&w));
        Some(GradSigns { centre, u, v })
    }

    /// Sign of `(S − q)·S_u` (`dir = 0`) or `(S − q)·S_v` (`dir = 1`) over the leaf.
    #[inline]
    pub(crate) fn sign(&self, dir: usize, q: &Vector3<f64>) -> i8 {
        let qc = q - self.centre;
        if dir == 0 {
            self.u.sign(&qc)
        } else {
            self.v.sign(&qc)
        }
    }
}
