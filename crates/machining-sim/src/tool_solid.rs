//! A cutter as a stack of convex solids of revolution, and the exact intersection of an
//! axis-parallel ray with it.
//!
//! Heights `h` are measured along the tool axis from the tip (APT convention, as in
//! `cam_core::Cutter`). The cutting part of every APT shape in `cam_core::CutterShape` has a
//! concave, non-decreasing radius profile `r(h)`, so it is a convex solid; the shank and each
//! holder segment are convex frustums. A ray therefore meets each piece in one interval.
//!
//! Ray–piece intersection (per piece, closed form): write the ray as `x(λ) = o + λ e` with
//! `o − tip = q`. Then `h(λ) = q·a + λ (e·a)` and the squared radial distance is the quadratic
//! `ρ²(λ) = |w₀|² + 2 λ (w₀·e) + λ² (1 − (e·a)²)` with `w₀ = q − (q·a) a`.
//! * frustum `r = r₀ + k (h − h₀)`: `ρ² − r(h)² ≤ 0` is a quadratic inequality in λ;
//! * sphere centred at height `h_c`: `ρ² + (h − h_c)² − R² ≤ 0`, quadratic;
//! * torus (bull-nose corner): the membership function `g(λ) = ρ(λ) − r(h(λ))` is convex on
//!   the slab (ρ convex, r concave), so its zero set is found by bracketing and bisection to
//!   [`TORUS_TOL_MM`].
//!
//! Each result is clipped to the slab `h₀ ≤ h(λ) ≤ h₁`. Cost O(1) per piece (≈ 60 bisection
//! steps for a torus piece).

use cam_core::{Cutter, CutterShape};

/// Bisection tolerance (mm) of the bull-nose torus intersection.
pub const TORUS_TOL_MM: f64 = 1e-6;

/// One convex slab `h₀ ≤ h ≤ h₁` of a solid of revolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// Cone frustum (cylinder when `r0 == r1`).
    Frustum {
        /// Lower height.
        h0: f64,
        /// Upper height.
        h1: f64,
        /// Radius at `h0`.
        r0: f64,
        /// Radius at `h1`.
        r1: f64,
    },
    /// Part of a ball of radius `radius` centred on the axis at height `hc`.
    Sphere {
        /// Lower height.
        h0: f64,
        /// Upper height.
        h1: f64,
        /// Centre height.
        hc: f64,
        /// Ball radius.
        radius: f64,
    },
    /// Part of a solid torus (tube radius `minor` around the circle of radius `major` at
    /// height `hc`), filled to the axis: `ρ ≤ major + sqrt(minor² − (h − hc)²)`.
    Torus {
        /// Lower height.
        h0: f64,
        /// Upper height.
        h1: f64,
        /// Centre height of the tube circle.
        hc: f64,
        /// Radius of the tube's centre circle.
        major: f64,
        /// Tube radius.
        minor: f64,
    },
}

impl Piece {
    /// Height range of the slab.
    pub fn heights(&self) -> (f64, f64) {
        match *self {
            Piece::Frustum { h0, h1, .. }
            | Piece::Sphere { h0, h1, .. }
            | Piece::Torus { h0, h1, .. } => (h0, h1),
        }
    }

    /// Largest radius over the slab.
    pub fn max_radius(&self) -> f64 {
        match *self {
            Piece::Frustum { r0, r1, .. } => r0.max(r1),
            Piece::Sphere { h0, h1, hc, radius } => {
                if (h0..=h1).contains(&hc) {
                    radius
                } else {
                    let d = (h0 - hc).abs().min((h1 - hc).abs());
                    (radius * radius - d * d).max(0.0).sqrt()
                }
            }
            Piece::Torus {
                h0,
                h1,
                hc,
                major,
                minor,
            } => {
                let d = if (h0..=h1).contains(&hc) {
                    0.0
                } else {
                    (h0 - hc).abs().min((h1 - hc).abs())
                };
                major + (minor * minor - d * d).max(0.0).sqrt()
            }
        }
    }

    /// Radius of the piece at height `h` (inside its slab).
    pub fn radius_at(&self, h: f64) -> f64 {
        match *self {
            Piece::Frustum { h0, h1, r0, r1 } => {
                if h1 > h0 {
                    r0 + (r1 - r0) * (h - h0) / (h1 - h0)
                } else {
                    r0.max(r1)
                }
            }
            Piece::Sphere { hc, radius, .. } => {
                (radius * radius - (h - hc) * (h - hc)).max(0.0).sqrt()
            }
            Piece::Torus {
                hc, major, minor, ..
            } => major + (minor * minor - (h - hc) * (h - hc)).max(0.0).sqrt(),
        }
    }

    /// Interval of λ where the ray lies inside this piece, given the ray's local quantities
    /// (see [`RayLocal`]). `None` when the ray misses.
    #[inline]
    pub fn ray_interval(&self, r: &RayLocal) -> Option<(f64, f64)> {
        let (h0, h1) = self.heights();
        let (lo, hi) = slab(r, h0, h1)?;
        match *self {
            Piece::Frustum { h0, h1, r0, r1 } => {
                let k = if h1 > h0 { (r1 - r0) / (h1 - h0) } else { 0.0 };
                let c0 = r0 + k * (r.qh - h0);
                let kad = k * r.ad;
                let a = r.w1sq - kad * kad;
                let b = r.w0d - kad * c0;
                let c = r.w0sq - c0 * c0;
                quad_le_zero(a, b, c, lo, hi)
            }
            Piece::Sphere { hc, radius, .. } => {
                let dh = r.qh - hc;
                let b = r.w0d + dh * r.ad;
                let c = r.w0sq + dh * dh - radius * radius;
                quad_le_zero(1.0, b, c, lo, hi)
            }
            Piece::Torus {
                hc, major, minor, ..
            } => torus_interval(r, hc, major, minor, lo, hi),
        }
    }
}

/// Local description of an axis-parallel ray relative to a tool position, with λ measured
/// from the ray point level with the tool tip along the ray direction `e`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayLocal {
    /// `h` at λ = 0.
    pub qh: f64,
    /// `dh/dλ = e·a`.
    pub ad: f64,
    /// `|w₀|²`: squared radial distance at λ = 0.
    pub w0sq: f64,
    /// `w₀·e`.
    pub w0d: f64,
    /// `1 − (e·a)²`.
    pub w1sq: f64,
}

impl RayLocal {
    /// Ray along coordinate `d` through the point whose other two coordinates differ from the
    /// tip's by `(du, dv)` (coordinates `(d+1)%3`, `(d+2)%3`); `axis` is the unit tool axis.
    #[inline]
    pub fn new(d: usize, du: f64, dv: f64, axis: &[f64; 3]) -> Self {
        let au = axis[(d + 1) % 3];
        let av = axis[(d + 2) % 3];
        let ad = axis[d];
        let qh = du * au + dv * av;
        let w0sq = (du * du + dv * dv - qh * qh).max(0.0);
        Self {
            qh,
            ad,
            w0sq,
            w0d: -qh * ad,
            w1sq: (1.0 - ad * ad).max(0.0),
        }
    }

    /// Smallest squared radial distance of the whole ray line to the axis.
    #[inline]
    pub fn min_rho_sq(&self) -> f64 {
        if self.w1sq > 1e-12 {
            (self.w0sq - self.w0d * self.w0d / self.w1sq).max(0.0)
        } else {
            self.w0sq
        }
    }

    #[inline]
    fn rho(&self, l: f64) -> f64 {
        (self.w0sq + 2.0 * self.w0d * l + self.w1sq * l * l)
            .max(0.0)
            .sqrt()
    }
}

/// λ range where `h0 <= h(λ) <= h1`.
#[inline]
fn slab(r: &RayLocal, h0: f64, h1: f64) -> Option<(f64, f64)> {
    if r.ad.abs() < 1e-12 {
        if r.qh >= h0 && r.qh <= h1 {
            Some((f64::NEG_INFINITY, f64::INFINITY))
        } else {
            None
        }
    } else {
        let la = (h0 - r.qh) / r.ad;
        let lb = (h1 - r.qh) / r.ad;
        Some(if la <= lb { (la, lb) } else { (lb, la) })
    }
}

/// Solution set of `a λ² + 2 b λ + c ≤ 0` within `[lo, hi]`, returned as its hull (the
/// callers' sets are intervals because the pieces are convex).
#[inline]
fn quad_le_zero(a: f64, b: f64, c: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    let clip = |s: f64, e: f64| {
        let s = s.max(lo);
        let e = e.min(hi);
        if s <= e {
            Some((s, e))
        } else {
            None
        }
    };
    if a.abs() <= 1e-12 {
        if b.abs() <= 1e-15 {
            return if c <= 0.0 { clip(lo, hi) } else { None };
        }
        let root = -c / (2.0 * b);
        return if b > 0.0 {
            clip(lo, root)
        } else {
            clip(root, hi)
        };
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return if a > 0.0 { None } else { clip(lo, hi) };
    }
    let sq = disc.sqrt();
    // Numerically stable roots of a λ² + 2 b λ + c.
    let q = -(b + b.signum() * sq);
    let (mut r1, mut r2) = if q != 0.0 {
        (q / a, c / q)
    } else {
        (-b / a, -b / a)
    };
    if r1 > r2 {
        std::mem::swap(&mut r1, &mut r2);
    }
    if a > 0.0 {
        clip(r1, r2)
    } else {
        let left = clip(lo, r1);
        let right = clip(r2, hi);
        match (left, right) {
            (Some(l), Some(r)) => Some((l.0, r.1)),
            (l, r) => l.or(r),
        }
    }
}

/// Intersection with the torus slab by convexity of `g(λ) = ρ(λ) − r(h(λ))`.
fn torus_interval(
    r: &RayLocal,
    hc: f64,
    major: f64,
    minor: f64,
    lo: f64,
    hi: f64,
) -> Option<(f64, f64)> {
    let outer = major + minor;
    if r.min_rho_sq() > outer * outer {
        return None;
    }
    if !(lo.is_finite() && hi.is_finite()) {
        // Ray perpendicular to the axis: constant height, a disc of radius r(h).
        let dh = r.qh - hc;
        let rad = major + (minor * minor - dh * dh).max(0.0).sqrt();
        return quad_le_zero(r.w1sq, r.w0d, r.w0sq - rad * rad, lo, hi);
    }
    // Bracket inside the circumscribing cylinder ρ ≤ major + minor.
    let (c0, c1) = quad_le_zero(r.w1sq, r.w0d, r.w0sq - outer * outer, lo, hi)?;
    let g = |l: f64| {
        let dh = r.qh + r.ad * l - hc;
        r.rho(l) - major - (minor * minor - dh * dh).max(0.0).sqrt()
    };
    // Find a point with g <= 0: inner cylinder first, then golden-section minimisation.
    let inside = match quad_le_zero(r.w1sq, r.w0d, r.w0sq - major * major, c0, c1) {
        Some((s, e)) if g(0.5 * (s + e)) <= 0.0 => Some(0.5 * (s + e)),
        _ => {
            let (mut a, mut b) = (c0, c1);
            let phi = 0.618_033_988_749_895;
            let mut x1 = b - phi * (b - a);
            let mut x2 = a + phi * (b - a);
            let (mut f1, mut f2) = (g(x1), g(x2));
            let mut found = None;
            for _ in 0..80 {
                if f1 <= 0.0 {
                    found = Some(x1);
                    break;
                }
                if f2 <= 0.0 {
                    found = Some(x2);
                    break;
                }
                if b - a < TORUS_TOL_MM {
                    break;
                }
                if f1 < f2 {
                    b = x2;
                    x2 = x1;
                    f2 = f1;
                    x1 = b - phi * (b - a);
                    f1 = g(x1);
                } else {
                    a = x1;
                    x1 = x2;
                    f1 = f2;
                    x2 = a + phi * (b - a);
                    f2 = g(x2);
                }
            }
            found
        }
    };
    let m = inside?;
    let bisect = |mut out: f64, mut inn: f64| {
        if g(out) <= 0.0 {
            return out;
        }
        while (out - inn).abs() > TORUS_TOL_MM {
            let mid = 0.5 * (out + inn);
            if g(mid) <= 0.0 {
                inn = mid;
            } else {
                out = mid;
            }
        }
        0.5 * (out + inn)
    };
    Some((bisect(c0, m), bisect(c1, m)))
}

/// A solid of revolution about the tool axis made of stacked convex pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct RevolvedSolid {
    pieces: Vec<Piece>,
    h_min: f64,
    h_max: f64,
    r_max: f64,
}

impl RevolvedSolid {
    /// Builds from pieces (empty slabs are dropped).
    pub fn new(pieces: Vec<Piece>) -> Self {
        let pieces: Vec<Piece> = pieces
            .into_iter()
            .filter(|p| {
                let (a, b) = p.heights();
                b > a
            })
            .collect();
        let h_min = pieces
            .iter()
            .map(|p| p.heights().0)
            .fold(f64::INFINITY, f64::min);
        let h_max = pieces
            .iter()
            .map(|p| p.heights().1)
            .fold(f64::NEG_INFINITY, f64::max);
        let r_max = pieces.iter().map(Piece::max_radius).fold(0.0, f64::max);
        Self {
            pieces,
            h_min,
            h_max,
            r_max,
        }
    }

    /// The cutting part of a cutter: its shape's profile from the tip up to the flute length.
    pub fn cutting_part(cutter: &Cutter) -> Self {
        let h = cutter.flute_length;
        let pieces = match cutter.shape {
            CutterShape::FlatEnd { radius } => vec![Piece::Frustum {
                h0: 0.0,
                h1: h,
                r0: radius,
                r1: radius,
            }],
            CutterShape::BallEnd { radius } => vec![
                Piece::Sphere {
                    h0: 0.0,
                    h1: radius.min(h),
                    hc: radius,
                    radius,
                },
                Piece::Frustum {
                    h0: radius,
                    h1: h,
                    r0: radius,
                    r1: radius,
                },
            ],
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => {
                let major = radius - corner_radius;
                let corner = if major <= 1e-12 {
                    Piece::Sphere {
                        h0: 0.0,
                        h1: corner_radius.min(h),
                        hc: corner_radius,
                        radius: corner_radius,
                    }
                } else {
                    Piece::Torus {
                        h0: 0.0,
                        h1: corner_radius.min(h),
                        hc: corner_radius,
                        major,
                        minor: corner_radius,
                    }
                };
                vec![
                    corner,
                    Piece::Frustum {
                        h0: corner_radius,
                        h1: h,
                        r0: radius,
                        r1: radius,
                    },
                ]
            }
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => {
                let h_t = ball_radius * (1.0 - half_angle.sin());
                let r_t = ball_radius * half_angle.cos();
                vec![
                    Piece::Sphere {
                        h0: 0.0,
                        h1: h_t.min(h),
                        hc: ball_radius,
                        radius: ball_radius,
                    },
                    Piece::Frustum {
                        h0: h_t,
                        h1: h,
                        r0: r_t,
                        r1: r_t + (h - h_t).max(0.0) * half_angle.tan(),
                    },
                ]
            }
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            } => vec![Piece::Frustum {
                h0: 0.0,
                h1: h,
                r0: tip_radius,
                r1: tip_radius + h * half_angle.tan(),
            }],
        };
        Self::new(pieces)
    }

    /// The non-cutting parts: shank from the flute length to the holder face, then each
    /// holder segment (each a separate convex frustum).
    pub fn non_cutting_parts(cutter: &Cutter) -> Self {
        let mut pieces = vec![Piece::Frustum {
            h0: cutter.flute_length,
            h1: cutter.overall_length,
            r0: cutter.shank_radius,
            r1: cutter.shank_radius,
        }];
        let mut base = cutter.overall_length;
        for seg in &cutter.holder {
            pieces.push(Piece::Frustum {
                h0: base,
                h1: base + seg.length,
                r0: seg.bottom_radius,
                r1: seg.top_radius,
            });
            base += seg.length;
        }
        Self::new(pieces)
    }

    /// The pieces, bottom to top.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// Whether the solid has no volume.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// Lowest height of the solid.
    pub fn h_min(&self) -> f64 {
        self.h_min
    }

    /// Highest height of the solid.
    pub fn h_max(&self) -> f64 {
        self.h_max
    }

    /// Largest radius.
    pub fn r_max(&self) -> f64 {
        self.r_max
    }

    /// Hull of the piece intervals (exact for a convex solid, i.e. a cutting part).
    #[inline]
    pub fn ray_hull(&self, r: &RayLocal) -> Option<(f64, f64)> {
        if r.min_rho_sq() > self.r_max * self.r_max {
            return None;
        }
        let mut out: Option<(f64, f64)> = None;
        for p in &self.pieces {
            if let Some((s, e)) = p.ray_interval(r) {
                out = Some(match out {
                    Some((a, b)) => (a.min(s), b.max(e)),
                    None => (s, e),
                });
            }
        }
        out
    }

    /// Whether the point at height `h` and squared radial distance `rho_sq` lies farther than
    /// `margin` from every piece (so from the solid): beyond the piece's slab, or beyond its
    /// side (frustum: the side line moved out by `margin·(1 + k²/2) ≥ margin·√(1 + k²)`,
    /// `k` the slope; ball: radius plus `margin`; torus: its outer cylinder). No square root.
    /// O(pieces).
    pub fn outside_by(&self, h: f64, rho_sq: f64, margin: f64) -> bool {
        self.pieces.iter().all(|p| {
            let (h0, h1) = p.heights();
            if h < h0 - margin || h > h1 + margin {
                return true;
            }
            let lim = match *p {
                Piece::Frustum { r0, r1, .. } => {
                    let k = if h1 > h0 { (r1 - r0) / (h1 - h0) } else { 0.0 };
                    (r0 + k * (h - h0)).max(0.0) + margin * (1.0 + 0.5 * k * k)
                }
                Piece::Sphere { hc, radius, .. } => {
                    let r = radius + margin;
                    return (h - hc) * (h - hc) + rho_sq > r * r;
                }
                Piece::Torus { major, minor, .. } => major + minor + margin,
            };
            rho_sq > lim * lim
        })
    }

    /// Whether the point at height `h` and squared radial distance `rho_sq` lies inside one
    /// piece at a distance larger than `margin` from every face of that piece (a sufficient
    /// condition for lying inside the solid by `margin`; a torus piece never qualifies).
    /// O(pieces).
    pub fn inside_by(&self, h: f64, rho_sq: f64, margin: f64) -> bool {
        self.pieces.iter().any(|p| {
            let (h0, h1) = p.heights();
            if h < h0 + margin || h > h1 - margin {
                return false;
            }
            match *p {
                Piece::Frustum { r0, r1, .. } => {
                    let k = (r1 - r0) / (h1 - h0);
                    let lim = r0 + k * (h - h0) - margin * (1.0 + 0.5 * k * k);
                    lim > 0.0 && rho_sq < lim * lim
                }
                Piece::Sphere { hc, radius, .. } => {
                    let lim = radius - margin;
                    lim > 0.0 && (h - hc) * (h - hc) + rho_sq < lim * lim
                }
                Piece::Torus { .. } => false,
            }
        })
    }

    /// Whether a point at height `h` and radial distance `rho` lies inside the solid.
    pub fn contains_local(&self, h: f64, rho: f64) -> bool {
        self.pieces.iter().any(|p| {
            let (a, b) = p.heights();
            h >= a && h <= b && rho <= p.radius_at(h)
        })
    }

    /// Signed distance (negative inside) of the point at (`h`, `rho`) of the meridional half
    /// plane to the solid, computed in that plane (exact for solids of revolution: the
    /// nearest boundary point lies in the point's meridional plane). The section is sampled
    /// as a polygon with chord error below `chord_tol`.
    pub fn signed_distance_local(&self, h: f64, rho: f64, chord_tol: f64) -> f64 {
        let poly = self.meridian_polygon(chord_tol);
        let mut best = f64::INFINITY;
        for w in poly.windows(2) {
            let (a, b) = (w[0], w[1]);
            let ab = (b.0 - a.0, b.1 - a.1);
            let ap = (h - a.0, rho - a.1);
            let l2 = ab.0 * ab.0 + ab.1 * ab.1;
            let t = if l2 > 0.0 {
                ((ap.0 * ab.0 + ap.1 * ab.1) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let dx = ap.0 - t * ab.0;
            let dy = ap.1 - t * ab.1;
            best = best.min((dx * dx + dy * dy).sqrt());
        }
        if self.contains_local(h, rho) {
            -best
        } else {
            best
        }
    }

    /// Closed polygon (h, ρ) of the meridional section mirrored about nothing: from the tip
    /// on the axis up the profile to the top and back down the axis.
    pub fn meridian_polygon(&self, chord_tol: f64) -> Vec<(f64, f64)> {
        let mut pts = vec![(self.h_min, 0.0)];
        for p in &self.pieces {
            let (a, b) = p.heights();
            let n = match p {
                Piece::Frustum { .. } => 1,
                Piece::Sphere { radius, .. } => segments_for(*radius, b - a, chord_tol),
                Piece::Torus { minor, .. } => segments_for(*minor, b - a, chord_tol),
            };
            for i in 0..=n {
                let h = a + (b - a) * i as f64 / n as f64;
                pts.push((h, p.radius_at(h)));
            }
        }
        pts.push((self.h_max, 0.0));
        pts.push((self.h_min, 0.0));
        pts
    }
}

fn segments_for(radius: f64, span: f64, chord_tol: f64) -> usize {
    // Arc of length ≈ span·π/2 on a circle of `radius`; chord error r(1 − cos(θ/2)).
    let tol = chord_tol.max(1e-9);
    let dtheta = 2.0 * (1.0 - (tol / radius.max(1e-12)).min(1.0)).acos();
    let total = (span / radius.max(1e-12)).min(1.0) * std::f64::consts::FRAC_PI_2 * 2.0;
    ((total / dtheta.max(1e-6)).ceil() as usize).clamp(2, 10_000)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(
        solid: &RevolvedSolid,
        d: usize,
        du: f64,
        dv: f64,
        axis: [f64; 3],
    ) -> Option<(f64, f64)> {
        let mut first = None;
        let mut last = None;
        let n = 40_000;
        for i in 0..=n {
            let l = -20.0 + 40.0 * i as f64 / n as f64;
            let mut q = [0.0; 3];
            q[d] = l;
            q[(d + 1) % 3] = du;
            q[(d + 2) % 3] = dv;
            let h = q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2];
            let r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - h * h;
            if solid.contains_local(h, r2.max(0.0).sqrt()) {
                if first.is_none() {
                    first = Some(l);
                }
                last = Some(l);
            }
        }
        Some((first?, last?))
    }

    fn shapes() -> Vec<Cutter> {
        let mk = |s| Cutter::new("t", s, 8.0, 2.0, 30.0).unwrap();
        vec![
            mk(CutterShape::FlatEnd { radius: 3.0 }),
            mk(CutterShape::BallEnd { radius: 3.0 }),
            mk(CutterShape::BullNose {
                radius: 3.0,
                corner_radius: 1.0,
            }),
            mk(CutterShape::TaperedBallEnd {
                ball_radius: 1.5,
                half_angle: 0.1,
            }),
            mk(CutterShape::TaperedFlatEnd {
                tip_radius: 1.0,
                half_angle: 0.2,
            }),
        ]
    }

    #[test]
    fn ray_intervals_match_brute_force_membership() {
        let axes = [
            [0.0, 0.0, 1.0],
            [0.0, 0.6, 0.8],
            [0.48, -0.6, 0.64],
            [1.0, 0.0, 0.0],
        ];
        let step = 40.0 / 40_000.0;
        for c in shapes() {
            let s = RevolvedSolid::cutting_part(&c);
            for axis in axes {
                for d in 0..3 {
                    for (du, dv) in [(0.3, 0.2), (1.7, -0.4), (-2.5, 2.0), (0.0, 0.0), (2.9, 0.1)] {
                        let got = s.ray_hull(&RayLocal::new(d, du, dv, &axis));
                        let want = brute(&s, d, du, dv, axis);
                        match (got, want) {
                            (Some(g), Some(w)) => {
                                assert!(
                                    (g.0 - w.0).abs() <= 1.5 * step
                                        && (g.1 - w.1).abs() <= 1.5 * step,
                                    "{:?} axis {axis:?} d {d} ({du},{dv}): {g:?} vs {w:?}",
                                    c.shape
                                );
                            }
                            (None, None) => {}
                            (Some(g), None) => assert!(g.1 - g.0 < 2.0 * step, "{g:?}"),
                            (None, Some(w)) => assert!(w.1 - w.0 < 2.0 * step, "{w:?}"),
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn meridian_distance_of_ball_is_exact() {
        let c = Cutter::new("b", CutterShape::BallEnd { radius: 2.0 }, 10.0, 2.0, 30.0).unwrap();
        let s = RevolvedSolid::cutting_part(&c);
        // Point below the ball centre at distance 3: distance 1 outside.
        let d = s.signed_distance_local(-1.0, 0.0, 1e-5);
        assert!((d - 1.0).abs() < 1e-4, "{d}");
        let d = s.signed_distance_local(2.0, 1.5, 1e-5);
        assert!((d + 0.5).abs() < 1e-4, "{d}");
    }
}
