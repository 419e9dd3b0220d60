//! Faces a block down to a design plane with a flat end, with one pass that cuts 0.3 mm too
//! deep, and prints what the independent verification finds.
//!
//! `cargo run -p machining-sim --example face_block`
//!
//! Stock: a 20 × 20 × 10 mm block sampled by a tri-dexel grid at 0.25 mm. Design: the lower
//! 6 mm of the block. A Ø6 mm flat end faces the top at z = 6 in zig-zag passes 4 mm apart,
//! the third pass at z = 5.7. The report gives the largest overcut (where it is), the largest
//! residual left above the design, the removed volume and the counters.

use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath};
use machining_sim::{simulate, BoxDesign, BoxStock, SimOptions, TriDexel};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let blank = BoxStock::new([0.0, 0.0, 0.0], [20.0, 20.0, 10.0])?;
    let mut stock = TriDexel::from_shape(&blank, 0.25)?;
    let design = BoxDesign {
        min: [0.0, 0.0, 0.0],
        max: [20.0, 20.0, 6.0],
        sample_spacing: 1.0,
    };
    let cutter = Cutter::new("f6", CutterShape::FlatEnd { radius: 3.0 }, 20.0, 3.0, 40.0)?;
    let mut path = ToolPath::new("facing", "f6");
    let at = |x: f64, y: f64, z: f64| CutterLocation::vertical(Point3::new(x, y, z));
    let push = |path: &mut ToolPath, kind, cl| {
        path.moves.push(Move {
            kind,
            cl,
            feed_mm_per_min: None,
        })
    };
    push(&mut path, MoveKind::Rapid, at(-4.0, 0.0, 15.0));
    for (k, y) in [0.0, 4.0, 8.0, 12.0, 16.0, 20.0].into_iter().enumerate() {
        let z = if k == 2 { 5.7 } else { 6.0 };
        let (x0, x1) = if k % 2 == 0 {
            (-4.0, 24.0)
        } else {
            (24.0, -4.0)
        };
        push(&mut path, MoveKind::Plunge, at(x0, y, z));
        push(&mut path, MoveKind::Feed, at(x1, y, z));
        push(&mut path, MoveKind::Retract, at(x1, y, 15.0));
    }
    let report = simulate(
        &mut stock,
        &design,
        &[(cutter, path)],
        &SimOptions::default(),
    )?;
    let m = &report.metrics;
    println!(
        "max overcut   {:.3} mm (error bound {:.3} mm)",
        m.max_overcut_mm, m.overcut_error_bound_mm
    );
    if let Some(e) = &report.max_overcut {
        println!(
            "  at ({:.2}, {:.2}, {:.2}) on `{}`",
            e.point[0], e.point[1], e.point[2], e.surface
        );
    }
    println!("max residual  {:.3} mm", m.max_residual_mm);
    println!("collisions    {}", m.collisions);
    let s = &report.stats;
    println!(
        "moves {}, cutter positions {}, rays {}, removed {:.1} mm³ (expected ≈ {:.1} mm³)",
        s.moves,
        s.positions,
        s.rays,
        s.removed_volume_mm3,
        20.0 * 20.0 * 4.0 + 0.3 * 20.0 * 6.0
    );
    Ok(())
}
