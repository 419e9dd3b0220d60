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

    /// The turned blank ([`Stock::turned`]) also turned down to the hub where there are no
    /// blades: outside the blades' axial extent `blade_z_mm` widened by the allowance, the
    /// outer radius is capped by the hub's `E(z) = max r(hub at height z) + allowance`, the
    /// smallest solid of revolution holding the hub there. This is what turning can reach on
    /// an axial rotor (the hub before and after the blade row) and at a centrifugal
    /// impeller's eye (the hub's nose above the leading edges); it leaves no ring of stock
    /// that only a shank could meet.
    ///
    /// The result is `R(z) = min(R_turned(z), E(z))`, exact for the two piecewise-linear
    /// profiles (their breakpoints and crossings are all breakpoints), so it is never larger
    /// than [`Stock::turned`]'s and still holds every design point that one holds: within the
    /// widened blade band `E` is not applied; over a ramp of [`HUB_RAMP_MM`] beyond each band
    /// edge `E` runs linearly from the turned radius down to the largest hub radius over the
    /// ramp; elsewhere `E` interpolates the hub's sampled polyline (its vertices pushed
    /// outward by the contour's chord sag, as in [`Stock::turned`]) at every vertex height,
    /// taking the largest of the polyline's crossings at a height, which lies on or above the
    /// hub between vertices because the largest of linear pieces is convex. Below the hub's
    /// lowest point `E` keeps the hub's end radius (the back plate), above its highest the
    /// hub's end radius there.
    ///
    /// Cost O(samples · 8) contour evaluations plus O(samples²) for the crossings of the
    /// hub polyline at each height.
    pub fn turned_to_hub_beyond_blades(
        blank: &Stock,
        shroud: &crate::MeridionalCurve,
        hub: &crate::MeridionalCurve,
        blade_z_mm: (f64, f64),
        top_z_mm: f64,
        allowance_mm: f64,
        samples: usize,
    ) -> Result<Self, ModelError> {
        let turned = Self::turned(blank, shroud, top_z_mm, allowance_mm, samples)?;
        let (b0, b1) = (
            blade_z_mm.0.min(blade_z_mm.1),
            blade_z_mm.0.max(blade_z_mm.1),
        );
        if !(b0.is_finite() && b1.is_finite()) {
            return Err(ModelError::invalid(
                "stock",
                "the blades' axial extent is not finite",
            ));
        }
        let (band0, band1) = (b0 - allowance_mm, b1 + allowance_mm);
        let (z0, z1) = turned.z_range();
        let hub_pts = raised_polyline(hub, samples.max(8), allowance_mm);
        // The largest hub radius at height z (the crossings of the raised polyline), or the
        // radius of its end beyond its axial extent.
        let (lo, hi) = hub_pts
            .iter()
            .fold((hub_pts[0], hub_pts[0]), |(lo, hi), p| {
                (
                    if p[0] < lo[0] { *p } else { lo },
                    if p[0] > hi[0] { *p } else { hi },
                )
            });
        let hub_r = |z: f64| -> f64 {
            if z <= lo[0] {
                return lo[1];
            }
            if z >= hi[0] {
                return hi[1];
            }
            let mut best = f64::NEG_INFINITY;
            for w in hub_pts.windows(2) {
                let (a, b) = (w[0], w[1]);
                let (za, zb) = (a[0].min(b[0]), a[0].max(b[0]));
                if z < za || z > zb {
                    continue;
                }
                let r = if zb - za <= 1e-12 {
                    a[1].max(b[1])
                } else {
                    a[1] + (z - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
                };
                best = best.max(r);
            }
            best
        };
        // The largest hub radius over [za, zb]: at the ends and at the vertices between.
        let hub_max = |za: f64, zb: f64| -> f64 {
            hub_pts
                .iter()
                .filter(|p| p[0] > za && p[0] < zb)
                .map(|p| p[1])
                .fold(hub_r(za).max(hub_r(zb)), f64::max)
        };
        let big = turned.max_radius().max(hub_max(z0, z1)) + 1.0;
        // E's breakpoints (z, value), increasing z.
        let mut e: Vec<[f64; 2]> = Vec::new();
        let below_end = band0 - HUB_RAMP_MM;
        if below_end > z0 {
            e.push([z0, hub_r(z0)]);
            e.extend(
                hub_pts
                    .iter()
                    .filter(|p| p[0] > z0 && p[0] < below_end)
                    .map(|p| [p[0], hub_r(p[0])]),
            );
            e.push([below_end, hub_max(below_end, band0)]);
        }
        e.push([band0, big]);
        e.push([band1, big]);
        let above_start = band1 + HUB_RAMP_MM;
        if above_start < z1 {
            e.push([above_start, hub_max(band1, above_start)]);
            e.extend(
                hub_pts
                    .iter()
                    .filter(|p| p[0] > above_start && p[0] < z1)
                    .map(|p| [p[0], hub_r(p[0])]),
            );
            e.push([z1, hub_r(z1)]);
        }
        e.sort_by(|a, b| a[0].total_cmp(&b[0]));
        e.dedup_by(|a, b| {
            if (a[0] - b[0]).abs() < 1e-9 {
                b[1] = b[1].max(a[1]);
                true
            } else {
                false
            }
        });
        let e_at = |z: f64| interpolate(&e, z);
        let t_at = |z: f64| turned.radius_at(z).unwrap_or(0.0);
        let mut zs: Vec<f64> = turned.profile_zr.iter().map(|p| p[0]).collect();
        zs.extend(e.iter().map(|p| p[0]).filter(|z| *z > z0 && *z < z1));
        zs.sort_by(f64::total_cmp);
        zs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        // The ends are the turned stock's, exactly.
        if let Some(first) = zs.first_mut() {
            *first = z0;
        }
        if let Some(last) = zs.last_mut() {
            *last = z1;
        }
        let mut profile: Vec<[f64; 2]> = Vec::with_capacity(2 * zs.len());
        for (k, &z) in zs.iter().enumerate() {
            if k > 0 {
                // The crossing of the two linear pieces inside (zs[k-1], z), if any.
                let za = zs[k - 1];
                let (da, db) = (t_at(za) - e_at(za), t_at(z) - e_at(z));
                if da * db < 0.0 {
                    let zc = za + (z - za) * da / (da - db);
                    if zc - za > 1e-9 && z - zc > 1e-9 {
                        profile.push([zc, t_at(zc).min(e_at(zc)).max(0.0)]);
                    }
                }
            }
            profile.push([z, t_at(z).min(e_at(z)).max(0.0)]);
        }
        Self::from_profile(profile)
    }

    /// Euclidean distance (mm) from the point (x, y, z) to the blank: 0 inside it.
    ///
    /// The blank is a solid of revolution, so its nearest point to `p` lies in `p`'s own
    /// meridional half-plane: the distance is the plane distance from `(r, z)` =
    /// `(|xy(p)|, p.z)` to the region `{z₀ ≤ z ≤ z₁, 0 ≤ r ≤ R(z)}`, i.e. to the nearest of
    /// its profile segments and its two end caps. Exact; O(profile points).
    pub fn distance_to(&self, p: &nalgebra::Vector3<f64>) -> f64 {
        if self.contains(p) {
            return 0.0;
        }
        use nalgebra::Vector2;
        use nurbs::discretise::point_segment_distance;
        let q = Vector2::new(p.x.hypot(p.y), p.z);
        let rz = |p: &[f64; 2]| Vector2::new(p[1], p[0]);
        let pts = &self.profile_zr;
        let (first, last) = (rz(&pts[0]), rz(&pts[pts.len() - 1]));
        let cap = |e: &Vector2<f64>| point_segment_distance(&q, &Vector2::new(0.0, e.y), e);
        pts.windows(2)
            .map(|w| point_segment_distance(&q, &rz(&w[0]), &rz(&w[1])))
            .fold(cap(&first).min(cap(&last)), f64::min)
    }

    /// Whether the point (x, y, z) lies in the blank.
    pub fn contains(&self, p: &nalgebra::Vector3<f64>) -> bool {
        self.radius_at(p.z)
            .is_some_and(|r| (p.x * p.x + p.y * p.y).sqrt() <= r)
    }
}

/// Width (mm) of the ramp over which [`Stock::turned_to_hub_beyond_blades`] brings the
/// turned radius down to the hub's beyond the blades' axial extent.
pub const HUB_RAMP_MM: f64 = 1.0;

/// The contour sampled at `n + 1` points, each pushed outward (+r) by the larger chord sag
/// of its two chords (7 points per chord) plus `allowance_mm`: a polyline on or outside the
/// contour.
fn raised_polyline(c: &crate::MeridionalCurve, n: usize, allowance_mm: f64) -> Vec<[f64; 2]> {
    let mut pts: Vec<[f64; 2]> = (0..=n)
        .map(|k| {
            let p = c.point_at_fraction(k as f64 / n as f64);
            [p.x, p.y]
        })
        .collect();
    let mut sag = vec![0.0f64; n + 1];
    for k in 1..=n {
        let (f0, f1) = ((k - 1) as f64 / n as f64, k as f64 / n as f64);
        let (a, b) = (pts[k - 1], pts[k]);
        let ab = [b[0] - a[0], b[1] - a[1]];
        let len2 = (ab[0] * ab[0] + ab[1] * ab[1]).max(1e-300);
        let mut worst: f64 = 0.0;
        for j in 1..8 {
            let q = c.point_at_fraction(f0 + (f1 - f0) * j as f64 / 8.0);
            // Radial distance of q above the chord at q's height, or its distance to the
            // chord where the chord is (nearly) radial.
            let t = ((q.x - a[0]) * ab[0] + (q.y - a[1]) * ab[1]) / len2;
            let t = t.clamp(0.0, 1.0);
            let d = ((q.x - a[0] - t * ab[0]).powi(2) + (q.y - a[1] - t * ab[1]).powi(2)).sqrt();
            worst = worst.max(d);
        }
        sag[k - 1] = sag[k - 1].max(worst);
        sag[k] = sag[k].max(worst);
    }
    for (p, g) in pts.iter_mut().zip(&sag) {
        p[1] += g + allowance_mm;
    }
    pts
}

/// Linear interpolation of `(z, v)` points sorted by z, the end values beyond them.
fn interpolate(pts: &[[f64; 2]], z: f64) -> f64 {
    let n = pts.len();
    if z <= pts[0][0] {
        return pts[0][1];
    }
    if z >= pts[n - 1][0] {
        return pts[n - 1][1];
    }
    let k = pts.partition_point(|p| p[0] <= z).clamp(1, n - 1);
    let (a, b) = (pts[k - 1], pts[k]);
    a[1] + (z - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
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
    fn distance_to_the_blank_is_the_distance_to_its_nearest_point() {
        use nalgebra::Vector3 as V;
        let p = Stock::from_profile(vec![[0.0, 40.0], [10.0, 40.0], [45.0, 20.0]]).unwrap();
        // Closed forms: beside the cylinder, above the top cap, beyond its rim, inside.
        assert!((p.distance_to(&V::new(0.0, 50.0, 5.0)) - 10.0).abs() < 1e-12);
        assert!((p.distance_to(&V::new(3.0, 4.0, 50.0)) - 5.0).abs() < 1e-12);
        assert!((p.distance_to(&V::new(0.0, -25.0, 60.0)) - 5f64.hypot(15.0)).abs() < 1e-12);
        assert!((p.distance_to(&V::new(0.0, 0.0, -2.0)) - 2.0).abs() < 1e-12);
        assert_eq!(p.distance_to(&V::new(10.0, 10.0, 20.0)), 0.0);
        // Against the nearest of 40 000 boundary points of the meridional section (spacing
        // below 0.004 mm), on a grid of outside points: never farther than the nearest sample,
        // never nearer than it by more than the spacing.
        let mut boundary = Vec::new();
        let n = 10_000;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            boundary.push([40.0, 10.0 * t]);
            boundary.push([40.0 - 20.0 * t, 10.0 + 35.0 * t]);
            boundary.push([40.0 * t, 0.0]);
            boundary.push([20.0 * t, 45.0]);
        }
        for i in 0..25 {
            for j in 0..25 {
                let (r, z) = (2.5 * i as f64, -5.0 + 2.3 * j as f64);
                let q = V::new(r * 0.6, r * 0.8, z);
                let d = p.distance_to(&q);
                if p.contains(&q) {
                    assert_eq!(d, 0.0);
                    continue;
                }
                let near = boundary
                    .iter()
                    .map(|b| (r - b[0]).hypot(z - b[1]))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d <= near + 1e-12 && d >= near - 0.004,
                    "at ({r}, {z}): {d} vs {near}"
                );
            }
        }
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

    fn line(a: [f64; 2], b: [f64; 2]) -> crate::MeridionalCurve {
        let curve = nurbs::NurbsCurve::new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![
                nalgebra::Vector2::new(a[0], a[1]),
                nalgebra::Vector2::new(b[0], b[1]),
            ],
            None,
        )
        .unwrap();
        crate::MeridionalCurve::new(curve).unwrap()
    }

    #[test]
    fn turned_to_hub_beyond_an_axial_rows_blades() {
        // An axial rotor: hub r 30 → 34 and casing r 50 from z 0 to 40, blades over z 10–30.
        let (hub, shroud) = (
            line([0.0, 30.0], [40.0, 34.0]),
            line([0.0, 50.0], [40.0, 50.0]),
        );
        let blank = Stock::cylinder(110.0, 40.0).unwrap();
        let a = 0.5;
        let t = Stock::turned(&blank, &shroud, 40.0, a, 64).unwrap();
        let s =
            Stock::turned_to_hub_beyond_blades(&blank, &shroud, &hub, (10.0, 30.0), 40.0, a, 64)
                .unwrap();
        assert_eq!(s.z_range(), t.z_range());
        let hub_r = |z: f64| 30.0 + 4.0 * z / 40.0;
        for k in 0..=800 {
            let z = s.z_range().0 + (s.z_range().1 - s.z_range().0) * k as f64 / 800.0;
            let (rs, rt) = (s.radius_at(z).unwrap(), t.radius_at(z).unwrap());
            // Never more than the turned blank; the hub (+ allowance) always inside.
            assert!(rs <= rt + 1e-12, "z {z}: {rs} > turned {rt}");
            assert!(
                rs >= hub_r(z.min(40.0)) + a - 1e-9,
                "z {z}: {rs} below the hub"
            );
            // The blades' band keeps the casing radius; beyond the ramp, the hub's.
            if (10.0 - a..=30.0 + a).contains(&z) {
                assert!((rs - rt).abs() < 1e-12, "z {z}: band cut to {rs}");
            }
            // (one hub sample, 0.625 mm, next to the ramp interpolates to its larger end)
            if z < 10.0 - a - HUB_RAMP_MM - 0.7 || z > 30.0 + a + HUB_RAMP_MM + 0.7 {
                assert!(
                    rs - (hub_r(z.min(40.0)) + a) < 1e-6,
                    "z {z}: {rs} left above the hub"
                );
            }
        }
    }

    #[test]
    fn turned_to_hub_keeps_a_centrifugal_blank_where_blades_span_it() {
        // impeller-8+8's contours: the blades span z 0–43, so nothing changes but the
        // faced eye above the leading edge when the band stops below it.
        let shroud = crate::MeridionalCurve::quarter_ellipse([43.0, 22.0], [11.0, 38.5]).unwrap();
        let hub = crate::MeridionalCurve::quarter_ellipse([43.0, 8.0], [0.0, 38.5]).unwrap();
        let blank = Stock::cylinder(79.0, 44.0).unwrap();
        let t = Stock::turned(&blank, &shroud, 43.0, 0.0, 256).unwrap();
        let full =
            Stock::turned_to_hub_beyond_blades(&blank, &shroud, &hub, (0.0, 43.0), 43.0, 0.0, 256)
                .unwrap();
        for k in 0..=400 {
            let z = 43.0 * k as f64 / 400.0;
            assert!((full.radius_at(z).unwrap() - t.radius_at(z).unwrap()).abs() < 1e-9);
        }
        // Blades ending at z 38: above 39 the stock is the hub's nose (r ≤ ~13.1 at z 39).
        let eye =
            Stock::turned_to_hub_beyond_blades(&blank, &shroud, &hub, (0.0, 38.0), 43.0, 0.0, 256)
                .unwrap();
        let nose = |z: f64| {
            // hub: z = 43 cos φ, r = 38.5 - 30.5 cos φ... sampled by closest point instead
            (0..=4000)
                .map(|j| hub.point_at_fraction(j as f64 / 4000.0))
                .filter(|p| (p.x - z).abs() < 0.05)
                .map(|p| p.y)
                .fold(0.0f64, f64::max)
        };
        for z in [39.5, 41.0, 42.5] {
            let r = eye.radius_at(z).unwrap();
            assert!(
                r >= nose(z) - 0.01 && r <= nose(z) + 0.2,
                "z {z}: {r} vs hub {}",
                nose(z)
            );
            assert!(r < t.radius_at(z).unwrap() - 5.0);
        }
    }
}
