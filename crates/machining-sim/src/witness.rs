//! A witness that a placed cutter removes nothing from one ray, checked without a
//! ray–solid intersection.
//!
//! After the cutter's interval `[s, e]` on a ray has been subtracted (or lay in air), its
//! midpoint `m` lies in a gap `(g_lo, g_hi)` of the ray's material (`g_lo` the end of the
//! material interval below it, `g_hi` the start of the one above; ±∞ when there is none).
//! For a later placement with convex cutting solid `C` (every cutting part of
//! `cam_core::CutterShape` is convex, [`crate::tool_solid`]): if `m ∈ C` and neither gap end
//! is in `C`, the ray's chord through `C` is an interval containing `m` and neither end, so
//! it lies inside `(g_lo, g_hi)` and meets no material. Removal only shrinks material, so
//! the gap stays air for the rest of the batch.
//!
//! The three memberships are decided with a margin ([`RevolvedSolid::inside_by`],
//! [`RevolvedSolid::outside_by`]) larger than the rounding of the chord the
//! intersection would compute and of its storage in `f32`: where the witness holds, the
//! intersection and subtraction of [`crate::removal`] would leave the ray bit for bit as it
//! is. Cost: three point classifications (O(pieces), no division) instead of an
//! intersection and a subtraction.

use crate::tool_solid::{RayLocal, RevolvedSolid};

/// The witness of one ray (none when `m` is NaN).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Witness {
    m: f64,
    lo: f64,
    hi: f64,
}

impl Witness {
    /// No witness.
    pub(crate) const NONE: Self = Self {
        m: f64::NAN,
        lo: 0.0,
        hi: 0.0,
    };

    /// The witness after the chord `[s, e]` (ray coordinates) was subtracted from a ray
    /// now holding `segs`: the chord's midpoint and the gap around it; none when the
    /// midpoint is in material (a chord too short to clear anything in `f32`).
    pub(crate) fn after_cut(segs: &[[f32; 2]], s: f64, e: f64) -> Self {
        let m = 0.5 * (s + e);
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for seg in segs {
            let (a, b) = (f64::from(seg[0]), f64::from(seg[1]));
            if b < m {
                lo = b;
            } else if a > m {
                hi = a;
                break;
            } else {
                return Self::NONE;
            }
        }
        Self { m, lo, hi }
    }

    /// Whether the witness proves that the cutting solid `solid`, placed with tip
    /// coordinate `tip_d` along the ray and seen from the ray as `rl`, meets no material of
    /// the ray, with `margin` (mm) against rounding.
    #[inline]
    pub(crate) fn holds(
        &self,
        rl: &RayLocal,
        tip_d: f64,
        solid: &RevolvedSolid,
        margin: f64,
    ) -> bool {
        if self.m.is_nan() {
            return false;
        }
        let at = |t: f64| {
            let l = t - tip_d;
            (
                rl.qh + l * rl.ad,
                rl.w0sq + l * (2.0 * rl.w0d + l * rl.w1sq),
            )
        };
        let (h, r2) = at(self.m);
        solid.inside_by(h, r2, margin)
            && (self.lo == f64::NEG_INFINITY || {
                let (h, r2) = at(self.lo);
                solid.outside_by(h, r2, margin)
            })
            && (self.hi == f64::INFINITY || {
                let (h, r2) = at(self.hi);
                solid.outside_by(h, r2, margin)
            })
    }
}
