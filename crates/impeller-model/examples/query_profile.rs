//! Profiling aid for the point queries of the default impeller: prints the structure of the
//! blade-side and hub queries and times cold / warm blade-side and hub queries in a loop
//! (run in release: `cargo run --release -p impeller-model --example query_profile`).

use impeller_model::query::blade_side_distance;
use impeller_model::{fixtures, Side};
use nalgebra::Vector3;
use std::hint::black_box;
use std::time::Instant;

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
    let proj = blade.projector(Side::Suction);
    println!("leaves {}", proj.leaf_count());
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
    let reps = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200usize);
    let only_hub = std::env::args().nth(2).is_some();
    let t = Instant::now();
    for _ in 0..if only_hub { 0 } else { reps } {
        for p in &pts {
            black_box(blade_side_distance(blade, Side::Suction, p, None));
        }
    }
    let n = (reps * pts.len()) as f64;
    println!("blade cold: {:.3} us", t.elapsed().as_secs_f64() * 1e6 / n);
    let only_hub = std::env::args().nth(2).is_some();
    let t = Instant::now();
    for _ in 0..if only_hub { 0 } else { reps } {
        for p in &pts {
            black_box(blade_side_distance(blade, Side::Suction, p, None));
        }
    }
    let n = (reps * pts.len()) as f64;
    println!("blade cold: {:.3} us", t.elapsed().as_secs_f64() * 1e6 / n);
    // Best of 20 rounds (the machine is shared: the minimum is the least disturbed figure).
    let mut best = f64::INFINITY;
    for _ in 0..20 {
        let t = Instant::now();
        for _ in 0..reps {
            for p in &pts {
                black_box(imp.hub().signed_distance(p));
            }
        }
        best = best.min(t.elapsed().as_secs_f64() * 1e6 / n);
    }
    println!("hub: {best:.3} us (best of 20 rounds)");
    Ok(())
}
