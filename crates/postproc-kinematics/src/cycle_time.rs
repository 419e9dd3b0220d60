//! Cycle time of joint-space motion from the machine's axis speed and acceleration limits.
//!
//! What a controller without tool-centre-point control does between two blocks is joint
//! interpolation: every axis moves linearly in one path parameter `s ∈ [0, 1]` from the
//! block's start joints `J₀` to its end joints `J₁`, axis `i` by `Dᵢ = J₁ᵢ − J₀ᵢ`. The
//! block's time follows from one trapezoidal profile of `s` (the slowest axis sets the
//! block):
//!
//! - cruise rate `u = min(1/T_prog, minᵢ vᵢ/|Dᵢ|)` (1/s), where `T_prog` is the programmed
//!   duration of a feed block (inverse time `1/F` minutes, or tip length over the mm/min
//!   feed; none for rapids) and `vᵢ` the axis' largest speed (`max_speed`);
//! - acceleration `α = k · minᵢ aᵢ/|Dᵢ|` (1/s²), `aᵢ` the axis' largest acceleration
//!   (`max_acceleration`, LinuxCNC's `MAX_ACCELERATION`), `k = ½` when blocks blend and 1 at
//!   exact stop;
//! - from rest to rest: `T = 1/u + u/α` with the final deceleration lasting `u/α` when
//!   `u²/α ≤ 1` (trapezoid), else `T = 2/√α` with deceleration `1/√α` (triangle: the block
//!   is too short to reach `u`).
//!
//! Blocks blend ([`Blending::Parabolic`], LinuxCNC's `G64` for moves that turn a rotary axis,
//! which get no arc blend): the next block starts when the one before begins its final
//! deceleration (not before the block before that one has ended: one blend at a time), and
//! each block runs at half the acceleration limits so that the two superposed profiles stay
//! within them (LinuxCNC `tc.c`). So `N` equal collinear blocks of length `L` at cruise take
//! `N·L/v + 2v/a` (one acceleration and one deceleration at `a/2`), `N` equal blocks too
//! short to reach it `(N + 1)·√(2L/a)`. At exact stop ([`Blending::ExactStop`]) every block
//! starts and ends at rest at the full limits. Non-motion blocks (tool change, spindle,
//! coolant, kinematics switches) stop the motion ([`MotionTimer::stop`]) and add their own
//! time ([`MotionTimer::dwell`]).
//!
//! The model ignores jerk limits, the trajectory planner's look-ahead beyond one blend (a
//! controller with deeper look-ahead runs chains of short blocks faster: the figure is then
//! an upper bound) and the controller's block processing rate. An axis without
//! `max_acceleration` accelerates instantly ([`MotionTimer::unlimited_acceleration`] names
//! them); an axis without `max_speed` makes rapids impossible to time, so
//! [`MotionTimer::new`] refuses the machine. O(1) per block, no allocation.

use crate::joints::{AxisId, Joints};
use crate::machine::{Blending, Machine};

/// Why a machine's motion cannot be timed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CycleTimeError {
    /// An axis has no `max_speed`: a rapid on it would take no time.
    #[error(
        "machine `{machine}`: axis {axis} has no `max_speed`; the cycle time needs every axis' \
         speed (add `max_speed` to [axes.{axis}])"
    )]
    MissingSpeed {
        /// Machine name.
        machine: String,
        /// Axis letter.
        axis: char,
    },
}

/// The time profile of one block from rest to rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockProfile {
    /// Duration from rest to rest (s).
    pub duration_s: f64,
    /// Duration of the final deceleration (s).
    pub deceleration_s: f64,
}

/// Accumulates the time of a sequence of joint-space blocks (see the module docs).
#[derive(Debug, Clone)]
pub struct MotionTimer {
    /// Largest speed per axis (mm/s, rad/s), word order X Y Z tilt C.
    speed: [f64; 5],
    /// Largest acceleration per axis (mm/s², rad/s²); infinite when not given.
    acceleration: [f64; 5],
    blending: Blending,
    /// End time of the program so far (s).
    end: f64,
    /// Earliest start of the next block (s).
    next_start: f64,
    /// End of the block before the last one (s): a block may not start before it (one blend
    /// at a time).
    last_end: f64,
}

/// Displacements below this (mm or rad) count as no motion.
const NO_MOTION: f64 = 1e-12;

impl MotionTimer {
    /// A timer at time 0 for `machine`'s limits and blending. Errors: an axis without
    /// `max_speed`.
    pub fn new(machine: &Machine) -> Result<Self, CycleTimeError> {
        let mut speed = [0.0; 5];
        let mut acceleration = [f64::INFINITY; 5];
        for (i, a) in AxisId::ALL.iter().enumerate() {
            let spec = machine.axis(*a);
            speed[i] = spec.max_speed.ok_or_else(|| CycleTimeError::MissingSpeed {
                machine: machine.name().to_string(),
                axis: spec.letter,
            })? / 60.0;
            if let Some(acc) = spec.max_acceleration {
                acceleration[i] = acc;
            }
        }
        Ok(Self {
            speed,
            acceleration,
            blending: machine.blending(),
            end: 0.0,
            next_start: 0.0,
            last_end: 0.0,
        })
    }

    /// Letters of the axes whose acceleration the machine file does not give (they are
    /// treated as accelerating instantly).
    pub fn unlimited_acceleration(machine: &Machine) -> Vec<char> {
        AxisId::ALL
            .iter()
            .map(|a| machine.axis(*a))
            .filter(|s| s.max_acceleration.is_none())
            .map(|s| s.letter)
            .collect()
    }

    /// The profile of the block `from → to` with programmed duration `programmed_s` (`None`
    /// for a rapid), as it runs under this timer's blending; `None` when no axis moves.
    pub fn profile(
        &self,
        from: &Joints,
        to: &Joints,
        programmed_s: Option<f64>,
    ) -> Option<BlockProfile> {
        let (a, b) = (from.to_array(), to.to_array());
        let mut rate = match programmed_s {
            Some(t) if t > 0.0 => 1.0 / t,
            _ => f64::INFINITY,
        };
        let mut accel = f64::INFINITY;
        let mut moves = false;
        for i in 0..5 {
            let d = (b[i] - a[i]).abs();
            if d <= NO_MOTION {
                continue;
            }
            moves = true;
            rate = rate.min(self.speed[i] / d);
            accel = accel.min(self.acceleration[i] / d);
        }
        if !moves || !rate.is_finite() {
            return None;
        }
        if self.blending == Blending::Parabolic {
            accel *= 0.5;
        }
        Some(if !accel.is_finite() {
            BlockProfile {
                duration_s: 1.0 / rate,
                deceleration_s: 0.0,
            }
        } else if rate * rate / accel <= 1.0 {
            BlockProfile {
                duration_s: 1.0 / rate + rate / accel,
                deceleration_s: rate / accel,
            }
        } else {
            let half = 1.0 / accel.sqrt();
            BlockProfile {
                duration_s: 2.0 * half,
                deceleration_s: half,
            }
        })
    }

    /// Adds the block `from → to` (programmed duration `programmed_s`, `None` for a rapid)
    /// and returns how much it extends the program (s): its duration less its overlap with
    /// the block before when blocks blend.
    pub fn block(&mut self, from: &Joints, to: &Joints, programmed_s: Option<f64>) -> f64 {
        let Some(p) = self.profile(from, to, programmed_s) else {
            return 0.0;
        };
        let start = match self.blending {
            Blending::Parabolic => self.next_start.max(self.last_end),
            Blending::ExactStop => self.end,
        };
        let end = start + p.duration_s;
        let added = (end - self.end).max(0.0);
        self.last_end = self.end;
        self.end = self.end.max(end);
        self.next_start = end - p.deceleration_s;
        added
    }

    /// Ends the motion: the next block starts after every block so far has ended (a tool
    /// change, a spindle or coolant command, a kinematics switch).
    pub fn stop(&mut self) {
        self.next_start = self.end;
        self.last_end = self.end;
    }

    /// Stops the motion and waits `seconds` (a tool change); returns `seconds`.
    pub fn dwell(&mut self, seconds: f64) -> f64 {
        self.stop();
        self.end += seconds.max(0.0);
        self.stop();
        seconds.max(0.0)
    }

    /// The program's time so far (s).
    pub fn elapsed_s(&self) -> f64 {
        self.end
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A table-table machine with the LinuxCNC xyzac-trt sample configuration's limits:
    /// 20 mm/s and 300 mm/s² on X Y Z, 30 °/s and 300 °/s² on A and C.
    fn machine(blending: &str, accel: bool) -> Machine {
        let acc = |a: f64| {
            if accel {
                format!("max_acceleration = {a}\n")
            } else {
                String::new()
            }
        };
        let text = format!(
            "name = \"t\"\nblending = \"{blending}\"\n[kinematics]\ntype = \"table-table\"\n\
             tilt_axis = \"A\"\n\
             [axes.X]\nmin = -500.0\nmax = 500.0\nmax_speed = 1200.0\n{0}\
             [axes.Y]\nmin = -500.0\nmax = 500.0\nmax_speed = 1200.0\n{0}\
             [axes.Z]\nmin = -500.0\nmax = 500.0\nmax_speed = 1200.0\n{0}\
             [axes.A]\nmin = -120.0\nmax = 120.0\nmax_speed = 1800.0\n{0}\
             [axes.C]\nmode = \"continuous\"\nmax_speed = 1800.0\n{0}",
            acc(300.0)
        );
        Machine::from_toml_str(&text, "t.toml").unwrap()
    }

    fn x(v: f64) -> Joints {
        Joints {
            x: v,
            ..Joints::default()
        }
    }

    /// One 100 mm rapid at exact stop: 100/20 + 20/300 s (accelerate to 20 mm/s at
    /// 300 mm/s², cruise, decelerate).
    #[test]
    fn a_single_rapid_is_a_trapezoid() {
        let mut t = MotionTimer::new(&machine("exact_stop", true)).unwrap();
        let added = t.block(&x(0.0), &x(100.0), None);
        let want = 100.0 / 20.0 + 20.0 / 300.0;
        assert!((added - want).abs() < 1e-12, "{added} vs {want}");
        assert!((t.elapsed_s() - want).abs() < 1e-12);
    }

    /// Two collinear 50 mm blocks that blend: one acceleration and one deceleration at half
    /// the limit, the cruise between them unbroken: 100/20 + 20/150 s.
    #[test]
    fn blended_collinear_blocks_keep_their_speed() {
        let mut t = MotionTimer::new(&machine("parabolic", true)).unwrap();
        t.block(&x(0.0), &x(50.0), None);
        t.block(&x(50.0), &x(100.0), None);
        let want = 100.0 / 20.0 + 20.0 / 150.0;
        assert!((t.elapsed_s() - want).abs() < 1e-12, "{}", t.elapsed_s());
        // At exact stop each block accelerates and stops at the full limit.
        let mut e = MotionTimer::new(&machine("exact_stop", true)).unwrap();
        e.block(&x(0.0), &x(50.0), None);
        e.block(&x(50.0), &x(100.0), None);
        let want = 2.0 * (50.0 / 20.0 + 20.0 / 300.0);
        assert!((e.elapsed_s() - want).abs() < 1e-12);
    }

    /// N = 100 blocks of 0.1 mm, too short to reach 20 mm/s at 150 mm/s²: triangles of
    /// 2·√(2L/a) each, each starting half-way through the one before: (N + 1)·√(2L/a).
    #[test]
    fn short_blocks_are_triangles_that_overlap_by_half() {
        let mut t = MotionTimer::new(&machine("parabolic", true)).unwrap();
        for k in 0..100 {
            t.block(&x(0.1 * k as f64), &x(0.1 * (k + 1) as f64), Some(1e-3));
        }
        let want = 101.0 * (2.0f64 * 0.1 / 300.0).sqrt();
        assert!((t.elapsed_s() - want).abs() < 1e-9, "{}", t.elapsed_s());
    }

    /// The programmed duration (inverse time) caps the rate; the slowest axis sets it
    /// otherwise; without accelerations a block takes its length over its rate.
    #[test]
    fn feed_and_the_slowest_axis_set_the_rate() {
        let mut t = MotionTimer::new(&machine("exact_stop", false)).unwrap();
        // 10 mm in X programmed to take 2 s (5 mm/s < 20 mm/s).
        assert!((t.block(&x(0.0), &x(10.0), Some(2.0)) - 2.0).abs() < 1e-12);
        // 10 mm in X with 90° of C: C needs 3 s at 30 °/s, X only 0.5 s.
        let to = Joints {
            x: 20.0,
            rotate: 90f64.to_radians(),
            ..Joints::default()
        };
        assert!((t.block(&x(10.0), &to, Some(0.1)) - 3.0).abs() < 1e-9);
        // No motion adds nothing.
        assert_eq!(t.block(&to, &to, Some(1.0)), 0.0);
        // A dwell stops and waits.
        assert_eq!(t.dwell(6.0), 6.0);
        assert!((t.elapsed_s() - 11.0).abs() < 1e-9);
        assert_eq!(
            MotionTimer::unlimited_acceleration(&machine("exact_stop", false)),
            vec!['X', 'Y', 'Z', 'A', 'C']
        );
    }

    /// After a stop the next block starts at rest after the last one ended, even when they
    /// would blend.
    #[test]
    fn a_stop_breaks_the_blend() {
        let mut t = MotionTimer::new(&machine("parabolic", true)).unwrap();
        t.block(&x(0.0), &x(50.0), None);
        t.stop();
        t.block(&x(50.0), &x(100.0), None);
        let want = 2.0 * (50.0 / 20.0 + 20.0 / 150.0);
        assert!((t.elapsed_s() - want).abs() < 1e-12);
    }

    #[test]
    fn a_machine_without_an_axis_speed_is_refused() {
        let m = Machine::from_toml_str(
            "name = \"n\"\n[kinematics]\ntype = \"table-table\"\ntilt_axis = \"A\"\n\
             [axes.X]\nmin = -1.0\nmax = 1.0\n[axes.Y]\nmin = -1.0\nmax = 1.0\n\
             [axes.Z]\nmin = -1.0\nmax = 1.0\n[axes.A]\nmin = -1.0\nmax = 1.0\n\
             [axes.C]\nmode = \"continuous\"\n",
            "n.toml",
        )
        .unwrap();
        let e = MotionTimer::new(&m).unwrap_err();
        assert!(e.to_string().contains("axis X has no `max_speed`"), "{e}");
    }
}
