//! The APT 7-parameter cutter `(d, r, e, f, α, β, h)` and its conversion to and from
//! [`CutterShape`].
//!
//! APT (and ISO 3592 CLDATA `CUTTER/d, r, e, f, α, β, h`) describes a milling cutter's profile
//! in its axial half plane: `d` the diameter at the intersection of the bottom and side lines,
//! `r` the corner radius, `e` and `f` the radial and axial distances from the tool tip to the
//! corner-radius centre, `α` the angle of the bottom line above the horizontal, `β` the side
//! taper angle from the tool axis, `h` the height (flute length). Angles are radians here;
//! CLDATA files carry degrees and are converted by whoever reads them.
//!
//! Mapping (one canonical 7-tuple per shape; [`AptCutter::to_shape`] accepts exactly these,
//! plus `e = 0` for a sharp-cornered cutter, which some systems write):
//!
//! | shape | d | r | e | f | α | β |
//! |---|---|---|---|---|---|---|
//! | flat end `R` | 2R | 0 | R | 0 | 0 | 0 |
//! | ball end `R` | 2R | R | 0 | R | 0 | 0 |
//! | bull nose `R, r_c` | 2R | r_c | R − r_c | r_c | 0 | 0 |
//! | tapered ball `r, θ` | 2r(1 − sin θ)/cos θ | r | 0 | r | 0 | θ |
//! | tapered flat `R₀, θ` | 2R₀ | 0 | R₀ | 0 | 0 | θ |
//!
//! For the tapered ball, `d` is where the cone (tangent to the ball) meets the tip plane:
//! `R(0) = r cos θ − r(1 − sin θ) tan θ = r(1 − sin θ)/cos θ`.
//! Shapes with no exact model here are typed errors: a non-zero bottom angle α (drills,
//! engraving cones), a negative taper, a tapered bull nose (`r > 0, e > 0, β > 0`), a corner
//! that is not tangent to the bottom (`f ≠ r`).

use crate::{CamError, Cutter, CutterShape};
use serde::{Deserialize, Serialize};

/// Tolerance (mm for lengths, rad for angles) within which APT fields must agree with the
/// shape they select; CLDATA writers commonly print 4–6 decimals.
pub const APT_CONSISTENCY_TOL: f64 = 1e-6;

/// The APT 7-parameter cutter. Lengths in mm, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AptCutter {
    /// Diameter at the intersection of the bottom and side lines.
    pub d: f64,
    /// Corner radius.
    pub r: f64,
    /// Radial distance from the axis to the corner-radius centre.
    pub e: f64,
    /// Axial distance from the tip to the corner-radius centre.
    pub f: f64,
    /// Bottom angle above the horizontal (rad).
    pub alpha: f64,
    /// Side taper angle from the axis (rad).
    pub beta: f64,
    /// Height (flute length).
    pub h: f64,
}

fn nonneg(field: &'static str, value: f64) -> Result<(), CamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(CamError::InvalidCutter {
            field,
            value,
            reason: "APT field must be finite and >= 0",
        })
    }
}

fn expect(field: &'static str, value: f64, expected: f64) -> Result<(), CamError> {
    if (value - expected).abs() <= APT_CONSISTENCY_TOL {
        Ok(())
    } else {
        Err(CamError::AptInconsistent {
            field,
            value,
            expected,
        })
    }
}

impl AptCutter {
    /// The canonical APT tuple of a shape with flute length `h` (table in the module docs).
    pub fn from_shape(shape: &CutterShape, h: f64) -> Self {
        let (d, r, e, f, beta) = match *shape {
            CutterShape::FlatEnd { radius } => (2.0 * radius, 0.0, radius, 0.0, 0.0),
            CutterShape::BallEnd { radius } => (2.0 * radius, radius, 0.0, radius, 0.0),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => (
                2.0 * radius,
                corner_radius,
                radius - corner_radius,
                corner_radius,
                0.0,
            ),
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => {
                let (s, c) = half_angle.sin_cos();
                (
                    2.0 * ball_radius * (1.0 - s) / c,
                    ball_radius,
                    0.0,
                    ball_radius,
                    half_angle,
                )
            }
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            } => (2.0 * tip_radius, 0.0, tip_radius, 0.0, half_angle),
        };
        Self {
            d,
            r,
            e,
            f,
            alpha: 0.0,
            beta,
            h,
        }
    }

    /// The APT tuple of a cutter (its flute length as `h`).
    pub fn from_cutter(cutter: &Cutter) -> Self {
        Self::from_shape(&cutter.shape, cutter.flute_length)
    }

    /// The shape this tuple describes and its flute length `h`.
    ///
    /// Errors: [`CamError::InvalidCutter`] for negative / non-finite fields or zero `d`, `h`;
    /// [`CamError::AptUnsupported`] for shapes without an exact model;
    /// [`CamError::AptInconsistent`] when fields contradict the selected shape by more than
    /// [`APT_CONSISTENCY_TOL`].
    pub fn to_shape(&self) -> Result<(CutterShape, f64), CamError> {
        for (field, v) in [
            ("d", self.d),
            ("r", self.r),
            ("e", self.e),
            ("f", self.f),
            ("h", self.h),
        ] {
            nonneg(field, v)?;
        }
        if !self.alpha.is_finite() || !self.beta.is_finite() {
            return Err(CamError::InvalidCutter {
                field: "alpha/beta",
                value: if self.alpha.is_finite() {
                    self.beta
                } else {
                    self.alpha
                },
                reason: "APT angles must be finite",
            });
        }
        if self.alpha.abs() > APT_CONSISTENCY_TOL {
            return Err(CamError::AptUnsupported {
                reason: "non-zero bottom angle alpha (conical tip) has no exact model",
            });
        }
        if self.beta < -APT_CONSISTENCY_TOL {
            return Err(CamError::AptUnsupported {
                reason: "negative side taper beta (dovetail) has no exact model",
            });
        }
        let beta = self.beta.max(0.0);
        let tapered = beta > APT_CONSISTENCY_TOL;
        let radius = 0.5 * self.d;
        let shape = if self.r <= APT_CONSISTENCY_TOL {
            if self.e > APT_CONSISTENCY_TOL {
                expect("e", self.e, radius)?;
            }
            expect("f", self.f, 0.0)?;
            if tapered {
                CutterShape::TaperedFlatEnd {
                    tip_radius: radius,
                    half_angle: beta,
                }
            } else {
                CutterShape::FlatEnd { radius }
            }
        } else {
            expect("f", self.f, self.r)?;
            if tapered {
                if self.e > APT_CONSISTENCY_TOL {
                    return Err(CamError::AptUnsupported {
                        reason: "tapered bull nose (r > 0, e > 0, beta > 0) has no exact model",
                    });
                }
                let (s, c) = beta.sin_cos();
                expect("d", self.d, 2.0 * self.r * (1.0 - s) / c)?;
                CutterShape::TaperedBallEnd {
                    ball_radius: self.r,
                    half_angle: beta,
                }
            } else {
                expect("e", self.e, radius - self.r)?;
                if self.e <= APT_CONSISTENCY_TOL {
                    CutterShape::BallEnd { radius: self.r }
                } else {
                    CutterShape::BullNose {
                        radius,
                        corner_radius: self.r,
                    }
                }
            }
        };
        shape.validate()?;
        if self.h <= 0.0 {
            return Err(CamError::InvalidCutter {
                field: "h",
                value: self.h,
                reason: "flute length must be > 0",
            });
        }
        Ok((shape, self.h))
    }
}

impl Cutter {
    /// A cutter (no holder) from an APT tuple, with its shank radius and stick-out.
    pub fn from_apt(
        name: impl Into<String>,
        apt: &AptCutter,
        shank_radius: f64,
        overall_length: f64,
    ) -> Result<Self, CamError> {
        let (shape, h) = apt.to_shape()?;
        Cutter::new(name, shape, h, shank_radius, overall_length)
    }

    /// This cutter's APT tuple.
    pub fn to_apt(&self) -> AptCutter {
        AptCutter::from_cutter(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shape_round_trips() {
        let shapes = [
            CutterShape::FlatEnd { radius: 5.0 },
            CutterShape::BallEnd { radius: 3.0 },
            CutterShape::BullNose {
                radius: 6.0,
                corner_radius: 1.0,
            },
            CutterShape::TaperedBallEnd {
                ball_radius: 3.0,
                half_angle: 3f64.to_radians(),
            },
            CutterShape::TaperedFlatEnd {
                tip_radius: 2.0,
                half_angle: 5f64.to_radians(),
            },
        ];
        for shape in shapes {
            let apt = AptCutter::from_shape(&shape, 25.0);
            let (back, h) = apt.to_shape().unwrap();
            assert_eq!(h, 25.0);
            assert_eq!(back, shape, "{apt:?}");
            // The APT diameter is twice the profile radius at the tip plane's side line.
            if let CutterShape::TaperedBallEnd { half_angle, .. } = shape {
                let r_side = shape.radius_at(10.0) - 10.0 * half_angle.tan();
                assert!((apt.d - 2.0 * r_side).abs() < 1e-12);
            }
        }
        let c = Cutter::new("b", CutterShape::BallEnd { radius: 2.0 }, 20.0, 3.0, 40.0).unwrap();
        let c2 = Cutter::from_apt("b", &c.to_apt(), 3.0, 40.0).unwrap();
        assert_eq!(c, c2);
        // A flat end written with e = 0 is accepted.
        let apt = AptCutter {
            d: 10.0,
            r: 0.0,
            e: 0.0,
            f: 0.0,
            alpha: 0.0,
            beta: 0.0,
            h: 20.0,
        };
        assert_eq!(
            apt.to_shape().unwrap().0,
            CutterShape::FlatEnd { radius: 5.0 }
        );
    }

    #[test]
    fn unmapped_combinations_are_typed_errors() {
        let base = AptCutter {
            d: 10.0,
            r: 1.0,
            e: 4.0,
            f: 1.0,
            alpha: 0.0,
            beta: 0.0,
            h: 20.0,
        };
        assert!(base.to_shape().is_ok());
        let drill = AptCutter { alpha: 0.5, ..base };
        assert!(matches!(
            drill.to_shape(),
            Err(CamError::AptUnsupported { .. })
        ));
        let dovetail = AptCutter { beta: -0.2, ..base };
        assert!(matches!(
            dovetail.to_shape(),
            Err(CamError::AptUnsupported { .. })
        ));
        let tapered_bull = AptCutter { beta: 0.1, ..base };
        assert!(matches!(
            tapered_bull.to_shape(),
            Err(CamError::AptUnsupported { .. })
        ));
        let bad_e = AptCutter { e: 3.0, ..base };
        assert!(matches!(
            bad_e.to_shape(),
            Err(CamError::AptInconsistent { field: "e", .. })
        ));
        let bad_f = AptCutter { f: 2.0, ..base };
        assert!(matches!(
            bad_f.to_shape(),
            Err(CamError::AptInconsistent { field: "f", .. })
        ));
        let bad_d = AptCutter {
            e: 0.0,
            beta: 0.1,
            ..base
        };
        assert!(matches!(
            bad_d.to_shape(),
            Err(CamError::AptInconsistent { field: "d", .. })
        ));
        let neg = AptCutter { r: -1.0, ..base };
        assert!(matches!(
            neg.to_shape(),
            Err(CamError::InvalidCutter { field: "r", .. })
        ));
        let no_h = AptCutter { h: 0.0, ..base };
        assert!(matches!(
            no_h.to_shape(),
            Err(CamError::InvalidCutter { field: "h", .. })
        ));
    }
}
