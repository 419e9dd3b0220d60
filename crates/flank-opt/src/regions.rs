//! The rule that chooses, per blade side and per region of it, how the side is cut: one
//! flank pass, flank passes over sub-ruled strips, or five-axis point milling.
//!
//! A side is split into sub-ruled strips within the tolerance `τ`
//! ([`impeller_model::ruled::sub_ruled_strips`], greedy from the shroud down; paper 001
//! §4). Each strip gets its flank pass ([`crate::semi::strip_pass`]); the pass is kept when
//! its whole tool — cutter over its whole flute length, shank and holder — keeps the pass
//! floors against the whole design along every posture and motion
//! ([`cam_plan::PassCheck`]): the blade side itself and every other blade at the blade
//! allowance less `τ` and the chord tolerance, the hub at the hub allowance less the same.
//! Otherwise the strip is point-milled ([`crate::point`]), and the message of the first
//! violation is the reason given. A flank pass over a concave side fails this way: the
//! straight flutes above a lower strip run into the side's upper part.
//!
//! The method of each region is reported: `flank` when one strip covers the whole side
//! (the side is ruled within `τ`), `sub_ruled_flank` for the strips of a free-form side,
//! `point` for the rest, with the reason. Adjacent point-milled strips form one band.
//! `method = "point"` point-mills every side whole; `method = "flank"` refuses a side with
//! a strip that cannot be flanked (naming the strip and the violation).
//!
//! Measurement: flank regions are measured against the pass's swept envelope (certified
//! signed distances, [`cam_core::SweptEnvelope`]) and point regions against the swept balls
//! ([`crate::point::scallop`]), over a grid of the region, giving the largest overcut and
//! residual of the surface the operation is to leave (the side offset by its allowance).

use crate::axis_smoothing::{accuracy_turn_limit, kept_for_accuracy, within_budget};
use crate::point::{self, scallop::SweptBalls, BandPlan, PointSettings};
use crate::rows;
use crate::semi::strip_pass;
use crate::FlankError;
use cam_core::{CutterLocation, Point3};
use cam_plan::axis_smoothing::RunSmoothing;
use cam_plan::{FilletMargin, PassCheck, PassFloors, PlanContext, Row};
use impeller_model::{Blade, Side};
use serde::Deserialize;

/// How a side may be cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MethodChoice {
    /// Flank where a flank pass is within tolerance and clear, point milling elsewhere.
    Auto,
    /// Point milling everywhere.
    Point,
    /// Flank passes only (an error where one cannot be made).
    Flank,
}

/// The method a region got.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// One flank pass over the whole side.
    Flank,
    /// A flank pass over a sub-ruled strip.
    SubRuledFlank,
    /// Five-axis point milling.
    Point,
}

impl Method {
    /// The report's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Flank => "flank",
            Method::SubRuledFlank => "sub_ruled_flank",
            Method::Point => "point",
        }
    }
}

/// What a side's planning needs.
#[derive(Debug, Clone, Copy)]
pub struct SideSettings {
    /// Method choice.
    pub choice: MethodChoice,
    /// Sub-ruled strip tolerance τ (mm).
    pub strip_tol_mm: f64,
    /// Even rulings per flank pass.
    pub passes_along: usize,
    /// Largest material a flank pass may leave on its strip (mm, measured on the side offset
    /// by the allowance); a strip whose clear flank pass leaves more is point-milled. `None`
    /// accepts any clear flank pass (semi-finishing, whose leftover the finishing takes).
    /// A ruled strip within τ does not make a flank pass within τ: the cone cannot stay
    /// tangent along every ruling of a twisted (non-developable) ruled surface.
    pub flank_residual_mm: Option<f64>,
    /// Whether the tool axes of each flank pass are smoothed within its accuracy slack
    /// ([`smooth_flank_region`]).
    pub smooth_flank_axes: bool,
    /// Point milling of the other regions.
    pub point: PointSettings,
}

/// One region of a side and how it was cut.
#[derive(Debug, Clone)]
pub struct Region {
    /// Row.
    pub row: Row,
    /// Side.
    pub side: Side,
    /// Side parameters v (low, high).
    pub v_range: (f64, f64),
    /// Method.
    pub method: Method,
    /// Why.
    pub reason: String,
    /// Largest strip deviation from its ruled surface (flank regions), mm.
    pub deviation_mm: Option<f64>,
    /// Feed runs in machining order (each needs a link before it unless it continues the
    /// previous one directly).
    pub runs: Vec<Vec<CutterLocation>>,
    /// Largest overcut measured (mm).
    pub max_overcut_mm: f64,
    /// Largest residual above the allowance measured over the region (mm).
    pub max_residual_mm: f64,
    /// Largest residual between point-milling passes (mm; 0 for flank regions).
    pub max_scallop_mm: f64,
    /// Whether a flank pass was lifted.
    pub lifted: bool,
    /// The point-milling plan (point regions).
    pub band: Option<BandPlan>,
    /// The axis smoothing of a flank pass ([`smooth_flank_region`]), when asked for.
    pub axis_smoothing: Option<RunSmoothing>,
}

/// The regions of one side, shroud end first.
#[derive(Debug, Clone)]
pub struct SidePlan {
    /// Regions in machining order.
    pub regions: Vec<Region>,
    /// Sub-ruled strips found at τ.
    pub strips: usize,
    /// Largest strip deviation (mm).
    pub max_strip_deviation_mm: f64,
}

/// Grid of the measurement of a region: points along u and across v per mm.
const MEASURE_ALONG: usize = 160;
/// Measurement rows across a region per point-milling pass step (at least 6 rows).
const MEASURE_ROWS_PER_PASS: usize = 4;
/// Residual cap of the measurement (mm above the allowance).
const MEASURE_CAP_MM: f64 = 2.0;

/// The pass floors of a cut leaving `allowance` on blades and `hub_allowance` on the hub,
/// eating at most `tol` into either; motions certified within `motion_tol`.
pub fn floors(allowance: f64, hub_allowance: f64, tol: f64, motion_tol: f64) -> PassFloors {
    PassFloors {
        blades_mm: allowance - tol,
        hub_mm: hub_allowance - tol,
        motion_tol_mm: motion_tol,
    }
}

/// Height above the tip (mm) from which a point-milling motion is certified as a whole: the
/// ball and the flutes just above it, which run at the allowance from the side, are checked
/// at sampled postures instead ([`cam_plan::pass_check`], [`point::split_height`]).
pub fn point_split_mm(ctx: &PlanContext<'_>, st: &PointSettings) -> f64 {
    point::split_height(
        st.ball_radius,
        st.half_angle,
        st.limits.tilt,
        ctx.tool.cutter.flute_length,
    )
}

/// The side's v range between hub and shroud edges.
pub fn side_v_range(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    side: Side,
) -> Result<(f64, f64), FlankError> {
    match blade.design() {
        Some(_) => Ok(blade.hub_shroud_v(side)),
        None => ctx.impeller.span_v_range(blade, side).map_err(|e| {
            FlankError::Geometry(format!("{side:?} side: hub or shroud edge not found: {e}"))
        }),
    }
}

/// Plans one side of the reference blade of `row` (module docs).
pub fn plan_side(
    ctx: &PlanContext<'_>,
    row: Row,
    side: Side,
    st: &SideSettings,
    fillets: Option<&FilletMargin>,
) -> Result<SidePlan, FlankError> {
    let blade = rows::blade_set(ctx.impeller, row)?.blade().clone();
    let v_range = side_v_range(ctx, &blade, side)?;
    let a = st.point.allowance_mm;
    let a_h = st.point.hub_allowance_mm;
    let tol = st.strip_tol_mm;
    let chord = ctx.tolerances.chord_tol;
    let flank_check = PassCheck::new(
        ctx.clearance,
        floors(a, a_h, tol + chord, chord),
        ctx.tool.cutter.flute_length,
    )
    .with_fillets(fillets);
    let point_check = PassCheck::new(
        ctx.clearance,
        floors(a, a_h, st.point.tol_mm, chord),
        point_split_mm(ctx, &st.point),
    )
    .with_postures_above(st.point.ball_radius)
    .with_fillets(fillets);
    let label = rows::label(row);
    let strips = if st.choice == MethodChoice::Point {
        Vec::new()
    } else {
        impeller_model::ruled::sub_ruled_strips(&blade, side, v_range, tol)?
    };
    let max_dev = strips
        .iter()
        .map(|s| s.max_deviation_mm)
        .fold(0.0f64, f64::max);
    let whole = strips.len() == 1;
    // Each strip: a flank pass if it is clear, else a point band (merged with neighbours).
    let mut regions: Vec<Region> = Vec::new();
    let mut pending_point: Option<((f64, f64), String)> = None;
    let flush = |pending: &mut Option<((f64, f64), String)>,
                 regions: &mut Vec<Region>|
     -> Result<(), FlankError> {
        if let Some((band, reason)) = pending.take() {
            regions.push(point_region(
                ctx,
                &blade,
                row,
                side,
                band,
                reason,
                st,
                &point_check,
            )?);
        }
        Ok(())
    };
    if st.choice == MethodChoice::Point {
        pending_point = Some((v_range, "method = \"point\"".into()));
    }
    for strip in &strips {
        let outcome = strip_pass(ctx, &blade, side, strip, v_range, a, st.passes_along, tol)
            .map_err(|e| e.to_string())
            .and_then(|pass| {
                let v = flank_check.check(&pass.locations);
                match v
                    .iter()
                    .max_by(|x, y| x.depth_mm().total_cmp(&y.depth_mm()))
                {
                    Some(w) => Err(format!(
                        "its flank pass is not clear ({} postures or motions): {}",
                        v.len(),
                        w.describe()
                    )),
                    None => Ok(pass),
                }
            });
        // A clear pass must also leave no more than the residual limit on its strip.
        let outcome = match outcome {
            Ok(pass) => {
                let (over, residual) =
                    measure_flank(&blade, side, strip.v_range, &pass.envelope, a)?;
                match st.flank_residual_mm {
                    Some(limit) if residual > limit => Err(format!(
                        "its flank pass is clear but leaves {residual:.4} mm > {limit} mm \
                         (the cone cannot follow the strip's twist)"
                    )),
                    _ => Ok((pass, over, residual)),
                }
            }
            Err(why) => Err(why),
        };
        let outcome = match outcome {
            Ok((pass, over, residual)) if st.smooth_flank_axes => {
                let sm = smooth_flank_region(
                    ctx,
                    (&blade, side, strip.v_range),
                    &pass,
                    (over, residual),
                    st,
                    &flank_check,
                )?;
                Ok((pass, sm.over, sm.residual, Some(sm)))
            }
            Ok((pass, over, residual)) => Ok((pass, over, residual, None)),
            Err(why) => Err(why),
        };
        match outcome {
            Ok((pass, over, residual, smoothed)) => {
                flush(&mut pending_point, &mut regions)?;
                let (locations, axis_smoothing) = match smoothed {
                    Some(sm) => (sm.run.postures.clone(), Some(sm.run)),
                    None => (pass.locations, None),
                };
                let method = if whole {
                    Method::Flank
                } else {
                    Method::SubRuledFlank
                };
                regions.push(Region {
                    row,
                    side,
                    v_range: strip.v_range,
                    method,
                    reason: match st.flank_residual_mm {
                        Some(limit) => format!(
                            "ruled within {:.4} mm ≤ {tol} mm, the whole tool is clear and \
                             the pass leaves {residual:.4} mm ≤ {limit} mm",
                            strip.max_deviation_mm
                        ),
                        None => format!(
                            "ruled within {:.4} mm ≤ {tol} mm and the whole tool is clear",
                            strip.max_deviation_mm
                        ),
                    },
                    deviation_mm: Some(strip.max_deviation_mm),
                    runs: vec![locations],
                    max_overcut_mm: over,
                    max_residual_mm: residual,
                    max_scallop_mm: 0.0,
                    lifted: pass.lifted,
                    band: None,
                    axis_smoothing,
                });
            }
            Err(why) => {
                if st.choice == MethodChoice::Flank {
                    return Err(FlankError::Geometry(format!(
                        "{label} blade {side:?} side, strip v ∈ [{:.4}, {:.4}]: {why} \
                         (method = \"flank\"; \"auto\" point-mills such strips)",
                        strip.v_range.0, strip.v_range.1
                    )));
                }
                let band = match pending_point.take() {
                    Some(((lo, hi), first)) => {
                        ((lo.min(strip.v_range.0), hi.max(strip.v_range.1)), first)
                    }
                    None => (strip.v_range, why),
                };
                pending_point = Some(band);
            }
        }
    }
    flush(&mut pending_point, &mut regions)?;
    Ok(SidePlan {
        regions,
        strips: strips.len(),
        max_strip_deviation_mm: max_dev,
    })
}

/// Rounding allowed to the overcut of a smoothed flank pass over its planned one (mm).
pub const NO_WORSE_MM: f64 = 1e-6;

/// A flank pass after [`smooth_flank_region`]: its axis smoothing and the measurement of
/// the pass written.
#[derive(Debug, Clone)]
pub struct SmoothedFlank {
    /// The smoothing (its postures are the pass written).
    pub run: RunSmoothing,
    /// Largest overcut and residual of the pass written (mm, [`measure_flank`]).
    pub over: f64,
    /// See `over`.
    pub residual: f64,
}

/// The tool axes of a clear flank pass over a strip made monotone about the impeller axis
/// within the strip tolerance's slack ([`crate::axis_smoothing`]): the turn about the ball
/// centres limited to what moves no cutter point more than `τ − overcut` (first four times
/// that, then that), the changed postures and motions checked with the pass's whole-tool
/// `check`, the smoothed pass's envelope ([`crate::semi::pass_envelope`]) measured again over
/// the strip ([`measure_flank`]) and accepted only when its overcut does not grow (the
/// allowance left to finishing is not eaten further; [`NO_WORSE_MM`] for rounding) and its
/// residual grows by at most the slack, and stays within the operation's residual limit
/// where it has one (finishing: `flank_residual_mm`). Otherwise the planned pass stays and every
/// direction change of its axis is reported with [`cam_plan::KeptReason::Accuracy`]. Cost: up to two
/// smoothings and two envelope measurements.
pub fn smooth_flank_region(
    ctx: &PlanContext<'_>,
    (blade, side, strip): (&Blade, Side, (f64, f64)),
    pass: &crate::semi::StripPass,
    (over, residual): (f64, f64),
    st: &SideSettings,
    check: &PassCheck<'_>,
) -> Result<SmoothedFlank, FlankError> {
    let cutter = &ctx.tool.cutter;
    let tol = st.strip_tol_mm;
    let slack = tol - over;
    let budget = accuracy_turn_limit(&cutter.shape, cutter.flute_length, slack);
    let accepted = within_budget(&pass.locations, &cutter.shape, budget, check, |postures| {
        let env = crate::semi::pass_envelope(
            &cutter.shape,
            cutter.flute_length,
            postures,
            pass.upper_mm,
        )?;
        let (o2, r2) = measure_flank(blade, side, strip, &env, st.point.allowance_mm)?;
        let r_max = match st.flank_residual_mm {
            Some(limit) => (residual + slack).min(limit.max(residual)),
            None => residual + slack,
        };
        Ok((o2 <= over + NO_WORSE_MM && r2 <= r_max).then_some((o2, r2)))
    })?;
    Ok(match accepted {
        Some((run, (over, residual))) => SmoothedFlank {
            run,
            over,
            residual,
        },
        None => SmoothedFlank {
            run: kept_for_accuracy(&pass.locations),
            over,
            residual,
        },
    })
}

/// Point-mills `band` of the side and measures it.
#[allow(clippy::too_many_arguments)]
fn point_region(
    ctx: &PlanContext<'_>,
    blade: &Blade,
    row: Row,
    side: Side,
    band: (f64, f64),
    reason: String,
    st: &SideSettings,
    check: &PassCheck<'_>,
) -> Result<Region, FlankError> {
    let plan = point::plan_band(ctx, blade, side, band, &st.point, check)?;
    let runs: Vec<Vec<CutterLocation>> = plan
        .runs()
        .map(|r| r.iter().map(|s| s.cl).collect())
        .collect();
    let (over, residual, scallop) = measure_point(blade, side, band, &plan, &st.point);
    Ok(Region {
        row,
        side,
        v_range: band,
        method: Method::Point,
        reason,
        deviation_mm: None,
        runs,
        max_overcut_mm: over,
        max_residual_mm: residual,
        max_scallop_mm: scallop,
        lifted: false,
        band: Some(plan),
        axis_smoothing: None,
    })
}

/// (largest overcut, largest residual above the allowance) of a flank pass's envelope over
/// a grid of the strip.
fn measure_flank(
    blade: &Blade,
    side: Side,
    strip: (f64, f64),
    env: &cam_core::SweptEnvelope,
    allowance: f64,
) -> Result<(f64, f64), FlankError> {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let (nu, nv) = (MEASURE_ALONG, 6);
    let mut over = 0.0f64;
    let mut residual = 0.0f64;
    let mut hint = None;
    for i in 0..=nu {
        let u = u0 + (u1 - u0) * i as f64 / nu as f64;
        for j in 0..=nv {
            let v = strip.0 + (strip.1 - strip.0) * j as f64 / nv as f64;
            let d = env.signed_distance(&Point3::from(s.point(u, v)), hint)?;
            hint = Some(d.param);
            let dev = d.distance - allowance;
            over = over.max(-dev);
            residual = residual.max(dev);
        }
    }
    Ok((over, residual))
}

/// (largest overcut, largest residual, largest scallop) of a point band, measured on the
/// surface the operation leaves (the side offset by the allowance): overcut over the whole
/// band; residual from the band's top down to the lowest contact at that u (below it the
/// balls rode up the root: the corner is left to blade-root finishing); scallop strictly
/// between the first pass line and that lowest contact.
fn measure_point(
    blade: &Blade,
    side: Side,
    band: (f64, f64),
    plan: &BandPlan,
    st: &PointSettings,
) -> (f64, f64, f64) {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let r = st.ball_radius;
    let centres: Vec<Vec<nalgebra::Vector3<f64>>> = plan
        .runs()
        .map(|run| run.iter().map(|s| s.contact.centre).collect())
        .collect();
    let balls = SweptBalls::new(&centres, r);
    // The lowest contact per u (the last pass's stations), to tell scallop from root.
    let mut low: Vec<(f64, f64)> = plan
        .passes
        .last()
        .map(|p| {
            p.runs
                .iter()
                .flatten()
                .map(|s| (s.contact.u, s.contact.v))
                .collect()
        })
        .unwrap_or_default();
    low.sort_by(|a, b| a.0.total_cmp(&b.0));
    let low_v = |u: f64| -> f64 {
        match low.binary_search_by(|p| p.0.total_cmp(&u)) {
            Ok(k) => low[k].1,
            Err(0) => low.first().map_or(band.0, |p| p.1),
            Err(k) if k >= low.len() => low.last().map_or(band.0, |p| p.1),
            Err(k) => low[k - 1].1.max(low[k].1),
        }
    };
    let rows = (plan.passes.len() * MEASURE_ROWS_PER_PASS).max(6);
    let top = band.1;
    let mut pts = Vec::with_capacity((MEASURE_ALONG + 1) * (rows + 1));
    let mut inner = Vec::with_capacity(pts.capacity());
    for i in 0..=MEASURE_ALONG {
        let u = u0 + (u1 - u0) * i as f64 / MEASURE_ALONG as f64;
        let lv = low_v(u);
        for j in 0..=rows {
            let v = band.0 + (band.1 - band.0) * j as f64 / rows as f64;
            if let Some(n) = blade.outward_normal(side, u, v) {
                // On the surface the operation leaves: the side offset by the allowance.
                pts.push((s.point(u, v) + n * st.allowance_mm, n));
                let inside = v >= lv - 1e-12;
                inner.push((inside, inside && v <= top - 1e-12 && v > lv + 1e-12));
            }
        }
    }
    let measured = balls.measure_all(&pts, MEASURE_CAP_MM);
    let mut over = 0.0f64;
    let mut residual = 0.0f64;
    let mut scallop = 0.0f64;
    for ((res, ov), (inside, between)) in measured.into_iter().zip(inner) {
        over = over.max(ov);
        if inside {
            residual = residual.max(res);
        }
        if between {
            scallop = scallop.max(res);
        }
    }
    (over, residual, scallop)
}

/// Every side of every row planned, assembled and copied to every blade.
#[derive(Debug, Clone)]
pub struct RowsPlan {
    /// Tool paths, one per blade (row by row), each closed by its approach and retract.
    pub paths: Vec<cam_core::ToolPath>,
    /// The side plans (reference blades).
    pub sides: Vec<(Row, Side, SidePlan)>,
    /// Steps from one run to the next cut directly (a certified feed move).
    pub direct_steps: usize,
    /// Steps from one run to the next linked over the safety surface.
    pub linked_steps: usize,
    /// Cutting length of one blade of each row (reference blades), mm.
    pub reference_cut_mm: f64,
}

/// Approach distance above the first posture of a linked run (mm).
const APPROACH_MM: f64 = 5.0;
/// Longest step cut directly from one run to the next (mm): the zig-zag step at an edge.
const DIRECT_STEP_MM: f64 = 10.0;
/// Spacing (mm) of the postures at which a direct step is checked, ball included: nothing
/// refines the step along the side, so between two samples the ball's chord sags into a side
/// of curvature radius `ρ` by at most `0.25²/(8ρ)` (≤ 0.0016 mm for `ρ ≥ 5 mm`).
const DIRECT_STEP_SAMPLE_MM: f64 = 0.25;

/// Plans both sides of every row in `rows` (in parallel), assembles each row's runs into
/// one path (direct certified feed steps between runs where the whole tool keeps the floors,
/// else links over the safety surface) and copies it to every blade of the row. Reports the
/// blade sides planned as progress ([`PlanContext::progress`]).
pub fn plan_rows(
    ctx: &PlanContext<'_>,
    op_name: &str,
    tool_name: &str,
    row_list: &[Row],
    st: &SideSettings,
) -> Result<RowsPlan, FlankError> {
    use rayon::prelude::*;
    let jobs: Vec<(Row, Side)> = row_list
        .iter()
        .flat_map(|&r| [Side::Pressure, Side::Suction].map(move |s| (r, s)))
        .collect();
    let sides_done = std::sync::atomic::AtomicUsize::new(0);
    let fillets = FilletMargin::new(ctx.impeller)
        .map_err(|e| FlankError::Geometry(format!("blade-root fillets: {e}")))?;
    ctx.progress("blade sides", 0, jobs.len());
    let planned: Vec<(Row, Side, SidePlan)> = jobs
        .par_iter()
        .map(|&(row, side)| plan_side(ctx, row, side, st, fillets.as_ref()).map(|p| (row, side, p)))
        .inspect(|_| {
            let done = sides_done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            ctx.progress("blade sides", done, jobs.len());
        })
        .collect::<Result<_, _>>()?;
    let check = PassCheck::new(
        ctx.clearance,
        floors(
            st.point.allowance_mm,
            st.point.hub_allowance_mm,
            st.point.tol_mm,
            ctx.tolerances.chord_tol,
        ),
        point_split_mm(ctx, &st.point),
    )
    .with_postures_above(st.point.ball_radius)
    .with_fillets(fillets.as_ref());
    let mut paths = Vec::new();
    let (mut direct, mut linked) = (0, 0);
    let mut reference_cut = 0.0;
    for &row in row_list {
        let mut path =
            cam_core::ToolPath::new(format!("{op_name} {} blade", rows::label(row)), tool_name);
        for (_, _, plan) in planned.iter().filter(|(r, _, _)| *r == row) {
            for run in plan.regions.iter().flat_map(|g| g.runs.iter()) {
                let Some(first) = run.first() else { continue };
                if let Some(last) = path.moves.last().map(|m| m.cl) {
                    let near = (first.tip - last.tip).norm() <= DIRECT_STEP_MM;
                    let clear = near && {
                        let (ca, cb) = (check.measure(&last), check.measure(first));
                        check.keeps_floors(ca.whole)
                            && check.keeps_floors(cb.whole)
                            && check
                                .motion_sampled(
                                    0,
                                    (&last, &ca),
                                    (first, &cb),
                                    DIRECT_STEP_SAMPLE_MM,
                                )
                                .is_none()
                    };
                    if clear {
                        direct += 1;
                        path.moves.push(cam_core::Move::link(*first));
                    } else {
                        linked += 1;
                        let link = ctx
                            .link(&last, first, APPROACH_MM)
                            .map_err(|e| FlankError::Geometry(e.to_string()))?;
                        path.moves.extend(link);
                    }
                }
                path.moves
                    .extend(run.iter().map(|cl| cam_core::Move::feed(*cl)));
            }
        }
        if path.moves.is_empty() {
            continue;
        }
        reference_cut += path.cutting_length_mm();
        ctx.close(&mut path, APPROACH_MM)
            .map_err(|e| FlankError::Geometry(e.to_string()))?;
        let (pitch, count) = rows::pitch_and_count(ctx.impeller, row)?;
        let order = cam_plan::order::angular_sequence(count, 0);
        paths.extend(cam_plan::pattern::copy_to(&path, pitch, &order));
    }
    Ok(RowsPlan {
        paths,
        sides: planned,
        direct_steps: direct,
        linked_steps: linked,
        reference_cut_mm: reference_cut,
    })
}

impl RowsPlan {
    /// Every region of every side.
    pub fn regions(&self) -> impl Iterator<Item = &Region> {
        self.sides.iter().flat_map(|(_, _, p)| p.regions.iter())
    }

    /// One line per region for the report: row, side, v range, method and why.
    pub fn describe(&self) -> String {
        self.regions()
            .map(|g| {
                format!(
                    "{} {:?} v {:.3}–{:.3}: {} ({})",
                    rows::label(g.row),
                    g.side,
                    g.v_range.0,
                    g.v_range.1,
                    g.method.as_str(),
                    g.reason
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    }

    /// The metrics every blade-side operation reports from its regions.
    pub fn metrics(&self, m: &mut cam_plan::Metrics) {
        let count = |k: Method| self.regions().filter(|g| g.method == k).count();
        let fold = |f: fn(&Region) -> f64| self.regions().map(f).fold(0.0f64, f64::max);
        m.count("regions_flank", count(Method::Flank));
        m.count("regions_sub_ruled_flank", count(Method::SubRuledFlank));
        m.count("regions_point", count(Method::Point));
        m.text("regions", self.describe());
        m.number("max_overcut_mm", fold(|g| g.max_overcut_mm));
        m.number("max_undercut_mm", fold(|g| g.max_residual_mm));
        m.number("max_scallop_mm", fold(|g| g.max_scallop_mm));
        let bands = || self.regions().filter_map(|g| g.band.as_ref());
        m.count("point_passes", bands().map(|b| b.passes.len()).sum());
        m.count("skipped_stations", bands().map(BandPlan::skipped).sum());
        m.count("split_motions", bands().map(BandPlan::split_motions).sum());
        m.count(
            "accessibility_steps",
            bands().map(BandPlan::search_steps).sum(),
        );
        let (tilt, lead) = bands()
            .map(BandPlan::largest_angles)
            .fold((0.0f64, 0.0f64), |a, b| (a.0.max(b.0), a.1.max(b.1)));
        m.number("max_tilt_deg", tilt.to_degrees());
        m.number("max_lead_deg", lead.to_degrees());
        m.count("direct_steps", self.direct_steps);
        m.count("linked_steps", self.linked_steps);
        m.count(
            "interference_lifts",
            self.regions().filter(|g| g.lifted).count(),
        );
    }

    /// The axis smoothing of every flank pass and point-milling run, counted over every
    /// blade of each row (the reference blade's figures times the row's blade count).
    pub fn smoothing(
        &self,
        impeller: &impeller_model::Impeller,
    ) -> Result<cam_plan::SmoothingSummary, FlankError> {
        let mut all = cam_plan::SmoothingSummary::default();
        for (row, _, sp) in &self.sides {
            let (_, copies) = rows::pitch_and_count(impeller, *row)?;
            let mut one = cam_plan::SmoothingSummary::default();
            for g in &sp.regions {
                if let Some(rs) = &g.axis_smoothing {
                    one.add(rs);
                }
                if let Some(b) = &g.band {
                    one.merge(&b.smoothing());
                }
            }
            all.merge(&one.times(copies));
        }
        Ok(all)
    }

    /// Notes: skipped stations with where the first was, split motions.
    pub fn notes(&self) -> Vec<String> {
        let mut out = Vec::new();
        for g in self.regions() {
            let Some(b) = &g.band else { continue };
            let skipped = b.skipped();
            if skipped > 0 {
                let first = b.passes.iter().find_map(|p| p.first_skip);
                out.push(format!(
                    "{} blade {:?} side: {skipped} point-milling station(s) left out{}",
                    rows::label(g.row),
                    g.side,
                    first
                        .map(|(u, v, why)| format!(" (first at u = {u:.4}, v = {v:.4}: {why})"))
                        .unwrap_or_default()
                ));
            }
            if b.split_motions() > 0 {
                out.push(format!(
                    "{} blade {:?} side: {} point-milling motion(s) not clear even through \
                     midpoints: the pass is split there and linked over the safety surface",
                    rows::label(g.row),
                    g.side,
                    b.split_motions()
                ));
            }
        }
        out
    }
}
