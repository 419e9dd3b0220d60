//! Tangent cones of a leaf: cones containing every tangent `S_u` (or `S_v`), and the test
//! that `(S − q)·t` has one sign over the leaf's oriented box and the cone.

use nalgebra::Vector3;

use super::tree::Obb;

/// Cone `{t : angle(t, axis) ≤ α}` containing every tangent `S_u` (or `S_v`) of a leaf.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cone {
    pub(super) axis: Vector3<f64>,
    pub(super) sin_half_angle: f64,
    /// `Σ_k h_k |e_k · axis|` for the leaf's OBB: half the width of the box along the axis.
    pub(super) obb_half_width: f64,
}

impl Cone {
    /// Cone of the non-zero vectors `dirs`, or `None` if they span a half-space or more.
    pub(super) fn of(dirs: &[Vector3<f64>], obb: &Obb) -> Option<Cone> {
        let mut axis = Vector3::zeros();
        for d in dirs {
            let n = d.norm();
            if n > 0.0 {
                axis += d / n;
            }
        }
        let len = axis.norm();
        if len <= 0.0 {
            return None;
        }
        axis /= len;
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
            sin_max = sin_max.max(d.cross(&axis).norm() / n);
        }
        // Cover round-off in the hodograph and in the sine.
        let sin_half_angle = (sin_max * (1.0 + 1e-9) + 1e-12).min(1.0);
        let obb_half_width = (0..3)
            .map(|k| obb.h[k] * obb.axes[k].dot(&axis).abs())
            .sum();
        Some(Cone {
            axis,
            sin_half_angle,
            obb_half_width,
        })
    }

    /// Sign of `(S − q)·t` over all `S` in the box and `t` in the cone: +1 if certainly
    /// positive, -1 if certainly negative, 0 if undecided.
    #[inline]
    pub(super) fn sign(&self, obb: &Obb, cq: &Vector3<f64>, max_w: f64) -> i8 {
        let mid = cq.dot(&self.axis);
        let margin = max_w * self.sin_half_angle;
        if mid - self.obb_half_width > margin {
            1
        } else if mid + self.obb_half_width < -margin {
            -1
        } else {
            let _ = obb;
            0
        }
    }
}
