//! The tool axis of a blade-root position (paper 004 §"Preliminary 5-axis tool paths", steps
//! (6)–(8), eq. 7), with a tilt about the root tangent where the paper's turn about the
//! impeller axis finds none.
//!
//! # Geometry
//! The first axis `a₀` is the ruling of the blade side at the station: the direction from the
//! side's hub edge to its shroud edge, turned to point away from the hub. A position is
//! *accessible* when every sample of the tool above the ball (flutes, shank, holder) keeps at
//! least `−machining_tol` from the design ([`cam_plan::DesignClearance`]).
//!
//! 1. **Turn about the impeller axis** (paper 004): `a₀` is turned about a line parallel to
//!    +Z through the ball centre by `k·step`, `k = 0, 1, …`, toward the channel (away from
//!    the blade), never beyond `C_max`, eq. 7: the angle at the ball centre E between the
//!    first axis (to C, the axis point at shroud height) and the direction to F, the point of
//!    the neighbouring blade nearest to C. Where `a₀` is within 10° of +Z (a radial blade at
//!    the outlet) that turn cannot move it, and the root tangent (the path direction) is the
//!    turning axis instead.
//! 2. **Tilt about the root tangent**, when step 1 turned about the impeller axis and found no
//!    accessible axis: `a₀` is tilted about the root tangent by `k·step`, `k = 1, 2, …`, straight
//!    away from the blade, within the same `C_max`. On a free-form blade with backsweep the
//!    side bulges into the straight ruling's flutes while a turn about +Z swings the tool
//!    along the blade rather than off it: on the NASA HECC impeller's main pressure sides,
//!    from u = 0.83 to the trailing edge, the flutes of a Ø3 mm tapered ball along the ruling
//!    reach 0.4 mm or more into the blade at every turn about +Z between −90° and +90°, and
//!    are clear after a 5–10° tilt about the tangent.
//!
//! The first accessible axis in that order is taken; a station with none is left to the
//! caller (skipped and reported by blade-root finishing).
//!
//! Cost: O(steps · tool samples · design distance) per position, steps ≤ 2·C_max/step.

use cam_core::CutterLocation;
use cam_plan::{ClearanceOptions, DesignClearance, PartSet, PlanContext, Point3};
use impeller_model::{channel::edge_v, Blade, Side};
use nalgebra::{Rotation3, Unit, Vector3};

use crate::accessibility::upper_clearance;

/// Smallest tilt of the first axis from +Z for which turning about the impeller axis moves
/// it (10°); below it the root tangent is the turning axis.
const MIN_TILT: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// The line the first axis was turned about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TurnAxis {
    /// A line parallel to the impeller axis through the ball centre (paper 004).
    Impeller,
    /// The root tangent (the path direction) through the ball centre.
    RootTangent,
    /// Not turned: the slerp of two neighbouring positions' axes, taken at a position
    /// inserted to make the motion between them clear.
    Interpolated,
}

/// Outcome of the axis search at one position.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Search {
    /// An accessible axis.
    Found {
        /// Unit tool axis.
        axis: Vector3<f64>,
        /// Turning steps taken in the family that found it (0 = the ruling).
        steps: usize,
        /// Signed turning angle (rad) about `turn`.
        rotation: f64,
        /// Which line the axis was turned about.
        turn: TurnAxis,
        /// Smallest clearance of flutes, shank and holder (mm).
        clearance: f64,
    },
    /// No accessible axis within `c_max` (rad) in either family.
    None {
        /// Paper 004's bound of the turning angle here (rad).
        c_max: f64,
    },
}

/// The clearance query of the shank and holder alone (cutter samples left out: the flutes
/// are measured by [`upper_clearance`], which can also place a smaller ball).
pub(crate) fn shank_and_holder<'a>(ctx: &PlanContext<'a>) -> DesignClearance<'a> {
    ctx.clearance.with_options(ClearanceOptions {
        parts: PartSet::MATERIAL,
        above_mm: ctx.tool.cutter.flute_length,
        ..ClearanceOptions::default()
    })
}

/// What the shank and holder keep from the design (mm): they do not cut, and any contact of
/// theirs with the design is a collision. The clearance query's mesh can read up to its chord
/// above the truth at a convex edge, so they keep the larger of the chord and the machining
/// tolerance (the cutter may touch within `−machining_tol`: it cuts there).
pub(crate) fn shank_keep(ctx: &PlanContext<'_>) -> f64 {
    ctx.tolerances
        .machining_tol
        .max(ctx.tolerances.chord_tol)
        .max(0.0)
}

/// Whether the shank and holder (`upper`) of the posture with ball centre `centre`, unit
/// `axis` and ball radius `r` keep [`shank_keep`] from the design.
pub(crate) fn shank_clear(
    ctx: &PlanContext<'_>,
    upper: &DesignClearance<'_>,
    centre: &Vector3<f64>,
    axis: &Vector3<f64>,
    r: f64,
) -> bool {
    posture_cl(centre, axis, r)
        .is_some_and(|cl| upper.clearance_if_clear(&cl, shank_keep(ctx)).is_some())
}

/// The cutter location of the posture with ball centre `centre`, unit `axis` and ball radius
/// `r` (tip at `centre − r·axis`); `None` for a zero or non-finite axis.
fn posture_cl(centre: &Vector3<f64>, axis: &Vector3<f64>, r: f64) -> Option<CutterLocation> {
    CutterLocation::new(Point3::from(centre - axis * r), *axis).ok()
}

/// One blade-root station as the axis search sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Station<'b> {
    /// The blade finished.
    pub blade: &'b Blade,
    /// Its side.
    pub side: Side,
    /// The neighbouring blade that side faces.
    pub neighbour: &'b Blade,
    /// The side's u parameter.
    pub u: f64,
    /// Ball centre.
    pub centre: Vector3<f64>,
    /// Outward unit normal of the side at the ball's contact.
    pub normal: Vector3<f64>,
}

/// The axis search of the module docs at `at`, for the job's tool of ball radius `r` with a
/// ball (and flutes) of radius `ball` (`ball < r` asks whether a smaller ball would fit);
/// `upper` is [`shank_and_holder`], `step` the turning step (rad). Axes the job's machine
/// cannot take within its rotary travel are passed over ([`PlanContext::reaches`]).
pub(crate) fn search_axis(
    ctx: &PlanContext<'_>,
    upper: &DesignClearance<'_>,
    at: &Station<'_>,
    r: f64,
    ball: f64,
    step: f64,
) -> Search {
    let imp = ctx.impeller;
    let (blade, side, u, centre) = (at.blade, at.side, at.u, &at.centre);
    let s = blade.side(side);
    let nh = {
        let (t, phi, _) = imp.hub().closest(centre);
        imp.hub().normal(t, phi)
    };
    // The ruling: hub edge to shroud edge at u.
    let v_hub = edge_v(blade, side, imp.hub(), u);
    let ruling = match (&v_hub, edge_v(blade, side, imp.shroud(), u)) {
        (Ok(a), Ok(b)) => s.point(u, b) - s.point(u, *a),
        _ => s.derivs2(u, 0.5 * (s.domain().1 .0 + s.domain().1 .1)).sv,
    };
    let mut a0 = ruling.try_normalize(1e-12).unwrap_or(nh);
    if a0.dot(&nh) < 0.0 {
        a0 = -a0;
    }
    // Away from the blade: the θ direction on the channel side of the blade.
    let e_theta = Vector3::new(-centre.y, centre.x, 0.0)
        .try_normalize(1e-12)
        .unwrap_or(Vector3::x());
    let away = if at.normal.dot(&e_theta) >= 0.0 {
        e_theta
    } else {
        -e_theta
    };
    let tangent = {
        let t = s.derivs2(u, v_hub.unwrap_or(s.domain().1 .0)).su;
        Unit::try_new(t, 1e-12).unwrap_or(Vector3::z_axis())
    };
    let c_max = c_max(ctx, at, &a0, &away, ball);
    let mut families = Vec::with_capacity(2);
    if a0.xy().norm() >= MIN_TILT.sin() {
        families.push((TurnAxis::Impeller, Vector3::z_axis(), 0usize));
        families.push((TurnAxis::RootTangent, tangent, 1));
    } else {
        families.push((TurnAxis::RootTangent, tangent, 0));
    }
    let tol = ctx.tolerances.machining_tol;
    for (turn, line, first) in families {
        let sigma = if line.cross(&a0).dot(&away) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let mut k = first;
        loop {
            let rot = sigma * step * k as f64;
            if rot.abs() > c_max + 1e-12 {
                break;
            }
            let axis = Rotation3::from_axis_angle(&line, rot) * a0;
            if ctx.reaches(&axis)
                && assembly_clearance(ctx, upper, centre, &axis, r, ball, -tol) >= -tol
            {
                let clearance =
                    assembly_clearance(ctx, upper, centre, &axis, r, ball, f64::NEG_INFINITY);
                return Search::Found {
                    axis,
                    steps: k,
                    rotation: rot,
                    turn,
                    clearance,
                };
            }
            k += 1;
        }
    }
    Search::None { c_max }
}

/// `C_max` of paper 004 eq. 7 (rad): E = the ball centre, C = the point of the first axis
/// `a0` at shroud height (at least `ball` above E), F = the point of the neighbouring blade
/// nearest to C; the angle CEF.
fn c_max(
    ctx: &PlanContext<'_>,
    at: &Station<'_>,
    a0: &Vector3<f64>,
    away: &Vector3<f64>,
    ball: f64,
) -> f64 {
    let centre = &at.centre;
    let shroud = ctx.impeller.shroud();
    let mut hgt = 0.0;
    let stick = ctx.tool.cutter.overall_length.max(1.0);
    while hgt < stick && shroud.signed_distance(&(centre + a0 * hgt)) < 0.0 {
        hgt += 0.25;
    }
    let c_pt = centre + a0 * hgt.max(ball);
    let f_pt = [Side::Pressure, Side::Suction]
        .iter()
        .map(|&sd| at.neighbour.projector(sd).closest_point(&c_pt))
        .min_by(|x, y| x.distance.total_cmp(&y.distance))
        .map(|sp| sp.point)
        .unwrap_or(c_pt + away);
    let ec = c_pt - centre;
    let ef = f_pt - centre;
    (ec.dot(&ef) / (ec.norm() * ef.norm()).max(1e-300))
        .clamp(-1.0, 1.0)
        .acos()
}

/// Smallest signed clearance (mm) of everything above the ball with its centre at `centre`
/// and unit `axis`: the flutes ([`upper_clearance`], with a ball of radius `ball`) and the
/// shank and holder frusta (`upper`, placed as on the job's tool: tip at `centre − r·axis`).
/// With a finite `stop_below` it returns as soon as a part is found below it (the shank and
/// holder are queried first, the cheaper query), with a value below `stop_below`: the flutes'
/// sample there, or −∞ for the shank or holder, which must also keep [`shank_keep`]; with
/// `f64::NEG_INFINITY` the exact minimum.
pub(crate) fn assembly_clearance(
    ctx: &PlanContext<'_>,
    upper: &DesignClearance<'_>,
    centre: &Vector3<f64>,
    axis: &Vector3<f64>,
    r: f64,
    ball: f64,
    stop_below: f64,
) -> f64 {
    let shank = posture_cl(centre, axis, r);
    if stop_below.is_finite() {
        if let Some(cl) = &shank {
            if let Some(c) = upper.clearance_if_clear(cl, stop_below.max(shank_keep(ctx))) {
                return upper_clearance(ctx, centre, axis, r, ball, stop_below).min(c.distance_mm);
            }
            return f64::NEG_INFINITY;
        }
    }
    let flutes = upper_clearance(ctx, centre, axis, r, ball, stop_below);
    match shank {
        Some(cl) => flutes.min(upper.clearance(&cl).distance_mm),
        None => flutes,
    }
}
