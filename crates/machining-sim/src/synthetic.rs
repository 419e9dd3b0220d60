//! A synthetic five-axis workload for benchmarks and the 100k-move measurement: layered
//! zig-zag passes of a tapered ball end over a cylindrical blank, with the tool axis tilting
//! smoothly (up to 15°) along the path.

use cam_core::{
    Cutter, CutterLocation, CutterShape, HolderSegment, Move, MoveKind, Point3, ToolPath, Vector3,
};

/// Tapered ball end used by the workload: ball radius 1.5 mm, half angle 3°, flutes 25 mm,
/// shank radius 3 mm, stick-out 50 mm, holder Ø40 × 40 mm.
pub fn workload_cutter() -> Cutter {
    Cutter {
        name: "tb3".into(),
        shape: CutterShape::TaperedBallEnd {
            ball_radius: 1.5,
            half_angle: 3f64.to_radians(),
        },
        flute_length: 25.0,
        shank_radius: 3.0,
        overall_length: 50.0,
        holder: vec![HolderSegment {
            bottom_radius: 20.0,
            top_radius: 20.0,
            length: 40.0,
        }],
    }
}

/// `moves` moves of zig-zag layers over the disc of radius `radius` below `top` (mm): lines
/// 1.5 mm apart, moves of 0.5 mm, layers 0.5 mm deep, a retract and rapid between layers.
pub fn zigzag_path(moves: usize, radius: f64, top: f64) -> ToolPath {
    let mut p = ToolPath::new("synthetic_zigzag", "tb3");
    let step = 0.5;
    let pitch = 1.5;
    let mut layer = 0usize;
    let mut s_total = 0.0f64;
    let axis_at = |s: f64, x: f64, y: f64| {
        let a = 15f64.to_radians() * (s / 7.0).sin();
        let phi = y.atan2(x) + 0.3;
        Vector3::new(a.sin() * phi.cos(), a.sin() * phi.sin(), a.cos())
    };
    let cl = |x: f64, y: f64, z: f64, s: f64| CutterLocation {
        tip: Point3::new(x, y, z),
        axis: cam_core::UnitVector3::new_normalize(axis_at(s, x, y)),
    };
    'outer: loop {
        let z = top - 0.5 * (layer as f64 + 1.0);
        let mut y = -radius + pitch / 2.0;
        let mut dir = 1.0;
        let mut first = true;
        while y < radius {
            let half = (radius * radius - y * y).max(0.0).sqrt();
            let n = ((2.0 * half) / step).ceil().max(1.0) as usize;
            for k in 0..=n {
                let x = dir * (-half + 2.0 * half * k as f64 / n as f64);
                s_total += step;
                let kind = if first {
                    first = false;
                    p.moves.push(Move::rapid(cl(x, y, top + 5.0, s_total)));
                    MoveKind::Plunge
                } else {
                    MoveKind::Feed
                };
                p.moves.push(Move {
                    kind,
                    cl: cl(x, y, z, s_total),
                    feed_mm_per_min: None,
                });
                if p.moves.len() >= moves {
                    break 'outer;
                }
            }
            y += pitch;
            dir = -dir;
        }
        if let Some(last) = p.moves.last().copied() {
            let mut up = last.cl;
            up.tip.z = top + 5.0;
            p.moves.push(Move {
                kind: MoveKind::Retract,
                cl: up,
                feed_mm_per_min: None,
            });
        }
        layer += 1;
        if p.moves.len() >= moves {
            break;
        }
    }
    p.moves.truncate(moves);
    p
}
