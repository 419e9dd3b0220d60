//! Centre interference of plunges (paper 000 §2, Figs. 1–3), measured exactly from the
//! geometry, independently of any stock simulation.
//!
//! # Definition
//! A plunge cutter's bottom cuts only on the ring of its cutting edge; the disk of radius
//! `r_core = R − plunge_edge_length` around the axis does not cut. A plunge *interferes* when
//! this centre disk, on its stroke from the start to the depth, passes through material by
//! more than [`INTERFERENCE_TRAVEL_TOL_MM`] of axial travel. Material is the blank (solid of
//! revolution, below its top) minus
//! - what earlier plunges removed: each plunge removes the half-infinite cylinder of its
//!   cutter radius about its axis above its tip (the cutter came down along the axis from
//!   the safety surface; exact for flat ends, which plunge cutters are);
//! - optionally a *cleared region* declared removed before the operation: the points whose
//!   hub meridional fraction exceeds a given value (the part of the channel an earlier
//!   section's operation roughed out, see the crate docs).
//!
//! # Computation
//! The centre disk is sampled on rings [`CORE_SAMPLE_SPACING_MM`] apart, each ring with
//! points at most that far apart around it (plus the centre). Each sample's stroke is a
//! segment; along it, membership in the blank (per piece of the blank's piecewise-linear
//! profile: a quadratic inequality in the stroke parameter), in each earlier cylinder (a
//! quadratic inequality and a half-line) are intervals in closed form; the cleared region's
//! boundary is found by bisection when the segment's end points lie on different sides of it
//! (one crossing assumed: strokes run across the hub, the boundary along its normal). The
//! length of the segment inside the blank and outside every removal is the sample's
//! travel through material; a plunge's value is the largest over its samples. The answer is
//! exact per sample; between samples the travel can be larger by at most what a
//! [`CORE_SAMPLE_SPACING_MM`] shift of the sample changes it (the boundaries are smooth).
//!
//! Cost: O(samples × nearby earlier plunges) closed-form interval computations per plunge;
//! earlier plunges whose cylinder cannot reach the core's swept cylinder are skipped by a
//! line-distance test. Plunges are checked in parallel (rayon).

use cam_core::{Point3, Vector3};
use impeller_model::{MeridionalCurve, Stock};
use nalgebra::Vector2;
use rayon::prelude::*;

/// Axial travel (mm) of the centre disk through uncut material above which a plunge counts
/// as interfering (the threshold: below it is contact noise, not cutting).
pub const INTERFERENCE_TRAVEL_TOL_MM: f64 = 0.01;
/// Spacing (mm) of the centre-disk samples: well below any cutting-edge length, so a leftover
/// layer narrower than this is the only thing the sampling can miss.
pub const CORE_SAMPLE_SPACING_MM: f64 = 0.25;

/// One plunge stroke.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    /// Tool tip at the start of the stroke.
    pub start: Point3,
    /// Tool tip at depth.
    pub end: Point3,
    /// Unit tool axis (tip → spindle).
    pub axis: Vector3,
    /// Cutter radius (mm).
    pub radius: f64,
    /// Radius of the non-cutting centre disk (mm).
    pub core_radius: f64,
}

/// Material removed before the operation: the points whose meridional fraction on the hub
/// contour exceeds `fraction`.
#[derive(Debug, Clone, Copy)]
pub struct ClearedRegion<'a> {
    /// The hub contour.
    pub hub: &'a MeridionalCurve,
    /// Fraction beyond which (toward the outlet) everything counts as removed.
    pub fraction: f64,
}

impl ClearedRegion<'_> {
    fn contains(&self, p: &Vector3) -> bool {
        let zr = Vector2::new(p.z, p.x.hypot(p.y));
        let (t, _) = self.hub.closest(zr);
        self.hub.arc_length_at(t) / self.hub.length_mm() > self.fraction
    }
}

/// The material the strokes run through.
#[derive(Debug, Clone, Copy)]
pub struct Material<'a> {
    /// The blank.
    pub stock: &'a Stock,
    /// What an earlier operation cleared, if anything.
    pub cleared: Option<ClearedRegion<'a>>,
}

/// Closed interval list helper: the parameters in `[lo, hi]` where `a τ² + b τ + c ≤ 0`.
fn quad_le0(a: f64, b: f64, c: f64, lo: f64, hi: f64, out: &mut Vec<(f64, f64)>) {
    let scale = a.abs().max(b.abs()).max(c.abs()).max(1e-300);
    if a.abs() <= 1e-14 * scale {
        if b.abs() <= 1e-300 {
            if c <= 0.0 {
                out.push((lo, hi));
            }
            return;
        }
        let r = -c / b;
        let (x, y) = if b > 0.0 {
            (lo, r.min(hi))
        } else {
            (r.max(lo), hi)
        };
        if x < y {
            out.push((x, y));
        }
        return;
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        if a < 0.0 {
            out.push((lo, hi));
        }
        return;
    }
    let sq = disc.sqrt();
    // Numerically stable roots.
    let qq = -0.5 * (b + b.signum() * sq);
    let (mut r1, mut r2) = if qq != 0.0 {
        (qq / a, c / qq)
    } else {
        (0.0, 0.0)
    };
    if r1 > r2 {
        std::mem::swap(&mut r1, &mut r2);
    }
    if a > 0.0 {
        let (x, y) = (r1.max(lo), r2.min(hi));
        if x < y {
            out.push((x, y));
        }
    } else {
        if lo < r1.min(hi) {
            out.push((lo, r1.min(hi)));
        }
        if r2.max(lo) < hi {
            out.push((r2.max(lo), hi));
        }
    }
}

/// Parameters `τ ∈ [0, len]` of `x0 + τ·d` inside the blank.
fn stock_intervals(stock: &Stock, x0: &Vector3, d: &Vector3, len: f64, out: &mut Vec<(f64, f64)>) {
    let prof = stock.profile_zr();
    for w in prof.windows(2) {
        let (za, ra, zb, rb) = (w[0][0], w[0][1], w[1][0], w[1][1]);
        // τ-range where z ∈ [za, zb].
        let (mut lo, mut hi) = (0.0f64, len);
        if d.z.abs() < 1e-300 {
            if x0.z < za || x0.z > zb {
                continue;
            }
        } else {
            let (t1, t2) = ((za - x0.z) / d.z, (zb - x0.z) / d.z);
            lo = lo.max(t1.min(t2));
            hi = hi.min(t1.max(t2));
        }
        if lo >= hi {
            continue;
        }
        // ρ²(τ) − R(τ)² ≤ 0 with R linear in z.
        let k = (rb - ra) / (zb - za);
        let r0 = ra + k * (x0.z - za);
        let r1 = k * d.z;
        let a = d.x * d.x + d.y * d.y - r1 * r1;
        let b = 2.0 * (x0.x * d.x + x0.y * d.y) - 2.0 * r0 * r1;
        let c = x0.x * x0.x + x0.y * x0.y - r0 * r0;
        quad_le0(a, b, c, lo, hi, out);
    }
}

/// Parameters `τ ∈ [0, len]` of `x0 + τ·d` inside the removal cylinder of `s`.
fn cylinder_intervals(s: &Stroke, x0: &Vector3, d: &Vector3, len: f64, out: &mut Vec<(f64, f64)>) {
    let a_ax = s.axis;
    let e = x0 - s.end.coords;
    // Axial height above the tip: h(τ) = h0 + h1 τ ≥ 0.
    let (h0, h1) = (e.dot(&a_ax), d.dot(&a_ax));
    let (mut lo, mut hi) = (0.0f64, len);
    if h1.abs() < 1e-300 {
        if h0 < 0.0 {
            return;
        }
    } else {
        let r = -h0 / h1;
        if h1 > 0.0 {
            lo = lo.max(r);
        } else {
            hi = hi.min(r);
        }
    }
    if lo >= hi {
        return;
    }
    let ep = e - a_ax * h0;
    let dp = d - a_ax * h1;
    quad_le0(
        dp.norm_squared(),
        2.0 * ep.dot(&dp),
        ep.norm_squared() - s.radius * s.radius,
        lo,
        hi,
        out,
    );
}

/// Measure of `base` minus the union of `remove` (both lists of intervals).
fn measure_minus(base: &mut [(f64, f64)], remove: &mut [(f64, f64)]) -> f64 {
    base.sort_by(|a, b| a.0.total_cmp(&b.0));
    remove.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    // Merge base into disjoint intervals, then subtract the sorted removals.
    let mut merged: Vec<(f64, f64)> = Vec::with_capacity(base.len());
    for &(a, b) in base.iter() {
        match merged.last_mut() {
            Some(l) if a <= l.1 => l.1 = l.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    for (a, b) in merged {
        let mut cur = a;
        for &(ra, rb) in remove.iter() {
            if rb <= cur {
                continue;
            }
            if ra >= b {
                break;
            }
            if ra > cur {
                total += ra.min(b) - cur;
            }
            cur = cur.max(rb);
            if cur >= b {
                break;
            }
        }
        if cur < b {
            total += b - cur;
        }
    }
    total
}

/// Sample offsets of the centre disk in its plane (frame `e1, e2`).
fn core_samples(core_radius: f64, e1: &Vector3, e2: &Vector3) -> Vec<Vector3> {
    let mut out = vec![Vector3::zeros()];
    let rings = (core_radius / CORE_SAMPLE_SPACING_MM).ceil() as usize;
    for i in 1..=rings {
        let rho = core_radius * i as f64 / rings as f64;
        let n = ((std::f64::consts::TAU * rho / CORE_SAMPLE_SPACING_MM).ceil() as usize).max(6);
        for k in 0..n {
            let th = std::f64::consts::TAU * k as f64 / n as f64;
            out.push((e1 * th.cos() + e2 * th.sin()) * rho);
        }
    }
    out
}

/// Whether the infinite axis line of `other` can come within `reach` of the centre line of
/// `s`'s stroke (a cheap necessary condition for any sample to meet `other`'s cylinder).
fn may_meet(s: &Stroke, other: &Stroke, reach: f64) -> bool {
    let d = s.end - s.start;
    let len = d.norm();
    if len <= 0.0 {
        return true;
    }
    let d = d / len;
    let mut tmp = Vec::with_capacity(2);
    let e = s.start.coords - other.end.coords;
    let a = other.axis;
    let (h0, h1) = (e.dot(&a), d.dot(&a));
    let ep = e - a * h0;
    let dp = d - a * h1;
    let r = other.radius + reach;
    quad_le0(
        dp.norm_squared(),
        2.0 * ep.dot(&dp),
        ep.norm_squared() - r * r,
        0.0,
        len,
        &mut tmp,
    );
    !tmp.is_empty()
}

/// The largest axial travel (mm) of stroke `i`'s centre disk through material left by the
/// strokes before it (in the given order), for every stroke.
pub fn core_travel(strokes: &[Stroke], material: &Material<'_>) -> Vec<f64> {
    (0..strokes.len())
        .into_par_iter()
        .map(|i| travel_of(strokes, i, material))
        .collect()
}

/// [`core_travel`] of stroke `i` alone.
pub fn travel_of(strokes: &[Stroke], i: usize, material: &Material<'_>) -> f64 {
    let s = &strokes[i];
    if s.core_radius <= 0.0 {
        // No centre disk: the centre point alone (zero-radius disk) still cannot cut.
    }
    let dvec = s.end - s.start;
    let len = dvec.norm();
    if len <= 0.0 {
        return 0.0;
    }
    let d = dvec / len;
    let (e1, e2) = crate::axial_depth::perpendicular_frame(&s.axis);
    let samples = core_samples(s.core_radius.max(0.0), &e1, &e2);
    let near: Vec<&Stroke> = strokes[..i]
        .iter()
        .filter(|o| may_meet(s, o, s.core_radius))
        .collect();
    let mut base = Vec::with_capacity(8);
    let mut remove = Vec::with_capacity(near.len() * 2 + 2);
    let mut worst: f64 = 0.0;
    for off in &samples {
        let x0 = s.start.coords + off;
        base.clear();
        remove.clear();
        stock_intervals(material.stock, &x0, &d, len, &mut base);
        if base.is_empty() {
            continue;
        }
        for o in &near {
            cylinder_intervals(o, &x0, &d, len, &mut remove);
        }
        if let Some(c) = &material.cleared {
            let a_in = c.contains(&x0);
            let b_in = c.contains(&(x0 + d * len));
            match (a_in, b_in) {
                (true, true) => remove.push((0.0, len)),
                (false, false) => {}
                _ => {
                    let (mut lo, mut hi) = (0.0f64, len);
                    for _ in 0..50 {
                        let mid = 0.5 * (lo + hi);
                        if c.contains(&(x0 + d * mid)) == a_in {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    let cut = 0.5 * (lo + hi);
                    remove.push(if a_in { (0.0, cut) } else { (cut, len) });
                }
            }
        }
        worst = worst.max(measure_minus(&mut base, &mut remove));
    }
    worst
}

/// Number of strokes whose centre travel through material exceeds
/// [`INTERFERENCE_TRAVEL_TOL_MM`].
pub fn interfering_count(travel: &[f64]) -> usize {
    travel
        .iter()
        .filter(|&&t| t > INTERFERENCE_TRAVEL_TOL_MM)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stroke(x: f64, depth: f64, axis: Vector3) -> Stroke {
        let a = axis.normalize();
        let end = Point3::new(x, 0.0, depth);
        Stroke {
            start: end + a * 40.0,
            end,
            axis: a,
            radius: 10.0,
            core_radius: 4.0,
        }
    }

    /// A blank 100 mm in radius from z = 0 to z = 20; strokes end at x ≈ 50.
    fn blank() -> Stock {
        Stock::cylinder(200.0, 20.0).unwrap()
    }

    #[test]
    fn second_plunge_inside_the_first_does_not_interfere() {
        // Two vertical plunges 5 mm apart to the same depth: the second one's centre disk
        // (radius 4, centre 5 from the first axis: reaches 9 < 10) lies in the first hole.
        let st = blank();
        let m = Material {
            stock: &st,
            cleared: None,
        };
        let s = [
            stroke(50.0, 5.0, Vector3::z()),
            stroke(55.0, 5.0, Vector3::z()),
        ];
        let t = core_travel(&s, &m);
        // The first plunge drills with its core: 15 mm of blank (z from 20 down to 5).
        assert!((t[0] - 15.0).abs() < 1e-9, "{}", t[0]);
        assert!(t[1] < 1e-12, "{}", t[1]);
        assert_eq!(interfering_count(&t), 1);
    }

    #[test]
    fn deeper_second_plunge_runs_into_the_leftover() {
        // The second plunge goes 0.5 mm deeper: its core travels 0.5 mm through the layer
        // below the first hole's bottom.
        let st = blank();
        let m = Material {
            stock: &st,
            cleared: None,
        };
        let s = [
            stroke(50.0, 5.0, Vector3::z()),
            stroke(55.0, 4.5, Vector3::z()),
        ];
        let t = core_travel(&s, &m);
        assert!((t[1] - 0.5).abs() < 1e-9, "{}", t[1]);
        // Tilted first plunge (its bottom plane rises toward +x): the second plunge at the
        // same tip depth meets the wedge the tilt left under its core. At the core's far
        // edge (x = 57, 7 mm from the first tip along x) the first bottom is
        // 7·tan(0.1 rad) higher: that is the deepest travel (the first hole still contains
        // the core's whole stroke above it: its axis leans 1.5 mm over 15 mm of blank).
        let s = [
            stroke(50.0, 5.0, Vector3::new(-0.1f64.sin(), 0.0, 0.1f64.cos())),
            stroke(53.0, 5.0, Vector3::z()),
        ];
        let t = core_travel(&s, &m);
        let expect = 7.0 * 0.1f64.tan();
        assert!((t[1] - expect).abs() < 2e-3, "{} vs {}", t[1], expect);
        assert!(interfering_count(&t[1..]) == 1);
        // Tilted the other way the first bottom drops toward the second: no leftover where
        // the core (x from 51 to 59, all beyond the first tip) runs.
        let s = [
            stroke(50.0, 5.0, Vector3::new(0.1f64.sin(), 0.0, 0.1f64.cos())),
            stroke(55.0, 5.0, Vector3::z()),
        ];
        let t = core_travel(&s, &m);
        assert!(t[1] < 1e-9, "{}", t[1]);
    }

    #[test]
    fn core_outside_the_blank_travels_through_nothing() {
        let st = blank();
        let m = Material {
            stock: &st,
            cleared: None,
        };
        // Centre at x = 106: core spans 102..110, outside the 100 mm blank.
        let s = [stroke(106.0, 5.0, Vector3::z())];
        assert!(core_travel(&s, &m)[0] < 1e-12);
    }

    #[test]
    fn measure_minus_subtracts_unions() {
        let mut base = vec![(0.0, 10.0), (5.0, 12.0)];
        let mut rem = vec![(1.0, 2.0), (1.5, 3.0), (11.0, 20.0)];
        assert!((measure_minus(&mut base, &mut rem) - 9.0).abs() < 1e-12);
    }
}
