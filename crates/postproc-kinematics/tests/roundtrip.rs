//! forward(inverse(cl)) = cl over random poses within the limits, for every fixture machine.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::CutterLocation;
use postproc_kinematics::{AxisId, Joints, Machine, RotaryMode};
use proptest::prelude::*;

const MACHINES: [&str; 4] = ["xyzac-trt", "xyzbc-trt", "turnmill-bc", "headhead-ac"];

fn machines() -> &'static [Machine] {
    static M: std::sync::OnceLock<Vec<Machine>> = std::sync::OnceLock::new();
    M.get_or_init(|| {
        MACHINES
            .iter()
            .map(|name| {
                let path = format!(
                    "{}/../../fixtures/machines/{name}.toml",
                    env!("CARGO_MANIFEST_DIR")
                );
                Machine::from_file(&path).unwrap()
            })
            .collect()
    })
}

/// A random joint pose strictly inside the limits (rotary axes limited to ±400° where they are
/// continuous or wider), mapped from unit-cube coordinates.
fn pose(m: &Machine, t: [f64; 5]) -> Joints {
    let mut j = Joints::default();
    for (i, a) in AxisId::ALL.iter().enumerate() {
        let (lo, hi) = match m.axis(*a).mode {
            RotaryMode::Continuous => (-400f64.to_radians(), 400f64.to_radians()),
            RotaryMode::Limited { min, max } => {
                (min.max(-400f64.to_radians()), max.min(400f64.to_radians()))
            }
        };
        // keep a 1 % margin so the inverse finds the pose inside the limits
        let (lo, hi) = (lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo));
        j.set(*a, lo + t[i] * (hi - lo));
    }
    j
}

fn close(a: &CutterLocation, b: &CutterLocation) -> (f64, f64) {
    let dp = (a.tip - b.tip).norm();
    let da = a.axis.dot(&b.axis).clamp(-1.0, 1.0).acos();
    let da = if da.is_nan() { 0.0 } else { da };
    // acos is ill-conditioned near 1: use the chord instead for the angle estimate
    let chord = (a.axis.into_inner() - b.axis.into_inner()).norm();
    (dp, da.min(chord * 1.0000001))
}

proptest! {
    #[test]
    fn forward_inverse_round_trip(t in prop::array::uniform5(0.0f64..1.0), tl in 0.0f64..150.0) {
        for (which, m) in machines().iter().enumerate() {
            let j = pose(m, t);
            let cl = m.forward(&j, tl);
            // inverse from the pose itself as previous block, and from home
            for prev in [Some(j), None] {
                match m.inverse(&cl, tl, prev.as_ref()) {
                    Ok(k) => {
                        let back = m.forward(&k, tl);
                        let (dp, da) = close(&cl, &back);
                        prop_assert!(dp < 1e-9, "{}: tip error {dp} mm", MACHINES[which]);
                        prop_assert!(da < 1e-9, "{}: axis error {da} rad", MACHINES[which]);
                        prop_assert!(m.check_limits(&k, 1e-9).is_ok());
                        if prev.is_some() {
                            // continuity: with the pose itself as previous block, it is found again
                            prop_assert!((k.tilt - j.tilt).abs() < 1e-7 && (k.rotate - j.rotate).abs() < 1e-7,
                                "{}: {:?} vs {:?}", MACHINES[which], k, j);
                        }
                    }
                    Err(e) => prop_assert!(prev.is_none(), "{}: inverse failed from its own pose: {e}", MACHINES[which]),
                }
            }
        }
    }

    /// Arbitrary cutter locations: a solution that round-trips, or a typed error.
    #[test]
    fn arbitrary_cl_round_trips_or_errors(p in prop::array::uniform3(-300.0f64..300.0), a in prop::array::uniform3(-1.0f64..1.0), tl in 0.0f64..150.0) {
        let axis = nalgebra::Vector3::new(a[0], a[1], a[2]);
        prop_assume!(axis.norm() > 1e-3);
        let cl = CutterLocation::new(nalgebra::Point3::new(p[0], p[1], p[2]), axis).unwrap();
        for m in machines() {
            if let Ok(k) = m.inverse(&cl, tl, None) {
                let (dp, da) = close(&cl, &m.forward(&k, tl));
                prop_assert!(dp < 1e-9 && da < 1e-9);
                prop_assert!(m.check_limits(&k, 1e-9).is_ok());
            }
        }
    }
}
