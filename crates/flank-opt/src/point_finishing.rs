//! The `blade_point_finishing` operation: finishing of every blade side of any impeller,
//! ruled or free-form, with a ball or tapered ball end.
//!
//! Per row (main, splitter) and side, [`crate::regions`] splits the side into sub-ruled
//! strips within the flank tolerance and keeps a flank pass for each strip whose whole tool
//! is clear of the design (one pass for a ruled side: paper 002's situation; several on a
//! free-form side: paper 001 §4), and point-mills the rest ([`crate::point`]: passes along
//! the flow from tip to root, scallop-controlled, tool axis tilted within the accessible
//! cone, every posture and motion certified for the whole tool, the ball also against the
//! blade-root fillets, [`cam_plan::PassCheck::with_fillets`]). The report says which
//! method each region got and why (`regions`), and what it measured: `max_scallop_mm`
//! (between point-milling passes), `max_overcut_mm` and `max_undercut_mm` (over every
//! region, on the surface the operation leaves), `min_clearance_mm` (smallest clearance of
//! the tool above the ball, shank and holder included, to the design over every posture).
//!
//! The paths are planned on each row's reference blade and copied to every blade of the
//! row.

use crate::geometry::ball_radius;
use crate::point::{AxisParams, PointSettings};
use crate::regions::{self, Method, MethodChoice, SideSettings};
use crate::rows::{self, RowName};
use crate::FlankError;
use cam_core::CutterShape;
use cam_plan::{
    ClearanceOptions, Metrics, Operation, OperationSpec, PartSet, PlanContext, PlanError,
    PlannedOperation,
};
use rayon::prelude::*;
use serde::Deserialize;

/// Kind name in job files.
pub const BLADE_POINT_FINISHING: &str = "blade_point_finishing";

fn default_scallop() -> f64 {
    0.01
}
fn default_method() -> MethodChoice {
    MethodChoice::Auto
}
fn default_along() -> usize {
    30
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

/// The kind's own keys (job file).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointFinishingParams {
    /// Scallop height left between point-milling passes (mm, default 0.01).
    #[serde(default = "default_scallop")]
    pub scallop_mm: f64,
    /// `auto` (default), `point` or `flank`.
    #[serde(default = "default_method")]
    pub method: MethodChoice,
    /// Sub-ruled strip tolerance of the flank regions (mm; default the job's machining_tol).
    #[serde(default)]
    pub flank_tol_mm: Option<f64>,
    /// Even rulings of a flank pass (default 30).
    #[serde(default = "default_along")]
    pub passes_along: usize,
    /// Blade rows finished (default: both rows the impeller has).
    #[serde(default)]
    pub rows: Option<Vec<RowName>>,
    // The axis keys of `point::AxisParams`, spelled out: serde cannot flatten a struct into
    // one with `deny_unknown_fields`, and a misspelt key must stay an error.
    /// Preferred tilt of the axis from the side (deg; default the taper half angle + 8°).
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

impl PointFinishingParams {
    fn axis(&self) -> AxisParams {
        AxisParams {
            tilt_deg: self.tilt_deg,
            max_tilt_deg: self.max_tilt_deg,
            max_lead_deg: self.max_lead_deg,
            search_step_deg: self.search_step_deg,
            max_axis_step_deg: self.max_axis_step_deg,
        }
    }

    fn validate(&self) -> Result<(), FlankError> {
        if !(self.scallop_mm.is_finite() && self.scallop_mm > 0.0 && self.scallop_mm <= 1.0) {
            return Err(FlankError::Param(format!(
                "scallop_mm = {} must be in (0, 1]",
                self.scallop_mm
            )));
        }
        if let Some(t) = self.flank_tol_mm {
            if !(t.is_finite() && t > 0.0) {
                return Err(FlankError::Param(format!("flank_tol_mm = {t} must be > 0")));
            }
        }
        if !(4..=500).contains(&self.passes_along) {
            return Err(FlankError::Param("passes_along must be in 4..=500".into()));
        }
        self.axis().validate()
    }
}

/// The operation.
#[derive(Debug, Clone)]
pub struct BladePointFinishing {
    name: String,
    tool: String,
    params: PointFinishingParams,
}

/// Builds a `blade_point_finishing` operation from its job table.
pub fn build_blade_point_finishing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let params: PointFinishingParams = cam_plan::params::parse(spec)?;
    params.validate().map_err(|e| e.plan(&spec.name))?;
    Ok(Box::new(BladePointFinishing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params,
    }))
}

impl Operation for BladePointFinishing {
    fn kind(&self) -> &'static str {
        BLADE_POINT_FINISHING
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

impl BladePointFinishing {
    fn plan_inner(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, FlankError> {
        let p = &self.params;
        let shape = ctx.tool.cutter.shape;
        let half_angle = match shape {
            CutterShape::BallEnd { .. } => 0.0,
            CutterShape::TaperedBallEnd { half_angle, .. } => half_angle,
            other => {
                return Err(FlankError::Param(format!(
                    "blade point finishing needs a ball or tapered ball end, not {other:?}"
                )))
            }
        };
        let row_list = match &p.rows {
            Some(names) => rows::rows_of(ctx.impeller, names, true)?,
            None => rows::rows_of(ctx.impeller, &rows::default_rows(), false)?,
        };
        let tol = ctx.tolerances.machining_tol;
        let settings = SideSettings {
            choice: p.method,
            strip_tol_mm: p.flank_tol_mm.unwrap_or(tol),
            passes_along: p.passes_along,
            // Finishing: a flank region must leave no more than the flank tolerance.
            flank_residual_mm: Some(p.flank_tol_mm.unwrap_or(tol)),
            // Issue 37: the flank regions' axes are smoothed within the flank tolerance's
            // slack, their residual kept within the flank tolerance
            // (`regions::smooth_flank_region`), as the point-milling runs are
            // (`PointSettings::smooth_axes`). Before, they kept their planned axes and their
            // direction changes went uncounted: on impeller-5-freeform the post found 40
            // reversals inside cuts beyond the operation's reported 280 (3 + 3 + 2 per blade,
            // its three flank strips).
            smooth_flank_axes: true,
            point: PointSettings {
                ball_radius: ball_radius(&shape),
                half_angle,
                allowance_mm: ctx.process.blade_allowance_mm,
                hub_allowance_mm: ctx.process.hub_allowance_mm,
                scallop_mm: p.scallop_mm,
                chord_mm: ctx.tolerances.chord_tol.min(tol),
                tol_mm: tol,
                limits: p.axis().limits(half_angle),
                max_axis_step: p.max_axis_step_deg.to_radians(),
                smooth_axes: true,
            },
        };
        let plan = regions::plan_rows(ctx, &self.name, &self.tool, &row_list, &settings)?;
        let mut m = Metrics::new();
        plan.metrics(&mut m);
        // Issue 37: the point-milling runs' axes smoothed about the ball centres.
        let smoothing = plan.smoothing(ctx.impeller)?;
        smoothing.add_metrics(&mut m);
        // The tool above its ball (flutes, shank, holder) against the design.
        let above = ctx.clearance.with_options(ClearanceOptions {
            parts: PartSet::MATERIAL,
            above_mm: 2.0 * settings.point.ball_radius,
            ..ctx.clearance.options()
        });
        let min_clear = plan
            .regions()
            .flat_map(|g| g.runs.iter())
            .collect::<Vec<_>>()
            .par_iter()
            .map(|run| {
                run.iter()
                    .map(|cl| above.clearance(cl).distance_mm)
                    .fold(f64::INFINITY, f64::min)
            })
            .reduce(|| f64::INFINITY, f64::min);
        m.number("min_clearance_mm", min_clear);
        let len = |method: fn(&Method) -> bool| -> f64 {
            plan.regions()
                .filter(|g| method(&g.method))
                .flat_map(|g| g.runs.iter())
                .map(|run| {
                    run.windows(2)
                        .map(|w| (w[1].tip - w[0].tip).norm())
                        .sum::<f64>()
                })
                .sum()
        };
        m.number("flank_path_length_mm", len(|k| *k != Method::Point));
        m.number("point_path_length_mm", len(|k| *k == Method::Point));
        m.number("scallop_target_mm", p.scallop_mm);
        m.text(
            "rows",
            row_list
                .iter()
                .map(|r| rows::label(*r))
                .collect::<Vec<_>>()
                .join(", "),
        );
        let mut notes = plan.notes();
        notes.push(format!(
            "point-milling runs: {} (about the ball centre: contacts and scallops as planned, \
             the turned postures and their motions checked again for the whole tool)",
            smoothing.note()
        ));
        Ok(PlannedOperation {
            paths: plan.paths.clone(),
            metrics: m,
            plots: smoothing.plot().into_iter().collect(),
            notes,
        })
    }
}
