//! Closed-form reproduction: LinuxCNC's trt formulas and the published turn-mill case;
//! solution choice, singularity, unwinding.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{CutterLocation, Point3, Vector3};
use postproc_kinematics::{Joints, KinematicsError, Machine};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn fixture(name: &str) -> Machine {
    let path = format!(
        "{}/../../fixtures/machines/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    Machine::from_file(&path).unwrap()
}

/// LinuxCNC 2.9 `xyzacKinematicsForward` (trtfuncs.c), transcribed term by term; angles in
/// degrees, `dt` the tool offset.
fn linuxcnc_xyzac_forward(j: [f64; 5], rp: [f64; 3], dy: f64, dz: f64, dt: f64) -> [f64; 3] {
    let (a, c) = (j[3].to_radians(), j[4].to_radians());
    let dz = dz + dt;
    let (xr, yr, zr) = (rp[0], rp[1], rp[2]);
    [
        c.cos() * (j[0] - xr)
            + c.sin() * a.cos() * (j[1] - dy - yr)
            + c.sin() * a.sin() * (j[2] - dz - zr)
            + c.sin() * dy
            + xr,
        -c.sin() * (j[0] - xr)
            + c.cos() * a.cos() * (j[1] - dy - yr)
            + c.cos() * a.sin() * (j[2] - dz - zr)
            + c.cos() * dy
            + yr,
        -a.sin() * (j[1] - dy - yr) + a.cos() * (j[2] - dz - zr) + dz + zr,
    ]
}

/// LinuxCNC 2.9 `xyzacKinematicsInverse`.
fn linuxcnc_xyzac_inverse(
    p: [f64; 3],
    a_deg: f64,
    c_deg: f64,
    rp: [f64; 3],
    dy: f64,
    dz: f64,
    dt: f64,
) -> [f64; 3] {
    let (a, c) = (a_deg.to_radians(), c_deg.to_radians());
    let dz = dz + dt;
    let (xr, yr, zr) = (rp[0], rp[1], rp[2]);
    let (x, y, z) = (p[0] - xr, p[1] - yr, p[2] - zr);
    [
        c.cos() * x - c.sin() * y + xr,
        c.sin() * a.cos() * x + c.cos() * a.cos() * y - a.sin() * z - a.cos() * dy
            + a.sin() * dz
            + dy
            + yr,
        c.sin() * a.sin() * x + c.cos() * a.sin() * y + a.cos() * z - a.sin() * dy - a.cos() * dz
            + dz
            + zr,
    ]
}

/// LinuxCNC 2.9 `xyzbcKinematicsInverse`.
fn linuxcnc_xyzbc_inverse(
    p: [f64; 3],
    b_deg: f64,
    c_deg: f64,
    rp: [f64; 3],
    dx: f64,
    dz: f64,
    dt: f64,
) -> [f64; 3] {
    let (b, c) = (b_deg.to_radians(), c_deg.to_radians());
    let dz = dz + dt;
    let dpx = -b.cos() * dx - b.sin() * dz + dx;
    let dpz = b.sin() * dx - b.cos() * dz + dz;
    let (x, y, z) = (p[0] - rp[0], p[1] - rp[1], p[2] - rp[2]);
    [
        c.cos() * b.cos() * x - c.sin() * b.cos() * y + b.sin() * z + dpx + rp[0],
        c.sin() * x + c.cos() * y + rp[1],
        -c.cos() * b.sin() * x + c.sin() * b.sin() * y + b.cos() * z + dpz + rp[2],
    ]
}

#[test]
fn xyzac_trt_hand_computed_case() {
    // A = 90°, C = 0, y-offset 20, z-offset 10, rot point 0, world point at the origin:
    // LinuxCNC inverse gives Y = sin(90°)·10 + 20 = 30, Z = −sin(90°)·20 + 10 = −10.
    let m = fixture("xyzac-trt");
    let j = m.joints_for_angles(&Point3::origin(), 0.0, 90f64.to_radians(), 0.0);
    assert!(
        (j.x - 0.0).abs() < 1e-12 && (j.y - 30.0).abs() < 1e-12 && (j.z + 10.0).abs() < 1e-12,
        "{j:?}"
    );
    // ... and the tool axis seen from the table is +Y (Rz(−C)·Rx(−A)·ẑ).
    let cl = m.forward(&j, 0.0);
    assert!((cl.axis.into_inner() - Vector3::y()).norm() < 1e-12);
    assert!(cl.tip.coords.norm() < 1e-12);
    // Inverse: A = +90° is beyond A's +50° limit, so the other tilt sign (A = −90°, C = ±180°)
    // must be chosen.
    let k = m.inverse(&cl, 0.0, None).unwrap();
    assert!((k.tilt.to_degrees() + 90.0).abs() < 1e-9, "{k:?}");
    assert!((k.rotate.to_degrees().abs() - 180.0).abs() < 1e-9, "{k:?}");
}

#[test]
fn xyzac_trt_matches_linuxcnc_formulas() {
    // Non-zero rot points / offsets through a modified fixture.
    let text = std::fs::read_to_string(format!(
        "{}/../../fixtures/machines/xyzac-trt.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace("x_rot_point = 0.0", "x_rot_point = 12.5")
    .replace("y_rot_point = 0.0", "y_rot_point = -7.0")
    .replace("z_rot_point = 0.0", "z_rot_point = 3.25");
    let m = Machine::from_toml_str(&text, "mod.toml").unwrap();
    let (rp, dy, dz) = ([12.5, -7.0, 3.25], 20.0, 10.0);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..200 {
        let j = [
            rng.random_range(-150.0..150.0),
            rng.random_range(-80.0..80.0),
            rng.random_range(-100.0..100.0),
            rng.random_range(-100.0..50.0),
            rng.random_range(-720.0..720.0),
        ];
        let joints = Joints {
            x: j[0],
            y: j[1],
            z: j[2],
            tilt: j[3].to_radians(),
            rotate: j[4].to_radians(),
        };
        // Tool offset dt does not change the tool-tip joints: LinuxCNC's J includes +dt in Z.
        for dt in [0.0, 55.0] {
            let mut jl = j;
            jl[2] += dt;
            // LinuxCNC's world point is the tip raised by the tool offset along the table Z.
            let w = linuxcnc_xyzac_forward(jl, rp, dy, dz, dt);
            let ours = m.forward(&joints, 77.0).tip;
            let tip = [w[0], w[1], w[2] - dt];
            for k in 0..3 {
                assert!(
                    (tip[k] - ours[k]).abs() < 1e-9,
                    "forward {k}: {w:?} vs {ours:?}"
                );
            }
            let inv = linuxcnc_xyzac_inverse(w, j[3], j[4], rp, dy, dz, dt);
            let back = m.joints_for_angles(
                &Point3::new(tip[0], tip[1], tip[2]),
                77.0,
                joints.tilt,
                joints.rotate,
            );
            assert!(
                (inv[0] - back.x).abs() < 1e-9
                    && (inv[1] - back.y).abs() < 1e-9
                    && (inv[2] - dt - back.z).abs() < 1e-9
            );
        }
    }
}

#[test]
fn xyzbc_trt_matches_linuxcnc_formulas() {
    let m = fixture("xyzbc-trt");
    let (rp, dx, dz) = ([0.0, 0.0, 0.0], -20.0, -15.0);
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    for _ in 0..200 {
        let p = [
            rng.random_range(-50.0..50.0),
            rng.random_range(-50.0..50.0),
            rng.random_range(-30.0..30.0),
        ];
        let (b, c) = (
            rng.random_range(-100.0..50.0),
            rng.random_range(-400.0..400.0),
        );
        let inv = linuxcnc_xyzbc_inverse(p, b, c, rp, dx, dz, 0.0);
        let ours = m.joints_for_angles(
            &Point3::new(p[0], p[1], p[2]),
            0.0,
            f64::to_radians(b),
            f64::to_radians(c),
        );
        assert!(
            (inv[0] - ours.x).abs() < 1e-9
                && (inv[1] - ours.y).abs() < 1e-9
                && (inv[2] - ours.z).abs() < 1e-9
        );
    }
}

/// Published turn-mill case (paper 003): tool axis eq. 5, angles eqs. 1–2 (principal
/// branch), positions eq. 7 with the `L·cos q_B` term that eq. 6 implies (eq. 7's X line as
/// printed drops it).
#[test]
fn turnmill_matches_published_closed_form() {
    let m = fixture("turnmill-bc");
    let pivot = 150.0;
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for _ in 0..300 {
        let tool = rng.random_range(20.0..120.0);
        let l = pivot + tool;
        let qb: f64 = rng.random_range(-85f64..85.0).to_radians();
        let qc: f64 = rng.random_range(-170f64..170.0).to_radians();
        let p = Point3::new(
            rng.random_range(-60.0..60.0),
            rng.random_range(-60.0..60.0),
            rng.random_range(0.0..50.0),
        );
        // eq. 5
        let u = Vector3::new(qc.cos() * qb.cos(), -qc.sin() * qb.cos(), -qb.sin());
        let cl = CutterLocation::new(p, u).unwrap();
        let j = m.inverse(&cl, tool, None).unwrap();
        // eq. 1: q_B = −asin(u_z) (k = 0, n = 1) or q_B = k·π + asin(u_z) (n = −1,
        // k = sign(asin u_z)); eq. 2 (with u_y/u_x): q_C = −atan(u_y/u_x) + k·π. The inverse
        // picks the branch with the least travel from home; both satisfy eq. 5.
        let principal = -u.z.asin();
        let other = u.z.asin().signum() * std::f64::consts::PI + u.z.asin();
        let c0 = -u.y.atan2(u.x);
        let (b_expected, c_expected) =
            if postproc_kinematics::wrap_pi(j.tilt - principal).abs() < 1e-6 {
                (principal, c0)
            } else {
                (other, c0 + std::f64::consts::PI)
            };
        // (equal up to a full turn: the printed sign of k is garbled in the extraction)
        assert!(
            postproc_kinematics::wrap_pi(j.tilt - b_expected).abs() < 1e-9,
            "B {} vs {}",
            j.tilt,
            b_expected
        );
        assert!(
            postproc_kinematics::wrap_pi(j.rotate - c_expected).abs() < 1e-9,
            "C {} vs {}",
            j.rotate,
            c_expected
        );
        // from the published pose as previous block, continuity returns exactly it
        let prev = Joints {
            tilt: qb,
            rotate: qc,
            ..Default::default()
        };
        let jp = m.inverse(&cl, tool, Some(&prev)).unwrap();
        assert!((jp.tilt - qb).abs() < 1e-9 && (jp.rotate - qc).abs() < 1e-9);
        // eq. 7 (m = 0) with the angles of the chosen branch
        for j in [j, jp] {
            let (qb, qc) = (j.tilt, j.rotate);
            let x = -l + l * qb.cos() + qc.cos() * p.x - qc.sin() * p.y;
            let y = qc.cos() * p.y + qc.sin() * p.x;
            let z = -qb.sin() * l + p.z;
            assert!(
                (j.x - x).abs() < 1e-9 && (j.y - y).abs() < 1e-9 && (j.z - z).abs() < 1e-9,
                "{j:?} vs ({x},{y},{z})"
            );
        }
        // eq. 5 from forward kinematics
        let f = m.forward(&j, tool);
        assert!((f.axis.into_inner() - u.normalize()).norm() < 1e-12);
    }
}

#[test]
fn both_tilt_solutions_are_offered_and_continuity_picks() {
    let m = fixture("headhead-ac");
    let cl =
        CutterLocation::new(Point3::new(10.0, 20.0, 30.0), Vector3::new(0.3, -0.4, 0.8)).unwrap();
    let sols = m.rotary_solutions(&cl.axis, 0.0).unwrap();
    assert!(
        (sols[0].0 + sols[1].0).abs() < 1e-12,
        "tilt signs opposite: {sols:?}"
    );
    for (t, c) in sols {
        assert!((m.tool_axis(t, c).into_inner() - cl.axis.into_inner()).norm() < 1e-12);
    }
    // starting from each solution as previous block, the inverse stays on it
    for (t, c) in sols {
        let prev = Joints {
            tilt: t,
            rotate: c,
            ..Default::default()
        };
        let j = m.inverse(&cl, 50.0, Some(&prev)).unwrap();
        assert!((j.tilt - t).abs() < 1e-9);
        assert!((postproc_kinematics::wrap_pi(j.rotate - c)).abs() < 1e-9);
    }
}

#[test]
fn singular_pose_holds_previous_c() {
    for name in ["xyzac-trt", "xyzbc-trt", "headhead-ac"] {
        let m = fixture(name);
        let prev = Joints {
            tilt: 0.1,
            rotate: 37f64.to_radians(),
            ..Default::default()
        };
        let cl = CutterLocation::vertical(Point3::new(5.0, -3.0, 12.0));
        let j = m.inverse(&cl, 40.0, Some(&prev)).unwrap();
        assert!(
            (j.rotate - prev.rotate).abs() < 1e-12,
            "{name}: C {}",
            j.rotate.to_degrees()
        );
        assert!(j.tilt.abs() < 1e-12);
        assert!((m.forward(&j, 40.0).tip - cl.tip).norm() < 1e-9);
    }
    // turn-mill: tool axis −Z (B = 90°) is parallel to C as well
    let m = fixture("turnmill-bc");
    let prev = Joints {
        tilt: 1.5,
        rotate: -2.0,
        ..Default::default()
    };
    let cl = CutterLocation::new(Point3::new(1.0, 2.0, 3.0), Vector3::new(0.0, 0.0, -1.0)).unwrap();
    let j = m.inverse(&cl, 40.0, Some(&prev)).unwrap();
    assert!((j.rotate + 2.0).abs() < 1e-12 && (j.tilt - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn continuous_axis_follows_and_unwinds() {
    let m = fixture("xyzbc-trt"); // C continuous
    let mut prev: Option<Joints> = None;
    let mut last_c = 0.0;
    // three full turns of the tool axis about Z at 30° tilt
    for i in 0..=360 {
        let phi = (i as f64 * 3.0).to_radians();
        let u = Vector3::new(phi.cos() * 0.5, phi.sin() * 0.5, 0.75f64.sqrt());
        let cl = CutterLocation::new(Point3::new(1.0, 2.0, 3.0), u).unwrap();
        let j = m.inverse(&cl, 0.0, prev.as_ref()).unwrap();
        if let Some(p) = prev {
            assert!(
                (j.rotate - p.rotate).abs() < 4f64.to_radians(),
                "jump at {i}"
            );
        }
        last_c = j.rotate;
        prev = Some(j);
    }
    assert!(
        last_c.abs().to_degrees() > 1000.0,
        "C wound up: {}",
        last_c.to_degrees()
    );
    let mut j = prev.unwrap();
    assert!(m.unwind(&mut j));
    assert!(j.rotate.abs() <= std::f64::consts::PI);
    assert!(
        (m.tool_axis(j.tilt, j.rotate).into_inner() - m.tool_axis(j.tilt, last_c).into_inner())
            .norm()
            < 1e-9
    );
}

#[test]
fn out_of_limits_names_axis() {
    let m = fixture("xyzac-trt");
    // tilt of 120° from Z cannot be reached with A in [−100°, 50°]
    let t = 120f64.to_radians();
    let cl = CutterLocation::new(Point3::origin(), Vector3::new(0.0, t.sin(), t.cos())).unwrap();
    match m.inverse(&cl, 0.0, None) {
        Err(KinematicsError::OutOfLimits { axis, .. }) => assert_eq!(axis, 'A'),
        other => panic!("expected limit error, got {other:?}"),
    }
    // linear travel: a tip 500 mm away violates X
    let cl = CutterLocation::vertical(Point3::new(500.0, 0.0, 0.0));
    match m.inverse(&cl, 0.0, None) {
        Err(KinematicsError::OutOfLimits { axis, value, .. }) => {
            assert_eq!(axis, 'X');
            assert!((value - 500.0).abs() < 1e-9);
        }
        other => panic!("expected limit error, got {other:?}"),
    }
}

/// LinuxCNC (2.10) `xyzac_forward_math` / `xyzbc_forward_math` with `conventional_directions`
/// (`con = ±1`), transcribed term by term; angles in degrees, tool offset 0.
fn linuxcnc_forward_con(ac: bool, j: [f64; 5], off: [f64; 3], con: f64) -> [f64; 3] {
    let (t, c) = (j[3].to_radians(), j[4].to_radians());
    if ac {
        let (dy, dz) = (off[1], off[2]);
        [
            c.cos() * j[0] - con * c.sin() * t.cos() * (j[1] - dy)
                + c.sin() * t.sin() * (j[2] - dz)
                - con * c.sin() * dy,
            con * c.sin() * j[0] + c.cos() * t.cos() * (j[1] - dy)
                - con * c.cos() * t.sin() * (j[2] - dz)
                + c.cos() * dy,
            con * t.sin() * (j[1] - dy) + t.cos() * (j[2] - dz) + dz,
        ]
    } else {
        let (dx, dz) = (off[0], off[2]);
        [
            c.cos() * t.cos() * (j[0] - dx) - con * c.sin() * j[1]
                + con * c.cos() * t.sin() * (j[2] - dz)
                + c.cos() * dx,
            con * c.sin() * t.cos() * (j[0] - dx)
                + c.cos() * j[1]
                + c.sin() * t.sin() * (j[2] - dz)
                + con * c.sin() * dx,
            -con * t.sin() * (j[0] - dx) + t.cos() * (j[2] - dz) + dz,
        ]
    }
}

#[test]
fn conventional_directions_match_linuxcnc_both_ways() {
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    for (name, ac, off) in [
        ("xyzac-trt", true, [0.0, 20.0, 10.0]),
        ("xyzbc-trt", false, [-20.0, 0.0, -15.0]),
    ] {
        for conventional in [false, true] {
            let text = std::fs::read_to_string(format!(
                "{}/../../fixtures/machines/{name}.toml",
                env!("CARGO_MANIFEST_DIR")
            ))
            .unwrap()
            .replace(
                "conventional_directions = false",
                &format!("conventional_directions = {conventional}"),
            );
            let m = Machine::from_toml_str(&text, "m.toml").unwrap();
            let con = if conventional { 1.0 } else { -1.0 };
            for _ in 0..100 {
                let j = [
                    rng.random_range(-150.0..150.0),
                    rng.random_range(-80.0..80.0),
                    rng.random_range(-100.0..100.0),
                    rng.random_range(-100.0..50.0),
                    rng.random_range(-360.0..360.0),
                ];
                let w = linuxcnc_forward_con(ac, j, off, con);
                let joints = Joints {
                    x: j[0],
                    y: j[1],
                    z: j[2],
                    tilt: j[3].to_radians(),
                    rotate: j[4].to_radians(),
                };
                let ours = m.forward(&joints, 0.0).tip;
                for k in 0..3 {
                    assert!(
                        (w[k] - ours[k]).abs() < 1e-9,
                        "{name} con={con}: {w:?} vs {ours:?}"
                    );
                }
            }
        }
    }
}

/// Which tool axes a machine can present: xyzac-trt tilts A from −100° to 50°, so of the two
/// solutions (A, C) and (−A, C + 180°) one reaches every axis up to 100° from the C axis and
/// none beyond; narrowed to A ∈ [−5°, 5°], only a 5° cone is left.
#[test]
fn reachable_orientations_follow_the_tilt_travel() {
    let tilted = |deg: f64, az: f64| {
        let (t, a) = (deg.to_radians(), az.to_radians());
        cam_core::UnitVector3::new_normalize(Vector3::new(
            t.sin() * a.cos(),
            t.sin() * a.sin(),
            t.cos(),
        ))
    };
    let m = fixture("xyzac-trt");
    for az in [0.0, 70.0, 180.0, 250.0] {
        for deg in [0.0, 30.0, 60.0, 99.0] {
            assert!(m.orientation_reachable(&tilted(deg, az)), "{deg}° at {az}°");
        }
        assert!(
            !m.orientation_reachable(&tilted(101.0, az)),
            "101° at {az}°"
        );
    }
    let text = std::fs::read_to_string(format!(
        "{}/../../fixtures/machines/xyzac-trt.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let (a, c) = (
        text.find("[axes.A]").unwrap(),
        text.find("[axes.C]").unwrap(),
    );
    let narrow = format!(
        "{}{}{}",
        &text[..a],
        text[a..c]
            .replace("min = -100.0", "min = -5.0")
            .replace("max = 50.0", "max = 5.0"),
        &text[c..]
    );
    let m = Machine::from_toml_str(&narrow, "narrow.toml").unwrap();
    assert!(m.orientation_reachable(&tilted(4.9, 123.0)));
    assert!(!m.orientation_reachable(&tilted(5.2, 123.0)));
}
