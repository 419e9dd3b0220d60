//! Where the point-milling passes of a band run: lines parallel to the band's upper edge
//! (the blade tip, or the lower edge of a flanked strip above), spaced for the scallop
//! height, each ending where it reaches the band's lower edge, and a last line along that
//! lower edge.
//!
//! **Spacing.** Two balls of radius `R` whose contacts are `w` apart over a side of normal
//! curvature `κ` across the passes (`κ > 0` where the side bulges toward the tool) leave a
//! cusp of height `h ≈ (w²/8)(1/R + κ)` (the two circles' sagittas over a circle of curvature
//! `κ`, to second order in `w`). The step that leaves `h` is therefore
//! `w = √(8h / (1/R + κ))`, capped at `√3·R` (where the formula's small-`w` assumption fails
//! on concave sides). Each line keeps the smallest step over its length from the one above.
//! The cusps are given the scallop height less the share the chords between stations along a
//! pass may leave away from the side (`CHORD_SCALLOP_SHARE`).
//!
//! **Lines.** Line `k` runs at arc length `d_k` below the upper edge, measured down each
//! isoparametric curve `u = const` of the side: `d_0 = 0`, `d_{k+1} = d_k + min_u w`. Where
//! the band is narrower than `d_k` (a blade whose span shrinks toward the trailing edge) the
//! line does not exist: it ends where it meets the lower edge. So the lines cover the band
//! with about `area / w` of path, where isoparametric lines at the widest place's spacing would
//! crowd the narrow end (the HECC impeller's main blade spans 68 mm at the leading edge and
//! 16 mm at the trailing edge). The spacing measured along `u = const` is at least the spacing
//! across the lines, so the cusp never exceeds `h`.
//!
//! A line is tabulated at `U_SAMPLES + 1` stations of `u`; between them its `v` is
//! interpolated linearly ([`PassLine::v_at`]).
//!
//! Complexity: O(`U_SAMPLES` · `ARC_STEPS`) evaluations for the arc-length table plus
//! O(lines · `U_SAMPLES`) curvature evaluations.

use super::PointSettings;
use crate::FlankError;
use impeller_model::{Blade, Side};

/// Samples along u of the arc-length table and of each line.
const U_SAMPLES: usize = 96;
/// Steps of the arc-length table along each u = const curve.
const ARC_STEPS: usize = 200;
/// Most pass lines of one band.
pub const MAX_LINES: usize = 4000;

/// The step `w` (mm) between two balls of radius `r` that leaves the scallop `h` over a side
/// of normal curvature `kappa` across the passes (module docs).
pub fn step_for_scallop(r: f64, h: f64, kappa: f64) -> f64 {
    let cap = 3f64.sqrt() * r;
    let k = 1.0 / r + kappa;
    if k <= 1e-9 {
        return cap;
    }
    (8.0 * h / k).sqrt().min(cap)
}

/// Convex normal curvature of `side` in the v direction at `(u, v)` (1/mm; positive where
/// the side bulges outward, toward a tool outside it) and `|∂S/∂v|`.
pub fn across_curvature(blade: &Blade, side: Side, u: f64, v: f64) -> Option<(f64, f64)> {
    let s = blade.side(side);
    let d = s.derivs2(u, v);
    let n = blade.outward_normal(side, u, v)?;
    let sv2 = d.sv.norm_squared();
    if sv2 < 1e-18 {
        return None;
    }
    Some((-(d.svv.dot(&n)) / sv2, sv2.sqrt()))
}

/// One pass line: a contiguous run of `(u, v)` samples, u increasing.
#[derive(Debug, Clone, PartialEq)]
pub struct PassLine {
    /// Index of the line from the band's upper edge (0 = the edge itself).
    pub index: usize,
    /// `(u, v)` samples, u increasing.
    pub samples: Vec<(f64, f64)>,
}

impl PassLine {
    /// The u range.
    pub fn u_range(&self) -> (f64, f64) {
        (
            self.samples.first().map_or(0.0, |s| s.0),
            self.samples.last().map_or(0.0, |s| s.0),
        )
    }

    /// `v` at `u` (linear between samples, clamped to the ends).
    pub fn v_at(&self, u: f64) -> f64 {
        let s = &self.samples;
        match s.binary_search_by(|p| p.0.total_cmp(&u)) {
            Ok(k) => s[k].1,
            Err(0) => s.first().map_or(0.0, |p| p.1),
            Err(k) if k >= s.len() => s.last().map_or(0.0, |p| p.1),
            Err(k) => {
                let (a, b) = (s[k - 1], s[k]);
                let t = (u - a.0) / (b.0 - a.0);
                a.1 + (b.1 - a.1) * t
            }
        }
    }

    /// Length (mm) of the line on the side (polyline through its samples).
    pub fn length(&self, blade: &Blade, side: Side) -> f64 {
        let s = blade.side(side);
        self.samples
            .windows(2)
            .map(|w| (s.point(w[1].0, w[1].1) - s.point(w[0].0, w[0].1)).norm())
            .sum()
    }
}

/// Arc length down one u = const curve from `v_hi` to `v_lo`: (v, arc) pairs, arc
/// increasing from 0.
fn arc_table(blade: &Blade, side: Side, u: f64, (v_lo, v_hi): (f64, f64)) -> Vec<(f64, f64)> {
    let s = blade.side(side);
    let mut out = Vec::with_capacity(ARC_STEPS + 1);
    let mut prev = s.point(u, v_hi);
    let mut arc = 0.0;
    out.push((v_hi, 0.0));
    for j in 1..=ARC_STEPS {
        let v = v_hi + (v_lo - v_hi) * j as f64 / ARC_STEPS as f64;
        let p = s.point(u, v);
        arc += (p - prev).norm();
        prev = p;
        out.push((v, arc));
    }
    out
}

/// `v` at arc length `d` below the upper edge on a table, `None` beyond its end.
fn v_at_arc(table: &[(f64, f64)], d: f64) -> Option<f64> {
    let k = table.partition_point(|p| p.1 < d);
    if k == 0 {
        return table.first().map(|p| p.0);
    }
    let b = table.get(k)?;
    let a = table[k - 1];
    let t = if b.1 > a.1 {
        (d - a.1) / (b.1 - a.1)
    } else {
        0.0
    };
    Some(a.0 + (b.0 - a.0) * t)
}

/// The pass lines of `band = (v_lo, v_hi)` (module docs), upper edge first, the lower edge
/// last. Errors when more than [`MAX_LINES`] would be needed.
pub fn pass_lines(
    blade: &Blade,
    side: Side,
    band: (f64, f64),
    st: &PointSettings,
) -> Result<Vec<PassLine>, FlankError> {
    let (lo, hi) = (band.0.min(band.1), band.0.max(band.1));
    let ((u0, u1), _) = blade.side(side).domain();
    let us: Vec<f64> = (0..=U_SAMPLES)
        .map(|i| u0 + (u1 - u0) * i as f64 / U_SAMPLES as f64)
        .collect();
    let tables: Vec<Vec<(f64, f64)>> = us
        .iter()
        .map(|&u| arc_table(blade, side, u, (lo, hi)))
        .collect();
    let widest = tables
        .iter()
        .filter_map(|t| t.last().map(|p| p.1))
        .fold(0.0f64, f64::max);
    let r = st.ball_radius;
    // The cusps get the scallop less the share the chords along the passes may leave.
    let cusp = st.scallop_mm * (1.0 - super::CHORD_SCALLOP_SHARE);
    let mut lines: Vec<PassLine> = Vec::new();
    let mut d = 0.0f64;
    let mut index = 0usize;
    loop {
        // The line at depth d: its pieces where the band is at least that wide.
        let at: Vec<Option<f64>> = tables.iter().map(|t| v_at_arc(t, d)).collect();
        let mut piece: Vec<(f64, f64)> = Vec::new();
        let mut step = f64::INFINITY;
        for (k, v) in at.iter().enumerate() {
            match v {
                Some(v) => {
                    piece.push((us[k], *v));
                    if let Some((kappa, _)) = across_curvature(blade, side, us[k], *v) {
                        step = step.min(step_for_scallop(r, cusp, kappa));
                    }
                }
                None => {
                    if piece.len() >= 2 {
                        lines.push(PassLine {
                            index,
                            samples: std::mem::take(&mut piece),
                        });
                    }
                    piece.clear();
                }
            }
        }
        if piece.len() >= 2 {
            lines.push(PassLine {
                index,
                samples: piece,
            });
        }
        if !(step.is_finite() && step > 0.0) {
            return Err(FlankError::Geometry(format!(
                "{side:?} side: no pass step at {d:.3} mm below the band's upper edge \
                 (degenerate side)"
            )));
        }
        d += step;
        index += 1;
        if d >= widest - 0.05 * step {
            break;
        }
        if index > MAX_LINES {
            return Err(FlankError::Geometry(format!(
                "{side:?} side: more than {MAX_LINES} point-milling passes needed for a \
                 scallop of {} mm",
                st.scallop_mm
            )));
        }
    }
    // The lower edge itself.
    lines.push(PassLine {
        index,
        samples: us.iter().map(|&u| (u, lo)).collect(),
    });
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a flat side the cusp of two balls `w` apart is `R − √(R² − w²/4)`; the step for
    /// `h` must leave at most `h` (and nearly `h`: within the second-order error).
    #[test]
    fn step_leaves_the_scallop_on_a_flat_side() {
        for &(r, h) in &[(1.0, 0.01), (2.0, 0.02), (3.0, 0.005), (1.5, 0.1)] {
            let w = step_for_scallop(r, h, 0.0);
            let cusp = r - (r * r - w * w / 4.0).sqrt();
            assert!(
                cusp <= h * 1.05 && cusp >= h * 0.9,
                "r {r} h {h}: w {w} cusp {cusp}"
            );
        }
    }

    /// Convex sides need smaller steps, concave ones allow larger (capped).
    #[test]
    fn curvature_changes_the_step() {
        let flat = step_for_scallop(2.0, 0.02, 0.0);
        assert!(step_for_scallop(2.0, 0.02, 0.1) < flat);
        assert!(step_for_scallop(2.0, 0.02, -0.1) > flat);
        assert!(step_for_scallop(2.0, 0.02, -0.6) <= 3f64.sqrt() * 2.0 + 1e-12);
    }

    #[test]
    fn arc_lookup_interpolates() {
        let t = vec![(1.0, 0.0), (0.5, 2.0), (0.0, 4.0)];
        assert_eq!(v_at_arc(&t, 0.0), Some(1.0));
        assert!((v_at_arc(&t, 1.0).unwrap() - 0.75).abs() < 1e-12);
        assert!((v_at_arc(&t, 3.0).unwrap() - 0.25).abs() < 1e-12);
        assert_eq!(v_at_arc(&t, 4.5), None);
        let line = PassLine {
            index: 0,
            samples: vec![(0.0, 1.0), (1.0, 3.0)],
        };
        assert!((line.v_at(0.25) - 1.5).abs() < 1e-12);
        assert_eq!(line.v_at(2.0), 3.0);
    }
}
