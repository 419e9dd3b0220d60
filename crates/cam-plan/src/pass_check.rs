//! Whole-tool check of a cutting pass: every posture of a pass and every motion between two
//! consecutive postures, for the cutter, its shank and its holder, against the whole design
//! (hub and every blade of both rows), each part with its own floor.
//!
//! A finishing pass touches the surface it machines, so "clear" cannot mean "away from the
//! design": it means that no tool point comes nearer to a design part than that part's
//! *floor* — the allowance the operation leaves on it less the tolerance it may eat into it
//! (a flank pass over a sub-ruled strip reaches the strip's deviation into its allowance; a
//! finishing pass may overcut by the machining tolerance). The blades and the hub are
//! measured with separate queries because their allowances differ (blade semi-finishing
//! keeps 0.3 mm on a finished hub while it leaves 0.1 mm on the blades).
//!
//! **Postures**: [`DesignClearance::clearance`] of the whole tool (a ball end from its ball
//! centre up: the ball is that sample exactly, the samples below it would bound it by
//! spheres reaching below the tip).
//!
//! **Motions** (tip on the chord, axis on the great circle, as a five-axis controller moves
//! between two blocks) are checked in two parts split at a height `h_c` above the tip:
//! - above `h_c` (the shank and holder of a flank pass; everything above the ball of a
//!   point-milling posture), where the tool keeps away from the design, by certified
//!   bisection ([`DesignClearance::segment_clearance_between`]: the clearance is 1-Lipschitz
//!   in the displacement of any tool point, so two clear ends and a sweep `D` bound the
//!   clearance between them by `(c₀ + c₁ − D)/2`), to the floor less `motion_tol_mm`;
//! - below `h_c`, where the tool cuts and its clearance is the allowance itself (so the
//!   Lipschitz bound could certify nothing without splitting the motion into pieces of the
//!   tolerance), at the postures along the motion every `MOTION_STEP_MM` of displacement of
//!   its highest point (tip travel plus axis turn times `h_c`), against the same floors. Its
//!   deviation between those postures is what the planners' chord refinement bounds (the
//!   flank pass's two-point tangency solution and the point-milling ball centre within the
//!   chord tolerance of their curves).
//!
//! Shank and holder keep at least [`NON_CUTTING_CLEARANCE_MM`] from the design whatever the
//! floors ([`DesignClearance::with_non_cutting_margin`]): a finishing floor lets the flutes
//! reach the tolerance into the surface they finish, never the parts that do not cut.
//!
//! The answers are conservative like the query itself (a lower bound of the true clearance
//! within the query's sampling tolerance).
//!
//! Cost: two clearance queries per posture; per motion, two capped queries of the upper part
//! when it is clear by more than its sweep, O(log(sweep/tol)) more where it comes near, and
//! two per sampled posture of the lower part. Postures and motions are checked in parallel
//! (rayon).

use crate::clearance::{ClearanceOptions, DesignClearance, DesignPart, PartSet, ToolPart};
use crate::FilletMargin;
use cam_core::CutterLocation;
use rayon::prelude::*;

/// Most midpoint queries of one motion's certified bisection (upper part).
pub const MOTION_QUERIES: usize = 48;
/// How far above the floor (mm) the upper part's clearance of a posture is measured: a
/// motion whose ends keep the upper part this clear is certified without a midpoint when its
/// sweep is at most twice that.
pub const UPPER_CAP_MM: f64 = 4.0;
/// Largest displacement (mm) of the lower part's highest point between two sampled postures
/// of a motion.
pub const MOTION_STEP_MM: f64 = 1.0;

/// Least clearance (mm) of the shank and holder from the design in every pass check, below
/// whatever floor the cutting part keeps: they do not cut, and a finishing floor (the
/// machining tolerance into the finished surface) would let them rub the finished part.
/// Twice the default mesh chord, so that a check of the finished part on its own
/// tessellation does not read the clearance as contact.
pub const NON_CUTTING_CLEARANCE_MM: f64 = 0.02;

/// How near each design part a pass may bring the tool (mm; negative = into the design).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassFloors {
    /// Floor against every blade.
    pub blades_mm: f64,
    /// Floor against the hub.
    pub hub_mm: f64,
    /// Tolerance of the motion bisection: a motion is accepted when it provably keeps
    /// `floor − motion_tol_mm` (its ends must keep the floor itself).
    pub motion_tol_mm: f64,
}

/// Where a pass comes nearer to the design than its floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassViolation {
    /// Index of the posture (`s = 0`) or of the motion's start posture (`0 < s < 1`) in the
    /// checked sequence.
    pub index: usize,
    /// Fraction of the motion from posture `index` to `index + 1` (0 at a posture).
    pub s: f64,
    /// The clearance measured there (mm; a lower bound).
    pub clearance_mm: f64,
    /// The floor it missed (mm).
    pub floor_mm: f64,
    /// The design part.
    pub design_part: DesignPart,
    /// The tool part.
    pub tool_part: ToolPart,
    /// Height above the tip of the nearest tool sample (mm).
    pub height_mm: f64,
    /// The posture where it was found (tip and axis).
    pub at: CutterLocation,
}

impl PassViolation {
    /// How far the tool comes below the floor (mm, > 0).
    pub fn depth_mm(&self) -> f64 {
        self.floor_mm - self.clearance_mm
    }

    /// One line for a message: tool part, design part, depth and place.
    pub fn describe(&self) -> String {
        let part = match self.design_part {
            DesignPart::Hub => "the hub".to_string(),
            DesignPart::Shroud => "the shroud contour".to_string(),
            DesignPart::Fillet => "a blade-root fillet".to_string(),
            DesignPart::Blade { row, index } => format!(
                "{} blade {index}",
                match row {
                    crate::Row::Main => "main",
                    crate::Row::Splitter => "splitter",
                }
            ),
        };
        let tool = match self.tool_part {
            ToolPart::Cutter => "cutter",
            ToolPart::Shank => "shank",
            ToolPart::Holder => "holder",
        };
        let p = self.at.axis_point(self.height_mm);
        if self.depth_mm() <= 0.0 {
            return format!(
                "the motion near ({:.3}, {:.3}, {:.3}) could not be certified to keep its floor \
                 {:.3} mm from {part} within {MOTION_QUERIES} queries",
                p.x, p.y, p.z, self.floor_mm
            );
        }
        format!(
            "the {tool} ({:.1} mm above the tip) comes {:.3} mm nearer to {part} than its \
             floor {:.3} mm at ({:.3}, {:.3}, {:.3})",
            self.height_mm,
            self.depth_mm(),
            self.floor_mm,
            p.x,
            p.y,
            p.z
        )
    }
}

/// The clearances of one posture a motion check starts or ends at (mm): lower bounds of
/// the true clearances (see [`PassCheck::clear_posture`], [`PassCheck::measure`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostureClearance {
    /// (blade, hub) clearance of the checked part of the tool.
    pub whole: (f64, f64),
    /// (blade, hub) clearance of the part above the split height, capped
    /// [`UPPER_CAP_MM`] above the floors.
    pub upper: (f64, f64),
}

/// The queries of a pass check (blades, hub; the whole tool and its part above the split
/// height) built from one tool's clearance query.
#[derive(Debug, Clone)]
pub struct PassCheck<'a> {
    blades: DesignClearance<'a>,
    hub: DesignClearance<'a>,
    /// The queries of the sampled postures along a motion: the whole tool from the ball
    /// centre up, whatever [`PassCheck::with_postures_above`] leaves out of the posture
    /// queries (a planner places its ball exactly at its stations, not between them).
    motion_blades: DesignClearance<'a>,
    motion_hub: DesignClearance<'a>,
    upper_blades: DesignClearance<'a>,
    upper_hub: DesignClearance<'a>,
    floors: PassFloors,
    split_mm: f64,
    /// The blade-root fillets when asked for ([`PassCheck::with_fillets`]), with the ball
    /// they are checked against: (fillets, height of the ball centre above the tip, radius).
    fillets: Option<(&'a FilletMargin, f64, f64)>,
    /// Whether the posture queries hold the ball ([`PassCheck::with_postures_above`] may
    /// leave it to the planner).
    postures_hold_ball: bool,
}

impl<'a> PassCheck<'a> {
    /// The check of the tool of `clearance` (its sampling tolerance and mesh are kept) with
    /// `floors`, each lowered by the query's sampling error
    /// ([`DesignClearance::sampling_error_mm`]); motions are certified above `split_mm` and
    /// sampled below it (module docs).
    pub fn new(clearance: &DesignClearance<'a>, floors: PassFloors, split_mm: f64) -> Self {
        let o = clearance.options();
        let with = |parts: PartSet, above_mm: f64| {
            clearance.with_options(ClearanceOptions {
                parts,
                above_mm,
                ..o
            })
        };
        let hub = PartSet {
            hub: true,
            blades: false,
            shroud: false,
        };
        let split_mm = split_mm.max(0.0);
        // A ball end is measured by its centre sample (the ball itself, exactly): the
        // samples below it are spheres reaching below the tip, which would read a false
        // penetration of the surface the ball touches.
        let lowest = clearance
            .ball_centre_mm()
            .map_or(0.0, |h| (h - 1e-9).max(0.0));
        // The queries read up to their sampling error below the true clearance: a pass that
        // keeps its floor exactly (a finishing flank touching its side) may read that much
        // below it.
        let err = clearance.sampling_error_mm();
        let floors = PassFloors {
            blades_mm: floors.blades_mm - err,
            hub_mm: floors.hub_mm - err,
            ..floors
        };
        // Shank and holder keep NON_CUTTING_CLEARANCE_MM from the finished part whatever
        // the floor lets the flutes do (module docs).
        let lifted = |q: DesignClearance<'a>, floor: f64| {
            q.with_non_cutting_margin(NON_CUTTING_CLEARANCE_MM - floor)
        };
        let (fb, fh) = (floors.blades_mm, floors.hub_mm);
        Self {
            blades: lifted(with(PartSet::BLADES, lowest), fb),
            hub: lifted(with(hub, lowest), fh),
            motion_blades: lifted(with(PartSet::BLADES, lowest), fb),
            motion_hub: lifted(with(hub, lowest), fh),
            upper_blades: lifted(with(PartSet::BLADES, split_mm), fb),
            upper_hub: lifted(with(hub, split_mm), fh),
            floors,
            split_mm,
            fillets: None,
            postures_hold_ball: true,
        }
    }

    /// The same check with the ball of a ball or tapered ball end also kept clear of the
    /// blade-root fillets ([`FilletMargin`]; floor: the smaller of the blade and hub
    /// floors): at every posture whose query holds the ball, and along every motion
    /// (certified, [`FilletMargin::certify_motion`]). The sharp design queries read a
    /// fillet's material as air; only the ball is checked against it, since the parts above
    /// it stay farther from the corner than the ball wherever the axis leans away from hub
    /// and side. A tool without a ball end is returned unchanged.
    pub fn with_fillets(mut self, fillets: Option<&'a FilletMargin>) -> Self {
        let Some(f) = fillets else {
            return self;
        };
        let Some(h) = self.motion_hub.ball_centre_mm() else {
            return self;
        };
        let rho = self
            .motion_hub
            .samples()
            .find(|&(hs, _)| (hs - h).abs() <= 1e-9)
            .map(|(_, rho)| rho);
        if let Some(rho) = rho {
            self.fillets = Some((f, h, rho));
        }
        self
    }

    /// Whether the ball about `centre` keeps `floor` from the fillets (true when the check
    /// holds no fillets): for a planner that places the ball itself
    /// ([`PassCheck::with_postures_above`]).
    pub fn ball_keeps_fillets(&self, centre: &crate::Vector3, floor: f64) -> bool {
        self.fillets
            .is_none_or(|(f, _, rho)| f.clearance(&self.motion_hub, centre, rho, floor) >= floor)
    }

    /// The floor of the fillets: the smaller of the blade and hub floors.
    fn fillet_floor(&self) -> f64 {
        self.floors.blades_mm.min(self.floors.hub_mm)
    }

    /// The fillet clearance of the posture's ball when it comes below the fillet floor
    /// (checked only when the fillets were asked for and the posture queries hold the ball).
    fn fillet_violation(&self, index: usize, cl: &CutterLocation) -> Option<PassViolation> {
        let (f, h, rho) = self.fillets?;
        if !self.postures_hold_ball {
            return None;
        }
        let floor = self.fillet_floor();
        let c = cl.axis_point(h).coords;
        let value = f.clearance(&self.motion_hub, &c, rho, floor);
        (value < floor).then_some(PassViolation {
            index,
            s: 0.0,
            clearance_mm: value,
            floor_mm: floor,
            design_part: DesignPart::Fillet,
            tool_part: ToolPart::Cutter,
            height_mm: h,
            at: *cl,
        })
    }

    /// The same check with the tool samples up to `above_mm` above the tip left out of the
    /// posture queries: for a planner that places its ball itself at a verified distance
    /// from the design (the point-milling ball centre is measured exactly against the whole
    /// design before a posture is tried), so only the tool above it needs the query. The
    /// sampled postures between two postures of a motion keep the whole tool: nothing placed
    /// the ball there (a step between two passes cuts a chord across the side's offset).
    pub fn with_postures_above(mut self, above_mm: f64) -> Self {
        let set = |q: &DesignClearance<'a>| {
            q.with_options(ClearanceOptions {
                above_mm: above_mm.max(0.0),
                ..q.options()
            })
        };
        self.blades = set(&self.blades);
        self.hub = set(&self.hub);
        self.postures_hold_ball = self
            .motion_hub
            .ball_centre_mm()
            .is_some_and(|h| above_mm < h - 1e-9);
        self
    }

    /// The floors checked.
    pub fn floors(&self) -> PassFloors {
        self.floors
    }

    /// Whether the posture keeps both floors (stops at the first part below its floor:
    /// cheaper than [`PassCheck::posture`]).
    pub fn is_clear(&self, cl: &CutterLocation) -> bool {
        self.blades.is_clear(cl, self.floors.blades_mm)
            && self.hub.is_clear(cl, self.floors.hub_mm)
            && self.fillet_violation(0, cl).is_none()
    }

    /// The violation of one posture, if any (blades first, then hub).
    pub fn posture(&self, index: usize, cl: &CutterLocation) -> Option<PassViolation> {
        self.posture_clearances(index, cl).1
    }

    /// The posture's clearances when it keeps both floors, `None` otherwise. The whole-tool
    /// values are the floors themselves (lower bounds: the queries stop as soon as the floor
    /// is proven), the upper part's are capped ([`UPPER_CAP_MM`] above the floors).
    pub fn clear_posture(&self, cl: &CutterLocation) -> Option<PostureClearance> {
        if !self.is_clear(cl) {
            return None;
        }
        Some(self.with_upper(cl, (self.floors.blades_mm, self.floors.hub_mm)))
    }

    /// The posture's clearances (whole and upper part).
    pub fn measure(&self, cl: &CutterLocation) -> PostureClearance {
        let whole = self.posture_clearances(0, cl).0;
        self.with_upper(cl, whole)
    }

    fn with_upper(&self, cl: &CutterLocation, whole: (f64, f64)) -> PostureClearance {
        let upper = if self.split_mm > 0.0 {
            let cap = |floor: f64| floor + UPPER_CAP_MM;
            (
                self.upper_blades
                    .clearance_capped(cl, cap(self.floors.blades_mm))
                    .distance_mm
                    .max(whole.0),
                self.upper_hub
                    .clearance_capped(cl, cap(self.floors.hub_mm))
                    .distance_mm
                    .max(whole.1),
            )
        } else {
            whole
        };
        PostureClearance { whole, upper }
    }

    /// (blade clearance, hub clearance) of a posture, and its violation if any.
    fn posture_clearances(
        &self,
        index: usize,
        cl: &CutterLocation,
    ) -> ((f64, f64), Option<PassViolation>) {
        let b = self.blades.clearance(cl);
        let h = self.hub.clearance(cl);
        let v = [(b, self.floors.blades_mm), (h, self.floors.hub_mm)]
            .into_iter()
            .filter(|(c, floor)| c.distance_mm < *floor)
            .min_by(|x, y| (x.0.distance_mm - x.1).total_cmp(&(y.0.distance_mm - y.1)))
            .map(|(c, floor)| PassViolation {
                index,
                s: 0.0,
                clearance_mm: c.distance_mm,
                floor_mm: floor,
                design_part: c.design_part,
                tool_part: c.tool_part,
                height_mm: c.height_mm,
                at: *cl,
            })
            .or_else(|| self.fillet_violation(index, cl));
        ((b.distance_mm, h.distance_mm), v)
    }

    /// Every posture and motion of `pass` that comes below its floor: at most one violation
    /// per posture and one per motion, in pass order. Empty when the whole pass is clear.
    pub fn check(&self, pass: &[CutterLocation]) -> Vec<PassViolation> {
        let ends: Vec<(PostureClearance, Option<PassViolation>)> = pass
            .par_iter()
            .enumerate()
            .map(|(i, cl)| {
                let (whole, v) = self.posture_clearances(i, cl);
                (self.with_upper(cl, whole), v)
            })
            .collect();
        let motions: Vec<Option<PassViolation>> = (0..pass.len().saturating_sub(1))
            .into_par_iter()
            .map(|i| {
                if ends[i].1.is_some() || ends[i + 1].1.is_some() {
                    return None;
                }
                self.motion(i, (&pass[i], &ends[i].0), (&pass[i + 1], &ends[i + 1].0))
            })
            .collect();
        let mut out = Vec::new();
        for (i, (_, end)) in ends.iter().enumerate() {
            if let Some(v) = end {
                out.push(*v);
            }
            if let Some(Some(v)) = motions.get(i) {
                out.push(*v);
            }
        }
        out
    }

    /// The violation of the motion from posture `index` (`a`) to the next (`b`), given their
    /// (blade, hub) clearances; `None` when it keeps its floors (module docs: certified above
    /// the split height within `motion_tol_mm`, sampled below it every
    /// [`MOTION_STEP_MM`]).
    pub fn motion(
        &self,
        index: usize,
        a: (&CutterLocation, &PostureClearance),
        b: (&CutterLocation, &PostureClearance),
    ) -> Option<PassViolation> {
        self.motion_sampled(index, a, b, MOTION_STEP_MM)
    }

    /// [`PassCheck::motion`] with the lower part sampled every `step_mm` of displacement of
    /// its highest point: for a motion no planner refined along a curve (a step between two
    /// passes), where the ball's deviation between two samples is bounded only by the
    /// surface's curvature (a chord of a surface of radius `ρ` sags at most `step²/(8ρ)`
    /// between samples `step` apart).
    pub fn motion_sampled(
        &self,
        index: usize,
        (a, ca): (&CutterLocation, &PostureClearance),
        (b, cb): (&CutterLocation, &PostureClearance),
        step_mm: f64,
    ) -> Option<PassViolation> {
        let tol = self.floors.motion_tol_mm.max(0.0);
        let at = |s: f64| CutterLocation {
            tip: a.tip + (b.tip - a.tip) * s,
            axis: a.axis.slerp(&b.axis, s),
        };
        let violation = |query: &DesignClearance<'_>, s: f64, floor: f64| {
            let cl = at(s);
            let c = query.clearance(&cl);
            PassViolation {
                index,
                s,
                clearance_mm: c.distance_mm,
                floor_mm: floor,
                design_part: c.design_part,
                tool_part: c.tool_part,
                height_mm: c.height_mm,
                at: cl,
            }
        };
        // The lower part at sampled postures.
        let sweep = (b.tip - a.tip).norm() + a.axis.angle(&b.axis) * self.split_mm;
        let n = (sweep / step_mm.max(1e-3)).ceil() as usize;
        for k in 1..n {
            let s = k as f64 / n as f64;
            let cl = at(s);
            if !self.motion_blades.is_clear(&cl, self.floors.blades_mm) {
                return Some(violation(&self.motion_blades, s, self.floors.blades_mm));
            }
            if !self.motion_hub.is_clear(&cl, self.floors.hub_mm) {
                return Some(violation(&self.motion_hub, s, self.floors.hub_mm));
            }
        }
        // The ball against the fillets, certified.
        if let Some((f, h, rho)) = self.fillets {
            let floor = self.fillet_floor();
            if let Err(s) =
                f.certify_motion(&self.motion_hub, a, b, h, rho, floor, tol, MOTION_QUERIES)
            {
                let cl = at(s);
                let c = cl.axis_point(h).coords;
                return Some(PassViolation {
                    index,
                    s,
                    clearance_mm: f.clearance(&self.motion_hub, &c, rho, floor),
                    floor_mm: floor,
                    design_part: DesignPart::Fillet,
                    tool_part: ToolPart::Cutter,
                    height_mm: h,
                    at: cl,
                });
            }
        }
        // The upper part, certified.
        if self.split_mm > 0.0 {
            let parts = [
                (
                    &self.upper_blades,
                    ca.upper.0,
                    cb.upper.0,
                    self.floors.blades_mm,
                ),
                (&self.upper_hub, ca.upper.1, cb.upper.1, self.floors.hub_mm),
            ];
            for (query, c0, c1, floor) in parts {
                if let Err(s) =
                    query.segment_clearance_between((a, c0), (b, c1), floor, tol, MOTION_QUERIES)
                {
                    return Some(violation(query, s, floor));
                }
            }
        }
        None
    }

    /// The smallest (blade, hub) clearance of a posture (mm).
    pub fn clearances(&self, cl: &CutterLocation) -> (f64, f64) {
        self.posture_clearances(0, cl).0
    }

    /// Whether both (blade, hub) clearances keep the floors.
    pub fn keeps_floors(&self, (b, h): (f64, f64)) -> bool {
        b >= self.floors.blades_mm && h >= self.floors.hub_mm
    }
}
