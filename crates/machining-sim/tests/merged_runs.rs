//! Runs of short feed blocks sampled as a whole ([`machining_sim::merge`]) against
//! block-by-block sampling of the same path: far fewer positions, the same removed volume
//! within what the sweep tolerance allows, and a planted dip of one block still cut.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath, Vector3};
use machining_sim::{cut, BoxStock, SimOptions, TriDexel};

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

fn run(path: ToolPath, merge: bool) -> (f64, usize) {
    let cutter = Cutter::new("b2", CutterShape::BallEnd { radius: 2.0 }, 8.0, 2.0, 30.0).unwrap();
    let stock = BoxStock::new([-20.0, -8.0, -6.0], [20.0, 10.0, 0.0]).unwrap();
    let mut dexel = TriDexel::from_shape(&stock, CELL).unwrap();
    let before = dexel.volume();
    let opts = SimOptions {
        check_collisions: false,
        merge_blocks: merge,
        ..SimOptions::default()
    };
    let out = cut(&mut dexel, None, &[(cutter, path)], &opts).unwrap();
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
