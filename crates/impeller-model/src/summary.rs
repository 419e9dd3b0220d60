//! The impeller summary printed by `impeller-cam model --json` and stored in reports.
//!
//! Every number is measured on the NURBS geometry, not copied from parameters:
//! - `blade_tip_diameter_mm`: twice the largest radius of any blade point between hub and
//!   shroud (each side sampled on 121 u-values × 9 span rows between its hub and shroud edges,
//!   plus the edges themselves);
//! - `axial_height_mm`: the largest z of hub and shroud contours (the back face is z = 0);
//! - `min_channel_width_{hub,shroud}_mm`: see [`crate::channel`];
//! - `min_blade_thickness_mm`: the smallest distance from points of the −θ side to the +θ side
//!   of each distinct blade (closest point, 61 × 9 samples between hub and shroud), leaving out
//!   rounded noses (blade-local m within twice the nose length of an edge) or, for blades
//!   without design data, the first and last 5 % of u.

use crate::blade::{Blade, Side};
use crate::channel::{edge_v, Wall};
use crate::impeller::Impeller;
use crate::query::closest_point;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Key figures of an impeller (fixed names: regressions and dashboards read them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpellerSummary {
    /// Impeller name.
    pub name: String,
    /// Number of main blades.
    pub main_blade_count: usize,
    /// Number of splitter blades (0 without splitters).
    pub splitter_blade_count: usize,
    /// "ruled" or "free_form".
    pub blade_kind: crate::blade::BladeKind,
    /// Twice the largest radius of any blade point (mm).
    pub blade_tip_diameter_mm: f64,
    /// Height of the impeller above the hub back face (mm).
    pub axial_height_mm: f64,
    /// Narrowest channel at the hub (mm).
    pub min_channel_width_hub_mm: f64,
    /// Narrowest channel at the shroud (mm).
    pub min_channel_width_shroud_mm: f64,
    /// Thinnest blade (normal thickness away from rounded noses, mm).
    pub min_blade_thickness_mm: f64,
    /// Blade-root fillet radius (mm).
    pub fillet_radius_mm: f64,
    /// Largest radius of the blank (mm).
    pub stock_radius_mm: f64,
}

/// Blade-local u range where thickness is measured (rounded noses left out).
fn thickness_u_range(b: &Blade) -> (f64, f64) {
    let ((u0, u1), _) = b.pressure().domain();
    match b.design() {
        Some(d) => {
            let (le, te) = d.thickness.nose_lengths();
            let lo = 2.0 * le;
            let hi = 1.0 - 2.0 * te;
            // Invert m_of_u by bisection (monotone).
            let inv = |m: f64| {
                let (mut a, mut b) = (0.0, 1.0);
                for _ in 0..60 {
                    let c = 0.5 * (a + b);
                    if d.m_local(c) < m {
                        a = c;
                    } else {
                        b = c;
                    }
                }
                0.5 * (a + b)
            };
            (inv(lo), inv(hi))
        }
        None => (u0 + 0.05 * (u1 - u0), u1 - 0.05 * (u1 - u0)),
    }
}

impl Impeller {
    /// Smallest normal thickness of `blade` between hub and shroud (see module docs).
    pub fn min_thickness_of(&self, blade: &Blade) -> f64 {
        let (ua, ub) = thickness_u_range(blade);
        let side = blade.plus_theta_side().other();
        let other = side.other();
        let nu = 61;
        (0..nu)
            .into_par_iter()
            .map(|i| {
                let u = ua + (ub - ua) * i as f64 / (nu - 1) as f64;
                let vh = edge_v(blade, side, self.hub(), u);
                let vs = edge_v(blade, side, self.shroud(), u);
                // No span at this u (beyond a wall's end) is normal: nothing to measure.
                let (Ok(vh), Ok(vs)) = (vh, vs) else {
                    return f64::INFINITY;
                };
                (0..9)
                    .map(|j| {
                        let v = vh + (vs - vh) * j as f64 / 8.0;
                        let p = blade.side(side).point(u, v);
                        closest_point(blade.side(other), &p, Some((u, v))).distance
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .reduce(|| f64::INFINITY, f64::min)
    }

    /// Largest radius of any point of `blade` between hub and shroud.
    pub fn max_blade_radius_of(&self, blade: &Blade) -> f64 {
        [Side::Pressure, Side::Suction]
            .par_iter()
            .map(|&side| {
                let s = blade.side(side);
                let ((u0, u1), _) = s.domain();
                let nu = 121;
                (0..nu)
                    .map(|i| {
                        let u = u0 + (u1 - u0) * i as f64 / (nu - 1) as f64;
                        // No span at this u (beyond a wall's end): nothing to measure.
                        let (Ok(vh), Ok(vs)) = (
                            edge_v(blade, side, self.hub(), u),
                            edge_v(blade, side, self.shroud(), u),
                        ) else {
                            return 0.0;
                        };
                        (0..9)
                            .map(|j| {
                                let p = s.point(u, vh + (vs - vh) * j as f64 / 8.0);
                                (p.x * p.x + p.y * p.y).sqrt()
                            })
                            .fold(0.0, f64::max)
                    })
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    }

    /// The measured summary (a few hundred thousand surface evaluations; well under a second).
    pub fn summary(&self) -> ImpellerSummary {
        let mut blades = vec![self.main().blade()];
        if let Some(s) = self.splitter() {
            blades.push(s.blade());
        }
        let tip = blades
            .iter()
            .map(|b| self.max_blade_radius_of(b))
            .fold(0.0, f64::max);
        let thick = blades
            .iter()
            .map(|b| self.min_thickness_of(b))
            .fold(f64::INFINITY, f64::min);
        let top = |m: &crate::meridional::MeridionalCurve| {
            let (a, b) = m.domain();
            (0..=64)
                .map(|k| m.point(a + (b - a) * k as f64 / 64.0).x)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let axial = top(self.hub().meridional()).max(top(self.shroud().meridional()));
        ImpellerSummary {
            name: self.name().to_string(),
            main_blade_count: self.main().count(),
            splitter_blade_count: self.splitter().map_or(0, |s| s.count()),
            blade_kind: self.main().blade().kind(),
            blade_tip_diameter_mm: 2.0 * tip,
            axial_height_mm: axial,
            min_channel_width_hub_mm: self.min_channel_width(Wall::Hub).unwrap_or(f64::NAN),
            min_channel_width_shroud_mm: self.min_channel_width(Wall::Shroud).unwrap_or(f64::NAN),
            min_blade_thickness_mm: thick,
            fillet_radius_mm: self.fillet_radius_mm(),
            stock_radius_mm: self.stock().max_radius(),
        }
    }
}
