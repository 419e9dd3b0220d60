//! Global closest points on curves and surfaces.
//!
//! * [`SurfaceProjector`] — precomputed query structure for a [`crate::NurbsSurface`]; global
//!   minimum with boundary handling and optional warm start.
//! * [`CurveProjector`] — the same for a [`crate::NurbsCurve`] in any dimension.
//! * [`PointQuery`] — the point-query vocabulary (closest point, signed distance, warm-start
//!   hint, certified flag) shared with the other crates' shapes.
//! * [`closest_point_on_surface`], [`closest_point_on_curve`] — one-off conveniences that
//!   build the projector and answer one query.
//! * [`local_closest_point`] — bound-constrained Newton from a known start (local, not
//!   certified), for callers that already hold a good start.

pub(crate) mod bezier;
mod curve;
mod curve_cert;
pub(crate) mod decompose;
mod local;
mod newton;
mod query;
mod surface;

/// Bounding volumes shared with the projection module.
pub(crate) mod surface_bounds {
    pub(crate) use super::surface::Obb;
}

pub use curve::{closest_point_on_curve, CurvePoint, CurveProjector};
pub use local::local_closest_point;
pub use query::{PointProjection, PointQuery};
pub use surface::{SurfacePoint, SurfaceProjector};

pub(crate) use decompose::{decompose_curve, decompose_surface};

use nalgebra::Vector3;

use crate::NurbsSurface;

/// Global closest point of `surface` to `q` (builds a [`SurfaceProjector`]; for more than a
/// few queries on one surface, build the projector once and reuse it).
pub fn closest_point_on_surface(surface: &NurbsSurface, q: &Vector3<f64>) -> SurfacePoint {
    SurfaceProjector::new(surface).closest_point(q)
}

/// A wavy bicubic test surface: 8 × 8 control points `(x, y, a·sin(x/wx)·cos(y/wy))` with
/// `x, y = step·(0..8)` (mm), clamped uniform knots, unit weights.
#[cfg(test)]
pub(crate) fn wavy_test_surface(step: f64, a: f64, wx: f64, wy: f64) -> NurbsSurface {
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..8)
        .map(|i| {
            (0..8)
                .map(|j| {
                    let (x, y) = (step * i as f64, step * j as f64);
                    Vector3::new(x, y, a * (x / wx).sin() * (y / wy).cos())
                })
                .collect()
        })
        .collect();
    let knots = crate::KnotVector::clamped_uniform(3, 8)
        .unwrap()
        .knots()
        .to_vec();
    NurbsSurface::new(3, 3, knots.clone(), knots, ctrl, None).unwrap()
}
