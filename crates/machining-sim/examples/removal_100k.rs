//! One-off measurement: 100,000 moves of a five-axis tapered ball end on the 77 mm fixture's
//! blank (Ø79 × 44 mm) at 0.1 mm. Run in release with peak memory:
//! `/usr/bin/time -v cargo run --release -p machining-sim --example removal_100k -- 0.1 100000`
//! A third argument `design` runs the full `simulate` against the fixture impeller (design
//! collisions through parry, overcut/residual maps) instead of the removal alone.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use impeller_model::fixtures::default_impeller;
use machining_sim::synthetic::{workload_cutter, zigzag_path};
use machining_sim::{
    blank_of, cut, simulate, ImpellerDesign, ImpellerSampling, SimOptions, TriDexel,
};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let h: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0.1);
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let imp = default_impeller().unwrap();
    let blank = blank_of(&imp).unwrap();
    let t = Instant::now();
    let mut stock = TriDexel::from_shape(&blank, h).unwrap();
    let init_s = t.elapsed().as_secs_f64();
    let [nx, ny, nz] = stock.cells();
    println!(
        "stock: cell {h} mm, lattice {nx}×{ny}×{nz}, rays {}, memory {:.1} MB, init {:.2} s, volume {:.0} mm³",
        stock.ray_count(),
        stock.memory_bytes() as f64 / 1e6,
        init_s,
        stock.volume()
    );
    let r = imp.stock().max_radius();
    let top = imp.stock().z_range().1;
    let path = zigzag_path(n, r - 1.0, top);
    let cutter = workload_cutter();
    let opts = SimOptions {
        progress: true,
        ..SimOptions::default()
    };
    let with_design = args.get(3).is_some_and(|a| a == "design");
    let t = Instant::now();
    let ops = [(cutter, path)];
    let out = if with_design {
        let design = ImpellerDesign::new(&imp, ImpellerSampling::default()).unwrap();
        let rep = simulate(&mut stock, &design, &ops, &opts).unwrap();
        println!(
            "simulate: max_overcut_mm {:.3}, max_residual_mm {:.3}, collisions {}, \
             design collision {:.2} s, measure {:.2} s",
            rep.metrics.max_overcut_mm,
            rep.metrics.max_residual_mm,
            rep.metrics.collisions,
            rep.stats.design_collision_ms / 1e3,
            rep.stats.measure_ms / 1e3
        );
        machining_sim::CutOutcome {
            collisions: rep.collisions,
            stats: rep.stats,
        }
    } else {
        cut(&mut stock, None, &ops, &opts).unwrap()
    };
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{} moves, {} positions, {:.2} s wall ({:.1} µs/move), removed {:.0} mm³, \
         colliding moves {}, memory after {:.1} MB",
        out.stats.moves,
        out.stats.positions,
        dt,
        dt * 1e6 / out.stats.moves as f64,
        out.stats.removed_volume_mm3,
        machining_sim::simulate::colliding_moves(&out.collisions),
        stock.memory_bytes() as f64 / 1e6
    );
    let t = Instant::now();
    let mesh = machining_sim::extract_surface(&stock, 3);
    println!(
        "surface (stride 3): {} triangles in {:.2} s",
        mesh.triangles.len(),
        t.elapsed().as_secs_f64()
    );
}
