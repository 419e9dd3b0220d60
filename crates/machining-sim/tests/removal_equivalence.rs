//! The culled, row-parallel removal ([`apply_batch`]) against the sequential, unculled
//! reference ([`apply_batch_reference`]) on a few hundred five-axis placements: every ray's
//! intervals must be bit-identical, the stock contacts identical (as sets), and the removed
//! volumes equal up to the order of the floating-point sum (relative 10⁻¹²).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Cutter, CutterShape, HolderSegment, MoveKind, Point3, UnitVector3, Vector3};
use machining_sim::removal::{apply_batch, apply_batch_reference, Placement, StockHit, ToolBody};
use machining_sim::synthetic::{workload_cutter, zigzag_path};
use machining_sim::{BoxStock, RevolvedStock, StockShape, TriDexel};

fn placements(radius: f64, top: f64) -> Vec<Placement> {
    let path = zigzag_path(420, radius, top);
    let mut out: Vec<Placement> = path
        .moves
        .iter()
        .map(|m| Placement {
            tip: [m.cl.tip.x, m.cl.tip.y, m.cl.tip.z],
            axis: [m.cl.axis.x, m.cl.axis.y, m.cl.axis.z],
            tool: 0,
            rapid: m.kind == MoveKind::Rapid,
        })
        .collect();
    // Plunges deep enough for the shank (r 3 mm above 25 mm of flutes) and the holder to
    // touch the stock, strongly tilted, and a rapid through the material.
    for k in 0..40 {
        let t = k as f64 / 40.0;
        let a = UnitVector3::new_normalize(Vector3::new(
            0.8 * (6.0 * t).cos(),
            0.8 * (6.0 * t).sin(),
            1.0,
        ));
        let tip = Point3::new(
            radius * 0.5 * (6.0 * t).cos(),
            radius * 0.5 * (6.0 * t).sin(),
            top - 28.0 + 4.0 * t,
        );
        out.push(Placement {
            tip: [tip.x, tip.y, tip.z],
            axis: [a.x, a.y, a.z],
            tool: 0,
            rapid: k % 13 == 12,
        });
    }
    // Axes along each coordinate (degenerate projected bands) and an antiparallel one.
    for axis in [
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ] {
        out.push(Placement {
            tip: [1.0, 2.0, top - 3.0],
            axis,
            tool: 0,
            rapid: false,
        });
    }
    out
}

fn key(h: &StockHit) -> (usize, u8, u64, [u64; 3]) {
    let part = h.part as u8;
    (
        h.placement,
        part,
        h.depth.to_bits(),
        h.point.map(f64::to_bits),
    )
}

fn assert_same_stock(a: &TriDexel, b: &TriDexel) {
    for d in 0..3 {
        let (ga, gb) = (a.grid(d), b.grid(d));
        let (nu, nv) = ga.size();
        assert_eq!((nu, nv), gb.size());
        for j in 0..nv {
            for i in 0..nu {
                let (sa, sb) = (ga.ray(i, j).as_slice(), gb.ray(i, j).as_slice());
                let bits = |s: &[[f32; 2]]| -> Vec<[u32; 2]> {
                    s.iter().map(|p| [p[0].to_bits(), p[1].to_bits()]).collect()
                };
                assert_eq!(bits(sa), bits(sb), "grid {d} ray ({i}, {j})");
            }
        }
    }
}

fn check(cutter: &Cutter, shape: &dyn StockShape, cell: f64, radius: f64, top: f64, batch: usize) {
    let stock0 = TriDexel::from_shape(shape, cell).unwrap();
    let bodies = vec![ToolBody::new(cutter)];
    let pls = placements(radius, top);
    assert!(pls.len() >= 400);
    let (mut fast, mut slow) = (stock0.clone(), stock0.clone());
    let (mut hits_fast, mut hits_slow) = (Vec::new(), Vec::new());
    let (mut vol_fast, mut vol_slow) = (0.0, 0.0);
    for (b, chunk) in pls.chunks(batch).enumerate() {
        let f = apply_batch(&mut fast, &bodies, chunk, true, 0.01);
        let s = apply_batch_reference(&mut slow, &bodies, chunk, true, 0.01);
        vol_fast += f.removed_volume;
        vol_slow += s.removed_volume;
        hits_fast.extend(f.hits.iter().map(|h| (b, key(h))));
        hits_slow.extend(s.hits.iter().map(|h| (b, key(h))));
    }
    assert_same_stock(&fast, &slow);
    hits_fast.sort_unstable();
    hits_slow.sort_unstable();
    assert!(
        !hits_slow.is_empty(),
        "the case must exercise stock contacts"
    );
    assert_eq!(hits_fast, hits_slow);
    assert!(vol_slow > 1.0, "the case must remove material: {vol_slow}");
    assert!(
        (vol_fast - vol_slow).abs() <= 1e-12 * vol_slow,
        "{vol_fast} vs {vol_slow}"
    );
    // The stock really changed, and both agree with its volume.
    assert!(stock0.volume() - fast.volume() > 1.0);
}

/// A Ø28 × 12 mm blank with a conical shoulder.
fn revolved_blank() -> RevolvedStock {
    RevolvedStock::new(vec![
        (0.0, 0.0),
        (0.0, 12.0),
        (8.0, 12.0),
        (14.0, 6.0),
        (14.0, 0.0),
    ])
    .unwrap()
}

#[test]
fn culled_parallel_removal_is_bit_identical_on_a_revolved_blank() {
    let blank = revolved_blank();
    check(&workload_cutter(), &blank, 0.2, 10.0, 14.0, 37);
}

#[test]
fn culled_parallel_removal_is_bit_identical_on_a_block() {
    let block = BoxStock::new([-10.0, -10.0, 0.0], [10.0, 10.0, 30.0]).unwrap();
    check(&workload_cutter(), &block, 0.25, 9.0, 30.0, 4096);
}

/// The same on every cutting profile (the per-ray skips rest on the convexity of the
/// cutting part: flat end, ball end, bull nose with its torus, tapered flat end), the
/// placements revisiting the same rays many times in one batch.
#[test]
fn culled_parallel_removal_is_bit_identical_for_every_cutting_profile() {
    let blank = revolved_blank();
    for shape in [
        CutterShape::FlatEnd { radius: 2.0 },
        CutterShape::BallEnd { radius: 2.0 },
        CutterShape::BullNose {
            radius: 2.0,
            corner_radius: 0.6,
        },
        CutterShape::TaperedFlatEnd {
            tip_radius: 0.8,
            half_angle: 4f64.to_radians(),
        },
    ] {
        let mut cutter = Cutter::new("t", shape, 25.0, 3.0, 50.0).unwrap();
        cutter.holder = vec![HolderSegment {
            bottom_radius: 20.0,
            top_radius: 20.0,
            length: 40.0,
        }];
        check(&cutter, &blank, 0.2, 10.0, 14.0, 211);
    }
}
