//! The whole tool assembly (flutes, shank, holder) as a stack of solid cone frusta, ready for
//! collision checks (e.g. as parry convex shapes).
//!
//! Every part that is a cylinder or cone is one exact frustum: the flutes of flat and tapered
//! flat ends, the cylinder/cone above a ball or bull-nose corner, the shank and each holder
//! segment. Circular arcs of the profile (ball, bull-nose corner) cannot be frusta; they are
//! replaced by the *circumscribed* polyline through the tangent lines at evenly spaced angles,
//! so the frusta contain the true cutter (conservative for collisions) and exceed it by at most
//! `ρ(1/cos(Δ/2) − 1) <= chord_tol`, where `Δ` is the angular step:
//! `Δ = 2·acos(1/(1 + chord_tol/ρ))` rounded down to divide the arc evenly.

use crate::{CamError, Cutter, CutterShape};
use serde::{Deserialize, Serialize};

/// A solid cone frustum along the tool axis: radius `r0` at height `h0`, `r1` at `h1 > h0`
/// (heights above the tool tip, mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Frustum {
    /// Lower height (mm above the tip).
    pub h0: f64,
    /// Upper height.
    pub h1: f64,
    /// Radius at `h0`.
    pub r0: f64,
    /// Radius at `h1`.
    pub r1: f64,
}

impl Frustum {
    /// Radius at height `h` (linear between the ends; `None` outside `[h0, h1]`).
    pub fn radius_at(&self, h: f64) -> Option<f64> {
        if !(self.h0..=self.h1).contains(&h) {
            return None;
        }
        Some(self.r0 + (h - self.h0) / (self.h1 - self.h0) * (self.r1 - self.r0))
    }
}

/// Circumscribed polyline of the arc centred `(cw, ch)` with radius `rho` from angle `a0` to
/// `a1` (angles in the (w, h) half plane, measured from +w toward +h), as (w, h) points.
fn arc_polyline(cw: f64, ch: f64, rho: f64, a0: f64, a1: f64, tol: f64, out: &mut Vec<[f64; 2]>) {
    let span = a1 - a0;
    if span <= 0.0 {
        return;
    }
    let dmax = 2.0 * (1.0 / (1.0 + tol / rho)).acos();
    let n = (span / dmax).ceil().max(1.0) as usize;
    let d = span / n as f64;
    let scale = rho / (0.5 * d).cos();
    out.push([cw + rho * a0.cos(), ch + rho * a0.sin()]);
    for k in 0..n {
        let a = a0 + (k as f64 + 0.5) * d;
        out.push([cw + scale * a.cos(), ch + scale * a.sin()]);
    }
    out.push([cw + rho * a1.cos(), ch + rho * a1.sin()]);
}

impl Cutter {
    /// The assembly as frusta stacked from the tip up: flutes (exact where they are cones,
    /// circumscribed within `chord_tol` on arcs), shank (from the flute length to the
    /// stick-out) and holder segments. O(arc length / √(chord_tol·ρ)).
    ///
    /// Errors: invalid cutter, or `chord_tol` not finite and > 0.
    pub fn frusta(&self, chord_tol: f64) -> Result<Vec<Frustum>, CamError> {
        self.validate()?;
        if !(chord_tol.is_finite() && chord_tol > 0.0) {
            return Err(CamError::NonPositive {
                field: "chord_tol",
                value: chord_tol,
            });
        }
        let l = self.flute_length;
        let half_pi = std::f64::consts::FRAC_PI_2;
        let mut pts: Vec<[f64; 2]> = Vec::new();
        match self.shape {
            CutterShape::BallEnd { radius } => {
                arc_polyline(0.0, radius, radius, -half_pi, 0.0, chord_tol, &mut pts);
            }
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => {
                let r = ball_radius;
                arc_polyline(0.0, r, r, -half_pi, -half_angle, chord_tol, &mut pts);
            }
            CutterShape::BullNose {
                radius,
                corner_radius: rc,
            } => {
                arc_polyline(radius - rc, rc, rc, -half_pi, 0.0, chord_tol, &mut pts);
            }
            CutterShape::FlatEnd { .. } | CutterShape::TaperedFlatEnd { .. } => {
                pts.push([self.shape.radius_at(0.0), 0.0]);
            }
        }
        // Continue straight (cylinder / cone, exact) up to the flute length, then clip.
        if pts.last().is_some_and(|p| p[1] < l) {
            pts.push([self.shape.radius_at(l), l]);
        }
        let mut out = Vec::new();
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b[1] <= a[1] || a[1] >= l {
                continue; // flat bottom disc (covered by the solid frustum above) or above L
            }
            let (h1, r1) = if b[1] > l {
                (l, a[0] + (l - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
            } else {
                (b[1], b[0])
            };
            out.push(Frustum {
                h0: a[1],
                h1,
                r0: a[0],
                r1,
            });
        }
        if self.overall_length > l {
            out.push(Frustum {
                h0: l,
                h1: self.overall_length,
                r0: self.shank_radius,
                r1: self.shank_radius,
            });
        }
        let mut base = self.overall_length;
        for seg in &self.holder {
            out.push(Frustum {
                h0: base,
                h1: base + seg.length,
                r0: seg.bottom_radius,
                r1: seg.top_radius,
            });
            base += seg.length;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HolderSegment;

    #[test]
    fn frusta_contain_the_cutter_within_chord_tol() {
        let shapes = [
            CutterShape::BallEnd { radius: 3.0 },
            CutterShape::TaperedBallEnd {
                ball_radius: 3.0,
                half_angle: 0.08,
            },
            CutterShape::BullNose {
                radius: 5.0,
                corner_radius: 1.0,
            },
            CutterShape::FlatEnd { radius: 4.0 },
            CutterShape::TaperedFlatEnd {
                tip_radius: 2.0,
                half_angle: 0.1,
            },
        ];
        let tol = 1e-3;
        for shape in shapes {
            let mut c = Cutter::new("t", shape, 20.0, 6.0, 50.0).unwrap();
            c.holder.push(HolderSegment {
                bottom_radius: 10.0,
                top_radius: 15.0,
                length: 30.0,
            });
            let fr = c.frusta(tol).unwrap();
            // Contiguous stack from the tip to the holder top.
            assert_eq!(fr[0].h0, 0.0);
            for w in fr.windows(2) {
                assert!((w[0].h1 - w[1].h0).abs() < 1e-12, "{shape:?}");
            }
            assert!((fr.last().unwrap().h1 - 80.0).abs() < 1e-12);
            for i in 1..8000 {
                let h = 80.0 * i as f64 / 8000.0;
                let exact = c.assembly_radius_at(h).unwrap();
                let approx = fr.iter().find_map(|f| f.radius_at(h)).unwrap();
                // The normal offset is bounded by tol; the radial one by tol / |cos(normal)|,
                // so compare away from the horizontal tangent at the very tip.
                assert!(
                    approx >= exact - 1e-9,
                    "{shape:?} h={h}: {approx} < {exact}"
                );
                if h > 0.3 {
                    assert!(
                        approx <= exact + 5.0 * tol,
                        "{shape:?} h={h}: {approx} vs {exact}"
                    );
                }
            }
        }
        let c = Cutter::new("t", CutterShape::FlatEnd { radius: 4.0 }, 20.0, 6.0, 50.0).unwrap();
        assert_eq!(
            c.frusta(1e-3).unwrap().len(),
            2,
            "flat end + shank are exact"
        );
        assert!(matches!(c.frusta(0.0), Err(CamError::NonPositive { .. })));
    }
}
