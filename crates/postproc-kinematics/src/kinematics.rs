//! Forward and inverse kinematics of the three machine structures, solution choice by limits
//! and continuity, singularity handling and unwinding of continuous axes.
//!
//! Every structure shares one orientation chain: the tool axis in the workpiece frame is
//! `u = Rz(ψ)·R_k(θ)·u₀` with `ψ = s_c·C`, `θ = s_t·T` (T the tilt angle A or B about the unit
//! direction `k` = X or Y, `u₀` the spindle direction at zero angles, `s_c`, `s_t` = ±1 the
//! axis senses). Positions:
//!
//! * table-table (LinuxCNC `xyzac-trt` / `xyzbc-trt`, `trtfuncs.c`): the table-fixed world
//!   point is `P = r + Rz(ψ)·(o + R_k(θ)·(J − r − o))` with `r` the C-axis rotation point, `o`
//!   the tilt-axis offset and `s_c = s_t = +1` for `conventional_directions`, `−1` otherwise
//!   (LinuxCNC's default). Tool length does not enter (G43 active: J is the tool tip).
//! * head-table (the B-C turn-milling centre, paper 003 eqs. 3–6): the tip in the machine
//!   frame is `T = J + L·(u₀ − R_k(θ)u₀)` with `L` = pivot length + tool length, and the
//!   table-fixed point `P = r + Rz(ψ)·(T − r)`.
//! * head-head (fork head): `P = J + L·(u₀ − u)`.
//!
//! In all three `P` is the tip in the machine frame at zero table angles; the CL tip is
//! `P − workpiece_origin`.
//!
//! Inverse: `u_z = u₀_z·cos θ + (k×u₀)_z·sin θ` (rotation about Z keeps the z component) gives
//! the two tilt solutions `θ = φ ± acos(u_z/R)`; for each, `ψ = atan2(u_y,u_x) − atan2(v_y,v_x)`
//! with `v = R_k(θ)u₀`; positions follow in closed form. Constant time per pose, no
//! allocation.

use crate::error::KinematicsError;
use crate::joints::{AxisId, Joints};
use crate::machine::{AxisSpec, Kinematics, Machine, RotaryMode, TiltAxis};
use cam_core::{CutterLocation, Point3, UnitVector3, Vector3};
use std::f64::consts::TAU;

/// Slack when testing limits (mm for linear axes, rad for rotary axes): values within it of
/// a limit count as inside.
pub const LIMIT_SLACK: f64 = 1e-9;

#[inline]
fn rot_z(psi: f64, v: &Vector3) -> Vector3 {
    let (s, c) = psi.sin_cos();
    Vector3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

#[inline]
fn rot_tilt(axis: TiltAxis, theta: f64, v: &Vector3) -> Vector3 {
    let (s, c) = theta.sin_cos();
    match axis {
        TiltAxis::A => Vector3::new(v.x, c * v.y - s * v.z, s * v.y + c * v.z),
        TiltAxis::B => Vector3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z),
    }
}

/// Orientation chain constants of a machine.
#[derive(Debug, Clone, Copy)]
struct Chain {
    tilt: TiltAxis,
    u0: Vector3,
    s_t: f64,
    s_c: f64,
}

impl Machine {
    fn chain(&self) -> Chain {
        match &self.kinematics {
            Kinematics::TableTable(k) => {
                let s = if k.conventional_directions { 1.0 } else { -1.0 };
                Chain {
                    tilt: k.tilt_axis,
                    u0: Vector3::z(),
                    s_t: s,
                    s_c: s,
                }
            }
            Kinematics::HeadTable(k) => Chain {
                tilt: k.tilt_axis,
                u0: k.spindle_direction.into_inner(),
                s_t: k.tilt_sign,
                s_c: k.rotary_sign,
            },
            Kinematics::HeadHead(k) => Chain {
                tilt: k.tilt_axis,
                u0: k.spindle_direction.into_inner(),
                s_t: k.tilt_sign,
                s_c: k.rotary_sign,
            },
        }
    }

    /// Tool axis (tip → spindle) in the machine frame at zero rotary angles (`u₀`): +Z for
    /// table-table machines, the configured `spindle_direction` for head machines. Joint X Y Z
    /// of head machines assume tool length compensation along it; a program without tool
    /// length compensation adds `tool_length·u₀` to X Y Z.
    pub fn zero_spindle_direction(&self) -> UnitVector3 {
        UnitVector3::new_normalize(self.chain().u0)
    }

    /// Tool axis (tip → spindle, workpiece frame) produced by the rotary angles (rad).
    pub fn tool_axis(&self, tilt: f64, rotate: f64) -> UnitVector3 {
        let ch = self.chain();
        let u = rot_z(ch.s_c * rotate, &rot_tilt(ch.tilt, ch.s_t * tilt, &ch.u0));
        UnitVector3::new_normalize(u)
    }

    /// The tool tip in the machine frame at zero table angles (`cl.tip + workpiece_origin`):
    /// the X Y Z a controller in tool-centre-point mode expects (LinuxCNC `xyzac-trt` /
    /// `xyzbc-trt` world coordinates with G43 active and a zero work offset; Fanuc G43.4,
    /// Sinumerik TRAORI, Heidenhain M128 likewise program the tip in the workpiece frame).
    pub fn tcp_point(&self, cl: &CutterLocation) -> Point3 {
        Point3::from(cl.tip.coords + self.workpiece_origin)
    }

    /// Forward kinematics: the cutter location (tip in the workpiece frame, tool axis) that
    /// the joint values produce with a tool of length `tool_length` (mm, gauge line to tip;
    /// ignored by table-table machines, whose X Y Z are tool-tip coordinates).
    pub fn forward(&self, j: &Joints, tool_length: f64) -> CutterLocation {
        let ch = self.chain();
        let theta = ch.s_t * j.tilt;
        let psi = ch.s_c * j.rotate;
        let jv = Vector3::new(j.x, j.y, j.z);
        let (p, u) = match &self.kinematics {
            Kinematics::TableTable(k) => {
                let r = k.rot_point.coords;
                let o = k.offset;
                let p = r + rot_z(psi, &(o + rot_tilt(ch.tilt, theta, &(jv - r - o))));
                let u = rot_z(psi, &rot_tilt(ch.tilt, theta, &ch.u0));
                (p, u)
            }
            Kinematics::HeadTable(k) => {
                let l = k.pivot_length + tool_length;
                let vm = rot_tilt(ch.tilt, theta, &ch.u0);
                let t = jv + (ch.u0 - vm) * l;
                let r = k.rot_point.coords;
                (r + rot_z(psi, &(t - r)), rot_z(psi, &vm))
            }
            Kinematics::HeadHead(k) => {
                let l = k.pivot_length + tool_length;
                let u = rot_z(psi, &rot_tilt(ch.tilt, theta, &ch.u0));
                (jv + (ch.u0 - u) * l, u)
            }
        };
        CutterLocation {
            tip: Point3::from(p - self.workpiece_origin),
            axis: UnitVector3::new_normalize(u),
        }
    }

    /// Linear-axis values that put the tool tip on `tip` (workpiece frame) when the rotary
    /// axes stand at `tilt`, `rotate` (rad); the tool axis is then
    /// [`Machine::tool_axis`]`(tilt, rotate)`. Used to recompute positions after the angles
    /// were changed (reverse-motion smoothing).
    pub fn joints_for_angles(
        &self,
        tip: &Point3,
        tool_length: f64,
        tilt: f64,
        rotate: f64,
    ) -> Joints {
        let ch = self.chain();
        let theta = ch.s_t * tilt;
        let psi = ch.s_c * rotate;
        let p = tip.coords + self.workpiece_origin;
        let jv = match &self.kinematics {
            Kinematics::TableTable(k) => {
                let r = k.rot_point.coords;
                let o = k.offset;
                r + o + rot_tilt(ch.tilt, -theta, &(rot_z(-psi, &(p - r)) - o))
            }
            Kinematics::HeadTable(k) => {
                let l = k.pivot_length + tool_length;
                let r = k.rot_point.coords;
                let t = r + rot_z(-psi, &(p - r));
                let vm = rot_tilt(ch.tilt, theta, &ch.u0);
                t - (ch.u0 - vm) * l
            }
            Kinematics::HeadHead(k) => {
                let l = k.pivot_length + tool_length;
                let u = rot_z(psi, &rot_tilt(ch.tilt, theta, &ch.u0));
                p - (ch.u0 - u) * l
            }
        };
        Joints {
            x: jv.x,
            y: jv.y,
            z: jv.z,
            tilt,
            rotate,
        }
    }

    /// The raw rotary solutions `(tilt, rotate)` (rad, not yet shifted by multiples of 2π) for
    /// a tool axis: two tilt signs. At a singular pose (tool axis within
    /// [`Machine::singularity_tol`] of the C axis) the rotate angle is `hold_rotate`.
    pub fn rotary_solutions(
        &self,
        axis: &UnitVector3,
        hold_rotate: f64,
    ) -> Result<[(f64, f64); 2], KinematicsError> {
        let ch = self.chain();
        let u = axis.into_inner();
        let k = ch.tilt.direction();
        let w = k.cross(&ch.u0);
        let r = ch.u0.z.hypot(w.z);
        let phi = w.z.atan2(ch.u0.z);
        let ratio = u.z / r;
        if ratio.is_nan() || ratio.abs() > 1.0 + 1e-12 {
            return Err(KinematicsError::UnreachableOrientation(u.x, u.y, u.z));
        }
        let delta = ratio.clamp(-1.0, 1.0).acos();
        let ru = u.x.hypot(u.y);
        let singular = ru < self.singularity_tol.sin();
        let mut out = [(0.0, 0.0); 2];
        for (slot, theta) in out.iter_mut().zip([phi + delta, phi - delta]) {
            let psi = if singular {
                ch.s_c * hold_rotate
            } else {
                let v = rot_tilt(ch.tilt, theta, &ch.u0);
                u.y.atan2(u.x) - v.y.atan2(v.x)
            };
            *slot = (ch.s_t * theta, ch.s_c * psi);
        }
        Ok(out)
    }

    /// Inverse kinematics: joint values that put the tool tip on `cl.tip` with the tool axis
    /// `cl.axis`.
    ///
    /// Of the two tilt-sign solutions and the 2π-equivalents of each rotary angle, the choice
    /// is (1) within all axis limits, then (2) the smallest rotary travel
    /// `|ΔT| + |ΔC|` from `prev` (or from the home position when `prev` is `None`). At a
    /// singular pose (tool axis parallel to the C axis) C keeps its previous value. Continuous
    /// axes take the equivalent angle nearest the previous one (they unwind only where the
    /// caller asks, see [`Machine::unwind`]).
    ///
    /// Errors: non-finite input; an orientation the rotary axes cannot produce; no solution
    /// within limits — the error names the violated axis of the closest solution.
    pub fn inverse(
        &self,
        cl: &CutterLocation,
        tool_length: f64,
        prev: Option<&Joints>,
    ) -> Result<Joints, KinematicsError> {
        match self.inverse_best_effort(cl, tool_length, prev)? {
            (j, None) => Ok(j),
            (_, Some(e)) => Err(e),
        }
    }

    /// Like [`Machine::inverse`], but when no solution lies within the limits it still returns
    /// the closest one (by the same choice rule) together with the limit error, so a caller
    /// can report violations instead of stopping.
    pub fn inverse_best_effort(
        &self,
        cl: &CutterLocation,
        tool_length: f64,
        prev: Option<&Joints>,
    ) -> Result<(Joints, Option<KinematicsError>), KinematicsError> {
        let reference = prev.copied().unwrap_or(self.home);
        check_finite(cl, tool_length)?;
        // The choice of `choose_solution` with the rotary travel as cost, which needs the
        // angles only: the two solutions are taken cheapest first (the first of equal ones)
        // and the linear axes computed only until one lies within the limits.
        let sols = self.rotary_solutions(&cl.axis, reference.rotate)?;
        let tilt_spec = self.axis(AxisId::Tilt);
        let rot_spec = self.axis(AxisId::Rotate);
        let angles = sols.map(|(t, c)| {
            let (t, t_ok) = equivalent_angle(t, tilt_spec, reference.tilt);
            let (c, c_ok) = equivalent_angle(c, rot_spec, reference.rotate);
            let cost = (t - reference.tilt).abs() + (c - reference.rotate).abs();
            (t, c, t_ok && c_ok, cost)
        });
        let order = if angles[1].3 < angles[0].3 {
            [1, 0]
        } else {
            [0, 1]
        };
        let mut cheapest: Option<Joints> = None;
        for k in order {
            let (t, c, ok, _) = angles[k];
            let j = self.joints_for_angles(&cl.tip, tool_length, t, c);
            if ok && self.check_limits(&j, LIMIT_SLACK).is_ok() {
                return Ok((j, None));
            }
            cheapest.get_or_insert(j);
        }
        let a = cl.axis.into_inner();
        match cheapest {
            Some(j) => match self.check_limits(&j, LIMIT_SLACK) {
                Err(e) => Ok((j, Some(e))),
                Ok(()) => Err(KinematicsError::UnreachableOrientation(a.x, a.y, a.z)),
            },
            None => Err(KinematicsError::UnreachableOrientation(a.x, a.y, a.z)),
        }
    }

    /// Of the two tilt-sign solutions for `cl`, each with the rotary equivalents nearest
    /// `reference` (which also holds the rotate angle at a singular pose), the cheapest by
    /// `cost` within the limits and the cheapest outside them: `(best, fallback)`, each with
    /// its cost. Errors: non-finite input, an orientation the rotary axes cannot produce.
    fn choose_solution(
        &self,
        cl: &CutterLocation,
        tool_length: f64,
        reference: &Joints,
        cost: impl Fn(&Joints) -> f64,
    ) -> Result<(Scored, Scored), KinematicsError> {
        check_finite(cl, tool_length)?;
        let sols = self.rotary_solutions(&cl.axis, reference.rotate)?;
        let tilt_spec = self.axis(AxisId::Tilt);
        let rot_spec = self.axis(AxisId::Rotate);
        let mut best: Option<(f64, Joints)> = None;
        let mut fallback: Option<(f64, Joints)> = None;
        for (t, c) in sols {
            let (t, t_ok) = equivalent_angle(t, tilt_spec, reference.tilt);
            let (c, c_ok) = equivalent_angle(c, rot_spec, reference.rotate);
            let j = self.joints_for_angles(&cl.tip, tool_length, t, c);
            let cost = cost(&j);
            let feasible = t_ok && c_ok && self.check_limits(&j, LIMIT_SLACK).is_ok();
            let slot = if feasible { &mut best } else { &mut fallback };
            if slot.as_ref().is_none_or(|(bc, _)| cost < *bc) {
                *slot = Some((cost, j));
            }
        }
        Ok((best, fallback))
    }

    /// Inverse kinematics for a posture on the motion from `a` to `b` (the midpoint a
    /// linearisation inserts): of the two tilt-sign solutions, each with the rotary
    /// equivalents nearest the middle of `a` and `b`, the one within limits with the least
    /// rotary travel `|a → j| + |j → b|` (`|ΔT| + |ΔC|` each).
    ///
    /// [`Machine::inverse`] from `a` alone can pick the wrong branch near the singular
    /// direction: an axis a few hundredths of a degree from the C axis is reached by both
    /// tilt signs with C 180° apart, so the solution nearest `a` may lie on the other branch
    /// than `b`, and the motion on to `b` swings C by 180° (on impeller-8+8's hub finishing
    /// the linearisation then interpolated the joints instead and left 0.16 mm of deviation
    /// at the top of the flutes). At a singular pose C is the middle of `a`'s and `b`'s.
    /// Errors as [`Machine::inverse`].
    pub fn inverse_between(
        &self,
        cl: &CutterLocation,
        tool_length: f64,
        a: &Joints,
        b: &Joints,
    ) -> Result<Joints, KinematicsError> {
        let middle = Joints {
            tilt: 0.5 * (a.tilt + b.tilt),
            rotate: 0.5 * (a.rotate + b.rotate),
            ..*a
        };
        let (best, _) = self.choose_solution(cl, tool_length, &middle, |j| {
            a.rotary_travel(j) + j.rotary_travel(b)
        })?;
        match best {
            Some((_, j)) => Ok(j),
            None => self.inverse(cl, tool_length, Some(a)),
        }
    }

    /// Whether some posture within the rotary axes' travel gives the tool axis `axis` (of the
    /// two tilt signs and the 2π-equivalents of each angle; the linear axes, which depend on
    /// the tip, are not checked). What a planner may choose among tool axes on this machine.
    /// O(1).
    pub fn orientation_reachable(&self, axis: &UnitVector3) -> bool {
        let cl = CutterLocation {
            tip: Point3::origin(),
            axis: *axis,
        };
        self.candidate_angles(&cl, &self.home())
            .map(|mut c| c.next().is_some())
            .unwrap_or(false)
    }

    /// All postures that reach `cl` within the limits: both tilt signs and, for each, the
    /// 2π-equivalents of the rotary angles next to the one nearest `reference` (at most three
    /// per axis). Used to look ahead along a path when the greedy choice runs into a limit.
    pub fn inverse_candidates(
        &self,
        cl: &CutterLocation,
        tool_length: f64,
        reference: &Joints,
    ) -> Result<Vec<Joints>, KinematicsError> {
        let mut out = Vec::new();
        for (tt, cc) in self.candidate_angles(cl, reference)? {
            let j = self.joints_for_angles(&cl.tip, tool_length, tt, cc);
            if self.check_limits(&j, LIMIT_SLACK).is_ok()
                && !out
                    .iter()
                    .any(|o: &Joints| (o.tilt - tt).abs() < 1e-12 && (o.rotate - cc).abs() < 1e-12)
            {
                out.push(j);
            }
        }
        Ok(out)
    }

    /// The rotary angles `(tilt, rotate)` of [`Self::inverse_candidates`], in its order,
    /// before the linear axes are computed: for both tilt signs, the 2π-equivalents next to
    /// the ones nearest `reference` that lie within the rotary limits (a continuous axis keeps
    /// the nearest one only).
    fn candidate_angles(
        &self,
        cl: &CutterLocation,
        reference: &Joints,
    ) -> Result<impl Iterator<Item = (f64, f64)> + '_, KinematicsError> {
        let sols = self.rotary_solutions(&cl.axis, reference.rotate)?;
        let tilt_spec = self.axis(AxisId::Tilt);
        let rot_spec = self.axis(AxisId::Rotate);
        let shifts = |spec: &AxisSpec| -> &'static [f64] {
            if matches!(spec.mode, RotaryMode::Continuous) {
                &[0.0]
            } else {
                &[-TAU, 0.0, TAU]
            }
        };
        let (t_shifts, c_shifts) = (shifts(tilt_spec), shifts(rot_spec));
        let (ref_t, ref_c) = (reference.tilt, reference.rotate);
        Ok(sols.into_iter().flat_map(move |(t, c)| {
            let (t0, _) = equivalent_angle(t, tilt_spec, ref_t);
            let (c0, _) = equivalent_angle(c, rot_spec, ref_c);
            t_shifts.iter().flat_map(move |&dt| {
                c_shifts.iter().filter_map(move |&dc| {
                    let (tt, cc) = (t0 + dt, c0 + dc);
                    (tilt_spec.contains(tt, LIMIT_SLACK) && rot_spec.contains(cc, LIMIT_SLACK))
                        .then_some((tt, cc))
                })
            })
        }))
    }

    /// The posture nearest `reference` (least rotary travel `|ΔT| + |ΔC|`, the first of equal
    /// ones) among [`Self::inverse_candidates`] whose tilt passes `keep`; `None` when no
    /// candidate does. The candidates' angles decide the order, so the linear axes are
    /// computed (and checked against their limits) only for a candidate that improves on the
    /// best so far: a continuation along a sweep asks this at every step.
    pub fn nearest_candidate(
        &self,
        cl: &CutterLocation,
        tool_length: f64,
        reference: &Joints,
        keep: impl Fn(f64) -> bool,
    ) -> Result<Option<Joints>, KinematicsError> {
        let mut best: Option<(f64, Joints)> = None;
        // Angles of the candidates within the limits so far (the list's duplicates are
        // dropped as in `inverse_candidates`).
        let mut seen = [(0.0f64, 0.0f64); 18];
        let mut n_seen = 0;
        for (tt, cc) in self.candidate_angles(cl, reference)? {
            if seen[..n_seen]
                .iter()
                .any(|&(st, sc)| (st - tt).abs() < 1e-12 && (sc - cc).abs() < 1e-12)
            {
                continue;
            }
            let travel = (tt - reference.tilt).abs() + (cc - reference.rotate).abs();
            let improves = best.is_none_or(|(b, _)| travel < b);
            if !(keep(tt) && improves) {
                // Not chosen; whether it lies within the linear limits (and so shadows a
                // later duplicate) only matters for an equal angle pair, which would not
                // improve either.
                continue;
            }
            let j = self.joints_for_angles(&cl.tip, tool_length, tt, cc);
            if self.check_limits(&j, LIMIT_SLACK).is_ok() {
                if n_seen < seen.len() {
                    seen[n_seen] = (tt, cc);
                    n_seen += 1;
                }
                best = Some((travel, j));
            }
        }
        Ok(best.map(|(_, j)| j))
    }

    /// Reduces continuous rotary axes to the equivalent angle in (−π, π] and recomputes the
    /// linear axes (unchanged for a pure 2π shift). Returns `true` when a value changed.
    pub fn unwind(&self, j: &mut Joints) -> bool {
        let mut changed = false;
        for a in [AxisId::Tilt, AxisId::Rotate] {
            if matches!(self.axis(a).mode, RotaryMode::Continuous) {
                let v = j.get(a);
                let w = wrap_pi(v);
                if w != v {
                    j.set(a, w);
                    changed = true;
                }
            }
        }
        changed
    }
}

/// Errors: a non-finite tool tip, tool axis or tool length.
fn check_finite(cl: &CutterLocation, tool_length: f64) -> Result<(), KinematicsError> {
    if !(cl.tip.x.is_finite() && cl.tip.y.is_finite() && cl.tip.z.is_finite()) {
        return Err(KinematicsError::NonFinite("tool tip"));
    }
    let a = cl.axis.into_inner();
    if !(a.x.is_finite() && a.y.is_finite() && a.z.is_finite()) {
        return Err(KinematicsError::NonFinite("tool axis"));
    }
    if !tool_length.is_finite() {
        return Err(KinematicsError::NonFinite("tool length"));
    }
    Ok(())
}

/// Angle in (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let w = a - TAU * (a / TAU).round();
    if w <= -std::f64::consts::PI {
        w + TAU
    } else {
        w
    }
}

/// A posture with its cost, if any (see `Machine::choose_solution`).
type Scored = Option<(f64, Joints)>;

/// The 2π-equivalent of `angle` nearest `reference` within the axis travel; `false` when no
/// equivalent lies within the travel (then the one nearest the travel is returned).
fn equivalent_angle(angle: f64, spec: &AxisSpec, reference: f64) -> (f64, bool) {
    let k_ref = ((reference - angle) / TAU).round();
    match spec.mode {
        RotaryMode::Continuous => (angle + TAU * k_ref, true),
        RotaryMode::Limited { min, max } => {
            let kmin = ((min - LIMIT_SLACK - angle) / TAU).ceil();
            let kmax = ((max + LIMIT_SLACK - angle) / TAU).floor();
            if kmin <= kmax {
                let k = k_ref.clamp(kmin, kmax);
                (angle + TAU * k, true)
            } else {
                let k = ((reference.clamp(min, max) - angle) / TAU).round();
                (angle + TAU * k, false)
            }
        }
    }
}

#[cfg(test)]
mod lazy_choice_tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use cam_core::{Point3, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn machines() -> Vec<Machine> {
        ["xyzac-trt", "xyzbc-trt", "turnmill-bc", "headhead-ac"]
            .iter()
            .map(|n| {
                Machine::from_file(format!(
                    "{}/../../fixtures/machines/{n}.toml",
                    env!("CARGO_MANIFEST_DIR")
                ))
                .unwrap()
            })
            .collect()
    }

    /// Random postures across the four fixture machines, a third of them within 0.1° of the
    /// rotary axis' singular direction (where the continuation along a sweep asks most):
    /// [`Machine::nearest_candidate`] returns exactly the first least-travel posture of the
    /// filtered [`Machine::inverse_candidates`], and the lazy [`Machine::inverse_best_effort`]
    /// exactly the choice of `choose_solution` with the rotary travel as cost (the rule it
    /// replaced), limit errors included.
    #[test]
    fn lazy_choices_equal_the_full_ones() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        let mut compared = 0;
        for m in machines() {
            for k in 0..3000 {
                let pole = k % 3 == 0;
                let (tilt, rot) = if pole {
                    (
                        rng.random_range(-0.1f64..0.1).to_radians(),
                        rng.random_range(-3.2..3.2),
                    )
                } else {
                    (rng.random_range(-1.6f64..1.6), rng.random_range(-7.0..7.0))
                };
                let axis = m.tool_axis(tilt, rot).into_inner()
                    + Vector3::new(
                        rng.random_range(-1e-3..1e-3),
                        rng.random_range(-1e-3..1e-3),
                        rng.random_range(-1e-3..1e-3),
                    ) * f64::from(u8::from(!pole));
                let tip = Point3::new(
                    rng.random_range(-80.0..80.0),
                    rng.random_range(-80.0..80.0),
                    rng.random_range(-20.0..80.0),
                );
                let Ok(cl) = CutterLocation::new(tip, axis) else {
                    continue;
                };
                let reference = Joints {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    tilt: rng.random_range(-1.6..1.6),
                    rotate: rng.random_range(-7.0..7.0),
                };
                let tl = rng.random_range(50.0..150.0);
                let sign = rng.random_bool(0.5);
                let keep = |t: f64| (t < 0.0) == sign && t != 0.0;
                let lazy = m.nearest_candidate(&cl, tl, &reference, keep);
                let full = m.inverse_candidates(&cl, tl, &reference).map(|c| {
                    c.into_iter().filter(|j| keep(j.tilt)).min_by(|p, q| {
                        reference
                            .rotary_travel(p)
                            .total_cmp(&reference.rotary_travel(q))
                    })
                });
                match (lazy, full) {
                    (Ok(a), Ok(b)) => assert_eq!(a, b, "{} {cl:?}", m.name()),
                    (Err(_), Err(_)) => {}
                    (a, b) => panic!("{}: {a:?} vs {b:?}", m.name()),
                }
                let lazy = m.inverse_best_effort(&cl, tl, Some(&reference));
                let full = m
                    .choose_solution(&cl, tl, &reference, |j| reference.rotary_travel(j))
                    .map(|(best, fallback)| match (best, fallback) {
                        (Some((_, j)), _) => Some((j, None)),
                        (None, Some((_, j))) => {
                            m.check_limits(&j, LIMIT_SLACK).err().map(|e| (j, Some(e)))
                        }
                        (None, None) => None,
                    });
                match (lazy, full) {
                    (Ok(a), Ok(Some(b))) => assert_eq!(a, b, "{} {cl:?}", m.name()),
                    (Err(_), Ok(None)) | (Err(_), Err(_)) => {}
                    (a, b) => panic!("{}: {a:?} vs {b:?}", m.name()),
                }
                compared += 1;
            }
        }
        assert!(compared > 10_000, "{compared}");
    }
}
