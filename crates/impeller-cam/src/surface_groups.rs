//! The residual distribution of each surface group of the verification maps: the blades'
//! pressure sides, suction sides and tips of each row, and the hub. A map's group is its name
//! without the blade number (`splitter3_suction` → `splitter_suction`), so the groups compare
//! like surfaces across the rows — the figure that shows whether splitters are finished like
//! the main blades.

use machining_sim::measure::SurfaceMap;
use serde::Serialize;
use std::collections::BTreeMap;

/// Residual thresholds of the shares (mm).
pub const THRESHOLDS_MM: [f64; 3] = [0.05, 0.1, 0.2];

/// The residual distribution of one group over its measured map points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupResidual {
    /// Measured points.
    pub points: usize,
    /// Share of the points with residual above 0.05 mm (0–1).
    pub share_above_0_05_mm: f64,
    /// Share above 0.1 mm.
    pub share_above_0_1_mm: f64,
    /// Share above 0.2 mm.
    pub share_above_0_2_mm: f64,
    /// 90th percentile of the residual (mm; nearest rank).
    pub p90_mm: f64,
    /// Largest residual (mm).
    pub max_mm: f64,
    /// Largest overcut (mm).
    pub max_overcut_mm: f64,
}

/// The group of a map name: the name with its digits removed.
pub fn group_of(name: &str) -> String {
    name.chars().filter(|c| !c.is_ascii_digit()).collect()
}

/// The residual distribution per group of `maps` (groups without measured points are left
/// out). O(points · log points).
pub fn surface_groups(maps: &[SurfaceMap]) -> BTreeMap<String, GroupResidual> {
    let mut residuals: BTreeMap<String, (Vec<f64>, f64)> = BTreeMap::new();
    for m in maps {
        let e = residuals.entry(group_of(&m.name)).or_default();
        e.0.extend(m.residual_mm.iter().flatten().copied());
        e.1 = m.overcut_mm.iter().flatten().copied().fold(e.1, f64::max);
    }
    residuals
        .into_iter()
        .filter(|(_, (v, _))| !v.is_empty())
        .map(|(name, (mut v, overcut))| {
            v.sort_by(f64::total_cmp);
            let n = v.len();
            let share = |t: f64| v.iter().filter(|&&x| x > t).count() as f64 / n as f64;
            let rank = ((0.9 * n as f64).ceil() as usize).clamp(1, n) - 1;
            (
                name,
                GroupResidual {
                    points: n,
                    share_above_0_05_mm: share(THRESHOLDS_MM[0]),
                    share_above_0_1_mm: share(THRESHOLDS_MM[1]),
                    share_above_0_2_mm: share(THRESHOLDS_MM[2]),
                    p90_mm: v[rank],
                    max_mm: v[n - 1],
                    max_overcut_mm: overcut,
                },
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(name: &str, residual: &[f64]) -> SurfaceMap {
        SurfaceMap {
            name: name.into(),
            nu: residual.len(),
            nv: 1,
            points: vec![[0.0; 3]; residual.len()],
            overcut_mm: vec![Some(0.0); residual.len()],
            residual_mm: residual.iter().map(|&r| Some(r)).collect(),
        }
    }

    #[test]
    fn groups_merge_blades_and_count_shares() {
        let maps = [
            map("main0_pressure", &[0.0, 0.06, 0.3, 0.01, 0.02]),
            map("main1_pressure", &[0.11, 0.0, 0.0, 0.0, 0.0]),
            map("hub", &[0.5]),
        ];
        let g = surface_groups(&maps);
        let p = &g["main_pressure"];
        assert_eq!(p.points, 10);
        assert!((p.share_above_0_05_mm - 0.3).abs() < 1e-12);
        assert!((p.share_above_0_1_mm - 0.2).abs() < 1e-12);
        assert!((p.share_above_0_2_mm - 0.1).abs() < 1e-12);
        assert_eq!(p.max_mm, 0.3);
        // Nearest rank: the 9th of 10 sorted values.
        assert_eq!(p.p90_mm, 0.11);
        assert_eq!(g["hub"].points, 1);
    }
}
