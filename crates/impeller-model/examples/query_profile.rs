//! Profiling aid for the point queries of the default impeller: prints the structure of the
//! blade-side query and times, in a loop, cold blade-side queries (no hint), warm ones (a
//! path 1 mm off the side, each hinted with the previous answer) and hub queries. Each figure
//! is the best of `ROUNDS` rounds (the least disturbed one on a shared machine).
//!
//! `cargo run --release -p impeller-model --example query_profile [REPS] [warm]` (`warm`:
//! mostly the warm blade queries); under `perf record` it shows where a query spends its
//! time.

use impeller_model::query::blade_side_distance;
use impeller_model::{fixtures, Side};
use nalgebra::Vector3;
use std::hint::black_box;
use std::time::Instant;

const ROUNDS: usize = 10;

/// Best time per call (µs) of `f` run `reps` times over `n` calls per run.
fn best_of(reps: usize, n: usize, mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..ROUNDS {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        best = best.min(t.elapsed().as_secs_f64() * 1e6 / (reps * n) as f64);
    }
    best
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let imp = fixtures::default_impeller()?;
    let blade = imp.main().blade();
    let s = blade.suction();
    println!(
        "suction side: degree ({}, {}), control net {}x{}, rational {}",
        s.degree_u(),
        s.degree_v(),
        s.knots_u().knots().len() - s.degree_u() - 1,
        s.knots_v().knots().len() - s.degree_v() - 1,
        s.is_rational()
    );
    let t = Instant::now();
    let built = nurbs::closest::SurfaceProjector::new(s);
    println!(
        "projector: {} leaves, built in {:.2} ms",
        built.leaf_count(),
        t.elapsed().as_secs_f64() * 1e3
    );
    blade.projector(Side::Suction);
    // Deterministic points within 3 mm of the side (a simple LCG).
    let mut seed = 7u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<Vector3<f64>> = (0..256)
        .map(|_| {
            let (u, v) = (rnd(), rnd());
            let n = blade
                .outward_normal(Side::Suction, u, v)
                .unwrap_or(Vector3::z());
            s.point(u, v) + n * (rnd() * 6.0 - 3.0)
        })
        .collect();
    // A path 1 mm off the side, 0.2 % of u apart (as the criterion bench).
    let path: Vec<Vector3<f64>> = (0..400)
        .map(|k| {
            let (u, v) = (0.1 + 0.002 * k as f64, 0.4 + 0.0005 * k as f64);
            let n = blade
                .outward_normal(Side::Suction, u, v)
                .unwrap_or(Vector3::z());
            s.point(u, v) + n
        })
        .collect();
    let reps = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20usize);
    let only_warm = std::env::args().nth(2).as_deref() == Some("warm");
    let cold = best_of(if only_warm { 1 } else { reps }, pts.len(), || {
        for p in &pts {
            black_box(blade_side_distance(blade, Side::Suction, p, None));
        }
    });
    println!("blade cold: {cold:.3} us");
    let warm = best_of(reps, path.len(), || {
        let mut prev = None;
        for p in &path {
            let (sp, d) = blade_side_distance(blade, Side::Suction, p, prev);
            prev = Some((sp.u, sp.v));
            black_box(d);
        }
    });
    println!("blade warm: {warm:.3} us");
    // `query_profile REPS warm` times the warm blade queries only (for `perf record`).
    if std::env::args().nth(2).as_deref() == Some("warm") {
        return Ok(());
    }
    let hub = best_of(reps * 10, pts.len(), || {
        for p in &pts {
            black_box(imp.hub().signed_distance(p));
        }
    });
    println!("hub: {hub:.3} us");
    Ok(())
}
