//! Cutter geometry: the cutting part as a solid of revolution about the tool axis, plus shank
//! and holder for collision checks.
//!
//! Heights `h` are measured along the tool axis from the tool tip (h = 0) toward the spindle.

use crate::CamError;
use serde::{Deserialize, Serialize};

/// Shape of the cutting end. All radii in mm, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CutterShape {
    /// Flat end mill of radius `radius`.
    FlatEnd {
        /// Cutter radius.
        radius: f64,
    },
    /// Ball end mill: hemisphere of radius `radius` on a cylinder of the same radius.
    BallEnd {
        /// Ball (and cylinder) radius.
        radius: f64,
    },
    /// Bull nose (toroidal) end mill.
    BullNose {
        /// Outer radius.
        radius: f64,
        /// Corner radius, `0 < corner_radius <= radius`.
        corner_radius: f64,
    },
    /// Tapered (conical) ball end: ball of radius `ball_radius` at the tip, cone tangent to
    /// the ball opening upward with half angle `half_angle`.
    TaperedBallEnd {
        /// Ball radius at the tip.
        ball_radius: f64,
        /// Half taper angle (rad), `0 <= half_angle < π/2`.
        half_angle: f64,
    },
    /// Tapered flat end: a cone frustum of radius `tip_radius` at the tip opening upward.
    TaperedFlatEnd {
        /// Radius of the flat end face.
        tip_radius: f64,
        /// Half taper angle (rad), `0 <= half_angle < π/2`.
        half_angle: f64,
    },
}

/// A cylinder or cone frustum of the holder, stacked along the axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HolderSegment {
    /// Radius at the segment's lower end (mm).
    pub bottom_radius: f64,
    /// Radius at the segment's upper end (mm).
    pub top_radius: f64,
    /// Length along the axis (mm).
    pub length: f64,
}

/// A complete cutter: cutting end, flutes, shank and holder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cutter {
    /// Name used in tool paths and programs.
    pub name: String,
    /// Shape of the cutting end.
    pub shape: CutterShape,
    /// Length of the fluted (cutting) part from the tip (mm).
    pub flute_length: f64,
    /// Shank radius above the flutes (mm).
    pub shank_radius: f64,
    /// Stick-out: tip to holder face (mm).
    pub overall_length: f64,
    /// Holder segments stacked from the holder face upward.
    pub holder: Vec<HolderSegment>,
}

fn positive(field: &'static str, value: f64) -> Result<(), CamError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(CamError::InvalidCutter {
            field,
            value,
            reason: "must be finite and > 0",
        })
    }
}

fn angle(field: &'static str, value: f64) -> Result<(), CamError> {
    if value.is_finite() && (0.0..std::f64::consts::FRAC_PI_2).contains(&value) {
        Ok(())
    } else {
        Err(CamError::InvalidCutter {
            field,
            value,
            reason: "half angle must be in [0, π/2) rad",
        })
    }
}

impl CutterShape {
    /// Checks the dimensions.
    pub fn validate(&self) -> Result<(), CamError> {
        match *self {
            CutterShape::FlatEnd { radius } | CutterShape::BallEnd { radius } => {
                positive("radius", radius)
            }
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => {
                positive("radius", radius)?;
                positive("corner_radius", corner_radius)?;
                if corner_radius > radius {
                    return Err(CamError::InvalidCutter {
                        field: "corner_radius",
                        value: corner_radius,
                        reason: "must not exceed the cutter radius",
                    });
                }
                Ok(())
            }
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => {
                positive("ball_radius", ball_radius)?;
                angle("half_angle", half_angle)
            }
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            } => {
                positive("tip_radius", tip_radius)?;
                angle("half_angle", half_angle)
            }
        }
    }

    /// Radius of the cutting end's solid of revolution at height `h >= 0` above the tip,
    /// assuming the flutes continue indefinitely (closed form, O(1)). For many queries of one
    /// shape, [`RadiusProfile`] computes the same values without the trigonometry per call.
    pub fn radius_at(&self, h: f64) -> f64 {
        RadiusProfile::new(self).radius_at(h)
    }

    /// The shape's [`RadiusProfile`].
    pub fn profile(&self) -> RadiusProfile {
        RadiusProfile::new(self)
    }
}

/// The radius of a cutting end as a function of the height above the tip, with the shape's
/// trigonometric constants (taper and the ball–cone tangency) evaluated once:
/// [`CutterShape::radius_at`] for repeated queries, bit for bit the same values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadiusProfile(Profile);

#[derive(Debug, Clone, Copy, PartialEq)]
enum Profile {
    /// A cylinder of this radius.
    Flat(f64),
    /// A rounded end: a quarter circle of radius `corner` whose centre lies `offset` from
    /// the axis, then the cylinder of radius `radius` = `offset + corner` (ball end:
    /// offset 0).
    Rounded {
        radius: f64,
        offset: f64,
        corner: f64,
    },
    /// A ball of radius `r` tangent at height `h_t` (radius `r_t`) to a cone of slope `tan`.
    TaperedBall {
        r: f64,
        h_t: f64,
        r_t: f64,
        tan: f64,
    },
    /// A cone of tip radius `r0` and slope `tan`.
    TaperedFlat { r0: f64, tan: f64 },
}

impl RadiusProfile {
    /// The profile of `shape`.
    pub fn new(shape: &CutterShape) -> Self {
        Self(match *shape {
            CutterShape::FlatEnd { radius } => Profile::Flat(radius),
            CutterShape::BallEnd { radius } => Profile::Rounded {
                radius,
                offset: 0.0,
                corner: radius,
            },
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => Profile::Rounded {
                radius,
                offset: radius - corner_radius,
                corner: corner_radius,
            },
            CutterShape::TaperedBallEnd {
                ball_radius: r,
                half_angle: t,
            } => Profile::TaperedBall {
                // Tangency of the cone and the ball lies at height r(1 - sin θ), radius r cos θ.
                r,
                h_t: r * (1.0 - t.sin()),
                r_t: r * t.cos(),
                tan: t.tan(),
            },
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            } => Profile::TaperedFlat {
                r0: tip_radius,
                tan: half_angle.tan(),
            },
        })
    }

    /// Radius at height `h` (heights below the tip count as 0), as
    /// [`CutterShape::radius_at`].
    #[inline]
    pub fn radius_at(&self, h: f64) -> f64 {
        let h = h.max(0.0);
        match self.0 {
            Profile::Flat(radius) => radius,
            Profile::Rounded {
                radius,
                offset,
                corner: rc,
            } => {
                if h >= rc {
                    radius
                } else {
                    // `0 + x` is `x` for the ball end's `x ≥ 0`.
                    offset + (rc * rc - (rc - h) * (rc - h)).max(0.0).sqrt()
                }
            }
            Profile::TaperedBall { r, h_t, r_t, tan } => {
                if h <= h_t {
                    (r * r - (r - h) * (r - h)).max(0.0).sqrt()
                } else {
                    r_t + (h - h_t) * tan
                }
            }
            Profile::TaperedFlat { r0, tan } => r0 + h * tan,
        }
    }
}

impl Cutter {
    /// Builds and validates a cutter with no holder.
    pub fn new(
        name: impl Into<String>,
        shape: CutterShape,
        flute_length: f64,
        shank_radius: f64,
        overall_length: f64,
    ) -> Result<Self, CamError> {
        let c = Self {
            name: name.into(),
            shape,
            flute_length,
            shank_radius,
            overall_length,
            holder: Vec::new(),
        };
        c.validate()?;
        Ok(c)
    }

    /// Checks every dimension: shape, positive lengths, flutes within the stick-out, holder
    /// segments positive.
    pub fn validate(&self) -> Result<(), CamError> {
        self.shape.validate()?;
        positive("flute_length", self.flute_length)?;
        positive("shank_radius", self.shank_radius)?;
        positive("overall_length", self.overall_length)?;
        if self.flute_length > self.overall_length {
            return Err(CamError::InvalidCutter {
                field: "flute_length",
                value: self.flute_length,
                reason: "must not exceed overall_length",
            });
        }
        for seg in &self.holder {
            positive("holder.bottom_radius", seg.bottom_radius)?;
            positive("holder.top_radius", seg.top_radius)?;
            positive("holder.length", seg.length)?;
        }
        Ok(())
    }

    /// Radius of the cutting part at height `h` above the tip (flutes only; `None` above
    /// the flute length or below the tip).
    pub fn cutting_radius_at(&self, h: f64) -> Option<f64> {
        if !(0.0..=self.flute_length).contains(&h) {
            return None;
        }
        Some(self.shape.radius_at(h))
    }

    /// Radius of the whole tool assembly (flutes, shank, holder) at height `h` above the tip;
    /// `None` below the tip or above the holder's top.
    pub fn assembly_radius_at(&self, h: f64) -> Option<f64> {
        if h < 0.0 {
            return None;
        }
        if h <= self.flute_length {
            return Some(self.shape.radius_at(h));
        }
        if h <= self.overall_length {
            return Some(self.shank_radius);
        }
        let mut base = self.overall_length;
        for seg in &self.holder {
            if h <= base + seg.length {
                let t = (h - base) / seg.length;
                return Some(seg.bottom_radius + t * (seg.top_radius - seg.bottom_radius));
            }
            base += seg.length;
        }
        None
    }

    /// Largest radius of the cutting part.
    pub fn max_cutting_radius(&self) -> f64 {
        self.shape.radius_at(self.flute_length)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tapered_ball_profile_is_continuous_at_tangency() {
        let s = CutterShape::TaperedBallEnd {
            ball_radius: 3.0,
            half_angle: 5f64.to_radians(),
        };
        let h_t = 3.0 * (1.0 - 5f64.to_radians().sin());
        let below = s.radius_at(h_t - 1e-9);
        let above = s.radius_at(h_t + 1e-9);
        assert!((below - above).abs() < 1e-7, "{below} vs {above}");
        // At the ball centre height the radius exceeds the ball radius' cosine projection.
        assert!((s.radius_at(h_t) - 3.0 * 5f64.to_radians().cos()).abs() < 1e-12);
    }

    #[test]
    fn invalid_dimensions_are_typed_errors() {
        let bad = CutterShape::BullNose {
            radius: 2.0,
            corner_radius: 3.0,
        };
        assert!(matches!(
            bad.validate(),
            Err(CamError::InvalidCutter {
                field: "corner_radius",
                ..
            })
        ));
        let bad = CutterShape::TaperedBallEnd {
            ball_radius: 1.0,
            half_angle: 2.0,
        };
        assert!(bad.validate().is_err());
        assert!(Cutter::new("t", CutterShape::FlatEnd { radius: 1.0 }, 30.0, 1.0, 20.0).is_err());
    }
}
