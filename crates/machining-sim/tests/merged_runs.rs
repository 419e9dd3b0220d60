//! Runs of short feed blocks sampled as a whole ([`machining_sim::merge`]) against
//! block-by-block sampling of the same path and against the exact swept volume: far fewer
//! positions, never more material removed than the path sweeps, never more than the sweep
//! tolerance left, and a planted dip of one block still cut.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::path::point_segment_distance;
use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath, Vector3};
use machining_sim::{cut, BoxStock, CutOutcome, SimOptions, TriDexel};

const CELL: f64 = 0.1;

/// A five-axis pass across a box, 30 mm long in 0.05 mm blocks, the axis tilting slowly and
/// the tip on a gentle arc 0.5 mm below the top; `dip` lowers the end of block 300 (mm).
fn pass(dip: f64) -> ToolPath {
    let mut path = ToolPath::new("pass", "b2");
    for k in 0..=600 {
        let t = k as f64 / 600.0;
        let x = -15.0 + 30.0 * t;
        let y = 2.0 * (std::f64::consts::PI * t).sin();
        let z = -0.5 - if k == 300 { dip } else { 0.0 };
        let axis = Vector3::new(0.2 * (t - 0.5), 0.1 * t, 1.0);
        path.moves.push(Move {
            kind: MoveKind::Feed,
            cl: CutterLocation::new(Point3::new(x, y, z), axis).unwrap(),
            feed_mm_per_min: None,
        });
    }
    path
}

/// `path` of a ball end of radius 2 mm through the box `lo`–`hi` at `CELL`: the stock after
/// it and the simulation's outcome.
fn simulate(path: ToolPath, (lo, hi): ([f64; 3], [f64; 3]), merge: bool) -> (TriDexel, CutOutcome) {
    let cutter = Cutter::new("b2", CutterShape::BallEnd { radius: 2.0 }, 8.0, 2.0, 30.0).unwrap();
    let mut dexel = TriDexel::from_shape(&BoxStock::new(lo, hi).unwrap(), CELL).unwrap();
    let opts = SimOptions {
        check_collisions: false,
        merge_blocks: merge,
        ..SimOptions::default()
    };
    let out = cut(&mut dexel, None, &[(cutter, path)], &opts).unwrap();
    (dexel, out)
}

/// Removed volume and positions of `path` through a 40 × 18 × 6 mm box.
fn run(path: ToolPath, merge: bool) -> (f64, usize) {
    let stock = ([-20.0, -8.0, -6.0], [20.0, 10.0, 0.0]);
    let before = TriDexel::from_shape(&BoxStock::new(stock.0, stock.1).unwrap(), CELL)
        .unwrap()
        .volume();
    let (dexel, out) = simulate(path, stock, merge);
    (before - dexel.volume(), out.stats.positions)
}

#[test]
fn merged_runs_remove_the_same_material_with_fewer_positions() {
    let (v_blocks, n_blocks) = run(pass(0.0), false);
    let (v_runs, n_runs) = run(pass(0.0), true);
    // Every 0.05 mm block costs a position; the runs need one per ~0.3 mm.
    assert!(n_runs * 3 < n_blocks, "{n_runs} positions vs {n_blocks}");
    // The groove is 30 mm long and about 2.6 mm wide at the top: an under-read of at most
    // the sweep tolerance (cell/4) over its surface bounds the volume difference.
    let bound = 30.0 * 2.0 * 2.0 * CELL / 4.0;
    assert!(
        (v_blocks - v_runs).abs() <= bound,
        "removed {v_runs} mm³ with runs, {v_blocks} mm³ block by block"
    );
}

#[test]
fn a_dipping_block_is_not_merged_away() {
    let dip = 0.2;
    let (v0, _) = run(pass(0.0), true);
    let (v1, _) = run(pass(dip), true);
    let (w0, _) = run(pass(0.0), false);
    let (w1, _) = run(pass(dip), false);
    // The dip removes extra material block by block; the runs see (nearly) all of it.
    let extra_blocks = w1 - w0;
    let extra_runs = v1 - v0;
    assert!(extra_blocks > 0.05, "the dip removes {extra_blocks} mm³");
    assert!(
        extra_runs >= 0.8 * extra_blocks,
        "runs: {extra_runs} mm³ of the dip's {extra_blocks} mm³"
    );
}

/// A ball end with a vertical axis moving at constant height along a wiggling polyline of
/// 0.05 mm blocks: its swept floor is exactly `z_c − √(R² − d²)`, `d` the distance in the
/// plane from the ray to the polyline. Every ray of the Z grid within `R/2` of the path
/// (floor slope ≤ 30°) must lie between the exact floor (no over-read; the dexels store
/// `f32`) and the exact floor plus the sweep tolerance read along the ray
/// (`tol / cos 30°`).
fn floor_against_exact(wiggle: f64, merge: bool) -> (usize, usize) {
    let r = 2.0; // the ball of `simulate`
    let z_tip = -0.5;
    let pts: Vec<(f64, f64)> = (0..=400)
        .map(|k| {
            let x = -10.0 + 0.05 * k as f64;
            (x, wiggle * (k as f64 * 0.9).sin())
        })
        .collect();
    let mut path = ToolPath::new("wiggle", "b2");
    for &(x, y) in &pts {
        path.moves.push(Move {
            kind: MoveKind::Feed,
            cl: CutterLocation::new(Point3::new(x, y, z_tip), Vector3::z()).unwrap(),
            feed_mm_per_min: None,
        });
    }
    let (dexel, out) = simulate(path, ([-12.0, -4.0, -6.0], [12.0, 4.0, 0.0]), merge);
    let tol = out.stats.sweep_tol_mm;
    let grid = dexel.grid(2);
    let (nu, nv) = grid.size();
    let mut checked = 0;
    for i in 0..nu {
        for j in 0..nv {
            let (x, y) = grid.ray_uv(i, j);
            if !(-9.0..=9.0).contains(&x) {
                continue;
            }
            let q = Point3::new(x, y, 0.0);
            let d = pts
                .windows(2)
                .map(|w| {
                    let a = Point3::new(w[0].0, w[0].1, 0.0);
                    point_segment_distance(&q, &a, &Point3::new(w[1].0, w[1].1, 0.0))
                })
                .fold(f64::INFINITY, f64::min);
            if d > 0.5 * r {
                continue;
            }
            let exact = z_tip + r - (r * r - d * d).sqrt();
            let segs = grid.ray(i, j).as_slice();
            let top = segs.last().map_or(f64::NEG_INFINITY, |s| f64::from(s[1]));
            assert!(
                top >= exact - 1e-5,
                "({x:.2}, {y:.2}): floor {top:.5} below the swept {exact:.5} (merge {merge})"
            );
            assert!(
                top <= exact + tol / 30f64.to_radians().cos() + 1e-5,
                "({x:.2}, {y:.2}): floor {top:.5} more than the tolerance above {exact:.5} \
                 (merge {merge})"
            );
            checked += 1;
        }
    }
    (checked, out.stats.positions)
}

#[test]
fn merged_runs_stay_between_the_exact_floor_and_the_tolerance() {
    // A zigzag within the merge budget (cell/16 = 0.00625 mm: the polyline leaves its chords
    // by up to twice the amplitude), one beyond it.
    for wiggle in [0.002, 0.05] {
        let (checked, merged) = floor_against_exact(wiggle, true);
        let (_, blocks) = floor_against_exact(wiggle, false);
        assert!(checked > 3_000);
        if wiggle < 0.003 {
            assert!(
                merged * 3 < blocks,
                "{merged} positions merged, {blocks} block by block"
            );
        } else {
            assert!(merged <= blocks);
        }
    }
}
