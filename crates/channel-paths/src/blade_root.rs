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
//! signed distance is exact: closest point in the meridional half plane), to 1e-12 mm
//! ([`impeller_model::fillet::FilletSection::solve`], the fillet's own cross-section).
//! - `r ≥ R_f`: the ball centre is `c` itself, at distance `r` from both hub and blade side
//!   (it leaves a corner radius `r ≥ R_f`: undercut only).
//! - `r < R_f`: `c` is the centre of the fillet's rolling ball; the cutter's centre is moved
//!   by `R_f − r` from `c` toward the corner along the bisector `−(n + n_hub)/|n + n_hub|`, so
//!   the cutter ball lies inside the rolling ball (no overcut) and touches the fillet on its
//!   middle line.
//!
//! # Tool axis and accessibility (paper 004, steps (6)–(8))
//! The first axis is the ruling of the blade side at `u` (hub edge to shroud edge), turned
//! about the impeller axis away from the blade until flutes, shank and holder clear the
//! design, within paper 004's `C_max` (eq. 7); where that finds none (or the ruling is within
//! 10° of +Z), it is tilted about the root tangent instead ([`crate::root_axis`]).
//!
//! # Blade edges and left-out stations
//! Before its axis is searched, a station's ball must *fit*: the ball of the tool's radius
//! at the centre found above must keep within `machining_tol` of outside the whole blade —
//! both sides and, at a blunt (open) edge, the face closing it ([`crate::ball_fit`]). A
//! centre inside the blade, or within the ball radius of the edge face or of the other side
//! beyond a blunt edge, fails that test, and so does a station whose offset surfaces do not
//! meet. Such a station carries no position, and neither does one that no tool axis makes
//! accessible; the path is split there (a retract and an approach through the operation's
//! linking, [`cam_plan::PlanContext::link`]) and the station is reported in the operation's
//! notes and metrics (`skipped_stations`, `unfit_stations`). A side is an error only when
//! none of its stations carries a position.
//!
//! At a **rounded** edge (the sides meet) the offset of the nose is smooth: both sides' paths
//! run around the nose to the point where they meet, and the chord refinement below follows
//! the tight turn. At a **blunt** edge the ball stops fitting at the edge's start; the run of
//! positions is then extended by bisection of u toward the first station that does not fit
//! (at most 10 levels, or until the two ball centres are within `machining_tol`), so the path
//! stops at the last u where the ball fits against hub and side. Running around a blunt edge
//! (a ball rolling over the face's corners) is not done: it would need a second contact
//! (face and hub) with its own spine, and the face of an impeller's trailing edge is usually
//! left to blade finishing; stopping keeps every placed ball clear of the design.
//! The same rules hold inside a side (a concave region tighter than the ball, a stretch the
//! tool cannot reach), so they hold for any design, not only at edges.
//!
//! Positions: `stations` uniform in the side's u parameter, then positions inserted by
//! bisection (at most 6 levels per gap) wherever the spine point halfway between two
//! positions lies farther than `machining_tol` from the chord of their ball centres, which
//! the ball follows between them (around a rounded leading edge the spine turns tightly).
//! An inserted position first tries the slerp of its neighbours' axes (keeping the axis
//! continuous), then the axis search. Stations are evaluated in parallel (rayon).
//!
//! # Motion between positions
//! Two accessible postures do not make an accessible motion: where the axis search turns
//! the axis by many steps between neighbours (around a rounded leading edge the ruling swings
//! by 10–36°), the long flutes sweep through the blade between them (the NASA HECC root path
//! cut 3 mm into its main blades' leading edge so). Every motion between consecutive
//! positions is checked for the tool above the ball — flutes, shank, holder — against hub and
//! blades by [`cam_plan::DesignClearance::segment_clearance_between`], the clearance's
//! certified Lipschitz bisection, at least `−machining_tol − 0.25 mm` along the tip-linear,
//! axis-slerp motion (`0.25 mm` = half the tool displacement between two checked postures;
//! the flutes of a root position touch hub and blade near the ball, where no bisection can
//! certify less). A motion that fails is bridged by positions inserted halfway with the
//! slerp of the two axes (at most 5 levels, each posture accessible); where the slerp is not
//! accessible the run is split there with a retract and an approach (`path_splits`, a note).
//!
//! The axes of each run are then smoothed about the ball centres by the shared step
//! [`cam_plan::axis_smoothing`] (the search's turns in whole steps alternate between
//! neighbouring positions), every changed posture checked with the axis search's test and
//! every motion with the check above (`axis_reversals_*`, `axis_smoothing_*` metrics).
//!
//! Cost: O(positions · (regula-falsi iterations + 4 blade projections + steps · tool samples
//! · design distance)), plus 12 axis searches per inaccessible station for its largest ball.

use cam_core::{CutterLocation, Move, ToolPath};
use cam_plan::{
    pattern, ClearanceOptions, DesignClearance, Metrics, Operation, OperationSpec, PartSet,
    PlanContext, PlanError, PlannedOperation, Plot, PlotKind, PlotSeries, Point3,
};
use impeller_model::fillet::FilletSection;
use impeller_model::{Blade, Impeller, Side};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::Deserialize;

use crate::accessibility::ball_radius;
use crate::ball_fit::{BladeBoundary, BoundaryPart};
use crate::root_axis::{
    self, assembly_clearance, search_axis, shank_and_holder, shank_clear, shank_keep, Search,
    TurnAxis,
};

/// Kind key of blade-root finishing in job files.
pub const BLADE_ROOT_FINISHING: &str = "blade_root_finishing";

/// Default stations per blade side (paper 004 used 475 CC points on one pressure side of a
/// larger impeller; 120 keeps the chord deviation of a 30–60 mm root well under 0.01 mm).
const DEFAULT_STATIONS: usize = 120;
/// Default turning step of the axis (paper 004: "about 1 ~ 2 degrees").
const DEFAULT_STEP_DEG: f64 = 1.5;
/// Bisection levels of the stations inserted between two uniform ones (2^6 = 64 per gap).
const MAX_REFINE_DEPTH: u32 = 6;
/// Bisection levels of the end of a run of positions toward a station left out (2^10 = 1024
/// per gap).
const MAX_END_DEPTH: u32 = 10;
/// The same toward a station that no axis makes accessible (2^5 = 32 per gap): each probe
/// there costs a whole axis search, and the run's end needs no edge's precision.
const MAX_END_DEPTH_INACCESSIBLE: u32 = 5;
/// Bisection levels of the positions inserted to make a motion clear (2^5 = 32 per gap).
const MOTION_DEPTH: u32 = 5;
/// Largest number of clearance queries certifying one motion between positions.
const SEGMENT_QUERIES: usize = 48;
/// Allowance of the motion check beyond `machining_tol` (mm): half the largest tool
/// displacement between two checked postures of a motion ([`SidePlanner::motion_clear`]).
const MOTION_TOL_MM: f64 = 0.25;
/// Sampling tolerance of the motion check's tool samples (mm): its reading is a lower bound
/// of the clearance within this, taken out of `MOTION_TOL_MM`.
const MOTION_SAMPLE_TOL_MM: f64 = 0.05;
/// Bisection steps of the largest accessible ball radius (2^-8 of the radius).
const RADIUS_BISECTIONS: usize = 8;
/// Approach length above the first point (mm) before plunging at feed.
const APPROACH_MM: f64 = 2.0;
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
    /// The side's u parameter.
    pub u: f64,
    /// Ball centre.
    pub centre: Vector3<f64>,
    /// Unit tool axis.
    pub axis: Vector3<f64>,
    /// Turning steps taken (0 = the ruling was accessible).
    pub steps: usize,
    /// Signed turning angle of the axis from the ruling (rad) about `turn`.
    pub rotation: f64,
    /// The line the axis was turned about.
    pub turn: TurnAxis,
    /// Smallest clearance of flutes, shank and holder (mm).
    pub clearance: f64,
    /// Largest penetration of the ball into hub, blades or fillet (mm, ≥ 0).
    pub overcut: f64,
    /// Largest distance of the design corner (fillet arc or sharp corner) from the ball (mm).
    pub undercut: f64,
}

/// Ball centre data of one station: (centre, spine, blade normal, hub normal).
type Station = (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>);

/// Ball centre data of one station: the fillet section of radius `max(r, R_f)`
/// ([`impeller_model::fillet::FilletSection::solve`], module docs), its centre moved toward
/// the corner by `R_f − r` when the ball is smaller than the fillet.
fn spine(imp: &Impeller, blade: &Blade, side: Side, u: f64, r: f64) -> Option<Station> {
    let rf = imp.fillet_radius_mm();
    let s = FilletSection::solve(imp.hub(), blade, side, u, r.max(rf))?;
    let (c, nb, nh) = (s.centre, s.blade_normal, s.hub_normal);
    let centre = if r < rf {
        let m = (nb + nh).try_normalize(1e-12)?;
        c - m * (rf - r)
    } else {
        c
    };
    Some((centre, c, nb, nh))
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

/// Why a station of a blade side carries no position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LeftOut {
    /// The hub's and the side's offset surfaces do not meet at this u: no ball of the tool's
    /// radius touches both hub and side here.
    NoSpine,
    /// The ball touching hub and side would reach into the blade by more than the machining
    /// tolerance — its centre lies inside the blade, or within the ball radius of an edge face
    /// or of the other side beyond a blunt edge ([`crate::ball_fit`]).
    BallMeetsBlade {
        /// Ball centre.
        centre: Vector3<f64>,
        /// `gap` of [`crate::ball_fit`] (mm, negative).
        gap_mm: f64,
        /// The boundary part the ball reaches.
        part: BoundaryPart,
    },
    /// The ball fits, but no tool axis up to `C_max` makes flutes, shank and holder clear.
    Inaccessible {
        /// Ball centre.
        centre: Vector3<f64>,
        /// Paper 004's bound of the turning angle here (rad).
        c_max: f64,
    },
}

impl LeftOut {
    /// The ball centre, when a ball touching hub and side exists.
    pub fn centre(&self) -> Option<Vector3<f64>> {
        match self {
            LeftOut::NoSpine => None,
            LeftOut::BallMeetsBlade { centre, .. } | LeftOut::Inaccessible { centre, .. } => {
                Some(*centre)
            }
        }
    }

    /// Whether the ball does not fit against hub and side (no spine, or it meets the blade).
    pub fn is_unfit(&self) -> bool {
        !matches!(self, LeftOut::Inaccessible { .. })
    }
}

/// A station of a blade side that carries no position.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftOutStation {
    /// Which station: `"k/n"` for the uniform ones, `"inserted at u = …"` for one inserted
    /// between two positions whose chord strayed from the root curve.
    pub station: String,
    /// Whether it was inserted (not one of the uniform stations).
    pub inserted: bool,
    /// The side's u parameter.
    pub u: f64,
    /// Why it carries no position.
    pub reason: LeftOut,
    /// For an inaccessible station: the largest ball radius (mm) that fits there and has an
    /// accessible axis with the same shank and holder (bisection, 2^-8 of the tool's radius).
    pub largest_ball_mm: Option<f64>,
}

/// The root path of one blade side.
#[derive(Debug, Clone, Default)]
pub struct SidePlan {
    /// Runs of positions, leading to trailing edge; consecutive runs are joined by a retract
    /// and an approach (the positions between them are left out).
    pub runs: Vec<Vec<RootPosition>>,
    /// Uniform stations asked for.
    pub stations: usize,
    /// Uniform stations that carry a position.
    pub kept: usize,
    /// Stations left out, uniform and inserted, in u order. The inserted ones listed are
    /// those that split a run; the probes of the bisection for a run's end are not listed.
    pub left_out: Vec<LeftOutStation>,
    /// Where the motion between two consecutive positions could not be made clear (tool
    /// above the ball against the design) by inserted positions: the run is split there, a
    /// retract and an approach replace the motion.
    pub motion_splits: Vec<MotionSplit>,
    /// The axis smoothing of the runs ([`cam_plan::axis_smoothing`]).
    pub smoothing: cam_plan::SmoothingSummary,
}

/// A motion between two consecutive positions replaced by a retract and an approach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionSplit {
    /// u of the position before.
    pub from_u: f64,
    /// u of the position after.
    pub to_u: f64,
    /// Angle between their tool axes (degrees).
    pub turn_deg: f64,
}

impl SidePlan {
    /// Stations left out because no tool axis makes them accessible.
    pub fn skipped(&self) -> usize {
        self.left_out
            .iter()
            .filter(|s| !s.reason.is_unfit())
            .count()
    }

    /// Uniform stations left out because the ball does not fit against hub and side.
    pub fn unfit(&self) -> usize {
        self.left_out
            .iter()
            .filter(|s| s.reason.is_unfit() && !s.inserted)
            .count()
    }
}

/// One evaluated station.
#[derive(Debug, Clone, Copy)]
enum Eval {
    Placed(RootPosition),
    Out(LeftOut),
}

/// A sample of the side's u range: its u, evaluation, and — for the samples listed when left
/// out (uniform stations and stations splitting a run) — its station label and whether it
/// was inserted.
#[derive(Debug, Clone)]
struct Sample {
    u: f64,
    eval: Eval,
    listed: Option<(String, bool)>,
}

/// Evaluates stations of one blade side.
struct SidePlanner<'p, 'a> {
    ctx: &'p PlanContext<'a>,
    upper: DesignClearance<'a>,
    /// The tool above its ball (flutes, shank, holder) against hub and blades: the query of
    /// the motion check.
    motion: DesignClearance<'a>,
    boundary: BladeBoundary<'p>,
    blade: &'p Blade,
    side: Side,
    neighbour: &'p Blade,
    r: f64,
    step: f64,
}

impl SidePlanner<'_, '_> {
    /// The position at `u`, or why there is none.
    fn evaluate(&self, u: f64) -> Eval {
        self.evaluate_near(u, None, true)
    }

    /// [`Self::evaluate`] trying first the unit axis `preferred` — the interpolation of two
    /// neighbouring positions' axes, with the mean of their turns (rad) — then, with
    /// `search`, the axis search.
    fn evaluate_near(&self, u: f64, preferred: Option<(Vector3<f64>, f64)>, search: bool) -> Eval {
        let imp = self.ctx.impeller;
        let Some((centre, spine_c, nb, nh)) = spine(imp, self.blade, self.side, u, self.r) else {
            return Eval::Out(LeftOut::NoSpine);
        };
        let tol = self.ctx.tolerances.machining_tol;
        let (gap, part) = self.boundary.gap(&centre, self.r);
        if gap < -tol {
            return Eval::Out(LeftOut::BallMeetsBlade {
                centre,
                gap_mm: gap,
                part,
            });
        }
        let at = root_axis::Station {
            blade: self.blade,
            side: self.side,
            neighbour: self.neighbour,
            u,
            centre,
            normal: nb,
        };
        let interpolated = preferred.and_then(|(axis, rotation)| {
            let clearance = assembly_clearance(
                self.ctx,
                &self.upper,
                &centre,
                &axis,
                self.r,
                self.r,
                f64::NEG_INFINITY,
            );
            (clearance >= -tol && shank_clear(self.ctx, &self.upper, &centre, &axis, self.r))
                .then_some(Search::Found {
                    axis,
                    steps: 0,
                    rotation,
                    turn: TurnAxis::Interpolated,
                    clearance,
                })
        });
        let found = match interpolated {
            Some(f) => f,
            None if search => search_axis(self.ctx, &self.upper, &at, self.r, self.r, self.step),
            None => Search::None { c_max: 0.0 },
        };
        match found {
            Search::Found {
                axis,
                steps,
                rotation,
                turn,
                clearance,
            } => {
                let (overcut, undercut) = deviations(self.ctx, &centre, &spine_c, &nb, &nh, self.r);
                Eval::Placed(RootPosition {
                    u,
                    centre,
                    axis,
                    steps,
                    rotation,
                    turn,
                    clearance,
                    overcut,
                    undercut,
                })
            }
            Search::None { c_max } => Eval::Out(LeftOut::Inaccessible { centre, c_max }),
        }
    }

    /// The largest ball radius (≤ the tool's) at `u` whose ball fits against hub and side and
    /// has an accessible axis with the tool's shank and holder: bisection between
    /// `r·2^-RADIUS_BISECTIONS` (0 when even that fails) and `r`.
    fn largest_ball(&self, u: f64) -> f64 {
        let imp = self.ctx.impeller;
        let tol = self.ctx.tolerances.machining_tol;
        let fits = |ball: f64| {
            spine(imp, self.blade, self.side, u, ball).is_some_and(|(c, _, nb, _)| {
                let at = root_axis::Station {
                    blade: self.blade,
                    side: self.side,
                    neighbour: self.neighbour,
                    u,
                    centre: c,
                    normal: nb,
                };
                self.boundary.gap(&c, ball).0 >= -tol
                    && matches!(
                        search_axis(self.ctx, &self.upper, &at, self.r, ball, self.step),
                        Search::Found { .. }
                    )
            })
        };
        // The smallest ball first: where the shank or holder is what collides, no ball fits
        // and one search answers.
        let smallest = self.r * 0.5f64.powi(RADIUS_BISECTIONS as i32);
        if !fits(smallest) {
            return 0.0;
        }
        let (mut lo, mut hi) = (smallest, self.r);
        for _ in 0..RADIUS_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if fits(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The cutter location of a position (tip = ball centre − r·axis).
    fn cl_of(&self, p: &RootPosition) -> Option<CutterLocation> {
        CutterLocation::new(Point3::from(p.centre - p.axis * self.r), p.axis).ok()
    }

    /// Whether the motion from `a` to `b` (tip interpolated linearly, axis by slerp, the
    /// clearance query's motion model) keeps the tool above the ball — flutes, shank and
    /// holder — at least `−machining_tol − MOTION_TOL_MM` from hub and blades, certified by
    /// [`DesignClearance::segment_clearance_between`] (Lipschitz bisection). The flutes of a
    /// root position touch the blade and hub near the ball (clearance ≈ 0, the contact the
    /// positions are planned for), where no bisection certifies the `−machining_tol` of the
    /// positions themselves; with `MOTION_TOL_MM` the bisection checks postures at most
    /// `2·MOTION_TOL_MM` of tool displacement apart, which finds every motion that sweeps the
    /// tool through the blade (the jumps of the axis search between neighbouring positions)
    /// at a few queries per motion. The ball itself follows the chord of the two centres,
    /// kept within `machining_tol` of the root curve by the chord refinement.
    fn motion_clear(&self, a: &RootPosition, b: &RootPosition) -> bool {
        let (Some(ca), Some(cb)) = (self.cl_of(a), self.cl_of(b)) else {
            return false;
        };
        self.motion_clear_cl(&ca, &cb)
    }

    /// [`Self::motion_clear`] of two cutter locations.
    fn motion_clear_cl(&self, ca: &CutterLocation, cb: &CutterLocation) -> bool {
        let qa = self.motion.clearance(ca).distance_mm;
        let qb = self.motion.clearance(cb).distance_mm;
        self.motion_clear_between((ca, qa), (cb, qb))
    }

    /// [`Self::motion_clear_cl`] with the motion query's clearances `qa`, `qb` of the ends
    /// already measured.
    fn motion_clear_between(
        &self,
        (ca, qa): (&CutterLocation, f64),
        (cb, qb): (&CutterLocation, f64),
    ) -> bool {
        let min = -self.ctx.tolerances.machining_tol - MOTION_SAMPLE_TOL_MM;
        // Shank and holder, which do not cut, keep half of `shank_keep` all along the motion
        // (their postures keep all of it): the coarse bisection of the whole tool above
        // admits `min − (MOTION_TOL_MM − MOTION_SAMPLE_TOL_MM)`, which lets a shank graze a
        // blade (impeller-11+11-freeform: 0.022 mm into the design, found by the verifier).
        let keep = shank_keep(self.ctx);
        let upper_clear = || {
            let ua = self.upper.clearance(ca).distance_mm;
            let ub = self.upper.clearance(cb).distance_mm;
            self.upper
                .segment_clearance_between((ca, ua), (cb, ub), keep, 0.5 * keep, SEGMENT_QUERIES)
                .is_ok()
        };
        self.motion
            .segment_clearance_between(
                (ca, qa),
                (cb, qb),
                min,
                MOTION_TOL_MM - MOTION_SAMPLE_TOL_MM,
                SEGMENT_QUERIES,
            )
            .is_ok()
            && upper_clear()
    }

    /// The clearance of flutes, shank and holder of the posture with ball centre `centre` and
    /// axis `axis` (the accessibility test of the axis search).
    fn posture_clearance(&self, centre: &Vector3<f64>, axis: &Vector3<f64>) -> f64 {
        assembly_clearance(
            self.ctx,
            &self.upper,
            centre,
            axis,
            self.r,
            self.r,
            f64::NEG_INFINITY,
        )
    }

    /// The shared axis smoothing ([`cam_plan::axis_smoothing`]) of a run: turns about the
    /// ball centres (the ball's contact with hub, fillet and side stays exact), checked with
    /// the axis search's accessibility test and this planner's motion check.
    fn smooth_axes(&self, run: &mut [RootPosition], summary: &mut cam_plan::SmoothingSummary) {
        let cls: Vec<CutterLocation> = run.iter().filter_map(|p| self.cl_of(p)).collect();
        if cls.len() != run.len() {
            return;
        }
        let out = cam_plan::axis_smoothing::smooth_run(
            &cls,
            &cam_plan::AxisSmoothing::ball_end(self.r),
            self,
        );
        summary.add(&out);
        for (p, cl) in run.iter_mut().zip(out.postures) {
            let axis = cl.axis.into_inner();
            if axis != p.axis {
                p.axis = axis;
                p.clearance = self.posture_clearance(&p.centre, &axis);
            }
        }
    }

    /// Positions inserted between `a` and `b` so that every motion between consecutive
    /// positions is clear ([`Self::motion_clear`]): the midpoint in u, with the slerp of the
    /// two axes when that is accessible (else the axis search), then both halves, at most
    /// `depth` levels. `Err` when a motion stays unclear: the run is split there.
    fn bridge(
        &self,
        (ua, a): (f64, &RootPosition),
        (ub, b): (f64, &RootPosition),
        depth: u32,
        out: &mut Vec<RootPosition>,
    ) -> Result<(), ()> {
        if self.motion_clear(a, b) {
            return Ok(());
        }
        if depth == 0 {
            return Err(());
        }
        let um = 0.5 * (ua + ub);
        // Only the interpolated axis bridges: an axis found by the search where it is not
        // accessible would be another jump.
        let Eval::Placed(m) = self.evaluate_near(um, Some(between(a, b).ok_or(())?), false) else {
            return Err(());
        };
        self.bridge((ua, a), (um, &m), depth - 1, out)?;
        out.push(m);
        self.bridge((um, &m), (ub, b), depth - 1, out)
    }

    /// Samples inserted between `a` and `b` (exclusive), appended to `out`:
    /// - both placed: the midpoint where the spine point halfway lies farther than
    ///   `machining_tol` from the chord of the two ball centres (at most
    ///   [`MAX_REFINE_DEPTH`] levels); a midpoint left out splits the run and is listed;
    /// - one placed: the boundary of a run, bisected ([`MAX_END_DEPTH`] levels, or until the
    ///   two ball centres are within `machining_tol`) so the run ends as close as the
    ///   station spacing allows to where the ball stops fitting or being accessible — at a
    ///   blunt edge, the start of the edge;
    /// - neither: nothing.
    fn refine(&self, a: &Sample, b: &Sample, depth: (u32, u32), out: &mut Vec<Sample>) {
        let tol = self.ctx.tolerances.machining_tol;
        let um = 0.5 * (a.u + b.u);
        let (chord, end) = depth;
        let next = match (&a.eval, &b.eval) {
            (Eval::Placed(pa), Eval::Placed(pb)) => {
                if chord >= MAX_REFINE_DEPTH {
                    return;
                }
                let Some((cm, ..)) = spine(self.ctx.impeller, self.blade, self.side, um, self.r)
                else {
                    // No spine halfway: split there.
                    let m = Sample {
                        u: um,
                        eval: Eval::Out(LeftOut::NoSpine),
                        listed: Some((format!("inserted at u = {um:.5}"), true)),
                    };
                    self.refine(a, &m, (chord + 1, end), out);
                    self.refine(&m, b, (chord + 1, end), out);
                    out.push(m);
                    return;
                };
                let off = cam_core::path::point_segment_distance(
                    &Point3::from(cm),
                    &Point3::from(pa.centre),
                    &Point3::from(pb.centre),
                );
                if off <= tol {
                    return;
                }
                let eval = self.evaluate_near(um, between(pa, pb), true);
                let listed = matches!(eval, Eval::Out(_))
                    .then(|| (format!("inserted at u = {um:.5}"), true));
                (
                    Sample {
                        u: um,
                        eval,
                        listed,
                    },
                    (chord + 1, end),
                )
            }
            (Eval::Placed(p), Eval::Out(o)) | (Eval::Out(o), Eval::Placed(p)) => {
                let max_end = if o.is_unfit() {
                    MAX_END_DEPTH
                } else {
                    MAX_END_DEPTH_INACCESSIBLE
                };
                if end >= max_end || o.centre().is_some_and(|c| (c - p.centre).norm() <= tol) {
                    return;
                }
                let eval = self.evaluate(um);
                (
                    Sample {
                        u: um,
                        eval,
                        listed: None,
                    },
                    (chord, end + 1),
                )
            }
            (Eval::Out(_), Eval::Out(_)) => return,
        };
        let (m, d) = next;
        self.refine(a, &m, d, out);
        self.refine(&m, b, d, out);
        out.push(m);
    }
}

/// The slerp halfway between two positions' axes and the mean of their turns (rad); `None`
/// for opposite axes.
fn between(a: &RootPosition, b: &RootPosition) -> Option<(Vector3<f64>, f64)> {
    let ua = nalgebra::Unit::try_new(a.axis, 1e-12)?;
    let ub = nalgebra::Unit::try_new(b.axis, 1e-12)?;
    let m = ua.try_slerp(&ub, 0.5, 1e-9)?;
    Some((m.into_inner().normalize(), 0.5 * (a.rotation + b.rotation)))
}

/// Plans the root path of one blade side (the reference instance): uniform stations, then
/// stations inserted where the chord strays from the root curve and where a run of positions
/// ends ([`SidePlanner::refine`]). A station where the ball does not fit against hub and side
/// ([`LeftOut::NoSpine`], [`LeftOut::BallMeetsBlade`]) or that no tool axis makes accessible
/// ([`LeftOut::Inaccessible`]) carries no position: the path is split there. Errs only when
/// no station of the side carries one. Public for tests and benchmarks.
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
) -> Result<SidePlan, PlanError> {
    let r = ball_radius(ctx, operation, "blade-root finishing")?;
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let plus = blade.plus_theta_side() == side;
    let planner = SidePlanner {
        ctx,
        upper: shank_and_holder(ctx),
        motion: DesignClearance::with_mesh(
            ctx.impeller,
            ctx.clearance.mesh().clone(),
            ctx.tool,
            ClearanceOptions {
                parts: PartSet::MATERIAL,
                sample_tol_mm: MOTION_SAMPLE_TOL_MM.max(ctx.clearance.options().sample_tol_mm),
                above_mm: r,
            },
        )
        .map_err(|e| PlanError::tool(operation, ctx.tool.name(), e.to_string()))?,
        boundary: BladeBoundary::new(blade),
        blade,
        side,
        neighbour: if plus { next } else { prev },
        r,
        step,
    };
    let n = stations.max(2);
    let uniform: Vec<Sample> = (0..n)
        .into_par_iter()
        .map(|k| {
            let u = u0 + (u1 - u0) * k as f64 / (n - 1) as f64;
            Sample {
                u,
                eval: planner.evaluate(u),
                listed: Some((format!("{k}/{n}"), false)),
            }
        })
        .collect();
    let inserted: Vec<Vec<Sample>> = uniform
        .par_windows(2)
        .map(|w| {
            let mut out = Vec::new();
            planner.refine(&w[0], &w[1], (0, 0), &mut out);
            out
        })
        .collect();
    let kept = uniform
        .iter()
        .filter(|s| matches!(s.eval, Eval::Placed(_)))
        .count();
    let mut samples: Vec<Sample> = uniform
        .into_iter()
        .chain(inserted.into_iter().flatten())
        .collect();
    samples.sort_by(|a, b| a.u.total_cmp(&b.u));
    let mut plan = SidePlan {
        stations: n,
        kept,
        ..SidePlan::default()
    };
    let mut run: Vec<RootPosition> = Vec::new();
    let mut listed = Vec::new();
    for s in samples {
        match s.eval {
            Eval::Placed(p) => run.push(p),
            Eval::Out(reason) => {
                if !run.is_empty() {
                    plan.runs.push(std::mem::take(&mut run));
                }
                if let Some((station, inserted)) = s.listed {
                    listed.push(LeftOutStation {
                        station,
                        inserted,
                        u: s.u,
                        reason,
                        largest_ball_mm: None,
                    });
                }
            }
        }
    }
    if !run.is_empty() {
        plan.runs.push(run);
    }
    // Every motion between consecutive positions is checked; unclear ones are bridged by
    // inserted positions or split the run.
    let mut runs = Vec::with_capacity(plan.runs.len());
    for run in std::mem::take(&mut plan.runs) {
        let bridged: Vec<Result<Vec<RootPosition>, ()>> = run
            .par_windows(2)
            .map(|w| {
                let mut out = Vec::new();
                planner
                    .bridge((w[0].u, &w[0]), (w[1].u, &w[1]), MOTION_DEPTH, &mut out)
                    .map(|()| out)
            })
            .collect();
        let mut cur = vec![run[0]];
        for (w, b) in run.windows(2).zip(bridged) {
            match b {
                Ok(mid) => cur.extend(mid),
                Err(()) => {
                    plan.motion_splits.push(MotionSplit {
                        from_u: w[0].u,
                        to_u: w[1].u,
                        turn_deg: w[0].axis.angle(&w[1].axis).to_degrees(),
                    });
                    runs.push(std::mem::take(&mut cur));
                }
            }
            cur.push(w[1]);
        }
        runs.push(cur);
    }
    for run in &mut runs {
        planner.smooth_axes(run, &mut plan.smoothing);
    }
    plan.runs = runs;
    listed.par_iter_mut().for_each(|l| {
        if !l.reason.is_unfit() {
            l.largest_ball_mm = Some(planner.largest_ball(l.u));
        }
    });
    plan.left_out = listed;
    if plan.runs.is_empty() {
        let first = plan.left_out.first();
        return Err(PlanError::geometry(
            operation,
            format!("{label}, {side:?} side"),
            format!(
                "no station of the side can be finished ({} stations); at station {}: {}",
                n,
                first.map_or("?", |f| f.station.as_str()),
                first.map_or_else(String::new, |f| reason_text(f, r, step)),
            ),
        ));
    }
    Ok(plan)
}

/// The checks a smoothed root posture and motion must pass: the axis search's (flutes,
/// shank and holder at least `−machining_tol` from the design) and the motion check between
/// positions ([`SidePlanner::motion_clear`]); the ball is not moved by a turn about its
/// centre.
/// The measure of a posture is the motion query's clearance of it, an end of the motion's
/// bisection.
impl cam_plan::PostureCheck for SidePlanner<'_, '_> {
    type Clear = f64;
    fn posture_clear(&self, i: usize, cl: &CutterLocation) -> Option<f64> {
        let centre = cl.axis_point(self.r).coords;
        let axis = cl.axis.into_inner();
        let clear = self.ctx.reaches(&axis)
            && self.posture_clearance(&centre, &axis) >= -self.ctx.tolerances.machining_tol
            && shank_clear(self.ctx, &self.upper, &centre, &axis, self.r);
        if !clear {
            return None;
        }
        self.planned_clear(i, cl)
    }
    fn planned_clear(&self, _: usize, cl: &CutterLocation) -> Option<f64> {
        Some(self.motion.clearance(cl).distance_mm)
    }
    fn motion_clear(
        &self,
        _: usize,
        (a, qa): (&CutterLocation, &f64),
        (b, qb): (&CutterLocation, &f64),
    ) -> bool {
        self.motion_clear_between((a, *qa), (b, *qb))
    }
}

/// Why a station was left out, in words (for notes and errors).
fn reason_text(s: &LeftOutStation, r: f64, step: f64) -> String {
    let at = s.reason.centre().map_or_else(String::new, |c| {
        format!("ball centre ({:.3}, {:.3}, {:.3}): ", c.x, c.y, c.z)
    });
    match s.reason {
        LeftOut::NoSpine => format!(
            "the hub's and the side's offset surfaces do not meet here: no ball of radius {r:.3} mm touches both hub and side"
        ),
        LeftOut::BallMeetsBlade { gap_mm, part, .. } => format!(
            "{at}the ball touching hub and side would reach {:.3} mm into the blade's {part}",
            -gap_mm
        ),
        LeftOut::Inaccessible { c_max, .. } => {
            let largest = s.largest_ball_mm.unwrap_or(0.0);
            let fit = if largest >= 1e-3 * r {
                format!("the largest ball radius accessible here is {largest:.3} mm (tool has {r:.3} mm)")
            } else {
                format!("the largest ball radius accessible here is 0 mm: with this tool's shank and holder no ball fits (tool has {r:.3} mm; a longer or thinner neck is needed)")
            };
            format!(
                "{at}no accessible tool axis up to C_max = {:.2}° (turned about the impeller axis and tilted about the root tangent in steps of {:.2}°); {fit}",
                c_max.to_degrees(),
                step.to_degrees()
            )
        }
    }
}

/// The notes of one side (the pipeline prefixes the operation's name): one per inaccessible
/// station, one per stretch of stations where the
/// ball does not fit, with the ends of the path beside it.
fn side_notes(label: &str, side: Side, plan: &SidePlan, r: f64, step: f64) -> Vec<String> {
    let mut notes = Vec::new();
    let side_name = match side {
        Side::Pressure => "pressure side",
        Side::Suction => "suction side",
    };
    let ends: Vec<(f64, Vector3<f64>)> = plan
        .runs
        .iter()
        .flat_map(|run| [run.first(), run.last()])
        .flatten()
        .map(|p| (p.u, p.centre))
        .collect();
    let mut k = 0;
    while k < plan.left_out.len() {
        let s = &plan.left_out[k];
        if !s.reason.is_unfit() {
            notes.push(format!(
                "{label}, {side_name}, station {} (u = {:.4}) skipped: {}",
                s.station,
                s.u,
                reason_text(s, r, step)
            ));
            k += 1;
            continue;
        }
        // A stretch of unfit stations.
        let mut j = k;
        while j + 1 < plan.left_out.len() && plan.left_out[j + 1].reason.is_unfit() {
            j += 1;
        }
        let (a, b) = (&plan.left_out[k], &plan.left_out[j]);
        let worst = plan.left_out[k..=j]
            .iter()
            .min_by(|x, y| {
                let g = |s: &LeftOutStation| match s.reason {
                    LeftOut::BallMeetsBlade { gap_mm, .. } => gap_mm,
                    _ => 0.0,
                };
                g(x).total_cmp(&g(y))
            })
            .unwrap_or(a);
        let stops: Vec<String> = ends
            .iter()
            .filter(|(u, _)| {
                let before = *u < a.u && !ends.iter().any(|(w, _)| *w > *u && *w < a.u);
                let after = *u > b.u && !ends.iter().any(|(w, _)| *w < *u && *w > b.u);
                before || after
            })
            .map(|(u, c)| {
                format!(
                    "u = {u:.4}, ball centre ({:.3}, {:.3}, {:.3})",
                    c.x, c.y, c.z
                )
            })
            .collect();
        notes.push(format!(
            "{label}, {side_name}, station{} {}{} (u = {:.4}{}) left out, the ball does not fit against hub and side: at station {}, {}; the path stops beside them at {}",
            if j > k { "s" } else { "" },
            a.station,
            if j > k { format!(" to {}", b.station) } else { String::new() },
            a.u,
            if j > k { format!(" to {:.4}", b.u) } else { String::new() },
            worst.station,
            reason_text(worst, r, step),
            if stops.is_empty() { "no position".to_string() } else { stops.join(" and ") }
        ));
        k = j + 1;
    }
    for m in &plan.motion_splits {
        notes.push(format!(
            "{label}, {side_name}: the motion from u = {:.5} to u = {:.5} (the tool axis turns {:.1}° there) could not be made clear of the design; a retract and an approach replace it",
            m.from_u, m.to_u, m.turn_deg
        ));
    }
    notes
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
        let mut notes = Vec::new();
        let (mut over, mut under, mut clear, mut steps, mut max_rot) =
            (0.0f64, 0.0f64, f64::INFINITY, 0usize, 0.0f64);
        let (mut kept, mut skipped, mut unfit, mut splits, mut tilts) = (0, 0, 0, 0, 0);
        let mut smoothing = cam_plan::SmoothingSummary::default();
        for (label, blade, next, prev) in reference_blades(imp) {
            let count = if label.starts_with("main") {
                imp.main().count()
            } else {
                imp.splitter().map_or(0, |s| s.count())
            };
            let pitch = std::f64::consts::TAU / count.max(1) as f64;
            for side in [Side::Pressure, Side::Suction] {
                let plan = plan_side(
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
                kept += plan.kept;
                skipped += plan.skipped();
                unfit += plan.unfit();
                splits += plan.runs.len().saturating_sub(1);
                smoothing.merge(&plan.smoothing.clone().times(count));
                notes.extend(side_notes(&label, side, &plan, r, self.step_rad));
                let mut path = ToolPath::new(format!("{} {label} {side:?}", self.name), &self.tool);
                let many = plan.runs.len() > 1;
                for (k, run) in plan.runs.iter().enumerate() {
                    let mut cls = Vec::with_capacity(run.len());
                    for p in run {
                        let cl = CutterLocation::new(Point3::from(p.centre - p.axis * r), p.axis)
                            .map_err(|e| PlanError::cam(&self.name, e))?;
                        cls.push(cl);
                        over = over.max(p.overcut);
                        under = under.max(p.undercut);
                        clear = clear.min(p.clearance);
                        steps += p.steps;
                        max_rot = max_rot.max(p.rotation.abs());
                        tilts += usize::from(p.turn == TurnAxis::RootTangent);
                    }
                    if let (Some(last), Some(first)) = (path.moves.last(), cls.first()) {
                        let link = ctx.link(&last.cl, first, APPROACH_MM)?;
                        path.moves.extend(link);
                    }
                    path.moves.extend(cls.into_iter().map(Move::feed));
                    series.push(PlotSeries {
                        label: if many {
                            format!("{label} {side:?} (part {})", k + 1)
                        } else {
                            format!("{label} {side:?}")
                        },
                        points: run.iter().map(|p| [p.u, p.rotation.to_degrees()]).collect(),
                    });
                }
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
            .number("max_axis_rotation_deg", max_rot.to_degrees())
            .count("tangent_tilts", tilts)
            .count("stations_kept", kept)
            .count("skipped_stations", skipped)
            .count("unfit_stations", unfit)
            .count("path_splits", splits);
        smoothing.add_metrics(&mut metrics);
        notes.push(smoothing.note());
        let mut plots = vec![Plot {
                title: "Tool-axis turn from the blade's ruling per position (about the impeller axis, or tilted about the root tangent)".into(),
                kind: PlotKind::Lines {
                    x_label: "blade side parameter u (leading → trailing edge)".into(),
                    y_label: "turn (deg)".into(),
                    series,
                    equal_aspect: false,
                },
            }];
        plots.extend(smoothing.plot());
        Ok(PlannedOperation {
            paths,
            metrics,
            plots,
            notes,
        })
    }
}
