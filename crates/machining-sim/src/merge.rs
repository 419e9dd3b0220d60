//! Sampling runs of short feed blocks together for the removal.
//!
//! A program read back for verification holds many short moves: the post-processor splits
//! a cutter-location move into blocks to keep the joint-interpolated motion within its
//! linearisation tolerance, and the read-back cuts each block into chords within 1 µm of the
//! controller's motion (on the default job, 50k cutter locations become 162k blocks and 383k
//! read-back moves). Every move costs at least one position, however short it is, far more
//! than the sweep tolerance needs. This module lets the positions of a run of consecutive feed blocks be spaced
//! along the run as a whole, when the actual motion through the run stays within a
//! deviation budget `e` of the straight tool-centre-point motion (the *chord*) from the run's
//! start to its end. The positions stay on the actual motion (block ends in between are
//! skipped, not moved), so the removal never takes more than the program sweeps.
//!
//! # Bound
//! Let `Q` be a cutter location on the actual motion and `Q'` a location on the chord. A
//! cutting point `tip + h·a + w` (`0 ≤ h ≤ H`, `w ⊥ a`, `|w| ≤ ρ`) of `Q` lies within
//! `δ(Q, Q') = max(|Δtip|, |Δtip + H·Δa|) + ρ·|Δa|` of the corresponding point of `Q'`
//! ([`cutting_displacement`]: `|Δtip + h·Δa|` is convex in `h`, so its largest value is at
//! an end of the flutes; the radial offset turns with the axis by at most `|Δa|` in chord
//! length). Every location of the run lies within `e` of the chord in this sense. Two
//! consecutive positions `P_k`, `P_{k+1}` are at most `s` apart in cumulative cutting
//! displacement along the actual motion, so their chord locations are at most `s + 2e`
//! apart; the cutter swept along the chord between them lies within the scallop
//! `(s + 2e)²/(8ρ_min)` of the cutters at those two chord locations, and these lie within `e`
//! of the cutters at `P_k`, `P_{k+1}`. So what the actual motion sweeps is within
//! `(s + 2e)²/(8ρ_min) + 2e` of the cutters at the positions, and [`run_step`] picks `s` so
//! that this is at most the sweep tolerance: the removal under-reads by at most the same
//! bound as block-by-block sampling, and never over-reads.
//!
//! The deviation of a run is measured at the blocks' sub-positions (the eight samples per
//! block that [`crate::motion::positions_for_move`] uses for a joint-interpolated move, the
//! midpoint and end of a straight one), each against the chord location at the projection of
//! its tip on the chord. A run is extended block by block while every sample of every block
//! stays within `e` of the new chord; at most [`MAX_BLOCKS`] blocks are merged, so the
//! checks cost O([`MAX_BLOCKS`]) per block. Rapids are never merged (any contact during a
//! rapid is a collision, checked at the rapid's own positions), nor are blocks of cutters
//! with a flat face (whose step also depends on the direction of motion), nor blocks that do
//! not move the tip (a pure reorientation has no chord).

use crate::motion::tcp_at;
use cam_core::{Cutter, CutterLocation};

/// Most blocks merged into one chord.
pub const MAX_BLOCKS: usize = 32;

/// What [`cutting_displacement`] needs of a cutter: its flute length `H` and the largest
/// radius `ρ` of its flutes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuttingReach {
    /// Flute length (mm).
    pub flute_mm: f64,
    /// Largest radius of the fluted part (mm).
    pub radius_mm: f64,
}

impl CuttingReach {
    /// The reach of `cutter`.
    pub fn of(cutter: &Cutter) -> Self {
        let h = cutter.flute_length;
        let profile = cutter.shape.profile();
        Self {
            flute_mm: h,
            radius_mm: profile.radius_at(h).max(profile.radius_at(0.0)),
        }
    }
}

/// Largest displacement `δ(a, b)` of a cutting point of a cutter of reach `reach` between
/// the cutter locations `a` and `b` (module docs). O(1).
pub fn cutting_displacement(reach: &CuttingReach, a: &CutterLocation, b: &CutterLocation) -> f64 {
    let dt = b.tip - a.tip;
    let da = b.axis.into_inner() - a.axis.into_inner();
    dt.norm().max((dt + da * reach.flute_mm).norm()) + reach.radius_mm * da.norm()
}

/// A run of feed blocks being merged: its start, the samples of its blocks, the blocks with
/// their cumulative cutting displacement, and the samples' largest deviation from the chord.
#[derive(Debug, Clone, Default)]
pub struct Run {
    /// Start of the run (end of the block before it).
    pub start: Option<CutterLocation>,
    /// Samples of the blocks on the actual motion.
    samples: Vec<CutterLocation>,
    /// The blocks: (move index, start location, end location, cumulative cutting
    /// displacement of the run at the block's end).
    pub blocks: Vec<(usize, CutterLocation, CutterLocation, f64)>,
    /// Largest deviation of the samples from the current chord (mm).
    pub deviation_mm: f64,
}

impl Run {
    /// Whether no block is pending.
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Clears the run.
    pub fn clear(&mut self) {
        self.start = None;
        self.samples.clear();
        self.blocks.clear();
        self.deviation_mm = 0.0;
    }

    /// The samples of the run's blocks, in order.
    pub fn samples(&self) -> &[CutterLocation] {
        &self.samples
    }

    /// Starts a run at `start` with one block `(index, end)` sampled at `samples` (the last
    /// sample is the block's end).
    pub fn begin(
        &mut self,
        reach: &CuttingReach,
        start: CutterLocation,
        index: usize,
        end: CutterLocation,
        samples: &[CutterLocation],
    ) {
        self.clear();
        self.start = Some(start);
        let d = path_displacement(reach, &start, samples);
        self.blocks.push((index, start, end, d));
        self.samples.extend_from_slice(samples);
    }

    /// Cumulative cutting displacement of the run (mm).
    pub fn displacement_mm(&self) -> f64 {
        self.blocks.last().map_or(0.0, |b| b.3)
    }

    /// Extends the run by the block `(index, end)` sampled at `samples` when every sample of
    /// the run stays within `budget_mm` of the chord from the run's start to `end`; returns
    /// whether it did. A run of [`MAX_BLOCKS`] blocks, or a chord whose tip does not move,
    /// is not extended.
    pub fn try_extend(
        &mut self,
        reach: &CuttingReach,
        index: usize,
        end: CutterLocation,
        samples: &[CutterLocation],
        budget_mm: f64,
    ) -> bool {
        let (Some(start), Some(&(_, _, last_end, cum))) = (self.start, self.blocks.last()) else {
            return false;
        };
        if self.blocks.len() >= MAX_BLOCKS {
            return false;
        }
        let d = end.tip - start.tip;
        let len2 = d.norm_squared();
        if len2.is_nan() || len2 <= 1e-18 {
            return false;
        }
        let deviation = |q: &CutterLocation| {
            let s = ((q.tip - start.tip).dot(&d) / len2).clamp(0.0, 1.0);
            cutting_displacement(reach, &tcp_at(&start, &end, s), q)
        };
        let mut worst = 0.0f64;
        for q in self.samples.iter().chain(samples) {
            let e = deviation(q);
            if e.is_nan() || e > budget_mm {
                return false;
            }
            worst = worst.max(e);
        }
        let d = path_displacement(reach, &last_end, samples);
        self.blocks.push((index, last_end, end, cum + d));
        self.samples.extend_from_slice(samples);
        self.deviation_mm = worst;
        true
    }

    /// The `n` positions of the run, spaced evenly in cumulative cutting displacement along
    /// the actual motion: for each, the block (move index, start, end) and the fraction of
    /// the block at which it lies (the last is the run's end).
    pub fn positions(
        &self,
        n: usize,
    ) -> impl Iterator<Item = (usize, CutterLocation, CutterLocation, f64)> + '_ {
        let total = self.displacement_mm();
        let mut b = 0;
        (1..=n).filter_map(move |k| {
            let target = total * k as f64 / n as f64;
            while b + 1 < self.blocks.len() && self.blocks[b].3 < target {
                b += 1;
            }
            let &(mi, from, to, cum) = self.blocks.get(b)?;
            let before = if b == 0 { 0.0 } else { self.blocks[b - 1].3 };
            let f = if k == n || cum <= before {
                1.0
            } else {
                ((target - before) / (cum - before)).clamp(0.0, 1.0)
            };
            Some((mi, from, to, f))
        })
    }
}

/// Cumulative cutting displacement ([`cutting_displacement`]) along `samples` from `from`.
fn path_displacement(
    reach: &CuttingReach,
    from: &CutterLocation,
    samples: &[CutterLocation],
) -> f64 {
    let mut prev = from;
    let mut d = 0.0;
    for s in samples {
        d += cutting_displacement(reach, prev, s);
        prev = s;
    }
    d
}

/// Largest spacing `s` (cumulative cutting displacement) of the positions of a run whose
/// deviation from its chord is `e`, for the sweep tolerance `tol` and the cutter's smallest
/// principal radius `rho_min` (module docs): `(s + 2e)²/(8ρ) + 2e ≤ tol`. `None` when
/// `2e ≥ tol`.
pub fn run_step(rho_min: f64, tol: f64, e: f64) -> Option<f64> {
    let room = tol - 2.0 * e;
    (room > 0.0)
        .then(|| (8.0 * rho_min * room).sqrt() - 2.0 * e)
        .filter(|s| *s > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{CutterShape, Point3, UnitVector3, Vector3};

    fn ball() -> Cutter {
        Cutter::new("b", CutterShape::BallEnd { radius: 1.0 }, 10.0, 2.0, 30.0).unwrap()
    }

    fn at(x: f64, y: f64) -> CutterLocation {
        CutterLocation::vertical(Point3::new(x, y, 0.0))
    }

    #[test]
    fn displacement_bounds_every_cutting_point() {
        let c = ball();
        let a = at(0.0, 0.0);
        let b = CutterLocation {
            tip: Point3::new(0.1, 0.0, 0.0),
            axis: UnitVector3::new_normalize(Vector3::new(0.02, 0.01, 1.0)),
        };
        let bound = cutting_displacement(&CuttingReach::of(&c), &a, &b);
        // Every point of the flutes' surface moves by no more than the bound.
        let ra = nalgebra::Rotation3::rotation_between(&a.axis, &b.axis).unwrap();
        for i in 0..=20 {
            let h = 10.0 * i as f64 / 20.0;
            let r = c.shape.radius_at(h);
            for k in 0..16 {
                let t = k as f64 * std::f64::consts::TAU / 16.0;
                let w = Vector3::new(r * t.cos(), r * t.sin(), 0.0);
                let pa = a.tip + a.axis.into_inner() * h + w;
                let pb = b.tip + b.axis.into_inner() * h + ra * w;
                assert!((pb - pa).norm() <= bound + 1e-12);
            }
        }
    }

    #[test]
    fn collinear_blocks_merge_and_a_corner_does_not() {
        let r = CuttingReach::of(&ball());
        let mut run = Run::default();
        let s = |x: f64| [at(x - 0.05, 0.0), at(x, 0.0)];
        run.begin(&r, at(0.0, 0.0), 1, at(0.1, 0.0), &s(0.1));
        assert!(run.try_extend(&r, 2, at(0.2, 0.0), &s(0.2), 0.01));
        assert!(run.try_extend(&r, 3, at(0.3, 0.0), &s(0.3), 0.01));
        assert!(run.deviation_mm < 1e-12);
        // A block that turns by 90°: its end is 0.1 mm off the line of the run, and the
        // run's own samples leave the new chord by more than the budget.
        let turn = [at(0.3, 0.05), at(0.3, 0.1)];
        assert!(!run.try_extend(&r, 4, at(0.3, 0.1), &turn, 0.01));
        assert_eq!(run.blocks.len(), 3);
        assert!((run.displacement_mm() - 0.3).abs() < 1e-12);
        // Six positions spaced 0.05 mm along the actual motion: two per block, at its
        // middle and end.
        let p: Vec<(usize, f64)> = run.positions(6).map(|(i, _, _, f)| (i, f)).collect();
        let want = [(1, 0.5), (1, 1.0), (2, 0.5), (2, 1.0), (3, 0.5), (3, 1.0)];
        assert_eq!(p.len(), 6);
        for ((i, f), (wi, wf)) in p.iter().zip(want) {
            assert_eq!(*i, wi);
            assert!((f - wf).abs() < 1e-9, "{f} vs {wf}");
        }
    }

    #[test]
    fn run_step_meets_the_sweep_tolerance() {
        for (rho, tol, e) in [(1.5, 0.025, 0.0), (1.5, 0.025, 0.006), (1.0, 0.0625, 0.015)] {
            let s = run_step(rho, tol, e).unwrap();
            let under = (s + 2.0 * e).powi(2) / (8.0 * rho) + 2.0 * e;
            assert!(under <= tol * (1.0 + 1e-12), "{under} > {tol}");
            assert!(
                under >= tol * (1.0 - 1e-9),
                "not the largest step: {under} < {tol}"
            );
        }
        // Without deviation: the block-by-block scallop step sqrt(8 ρ tol).
        assert!((run_step(2.0, 0.01, 0.0).unwrap() - 0.4).abs() < 1e-12);
        assert!(run_step(1.0, 0.01, 0.005).is_none());
    }

    #[test]
    fn a_bulging_block_is_measured_at_its_samples() {
        let r = CuttingReach::of(&ball());
        let mut run = Run::default();
        run.begin(
            &r,
            at(0.0, 0.0),
            1,
            at(0.1, 0.0),
            &[at(0.05, 0.0), at(0.1, 0.0)],
        );
        // The next block ends on the line but bulges 0.02 mm sideways in its middle.
        let bulge = [at(0.15, 0.02), at(0.2, 0.0)];
        assert!(!run.try_extend(&r, 2, at(0.2, 0.0), &bulge, 0.01));
        assert!(run.try_extend(&r, 2, at(0.2, 0.0), &bulge, 0.03));
        assert!((run.deviation_mm - 0.02).abs() < 1e-12);
    }
}
