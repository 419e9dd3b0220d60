//! Decomposition of curves and surfaces into Bézier pieces (NURBS Book §5.4; implemented
//! with knot refinement A5.4 raising every interior knot to multiplicity `p`). Each piece is
//! returned as a NURBS entity with clamped single-span knot vectors that keep the original
//! parameter range, so `piece.point(u) == original.point(u)` on that range.

use crate::curve::NurbsCurve;
use crate::error::{Direction, NurbsError};
use crate::homogeneous::HSpline;
use crate::knots::KnotVector;
use crate::surface::NurbsSurface;

/// One Bézier patch of a surface decomposition.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierPatch {
    /// Index of the knot span along `u` (0-based among the non-empty spans).
    pub span_u: usize,
    /// Index of the knot span along `v`.
    pub span_v: usize,
    /// Parameter range `[u0, u1]` of the patch in the original surface.
    pub u_range: (f64, f64),
    /// Parameter range `[v0, v1]`.
    pub v_range: (f64, f64),
    /// The patch: degrees `(p, q)`, `(p+1) × (q+1)` control points, knots
    /// `{u0^(p+1), u1^(p+1)}` × `{v0^(q+1), v1^(q+1)}`.
    pub surface: NurbsSurface,
}

fn bezier_knots(p: usize, a: f64, b: f64) -> Result<KnotVector, NurbsError> {
    let mut k = vec![a; p + 1];
    k.extend(std::iter::repeat_n(b, p + 1));
    KnotVector::new(p, k)
}

impl<const D: usize> NurbsCurve<D> {
    /// Splits the curve into its Bézier segments, one per non-empty knot span, in order
    /// (O(n p D)). Segment `k` has domain `[t_k, t_{k+1}]` of the original curve.
    pub fn bezier_segments(&self) -> Result<Vec<NurbsCurve<D>>, NurbsError> {
        let p = self.degree();
        let (h, breaks) = self.to_hspline().clamped().to_bezier();
        let dim = h.dim;
        let mut out = Vec::with_capacity(breaks.len() - 1);
        for (k, w) in breaks.windows(2).enumerate() {
            let pts = &h.pts[k * p * dim..(k * p + p + 1) * dim];
            let kv = bezier_knots(p, w[0], w[1])?;
            out.push(NurbsCurve::from_homogeneous(kv, pts, self.is_rational())?);
        }
        Ok(out)
    }
}

impl NurbsSurface {
    /// Splits the surface into its Bézier patches, one per pair of non-empty knot spans,
    /// ordered `span_u`-major (O(n_u n_v (p + q))). Used for global closest-point candidate
    /// selection (convex-hull bounds per patch).
    pub fn bezier_patches(&self) -> Result<Vec<BezierPatch>, NurbsError> {
        let (p, q) = (self.degree_u(), self.degree_v());
        let mut breaks_u = Vec::new();
        let mut breaks_v = Vec::new();
        let refined = self
            .map_lines(Direction::U, |h: &HSpline| h.clamped().to_bezier().0)?
            .map_lines(Direction::V, |h: &HSpline| h.clamped().to_bezier().0)?;
        for (kv, out) in [
            (self.knots_u(), &mut breaks_u),
            (self.knots_v(), &mut breaks_v),
        ] {
            let (a, b) = kv.domain();
            out.push(a);
            out.extend(kv.interior_breaks().iter().map(|(x, _)| *x));
            out.push(b);
        }
        let nv = refined.n_v();
        let mut patches = Vec::with_capacity((breaks_u.len() - 1) * (breaks_v.len() - 1));
        for (iu, wu) in breaks_u.windows(2).enumerate() {
            for (iv, wv) in breaks_v.windows(2).enumerate() {
                let mut ctrl = Vec::with_capacity((p + 1) * (q + 1));
                let mut weights = refined
                    .weights()
                    .map(|_| Vec::with_capacity((p + 1) * (q + 1)));
                for i in iu * p..=iu * p + p {
                    for j in iv * q..=iv * q + q {
                        ctrl.push(refined.control_points()[i * nv + j]);
                        if let Some(w) = weights.as_mut() {
                            w.push(refined.weight(i, j));
                        }
                    }
                }
                let surface = NurbsSurface::from_flat(
                    bezier_knots(p, wu[0], wu[1])?,
                    bezier_knots(q, wv[0], wv[1])?,
                    ctrl,
                    weights,
                )?;
                patches.push(BezierPatch {
                    span_u: iu,
                    span_v: iv,
                    u_range: (wu[0], wu[1]),
                    v_range: (wv[0], wv[1]),
                    surface,
                });
            }
        }
        Ok(patches)
    }
}
