//! The `channel_roughing` operation: the channel between the approximated ruled blades
//! roughed level by level from the shroud down to the hub, each level planned with triangle
//! paths (paper 001 §3) in the areas of paper 003 (upstream of the splitter's leading edge and
//! the two sub-channels beside the splitter).
//!
//! Per channel (channel 0, copied to every channel by rotation):
//! 1. Every bounding blade side is replaced by its ruled approximation
//!    ([`impeller_model::ruled::ruled_approximation`]) pushed out by its allowance so that it
//!    contains the true side ("blade with thickness"), and offset by the cutter radius plus
//!    the process' blade allowance: `δ = R + blade_allowance + ruled allowance`.
//! 2. Levels: `n = ⌈max depth / depth_of_cut⌉` interpolated levels between the shroud
//!    (excluded) and the hub offset by the hub allowance (the last level), so that no step
//!    between levels exceeds `depth_of_cut_mm` anywhere along the channel.
//! 3. On each level the boundaries are where the offset ruled sides meet the level
//!    ([`impeller_model::levels::offset_surface_on_level`]), the area(s) between them are
//!    planned in the developed plane ([`super::plan2d`]) with the path interval that leaves
//!    `scallop_mm` on the level: the exact inverse of the scallop construction of
//!    [`cam_core::contact`] at the level's largest convex curvature across the channel
//!    (`κ = N_r / r`), capped by the process' `width_of_cut_mm`.
//! 4. Each path point is put on the level; the tool axis interpolates the rulings of the two
//!    ruled blades bounding the area at the point's cross-channel fraction (leaning with the
//!    blades), limited to `max_tilt_deg` from the level normal, averaged over
//!    `axis_smoothing` neighbours along the path; the cutter location touches the level there
//!    ([`cam_core::contact_location`]); every location is checked with the design clearance
//!    query (cutter, shank, holder against hub and true blades) and, if not clear, retried
//!    with the axis along the level normal; a location clear in neither posture is left
//!    uncut (the path is split there, linked over the safety surface, and counted in
//!    `skipped_locations`), so no emitted location gouges the design. The motion between two
//!    consecutive locations (and every link move inside an area) is checked as a whole with
//!    [`cam_plan::DesignClearance::segment_clearance_between`] (certified bisection, within
//!    half the machining tolerance); a motion that is not clear gets one planned midpoint
//!    and, if a half is still not clear, the path is split there (`split_motions`).
//!
//! Metrics: `path_length_mm` (pipeline), `triangle_path_length_mm` and
//! `isoparametric_path_length_mm` (cutting paths of all channels, measured in space on the
//! levels), `saving_ratio = 1 − triangle / isoparametric`, `max_scallop_mm` (measured: rays
//! along the level normal from a grid of points of every area to the first cutter position
//! of the level, the cutters taken at locations densified to a quarter radius), `levels`,
//! `paths`, `min_blade_clearance_mm` (clearance query against the true blades).

use super::plan2d::{self, Linking, Path2, Region};
use crate::accessibility::limit_tilt;
use cam_core::{contact_location, CutterLocation, CutterShape, Move, MoveKind, ToolPath};
use cam_plan::{
    ClearanceOptions, Metrics, Operation, OperationSpec, PartSet, PlanContext, PlanError,
    PlannedOperation, Plot, PlotKind, PlotSeries,
};
use impeller_model::levels::{depth_level, offset_surface_on_level, DepthLevel, LevelSpacing};
use impeller_model::ruled::ruled_approximation;
use impeller_model::{Blade, Impeller, Side};
use nalgebra::{Unit, Vector3};
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
const SEGMENT_QUERIES: usize = 24;

/// Largest spacing of path points along the flow (mm) when the chord rule allows more.
const MAX_POINT_SPACING_MM: f64 = 1.0;

/// Grid of scallop measurement per area and level (along × across the flow).
const SCALLOP_GRID: (usize, usize) = (40, 16);

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

/// One planned area of one level.
struct AreaPlan {
    level: usize,
    tri: Vec<Path2>,
    iso: Vec<Path2>,
    links: Vec<Path2>,
    region: Region,
    left: Tab,
    right: Tab,
}

struct LevelPlan {
    level: DepthLevel,
    areas: Vec<AreaPlan>,
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

    fn bound(
        &self,
        ctx: &PlanContext<'_>,
        blade: &Blade,
        side: Side,
        label: &str,
        radius: f64,
    ) -> Result<Bound, PlanError> {
        let imp = ctx.impeller;
        let v = side_v_range(imp, blade, side).map_err(|e| {
            self.geo(
                label,
                format!("blade side does not reach both hub and shroud: {e}"),
            )
        })?;
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
        Ok(Bound {
            label: label.into(),
            ruled: ruled.surface,
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
        let mut bounds = vec![
            self.bound(ctx, &ch.left, ch.left_side(), "left blade", radius)?,
            self.bound(ctx, &ch.right, ch.right_side(), "right blade", radius)?,
        ];
        if let Some(sp) = &ch.splitter {
            let minus = sp.plus_theta_side().other();
            bounds.push(self.bound(ctx, sp, minus, "splitter −θ side", radius)?);
            bounds.push(self.bound(ctx, sp, sp.plus_theta_side(), "splitter +θ side", radius)?);
        }
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
        let levels: Vec<Result<LevelPlan, PlanError>> = (1..=n_levels)
            .into_par_iter()
            .map(|j| {
                let spacing = LevelSpacing::Interpolated {
                    fraction: j as f64 / n_levels as f64,
                    hub_offset: hub_allow,
                };
                let level =
                    depth_level(imp, spacing).map_err(|e| PlanError::model(&self.name, e))?;
                self.plan_level(ctx, j, level, &bounds)
            })
            .collect();
        let levels: Vec<LevelPlan> = levels.into_iter().collect::<Result<_, _>>()?;

        // Cutter locations, level by level.
        let blades_only = ctx.clearance.with_options(ClearanceOptions {
            parts: PartSet {
                hub: false,
                blades: true,
                shroud: false,
            },
            ..ClearanceOptions::default()
        });
        let per_level: Vec<Result<LevelCl, PlanError>> = levels
            .par_iter()
            .map(|lp| self.locate_level(ctx, lp, &bounds, &blades_only, doc))
            .collect();
        let per_level: Vec<LevelCl> = per_level.into_iter().collect::<Result<_, _>>()?;

        // One channel's path, levels shroud → hub, areas in order, linked over the safety
        // surface between areas.
        let mut path = ToolPath::new(self.name.clone(), self.tool.clone());
        let mut last: Option<CutterLocation> = None;
        let mut tri_len = 0.0;
        let mut iso_len = 0.0;
        let mut min_clear = f64::INFINITY;
        let mut max_scallop: f64 = 0.0;
        let mut n_paths = 0usize;
        let mut skipped = 0usize;
        let mut split = 0usize;
        for lc in &per_level {
            tri_len += lc.tri_len;
            iso_len += lc.iso_len;
            min_clear = min_clear.min(lc.min_blade_clearance);
            max_scallop = max_scallop.max(lc.max_scallop);
            n_paths += lc.paths;
            skipped += lc.skipped;
            split += lc.split_motions;
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
            .number(
                "saving_ratio",
                if iso_len > 0.0 {
                    1.0 - tri_len / iso_len
                } else {
                    0.0
                },
            )
            .number("max_scallop_mm", max_scallop)
            .number("scallop_target_mm", self.params.scallop_mm)
            .count("levels", n_levels)
            .count("paths", n_paths * count)
            .number("min_blade_clearance_mm", min_clear)
            .count("skipped_locations", skipped * count)
            .count("split_motions", split * count);
        let plots = self.plot(&levels);
        Ok(PlannedOperation {
            paths,
            metrics,
            plots,
            notes: vec![format!(
                "{n_levels} levels of ≤ {doc} mm; {} bounding sides (ruled, offset {:.3} mm)",
                bounds.len(),
                bounds.first().map_or(0.0, |b| b.offset.abs())
            )],
        })
    }

    fn plan_level(
        &self,
        ctx: &PlanContext<'_>,
        j: usize,
        level: DepthLevel,
        bounds: &[Bound],
    ) -> Result<LevelPlan, PlanError> {
        let place = |b: &Bound| format!("level {j}, {}", b.label);
        let mut curves = Vec::with_capacity(bounds.len());
        for b in bounds {
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
        let step = self.interval(ctx, &level)?;
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
            // Unwrap the right boundary to the turn nearest the left one: the channel spans
            // less than half a turn, so a negative width means the offset boundaries cross.
            let tau = std::f64::consts::TAU;
            for ((ry, ly), &si) in right.y.iter_mut().zip(&left.y).zip(&s) {
                let turn = tau * level.radius_at(si);
                *ry = ly + (*ry - ly + 0.5 * turn).rem_euclid(turn) - 0.5 * turn;
            }
            // The tool fits where the offset boundaries do not cross: plan every run of
            // grid points with right ≥ left as its own area (narrower parts are left for
            // the next tool / operation and counted in the notes of the caller).
            let mut i = 0;
            while i < n {
                if right.y[i] < left.y[i] {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < n && right.y[i] >= left.y[i] {
                    i += 1;
                }
                if i - start < 2 {
                    continue;
                }
                let cut = |t: &Tab| Tab {
                    y: t.y[start..i].to_vec(),
                    u: t.u[start..i].to_vec(),
                    ruled: t.ruled,
                };
                let region = Region {
                    s: s[start..i].to_vec(),
                    left: left.y[start..i].to_vec(),
                    right: right.y[start..i].to_vec(),
                };
                let area_place =
                    format!("level {j}, area {} / {}", bounds[a].label, bounds[b].label);
                let tri = plan2d::triangle(&region, step)
                    .map_err(|e| self.geo(&area_place, e.to_string()))?;
                let iso = plan2d::isoparametric(&region, step)
                    .map_err(|e| self.geo(&area_place, e.to_string()))?;
                let (tri, links) = plan2d::link(tri, self.params.linking);
                areas.push(AreaPlan {
                    level: j,
                    tri,
                    iso,
                    links,
                    region,
                    left: cut(&left),
                    right: cut(&right),
                });
            }
        }
        Ok(LevelPlan { level, areas })
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
    min_blade_clearance: f64,
    max_scallop: f64,
    paths: usize,
    skipped: usize,
    /// Motions between two collision-free postures that were not clear even with a planned
    /// midpoint (the path was split there).
    split_motions: usize,
}

impl ChannelRoughing {
    fn locate_level(
        &self,
        ctx: &PlanContext<'_>,
        lp: &LevelPlan,
        bounds: &[Bound],
        blades_only: &cam_plan::DesignClearance<'_>,
        doc: f64,
    ) -> Result<LevelCl, PlanError> {
        let shape = ctx.tool.cutter.shape;
        let max_tilt = self.params.max_tilt_deg.to_radians();
        let mut out = LevelCl {
            moves: Vec::new(),
            tri_len: 0.0,
            iso_len: 0.0,
            min_blade_clearance: f64::INFINITY,
            max_scallop: 0.0,
            paths: 0,
            skipped: 0,
            split_motions: 0,
        };
        // Motions between postures may come this far below zero clearance (the other half
        // of the machining tolerance is the clearance query's own sampling error).
        let seg_tol = 0.5 * ctx.tolerances.machining_tol;
        for area in &lp.areas {
            let lv = &lp.level;
            let point_of = |q: [f64; 2]| {
                let theta = q[1] / lv.radius_at(q[0]);
                lv.at_developed(q[0], theta)
            };
            let ruling = |b: usize, u: f64| {
                let r = &bounds[b].ruled;
                (r.point(u, 1.0) - r.point(u, 0.0)).normalize()
            };
            // Axis wanted at a planar point: rulings interpolated across the area.
            let axis_at = |q: [f64; 2], n: &Vector3<f64>| {
                let (l, r) = area.region.bounds(q[0]);
                let f = if r > l {
                    ((q[1] - l) / (r - l)).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                let ul = interp(&area.region.s, &area.left.u, q[0]);
                let ur = interp(&area.region.s, &area.right.u, q[0]);
                let a = ruling(area.left.ruled, ul) * (1.0 - f) + ruling(area.right.ruled, ur) * f;
                limit_tilt(a.try_normalize(1e-12).unwrap_or(*n), n, max_tilt)
            };
            let place = |q: [f64; 2]| {
                format!(
                    "level {}, s = {:.3} mm, y = {:.3} mm",
                    area.level, q[0], q[1]
                )
            };
            let mut chunks: Vec<Vec<Move>> = Vec::new();
            let mut cur: Vec<Move> = Vec::new();
            let mut level_cls: Vec<CutterLocation> = Vec::new();
            for (pi, path) in area.tri.iter().enumerate() {
                let pts: Vec<(Vector3<f64>, Vector3<f64>)> =
                    path.iter().map(|&q| point_of(q)).collect();
                let raw: Vec<Vector3<f64>> = path
                    .iter()
                    .zip(&pts)
                    .map(|(&q, (_, n))| axis_at(q, n))
                    .collect();
                let smooth = smooth_axes(&raw, self.params.axis_smoothing);
                // A collision-free posture at planar point `q` (wanted axis `a`, else the
                // level normal) with its clearance, or `None`.
                let posture = |q: [f64; 2],
                               p: &Vector3<f64>,
                               n: &Vector3<f64>,
                               a: &Vector3<f64>|
                 -> Result<
                    Option<(CutterLocation, cam_plan::Clearance)>,
                    PlanError,
                > {
                    let a = limit_tilt(*a, n, max_tilt);
                    let cl = self.touch(&shape, p, n, &a, q, &place)?;
                    let c = ctx.clearance.clearance(&cl);
                    if c.distance_mm >= 0.0 {
                        return Ok(Some((cl, c)));
                    }
                    let alt = self.touch(&shape, p, n, n, q, &place)?;
                    let ca = ctx.clearance.clearance(&alt);
                    Ok((ca.distance_mm >= 0.0).then_some((alt, ca)))
                };
                let mut found: Vec<Option<(CutterLocation, cam_plan::Clearance)>> =
                    Vec::with_capacity(path.len());
                for ((&q, (p, n)), a) in path.iter().zip(&pts).zip(&smooth) {
                    let f = posture(q, p, n, a)?;
                    if f.is_none() {
                        // Neither posture is collision-free: the point is left uncut (the
                        // path is split there and the measured scallop shows the residue).
                        out.skipped += 1;
                    }
                    found.push(f);
                }
                // The motions between consecutive postures are checked too (the axis may
                // change between them): a motion that is not clear gets one planned
                // midpoint; when a half is still not clear the path is split there (the
                // linker retracts and approaches around the gap).
                let seg_ok =
                    |a: &(CutterLocation, cam_plan::Clearance),
                     b: &(CutterLocation, cam_plan::Clearance)| {
                        ctx.clearance
                            .segment_clearance_between(
                                (&a.0, a.1.distance_mm),
                                (&b.0, b.1.distance_mm),
                                0.0,
                                seg_tol,
                                SEGMENT_QUERIES,
                            )
                            .is_ok()
                    };
                let mut checked: Vec<Option<(CutterLocation, cam_plan::Clearance)>> =
                    Vec::with_capacity(found.len());
                for k in 0..found.len() {
                    if k > 0 {
                        if let (Some(a), Some(b)) = (&found[k - 1], &found[k]) {
                            if !seg_ok(a, b) {
                                let qm = [
                                    0.5 * (path[k - 1][0] + path[k][0]),
                                    0.5 * (path[k - 1][1] + path[k][1]),
                                ];
                                let (pm, nm) = point_of(qm);
                                let am = smooth[k - 1] + smooth[k];
                                let mid = posture(qm, &pm, &nm, &am)?
                                    .filter(|m| seg_ok(a, m) && seg_ok(m, b));
                                if mid.is_none() {
                                    out.split_motions += 1;
                                }
                                checked.push(mid);
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
                // Link from the previous path inside the area (one-way links lifted by the
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
                            let (p, n) = point_of(q);
                            let a = axis_at(q, &n);
                            let cl = self.touch(&shape, &p, &n, &a, q, &place)?;
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
                for (k, c) in cls.iter().enumerate() {
                    match c {
                        Some(cl) => {
                            // The path's first point is already the link's end.
                            let dup = k == 0 && cur.last().is_some_and(|m| m.cl == *cl);
                            if !dup {
                                cur.push(Move::feed(*cl));
                            }
                            level_cls.push(*cl);
                        }
                        None => {
                            if !cur.is_empty() {
                                chunks.push(std::mem::take(&mut cur));
                            }
                        }
                    }
                }
                out.paths += 1;
            }
            if !cur.is_empty() {
                chunks.push(cur);
            }
            for path in &area.iso {
                out.iso_len += polyline_len(path.iter().map(|&q| point_of(q).0));
            }
            out.max_scallop = out.max_scallop.max(measure_scallop(
                &shape,
                ctx.tool.cutter.flute_length,
                &level_cls,
                area,
                lv,
                doc,
            ));
            out.moves.extend(chunks);
        }
        Ok(out)
    }

    fn touch(
        &self,
        shape: &CutterShape,
        p: &Vector3<f64>,
        n: &Vector3<f64>,
        a: &Vector3<f64>,
        q: [f64; 2],
        place: &impl Fn([f64; 2]) -> String,
    ) -> Result<CutterLocation, PlanError> {
        contact_location(
            shape,
            (*p).into(),
            Unit::new_normalize(*n),
            Unit::new_normalize(*a),
        )
        .map(|c| c.cl)
        .map_err(|e| self.geo(place(q), e.to_string()))
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
fn inside(shape: &CutterShape, flute: f64, cl: &CutterLocation, x: &Vector3<f64>) -> bool {
    let a = cl.axis.into_inner();
    let d = x - cl.tip.coords;
    let h = d.dot(&a);
    if !(0.0..=flute).contains(&h) {
        return false;
    }
    (d - a * h).norm() <= shape.radius_at(h)
}

/// Largest scallop over a grid of the area: from each grid point of the level, the distance
/// along the level normal to the first cutter position (module docs); at most `cap`.
fn measure_scallop(
    shape: &CutterShape,
    flute: f64,
    cls: &[CutterLocation],
    area: &AreaPlan,
    lv: &DepthLevel,
    cap: f64,
) -> f64 {
    if cls.is_empty() {
        return 0.0;
    }
    let reach = match *shape {
        CutterShape::BallEnd { radius }
        | CutterShape::BullNose { radius, .. }
        | CutterShape::TaperedBallEnd {
            ball_radius: radius,
            ..
        } => radius,
        _ => 0.0,
    };
    // Densify consecutive locations to a quarter radius.
    let mut dense: Vec<CutterLocation> = Vec::with_capacity(cls.len() * 2);
    for w in cls.windows(2) {
        let d = (w[1].tip - w[0].tip).norm();
        let k = ((d / (0.25 * reach)).ceil() as usize).clamp(1, 64);
        if d > 4.0 * reach {
            dense.push(w[0]);
            continue;
        }
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
    let (ns, ny) = SCALLOP_GRID;
    let (s0, s1) = (area.region.s[0], area.region.s[area.region.s.len() - 1]);
    let mut worst: f64 = 0.0;
    for i in 0..=ns {
        let s = s0 + (s1 - s0) * i as f64 / ns as f64;
        let (l, r) = area.region.bounds(s);
        for j in 0..=ny {
            let y = l + (r - l) * j as f64 / ny as f64;
            let (p, n) = lv.at_developed(s, y / lv.radius_at(s));
            let near: Vec<&CutterLocation> = dense
                .iter()
                .filter(|c| (c.tip.coords - p).norm() <= 2.0 * reach + cap)
                .collect();
            let hit = |t: f64| {
                let x = p + n * t;
                near.iter().any(|c| inside(shape, flute, c, &x))
            };
            if hit(0.0) {
                continue;
            }
            if !hit(cap) {
                worst = worst.max(cap);
                continue;
            }
            let (mut lo, mut hi) = (0.0, cap);
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
