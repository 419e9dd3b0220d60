//! The report's plots: per level, in the developed plane, the lanes with the triangle pieces
//! as cut and their links, and beside them (shifted across the flow) the isoparametric
//! baseline ordered and linked by the same code.

use super::level::LevelPlan;
use super::locate::LevelCl;
use super::operation::ChannelRoughing;
use super::plan2d::Path2;
use cam_plan::{Plot, PlotKind, PlotSeries};

/// Gap (in widths of the drawing) between the triangle plan and the baseline beside it.
const BESIDE_GAP: f64 = 0.15;

/// One series of several polylines, separated by a non-finite point (the chart lifts its
/// pen there), shifted by `dy` across the flow.
fn series(label: &str, paths: &[&Path2], dy: f64) -> PlotSeries {
    let mut points = Vec::new();
    for p in paths {
        if !points.is_empty() {
            points.push([f64::NAN, f64::NAN]);
        }
        points.extend(p.iter().map(|q| [q[0], q[1] + dy]));
    }
    PlotSeries {
        label: label.into(),
        points,
    }
}

/// The lane outlines, drawn under both plans.
fn lanes(outlines: &[&Path2], dy: f64) -> PlotSeries {
    let mut s = series("lanes", outlines, 0.0);
    let shifted = series("lanes", outlines, dy);
    s.points.push([f64::NAN, f64::NAN]);
    s.points.extend(shifted.points);
    s
}

impl ChannelRoughing {
    /// One plot per level (module docs).
    pub(super) fn plot(&self, levels: &[LevelPlan], located: &[LevelCl]) -> Vec<Plot> {
        let n = levels.len();
        levels
            .iter()
            .zip(located)
            .enumerate()
            .filter(|(_, (_, lc))| !lc.sketch.is_empty())
            .map(|(j, (_, lc))| {
                let outlines: Vec<&Path2> = lc.sketch.iter().map(|l| &l.outline).collect();
                let (lo, hi) = outlines
                    .iter()
                    .flat_map(|p| p.iter())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
                        (a.min(q[1]), b.max(q[1]))
                    });
                let dy = (hi - lo) * (1.0 + BESIDE_GAP);
                let tri: Vec<&Path2> = lc.sketch.iter().flat_map(|l| &l.tri).collect();
                let tri_links: Vec<&Path2> = lc.sketch.iter().flat_map(|l| &l.tri_links).collect();
                let iso: Vec<&Path2> = lc.sketch.iter().flat_map(|l| &l.iso).collect();
                let iso_links: Vec<&Path2> = lc.sketch.iter().flat_map(|l| &l.iso_links).collect();
                Plot {
                    title: format!(
                        "Channel roughing, level {} of {n}: triangle paths and their links \
                         (bottom) beside the isoparametric baseline linked the same way (top)",
                        j + 1
                    ),
                    kind: PlotKind::Lines {
                        x_label: "s along the level contour (mm)".into(),
                        y_label: format!(
                            "r·θ across the channel (mm; baseline shifted by {dy:.1} mm)"
                        ),
                        series: vec![
                            lanes(&outlines, dy),
                            series("triangle paths", &tri, 0.0),
                            series("links between paths", &tri_links, 0.0),
                            series("isoparametric baseline", &iso, dy),
                            series("baseline links", &iso_links, dy),
                        ],
                        equal_aspect: true,
                    },
                }
            })
            .collect()
    }
}
