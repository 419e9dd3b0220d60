//! Ruled surfaces between two curves, after making them compatible (same degree, same
//! domain, same knot vector) — NURBS Book §8.4 with A5.9 degree elevation and A5.4 knot
//! refinement.

use crate::curve::NurbsCurve;
use crate::error::NurbsError;
use crate::homogeneous::HSpline;
use crate::knots::KnotVector;
use crate::surface::NurbsSurface;

/// Homogeneous (stride 4) clamped polygon of `c` on `[0, 1]` at degree `p`.
fn prepared(c: &NurbsCurve<3>, p: usize) -> Result<HSpline, NurbsError> {
    let c = c.clamped()?.reparametrize(0.0, 1.0)?;
    let w = c
        .weights()
        .map_or_else(|| vec![1.0; c.control_points().len()], <[f64]>::to_vec);
    let unit = NurbsCurve::<3>::new(
        c.degree(),
        c.knots().knots().to_vec(),
        c.control_points().to_vec(),
        Some(w),
    )?;
    Ok(unit.to_hspline().elevate(p - c.degree()))
}

/// Knots of `target` (distinct value, multiplicity) missing from `have`.
fn missing(have: &[f64], target: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < target.len() {
        let v = target[i];
        let mut j = i;
        while j < target.len() && target[j] == v {
            j += 1;
        }
        let need = j - i;
        let got = have.iter().filter(|&&k| k == v).count();
        out.extend(std::iter::repeat_n(v, need.saturating_sub(got)));
        i = j;
    }
    out
}

/// Strictly interior knots of a clamped degree-`p` vector.
fn interior(knots: &[f64], p: usize) -> &[f64] {
    &knots[p + 1..knots.len() - p - 1]
}

impl NurbsSurface {
    /// Ruled surface `S(u, v)` whose rulings (`u` fixed, `v ∈ [0, 1]`) are the straight
    /// segments from `c1(u)` to `c2(u)`; both curves are mapped to `u ∈ [0, 1]`.
    ///
    /// Compatibility: both curves are clamped, reparametrised linearly to `[0, 1]`, raised
    /// to the common degree (A5.9) and refined to the union of their knot vectors with the
    /// larger multiplicity of each value (A5.4; knots are merged by exact equality). Degree
    /// in `v` is 1 with knots `{0, 0, 1, 1}`. Exact: `S(u, 0) = c1(u')`, `S(u, 1) = c2(u'')`
    /// to rounding. For rational curves the rulings are straight but the `v` speed along
    /// them is not uniform (weights blend linearly). Cost O((n1 + n2) p t) for the
    /// elevation and refinement.
    pub fn ruled(c1: &NurbsCurve<3>, c2: &NurbsCurve<3>) -> Result<Self, NurbsError> {
        let p = c1.degree().max(c2.degree());
        let h1 = prepared(c1, p)?;
        let h2 = prepared(c2, p)?;
        let h1r = h1.refine(&missing(interior(&h1.knots, p), interior(&h2.knots, p)));
        let h2r = h2.refine(&missing(interior(&h2.knots, p), interior(&h1.knots, p)));
        let n = h1r.n_ctrl();
        let mut ctrl = Vec::with_capacity(2 * n);
        let mut w = Vec::with_capacity(2 * n);
        for (a, b) in h1r.pts.chunks_exact(4).zip(h2r.pts.chunks_exact(4)) {
            for c in [a, b] {
                ctrl.push(nalgebra::Vector3::new(
                    c[0] / c[3],
                    c[1] / c[3],
                    c[2] / c[3],
                ));
                w.push(c[3]);
            }
        }
        let rational = c1.is_rational() || c2.is_rational();
        NurbsSurface::from_flat(
            KnotVector::new(p, h1r.knots)?,
            KnotVector::new(1, vec![0.0, 0.0, 1.0, 1.0])?,
            ctrl,
            rational.then_some(w),
        )
    }
}
