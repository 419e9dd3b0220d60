//! Centre interference of plunges (paper 000 §2, Figs. 1–3), measured from the geometry
//! (closed-form intervals per sample, a closed-form bound where one earlier hole contains the
//! stroke), independently of any stock simulation.
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
//! - the *pilot holes* drilled before the operation ([`Material::drilled`]): each removes the
//!   half-infinite cylinder of the drill's radius about its axis above its tip, like a plunge
//!   (a flat-bottom drill cuts across its whole bottom);
//! - optionally a *cleared region* declared removed before the operation: the points whose
//!   hub meridional fraction exceeds a given value (the part of the channel an earlier
//!   section's operation roughed out, see the crate docs). Without it the measure is an upper
//!   bound of the real travel whatever earlier operations removed: the real material is a
//!   subset of the stock minus the removals counted here.
//!
//! # Computation
//! Per sample point of the centre disk, the stroke is a segment; along it, membership in the
//! blank (per piece of the blank's piecewise-linear profile: a quadratic inequality in the
//! stroke parameter) and in each earlier cylinder (a quadratic inequality and a half-line)
//! are intervals in closed form; the cleared region's boundary is found by bisection when the
//! segment's end points lie on different sides of it (one crossing assumed: strokes run
//! across the hub, the boundary along its normal). The length of the segment inside the blank
//! and outside every removal is the sample's travel through material, exact per sample. A
//! plunge's value is the largest over the disk, found in three stages:
//!
//! 1. **Certificate.** When one earlier removal contains the whole sweep radially, the
//!    travel through what lies below its bottom plane has a closed form (the plane's height
//!    is affine over the disk, lowest on the rim); it bounds the travel from above. A plunge
//!    whose bound is within the tolerance is clean, exactly, with no sampling — most plunges
//!    of a row whose centre stays in the previous hole.
//! 2. **Grid.** Rings [`CORE_SAMPLE_SPACING_MM`] apart with points that far apart on them
//!    (plus the centre). A value above the tolerance settles it (interfering; the value found
//!    is then a lower bound of the largest).
//! 3. **Refinement**, only when the grid found at most the tolerance: the leftovers met at
//!    the bottom of a stroke are wedges below earlier bottom planes, cut off by the walls of
//!    earlier cylinders and by the blank's surface; over each piece the travel is affine, so
//!    its largest value lies on the disk's rim or against such a wall, between grid points.
//!    The rim is sampled [`RIM_SAMPLE_SPACING_MM`] apart, and around the
//!    [`REFINED_SAMPLES`] largest samples that met material the disk is sampled at a fifth of
//!    the grid spacing, then around the largest at [`RIM_SAMPLE_SPACING_MM`].
//!
//! What this can still miss is a sliver narrower than the grid spacing that no grid or rim
//! sample touches; the plunge planner aims at half the tolerance to leave room for it
//! ([`crate::feed_plan::PLAN_TRAVEL_TARGET_MM`]). On `impeller-plunge-400` the planned
//! sections re-measured with the interior sampled 0.05 mm apart stay below the tolerance
//! (example `plan_plunge400 --fine`).
//!
//! Cost: O(1) per earlier plunge for the certificate; otherwise O(samples × (nearby earlier
//! plunges + profile pieces the stroke spans)) closed-form interval computations per plunge
//! (the profile pieces are found by bisection on the stroke's axial extent); earlier plunges
//! whose cylinder cannot reach the core's swept cylinder are skipped by a line-distance
//! test. Plunges are measured in parallel (rayon).

use cam_core::{Point3, Vector3};
use impeller_model::{MeridionalCurve, Stock};
use nalgebra::Vector2;
use rayon::prelude::*;

/// Axial travel (mm) of the centre disk through uncut material above which a plunge counts
/// as interfering (the threshold: below it is contact noise, not cutting).
pub const INTERFERENCE_TRAVEL_TOL_MM: f64 = 0.01;
/// Spacing (mm) of the samples of the centre disk's interior: well below any cutting-edge
/// length. The largest travel lies on the disk's rim or on an earlier footprint's boundary
/// (see the module docs), which are sampled [`RIM_SAMPLE_SPACING_MM`] apart.
pub const CORE_SAMPLE_SPACING_MM: f64 = 0.25;
/// Spacing (mm) of the samples on the centre disk's rim and on the boundaries of earlier
/// footprints across it: along them the travel changes by at most the slope between two
/// bottom planes (below 1 for leans under 45°) per mm, so by at most 0.005 mm between
/// neighbouring samples.
pub const RIM_SAMPLE_SPACING_MM: f64 = 0.01;
/// How many of the samples that met material get a refining patch around them (the
/// largest first).
pub const REFINED_SAMPLES: usize = 16;

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
    /// Pilot holes drilled before every stroke (their `core_radius` is not used).
    pub drilled: &'a [Stroke],
}

impl<'a> Material<'a> {
    /// The stock alone: no cleared region, no pilot hole.
    pub fn stock(stock: &'a Stock) -> Self {
        Self {
            stock,
            cleared: None,
            drilled: &[],
        }
    }
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

/// The pieces `profile[k..=k + 1]` of the blank's profile (sorted by `z`) that can meet
/// the axial band `[z_lo, z_hi]`: the range of `k` (bisection, O(log profile)).
fn profile_pieces(profile: &[[f64; 2]], z_lo: f64, z_hi: f64) -> std::ops::Range<usize> {
    if profile.len() < 2 {
        return 0..0;
    }
    let first = profile.partition_point(|p| p[0] < z_lo).saturating_sub(1);
    let last = profile
        .partition_point(|p| p[0] <= z_hi)
        .min(profile.len() - 1);
    first..last.max(first)
}

/// Parameters `τ ∈ [0, len]` of `x0 + τ·d` inside the blank, testing the profile pieces
/// `pieces` only (those the segment can reach; all of them: `0..profile.len() − 1`).
fn stock_intervals(
    stock: &Stock,
    pieces: std::ops::Range<usize>,
    x0: &Vector3,
    d: &Vector3,
    len: f64,
    out: &mut Vec<(f64, f64)>,
) {
    let prof = stock.profile_zr();
    let pieces = pieces.start.min(prof.len())..(pieces.end + 1).min(prof.len());
    for w in prof[pieces].windows(2) {
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
fn core_samples(core_radius: f64, e1: &Vector3, e2: &Vector3, spacing: f64) -> Vec<Vector3> {
    let mut out = vec![Vector3::zeros()];
    let spacing = spacing.max(1e-3);
    let rings = (core_radius / spacing).ceil() as usize;
    for i in 1..=rings {
        let rho = core_radius * i as f64 / rings as f64;
        let n = ((std::f64::consts::TAU * rho / spacing).ceil() as usize).max(6);
        for k in 0..n {
            let th = std::f64::consts::TAU * k as f64 / n as f64;
            out.push((e1 * th.cos() + e2 * th.sin()) * rho);
        }
    }
    out
}

/// Whether the travel of `later` may depend on `earlier` having been machined before it (a
/// necessary condition: `earlier`'s axis line comes within its radius of `later`'s centre
/// disk's sweep). Used to re-measure only the plunges a changed one can affect.
pub fn may_affect(later: &Stroke, earlier: &Stroke) -> bool {
    may_meet(later, earlier, later.core_radius.max(0.0))
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
    travel_after(&strokes[i], &strokes[..i], material)
}

/// The largest axial travel (mm) of the centre disk of `s` through the material left by
/// `earlier` (machined before it, in any order) and by `material`'s pilot holes and cleared
/// region. A zero core radius measures the axis point alone. See the module docs for how it
/// is computed and how exact it is.
pub fn travel_after(s: &Stroke, earlier: &[Stroke], material: &Material<'_>) -> f64 {
    travel_sampled(s, earlier, material, CORE_SAMPLE_SPACING_MM)
}

/// The exact travel of `s`'s centre disk through what lies below the bottom of the single
/// removal `o`, when the whole sweep lies within `o`'s radius (`None` otherwise): an upper
/// bound of the travel through the material `o` leaves (other removals and the stock's
/// boundary only lower it). A sample `y` of the disk meets `o`'s bottom plane
/// `h(x) = (x − tip)·a = 0` on its segment, and runs below it for
/// `min(L, −h(x_end(y)) / |d·a|)`; `h(x_end(y))` is affine in `y`, smallest at
/// `h(c_end) − r_c·|a − (a·q)q|`. O(1).
fn single_removal_bound(s: &Stroke, o: &Stroke, d: &Vector3, len: f64) -> Option<f64> {
    let a = o.axis;
    let descent = -d.dot(&a);
    if descent <= 1e-9 {
        return None;
    }
    let r = s.core_radius.max(0.0);
    let radial = |c: &Point3| {
        let e = c - o.end;
        (e - a * e.dot(&a)).norm() + r <= o.radius
    };
    if !(radial(&s.start) && radial(&s.end)) {
        return None;
    }
    let sin = (1.0 - s.axis.dot(&a).powi(2)).max(0.0).sqrt();
    let lowest = (s.end - o.end).dot(&a) - r * sin;
    Some((-lowest).max(0.0).min(len * descent) / descent)
}

/// [`travel_after`] with the centre disk's interior sampled `spacing` mm apart (rings and
/// points on them) instead of [`CORE_SAMPLE_SPACING_MM`]; the rim and the footprint
/// boundaries are sampled [`RIM_SAMPLE_SPACING_MM`] apart (or `spacing` if finer).
pub fn travel_sampled(
    s: &Stroke,
    earlier: &[Stroke],
    material: &Material<'_>,
    spacing: f64,
) -> f64 {
    let dvec = s.end - s.start;
    let len = dvec.norm();
    if len <= 0.0 {
        return 0.0;
    }
    let d = dvec / len;
    let (e1, e2) = crate::axial_depth::perpendicular_frame(&s.axis);
    let core = s.core_radius.max(0.0);
    let near: Vec<&Stroke> = material
        .drilled
        .iter()
        .chain(earlier)
        .filter(|o| may_meet(s, o, core))
        .collect();
    // An earlier removal that contains the sweep radially bounds the travel exactly; when
    // the bound is within the tolerance the plunge is certified clean without sampling.
    let bound = near
        .iter()
        .filter_map(|o| single_removal_bound(s, o, &d, len))
        .fold(f64::INFINITY, f64::min);
    if bound <= INTERFERENCE_TRAVEL_TOL_MM {
        return bound;
    }
    // The profile pieces every sample's segment can reach: the stroke's axial extent widened
    // by the disk's.
    let reach_z = core * (1.0 - s.axis.z * s.axis.z).max(0.0).sqrt();
    let (za, zb) = (s.start.z.min(s.end.z), s.start.z.max(s.end.z));
    let pieces = profile_pieces(material.stock.profile_zr(), za - reach_z, zb + reach_z);
    let mut base = Vec::with_capacity(8);
    let mut remove = Vec::with_capacity(near.len() * 2 + 2);
    let mut at = |off: &Vector3| -> f64 {
        let x0 = s.start.coords + off;
        base.clear();
        remove.clear();
        stock_intervals(material.stock, pieces.clone(), &x0, &d, len, &mut base);
        if base.is_empty() {
            return 0.0;
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
        measure_minus(&mut base, &mut remove)
    };
    // Stage 1: the interior grid (its outer ring is the rim).
    let grid = core_samples(core, &e1, &e2, spacing);
    let mut hits: Vec<(Vector3, f64)> = Vec::new();
    let mut worst: f64 = 0.0;
    for off in &grid {
        let t = at(off);
        if t > 0.0 {
            hits.push((*off, t));
        }
        worst = worst.max(t);
    }
    if worst > INTERFERENCE_TRAVEL_TOL_MM || core <= 0.0 {
        // Interfering (the value found is a lower bound of the largest), or a bare axis.
        return worst.min(bound);
    }
    // Stage 2, where the answer is not yet clear: the rim every RIM_SAMPLE_SPACING_MM, and
    // around the REFINED_SAMPLES largest samples that met material, patches at a fifth of
    // the spacing and then,
    // around the largest, at RIM_SAMPLE_SPACING_MM (thin leftovers whose largest value lies
    // between the grid's samples).
    let fine = RIM_SAMPLE_SPACING_MM.min(spacing);
    let n = ((std::f64::consts::TAU * core / fine).ceil() as usize).max(6);
    for k in 0..n {
        let th = std::f64::consts::TAU * k as f64 / n as f64;
        let off = (e1 * th.cos() + e2 * th.sin()) * core;
        let t = at(&off);
        if t > 0.0 {
            hits.push((off, t));
        }
        worst = worst.max(t);
    }
    let in_disk = |y: &Vector3| y.norm() <= core;
    let mut patch = |centre: &Vector3, half: f64, step: f64, best: &mut (Vector3, f64)| {
        let m = (half / step).round() as i64;
        for i in -m..=m {
            for j in -m..=m {
                let y = centre + e1 * (i as f64 * step) + e2 * (j as f64 * step);
                let y = if in_disk(&y) {
                    y
                } else {
                    y * (core / y.norm())
                };
                let t = at(&y);
                if t > best.1 {
                    *best = (y, t);
                }
            }
        }
    };
    let mut best =
        hits.iter().copied().fold(
            (Vector3::zeros(), 0.0),
            |b, h| if h.1 > b.1 { h } else { b },
        );
    let medium = spacing / 5.0;
    hits.sort_by(|a, b| b.1.total_cmp(&a.1));
    for (y, _) in hits.iter().take(REFINED_SAMPLES) {
        patch(y, spacing, medium, &mut best);
    }
    if best.1 > 0.0 {
        let centre = best.0;
        patch(&centre, medium, fine, &mut best);
    }
    worst = worst.max(best.1);
    worst.min(bound)
}

/// Length (mm) of the axis segment of `s` (start → tip) that lies inside the blank: how deep
/// a drill along it cuts (a pilot hole's drilled depth).
pub fn depth_in_stock(s: &Stroke, stock: &Stock) -> f64 {
    let dvec = s.end - s.start;
    let len = dvec.norm();
    if len <= 0.0 {
        return 0.0;
    }
    let mut base = Vec::with_capacity(8);
    let profile = stock.profile_zr();
    let all = 0..profile.len().saturating_sub(1);
    stock_intervals(stock, all, &s.start.coords, &(dvec / len), len, &mut base);
    measure_minus(&mut base, &mut [])
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
        let m = Material::stock(&st);
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
        let m = Material::stock(&st);
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
        let m = Material::stock(&st);
        // Centre at x = 106: core spans 102..110, outside the 100 mm blank.
        let s = [stroke(106.0, 5.0, Vector3::z())];
        assert!(core_travel(&s, &m)[0] < 1e-12);
    }

    #[test]
    fn an_entry_into_virgin_stock_interferes_unless_a_pilot_was_drilled() {
        // A vertical plunge from above the blank's top (z = 20) down to z = 5: its centre
        // disk drills 15 mm through the blank.
        let st = blank();
        let entry = [stroke(50.0, 5.0, Vector3::z())];
        let t = core_travel(&entry, &Material::stock(&st));
        assert!((t[0] - 15.0).abs() < 1e-9, "{}", t[0]);
        assert_eq!(interfering_count(&t), 1);
        // A pilot hole along its axis to its depth, 0.5 mm wider in radius than the centre
        // disk, removes everything the disk passes through.
        let pilot = Stroke {
            radius: 4.5,
            core_radius: 0.0,
            ..entry[0]
        };
        let drilled = [pilot];
        let m = Material {
            drilled: &drilled,
            ..Material::stock(&st)
        };
        let t = core_travel(&entry, &m);
        assert!(t[0] <= 1e-12, "{}", t[0]);
        // A pilot stopping 1 mm short leaves 1 mm for the centre; one narrower than the disk
        // leaves the whole depth at the disk's rim.
        let short = [Stroke {
            end: pilot.end + Vector3::z(),
            ..pilot
        }];
        let m = Material {
            drilled: &short,
            ..Material::stock(&st)
        };
        assert!((core_travel(&entry, &m)[0] - 1.0).abs() < 1e-9);
        let narrow = [Stroke {
            radius: 3.0,
            ..pilot
        }];
        let m = Material {
            drilled: &narrow,
            ..Material::stock(&st)
        };
        assert!((core_travel(&entry, &m)[0] - 15.0).abs() < 1e-9);
    }

    #[test]
    fn the_single_removal_bound_is_the_sampled_travel_below_a_tilted_bottom() {
        // The first plunge's bottom tilted by 0.1 rad: the second, 3 mm away, meets the
        // wedge under its centre disk (see `deeper_second_plunge_runs_into_the_leftover`).
        // Its sweep lies within the first hole's radius, so the closed-form bound applies and
        // equals the largest sampled travel (the wedge is deepest on the disk's rim).
        let st = blank();
        // The second stroke starts 5 mm above the blank: its whole sweep lies within the
        // first hole's radius (10 mm) about the first's tilted axis.
        let second = stroke(53.0, 5.0, Vector3::z());
        let s = [
            stroke(50.0, 5.0, Vector3::new(-0.1f64.sin(), 0.0, 0.1f64.cos())),
            Stroke {
                start: Point3::new(53.0, 0.0, 25.0),
                ..second
            },
        ];
        let d = (s[1].end - s[1].start).normalize();
        let len = (s[1].end - s[1].start).norm();
        let bound = single_removal_bound(&s[1], &s[0], &d, len).unwrap_or(f64::NAN);
        let sampled = travel_sampled(&s[1], &s[..1], &Material::stock(&st), 0.01);
        assert!((bound - sampled).abs() < 1e-4, "{bound} vs {sampled}");
        assert!((bound - 7.0 * 0.1f64.tan()).abs() < 1e-9, "{bound}");
        // Laterally beyond the first hole's radius there is no bound.
        let far = stroke(62.0, 5.0, Vector3::z());
        assert!(single_removal_bound(&far, &s[0], &d, len).is_none());
    }

    #[test]
    fn measure_minus_subtracts_unions() {
        let mut base = vec![(0.0, 10.0), (5.0, 12.0)];
        let mut rem = vec![(1.0, 2.0), (1.5, 3.0), (11.0, 20.0)];
        assert!((measure_minus(&mut base, &mut rem) - 9.0).abs() < 1e-12);
    }
}
