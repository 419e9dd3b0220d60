//! Axis optimisation on a row of plunges whose axes zig-zag (paper 000 Fig. 2): moved plunges
//! beat their predecessor's α, every moved shroud point is the first discrete point that does
//! it (one step back toward the outlet breaks the inequality), and a row whose W curve ends
//! before α can rise is reported non-monotone.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::needless_range_loop)]

use cam_core::Vector3;
use plunge_opt::axis_optimisation::{alpha_at_index, optimise_row, optimise_row_within};
use plunge_opt::conventional_axes::{Posture, PostureBuilder};
use std::path::PathBuf;

#[test]
fn zigzag_row_becomes_monotone_with_smallest_moves() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/impeller-plunge-400");
    let imp = impeller_model::load(root.join("impeller.toml")).unwrap();
    let stock = imp.stock().clone();
    let builder = PostureBuilder::new(&imp, &stock, 15.0, 0.0, 0.5, 2.0, "test");
    let hub = imp.hub();
    let shroud = imp.shroud();
    // Six plunges from m = 0.95 toward the inlet, 0.3 % apart, on the meridian φ = 0; the
    // shroud points lie 10 % of the meridian toward the inlet, alternately 1 % less and more, so the axes lean back and
    // forth along the flow (the conventional α alone rises steadily on this hub).
    let row: Vec<Posture> = (0..6)
        .map(|i| {
            let m = 0.95 - 0.003 * i as f64;
            let th = hub.meridional().param_at_fraction(m);
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let ts = shroud.meridional().param_at_fraction(m - 0.1 + 0.01 * sign);
            let centre: Vector3 = hub.point(th, 0.0);
            let w: Vector3 = shroud.point(ts, 0.0);
            builder.through(m, 0.5, centre, w, None).unwrap()
        })
        .collect();
    let before: Vec<f64> = row.iter().map(|p| p.alpha).collect();
    assert!(
        before.windows(2).any(|w| w[1] <= w[0]),
        "the conventional row must not already be monotone: {before:?}"
    );
    let opt = optimise_row(&builder, &row, 1e-5, "test").unwrap();
    // The row flag says exactly whether α increases strictly along the row.
    assert_eq!(
        opt.monotone,
        opt.alpha_after.windows(2).all(|w| w[1] > w[0])
    );
    // Every moved plunge now beats its predecessor; an unmoved one either already did, or
    // the W curve ended first (then the row is flagged and the plunge keeps its axis).
    for i in 1..row.len() {
        match opt.moves[i] {
            Some(_) => assert!(opt.alpha_after[i] > opt.alpha_after[i - 1]),
            None if opt.alpha_after[i] > opt.alpha_after[i - 1] => {}
            None => assert!(!opt.monotone),
        }
    }
    // On this row the first four plunges are made monotone (the dip at plunge 2 is lifted
    // by moving W₂ and W₃ toward the inlet); plunge 4 needs a W beyond the curve's inlet end.
    for w in opt.alpha_after[..4].windows(2) {
        assert!(w[1] > w[0], "α not increasing: {:?}", opt.alpha_after);
    }
    // The first plunge keeps its axis; plunges already above their predecessor keep theirs.
    assert_eq!(opt.postures[0].cl, row[0].cl);
    let mut moved = 0;
    for i in 1..row.len() {
        match opt.moves[i] {
            Some((k, k0)) => {
                moved += 1;
                assert!(k >= k0);
                if k > k0 {
                    let back = alpha_at_index(&builder, &opt, i, k - 1).unwrap();
                    assert!(
                        back <= opt.alpha_after[i - 1],
                        "plunge {i}: one step back ({back}) still beats α{} = {}",
                        i - 1,
                        opt.alpha_after[i - 1]
                    );
                }
                // The moved axis still passes through the plunge's centre point.
                let p = &opt.postures[i];
                let a = p.cl.axis.into_inner();
                let d = (p.centre - p.cl.tip.coords) - a * (p.centre - p.cl.tip.coords).dot(&a);
                assert!(d.norm() < 1e-9);
            }
            None => assert_eq!(opt.postures[i].cl, row[i].cl),
        }
    }
    assert!(moved > 0);

    // With a blade-allowance check that refuses every moved posture, each plunge that would
    // move keeps its conventional axis and is counted; one that refuses only the second
    // moved plunge keeps the first move.
    let none = optimise_row_within(&builder, &row, 1e-5, "test", &|_, _, _| false).unwrap();
    assert_eq!(none.kept_for_clearance, moved);
    assert!(none.moves.iter().all(Option::is_none));
    for i in 0..row.len() {
        assert_eq!(none.postures[i].cl, row[i].cl);
    }
    assert!(!none.monotone);
    let first = opt.moves.iter().position(Option::is_some).unwrap();
    let keep_first =
        optimise_row_within(&builder, &row, 1e-5, "test", &|p, _, _| p.m == row[first].m).unwrap();
    assert_eq!(keep_first.postures[first].cl, opt.postures[first].cl);
    assert!(keep_first.kept_for_clearance >= 1);
}
