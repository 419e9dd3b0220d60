//! The swept-segment kernel ([`machining_sim::swept`]) against the limit of densely sampled
//! positions, a grazing ray, a zero-length segment, and a slot cut through `simulate`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath};
use machining_sim::swept::SweptSolid;
use machining_sim::tool_solid::{RayLocal, RevolvedSolid};
use machining_sim::{cut, BoxStock, SimOptions, TriDexel};
use proptest::prelude::*;

/// The interval at fraction `s` (positions at tip `−s·sweep`), in the end tip's λ.
fn at(
    solid: &RevolvedSolid,
    d: usize,
    (du, dv): (f64, f64),
    axis: &[f64; 3],
    sweep: &[f64; 3],
    s: f64,
) -> Option<(f64, f64)> {
    let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
    let rl = RayLocal::new(d, du + s * sweep[ua], dv + s * sweep[va], axis);
    solid
        .ray_hull(&rl)
        .map(|(a, b)| (a - s * sweep[d], b - s * sweep[d]))
}

/// The limit of the union of positions: positions every 10⁻⁴ mm, then every 10⁻⁷ mm
/// around the best one for each end (under-read at a kink ≤ slope × 10⁻⁷ mm).
fn dense(
    solid: &RevolvedSolid,
    d: usize,
    off: (f64, f64),
    axis: &[f64; 3],
    sweep: &[f64; 3],
) -> Option<(f64, f64)> {
    let len = sweep.iter().map(|x| x * x).sum::<f64>().sqrt();
    let n = ((len / 1e-4).ceil() as usize).max(1);
    let (mut lo, mut hi) = ((f64::INFINITY, 0usize), (f64::NEG_INFINITY, 0usize));
    for k in 0..=n {
        if let Some((a, b)) = at(solid, d, off, axis, sweep, k as f64 / n as f64) {
            if a < lo.0 {
                lo = (a, k);
            }
            if b > hi.0 {
                hi = (b, k);
            }
        }
    }
    if lo.0 > hi.0 {
        return None;
    }
    let refine = |k: usize, f: &dyn Fn((f64, f64)) -> f64| -> f64 {
        let (s0, s1) = (
            k.saturating_sub(1) as f64 / n as f64,
            (k + 1).min(n) as f64 / n as f64,
        );
        let m = 2000;
        let mut best = f64::INFINITY;
        for j in 0..=m {
            let s = s0 + (s1 - s0) * j as f64 / m as f64;
            if let Some(iv) = at(solid, d, off, axis, sweep, s) {
                best = best.min(f(iv));
            }
        }
        best
    };
    let l = refine(lo.1, &|iv| iv.0).min(lo.0);
    let h = -refine(hi.1, &|iv| -iv.1).min(-hi.0);
    Some((l, h))
}

fn shape_strategy() -> impl Strategy<Value = CutterShape> {
    prop_oneof![
        (0.5f64..3.0).prop_map(|radius| CutterShape::FlatEnd { radius }),
        (0.5f64..3.0).prop_map(|radius| CutterShape::BallEnd { radius }),
        (0.5f64..2.0, 0.0f64..0.3).prop_map(|(ball_radius, half_angle)| {
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            }
        }),
        (0.3f64..2.0, 0.0f64..0.3).prop_map(|(tip_radius, half_angle)| {
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            }
        }),
    ]
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (n > 0.2).then(|| v.map(|x| x / n))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The kernel's interval equals the dense-sampled limit within 10⁻⁶ mm.
    #[test]
    fn kernel_equals_the_dense_sampled_limit(
        shape in shape_strategy(),
        axis in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        sweep in (-2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0),
        axial in prop::bool::ANY,
        rays in prop::collection::vec((0usize..3, -1.0f64..1.0, -1.0f64..1.0), 6),
    ) {
        let Some(axis) = unit([axis.0, axis.1, axis.2]) else { return Ok(()) };
        let mut sweep = [sweep.0, sweep.1, sweep.2];
        if axial {
            // A move with no component along the axis (a face sweeps a plane).
            let p: f64 = (0..3).map(|k| sweep[k] * axis[k]).sum();
            sweep = [0, 1, 2].map(|k| sweep[k] - p * axis[k]);
        }
        let cutter = Cutter::new("t", shape, 4.0, 1.0, 30.0).unwrap();
        let solid = RevolvedSolid::cutting_part(&cutter);
        let kernel = SweptSolid::new(&solid).unwrap();
        let reach = solid.r_max() + sweep.iter().map(|x| x.abs()).sum::<f64>();
        for (d, a, b) in rays {
            let off = (a * reach, b * reach);
            let got = kernel.ray_interval(d, off.0, off.1, &axis, &sweep);
            let want = dense(&solid, d, off, &axis, &sweep);
            match (got, want) {
                (Some(g), Some(w)) => prop_assert!(
                    (g.0 - w.0).abs() <= 1e-6 && (g.1 - w.1).abs() <= 1e-6,
                    "{shape:?} d {d} off {off:?} axis {axis:?} sweep {sweep:?}: {g:?} vs {w:?}"
                ),
                (None, None) => {}
                // A graze the samples step over.
                (Some(g), None) => prop_assert!(g.1 - g.0 < 0.05, "{g:?}"),
                (None, Some(w)) => prop_assert!(false, "missed {w:?}"),
            }
        }
    }

    /// A zero-length segment is the single position, bit for bit.
    #[test]
    fn zero_length_segment_is_the_position(
        shape in shape_strategy(),
        axis in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        ray in (0usize..3, -3.0f64..3.0, -3.0f64..3.0),
    ) {
        let Some(axis) = unit([axis.0, axis.1, axis.2]) else { return Ok(()) };
        let cutter = Cutter::new("t", shape, 4.0, 1.0, 30.0).unwrap();
        let solid = RevolvedSolid::cutting_part(&cutter);
        let kernel = SweptSolid::new(&solid).unwrap();
        let (d, du, dv) = ray;
        let got = kernel.ray_interval(d, du, dv, &axis, &[0.0; 3]);
        prop_assert_eq!(got, solid.ray_hull(&RayLocal::new(d, du, dv, &axis)));
    }
}

/// A ray tangent to the capsule's side meets it in one point; just inside, in a short
/// chord of the predicted length; just outside, not at all.
#[test]
fn grazing_ray() {
    let r = 1.5;
    let cutter = Cutter::new("b", CutterShape::BallEnd { radius: r }, 4.0, 1.0, 30.0).unwrap();
    let solid = RevolvedSolid::cutting_part(&cutter);
    let k = SweptSolid::new(&solid).unwrap();
    let (axis, sweep) = ([0.0, 0.0, 1.0], [5.0, 0.0, 0.0]);
    // Rays along z at x = tip − 2.5 (the segment's middle), y = r: tangent to the
    // capsule's side at the ball's equator, then along the flutes' cylinder side up to the
    // flute length (4 mm); just inside, the chord starts below the equator.
    let g = k.ray_interval(2, -2.5, r, &axis, &sweep).unwrap();
    assert!((g.0 - r).abs() < 1e-7 && (g.1 - 4.0).abs() < 1e-12, "{g:?}");
    assert!(k.ray_interval(2, -2.5, r + 1e-9, &axis, &sweep).is_none());
    let eps = 1e-6;
    let (a, _) = k.ray_interval(2, -2.5, r - eps, &axis, &sweep).unwrap();
    let want = r - (r * r - (r - eps) * (r - eps)).sqrt();
    assert!((a - want).abs() < 1e-9, "{a} vs {want}");
    // A ray along y at the tip's height (du: z, dv: x) under the segment's middle touches
    // the capsule's lowest line in one point.
    let g = k.ray_interval(1, 0.0, -2.5, &axis, &sweep).unwrap();
    assert!(g.0.abs() < 1e-7 && g.1.abs() < 1e-7, "{g:?}");
}

/// A ball-end slot cut through `simulate`: every ray along z near the slot's centre line
/// ends exactly on the capsule, `z + R − √(R² − (y − y₀)²)`, between and at the positions
/// the sampled union used. The sampled union left scallops up to the sweep tolerance
/// between positions (0.02 mm here: positions every ~0.7 mm).
#[test]
fn ball_slot_floor_is_exact() {
    let cell = 0.1;
    let blank = BoxStock::new([0.0, 0.0, 0.0], [20.0, 10.0, 10.0]).unwrap();
    let mut stock = TriDexel::from_shape(&blank, cell).unwrap();
    let cutter = Cutter::new("b3", CutterShape::BallEnd { radius: 3.0 }, 20.0, 3.0, 40.0).unwrap();
    let mut path = ToolPath::new("slot", "b3");
    let (y, z) = (5.0, 8.0);
    let mv = |kind, x: f64, z: f64| Move {
        kind,
        cl: CutterLocation::vertical(Point3::new(x, y, z)),
        feed_mm_per_min: None,
    };
    path.moves.push(mv(MoveKind::Rapid, -5.0, 15.0));
    path.moves.push(mv(MoveKind::Plunge, -5.0, z));
    path.moves.push(mv(MoveKind::Feed, 25.0, z));
    path.moves.push(mv(MoveKind::Retract, 25.0, 15.0));
    let opts = SimOptions {
        sweep_tol_mm: Some(0.02),
        ..SimOptions::default()
    };
    cut(&mut stock, None, &[(cutter, path)], &opts).unwrap();
    let g = stock.grid(2);
    let (nu, nv) = g.size();
    let mut checked = 0;
    for j in 0..nv {
        for i in 0..nu {
            let (u, v) = g.ray_uv(i, j);
            if (v - y).abs() > 1.0 || !(2.0..18.0).contains(&u) {
                continue;
            }
            let want = z + 3.0 - (9.0 - (v - y) * (v - y)).sqrt();
            let top = g.ray(i, j).as_slice().last().map(|s| s[1]).unwrap();
            assert!(
                (f64::from(top) - want).abs() < 1e-5,
                "ray at ({u}, {v}): floor {top} vs {want}"
            );
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked}");
}
