//! The tool axes of an area: the rulings of its two bounding sides interpolated across the
//! channel, and the candidate axes tried around them (module docs of [`super`], step 5).

use super::level::Field;
use super::sides::Bound;
use crate::accessibility::limit_tilt;
use impeller_model::levels::DepthLevel;
use nalgebra::{Rotation3, Unit, Vector3};

/// Angular step of the axis search (degrees) and its number of steps in lean (across the
/// flow, away from the nearer side) and in lead (along the flow, both ways).
pub(super) const AXIS_STEP_DEG: f64 = 3.0;
pub(super) const LEAN_STEPS: usize = 4;
pub(super) const LEAD_STEPS: usize = 2;

/// The tool axes of one area (module docs, step 5).
pub(super) struct Axes<'a> {
    pub(super) lv: &'a DepthLevel,
    pub(super) field: &'a Field,
    pub(super) bounds: &'a [Bound],
    pub(super) max_tilt: f64,
    /// Level number (for error places).
    pub(super) level: usize,
}

impl Axes<'_> {
    /// Point of the level and its unit normal at planar `q = (s, y)`.
    pub(super) fn point_of(&self, q: [f64; 2]) -> (Vector3<f64>, Vector3<f64>) {
        let theta = q[1] / self.lv.radius_at(q[0]);
        self.lv.at_developed(q[0], theta)
    }

    /// Cross-channel fraction of `q` in the field (0 on the left side, 1 on the right).
    pub(super) fn fraction(&self, q: [f64; 2]) -> f64 {
        let (l, r) = self.field.region.bounds(q[0]);
        if r > l {
            ((q[1] - l) / (r - l)).clamp(0.0, 1.0)
        } else {
            0.5
        }
    }

    /// The wanted axis: the rulings of the two sides bounding the field interpolated at the
    /// fraction of `q`, limited to `max_tilt` from the level normal `n`. O(1).
    pub(super) fn wanted(&self, q: [f64; 2], n: &Vector3<f64>) -> Vector3<f64> {
        let f = self.fraction(q);
        let ruling = |b: usize, u: f64| {
            let r = &self.bounds[b].ruled;
            (r.point(u, 1.0) - r.point(u, 0.0)).normalize()
        };
        let reg = &self.field.region;
        let ul = interp(&reg.s, &self.field.left.u, q[0]);
        let ur = interp(&reg.s, &self.field.right.u, q[0]);
        let a =
            ruling(self.field.left.ruled, ul) * (1.0 - f) + ruling(self.field.right.ruled, ur) * f;
        limit_tilt(a.try_normalize(1e-12).unwrap_or(*n), n, self.max_tilt)
    }

    /// Candidate axes at `q` (point `p`, normal `n`), in the order tried (module docs,
    /// step 5): the wanted axis; leaned away from the nearer side by `k·AXIS_STEP_DEG`
    /// (`k ≤ LEAN_STEPS`); led forward and back along the flow (`≤ LEAD_STEPS`); both; leaned
    /// toward the nearer side (`≤ 2` steps); the level normal. Each limited to `max_tilt`
    /// from `n`. O(LEAN_STEPS · LEAD_STEPS).
    pub(super) fn candidates(
        &self,
        q: [f64; 2],
        p: &Vector3<f64>,
        n: &Vector3<f64>,
    ) -> Vec<Vector3<f64>> {
        let a0 = self.wanted(q, n);
        // Circumferential direction (increasing y), flow tangent and cross direction.
        let e_y = Vector3::new(-p.y, p.x, 0.0)
            .try_normalize(1e-12)
            .unwrap_or_else(|| n.cross(&Vector3::x()));
        let t = e_y.cross(n).try_normalize(1e-12).unwrap_or(e_y);
        let c = n.cross(&t);
        // Lean about the flow tangent: the sign that moves the axis toward +y, flipped when
        // the nearer side is the right one.
        let toward_plus_y = if t.cross(&a0).dot(&e_y) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let away = if self.fraction(q) < 0.5 {
            toward_plus_y
        } else {
            -toward_plus_y
        };
        let step = AXIS_STEP_DEG.to_radians();
        let turn = |lean: f64, lead: f64| {
            let r = Rotation3::from_axis_angle(&Unit::new_normalize(c), lead)
                * Rotation3::from_axis_angle(&Unit::new_normalize(t), lean);
            limit_tilt(r * a0, n, self.max_tilt)
        };
        let mut out = vec![a0];
        for k in 1..=LEAN_STEPS {
            out.push(turn(away * step * k as f64, 0.0));
        }
        for j in 1..=LEAD_STEPS {
            for sign in [1.0, -1.0] {
                out.push(turn(0.0, sign * step * j as f64));
            }
        }
        for k in 1..=LEAN_STEPS {
            for j in 1..=LEAD_STEPS {
                for sign in [1.0, -1.0] {
                    out.push(turn(away * step * k as f64, sign * step * j as f64));
                }
            }
        }
        for k in 1..=2 {
            out.push(turn(-away * step * k as f64, 0.0));
        }
        out.push(*n);
        out
    }
}

pub(super) fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let k = xs.partition_point(|&v| v <= x).clamp(1, xs.len() - 1);
    let t = ((x - xs[k - 1]) / (xs[k] - xs[k - 1])).clamp(0.0, 1.0);
    ys[k - 1] + t * (ys[k] - ys[k - 1])
}

/// Moving average of unit axes over `w` neighbours (renormalised).
pub(super) fn smooth_axes(a: &[Vector3<f64>], w: usize) -> Vec<Vector3<f64>> {
    let h = w / 2;
    (0..a.len())
        .map(|i| {
            let lo = i.saturating_sub(h);
            let hi = (i + h + 1).min(a.len());
            let s: Vector3<f64> = a[lo..hi].iter().sum();
            s.try_normalize(1e-12).unwrap_or(a[i])
        })
        .collect()
}
