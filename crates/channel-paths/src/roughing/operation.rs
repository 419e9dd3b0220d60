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
//! where a path runs into the splitter or an unmachinable strip), `saving_ratio_count_bound`
//! (what the lanes' shape allows: paths at a constant interval `d` are `⌈w/d⌉ + 1` at a
//! section of width `w(s)`, the two boundary paths included, while the baseline runs
//! `⌈w_max/d⌉ + 1` paths the whole length `L` of the lane, so no such path set saves more than
//! `1 − Σ ∫ (⌈w/d⌉ + 1) ds / Σ (⌈w_max/d⌉ + 1)·L` over the lanes, up to the paths' slant; a
//! lane that narrows little toward the inlet leaves little to save), `saving_ratio_with_links`
//! (the in-lane feed with the links between paths against the baseline planned, ordered and
//! linked by the same code; see [`super::ordering`] and [`super::locate`]),
//! `max_scallop_mm` (measured over the machinable region: rays along the level normal from a
//! grid of points of every lane to the first cutter position of the level, the cutters taken
//! at the emitted locations of every lane of the level densified to a sixteenth of the ball
//! radius along each cut, within 0.002 mm of the swept cutter at 0.5 mm scallops), `levels`,
//! `paths`, `min_blade_clearance_mm` (the whole tool against the blades alone, asked as the
//! postures are certified: exact up to [`super::locate::BLADE_METRIC_BAND_MM`] above the
//! allowance), `level_area_mm2` and `unmachinable_area_mm2` (developed areas over all levels and
//! channels, trapezoidal on the area grids), the skip, split and bridge counts above.
//!
//! Cost: per level O(sections · (width / scan + 12) · candidates) cutter queries for the fit
//! (most sections need one query per sample: the ball test and the first axis settle them),
//! O(points · candidates) posture queries (mostly one or two) and O(points · 2⁴) motion
//! checks in the worst case. Levels run in parallel (rayon).

use super::fit::FitQuery;
use super::joins::{self, LevelChunks};
use super::level::LevelPlan;
use super::locate::{LevelCl, Locator};
use super::ordering::Linking;
use cam_core::{CutterShape, ToolPath};
use cam_plan::{
    ClearanceOptions, DesignClearance, Metrics, Operation, OperationSpec, PartSet, PlanContext,
    PlanError, PlannedOperation,
};
use impeller_model::levels::{depth_level, DepthLevel, LevelSpacing};
use rayon::prelude::*;
use serde::Deserialize;

/// Kind name in job files.
pub const CHANNEL_ROUGHING: &str = "channel_roughing";

/// How many times a level is planned again with a narrower path interval when its measured
/// scallop exceeds the target (module docs, step 3).
pub const SCALLOP_REPLANS: usize = 3;
/// Factor applied to the interval correction `√(target / measured)` of a re-plan, so that
/// the next measurement lands below the target rather than on it (the scallop of a ball
/// grows about with the square of the step-over).
pub const SCALLOP_REPLAN_MARGIN: f64 = 0.99;

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
    /// Feed (mm/min) of the retracts that cut nothing (module docs of `joins`); default: the
    /// process row's `rapid_mm_per_min`.
    #[serde(default)]
    pub link_feed_mm_per_min: Option<f64>,
}

/// The operation.
#[derive(Debug, Clone)]
pub struct ChannelRoughing {
    pub(super) name: String,
    pub(super) tool: String,
    pub(super) params: ChannelRoughingParams,
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
    if params
        .link_feed_mm_per_min
        .is_some_and(|f| !(f.is_finite() && f > 0.0))
    {
        return Err(PlanError::param(
            &spec.name,
            "link_feed_mm_per_min",
            "must be finite and > 0",
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

impl ChannelRoughing {
    pub(super) fn geo(&self, place: impl Into<String>, reason: impl Into<String>) -> PlanError {
        PlanError::geometry(&self.name, place, reason)
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
        // A level's wall is cut by the flutes over the whole depth of cut: deeper, the shank
        // would rub on it (and the blade offset below would be the cone's radius at a height
        // the cutter does not have).
        let flutes = ctx.tool.cutter.flute_length;
        if doc > flutes + 1e-9 {
            return Err(PlanError::param(
                &self.name,
                "process.depth_of_cut_mm",
                format!(
                    "{doc} mm is deeper than the flutes of tool {} ({flutes} mm): the shank \
                     would rub on every level's wall",
                    self.tool
                ),
            ));
        }
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
        let blades_only = ctx.clearance.with_options(ClearanceOptions {
            parts: PartSet {
                hub: false,
                blades: true,
                shroud: false,
            },
            ..ClearanceOptions::default()
        });
        let fit = FitQuery {
            tool: blades_only.clone(),
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
        let loc = Locator {
            op: self,
            ctx,
            fit: &fit,
            fit_min,
            doc,
            blades_only: &blades_only,
        };
        // Each level planned, located and measured; a level whose measured scallop exceeds
        // the target is planned again with its path interval narrowed (module docs, step 3).
        let target = self.params.scallop_mm;
        let levels_done = std::sync::atomic::AtomicUsize::new(0);
        ctx.progress("levels", 0, n_levels);
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
                    let lc = self.locate_level(&loc, &lp, &lp.bounds)?;
                    if lc.max_scallop <= target || replans == SCALLOP_REPLANS {
                        return Ok((lp, lc, replans));
                    }
                    scale *= (target / lc.max_scallop).sqrt() * SCALLOP_REPLAN_MARGIN;
                    replans += 1;
                    level = lp.level;
                    bounds = lp.bounds;
                }
            })
            .inspect(|_| {
                let done = levels_done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                ctx.progress("levels", done, n_levels);
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

        // One channel's path: the chunks of every level joined, levels shroud → hub (module
        // docs of `joins`).
        let mut sum = Sums {
            min_clear: f64::INFINITY,
            ..Sums::default()
        };
        for lc in &per_level {
            sum.add(lc);
        }
        let area_mm2: f64 = levels.iter().map(|l| l.area_mm2).sum();
        let planned_mm2: f64 = levels.iter().map(|l| l.planned_mm2).sum();
        let chunks: Vec<LevelChunks> = levels
            .iter()
            .zip(&per_level)
            .map(|(lp, lc)| LevelChunks {
                chunks: lc.chunks.clone(),
                step: lp
                    .areas
                    .iter()
                    .map(|a| a.step)
                    .fold(f64::INFINITY, f64::min),
            })
            .collect();
        let joined = joins::join(ctx, &chunks, doc, self.params.linking == Linking::ZigZag)?;
        let mut path = ToolPath::new(self.name.clone(), self.tool.clone());
        path.moves = joined.moves;
        ctx.close(&mut path, doc)?;
        let link_feed = self
            .params
            .link_feed_mm_per_min
            .unwrap_or(ctx.process.rapid_mm_per_min);
        let (fast_retracts, slow_retracts) = joins::retract_feeds(ctx, &mut path.moves, link_feed);
        let count = imp.main().count();
        let order = cam_plan::order::angular_sequence(count, 0);
        let paths = cam_plan::pattern::copy_to(&path, imp.main().pitch_rad(), &order);
        let k = count as f64;
        let mut metrics = Metrics::new();
        metrics
            .number("triangle_path_length_mm", sum.tri_len * k)
            .number("isoparametric_path_length_mm", sum.iso_len * k)
            .number("saving_ratio", saving(sum.tri_len, sum.iso_len))
            .number(
                "saving_ratio_count_bound",
                saving(sum.count_len, sum.baseline_count_len),
            )
            .number(
                "saving_ratio_with_links",
                saving(sum.lane_feed_len, sum.iso_lane_feed_len),
            )
            .number("lane_feed_length_mm", sum.lane_feed_len * k)
            .number(
                "isoparametric_lane_feed_length_mm",
                sum.iso_lane_feed_len * k,
            )
            .number(
                "isoparametric_channel_path_length_mm",
                sum.channel_iso_len * k,
            )
            .number(
                "saving_ratio_whole_channel",
                saving(sum.tri_len, sum.channel_iso_len),
            )
            .number("in_lane_link_length_mm", sum.lane_link_len * k)
            .number("level_link_length_mm", sum.level_link_len * k)
            .count("in_lane_links", sum.lane_links * count)
            .count("in_lane_breaks", sum.lane_breaks * count)
            .count("retracts_per_channel", joined.retracts + 1)
            .count("level_links_per_channel", sum.level_links)
            .count("step_downs_per_channel", joined.step_downs)
            .count("retracts_at_link_feed", fast_retracts * count)
            .count("retracts_at_cutting_feed", slow_retracts * count)
            .count("dropped_short_pieces", sum.dropped * count)
            .count("kept_short_pieces", sum.short_kept * count)
            .number("max_scallop_mm", sum.max_scallop)
            .number("scallop_target_mm", self.params.scallop_mm)
            .count("scallop_replanned_levels", replanned_levels)
            .count("levels", n_levels)
            .count("paths", sum.paths * count)
            .number("min_blade_clearance_mm", sum.min_clear)
            .number("level_area_mm2", area_mm2 * k)
            .number(
                "unmachinable_area_mm2",
                (area_mm2 - planned_mm2).max(0.0) * k,
            )
            .count(
                "skipped_locations",
                (sum.skipped_cutter + sum.skipped_tool) * count,
            )
            .count("skipped_cutter_blocked", sum.skipped_cutter * count)
            .count("skipped_shank_or_holder", sum.skipped_tool * count)
            .count("split_motions", sum.split * count)
            .count("bridge_postures", sum.bridged * count);
        let smoothing = std::mem::take(&mut sum.smoothing).times(count);
        smoothing.add_metrics(&mut metrics);
        let mut plots = self.plot(&levels, &per_level);
        plots.extend(smoothing.plot());
        let offsets = levels
            .iter()
            .flat_map(|l| l.bounds.iter().map(|b| b.offset.abs()))
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), o| {
                (lo.min(o), hi.max(o))
            });
        if paths.iter().all(|p| p.moves.is_empty()) {
            // Nothing roughed: every later operation would meet the whole blank.
            return Err(self.geo(
                "every level",
                format!(
                    "the cutter (blade offset {:.3}–{:.3} mm) fits nowhere between the blades \
                     on the {n_levels} level(s) of ≤ {doc} mm ({:.0} mm² of levels, all \
                     channels): nothing is roughed; a smaller cutter or a smaller depth of cut \
                     may fit",
                    offsets.0,
                    offsets.1,
                    area_mm2 * k,
                ),
            ));
        }
        Ok(PlannedOperation {
            paths,
            metrics,
            plots,
            notes: vec![
                smoothing.note(),
                format!(
                    "{n_levels} levels of ≤ {doc} mm; {} bounding sides per level (ruled over \
                     each level's span band, offset {:.3}–{:.3} mm); the cutter does not fit \
                     with {:.3} mm from the blades on {:.0} of {:.0} mm² of the levels (all \
                     channels), left unplanned",
                    levels.first().map_or(0, |l| l.bounds.len()),
                    offsets.0,
                    offsets.1,
                    fit_min,
                    (area_mm2 - planned_mm2).max(0.0) * k,
                    area_mm2 * k,
                ),
                format!(
                    "links: per channel {} links between paths on the level at the cutting \
                     feed (they may cut: they cross the lane at the level), {} joins between \
                     lanes on a level at the cutting feed and {} step downs to the next level \
                     at the plunge feed (each certified clear of the design by the roughing \
                     allowance); {} retracts over the safety surface, of which {} along the \
                     tool axis clear of the blank at {:.0} mm/min (they cut nothing) and {} at \
                     the cutting feed; approaches rapid down to the blank, then at the plunge \
                     feed",
                    sum.lane_links,
                    sum.level_links,
                    joined.step_downs,
                    joined.retracts + 1,
                    fast_retracts,
                    link_feed,
                    slow_retracts,
                ),
            ],
        })
    }
}

/// The level measurements summed over the levels of one channel.
#[derive(Debug, Default)]
struct Sums {
    tri_len: f64,
    iso_len: f64,
    channel_iso_len: f64,
    lane_feed_len: f64,
    iso_lane_feed_len: f64,
    count_len: f64,
    baseline_count_len: f64,
    lane_link_len: f64,
    lane_links: usize,
    lane_breaks: usize,
    level_links: usize,
    level_link_len: f64,
    dropped: usize,
    short_kept: usize,
    min_clear: f64,
    max_scallop: f64,
    paths: usize,
    skipped_cutter: usize,
    skipped_tool: usize,
    split: usize,
    bridged: usize,
    smoothing: cam_plan::SmoothingSummary,
}

impl Sums {
    fn add(&mut self, lc: &LevelCl) {
        self.tri_len += lc.tri_len;
        self.iso_len += lc.iso_len;
        self.channel_iso_len += lc.channel_iso_len;
        self.lane_feed_len += lc.lane_feed_len;
        self.iso_lane_feed_len += lc.iso_lane_feed_len;
        self.count_len += lc.count_len;
        self.baseline_count_len += lc.baseline_count_len;
        self.lane_link_len += lc.lane_link_len;
        self.lane_links += lc.lane_links;
        self.lane_breaks += lc.lane_breaks;
        self.level_links += lc.level_links;
        self.level_link_len += lc.level_link_len;
        self.dropped += lc.dropped_pieces;
        self.short_kept += lc.short_pieces_kept;
        self.min_clear = self.min_clear.min(lc.min_blade_clearance);
        self.max_scallop = self.max_scallop.max(lc.max_scallop);
        self.paths += lc.paths;
        self.skipped_cutter += lc.skipped_cutter;
        self.skipped_tool += lc.skipped_tool;
        self.split += lc.split_motions;
        self.bridged += lc.bridge_postures;
        self.smoothing.merge(&lc.smoothing);
    }
}

/// `1 − triangle / baseline` (0 without a baseline).
fn saving(triangle: f64, baseline: f64) -> f64 {
    if baseline > 0.0 {
        1.0 - triangle / baseline
    } else {
        0.0
    }
}
