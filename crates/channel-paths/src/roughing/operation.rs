//! The `channel_roughing` operation: the channel between the approximated ruled blades
//! roughed level by level from the shroud down to the hub, each level planned with triangle
//! paths (paper 001 §3) in the areas of paper 003 (upstream of the splitter's leading edge and
//! the two sub-channels beside the splitter).
//!
//! Per channel (channel 0, copied to every channel by rotation):
//! 1. On each level every bounding blade side is replaced by its ruled approximation
//!    ([`impeller_model::ruled::ruled_approximation`]) over the span band that the level's
//!    slab reaches (side parameters v from the side's lowest crossing with the level to its
//!    highest crossing with the level above, the shroud edge for the first level), pushed out
//!    by that band's allowance so that it contains the true side there ("blade with
//!    thickness"), and offset by the cutter radius plus the process' blade allowance:
//!    `δ = R + blade_allowance + ruled allowance`. One ruled surface over the whole span
//!    deviates from a strongly twisted free-form side by more than the channel is wide
//!    (7.6–7.9 mm on impeller-11+11-freeform, whose hub channel is 3.9 mm wide: no level was
//!    left); paper 001 splits the approximated ruled blade along the span for the same
//!    reason. Each ruling is prolonged beyond both edges by `δ` plus one depth of cut
//!    ([`impeller_model::ruled::prolong_rulings`]): the offset moves a side leaning from the
//!    hub or shroud normal up to `δ` along it, and the offset edge then missed the hub level
//!    (impeller-5-freeform).
//! 2. Levels: `n = ⌈max depth / depth_of_cut⌉` interpolated levels between the shroud
//!    (excluded) and the hub offset by the hub allowance (the last level), so that no step
//!    between levels exceeds `depth_of_cut_mm` anywhere along the channel.
//! 3. On each level the boundaries are where the offset ruled sides meet the level
//!    ([`impeller_model::levels::offset_surface_on_level`]), the area(s) between them are
//!    trimmed to where the cutter fits (step 4) and planned in the developed plane
//!    ([`super::plan2d`]) with the path interval that leaves
//!    `scallop_mm` on the level: the exact inverse of the scallop construction of
//!    [`cam_core::contact`] at the level's largest convex curvature across the channel
//!    (`κ = N_r / r`), capped by the process' `width_of_cut_mm`. That curvature is the
//!    level's across the flow only; where the paths run obliquely in the developed plane
//!    (whose metric is exact along the parallels only) the cusps between them can stand a
//!    little higher. So each level's scallop is measured (`max_scallop_mm` below) and a level
//!    above the target is planned again with its interval scaled by
//!    `0.99·√(target / measured)`, at most [`SCALLOP_REPLANS`] times
//!    (`scallop_replanned_levels` counts them).
//! 4. **Where the cutter fits.** On each grid section of an area the cutter alone (ball and
//!    flutes, the tool without shank and holder, [`cam_plan::DesignClearance`] against the
//!    blades) must keep `fit_min = blade_allowance − machining_tol/2` from the true blades
//!    with one of the candidate axes of step 5. The offset of step 1 is measured in the level
//!    for the cutter's slab only: it does not hold the flutes above the slab, which widen
//!    (tapered ends) and reach into the channel above along the blades' rulings (issue 11:
//!    every location the earlier planner skipped on impeller-8+8 was a flute sample 2–9 mm
//!    above the tip against the nearest blade), nor the ball's centre where the level is not
//!    perpendicular to the blade (the ball touching the level sits `r·sin β` nearer a blade
//!    leaning by `β` from the level normal). The section is sampled
//!    across at `min(step/2, 0.5 mm)` and each end between a fitting and a blocked sample is
//!    bisected 6 times (the kept end fits; within `2⁻⁶` of the sample spacing). A ball end
//!    whose centre (`p + r·n`, whatever the axis) is nearer than `r + fit_min` to a blade
//!    rules the point out at once. Sections with the same number of fitting intervals, each
//!    overlapping its neighbour's, form *lanes*: graph regions planned like an area (paths,
//!    baseline, scallop). What is left (between the offset sides but outside every lane) is
//!    not machinable by this cutter at this level: it is no path point, and its developed
//!    area is reported (`unmachinable_area_mm2`, of `level_area_mm2`).
//! 5. Each path point is put on the level; the wanted tool axis interpolates the rulings of
//!    the two ruled blades bounding the area at the point's cross-channel fraction (leaning
//!    with the blades), limited to `max_tilt_deg` from the level normal, averaged over
//!    `axis_smoothing` neighbours along the path; the cutter location touches the level there
//!    ([`cam_core::contact_location`]). A posture is accepted when the cutter keeps `fit_min`
//!    from the blades and the whole tool (cutter, shank, holder) is clear of hub and blades
//!    by the design clearance query; tried in order: the smoothed axis, the unsmoothed one,
//!    then leaned away from the nearer side in steps of 3° up to 12°, led along the flow by
//!    ±3°, ±6°, both combined, leaned toward the nearer side by 3° and 6°, and the level
//!    normal (each limited to `max_tilt_deg`); one with the machining tolerance to spare is
//!    preferred. A point with no posture is left uncut (the path is split there, linked over
//!    the safety surface) and counted in `skipped_locations`, by reason:
//!    `skipped_cutter_blocked` (the cutter fits with no axis: between the fit samples) or
//!    `skipped_shank_or_holder`. The motion between two consecutive postures (and every link
//!    move inside a lane) is certified as a whole with
//!    [`cam_plan::DesignClearance::segment_clearance_between`] (certified bisection, within
//!    half the machining tolerance); a motion that is not gets a planned posture at its planar
//!    midpoint (first axis: the mean of the end axes), recursively up to 4 levels
//!    (`bridge_postures`), and the path is split only when that fails (`split_motions`).
//!
//! Metrics: `path_length_mm` (pipeline), `triangle_path_length_mm` and
//! `isoparametric_path_length_mm` (cutting paths of all channels, measured in space on the
//! levels; the baseline over the same lanes), `saving_ratio = 1 − triangle / isoparametric`,
//! `isoparametric_channel_path_length_mm` and `saving_ratio_whole_channel` (the baseline
//! taken over the whole channel instead: paths of constant fraction between the two main
//! blades' offset sides from inlet to outlet, as many as the channel's widest section needs,
//! kept where they run inside a planned lane, [`plan2d::clip_to_regions`]; with a splitter
//! it differs from the per-lane baseline both ways: denser upstream of the splitter, none
//! where a path runs into the splitter or an unmachinable strip), `saving_ratio_width_bound`
//! (what the lanes' shape allows: paths at a constant interval `d` are as many at a section as
//! its width `w(s)` needs, `∫ w ds / d` in length, while the baseline runs `w_max / d` paths
//! the whole length `L` of the lane, so no such path set saves more than
//! `1 − Σ ∫ w ds / Σ w_max·L` over the lanes, up to the rounding of path counts and the
//! paths' slant; a lane that narrows little toward the inlet leaves little to save),
//! `max_scallop_mm` (measured over the machinable region: rays along the level normal from a
//! grid of points of every lane to the first cutter position of the level, the cutters taken
//! at the emitted locations of every lane of the level densified to a sixteenth of the ball
//! radius along each cut, within 0.002 mm of the swept cutter at 0.5 mm scallops), `levels`, `paths`, `min_blade_clearance_mm` (clearance query against the true
//! blades), `level_area_mm2` and `unmachinable_area_mm2` (developed areas over all levels and
//! channels, trapezoidal on the area grids), the skip, split and bridge counts above.
//!
//! Cost: per level O(sections · (width / scan + 12) · candidates) cutter queries for the fit
//! (most sections need one query per sample: the ball test and the first axis settle them),
//! O(points · candidates) posture queries (mostly one or two) and O(points · 2⁴) motion
//! checks in the worst case. Levels run in parallel (rayon).

use super::plan2d::{self, Linking, Path2, Region};
use crate::accessibility::limit_tilt;
use cam_core::{contact_location, CutterLocation, CutterShape, Move, MoveKind, ToolPath};
use cam_plan::{
    ClearanceOptions, DesignClearance, Metrics, Operation, OperationSpec, PartSet, PlanContext,
    PlanError, PlannedOperation, Plot, PlotKind, PlotSeries,
};
use impeller_model::levels::{depth_level, offset_surface_on_level, DepthLevel, LevelSpacing};
use impeller_model::ruled::{prolong_rulings, ruled_approximation};
use impeller_model::{Blade, Impeller, Side};
use nalgebra::{Rotation3, Unit, Vector3};
use nurbs::NurbsSurface;
use rayon::prelude::*;
use serde::Deserialize;

/// Kind name in job files.
pub const CHANNEL_ROUGHING: &str = "channel_roughing";

/// Samples along the flow of each boundary curve: the ruled blades are cubic in u with a
/// handful of spans; 61 samples keep the interpolated boundary within µm of the true one
/// (checked by the level tests of `impeller-model`).
const BOUNDARY_SAMPLES: usize = 61;

/// Midpoint queries allowed per motion check (beyond them the motion counts as not clear).
/// A motion between postures with little clearance to spare (a shank beside a twisted blade)
/// needs many certified bisections: at 24 queries such motions ran out and were bridged or
/// split although clear (impeller-11+11-freeform: 451 split motions and 11 506 bridge
/// postures; at 384: 33 and 165, and planning faster, since failed checks were retried
/// through bridge postures).
const SEGMENT_QUERIES: usize = 384;

/// Largest spacing of path points along the flow (mm) when the chord rule allows more.
const MAX_POINT_SPACING_MM: f64 = 1.0;

/// How many times a level is planned again with a narrower path interval when its measured
/// scallop exceeds the target (module docs, step 3).
pub const SCALLOP_REPLANS: usize = 3;
/// Factor applied to the interval correction `√(target / measured)` of a re-plan, so that
/// the next measurement lands below the target rather than on it (the scallop of a ball
/// grows about with the square of the step-over).
pub const SCALLOP_REPLAN_MARGIN: f64 = 0.99;

/// Grid of scallop measurement per area and level (along × across the flow).
const SCALLOP_GRID: (usize, usize) = (40, 16);

/// Cutter positions per ball radius along each cut in the scallop measurement (see
/// `measure_scallop`: the discrete positions' cusps read at most ~0.002 mm above the swept
/// cutter's scallop at this density for the fixtures' 0.5 mm targets).
const SCALLOP_DENSIFY: f64 = 16.0;

/// Largest spacing (mm) of the cross-channel samples of where the cutter fits on each grid
/// section (half the path interval when that is finer).
const FIT_SCAN_MAX_MM: f64 = 0.5;

/// Bisections refining each end of a fitting interval (to `2⁻⁶` of the sample spacing, the kept end on the fitting side).
const FIT_BISECTIONS: usize = 6;

/// Angular step of the axis search (degrees) and its number of steps in lean (across the
/// flow, away from the nearer side) and in lead (along the flow, both ways).
const AXIS_STEP_DEG: f64 = 3.0;
const LEAN_STEPS: usize = 4;
const LEAD_STEPS: usize = 2;

/// Levels of planned intermediate postures between two postures (up to `2^d − 1` per
/// motion) before a motion is split.
const BRIDGE_DEPTH: usize = 4;

/// Depth samples along the channel used to find its largest depth.
const DEPTH_SAMPLES: usize = 65;

fn default_linking() -> Linking {
    Linking::ZigZag
}
fn default_max_tilt() -> f64 {
    30.0
}
fn default_smoothing() -> usize {
    5
}

/// The kind's own keys (see `docs/job.md`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelRoughingParams {
    /// Target scallop height on the levels (mm).
    pub scallop_mm: f64,
    /// `zig_zag` or `one_way`.
    #[serde(default = "default_linking")]
    pub linking: Linking,
    /// Largest angle between tool axis and level normal (degrees).
    #[serde(default = "default_max_tilt")]
    pub max_tilt_deg: f64,
    /// Points averaged when smoothing the axes along a path (1 = none).
    #[serde(default = "default_smoothing")]
    pub axis_smoothing: usize,
}

/// The operation.
#[derive(Debug, Clone)]
pub struct ChannelRoughing {
    name: String,
    tool: String,
    params: ChannelRoughingParams,
}

/// Builder registered under [`CHANNEL_ROUGHING`].
pub fn build_channel_roughing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let params: ChannelRoughingParams = cam_plan::params::parse(spec)?;
    if !(params.scallop_mm.is_finite() && params.scallop_mm > 0.0) {
        return Err(PlanError::param(
            &spec.name,
            "scallop_mm",
            "must be finite and > 0",
        ));
    }
    if !(params.max_tilt_deg.is_finite() && (0.0..90.0).contains(&params.max_tilt_deg)) {
        return Err(PlanError::param(
            &spec.name,
            "max_tilt_deg",
            "must be in [0, 90)",
        ));
    }
    if params.axis_smoothing == 0 {
        return Err(PlanError::param(
            &spec.name,
            "axis_smoothing",
            "must be ≥ 1",
        ));
    }
    Ok(Box::new(ChannelRoughing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params,
    }))
}

/// A bounding side: its ruled approximation and the offset that keeps the cutter off it.
struct Bound {
    label: String,
    ruled: NurbsSurface,
    offset: f64,
}

/// Boundary of an area on one level, tabulated on the area's s grid.
struct Tab {
    y: Vec<f64>,
    u: Vec<f64>,
    ruled: usize,
}

/// An area of one level as bounded by the offset ruled sides, before trimming: the region
/// whose boundaries and rulings define the tool axis (module docs, step 5) of its lanes.
struct Field {
    region: Region,
    left: Tab,
    right: Tab,
}

/// One planned lane (a graph region where the cutter fits) of one area of one level.
struct AreaPlan {
    level: usize,
    /// Index of the area's [`Field`] in its level.
    field: usize,
    tri: Vec<Path2>,
    iso: Vec<Path2>,
    links: Vec<Path2>,
    region: Region,
}

struct LevelPlan {
    level: DepthLevel,
    /// The level's bounding sides (module docs, step 1).
    bounds: Vec<Bound>,
    fields: Vec<Field>,
    areas: Vec<AreaPlan>,
    /// The whole-channel isoparametric baseline, clipped to the planned lanes.
    channel_iso: Vec<Path2>,
    /// Developed area between the offset ruled sides (mm²).
    area_mm2: f64,
    /// Developed area of the planned lanes (mm²).
    planned_mm2: f64,
}

/// The cutter alone (ball and flutes: the tool without shank and holder) against the blades:
/// the query that decides where the cutter fits (module docs, step 4).
struct FitQuery<'a> {
    cutter: DesignClearance<'a>,
    shape: CutterShape,
    /// Radius of a ball end (ball or tapered ball): its centre touching the level at `p`
    /// with normal `n` is `p + r·n` whatever the axis, so a centre closer than `r + fit_min`
    /// to a blade rules out every axis with one exact distance.
    ball: Option<f64>,
}

impl FitQuery<'_> {
    /// Whether the ball (if the cutter has one) touching the level at `p` (normal `n`) keeps
    /// `fit_min` from the blades (exact blade distance of its centre). O(1) projections.
    fn ball_fits(&self, p: &Vector3<f64>, n: &Vector3<f64>, fit_min: f64) -> bool {
        self.ball.is_none_or(|r| {
            let c = cam_plan::Point3::from(p + n * r);
            self.cutter.blade_signed_distance(&c).0 - r >= fit_min
        })
    }
}

/// The tool axes of one area (module docs, step 5).
struct Axes<'a> {
    lv: &'a DepthLevel,
    field: &'a Field,
    bounds: &'a [Bound],
    max_tilt: f64,
    /// Level number (for error places).
    level: usize,
}

impl Axes<'_> {
    /// Point of the level and its unit normal at planar `q = (s, y)`.
    fn point_of(&self, q: [f64; 2]) -> (Vector3<f64>, Vector3<f64>) {
        let theta = q[1] / self.lv.radius_at(q[0]);
        self.lv.at_developed(q[0], theta)
    }

    /// Cross-channel fraction of `q` in the field (0 on the left side, 1 on the right).
    fn fraction(&self, q: [f64; 2]) -> f64 {
        let (l, r) = self.field.region.bounds(q[0]);
        if r > l {
            ((q[1] - l) / (r - l)).clamp(0.0, 1.0)
        } else {
            0.5
        }
    }

    /// The wanted axis: the rulings of the two sides bounding the field interpolated at the
    /// fraction of `q`, limited to `max_tilt` from the level normal `n`. O(1).
    fn wanted(&self, q: [f64; 2], n: &Vector3<f64>) -> Vector3<f64> {
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
    fn candidates(&self, q: [f64; 2], p: &Vector3<f64>, n: &Vector3<f64>) -> Vec<Vector3<f64>> {
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

impl Operation for ChannelRoughing {
    fn kind(&self) -> &'static str {
        CHANNEL_ROUGHING
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        self.plan_inner(ctx)
    }
}

fn side_v_range(
    imp: &Impeller,
    blade: &Blade,
    side: Side,
) -> Result<(f64, f64), impeller_model::ModelError> {
    match blade.design() {
        Some(_) => Ok(blade.hub_shroud_v(side)),
        None => imp.span_v_range(blade, side),
    }
}

impl ChannelRoughing {
    fn geo(&self, place: impl Into<String>, reason: impl Into<String>) -> PlanError {
        PlanError::geometry(&self.name, place, reason)
    }

    #[allow(clippy::too_many_arguments)]
    fn bound(
        &self,
        ctx: &PlanContext<'_>,
        blade: &Blade,
        side: Side,
        label: &str,
        radius: f64,
        doc: f64,
        band: (&DepthLevel, Option<&DepthLevel>),
    ) -> Result<Bound, PlanError> {
        let imp = ctx.impeller;
        let full = side_v_range(imp, blade, side).map_err(|e| {
            self.geo(
                label,
                format!("blade side does not reach both hub and shroud: {e}"),
            )
        })?;
        let v = level_band(blade.side(side), full, band);
        let ruled =
            ruled_approximation(blade, side, v).map_err(|e| PlanError::model(&self.name, e))?;
        // Orient the offset along the blade's outward normal (into the channel).
        let ((u0, u1), _) = ruled.surface.domain();
        let um = 0.5 * (u0 + u1);
        let d = ruled.surface.derivs2(um, 0.5);
        let n = d.su.cross(&d.sv);
        let out = blade
            .outward_normal(side, um, 0.5 * (v.0 + v.1))
            .ok_or_else(|| self.geo(label, "blade side normal undefined"))?;
        let sign = if n.dot(&out) >= 0.0 { 1.0 } else { -1.0 };
        let delta = radius + ctx.process.blade_allowance_mm + ruled.allowance_mm;
        // The offset moves the surface by δ across its rulings, so where the blade leans from
        // the hub (or shroud) normal the offset surface's edge lies up to δ off the hub (or
        // shroud): prolong every ruling beyond both edges by δ plus one depth of cut so that
        // the offset meets the hub level and the first level below the shroud (module docs,
        // step 1).
        let shortest = (0..=BOUNDARY_SAMPLES)
            .map(|i| {
                let u = u0 + (u1 - u0) * i as f64 / BOUNDARY_SAMPLES as f64;
                (ruled.surface.point(u, 1.0) - ruled.surface.point(u, 0.0)).norm()
            })
            .fold(f64::INFINITY, f64::min);
        if !(shortest.is_finite() && shortest > 0.0) {
            return Err(self.geo(label, "ruled approximation has a degenerate ruling"));
        }
        let e = (delta + doc) / shortest;
        let ruled =
            prolong_rulings(&ruled.surface, e, e).map_err(|e| PlanError::model(&self.name, e))?;
        Ok(Bound {
            label: label.into(),
            ruled,
            offset: sign * delta,
        })
    }

    /// Path interval on `level` for the tool and target scallop (module docs, step 3).
    fn interval(&self, ctx: &PlanContext<'_>, level: &DepthLevel) -> Result<f64, PlanError> {
        let h = self.params.scallop_mm;
        let m = level.surface.meridional();
        let mut kappa: f64 = 0.0;
        for i in 0..=32 {
            let t = m.param_at_fraction(i as f64 / 32.0);
            let n = m.normal(t);
            let r = m.point(t)[1];
            kappa = kappa.max(n[1] / r);
        }
        let step = match ctx.tool.cutter.shape {
            CutterShape::BallEnd { radius }
            | CutterShape::TaperedBallEnd {
                ball_radius: radius,
                ..
            } => cam_core::ball_step_over(radius, kappa, h),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => cam_core::bull_nose_step_over(
                radius,
                corner_radius,
                self.params.max_tilt_deg.to_radians(),
                kappa,
                h,
            ),
            _ => unreachable_shape(),
        }
        .map_err(|e| PlanError::param(&self.name, "scallop_mm", e.to_string()))?;
        Ok(match ctx.process.width_of_cut_mm {
            Some(w) if w > 0.0 => step.min(w),
            _ => step,
        })
    }

    fn plan_inner(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        let shape = ctx.tool.cutter.shape;
        let doc = ctx
            .process
            .depth_of_cut_mm
            .filter(|d| d.is_finite() && *d > 0.0)
            .ok_or_else(|| {
                PlanError::param(
                    &self.name,
                    "process.depth_of_cut_mm",
                    "needed (> 0) for levels",
                )
            })?;
        // The blade offset is the cutter's largest radius within one level's slab: the
        // radius for ball and bull-nose ends; for a tapered ball end the ball radius or, when
        // the depth of cut reaches the cone, the cone's radius at that height.
        let radius = match shape {
            CutterShape::BallEnd { radius } | CutterShape::BullNose { radius, .. } => radius,
            CutterShape::TaperedBallEnd { ball_radius, .. } => {
                ball_radius.max(shape.radius_at(doc))
            }
            _ => {
                return Err(PlanError::tool(
                    &self.name,
                    &self.tool,
                    "channel roughing needs a ball-end, tapered ball-end or bull-nose cutter",
                ))
            }
        };
        let imp = ctx.impeller;
        let hub_allow = ctx.process.hub_allowance_mm;
        let ch = imp.channel(0);
        // The bounding sides of one level (module docs, step 1): each ruled over the span
        // band the level's slab reaches.
        let level_bounds = |band: (&DepthLevel, Option<&DepthLevel>)| {
            let mut bounds = vec![
                self.bound(
                    ctx,
                    &ch.left,
                    ch.left_side(),
                    "left blade",
                    radius,
                    doc,
                    band,
                )?,
                self.bound(
                    ctx,
                    &ch.right,
                    ch.right_side(),
                    "right blade",
                    radius,
                    doc,
                    band,
                )?,
            ];
            if let Some(sp) = &ch.splitter {
                let minus = sp.plus_theta_side().other();
                let plus = sp.plus_theta_side();
                bounds.push(self.bound(ctx, sp, minus, "splitter −θ side", radius, doc, band)?);
                bounds.push(self.bound(ctx, sp, plus, "splitter +θ side", radius, doc, band)?);
            }
            Ok::<_, PlanError>(bounds)
        };
        // Levels.
        let hub = imp.hub().meridional();
        let shroud = imp.shroud().meridional();
        let mut depth: f64 = 0.0;
        for i in 0..DEPTH_SAMPLES {
            let m = i as f64 / (DEPTH_SAMPLES - 1) as f64;
            let th = hub.param_at_fraction(m);
            let h = hub.point(th) + hub.normal(th) * hub_allow;
            depth = depth.max((shroud.point_at_fraction(m) - h).norm());
        }
        let n_levels = ((depth / doc).ceil() as usize).max(1);
        // The cutter alone against the blades (module docs, step 4): the tool cut at its
        // flute length, without holder, sampled as the context's query (so that the whole
        // tool's clearance bounds the cutter's from below sample by sample).
        let mut cutter_tool = ctx.tool.clone();
        cutter_tool.cutter.overall_length = cutter_tool.cutter.flute_length;
        cutter_tool.cutter.holder.clear();
        let fit = FitQuery {
            cutter: DesignClearance::with_mesh(
                imp,
                ctx.clearance.mesh().clone(),
                &cutter_tool,
                ClearanceOptions {
                    parts: PartSet::BLADES,
                    above_mm: 0.0,
                    ..ctx.clearance.options()
                },
            )
            .map_err(|e| self.geo("cutter fit query", e.to_string()))?,
            shape,
            ball: match shape {
                CutterShape::BallEnd { radius }
                | CutterShape::TaperedBallEnd {
                    ball_radius: radius,
                    ..
                } => Some(radius),
                _ => None,
            },
        };
        let fit_min = ctx.process.blade_allowance_mm - 0.5 * ctx.tolerances.machining_tol;
        let blades_only = ctx.clearance.with_options(ClearanceOptions {
            parts: PartSet {
                hub: false,
                blades: true,
                shroud: false,
            },
            ..ClearanceOptions::default()
        });
        // Each level planned, located and measured; a level whose measured scallop exceeds
        // the target is planned again with its path interval narrowed (module docs, step 3).
        let target = self.params.scallop_mm;
        let planned: Vec<Result<(LevelPlan, LevelCl, usize), PlanError>> = (1..=n_levels)
            .into_par_iter()
            .map(|j| {
                let at = |j: usize| {
                    let spacing = LevelSpacing::Interpolated {
                        fraction: j as f64 / n_levels as f64,
                        hub_offset: hub_allow,
                    };
                    depth_level(imp, spacing).map_err(|e| PlanError::model(&self.name, e))
                };
                let mut level = at(j)?;
                let above = if j > 1 { Some(at(j - 1)?) } else { None };
                let mut bounds = level_bounds((&level, above.as_ref()))?;
                let mut scale = 1.0;
                let mut replans = 0;
                loop {
                    let lp = self.plan_level(ctx, j, level, bounds, &fit, fit_min, scale)?;
                    let lc =
                        self.locate_level(ctx, &lp, &lp.bounds, &blades_only, &fit, fit_min, doc)?;
                    if lc.max_scallop <= target || replans == SCALLOP_REPLANS {
                        return Ok((lp, lc, replans));
                    }
                    scale *= (target / lc.max_scallop).sqrt() * SCALLOP_REPLAN_MARGIN;
                    replans += 1;
                    level = lp.level;
                    bounds = lp.bounds;
                }
            })
            .collect();
        let mut levels: Vec<LevelPlan> = Vec::with_capacity(n_levels);
        let mut per_level: Vec<LevelCl> = Vec::with_capacity(n_levels);
        let mut replanned_levels = 0;
        for r in planned {
            let (lp, lc, replans) = r?;
            levels.push(lp);
            per_level.push(lc);
            replanned_levels += usize::from(replans > 0);
        }

        // One channel's path, levels shroud → hub, areas in order, linked over the safety
        // surface between areas.
        let mut path = ToolPath::new(self.name.clone(), self.tool.clone());
        let mut last: Option<CutterLocation> = None;
        let mut tri_len = 0.0;
        let mut iso_len = 0.0;
        let mut channel_iso_len = 0.0;
        let mut min_clear = f64::INFINITY;
        let mut max_scallop: f64 = 0.0;
        let mut n_paths = 0usize;
        let mut skipped_cutter = 0usize;
        let mut skipped_tool = 0usize;
        let mut split = 0usize;
        let mut bridged = 0usize;
        let area_mm2: f64 = levels.iter().map(|l| l.area_mm2).sum();
        let planned_mm2: f64 = levels.iter().map(|l| l.planned_mm2).sum();
        // The most any paths spaced like the triangle paths can save against the lanes'
        // isoparametric baseline (module docs): Σ ∫w ds over Σ w_max·L of every lane.
        let (width_area, box_area) = levels
            .iter()
            .flat_map(|l| &l.areas)
            .map(|a| {
                let r = &a.region;
                let len = r.s.last().zip(r.s.first()).map_or(0.0, |(b, a)| b - a);
                (r.width_integral(), r.max_width().max(0.0) * len)
            })
            .fold((0.0, 0.0), |(x, y), (a, b)| (x + a, y + b));
        for lc in &per_level {
            tri_len += lc.tri_len;
            iso_len += lc.iso_len;
            channel_iso_len += lc.channel_iso_len;
            min_clear = min_clear.min(lc.min_blade_clearance);
            max_scallop = max_scallop.max(lc.max_scallop);
            n_paths += lc.paths;
            skipped_cutter += lc.skipped_cutter;
            skipped_tool += lc.skipped_tool;
            split += lc.split_motions;
            bridged += lc.bridge_postures;
            for area in &lc.moves {
                let Some(first) = area.first() else { continue };
                if let Some(prev) = last {
                    path.moves.extend(ctx.link(&prev, &first.cl, doc)?);
                    path.moves.extend(area.iter().skip(1).copied());
                } else {
                    path.moves.extend(area.iter().copied());
                }
                last = area.last().map(|m| m.cl);
            }
        }
        ctx.close(&mut path, doc)?;
        let count = imp.main().count();
        let order = cam_plan::order::angular_sequence(count, 0);
        let paths = cam_plan::pattern::copy_to(&path, imp.main().pitch_rad(), &order);
        let k = count as f64;
        let mut metrics = Metrics::new();
        metrics
            .number("triangle_path_length_mm", tri_len * k)
            .number("isoparametric_path_length_mm", iso_len * k)
            .number("saving_ratio", saving(tri_len, iso_len))
            .number("isoparametric_channel_path_length_mm", channel_iso_len * k)
            .number(
                "saving_ratio_whole_channel",
                saving(tri_len, channel_iso_len),
            )
            .number("saving_ratio_width_bound", saving(width_area, box_area))
            .number("max_scallop_mm", max_scallop)
            .number("scallop_target_mm", self.params.scallop_mm)
            .count("scallop_replanned_levels", replanned_levels)
            .count("levels", n_levels)
            .count("paths", n_paths * count)
            .number("min_blade_clearance_mm", min_clear)
            .number("level_area_mm2", area_mm2 * k)
            .number(
                "unmachinable_area_mm2",
                (area_mm2 - planned_mm2).max(0.0) * k,
            )
            .count("skipped_locations", (skipped_cutter + skipped_tool) * count)
            .count("skipped_cutter_blocked", skipped_cutter * count)
            .count("skipped_shank_or_holder", skipped_tool * count)
            .count("split_motions", split * count)
            .count("bridge_postures", bridged * count);
        let plots = self.plot(&levels);
        let offsets = levels
            .iter()
            .flat_map(|l| l.bounds.iter().map(|b| b.offset.abs()))
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), o| {
                (lo.min(o), hi.max(o))
            });
        Ok(PlannedOperation {
            paths,
            metrics,
            plots,
            notes: vec![format!(
                "{n_levels} levels of ≤ {doc} mm; {} bounding sides per level (ruled over \
                 each level's span band, offset {:.3}–{:.3} mm); the cutter does not fit with \
                 {:.3} mm from the blades on {:.0} of {:.0} mm² of the levels (all channels), \
                 left unplanned",
                levels.first().map_or(0, |l| l.bounds.len()),
                offsets.0,
                offsets.1,
                fit_min,
                (area_mm2 - planned_mm2).max(0.0) * k,
                area_mm2 * k,
            )],
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn plan_level(
        &self,
        ctx: &PlanContext<'_>,
        j: usize,
        level: DepthLevel,
        bounds: Vec<Bound>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        step_scale: f64,
    ) -> Result<LevelPlan, PlanError> {
        let place = |b: &Bound| format!("level {j}, {}", b.label);
        let mut curves = Vec::with_capacity(bounds.len());
        for b in &bounds {
            let ((u0, u1), _) = b.ruled.domain();
            let c = offset_surface_on_level(&b.ruled, b.offset, &level, (u0, u1), BOUNDARY_SAMPLES)
                .map_err(|e| self.geo(place(b), e.to_string()))?;
            // (s, θ, u) samples of the boundary (θ unwrapped along the curve).
            let mut tab: Vec<(f64, f64, f64)> = Vec::with_capacity(c.samples.len());
            let mut prev: Option<f64> = None;
            for &(u, v) in &c.samples {
                let d = b.ruled.derivs2(u, v);
                let nn = d.su.cross(&d.sv);
                let p = d.p + nn * (b.offset / nn.norm());
                let (s, th) = level.developed(&p);
                let th = match prev {
                    Some(pv) => {
                        pv + (th - pv + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI
                    }
                    None => th,
                };
                prev = Some(th);
                tab.push((s, th, u));
            }
            // Keep the longest run advancing from inlet to outlet (the sides' u domain
            // reaches a little past the edges, where the offset may turn back).
            let (mut best, mut start) = ((0usize, 1usize), 0usize);
            for i in 1..=tab.len() {
                if i == tab.len() || tab[i].0 <= tab[i - 1].0 {
                    if i - start > best.1 - best.0 {
                        best = (start, i);
                    }
                    start = i;
                }
            }
            if best.1 - best.0 < 4 {
                return Err(self.geo(place(b), "boundary does not advance from inlet to outlet"));
            }
            curves.push(tab[best.0..best.1].to_vec());
        }
        let step = self.interval(ctx, &level)? * step_scale;
        let spacing = (8.0 * min_radius(&level) * ctx.tolerances.chord_tol)
            .sqrt()
            .min(MAX_POINT_SPACING_MM);
        // Areas (paper 003): without splitter one; with, upstream of its leading edge and
        // the two sub-channels.
        let s_lo = curves[0][0].0.max(curves[1][0].0);
        let s_hi = curves[0]
            .last()
            .map_or(0.0, |x| x.0)
            .min(curves[1].last().map_or(0.0, |x| x.0));
        let mut specs: Vec<(usize, usize, f64, f64)> = Vec::new();
        if curves.len() == 4 {
            let s_le = curves[2][0].0.max(curves[3][0].0).max(s_lo);
            let s_te = curves[2].last().map_or(s_hi, |x| x.0).min(s_hi);
            if s_le > s_lo + spacing {
                specs.push((0, 1, s_lo, s_le));
            }
            specs.push((0, 2, s_le, s_te));
            specs.push((3, 1, s_le, s_te));
        } else {
            specs.push((0, 1, s_lo, s_hi));
        }
        let mut areas = Vec::new();
        let mut fields: Vec<Field> = Vec::new();
        let mut area_mm2 = 0.0;
        let mut planned_mm2 = 0.0;
        for (a, b, s0, s1) in specs {
            if s1 <= s0 {
                continue;
            }
            let n = (((s1 - s0) / spacing).ceil() as usize).max(2) + 1;
            let s: Vec<f64> = (0..n)
                .map(|i| s0 + (s1 - s0) * i as f64 / (n - 1) as f64)
                .collect();
            let left = tabulate(&curves[a], &s, a, &level);
            let mut right = tabulate(&curves[b], &s, b, &level);
            unwrap_to_left(&mut right.y, &left.y, &s, &level);
            let field = Field {
                region: Region {
                    s,
                    left: left.y.clone(),
                    right: right.y.clone(),
                },
                left,
                right,
            };
            area_mm2 += trapezoid(&field.region.s, |i| {
                (field.region.right[i] - field.region.left[i]).max(0.0)
            });
            // Trim by where the cutter fits (module docs, step 4): the fitting intervals of
            // every grid section, then lanes of sections with the same number of intervals.
            let axes = Axes {
                lv: &level,
                field: &field,
                bounds: &bounds,
                max_tilt: self.params.max_tilt_deg.to_radians(),
                level: j,
            };
            let scan = (0.5 * step).min(FIT_SCAN_MAX_MM);
            let mut sections: Vec<Vec<(f64, f64)>> = Vec::with_capacity(n);
            for i in 0..n {
                sections.push(self.fit_intervals(fit, &axes, i, scan, fit_min)?);
            }
            let area_place = format!("level {j}, area {} / {}", bounds[a].label, bounds[b].label);
            for (lo, hi, lane) in lanes(&sections) {
                let region = Region {
                    s: field.region.s[lo..hi].to_vec(),
                    left: sections[lo..hi].iter().map(|x| x[lane].0).collect(),
                    right: sections[lo..hi].iter().map(|x| x[lane].1).collect(),
                };
                planned_mm2 += trapezoid(&region.s, |i| region.right[i] - region.left[i]);
                let tri = plan2d::triangle(&region, step)
                    .map_err(|e| self.geo(&area_place, e.to_string()))?;
                let iso = plan2d::isoparametric(&region, step)
                    .map_err(|e| self.geo(&area_place, e.to_string()))?;
                let (tri, links) = plan2d::link(tri, self.params.linking);
                areas.push(AreaPlan {
                    level: j,
                    field: fields.len(),
                    tri,
                    iso,
                    links,
                    region,
                });
            }
            fields.push(field);
        }
        // The isoparametric baseline over the whole channel (module docs, metrics): paths of
        // constant fraction between the two main blades' offset sides from inlet to outlet,
        // as many as the widest section needs, kept where they run inside a planned lane.
        let mut channel_iso = Vec::new();
        if s_hi > s_lo {
            let n = (((s_hi - s_lo) / spacing).ceil() as usize).max(2) + 1;
            let s: Vec<f64> = (0..n)
                .map(|i| s_lo + (s_hi - s_lo) * i as f64 / (n - 1) as f64)
                .collect();
            let left = tabulate(&curves[0], &s, 0, &level);
            let mut right = tabulate(&curves[1], &s, 1, &level);
            unwrap_to_left(&mut right.y, &left.y, &s, &level);
            let right_y: Vec<f64> = right
                .y
                .iter()
                .zip(&left.y)
                .map(|(r, l)| r.max(*l))
                .collect();
            let whole = Region {
                s,
                left: left.y,
                right: right_y,
            };
            let paths = plan2d::isoparametric(&whole, step)
                .map_err(|e| self.geo(format!("level {j}, whole channel"), e.to_string()))?;
            let lanes: Vec<&Region> = areas.iter().map(|a| &a.region).collect();
            channel_iso = plan2d::clip_to_regions(paths, &lanes);
        }
        Ok(LevelPlan {
            level,
            bounds,
            fields,
            areas,
            channel_iso,
            area_mm2,
            planned_mm2,
        })
    }

    /// The intervals `[y₀, y₁]` of grid section `i` of `axes.field` where the cutter fits
    /// ([`Self::cutter_fits`]): samples across the section at most `scan` mm apart, then
    /// every end between a fitting and a blocked sample refined by [`FIT_BISECTIONS`]
    /// bisections (to `scan·2⁻⁶`). An end at a section boundary is that boundary. Cost:
    /// O((width / scan + ends · FIT_BISECTIONS) · candidates) cutter queries.
    fn fit_intervals(
        &self,
        fit: &FitQuery<'_>,
        axes: &Axes<'_>,
        i: usize,
        scan: f64,
        fit_min: f64,
    ) -> Result<Vec<(f64, f64)>, PlanError> {
        let reg = &axes.field.region;
        let (s, l, r) = (reg.s[i], reg.left[i], reg.right[i]);
        if r < l {
            return Ok(Vec::new());
        }
        let k = (((r - l) / scan).ceil() as usize).max(1);
        let ys: Vec<f64> = (0..=k).map(|m| l + (r - l) * m as f64 / k as f64).collect();
        let mut ok = Vec::with_capacity(ys.len());
        for &y in &ys {
            ok.push(self.cutter_fits(fit, axes, [s, y], fit_min)?);
        }
        // Refine the end between a blocked `bad` and a fitting `good` ordinate.
        let refine = |mut bad: f64, mut good: f64| -> Result<f64, PlanError> {
            for _ in 0..FIT_BISECTIONS {
                let m = 0.5 * (bad + good);
                if self.cutter_fits(fit, axes, [s, m], fit_min)? {
                    good = m;
                } else {
                    bad = m;
                }
            }
            Ok(good)
        };
        let mut out = Vec::new();
        let mut m = 0;
        while m < ys.len() {
            if !ok[m] {
                m += 1;
                continue;
            }
            let start = m;
            while m < ys.len() && ok[m] {
                m += 1;
            }
            let y0 = if start == 0 {
                ys[0]
            } else {
                refine(ys[start - 1], ys[start])?
            };
            let y1 = if m == ys.len() {
                ys[ys.len() - 1]
            } else {
                refine(ys[m], ys[m - 1])?
            };
            out.push((y0, y1));
        }
        Ok(out)
    }

    /// Whether the cutter (ball and flutes, not shank nor holder) at planar point `q`, touching
    /// the level, keeps `fit_min` from the blades with one of the candidate axes of
    /// [`Axes::candidates`] (each with the early-exit query). O(candidates · query).
    fn cutter_fits(
        &self,
        fit: &FitQuery<'_>,
        axes: &Axes<'_>,
        q: [f64; 2],
        fit_min: f64,
    ) -> Result<bool, PlanError> {
        let (p, n) = axes.point_of(q);
        if !fit.ball_fits(&p, &n, fit_min) {
            return Ok(false);
        }
        for a in axes.candidates(q, &p, &n) {
            let cl = self.touch(&fit.shape, &p, &n, &a, axes.level, q)?;
            if fit.cutter.is_clear(&cl, fit_min) {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// The span band of a blade side that one level's slab reaches (module docs, step 1): side
/// parameters v from the lowest crossing of the side with the level `band.0` to the highest
/// with the level above `band.1` (the shroud edge for the first level), within `full` (the
/// side's hub–shroud range). A crossing that cannot be found leaves that end of `full`.
fn level_band(
    side: &NurbsSurface,
    full: (f64, f64),
    band: (&DepthLevel, Option<&DepthLevel>),
) -> (f64, f64) {
    let ((u0, u1), _) = side.domain();
    let crossing_vs = |lv: &DepthLevel| {
        offset_surface_on_level(side, 0.0, lv, (u0, u1), BOUNDARY_SAMPLES)
            .ok()
            .map(|c| c.samples.iter().map(|&(_, v)| v).collect::<Vec<f64>>())
    };
    let lo = crossing_vs(band.0)
        .map(|vs| vs.into_iter().fold(f64::INFINITY, f64::min))
        .filter(|v| v.is_finite())
        .map_or(full.0, |v| v.max(full.0));
    let hi = band
        .1
        .and_then(crossing_vs)
        .map(|vs| vs.into_iter().fold(f64::NEG_INFINITY, f64::max))
        .filter(|v| v.is_finite())
        .map_or(full.1, |v| v.min(full.1));
    if lo < hi {
        (lo, hi)
    } else {
        full
    }
}

fn unreachable_shape() -> Result<f64, cam_core::ContactError> {
    Err(cam_core::ContactError::Invalid {
        field: "shape",
        value: f64::NAN,
        reason: "channel roughing needs a ball-end, tapered ball-end or bull-nose cutter",
    })
}

fn min_radius(level: &DepthLevel) -> f64 {
    let m = level.surface.meridional();
    (0..=32)
        .map(|i| m.point_at_fraction(i as f64 / 32.0)[1])
        .fold(f64::INFINITY, f64::min)
}

/// Boundary y = r(s)·θ(s) and ruled u at each grid s (linear in the boundary's samples,
/// which are dense: the developed curve is their interpolant).
/// `1 − triangle / baseline` (0 without a baseline).
fn saving(triangle: f64, baseline: f64) -> f64 {
    if baseline > 0.0 {
        1.0 - triangle / baseline
    } else {
        0.0
    }
}

/// Moves each right boundary `y` by whole turns of its parallel (`2π·r(s)`) to the turn
/// nearest the left one: the channel spans less than half a turn, so a negative width then
/// means the offset boundaries cross.
fn unwrap_to_left(right: &mut [f64], left: &[f64], s: &[f64], level: &DepthLevel) {
    let tau = std::f64::consts::TAU;
    for ((ry, ly), &si) in right.iter_mut().zip(left).zip(s) {
        let turn = tau * level.radius_at(si);
        *ry = ly + (*ry - ly + 0.5 * turn).rem_euclid(turn) - 0.5 * turn;
    }
}

fn tabulate(tab: &[(f64, f64, f64)], s: &[f64], ruled: usize, level: &DepthLevel) -> Tab {
    let mut y = Vec::with_capacity(s.len());
    let mut u = Vec::with_capacity(s.len());
    for &x in s {
        let k = tab.partition_point(|t| t.0 <= x).clamp(1, tab.len() - 1);
        let (a, b) = (tab[k - 1], tab[k]);
        let t = ((x - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
        let th = a.1 + t * (b.1 - a.1);
        y.push(level.radius_at(x) * th);
        u.push(a.2 + t * (b.2 - a.2));
    }
    Tab { y, u, ruled }
}

/// Cutter locations and measurements of one level.
struct LevelCl {
    moves: Vec<Vec<Move>>,
    tri_len: f64,
    iso_len: f64,
    /// Length of the whole-channel isoparametric baseline (mm).
    channel_iso_len: f64,
    min_blade_clearance: f64,
    max_scallop: f64,
    paths: usize,
    /// Path points where the cutter fits with no candidate axis (between the fit samples).
    skipped_cutter: usize,
    /// Path points where the cutter fits but shank or holder hit with every candidate axis.
    skipped_tool: usize,
    /// Motions between two collision-free postures that were not clear even through planned
    /// intermediate postures (the path was split there).
    split_motions: usize,
    /// Intermediate postures inserted to certify motions.
    bridge_postures: usize,
}

/// A certified posture: the location and its clearance (whole tool against the design).
type Posture = (CutterLocation, cam_plan::Clearance);

/// Why a point has no posture.
enum Blocked {
    /// The cutter itself keeps `fit_min` from the blades with no candidate axis.
    Cutter,
    /// The cutter does with some axis, but never with shank and holder clear as well.
    ShankOrHolder,
}

impl ChannelRoughing {
    /// A posture at planar `q` (module docs, step 5): the axes `first` (when given), then
    /// the candidates of [`Axes::candidates`]; the cutter must keep `fit_min` from the
    /// blades and the whole tool `0` from the design. A posture with at least the machining
    /// tolerance to spare (so that the motions between postures certify) is preferred, else
    /// the first clear one. O(candidates · query).
    #[allow(clippy::too_many_arguments)]
    fn posture(
        &self,
        ctx: &PlanContext<'_>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        axes: &Axes<'_>,
        q: [f64; 2],
        first: Option<Vector3<f64>>,
    ) -> Result<Result<Posture, Blocked>, PlanError> {
        let (p, n) = axes.point_of(q);
        if !fit.ball_fits(&p, &n, fit_min) {
            return Ok(Err(Blocked::Cutter));
        }
        let room = ctx.tolerances.machining_tol;
        let mut cutter_fits = false;
        let mut fallback: Option<Posture> = None;
        let tries = first
            .map(|a| limit_tilt(a, &n, axes.max_tilt))
            .into_iter()
            .chain(axes.candidates(q, &p, &n));
        for a in tries {
            let cl = self.touch(&fit.shape, &p, &n, &a, axes.level, q)?;
            // The whole tool's clearance bounds the cutter's against the blades from below:
            // the cutter query runs only when the whole tool's does not settle it.
            let want = if fallback.is_none() { 0.0 } else { room };
            let Some(c) = ctx.clearance.clearance_if_clear(&cl, want) else {
                cutter_fits = cutter_fits || fit.cutter.is_clear(&cl, fit_min);
                continue;
            };
            if c.distance_mm < fit_min && !fit.cutter.is_clear(&cl, fit_min) {
                continue;
            }
            cutter_fits = true;
            if c.distance_mm >= room {
                return Ok(Ok((cl, c)));
            }
            if fallback.is_none() {
                fallback = Some((cl, c));
            }
        }
        Ok(match fallback {
            Some(f) => Ok(f),
            None if cutter_fits => Err(Blocked::ShankOrHolder),
            None => Err(Blocked::Cutter),
        })
    }

    /// Connects `a` (planar `qa`) to `b` (`qb`): `true` when the motion is certified clear
    /// ([`cam_plan::DesignClearance::segment_clearance_between`], within `seg_tol`), or its
    /// halves are through a planned posture at the planar midpoint (first axis: the mean of
    /// the end axes), recursively up to `depth` levels; the inserted postures are pushed to
    /// `out` in order. O(2^depth · (posture + motion check)).
    #[allow(clippy::too_many_arguments)]
    fn bridge(
        &self,
        ctx: &PlanContext<'_>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        axes: &Axes<'_>,
        (a, qa): (&Posture, [f64; 2]),
        (b, qb): (&Posture, [f64; 2]),
        seg_tol: f64,
        depth: usize,
        out: &mut Vec<Posture>,
    ) -> Result<bool, PlanError> {
        let clear = ctx
            .clearance
            .segment_clearance_between(
                (&a.0, a.1.distance_mm),
                (&b.0, b.1.distance_mm),
                0.0,
                seg_tol,
                SEGMENT_QUERIES,
            )
            .is_ok();
        if clear {
            return Ok(true);
        }
        if depth == 0 {
            return Ok(false);
        }
        let qm = [0.5 * (qa[0] + qb[0]), 0.5 * (qa[1] + qb[1])];
        let am = (a.0.axis.into_inner() + b.0.axis.into_inner()).try_normalize(1e-12);
        let Ok(m) = self.posture(ctx, fit, fit_min, axes, qm, am)? else {
            return Ok(false);
        };
        if !self.bridge(
            ctx,
            fit,
            fit_min,
            axes,
            (a, qa),
            (&m, qm),
            seg_tol,
            depth - 1,
            out,
        )? {
            return Ok(false);
        }
        out.push(m);
        self.bridge(
            ctx,
            fit,
            fit_min,
            axes,
            (&m, qm),
            (b, qb),
            seg_tol,
            depth - 1,
            out,
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn locate_level(
        &self,
        ctx: &PlanContext<'_>,
        lp: &LevelPlan,
        bounds: &[Bound],
        blades_only: &cam_plan::DesignClearance<'_>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        doc: f64,
    ) -> Result<LevelCl, PlanError> {
        let shape = ctx.tool.cutter.shape;
        let max_tilt = self.params.max_tilt_deg.to_radians();
        let mut out = LevelCl {
            moves: Vec::new(),
            tri_len: 0.0,
            iso_len: 0.0,
            channel_iso_len: 0.0,
            min_blade_clearance: f64::INFINITY,
            max_scallop: 0.0,
            paths: 0,
            skipped_cutter: 0,
            skipped_tool: 0,
            split_motions: 0,
            bridge_postures: 0,
        };
        // Motions between postures may come this far below zero clearance (the other half
        // of the machining tolerance is the clearance query's own sampling error).
        let seg_tol = 0.5 * ctx.tolerances.machining_tol;
        let lv = &lp.level;
        // Every cutter location of the level (all lanes), for the scallop measurement.
        let mut level_runs: Vec<Vec<CutterLocation>> = Vec::new();
        for area in &lp.areas {
            let Some(field) = lp.fields.get(area.field) else {
                continue;
            };
            let axes = Axes {
                lv,
                field,
                bounds,
                max_tilt,
                level: area.level,
            };
            let mut chunks: Vec<Vec<Move>> = Vec::new();
            let mut cur: Vec<Move> = Vec::new();
            for (pi, path) in area.tri.iter().enumerate() {
                let raw: Vec<Vector3<f64>> = path
                    .iter()
                    .map(|&q| axes.wanted(q, &axes.point_of(q).1))
                    .collect();
                let smooth = smooth_axes(&raw, self.params.axis_smoothing);
                let mut found: Vec<Option<Posture>> = Vec::with_capacity(path.len());
                for (&q, a) in path.iter().zip(&smooth) {
                    match self.posture(ctx, fit, fit_min, &axes, q, Some(*a))? {
                        Ok(p) => found.push(Some(p)),
                        Err(why) => {
                            // No certified posture: the point is left uncut (the path is
                            // split there; the measured scallop shows the residue).
                            match why {
                                Blocked::Cutter => out.skipped_cutter += 1,
                                Blocked::ShankOrHolder => out.skipped_tool += 1,
                            }
                            found.push(None);
                        }
                    }
                }
                // The motions between consecutive postures are certified too (the axis may
                // change between them), through planned intermediate postures where needed;
                // when that fails the path is split there (the linker retracts and
                // approaches around the gap).
                let mut checked: Vec<Option<Posture>> = Vec::with_capacity(found.len());
                let mut mids: Vec<Posture> = Vec::new();
                for k in 0..found.len() {
                    if k > 0 {
                        if let (Some(a), Some(b)) = (&found[k - 1], &found[k]) {
                            mids.clear();
                            let ok = self.bridge(
                                ctx,
                                fit,
                                fit_min,
                                &axes,
                                (a, path[k - 1]),
                                (b, path[k]),
                                seg_tol,
                                BRIDGE_DEPTH,
                                &mut mids,
                            )?;
                            if ok {
                                out.bridge_postures += mids.len();
                                checked.extend(mids.drain(..).map(Some));
                            } else {
                                out.split_motions += 1;
                                checked.push(None);
                            }
                        }
                    }
                    checked.push(found[k]);
                }
                let mut cls: Vec<Option<CutterLocation>> = Vec::with_capacity(checked.len());
                for f in checked {
                    let Some((cl, c)) = f else {
                        cls.push(None);
                        continue;
                    };
                    // The nearest part is a blade: that is the blade clearance; otherwise ask
                    // the blades alone.
                    let blade_clear = match c.design_part {
                        cam_plan::DesignPart::Blade { .. } => c.distance_mm,
                        _ => blades_only.clearance(&cl).distance_mm,
                    };
                    out.min_blade_clearance = out.min_blade_clearance.min(blade_clear);
                    cls.push(Some(cl));
                }
                for run in cls.split(Option::is_none) {
                    out.tri_len += polyline_len(run.iter().flatten().map(|c| c.tip.coords));
                }
                // Link from the previous path inside the lane (one-way links lifted by the
                // depth of cut); a link that is not collision-free ends the chunk instead.
                let first = cls.first().copied().flatten();
                if pi > 0 && !cur.is_empty() {
                    let mut linked = false;
                    if let (Some(link), Some(first)) = (area.links.get(pi - 1), first) {
                        let lift = if self.params.linking == Linking::OneWay {
                            doc
                        } else {
                            0.0
                        };
                        let kind = if lift > 0.0 {
                            MoveKind::Rapid
                        } else {
                            MoveKind::Feed
                        };
                        let mut moves: Vec<Move> = Vec::new();
                        let mut clear = true;
                        let mut prev = cur.last().map(|m| m.cl);
                        for &q in link.iter().skip(1).take(link.len().saturating_sub(2)) {
                            let (p, n) = axes.point_of(q);
                            let a = axes.wanted(q, &n);
                            let cl = self.touch(&shape, &p, &n, &a, area.level, q)?;
                            let cl = CutterLocation {
                                tip: cl.tip + n * lift,
                                axis: cl.axis,
                            };
                            let motion_clear = prev.is_none_or(|from| {
                                ctx.clearance
                                    .segment_clearance(&from, &cl, 0.0, seg_tol, SEGMENT_QUERIES)
                                    .is_ok()
                            });
                            if !motion_clear {
                                clear = false;
                                break;
                            }
                            prev = Some(cl);
                            moves.push(Move {
                                kind,
                                cl,
                                feed_mm_per_min: None,
                            });
                        }
                        clear = clear
                            && prev.is_none_or(|from| {
                                ctx.clearance
                                    .segment_clearance(&from, &first, 0.0, seg_tol, SEGMENT_QUERIES)
                                    .is_ok()
                            });
                        if clear {
                            cur.extend(moves);
                            cur.push(Move {
                                kind: if lift > 0.0 {
                                    MoveKind::Plunge
                                } else {
                                    MoveKind::Feed
                                },
                                cl: first,
                                feed_mm_per_min: None,
                            });
                            linked = true;
                        }
                    }
                    if !linked {
                        chunks.push(std::mem::take(&mut cur));
                    }
                }
                let mut run: Vec<CutterLocation> = Vec::new();
                for (k, c) in cls.iter().enumerate() {
                    match c {
                        Some(cl) => {
                            // The path's first point is already the link's end.
                            let dup = k == 0 && cur.last().is_some_and(|m| m.cl == *cl);
                            if !dup {
                                cur.push(Move::feed(*cl));
                            }
                            run.push(*cl);
                        }
                        None => {
                            if !cur.is_empty() {
                                chunks.push(std::mem::take(&mut cur));
                            }
                            if !run.is_empty() {
                                level_runs.push(std::mem::take(&mut run));
                            }
                        }
                    }
                }
                if !run.is_empty() {
                    level_runs.push(run);
                }
                out.paths += 1;
            }
            if !cur.is_empty() {
                chunks.push(cur);
            }
            for path in &area.iso {
                out.iso_len += polyline_len(path.iter().map(|&q| axes.point_of(q).0));
            }
            out.moves.extend(chunks);
        }
        for path in &lp.channel_iso {
            out.channel_iso_len += polyline_len(
                path.iter()
                    .map(|q| lv.at_developed(q[0], q[1] / lv.radius_at(q[0])).0),
            );
        }
        // The scallop of every lane (its machinable region), against every cutter position
        // of the level.
        let probe = ScallopProbe::new(&shape, ctx.tool.cutter.flute_length, &level_runs, doc);
        for area in &lp.areas {
            out.max_scallop = out.max_scallop.max(probe.measure(&area.region, lv));
        }
        Ok(out)
    }

    /// The cutter location touching the level at `p` (normal `n`) with axis `a`; a contact
    /// error names level `level` and planar point `q`.
    fn touch(
        &self,
        shape: &CutterShape,
        p: &Vector3<f64>,
        n: &Vector3<f64>,
        a: &Vector3<f64>,
        level: usize,
        q: [f64; 2],
    ) -> Result<CutterLocation, PlanError> {
        contact_location(
            shape,
            (*p).into(),
            Unit::new_normalize(*n),
            Unit::new_normalize(*a),
        )
        .map(|c| c.cl)
        .map_err(|e| {
            self.geo(
                format!("level {level}, s = {:.3} mm, y = {:.3} mm", q[0], q[1]),
                e.to_string(),
            )
        })
    }

    fn plot(&self, levels: &[LevelPlan]) -> Vec<Plot> {
        let Some(lp) = levels.get(levels.len() / 2) else {
            return Vec::new();
        };
        let mut series = Vec::new();
        for (ai, area) in lp.areas.iter().enumerate() {
            for (k, p) in area.tri.iter().enumerate() {
                series.push(PlotSeries {
                    label: format!("triangle area {ai} path {k}"),
                    points: p.clone(),
                });
            }
            for (k, p) in area.iso.iter().enumerate() {
                series.push(PlotSeries {
                    label: format!("isoparametric area {ai} path {k}"),
                    points: p.clone(),
                });
            }
        }
        vec![Plot {
            title: format!(
                "Channel roughing, level {} of {}: triangle vs isoparametric paths (developed)",
                levels.len() / 2 + 1,
                levels.len()
            ),
            kind: PlotKind::Lines {
                x_label: "s along the level contour (mm)".into(),
                y_label: "r·θ across the channel (mm)".into(),
                series,
                equal_aspect: true,
            },
        }]
    }
}

/// Trapezoidal integral over the grid `s` of the values `f(i)` at its points.
fn trapezoid(s: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    (1..s.len())
        .map(|i| 0.5 * (f(i - 1) + f(i)) * (s[i] - s[i - 1]))
        .sum()
}

/// The lanes of a trimmed area (module docs, step 4): maximal runs `lo..hi` of consecutive
/// grid sections with the same number of fitting intervals, each interval `k` of such a run
/// overlapping its neighbour's in `y`, as `(lo, hi, k)`; runs of fewer than 2 sections are
/// left out (their area counts as unmachinable). O(sections · intervals).
fn lanes(sections: &[Vec<(f64, f64)>]) -> Vec<(usize, usize, usize)> {
    let joins = |a: &[(f64, f64)], b: &[(f64, f64)]| {
        !a.is_empty()
            && a.len() == b.len()
            && a.iter().zip(b).all(|(x, y)| x.0 <= y.1 && y.0 <= x.1)
    };
    let mut out = Vec::new();
    let mut lo = 0;
    while lo < sections.len() {
        let mut hi = lo + 1;
        while hi < sections.len() && joins(&sections[hi - 1], &sections[hi]) {
            hi += 1;
        }
        if hi - lo >= 2 {
            out.extend((0..sections[lo].len()).map(|k| (lo, hi, k)));
        }
        lo = hi;
    }
    out
}

fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let k = xs.partition_point(|&v| v <= x).clamp(1, xs.len() - 1);
    let t = ((x - xs[k - 1]) / (xs[k] - xs[k - 1])).clamp(0.0, 1.0);
    ys[k - 1] + t * (ys[k] - ys[k - 1])
}

/// Moving average of unit axes over `w` neighbours (renormalised).
fn smooth_axes(a: &[Vector3<f64>], w: usize) -> Vec<Vector3<f64>> {
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

fn polyline_len(pts: impl Iterator<Item = Vector3<f64>>) -> f64 {
    let mut len = 0.0;
    let mut prev: Option<Vector3<f64>> = None;
    for p in pts {
        if let Some(q) = prev {
            len += (p - q).norm();
        }
        prev = Some(p);
    }
    len
}

/// Whether `x` lies inside the cutter at `cl` (solid of revolution up to the flute length).
fn inside(
    profile: &cam_core::RadiusProfile,
    flute: f64,
    cl: &CutterLocation,
    x: &Vector3<f64>,
) -> bool {
    let a = cl.axis.into_inner();
    let d = x - cl.tip.coords;
    let h = d.dot(&a);
    if !(0.0..=flute).contains(&h) {
        return false;
    }
    (d - a * h).norm() <= profile.radius_at(h)
}

/// The cutter locations of one level, densified along their runs and bucketed in space,
/// for [`ScallopProbe::measure`].
struct ScallopProbe {
    shape: CutterShape,
    flute: f64,
    cap: f64,
    /// The ball radius (0 for a flat end).
    reach: f64,
    /// The distance within which a location can hold a point of a probe ray: `2·reach + cap`.
    radius: f64,
    dense: Vec<CutterLocation>,
    /// Indices into `dense` by cubic cell of side `radius` (the 27 cells around a point's
    /// cell hold every location within `radius` of it).
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl ScallopProbe {
    /// The locations of `runs` (each a sequence of consecutive locations joined by cutting
    /// motions), densified to `reach / SCALLOP_DENSIFY`, for rays of length `cap`. O(dense).
    fn new(shape: &CutterShape, flute: f64, runs: &[Vec<CutterLocation>], cap: f64) -> Self {
        let reach = match *shape {
            CutterShape::BallEnd { radius }
            | CutterShape::BullNose { radius, .. }
            | CutterShape::TaperedBallEnd {
                ball_radius: radius,
                ..
            } => radius,
            _ => 0.0,
        };
        // Densify consecutive locations to `reach / SCALLOP_DENSIFY`: the union of discrete
        // cutters under-reads the swept one between them, so that a point at lateral distance
        // `d` from the path is reached only as if `√(d² + (a/2)²)` away for spacing `a`. At a
        // quarter radius this read up to 0.018 mm above a 0.5 mm scallop of a ball R1.5 (the
        // cusps of the discrete balls); at a sixteenth it is below 0.002 mm.
        let mut dense: Vec<CutterLocation> = Vec::new();
        for cls in runs {
            for w in cls.windows(2) {
                let d = (w[1].tip - w[0].tip).norm();
                let k = ((d * SCALLOP_DENSIFY / reach).ceil() as usize).clamp(1, 256);
                for i in 0..k {
                    let t = i as f64 / k as f64;
                    let axis = w[0].axis.into_inner() * (1.0 - t) + w[1].axis.into_inner() * t;
                    dense.push(CutterLocation {
                        tip: w[0].tip + (w[1].tip - w[0].tip) * t,
                        axis: Unit::new_normalize(axis),
                    });
                }
            }
            if let Some(l) = cls.last() {
                dense.push(*l);
            }
        }
        let radius = 2.0 * reach + cap;
        let mut cells: std::collections::HashMap<[i64; 3], Vec<u32>> =
            std::collections::HashMap::new();
        if radius > 0.0 && radius.is_finite() {
            for (i, c) in dense.iter().enumerate() {
                if let Some(key) = Self::cell(&c.tip.coords, radius) {
                    cells.entry(key).or_default().push(i as u32);
                }
            }
        }
        Self {
            shape: *shape,
            flute,
            cap,
            reach,
            radius,
            dense,
            cells,
        }
    }

    /// The cell of `p` (`None` for a point too far out to bucket).
    fn cell(p: &Vector3<f64>, side: f64) -> Option<[i64; 3]> {
        let k = |x: f64| {
            let c = (x / side).floor();
            (c.abs() < 1e15).then_some(c as i64)
        };
        Some([k(p.x)?, k(p.y)?, k(p.z)?])
    }

    /// Whether the cutter at `c` can hold a point of the segment `x0`–`x1`: its axis from the
    /// tip to the flute top passes within `r_max` of the segment.
    fn may_hold(
        &self,
        c: &CutterLocation,
        x0: &Vector3<f64>,
        x1: &Vector3<f64>,
        r_max: f64,
    ) -> bool {
        let top = c.tip + c.axis.into_inner() * self.flute;
        let (x0, x1) = (cam_core::Point3::from(*x0), cam_core::Point3::from(*x1));
        cam_core::path::segment_segment_distance(&x0, &x1, &c.tip, &top) <= r_max
    }

    /// Largest scallop over a grid of the lane `region` (its machinable region) of level
    /// `lv`: from each grid point, the distance along the level normal to the first cutter
    /// position, at most `cap`: the ray is marched at a quarter of the ball radius and the
    /// first entry bisected (40 steps); a cutter crossed by the ray over less than a march
    /// step may be missed, which only reads more. O(grid · (cap / step) · dense locations
    /// near the point).
    fn measure(&self, region: &Region, lv: &DepthLevel) -> f64 {
        if self.dense.is_empty() {
            return 0.0;
        }
        let (reach, cap) = (self.reach, self.cap);
        let (ns, ny) = SCALLOP_GRID;
        let (s0, s1) = (region.s[0], region.s[region.s.len() - 1]);
        let profile = self.shape.profile();
        let mut near: Vec<&CutterLocation> = Vec::new();
        let mut bracket: Vec<&CutterLocation> = Vec::new();
        // The widest radius of the cutting end (its profile does not narrow upward), with a
        // margin over the rounding of `inside`.
        let r_max = profile.radius_at(self.flute).max(profile.radius_at(0.0));
        let r_max = r_max + 1e-9 * (1.0 + r_max);
        let mut worst: f64 = 0.0;
        for i in 0..=ns {
            let s = s0 + (s1 - s0) * i as f64 / ns as f64;
            let (l, r) = region.bounds(s);
            for j in 0..=ny {
                let y = l + (r - l) * j as f64 / ny as f64;
                let (p, n) = lv.at_developed(s, y / lv.radius_at(s));
                near.clear();
                let within = |c: &&CutterLocation| (c.tip.coords - p).norm() <= self.radius;
                match Self::cell(&p, self.radius).filter(|_| !self.cells.is_empty()) {
                    Some([x, y, z]) => {
                        for dx in -1..=1 {
                            for dy in -1..=1 {
                                for dz in -1..=1 {
                                    if let Some(ids) = self.cells.get(&[x + dx, y + dy, z + dz]) {
                                        near.extend(
                                            ids.iter()
                                                .filter_map(|&k| self.dense.get(k as usize))
                                                .filter(within),
                                        );
                                    }
                                }
                            }
                        }
                    }
                    None => near.extend(self.dense.iter().filter(within)),
                }
                // Only a cutter whose axis (tip to flute top) passes within its widest radius
                // of a stretch of the ray can hold a point of it: the march looks at those of
                // the whole ray, the bisection at those of its bracket (the same answers as
                // testing every nearby cutter, with fewer tests).
                near.retain(|c| self.may_hold(c, &p, &(p + n * cap), r_max));
                let hit = |t: f64| {
                    let x = p + n * t;
                    near.iter().any(|c| inside(&profile, self.flute, c, &x))
                };
                if hit(0.0) {
                    continue;
                }
                // March up the ray at a quarter radius to the first position inside a cutter
                // (a ray may pass above or beside the cutters: the cap alone does not tell),
                // then bisect between the last miss and the first hit.
                let step = (0.25 * reach).max(1e-3).min(cap);
                let mut lo = 0.0;
                let mut first_hit = None;
                while lo < cap {
                    let t = (lo + step).min(cap);
                    if hit(t) {
                        first_hit = Some(t);
                        break;
                    }
                    lo = t;
                }
                let Some(mut hi) = first_hit else {
                    worst = worst.max(cap);
                    continue;
                };
                bracket.clear();
                bracket.extend(
                    near.iter()
                        .filter(|c| self.may_hold(c, &(p + n * lo), &(p + n * hi), r_max)),
                );
                let hit = |t: f64| {
                    let x = p + n * t;
                    bracket.iter().any(|c| inside(&profile, self.flute, c, &x))
                };
                for _ in 0..40 {
                    let m = 0.5 * (lo + hi);
                    if hit(m) {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                worst = worst.max(hi);
            }
        }
        worst
    }
}
