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

    /// The blank after facing and turning its outside to a contour (paper 003, Table 1,
    /// steps 1–3: "face cutting", "rough/finish turning outside contour"): the solid
    /// `r ≤ min(R_blank(z), R_c(z) + allowance)` for `z` up to `top_z_mm + allowance` (the
    /// faced top, never above the blank's), with `R_c` the contour's radius as a function of
    /// `z` and, beyond the contour's axial ends, its end radius (the back plate below the
    /// outlet, the faced top above the inlet).
    ///
    /// The contour is sampled at `samples` points; each point of the polyline through them is
    /// pushed outward by the larger sag of the contour beyond its two chords (measured at 7
    /// points per chord), so the turned stock contains every point of the solid under the
    /// contour: a design bounded by the contour stays inside the stock. Cost O(samples · 8)
    /// contour evaluations.
    ///
    /// Errors: a contour whose radius is not a function of `z` (it turns back axially), or
    /// that lies outside the blank, or an allowance that is negative.
    pub fn turned(
        blank: &Stock,
        contour: &crate::MeridionalCurve,
        top_z_mm: f64,
        allowance_mm: f64,
        samples: usize,
    ) -> Result<Self, ModelError> {
        if !(allowance_mm.is_finite() && allowance_mm >= 0.0) {
            return Err(ModelError::invalid(
                "stock.turning_allowance_mm",
                "must be >= 0",
            ));
        }
        let n = samples.max(8);
        // Contour points ordered by increasing z.
        let mut pts: Vec<[f64; 2]> = (0..=n)
            .map(|k| {
                let p = contour.point_at_fraction(k as f64 / n as f64);
                [p.x, p.y]
            })
            .collect();
        if pts[0][0] > pts[n][0] {
            pts.reverse();
        }
        let frac_of = |k: usize| {
            if contour.point_at_fraction(0.0).x <= contour.point_at_fraction(1.0).x {
                k as f64 / n as f64
            } else {
                1.0 - k as f64 / n as f64
            }
        };
        let z_span = (pts[n][0] - pts[0][0]).abs().max(1e-9);
        for k in 1..=n {
            if pts[k][0] <= pts[k - 1][0] + 1e-9 * z_span {
                return Err(ModelError::invalid(
                    "stock",
                    format!(
                        "the shroud contour turns back axially near (z, r) = ({:.3}, {:.3}) mm: \
                         a turned stock needs its radius as a function of z",
                        pts[k][0], pts[k][1]
                    ),
                ));
            }
        }
        // Sag of the contour outside each chord; each vertex is raised by the larger sag of
        // its two chords, so every raised chord lies on or outside the contour.
        let mut sag = vec![0.0f64; n + 1];
        for k in 1..=n {
            let (f0, f1) = (frac_of(k - 1), frac_of(k));
            let (a, b) = (pts[k - 1], pts[k]);
            let mut worst: f64 = 0.0;
            for j in 1..8 {
                let q = contour.point_at_fraction(f0 + (f1 - f0) * j as f64 / 8.0);
                let t = ((q.x - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0);
                worst = worst.max(q.y - (a[1] + t * (b[1] - a[1])));
            }
            sag[k - 1] = sag[k - 1].max(worst);
            sag[k] = sag[k].max(worst);
        }
        for (p, g) in pts.iter_mut().zip(&sag) {
            p[1] += g + allowance_mm;
        }
        let (z0, z1) = blank.z_range();
        let top = (top_z_mm + allowance_mm).min(z1);
        let (zc0, zc1) = (pts[0][0], pts[n][0]);
        if top <= z0 {
            return Err(ModelError::invalid(
                "stock",
                format!("the faced top z {top:.3} mm is below the blank's bottom z {z0:.3} mm"),
            ));
        }
        // Breakpoints: the blank's, the contour's and the top, within [z0, top].
        let mut zs: Vec<f64> = blank.profile_zr.iter().map(|p| p[0]).collect();
        zs.extend(pts.iter().map(|p| p[0]));
        zs.retain(|z| *z >= z0 && *z < top - 1e-9);
        zs.sort_by(f64::total_cmp);
        zs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        zs.push(top);
        let contour_r = |z: f64| {
            if z <= zc0 {
                return pts[0][1];
            }
            if z >= zc1 {
                return pts[n][1];
            }
            let k = pts.partition_point(|p| p[0] <= z).clamp(1, n);
            let (a, b) = (pts[k - 1], pts[k]);
            a[1] + (z - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
        };
        let profile: Vec<[f64; 2]> = zs
            .iter()
            .map(|&z| {
                let rb = blank.radius_at(z).unwrap_or(0.0);
                [z, rb.min(contour_r(z))]
            })
            .collect();
        Self::from_profile(profile)
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

    #[test]
    fn turned_stock_contains_the_contour_and_follows_it() {
        // Quarter ellipse shroud (impeller-8+8): inlet (43, 22), outlet (11, 38.5).
        let c = crate::MeridionalCurve::quarter_ellipse([43.0, 22.0], [11.0, 38.5]).unwrap();
        let blank = Stock::cylinder(79.0, 44.0).unwrap();
        let t = Stock::turned(&blank, &c, 43.0, 0.0, 256).unwrap();
        assert_eq!(t.z_range(), (0.0, 43.0));
        assert!((t.radius_at(5.0).unwrap() - 38.5).abs() < 1e-3);
        // Every contour point lies inside the turned stock, at most the chord sag outside.
        for k in 0..=400 {
            let p = c.point_at_fraction(k as f64 / 400.0);
            let r = t.radius_at(p.x).unwrap();
            assert!(r >= p.y - 1e-12, "contour outside the stock at z {}", p.x);
            assert!(
                r - p.y < 0.05,
                "stock {r} far beyond the contour {} at z {}",
                p.y,
                p.x
            );
        }
        // An allowance grows the radius by that much (within the blank).
        let a = Stock::turned(&blank, &c, 43.0, 0.5, 256).unwrap();
        assert!((a.radius_at(20.0).unwrap() - t.radius_at(20.0).unwrap() - 0.5).abs() < 1e-9);
        assert_eq!(a.z_range().1, 43.5);
        // Never beyond the blank.
        assert!(a.radius_at(5.0).unwrap() <= 39.5 + 1e-12);
        assert!(Stock::turned(&blank, &c, 43.0, -1.0, 64).is_err());
    }
}
