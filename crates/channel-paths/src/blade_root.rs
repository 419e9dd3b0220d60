//! Blade-root finishing (paper 004 §"Preliminary 5-axis tool paths", Figs. 6–7, eq. 7; paper
//! 003 Table 1, process 10): a ball-end pass along the root of every blade side, leading to
//! trailing edge, on the pressure and the suction side.
//!
//! # Geometry
//! With ball radius `r` and design fillet radius `R_f`, let `ρ = max(r, R_f)`. The *spine*
//! of station `u` is the point `c = B(u, v) + ρ·n(u, v)` of the blade side's offset surface
//! (outward unit normal `n`) that lies on the hub's offset surface, `d_hub(c) = ρ` — the
//! intersection of the two offset surfaces of paper 004 Fig. 6, found per station by a
//! bracketed Illinois regula-falsi root of `v ↦ d_hub(B(u, v) + ρ n(u, v)) − ρ` (the hub's
//! signed distance is exact: closest point in the meridional half plane), to 1e-12 mm.
//! - `r ≥ R_f`: the ball centre is `c` itself, at distance `r` from both hub and blade side
//!   (it leaves a corner radius `r ≥ R_f`: undercut only).
//! - `r < R_f`: `c` is the centre of the fillet's rolling ball; the cutter's centre is moved
//!   by `R_f − r` from `c` toward the corner along the bisector `−(n + n_hub)/|n + n_hub|`, so
//!   the cutter ball lies inside the rolling ball (no overcut) and touches the fillet on its
//!   middle line.
//!
//! # Tool axis and accessibility (paper 004, steps (6)–(8))
//! The first axis is the ruling of the blade side's ruled surface at `u`: the direction from
//! the side's hub edge to its shroud edge (turned to point away from the hub). A position is
//! *accessible* when every sample of the tool above the ball (flutes, shank, holder) keeps at
//! least `−machining_tol` from the design ([`cam_plan::DesignClearance`]). If not, the axis is
//! turned about the impeller axis (a line parallel to +Z through the ball centre) by
//! `step_deg`, away from the blade, until accessible — never beyond `C_max`, eq. 7: the angle
//! at the ball centre E between the first axis (to C, the axis point at shroud height) and
//! the direction to F, the nearest point of the neighbouring blade to C. Where the first
//! axis is within 10° of +Z (a radial blade at the outlet) a turn about the impeller axis
//! leaves it unchanged; there the turn is about the root tangent (the path direction)
//! instead, which tilts the axis straight away from the blade. Where no angle works
//! the plan fails with [`PlanError::Geometry`] naming the blade, side, station and point, and
//! the largest ball radius (bisection, same shank and holder, flutes of the ball's radius)
//! that is accessible there.
//!
//! Positions: `stations` uniform in the side's u parameter, then positions inserted by
//! bisection (at most 6 levels per gap) wherever the spine point halfway
//! between two positions lies farther than `machining_tol` from the chord of their ball
//! centres, which the ball follows between them (around a rounded leading edge the spine
//! turns tightly).
//!
//! Cost: O(positions · (regula-falsi iterations + steps · tool samples · design distance)).

use cam_core::{CutterLocation, Move, ToolPath};
use cam_plan::{
    pattern, ClearanceOptions, DesignClearance, Metrics, Operation, OperationSpec, PartSet,
    PlanContext, PlanError, PlannedOperation, Plot, PlotKind, PlotSeries, Point3,
};
use impeller_model::{channel::edge_v, Blade, Impeller, Side};
use nalgebra::{Rotation3, Vector3};
use serde::Deserialize;

use crate::accessibility::{ball_radius, upper_clearance};

/// Kind key of blade-root finishing in job files.
pub const BLADE_ROOT_FINISHING: &str = "blade_root_finishing";

/// Default stations per blade side (paper 004 used 475 CC points on one pressure side of a
/// larger impeller; 120 keeps the chord deviation of a 30–60 mm root well under 0.01 mm).
const DEFAULT_STATIONS: usize = 120;
/// Default turning step of the axis (paper 004: "about 1 ~ 2 degrees").
const DEFAULT_STEP_DEG: f64 = 1.5;
/// Iterations of the regula-falsi root and of the bisection for the largest ball.
const ROOT_ITERS: usize = 200;
/// Bisection levels of the stations inserted between two uniform ones (2^6 = 64 per gap).
const MAX_REFINE_DEPTH: u32 = 6;
/// Bisection steps of the largest accessible ball radius (2^-12 of the radius).
const RADIUS_BISECTIONS: usize = 12;
/// Samples of the v range searched for the spine bracket.
const BRACKET_SAMPLES: usize = 64;
/// Approach length above the first point (mm) before plunging at feed.
const APPROACH_MM: f64 = 2.0;
/// Smallest tilt of the first axis from +Z for which turning about the impeller axis moves
/// it (10°); below it the root tangent is the turning axis.
const MIN_TILT: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// Samples of the design fillet arc for the undercut.
const ARC_SAMPLES: usize = 9;

/// The kind's own job keys.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Positions per blade side, leading to trailing edge.
    #[serde(default = "default_stations")]
    stations: usize,
    /// Turning step of the tool axis about the impeller axis (degrees).
    #[serde(default = "default_step_deg")]
    step_deg: f64,
}

fn default_stations() -> usize {
    DEFAULT_STATIONS
}
fn default_step_deg() -> f64 {
    DEFAULT_STEP_DEG
}

/// Blade-root finishing, kind [`BLADE_ROOT_FINISHING`].
#[derive(Debug, Clone)]
pub struct BladeRootFinishing {
    name: String,
    tool: String,
    stations: usize,
    step_rad: f64,
}

/// Builds a [`BladeRootFinishing`] from its job table. Keys: `stations` (2..=5000, default
/// 120), `step_deg` (0 < step ≤ 5, default 1.5).
pub fn build_blade_root_finishing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let p: Params = cam_plan::params::parse(spec)?;
    if !(2..=5000).contains(&p.stations) {
        return Err(PlanError::param(
            &spec.name,
            "stations",
            format!("{} must be in 2..=5000", p.stations),
        ));
    }
    if !(p.step_deg.is_finite() && p.step_deg > 0.0 && p.step_deg <= 5.0) {
        return Err(PlanError::param(
            &spec.name,
            "step_deg",
            format!("{} must be in (0, 5]", p.step_deg),
        ));
    }
    Ok(Box::new(BladeRootFinishing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        stations: p.stations,
        step_rad: p.step_deg.to_radians(),
    }))
}

/// One planned position.
#[derive(Debug, Clone, Copy)]
pub struct RootPosition {
    /// Ball centre.
    pub centre: Vector3<f64>,
    /// Unit tool axis.
    pub axis: Vector3<f64>,
    /// Turning steps taken (0 = the ruling was accessible).
    pub steps: usize,
    /// Rotation of the axis about the impeller axis (rad).
    pub rotation: f64,
    /// Smallest clearance of flutes, shank and holder (mm).
    pub clearance: f64,
    /// Largest penetration of the ball into hub, blades or fillet (mm, ≥ 0).
    pub overcut: f64,
    /// Largest distance of the design corner (fillet arc or sharp corner) from the ball (mm).
    pub undercut: f64,
}

/// Ball centre data of one station: (centre, spine, blade normal, hub normal).
type Station = (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>);

/// Ball centre data of one station.
fn spine(imp: &Impeller, blade: &Blade, side: Side, u: f64, r: f64) -> Option<Station> {
    let rf = imp.fillet_radius_mm();
    let rho = r.max(rf);
    let s = blade.side(side);
    let (_, (v0, v1)) = s.domain();
    let hub = imp.hub();
    let off = |v: f64| -> Option<(Vector3<f64>, Vector3<f64>)> {
        let n = blade.outward_normal(side, u, v)?;
        Some((s.point(u, v) + n * rho, n))
    };
    let g = |v: f64| off(v).map(|(c, _)| hub.signed_distance(&c) - rho);
    let v_root = edge_v(blade, side, hub, u).unwrap_or(v0);
    // Bracket: first sign change of g above the root.
    let mut a = v_root.max(v0);
    let mut ga = g(a)?;
    let mut bracket = None;
    for k in 1..=BRACKET_SAMPLES {
        let b = a + (v1 - v_root.max(v0)) * 1.0 / BRACKET_SAMPLES as f64;
        let b = b.min(v1);
        let gb = g(b)?;
        if ga <= 0.0 && gb > 0.0 {
            bracket = Some((a, b, ga, gb));
            break;
        }
        a = b;
        ga = gb;
        if k == BRACKET_SAMPLES || b >= v1 {
            break;
        }
    }
    let (mut lo, mut hi, mut flo, mut fhi) = bracket?;
    let mut last = 0i8;
    let mut v = lo;
    for _ in 0..ROOT_ITERS {
        v = (lo * fhi - hi * flo) / (fhi - flo);
        let fv = g(v)?;
        if fv.abs() < 1e-13 || (hi - lo) < 1e-15 {
            break;
        }
        if fv <= 0.0 {
            lo = v;
            flo = fv;
            if last == -1 {
                fhi *= 0.5;
            }
            last = -1;
        } else {
            hi = v;
            fhi = fv;
            if last == 1 {
                flo *= 0.5;
            }
            last = 1;
        }
    }
    let (c, nb) = off(v)?;
    let (t, phi, _) = hub.closest(&c);
    let nh = hub.normal(t, phi);
    let centre = if r < rf {
        let m = (nb + nh).try_normalize(1e-12)?;
        c - m * (rf - r)
    } else {
        c
    };
    Some((centre, c, nb, nh))
}

/// Outcome of the axis search at one position.
enum Search {
    Found {
        axis: Vector3<f64>,
        steps: usize,
        rotation: f64,
        clearance: f64,
    },
    None {
        c_max: f64,
    },
}

#[allow(clippy::too_many_arguments)]
fn search_axis(
    ctx: &PlanContext<'_>,
    upper: &DesignClearance<'_>,
    blade: &Blade,
    side: Side,
    neighbour: &Blade,
    u: f64,
    centre: &Vector3<f64>,
    nb: &Vector3<f64>,
    r: f64,
    ball: f64,
    step: f64,
) -> Search {
    let imp = ctx.impeller;
    let s = blade.side(side);
    let nh = {
        let (t, phi, _) = imp.hub().closest(centre);
        imp.hub().normal(t, phi)
    };
    // The ruling: hub edge to shroud edge at u.
    let ruling = match (
        edge_v(blade, side, imp.hub(), u),
        edge_v(blade, side, imp.shroud(), u),
    ) {
        (Ok(a), Ok(b)) => s.point(u, b) - s.point(u, a),
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
    let away = if nb.dot(&e_theta) >= 0.0 {
        e_theta
    } else {
        -e_theta
    };
    // Turning axis: the impeller axis (paper 004's C rotation); where the first axis is
    // within MIN_TILT of +Z that rotation cannot move it, so the root tangent (the path
    // direction) is used instead, tilting the axis straight away from the blade.
    let turn_axis = if a0.xy().norm() >= MIN_TILT.sin() {
        Vector3::z_axis()
    } else {
        let t = s
            .derivs2(
                u,
                edge_v(blade, side, imp.hub(), u).unwrap_or(s.domain().1 .0),
            )
            .su;
        nalgebra::Unit::try_new(t, 1e-12).unwrap_or(Vector3::z_axis())
    };
    let sigma = if turn_axis.cross(&a0).dot(&away) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    // C_max (paper 004 eq. 7): E = centre, C = axis point at shroud height, F = nearest point
    // of the neighbouring blade to C.
    let shroud = imp.shroud();
    let mut hgt = 0.0;
    let stick = ctx.tool.cutter.overall_length.max(1.0);
    while hgt < stick && shroud.signed_distance(&(centre + a0 * hgt)) < 0.0 {
        hgt += 0.25;
    }
    let c_pt = centre + a0 * hgt.max(ball);
    let f_pt = [Side::Pressure, Side::Suction]
        .iter()
        .map(|&sd| neighbour.projector(sd).closest_point(&c_pt))
        .min_by(|x, y| x.distance.total_cmp(&y.distance))
        .map(|sp| sp.point)
        .unwrap_or(c_pt + away);
    let ec = c_pt - centre;
    let ef = f_pt - centre;
    let c_max = (ec.dot(&ef) / (ec.norm() * ef.norm()).max(1e-300))
        .clamp(-1.0, 1.0)
        .acos();
    let tol = ctx.tolerances.machining_tol;
    let mut k = 0usize;
    loop {
        let rot = sigma * step * k as f64;
        if rot.abs() > c_max + 1e-12 {
            return Search::None { c_max };
        }
        let axis = Rotation3::from_axis_angle(&turn_axis, rot) * a0;
        if assembly_clearance(ctx, upper, centre, &axis, r, ball, -tol) >= -tol {
            let clearance =
                assembly_clearance(ctx, upper, centre, &axis, r, ball, f64::NEG_INFINITY);
            return Search::Found {
                axis,
                steps: k,
                rotation: rot,
                clearance,
            };
        }
        k += 1;
    }
}

/// The clearance query of the shank and holder alone (cutter samples left out: the flutes
/// are measured by [`upper_clearance`], which can also place a smaller ball).
fn shank_and_holder<'a>(ctx: &PlanContext<'a>) -> DesignClearance<'a> {
    ctx.clearance.with_options(ClearanceOptions {
        parts: PartSet::MATERIAL,
        above_mm: ctx.tool.cutter.flute_length,
        ..ClearanceOptions::default()
    })
}

/// Smallest signed clearance (mm) of everything above the ball with its centre at `centre`
/// and unit `axis`: the flutes ([`upper_clearance`], with a ball of radius `ball`) and the
/// shank and holder frusta (`upper`, placed as on the job's tool: tip at `centre − r·axis`).
/// Stops below `stop_below` like [`upper_clearance`].
fn assembly_clearance(
    ctx: &PlanContext<'_>,
    upper: &DesignClearance<'_>,
    centre: &Vector3<f64>,
    axis: &Vector3<f64>,
    r: f64,
    ball: f64,
    stop_below: f64,
) -> f64 {
    let flutes = upper_clearance(ctx, centre, axis, r, ball, stop_below);
    if flutes < stop_below {
        return flutes;
    }
    let Some(unit) = nalgebra::Unit::try_new(*axis, 1e-12) else {
        return flutes;
    };
    let cl = CutterLocation {
        tip: Point3::from(centre - axis * r),
        axis: unit,
    };
    flutes.min(upper.clearance(&cl).distance_mm)
}

/// Largest penetration of the ball (centre, radius `r`) into hub, blades and the fillet of
/// spine `c`, and the largest distance of the design corner from the ball.
fn deviations(
    ctx: &PlanContext<'_>,
    centre: &Vector3<f64>,
    spine_c: &Vector3<f64>,
    nb: &Vector3<f64>,
    nh: &Vector3<f64>,
    r: f64,
) -> (f64, f64) {
    let imp = ctx.impeller;
    let rf = imp.fillet_radius_mm();
    let p = Point3::from(*centre);
    let d_hub = ctx.clearance.hub_signed_distance(&p);
    let d_blade = ctx.clearance.blade_signed_distance(&p).0;
    let mut d = d_hub.min(d_blade);
    if rf > 0.0 && r <= rf {
        d = d.min(rf - (centre - spine_c).norm());
    }
    let overcut = (r - d).max(0.0);
    let rho = r.max(rf);
    let undercut = if rf > 0.0 {
        // Fillet arc from its hub foot to its blade foot (rolling ball of radius R_f at the
        // fillet spine; when r > R_f the spine is re-found at offset R_f).
        let fs = if r > rf {
            // The fillet spine lies on the bisector plane at distance R_f: shift the ρ-spine
            // by (ρ − R_f) toward the corner along the corner's diagonal.
            let cosang = nb.dot(nh);
            spine_c - (nb + nh) * ((rho - rf) / (1.0 + cosang))
        } else {
            *spine_c
        };
        (0..ARC_SAMPLES)
            .map(|k| {
                let t = k as f64 / (ARC_SAMPLES - 1) as f64;
                let dir = (-nh * (1.0 - t) - nb * t).normalize();
                ((fs + dir * rf) - centre).norm() - r
            })
            .fold(0.0, f64::max)
    } else {
        let cosang = nb.dot(nh);
        let corner = spine_c - (nb + nh) * (rho / (1.0 + cosang));
        ((corner - centre).norm() - r).max(0.0)
    };
    (overcut, undercut)
}

/// Reference blades with their neighbours in +θ and −θ: (label, blade, next, previous).
fn reference_blades(imp: &Impeller) -> Vec<(String, Blade, Blade, Blade)> {
    let order = imp.blades_in_order();
    let n = order.len();
    let mut out = vec![(
        "main blade 0".to_string(),
        order[0].clone(),
        order[1 % n].clone(),
        order[n - 1].clone(),
    )];
    if imp.splitter().is_some() && n >= 2 {
        out.push((
            "splitter blade 0".to_string(),
            order[1].clone(),
            order[2 % n].clone(),
            order[0].clone(),
        ));
    }
    out
}

/// Plans the positions of one blade side (the reference instance). Public for tests and
/// benchmarks.
#[allow(clippy::too_many_arguments)]
pub fn plan_side(
    ctx: &PlanContext<'_>,
    operation: &str,
    label: &str,
    blade: &Blade,
    side: Side,
    next: &Blade,
    prev: &Blade,
    stations: usize,
    step: f64,
) -> Result<Vec<RootPosition>, PlanError> {
    let r = ball_radius(ctx, operation, "blade-root finishing")?;
    let imp = ctx.impeller;
    let upper = shank_and_holder(ctx);
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let plus = blade.plus_theta_side() == side;
    let neighbour = if plus { next } else { prev };
    let position_at = |u: f64, station: &str| -> Result<RootPosition, PlanError> {
        let place = || format!("{label}, {side:?} side, station {station} (u = {u:.4})");
        let (centre, spine_c, nb, nh) = spine(imp, blade, side, u, r).ok_or_else(|| {
            PlanError::geometry(
                operation,
                place(),
                "the hub and blade offset surfaces do not intersect here",
            )
        })?;
        match search_axis(
            ctx, &upper, blade, side, neighbour, u, &centre, &nb, r, r, step,
        ) {
            Search::Found {
                axis,
                steps,
                rotation,
                clearance,
            } => {
                let (overcut, undercut) = deviations(ctx, &centre, &spine_c, &nb, &nh, r);
                Ok(RootPosition {
                    centre,
                    axis,
                    steps,
                    rotation,
                    clearance,
                    overcut,
                    undercut,
                })
            }
            Search::None { c_max } => {
                // Largest accessible ball radius here: bisection with the same shank and
                // holder.
                let (mut lo, mut hi) = (0.0f64, r);
                for _ in 0..RADIUS_BISECTIONS {
                    let mid = 0.5 * (lo + hi);
                    let ok = spine(imp, blade, side, u, mid).is_some_and(|(c, _, nb2, _)| {
                        matches!(
                            search_axis(
                                ctx, &upper, blade, side, neighbour, u, &c, &nb2, r, mid, step,
                            ),
                            Search::Found { .. }
                        )
                    });
                    if ok {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                Err(PlanError::geometry(
                    operation,
                    format!(
                        "{}, ball centre ({:.3}, {:.3}, {:.3})",
                        place(),
                        centre.x,
                        centre.y,
                        centre.z
                    ),
                    if lo >= 1e-3 * r {
                        format!(
                            "no accessible tool axis up to C_max = {:.2}° (steps of {:.2}°); the largest ball radius accessible here is {:.3} mm (tool has {:.3} mm)",
                            c_max.to_degrees(),
                            step.to_degrees(),
                            lo,
                            r
                        )
                    } else {
                        format!(
                            "no accessible tool axis up to C_max = {:.2}° (steps of {:.2}°); the largest ball radius accessible here is 0 mm: with this tool's shank and holder no ball fits (tool has {:.3} mm; a longer or thinner neck is needed)",
                            c_max.to_degrees(),
                            step.to_degrees(),
                            r
                        )
                    },
                ))
            }
        }
    };
    // Uniform stations, then stations inserted where the chord between two ball centres
    // strays from the root curve (the spine) by more than the machining tolerance at its
    // midpoint: around a rounded leading edge the spine turns on a radius of the ball plus
    // the nose, and 40 uniform stations left 0.12 mm there (verifier, 0.1 mm).
    let tol = ctx.tolerances.machining_tol;
    let mut out: Vec<(f64, RootPosition)> = Vec::with_capacity(stations);
    for k in 0..stations {
        let u = u0 + (u1 - u0) * k as f64 / (stations - 1) as f64;
        out.push((u, position_at(u, &format!("{k}/{stations}"))?));
    }
    let mut refined: Vec<(f64, RootPosition)> = Vec::with_capacity(out.len());
    for w in out.windows(2) {
        refined.push(w[0]);
        let mut stack = vec![(w[0], w[1], 0u32)];
        let mut inserted: Vec<(f64, RootPosition)> = Vec::new();
        while let Some((a, b, depth)) = stack.pop() {
            let um = 0.5 * (a.0 + b.0);
            let Some((cm, ..)) = spine(imp, blade, side, um, r) else {
                continue;
            };
            let off = cam_core::path::point_segment_distance(
                &Point3::from(cm),
                &Point3::from(a.1.centre),
                &Point3::from(b.1.centre),
            );
            if off <= tol || depth >= MAX_REFINE_DEPTH {
                continue;
            }
            let m = (um, position_at(um, &format!("inserted at u = {um:.5}"))?);
            inserted.push(m);
            stack.push((m, b, depth + 1));
            stack.push((a, m, depth + 1));
        }
        inserted.sort_by(|x, y| x.0.total_cmp(&y.0));
        refined.extend(inserted);
    }
    if let Some(last) = out.last() {
        refined.push(*last);
    }
    let out: Vec<RootPosition> = refined.into_iter().map(|(_, p)| p).collect();
    Ok(out)
}

impl Operation for BladeRootFinishing {
    fn kind(&self) -> &'static str {
        BLADE_ROOT_FINISHING
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        let r = ball_radius(ctx, &self.name, "blade-root finishing")?;
        let imp = ctx.impeller;
        let mut paths = Vec::new();
        let mut metrics = Metrics::new();
        let mut series = Vec::new();
        let (mut over, mut under, mut clear, mut steps, mut max_rot) =
            (0.0f64, 0.0f64, f64::INFINITY, 0usize, 0.0f64);
        for (label, blade, next, prev) in reference_blades(imp) {
            let count = if label.starts_with("main") {
                imp.main().count()
            } else {
                imp.splitter().map_or(0, |s| s.count())
            };
            let pitch = std::f64::consts::TAU / count.max(1) as f64;
            for side in [Side::Pressure, Side::Suction] {
                let pos = plan_side(
                    ctx,
                    &self.name,
                    &label,
                    &blade,
                    side,
                    &next,
                    &prev,
                    self.stations,
                    self.step_rad,
                )?;
                let mut path = ToolPath::new(format!("{} {label} {side:?}", self.name), &self.tool);
                for p in &pos {
                    let cl = CutterLocation::new(Point3::from(p.centre - p.axis * r), p.axis)
                        .map_err(|e| PlanError::cam(&self.name, e))?;
                    path.moves.push(Move::feed(cl));
                    over = over.max(p.overcut);
                    under = under.max(p.undercut);
                    clear = clear.min(p.clearance);
                    steps += p.steps;
                    max_rot = max_rot.max(p.rotation.abs());
                }
                series.push(PlotSeries {
                    label: format!("{label} {side:?}"),
                    points: pos
                        .iter()
                        .enumerate()
                        .map(|(k, p)| [k as f64, p.rotation.to_degrees()])
                        .collect(),
                });
                ctx.close(&mut path, APPROACH_MM)?;
                let order = cam_plan::order::angular_sequence(count, 0);
                paths.extend(pattern::copy_to(&path, pitch, &order));
            }
        }
        metrics
            .number("max_overcut_mm", over)
            .number("max_undercut_mm", under)
            .number("min_blade_clearance_mm", clear)
            .count("accessibility_steps", steps)
            .number("max_axis_rotation_deg", max_rot.to_degrees());
        Ok(PlannedOperation {
            paths,
            metrics,
            plots: vec![Plot {
                title: "Tool-axis rotation about the impeller axis per position".into(),
                kind: PlotKind::Lines {
                    x_label: "position (leading → trailing edge)".into(),
                    y_label: "rotation (deg)".into(),
                    series,
                    equal_aspect: false,
                },
            }],
            notes: Vec::new(),
        })
    }
}
