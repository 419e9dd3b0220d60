//! The report's plot of the planned paths.

use super::level::LevelPlan;
use super::operation::ChannelRoughing;
use cam_plan::{Plot, PlotKind, PlotSeries};

impl ChannelRoughing {
    pub(super) fn plot(&self, levels: &[LevelPlan]) -> Vec<Plot> {
        let Some(lp) = levels.get(levels.len() / 2) else {
            return Vec::new();
        };
        let mut series = Vec::new();
        for (ai, area) in lp.areas.iter().enumerate() {
            for (k, p) in area.tri.iter().enumerate() {
                series.push(PlotSeries {
                    label: format!("triangle area {ai} path {k}"),
                    points: p.clone(),
                });
            }
            for (k, p) in area.iso.iter().enumerate() {
                series.push(PlotSeries {
                    label: format!("isoparametric area {ai} path {k}"),
                    points: p.clone(),
                });
            }
        }
        vec![Plot {
            title: format!(
                "Channel roughing, level {} of {}: triangle vs isoparametric paths (developed)",
                levels.len() / 2 + 1,
                levels.len()
            ),
            kind: PlotKind::Lines {
                x_label: "s along the level contour (mm)".into(),
                y_label: "r·θ across the channel (mm)".into(),
                series,
                equal_aspect: true,
            },
        }]
    }
}
