//! Smooth tool axes along the runs of a point-milling pass (issue 37): the shared step of
//! [`cam_plan::axis_smoothing`] applied to every run once its postures are chosen.
//!
//! The accessibility search ([`super::axis::search`]) picks each station's tilt and lead in
//! whole search steps (3° by default), nearest the previous station's: along a pass over a
//! twisted free-form side the chosen axis alternates between neighbouring steps and the
//! rotary axes reverse inside the cut. The smoothing turns every posture about its ball
//! centre (`C = S + (R + a)·n`, fixed by the contact: the ball, hence every contact, the
//! scallops and the measured overcut and residual of the band stay exactly what the planner
//! measured) to the monotone smooth fit of the run's spherical axis angles, and accepts a
//! turned posture only when
//! - the machine can take its axis ([`cam_plan::PlanContext::reaches`]);
//! - the whole tool above the ball keeps the pass floors ([`PassCheck::is_clear`], the query
//!   the axis search used);
//! - every motion touching it keeps them ([`PassCheck::motion`], sampled with the ball and
//!   certified above the split height, as the planner's own motion certificates), and turns
//!   the axis by at most the pass's `max_axis_step`.
//!
//! What is refused keeps the planned posture; every direction change left is reported with
//! its reason ([`cam_plan::KeptReason`]; a motion refused for its axis step counts as
//! `clearance`, the planner's floor it breaks).
//!
//! Cost per run: at most [`MAX_FITS`] fits of O(m·w) (`m` postures, `w` within the kernel)
//! and the clearance checks of the changed postures and motions (which dominate).

use super::{PointPass, Station};
use cam_core::CutterLocation;
use cam_plan::axis_smoothing::smooth_run;
use cam_plan::{
    AxisSmoothing, PassCheck, PlanContext, PostureCheck, PostureClearance, SmoothingSummary,
};

/// Fits (and checks) per run: each refused fit splits the run at the refused postures; six
/// bound the cost of a run that cannot be smoothed as a whole (as channel roughing's runs).
/// Measured on `impeller-5-freeform/job-semi.toml` (2026-11-28): with 24 fits the
/// reversals left in blade finishing fall only from 280 to 270 (the reason of most moves
/// from `budget` to `clearance`: a smooth fit that would turn the axis by more than
/// `max_axis_step` between two stations is refused, and such refusals dominate), while the
/// blade operations' planning time doubles (4.7 → 9.9 s).
pub const MAX_FITS: usize = 6;

/// The checks a turned posture and its motions pass (module docs).
struct RunCheck<'a> {
    ctx: &'a PlanContext<'a>,
    check: &'a PassCheck<'a>,
    max_axis_step: f64,
}

/// The measure of a posture is the pass check's (whole tool and upper part clearances).
impl PostureCheck for RunCheck<'_> {
    type Clear = PostureClearance;
    fn posture_clear(&self, _: usize, cl: &CutterLocation) -> Option<PostureClearance> {
        if !self.ctx.reaches(&cl.axis.into_inner()) {
            return None;
        }
        self.check.clear_posture(cl)
    }

    fn planned_clear(&self, _: usize, cl: &CutterLocation) -> Option<PostureClearance> {
        self.check.clear_posture(cl)
    }

    fn motion_clear(
        &self,
        i: usize,
        a: (&CutterLocation, &PostureClearance),
        b: (&CutterLocation, &PostureClearance),
    ) -> bool {
        a.0.axis.angle(&b.0.axis) <= self.max_axis_step + 1e-12
            && PostureCheck::motion_clear(self.check, i, a, b)
    }
}

/// Smooths the axes of every run of `pass` in place (module docs) and returns the figures.
/// `r` is the ball radius (the pivot of the turn), `max_axis_step` the largest turn of the
/// axis between two postures (rad).
pub fn smooth_pass(
    ctx: &PlanContext<'_>,
    check: &PassCheck<'_>,
    pass: &mut PointPass,
    r: f64,
    max_axis_step: f64,
) -> SmoothingSummary {
    let opts = AxisSmoothing {
        max_fits: MAX_FITS,
        ..AxisSmoothing::ball_end(r)
    };
    let rc = RunCheck {
        ctx,
        check,
        max_axis_step,
    };
    let mut sum = SmoothingSummary::default();
    for run in &mut pass.runs {
        let cls: Vec<CutterLocation> = run.iter().map(|s| s.cl).collect();
        let out = smooth_run(&cls, &opts, &rc);
        sum.add(&out);
        for (s, cl) in run.iter_mut().zip(out.postures) {
            if s.cl != cl {
                retarget(s, cl, check);
            }
        }
    }
    sum
}

/// `s` with its posture turned to `cl` (same ball centre): its tilt and lead in the contact
/// frame and its clearances measured again. `smooth_run` accepted `cl` as clear, so the
/// clearance query answers; if it did not, the planned posture is kept.
fn retarget(s: &mut Station, cl: CutterLocation, check: &PassCheck<'_>) {
    if let Some(clearance) = check.clear_posture(&cl) {
        s.angles = s.contact.frame.angles(&cl.axis.into_inner());
        s.cl = cl;
        s.clearance = clearance;
    }
}
