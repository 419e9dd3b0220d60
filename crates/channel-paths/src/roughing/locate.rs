//! The cutter locations of one level: postures along every planned path, certified motions,
//! links inside each lane, and the level's measurements.

use super::axes::{smooth_axes, Axes};
use super::fit::FitQuery;
use super::level::LevelPlan;
use super::operation::ChannelRoughing;
use super::plan2d::Linking;
use super::posture::{Blocked, Posture, BRIDGE_DEPTH, SEGMENT_QUERIES};
use super::scallop::ScallopProbe;
use super::sides::Bound;
use cam_core::{CutterLocation, Move, MoveKind};
use cam_plan::{PlanContext, PlanError};
use nalgebra::Vector3;

/// Cutter locations and measurements of one level.
pub(super) struct LevelCl {
    pub(super) moves: Vec<Vec<Move>>,
    pub(super) tri_len: f64,
    pub(super) iso_len: f64,
    /// Length of the whole-channel isoparametric baseline (mm).
    pub(super) channel_iso_len: f64,
    pub(super) min_blade_clearance: f64,
    pub(super) max_scallop: f64,
    pub(super) paths: usize,
    /// Path points where the cutter fits with no candidate axis (between the fit samples).
    pub(super) skipped_cutter: usize,
    /// Path points where the cutter fits but shank or holder hit with every candidate axis.
    pub(super) skipped_tool: usize,
    /// Motions between two collision-free postures that were not clear even through planned
    /// intermediate postures (the path was split there).
    pub(super) split_motions: usize,
    /// Intermediate postures inserted to certify motions.
    pub(super) bridge_postures: usize,
}

impl ChannelRoughing {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn locate_level(
        &self,
        ctx: &PlanContext<'_>,
        lp: &LevelPlan,
        bounds: &[Bound],
        blades_only: &cam_plan::DesignClearance<'_>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        doc: f64,
    ) -> Result<LevelCl, PlanError> {
        let shape = ctx.tool.cutter.shape;
        let max_tilt = self.params.max_tilt_deg.to_radians();
        let mut out = LevelCl {
            moves: Vec::new(),
            tri_len: 0.0,
            iso_len: 0.0,
            channel_iso_len: 0.0,
            min_blade_clearance: f64::INFINITY,
            max_scallop: 0.0,
            paths: 0,
            skipped_cutter: 0,
            skipped_tool: 0,
            split_motions: 0,
            bridge_postures: 0,
        };
        // Motions between postures may come this far below zero clearance (the other half
        // of the machining tolerance is the clearance query's own sampling error).
        let seg_tol = 0.5 * ctx.tolerances.machining_tol;
        let lv = &lp.level;
        // Every cutter location of the level (all lanes), for the scallop measurement.
        let mut level_runs: Vec<Vec<CutterLocation>> = Vec::new();
        for area in &lp.areas {
            let Some(field) = lp.fields.get(area.field) else {
                continue;
            };
            let axes = Axes {
                lv,
                field,
                bounds,
                max_tilt,
                level: area.level,
            };
            let mut chunks: Vec<Vec<Move>> = Vec::new();
            let mut cur: Vec<Move> = Vec::new();
            for (pi, path) in area.tri.iter().enumerate() {
                let raw: Vec<Vector3<f64>> = path
                    .iter()
                    .map(|&q| axes.wanted(q, &axes.point_of(q).1))
                    .collect();
                let smooth = smooth_axes(&raw, self.params.axis_smoothing);
                let mut found: Vec<Option<Posture>> = Vec::with_capacity(path.len());
                for (&q, a) in path.iter().zip(&smooth) {
                    match self.posture(ctx, fit, fit_min, &axes, q, Some(*a))? {
                        Ok(p) => found.push(Some(p)),
                        Err(why) => {
                            // No certified posture: the point is left uncut (the path is
                            // split there; the measured scallop shows the residue).
                            match why {
                                Blocked::Cutter => out.skipped_cutter += 1,
                                Blocked::ShankOrHolder => out.skipped_tool += 1,
                            }
                            found.push(None);
                        }
                    }
                }
                // The motions between consecutive postures are certified too (the axis may
                // change between them), through planned intermediate postures where needed;
                // when that fails the path is split there (the linker retracts and
                // approaches around the gap).
                let mut checked: Vec<Option<Posture>> = Vec::with_capacity(found.len());
                let mut mids: Vec<Posture> = Vec::new();
                for k in 0..found.len() {
                    if k > 0 {
                        if let (Some(a), Some(b)) = (&found[k - 1], &found[k]) {
                            mids.clear();
                            let ok = self.bridge(
                                ctx,
                                fit,
                                fit_min,
                                &axes,
                                (a, path[k - 1]),
                                (b, path[k]),
                                seg_tol,
                                BRIDGE_DEPTH,
                                &mut mids,
                            )?;
                            if ok {
                                out.bridge_postures += mids.len();
                                checked.extend(mids.drain(..).map(Some));
                            } else {
                                out.split_motions += 1;
                                checked.push(None);
                            }
                        }
                    }
                    checked.push(found[k]);
                }
                let mut cls: Vec<Option<CutterLocation>> = Vec::with_capacity(checked.len());
                for f in checked {
                    let Some((cl, c)) = f else {
                        cls.push(None);
                        continue;
                    };
                    // The nearest part is a blade: that is the blade clearance; otherwise ask
                    // the blades alone.
                    let blade_clear = match c.design_part {
                        cam_plan::DesignPart::Blade { .. } => c.distance_mm,
                        _ => blades_only.clearance(&cl).distance_mm,
                    };
                    out.min_blade_clearance = out.min_blade_clearance.min(blade_clear);
                    cls.push(Some(cl));
                }
                for run in cls.split(Option::is_none) {
                    out.tri_len += polyline_len(run.iter().flatten().map(|c| c.tip.coords));
                }
                // Link from the previous path inside the lane (one-way links lifted by the
                // depth of cut); a link that is not collision-free ends the chunk instead.
                let first = cls.first().copied().flatten();
                if pi > 0 && !cur.is_empty() {
                    let mut linked = false;
                    if let (Some(link), Some(first)) = (area.links.get(pi - 1), first) {
                        let lift = if self.params.linking == Linking::OneWay {
                            doc
                        } else {
                            0.0
                        };
                        let kind = if lift > 0.0 {
                            MoveKind::Rapid
                        } else {
                            MoveKind::Feed
                        };
                        let mut moves: Vec<Move> = Vec::new();
                        let mut clear = true;
                        let mut prev = cur.last().map(|m| m.cl);
                        for &q in link.iter().skip(1).take(link.len().saturating_sub(2)) {
                            let (p, n) = axes.point_of(q);
                            let a = axes.wanted(q, &n);
                            let cl = self.touch(&shape, &p, &n, &a, area.level, q)?;
                            let cl = CutterLocation {
                                tip: cl.tip + n * lift,
                                axis: cl.axis,
                            };
                            let motion_clear = prev.is_none_or(|from| {
                                ctx.clearance
                                    .segment_clearance(&from, &cl, 0.0, seg_tol, SEGMENT_QUERIES)
                                    .is_ok()
                            });
                            if !motion_clear {
                                clear = false;
                                break;
                            }
                            prev = Some(cl);
                            moves.push(Move {
                                kind,
                                cl,
                                feed_mm_per_min: None,
                            });
                        }
                        clear = clear
                            && prev.is_none_or(|from| {
                                ctx.clearance
                                    .segment_clearance(&from, &first, 0.0, seg_tol, SEGMENT_QUERIES)
                                    .is_ok()
                            });
                        if clear {
                            cur.extend(moves);
                            cur.push(Move {
                                kind: if lift > 0.0 {
                                    MoveKind::Plunge
                                } else {
                                    MoveKind::Feed
                                },
                                cl: first,
                                feed_mm_per_min: None,
                            });
                            linked = true;
                        }
                    }
                    if !linked {
                        chunks.push(std::mem::take(&mut cur));
                    }
                }
                let mut run: Vec<CutterLocation> = Vec::new();
                for (k, c) in cls.iter().enumerate() {
                    match c {
                        Some(cl) => {
                            // The path's first point is already the link's end.
                            let dup = k == 0 && cur.last().is_some_and(|m| m.cl == *cl);
                            if !dup {
                                cur.push(Move::feed(*cl));
                            }
                            run.push(*cl);
                        }
                        None => {
                            if !cur.is_empty() {
                                chunks.push(std::mem::take(&mut cur));
                            }
                            if !run.is_empty() {
                                level_runs.push(std::mem::take(&mut run));
                            }
                        }
                    }
                }
                if !run.is_empty() {
                    level_runs.push(run);
                }
                out.paths += 1;
            }
            if !cur.is_empty() {
                chunks.push(cur);
            }
            for path in &area.iso {
                out.iso_len += polyline_len(path.iter().map(|&q| axes.point_of(q).0));
            }
            out.moves.extend(chunks);
        }
        for path in &lp.channel_iso {
            out.channel_iso_len += polyline_len(
                path.iter()
                    .map(|q| lv.at_developed(q[0], q[1] / lv.radius_at(q[0])).0),
            );
        }
        // The scallop of every lane (its machinable region), against every cutter position
        // of the level.
        let probe = ScallopProbe::new(&shape, ctx.tool.cutter.flute_length, &level_runs, doc);
        for area in &lp.areas {
            out.max_scallop = out.max_scallop.max(probe.measure(&area.region, lv));
        }
        Ok(out)
    }
}

pub(super) fn polyline_len(pts: impl Iterator<Item = Vector3<f64>>) -> f64 {
    let mut len = 0.0;
    let mut prev: Option<Vector3<f64>> = None;
    for p in pts {
        if let Some(q) = prev {
            len += (p - q).norm();
        }
        prev = Some(p);
    }
    len
}
