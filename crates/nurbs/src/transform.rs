//! Rigid motions of curves and surfaces. NURBS are affinely invariant: moving the control
//! points (weights unchanged) moves the geometry exactly. Impeller blades are N-fold
//! copies rotated about the +Z axis.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::curve::NurbsCurve;
use crate::surface::NurbsSurface;

fn rotation_z(angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle),
    )
}

impl NurbsCurve<3> {
    /// The curve moved by the rigid motion `iso` (control points transformed, weights and
    /// knots kept; exact, O(n)).
    pub fn transformed(&self, iso: &Isometry3<f64>) -> Self {
        self.map_control_points(|p| iso.transform_point(&p.into()).coords)
    }

    /// The curve rotated by `angle` radians about the +Z axis (right-handed).
    pub fn rotated_about_z(&self, angle: f64) -> Self {
        self.transformed(&rotation_z(angle))
    }
}

impl NurbsSurface {
    /// The surface moved by the rigid motion `iso` (exact, O(n_u n_v)).
    pub fn transformed(&self, iso: &Isometry3<f64>) -> Self {
        self.map_control_points(|p| iso.transform_point(&p.into()).coords)
    }

    /// The surface rotated by `angle` radians about the +Z axis (right-handed): blade `k`
    /// of an `N`-blade impeller is `blade.rotated_about_z(2π k / N)`.
    pub fn rotated_about_z(&self, angle: f64) -> Self {
        self.transformed(&rotation_z(angle))
    }
}
