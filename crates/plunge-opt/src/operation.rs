//! The `plunge_roughing` operation: its job keys, planning of one section of every channel,
//! metrics and plots.

use crate::allowance::{hub_allowance, HubAllowance};
use crate::axis_optimisation::DEFAULT_W_STEP;
use crate::conventional_axes::{Posture, PostureBuilder};
use crate::entries::{pilot_radius, EntryKind, EntryMode, PilotParams};
use crate::feed::{is_increasing, signed_alpha, Feed};
use crate::feed_plan::{plan_feed, stroke, FeedInput, FeedPlan};
use crate::fillet_clearance::{cutter_clears_fillets, FILLET_TOL_MM};
use crate::interference::{
    core_travel, depth_in_stock, interfering_count, travel_of, ClearedRegion, Material, Stroke,
    INTERFERENCE_TRAVEL_TOL_MM,
};
use crate::rows::{plan_rows, stations, ChannelFrame, RowSettings};
use crate::stock_clearance::StockClearance;
use crate::toolpath::channel_path;
use crate::KIND;
use cam_core::CutterShape;
use cam_plan::{
    order, pattern, ClearanceOptions, DesignClearance, Metrics, Operation, OperationSpec, PartSet,
    PlanContext, PlanError, PlannedOperation, PlannedStep, Plot, PlotKind, PlotSeries, StepTool,
    Tool,
};
use impeller_model::fillet::ImpellerFillets;
use rayon::prelude::*;
use serde::Deserialize;

/// Default fraction of the cutting-edge length used as width of cut and plunge step when the
/// process row gives none: 80 % keeps the centre disk inside the previous holes with a margin.
pub const DEFAULT_ENGAGEMENT_FRACTION: f64 = 0.8;
/// Default clearance (mm) of the plunge start over the shroud and the blank.
pub const DEFAULT_START_CLEARANCE_MM: f64 = 2.0;
/// Default number of table stations for the side rows and the section-end search.
pub const DEFAULT_ROW_TABLE_STATIONS: usize = 12;

fn one() -> f64 {
    1.0
}
fn w_step() -> f64 {
    DEFAULT_W_STEP
}
fn yes() -> bool {
    true
}
fn start_clearance() -> f64 {
    DEFAULT_START_CLEARANCE_MM
}
fn table_stations() -> usize {
    DEFAULT_ROW_TABLE_STATIONS
}
fn pilot_mode() -> EntryMode {
    EntryMode::Pilot
}

/// Kind name of the pilot-drilling step in reports.
pub const PILOT_KIND: &str = "pilot_drilling";

/// The kind's own keys (see the crate docs and docs/job.md).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlungeParams {
    /// Meridional fraction of the hub contour where the section begins on its outlet side
    /// (1 = the outlet; the rows then start with a lead-in plunge off the blank). A section
    /// that starts inside the channel treats everything toward the outlet from here as
    /// cleared by the previous section's operation.
    #[serde(default = "one")]
    pub start_fraction: f64,
    /// Where the section ends on its inlet side; default: where the cutter no longer fits
    /// between the blades with the blade allowance.
    #[serde(default)]
    pub end_fraction: Option<f64>,
    /// Parameter step of the discretised W curve (paper 000: 1e-5).
    #[serde(default = "w_step")]
    pub w_curve_step: f64,
    /// Optimise the axes (paper 000 §3); `false` plans the conventional axes.
    #[serde(default = "yes")]
    pub optimise_axes: bool,
    /// Clearance (mm) of the plunge start over the shroud and the blank.
    #[serde(default = "start_clearance")]
    pub start_clearance_mm: f64,
    /// Stations of the side-row table and the section-end search.
    #[serde(default = "table_stations")]
    pub row_table_stations: usize,
    /// First channel machined (the others follow in +θ order).
    #[serde(default)]
    pub first_channel: usize,
    /// Which entries the section may use (see [`crate::entries`]; default `pilot`).
    #[serde(default = "pilot_mode")]
    pub entry: EntryMode,
    /// The pilot drill and its cutting data (`entry = "pilot"` only, and required there).
    #[serde(default)]
    pub pilot: Option<PilotParams>,
}

/// A plunge-roughing operation (one section of every channel).
#[derive(Debug, Clone)]
pub struct PlungeRoughing {
    name: String,
    tool: String,
    params: PlungeParams,
}

impl PlungeRoughing {
    /// From a job's operation table.
    pub fn from_spec(spec: &OperationSpec) -> Result<Self, PlanError> {
        let params: PlungeParams = cam_plan::params::parse(spec)?;
        let bad = |key: &str, reason: String| Err(PlanError::param(&spec.name, key, reason));
        let p = &params;
        if !(p.start_fraction.is_finite() && p.start_fraction > 0.0 && p.start_fraction <= 1.0) {
            return bad(
                "start_fraction",
                format!("{} must be in (0, 1]", p.start_fraction),
            );
        }
        if let Some(e) = p.end_fraction {
            if !(e.is_finite() && (0.0..p.start_fraction).contains(&e)) {
                return bad(
                    "end_fraction",
                    format!("{e} must be in [0, start_fraction = {})", p.start_fraction),
                );
            }
        }
        if !(p.w_curve_step.is_finite() && p.w_curve_step > 0.0 && p.w_curve_step <= 0.01) {
            return bad(
                "w_curve_step",
                format!("{} must be in (0, 0.01]", p.w_curve_step),
            );
        }
        if !(p.start_clearance_mm.is_finite() && p.start_clearance_mm > 0.0) {
            return bad(
                "start_clearance_mm",
                format!("{} must be finite and > 0", p.start_clearance_mm),
            );
        }
        if p.row_table_stations < 2 {
            return bad(
                "row_table_stations",
                format!("{} must be at least 2", p.row_table_stations),
            );
        }
        match (&p.pilot, p.entry) {
            (None, EntryMode::Pilot) => {
                return bad(
                    "pilot",
                    "entry = \"pilot\" (the default) needs a [pilot] table naming the drill \
                     of the job's tools (tool, spindle_rpm, feed_per_tooth_mm); without one, \
                     entry = \"lead_in\" or \"cleared\" lets rows enter only off the blank or \
                     where something already cut"
                        .into(),
                )
            }
            (Some(_), mode) if mode != EntryMode::Pilot => {
                return bad(
                    "pilot",
                    format!(
                        "a pilot drill is used only with entry = \"pilot\", not \"{}\"",
                        mode.name()
                    ),
                )
            }
            (Some(pilot), _) => pilot.validate(&spec.name)?,
            (None, _) => {}
        }
        Ok(Self {
            name: spec.name.clone(),
            tool: spec.tool.clone(),
            params,
        })
    }

    /// The parsed keys.
    pub fn params(&self) -> &PlungeParams {
        &self.params
    }
}

/// Everything planned for channel 0 of one section (before the rotational copy).
#[derive(Debug, Clone)]
pub struct SectionPlan {
    /// Conventional postures per row (station order: outlet → inlet), rows suction →
    /// pressure side.
    pub conventional: Vec<Vec<Posture>>,
    /// The machining order: segments fed by lean, entries, pilots, walked axes, travels.
    pub feed: FeedPlan,
    /// Section ends (meridional fractions): outlet side, inlet side.
    pub range: (f64, f64),
    /// Centre-disk travel through uncut material per plunge of the conventional plan:
    /// conventional axes, every row fed outlet → inlet (mm).
    pub travel_before: Vec<f64>,
    /// Hub allowance with conventional axes.
    pub allowance_before: HubAllowance,
    /// Hub allowance with the final axes.
    pub allowance_after: HubAllowance,
    /// Smallest blade clearance (cutter, shank, holder) of the final postures (mm).
    pub min_blade_clearance_mm: f64,
    /// Positions moved across the channel toward its middle to keep the blade allowance.
    pub shifted_for_clearance: usize,
    /// Plunges left out because shank or holder would enter the stock
    /// ([`crate::stock_clearance`]).
    pub skipped_for_stock: usize,
    /// The pilot drill's radius and the deepest hole it drills in the stock (mm), when the
    /// plan drills pilots.
    pub pilot: Option<(f64, f64)>,
    /// Smallest blade clearance of the pilot drill (cutter, shank, holder) at its holes'
    /// depths (mm; infinite without pilots).
    pub pilot_min_blade_clearance_mm: f64,
    /// Hub length (mm) from the inlet to the section's inlet end: the strip this section
    /// does not rough toward the inlet.
    pub unroughed_hub_length_mm: f64,
    /// Wall-clock time of each planning stage (ms).
    pub timings_ms: Vec<(&'static str, f64)>,
}

impl SectionPlan {
    /// The final postures per segment, in machining order (each in feed order).
    pub fn final_segments(&self) -> Vec<Vec<Posture>> {
        self.feed
            .segments
            .iter()
            .map(|s| s.postures.clone())
            .collect()
    }

    /// Number of segment entries of each kind per channel.
    pub fn entries(&self, kind: EntryKind) -> usize {
        self.feed
            .segments
            .iter()
            .filter(|s| s.entry == kind)
            .count()
    }
}

/// A position tried by the placement: its meridional fraction and, where the cutter keeps the
/// blade allowance somewhere across the channel, the posture and whether it was moved.
type Tried = (f64, Option<(Posture, bool)>);

/// The strokes of `rows` in order.
fn strokes(rows: &[Vec<Posture>], radius: f64, core: f64) -> Vec<Stroke> {
    rows.iter()
        .flatten()
        .map(|p| stroke(p, radius, core))
        .collect()
}

impl PlungeRoughing {
    /// Plans channel 0 of the section with the pilot drill `pilot_tool` (needed when
    /// `entry = "pilot"` and some entry needs a pilot): the geometry behind
    /// [`Operation::plan_with_steps`].
    pub fn plan_section(
        &self,
        ctx: &PlanContext<'_>,
        pilot_tool: Option<&Tool>,
    ) -> Result<SectionPlan, PlanError> {
        let op = self.name.as_str();
        let tool = ctx.tool;
        ctx.process.validate(op)?;
        let (radius, corner) = match tool.cutter.shape {
            CutterShape::FlatEnd { radius } => (radius, 0.0),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => (radius, corner_radius),
            _ => {
                return Err(PlanError::tool(
                    op,
                    tool.name(),
                    "plunge roughing needs a flat-end (or bull-nose) plunge cutter",
                ))
            }
        };
        let edge = tool.plunge_edge_length_mm.ok_or_else(|| {
            PlanError::tool(
                op,
                tool.name(),
                "plunge_edge_length_mm is required (it defines the non-cutting centre disk)",
            )
        })?;
        let core = tool.core_radius().unwrap_or(0.0);
        let pilot_r = match (self.params.entry, pilot_tool) {
            (EntryMode::Pilot, Some(t)) => Some(pilot_radius(t, radius, core, op)?),
            _ => None,
        };
        let engagement = |key: &str, v: Option<f64>| -> Result<f64, PlanError> {
            let v = v.unwrap_or(DEFAULT_ENGAGEMENT_FRACTION * edge);
            if v < edge {
                Ok(v)
            } else {
                Err(PlanError::param(
                    op,
                    format!("process.{key}"),
                    format!("{v} must be below the cutting-edge length {edge} mm"),
                ))
            }
        };
        let width = engagement("width_of_cut_mm", ctx.process.width_of_cut_mm)?;
        let step = engagement("depth_of_cut_mm", ctx.process.depth_of_cut_mm)?;
        let impeller = ctx.impeller;
        let mut clock = std::time::Instant::now();
        let mut timings_ms = Vec::new();
        let mut lap = |stage: &'static str| {
            timings_ms.push((stage, clock.elapsed().as_secs_f64() * 1e3));
            clock = std::time::Instant::now();
        };
        let frame = ChannelFrame::new(impeller, op)?;
        lap("channel_frame");
        let blades = DesignClearance::new(
            impeller,
            tool,
            ClearanceOptions {
                parts: PartSet::BLADES,
                sample_tol_mm: crate::rows::FINAL_CHECK_SAMPLE_TOL_MM,
                above_mm: 0.0,
            },
        )?;
        let required =
            ctx.process.blade_allowance_mm + 0.5 * crate::rows::FINAL_CHECK_SAMPLE_TOL_MM;
        // The blade-root fillets fill the corner the hub floor and the blade clearance leave
        // open; the cutter keeps the smaller of the two allowances from them
        // (crate::fillet_clearance).
        let fillets = ImpellerFillets::new(impeller, FILLET_TOL_MM)
            .map_err(|e| PlanError::geometry(op, "blade-root fillets", e.to_string()))?;
        let fillet_allowance = ctx
            .process
            .blade_allowance_mm
            .min(ctx.process.hub_allowance_mm);
        let keeps_fillets = |p: &Posture, blade_clearance: f64| {
            fillets.as_ref().is_none_or(|f| {
                cutter_clears_fillets(f, &p.cl, radius, blade_clearance, fillet_allowance)
            })
        };
        let builder = PostureBuilder::new(
            impeller,
            ctx.stock,
            radius,
            corner,
            ctx.process.hub_allowance_mm,
            self.params.start_clearance_mm,
            op,
        );
        let search = DesignClearance::new(
            impeller,
            tool,
            ClearanceOptions {
                parts: PartSet::BLADES,
                sample_tol_mm: crate::rows::ROW_SEARCH_SAMPLE_TOL_MM,
                above_mm: 0.0,
            },
        )?;
        let settings = RowSettings {
            blades: &search,
            posture: &builder,
            blade_allowance_mm: ctx.process.blade_allowance_mm,
            width_of_cut_mm: width,
            stations: self.params.row_table_stations,
            operation: op,
        };
        let rows = plan_rows(
            &frame,
            &settings,
            self.params.start_fraction,
            self.params.end_fraction,
        )?;
        lap("rows");
        // The region toward the outlet from a later section's start counts as cleared by the
        // previous section where the stations are placed and in the conventional baseline;
        // the final plan trusts it only with entry = "cleared" (otherwise its measure ignores
        // the previous section: an upper bound of the real travel).
        let cleared = (self.params.start_fraction < 1.0).then(|| ClearedRegion {
            hub: impeller.hub().meridional(),
            fraction: self.params.start_fraction,
        });
        let material = Material {
            cleared,
            ..Material::stock(ctx.stock)
        };
        // The first station: no row's first plunge, fed outlet → inlet, drills with its
        // centre: its centre disk's whole stroke, from the start above the stock to the
        // depth, passes through no material (the axis leans, so the top of the stroke can
        // reach material its hub point is clear of). At the outlet it is a lead-in beyond
        // the outlet whose hub point also lies outside the blank by the core radius plus a
        // margin; inside the channel (a later section) it is moved toward the outlet into
        // what the previous section cleared.
        let at_outlet = self.params.start_fraction >= 1.0;
        let first_clear = |m: f64| -> bool {
            (0..rows.count).all(|j| {
                let s = rows.s(j, m);
                let hub = frame.hub_point(m, s);
                let need = ctx.stock.max_radius() + core + crate::rows::LEAD_IN_MARGIN_MM;
                (!at_outlet || hub.x.hypot(hub.y) >= need)
                    && builder.conventional(&frame, m, s).is_ok_and(|p| {
                        travel_of(&[stroke(&p, radius, core)], 0, &material)
                            <= INTERFERENCE_TRAVEL_TOL_MM
                    })
            })
        };
        let start_point = |j: usize, m: f64| {
            let s = rows.s(j, m);
            Some(builder.stroke_top(&frame.hub_point(m, s), &frame.shroud_point(m, s)))
        };
        let ms = stations(&frame, &rows, step, &first_clear, &start_point);
        // Each position is checked with the fine query; one that misses the allowance
        // (between the row table's stations the interpolated row may approach a blade by
        // more than the search margin) is moved across the channel toward its middle by
        // bisection, to the first place that keeps the allowance.
        let clear = |p: &Posture| {
            let c = blades.clearance(&p.cl).distance_mm;
            c >= required && keeps_fillets(p, c)
        };
        let place = |m: f64, s0: f64| -> Result<Option<(Posture, bool)>, PlanError> {
            let p = builder.conventional(&frame, m, s0)?;
            if clear(&p) {
                return Ok(Some((p, false)));
            }
            let mid = builder.conventional(&frame, m, 0.5)?;
            if !clear(&mid) {
                return Ok(None);
            }
            let (mut bad, mut good, mut best) = (s0, 0.5, mid);
            for _ in 0..crate::rows::SIDE_BISECTIONS {
                let s = 0.5 * (bad + good);
                let q = builder.conventional(&frame, m, s)?;
                if clear(&q) {
                    good = s;
                    best = q;
                } else {
                    bad = s;
                }
            }
            Ok(Some((best, true)))
        };
        let tried: Vec<Vec<Tried>> = (0..rows.count)
            .into_par_iter()
            .map(|j| {
                ms.iter()
                    .map(|&m| place(m, rows.s(j, m)).map(|p| (m, p)))
                    .collect::<Result<Vec<_>, _>>()
            })
            .collect::<Result<_, _>>()?;
        // Where the cutter keeps the allowance nowhere across the channel the section ends
        // (the row planner's coarse search may place its end a little beyond): every position
        // from the first such place toward the inlet is left to the next section.
        let m_cut = tried
            .iter()
            .flatten()
            .filter(|(_, p)| p.is_none())
            .map(|(m, _)| *m)
            .fold(f64::NEG_INFINITY, f64::max);
        let placed: Vec<Vec<(Posture, bool)>> = tried
            .into_iter()
            .map(|r| {
                r.into_iter()
                    .filter(|(m, _)| *m > m_cut)
                    .filter_map(|(_, p)| p)
                    .collect::<Vec<_>>()
            })
            .filter(|r| !r.is_empty())
            .collect();
        if placed.is_empty() {
            return Err(PlanError::geometry(
                op,
                format!(
                    "channel 0, section start at meridional fraction {:.4}",
                    rows.start
                ),
                format!(
                    "the cutter does not keep the blade allowance {} mm anywhere across the \
                     channel",
                    ctx.process.blade_allowance_mm
                ),
            ));
        }
        let section_end = if m_cut.is_finite() {
            placed
                .iter()
                .flatten()
                .map(|(p, _)| p.m)
                .fold(f64::INFINITY, f64::min)
        } else {
            rows.end
        };
        let shifted_for_clearance = placed.iter().flatten().filter(|(_, moved)| *moved).count();
        lap("conventional_axes");
        // Shank and holder keep out of the stock (blank or turned stock) along every plunge;
        // a plunge that cannot is left out (the next section or a shorter stroke from a
        // turned stock reaches its material).
        let stock_check = StockClearance::new(ctx.stock, &tool.cutter, radius);
        let mut skipped_for_stock = 0;
        let mut conventional: Vec<Vec<Posture>> = Vec::with_capacity(placed.len());
        for row in placed {
            let keep: Vec<bool> = row
                .par_iter()
                .map(|(p, _)| stock_check.plunge_clear(p))
                .collect();
            skipped_for_stock += keep.iter().filter(|k| !**k).count();
            let kept: Vec<Posture> = row
                .into_iter()
                .zip(keep)
                .filter(|(_, k)| *k)
                .map(|((p, _), _)| p)
                .collect();
            if !kept.is_empty() {
                conventional.push(kept);
            }
        }
        if conventional.is_empty() {
            return Err(PlanError::tool(
                op,
                tool.name(),
                format!(
                    "at every plunge of the section the shank or holder would enter the stock \
                     (clearance {} mm): a longer stick-out or a turned stock is needed",
                    crate::stock_clearance::STOCK_CLEARANCE_MM
                ),
            ));
        }
        lap("stock_clearance_check");
        // The conventional baseline: conventional axes, every row fed outlet → inlet.
        let before = strokes(&conventional, radius, core);
        let travel_before = core_travel(&before, &material);
        lap("interference_before");
        // The plan: segments fed by lean, entries, pilots, walked axes.
        let admissible = |p: &Posture| {
            let c = blades.clearance(&p.cl).distance_mm;
            c >= required && keeps_fillets(p, c) && stock_check.plunge_clear(p)
        };
        let feed = plan_feed(&FeedInput {
            rows: &conventional,
            radius,
            core,
            mode: self.params.entry,
            pilot_radius: pilot_r,
            material: Material {
                cleared: cleared.filter(|_| self.params.entry == EntryMode::Cleared),
                ..Material::stock(ctx.stock)
            },
            optimise: self.params.optimise_axes,
            w_step: self.params.w_curve_step,
            builder: &builder,
            admissible: &admissible,
            operation: op,
        })?;
        lap("feed_plan");
        // Every final position keeps the blade allowance (cutter, shank, holder).
        let finals: Vec<&Posture> = feed.segments.iter().flat_map(|s| &s.postures).collect();
        // (blade clearance, fillets kept) of each, in parallel: the fillet test samples the
        // cutter where it comes near a blade.
        let clear: Vec<(f64, bool)> = finals
            .par_iter()
            .map(|p| {
                let c = blades.clearance(&p.cl).distance_mm;
                (c, keeps_fillets(p, c))
            })
            .collect();
        let mut min_clear = f64::INFINITY;
        for (p, (c, kept)) in finals.iter().zip(&clear) {
            let why = if *c < required {
                format!(
                    "blade clearance {c:.4} mm is below the blade allowance plus the query's \
                     sampling band, {required} mm"
                )
            } else if !kept {
                format!(
                    "the cutter comes within the allowance {fillet_allowance} mm of a \
                     blade-root fillet"
                )
            } else {
                String::new()
            };
            if !why.is_empty() {
                return Err(PlanError::geometry(
                    op,
                    format!(
                        "channel 0, plunge at meridional fraction {:.4}, row fraction {:.4}",
                        p.m, p.s
                    ),
                    why,
                ));
            }
            min_clear = min_clear.min(*c);
        }
        lap("blade_clearance_check");
        // The pilot drill: blade allowance at every hole's depth, shank and holder out of the
        // stock along every hole.
        let mut pilot = None;
        let mut pilot_min_clear = f64::INFINITY;
        if let (Some(r), Some(drill), false) = (pilot_r, pilot_tool, feed.pilots.is_empty()) {
            let drill_blades = DesignClearance::new(
                impeller,
                drill,
                ClearanceOptions {
                    parts: PartSet::BLADES,
                    sample_tol_mm: crate::rows::FINAL_CHECK_SAMPLE_TOL_MM,
                    above_mm: 0.0,
                },
            )?;
            let drill_stock = StockClearance::new(ctx.stock, &drill.cutter, r);
            let mut depth: f64 = 0.0;
            for p in &feed.pilots {
                let c = drill_blades.clearance(&p.cl).distance_mm;
                let place = || {
                    format!(
                        "pilot hole at meridional fraction {:.4}, row fraction {:.4}",
                        p.m, p.s
                    )
                };
                if c < required {
                    return Err(PlanError::geometry(
                        op,
                        place(),
                        format!(
                            "the pilot drill {} keeps {c:.4} mm from the blades, below the \
                             blade allowance plus the query's sampling band, {required} mm",
                            drill.name()
                        ),
                    ));
                }
                if !drill_stock.plunge_clear(p) {
                    return Err(PlanError::geometry(
                        op,
                        place(),
                        format!(
                            "the shank or holder of the pilot drill {} would enter the stock \
                             (clearance {} mm): a longer drill or stick-out is needed",
                            drill.name(),
                            crate::stock_clearance::STOCK_CLEARANCE_MM
                        ),
                    ));
                }
                pilot_min_clear = pilot_min_clear.min(c);
                depth = depth.max(depth_in_stock(
                    &crate::entries::pilot_stroke(p, r),
                    ctx.stock,
                ));
            }
            pilot = Some((r, depth));
        }
        lap("pilot_check");
        let after: Vec<Stroke> = feed
            .segments
            .iter()
            .flat_map(|s| &s.postures)
            .map(|p| stroke(p, radius, core))
            .collect();
        let m_hi = rows.start.min(1.0);
        let allowance_before = hub_allowance(&frame, &before, section_end, m_hi);
        let allowance_after = hub_allowance(&frame, &after, section_end, m_hi);
        lap("hub_allowance");
        let hub = impeller.hub().meridional();
        let unroughed = hub.arc_length_at(hub.param_at_fraction(section_end.clamp(0.0, 1.0)));
        Ok(SectionPlan {
            conventional,
            feed,
            range: (rows.start, section_end),
            travel_before,
            allowance_before,
            allowance_after,
            min_blade_clearance_mm: min_clear,
            shifted_for_clearance,
            skipped_for_stock,
            pilot,
            pilot_min_blade_clearance_mm: pilot_min_clear,
            unroughed_hub_length_mm: unroughed,
            timings_ms,
        })
    }

    /// The pilot drill named by the job's `[pilot]` table, among `tools`.
    fn pilot_tool<'t>(&self, tools: &[&'t Tool]) -> Option<&'t Tool> {
        let name = &self.params.pilot.as_ref()?.tool;
        tools.iter().copied().find(|t| t.name() == name)
    }

    /// The operation and its pilot-drilling step (when the plan drills pilots).
    fn plan_all(
        &self,
        ctx: &PlanContext<'_>,
        pilot_tool: Option<&Tool>,
    ) -> Result<(PlannedOperation, Vec<PlannedStep>), PlanError> {
        let plan = self.plan_section(ctx, pilot_tool)?;
        let segments = plan.final_segments();
        let radius = ctx
            .tool
            .cutter
            .shape
            .radius_at(ctx.tool.cutter.flute_length);
        let stock_check = StockClearance::new(ctx.stock, &ctx.tool.cutter, radius);
        let rename = |e: PlanError| match e {
            PlanError::Geometry { place, reason, .. } => {
                PlanError::geometry(&self.name, place, reason)
            }
            other => other,
        };
        let (path, lifted) = channel_path(
            &self.name,
            ctx.tool.name(),
            &segments,
            ctx.linker,
            ctx.rates().plunge_mm_per_min,
            &|a, b| stock_check.rapid_clear(a, b),
        )
        .map_err(rename)?;
        let set = ctx.impeller.main();
        let channels = set.count();
        let order = order::angular_sequence(channels, self.params.first_channel % channels.max(1));
        let paths = pattern::copy_to(&path, set.pitch_rad(), &order);

        let mut steps = Vec::new();
        if let (Some(drill), Some(pp), Some((r, _))) =
            (pilot_tool, self.params.pilot.as_ref(), plan.pilot)
        {
            let process = pp.process(ctx.process);
            let holes: Vec<Vec<Posture>> = plan.feed.pilots.iter().map(|p| vec![*p]).collect();
            let drill_stock = StockClearance::new(ctx.stock, &drill.cutter, r);
            let name = format!("{}-pilot", self.name);
            let (pilot_path, _) = channel_path(
                &name,
                drill.name(),
                &holes,
                ctx.linker,
                process.plunge_mm_per_min(drill.teeth),
                &|a, b| drill_stock.rapid_clear(a, b),
            )
            .map_err(rename)?;
            let mut m = Metrics::new();
            m.count("pilots", plan.feed.pilots.len() * channels);
            m.count("pilots_per_channel", plan.feed.pilots.len());
            m.number("pilot_diameter_mm", 2.0 * r);
            m.number("pilot_depth_mm", plan.pilot.map_or(0.0, |p| p.1));
            m.number("min_blade_clearance_mm", plan.pilot_min_blade_clearance_mm);
            steps.push(PlannedStep {
                name: name.clone(),
                kind: PILOT_KIND.into(),
                tool: drill.name().into(),
                process,
                before: true,
                planned: PlannedOperation {
                    paths: pattern::copy_to(&pilot_path, set.pitch_rad(), &order),
                    metrics: m,
                    plots: Vec::new(),
                    notes: vec![format!(
                        "pilot holes of {}: {} per channel, Ø{:.1} mm flat-bottom drill {} along \
                         the entry plunges' axes to their depth, up to {:.1} mm deep in the stock",
                        self.name,
                        plan.feed.pilots.len(),
                        2.0 * r,
                        drill.name(),
                        plan.pilot.map_or(0.0, |p| p.1)
                    )],
                },
            });
        }
        let planned = self.report(&plan, paths, lifted, channels);
        Ok((planned, steps))
    }

    /// Metrics, plots and notes of a planned section.
    fn report(
        &self,
        plan: &SectionPlan,
        paths: Vec<cam_core::ToolPath>,
        lifted: usize,
        channels: usize,
    ) -> PlannedOperation {
        let feed = &plan.feed;
        let per_channel = feed.travel.len();
        let rows = plan.conventional.len();
        let mut m = Metrics::new();
        let before = interfering_count(&plan.travel_before);
        let after = interfering_count(&feed.travel);
        m.count("interference_positions_before", before * channels);
        m.count("interference_positions_after", after * channels);
        m.count("plunges", per_channel * channels);
        m.count("plunges_per_channel", per_channel);
        m.count("rows", rows);
        m.count(
            "stations",
            plan.conventional.iter().map(Vec::len).max().unwrap_or(0),
        );
        m.number(
            "interference_share_before",
            before as f64 / plan.travel_before.len().max(1) as f64,
        );
        m.number(
            "interference_share_after",
            after as f64 / per_channel.max(1) as f64,
        );
        m.number(
            "max_core_travel_before_mm",
            plan.travel_before.iter().copied().fold(0.0, f64::max),
        );
        m.number(
            "max_core_travel_after_mm",
            feed.travel.iter().copied().fold(0.0, f64::max),
        );
        // Entries.
        let mut k = 0;
        let mut entry_travel: f64 = 0.0;
        for s in &feed.segments {
            if let Some(t) = feed.travel.get(k) {
                entry_travel = entry_travel.max(*t);
            }
            k += s.postures.len();
        }
        m.count("entries_per_channel", feed.segments.len());
        m.count(
            "entries_lead_in_per_channel",
            plan.entries(EntryKind::LeadIn),
        );
        m.count(
            "entries_cleared_per_channel",
            plan.entries(EntryKind::Cleared),
        );
        m.count("pilots_per_channel", feed.pilots.len());
        m.count("entries_pilot_per_channel", plan.entries(EntryKind::Pilot));
        m.count("pilots_for_other_plunges_per_channel", feed.interior_pilots);
        m.count(
            "entries_unhandled_per_channel",
            plan.entries(EntryKind::Unhandled),
        );
        m.number("entry_max_core_travel_mm", entry_travel);
        m.number("pilot_diameter_mm", plan.pilot.map_or(0.0, |p| 2.0 * p.0));
        m.number("pilot_depth_mm", plan.pilot.map_or(0.0, |p| p.1));
        m.count(
            "segments_fed_toward_outlet_per_channel",
            feed.segments
                .iter()
                .filter(|s| s.segment.feed == Feed::TowardOutlet)
                .count(),
        );
        // Signed α: the conventional plan (every row fed outlet → inlet) and the final one.
        let alpha_before: Vec<Vec<f64>> = plan
            .conventional
            .iter()
            .map(|r| {
                (0..r.len())
                    .map(|i| signed_alpha(r, i, Feed::TowardInlet))
                    .collect()
            })
            .collect();
        let final_rows = feed.rows(rows);
        let alpha_after: Vec<Vec<(usize, f64)>> = final_rows
            .iter()
            .map(|r| {
                let postures: Vec<Posture> = r.iter().map(|e| e.1).collect();
                r.iter()
                    .enumerate()
                    .map(|(i, e)| (e.0, signed_alpha(&postures, i, e.2)))
                    .collect()
            })
            .collect();
        let deg = |v: f64| v.to_degrees();
        let range = |vals: &mut dyn Iterator<Item = f64>| {
            vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
        };
        let (b_lo, b_hi) = range(&mut alpha_before.iter().flatten().copied());
        let (a_lo, a_hi) = range(&mut alpha_after.iter().flatten().map(|e| e.1));
        m.number("alpha_signed_min_deg", deg(a_lo));
        m.number("alpha_signed_max_deg", deg(a_hi));
        m.number("alpha_signed_min_before_deg", deg(b_lo));
        m.number("alpha_signed_max_before_deg", deg(b_hi));
        // The paper's rule as a diagnostic: signed α increasing along every segment's feed.
        let monotone = feed.segments.iter().all(|s| {
            let row = &final_rows[s.segment.row];
            let postures: Vec<Posture> = row.iter().map(|e| e.1).collect();
            let by_station = |k: usize| row.iter().position(|e| e.0 == k);
            let seq: Vec<f64> = s
                .segment
                .stations
                .iter()
                .filter_map(|&k| by_station(k))
                .map(|i| signed_alpha(&postures, i, s.segment.feed))
                .collect();
            is_increasing(&seq)
        });
        m.flag("alpha_monotone", monotone);
        m.flag(
            "alpha_monotone_before",
            alpha_before.iter().all(|r| is_increasing(r)),
        );
        m.number("hub_allowance_max_mm", plan.allowance_after.max_mm);
        m.number("hub_allowance_mean_mm", plan.allowance_after.mean_mm);
        m.number("hub_allowance_max_before_mm", plan.allowance_before.max_mm);
        m.number(
            "hub_allowance_mean_before_mm",
            plan.allowance_before.mean_mm,
        );
        m.number("min_blade_clearance_mm", plan.min_blade_clearance_mm);
        m.number("section_start_fraction", plan.range.0);
        m.number("section_end_fraction", plan.range.1);
        m.number("unroughed_hub_length_mm", plan.unroughed_hub_length_mm);
        let moved = feed
            .segments
            .iter()
            .flat_map(|s| &s.walked)
            .filter(|x| x.is_some())
            .count();
        m.count("axes_moved_per_channel", moved);
        m.count(
            "axes_moved_against_feed_per_channel",
            feed.segments
                .iter()
                .flat_map(|s| &s.walked)
                .filter(|x| x.is_some_and(|w| !w.1))
                .count(),
        );
        m.count("axes_kept_for_clearance_per_channel", feed.kept);
        m.count(
            "positions_shifted_for_clearance_per_channel",
            plan.shifted_for_clearance,
        );
        m.count(
            "positions_skipped_for_stock_per_channel",
            plan.skipped_for_stock,
        );
        m.count("row_rapids_over_safety_surface_per_channel", lifted);

        let mut series = Vec::new();
        for (j, row) in plan.conventional.iter().enumerate() {
            series.push(PlotSeries {
                label: format!("row {j} conventional, outlet → inlet"),
                points: row
                    .iter()
                    .zip(&alpha_before[j])
                    .map(|(p, a)| [p.m, deg(*a)])
                    .collect(),
            });
            series.push(PlotSeries {
                label: format!("row {j} planned, fed by lean"),
                points: final_rows[j]
                    .iter()
                    .zip(&alpha_after[j])
                    .map(|(e, a)| [e.1.m, deg(a.1)])
                    .collect(),
            });
        }
        let plots = vec![Plot {
            title: format!(
                "{}: signed α (hub normal at the contact vs cutter axis, + toward the feed) \
                 along each row",
                self.name
            ),
            kind: PlotKind::Lines {
                x_label: "meridional fraction (1 = outlet)".into(),
                y_label: "signed α (deg)".into(),
                series,
                equal_aspect: false,
            },
        }];
        let mut notes = vec![format!(
            "section from meridional fraction {:.4} to {:.4}: {} rows, {} plunges per channel \
             in {} segments fed toward where their axes lean ({} inlet → outlet); interference \
             and hub allowance measured on channel 0 (every channel is its rotated copy)",
            plan.range.0,
            plan.range.1,
            rows,
            per_channel,
            feed.segments.len(),
            feed.segments
                .iter()
                .filter(|s| s.segment.feed == Feed::TowardOutlet)
                .count(),
        )];
        notes.push(format!(
            "entries per channel: {} lead-in, {} cleared, {} pilot, {} unhandled (entry = \"{}\"); \
             {} more pilot hole(s) for plunges no admissible W clears",
            plan.entries(EntryKind::LeadIn),
            plan.entries(EntryKind::Cleared),
            plan.entries(EntryKind::Pilot),
            plan.entries(EntryKind::Unhandled),
            self.params.entry.name(),
            feed.interior_pilots
        ));
        if after > 0 {
            notes.push(format!(
                "{after} plunge(s) per channel still run their non-cutting centre through \
                 material (up to {:.3} mm): {} not corrected by any admissible W, {} unhandled \
                 entries",
                feed.travel.iter().copied().fold(0.0, f64::max),
                feed.kept,
                plan.entries(EntryKind::Unhandled)
            ));
        }
        notes.push(format!(
            "the hub from the inlet to meridional fraction {:.4} ({:.1} mm along the hub) is not \
             roughed by this section: its cutter does not fit between the blades with the blade \
             allowance there (unroughed_hub_length_mm; a later section with a smaller cutter, \
             or finishing, must take it)",
            plan.range.1, plan.unroughed_hub_length_mm
        ));
        notes.push(format!(
            "planning stages (ms): {}",
            plan.timings_ms
                .iter()
                .map(|(k, v)| format!("{k} {v:.0}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        if plan.skipped_for_stock > 0 {
            notes.push(format!(
                "{} plunge(s) per channel left out: the shank or holder would enter the stock \
                 (clearance {} mm; a turned stock or a longer stick-out reaches them)",
                plan.skipped_for_stock,
                crate::stock_clearance::STOCK_CLEARANCE_MM
            ));
        }
        PlannedOperation {
            paths,
            metrics: m,
            plots,
            notes,
        }
    }
}

impl Operation for PlungeRoughing {
    fn kind(&self) -> &'static str {
        KIND
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn tool(&self) -> &str {
        &self.tool
    }

    /// Plans without the pilot drill: fails when an entry needs a pilot hole (the pipeline
    /// calls [`Operation::plan_with_steps`] with the drill).
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        // Without the drill no pilot step is planned.
        let (planned, _) = self.plan_all(ctx, None)?;
        Ok(planned)
    }

    fn step_tools(&self) -> Vec<StepTool> {
        self.params
            .pilot
            .iter()
            .map(|p| StepTool {
                key: "pilot.tool".into(),
                tool: p.tool.clone(),
            })
            .collect()
    }

    fn plan_with_steps(
        &self,
        ctx: &PlanContext<'_>,
        tools: &[&Tool],
    ) -> Result<(PlannedOperation, Vec<PlannedStep>), PlanError> {
        self.plan_all(ctx, self.pilot_tool(tools))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(params: &str) -> OperationSpec {
        OperationSpec {
            name: "plunge".into(),
            kind: KIND.into(),
            tool: "plunge-d30".into(),
            process: toml::from_str("spindle_rpm = 3000.0\nfeed_per_tooth_mm = 0.1")
                .expect("process"),
            params: toml::from_str(params).expect("params"),
        }
    }

    fn key_of(r: Result<PlungeRoughing, PlanError>) -> String {
        match r {
            Err(PlanError::Param { key, .. }) => key,
            other => format!("not a parameter error: {other:?}"),
        }
    }

    #[test]
    fn entry_keys_name_the_pilot_drill_when_and_only_when_it_drills() {
        // The default entry is "pilot": it needs the drill.
        assert_eq!(key_of(PlungeRoughing::from_spec(&spec(""))), "pilot");
        let pilot = "[pilot]\ntool = \"drill-d16\"\nspindle_rpm = 4000.0\nfeed_per_tooth_mm = 0.1";
        let op = PlungeRoughing::from_spec(&spec(pilot)).expect("pilot entry");
        assert_eq!(op.params().entry, EntryMode::Pilot);
        assert_eq!(
            op.step_tools(),
            vec![StepTool {
                key: "pilot.tool".into(),
                tool: "drill-d16".into()
            }]
        );
        // Without a drill: lead-in or cleared entries, and no step.
        let op = PlungeRoughing::from_spec(&spec("entry = \"lead_in\"")).expect("lead-in");
        assert!(op.step_tools().is_empty());
        assert!(PlungeRoughing::from_spec(&spec("entry = \"cleared\"")).is_ok());
        // A drill with another mode would not be used; bad values name their key.
        assert_eq!(
            key_of(PlungeRoughing::from_spec(&spec(&format!(
                "entry = \"cleared\"\n{pilot}"
            )))),
            "pilot"
        );
        assert_eq!(
            key_of(PlungeRoughing::from_spec(&spec(
                "[pilot]\ntool = \"d\"\nspindle_rpm = -1.0\nfeed_per_tooth_mm = 0.1"
            ))),
            "pilot.spindle_rpm"
        );
        assert_eq!(
            key_of(PlungeRoughing::from_spec(&spec("entry = \"drill\""))),
            "entry"
        );
    }
}
