//! Certified postures and the motions between them (module docs of [`super`], step 5).

use super::axes::Axes;
use super::fit::FitQuery;
use super::operation::ChannelRoughing;
use crate::accessibility::limit_tilt;
use cam_core::{contact_location, CutterLocation, CutterShape};
use cam_plan::{PlanContext, PlanError};
use nalgebra::{Unit, Vector3};

/// Midpoint queries allowed per motion check (beyond them the motion counts as not clear).
/// A motion between postures with little clearance to spare (a shank beside a twisted blade)
/// needs many certified bisections: at 24 queries such motions ran out and were bridged or
/// split although clear (impeller-11+11-freeform: 451 split motions and 11 506 bridge
/// postures; at 384: 33 and 165, and planning faster, since failed checks were retried
/// through bridge postures).
pub(super) const SEGMENT_QUERIES: usize = 384;

/// Levels of planned intermediate postures between two postures (up to `2^d − 1` per
/// motion) before a motion is split.
pub(super) const BRIDGE_DEPTH: usize = 4;

/// A certified posture: the location and its clearance (whole tool against the design).
pub(super) type Posture = (CutterLocation, cam_plan::Clearance);

/// Why a point has no posture.
pub(super) enum Blocked {
    /// The cutter itself keeps `fit_min` from the blades with no candidate axis.
    Cutter,
    /// The cutter does with some axis, but never with shank and holder clear of the design
    /// and `fit_min` from the blades as well.
    ShankOrHolder,
}

/// The clearance of the whole tool at `cl` when it keeps `want` (at least 0) from the design
/// and `fit_min` from the blades, the test of [`ChannelRoughing::posture`]. The whole tool's
/// clearance to the design bounds its clearance to the blades from below: the blades alone are
/// asked only when the nearest part is the hub or the shroud and comes within `fit_min`.
pub(super) fn clear_posture(
    ctx: &PlanContext<'_>,
    fit: &FitQuery<'_>,
    fit_min: f64,
    cl: &CutterLocation,
    want: f64,
) -> Option<cam_plan::Clearance> {
    let c = ctx.clearance.clearance_if_clear(cl, want)?;
    if c.distance_mm < fit_min {
        let blades_kept = !matches!(c.design_part, cam_plan::DesignPart::Blade { .. })
            && fit.tool.is_clear(cl, fit_min);
        if !blades_kept {
            return None;
        }
    }
    Some(c)
}

impl ChannelRoughing {
    /// A posture at planar `q` (module docs, step 5): the axes `first` (when given), then
    /// the candidates of [`Axes::candidates`]; the whole tool (cutter, shank and holder) must
    /// keep `fit_min` from the blades (the blade allowance less half the machining tolerance:
    /// a shank that passes nearer rubs the allowance roughing leaves, measured 0.020 mm from a
    /// blade on impeller-11+11-freeform when only the cutter was held to it) and `0` from the
    /// design. A posture with at least the machining tolerance to spare (so that the motions
    /// between postures certify) is preferred, else the first clear one.
    /// O(candidates · query).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn posture(
        &self,
        ctx: &PlanContext<'_>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        axes: &Axes<'_>,
        q: [f64; 2],
        first: Option<Vector3<f64>>,
    ) -> Result<Result<Posture, Blocked>, PlanError> {
        let (p, n) = axes.point_of(q);
        if !fit.ball_fits(&p, &n, fit_min) {
            return Ok(Err(Blocked::Cutter));
        }
        let room = ctx.tolerances.machining_tol;
        let mut cutter_fits = false;
        let mut fallback: Option<Posture> = None;
        let tries = first
            .map(|a| limit_tilt(a, &n, axes.max_tilt))
            .into_iter()
            .chain(axes.candidates(q, &p, &n));
        for a in tries {
            let cl = self.touch(&fit.shape, &p, &n, &a, axes.level, q)?;
            // The whole tool's clearance bounds the cutter's against the blades from below:
            // the cutter query runs only when the whole tool's does not settle it.
            let want = if fallback.is_none() { 0.0 } else { room };
            let Some(c) = clear_posture(ctx, fit, fit_min, &cl, want) else {
                cutter_fits = cutter_fits || fit.cutter.is_clear(&cl, fit_min);
                continue;
            };
            cutter_fits = true;
            if c.distance_mm >= room {
                return Ok(Ok((cl, c)));
            }
            if fallback.is_none() {
                fallback = Some((cl, c));
            }
        }
        Ok(match fallback {
            Some(f) => Ok(f),
            None if cutter_fits => Err(Blocked::ShankOrHolder),
            None => Err(Blocked::Cutter),
        })
    }

    /// Connects `a` (planar `qa`) to `b` (`qb`): `true` when the motion is certified clear
    /// ([`cam_plan::DesignClearance::segment_clearance_between`], within `seg_tol`), or its
    /// halves are through a planned posture at the planar midpoint (first axis: the mean of
    /// the end axes), recursively up to `depth` levels; the inserted postures are pushed to
    /// `out` in order, with their planar points. O(2^depth · (posture + motion check)).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn bridge(
        &self,
        ctx: &PlanContext<'_>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        axes: &Axes<'_>,
        (a, qa): (&Posture, [f64; 2]),
        (b, qb): (&Posture, [f64; 2]),
        seg_tol: f64,
        depth: usize,
        out: &mut Vec<([f64; 2], Posture)>,
    ) -> Result<bool, PlanError> {
        let clear = ctx
            .clearance
            .segment_clearance_between(
                (&a.0, a.1.distance_mm),
                (&b.0, b.1.distance_mm),
                0.0,
                seg_tol,
                SEGMENT_QUERIES,
            )
            .is_ok();
        if clear {
            return Ok(true);
        }
        if depth == 0 {
            return Ok(false);
        }
        let qm = [0.5 * (qa[0] + qb[0]), 0.5 * (qa[1] + qb[1])];
        let am = (a.0.axis.into_inner() + b.0.axis.into_inner()).try_normalize(1e-12);
        let Ok(m) = self.posture(ctx, fit, fit_min, axes, qm, am)? else {
            return Ok(false);
        };
        if !self.bridge(
            ctx,
            fit,
            fit_min,
            axes,
            (a, qa),
            (&m, qm),
            seg_tol,
            depth - 1,
            out,
        )? {
            return Ok(false);
        }
        out.push((qm, m));
        self.bridge(
            ctx,
            fit,
            fit_min,
            axes,
            (&m, qm),
            (b, qb),
            seg_tol,
            depth - 1,
            out,
        )
    }

    /// The cutter location touching the level at `p` (normal `n`) with axis `a`; a contact
    /// error names level `level` and planar point `q`.
    pub(super) fn touch(
        &self,
        shape: &CutterShape,
        p: &Vector3<f64>,
        n: &Vector3<f64>,
        a: &Vector3<f64>,
        level: usize,
        q: [f64; 2],
    ) -> Result<CutterLocation, PlanError> {
        contact_location(
            shape,
            (*p).into(),
            Unit::new_normalize(*n),
            Unit::new_normalize(*a),
        )
        .map(|c| c.cl)
        .map_err(|e| {
            self.geo(
                format!("level {level}, s = {:.3} mm, y = {:.3} mm", q[0], q[1]),
                e.to_string(),
            )
        })
    }
}
