//! Rotational copy: one channel's or blade's paths turned to every channel or blade (the
//! "object transformation" of paper 003's process plan). A turn by `φ` about +Z maps each
//! tip `p ↦ R(φ) p` and each axis `a ↦ R(φ) a`; copies are exact up to the rounding of one
//! rotation matrix product (≈ 1e-15 relative).

use cam_core::{CutterLocation, ToolPath};
use nalgebra::{Rotation3, Unit, Vector3};

/// `cl` turned by `angle` (rad) about +Z.
pub fn rotate_location(cl: &CutterLocation, angle: f64) -> CutterLocation {
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), angle);
    CutterLocation {
        tip: rot * cl.tip,
        axis: Unit::new_unchecked(rot * cl.axis.into_inner()),
    }
}

/// `path` turned by `angle` (rad) about +Z, moves and feeds kept.
pub fn rotate_path(path: &ToolPath, angle: f64) -> ToolPath {
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), angle);
    let mut out = path.clone();
    for m in &mut out.moves {
        m.cl.tip = rot * m.cl.tip;
        m.cl.axis = Unit::new_unchecked(rot * m.cl.axis.into_inner());
    }
    out
}

/// Copies of `path` for the channels (or blades) `order`, each turned by `k · pitch`, named
/// `"{name} #k"`.
pub fn copy_to(path: &ToolPath, pitch_rad: f64, order: &[usize]) -> Vec<ToolPath> {
    order
        .iter()
        .map(|&k| {
            let mut p = rotate_path(path, pitch_rad * k as f64);
            p.name = format!("{} #{k}", path.name);
            p
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{Move, Point3};

    #[test]
    fn copies_are_rotations_by_k_pitch() {
        let mut path = ToolPath::new("p", "t");
        for i in 0..5 {
            let cl = CutterLocation::new(
                Point3::new(10.0 + i as f64, 2.0, 3.0 * i as f64),
                Vector3::new(0.1, 0.2, 1.0),
            )
            .unwrap();
            path.moves.push(Move::feed(cl));
        }
        let pitch = std::f64::consts::TAU / 7.0;
        let copies = copy_to(&path, pitch, &[0, 1, 2, 3, 4, 5, 6]);
        for (k, c) in copies.iter().enumerate() {
            let phi = pitch * k as f64;
            for (m, m0) in c.moves.iter().zip(&path.moves) {
                let (s, co) = phi.sin_cos();
                let expect = Point3::new(
                    co * m0.cl.tip.x - s * m0.cl.tip.y,
                    s * m0.cl.tip.x + co * m0.cl.tip.y,
                    m0.cl.tip.z,
                );
                assert!((m.cl.tip - expect).norm() < 1e-9);
                assert!((m.cl.axis.norm() - 1.0).abs() < 1e-12);
            }
        }
    }
}
