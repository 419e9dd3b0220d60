//! `simulate_residual` (what rest machining plans from) leaves the stock and reads the
//! residual exactly as the full verification `simulate` does on the same paths.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath, Vector3};
use machining_sim::{simulate, simulate_residual, BoxDesign, BoxStock, SimOptions, TriDexel};

fn at(x: f64, y: f64, z: f64, axis: Vector3) -> CutterLocation {
    CutterLocation::new(Point3::new(x, y, z), axis).unwrap()
}

/// A plate x ∈ [−1, 1] with stock on its +x side up to x = 5; a Ø4 ball end passes down the
/// face in three tilted, stepped passes (scallops and a strip left above the face) with a dip
/// of 0.3 mm into the plate on the middle pass (an overcut the full verification reads).
fn case() -> (BoxDesign, BoxStock, Vec<(Cutter, ToolPath)>) {
    let design = BoxDesign {
        min: [-1.0, -10.0, 0.0],
        max: [1.0, 10.0, 15.0],
        sample_spacing: 0.25,
    };
    let block = BoxStock::new([-1.0, -10.0, 0.0], [5.0, 10.0, 15.0]).unwrap();
    let r = 2.0;
    let cutter = Cutter::new("b4", CutterShape::BallEnd { radius: r }, 20.0, r, 40.0).unwrap();
    let axis = Vector3::new(0.3, 0.0, 1.0).normalize();
    let mut p = ToolPath::new("op", "t");
    let mut push = |kind, cl| {
        p.moves.push(Move {
            kind,
            cl,
            feed_mm_per_min: None,
        })
    };
    // Ball centre 1 + r (+ 0.05 on the first pass, leaving a strip) from the plate's centre.
    for (k, z) in [12.0, 9.5, 7.0].into_iter().enumerate() {
        let x = 1.0 + if k == 0 { 0.05 } else { 0.0 };
        let tip = |y: f64, dx: f64| at(x + dx + r * axis.x, y, z - r + r * axis.z, axis);
        push(MoveKind::Rapid, tip(-13.0, 0.0));
        push(MoveKind::Feed, tip(1.0, 0.0));
        let dip = if k == 1 { -0.3 } else { 0.0 };
        push(MoveKind::Feed, tip(2.0, dip));
        push(MoveKind::Feed, tip(3.0, 0.0));
        push(MoveKind::Feed, tip(13.0, 0.0));
    }
    (design, block, vec![(cutter, p)])
}

#[test]
fn residual_only_simulation_is_the_full_ones_stock_and_residual() {
    let (design, block, ops) = case();
    let h = 0.2;
    let mut full = TriDexel::from_shape(&block, h).unwrap();
    let rep = simulate(&mut full, &design, &ops, &SimOptions::default()).unwrap();
    let mut rest = TriDexel::from_shape(&block, h).unwrap();
    let maps = simulate_residual(&mut rest, &design, &ops, &SimOptions::default()).unwrap();
    // The case means something: the full verification reads the dip and a residual.
    assert!(
        rep.metrics.max_overcut_mm > 0.2,
        "{:?}",
        rep.metrics.max_overcut_mm
    );
    let residual_on_face = rep
        .maps
        .iter()
        .find(|m| m.name == "x_max")
        .unwrap()
        .residual_mm
        .iter()
        .flatten()
        .fold(0.0f64, |m, r| m.max(*r));
    assert!(residual_on_face > 0.04, "{residual_on_face}");
    // The same stock, ray by ray.
    for d in 0..3 {
        let (a, b) = (full.grid(d), rest.grid(d));
        let (nu, nv) = a.size();
        assert_eq!((nu, nv), b.size());
        for j in 0..nv {
            for i in 0..nu {
                assert_eq!(
                    a.ray(i, j).as_slice(),
                    b.ray(i, j).as_slice(),
                    "{d} {i} {j}"
                );
            }
        }
    }
    // The same residual, bit for bit, and no overcut read.
    assert_eq!(maps.len(), rep.maps.len());
    for (m, f) in maps.iter().zip(&rep.maps) {
        assert_eq!(
            (&m.name, m.nu, m.nv, &m.points),
            (&f.name, f.nu, f.nv, &f.points)
        );
        assert_eq!(m.residual_mm.len(), f.residual_mm.len());
        for (a, b) in m.residual_mm.iter().zip(&f.residual_mm) {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{}", m.name);
        }
        assert!(m.overcut_mm.iter().all(Option::is_none));
    }
}

#[test]
fn residual_only_simulation_refuses_a_bad_probe_depth() {
    let (design, block, ops) = case();
    let mut stock = TriDexel::from_shape(&block, 0.5).unwrap();
    let options = SimOptions {
        probe_depth_mm: f64::NAN,
        ..SimOptions::default()
    };
    let e = simulate_residual(&mut stock, &design, &ops, &options).unwrap_err();
    assert!(e.to_string().contains("probe_depth_mm"), "{e}");
}
