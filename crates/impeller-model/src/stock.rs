//! The blank (stock) as a solid of revolution about Z.
//!
//! The solid is { (r, φ, z) : z_first ≤ z ≤ z_last, r ≤ R(z) } where R(z) is the piecewise
//! linear outer profile through the given (z, r) points.

use crate::error::ModelError;

/// A blank turned about Z.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Stock {
    profile_zr: Vec<[f64; 2]>,
}

impl Stock {
    /// A blank with outer profile `(z, r)` points, z strictly increasing, r ≥ 0.
    pub fn from_profile(profile_zr: Vec<[f64; 2]>) -> Result<Self, ModelError> {
        if profile_zr.len() < 2 {
            return Err(ModelError::invalid(
                "stock.profile_zr_mm",
                "must hold at least two points",
            ));
        }
        for (i, p) in profile_zr.iter().enumerate() {
            if !p[0].is_finite() || !p[1].is_finite() || p[1] < 0.0 {
                return Err(ModelError::invalid(
                    format!("stock.profile_zr_mm[{i}]"),
                    "must be finite with r >= 0",
                ));
            }
            if i > 0 && p[0] <= profile_zr[i - 1][0] {
                return Err(ModelError::invalid(
                    format!("stock.profile_zr_mm[{i}]"),
                    "must have z increasing strictly",
                ));
            }
        }
        Ok(Self { profile_zr })
    }

    /// A cylinder of `diameter` from z = 0 to z = `height`.
    pub fn cylinder(diameter: f64, height: f64) -> Result<Self, ModelError> {
        if !(diameter.is_finite() && diameter > 0.0) {
            return Err(ModelError::invalid("stock.diameter_mm", "must be > 0"));
        }
        if !(height.is_finite() && height > 0.0) {
            return Err(ModelError::invalid("stock.height_mm", "must be > 0"));
        }
        Self::from_profile(vec![[0.0, 0.5 * diameter], [height, 0.5 * diameter]])
    }

    /// The outer profile (z, r).
    pub fn profile_zr(&self) -> &[[f64; 2]] {
        &self.profile_zr
    }

    /// Axial extent (z_min, z_max).
    pub fn z_range(&self) -> (f64, f64) {
        (
            self.profile_zr[0][0],
            self.profile_zr[self.profile_zr.len() - 1][0],
        )
    }

    /// Largest radius of the blank.
    pub fn max_radius(&self) -> f64 {
        self.profile_zr.iter().fold(0.0, |a, p| a.max(p[1]))
    }

    /// Outer radius at height z, `None` outside the axial extent.
    pub fn radius_at(&self, z: f64) -> Option<f64> {
        let (z0, z1) = self.z_range();
        if z < z0 || z > z1 {
            return None;
        }
        let k = self
            .profile_zr
            .partition_point(|p| p[0] <= z)
            .clamp(1, self.profile_zr.len() - 1);
        let (a, b) = (self.profile_zr[k - 1], self.profile_zr[k]);
        let t = (z - a[0]) / (b[0] - a[0]);
        Some(a[1] + t * (b[1] - a[1]))
    }

    /// Whether the point (x, y, z) lies in the blank.
    pub fn contains(&self, p: &nalgebra::Vector3<f64>) -> bool {
        self.radius_at(p.z)
            .is_some_and(|r| (p.x * p.x + p.y * p.y).sqrt() <= r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_and_profile() {
        let s = Stock::cylinder(80.0, 45.0).unwrap();
        assert_eq!(s.radius_at(10.0), Some(40.0));
        assert_eq!(s.radius_at(46.0), None);
        assert!(s.contains(&nalgebra::Vector3::new(30.0, 20.0, 1.0)));
        assert!(!s.contains(&nalgebra::Vector3::new(30.0, 30.0, 1.0)));
        let p = Stock::from_profile(vec![[0.0, 40.0], [10.0, 40.0], [45.0, 20.0]]).unwrap();
        assert!((p.radius_at(27.5).unwrap() - 30.0).abs() < 1e-12);
        assert!(Stock::from_profile(vec![[0.0, 1.0], [0.0, 2.0]]).is_err());
        assert!(Stock::cylinder(-1.0, 2.0).is_err());
    }
}
