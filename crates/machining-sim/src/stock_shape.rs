//! Blank shapes the tri-dexel stock is initialised from: a box, or a solid of revolution about
//! the workpiece Z axis given by its meridional (z, r) outline (a turned blank).

use crate::error::SimError;
use serde::{Deserialize, Serialize};

/// A solid that can report where an axis-parallel line crosses it.
pub trait StockShape: Sync {
    /// Axis-aligned bounding box (min, max).
    fn bounding_box(&self) -> ([f64; 3], [f64; 3]);
    /// Appends the intervals of coordinate `d` (0 = X, 1 = Y, 2 = Z) inside the solid along
    /// the line whose other coordinates are `u` (index `(d+1)%3`) and `v` (index `(d+2)%3`).
    fn ray_intervals(&self, d: usize, u: f64, v: f64, out: &mut Vec<(f64, f64)>);
}

/// Axis-aligned box stock.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoxStock {
    /// Lower corner (mm).
    pub min: [f64; 3],
    /// Upper corner (mm).
    pub max: [f64; 3],
}

impl BoxStock {
    /// A box from its corners; errors if not finite or empty.
    pub fn new(min: [f64; 3], max: [f64; 3]) -> Result<Self, SimError> {
        for k in 0..3 {
            if !(min[k].is_finite() && max[k].is_finite() && max[k] > min[k]) {
                return Err(SimError::InvalidStock(format!(
                    "box coordinate {k}: min {} must be below max {}",
                    min[k], max[k]
                )));
            }
        }
        Ok(Self { min, max })
    }
}

impl StockShape for BoxStock {
    fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        (self.min, self.max)
    }
    fn ray_intervals(&self, d: usize, u: f64, v: f64, out: &mut Vec<(f64, f64)>) {
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        if u >= self.min[ua] && u <= self.max[ua] && v >= self.min[va] && v <= self.max[va] {
            out.push((self.min[d], self.max[d]));
        }
    }
}

/// Solid of revolution about the Z axis: the points whose meridional coordinates
/// `(z, r = sqrt(x² + y²))` lie inside a closed polygon with `r >= 0` (e.g. a turned blank:
/// `[(0,0), (0,38.5), (30,38.5), (30,10), (45,10), (45,0)]`). Even–odd rule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RevolvedStock {
    /// Closed outline as (z, r) vertices (the last edge returns to the first vertex).
    pub profile: Vec<(f64, f64)>,
}

impl RevolvedStock {
    /// Validates the outline: at least 3 finite vertices, r >= 0.
    pub fn new(profile: Vec<(f64, f64)>) -> Result<Self, SimError> {
        if profile.len() < 3 {
            return Err(SimError::InvalidStock(
                "revolved profile needs at least 3 (z, r) vertices".into(),
            ));
        }
        for (i, &(z, r)) in profile.iter().enumerate() {
            if !(z.is_finite() && r.is_finite() && r >= 0.0) {
                return Err(SimError::InvalidStock(format!(
                    "revolved profile vertex {i}: (z {z}, r {r}) must be finite with r >= 0"
                )));
            }
        }
        Ok(Self { profile })
    }

    /// A cylinder blank of radius `radius` from `z0` to `z1`.
    pub fn cylinder(radius: f64, z0: f64, z1: f64) -> Result<Self, SimError> {
        Self::new(vec![(z0, 0.0), (z0, radius), (z1, radius), (z1, 0.0)])
    }

    fn edges(&self) -> impl Iterator<Item = ((f64, f64), (f64, f64))> + '_ {
        let n = self.profile.len();
        (0..n).map(move |i| (self.profile[i], self.profile[(i + 1) % n]))
    }

    /// Crossings of the outline with `r = rho` (returns z values, sorted).
    fn z_crossings(&self, rho: f64, out: &mut Vec<f64>) {
        for ((z0, r0), (z1, r1)) in self.edges() {
            if (r0 <= rho) != (r1 <= rho) {
                out.push(z0 + (rho - r0) * (z1 - z0) / (r1 - r0));
            }
        }
        out.sort_by(f64::total_cmp);
    }

    /// Crossings of the outline with `z = zc` (returns r values, sorted).
    fn r_crossings(&self, zc: f64, out: &mut Vec<f64>) {
        for ((z0, r0), (z1, r1)) in self.edges() {
            if (z0 <= zc) != (z1 <= zc) {
                out.push(r0 + (zc - z0) * (r1 - r0) / (z1 - z0));
            }
        }
        out.sort_by(f64::total_cmp);
    }
}

impl StockShape for RevolvedStock {
    fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let rmax = self.profile.iter().map(|p| p.1).fold(0.0, f64::max);
        let zmin = self
            .profile
            .iter()
            .map(|p| p.0)
            .fold(f64::INFINITY, f64::min);
        let zmax = self
            .profile
            .iter()
            .map(|p| p.0)
            .fold(f64::NEG_INFINITY, f64::max);
        ([-rmax, -rmax, zmin], [rmax, rmax, zmax])
    }

    fn ray_intervals(&self, d: usize, u: f64, v: f64, out: &mut Vec<(f64, f64)>) {
        let mut xs = Vec::new();
        if d == 2 {
            // u = x, v = y.
            self.z_crossings((u * u + v * v).sqrt(), &mut xs);
            for p in xs.chunks_exact(2) {
                out.push((p[0], p[1]));
            }
            return;
        }
        // d = 0: u = y, v = z; d = 1: u = z, v = x. Offset from the axis and height:
        let (off, z) = if d == 0 { (u, v) } else { (v, u) };
        self.r_crossings(z, &mut xs);
        let off2 = off * off;
        for p in xs.chunks_exact(2) {
            let (ra, rb) = (p[0].max(0.0), p[1]);
            if rb * rb <= off2 {
                continue;
            }
            let xb = (rb * rb - off2).sqrt();
            if ra * ra <= off2 {
                out.push((-xb, xb));
            } else {
                let xa = (ra * ra - off2).sqrt();
                out.push((-xb, -xa));
                out.push((xa, xb));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn revolved_rays_agree_in_all_directions() {
        let s = RevolvedStock::new(vec![
            (0.0, 0.0),
            (0.0, 10.0),
            (5.0, 10.0),
            (5.0, 4.0),
            (12.0, 4.0),
            (12.0, 0.0),
        ])
        .unwrap();
        let mut out = Vec::new();
        s.ray_intervals(2, 3.0, 0.0, &mut out);
        assert_eq!(out, vec![(0.0, 12.0)]);
        out.clear();
        s.ray_intervals(2, 6.0, 0.0, &mut out);
        assert_eq!(out, vec![(0.0, 5.0)]);
        out.clear();
        // X ray at y = 0, z = 8: |x| <= 4.
        s.ray_intervals(0, 0.0, 8.0, &mut out);
        assert_eq!(out, vec![(-4.0, 4.0)]);
        out.clear();
        // Y ray at z = 2, x = 6: |y| <= 8.
        s.ray_intervals(1, 2.0, 6.0, &mut out);
        assert_eq!(out, vec![(-8.0, 8.0)]);
    }
}
