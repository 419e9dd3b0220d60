//! The `flank_semi_finishing` operation: sub-ruled strips (paper 001 §4, "Generation of the
//! sub-ruled surface blades" and the semi-finishing it enables).
//!
//! A free-form blade side is not a ruled surface, so one flank pass cannot follow it; but a
//! narrow strip of it between two isoparametric lines `v = a, v = b` is within a tolerance of
//! the ruled surface through those lines. For each side:
//!
//! 1. strips: [`impeller_model::ruled::sub_ruled_strips`] within `strip_tol_mm` (greedy from
//!    the shroud down; each strip's measured deviation kept);
//! 2. one flank pass per strip, the strip nearest the shroud first: at `passes_along`
//!    rulings the cutter axis is tangent, at the strip's two edge points, to the ruled
//!    surface offset by the blade allowance (two-point tangency with the cutter's own radius
//!    at each contact height), the strip's lower edge at the ball-centre height, the axis
//!    then moved away from any interior point of the ruling that comes nearer than the
//!    allowance (a twisted ruling turns away from the cutter's line; [`tangency_station`]);
//!    more rulings wherever the straight moves of the written pass would leave that solution
//!    by more than the job's `chord_tol` ([`pass_stations`]: around a rounded leading edge);
//! 3. interference check: the design side below the strip (the lower strips, still carrying
//!    their allowance) and the hub must stay at least `allowance − strip_tol` from the pass's
//!    swept envelope ([`cam_core::SweptEnvelope`], certified distances), and every ball
//!    centre its hub allowance less `strip_tol` from the hub body; a pass that comes nearer
//!    is lifted along its axes by bisection until it keeps that distance ([`strip_pass`]).
//!    The pass is then checked for its whole tool against the whole design
//!    ([`crate::regions`]); a strip whose pass is not clear is point-milled instead. Its
//!    tool axes are then made monotone about the impeller axis where the strip tolerance
//!    allows ([`crate::regions::smooth_flank_region`]: overcut not grown, clearance
//!    re-checked; the direction changes left reported as kept for accuracy);
//! 4. baseline: isoparametric point milling of the same side with the same tool: zig-zag
//!    passes along u, step-over across for the scallop height `h` equal to `strip_tol_mm`
//!    (`w = 2√(2Rh − h²)` between passes on a locally flat side, R the ball radius); its path
//!    length is the sum of the pass lengths and step-overs (arc lengths from 200-point
//!    polylines).
//!
//! Both rows are semi-finished (`rows`). Metrics: `sub_ruled_strips` (over every side of
//! both rows), `max_deviation_mm` (largest strip deviation), `point_milling_path_length_mm`,
//! `flank_path_length_mm` and `point_path_length_mm` (one blade of each row),
//! `interference_lifts` (passes lifted) and the region metrics of [`crate::regions`].
//! Complexity per side: the strip search (impeller-model) plus O(strips · passes_along ·
//! samples) envelope queries, the whole-tool checks and the point milling of what is not
//! flanked.

use crate::geometry::{ball_radius, guides_through, member_radius};
use crate::point::{AxisParams, PointSettings};
use crate::regions::{self, Method, MethodChoice, SideSettings};
use crate::rows::RowName;
use crate::{FlankError, FLANK_SEMI_FINISHING};
use cam_core::{CutterShape, EnvelopeOptions, Point3, SphereFamily, SweptEnvelope, Vector3};
use cam_plan::{Metrics, Operation, OperationSpec, PlanContext, PlanError, PlannedOperation};
use impeller_model::{Blade, Side};
use serde::Deserialize;

fn default_tol() -> f64 {
    0.1
}
fn default_along() -> usize {
    30
}

/// The kind's own keys (job file, `[[operations]]` of kind `flank_semi_finishing`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SemiParams {
    /// Semi-finish tolerance: largest deviation of a strip from its ruled surface, and the
    /// scallop height of the point-milling baseline (mm, default 0.1).
    #[serde(default = "default_tol")]
    pub strip_tol_mm: f64,
    /// Cutter locations per pass (default 30).
    #[serde(default = "default_along")]
    pub passes_along: usize,
    /// Blade rows semi-finished: `["main", "splitter"]` (default: both rows the impeller
    /// has).
    #[serde(default)]
    pub rows: Option<Vec<RowName>>,
    /// `auto` (default: flank passes where clear, point milling elsewhere), `flank` or
    /// `point`.
    #[serde(default = "default_method")]
    pub method: MethodChoice,
    // The axis keys of `point::AxisParams`, spelled out: serde cannot flatten a struct into
    // one with `deny_unknown_fields`, and a misspelt key must stay an error.
    /// Preferred tilt of the point-milling axis from the side (deg; see
    /// [`AxisParams`]).
    #[serde(default)]
    pub tilt_deg: Option<f64>,
    /// Largest tilt searched (deg, default 60).
    #[serde(default = "default_max_tilt")]
    pub max_tilt_deg: f64,
    /// Largest lead searched (deg, default 30).
    #[serde(default = "default_max_lead")]
    pub max_lead_deg: f64,
    /// Step of the accessibility search (deg, default 3).
    #[serde(default = "default_search_step")]
    pub search_step_deg: f64,
    /// Largest turn of the axis between two postures (deg, default 3).
    #[serde(default = "default_axis_step")]
    pub max_axis_step_deg: f64,
}

impl SemiParams {
    /// The point-milling axis keys.
    pub fn axis(&self) -> AxisParams {
        AxisParams {
            tilt_deg: self.tilt_deg,
            max_tilt_deg: self.max_tilt_deg,
            max_lead_deg: self.max_lead_deg,
            search_step_deg: self.search_step_deg,
            max_axis_step_deg: self.max_axis_step_deg,
        }
    }
}

fn default_max_tilt() -> f64 {
    AxisParams::default().max_tilt_deg
}
fn default_max_lead() -> f64 {
    AxisParams::default().max_lead_deg
}
fn default_search_step() -> f64 {
    AxisParams::default().search_step_deg
}
fn default_axis_step() -> f64 {
    AxisParams::default().max_axis_step_deg
}

fn default_method() -> MethodChoice {
    MethodChoice::Auto
}

/// The operation.
#[derive(Debug, Clone)]
pub struct FlankSemiFinishing {
    name: String,
    tool: String,
    params: SemiParams,
}

/// Builds a `flank_semi_finishing` operation from its job table.
pub fn build_flank_semi_finishing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let params: SemiParams = cam_plan::params::parse(spec)?;
    if !(params.strip_tol_mm.is_finite() && params.strip_tol_mm > 0.0) {
        return Err(PlanError::param(&spec.name, "strip_tol_mm", "must be > 0"));
    }
    params.axis().validate().map_err(|e| e.plan(&spec.name))?;
    if !(4..=500).contains(&params.passes_along) {
        return Err(PlanError::param(
            &spec.name,
            "passes_along",
            "must be in 4..=500",
        ));
    }
    Ok(Box::new(FlankSemiFinishing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params,
    }))
}

/// Bisection steps of the interference lift (the bracket is the strip height; 30 halvings
/// leave < 1e-7 of it).
const LIFT_BISECTIONS: usize = 30;
/// Fixed-point rounds of [`tangency_station`] (contact heights and offsets across the axis).
const TANGENCY_ROUNDS: usize = 6;
/// Interior points of a ruling checked against the cutter by [`tangency_station`] (the
/// ruling split into this many parts).
const RULING_CHECKS: usize = 8;
/// Rounds of the interior-point correction of [`tangency_station`].
const GOUGE_ROUNDS: usize = 4;
/// Missing clearance below which an interior point counts as kept (mm).
const CLEARANCE_SLACK_MM: f64 = 1e-6;
/// Most stations of one pass (the chord refinement of [`pass_stations`] stops there).
pub const MAX_STATIONS: usize = 4000;
/// Smallest station interval, as a fraction of the side's u range (the chord refinement
/// of [`pass_stations`] does not halve below it).
pub const MIN_STATION_DU: f64 = 1e-6;
/// Samples across and along the design side below a strip for the interference check.
const CHECK_GRID: (usize, usize) = (24, 6);
/// Points of the polylines measuring isocurve lengths for the baseline.
const LENGTH_POINTS: usize = 200;

impl Operation for FlankSemiFinishing {
    fn kind(&self) -> &'static str {
        FLANK_SEMI_FINISHING
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        self.plan_inner(ctx).map_err(|e| e.plan(&self.name))
    }
}

/// A cutter location of a strip's flank pass at side parameter `u`: two-point tangency with
/// the side offset by the allowance at the strip's edges `v = a` (at the ball-centre height)
/// and `v = b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    /// Side parameter u.
    pub u: f64,
    /// Ball centre.
    pub centre: Vector3,
    /// Unit axis.
    pub axis: Vector3,
    /// Height of the upper contact above the tip (mm).
    pub upper_contact: f64,
}

/// The [`Station`] at `u` of the strip `v ∈ [a, b]` of `side`: the cutter axis through the
/// offset points `p(u, a) + n·(ρ(h_a) + allowance)` and `p(u, b) + n·(ρ(h_b) + allowance)`
/// (ρ the cutter's radius at the contact height; `n` the side normal's part across the
/// axis), the lower contact at the ball-centre height; [`TANGENCY_ROUNDS`] fixed-point
/// rounds for the contact heights and the axis. O(1).
pub fn tangency_station(
    blade: &Blade,
    side: Side,
    (a, b): (f64, f64),
    shape: &CutterShape,
    allowance: f64,
    u: f64,
) -> Result<Station, FlankError> {
    let s = blade.side(side);
    let r = ball_radius(shape);
    let (pa, pb) = (s.point(u, a), s.point(u, b));
    let normal = |v: f64| {
        blade
            .outward_normal(side, u, v)
            .ok_or_else(|| FlankError::Geometry(format!("{side:?}: no normal at u = {u}")))
    };
    let (na, nb) = (normal(a)?, normal(b)?);
    let (mut ha, mut hb) = (r, r + (pb - pa).norm());
    let mut axis = (pb - pa).normalize();
    let mut tip = pa;
    // Each contact point is offset across the axis: along the part of its normal normal to
    // the axis, so the axis passes at ρ + allowance from it. (Along the normal itself the
    // distance would be only (ρ + allowance)·cos β where the normal leans by β along the
    // axis, as it does around a swept leading edge: with ρ = 6 mm and β = 20° the cutter
    // would reach 0.17 mm into the allowance.)
    let across = |n: &Vector3, axis: &Vector3| {
        let m = n - axis * n.dot(axis);
        let len = m.norm();
        if len > 1e-9 {
            m / len
        } else {
            *n
        }
    };
    for _ in 0..TANGENCY_ROUNDS {
        let qa = pa + across(&na, &axis) * (member_radius(shape, ha) + allowance);
        let qb = pb + across(&nb, &axis) * (member_radius(shape, hb) + allowance);
        axis = (qb - qa).normalize();
        tip = qa - axis * r;
        ha = r;
        hb = (qb - tip).dot(&axis);
    }
    // Between the two contacts a twisted ruling turns away from the cutter's line (the
    // normal of a non-developable side rotates along the ruling): around a swept leading
    // edge the cutter tangent at both ends reached 0.3 mm into the allowance halfway along.
    // The ruling's interior points are measured against the cutter and the axis is moved
    // away from the deepest by the missing clearance until each keeps the allowance.
    for _ in 0..GOUGE_ROUNDS {
        let mut worst: Option<(f64, Vector3)> = None;
        for k in 1..RULING_CHECKS {
            let v = a + (b - a) * k as f64 / RULING_CHECKS as f64;
            let p = s.point(u, v);
            let d = p - tip;
            let h = d.dot(&axis);
            let radial = d - axis * h;
            let w = radial.norm();
            if w <= 1e-9 {
                continue;
            }
            let missing = member_radius(shape, h.max(r)) + allowance - w;
            if missing > worst.map_or(CLEARANCE_SLACK_MM, |x| x.0) {
                worst = Some((missing, -radial / w));
            }
        }
        match worst {
            Some((missing, away)) => tip += away * missing,
            None => break,
        }
    }
    Ok(Station {
        u,
        centre: tip + axis * r,
        axis,
        upper_contact: hb,
    })
}

/// Largest distance, at the ball centre and at the higher upper contact, between the
/// station `mid` and the straight move from `s0` to `s1` halfway along it (the written pass
/// moves linearly between its locations).
pub fn chord_deviation(s0: &Station, mid: &Station, s1: &Station, ball_radius: f64) -> f64 {
    let h = s0
        .upper_contact
        .max(s1.upper_contact)
        .max(mid.upper_contact)
        - ball_radius;
    let at = |st: &Station| st.centre + st.axis * h;
    let e_ball = (mid.centre - 0.5 * (s0.centre + s1.centre)).norm();
    let e_top = (at(mid) - 0.5 * (at(s0) + at(s1))).norm();
    e_ball.max(e_top)
}

/// The stations of a strip's flank pass: `even` stations evenly spaced in u over the side,
/// and more wherever the straight move between two stations would leave the tangency
/// solution by more than `chord_mm` ([`chord_deviation`] halfway between them): such an
/// interval is halved until they agree, down to [`MIN_STATION_DU`] of the u range and at
/// most [`MAX_STATIONS`] stations. Around a rounded leading edge the side's normal turns
/// through 180° between two even stations: there the straight move cut 0.75 mm into the
/// nose of an imported 12 + 12 impeller. Cost: O(stations) tangency solves.
pub fn pass_stations(
    blade: &Blade,
    side: Side,
    strip: (f64, f64),
    shape: &CutterShape,
    allowance: f64,
    even: usize,
    chord_mm: f64,
) -> Result<Vec<Station>, FlankError> {
    let ((u0, u1), _) = blade.side(side).domain();
    let r = ball_radius(shape);
    let chord = chord_mm.max(1e-4);
    let even = even.max(2);
    let mut out: Vec<Station> = (0..even)
        .map(|i| {
            let u = u0 + (u1 - u0) * i as f64 / (even - 1) as f64;
            tangency_station(blade, side, strip, shape, allowance, u)
        })
        .collect::<Result<_, _>>()?;
    let mut k = 0;
    while k + 1 < out.len() && out.len() < MAX_STATIONS {
        let (s0, s1) = (out[k], out[k + 1]);
        if s1.u - s0.u <= MIN_STATION_DU * (u1 - u0) {
            k += 1;
            continue;
        }
        let mid = tangency_station(blade, side, strip, shape, allowance, 0.5 * (s0.u + s1.u))?;
        if chord_deviation(&s0, &mid, &s1, r) > chord {
            out.insert(k + 1, mid);
        } else {
            k += 1;
        }
    }
    Ok(out)
}

/// One flank pass over a strip.
#[derive(Debug, Clone)]
pub struct StripPass {
    /// The written cutter locations.
    pub locations: Vec<cam_core::CutterLocation>,
    /// Whether the pass was lifted along its axes.
    pub lifted: bool,
    /// The swept envelope of the pass (its tool surface, for measurements).
    pub envelope: SweptEnvelope,
    /// Height of the envelope's upper guide above the ball centres (mm; the highest contact).
    pub upper_mm: f64,
}

/// The swept envelope of a strip pass written at `locations`: the sphere family of `shape`
/// along the guides through the ball centres and the axis points `upper` above them, as
/// [`strip_pass`] builds it (so the envelope of its own locations is its own envelope).
/// O(locations).
pub fn pass_envelope(
    shape: &CutterShape,
    flute_length: f64,
    locations: &[cam_core::CutterLocation],
    upper: f64,
) -> Result<SweptEnvelope, FlankError> {
    let r = ball_radius(shape);
    let family = SphereFamily::from_shape(shape, flute_length)?;
    let c: Vec<Vector3> = locations
        .iter()
        .map(|l| l.tip.coords + l.axis.into_inner() * r)
        .collect();
    let t: Vec<Vector3> = c
        .iter()
        .zip(locations)
        .map(|(c, l)| c + l.axis.into_inner() * upper)
        .collect();
    let (g0, g1) = guides_through(&c, &t)?;
    Ok(SweptEnvelope::new(
        family,
        g0,
        g1,
        r,
        EnvelopeOptions::default(),
    )?)
}

fn polyline_length(pts: &[Vector3]) -> f64 {
    pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Path length of isoparametric zig-zag point milling of `side` between `v_range` with a
/// ball of radius `r` at scallop height `h` (module docs).
pub fn point_milling_length(blade: &Blade, side: Side, v_range: (f64, f64), r: f64, h: f64) -> f64 {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let m = LENGTH_POINTS;
    // Widest extent across (largest v-isocurve length over u).
    let across = (0..=10)
        .map(|i| {
            let u = u0 + (u1 - u0) * i as f64 / 10.0;
            let pts: Vec<Vector3> = (0..m)
                .map(|j| {
                    s.point(
                        u,
                        v_range.0 + (v_range.1 - v_range.0) * j as f64 / (m - 1) as f64,
                    )
                })
                .collect();
            polyline_length(&pts)
        })
        .fold(0.0, f64::max);
    let h = h.min(r);
    let step = 2.0 * (2.0 * r * h - h * h).sqrt();
    let passes = (across / step).ceil() as usize + 1;
    let mut total = 0.0;
    let mut prev_end: Option<Vector3> = None;
    for k in 0..passes {
        let v = v_range.0 + (v_range.1 - v_range.0) * k as f64 / (passes - 1).max(1) as f64;
        let mut pts: Vec<Vector3> = (0..m)
            .map(|j| s.point(u0 + (u1 - u0) * j as f64 / (m - 1) as f64, v))
            .collect();
        if k % 2 == 1 {
            pts.reverse();
        }
        total += polyline_length(&pts);
        if let (Some(e), Some(f)) = (prev_end, pts.first()) {
            total += (f - e).norm();
        }
        prev_end = pts.last().copied();
    }
    total
}

impl FlankSemiFinishing {
    fn plan_inner(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, FlankError> {
        let p = &self.params;
        let cutter = &ctx.tool.cutter;
        let shape = cutter.shape;
        let r = ball_radius(&shape);
        let half_angle = match shape {
            CutterShape::BallEnd { .. } => 0.0,
            CutterShape::TaperedBallEnd { half_angle, .. } => half_angle,
            other => {
                return Err(FlankError::Param(format!(
                    "flank semi-finishing needs a ball or tapered ball end, not {other:?}"
                )))
            }
        };
        let row_list = match &p.rows {
            Some(names) => crate::rows::rows_of(ctx.impeller, names, true)?,
            None => crate::rows::rows_of(ctx.impeller, &crate::rows::default_rows(), false)?,
        };
        let settings = SideSettings {
            choice: p.method,
            strip_tol_mm: p.strip_tol_mm,
            passes_along: p.passes_along,
            flank_residual_mm: None,
            smooth_flank_axes: true,
            point: PointSettings {
                ball_radius: r,
                half_angle,
                allowance_mm: ctx.process.blade_allowance_mm,
                hub_allowance_mm: ctx.process.hub_allowance_mm,
                scallop_mm: p.strip_tol_mm,
                chord_mm: ctx.tolerances.chord_tol,
                tol_mm: p.strip_tol_mm,
                limits: p.axis().limits(half_angle),
                max_axis_step: p.max_axis_step_deg.to_radians(),
                smooth_axes: true,
            },
        };
        let plan = regions::plan_rows(ctx, &self.name, &self.tool, &row_list, &settings)?;
        let mut baseline = 0.0;
        for &row in &row_list {
            let blade = crate::rows::blade_set(ctx.impeller, row)?.blade().clone();
            for side in [Side::Pressure, Side::Suction] {
                let v_range = regions::side_v_range(ctx, &blade, side)?;
                baseline += point_milling_length(&blade, side, v_range, r, p.strip_tol_mm);
            }
        }
        let flank_len: f64 = plan
            .regions()
            .filter(|g| g.method != Method::Point)
            .flat_map(|g| g.runs.iter())
            .map(|run| {
                run.windows(2)
                    .map(|w| (w[1].tip - w[0].tip).norm())
                    .sum::<f64>()
            })
            .sum();
        let point_len: f64 = plan
            .regions()
            .filter(|g| g.method == Method::Point)
            .flat_map(|g| g.runs.iter())
            .map(|run| {
                run.windows(2)
                    .map(|w| (w[1].tip - w[0].tip).norm())
                    .sum::<f64>()
            })
            .sum();
        let mut m = Metrics::new();
        m.count(
            "sub_ruled_strips",
            plan.sides.iter().map(|(_, _, s)| s.strips).sum(),
        );
        m.number(
            "max_deviation_mm",
            plan.sides
                .iter()
                .map(|(_, _, s)| s.max_strip_deviation_mm)
                .fold(0.0, f64::max),
        );
        m.number("point_milling_path_length_mm", baseline);
        m.number("flank_path_length_mm", flank_len);
        m.number("point_path_length_mm", point_len);
        plan.metrics(&mut m);
        m.text(
            "rows",
            row_list
                .iter()
                .map(|r| crate::rows::label(*r))
                .collect::<Vec<_>>()
                .join(", "),
        );
        // Issue 37: the axis smoothing of the flank passes and the point-milling runs,
        // counted over every blade.
        let smoothing = plan.smoothing(ctx.impeller)?;
        smoothing.add_metrics(&mut m);
        let lifts = plan.regions().filter(|g| g.lifted).count();
        let mut notes = plan.notes();
        notes.push(format!(
            "flank passes: {} (about the ball centre, within the strip tolerance's slack, the \
             smoothed pass measured again)",
            smoothing.note()
        ));
        if lifts > 0 {
            notes.push(format!(
                "{lifts} pass(es) lifted along the axis to keep the allowance on the strips \
                 below and the hub"
            ));
        }
        let point_regions = plan.regions().filter(|g| g.method == Method::Point).count();
        if point_regions > 0 {
            notes.push(format!(
                "{point_regions} region(s) point-milled where no flank pass is clear: {}",
                plan.regions()
                    .filter(|g| g.method == Method::Point)
                    .map(|g| format!(
                        "{} {:?} v {:.3}–{:.3} ({})",
                        crate::rows::label(g.row),
                        g.side,
                        g.v_range.0,
                        g.v_range.1,
                        g.reason
                    ))
                    .collect::<Vec<_>>()
                    .join("; ")
            ));
        }
        Ok(PlannedOperation {
            paths: plan.paths,
            metrics: m,
            plots: smoothing.plot().into_iter().collect(),
            notes,
        })
    }
}

/// The points `points` moved by `lift` along their tool axes `axes`.
fn along_axes(points: &[Vector3], axes: &[Vector3], lift: f64) -> Vec<Vector3> {
    points
        .iter()
        .zip(axes)
        .map(|(c, ax)| c + ax * lift)
        .collect()
}

/// The flank pass of one strip (module docs, steps 2–3): stations along the strip at
/// `passes_along` even rulings plus the chord refinement, lifted along the axes where the
/// side below the strip (keeping `allowance − strip_tol`) or the hub under the balls would
/// be cut. The pass is not checked against the rest of the design here (the caller does,
/// with [`cam_plan::PassCheck`]).
#[allow(clippy::too_many_arguments)]
pub fn strip_pass(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    side: Side,
    strip: &impeller_model::ruled::RuledStrip,
    v_range: (f64, f64),
    allowance: f64,
    passes_along: usize,
    strip_tol: f64,
) -> Result<StripPass, FlankError> {
    let cutter = &ctx.tool.cutter;
    let shape = cutter.shape;
    let r = ball_radius(&shape);
    let n = passes_along;
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let (a, b) = strip.v_range;
    let chord = ctx.tolerances.chord_tol;
    let stations = pass_stations(blade, side, (a, b), &shape, allowance, n, chord)?;
    let mut centres = Vec::with_capacity(stations.len());
    let mut tops = Vec::with_capacity(stations.len());
    let mut upper: f64 = 0.0;
    let mut axes = Vec::with_capacity(stations.len());
    for st in stations {
        upper = upper.max(st.upper_contact - r);
        centres.push(st.centre);
        axes.push(st.axis);
    }
    let upper = upper.max(r);
    for (c, ax) in centres.iter().zip(&axes) {
        tops.push(c + ax * upper);
    }
    // Interference check points: the side below the strip and the hub under the pass.
    let mut checks: Vec<(Point3, f64)> = Vec::new();
    let (cu, cv) = CHECK_GRID;
    if a > v_range.0 + 1e-9 {
        for i in 0..cu {
            let u = u0 + (u1 - u0) * i as f64 / (cu - 1) as f64;
            for j in 0..cv {
                let v = v_range.0 + (a - v_range.0) * j as f64 / (cv - 1) as f64;
                let q = s.point(u, v);
                if ctx.impeller.hub().signed_distance(&q) > r {
                    checks.push((Point3::from(q), allowance));
                }
            }
        }
    }
    for c in &centres {
        // The hub point below each ball centre.
        let hub = ctx.impeller.hub();
        let (t, phi, _) = hub.closest(c);
        checks.push((
            Point3::from(hub.point(t, phi)),
            ctx.process.hub_allowance_mm,
        ));
    }
    let tol = strip_tol;
    let family = SphereFamily::from_shape(&shape, cutter.flute_length)?;
    let fits = |lift: f64| -> Result<bool, FlankError> {
        let c = along_axes(&centres, &axes, lift);
        let t = along_axes(&tops, &axes, lift);
        // The ball against the hub body (exact: its centre's distance), wherever the
        // closest hub point below it is not the nearest part of the hub body (over the
        // inlet corner of the hub).
        let hub_keep = ctx.process.hub_allowance_mm - tol;
        if c.iter()
            .any(|c| ctx.clearance.hub_signed_distance(&Point3::from(*c)) - r < hub_keep)
        {
            return Ok(false);
        }
        let (g0, g1) = guides_through(&c, &t)?;
        let env = SweptEnvelope::new(family.clone(), g0, g1, r, EnvelopeOptions::default())?;
        let mut hint = None;
        for (q, keep) in &checks {
            let d = env.signed_distance(q, hint)?;
            hint = Some(d.param);
            if d.distance < keep - tol {
                return Ok(false);
            }
        }
        Ok(true)
    };
    let mut lift = 0.0;
    let mut lifted = false;
    if !fits(0.0)? {
        lifted = true;
        let (mut lo, mut hi) = (0.0, upper);
        if !fits(hi)? {
            return Err(FlankError::Geometry(format!(
                "{side:?} side: the pass of strip v ∈ [{a:.4}, {b:.4}] interferes below \
                 even when lifted by the strip height"
            )));
        }
        for _ in 0..LIFT_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if fits(mid)? {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lift = hi;
    }
    let c = along_axes(&centres, &axes, lift);
    let t = along_axes(&tops, &axes, lift);
    let (g0, g1) = guides_through(&c, &t)?;
    let env = SweptEnvelope::new(family, g0, g1, r, EnvelopeOptions::default())?;
    // The guides interpolate the stations at uniform parameters: station i at i/(m − 1).
    let (lo, hi) = env.domain();
    let m = centres.len();
    let locations = (0..m)
        .map(|i| env.cutter_location(lo + (hi - lo) * i as f64 / (m - 1) as f64))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(StripPass {
        locations,
        lifted,
        envelope: env,
        upper_mm: upper,
    })
}
