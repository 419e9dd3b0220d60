//! Exact cases: plunge of a flat end (volume, floor), ball-end groove profile, a deliberate
//! gouge into a blade-like plate, the resolution study and collisions.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{
    Cutter, CutterLocation, CutterShape, HolderSegment, Move, MoveKind, Point3, ToolPath,
};
use machining_sim::{
    cut, simulate, BoxDesign, BoxStock, CollisionTarget, DesignModel, PartKind, SimOptions,
    TriDexel,
};

fn vertical(x: f64, y: f64, z: f64) -> CutterLocation {
    CutterLocation::vertical(Point3::new(x, y, z))
}

fn path(moves: Vec<(MoveKind, CutterLocation)>) -> ToolPath {
    let mut p = ToolPath::new("op", "t");
    p.moves = moves
        .into_iter()
        .map(|(kind, cl)| Move {
            kind,
            cl,
            feed_mm_per_min: None,
        })
        .collect();
    p
}

#[test]
fn flat_end_plunge_removes_exact_cylinder() {
    let h = 0.2;
    let block = BoxStock::new([0.0, 0.0, 0.0], [20.0, 20.0, 10.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let v0 = stock.volume();
    assert!((v0 - 4000.0).abs() < 1e-6 * 4000.0 + 1e-3, "{v0}");
    let r = 3.0;
    let cutter = Cutter::new("f6", CutterShape::FlatEnd { radius: r }, 20.0, r, 40.0).unwrap();
    let p = path(vec![
        (MoveKind::Rapid, vertical(10.0, 10.0, 15.0)),
        (MoveKind::Plunge, vertical(10.0, 10.0, 6.0)),
        (MoveKind::Retract, vertical(10.0, 10.0, 15.0)),
    ]);
    let out = cut(&mut stock, None, &[(cutter, p)], &SimOptions::default()).unwrap();
    let exact = std::f64::consts::PI * r * r * 4.0;
    // Volume error bounded by one cell over the cut's boundary (wall + floor).
    let bound = (2.0 * std::f64::consts::PI * r * 4.0 + std::f64::consts::PI * r * r) * h;
    let removed = v0 - stock.volume();
    assert!(
        (removed - exact).abs() < bound,
        "removed {removed} vs {exact} (bound {bound})"
    );
    assert!((out.stats.removed_volume_mm3 - exact).abs() < bound);
    // Floor: every Z ray well inside the cutter ends at z = 6, every ray well outside at 10.
    let g = stock.grid(2);
    let (nu, nv) = g.size();
    let mut inside = 0;
    for j in 0..nv {
        for i in 0..nu {
            let (x, y) = g.ray_uv(i, j);
            let rho = ((x - 10.0).powi(2) + (y - 10.0).powi(2)).sqrt();
            let segs = g.ray(i, j).as_slice();
            if !(0.0..=20.0).contains(&x) || !(0.0..=20.0).contains(&y) {
                continue;
            }
            let top = f64::from(segs.last().unwrap()[1]);
            if rho < r - 1e-9 {
                inside += 1;
                assert!((top - 6.0).abs() < 1e-5, "floor {top} at ({x},{y})");
            } else if rho > r + 1e-9 {
                assert!((top - 10.0).abs() < 1e-5, "top {top} at ({x},{y})");
            }
        }
    }
    assert!(inside > 600, "{inside} rays under the cutter");
    // The plunge of a cylinder whose shank equals its radius does not collide.
    assert!(out.collisions.is_empty(), "{:?}", out.collisions);
}

#[test]
fn ball_end_groove_has_circular_profile() {
    let h = 0.1;
    let block = BoxStock::new([0.0, 0.0, 0.0], [20.0, 8.0, 5.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let r = 2.0;
    let cutter = Cutter::new("b4", CutterShape::BallEnd { radius: r }, 10.0, r, 30.0).unwrap();
    let depth = 1.2;
    let zt = 5.0 - depth;
    let p = path(vec![
        (MoveKind::Rapid, vertical(-3.0, 4.0, zt)),
        (MoveKind::Feed, vertical(23.0, 4.0, zt)),
    ]);
    let opts = SimOptions::default();
    cut(&mut stock, None, &[(cutter, p)], &opts).unwrap();
    let tol = h / 4.0;
    let half_width = (r * r - (r - depth).powi(2)).sqrt();
    // Z rays across the groove at x ≈ 10: floor follows the circle z = zt + r − sqrt(r² − dy²).
    let g = stock.grid(2);
    let (nu, nv) = g.size();
    let mut checked = 0;
    for j in 0..nv {
        for i in 0..nu {
            let (x, y) = g.ray_uv(i, j);
            if (x - 10.0).abs() > 0.3 || !(0.0..=8.0).contains(&y) {
                continue;
            }
            let dy = y - 4.0;
            let want = if dy.abs() < half_width {
                zt + r - (r * r - dy * dy).sqrt()
            } else {
                5.0
            };
            let top = f64::from(g.ray(i, j).as_slice().last().unwrap()[1]);
            // Error measured along the groove normal (the sweep tolerance bounds it there).
            let cos = if dy.abs() < half_width {
                (1.0 - (dy / r).powi(2)).sqrt()
            } else {
                1.0
            };
            assert!(
                (top - want).abs() * cos <= tol + 1e-4,
                "y {y}: {top} vs {want}"
            );
            checked += 1;
        }
    }
    assert!(checked > 100);
    // Y rays (along y) at x = 10, height z: the groove gap is 2·sqrt(r² − (zt + r − z)²).
    let gy = stock.grid(1);
    let (nu, nv) = gy.size(); // u = z, v = x
    for j in 0..nv {
        for i in 0..nu {
            let (z, x) = gy.ray_uv(i, j);
            if (x - 10.0).abs() > 0.15 || !(zt + 0.3..5.0).contains(&z) {
                continue;
            }
            let segs = gy.ray(i, j).as_slice();
            assert_eq!(segs.len(), 2, "z {z}: {segs:?}");
            let gap = f64::from(segs[1][0] - segs[0][1]);
            let half = (r * r - (zt + r - z).powi(2)).sqrt();
            // Normal error ≤ tol on each wall; along y it grows by r / half (wall slope).
            let bound = 2.0 * tol * r / half + 1e-4;
            assert!(
                (gap - 2.0 * half).abs() < bound,
                "z {z}: gap {gap} vs {}",
                2.0 * half
            );
        }
    }
}

/// Plate x ∈ [−1, 1] (blade-like), stock on its +x side, flank pass with a flat end along y
/// plus a deliberate dip of `gouge` mm into the plate at y = 2.
fn plate_case(h: f64, gouge: f64) -> machining_sim::Report {
    plate_case_with_ops(h, gouge).0
}

fn plate_case_with_ops(h: f64, gouge: f64) -> (machining_sim::Report, Vec<(Cutter, ToolPath)>) {
    let design = BoxDesign {
        min: [-1.0, -10.0, 0.0],
        max: [1.0, 10.0, 15.0],
        sample_spacing: 0.25,
    };
    let block = BoxStock::new([-1.0, -10.0, 0.0], [5.0, 10.0, 15.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let r = 2.0;
    let cutter = Cutter::new("f4", CutterShape::FlatEnd { radius: r }, 20.0, r, 40.0).unwrap();
    let x = 1.0 + r;
    let z = -1.0;
    let p = path(vec![
        (MoveKind::Rapid, vertical(x, -13.0, 30.0)),
        (MoveKind::Plunge, vertical(x, -13.0, z)),
        (MoveKind::Feed, vertical(x, 1.0, z)),
        (MoveKind::Feed, vertical(x - gouge, 2.0, z)),
        (MoveKind::Feed, vertical(x, 3.0, z)),
        (MoveKind::Feed, vertical(x, 13.0, z)),
        (MoveKind::Retract, vertical(x, 13.0, 30.0)),
    ]);
    let ops = vec![(cutter, p)];
    let rep = simulate(&mut stock, &design, &ops, &SimOptions::default()).unwrap();
    (rep, ops)
}

#[test]
fn deliberate_gouge_is_found_with_depth_and_location() {
    let h = 0.2;
    let rep = plate_case(h, 0.3);
    let e = rep.max_overcut.clone().unwrap();
    assert!((e.value_mm - 0.3).abs() < h, "{e:?}");
    assert_eq!(e.surface, "x_max");
    assert!((e.point[1] - 2.0).abs() < 0.3, "{e:?}");
    assert_eq!(rep.metrics.max_overcut_mm, e.value_mm);
    // Elsewhere on the machined face no overcut and residual below a cell.
    let face = rep.maps.iter().find(|m| m.name == "x_max").unwrap();
    for (k, p) in face.points.iter().enumerate() {
        if (p[1] - 2.0).abs() > 2.5 {
            assert!(
                face.overcut_mm[k].unwrap() < h,
                "{p:?} {:?}",
                face.overcut_mm[k]
            );
            assert!(
                face.residual_mm[k].unwrap() < h,
                "{p:?} {:?}",
                face.residual_mm[k]
            );
        }
    }
    assert_eq!(rep.metrics.collisions, 0, "{:?}", rep.collisions);
}

#[test]
fn resolution_study_halving_the_cell_changes_overcut_less_than_a_cell() {
    let coarse = plate_case(0.2, 0.45).metrics.max_overcut_mm;
    let fine = plate_case(0.1, 0.45).metrics.max_overcut_mm;
    assert!((coarse - fine).abs() < 0.1, "{coarse} vs {fine}");
    assert!((fine - 0.45).abs() < 0.1, "{fine}");
}

#[test]
fn residual_of_an_unmachined_strip_is_measured() {
    // Same plate, the cutter stays 0.4 mm away from the face: residual 0.4 everywhere.
    let design = BoxDesign {
        min: [-1.0, -10.0, 0.0],
        max: [1.0, 10.0, 15.0],
        sample_spacing: 0.5,
    };
    let h = 0.1;
    let block = BoxStock::new([-1.0, -10.0, 0.0], [5.0, 10.0, 15.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let cutter = Cutter::new("f4", CutterShape::FlatEnd { radius: 2.0 }, 20.0, 2.0, 40.0).unwrap();
    let p = path(vec![
        (MoveKind::Plunge, vertical(3.4, -13.0, -1.0)),
        (MoveKind::Feed, vertical(3.4, 13.0, -1.0)),
    ]);
    let rep = simulate(&mut stock, &design, &[(cutter, p)], &SimOptions::default()).unwrap();
    assert!(
        (rep.metrics.max_residual_mm - 0.4).abs() < h,
        "{:?}",
        rep.max_residual
    );
    assert!(rep.metrics.max_overcut_mm < h);
}

#[test]
fn shank_rub_and_rapid_through_material_are_collisions() {
    let h = 0.25;
    let block = BoxStock::new([0.0, 0.0, 0.0], [20.0, 20.0, 10.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    // Flutes 5 mm long, shank radius 1.5 < cutter radius 2.
    let mut cutter =
        Cutter::new("f4", CutterShape::FlatEnd { radius: 2.0 }, 5.0, 1.5, 30.0).unwrap();
    cutter.holder.push(HolderSegment {
        bottom_radius: 10.0,
        top_radius: 10.0,
        length: 20.0,
    });
    let p = path(vec![
        (MoveKind::Rapid, vertical(-5.0, 10.0, 2.0)),
        // Side cut at depth 8: the flutes reach z = 7, the shank rubs z ∈ [7, 10].
        (MoveKind::Feed, vertical(10.0, 10.0, 2.0)),
        (MoveKind::Retract, vertical(10.0, 10.0, 40.0)),
        // Rapid back down through uncut material.
        (MoveKind::Rapid, vertical(15.0, 15.0, 5.0)),
    ]);
    let design = BoxDesign {
        min: [0.0, 0.0, 0.0],
        max: [20.0, 20.0, 1.0],
        sample_spacing: 1.0,
    };
    let rep = simulate(&mut stock, &design, &[(cutter, p)], &SimOptions::default()).unwrap();
    let shank = rep
        .collisions
        .iter()
        .find(|c| {
            c.move_index == 1 && c.part == PartKind::Shank && c.target == CollisionTarget::Stock
        })
        .unwrap_or_else(|| panic!("{:?}", rep.collisions));
    assert!(shank.depth_mm > 1.0, "{shank:?}");
    assert!(
        shank.point[2] > 7.0 - h && shank.point[2] < 10.0 + h,
        "{shank:?}"
    );
    assert!(rep.collisions.iter().any(|c| c.move_index == 3
        && c.part == PartKind::RapidMove
        && c.target == CollisionTarget::Stock));
    // The shank stays buried in the uncut band while retracting: still a collision.
    assert!(rep
        .collisions
        .iter()
        .any(|c| c.move_index == 2 && c.part == PartKind::Shank));
    assert_eq!(rep.metrics.collisions, 3);
    // The approach rapid (move 0, outside the block) is clean.
    assert!(!rep.collisions.iter().any(|c| c.move_index == 0));
}

#[test]
fn holder_hitting_the_design_is_reported_through_the_mesh() {
    let h = 0.5;
    let block = BoxStock::new([0.0, 0.0, 0.0], [10.0, 10.0, 5.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let mut cutter =
        Cutter::new("f2", CutterShape::FlatEnd { radius: 1.0 }, 5.0, 1.0, 10.0).unwrap();
    cutter.holder.push(HolderSegment {
        bottom_radius: 8.0,
        top_radius: 8.0,
        length: 20.0,
    });
    // A tall design wall next to the stock, 5 mm from the tool axis: the holder (radius 8)
    // sweeps through it while the tool cuts air above the stock.
    let design = BoxDesign {
        min: [15.0, 0.0, 0.0],
        max: [17.0, 10.0, 40.0],
        sample_spacing: 2.0,
    };
    let p = path(vec![
        (MoveKind::Feed, vertical(10.0, 5.0, 20.0)),
        (MoveKind::Feed, vertical(10.0, 6.0, 20.0)),
    ]);
    let rep = simulate(&mut stock, &design, &[(cutter, p)], &SimOptions::default()).unwrap();
    let hit = rep
        .collisions
        .iter()
        .find(|c| c.target == CollisionTarget::Design && c.part == PartKind::Holder)
        .unwrap_or_else(|| panic!("{:?}", rep.collisions));
    // Holder face at x = 18 (circumscribed polygon: ≤ 18.14) against the wall [15, 17].
    assert!(hit.depth_mm > 1.5 && hit.depth_mm < 3.5, "{hit:?}");
}

#[test]
fn dexel_overcut_agrees_with_the_swept_envelope_within_a_cell() {
    let h = 0.2;
    let (rep, ops) = plate_case_with_ops(h, 0.35);
    let checks = machining_sim::crosscheck_overcut(&rep, &ops, 60).unwrap();
    let on_face: Vec<_> = checks.iter().filter(|c| c.surface == "x_max").collect();
    assert!(on_face.len() > 10);
    for c in &on_face {
        assert!(
            (c.dexel_overcut_mm - c.envelope_overcut_mm).abs() < h,
            "{c:?}"
        );
    }
    let env_max = on_face
        .iter()
        .map(|c| c.envelope_overcut_mm)
        .fold(0.0, f64::max);
    assert!((env_max - 0.35).abs() < 1e-6, "{env_max}");
    assert!((rep.metrics.max_overcut_mm - env_max).abs() < h);
}

/// The largest reading's own location re-measured on the envelopes: the plate's x_max face
/// is gouged 0.35 mm by the flat end's side (a cylinder: the gouge floor is parallel to the
/// face), so the surface point above the cut end point lies 0.35 mm inside the envelope.
#[test]
fn the_deepest_reading_is_re_measured_at_its_own_location() {
    let h = 0.2;
    let (rep, ops) = plate_case_with_ops(h, 0.35);
    let design = BoxDesign {
        min: [-1.0, -10.0, 0.0],
        max: [1.0, 10.0, 15.0],
        sample_spacing: 0.25,
    };
    let e = rep.max_overcut.clone().unwrap();
    let c = machining_sim::crosscheck_location(&design, &ops, e.point).unwrap();
    assert!((c.surface_point[0] - 1.0).abs() < 1e-6, "{c:?}");
    assert!((c.envelope_overcut_mm - 0.35).abs() < 0.01, "{c:?}");
    assert!(
        (c.envelope_overcut_mm - c.design_depth_mm).abs() < h,
        "{c:?}"
    );
}

#[test]
fn contour_around_a_cylinder_design_finds_the_radial_gouge() {
    // Cylinder design r = 5 (z 0..8) in a box blank; a flat end (r 2) contours it at
    // radius 5 + 2 − 0.2 over a quarter turn: 0.2 mm radial overcut on the side there,
    // the rest of the side keeps its stock.
    let h = 0.1;
    let design = machining_sim::CylinderDesign {
        radius: 5.0,
        z0: 0.0,
        z1: 8.0,
        sample_spacing: 0.4,
    };
    let block = BoxStock::new([-8.0, -8.0, 0.0], [8.0, 8.0, 8.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let cutter = Cutter::new("f4", CutterShape::FlatEnd { radius: 2.0 }, 12.0, 2.0, 40.0).unwrap();
    let rc = 5.0 + 2.0 - 0.2;
    let mut moves = vec![
        (MoveKind::Rapid, vertical(rc, 0.0, 20.0)),
        (MoveKind::Plunge, vertical(rc, 0.0, -1.0)),
    ];
    for k in 1..=60 {
        let a = std::f64::consts::FRAC_PI_2 * f64::from(k) / 60.0;
        moves.push((MoveKind::Feed, vertical(rc * a.cos(), rc * a.sin(), -1.0)));
    }
    let rep = simulate(
        &mut stock,
        &design,
        &[(cutter, path(moves))],
        &SimOptions::default(),
    )
    .unwrap();
    let e = rep.max_overcut.clone().unwrap();
    assert_eq!(e.surface, "side");
    // Chords of the 60-segment polygon cut slightly deeper than the arc: ≤ rc(1 − cos(π/240)).
    assert!((e.value_mm - 0.2).abs() < h, "{e:?}");
    let ang = e.point[1].atan2(e.point[0]);
    assert!(
        (-0.05..=std::f64::consts::FRAC_PI_2 + 0.05).contains(&ang),
        "{e:?}"
    );
    // Away from the contoured quarter the side is untouched: residual = stock thickness there
    // (capped by the probe depth or the box corner).
    let side = rep.maps.iter().find(|m| m.name == "side").unwrap();
    for (k, p) in side.points.iter().enumerate() {
        let a = p[1].atan2(p[0]);
        if a < -0.6 {
            assert_eq!(side.overcut_mm[k], Some(0.0), "{p:?}");
            assert!(
                side.residual_mm[k].unwrap() > 2.5,
                "{p:?} {:?}",
                side.residual_mm[k]
            );
        }
    }
}

/// A design model whose face choice misreads the depth below the entered face by 5 mm (as a
/// model can where faces meet at a sharp edge). The overcut read at a cut end point is capped
/// by the way back to the entry point on that face, so the plate's 0.3 mm gouge still reads
/// 0.3 mm within a cell, not 5.3 mm.
#[test]
fn an_inflated_face_depth_is_capped_by_the_way_back_to_the_entry() {
    struct Inflated(BoxDesign);
    impl DesignModel for Inflated {
        fn signed_distance(&self, p: &Point3) -> f64 {
            self.0.signed_distance(p)
        }
        fn surface_grids(&self) -> Vec<machining_sim::SurfaceGrid> {
            self.0.surface_grids()
        }
        fn triangle_mesh(&self) -> machining_sim::TriangleMesh {
            self.0.triangle_mesh()
        }
        fn depth_below(&self, p: &Point3, _entry: &Point3) -> f64 {
            -self.0.signed_distance(p) + 5.0
        }
    }
    let h = 0.2;
    let design = Inflated(BoxDesign {
        min: [-1.0, -10.0, 0.0],
        max: [1.0, 10.0, 15.0],
        sample_spacing: 0.25,
    });
    let (_, ops) = plate_case_with_ops(h, 0.3);
    let block = BoxStock::new([-1.0, -10.0, 0.0], [5.0, 10.0, 15.0]).unwrap();
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let rep = simulate(&mut stock, &design, &ops, &SimOptions::default()).unwrap();
    let e = rep.max_overcut.clone().unwrap();
    assert!((e.value_mm - 0.3).abs() < h, "{e:?}");
}

/// Two plunges of a Ø6 flat end, 4 mm then 2 mm deeper at the same place, as two operations,
/// each batch of positions a few long: every operation gets the volume it removed (π r² 4 and
/// π r² 2 within one cell over the cut's boundary), the two add up to the total, and the
/// stock equals the one-operation run's with the default batches bit for bit.
#[test]
fn each_operation_gets_the_volume_it_removed() {
    let h = 0.2;
    let block = BoxStock::new([0.0, 0.0, 0.0], [20.0, 20.0, 10.0]).unwrap();
    let r = 3.0;
    let cutter = Cutter::new("f6", CutterShape::FlatEnd { radius: r }, 20.0, r, 40.0).unwrap();
    let plunge = |z: f64| {
        path(vec![
            (MoveKind::Rapid, vertical(10.0, 10.0, 15.0)),
            (MoveKind::Plunge, vertical(10.0, 10.0, z)),
            (MoveKind::Retract, vertical(10.0, 10.0, 15.0)),
        ])
    };
    let ops = [(cutter.clone(), plunge(6.0)), (cutter.clone(), plunge(4.0))];
    let mut stock = TriDexel::from_shape(&block, h).unwrap();
    let small = SimOptions {
        batch_positions: 3,
        ..SimOptions::default()
    };
    let out = cut(&mut stock, None, &ops, &small).unwrap();
    let by_op = &out.stats.removed_volume_by_operation_mm3;
    assert_eq!(by_op.len(), 2);
    let bound =
        |depth: f64| (2.0 * std::f64::consts::PI * r * depth + std::f64::consts::PI * r * r) * h;
    let area = std::f64::consts::PI * r * r;
    assert!((by_op[0] - area * 4.0).abs() < bound(4.0), "{by_op:?}");
    assert!((by_op[1] - area * 2.0).abs() < bound(2.0), "{by_op:?}");
    assert!((by_op[0] + by_op[1] - out.stats.removed_volume_mm3).abs() < 1e-9);
    // The stock does not depend on where the batches end.
    let mut whole = TriDexel::from_shape(&block, h).unwrap();
    cut(&mut whole, None, &ops, &SimOptions::default()).unwrap();
    assert_eq!(whole.volume().to_bits(), stock.volume().to_bits());
}
