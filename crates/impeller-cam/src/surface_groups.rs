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

/// Per group with measured points: its residuals sorted ascending and its largest overcut.
fn by_group(maps: &[SurfaceMap]) -> BTreeMap<String, (Vec<f64>, f64)> {
    let mut groups: BTreeMap<String, (Vec<f64>, f64)> = BTreeMap::new();
    for m in maps {
        let e = groups.entry(group_of(&m.name)).or_default();
        e.0.extend(m.residual_mm.iter().flatten().copied());
        e.1 = m.overcut_mm.iter().flatten().copied().fold(e.1, f64::max);
    }
    groups.retain(|_, (v, _)| !v.is_empty());
    for (v, _) in groups.values_mut() {
        v.sort_by(f64::total_cmp);
    }
    groups
}

/// The residual distribution per group of `maps` (groups without measured points are left
/// out). O(points · log points).
pub fn surface_groups(maps: &[SurfaceMap]) -> BTreeMap<String, GroupResidual> {
    by_group(maps)
        .into_iter()
        .map(|(name, (v, overcut))| {
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

/// Largest residual (mm) of the exceedance curves of [`exceedance_curves`].
pub const CURVE_MAX_MM: f64 = 0.5;

/// Per group, the exceedance curve of its residual: the share of its measured points (in
/// percent) whose residual is above `x`, for `x` in `steps + 1` even steps from 0 to
/// [`CURVE_MAX_MM`] — the whole distribution of which [`GroupResidual`] gives three points
/// and the 90th percentile. O(points · log points).
pub fn exceedance_curves(maps: &[SurfaceMap], steps: usize) -> Vec<(String, Vec<(f64, f64)>)> {
    let steps = steps.max(1);
    by_group(maps)
        .into_iter()
        .map(|(name, (v, _))| {
            let n = v.len() as f64;
            let curve = (0..=steps)
                .map(|k| {
                    let x = CURVE_MAX_MM * k as f64 / steps as f64;
                    let above = v.len() - v.partition_point(|&r| r <= x);
                    (x, 100.0 * above as f64 / n)
                })
                .collect();
            (name, curve)
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
    fn exceedance_curves_count_the_points_above_each_residual() {
        let maps = [
            map("main0_pressure", &[0.0, 0.06, 0.3, 0.01, 0.02]),
            map("main1_pressure", &[0.11, 0.0, 0.0, 0.0, 0.6]),
            map("hub", &[0.2, 0.2]),
        ];
        let c = exceedance_curves(&maps, 10);
        let names: Vec<&str> = c.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["hub", "main_pressure"]);
        let main = &c[1].1;
        assert_eq!(main.len(), 11);
        // x = 0: 0.06, 0.3, 0.01, 0.02, 0.11, 0.6 are above: 6 of 10.
        assert!((main[0].0 - 0.0).abs() < 1e-12 && (main[0].1 - 60.0).abs() < 1e-9);
        // x = 0.05: 0.06, 0.3, 0.11, 0.6; x = 0.1: 0.3, 0.11, 0.6; x = 0.5: 0.6.
        assert!((main[1].1 - 40.0).abs() < 1e-9);
        assert!((main[2].1 - 30.0).abs() < 1e-9);
        assert!((main[10].0 - 0.5).abs() < 1e-12 && (main[10].1 - 10.0).abs() < 1e-9);
        // The hub's two points at 0.2 mm: all above 0.15, none above 0.2.
        let hub = &c[0].1;
        assert!((hub[3].1 - 100.0).abs() < 1e-9 && hub[4].1.abs() < 1e-9);
        // The curve agrees with the shares of the summary.
        let g = &surface_groups(&maps)["main_pressure"];
        assert!((main[2].1 / 100.0 - g.share_above_0_1_mm).abs() < 1e-12);
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
