//! Property tests: interval subtraction is set difference; the closed-form ray–cutter
//! interval agrees with point membership of the solid of revolution.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Cutter, CutterShape};
use machining_sim::tool_solid::{RayLocal, RevolvedSolid};
use machining_sim::Segments;
use proptest::prelude::*;

fn segments_strategy() -> impl Strategy<Value = Vec<[f32; 2]>> {
    prop::collection::vec((0.0f32..100.0, 0.1f32..5.0), 0..6).prop_map(|v| {
        let mut starts: Vec<(f32, f32)> = v;
        starts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut out: Vec<[f32; 2]> = Vec::new();
        for (s, l) in starts {
            let s = out.last().map_or(s, |p| s.max(p[1] + 0.5));
            out.push([s, s + l]);
        }
        out
    })
}

fn shape_strategy() -> impl Strategy<Value = CutterShape> {
    prop_oneof![
        (0.5f64..4.0).prop_map(|radius| CutterShape::FlatEnd { radius }),
        (0.5f64..4.0).prop_map(|radius| CutterShape::BallEnd { radius }),
        (1.0f64..4.0, 0.1f64..0.9).prop_map(|(radius, f)| CutterShape::BullNose {
            radius,
            corner_radius: f * radius
        }),
        (0.5f64..3.0, 0.0f64..0.3).prop_map(|(ball_radius, half_angle)| {
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            }
        }),
    ]
}

proptest! {
    #[test]
    fn subtract_is_set_difference(segs in segments_strategy(), a in -5.0f64..110.0, len in 0.0f64..40.0, probes in prop::collection::vec(-5.0f64..140.0, 32)) {
        let before = Segments::from_slice(&segs);
        let mut after = before.clone();
        let b = a + len;
        let removed = after.subtract(a, b);
        let mut expect = 0.0;
        for s in &segs {
            let lo = f64::from(s[0]).max(a);
            let hi = f64::from(s[1]).min(b);
            if hi > lo { expect += hi - lo; }
        }
        prop_assert!((removed - expect).abs() < 1e-4, "{removed} vs {expect}");
        // Sorted, disjoint, non-empty intervals.
        for w in after.as_slice().windows(2) {
            prop_assert!(w[0][1] <= w[1][0]);
        }
        for p in probes {
            // Skip points within f32 rounding of an end point.
            let near = segs.iter().flat_map(|s| [f64::from(s[0]), f64::from(s[1])])
                .chain([a, b]).any(|e| (e - p).abs() < 1e-3);
            if near { continue; }
            let want = before.contains(p) && !(p >= a && p <= b);
            prop_assert_eq!(after.contains(p), want, "p = {}", p);
        }
    }

    #[test]
    fn ray_interval_matches_membership(shape in shape_strategy(), ax in -1.0f64..1.0, ay in -1.0f64..1.0, az in 0.05f64..1.0, d in 0usize..3, du in -5.0f64..5.0, dv in -5.0f64..5.0) {
        let n = (ax * ax + ay * ay + az * az).sqrt();
        let axis = [ax / n, ay / n, az / n];
        let cutter = Cutter::new("t", shape, 8.0, 1.0, 30.0).unwrap();
        let solid = RevolvedSolid::cutting_part(&cutter);
        let rl = RayLocal::new(d, du, dv, &axis);
        let member = |l: f64| {
            let mut q = [0.0; 3];
            q[d] = l;
            q[(d + 1) % 3] = du;
            q[(d + 2) % 3] = dv;
            let h = q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2];
            let r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - h * h;
            solid.contains_local(h, r2.max(0.0).sqrt())
        };
        match solid.ray_hull(&rl) {
            Some((s, e)) => {
                prop_assert!(e >= s);
                if e - s > 1e-3 {
                    prop_assert!(member(0.5 * (s + e)));
                    prop_assert!(member(s + 1e-4) && member(e - 1e-4));
                }
                prop_assert!(!member(s - 1e-4) && !member(e + 1e-4));
            }
            None => {
                for k in 0..200 {
                    let l = -30.0 + 60.0 * f64::from(k) / 200.0;
                    prop_assert!(!member(l), "missed λ = {l}");
                }
            }
        }
    }
}
