//! The reference surface and query seed of issue 2's distance benchmarks, shared by
//! `benches/nurbs.rs` and `examples/closest_point_queries.rs` so both run exactly the same
//! work: bicubic, 12 × 12 control points `P(i,j) = (x, y, 8·sin(x/17)·cos(y/23) + 0.002·x·y)`,
//! `x = 100·i/11`, `y = 100·j/11` (mm), clamped uniform knots on [0, 1], unit weights.

use nalgebra::Vector3;
use nurbs::NurbsSurface;

/// Seed of the ChaCha8 query generator.
pub const SEED: u64 = 20_240_601;

/// The reference surface.
pub fn reference_surface() -> NurbsSurface {
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..12)
        .map(|i| {
            (0..12)
                .map(|j| {
                    let x = 100.0 * i as f64 / 11.0;
                    let y = 100.0 * j as f64 / 11.0;
                    Vector3::new(
                        x,
                        y,
                        8.0 * (x / 17.0).sin() * (y / 23.0).cos() + 0.002 * x * y,
                    )
                })
                .collect()
        })
        .collect();
    let knots = nurbs::KnotVector::clamped_uniform(3, 12)
        .expect("12 control points of degree 3 form a valid clamped knot vector")
        .knots()
        .to_vec();
    NurbsSurface::new(3, 3, knots.clone(), knots, ctrl, None)
        .expect("the reference control net is valid")
}
