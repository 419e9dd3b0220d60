//! Path planning of one channel area on one depth level, in the level's developed plane.
//!
//! Coordinates: `x = s` (mm of arc length along the level contour from the inlet) and
//! `y = r(s)·θ` (mm along the parallel circle), so that at fixed `s` distances in `y` are true
//! arc lengths across the channel. An area is a *graph region* `left(s) ≤ y ≤ right(s)` over
//! a grid `s_0 < … < s_n` (inlet → outlet), the boundaries being the blades offset by cutter
//! radius plus allowances, linear between grid points.
//!
//! * **Isoparametric baseline**: paths of constant cross-channel fraction
//!   `y = left + f·(right − left)`, `f = i/(N−1)`, with `N = ⌈max w / step⌉ + 1` paths so that
//!   the widest section (usually the outlet) is covered at the interval `step`.
//! * **Triangle planning** (paper 001 §3, Fig. "triangle tool path"): the left boundary offset
//!   toward the middle by `k·step` (`L_k`) and the right by `k·step` (`R_k`). Ordered
//!   `L_0, R_0, L_1, R_1, …`, path `j` is needed where the width exceeds `(j − 1)·step`; i.e.
//!   `L_k` is kept from its crossing with `R_{k−1}` and `R_k` from its crossing with `L_k`
//!   toward the outlet — the parts from the inlet to the crossings are deleted. The crossings
//!   are found with [`nurbs::intersect::intersect_curves`] on cubic interpolants of the offset
//!   curves, so a channel that narrows again yields several pieces. Neighbouring kept paths
//!   are at most `step` apart everywhere, the same covering as the baseline with fewer and
//!   shorter paths where the channel is narrow.
//!
//! Cost: O(K·n) for K offsets on an n-point grid plus one curve intersection per offset.

use nalgebra::Vector2;
use nurbs::fit::{interpolate_curve, Parametrisation};
use nurbs::intersect::{intersect_curves, CurveIntersection, IntersectOptions};

/// Crossing tolerance of the offset-curve intersection (mm): far below any step-over.
pub const CROSSING_TOL_MM: f64 = 1e-7;

/// Largest number of offsets per side: a guard against a step-over tiny against the width
/// (a 100 mm wide channel at a 0.01 mm step needs 5000); reported as an error beyond.
pub const MAX_OFFSETS: usize = 5000;

/// A graph region `left(s) ≤ y ≤ right(s)` on a grid of `s`.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Increasing arc-length grid (mm).
    pub s: Vec<f64>,
    /// Left boundary `y` at each grid point (mm).
    pub left: Vec<f64>,
    /// Right boundary `y` at each grid point (mm), `≥ left`.
    pub right: Vec<f64>,
}

/// How consecutive paths are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Linking {
    /// Alternate cutting direction; each path ends where the next starts its way back.
    ZigZag,
    /// Every path cut from the inlet toward the outlet.
    OneWay,
}

/// A planar path: (s, y) points in cutting order.
pub type Path2 = Vec<[f64; 2]>;

/// Errors of the planar planning.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Plan2dError {
    /// The region grid is malformed.
    #[error("channel area: {0}")]
    Region(String),
    /// The step-over needs too many paths.
    #[error("step-over {step:.5} mm needs {needed} offsets per side (limit {MAX_OFFSETS})")]
    TooManyPaths {
        /// The interval.
        step: f64,
        /// Offsets needed.
        needed: usize,
    },
    /// Building or intersecting offset curves failed.
    #[error("offset curve: {0}")]
    Curve(String),
}

impl Region {
    /// Checks the grid: ≥ 2 points, `s` increasing, finite, `left ≤ right`.
    pub fn validate(&self) -> Result<(), Plan2dError> {
        let n = self.s.len();
        if n < 2 || self.left.len() != n || self.right.len() != n {
            return Err(Plan2dError::Region(format!(
                "needs ≥ 2 grid points with matching boundaries (got {n})"
            )));
        }
        for i in 0..n {
            if !(self.s[i].is_finite() && self.left[i].is_finite() && self.right[i].is_finite()) {
                return Err(Plan2dError::Region(format!("grid point {i} is not finite")));
            }
            if i > 0 && self.s[i] <= self.s[i - 1] {
                return Err(Plan2dError::Region(format!("s not increasing at {i}")));
            }
            if self.left[i] > self.right[i] {
                return Err(Plan2dError::Region(format!(
                    "boundaries cross at s = {:.3} mm (left {:.3} > right {:.3})",
                    self.s[i], self.left[i], self.right[i]
                )));
            }
        }
        Ok(())
    }

    /// Width `right − left` at `s` (linear between grid points, clamped to the grid).
    pub fn width(&self, s: f64) -> f64 {
        let (l, r) = self.bounds(s);
        r - l
    }

    /// `(left, right)` at `s` (linear between grid points, clamped to the grid).
    pub fn bounds(&self, s: f64) -> (f64, f64) {
        let n = self.s.len();
        let k = self.s.partition_point(|&x| x <= s).clamp(1, n - 1);
        let (a, b) = (self.s[k - 1], self.s[k]);
        let t = ((s - a) / (b - a)).clamp(0.0, 1.0);
        (
            self.left[k - 1] + t * (self.left[k] - self.left[k - 1]),
            self.right[k - 1] + t * (self.right[k] - self.right[k - 1]),
        )
    }

    /// `∫ (right − left) ds` over the grid (trapezoidal; negative widths count as 0): the
    /// developed area of the region.
    pub fn width_integral(&self) -> f64 {
        let w = |k: usize| (self.right[k] - self.left[k]).max(0.0);
        (1..self.s.len())
            .map(|k| 0.5 * (w(k - 1) + w(k)) * (self.s[k] - self.s[k - 1]))
            .sum()
    }

    /// Largest width over the grid.
    pub fn max_width(&self) -> f64 {
        self.left
            .iter()
            .zip(&self.right)
            .map(|(l, r)| r - l)
            .fold(0.0, f64::max)
    }
}

/// Isoparametric baseline paths, inlet → outlet, ordered left to right (not yet linked).
pub fn isoparametric(region: &Region, step: f64) -> Result<Vec<Path2>, Plan2dError> {
    region.validate()?;
    check_step(step)?;
    let w = region.max_width();
    let needed = (w / step).ceil() as usize + 1;
    if needed > 2 * MAX_OFFSETS {
        return Err(Plan2dError::TooManyPaths { step, needed });
    }
    let n = needed.max(1);
    Ok((0..n)
        .map(|i| {
            let f = if n == 1 {
                0.5
            } else {
                i as f64 / (n - 1) as f64
            };
            region
                .s
                .iter()
                .zip(region.left.iter().zip(&region.right))
                .map(|(&s, (&l, &r))| [s, l + f * (r - l)])
                .collect()
        })
        .collect())
}

/// Tolerance (mm) of [`clip_to_regions`]' membership test across the flow: grid points of
/// a path on a region's boundary count as inside.
pub const CLIP_TOL_MM: f64 = 1e-9;

/// The parts of `paths` that run inside the union of `regions`: maximal runs of consecutive
/// path points each inside some region (between its boundaries, within its `s` range); runs
/// of fewer than two points are dropped. A run ends at the last point inside, so each cut
/// shortens a path by less than one grid spacing. O(points × regions).
pub fn clip_to_regions(paths: Vec<Path2>, regions: &[&Region]) -> Vec<Path2> {
    let inside = |q: &[f64; 2]| {
        regions.iter().any(|r| match (r.s.first(), r.s.last()) {
            (Some(&a), Some(&b)) if q[0] >= a && q[0] <= b => {
                let (l, rr) = r.bounds(q[0]);
                q[1] >= l - CLIP_TOL_MM && q[1] <= rr + CLIP_TOL_MM
            }
            _ => false,
        })
    };
    let mut out = Vec::new();
    for p in paths {
        let mut cur: Path2 = Vec::new();
        for q in p {
            if inside(&q) {
                cur.push(q);
            } else if cur.len() >= 2 {
                out.push(std::mem::take(&mut cur));
            } else {
                cur.clear();
            }
        }
        if cur.len() >= 2 {
            out.push(cur);
        }
    }
    out
}

fn check_step(step: f64) -> Result<(), Plan2dError> {
    if step.is_finite() && step > 0.0 {
        Ok(())
    } else {
        Err(Plan2dError::Region(format!(
            "path interval {step} must be > 0"
        )))
    }
}

/// One offset curve `y = boundary(s) ± k·step` as a cubic interpolant of the grid.
fn offset_curve(
    region: &Region,
    left: bool,
    k: usize,
    step: f64,
) -> Result<nurbs::Curve2, Plan2dError> {
    let pts: Vec<Vector2<f64>> = (0..region.s.len())
        .map(|i| {
            let y = if left {
                region.left[i] + k as f64 * step
            } else {
                region.right[i] - k as f64 * step
            };
            Vector2::new(region.s[i], y)
        })
        .collect();
    let deg = 3.min(pts.len() - 1);
    interpolate_curve(&pts, deg, Parametrisation::ChordLength, None)
        .map_err(|e| Plan2dError::Curve(e.to_string()))
}

/// Arc-length positions where two offset curves cross.
fn crossings(a: &nurbs::Curve2, b: &nurbs::Curve2) -> Result<Vec<f64>, Plan2dError> {
    let opts = IntersectOptions {
        tol: CROSSING_TOL_MM,
        min_overlap_length: None,
    };
    let hits = intersect_curves(a, b, &opts).map_err(|e| Plan2dError::Curve(e.to_string()))?;
    let mut out = Vec::new();
    for h in hits {
        match h {
            CurveIntersection::Point(p) => out.push(p.point[0]),
            // Coinciding offsets over a range: both ends bound the pieces.
            CurveIntersection::Overlap { u, .. } => {
                out.push(a.point(u.0)[0]);
                out.push(a.point(u.1)[0]);
            }
        }
    }
    Ok(out)
}

/// The kept pieces of offset `k` of one side: between consecutive crossings (and the grid
/// ends), those whose middle is wider than `threshold`.
fn pieces(
    region: &Region,
    left: bool,
    k: usize,
    step: f64,
    cuts: &[f64],
    threshold: f64,
) -> Vec<Path2> {
    let (s0, s1) = (region.s[0], region.s[region.s.len() - 1]);
    let mut bounds: Vec<f64> = vec![s0];
    bounds.extend(cuts.iter().copied().filter(|&c| c > s0 && c < s1));
    bounds.push(s1);
    bounds.sort_by(f64::total_cmp);
    bounds.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let y_at = |s: f64| {
        let (l, r) = region.bounds(s);
        if left {
            l + k as f64 * step
        } else {
            r - k as f64 * step
        }
    };
    let mut out = Vec::new();
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        if region.width(0.5 * (a + b)) <= threshold {
            continue;
        }
        let mut p: Path2 = vec![[a, y_at(a)]];
        p.extend(
            region
                .s
                .iter()
                .filter(|&&s| s > a + 1e-9 && s < b - 1e-9)
                .map(|&s| [s, y_at(s)]),
        );
        p.push([b, y_at(b)]);
        out.push(p);
    }
    out
}

/// Triangle-planned paths (module docs), inlet → outlet, ordered left to right: the left
/// offsets `L_0, L_1, …` then the right offsets `…, R_1, R_0` (not yet linked).
pub fn triangle(region: &Region, step: f64) -> Result<Vec<Path2>, Plan2dError> {
    region.validate()?;
    check_step(step)?;
    let w = region.max_width();
    // Offsets per side: L_k is needed where w > (2k − 1)·step, R_k where w > 2k·step.
    let k_left = ((w / step + 1.0) / 2.0).ceil() as usize;
    let k_right = (w / step / 2.0).ceil() as usize;
    if k_left > MAX_OFFSETS {
        return Err(Plan2dError::TooManyPaths {
            step,
            needed: k_left,
        });
    }
    let mut lefts: Vec<Vec<Path2>> = Vec::new();
    let mut rights: Vec<Vec<Path2>> = Vec::new();
    for k in 0..=k_left {
        // L_k against R_{k−1} (threshold (2k − 1)·step); L_0 always (threshold < 0).
        if k == 0 {
            lefts.push(pieces(region, true, 0, step, &[], -1.0));
            continue;
        }
        let l = offset_curve(region, true, k, step)?;
        let r = offset_curve(region, false, k - 1, step)?;
        let cuts = crossings(&l, &r)?;
        let p = pieces(region, true, k, step, &cuts, (2 * k - 1) as f64 * step);
        if p.is_empty() {
            break;
        }
        lefts.push(p);
    }
    for k in 0..=k_right {
        let l = offset_curve(region, true, k, step)?;
        let r = offset_curve(region, false, k, step)?;
        let threshold = if k == 0 { 0.0 } else { (2 * k) as f64 * step };
        let cuts = if k == 0 {
            Vec::new()
        } else {
            crossings(&r, &l)?
        };
        let p = pieces(region, false, k, step, &cuts, threshold);
        if p.is_empty() {
            break;
        }
        rights.push(p);
    }
    let mut out: Vec<Path2> = lefts.into_iter().flatten().collect();
    out.extend(rights.into_iter().rev().flatten());
    Ok(out)
}

/// Orders and orients `paths` (left to right as planned) for cutting and returns them with
/// the link polylines between consecutive ones. Zig-zag reverses every other path and links
/// neighbouring ends with a straight segment; one-way cuts every path inlet → outlet and
/// returns along the path just cut (lifted by the caller) to its inlet end, then steps to the
/// next path's start — so links stay inside the area cut on this or the previous level.
pub fn link(paths: Vec<Path2>, linking: Linking) -> (Vec<Path2>, Vec<Path2>) {
    let mut out: Vec<Path2> = Vec::with_capacity(paths.len());
    for (i, mut p) in paths.into_iter().enumerate() {
        if linking == Linking::ZigZag && i % 2 == 1 {
            p.reverse();
        }
        out.push(p);
    }
    let links = out
        .windows(2)
        .filter_map(|w| {
            let next = *w[1].first()?;
            Some(match linking {
                Linking::ZigZag => vec![*w[0].last()?, next],
                Linking::OneWay => {
                    let mut back: Path2 = w[0].iter().rev().copied().collect();
                    back.push(next);
                    back
                }
            })
        })
        .collect();
    (out, links)
}

/// Planar length of paths (mm).
pub fn length(paths: &[Path2]) -> f64 {
    paths
        .iter()
        .flat_map(|p| p.windows(2))
        .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_keeps_the_runs_inside_the_union_of_regions() {
        // Two regions side by side along s: [0, 4] × y ∈ [0, 2] and [4, 8] × y ∈ [1, 3].
        let a = Region {
            s: vec![0.0, 4.0],
            left: vec![0.0, 0.0],
            right: vec![2.0, 2.0],
        };
        let b = Region {
            s: vec![4.0, 8.0],
            left: vec![1.0, 1.0],
            right: vec![3.0, 3.0],
        };
        let line = |y: f64| -> Path2 { (0..=8).map(|i| [i as f64, y]).collect() };
        // y = 1.5 lies in both: one run over the whole length; y = 0.5 only in the first
        // (points s = 0..4); y = 2.5 only in the second (s = 4..8); y = 5 in neither.
        let out = clip_to_regions(vec![line(1.5), line(0.5), line(2.5), line(5.0)], &[&a, &b]);
        assert_eq!(out.len(), 3);
        assert_eq!(out[0].len(), 9);
        assert_eq!((out[1][0][0], out[1].last().unwrap()[0]), (0.0, 4.0));
        assert_eq!((out[2][0][0], out[2].last().unwrap()[0]), (4.0, 8.0));
        // A path that leaves the region ends its run there; a run of one point (the return
        // at s = 3) is dropped.
        let zig: Path2 = vec![[0.0, 1.0], [1.0, 1.0], [2.0, 9.0], [3.0, 1.0], [4.0, 9.0]];
        let out = clip_to_regions(vec![zig], &[&a]);
        assert_eq!(out, vec![vec![[0.0, 1.0], [1.0, 1.0]]]);
    }

    /// A channel widening from 3 mm at the inlet to 20 mm at the outlet, with a wavy centre.
    fn channel() -> Region {
        let n = 81;
        let s: Vec<f64> = (0..n).map(|i| 60.0 * i as f64 / (n - 1) as f64).collect();
        let mid: Vec<f64> = s.iter().map(|&x| 2.0 * (x / 15.0).sin()).collect();
        let half: Vec<f64> = s.iter().map(|&x| 1.5 + 8.5 * (x / 60.0).powi(2)).collect();
        Region {
            left: mid.iter().zip(&half).map(|(m, h)| m - h).collect(),
            right: mid.iter().zip(&half).map(|(m, h)| m + h).collect(),
            s,
        }
    }

    fn dist_to_polyline(p: [f64; 2], path: &Path2) -> f64 {
        path.windows(2)
            .map(|w| {
                let (a, b) = (Vector2::from(w[0]), Vector2::from(w[1]));
                let q = Vector2::from(p);
                let d = b - a;
                let t = ((q - a).dot(&d) / d.norm_squared().max(1e-300)).clamp(0.0, 1.0);
                (q - (a + d * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Every sampled point of the region lies within half the interval of some path, for
    /// triangle and isoparametric plans alike (same covering of the same region).
    #[test]
    fn both_plans_cover_the_region_at_the_interval() {
        let r = channel();
        let step = 1.2;
        let tri = triangle(&r, step).unwrap();
        let iso = isoparametric(&r, step).unwrap();
        for i in 0..=120 {
            let s = 60.0 * i as f64 / 120.0;
            let (l, rr) = r.bounds(s);
            for j in 0..=40 {
                let p = [s, l + (rr - l) * j as f64 / 40.0];
                for (name, plan) in [("triangle", &tri), ("iso", &iso)] {
                    let d = plan
                        .iter()
                        .map(|q| dist_to_polyline(p, q))
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        d <= 0.5 * step + 1e-6,
                        "{name}: {p:?} is {d} from every path"
                    );
                }
            }
        }
        // The triangle plan is shorter (the channel narrows toward the inlet).
        let (lt, li) = (length(&tri), length(&iso));
        assert!(lt < 0.8 * li, "triangle {lt} vs iso {li}");
    }

    /// The width integral of the test channel against its closed form
    /// `∫₀⁶⁰ 2 (1.5 + 8.5 x²/3600) dx = 520 mm²` (trapezoidal on 81 points: error
    /// `L h² f''/12 = 0.027`), and the triangle plan's saving against the isoparametric one
    /// reaching most of the width bound `1 − 520 / (20 · 60) = 0.567` (no more than it plus
    /// the rounding of path counts).
    #[test]
    fn width_bound_of_the_test_channel() {
        let r = channel();
        assert!(
            (r.width_integral() - 520.0).abs() < 0.03,
            "{}",
            r.width_integral()
        );
        assert!((r.max_width() - 20.0).abs() < 1e-12);
        let bound = 1.0 - r.width_integral() / (r.max_width() * 60.0);
        let step = 1.2;
        let saving =
            1.0 - length(&triangle(&r, step).unwrap()) / length(&isoparametric(&r, step).unwrap());
        assert!(
            saving > 0.8 * bound && saving < bound + 0.05,
            "saving {saving} vs bound {bound}"
        );
    }

    /// No path point lies outside the boundaries, and no link leaves the region.
    #[test]
    fn paths_and_links_stay_inside() {
        let r = channel();
        for linking in [Linking::ZigZag, Linking::OneWay] {
            let (paths, links) = link(triangle(&r, 0.9).unwrap(), linking);
            for p in paths.iter().flatten() {
                let (l, rr) = r.bounds(p[0]);
                assert!(
                    p[1] >= l - 1e-9 && p[1] <= rr + 1e-9,
                    "{p:?} outside [{l}, {rr}]"
                );
            }
            for link in links {
                for w in link.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    for k in 0..=20 {
                        let t = k as f64 / 20.0;
                        let q = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                        let (l, rr) = r.bounds(q[0]);
                        assert!(
                            q[1] >= l - 1e-6 && q[1] <= rr + 1e-6,
                            "{linking:?} link {q:?}"
                        );
                    }
                }
            }
        }
    }

    /// A channel that narrows in the middle gives offsets in two pieces, cut where the
    /// curve intersection finds the crossings (width = threshold there).
    #[test]
    fn narrowing_channel_splits_offsets_at_crossings() {
        let n = 101;
        let s: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let half: Vec<f64> = s
            .iter()
            .map(|&x| 3.0 + 2.0 * ((x - 50.0) / 50.0).powi(2) * 2.0)
            .collect();
        let r = Region {
            left: half.iter().map(|h| -h).collect(),
            right: half.clone(),
            s,
        };
        let step = 1.0;
        let tri = triangle(&r, step).unwrap();
        // Width 6 in the middle, 14 at the ends: L_4 (needed where w > 7) has two pieces.
        // Each piece ends where w = 7 exactly.
        let l4: Vec<&Path2> = tri
            .iter()
            .filter(|p| {
                p.iter()
                    .all(|q| (q[1] - (r.bounds(q[0]).0 + 4.0)).abs() < 1e-6)
            })
            .collect();
        assert_eq!(l4.len(), 2, "{l4:?}");
        for p in l4 {
            let inner = if p[0][0] < 50.0 { p.last() } else { p.first() };
            let w = r.width(inner.unwrap()[0]);
            assert!((w - 7.0).abs() < 1e-3, "cut at width {w}");
        }
    }

    #[test]
    fn malformed_regions_are_errors() {
        let mut r = channel();
        r.left[5] = r.right[5] + 1.0;
        assert!(triangle(&r, 1.0).is_err());
        assert!(isoparametric(&channel(), 0.0).is_err());
    }
}
