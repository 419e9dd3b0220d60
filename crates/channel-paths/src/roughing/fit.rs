//! Where the cutter fits on a level: the fitting intervals of each grid section and the lanes
//! they form (module docs of [`super`], step 4).

use super::axes::Axes;
use super::operation::ChannelRoughing;
use super::plan2d::Region;
use cam_core::CutterShape;
use cam_plan::{DesignClearance, PlanError};
use nalgebra::Vector3;

/// Largest spacing (mm) of the cross-channel samples of where the cutter fits on each grid
/// section (half the path interval when that is finer).
pub(super) const FIT_SCAN_MAX_MM: f64 = 0.5;

/// Bisections refining each end of a fitting interval (to `2⁻⁶` of the sample spacing, the kept end on the fitting side).
pub(super) const FIT_BISECTIONS: usize = 6;

/// The cutter alone (ball and flutes: the tool without shank and holder) against the blades:
/// the query that decides where the cutter fits (module docs, step 4).
pub(super) struct FitQuery<'a> {
    pub(super) cutter: DesignClearance<'a>,
    /// The whole tool (cutter, shank and holder) against the blades alone: postures keep
    /// `fit_min` from the blades with all of it (module docs of [`super::posture`]).
    pub(super) tool: DesignClearance<'a>,
    pub(super) shape: CutterShape,
    /// Radius of a ball end (ball or tapered ball): its centre touching the level at `p`
    /// with normal `n` is `p + r·n` whatever the axis, so a centre closer than `r + fit_min`
    /// to a blade rules out every axis with one exact distance.
    pub(super) ball: Option<f64>,
}

impl FitQuery<'_> {
    /// Whether the ball (if the cutter has one) touching the level at `p` (normal `n`) keeps
    /// `fit_min` from the blades (exact blade distance of its centre). O(1) projections.
    pub(super) fn ball_fits(&self, p: &Vector3<f64>, n: &Vector3<f64>, fit_min: f64) -> bool {
        self.ball.is_none_or(|r| {
            let c = cam_plan::Point3::from(p + n * r);
            self.cutter.blade_distance_at_least(&c, r + fit_min)
        })
    }
}

impl ChannelRoughing {
    /// The intervals `[y₀, y₁]` of grid section `i` of `axes.field` where the cutter fits
    /// ([`Self::cutter_fits`]): samples across the section at most `scan` mm apart, then
    /// every end between a fitting and a blocked sample refined by [`FIT_BISECTIONS`]
    /// bisections (to `scan·2⁻⁶`). An end at a section boundary is that boundary. Cost:
    /// O((width / scan + ends · FIT_BISECTIONS) · candidates) cutter queries.
    pub(super) fn fit_intervals(
        &self,
        fit: &FitQuery<'_>,
        axes: &Axes<'_>,
        i: usize,
        scan: f64,
        fit_min: f64,
    ) -> Result<Vec<(f64, f64)>, PlanError> {
        let reg = &axes.field.region;
        let (s, l, r) = (reg.s[i], reg.left[i], reg.right[i]);
        if r < l {
            return Ok(Vec::new());
        }
        let k = (((r - l) / scan).ceil() as usize).max(1);
        let ys: Vec<f64> = (0..=k).map(|m| l + (r - l) * m as f64 / k as f64).collect();
        let mut ok = Vec::with_capacity(ys.len());
        for &y in &ys {
            ok.push(self.cutter_fits(fit, axes, [s, y], fit_min)?);
        }
        // Refine the end between a blocked `bad` and a fitting `good` ordinate.
        let refine = |mut bad: f64, mut good: f64| -> Result<f64, PlanError> {
            for _ in 0..FIT_BISECTIONS {
                let m = 0.5 * (bad + good);
                if self.cutter_fits(fit, axes, [s, m], fit_min)? {
                    good = m;
                } else {
                    bad = m;
                }
            }
            Ok(good)
        };
        let mut out = Vec::new();
        let mut m = 0;
        while m < ys.len() {
            if !ok[m] {
                m += 1;
                continue;
            }
            let start = m;
            while m < ys.len() && ok[m] {
                m += 1;
            }
            let y0 = if start == 0 {
                ys[0]
            } else {
                refine(ys[start - 1], ys[start])?
            };
            let y1 = if m == ys.len() {
                ys[ys.len() - 1]
            } else {
                refine(ys[m], ys[m - 1])?
            };
            out.push((y0, y1));
        }
        Ok(out)
    }

    /// Whether the cutter (ball and flutes, not shank nor holder) at planar point `q`, touching
    /// the level, keeps `fit_min` from the blades with one of the candidate axes of
    /// [`Axes::candidates`] (each with the early-exit query). O(candidates · query).
    pub(super) fn cutter_fits(
        &self,
        fit: &FitQuery<'_>,
        axes: &Axes<'_>,
        q: [f64; 2],
        fit_min: f64,
    ) -> Result<bool, PlanError> {
        let (p, n) = axes.point_of(q);
        if !fit.ball_fits(&p, &n, fit_min) {
            return Ok(false);
        }
        for a in axes.candidates(q, &p, &n) {
            let cl = self.touch(&fit.shape, &p, &n, &a, axes.level, q)?;
            if fit.cutter.is_clear(&cl, fit_min) {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// The lanes of a trimmed area (module docs, step 4): maximal runs `lo..hi` of consecutive
/// grid sections of `field` with the same number of fitting intervals, each interval `k` of
/// such a run joining its neighbour's, as `(lo, hi, k)`; runs of fewer than 2 sections are
/// left out (their area counts as unmachinable). Two intervals join when they overlap in `y`,
/// or in `y` measured from the field's left boundary, or from its right one: a band that
/// follows a boundary sloping in the developed plane (a narrow strip beside a blade,
/// 0.7 mm wide where the boundary moves 1 mm between sections, at the splitter nose of
/// impeller-11+11-freeform) shifts between sections by more than its width and would
/// otherwise break into lanes of one section. Postures and motions between the sections are
/// certified when the lane is located, so a join never admits an uncertified cut.
/// O(sections · intervals).
pub(super) fn lanes(sections: &[Vec<(f64, f64)>], field: &Region) -> Vec<(usize, usize, usize)> {
    let overlap = |a: (f64, f64), b: (f64, f64), da: f64, db: f64| {
        a.0 - da <= b.1 - db && b.0 - db <= a.1 - da
    };
    let joins = |i: usize| {
        let (a, b) = (&sections[i - 1], &sections[i]);
        let (dl, dr) = (
            field.left[i] - field.left[i - 1],
            field.right[i] - field.right[i - 1],
        );
        !a.is_empty()
            && a.len() == b.len()
            && a.iter().zip(b).all(|(&x, &y)| {
                overlap(x, y, 0.0, 0.0) || overlap(x, y, 0.0, dl) || overlap(x, y, 0.0, dr)
            })
    };
    let mut out = Vec::new();
    let mut lo = 0;
    while lo < sections.len() {
        let mut hi = lo + 1;
        while hi < sections.len() && joins(hi) {
            hi += 1;
        }
        if hi - lo >= 2 {
            out.extend((0..sections[lo].len()).map(|k| (lo, hi, k)));
        }
        lo = hi;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 0.7 mm band beside a boundary that moves 1 mm per section is one lane (it used to
    /// break into lanes of one section, dropped), while a band that jumps across the area
    /// between two sections is not joined to the one before.
    #[test]
    fn a_band_following_a_sloped_boundary_is_one_lane() {
        let n = 6;
        let field = Region {
            s: (0..n).map(|i| i as f64).collect(),
            left: (0..n).map(|i| i as f64).collect(),
            right: (0..n).map(|i| 10.0 + i as f64).collect(),
        };
        let band: Vec<Vec<(f64, f64)>> = (0..n)
            .map(|i| vec![(field.left[i] + 0.3, field.left[i] + 1.0)])
            .collect();
        assert_eq!(lanes(&band, &field), vec![(0, n, 0)]);
        let mut jump = band.clone();
        for x in jump.iter_mut().skip(3) {
            x[0].0 += 5.0;
            x[0].1 += 5.0;
        }
        assert_eq!(lanes(&jump, &field), vec![(0, 3, 0), (3, n, 0)]);
    }
}
