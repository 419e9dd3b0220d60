//! The design clearance query against hand-built cases with known distances (cutter, shank,
//! holder), linking moves kept at the safety clearance, rotational copy of a whole planned
//! operation, and ordering that keeps rapids short.
#![allow(clippy::unwrap_used, clippy::panic)] // test code

use cam_core::{
    Cutter, CutterLocation, CutterShape, HolderSegment, Move, Point3, ToolPath, Vector3,
};
use cam_plan::clearance::DesignMesh;
use cam_plan::{
    order, pattern, ClearanceOptions, DesignClearance, DesignPart, LinkCheck, LinkStats, Linker,
    SafetySurface, Tool, ToolPart,
};
use impeller_model::{Impeller, Side};
use std::sync::{Arc, OnceLock};

/// Chord and sampling tolerance of these tests (mm).
const TOL: f64 = 0.01;

fn impeller() -> &'static Impeller {
    static IMP: OnceLock<Impeller> = OnceLock::new();
    IMP.get_or_init(|| impeller_model::fixtures::default_impeller().unwrap())
}

fn mesh() -> Arc<DesignMesh> {
    static MESH: OnceLock<Arc<DesignMesh>> = OnceLock::new();
    MESH.get_or_init(|| Arc::new(DesignMesh::new(impeller(), TOL).unwrap()))
        .clone()
}

fn tool(
    shape: CutterShape,
    flute: f64,
    shank_r: f64,
    stick_out: f64,
    holder: &[(f64, f64, f64)],
) -> Tool {
    let mut cutter = Cutter::new("t", shape, flute, shank_r, stick_out).unwrap();
    cutter.holder = holder
        .iter()
        .map(|&(bottom_radius, top_radius, length)| HolderSegment {
            bottom_radius,
            top_radius,
            length,
        })
        .collect();
    let total = stick_out + holder.iter().map(|h| h.2).sum::<f64>();
    Tool {
        number: 1,
        cutter,
        teeth: 2,
        tool_length_mm: total,
        plunge_edge_length_mm: None,
    }
}

fn query(t: &Tool) -> DesignClearance<'static> {
    DesignClearance::with_mesh(
        impeller(),
        mesh(),
        t,
        ClearanceOptions {
            sample_tol_mm: TOL,
            ..ClearanceOptions::default()
        },
    )
    .unwrap()
}

/// The hub's inlet disc (r < 9 mm) is the plane z = 43 mm; nothing of the design rises above
/// it within r < 8.5 mm (the blades' rounded leading edges, which reach z = 43.04 mm, start
/// at r = 9 mm).
fn top() -> f64 {
    impeller().summary().axial_height_mm
}

#[test]
fn mesh_stays_within_its_chord_of_the_design() {
    let m = mesh();
    assert!(m.chord_mm() <= TOL);
    // The fixture's blades are 0.8 mm thick (thicker near the rounded edges).
    assert!(
        m.thickest_blade_mm() > 0.7 && m.thickest_blade_mm() < 3.0,
        "{m:?}"
    );
}

#[test]
fn shank_lying_over_the_inlet_disc_is_clear_by_its_gap() {
    // A horizontal tool (axis +X) whose Ø4 shank lies over the inlet disc (x from −5 to 7,
    // |y| ≤ 2, so r < 7.3 mm) at gap g; the Ø1 flutes hang 1.5 mm higher. Known clearance: g,
    // on the shank.
    let t = tool(CutterShape::BallEnd { radius: 0.5 }, 2.0, 2.0, 14.0, &[]);
    let q = query(&t);
    for g in [0.05, 0.3, 1.0] {
        let cl =
            CutterLocation::new(Point3::new(-7.0, 0.0, top() + g + 2.0), Vector3::x()).unwrap();
        let c = q.clearance(&cl);
        assert_eq!(c.tool_part, ToolPart::Shank, "{c:?}");
        assert_eq!(c.design_part, DesignPart::Hub, "{c:?}");
        // A lower bound within the mesh chord plus the polygon's (2·TOL).
        assert!(
            c.distance_mm <= g + 1e-9 && c.distance_mm >= g - 2.0 * TOL,
            "g {g}: {c:?}"
        );
        assert!(q.is_clear(&cl, g - 2.0 * TOL));
        assert!(!q.is_clear(&cl, g + 1e-6));
    }
    // Lowered into the disc by 0.2 mm: penetration, negative.
    let cl = CutterLocation::new(Point3::new(-7.0, 0.0, top() - 0.2 + 2.0), Vector3::x()).unwrap();
    let c = q.clearance(&cl);
    assert!(
        c.distance_mm <= -0.2 + 1e-9 && c.distance_mm >= -0.2 - 3.0 * TOL,
        "{c:?}"
    );
    assert!(!q.is_clear(&cl, 0.0));
}

#[test]
fn a_non_cutting_margin_lowers_the_shank_and_not_the_flutes() {
    // The shank over the inlet disc at gap 0.3 (as above): with a 0.25 mm margin it reads
    // 0.05 (and a check at 0.1 fails), the flutes' own reading is untouched.
    let t = tool(CutterShape::BallEnd { radius: 0.5 }, 2.0, 2.0, 14.0, &[]);
    let q = query(&t);
    let lifted = q.with_non_cutting_margin(0.25);
    let cl = CutterLocation::new(Point3::new(-7.0, 0.0, top() + 0.3 + 2.0), Vector3::x()).unwrap();
    let (a, b) = (q.clearance(&cl), lifted.clearance(&cl));
    assert_eq!(b.tool_part, ToolPart::Shank, "{b:?}");
    assert!(
        (a.distance_mm - 0.25 - b.distance_mm).abs() < 1e-9,
        "{a:?} {b:?}"
    );
    assert!(q.is_clear(&cl, 0.1) && !lifted.is_clear(&cl, 0.1));
    // A vertical ball 0.2 mm over the disc: the flutes are nearest, the margin changes
    // nothing (the shank is 2 mm higher, farther than the margin makes it read).
    let down = CutterLocation::vertical(Point3::new(0.0, 0.0, top() + 0.2));
    let (a, b) = (q.clearance(&down), lifted.clearance(&down));
    assert_eq!(a.tool_part, ToolPart::Cutter, "{a:?}");
    assert_eq!(a, b);
    // A negative margin is none.
    assert_eq!(
        q.with_non_cutting_margin(-1.0).clearance(&cl),
        q.clearance(&cl)
    );
}

#[test]
fn holder_lying_over_the_inlet_disc_is_clear_by_its_gap() {
    // Horizontal: a Ø7 holder over the inlet disc (x from −7 to 6, r < 7.8 mm) at gap g; the
    // Ø2 shank and the flutes are 2.5 mm higher, out beyond the blades' tips.
    let t = tool(
        CutterShape::BallEnd { radius: 1.0 },
        3.0,
        1.0,
        23.0,
        &[(3.5, 3.5, 13.0)],
    );
    let q = query(&t);
    let g = 0.4;
    let cl = CutterLocation::new(Point3::new(-30.0, 0.0, top() + g + 3.5), Vector3::x()).unwrap();
    let c = q.clearance(&cl);
    assert_eq!(c.tool_part, ToolPart::Holder, "{c:?}");
    assert_eq!(c.design_part, DesignPart::Hub, "{c:?}");
    assert!(
        c.distance_mm <= g + 1e-9 && c.distance_mm >= g - 2.0 * TOL,
        "{c:?}"
    );
}

#[test]
fn a_wide_holder_above_a_short_tool_does_not_reach_down_its_radius() {
    // Vertical tool on the axis, tip 0.5 mm above the inlet disc, 6 mm stick-out under a
    // Ø40 holder: the holder face is 6.5 mm above the disc; a ball as wide as the holder
    // would reach 13.5 mm below it. The nearest part is the cutter at 0.5 mm.
    let t = tool(
        CutterShape::BallEnd { radius: 1.0 },
        3.0,
        1.5,
        6.0,
        &[(20.0, 20.0, 20.0)],
    );
    let q = query(&t);
    let cl = CutterLocation::new(Point3::new(0.0, 0.0, top() + 0.5), Vector3::z()).unwrap();
    let c = q.clearance(&cl);
    assert_eq!(c.tool_part, ToolPart::Cutter, "{c:?}");
    assert_eq!(c.design_part, DesignPart::Hub, "{c:?}");
    assert!((c.distance_mm - 0.5).abs() < 1e-9, "{c:?}");
    assert!(q.is_clear(&cl, 0.49));
}

/// Mid-meridian hub point farthest from the blades (0.5° scan over one pitch) and its normal.
fn hub_point_mid_channel(q: &DesignClearance<'_>) -> (Point3, Vector3) {
    let imp = impeller();
    let (t0, t1) = imp.hub().meridional().domain();
    let t = 0.5 * (t0 + t1);
    let steps = (imp.main().pitch_rad().to_degrees() * 2.0).ceil() as usize;
    let (_, phi) = (0..steps)
        .map(|k| {
            let phi = (k as f64 * 0.5).to_radians();
            let p = Point3::from(imp.hub().point(t, phi) + imp.hub().normal(t, phi));
            (q.blade_signed_distance(&p).0, phi)
        })
        .fold(
            (f64::NEG_INFINITY, 0.0),
            |a, b| if b.0 > a.0 { b } else { a },
        );
    (
        Point3::from(imp.hub().point(t, phi)),
        imp.hub().normal(t, phi),
    )
}

#[test]
fn ball_above_the_hub_is_clear_by_its_height_exactly() {
    let t = tool(CutterShape::BallEnd { radius: 0.5 }, 2.0, 0.5, 3.0, &[]);
    let q = query(&t);
    let (p, n) = hub_point_mid_channel(&q);
    for g in [0.0, 0.1, 0.3] {
        let cl = CutterLocation::new(p + n * g, n).unwrap();
        let c = q.clearance(&cl);
        assert_eq!(c.design_part, DesignPart::Hub, "{c:?}");
        // The ball centre sample is exact (hub distance by meridional projection).
        assert!((c.distance_mm - g).abs() < 1e-6, "g {g}: {c:?}");
    }
}

#[test]
fn ball_beside_a_blade_is_clear_by_its_lateral_gap() {
    // A ball end whose ball touches the main blade's pressure side at mid-chord, mid-span,
    // moved off along the side's normal by g; the axis runs along the blade's span (its
    // ruling), so the flutes stay beside the side. Known clearance: g (exact NURBS within
    // the band).
    let imp = impeller();
    let r = 0.5;
    let t = tool(CutterShape::BallEnd { radius: r }, 1.0, r, 1.0, &[]);
    let q = query(&t);
    let blade = imp.main().blade();
    let ps = blade.side(Side::Pressure);
    let ((u0, u1), (v0, v1)) = ps.domain();
    let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let p = ps.point(u, v);
    let e = 1e-5;
    let du = (ps.point(u + e, v) - ps.point(u - e, v)) / (2.0 * e);
    let dv = (ps.point(u, v + e) - ps.point(u, v - e)) / (2.0 * e);
    let mut n = du.cross(&dv).normalize();
    // Outward: the signed side distance is positive along it.
    let probe = Point3::from(p + n * 0.05);
    if q.blade_signed_distance(&probe).0 < 0.0 {
        n = -n;
    }
    let axis = (dv - n * dv.dot(&n)).normalize();
    for g in [0.05, 0.2] {
        let centre = p + n * (r + g);
        let cl = CutterLocation::new(Point3::from(centre - axis * r), axis).unwrap();
        let c = q.clearance(&cl);
        assert!(matches!(c.design_part, DesignPart::Blade { .. }), "{c:?}");
        assert!(
            c.distance_mm <= g + 1e-6 && c.distance_mm >= g - TOL,
            "g {g}: {c:?}"
        );
    }
}

/// Straight segments between consecutive postures, tip and axis interpolated (axis
/// normalised), sampled every `step` mm of tip travel (and at least 8 times per segment).
fn sample_moves(moves: &[Move], step: f64) -> Vec<CutterLocation> {
    let mut out = Vec::new();
    for w in moves.windows(2) {
        let (a, b) = (w[0].cl, w[1].cl);
        let n = (((b.tip - a.tip).norm() / step).ceil() as usize).max(8);
        for i in 0..=n {
            let f = i as f64 / n as f64;
            let axis = a.axis.into_inner() * (1.0 - f) + b.axis.into_inner() * f;
            out.push(CutterLocation::new(a.tip + (b.tip - a.tip) * f, axis).unwrap());
        }
    }
    out
}

#[test]
fn linking_moves_keep_the_safety_clearance_from_the_design() {
    // Two cutting postures deep in neighbouring channels, axes tilted differently (one
    // toward the impeller axis, one outward): the travel between their retract points on the
    // safety surface, sampled at 1 mm (a tenth of the clearance), never comes closer to the
    // design than the clearance (within the query's stated error).
    let imp = impeller();
    let clearance = 10.0;
    let linker = Linker::new(SafetySurface::around_stock(imp.stock(), clearance).unwrap());
    let t = tool(
        CutterShape::TaperedBallEnd {
            ball_radius: 1.5,
            half_angle: 2f64.to_radians(),
        },
        20.0,
        3.0,
        35.0,
        &[(10.5, 13.5, 38.0), (13.5, 13.5, 42.0)],
    );
    let q = query(&t);
    let (p, n) = hub_point_mid_channel(&q);
    let from = CutterLocation::new(p + n * 0.2, n + Vector3::new(-p.x, -p.y, 0.0) * 0.02).unwrap();
    let rot = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 1.3);
    let to_tip = rot * (p + n * 0.2);
    let to = CutterLocation::new(
        to_tip,
        rot * n + Vector3::new(to_tip.x, to_tip.y, 0.0) * 0.03,
    )
    .unwrap();
    let link = linker.connect(&from, &to, 2.0).unwrap();
    // The travel: from the retract point (first move) to the entry point above `to`.
    let out = linker.retract_point(&from).unwrap();
    let inn = linker.retract_point(&to).unwrap();
    let start = link.iter().position(|m| m.cl == out).unwrap();
    let end = link.iter().position(|m| m.cl == inn).unwrap();
    assert!(end > start + 1, "{link:?}");
    let mut min = f64::INFINITY;
    for cl in sample_moves(&link[start..=end], 1.0) {
        min = min.min(q.clearance(&cl).distance_mm);
    }
    assert!(min >= clearance - 2.0 * TOL, "closest {min} mm");
    // Retract and approach run along the cutting postures' axes: the clearance grows from the
    // cut out to the surface.
    let back: Vec<f64> = sample_moves(&[Move::feed(from), link[0]], 1.0)
        .iter()
        .map(|cl| q.clearance(cl).distance_mm)
        .collect();
    assert!(
        back.first().unwrap() < &1.0 && back.last().unwrap() >= &(clearance - 2.0 * TOL),
        "{back:?}"
    );
}

#[test]
fn rotational_copy_of_a_whole_planned_operation_is_exact() {
    // One channel's path with its approach and retract over the safety surface, copied to
    // every channel and joined: each channel's copy equals channel 0's turned by k·pitch
    // within 1e-9 mm (tips) and 1e-12 (axes).
    let imp = impeller();
    let set = imp.main();
    let pitch = set.pitch_rad();
    let linker = Linker::new(SafetySurface::around_stock(imp.stock(), 10.0).unwrap());
    let mut path = ToolPath::new("op", "t");
    for i in 0..40 {
        let s = i as f64 / 39.0;
        let tip = Point3::new(12.0 + 20.0 * s, 3.0 * s, 40.0 - 25.0 * s);
        path.moves.push(Move::feed(
            CutterLocation::new(tip, Vector3::new(0.2 * s, 0.1, 1.0)).unwrap(),
        ));
    }
    linker.close(&mut path, 2.0).unwrap();
    let order = order::angular_sequence(set.count(), 0);
    let copies = pattern::copy_to(&path, pitch, &order);
    let joined = linker.join("op", "t", &copies, 2.0).unwrap();
    for (k, c) in copies.iter().enumerate() {
        let rot = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), pitch * k as f64);
        assert_eq!(c.moves.len(), path.moves.len());
        for (m, m0) in c.moves.iter().zip(&path.moves) {
            assert!((m.cl.tip - rot * m0.cl.tip).norm() < 1e-9);
            assert!((m.cl.axis.into_inner() - rot * m0.cl.axis.into_inner()).norm() < 1e-12);
            assert_eq!(m.kind, m0.kind);
        }
        // Every cutting move of every copy is in the joined operation, in order.
        let cuts: Vec<&Move> = c
            .moves
            .iter()
            .filter(|m| m.kind.at_cutting_feed())
            .collect();
        let at = joined
            .moves
            .iter()
            .position(|m| m.cl == cuts[0].cl)
            .unwrap();
        for (j, m) in cuts.iter().enumerate() {
            assert_eq!(joined.moves[at + j].cl, m.cl);
        }
    }
}

#[test]
fn nearest_first_ordering_keeps_rapids_shortest() {
    // Copies of one path to 7 channels, shuffled: the greedy order from channel 0's start
    // gives the least total rapid length (tip of one path's end to the next one's start) of
    // every order starting with channel 0 (brute force over 6! orders).
    let mut path = ToolPath::new("p", "t");
    for i in 0..5 {
        let tip = Point3::new(20.0 + i as f64, 2.0 * i as f64, 30.0);
        path.moves
            .push(Move::feed(CutterLocation::new(tip, Vector3::z()).unwrap()));
    }
    let n = 7;
    let pitch = std::f64::consts::TAU / n as f64;
    let shuffled = [0, 4, 2, 6, 1, 5, 3];
    let copies = pattern::copy_to(&path, pitch, &shuffled);
    let start = copies[0].moves[0].cl.tip;
    let greedy = order::nearest_first(&copies, start);
    let rapid = |ord: &[usize]| -> f64 {
        ord.windows(2)
            .map(|w| {
                let a = copies[w[0]].moves.last().unwrap().cl.tip;
                let b = copies[w[1]].moves[0].cl.tip;
                (b - a).norm()
            })
            .sum()
    };
    let mut best = f64::INFINITY;
    let mut rest: Vec<usize> = (1..n).collect();
    permute(&mut rest, 0, &mut |p| {
        let mut ord = vec![0];
        ord.extend_from_slice(p);
        best = best.min(rapid(&ord));
    });
    assert_eq!(greedy[0], 0);
    assert!(
        rapid(&greedy) <= best + 1e-9,
        "{} vs {best}",
        rapid(&greedy)
    );
    // And it visits the channels in angular sequence (each link one pitch).
    let channels: Vec<usize> = greedy.iter().map(|&i| shuffled[i]).collect();
    assert_eq!(channels, order::angular_sequence(n, 0));
}

fn permute(v: &mut Vec<usize>, k: usize, f: &mut impl FnMut(&[usize])) {
    if k == v.len() {
        f(v);
        return;
    }
    for i in k..v.len() {
        v.swap(k, i);
        permute(v, k + 1, f);
        v.swap(k, i);
    }
}

#[test]
fn segment_clearance_finds_a_blade_between_two_clear_postures() {
    // A ball beside the main blade's pressure side, 0.5 mm off, moved along the side's normal
    // *through* the blade to the same gap on the suction side: both ends are clear by 0.5 mm,
    // the motion is not. A motion along the side (tip moved 2 mm along the ruling at the same
    // gap) is clear.
    let imp = impeller();
    let r = 0.5;
    let t = tool(CutterShape::BallEnd { radius: r }, 1.0, r, 1.0, &[]);
    let q = query(&t);
    let blade = imp.main().blade();
    let ps = blade.side(Side::Pressure);
    let ((u0, u1), (v0, v1)) = ps.domain();
    let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let p = ps.point(u, v);
    let e = 1e-5;
    let du = (ps.point(u + e, v) - ps.point(u - e, v)) / (2.0 * e);
    let dv = (ps.point(u, v + e) - ps.point(u, v - e)) / (2.0 * e);
    let mut n = du.cross(&dv).normalize();
    let probe = Point3::from(p + n * 0.05);
    if q.blade_signed_distance(&probe).0 < 0.0 {
        n = -n;
    }
    let axis = (dv - n * dv.dot(&n)).normalize();
    let g = 0.5;
    let a = CutterLocation::new(Point3::from(p + n * (r + g) - axis * r), axis).unwrap();
    // the other side of the blade: thickness 0.8 mm, same gap
    let b = CutterLocation::new(Point3::from(p - n * (0.8 + r + g) - axis * r), axis).unwrap();
    assert!(q.clearance(&a).distance_mm > 0.4 && q.clearance(&b).distance_mm > 0.4);
    let hit = q.segment_clearance(&a, &b, 0.0, 0.005, 200).unwrap_err();
    assert!(hit > 0.0 && hit < 1.0, "{hit}");
    let along = CutterLocation::new(a.tip + axis * 2.0, axis).unwrap();
    assert!(q.segment_clearance(&a, &along, 0.0, 0.005, 200).is_ok());
    // every sampled posture of the accepted motion is clear within the tolerance
    for k in 0..=50 {
        let s = k as f64 / 50.0;
        let cl = CutterLocation::new(a.tip + (along.tip - a.tip) * s, axis).unwrap();
        assert!(q.clearance(&cl).distance_mm >= -0.005);
    }
}

#[test]
fn approaches_are_rapid_only_outside_the_blank() {
    // An entry 20 mm down in a channel: with the blank known, the approach's last rapid ends
    // at least `approach` (2 mm) outside the blank on the entry's axis, the rest is a plunge;
    // no rapid posture (nor any interpolated between two rapids, sampled every 0.1 mm) has
    // its tip inside the blank.
    let imp = impeller();
    let surface = SafetySurface::around_stock(imp.stock(), 10.0).unwrap();
    let linker = Linker::with_blank(surface, imp.stock());
    let top = imp.stock().z_range().1;
    let to = CutterLocation::new(Point3::new(25.0, 3.0, top - 20.0), Vector3::z()).unwrap();
    let from = CutterLocation::new(Point3::new(-25.0, 3.0, top - 18.0), Vector3::z()).unwrap();
    let moves = linker.link(&from, &to, 2.0).unwrap();
    let last_rapid = moves
        .iter()
        .rev()
        .find(|m| m.kind == cam_core::MoveKind::Rapid)
        .unwrap();
    assert!(
        last_rapid.cl.tip.z >= top + 2.0 - 1e-9,
        "{:?}",
        last_rapid.cl.tip
    );
    assert_eq!(moves.last().unwrap().kind, cam_core::MoveKind::Plunge);
    for w in moves.windows(2) {
        if w[1].kind != cam_core::MoveKind::Rapid {
            continue;
        }
        let n = (((w[1].cl.tip - w[0].cl.tip).norm() / 0.1).ceil() as usize).max(1);
        for k in 0..=n {
            let p = w[0].cl.tip + (w[1].cl.tip - w[0].cl.tip) * (k as f64 / n as f64);
            assert!(
                !imp.stock().contains(&p.coords),
                "rapid inside the blank at {p:?}"
            );
        }
    }
    // without the blank the rapid goes down to 2 mm above the entry
    let plain = Linker::new(surface).link(&from, &to, 2.0).unwrap();
    let r = plain
        .iter()
        .rev()
        .find(|m| m.kind == cam_core::MoveKind::Rapid)
        .unwrap();
    assert!((r.cl.tip.z - (to.tip.z + 2.0)).abs() < 1e-9);
}

/// The smallest distance from the tool assembly at `cl` to the blank, from its surface
/// sampled every 0.05 mm of height and 2° of angle (plus its axis, for the end faces): above
/// the truth by at most half the samples' spacing, 0.24 mm on the Ø27 holder, 0.05 mm on
/// the Ø6 shank.
fn sampled_blank_distance(
    stock: &impeller_model::Stock,
    cutter: &Cutter,
    cl: &CutterLocation,
) -> f64 {
    let a = cl.axis.into_inner();
    let e1 = a
        .cross(&Vector3::x())
        .try_normalize(1e-6)
        .unwrap_or_else(|| a.cross(&Vector3::y()).normalize());
    let e2 = a.cross(&e1);
    let top = cutter.overall_length + cutter.holder.iter().map(|h| h.length).sum::<f64>();
    let n = (top / 0.05).ceil() as usize;
    let mut d = f64::INFINITY;
    for i in 0..=n {
        let h = top * i as f64 / n as f64;
        let r = cutter.assembly_radius_at(h).unwrap_or(0.0);
        let c = cl.tip + a * h;
        d = d.min(stock.distance_to(&c.coords));
        for k in 0..180 {
            let phi = (k as f64 * 2.0).to_radians();
            let p = c + (e1 * phi.cos() + e2 * phi.sin()) * r;
            d = d.min(stock.distance_to(&p.coords));
        }
    }
    d
}

#[test]
fn a_sideways_approach_keeps_the_whole_tool_away_from_the_blank() {
    // A Ø4 ball end on a Ø6 shank comes in sideways, its axis radial and tilted 0.2° down,
    // to a tip 2.006 mm above the blank's top face (the ball then clears the face by
    // 0.006 mm), like the blade-root approaches at a free-form impeller's inlet rim. The tip
    // stays above the face all the way, so the tip's probes let the rapid run to 2 mm from
    // the tip: the shank, 1 mm wider than the ball, runs through the blank. With the tool's
    // envelope every rapid posture keeps the approach distance (2 mm) from the blank.
    let imp = impeller();
    let stock = imp.stock();
    let surface = SafetySurface::around_stock(stock, 10.0).unwrap();
    let linker = Linker::with_blank(surface, stock);
    let top = stock.z_range().1;
    let t = tool(
        CutterShape::BallEnd { radius: 2.0 },
        20.0,
        3.0,
        45.0,
        &[(10.5, 13.5, 38.0)],
    );
    let tilt = 0.2f64.to_radians();
    let axis = Vector3::new(tilt.cos(), 0.0, tilt.sin());
    let to = CutterLocation::new(Point3::new(12.0, 0.0, top + 2.006), axis).unwrap();
    let from = CutterLocation::new(Point3::new(-12.0, 5.0, top + 2.006), Vector3::z()).unwrap();
    let rapids = |moves: &[Move]| -> Vec<CutterLocation> {
        let mut out = Vec::new();
        for w in moves.windows(2) {
            if w[1].kind != cam_core::MoveKind::Rapid {
                continue;
            }
            let n = (((w[1].cl.tip - w[0].cl.tip).norm() / 0.25).ceil() as usize).max(1);
            for k in 0..=n {
                let s = k as f64 / n as f64;
                let ax = (w[0].cl.axis.into_inner() * (1.0 - s) + w[1].cl.axis.into_inner() * s)
                    .normalize();
                out.push(
                    CutterLocation::new(w[0].cl.tip + (w[1].cl.tip - w[0].cl.tip) * s, ax).unwrap(),
                );
            }
        }
        out
    };
    let nearest = |moves: &[Move]| {
        rapids(moves)
            .iter()
            .map(|cl| sampled_blank_distance(stock, &t.cutter, cl))
            .fold(f64::INFINITY, f64::min)
    };
    let dirs = (&axis, &axis);
    let tip_only = linker
        .connect_along((&from, dirs.0), (&to, dirs.1), 2.0)
        .unwrap();
    assert!(
        nearest(&tip_only) <= 0.0,
        "the tip's probes should let the shank into the blank"
    );
    let envelope = cam_plan::ToolEnvelope::of(&t.cutter);
    let moves = linker
        .connect_enveloped((&from, dirs.0), (&to, dirs.1), 2.0, Some(&envelope))
        .unwrap();
    let d = nearest(&moves);
    assert!(d >= 2.0 - 1e-9, "a rapid posture {d} mm from the blank");
    assert_eq!(moves.last().unwrap().kind, cam_core::MoveKind::Plunge);
    assert_eq!(moves.last().unwrap().cl, to);
    // The rapid stops no farther out than the envelope's overreach (0.5 mm) plus the trace's
    // stop (0.05 mm) and the sampling allow: 2 mm from the blank within 0.6 mm.
    assert!(d <= 2.6, "the rapid stopped {d} mm from the blank");
}

/// The T5 roughing cutter of impeller-8+8 (tapered ball R1.5, 2°, 20 mm flutes, Ø6 shank).
fn t5() -> Tool {
    tool(
        CutterShape::TaperedBallEnd {
            ball_radius: 1.5,
            half_angle: 2f64.to_radians(),
        },
        20.0,
        3.0,
        35.0,
        &[(10.5, 13.5, 38.0), (13.5, 13.5, 42.0)],
    )
}

#[test]
fn cutter_beside_a_splitter_leading_edge_reads_its_penetration() {
    // A channel-roughing move planned on impeller-8+8 whose flutes cut into splitter 5 beside
    // its leading edge: the stock simulation measured 0.32 mm of overcut there, while the
    // blade distance max(d_pressure, d_suction) over-read beside the edge (the pressure side's
    // closest point lies on its edge) and the query answered +0.04 … +0.31 mm along the move.
    let q = query(&t5());
    let a = CutterLocation::new(
        Point3::new(
            -1.357_052_190_866_909,
            -17.350_289_114_561_15,
            27.050_912_497_983_14,
        ),
        Vector3::new(
            0.037_227_128_397_598_84,
            -0.900_449_779_238_418_3,
            0.433_363_976_330_235_3,
        ),
    )
    .unwrap();
    let b = CutterLocation::new(
        Point3::new(
            -0.035_802_192_405_006_04,
            -17.723_693_619_090_87,
            26.143_168_263_720_73,
        ),
        Vector3::new(
            0.043_724_916_296_149_33,
            -0.895_810_786_528_463,
            0.442_279_511_659_936,
        ),
    )
    .unwrap();
    let imp = impeller();
    let split = imp.splitter().unwrap();
    let ax = |s: f64| CutterLocation {
        tip: a.tip + (b.tip - a.tip) * s,
        axis: a.axis.slerp(&b.axis, s),
    };
    // Independent reference: flute surface points inside splitter 5 (behind both sides and
    // below the shroud, by each side's own closest point and normal).
    let inside_points = |cl: &CutterLocation| {
        let axis = cl.axis.into_inner();
        let e1 = axis.cross(&Vector3::x()).normalize();
        let e2 = axis.cross(&e1);
        let mut count = 0;
        for i in 0..=40 {
            let h = 4.0 + 0.1 * i as f64;
            let rho = t5().cutter.shape.radius_at(h);
            for j in 0..90 {
                let w = j as f64 * std::f64::consts::TAU / 90.0;
                let p = cl.tip.coords + axis * h + (e1 * w.cos() + e2 * w.sin()) * rho;
                let local = split.rotation(5).inverse() * p;
                let blade = split.blade();
                let (_, dp) =
                    impeller_model::query::blade_side_distance(blade, Side::Pressure, &local, None);
                let (_, ds) =
                    impeller_model::query::blade_side_distance(blade, Side::Suction, &local, None);
                if dp < -0.01 && ds < -0.01 && imp.shroud().signed_distance(&p) < 0.0 {
                    count += 1;
                }
            }
        }
        count
    };
    let mid = ax(0.45);
    assert!(
        inside_points(&mid) > 0,
        "the reference finds no flute point inside"
    );
    let c = q.clearance(&mid).distance_mm;
    assert!(c < -0.01, "query {c} mm: the penetration is not seen");
    assert!(q.segment_clearance(&a, &b, 0.0, 0.005, 64).is_err());
}

#[test]
fn retract_along_the_axis_of_a_widening_tool_is_certified_by_its_shape() {
    // T5 widens from the ball up to the holder: a retract along its axis covers nothing the
    // cutting posture does not, but the cylinder above the holder's top, far above the blank.
    let imp = impeller();
    let linker = Linker::with_blank(
        SafetySurface::around_stock(imp.stock(), 10.0).unwrap(),
        imp.stock(),
    );
    let t = t5();
    let q = query(&t);
    let (p, n) = hub_point_mid_channel(&q);
    let cl = CutterLocation::new(p + n * 0.3, n).unwrap();
    let profile = cam_plan::linking::widening_profile(&t.cutter);
    assert_eq!(profile, Some((115.0, 13.5)));
    let stats = LinkStats::default();
    let check = LinkCheck {
        clearance: &q,
        profile,
        stats: &stats,
        floor_mm: 0.3,
        tol_mm: 0.005,
        max_queries: 40,
        cutter: None,
    };
    let (d, certified) = linker.exit_direction(&cl, &check);
    assert!(certified && (d - n).norm() < 1e-12);
    // The certificate agrees with sampling: the retract never comes closer than the start.
    let c0 = q.clearance(&cl).distance_mm;
    let out = linker.exit_point(&cl, &d).unwrap();
    for i in 0..=200 {
        let s = i as f64 / 200.0;
        let at = CutterLocation {
            tip: cl.tip + (out.tip - cl.tip) * s,
            axis: cl.axis,
        };
        assert!(q.clearance(&at).distance_mm >= c0 - 1e-9);
    }
}

#[test]
fn a_retract_along_the_axis_sweeps_no_stock_when_the_cylinder_above_the_holder_is_outside_the_blank(
) {
    // T5 in the channel: a retract along its axis covers nothing beyond the tool's own
    // volume but the cylinder above its holder (115 mm above the tip, 13.5 mm radius), which
    // stays above the 43 mm high blank; a short tool (a 12 mm assembly) whose top stays inside
    // the blank, a move off the axis and a linker without blank are not certified.
    let imp = impeller();
    let surface = SafetySurface::around_stock(imp.stock(), 10.0).unwrap();
    let linker = Linker::with_blank(surface, imp.stock());
    let t = t5();
    let q = query(&t);
    let (p, n) = hub_point_mid_channel(&q);
    let cl = CutterLocation::new(p + n * 0.3, n).unwrap();
    let out = linker.exit_point(&cl, &n).unwrap();
    let profile = cam_plan::linking::widening_profile(&t.cutter).unwrap();
    assert!(linker.retract_sweeps_no_stock(&cl, &out.tip, profile));
    let short = tool(CutterShape::BallEnd { radius: 0.5 }, 2.0, 0.5, 12.0, &[]);
    let short_profile = cam_plan::linking::widening_profile(&short.cutter).unwrap();
    assert!(short_profile.0 <= 12.0 + 1e-9);
    assert!(!linker.retract_sweeps_no_stock(&cl, &out.tip, short_profile));
    let sideways = out.tip + Vector3::new(n.y, -n.x, 0.0).normalize() * 2.0;
    assert!(!linker.retract_sweeps_no_stock(&cl, &sideways, profile));
    assert!(!Linker::new(surface).retract_sweeps_no_stock(&cl, &out.tip, profile));
}

#[test]
fn retract_leaves_along_a_clear_direction_when_the_axis_would_cut_a_blade() {
    // A necked ball end (ball R1 on a R0.4 neck: its radius shrinks above the ball, so the
    // shape certifies nothing) leaning across the channel: the lean is raised until the ball
    // would cut the neighbouring blade on its way out along the axis while the cutting posture
    // itself is clear. The checked linker then picks another direction, certified clear, and
    // the move along it, sampled every 0.05 mm, keeps the clearance asked for (within the
    // certification tolerance).
    let imp = impeller();
    let linker = Linker::new(SafetySurface::around_stock(imp.stock(), 10.0).unwrap());
    let t = tool(
        CutterShape::BallEnd { radius: 1.0 },
        1.0,
        0.4,
        30.0,
        &[(10.0, 10.0, 40.0)],
    );
    assert_eq!(cam_plan::linking::widening_profile(&t.cutter), None);
    let q = query(&t);
    let (p, n) = hub_point_mid_channel(&q);
    let e_theta = Vector3::new(-p.y, p.x, 0.0).normalize();
    let side = (e_theta - n * n.dot(&e_theta)).normalize();
    let found = (0..=40).find_map(|k| {
        let lean = (2.0 * k as f64).to_radians();
        let axis = n * lean.cos() + side * lean.sin();
        let cl = CutterLocation::new(p + n * 2.0, axis).unwrap();
        let c0 = q.clearance(&cl).distance_mm;
        let out = linker.exit_point(&cl, &axis)?;
        (c0 > 0.2 && q.segment_clearance(&cl, &out, 0.0, 0.005, 400).is_err())
            .then_some((cl, axis, c0))
    });
    let (cl, axis, c0) = found.expect("no lean makes the axis retract cut a blade");
    let stats = LinkStats::default();
    let check = LinkCheck {
        clearance: &q,
        profile: None,
        stats: &stats,
        floor_mm: 0.1,
        tol_mm: 0.005,
        max_queries: 40,
        cutter: None,
    };
    let (d, certified) = linker.exit_direction(&cl, &check);
    assert!(certified);
    assert!(
        d.dot(&axis) < 1.0 - 1e-6,
        "expected a direction off the axis"
    );
    let out = linker.exit_point(&cl, &d).unwrap();
    assert!(linker.leaves_clear(&out));
    let floor = c0.min(0.1) - 0.005;
    let len = (out.tip - cl.tip).norm();
    let k = (len / 0.05).ceil() as usize;
    for i in 0..=k {
        let s = i as f64 / k as f64;
        let at = CutterLocation {
            tip: cl.tip + (out.tip - cl.tip) * s,
            axis: cl.axis,
        };
        let c = q.clearance(&at).distance_mm;
        assert!(c >= floor - 1e-9, "clearance {c} at {s} below {floor}");
    }
    // The checked link from this posture to itself leaves and comes back that way.
    let moves = linker.link_checked(&cl, &cl, 2.0, &check).unwrap();
    assert_eq!(moves.last().unwrap().cl, cl);
    assert_eq!(stats.uncertified(), 0);
    assert!(stats.turned() >= 2);
}
