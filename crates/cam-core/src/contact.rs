//! Cutter-to-surface contact: where to put the cutter so that it touches a surface at a given
//! point, and how much material two neighbouring passes leave between them (scallop height).
//!
//! # Cutter location from a contact point
//!
//! Every cutting end of [`CutterShape`] is a convex solid of revolution whose lower profile
//! (the part that can touch a surface facing the spindle) is a circular arc of radius `ρ_a`
//! whose centre lies at height `h_c` above the tip and at distance `ρ_0` from the axis:
//!
//! | shape | arc radius `ρ_a` | centre height `h_c` | centre offset `ρ_0` | normals reachable |
//! |---|---|---|---|---|
//! | ball end | r | r | 0 | `n·a ∈ [0, 1]` |
//! | bull nose | r_c | r_c | R − r_c | `n·a ∈ [0, 1]` (flat bottom at `n·a = 1`) |
//! | flat end | 0 (rim) | 0 | R | `n·a ∈ [0, 1]` (bottom at 1, side at 0) |
//! | tapered ball end | r | r | 0 | `n·a ∈ [sin θ, 1]` (cone flank at `sin θ`) |
//! | tapered flat end | 0 (rim) | 0 | R_tip | `n·a ∈ [sin θ, 1]` (cone flank at `sin θ`) |
//!
//! With `n` the unit surface normal at the contact point `c` (pointing out of the material,
//! toward the cutter) and `a` the unit tool axis, tangency means the cutter's outward normal
//! at the contact equals `−n`. For an arc part that fixes the radial direction
//! `e = −(n − (n·a)a)/|n − (n·a)a|` (from the axis toward the contact) and gives
//!
//! ```text
//!     tip = c + ρ_a·n − h_c·a − ρ_0·e,      contact height h = h_c − ρ_a·(n·a)
//! ```
//!
//! (ball: `tip = c + r·n − r·a`; bull nose: the torus' tube centre `c + r_c·n` lies on its
//! centre circle; flat end: the rim point `tip + R·e` is the contact). When `n ∥ a` a shape
//! with `ρ_0 > 0` touches with its flat bottom and `e` is undefined: the tip is put on the
//! contact point. Where the profile is straight (ball-end cylinder `n·a = 0`, flat-end side,
//! cone flanks `n·a = sin θ`) every height along the generator touches; [`contact_location`]
//! picks the lowest (the arc end) and [`contact_location_at_height`] takes the height from
//! the caller (flank contact).
//!
//! # Scallop height
//!
//! In the plane normal to the feed, the surface is a circle of signed normal curvature `κ`
//! (`κ > 0` convex: the material is on the centre's side; `κ < 0` concave; `κ = 0` a
//! straight line) and two neighbouring passes touch it at contact points an arc length `w`
//! (the step-over) apart. The material left between them is bounded by the two cutter
//! profiles; by symmetry their crossing (the cusp) lies on the normal line half-way between
//! the contacts, and the scallop height is the cusp's distance from the surface.
//!
//! * Ball end, exact: circle–circle construction ([`ball_scallop`]): the ball centres lie on
//!   the offset circle of radius `1/κ + r` at the half angle `α = κw/2` from the bisector; the
//!   cusp is the crossing of the two balls' circles on the bisector, in closed form.
//! * Bull nose with lead angle `λ` (axis tilted from the normal toward the feed), exact
//!   silhouette ([`bull_nose_scallop`]): seen along the feed the torus is the lower offset by
//!   `r_c` of its projected centre circle, an ellipse with semi-axes `R−r_c` (cross-feed) and
//!   `(R−r_c)·sin λ` (normal), i.e. the swept profile of a straight pass; the cusp is where
//!   that profile crosses the bisector (bisection on the profile parameter to
//!   [`SCALLOP_SOLVE_TOL`]).
//! * Curvature-corrected second-order formula for both ([`scallop_approx`]):
//!   `h ≈ w²/8 · (κ + 1/r_eff)`, with `r_eff = r` for a ball and
//!   `r_eff = r_c + (R − r_c)/sin λ` for a bull nose (the torus' normal curvature across the
//!   feed at the contact). It follows from expanding the exact construction to second order
//!   in `w`, so it over- or under-estimates by `O(w⁴)`.
//!
//! All functions here are O(1) except the bull-nose silhouette solve (O(log(1/tol))
//! profile evaluations); none allocates.

use crate::{CutterLocation, CutterShape, Point3, UnitVector3, Vector3};

/// How far `n·a` may lie outside a shape's reachable range and still count as on its border
/// (normals computed from fitted surfaces carry ~1e-12 rounding; 1e-9 leaves margin without
/// accepting a visibly wrong orientation: 1e-9 in cosine is ~4e-5 rad at the flank angle).
pub const NORMAL_ALIGN_TOL: f64 = 1e-9;

/// Below this length of the normal's component across the axis, the normal counts as parallel
/// to the axis (flat-bottom contact). Same rounding argument as [`NORMAL_ALIGN_TOL`].
pub const AXIAL_NORMAL_TOL: f64 = 1e-9;

/// Tolerance (mm) of the bull-nose cusp solve on the profile's lateral coordinate: far below
/// any machining tolerance (µm range), reached in ~50 bisection steps.
pub const SCALLOP_SOLVE_TOL: f64 = 1e-12;

/// Bisection steps cap of the cusp solve: the bracket halves each step, 200 is far more than
/// the ~60 needed to reach [`SCALLOP_SOLVE_TOL`] from any bracket under 1 m.
const MAX_BISECTION_STEPS: usize = 200;

/// A lead angle below this (rad) counts as zero: the bull nose then cuts with its flat bottom
/// and its silhouette has a flat segment (the ellipse degenerates). 1e-9 rad changes the
/// profile by less than 1e-9·R mm.
pub const MIN_LEAD_ANGLE: f64 = 1e-9;

/// Errors of contact and scallop computations.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// The surface faces away from the spindle more than the cutter's lower profile allows.
    #[error(
        "surface normal makes n·a = {normal_dot_axis:.6} with the tool axis; this cutter only \
         touches surfaces with n·a in [{min:.6}, 1]"
    )]
    Unreachable {
        /// Cosine between the surface normal and the tool axis.
        normal_dot_axis: f64,
        /// Smallest cosine the shape's lower profile reaches.
        min: f64,
    },
    /// An input was not finite or not in its range.
    #[error("`{field}` = {value}: {reason}")]
    Invalid {
        /// The input's name.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        reason: &'static str,
    },
    /// The cutter is larger than a concave surface's radius of curvature: it cannot touch
    /// without gouging.
    #[error(
        "concave surface radius {surface_radius:.6} mm is smaller than the cutter's effective \
         radius {cutter_radius:.6} mm: the cutter gouges"
    )]
    Gouge {
        /// Radius of curvature of the surface across the feed (mm).
        surface_radius: f64,
        /// Effective cutter radius across the feed (mm).
        cutter_radius: f64,
    },
    /// The step-over exceeds what the cutter profile spans: the passes leave a ridge that
    /// no profile point reaches.
    #[error("step-over {step:.6} mm exceeds the cutter's reach {reach:.6} mm across the feed")]
    StepTooLarge {
        /// Requested step-over (mm).
        step: f64,
        /// Largest step-over the profile spans (mm).
        reach: f64,
    },
}

/// Which part of the cutter touches the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactPart {
    /// Spherical end of a ball or tapered ball end.
    Ball,
    /// Torus corner of a bull nose.
    Corner,
    /// Rim circle of a flat or tapered flat end.
    Rim,
    /// Flat bottom face (normal parallel to the axis).
    Bottom,
    /// Straight side: ball-end / flat-end cylinder or a tapered cutter's cone flank.
    Side,
}

/// A cutter location that touches a surface at a given point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Tool tip and axis.
    pub cl: CutterLocation,
    /// Height of the contact point above the tip, along the axis (mm).
    pub height: f64,
    /// The part of the cutter that touches.
    pub part: ContactPart,
}

/// The lower arc of a shape (see the module table) and the smallest `n·a` it reaches.
#[derive(Debug, Clone, Copy)]
struct LowerArc {
    arc_radius: f64,
    centre_height: f64,
    centre_offset: f64,
    min_cos: f64,
    part: ContactPart,
    /// Slope of the straight side above the arc: `None` for cylinders, `Some(θ)` for cones.
    cone: Option<f64>,
}

fn lower_arc(shape: &CutterShape) -> LowerArc {
    match *shape {
        CutterShape::BallEnd { radius } => LowerArc {
            arc_radius: radius,
            centre_height: radius,
            centre_offset: 0.0,
            min_cos: 0.0,
            part: ContactPart::Ball,
            cone: None,
        },
        CutterShape::BullNose {
            radius,
            corner_radius,
        } => LowerArc {
            arc_radius: corner_radius,
            centre_height: corner_radius,
            centre_offset: radius - corner_radius,
            min_cos: 0.0,
            part: ContactPart::Corner,
            cone: None,
        },
        CutterShape::FlatEnd { radius } => LowerArc {
            arc_radius: 0.0,
            centre_height: 0.0,
            centre_offset: radius,
            min_cos: 0.0,
            part: ContactPart::Rim,
            cone: None,
        },
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => LowerArc {
            arc_radius: ball_radius,
            centre_height: ball_radius,
            centre_offset: 0.0,
            min_cos: half_angle.sin(),
            part: ContactPart::Ball,
            cone: Some(half_angle),
        },
        CutterShape::TaperedFlatEnd {
            tip_radius,
            half_angle,
        } => LowerArc {
            arc_radius: 0.0,
            centre_height: 0.0,
            centre_offset: tip_radius,
            min_cos: half_angle.sin(),
            part: ContactPart::Rim,
            cone: Some(half_angle),
        },
    }
}

fn finite_point(p: &Point3) -> Result<(), ContactError> {
    for (field, v) in [("contact.x", p.x), ("contact.y", p.y), ("contact.z", p.z)] {
        if !v.is_finite() {
            return Err(ContactError::Invalid {
                field,
                value: v,
                reason: "must be finite",
            });
        }
    }
    Ok(())
}

/// Checks the shape and the contact point, returns the lower arc, the clamped `n·a` and the
/// radial unit direction `e` (axis → contact), `None` when `n ∥ a`.
fn prepare(
    shape: &CutterShape,
    contact: &Point3,
    normal: &UnitVector3,
    axis: &UnitVector3,
) -> Result<(LowerArc, f64, Option<Vector3>), ContactError> {
    shape.validate().map_err(|_| ContactError::Invalid {
        field: "shape",
        value: f64::NAN,
        reason: "cutter dimensions out of range",
    })?;
    finite_point(contact)?;
    let arc = lower_arc(shape);
    let c = normal.dot(axis);
    if !c.is_finite() {
        return Err(ContactError::Invalid {
            field: "normal·axis",
            value: c,
            reason: "must be finite",
        });
    }
    if c < arc.min_cos - NORMAL_ALIGN_TOL {
        return Err(ContactError::Unreachable {
            normal_dot_axis: c,
            min: arc.min_cos,
        });
    }
    let c = c.clamp(arc.min_cos, 1.0);
    let across = -(normal.into_inner() - axis.into_inner() * normal.dot(axis));
    let len = across.norm();
    let e = (len > AXIAL_NORMAL_TOL).then(|| across / len);
    Ok((arc, c, e))
}

/// The cutter location whose cutter touches a surface at `contact`, where the surface's unit
/// normal `normal` points out of the material, with tool axis `axis` (module docs: the lower
/// arc formula `tip = c + ρ_a·n − h_c·a − ρ_0·e`). On a straight part of the profile (cylinder
/// or cone flank) the lowest touching height is used.
///
/// Errors: invalid shape or non-finite point; [`ContactError::Unreachable`] when `n·a` is
/// below the shape's reachable range (the surface faces away from the spindle, or is steeper
/// than a tapered cutter's flank). O(1).
pub fn contact_location(
    shape: &CutterShape,
    contact: Point3,
    normal: UnitVector3,
    axis: UnitVector3,
) -> Result<Contact, ContactError> {
    let (arc, c, e) = prepare(shape, &contact, &normal, &axis)?;
    let n = normal.into_inner();
    let a = axis.into_inner();
    let Some(e) = e else {
        // Normal along the axis: the lowest profile point(s) touch.
        let part = if arc.centre_offset > 0.0 {
            ContactPart::Bottom
        } else {
            arc.part
        };
        return Ok(Contact {
            cl: CutterLocation { tip: contact, axis },
            height: 0.0,
            part,
        });
    };
    let tip = contact + n * arc.arc_radius - a * arc.centre_height - e * arc.centre_offset;
    let height = arc.centre_height - arc.arc_radius * c;
    let on_side = match arc.cone {
        None => c <= NORMAL_ALIGN_TOL,
        Some(t) => c <= t.sin() + NORMAL_ALIGN_TOL,
    };
    let part = if arc.arc_radius == 0.0 && c >= 1.0 - NORMAL_ALIGN_TOL {
        ContactPart::Bottom
    } else if on_side && arc.arc_radius == 0.0 {
        ContactPart::Side
    } else {
        arc.part
    };
    Ok(Contact {
        cl: CutterLocation { tip, axis },
        height,
        part,
    })
}

/// Side (flank) contact at a chosen height `height` above the tip: the surface normal must be
/// the outward normal of the cutter's straight side — perpendicular to the axis for the
/// cylinder of a ball or flat end, at `n·a = sin θ` for a tapered cutter's cone. Then
/// `tip = c − h·a − ρ(h)·e` with `ρ(h)` the profile radius (flank milling: the contact line
/// runs up the flank). At or below the arc end the result equals [`contact_location`].
///
/// Errors: as [`contact_location`], plus [`ContactError::Invalid`] when the normal is not the
/// side's normal (within [`NORMAL_ALIGN_TOL`]), the shape has no straight side (bull nose:
/// its cylinder starts at the torus equator, where this is also accepted), or the height is
/// below the arc end. O(1).
pub fn contact_location_at_height(
    shape: &CutterShape,
    contact: Point3,
    normal: UnitVector3,
    axis: UnitVector3,
    height: f64,
) -> Result<Contact, ContactError> {
    let (arc, c, e) = prepare(shape, &contact, &normal, &axis)?;
    let side_cos = arc.cone.map_or(0.0, f64::sin);
    if (c - side_cos).abs() > NORMAL_ALIGN_TOL {
        return Err(ContactError::Invalid {
            field: "normal·axis",
            value: c,
            reason: "side contact needs the normal of the straight side (0 for a cylinder, \
                     sin θ for a cone)",
        });
    }
    let lowest = arc.centre_height - arc.arc_radius * c;
    if !height.is_finite() || height < lowest - NORMAL_ALIGN_TOL {
        return Err(ContactError::Invalid {
            field: "height",
            value: height,
            reason: "side contact height must be finite and at or above the end of the arc",
        });
    }
    let Some(e) = e else {
        // n·a = side_cos < 1 cannot be parallel to the axis; reaching here means rounding.
        return Err(ContactError::Invalid {
            field: "normal·axis",
            value: c,
            reason: "normal parallel to the axis has no side contact",
        });
    };
    let radius = shape.radius_at(height);
    let tip = contact - axis.into_inner() * height - e * radius;
    Ok(Contact {
        cl: CutterLocation { tip, axis },
        height,
        part: ContactPart::Side,
    })
}

fn check_positive(field: &'static str, v: f64) -> Result<(), ContactError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ContactError::Invalid {
            field,
            value: v,
            reason: "must be finite and > 0",
        })
    }
}

fn check_finite(field: &'static str, v: f64) -> Result<(), ContactError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ContactError::Invalid {
            field,
            value: v,
            reason: "must be finite",
        })
    }
}

fn check_concave(curvature: f64, cutter_radius: f64) -> Result<(), ContactError> {
    if curvature < 0.0 && cutter_radius * (-curvature) > 1.0 {
        return Err(ContactError::Gouge {
            surface_radius: -1.0 / curvature,
            cutter_radius,
        });
    }
    Ok(())
}

/// Exact scallop height (mm) of a ball end of radius `radius` stepping over `step` (arc length
/// on the surface, mm) across a surface of signed normal curvature `curvature` (1/mm, `> 0`
/// convex) — the circle–circle construction of the module docs:
///
/// ```text
///   ρ = 1/κ, R' = ρ + r, α = w/(2ρ):  cusp at distance d from the surface centre on the
///   bisector, d = R'cos α − sign(κ)·√(r² − R'² sin² α),  h = sign(κ)·(d − ρ)
///   κ = 0:  h = r − √(r² − w²/4)
/// ```
///
/// Errors: non-positive radius or negative step; [`ContactError::Gouge`] when a concave
/// radius is below `r`; [`ContactError::StepTooLarge`] when the balls no longer meet. O(1).
pub fn ball_scallop(radius: f64, curvature: f64, step: f64) -> Result<f64, ContactError> {
    check_positive("radius", radius)?;
    check_finite("curvature", curvature)?;
    if !(step.is_finite() && step >= 0.0) {
        return Err(ContactError::Invalid {
            field: "step",
            value: step,
            reason: "must be finite and >= 0",
        });
    }
    check_concave(curvature, radius)?;
    let r = radius;
    if curvature == 0.0 {
        let half = 0.5 * step;
        if half > r {
            return Err(ContactError::StepTooLarge {
                step,
                reach: 2.0 * r,
            });
        }
        return Ok(r - (r * r - half * half).max(0.0).sqrt());
    }
    let s = curvature.signum();
    let rho = 1.0 / curvature.abs();
    let alpha = 0.5 * step / rho;
    let rp = rho + s * r;
    let (sa, ca) = alpha.sin_cos();
    let disc = r * r - rp * rp * sa * sa;
    if disc < 0.0 || alpha >= std::f64::consts::FRAC_PI_2 {
        return Err(ContactError::StepTooLarge {
            step,
            reach: ball_reach(r, curvature),
        });
    }
    // h = s(d − ρ) rewritten without cancellation for nearly flat surfaces (ρ ≫ r):
    // r cos α − √(r² − R'² sin² α) = sin² α (R'² − r²) / (r cos α + √(…)), R'² − r² = ρ² + 2sρr.
    let half_sin = (0.5 * alpha).sin();
    let h = -2.0 * s * rho * half_sin * half_sin
        + sa * sa * (rho * rho + 2.0 * s * rho * r) / (r * ca + disc.sqrt());
    Ok(h)
}

/// Largest arc step-over at which two balls of radius `r` on a surface of curvature `κ` still
/// meet (their circles are tangent): `R' sin α = r`.
fn ball_reach(r: f64, curvature: f64) -> f64 {
    if curvature == 0.0 {
        return 2.0 * r;
    }
    let rho = 1.0 / curvature.abs();
    let rp = rho + curvature.signum() * r;
    let ratio = (r / rp).min(1.0);
    2.0 * rho * ratio.asin()
}

/// Exact inverse of [`ball_scallop`]: the arc step-over that leaves scallop height `scallop`
/// (mm). The cusp at distance `ρ + s·h` from the surface centre lies on a ball circle, so by
/// the law of cosines `cos α = (d² + R'² − r²)/(2dR')`, `w = 2ρα`; on a plane
/// `w = 2√(2rh − h²)`. O(1).
///
/// Errors: non-positive inputs, `scallop ≥ r` on a plane (every step-over up to `2r` leaves
/// less), gouging concave curvature.
pub fn ball_step_over(radius: f64, curvature: f64, scallop: f64) -> Result<f64, ContactError> {
    check_positive("radius", radius)?;
    check_positive("scallop", scallop)?;
    check_finite("curvature", curvature)?;
    check_concave(curvature, radius)?;
    let r = radius;
    if scallop >= r {
        return Err(ContactError::Invalid {
            field: "scallop",
            value: scallop,
            reason: "must be below the ball radius",
        });
    }
    if curvature == 0.0 {
        return Ok(2.0 * (2.0 * r * scallop - scallop * scallop).sqrt());
    }
    let s = curvature.signum();
    let rho = 1.0 / curvature.abs();
    let rp = rho + s * r;
    let d = rho + s * scallop;
    if d <= 0.0 {
        return Err(ContactError::Invalid {
            field: "scallop",
            value: scallop,
            reason: "exceeds the concave surface's radius",
        });
    }
    let cos_a = ((d * d + rp * rp - r * r) / (2.0 * d * rp)).clamp(-1.0, 1.0);
    Ok(2.0 * rho * cos_a.acos())
}

/// Effective radius (mm) of a bull nose across the feed when its axis leans by `lead` (rad)
/// from the surface normal toward the feed: the torus' normal curvature across the feed at
/// the contact is `sin λ / (R₀ + r_c sin λ)`, so `r_eff = r_c + R₀/sin λ` with `R₀ = R − r_c`
/// (infinite for `λ = 0`: the flat bottom). O(1).
pub fn bull_nose_effective_radius(radius: f64, corner_radius: f64, lead: f64) -> f64 {
    let r0 = radius - corner_radius;
    let sl = lead.abs().sin();
    if sl < MIN_LEAD_ANGLE {
        if r0 > 0.0 {
            f64::INFINITY
        } else {
            corner_radius
        }
    } else {
        corner_radius + r0 / sl
    }
}

/// Second-order, curvature-corrected scallop height `h ≈ w²/8 · (κ + 1/r_eff)` (mm) for a
/// cutter of effective radius `effective_radius` across the feed (ball: `r`; bull nose:
/// [`bull_nose_effective_radius`]). Clamped at 0 (a concave surface flatter than the cutter
/// cannot leave a negative scallop). Error `O(w⁴)` against the exact constructions. O(1).
pub fn scallop_approx(effective_radius: f64, curvature: f64, step: f64) -> f64 {
    let inv = if effective_radius.is_finite() {
        1.0 / effective_radius
    } else {
        0.0
    };
    (step * step / 8.0 * (curvature + inv)).max(0.0)
}

/// Inverse of [`scallop_approx`]: `w = √(8h / (κ + 1/r_eff))`; infinite when the bracket is
/// not positive (a surface at least as curved as the cutter leaves no scallop to this order).
pub fn step_over_approx(effective_radius: f64, curvature: f64, scallop: f64) -> f64 {
    let inv = if effective_radius.is_finite() {
        1.0 / effective_radius
    } else {
        0.0
    };
    let k = curvature + inv;
    if k <= 0.0 {
        f64::INFINITY
    } else {
        (8.0 * scallop.max(0.0) / k).sqrt()
    }
}

/// Cross-feed silhouette of a bull nose with lead `λ`: point `(s, g)` (lateral offset, height
/// above the contact) at parameter `t ∈ [0, 1]` from the contact (t = 0) to the lateral
/// extreme (t = 1). Lower offset by `r_c` of the ellipse with semi-axes `R₀` and `b = R₀ sin λ`
/// (module docs); for `λ = 0` a flat segment of length `R₀` followed by a quarter circle.
fn bull_profile(r0: f64, rc: f64, b: f64, t: f64) -> (f64, f64) {
    use std::f64::consts::FRAC_PI_2;
    if b <= 0.0 {
        // Piecewise: flat bottom for t ≤ ½, then the corner arc.
        let flat = if r0 > 0.0 { 0.5 } else { 0.0 };
        if t <= flat {
            return (r0 * t / flat, 0.0);
        }
        let phi = (t - flat) / (1.0 - flat) * FRAC_PI_2;
        return (r0 + rc * phi.sin(), rc * (1.0 - phi.cos()));
    }
    let th = t * FRAC_PI_2;
    let (st, ct) = th.sin_cos();
    let m = (b * b * st * st + r0 * r0 * ct * ct).sqrt();
    let (ns, nz) = if m > 0.0 {
        (b * st / m, -r0 * ct / m)
    } else {
        (1.0, 0.0)
    };
    (r0 * st + rc * ns, b * (1.0 - ct) + rc * (1.0 + nz))
}

/// Exact scallop height (mm) of a bull nose (outer radius `radius`, corner `corner_radius`)
/// with lead `lead` (rad, axis tilted from the surface normal toward the feed, no side tilt)
/// stepping over `step` (arc length, mm) on a surface of signed normal curvature `curvature`
/// across the feed. Both passes are the cutter's silhouette along the feed (module docs),
/// placed tangent to the surface circle at arc positions `±w/2`; the cusp is the first
/// profile's crossing of the bisector, found by bisection on the profile parameter to
/// [`SCALLOP_SOLVE_TOL`]; O(60) profile evaluations.
///
/// Errors: invalid dimensions; [`ContactError::Gouge`] for a concave surface tighter than the
/// effective radius; [`ContactError::StepTooLarge`] when the silhouettes do not reach the
/// bisector.
pub fn bull_nose_scallop(
    radius: f64,
    corner_radius: f64,
    lead: f64,
    curvature: f64,
    step: f64,
) -> Result<f64, ContactError> {
    check_positive("radius", radius)?;
    check_positive("corner_radius", corner_radius)?;
    if corner_radius > radius {
        return Err(ContactError::Invalid {
            field: "corner_radius",
            value: corner_radius,
            reason: "must not exceed the cutter radius",
        });
    }
    check_finite("lead", lead)?;
    check_finite("curvature", curvature)?;
    if !(step.is_finite() && step >= 0.0) {
        return Err(ContactError::Invalid {
            field: "step",
            value: step,
            reason: "must be finite and >= 0",
        });
    }
    let r_eff = bull_nose_effective_radius(radius, corner_radius, lead);
    check_concave(curvature, r_eff)?;
    let r0 = radius - corner_radius;
    let sl = lead.abs().sin();
    let b = if sl < MIN_LEAD_ANGLE { 0.0 } else { r0 * sl };
    // Surface circle through the origin with normal +y at the bisector: S(σ), N(σ), T(σ).
    let k = curvature;
    let sig = -0.5 * step;
    let (sx, sy, nx, ny, tx, ty) = if k == 0.0 {
        (sig, 0.0, 0.0, 1.0, 1.0, 0.0)
    } else {
        let (sn, cs) = (k * sig).sin_cos();
        (sn / k, (cs - 1.0) / k, sn, cs, cs, -sn)
    };
    let map = |t: f64| {
        let (s, g) = bull_profile(r0, corner_radius, b, t);
        (sx + g * nx + s * tx, sy + g * ny + s * ty)
    };
    if step == 0.0 {
        return Ok(0.0);
    }
    let (x_end, _) = map(1.0);
    if x_end < 0.0 {
        return Err(ContactError::StepTooLarge {
            step,
            reach: 2.0 * radius,
        });
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..MAX_BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        if map(mid).0 < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        let (xl, _) = map(lo);
        let (xh, _) = map(hi);
        if (xh - xl).abs() < SCALLOP_SOLVE_TOL {
            break;
        }
    }
    let (_, y) = map(0.5 * (lo + hi));
    // Distance from the cusp on the bisector (the surface's normal line) to the surface.
    Ok(y.max(0.0))
}

/// Step-over (arc length, mm) at which a bull nose leaves scallop height `scallop` (inverse of
/// [`bull_nose_scallop`] by bisection on the step, which the scallop grows with
/// monotonically, to [`SCALLOP_SOLVE_TOL`]·(1 + w)); O(60²) profile evaluations.
///
/// Errors: as [`bull_nose_scallop`]; [`ContactError::Invalid`] when `scallop` is not positive.
pub fn bull_nose_step_over(
    radius: f64,
    corner_radius: f64,
    lead: f64,
    curvature: f64,
    scallop: f64,
) -> Result<f64, ContactError> {
    check_positive("scallop", scallop)?;
    // Reject bad dimensions up front with the forward function's messages.
    bull_nose_scallop(radius, corner_radius, lead, curvature, 0.0)?;
    // The largest step the silhouettes span: bisection on "reaches the bisector".
    let (mut lo, mut hi) = (0.0_f64, 2.0 * radius);
    for _ in 0..MAX_BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        match bull_nose_scallop(radius, corner_radius, lead, curvature, mid) {
            Ok(h) if h <= scallop => lo = mid,
            _ => hi = mid,
        }
        if hi - lo < SCALLOP_SOLVE_TOL * (1.0 + hi) {
            break;
        }
    }
    Ok(lo)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    const TOL: f64 = 1e-10;

    fn unit(x: f64, y: f64, z: f64) -> UnitVector3 {
        UnitVector3::new_normalize(Vector3::new(x, y, z))
    }

    fn shapes() -> Vec<CutterShape> {
        vec![
            CutterShape::BallEnd { radius: 3.0 },
            CutterShape::BullNose {
                radius: 4.0,
                corner_radius: 1.0,
            },
            CutterShape::FlatEnd { radius: 2.5 },
            CutterShape::TaperedBallEnd {
                ball_radius: 1.5,
                half_angle: 5f64.to_radians(),
            },
            CutterShape::TaperedFlatEnd {
                tip_radius: 1.0,
                half_angle: 4f64.to_radians(),
            },
        ]
    }

    /// Points on the cutter's boundary (profile surface up to `h_max` and the bottom disc).
    fn cutter_samples(shape: &CutterShape, cl: &CutterLocation, h_max: f64) -> Vec<Point3> {
        let a = cl.axis.into_inner();
        let u = a
            .cross(&Vector3::x())
            .try_normalize(1e-6)
            .unwrap_or_else(|| a.cross(&Vector3::y()).normalize());
        let v = a.cross(&u);
        let mut out = Vec::new();
        let nh = 400;
        let nt = 360;
        for i in 0..=nh {
            let h = h_max * (i as f64 / nh as f64).powi(2);
            let r = shape.radius_at(h);
            for j in 0..nt {
                let t = 2.0 * PI * j as f64 / nt as f64;
                out.push(cl.tip + a * h + (u * t.cos() + v * t.sin()) * r);
            }
        }
        let r0 = shape.radius_at(0.0);
        for i in 0..20 {
            for j in 0..nt {
                let t = 2.0 * PI * j as f64 / nt as f64;
                out.push(cl.tip + (u * t.cos() + v * t.sin()) * (r0 * i as f64 / 20.0));
            }
        }
        out
    }

    /// Contact point on the cutter's surface: its distance to the solid of revolution's
    /// profile is zero (radial distance equals the profile radius at its height).
    fn on_cutter(shape: &CutterShape, cl: &CutterLocation, p: Point3) -> f64 {
        let a = cl.axis.into_inner();
        let d = p - cl.tip;
        let h = d.dot(&a);
        let rad = (d - a * h).norm();
        if h.abs() < 1e-12 {
            return (rad - shape.radius_at(0.0)).max(0.0);
        }
        (rad - shape.radius_at(h)).abs()
    }

    #[test]
    fn ball_on_plane_matches_closed_form() {
        let s = CutterShape::BallEnd { radius: 3.0 };
        let c = Point3::new(1.0, 2.0, 0.5);
        let n = unit(0.0, 0.0, 1.0);
        let a = unit(0.3, -0.2, 1.0);
        let got = contact_location(&s, c, n, a).unwrap();
        let want = c + n.into_inner() * 3.0 - a.into_inner() * 3.0;
        assert!((got.cl.tip - want).norm() < TOL);
        // Ball centre 3 mm above the plane.
        let centre = got.cl.axis_point(3.0);
        assert!((centre.z - 3.5).abs() < TOL);
        assert_eq!(got.part, ContactPart::Ball);
    }

    /// Every shape on a plane, a convex cylinder and a convex sphere at several axes: the
    /// contact point lies on the cutter's surface and no sampled cutter point penetrates the
    /// surface by more than the sampling can explain (brute force).
    #[test]
    fn every_shape_touches_without_penetrating_plane_cylinder_sphere() {
        let axes = [
            unit(0.0, 0.0, 1.0),
            unit(0.2, 0.1, 1.0),
            unit(-0.05, 0.04, 1.0),
            unit(0.6, -0.3, 1.0),
        ];
        for shape in shapes() {
            for a in axes {
                // Plane z = 0.
                let c = Point3::new(0.4, -0.7, 0.0);
                let n = unit(0.0, 0.0, 1.0);
                check_touch(&shape, c, n, a, |p| p.z);
                // Cylinder of radius 20 about the y axis, contact on top.
                let rc = 20.0;
                let ang: f64 = 0.15;
                let c = Point3::new(rc * ang.sin(), 1.0, rc * ang.cos());
                let n = unit(ang.sin(), 0.0, ang.cos());
                check_touch(&shape, c, n, a, |p| (p.x * p.x + p.z * p.z).sqrt() - rc);
                // Sphere of radius 15 at the origin.
                let rs = 15.0;
                let n = unit(0.1, -0.2, 1.0);
                let c = Point3::from(n.into_inner() * rs);
                check_touch(&shape, c, n, a, |p| p.coords.norm() - rs);
            }
        }
    }

    fn check_touch(
        shape: &CutterShape,
        c: Point3,
        n: UnitVector3,
        a: UnitVector3,
        signed: impl Fn(&Point3) -> f64,
    ) {
        let got = match contact_location(shape, c, n, a) {
            Ok(g) => g,
            Err(ContactError::Unreachable { .. }) => {
                assert!(n.dot(&a) < lower_arc(shape).min_cos);
                return;
            }
            Err(e) => panic!("{e}"),
        };
        assert!(
            on_cutter(shape, &got.cl, c) < 1e-9,
            "{shape:?}: contact off the cutter"
        );
        let h_max = 6.0;
        let worst = cutter_samples(shape, &got.cl, h_max)
            .iter()
            .map(&signed)
            .fold(f64::INFINITY, f64::min);
        assert!(worst > -1e-9, "{shape:?} axis {a:?}: penetrates by {worst}");
        // The contact height is the contact point's height above the tip.
        let h = (c - got.cl.tip).dot(&a);
        assert!(
            (h - got.height).abs() < 1e-9,
            "{shape:?}: height {h} vs {}",
            got.height
        );
    }

    #[test]
    fn bull_nose_torus_centre_offset() {
        // Surface normal tilted 30° from the axis in the x direction.
        let s = CutterShape::BullNose {
            radius: 4.0,
            corner_radius: 1.0,
        };
        let a = unit(0.0, 0.0, 1.0);
        let t = 30f64.to_radians();
        let n = unit(t.sin(), 0.0, t.cos());
        let c = Point3::new(10.0, 0.0, 0.0);
        let got = contact_location(&s, c, n, a).unwrap();
        // Tube centre = c + rc n; it lies 3 mm from the axis at height rc above the tip.
        let q = c + n.into_inner();
        let axis_pt = got.cl.tip + a.into_inner();
        assert!(((q - axis_pt).norm() - 3.0).abs() < TOL);
        assert!((q.z - axis_pt.z).abs() < TOL);
        // The contact is on the side away from the normal's lean: e = −x.
        assert!((q.x - axis_pt.x + 3.0).abs() < TOL);
        assert_eq!(got.part, ContactPart::Corner);
    }

    #[test]
    fn flat_end_bottom_rim_and_side() {
        let s = CutterShape::FlatEnd { radius: 2.0 };
        let a = unit(0.0, 0.0, 1.0);
        let c = Point3::new(1.0, 1.0, 1.0);
        let got = contact_location(&s, c, a, a).unwrap();
        assert_eq!(got.part, ContactPart::Bottom);
        assert!((got.cl.tip - c).norm() < TOL);
        let n = unit(1.0, 0.0, 1.0);
        let got = contact_location(&s, c, n, a).unwrap();
        assert_eq!(got.part, ContactPart::Rim);
        assert!((got.cl.tip - Point3::new(3.0, 1.0, 1.0)).norm() < TOL);
        let n = unit(1.0, 0.0, 0.0);
        let got = contact_location_at_height(&s, c, n, a, 5.0).unwrap();
        assert_eq!(got.part, ContactPart::Side);
        assert!((got.cl.tip - Point3::new(3.0, 1.0, -4.0)).norm() < TOL);
    }

    #[test]
    fn tapered_ball_flank_and_unreachable() {
        let th = 5f64.to_radians();
        let s = CutterShape::TaperedBallEnd {
            ball_radius: 1.5,
            half_angle: th,
        };
        let a = unit(0.0, 0.0, 1.0);
        // Cone normal: outward radial +x, tilted down by θ: the surface normal is its negative.
        let n = unit(-th.cos(), 0.0, th.sin());
        let c = Point3::new(0.0, 0.0, 0.0);
        let h = 12.0;
        let got = contact_location_at_height(&s, c, n, a, h).unwrap();
        // The contact point lies on the cone at height h: radius ρ(h) from the axis.
        assert!(on_cutter(&s, &got.cl, c) < 1e-9);
        assert!(((c - got.cl.tip).z - h).abs() < TOL);
        // The lowest-point variant touches at the ball/cone junction.
        let low = contact_location(&s, c, n, a).unwrap();
        assert!((low.height - 1.5 * (1.0 - th.sin())).abs() < 1e-12);
        // A surface steeper than the flank cannot be touched.
        let steep = unit(-1.0, 0.0, 0.0);
        assert!(matches!(
            contact_location(&s, c, steep, a),
            Err(ContactError::Unreachable { .. })
        ));
        // Facing away from the spindle: unreachable for a ball too.
        let down = unit(0.0, 0.3, -1.0);
        assert!(matches!(
            contact_location(&CutterShape::BallEnd { radius: 1.0 }, c, down, a),
            Err(ContactError::Unreachable { .. })
        ));
    }

    /// Brute-force circle–circle construction: intersect the two ball circles numerically
    /// (bisection on the bisector) and measure the cusp's distance to the surface circle.
    fn brute_ball_scallop(r: f64, k: f64, w: f64) -> f64 {
        // Surface circle centre (0, −1/k), contacts at arc ±w/2, ball centres offset by r.
        let rho = 1.0 / k;
        let contact = |sig: f64| {
            let (sn, cs) = (k * sig).sin_cos();
            (
                Vector3::new(sn / k, (cs - 1.0) / k, 0.0),
                Vector3::new(sn, cs, 0.0),
            )
        };
        let (p1, n1) = contact(-0.5 * w);
        let c1 = p1 + n1 * r;
        // Cusp on x = 0: |(0, y) − c1| = r, the root nearest the surface (y ∈ [−h_max, r]).
        let f = |y: f64| (Vector3::new(0.0, y, 0.0) - c1).norm() - r;
        let (mut lo, mut hi) = (0.0, r);
        assert!(f(lo) > 0.0 && f(hi) < 0.0);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if f(m) > 0.0 {
                lo = m;
            } else {
                hi = m;
            }
        }
        let y = 0.5 * (lo + hi);
        // Distance of (0, y) to the surface circle.
        ((Vector3::new(0.0, y + rho, 0.0)).norm() - rho.abs()).abs()
    }

    #[test]
    fn ball_scallop_matches_brute_circle_intersection() {
        for &k in &[0.05, 0.01, -0.01, -0.1, 0.2] {
            for &w in &[0.2, 0.8, 1.5, 2.5] {
                let exact = ball_scallop(3.0, k, w).unwrap();
                let brute = brute_ball_scallop(3.0, k, w);
                assert!(
                    (exact - brute).abs() < 1e-9,
                    "k {k} w {w}: {exact} vs {brute}"
                );
            }
        }
        // Plane closed form.
        let h = ball_scallop(3.0, 0.0, 2.0).unwrap();
        assert!((h - (3.0 - (9.0f64 - 1.0).sqrt())).abs() < 1e-14);
    }

    #[test]
    fn ball_step_over_inverts_scallop() {
        for &k in &[0.0, 0.05, -0.05, 0.3] {
            for &h in &[0.001, 0.01, 0.1, 0.5] {
                let w = ball_step_over(3.0, k, h).unwrap();
                let back = ball_scallop(3.0, k, w).unwrap();
                assert!((back - h).abs() < 1e-10, "k {k} h {h}: {back}");
            }
        }
    }

    #[test]
    fn approx_formula_converges_at_second_order() {
        // Relative error of w²(κ+1/r)/8 is O(w²): halving w quarters it.
        let (r, k) = (3.0, 0.04);
        let err = |w: f64| {
            let e = ball_scallop(r, k, w).unwrap();
            (scallop_approx(r, k, w) - e).abs() / e
        };
        let (e1, e2) = (err(0.4), err(0.2));
        assert!(e1 < 0.01 && e2 < e1 / 3.0, "{e1} {e2}");
    }

    #[test]
    fn concave_gouge_and_large_step_are_errors() {
        assert!(matches!(
            ball_scallop(3.0, -0.5, 0.1),
            Err(ContactError::Gouge { .. })
        ));
        assert!(matches!(
            ball_scallop(1.0, 0.0, 2.5),
            Err(ContactError::StepTooLarge { .. })
        ));
        assert!(ball_step_over(1.0, 0.0, 1.0).is_err());
    }

    #[test]
    fn bull_nose_scallop_reduces_to_circles() {
        // Zero lead on a plane: flat bottom 2R₀ wide, then corner circles of radius r_c.
        let (r, rc) = (4.0, 1.0);
        let r0 = r - rc;
        assert!(bull_nose_scallop(r, rc, 0.0, 0.0, 5.9).unwrap() < 1e-12);
        let w = 7.0;
        let gap = 0.5 * (w - 2.0 * r0);
        let want = rc - (rc * rc - gap * gap).sqrt();
        let got = bull_nose_scallop(r, rc, 0.0, 0.0, w).unwrap();
        assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        // A bull nose whose corner is the whole radius is a ball at any lead.
        for &k in &[0.0, 0.05, -0.05] {
            let b = bull_nose_scallop(2.0, 2.0, 0.3, k, 1.2).unwrap();
            let s = ball_scallop(2.0, k, 1.2).unwrap();
            assert!((b - s).abs() < 1e-9, "k {k}: {b} vs {s}");
        }
    }

    #[test]
    fn bull_nose_scallop_matches_effective_radius_for_small_steps() {
        let (r, rc, lead) = (4.0, 1.0, 10f64.to_radians());
        let r_eff = bull_nose_effective_radius(r, rc, lead);
        assert!((r_eff - (1.0 + 3.0 / lead.sin())).abs() < 1e-12);
        for &k in &[0.0, 0.02, -0.02] {
            let w = 0.3;
            let exact = bull_nose_scallop(r, rc, lead, k, w).unwrap();
            let approx = scallop_approx(r_eff, k, w);
            assert!(
                (exact - approx).abs() < 0.02 * exact,
                "k {k}: {exact} vs {approx}"
            );
        }
        // The brute silhouette: lowest point of the tilted torus over the cross-feed line.
        let w = 2.0;
        let exact = bull_nose_scallop(r, rc, lead, 0.0, w).unwrap();
        let brute = brute_torus_height(r - rc, rc, lead, 0.5 * w);
        assert!((exact - brute).abs() < 1e-6, "{exact} vs {brute}");
        // Inverse.
        let step = bull_nose_step_over(r, rc, lead, 0.01, 0.05).unwrap();
        let back = bull_nose_scallop(r, rc, lead, 0.01, step).unwrap();
        assert!((back - 0.05).abs() < 1e-9);
    }

    /// Height of the silhouette of a torus (tube `rc` around a circle of radius `r0`, axis
    /// tilted by `lead` about the cross-feed y axis) seen along the feed x, at lateral offset
    /// `s`, above its lowest point: brute force over the torus' surface, minimising z over
    /// the torus as the envelope of its tube spheres, 200 000 centres).
    fn brute_torus_height(r0: f64, rc: f64, lead: f64, s: f64) -> f64 {
        // The torus is the envelope of spheres of radius rc on the centre circle; the
        // silhouette's height at y = s is min over centres of (z_c − √(rc² − (s − y_c)²)).
        let u = Vector3::new(lead.cos(), 0.0, -lead.sin());
        let v = Vector3::y();
        let centre = |t: f64| (u * t.cos() + v * t.sin()) * r0;
        let low = |y: f64| {
            let mut best = f64::INFINITY;
            let n = 200_000;
            for i in 0..n {
                let t = 2.0 * PI * i as f64 / n as f64;
                let c = centre(t);
                let dy = y - c.y;
                if dy.abs() <= rc {
                    best = best.min(c.z - (rc * rc - dy * dy).sqrt());
                }
            }
            best
        };
        low(s) - low(0.0)
    }
}
