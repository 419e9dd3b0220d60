//! The tool axis of a point-milling posture: a frame at the contact, the tilt and lead
//! angles measured in it, and the search for an accessible axis.
//!
//! # Frame
//! At a contact point of a blade side with outward unit normal `n`, let `b` be the side's
//! span direction (`∂S/∂v`, toward the shroud) made perpendicular to `n`, and `t = n × b`
//! (along the pass). The axis with **tilt** `β` (from the side's tangent plane toward `n`)
//! and **lead** `λ` (turned about `n` toward `t`) is
//!
//! `a(β, λ) = R_n(λ) · (b cos β + n sin β)`.
//!
//! `β = 0` lays the axis along the span in the tangent plane (the posture of a flank cut);
//! `β = 90°` points it along the normal. The ball of a tapered ball end (half angle `θ`)
//! meets the side at its contact only while the axis keeps `β ≥ θ` from the tangent plane:
//! below that the cone above the ball, not the ball, would touch the side. So tilts start at
//! `θ` plus a margin.
//!
//! # Search
//! Candidate angles form a grid of `step` around the preferred posture `(β₀, 0)`: tilts
//! from the smallest allowed up to `β_max`, leads within `±λ_max`. They are tried in order
//! of `|β − β₀| + |λ| + ½(|β − β_p| + |λ − λ_p|)`, `(β_p, λ_p)` the previous posture of the
//! pass (so the axis returns to the preferred posture as soon as it can, and otherwise stays
//! near the one before: fewer rotary reversals). The first candidate whose whole tool keeps
//! the pass floors ([`cam_plan::PassCheck`], cutter, shank and holder against hub and every
//! blade) is taken. Cost: O(candidates tried · clearance query).

use cam_core::CutterLocation;
use cam_plan::{PassCheck, Point3, PostureClearance};
use nalgebra::{Rotation3, Unit, Vector3};

/// The contact frame `(n, b, t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Outward unit normal of the side.
    pub n: Vector3<f64>,
    /// Unit span direction (toward the shroud) in the tangent plane.
    pub b: Vector3<f64>,
    /// Unit direction along the pass, `n × b`.
    pub t: Vector3<f64>,
}

impl Frame {
    /// The frame from the normal and the side's `∂S/∂v`; `None` where `∂S/∂v` is parallel to
    /// the normal.
    pub fn new(n: Vector3<f64>, sv: Vector3<f64>) -> Option<Self> {
        let b = (sv - n * sv.dot(&n)).try_normalize(1e-12)?;
        Some(Self {
            n,
            b,
            t: n.cross(&b),
        })
    }

    /// The unit axis of tilt `beta` and lead `lambda` (rad).
    pub fn axis(&self, beta: f64, lambda: f64) -> Vector3<f64> {
        let base = self.b * beta.cos() + self.n * beta.sin();
        Rotation3::from_axis_angle(&Unit::new_unchecked(self.n), lambda) * base
    }

    /// Tilt and lead (rad) of a unit axis `a` in this frame (inverse of [`Frame::axis`]).
    pub fn angles(&self, a: &Vector3<f64>) -> (f64, f64) {
        let beta = a.dot(&self.n).clamp(-1.0, 1.0).asin();
        let inplane = a - self.n * a.dot(&self.n);
        let lambda = if inplane.norm() > 1e-12 {
            inplane.dot(&self.t).atan2(inplane.dot(&self.b))
        } else {
            0.0
        };
        (beta, lambda)
    }
}

/// Limits of the axis search (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLimits {
    /// Smallest tilt (the taper half angle plus a margin).
    pub min_tilt: f64,
    /// Preferred tilt.
    pub tilt: f64,
    /// Largest tilt.
    pub max_tilt: f64,
    /// Largest |lead|.
    pub max_lead: f64,
    /// Grid step.
    pub step: f64,
}

impl AxisLimits {
    /// The candidate (tilt, lead) pairs, nearest to the preferred posture and to `prev` first.
    pub fn candidates(&self, prev: (f64, f64)) -> Vec<(f64, f64)> {
        let step = self.step.max(1e-3);
        let mut betas = Vec::new();
        let mut b = self.min_tilt;
        while b <= self.max_tilt + 1e-12 {
            betas.push(b);
            b += step;
        }
        if !betas.iter().any(|x| (x - self.tilt).abs() < 1e-9) && self.tilt <= self.max_tilt {
            betas.push(self.tilt);
        }
        let nl = (self.max_lead / step).floor() as i64;
        let mut out: Vec<(f64, f64)> = Vec::with_capacity(betas.len() * (2 * nl as usize + 1));
        for &b in &betas {
            for k in -nl..=nl {
                out.push((b, k as f64 * step));
            }
        }
        let cost = |&(b, l): &(f64, f64)| {
            (b - self.tilt).abs() + l.abs() + 0.5 * ((b - prev.0).abs() + (l - prev.1).abs())
        };
        out.sort_by(|x, y| cost(x).total_cmp(&cost(y)));
        out
    }
}

/// The posture with ball centre `centre`, ball radius `r` and unit axis `axis`.
pub fn posture(centre: &Vector3<f64>, axis: &Vector3<f64>, r: f64) -> CutterLocation {
    CutterLocation {
        tip: Point3::from(centre - axis * r),
        axis: Unit::new_normalize(*axis),
    }
}

/// An accessible posture found by [`search`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// Tilt and lead (rad).
    pub angles: (f64, f64),
    /// The posture.
    pub cl: CutterLocation,
    /// Its clearances.
    pub clearance: PostureClearance,
    /// Candidates tried.
    pub tried: usize,
}

/// The first accessible (tilt, lead) in [`AxisLimits::candidates`] order whose axis the
/// machine can take (`reaches`, [`cam_plan::PlanContext::reaches`]); `None` when none keeps
/// the floors.
pub fn search(
    check: &PassCheck<'_>,
    frame: &Frame,
    centre: &Vector3<f64>,
    r: f64,
    limits: &AxisLimits,
    prev: (f64, f64),
    reaches: impl Fn(&Vector3<f64>) -> bool,
) -> Option<Found> {
    for (k, (beta, lambda)) in limits.candidates(prev).into_iter().enumerate() {
        let axis = frame.axis(beta, lambda);
        if !reaches(&axis) {
            continue;
        }
        let cl = posture(centre, &axis, r);
        if let Some(clearance) = check.clear_posture(&cl) {
            return Some(Found {
                angles: (beta, lambda),
                cl,
                clearance,
                tried: k + 1,
            });
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_invert_axis() {
        let f = Frame::new(Vector3::x(), Vector3::new(0.3, 0.2, 1.0)).unwrap();
        for &(b, l) in &[(0.1, 0.0), (0.5, -0.3), (1.2, 0.7)] {
            let a = f.axis(b, l);
            assert!((a.norm() - 1.0).abs() < 1e-12);
            let (b2, l2) = f.angles(&a);
            assert!(
                (b - b2).abs() < 1e-12 && (l - l2).abs() < 1e-12,
                "{b} {l} {b2} {l2}"
            );
            // The tilt is the angle from the tangent plane.
            assert!((a.dot(&f.n).asin() - b).abs() < 1e-12);
        }
    }

    #[test]
    fn candidates_start_at_the_preferred_posture() {
        let lim = AxisLimits {
            min_tilt: 0.05,
            tilt: 0.2,
            max_tilt: 0.8,
            max_lead: 0.3,
            step: 0.05,
        };
        let c = lim.candidates((0.2, 0.0));
        assert!((c[0].0 - 0.2).abs() < 1e-12 && c[0].1.abs() < 1e-12);
        assert!(c
            .iter()
            .all(|&(b, l)| (0.05 - 1e-12..=0.8 + 1e-9).contains(&b) && l.abs() <= 0.3 + 1e-9));
        // From another previous posture the preferred one still comes early.
        let c = lim.candidates((0.6, 0.2));
        let k = c
            .iter()
            .position(|&(b, l)| (b - 0.2).abs() < 1e-9 && l.abs() < 1e-9)
            .unwrap();
        assert!(k < 20, "{k}");
    }
}
