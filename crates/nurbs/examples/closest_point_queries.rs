//! Closest-point queries on the reference benchmark surface, verified against a dense search.
//!
//! Reference surface (issue 2, "Benchmark and targets"): bicubic, 12 × 12 control points
//! `P(i,j) = (x, y, 8·sin(x/17)·cos(y/23) + 0.002·x·y)` with `x = 100·i/11`, `y = 100·j/11`
//! (mm), clamped uniform knots on [0, 1], unit weights. Queries: `S(u,v) + (0, 0, d)` with
//! `u, v ~ U[0,1]`, `d ~ U[−5, 5]` mm from ChaCha8 seeded with `SEED`.
//!
//! ```text
//! cargo run --release -p nurbs --example closest_point_queries -- OUT.csv [COUNT]
//! ```
//! writes `x,y,z,u,v,distance` for each query (COUNT defaults to 20 000), then checks every
//! answer against an independent dense search: a 121 × 121 grid of the surface evaluated with
//! `NurbsSurface::point`, polished by a bound-constrained Newton iteration (written here on
//! `NurbsSurface::derivs2`) from the grid's best local minima. It prints the largest excess
//! of our distance over the best the dense search found (target ≤ 1e-9 mm) and the number of
//! answers on the domain boundary, and checks that warm-started queries (hint = previous
//! answer) give the same distances.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;

use nalgebra::Vector3;
use nurbs::closest::SurfaceProjector;
use nurbs::NurbsSurface;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "../benches/common/reference.rs"]
mod reference;
use reference::{reference_surface, SEED};

/// Bound-constrained Newton on [0,1]² (independent of the library's engine).
fn polish(s: &NurbsSurface, q: &Vector3<f64>, mut u: f64, mut v: f64) -> (f64, f64, f64) {
    let dist = |u: f64, v: f64| (s.point(u, v) - q).norm();
    for _ in 0..100 {
        let d = s.derivs2(u, v);
        let r = d.p - q;
        let g = [r.dot(&d.su), r.dot(&d.sv)];
        let h = [
            [
                d.su.dot(&d.su) + r.dot(&d.suu),
                d.su.dot(&d.sv) + r.dot(&d.suv),
            ],
            [
                d.su.dot(&d.sv) + r.dot(&d.suv),
                d.sv.dot(&d.sv) + r.dot(&d.svv),
            ],
        ];
        let at = |x: f64, gx: f64| (x <= 0.0 && gx > 0.0) || (x >= 1.0 && gx < 0.0);
        let (fu, fv) = (at(u, g[0]), at(v, g[1]));
        let (du, dv) = match (fu, fv) {
            (true, true) => break,
            (true, false) => (0.0, -g[1] / h[1][1].max(d.sv.norm_squared())),
            (false, true) => (-g[0] / h[0][0].max(d.su.norm_squared()), 0.0),
            (false, false) => {
                let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
                if det > 0.0 && h[0][0] > 0.0 {
                    (
                        (-g[0] * h[1][1] + g[1] * h[0][1]) / det,
                        (-g[1] * h[0][0] + g[0] * h[1][0]) / det,
                    )
                } else {
                    let s2 = d.su.norm_squared() + d.sv.norm_squared();
                    (-g[0] / s2, -g[1] / s2)
                }
            }
        };
        let f0 = dist(u, v);
        let mut t = 1.0;
        let mut moved = false;
        for _ in 0..30 {
            let (un, vn) = ((u + t * du).clamp(0.0, 1.0), (v + t * dv).clamp(0.0, 1.0));
            if dist(un, vn) <= f0 {
                moved = (un - u).abs() + (vn - v).abs() > 1e-17;
                u = un;
                v = vn;
                break;
            }
            t *= 0.5;
        }
        if !moved {
            break;
        }
    }
    (u, v, dist(u, v))
}

/// Dense search: grid minima polished.
fn dense(s: &NurbsSurface, q: &Vector3<f64>, grid: &[Vec<Vector3<f64>>]) -> f64 {
    let n = grid.len();
    let d: Vec<Vec<f64>> = grid
        .iter()
        .map(|row| row.iter().map(|p| (p - q).norm()).collect())
        .collect();
    let mut cands: Vec<(f64, usize, usize)> = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let x = d[i][j];
            let mut local = true;
            for (di, dj) in [
                (-1i64, 0i64),
                (1, 0),
                (0, -1),
                (0, 1),
                (-1, -1),
                (1, 1),
                (-1, 1),
                (1, -1),
            ] {
                let (a, b) = (i as i64 + di, j as i64 + dj);
                if a >= 0
                    && b >= 0
                    && (a as usize) < n
                    && (b as usize) < n
                    && d[a as usize][b as usize] < x
                {
                    local = false;
                }
            }
            if local {
                cands.push((x, i, j));
            }
        }
    }
    cands.sort_by(|a, b| a.0.total_cmp(&b.0));
    let h = 1.0 / (n - 1) as f64;
    cands
        .iter()
        .take(4)
        .map(|&(_, i, j)| polish(s, q, i as f64 * h, j as f64 * h).2)
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "closest_point_queries.csv".into());
    let count: usize = args
        .get(2)
        .map_or(20_000, |c| c.parse().expect("COUNT must be an integer"));
    let surface = reference_surface();
    let projector = SurfaceProjector::new(&surface);
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let queries: Vec<Vector3<f64>> = (0..count)
        .map(|_| {
            let u: f64 = rng.random_range(0.0..=1.0);
            let v: f64 = rng.random_range(0.0..=1.0);
            let d: f64 = rng.random_range(-5.0..=5.0);
            surface.point(u, v) + Vector3::new(0.0, 0.0, d)
        })
        .collect();
    let t0 = std::time::Instant::now();
    let answers: Vec<_> = queries.iter().map(|q| projector.closest_point(q)).collect();
    let elapsed = t0.elapsed();

    let tmp = format!("{out}.tmp");
    {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&tmp).expect("create output"));
        writeln!(w, "x,y,z,u,v,distance").unwrap();
        for (q, a) in queries.iter().zip(&answers) {
            writeln!(
                w,
                "{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e}",
                q.x, q.y, q.z, a.u, a.v, a.distance
            )
            .unwrap();
        }
        w.flush().unwrap();
    }
    std::fs::rename(&tmp, &out).expect("rename output");

    let n = 121;
    let grid: Vec<Vec<Vector3<f64>>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| surface.point(i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64))
                .collect()
        })
        .collect();
    let mut worst: f64 = 0.0;
    let mut worst_at = 0;
    let mut boundary = 0;
    for (k, (q, a)) in queries.iter().zip(&answers).enumerate() {
        let best = dense(&surface, q, &grid);
        let excess = a.distance - best;
        if excess > worst {
            worst = excess;
            worst_at = k;
        }
        if a.on_boundary {
            boundary += 1;
        }
    }
    // Warm starts (hint = previous answer) must give the same answers.
    let mut hint = None;
    let mut warm_diff: f64 = 0.0;
    for (q, a) in queries.iter().zip(&answers) {
        let w = projector.closest_point_with_hint(q, hint);
        hint = Some((w.u, w.v));
        warm_diff = warm_diff.max((w.distance - a.distance).abs());
    }
    println!("queries: {count}, written to {out}");
    println!(
        "mean time per cold query: {:.0} ns",
        elapsed.as_nanos() as f64 / count as f64
    );
    println!("largest excess over the dense search: {worst:.3e} mm (query {worst_at})");
    println!("answers on the domain boundary: {boundary}");
    println!("largest |warm − cold| distance difference: {warm_diff:.3e} mm");
    if worst > 1e-9 || warm_diff > 1e-9 {
        println!("FAIL: excess or warm/cold difference above 1e-9 mm");
        std::process::exit(1);
    }
}
