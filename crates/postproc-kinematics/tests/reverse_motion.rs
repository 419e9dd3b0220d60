//! Reverse-motion removal on a realistic cutting run: a plunge with a constant posture
//! followed by a five-axis sweep whose C angle swings back and forth. The paper's four cubic
//! B-splines cannot follow the plunge-to-sweep change within the 10° angle limit; the adaptive
//! control-value count must.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{CutterLocation, Move, Point3};
use postproc_kinematics::reverse_motion::{
    adaptive_control_cap, count_reverse_motions, reversal_windows, smooth_monotone,
    smooth_monotone_adaptive, smooth_monotone_windowed, REVERSE_DEAD_BAND_RAD,
};
use postproc_kinematics::{
    post_path, post_path_checked, AccessibilityChecker, AxisId, Machine, PostOptions,
    ReverseMotionOptions,
};

fn fixture(name: &str) -> Machine {
    let path = format!(
        "{}/../../fixtures/machines/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    Machine::from_file(&path).unwrap()
}

const PLUNGE_BLOCKS: usize = 8;
const SWEEP_BLOCKS: usize = 90;

/// C (deg) of the sweep at `s ∈ [0, 1]`: a steady 50° turn with a local swing of amplitude
/// 12° about s = 0.6 that runs C backwards (two reverse motions).
fn sweep_c_deg(s: f64) -> f64 {
    let u = (s - 0.6) / 0.05;
    50.0 * s - 12.0 * u * (-u * u).exp()
}

/// A rapid above the part, a plunge of `PLUNGE_BLOCKS` feed blocks from z = 60 to z = 5 with
/// A = −20°, C = 0 held, then a sweep of `SWEEP_BLOCKS` blocks along a 60 mm curve with A
/// tilting from −20° to −30° and C following [`sweep_c_deg`].
fn plunge_and_swing(m: &Machine) -> Vec<Move> {
    let axis = |a: f64, c: f64| m.tool_axis(a.to_radians(), c.to_radians()).into_inner();
    let cl = |tip: Point3, a: f64, c: f64| CutterLocation::new(tip, axis(a, c)).unwrap();
    let mut moves = vec![Move::rapid(cl(Point3::new(-30.0, 0.0, 70.0), -20.0, 0.0))];
    for i in 0..PLUNGE_BLOCKS {
        let z = 60.0 - 55.0 * i as f64 / (PLUNGE_BLOCKS - 1) as f64;
        let mut mv = Move::feed(cl(Point3::new(-30.0, 0.0, z), -20.0, 0.0));
        mv.feed_mm_per_min = Some(300.0);
        moves.push(mv);
    }
    for i in 1..=SWEEP_BLOCKS {
        let s = i as f64 / SWEEP_BLOCKS as f64;
        let tip = Point3::new(-30.0 + 60.0 * s, 10.0 * (3.0 * s).sin(), 5.0 + 3.0 * s);
        let mut mv = Move::feed(cl(tip, -20.0 - 10.0 * s, sweep_c_deg(s)));
        mv.feed_mm_per_min = Some(800.0);
        moves.push(mv);
    }
    moves
}

/// Normalised cumulative tip path length of a run of tips.
fn path_parameters(tips: &[Point3]) -> Vec<f64> {
    let mut t = vec![0.0];
    for w in tips.windows(2) {
        t.push(t.last().unwrap() + (w[1] - w[0]).norm());
    }
    let total = *t.last().unwrap();
    t.iter().map(|v| v / total).collect()
}

#[test]
fn plunge_then_swing_needs_more_than_four_control_points_and_leaves_no_reversal() {
    let m = fixture("xyzac-trt");
    let moves = plunge_and_swing(&m);
    let plain = post_path(&m, &moves, &PostOptions::default()).unwrap();
    let opts = ReverseMotionOptions::default();

    // The run as the removal sees it: the rapid's end point and every feed block.
    let run: Vec<_> = plain.blocks.iter().filter(|b| !b.inserted).collect();
    assert_eq!(run.len(), 1 + PLUNGE_BLOCKS + SWEEP_BLOCKS);
    let c: Vec<f64> = run.iter().map(|b| b.joints.get(AxisId::Rotate)).collect();
    let tips: Vec<Point3> = run.iter().map(|b| b.cl.tip).collect();
    let t = path_parameters(&tips);
    assert_eq!(count_reverse_motions(&c, REVERSE_DEAD_BAND_RAD), 2);

    // The paper's fixed four control values: no monotone result within the 10° limit.
    let (fixed, _, _) = smooth_monotone(&t, &c, &opts).unwrap();
    let fixed_change = c
        .iter()
        .zip(&fixed)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        count_reverse_motions(&fixed, REVERSE_DEAD_BAND_RAD) > 0
            || fixed_change > opts.max_angle_change,
        "four control values already suffice ({:.2}°): the test lost its point",
        fixed_change.to_degrees()
    );

    // The adaptive rule refits with more control values and accepts a monotone fit.
    let fit = smooth_monotone_adaptive(&t, &c, &opts).unwrap();
    assert!(fit.accepted, "{fit:?}");
    assert!(fit.control_points > opts.control_points);
    assert!(fit.control_points <= adaptive_control_cap(c.len(), opts.control_points));
    assert!(fit.fits >= 2);
    assert_eq!(count_reverse_motions(&fit.angles, REVERSE_DEAD_BAND_RAD), 0);
    assert!(fit.max_change <= opts.max_angle_change);

    // Smoothing only a window around the reversals: the plunge and the blocks far from the
    // swing keep their exact angles, the window joins them without a reversal.
    let win = smooth_monotone_windowed(&t, &c, &opts).unwrap();
    assert!(win.accepted, "{win:?}");
    assert_eq!(win.windows.len(), 1, "{:?}", win.windows);
    let (wa, wb) = win.windows[0];
    assert!(wa > PLUNGE_BLOCKS && wb < c.len() - 10, "{:?}", win.windows);
    assert_eq!(count_reverse_motions(&win.angles, REVERSE_DEAD_BAND_RAD), 0);
    assert!(win.max_change <= opts.max_angle_change && win.max_change > 1f64.to_radians());
    for (i, (a, b)) in c.iter().zip(&win.angles).enumerate() {
        if i < wa || i > wb {
            assert_eq!(a, b, "block {i} outside the window changed");
        }
    }

    // End to end through post-processing with a checker that accepts every posture.
    let all_ok = |_: &CutterLocation| true;
    let checker: &dyn AccessibilityChecker = &all_ok;
    let post_opts = PostOptions {
        reverse_motion: Some(opts),
        ..Default::default()
    };
    let posted = post_path_checked(&m, &moves, &post_opts, Some(checker)).unwrap();
    let rep = posted.reverse_motion.as_ref().unwrap();
    assert_eq!(rep.rotate_before, 2, "{rep:?}");
    assert_eq!((rep.rotate_after, rep.tilt_after), (0, 0), "{rep:?}");
    assert_eq!((rep.runs_changed, rep.runs_kept), (1, 0), "{rep:?}");
    assert_eq!(rep.windowed, 1, "{rep:?}");
    assert_eq!(rep.control_points_used, vec![win.control_points]);
    assert!((rep.max_angle_change_deg - win.max_change.to_degrees()).abs() < 1e-9);
    // the run's blocks outside the window keep their exact joints (X Y Z included)
    let kept: Vec<_> = posted.blocks.iter().filter(|b| !b.inserted).collect();
    assert_eq!(kept.len(), run.len());
    for (i, (p, o)) in kept.iter().zip(&run).enumerate() {
        if i < wa || i > wb {
            assert_eq!(p.joints, o.joints, "block {i}");
        }
    }
    assert!(rep.max_angle_change_deg > 1.0 && rep.max_angle_change_deg <= 10.0 + 1e-9);
    assert_eq!(posted.metrics.reverse_motions_after, 0);
    // every angle moved by at most the limit, tips kept, joints reach the smoothed CLs
    for b in posted.blocks.iter().filter(|b| !b.inserted) {
        let src = &plain
            .blocks
            .iter()
            .find(|p| !p.inserted && p.source_index == b.source_index)
            .unwrap();
        for axis in [AxisId::Tilt, AxisId::Rotate] {
            let d = (b.joints.get(axis) - src.joints.get(axis)).abs();
            assert!(
                d <= opts.max_angle_change + 1e-12,
                "block {}",
                b.source_index
            );
        }
        assert!((b.cl.tip - moves[b.source_index].cl.tip).norm() < 1e-12);
        let f = m.forward(&b.joints, 0.0);
        assert!((f.tip - b.cl.tip).norm() < 1e-9);
        assert!((f.axis.into_inner() - b.cl.axis.into_inner()).norm() < 1e-9);
    }
    // C along the posted run (inserted linearisation blocks included) never turns back.
    let cs: Vec<f64> = posted
        .blocks
        .iter()
        .skip(1)
        .map(|b| b.joints.get(AxisId::Rotate))
        .collect();
    assert!(cs.windows(2).all(|w| w[1] >= w[0] - 1e-6), "C not monotone");
}

#[test]
fn adaptive_fit_keeps_the_papers_four_control_points_when_they_suffice() {
    // A gentle swing on a steady turn (paper 004 fig. 12): four control values are enough,
    // so no refit happens and the result equals the fixed-count smoothing.
    let t: Vec<f64> = (0..100).map(|i| i as f64 / 99.0).collect();
    let a: Vec<f64> = t
        .iter()
        .map(|&x| x - 0.15 * (-((x - 0.5) / 0.05f64).powi(2)).exp() * (x - 0.5) / 0.05)
        .collect();
    let opts = ReverseMotionOptions::default();
    let fit = smooth_monotone_adaptive(&t, &a, &opts).unwrap();
    assert!(fit.accepted);
    assert_eq!((fit.control_points, fit.fits), (4, 1));
    let (fixed, _, _) = smooth_monotone(&t, &a, &opts).unwrap();
    assert_eq!(fit.angles, fixed);
}

#[test]
fn adaptive_fit_gives_up_at_the_cap_when_the_limit_is_too_tight() {
    // A 0.01° limit cannot absorb a swing of several degrees at any control-value count:
    // the rule tries n0, 2n0, … up to the cap and reports the fit as not accepted.
    let t: Vec<f64> = (0..60).map(|i| i as f64 / 59.0).collect();
    let a: Vec<f64> = t
        .iter()
        .map(|&x| x - 0.15 * (-((x - 0.5) / 0.05f64).powi(2)).exp() * (x - 0.5) / 0.05)
        .collect();
    let opts = ReverseMotionOptions {
        max_angle_change: 0.01f64.to_radians(),
        ..Default::default()
    };
    let fit = smooth_monotone_adaptive(&t, &a, &opts).unwrap();
    assert!(!fit.accepted);
    assert!(fit.max_change > opts.max_angle_change);
    // 4, 8, 16, 30 (= 60 / 2)
    assert_eq!(adaptive_control_cap(60, 4), 30);
    assert_eq!(fit.fits, 4);
}

#[test]
fn reversal_windows_cover_the_range_that_must_change() {
    // rises to 5, falls back to 3, rises again past 5 at index 7
    let a = [
        0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 3.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0,
    ];
    // 4 lies above the later 3 and 3 behind the earlier 5; 5 lies above the later 3
    assert_eq!(reversal_windows(&a, 1.0, 0), vec![(4, 6)]);
    assert_eq!(reversal_windows(&a, 1.0, 2), vec![(2, 8)]);
    // padding clamps at the ends and merges neighbouring ranges
    let b = [0.0, 2.0, 1.0, 3.0, 4.0, 6.0, 5.0, 7.0];
    assert_eq!(reversal_windows(&b, 1.0, 0), vec![(1, 2), (5, 6)]);
    assert_eq!(reversal_windows(&b, 1.0, 1), vec![(0, 7)]);
    // a monotone sequence (standing still included) has no window
    assert!(reversal_windows(&[3.0, 2.0, 2.0, 1.0], -1.0, 3).is_empty());
}

mod props {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A steadily turning axis (random positive steps) with one dip back of 0.5°–4° over a
        /// few blocks: the windowed smoothing leaves no reverse motion, changes no angle by
        /// more than the dip, and keeps every block outside its windows exactly.
        #[test]
        fn windowed_smoothing_removes_a_dip_and_keeps_the_rest(
            steps in proptest::collection::vec(0.05f64..0.6, 40..120),
            at in 0.15f64..0.85,
            width in 2usize..6,
            depth_deg in 0.5f64..4.0,
            down in any::<bool>(),
        ) {
            let sign = if down { -1.0 } else { 1.0 };
            let mut a = vec![0.0];
            for s in &steps {
                a.push(a.last().unwrap() + sign * s.to_radians());
            }
            let m = a.len();
            let c = ((at * m as f64) as usize).clamp(1, m - width - 1);
            let depth = depth_deg.to_radians();
            let peak = a[c];
            for (k, v) in a[c + 1..=c + width].iter_mut().enumerate() {
                // fall back to `peak - depth` and climb back over `width` blocks
                let f = 1.0 - (k as f64 + 1.0) / (width as f64 + 1.0);
                *v = peak - sign * depth * f;
            }
            prop_assume!(count_reverse_motions(&a, REVERSE_DEAD_BAND_RAD) >= 1);
            let t: Vec<f64> = (0..m).map(|i| i as f64 / (m - 1) as f64).collect();
            let opts = ReverseMotionOptions::default();
            let win = smooth_monotone_windowed(&t, &a, &opts).unwrap();
            prop_assert!(win.accepted, "{:?}", win.windows);
            prop_assert_eq!(count_reverse_motions(&win.angles, REVERSE_DEAD_BAND_RAD), 0);
            // the contract; and, since a window's ends are kept and its smoothed angles move
            // one way between them, no change exceeds the window's own net turn
            prop_assert!(win.max_change <= opts.max_angle_change);
            let turn = win
                .windows
                .iter()
                .map(|&(s, e)| (a[e] - a[s]).abs())
                .fold(0.0, f64::max);
            prop_assert!(win.max_change <= turn + 1e-12, "{} > {}", win.max_change, turn);
            for (i, (x, y)) in a.iter().zip(&win.angles).enumerate() {
                if win.windows.iter().all(|&(s, e)| i < s || i > e) {
                    prop_assert_eq!(x, y, "block {}", i);
                }
            }
        }
    }
}

/// Smoothing keeps the cutting contact: with a ball end the changed postures turn about the
/// ball centre (the ball surface turns onto itself: no contact movement), and a flank
/// contact line that would move beyond the bound keeps its run unchanged.
#[test]
fn smoothing_turns_a_ball_end_about_its_centre_and_bounds_flank_contact() {
    let m = fixture("xyzac-trt");
    let moves = plunge_and_swing(&m);
    let r = 3.0;
    let ball = cam_core::Cutter::new(
        "b6",
        cam_core::CutterShape::BallEnd { radius: r },
        20.0,
        r,
        50.0,
    )
    .unwrap();
    let opts = ReverseMotionOptions::keeping_contact(&ball, None);
    assert_eq!(opts.pivot_height_mm, r);
    let all_ok = |_: &CutterLocation| true;
    let checker: &dyn AccessibilityChecker = &all_ok;
    let post_opts = PostOptions {
        reverse_motion: Some(opts),
        ..Default::default()
    };
    let posted = post_path_checked(&m, &moves, &post_opts, Some(checker)).unwrap();
    let rep = posted.reverse_motion.as_ref().unwrap();
    assert_eq!(rep.runs_changed, 1, "{rep:?}");
    assert_eq!(rep.max_contact_shift_mm, 0.0);
    let mut turned = 0;
    for b in posted.blocks.iter().filter(|b| !b.inserted) {
        let src = moves[b.source_index].cl;
        let centre = src.tip + src.axis.into_inner() * r;
        let now = b.cl.tip + b.cl.axis.into_inner() * r;
        // The ball centre stays (the old smoothing kept the tip and moved the centre by
        // r·Δθ).
        assert!((now - centre).norm() < 1e-9, "block {}", b.source_index);
        if (b.cl.axis.into_inner() - src.axis.into_inner()).norm() > 1e-6 {
            turned += 1;
            assert!((b.cl.tip - src.tip).norm() > 1e-4);
        }
        let f = m.forward(&b.joints, 0.0);
        assert!((f.tip - b.cl.tip).norm() < 1e-9);
    }
    assert!(turned > 0);

    // Flank contact along 0..20 mm turning about its middle: a few degrees move the ends of
    // the contact line by far more than 0.01 mm, so the run keeps its postures.
    let flank = ReverseMotionOptions::keeping_contact(&ball, Some((0.0, 20.0)));
    assert_eq!(flank.pivot_height_mm, 10.0);
    let post_opts = PostOptions {
        reverse_motion: Some(flank),
        ..Default::default()
    };
    let posted = post_path_checked(&m, &moves, &post_opts, Some(checker)).unwrap();
    let rep = posted.reverse_motion.as_ref().unwrap();
    assert_eq!((rep.runs_changed, rep.runs_kept), (0, 1), "{rep:?}");
    assert_eq!(rep.runs_kept_for_contact, 1, "{rep:?}");
    assert_eq!(rep.rotate_after, rep.rotate_before);

    // A flat end Ø6 in bottom contact turns about its tip: its rim moves 3 mm·δ, so the
    // degrees this swing needs keep the run too; the bound itself is √(Δh² + ρ²)·δ.
    let flat = cam_core::Cutter::new(
        "f6",
        cam_core::CutterShape::FlatEnd { radius: r },
        20.0,
        r,
        50.0,
    )
    .unwrap();
    let bottom = ReverseMotionOptions::keeping_contact(&flat, None);
    assert_eq!(bottom.pivot_height_mm, 0.0);
    assert!((bottom.contact_shift(0.01) - 0.03).abs() < 1e-12);
    assert!((flank.contact_shift(0.01) - 0.1).abs() < 1e-12);
    let post_opts = PostOptions {
        reverse_motion: Some(bottom),
        ..Default::default()
    };
    let posted = post_path_checked(&m, &moves, &post_opts, Some(checker)).unwrap();
    let rep = posted.reverse_motion.as_ref().unwrap();
    assert_eq!(rep.runs_kept_for_contact, 1, "{rep:?}");
}
