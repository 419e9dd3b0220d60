//! Tilted working planes for 3+2 positioning: the rotation that takes the workpiece frame to a
//! frame whose Z axis is the tool axis, in the two conventions controllers use, and the
//! transformation of points into the tilted frame.
//!
//! - Axis by axis, X then Y about the *rotated* axes (Sinumerik `CYCLE800` mode 57, frame
//!   chaining like `ROT X.. AROT Y..`): `R = Rx(a)·Ry(b)`, so the tilted Z axis is
//!   `R·e_z = (sin b, −sin a cos b, cos a cos b)`; hence `b = asin(u_x)`,
//!   `a = atan2(−u_y, u_z)`.
//! - Spatial angles about the *fixed* axes in the order A, B, C (Heidenhain `PLANE SPATIAL`):
//!   `R = Rz(c)·Ry(b)·Rx(a)` with `c = 0`, tilted Z axis
//!   `(sin b cos a, −sin a, cos b cos a)`; hence `a = −asin(u_y)`, `b = atan2(u_x, u_z)`.
//!
//! - Euler angles Z, X', Z'' (Fanuc `G68.2 I J K`): `R = Rz(a)·Rx(b)` with the third angle 0,
//!   tilted Z axis `(sin a sin b, −cos a sin b, cos b)`; hence `b = acos(u_z)`,
//!   `a = atan2(u_x, −u_y)` (`a = 0` when `u = +Z`).
//!
//! In every case the third angle is 0 and the plane rotates about the active datum, so a
//! point `p` of the workpiece frame has tilted-frame coordinates `Rᵀ·p`. O(1).

use cam_core::{Point3, UnitVector3};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Angles (rad) and rotation of a tilted plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltedPlane {
    /// Rotation about X (rad).
    pub a: f64,
    /// Rotation about Y (rad).
    pub b: f64,
    /// Rotation taking tilted-frame coordinates to workpiece coordinates.
    pub rotation: Matrix3<f64>,
}

impl TiltedPlane {
    /// Axis-by-axis X-then-Y plane (rotated axes) whose Z axis is `u`.
    pub fn axis_by_axis_xy(u: &UnitVector3) -> Self {
        let b = u.x.clamp(-1.0, 1.0).asin();
        let a = (-u.y).atan2(u.z);
        let r = Rotation3::from_axis_angle(&Vector3::x_axis(), a)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), b);
        Self {
            a,
            b,
            rotation: *r.matrix(),
        }
    }

    /// Spatial-angle plane (fixed axes, order A then B) whose Z axis is `u`.
    pub fn spatial_ab(u: &UnitVector3) -> Self {
        let a = -(u.y.clamp(-1.0, 1.0).asin());
        let b = u.x.atan2(u.z);
        let r = Rotation3::from_axis_angle(&Vector3::y_axis(), b)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), a);
        Self {
            a,
            b,
            rotation: *r.matrix(),
        }
    }

    /// Euler Z-X'-Z'' plane (Fanuc `G68.2`) whose Z axis is `u`.
    pub fn euler_zxz(u: &UnitVector3) -> Self {
        let b = u.z.clamp(-1.0, 1.0).acos();
        let a = if u.x.hypot(u.y) > 0.0 {
            u.x.atan2(-u.y)
        } else {
            0.0
        };
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), a)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), b);
        Self {
            a,
            b,
            rotation: *r.matrix(),
        }
    }

    /// Coordinates of workpiece point `p` in the tilted frame.
    pub fn to_plane(&self, p: &Point3) -> Point3 {
        Point3::from(self.rotation.transpose() * p.coords)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn tilted_z_is_the_tool_axis_and_points_round_trip(
            x in -1.0f64..1.0, y in -1.0f64..1.0, z in 0.05f64..1.0,
            px in -100.0f64..100.0, py in -100.0f64..100.0, pz in -100.0f64..100.0)
        {
            let u = UnitVector3::new_normalize(Vector3::new(x, y, z));
            for plane in [TiltedPlane::axis_by_axis_xy(&u), TiltedPlane::spatial_ab(&u), TiltedPlane::euler_zxz(&u)] {
                let zt = plane.rotation * Vector3::z();
                prop_assert!((zt - u.into_inner()).norm() < 1e-12);
                let p = Point3::new(px, py, pz);
                let q = plane.to_plane(&p);
                prop_assert!((Point3::from(plane.rotation * q.coords) - p).norm() < 1e-10);
                // The tool axis direction becomes +Z' in the tilted frame.
                let t = plane.to_plane(&Point3::from(u.into_inner()));
                prop_assert!((t - Point3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
            }
        }
    }

    #[test]
    fn closed_form_components_match_the_documented_conventions() {
        let (a, b) = (0.3f64, -0.7f64);
        let u = UnitVector3::new_normalize(Vector3::new(
            b.sin(),
            -a.sin() * b.cos(),
            a.cos() * b.cos(),
        ));
        let p = TiltedPlane::axis_by_axis_xy(&u);
        assert!((p.a - a).abs() < 1e-12 && (p.b - b).abs() < 1e-12);
        let u = UnitVector3::new_normalize(Vector3::new(
            b.sin() * a.cos(),
            -a.sin(),
            b.cos() * a.cos(),
        ));
        let p = TiltedPlane::spatial_ab(&u);
        assert!((p.a - a).abs() < 1e-12 && (p.b - b).abs() < 1e-12);
        let (a, b) = (0.3f64, 0.7f64);
        let u = UnitVector3::new_normalize(Vector3::new(
            a.sin() * b.sin(),
            -a.cos() * b.sin(),
            b.cos(),
        ));
        let p = TiltedPlane::euler_zxz(&u);
        assert!((p.a - a).abs() < 1e-12 && (p.b - b).abs() < 1e-12);
    }
}
