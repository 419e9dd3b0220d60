//! The APT seven-parameter cutter (`CUTTER/d,r,e,f,a,b,h`) and its conversion to and from
//! `cam-core` cutter shapes.
//!
//! APT defines a milling cutter by its profile in the axial half plane: `d` diameter, `r`
//! corner radius, `e` and `f` the radial and axial distances of the corner-arc centre from
//! the tool axis and tip, `a` the angle of the end face against the plane normal to the axis
//! (degrees), `b` the half taper angle of the flank against the axis (degrees) and `h` the
//! height. For a tapered cutter `d` is the diameter where the (extended) flank line meets the
//! tip plane. Shorter forms are common: `CUTTER/d` (flat end) and `CUTTER/d,r`.
//!
//! Mapping to [`CutterShape`] (exact, no approximation):
//! - `r = 0`, `b = 0` → flat end, radius `d/2`;
//! - `r = d/2`, `b = 0` → ball end;
//! - `0 < r < d/2`, `b = 0` → bull nose (`e = d/2 − r`, `f = r`);
//! - `b > 0`, `e = 0`, `f = r > 0` → tapered ball end with ball radius `r`, half angle `b`;
//! - `b > 0`, `r = 0` → tapered flat end with tip radius `d/2`.
//!
//! Other combinations (tapered bull nose, drills with `a > 0`, barrel cutters) have no
//! `cam-core` shape and are reported as unsupported.

use cam_core::{Cutter, CutterShape};
use serde::{Deserialize, Serialize};

/// Relative tolerance used to recognise the special cases `r = d/2`, `e = 0`, `f = r` in the
/// printed APT numbers (CAM systems print 4–6 decimals).
pub const APT_SHAPE_REL_TOL: f64 = 1e-6;

/// The seven APT cutter parameters (lengths in mm, angles in degrees as in the file).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AptCutter {
    /// Diameter `d`.
    pub d: f64,
    /// Corner radius `r`.
    pub r: f64,
    /// Radial distance `e` of the corner centre from the axis.
    pub e: f64,
    /// Axial distance `f` of the corner centre above the tip.
    pub f: f64,
    /// End-face angle `a` (degrees).
    pub a_deg: f64,
    /// Half taper angle `b` of the flank (degrees).
    pub b_deg: f64,
    /// Height `h` (flute length); 0 when the file does not give it.
    pub h: f64,
}

impl AptCutter {
    /// Builds the parameters from the 1–7 numbers of a `CUTTER` record, completing the short
    /// forms: `CUTTER/d` is a flat end, `CUTTER/d,r` a torus with `e = d/2 − r`, `f = r`.
    /// Returns `None` for an empty list or more than seven numbers.
    pub fn from_params(p: &[f64]) -> Option<Self> {
        if p.is_empty() || p.len() > 7 {
            return None;
        }
        let d = p[0];
        let r = p.get(1).copied().unwrap_or(0.0);
        let (e, f) = if p.len() >= 4 {
            (p[2], p[3])
        } else {
            (d / 2.0 - r, r)
        };
        Some(Self {
            d,
            r,
            e,
            f,
            a_deg: p.get(4).copied().unwrap_or(0.0),
            b_deg: p.get(5).copied().unwrap_or(0.0),
            h: p.get(6).copied().unwrap_or(0.0),
        })
    }

    /// The seven parameters in file order.
    pub fn params(&self) -> [f64; 7] {
        [
            self.d, self.r, self.e, self.f, self.a_deg, self.b_deg, self.h,
        ]
    }

    /// The APT parameters of a `cam-core` shape with height `h` (exact inverse of
    /// [`AptCutter::to_shape`]).
    pub fn from_shape(shape: &CutterShape, h: f64) -> Self {
        match *shape {
            CutterShape::FlatEnd { radius } => Self::plain(2.0 * radius, 0.0, radius, 0.0, h),
            CutterShape::BallEnd { radius } => Self::plain(2.0 * radius, radius, 0.0, radius, h),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => Self::plain(
                2.0 * radius,
                corner_radius,
                radius - corner_radius,
                corner_radius,
                h,
            ),
            CutterShape::TaperedBallEnd {
                ball_radius: r,
                half_angle: t,
            } => {
                // The flank is tangent to the ball; extended down to the tip plane it has
                // radius r (1 − sin θ) / cos θ there.
                let d = 2.0 * r * (1.0 - t.sin()) / t.cos();
                Self {
                    d,
                    r,
                    e: 0.0,
                    f: r,
                    a_deg: 0.0,
                    b_deg: t.to_degrees(),
                    h,
                }
            }
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            } => Self {
                d: 2.0 * tip_radius,
                r: 0.0,
                e: 0.0,
                f: 0.0,
                a_deg: 0.0,
                b_deg: half_angle.to_degrees(),
                h,
            },
        }
    }

    fn plain(d: f64, r: f64, e: f64, f: f64, h: f64) -> Self {
        Self {
            d,
            r,
            e,
            f,
            a_deg: 0.0,
            b_deg: 0.0,
            h,
        }
    }

    /// The `cam-core` shape these parameters describe, or a reason why there is none.
    pub fn to_shape(&self) -> Result<CutterShape, String> {
        let close = |x: f64, y: f64| (x - y).abs() <= APT_SHAPE_REL_TOL * self.d.abs().max(1.0);
        let p = self.params();
        if let Some(i) = p.iter().position(|v| !v.is_finite()) {
            return Err(format!("parameter {} is not finite", i + 1));
        }
        if self.d <= 0.0 {
            return Err("diameter must be > 0".into());
        }
        if self.r < 0.0 || self.h < 0.0 {
            return Err("corner radius and height must be >= 0".into());
        }
        if !close(self.a_deg, 0.0) {
            return Err(format!(
                "end-face angle a = {}° has no cam-core shape",
                self.a_deg
            ));
        }
        let half = self.d / 2.0;
        let shape = if close(self.b_deg, 0.0) {
            if close(self.r, 0.0) {
                CutterShape::FlatEnd { radius: half }
            } else if close(self.r, half) && close(self.e, 0.0) {
                CutterShape::BallEnd { radius: half }
            } else if self.r < half && close(self.e, half - self.r) && close(self.f, self.r) {
                CutterShape::BullNose {
                    radius: half,
                    corner_radius: self.r,
                }
            } else {
                return Err(format!(
                    "corner r = {}, e = {}, f = {} does not fit a flat, ball or bull-nose cutter of diameter {}",
                    self.r, self.e, self.f, self.d
                ));
            }
        } else if self.b_deg > 0.0 && self.b_deg < 90.0 {
            let t = self.b_deg.to_radians();
            if close(self.r, 0.0) {
                CutterShape::TaperedFlatEnd {
                    tip_radius: half,
                    half_angle: t,
                }
            } else if close(self.e, 0.0) && close(self.f, self.r) {
                CutterShape::TaperedBallEnd {
                    ball_radius: self.r,
                    half_angle: t,
                }
            } else {
                return Err("tapered cutter with a corner off the axis (tapered bull nose) has no cam-core shape".into());
            }
        } else {
            return Err(format!(
                "taper angle b = {}° must be in [0, 90)",
                self.b_deg
            ));
        };
        shape.validate().map_err(|e| e.to_string())?;
        Ok(shape)
    }

    /// A validated `cam-core` cutter named `name`: flute length `h` (or `default_height` when
    /// the file gives none), shank radius equal to the cutting radius at the flute top,
    /// stick-out equal to the flute length, no holder.
    pub fn to_cutter(&self, name: &str, default_height: f64) -> Result<Cutter, String> {
        let shape = self.to_shape()?;
        let h = if self.h > 0.0 { self.h } else { default_height };
        let shank = shape.radius_at(h);
        Cutter::new(name, shape, h, shank, h).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_forms_complete_to_seven_parameters() {
        let c = AptCutter::from_params(&[10.0]).unwrap();
        assert_eq!(c.to_shape().unwrap(), CutterShape::FlatEnd { radius: 5.0 });
        let c = AptCutter::from_params(&[10.0, 5.0]).unwrap();
        assert_eq!(c.to_shape().unwrap(), CutterShape::BallEnd { radius: 5.0 });
        let c = AptCutter::from_params(&[10.0, 1.0]).unwrap();
        assert_eq!(
            c.to_shape().unwrap(),
            CutterShape::BullNose {
                radius: 5.0,
                corner_radius: 1.0
            }
        );
        assert!(AptCutter::from_params(&[]).is_none());
        assert!(AptCutter::from_params(&[1.0; 8]).is_none());
    }

    #[test]
    fn every_shape_round_trips_through_apt_parameters() {
        let shapes = [
            CutterShape::FlatEnd { radius: 4.0 },
            CutterShape::BallEnd { radius: 3.0 },
            CutterShape::BullNose {
                radius: 6.0,
                corner_radius: 1.5,
            },
            CutterShape::TaperedBallEnd {
                ball_radius: 2.0,
                half_angle: 4f64.to_radians(),
            },
            CutterShape::TaperedFlatEnd {
                tip_radius: 1.5,
                half_angle: 3f64.to_radians(),
            },
        ];
        for s in shapes {
            let apt = AptCutter::from_shape(&s, 25.0);
            let back = apt.to_shape().unwrap();
            assert_eq!(std::mem::discriminant(&s), std::mem::discriminant(&back));
            for h in [0.0, 0.5, 2.0, 10.0] {
                assert!((s.radius_at(h) - back.radius_at(h)).abs() < 1e-12, "{s:?}");
            }
        }
    }

    #[test]
    fn tapered_ball_d_is_the_flank_diameter_at_the_tip_plane() {
        // The flank line r(h) = r cos θ + (h − h_t) tan θ extended to h = 0.
        let (r, t) = (3.0f64, 5f64.to_radians());
        let apt = AptCutter::from_shape(
            &CutterShape::TaperedBallEnd {
                ball_radius: r,
                half_angle: t,
            },
            30.0,
        );
        let h_t = r * (1.0 - t.sin());
        let at_tip = r * t.cos() - h_t * t.tan();
        assert!((apt.d / 2.0 - at_tip).abs() < 1e-12);
    }

    #[test]
    fn unsupported_shapes_say_why() {
        let c = AptCutter::from_params(&[10.0, 1.0, 2.0, 1.0, 0.0, 5.0, 20.0]).unwrap();
        assert!(c.to_shape().unwrap_err().contains("tapered bull nose"));
        let c = AptCutter::from_params(&[10.0, 0.0, 0.0, 0.0, 59.0, 0.0, 20.0]).unwrap();
        assert!(c.to_shape().unwrap_err().contains("end-face angle"));
        let c = AptCutter::from_params(&[-1.0]).unwrap();
        assert!(c.to_shape().is_err());
    }
}
