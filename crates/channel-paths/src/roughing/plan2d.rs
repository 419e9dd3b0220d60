//! Path planning of one channel area on one depth level, in the level's developed plane:
//! the regions, the isoparametric baseline and what any planner at a constant interval can
//! save against it.
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
//! * **Count bound** ([`Region::count_integral`]): paths at the interval `d` that cover a
//!   section of width `w` and run along both of its boundaries are at least `⌈w/d⌉ + 1` at
//!   that section, so their length is at least `∫ (⌈w(s)/d⌉ + 1) ds`; the baseline's is
//!   `(⌈w_max/d⌉ + 1)·L`. The ratio bounds the saving of any such planner (the triangle
//!   planning of [`super::triangle`] places exactly `⌈w/d⌉ + 1` paths at each section).
//!
//! Cost: O(n) per path on an n-point grid.

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

    /// `∫ (⌈w(s)/d⌉ + 1) ds` over the grid, `w = right − left` linear between grid points
    /// (negative widths count as 0): the least total length of paths at the interval `d` that
    /// cover each section and run along both its boundaries, up to the paths' slant (module
    /// docs, count bound). Exact for the piecewise-linear width: on a grid interval where
    /// `x = w/d` runs linearly from `x₀` to `x₁`, the mean of `⌈x⌉` is
    /// `(C(x₁) − C(x₀)) / (x₁ − x₀)` with `C(x) = ∫₀ˣ ⌈t⌉ dt = m(m+1)/2 + (m+1)(x − m)`,
    /// `m = ⌊x⌋`. O(n).
    pub fn count_integral(&self, d: f64) -> f64 {
        let c = |x: f64| {
            let m = x.floor();
            0.5 * m * (m + 1.0) + (m + 1.0) * (x - m)
        };
        let x = |k: usize| (self.right[k] - self.left[k]).max(0.0) / d;
        (1..self.s.len())
            .map(|k| {
                let (x0, x1) = (x(k - 1), x(k));
                let mean = if (x1 - x0).abs() < 1e-12 {
                    x0.max(x1).ceil()
                } else {
                    (c(x1) - c(x0)) / (x1 - x0)
                };
                (mean + 1.0) * (self.s[k] - self.s[k - 1])
            })
            .sum()
    }

    /// `(⌈w_max/d⌉ + 1)·L`: the length of the isoparametric baseline at the interval `d`
    /// ([`isoparametric`]) measured along `s`.
    pub fn baseline_count_length(&self, d: f64) -> f64 {
        let len = self
            .s
            .last()
            .zip(self.s.first())
            .map_or(0.0, |(b, a)| b - a);
        ((self.max_width() / d).ceil() + 1.0) * len
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

pub(super) fn check_step(step: f64) -> Result<(), Plan2dError> {
    if step.is_finite() && step > 0.0 {
        Ok(())
    } else {
        Err(Plan2dError::Region(format!(
            "path interval {step} must be > 0"
        )))
    }
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
pub(super) mod tests {
    use super::*;
    use nalgebra::Vector2;

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
    pub(in crate::roughing) fn channel() -> Region {
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

    /// Distance from `p` to the polyline `path` in the plane.
    pub(in crate::roughing) fn dist_to_polyline(p: [f64; 2], path: &Path2) -> f64 {
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

    /// The count integral against closed forms: a constant width `w = 2.5 d` gives
    /// `(3 + 1)·L`; a width rising linearly from 0 to `4d` gives the mean of `⌈x⌉` over
    /// `[0, 4]`, `(1 + 2 + 3 + 4)/4 = 2.5`, plus 1; the baseline count length of the latter is
    /// `(4 + 1)·L`.
    #[test]
    fn count_integral_of_closed_forms() {
        // A binary fraction: 4d/d is exactly 4.
        let d = 0.5;
        let flat = Region {
            s: vec![0.0, 3.0, 10.0],
            left: vec![1.0, 1.0, 1.0],
            right: vec![1.0 + 2.5 * d; 3],
        };
        assert!((flat.count_integral(d) - 4.0 * 10.0).abs() < 1e-9);
        let n = 7;
        let s: Vec<f64> = (0..n).map(|i| 12.0 * i as f64 / (n - 1) as f64).collect();
        let ramp = Region {
            left: vec![0.0; n],
            right: s.iter().map(|&x| 4.0 * d * x / 12.0).collect(),
            s,
        };
        assert!(
            (ramp.count_integral(d) - 3.5 * 12.0).abs() < 1e-9,
            "{}",
            ramp.count_integral(d)
        );
        assert!((ramp.baseline_count_length(d) - 5.0 * 12.0).abs() < 1e-9);
    }

    #[test]
    fn malformed_regions_are_errors() {
        let mut r = channel();
        r.left[5] = r.right[5] + 1.0;
        assert!(r.validate().is_err());
        assert!(isoparametric(&r, 1.0).is_err());
        assert!(isoparametric(&channel(), 0.0).is_err());
    }
}
