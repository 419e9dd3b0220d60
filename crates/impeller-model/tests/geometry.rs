//! Geometric properties of parametrically built impellers (issue 3, "Tests").

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::channel::min_edge_distance;
use impeller_model::query::{blade_side_distance, Part};
use impeller_model::revolved::RevolvedSurface;
use impeller_model::{fixtures, load, Blade, Impeller, Side};
use nalgebra::Vector3;

fn fixture(name: &str) -> Impeller {
    load(format!(
        "{}/../../fixtures/{name}/impeller.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

#[test]
fn hub_and_shroud_radii_equal_their_meridional_curves() {
    let imp = fixtures::default_impeller().unwrap();
    for wall in [imp.hub(), imp.shroud()] {
        let (a, b) = wall.meridional().domain();
        for i in 0..=40 {
            let t = a + (b - a) * i as f64 / 40.0;
            let zr = wall.meridional().point(t);
            for k in 0..16 {
                let phi = k as f64 * 0.41;
                let p = wall.surface().point(t, RevolvedSurface::v_of_angle(phi));
                let r = (p.x * p.x + p.y * p.y).sqrt();
                assert!((r - zr[1]).abs() < 1e-9, "r {r} vs {}", zr[1]);
                assert!((p.z - zr[0]).abs() < 1e-9);
                assert!((p.y.atan2(p.x) - phi.sin().atan2(phi.cos())).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn isoparametric_curves_lie_on_their_surfaces() {
    let imp = fixtures::default_impeller().unwrap();
    let m = imp.hub().meridian(0.7).unwrap();
    let c = imp.hub().parallel(0.3).unwrap();
    let r = imp.hub().meridional().point(0.3)[1];
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        let p = m.point(t);
        assert!((p.y.atan2(p.x) - 0.7).abs() < 1e-12);
        assert!((p - imp.hub().point(t, 0.7)).norm() < 1e-9);
        let (a, b) = c.domain();
        let q = c.point(a + (b - a) * t);
        assert!(((q.x * q.x + q.y * q.y).sqrt() - r).abs() < 1e-9);
    }
    let b = imp.main().blade();
    let ruling = b.iso_u(Side::Suction, 0.4).unwrap();
    let flow = b.iso_v(Side::Pressure, 0.5).unwrap();
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        assert!((ruling.point(t) - b.suction().point(0.4, t)).norm() < 1e-9);
        assert!((flow.point(t) - b.pressure().point(t, 0.5)).norm() < 1e-9);
    }
    // Rulings of a ruled blade are straight: the midpoint is the mean of the ends.
    let mid = ruling.point(0.5);
    assert!((mid - 0.5 * (ruling.point(0.0) + ruling.point(1.0))).norm() < 1e-9);
}

#[test]
fn blunt_edges_have_faces_and_rounded_edges_are_closed() {
    use impeller_model::BladeEdge;
    let imp = fixtures::default_impeller().unwrap();
    let b = imp.main().blade();
    assert!(b.edge_face(BladeEdge::Leading).unwrap().is_none());
    let face = b.edge_face(BladeEdge::Trailing).unwrap().unwrap();
    let ((_, pu1), _) = b.pressure().domain();
    // The face joins the two sides' trailing isocurves; its width is the 0.8 mm blade.
    let d = b.design().unwrap();
    let v = d.v_of_span(0.0);
    let p = b.pressure().point(pu1, v);
    let s = b.suction().point(pu1, v);
    // Face u runs along the edge (the sides' v, here on [0, 1]); face v from pressure to suction.
    assert!((face.point(v, 0.0) - p).norm() < 1e-9);
    assert!((face.point(v, 1.0) - s).norm() < 1e-9);
    assert!(((p - s).norm() - 0.8).abs() < 1e-6);
}

#[test]
fn splitters_are_numbered_between_their_main_blades() {
    use impeller_model::BladeSet;
    let imp = fixtures::default_impeller().unwrap();
    let split = imp.splitter().unwrap();
    // Hand the importer's constructor a splitter row referenced one pitch too far on.
    let shifted = BladeSet::new(8, split.instance(3)).unwrap();
    let again = Impeller::from_parts(
        "x",
        imp.hub().clone(),
        imp.shroud().clone(),
        imp.main().clone(),
        Some(shifted),
        1.0,
        imp.stock().clone(),
    )
    .unwrap();
    let p = again.splitter().unwrap().blade().suction().point(0.5, 0.5);
    assert!((p - split.blade().suction().point(0.5, 0.5)).norm() < 1e-9);
}

/// Normal thickness along the camber normal against the designed distribution, on the hub
/// and shroud rows of ruled blades (where the ruled sides are offset exactly).
#[test]
fn ruled_blade_thickness_matches_distribution() {
    let imp = fixtures::default_impeller().unwrap();
    let splitter = imp.splitter().unwrap();
    for blade in [imp.main().blade(), splitter.blade()] {
        let d = blade.design().unwrap();
        let nose = d.thickness.nose_lengths().0;
        for s in [0.0, 1.0] {
            let v = d.v_of_span(s);
            let (mut far, mut near) = (0.0f64, 0.0f64);
            for i in 0..=1200 {
                let u = i as f64 / 1200.0;
                let m = d.m_local(u);
                if m < 1e-3 {
                    continue; // the normal line is tangent to both sides at the nose tip
                }
                let t = blade.normal_thickness(u, v).unwrap();
                let e = (t - d.thickness.thickness(m)).abs();
                if m > 2.0 * nose {
                    far = far.max(e);
                } else {
                    near = near.max(e);
                }
            }
            assert!(far < 1e-6, "thickness error {far} mm away from the nose");
            assert!(near < 2e-4, "thickness error {near} mm in the rounded nose");
        }
        // Exactly the nominal 0.8 mm wherever no nose is involved.
        assert!((d.thickness.nominal(0.5) - 0.8).abs() < 1e-12);
    }
}

/// Smallest angular gap (radians) from the +θ-facing side of `a` to the −θ-facing side of `b`
/// (rotated by `rot_b`) over (z, r) cells of 0.5 mm where both have points between hub and
/// shroud: negative means the blades overlap. Independent of closest-point machinery.
fn min_angular_gap(a: &Blade, b: &Blade, rot_b: f64) -> f64 {
    use std::collections::HashMap;
    let cell = |p: Vector3<f64>| {
        (
            (p.z / 0.5).floor() as i64,
            (p.x.hypot(p.y) / 0.5).floor() as i64,
        )
    };
    let rot = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), rot_b);
    let mut amax: HashMap<(i64, i64), f64> = HashMap::new();
    let mut bmin: HashMap<(i64, i64), f64> = HashMap::new();
    let (da, db) = (a.design().unwrap(), b.design().unwrap());
    let (sa, sb) = (a.plus_theta_side(), b.plus_theta_side().other());
    let phi0 = {
        let m = a.mid_point();
        m.y.atan2(m.x)
    };
    // Angles unwrapped around blade a's middle.
    let ang = |p: Vector3<f64>| {
        let d = p.y.atan2(p.x) - phi0;
        (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    for i in 0..=300 {
        for j in 0..=60 {
            let u = i as f64 / 300.0;
            let t = j as f64 / 60.0;
            let pa = a.side(sa).point(u, da.v_of_span(t));
            let e = amax.entry(cell(pa)).or_insert(f64::NEG_INFINITY);
            *e = e.max(ang(pa));
            let pb = rot * b.side(sb).point(u, db.v_of_span(t));
            let e = bmin.entry(cell(pb)).or_insert(f64::INFINITY);
            *e = e.min(ang(pb));
        }
    }
    amax.iter()
        .filter_map(|(c, &ta)| bmin.get(c).map(|&tb| tb - ta))
        .fold(f64::INFINITY, f64::min)
}

/// Free-form sides interpolate the offset grid: the thickness is exact at the grid and within
/// the fit tolerance between (moderate twist 1e-6 mm, strong twist 5e-4 mm), noses left out.
#[test]
fn free_form_blade_thickness_matches_distribution_within_fit_tolerance() {
    for (name, tol) in [
        ("impeller-5-freeform", 1e-6),
        ("impeller-11+11-freeform", 5e-4),
    ] {
        let imp = fixture(name);
        let b = imp.main().blade();
        let d = b.design().unwrap();
        let (le, te) = d.thickness.nose_lengths();
        let mut worst = 0.0f64;
        for j in 0..=16 {
            for i in 0..=160 {
                let u = i as f64 / 160.0;
                let m = d.m_local(u);
                if m < 2.0 * le || m > 1.0 - 2.0 * te {
                    continue;
                }
                // At a blunt edge the camber normal may leave a side's domain.
                let Some(t) = b.normal_thickness(u, d.v_of_span(j as f64 / 16.0)) else {
                    assert!(u > 0.98, "{name}: no thickness at u = {u}");
                    continue;
                };
                worst = worst.max((t - d.thickness.thickness(m)).abs());
            }
        }
        assert!(worst < tol, "{name}: thickness error {worst} mm");
    }
}

#[test]
fn blades_do_not_intersect_and_channels_are_positive() {
    for name in [
        "impeller-8+8",
        "impeller-11+11-freeform",
        "impeller-30-narrow",
    ] {
        let imp = fixture(name);
        let main = imp.main();
        let pitch = main.pitch_rad();
        let mut pairs = Vec::new();
        match imp.splitter() {
            Some(s) => {
                pairs.push((main.blade(), s.blade(), 0.0));
                pairs.push((s.blade(), main.blade(), pitch));
            }
            None => pairs.push((main.blade(), main.blade(), pitch)),
        }
        for (a, b, rot) in pairs {
            let gap = min_angular_gap(a, b, rot);
            assert!(
                gap > 0.0 && gap.is_finite(),
                "{name}: blades overlap ({gap} rad)"
            );
        }
        let c = imp.channel(0);
        let mut sides = vec![(&c.left, c.left_side(), &c.right, c.right_side())];
        if let Some(s) = &c.splitter {
            sides.push((&c.left, c.left_side(), s, s.plus_theta_side().other()));
            sides.push((s, s.plus_theta_side(), &c.right, c.right_side()));
        }
        for (a, sa, b, sb) in sides {
            for wall in [imp.hub(), imp.shroud()] {
                let (w, _, _) = min_edge_distance(a, sa, b, sb, wall).unwrap();
                assert!(w > 1.0, "{name}: channel width {w}");
            }
        }
        let s = imp.summary();
        assert!(s.min_channel_width_hub_mm > 0.0 && s.min_channel_width_shroud_mm > 0.0);
    }
}

#[test]
fn the_overlap_measure_detects_blades_that_touch() {
    // Negative control: 6 mm blades cannot fit the 4.3 mm main–splitter gap of impeller-8+8.
    let text = fixtures::IMPELLER_8_8_TOML.replace(
        "thickness_mm = [[0.0, 0.8], [1.0, 0.8]]",
        "thickness_mm = [[0.0, 6.0], [1.0, 6.0]]",
    );
    let imp = impeller_model::from_toml_str(&text, "thick.toml").unwrap();
    let gap = min_angular_gap(imp.main().blade(), imp.splitter().unwrap().blade(), 0.0);
    assert!(gap < 0.0, "{gap}");
}

#[test]
fn channel_sections_span_less_than_a_pitch_with_the_splitter_inside() {
    let imp = fixtures::default_impeller().unwrap();
    let pitch = imp.main().pitch_rad();
    let c = imp.channel(2);
    let (a, b) = imp.hub().meridional().domain();
    let mut with_splitter = 0;
    for k in 1..20 {
        let t = a + (b - a) * k as f64 / 20.0;
        for wall in [imp.hub(), imp.shroud()] {
            let s = c.section(wall, t).unwrap();
            assert!(s.right > s.left && s.right - s.left < pitch, "{s:?}");
            if let Some((p, q)) = s.splitter {
                with_splitter += 1;
                assert!(s.left < p && p < q && q < s.right, "{s:?}");
            }
        }
    }
    assert!(with_splitter > 10);
    // The left side sits where the blade's own edge is: rotating channel 0 by two pitches.
    let s0 = imp.channel(0).section(imp.hub(), 0.5 * (a + b)).unwrap();
    let s2 = c.section(imp.hub(), 0.5 * (a + b)).unwrap();
    let d = (s2.left - s0.left - 2.0 * pitch).rem_euclid(std::f64::consts::TAU);
    assert!(!(1e-9..=std::f64::consts::TAU - 1e-9).contains(&d));
}

#[test]
fn n_fold_symmetry_holds() {
    let imp = fixtures::default_impeller().unwrap();
    let n = imp.main().count();
    let pitch = std::f64::consts::TAU / n as f64;
    for set in [imp.main(), imp.splitter().unwrap()] {
        let b0 = set.blade();
        for k in 0..n {
            let bk = set.instance(k);
            let rot = set.rotation(k);
            for side in [Side::Pressure, Side::Suction] {
                for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.8)] {
                    let p0 = b0.side(side).point(u, v);
                    let pk = bk.side(side).point(u, v);
                    assert!((rot * p0 - pk).norm() < 1e-9);
                    // Same radius and z, angle advanced by k pitches.
                    let dphi = (pk.y.atan2(pk.x) - p0.y.atan2(p0.x) - k as f64 * pitch)
                        .rem_euclid(std::f64::consts::TAU);
                    assert!(!(1e-9..=std::f64::consts::TAU - 1e-9).contains(&dphi));
                }
            }
        }
    }
    // Every channel is as wide as channel 0.
    let w0 = {
        let c = imp.channel(0);
        min_edge_distance(&c.left, c.left_side(), &c.right, c.right_side(), imp.hub())
            .unwrap()
            .0
    };
    let c = imp.channel(5);
    let w5 = min_edge_distance(&c.left, c.left_side(), &c.right, c.right_side(), imp.hub())
        .unwrap()
        .0;
    assert!((w0 - w5).abs() < 1e-6);
    assert_eq!(imp.channel(n).index, 0);
}

#[test]
fn signed_distances_have_the_documented_signs() {
    let imp = fixtures::default_impeller().unwrap();
    let b = imp.main().blade();
    let d = b.design().unwrap();
    let (u, v) = (0.5, d.v_of_span(0.5));
    let camber = b.camber().unwrap().point(u, v);
    // The camber point is inside the blade: negative distance to both sides, about -0.4 mm.
    for side in [Side::Pressure, Side::Suction] {
        let (_, sd) = blade_side_distance(b, side, &camber, None);
        assert!(sd < -0.3 && sd > -0.5, "{sd}");
        let n = b.outward_normal(side, u, v).unwrap();
        let p = b.side(side).point(u, v) + n * 0.25;
        let (_, out) = blade_side_distance(b, side, &p, Some((u, v)));
        assert!((out - 0.25).abs() < 1e-6, "{out}");
    }
    // Rotated blade queries through the impeller.
    let rot = imp.main().rotation(3);
    let (_, sd) = imp
        .signed_distance(Part::Main(3, Side::Pressure), &(rot * camber))
        .unwrap();
    assert!(sd < 0.0);
    // Hub: a point on the axis side of the hub contour is negative, one in the channel positive.
    let mid = imp.hub().meridional().point_at_fraction(0.5);
    let n = imp
        .hub()
        .meridional()
        .normal(imp.hub().meridional().param_at_fraction(0.5));
    let inside = Vector3::new(mid[1] + 2.0 * n[1], 0.0, mid[0] + 2.0 * n[0]);
    let (_, dh) = imp.signed_distance(Part::Hub, &inside).unwrap();
    assert!((dh - 2.0).abs() < 1e-9, "{dh}");
    assert!(imp
        .signed_distance(Part::Splitter(8, Side::Pressure), &inside)
        .is_none());
}
