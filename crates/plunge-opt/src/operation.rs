//! The `plunge_roughing` operation: its job keys, planning of one section of every channel,
//! metrics and plots.

use crate::allowance::{hub_allowance, HubAllowance};
use crate::axis_optimisation::{optimise_row_within, OptimisedRow, DEFAULT_W_STEP};
use crate::conventional_axes::{Posture, PostureBuilder};
use crate::interference::{
    core_travel, interfering_count, travel_of, ClearedRegion, Material, Stroke,
    INTERFERENCE_TRAVEL_TOL_MM,
};
use crate::rows::{plan_rows, stations, ChannelFrame, RowSettings};
use crate::stock_clearance::StockClearance;
use crate::toolpath::channel_path;
use crate::KIND;
use cam_core::CutterShape;
use cam_plan::{
    order, pattern, ClearanceOptions, DesignClearance, Metrics, Operation, OperationSpec, PartSet,
    PlanContext, PlanError, PlannedOperation, Plot, PlotKind, PlotSeries,
};
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
    /// Conventional postures per row (outlet → inlet), rows suction → pressure side.
    pub conventional: Vec<Vec<Posture>>,
    /// Optimised rows (same order); equal to the conventional ones when optimisation is off.
    pub optimised: Vec<OptimisedRow>,
    /// Section ends (meridional fractions): outlet side, inlet side.
    pub range: (f64, f64),
    /// Centre-disk travel through uncut material per plunge, conventional axes (mm).
    pub travel_before: Vec<f64>,
    /// The same with the final axes (mm).
    pub travel_after: Vec<f64>,
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
    /// Wall-clock time of each planning stage (ms).
    pub timings_ms: Vec<(&'static str, f64)>,
}

impl SectionPlan {
    /// The final postures per row.
    pub fn final_rows(&self) -> Vec<Vec<Posture>> {
        self.optimised.iter().map(|r| r.postures.clone()).collect()
    }
}

/// A position tried by the placement: its meridional fraction and, where the cutter keeps the
/// blade allowance somewhere across the channel, the posture and whether it was moved.
type Tried = (f64, Option<(Posture, bool)>);

/// The stroke of one plunge.
fn stroke(p: &Posture, radius: f64, core: f64) -> Stroke {
    Stroke {
        start: p.start.tip,
        end: p.cl.tip,
        axis: p.cl.axis.into_inner(),
        radius,
        core_radius: core,
    }
}

/// The strokes of `rows` in machining order.
fn strokes(rows: &[Vec<Posture>], radius: f64, core: f64) -> Vec<Stroke> {
    rows.iter()
        .flatten()
        .map(|p| stroke(p, radius, core))
        .collect()
}

impl PlungeRoughing {
    /// Plans channel 0 of the section (the geometry behind [`Operation::plan`]).
    pub fn plan_section(&self, ctx: &PlanContext<'_>) -> Result<SectionPlan, PlanError> {
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
        // What the strokes run through: the stock, less what an earlier section cleared when
        // this one starts inside the channel (the interference metric's material).
        let material = Material {
            stock: ctx.stock,
            cleared: (self.params.start_fraction < 1.0).then(|| ClearedRegion {
                hub: impeller.hub().meridional(),
                fraction: self.params.start_fraction,
            }),
        };
        // The first plunge of every row must not drill: its centre disk's whole stroke, from
        // the start above the stock to the depth, passes through no material (the axis leans,
        // so the top of the stroke can reach material its hub point is clear of). At the
        // outlet it is a lead-in beyond the outlet whose hub point also lies outside the
        // blank by the core radius plus a margin; inside the channel (a later section) it is
        // moved toward the outlet into what the previous section cleared.
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
        let clear = |p: &Posture| blades.clearance(&p.cl).distance_mm >= required;
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
        let conventional: Vec<Vec<Posture>> = placed
            .into_iter()
            .map(|r| r.into_iter().map(|(p, _)| p).collect())
            .collect();
        lap("conventional_axes");
        let optimised: Vec<OptimisedRow> = if self.params.optimise_axes {
            conventional
                .par_iter()
                .map(|row| {
                    // A moved axis must keep the blade allowance, and the move must not
                    // make its centre disk run into more material than without it, counting
                    // the row's earlier plunges as optimised (a large move of W turns the
                    // axis by degrees: the centre disk can leave the previous hole on the
                    // way down). The next plunge is judged when its own turn comes.
                    let admissible = |p: &Posture, unmoved: &Posture, before: &[Posture]| {
                        if blades.clearance(&p.cl).distance_mm < required {
                            return false;
                        }
                        let n = before.len();
                        let mut list: Vec<Stroke> =
                            before.iter().map(|q| stroke(q, radius, core)).collect();
                        list.push(stroke(p, radius, core));
                        let moved = travel_of(&list, n, &material);
                        list[n] = stroke(unmoved, radius, core);
                        moved <= travel_of(&list, n, &material).max(INTERFERENCE_TRAVEL_TOL_MM)
                    };
                    optimise_row_within(&builder, row, self.params.w_curve_step, op, &admissible)
                })
                .collect::<Result<_, _>>()?
        } else {
            conventional
                .iter()
                .map(|row| OptimisedRow {
                    postures: row.clone(),
                    alpha_before: row.iter().map(|p| p.alpha).collect(),
                    alpha_after: row.iter().map(|p| p.alpha).collect(),
                    moves: vec![None; row.len()],
                    monotone: row.windows(2).all(|w| w[1].alpha > w[0].alpha),
                    w_curve: None,
                    step: self.params.w_curve_step,
                    kept_for_clearance: 0,
                })
                .collect()
        };
        lap("axis_optimisation");
        // Every final position keeps the blade allowance (cutter, shank, holder).
        let finals: Vec<&Posture> = optimised.iter().flat_map(|r| &r.postures).collect();
        let clear: Vec<f64> = finals
            .par_iter()
            .map(|p| blades.clearance(&p.cl).distance_mm)
            .collect();
        let mut min_clear = f64::INFINITY;
        for (p, c) in finals.iter().zip(&clear) {
            if *c < required {
                return Err(PlanError::geometry(
                    op,
                    format!(
                        "channel 0, plunge at meridional fraction {:.4}, row fraction {:.4}",
                        p.m, p.s
                    ),
                    format!(
                        "blade clearance {c:.4} mm is below the blade allowance plus the query's \
                         sampling band, {required} mm"
                    ),
                ));
            }
            min_clear = min_clear.min(*c);
        }
        lap("blade_clearance_check");
        // Shank and holder keep out of the stock (blank or turned stock) along every plunge;
        // a plunge that cannot is left out (the next section or a shorter stroke from a
        // turned stock reaches its material).
        let stock_check = StockClearance::new(ctx.stock, &tool.cutter, radius);
        let mut optimised = optimised;
        let mut skipped_for_stock = 0;
        for row in &mut optimised {
            let keep: Vec<bool> = row
                .postures
                .par_iter()
                .map(|p| stock_check.plunge_clear(p))
                .collect();
            skipped_for_stock += keep.iter().filter(|k| !**k).count();
            let mut k = keep.iter();
            row.postures.retain(|_| *k.next().unwrap_or(&true));
            let mut k = keep.iter();
            row.alpha_before.retain(|_| *k.next().unwrap_or(&true));
            let mut k = keep.iter();
            row.alpha_after.retain(|_| *k.next().unwrap_or(&true));
            let mut k = keep.iter();
            row.moves.retain(|_| *k.next().unwrap_or(&true));
        }
        optimised.retain(|r| !r.postures.is_empty());
        if optimised.is_empty() {
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
        let before = strokes(&conventional, radius, core);
        let final_rows: Vec<Vec<Posture>> = optimised.iter().map(|r| r.postures.clone()).collect();
        let after = strokes(&final_rows, radius, core);
        let travel_before = core_travel(&before, &material);
        let travel_after = core_travel(&after, &material);
        lap("interference");
        let m_hi = rows.start.min(1.0);
        let allowance_before = hub_allowance(&frame, &before, section_end, m_hi);
        let allowance_after = hub_allowance(&frame, &after, section_end, m_hi);
        lap("hub_allowance");
        Ok(SectionPlan {
            conventional,
            optimised,
            range: (rows.start, section_end),
            travel_before,
            travel_after,
            allowance_before,
            allowance_after,
            min_blade_clearance_mm: min_clear,
            shifted_for_clearance,
            skipped_for_stock,
            timings_ms,
        })
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

    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        let plan = self.plan_section(ctx)?;
        let rows = plan.final_rows();
        let radius = ctx
            .tool
            .cutter
            .shape
            .radius_at(ctx.tool.cutter.flute_length);
        let stock_check = StockClearance::new(ctx.stock, &ctx.tool.cutter, radius);
        let (path, lifted) = channel_path(
            &self.name,
            ctx.tool.name(),
            &rows,
            ctx.linker,
            ctx.rates().plunge_mm_per_min,
            &|a, b| stock_check.rapid_clear(a, b),
        )
        .map_err(|e| match e {
            PlanError::Geometry { place, reason, .. } => {
                PlanError::geometry(&self.name, place, reason)
            }
            other => other,
        })?;
        let set = ctx.impeller.main();
        let channels = set.count();
        let order = order::angular_sequence(channels, self.params.first_channel % channels.max(1));
        let paths = pattern::copy_to(&path, set.pitch_rad(), &order);

        let per_channel = plan.travel_after.len();
        let mut m = Metrics::new();
        let before = interfering_count(&plan.travel_before);
        let after = interfering_count(&plan.travel_after);
        m.count("interference_positions_before", before * channels);
        m.count("interference_positions_after", after * channels);
        // The first plunge of every row (the lead-in beyond the outlet, or the first plunge
        // inside what the previous section cleared) must not drill (see `plan_section`).
        let mut k = 0;
        let mut first: f64 = 0.0;
        for r in &plan.optimised {
            if let Some(t) = plan.travel_after.get(k) {
                first = first.max(*t);
            }
            k += r.postures.len();
        }
        m.number("first_plunge_max_core_travel_mm", first);
        m.count("plunges", per_channel * channels);
        m.count("plunges_per_channel", per_channel);
        m.count("rows", rows.len());
        m.count("stations", rows.first().map_or(0, Vec::len));
        m.number(
            "interference_share_before",
            before as f64 / per_channel.max(1) as f64,
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
            plan.travel_after.iter().copied().fold(0.0, f64::max),
        );
        let monotone = plan.optimised.iter().all(|r| r.monotone);
        m.flag("alpha_monotone", monotone);
        m.flag(
            "alpha_monotone_before",
            plan.optimised
                .iter()
                .all(|r| r.alpha_before.windows(2).all(|w| w[1] > w[0])),
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
        let moved = plan
            .optimised
            .iter()
            .flat_map(|r| &r.moves)
            .filter(|x| x.is_some())
            .count();
        m.count("axes_moved_per_channel", moved);
        m.count(
            "positions_shifted_for_clearance_per_channel",
            plan.shifted_for_clearance,
        );
        m.count(
            "positions_skipped_for_stock_per_channel",
            plan.skipped_for_stock,
        );
        m.count("row_rapids_over_safety_surface_per_channel", lifted);
        m.count(
            "axes_kept_for_clearance_per_channel",
            plan.optimised.iter().map(|r| r.kept_for_clearance).sum(),
        );

        let mut series = Vec::new();
        for (j, r) in plan.optimised.iter().enumerate() {
            let xs: Vec<f64> = r.postures.iter().map(|p| p.m).collect();
            let pts = |a: &[f64]| -> Vec<[f64; 2]> {
                xs.iter()
                    .zip(a)
                    .map(|(x, y)| [*x, y.to_degrees()])
                    .collect()
            };
            series.push(PlotSeries {
                label: format!("row {j} conventional"),
                points: pts(&r.alpha_before),
            });
            series.push(PlotSeries {
                label: format!("row {j} optimised"),
                points: pts(&r.alpha_after),
            });
        }
        let plots = vec![Plot {
            title: format!(
                "{}: α (hub normal at the contact vs cutter axis) along each row, outlet → inlet",
                self.name
            ),
            kind: PlotKind::Lines {
                x_label: "meridional fraction (1 = outlet)".into(),
                y_label: "α (deg)".into(),
                series,
                equal_aspect: false,
            },
        }];
        let mut notes = vec![format!(
            "section from meridional fraction {:.4} to {:.4}: {} rows × {} stations per channel; \
             interference and hub allowance measured on channel 0 (every channel is its rotated copy)",
            plan.range.0,
            plan.range.1,
            rows.len(),
            rows.first().map_or(0, Vec::len)
        )];
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
        if !monotone {
            notes.push(
                "alpha_monotone = false: on some row the W curve ended before α could increase"
                    .into(),
            );
        }
        Ok(PlannedOperation {
            paths,
            metrics: m,
            plots,
            notes,
        })
    }
}
