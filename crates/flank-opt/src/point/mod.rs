//! Five-axis point milling of a band of a blade side with a ball or tapered ball end: the
//! method for the parts of a free-form blade that no flank pass can follow.
//!
//! # Passes
//! A band is the part `v ∈ [v_lo, v_hi]` of a side, over its whole length (leading to
//! trailing edge). It is cut by passes along the flow, from the band's upper edge down (the
//! blade keeps its stiffness below the cut), zig-zag, on lines parallel to the upper edge
//! spaced for the scallop height `h` ([`layout`]: with ball radius `R` and the side's normal
//! curvature `κ` across the passes, two balls `w` apart leave `h ≈ w²/8 · (1/R + κ)`), each
//! ending where it meets the lower edge, and a last pass along the lower edge.
//!
//! # Postures
//! At a station `(u, v_k)` the ball centre is the contact's offset
//! `C = S + (R + a)·n` (`a` the blade allowance), so the ball touches the side at the
//! contact, whatever the axis. Where that ball would come nearer than `R + a_h` to the hub
//! (`a_h` the hub allowance: near the root), the contact rides up the side to where it
//! keeps exactly that (bisection in `v`): the ball then touches hub and side, the corner
//! below is left to blade-root finishing. A station whose ball would still come nearer than
//! the floor to any part of the design (a concave corner sharper than the ball), the
//! blade-root fillets included ([`cam_plan::FilletMargin`]: beyond a fillet's end, past the
//! hub's rim or an edge, a ball reads clear of hub and side and still reaches into the
//! fillet), is skipped; every motion keeps the ball off the fillets too (certified).
//! Stations are spaced along `u` (bisection) so that the chord between two ball centres
//! strays from the offset curve halfway by at most `chord_mm` where it runs toward the side
//! (where the straight move would cut into it) and by at most the scallop height where it
//! runs away from it (it only leaves material there), and the normal turns at most
//! `max_axis_step` between two postures.
//!
//! The axis is chosen per station by [`axis::search`]: tilt and lead from the side's
//! span direction, nearest the preferred posture and the previous one, the first whose whole
//! tool keeps the pass floors. Every motion between two postures is then certified for the
//! whole tool ([`cam_plan::PassCheck::motion`]); a motion that is not clear gets a
//! midpoint station (three levels), else the pass is split there (the caller links the
//! pieces over the safety surface).
//!
//! # Smooth axes
//! Once a pass is planned, the axes of each of its runs are smoothed about the ball centres
//! ([`smoothing`]): the ball, the contacts and the measurement below stay as planned; the
//! turned postures and their motions are checked again with the same whole-tool queries.
//!
//! # Measurement
//! [`scallop`] measures the residual and overcut of the emitted ball-centre polylines over a
//! dense grid of the band (exact ray–capsule entries along the normal).
//!
//! Complexity: O(stations · candidates tried · clearance query) for the postures, plus the
//! motion certificates; passes are planned in parallel (rayon).

pub mod axis;
pub mod layout;
pub mod scallop;
pub mod smoothing;

use crate::FlankError;
use axis::{AxisLimits, Frame};
use cam_core::CutterLocation;
use cam_plan::{PassCheck, PlanContext, Point3, PostureClearance};
use impeller_model::{Blade, Side};
use nalgebra::Vector3;
use rayon::prelude::*;

/// The job keys of the tool axis of point milling (degrees), shared by the operations that
/// point-mill: every key optional.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
pub struct AxisParams {
    /// Preferred tilt of the axis from the side's tangent plane (default: the taper half
    /// angle plus 8°).
    #[serde(default)]
    pub tilt_deg: Option<f64>,
    /// Largest tilt searched (default 60°).
    #[serde(default = "default_max_tilt")]
    pub max_tilt_deg: f64,
    /// Largest lead (turn about the normal, toward the feed) searched (default 30°).
    #[serde(default = "default_max_lead")]
    pub max_lead_deg: f64,
    /// Step of the accessibility search (default 3°).
    #[serde(default = "default_search_step")]
    pub search_step_deg: f64,
    /// Largest turn of the axis between two postures (default 3°).
    #[serde(default = "default_axis_step")]
    pub max_axis_step_deg: f64,
}

fn default_max_tilt() -> f64 {
    60.0
}
fn default_max_lead() -> f64 {
    30.0
}
fn default_search_step() -> f64 {
    3.0
}
fn default_axis_step() -> f64 {
    3.0
}

impl Default for AxisParams {
    fn default() -> Self {
        Self {
            tilt_deg: None,
            max_tilt_deg: default_max_tilt(),
            max_lead_deg: default_max_lead(),
            search_step_deg: default_search_step(),
            max_axis_step_deg: default_axis_step(),
        }
    }
}

/// Margin (rad) of the smallest tilt over the taper half angle: the cone above the ball
/// stays off the side's tangent plane by at least this.
pub const MIN_TILT_MARGIN: f64 = 1.0 * std::f64::consts::PI / 180.0;
/// Default tilt over the taper half angle (rad): the cone leaves the side at 8°, 0.5 mm
/// clear 3.6 mm above the ball centre.
pub const DEFAULT_TILT_MARGIN: f64 = 8.0 * std::f64::consts::PI / 180.0;
/// Gap (mm) of the cone above which a point-milling motion is certified as a whole (below
/// it the tool is checked at postures sampled along the motion).
pub const CERTIFIED_GAP_MM: f64 = 0.5;

/// Height above the tip (mm) of the split between the sampled and the certified part of a
/// point-milling motion check ([`cam_plan::pass_check`]): where a cone tilted `tilt` from the
/// side (half angle `half_angle`, ball radius `r`) leaves [`CERTIFIED_GAP_MM`] to the side's
/// tangent plane, at least three ball radii, at most `flute_length`.
pub fn split_height(r: f64, half_angle: f64, tilt: f64, flute_length: f64) -> f64 {
    let lean = (tilt - half_angle).max(MIN_TILT_MARGIN);
    (2.0 * r + CERTIFIED_GAP_MM / lean.sin())
        .max(3.0 * r)
        .min(flute_length.max(3.0 * r))
}

impl AxisParams {
    /// Checks ranges; the message names the key.
    pub fn validate(&self) -> Result<(), FlankError> {
        let bad = |k: &str, v: f64, range: &str| {
            Err(FlankError::Param(format!("{k} = {v} must be in {range}")))
        };
        if let Some(t) = self.tilt_deg {
            if !(t.is_finite() && (0.0..90.0).contains(&t)) {
                return bad("tilt_deg", t, "[0, 90)");
            }
        }
        if !(self.max_tilt_deg.is_finite() && self.max_tilt_deg > 0.0 && self.max_tilt_deg < 90.0) {
            return bad("max_tilt_deg", self.max_tilt_deg, "(0, 90)");
        }
        if !(self.max_lead_deg.is_finite() && (0.0..=80.0).contains(&self.max_lead_deg)) {
            return bad("max_lead_deg", self.max_lead_deg, "[0, 80]");
        }
        if !(self.search_step_deg.is_finite()
            && self.search_step_deg >= 0.25
            && self.search_step_deg <= 15.0)
        {
            return bad("search_step_deg", self.search_step_deg, "[0.25, 15]");
        }
        if !(self.max_axis_step_deg.is_finite()
            && self.max_axis_step_deg > 0.0
            && self.max_axis_step_deg <= 30.0)
        {
            return bad("max_axis_step_deg", self.max_axis_step_deg, "(0, 30]");
        }
        Ok(())
    }

    /// The search limits for a tool of taper half angle `half_angle` (rad).
    pub fn limits(&self, half_angle: f64) -> AxisLimits {
        let min_tilt = half_angle + MIN_TILT_MARGIN;
        let tilt = self
            .tilt_deg
            .map_or(half_angle + DEFAULT_TILT_MARGIN, f64::to_radians)
            .max(min_tilt);
        AxisLimits {
            min_tilt,
            tilt,
            max_tilt: self.max_tilt_deg.to_radians().max(tilt),
            max_lead: self.max_lead_deg.to_radians(),
            step: self.search_step_deg.to_radians(),
        }
    }
}

/// Settings of a band's point milling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointSettings {
    /// Ball radius of the tool (mm).
    pub ball_radius: f64,
    /// Taper half angle of the tool (rad; 0 for a ball end).
    pub half_angle: f64,
    /// Material left on the blade side (mm).
    pub allowance_mm: f64,
    /// Material left on the hub (mm).
    pub hub_allowance_mm: f64,
    /// Target scallop height (mm).
    pub scallop_mm: f64,
    /// Largest distance of the ball-centre chord from the offset curve (mm).
    pub chord_mm: f64,
    /// How far below its allowance the ball may reach on the design (mm, ≥ 0).
    pub tol_mm: f64,
    /// Axis limits (rad).
    pub limits: AxisLimits,
    /// Largest turn of the axis between two postures (rad).
    pub max_axis_step: f64,
    /// Whether the axes of each run are smoothed once planned ([`smoothing`]).
    pub smooth_axes: bool,
}

/// One station: its contact and ball centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Side parameter u.
    pub u: f64,
    /// Side parameter v of the contact (above the pass's v where the ball rides up the root).
    pub v: f64,
    /// The contact frame.
    pub frame: Frame,
    /// Ball centre.
    pub centre: Vector3<f64>,
    /// Whether the contact rode up from the pass's line to keep the hub allowance.
    pub rode_up: bool,
}

/// One planned posture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    /// The contact.
    pub contact: Contact,
    /// Tilt and lead (rad).
    pub angles: (f64, f64),
    /// The posture.
    pub cl: CutterLocation,
    /// Clearances of the posture.
    pub clearance: PostureClearance,
}

/// A pass as planned: continuous runs of stations (a split between two runs needs a link).
#[derive(Debug, Clone, Default)]
pub struct PointPass {
    /// Index of the pass line from the band's upper edge.
    pub line: usize,
    /// Runs of stations in machining order.
    pub runs: Vec<Vec<Station>>,
    /// Stations left out (no ball position or no accessible axis).
    pub skipped: usize,
    /// Where the first station was left out (for notes): (u, v, reason).
    pub first_skip: Option<(f64, f64, &'static str)>,
    /// Motions split (not clear even through midpoints).
    pub split_motions: usize,
    /// Candidates tried beyond the first, over the pass.
    pub search_steps: usize,
    /// The axis smoothing of its runs ([`smoothing`]; empty when not asked for).
    pub smoothing: cam_plan::SmoothingSummary,
}

/// The plan of a band.
#[derive(Debug, Clone, Default)]
pub struct BandPlan {
    /// Passes from the shroud end of the band down, alternating direction.
    pub passes: Vec<PointPass>,
}

impl BandPlan {
    /// Every run of every pass in machining order.
    pub fn runs(&self) -> impl Iterator<Item = &Vec<Station>> {
        self.passes.iter().flat_map(|p| p.runs.iter())
    }

    /// Number of postures.
    pub fn postures(&self) -> usize {
        self.runs().map(Vec::len).sum()
    }

    /// Stations left out.
    pub fn skipped(&self) -> usize {
        self.passes.iter().map(|p| p.skipped).sum()
    }

    /// Motions split.
    pub fn split_motions(&self) -> usize {
        self.passes.iter().map(|p| p.split_motions).sum()
    }

    /// Candidates tried beyond the first.
    pub fn search_steps(&self) -> usize {
        self.passes.iter().map(|p| p.search_steps).sum()
    }

    /// The axis smoothing of every pass.
    pub fn smoothing(&self) -> cam_plan::SmoothingSummary {
        let mut s = cam_plan::SmoothingSummary::default();
        for p in &self.passes {
            s.merge(&p.smoothing);
        }
        s
    }

    /// Largest tilt and |lead| used (rad).
    pub fn largest_angles(&self) -> (f64, f64) {
        self.runs().flatten().fold((0.0f64, 0.0f64), |(b, l), s| {
            (b.max(s.angles.0), l.max(s.angles.1.abs()))
        })
    }
}

/// Share of the scallop height that the chord between two stations may leave where it runs
/// away from the side; the pass layout spaces the passes for the remaining share.
pub const CHORD_SCALLOP_SHARE: f64 = 0.2;
/// Bisections of the ride up the root and of skipped-station searches.
const RIDE_BISECTIONS: usize = 48;
/// Initial stations per mm of the pass's length at the band's middle line.
const STATIONS_PER_MM: f64 = 0.25;
/// Bisection depth of the chord and axis-step refinement between two stations.
const REFINE_DEPTH: u32 = 10;
/// Midpoint levels tried for a motion that is not clear.
const MOTION_DEPTH: u32 = 3;

/// Point milling of `band = (v_lo, v_hi)` of `side` of `blade` (module docs). `check` holds
/// the pass floors of the whole tool; `tool_r` is the ball radius of the posture query.
pub fn plan_band(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    side: Side,
    band: (f64, f64),
    settings: &PointSettings,
    check: &PassCheck<'_>,
) -> Result<BandPlan, FlankError> {
    let lines = layout::pass_lines(blade, side, band, settings)?;
    let passes: Vec<PointPass> = lines
        .par_iter()
        .enumerate()
        .map(|(k, line)| {
            let mut pass = plan_pass(ctx, blade, side, line, k % 2 == 1, settings, check)?;
            if settings.smooth_axes {
                pass.smoothing = smoothing::smooth_pass(
                    ctx,
                    check,
                    &mut pass,
                    settings.ball_radius,
                    settings.max_axis_step,
                );
            }
            Ok(pass)
        })
        .collect::<Result<_, FlankError>>()?;
    Ok(BandPlan { passes })
}

/// Whether the ball at `c` keeps the floor from the whole design (a concave corner sharper
/// than the ball, a neighbouring blade) and from the blade-root fillets when `check` holds
/// them ([`PassCheck::ball_keeps_fillets`]: a ball hanging over a fillet's end, beyond the
/// hub's rim, reaches into it where hub and side read it clear): it may reach at most `tol`
/// below the smaller allowance. One exact design distance, and the fillet bound near the
/// corner.
pub fn ball_fits(
    ctx: &PlanContext<'_>,
    c: &Contact,
    st: &PointSettings,
    check: &PassCheck<'_>,
) -> bool {
    let floor = st.allowance_mm.min(st.hub_allowance_mm) - st.tol_mm;
    let (d, _) = ctx
        .clearance
        .design_signed_distance(&Point3::from(c.centre));
    d - st.ball_radius >= floor && check.ball_keeps_fillets(&c.centre, floor)
}

/// The contact and ball centre at `(u, v)`, riding up toward `v_top` where the ball would
/// come nearer than `R + a_h` to the hub; `Err(reason)` when no ball position keeps the hub
/// allowance there. The ball against the rest of the design is [`ball_fits`].
pub fn contact_at(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    side: Side,
    (u, v): (f64, f64),
    v_top: f64,
    st: &PointSettings,
) -> Result<Contact, &'static str> {
    let s = blade.side(side);
    let r = st.ball_radius;
    let at = |v: f64| -> Option<(Vector3<f64>, Frame)> {
        let n = blade.outward_normal(side, u, v)?;
        let d = s.derivs2(u, v);
        let frame = Frame::new(n, d.sv)?;
        Some((d.p + n * (r + st.allowance_mm), frame))
    };
    let hub_gap = |c: &Vector3<f64>| {
        ctx.clearance.hub_signed_distance(&Point3::from(*c)) - (r + st.hub_allowance_mm)
    };
    let (mut centre, mut frame) = at(v).ok_or("no normal")?;
    let mut v_c = v;
    let mut rode_up = false;
    if hub_gap(&centre) < 0.0 {
        // Ride up the side until the ball keeps the hub allowance.
        let (mut lo, mut hi) = (v, v_top);
        let top = at(hi).ok_or("no normal")?;
        if hub_gap(&top.0) < 0.0 {
            return Err("the ball does not fit between hub and side");
        }
        for _ in 0..RIDE_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            match at(mid) {
                Some((c, _)) if hub_gap(&c) >= 0.0 => hi = mid,
                _ => lo = mid,
            }
        }
        let (c, f) = at(hi).ok_or("no normal")?;
        centre = c;
        frame = f;
        v_c = hi;
        rode_up = true;
    }
    Ok(Contact {
        u,
        v: v_c,
        frame,
        centre,
        rode_up,
    })
}

/// The stations of one pass line (module docs): contacts, chord and axis-step refinement,
/// axis search, motion certificates. `reverse` runs it trailing → leading edge.
#[allow(clippy::too_many_arguments)]
fn plan_pass(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    side: Side,
    line: &layout::PassLine,
    reverse: bool,
    st: &PointSettings,
    check: &PassCheck<'_>,
) -> Result<PointPass, FlankError> {
    let s = blade.side(side);
    let (_, (_, v_max)) = s.domain();
    let (u0, u1) = line.u_range();
    let mut pass = PointPass {
        line: line.index,
        ..PointPass::default()
    };
    // Initial stations: uniform in u, about one per 4 mm of the line.
    let length = line.length(blade, side);
    let n0 = ((length * STATIONS_PER_MM).ceil() as usize).clamp(8, 2000);
    let mut us: Vec<f64> = (0..=n0)
        .map(|i| u0 + (u1 - u0) * i as f64 / n0 as f64)
        .collect();
    if reverse {
        us.reverse();
    }
    let contact = |u: f64| contact_at(ctx, blade, side, (u, line.v_at(u)), v_max, st);
    // How far the ball centre `c` keeps from the hub beyond the ball radius and the hub
    // allowance (negative: the ball would cut below the hub allowance).
    let hub_gap = |c: &Vector3<f64>| {
        ctx.clearance.hub_signed_distance(&Point3::from(*c))
            - (st.ball_radius + st.hub_allowance_mm)
    };
    // Contacts with chord refinement.
    let mut contacts: Vec<Result<Contact, (f64, &'static str)>> = Vec::new();
    let first = contact(us[0]).map_err(|e| (us[0], e));
    contacts.push(first);
    for w in us.windows(2) {
        let b = contact(w[1]).map_err(|e| (w[1], e));
        let a = *contacts.last().unwrap_or(&b);
        refine_between(&contact, &hub_gap, &a, &b, st, 0, &mut contacts);
        contacts.push(b);
    }
    // Axes along the pass.
    let mut prev = (st.limits.tilt, 0.0);
    let mut run: Vec<Station> = Vec::new();
    let mut stations: Vec<Option<Station>> = Vec::with_capacity(contacts.len());
    for c in &contacts {
        let c = match c {
            Ok(c) if !ball_fits(ctx, c, st, check) => Err((c.u, "the ball would cut the design")),
            other => *other,
        };
        match &c {
            Ok(c) => {
                match axis::search(
                    check,
                    &c.frame,
                    &c.centre,
                    st.ball_radius,
                    &st.limits,
                    prev,
                    |a| ctx.reaches(a),
                ) {
                    Some(f) => {
                        pass.search_steps += f.tried - 1;
                        prev = f.angles;
                        stations.push(Some(Station {
                            contact: *c,
                            angles: f.angles,
                            cl: f.cl,
                            clearance: f.clearance,
                        }));
                    }
                    None => {
                        pass.skipped += 1;
                        pass.first_skip
                            .get_or_insert((c.u, c.v, "no accessible tool axis"));
                        stations.push(None);
                    }
                }
            }
            Err((u, why)) => {
                pass.skipped += 1;
                pass.first_skip.get_or_insert((*u, line.v_at(*u), why));
                stations.push(None);
            }
        }
    }
    // Runs, with the axis step limited and every motion certified.
    for st_k in stations {
        let Some(b) = st_k else {
            if !run.is_empty() {
                pass.runs.push(std::mem::take(&mut run));
            }
            continue;
        };
        if let Some(a) = run.last().copied() {
            let mut inserted = Vec::new();
            let ok = connect(
                ctx,
                blade,
                side,
                line,
                v_max,
                st,
                check,
                &a,
                &b,
                0,
                &mut inserted,
            );
            if ok {
                run.extend(inserted);
            } else {
                pass.split_motions += 1;
                pass.runs.push(std::mem::take(&mut run));
            }
        }
        run.push(b);
    }
    if !run.is_empty() {
        pass.runs.push(run);
    }
    Ok(pass)
}

/// Inserts contacts between `a` and `b` (depth-first, in order) while the chord between
/// their ball centres strays from the offset curve halfway by more than `chord_mm` toward
/// the side (where the straight move would cut into it), by more than the scallop height
/// away from it (where it would only leave material), dips more than `chord_mm` below the
/// hub's offset by the ball radius and hub allowance (`hub_gap` < −`chord_mm` at the
/// chord's midpoint: where the balls ride along the hub, a chord over a hub that bulges
/// toward it cuts into the hub), or the normal turns more than `max_axis_step`.
fn refine_between(
    contact: &impl Fn(f64) -> Result<Contact, &'static str>,
    hub_gap: &impl Fn(&Vector3<f64>) -> f64,
    a: &Result<Contact, (f64, &'static str)>,
    b: &Result<Contact, (f64, &'static str)>,
    st: &PointSettings,
    depth: u32,
    out: &mut Vec<Result<Contact, (f64, &'static str)>>,
) {
    let (Ok(ca), Ok(cb)) = (a, b) else {
        return;
    };
    if depth >= REFINE_DEPTH {
        return;
    }
    let um = 0.5 * (ca.u + cb.u);
    let m = contact(um).map_err(|e| (um, e));
    let needs = match &m {
        Ok(cm) => {
            let (p, a0, b0) = (cm.centre, ca.centre, cb.centre);
            let ab = b0 - a0;
            let t = if ab.norm_squared() > 0.0 {
                ((p - a0).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let e = p - (a0 + ab * t);
            // The offset curve bulges away from the side: the chord runs inside it, toward
            // the side (an overcut risk); otherwise away from it (a residual, kept to a
            // share of the scallop: the layout leaves the rest to the cusps between passes).
            let limit = if e.dot(&cm.frame.n) > 0.0 {
                st.chord_mm
            } else {
                st.chord_mm.max(CHORD_SCALLOP_SHARE * st.scallop_mm)
            };
            let turn = ca.frame.n.angle(&cb.frame.n);
            let into_hub = hub_gap(&((a0 + b0) * 0.5)) < -st.chord_mm;
            e.norm() > limit || turn > st.max_axis_step || into_hub
        }
        Err(_) => true,
    };
    if !needs {
        return;
    }
    refine_between(contact, hub_gap, a, &m, st, depth + 1, out);
    out.push(m);
    refine_between(contact, hub_gap, &m, b, st, depth + 1, out);
}

/// Whether the motion `a → b` can be made: directly when the whole tool keeps the floors
/// along it and the axis turns at most `max_axis_step`, else through midpoint stations
/// (pushed to `out` in order; at most [`MOTION_DEPTH`] levels).
#[allow(clippy::too_many_arguments)]
fn connect(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    side: Side,
    line: &layout::PassLine,
    v_top: f64,
    st: &PointSettings,
    check: &PassCheck<'_>,
    a: &Station,
    b: &Station,
    depth: u32,
    out: &mut Vec<Station>,
) -> bool {
    let turn = a.cl.axis.angle(&b.cl.axis);
    if turn <= st.max_axis_step + 1e-12
        && check
            .motion(0, (&a.cl, &a.clearance), (&b.cl, &b.clearance))
            .is_none()
    {
        return true;
    }
    if depth >= MOTION_DEPTH {
        return false;
    }
    let um = 0.5 * (a.contact.u + b.contact.u);
    let Ok(c) = contact_at(ctx, blade, side, (um, line.v_at(um)), v_top, st) else {
        return false;
    };
    if !ball_fits(ctx, &c, st, check) {
        return false;
    }
    let prev = (
        0.5 * (a.angles.0 + b.angles.0),
        0.5 * (a.angles.1 + b.angles.1),
    );
    let Some(f) = axis::search(
        check,
        &c.frame,
        &c.centre,
        st.ball_radius,
        &st.limits,
        prev,
        |a| ctx.reaches(a),
    ) else {
        return false;
    };
    let m = Station {
        contact: c,
        angles: f.angles,
        cl: f.cl,
        clearance: f.clearance,
    };
    if !connect(
        ctx,
        blade,
        side,
        line,
        v_top,
        st,
        check,
        a,
        &m,
        depth + 1,
        out,
    ) {
        return false;
    }
    out.push(m);
    connect(
        ctx,
        blade,
        side,
        line,
        v_top,
        st,
        check,
        &m,
        b,
        depth + 1,
        out,
    )
}
