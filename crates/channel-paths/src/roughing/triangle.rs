//! Triangle path planning of one lane on one level (paper 001 §3, Fig. "triangle tool
//! path"), in the developed plane of [`super::plan2d`].
//!
//! The left boundary is offset toward the middle by `k·step` (`L_k`) and the right by
//! `k·step` (`R_k`). Ordered `L_0, R_0, L_1, R_1, …`, path `j` is needed where the width
//! exceeds `(j − 1)·step`; i.e. `L_k` is kept from its crossing with `R_{k−1}` and `R_k` from
//! its crossing with `L_k` toward the outlet — the parts from the inlet to the crossings are
//! deleted. The crossings are found with [`nurbs::intersect::intersect_curves`] on cubic
//! interpolants of the offset curves, so a channel that narrows again yields several pieces.
//! Neighbouring kept paths are at most `step` apart everywhere, the same covering as the
//! isoparametric baseline with fewer and shorter paths where the channel is narrow: at a
//! section of width `w` there are exactly `⌈w/step⌉ + 1` paths (the count bound of
//! [`super::plan2d`]).
//!
//! Cost: O(K·n) for K offsets on an n-point grid plus one curve intersection per offset.

use super::plan2d::{check_step, Path2, Plan2dError, Region, MAX_OFFSETS};
use nalgebra::Vector2;
use nurbs::fit::{interpolate_curve, Parametrisation};
use nurbs::intersect::{intersect_curves, CurveIntersection, IntersectOptions};

/// Crossing tolerance of the offset-curve intersection (mm): far below any step-over.
pub const CROSSING_TOL_MM: f64 = 1e-7;

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

#[cfg(test)]
mod tests {
    use super::super::plan2d::tests::{channel, dist_to_polyline};
    use super::super::plan2d::{isoparametric, length};
    use super::*;

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

    /// The triangle plan's saving against the isoparametric one reaches the count bound of
    /// the test channel within the paths' slant: its paths are exactly `⌈w/d⌉ + 1` at each
    /// section, so the planar lengths exceed the count integral only by the slant of the
    /// paths against `s` (here at most 8 %), and the saving is within 0.05 of the bound.
    #[test]
    fn triangle_saving_reaches_the_count_bound() {
        let r = channel();
        let step = 1.2;
        let tri = length(&triangle(&r, step).unwrap());
        let iso = length(&isoparametric(&r, step).unwrap());
        let counted = r.count_integral(step);
        assert!(
            tri >= counted - 1e-6 && tri <= 1.08 * counted,
            "{tri} vs {counted}"
        );
        let bound = 1.0 - counted / r.baseline_count_length(step);
        let saving = 1.0 - tri / iso;
        assert!(
            saving <= bound + 1e-9 && saving > bound - 0.05,
            "saving {saving} vs bound {bound}"
        );
    }

    /// No path point lies outside the boundaries.
    #[test]
    fn paths_stay_inside() {
        let r = channel();
        for p in triangle(&r, 0.9).unwrap().iter().flatten() {
            let (l, rr) = r.bounds(p[0]);
            assert!(
                p[1] >= l - 1e-9 && p[1] <= rr + 1e-9,
                "{p:?} outside [{l}, {rr}]"
            );
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
        assert!(triangle(&channel(), 0.0).is_err());
    }
}
