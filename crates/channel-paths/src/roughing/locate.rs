//! The cutter locations of one level: every planned path located (postures leaning with the
//! blades, certified motions between them), pieces shorter than two path intervals dropped
//! where the level's measured scallop stays within the target without them, the pieces of
//! each lane ordered ([`super::ordering`]) and linked on the level through certified
//! postures, and the level's measurements (lengths, the count bound, the baseline linked by
//! the same code, the scallop).
//!
//! A lane's pieces joined by links on the level form a *chunk*, cut without leaving the
//! level; a link that leaves the lane or does not certify ends the chunk (the chunks are
//! joined across lanes and levels by [`super::joins`]).
//!
//! Cost per level: O(points · candidates) posture queries, O(points · 2⁴) motion checks in
//! the worst case, the same per link point, and one or two scallop measurements.

use super::axes::{smooth_axes, Axes};
use super::fit::FitQuery;
use super::joins::Chunk;
use super::level::{AreaPlan, LevelPlan};
use super::operation::ChannelRoughing;
use super::ordering::{self, Anchors, Linking};
use super::plan2d::{Path2, Region};
use super::posture::{clear_posture, Blocked, Posture, BRIDGE_DEPTH, SEGMENT_QUERIES};
use super::scallop::ScallopProbe;
use super::sides::Bound;
use cam_core::CutterShape;
use cam_core::{CutterLocation, Move, MoveKind};
use cam_plan::{DesignClearance, PlanContext, PlanError, PostureCheck};
use impeller_model::levels::DepthLevel;
use nalgebra::Vector3;

/// Largest turn (rad) of the first axis tried from one path point's posture to the next's.
pub(super) const AXIS_RATE_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// `a` turned toward `b` (unit vectors) by at most `max` (rad), on their great circle.
fn turned_toward(a: &Vector3<f64>, b: &Vector3<f64>, max: f64) -> Vector3<f64> {
    let angle = a.dot(b).clamp(-1.0, 1.0).acos();
    if angle <= max {
        return *b;
    }
    let perp = b - a * a.dot(b);
    match perp.try_normalize(1e-12) {
        Some(e) => a * max.cos() + e * max.sin(),
        None => *b,
    }
}

/// The blade clearance metric is exact up to this far (mm) above the blade allowance kept
/// (`fit_min`) and reads this value beyond it (a lower bound). Capped as the posture checks
/// ask, the query bounds a tool sample by the blade side meshes where they are farther than
/// the cap; uncapped, it takes the exact blade distance everywhere, which above the shroud
/// beyond a blade's corner is the shroud distance (`impeller_model::query::blade_solid_distance`
/// bounds the clipped solid by `max(d_p, d_s, d_shroud)` there) and read a cutter flank 3.4 mm
/// from both blade sides, 1.75 mm above the shroud at the trailing edge, as 0.06 mm inside
/// the blade (impeller-11+11-freeform, `min_blade_clearance_mm = −0.058` before).
pub(super) const BLADE_METRIC_BAND_MM: f64 = 1.0;

/// A located piece of a planned path shorter than this many path intervals (in the plane)
/// is dropped when the level's scallop stays within the target without it (module docs).
pub(super) const SHORT_PIECE_INTERVALS: f64 = 2.0;

/// What the report draws of one lane (developed plane).
#[derive(Debug, Clone, Default)]
pub(super) struct LaneSketch {
    /// The lane's outline (closed).
    pub(super) outline: Path2,
    /// Triangle pieces as cut (ordered and oriented).
    pub(super) tri: Vec<Path2>,
    /// Links between consecutive pieces (straight when they leave the lane: retracts).
    pub(super) tri_links: Vec<Path2>,
    /// Isoparametric baseline paths, ordered and oriented by the same code.
    pub(super) iso: Vec<Path2>,
    /// The baseline's links.
    pub(super) iso_links: Vec<Path2>,
}

/// Cutter locations and measurements of one level.
pub(super) struct LevelCl {
    /// Chunks in lane order: each cut without leaving the level.
    pub(super) chunks: Vec<Chunk>,
    /// Cutting runs' tip length (mm).
    pub(super) tri_len: f64,
    pub(super) iso_len: f64,
    /// Length of the whole-channel isoparametric baseline (mm).
    pub(super) channel_iso_len: f64,
    /// Triangle pieces plus their links inside the lanes, on the level (mm).
    pub(super) lane_feed_len: f64,
    /// Baseline paths plus their links inside the lanes, on the level (mm).
    pub(super) iso_lane_feed_len: f64,
    /// `Σ ∫ (⌈w/d⌉ + 1) ds` and `Σ (⌈w_max/d⌉ + 1)·L` over the lanes (mm).
    pub(super) count_len: f64,
    pub(super) baseline_count_len: f64,
    /// Links made on the level inside lanes (count) and their tip length (mm).
    pub(super) lane_links: usize,
    pub(super) lane_link_len: f64,
    /// Links inside lanes that were not made (left the lane or did not certify).
    pub(super) lane_breaks: usize,
    /// Joins between lanes on the level (count) and their tip length (mm).
    pub(super) level_links: usize,
    pub(super) level_link_len: f64,
    /// Short pieces dropped, and short pieces kept because the scallop needed them.
    pub(super) dropped_pieces: usize,
    pub(super) short_pieces_kept: usize,
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
    /// The axis smoothing of the located runs ([`cam_plan::axis_smoothing`]).
    pub(super) smoothing: cam_plan::SmoothingSummary,
    /// Per lane, what the report draws.
    pub(super) sketch: Vec<LaneSketch>,
}

/// A located piece of a planned path: consecutive postures joined by certified motions, with
/// their planar points.
#[derive(Clone, Default)]
struct Run {
    q: Path2,
    postures: Vec<Posture>,
}

impl Run {
    /// Ends the run at a gap: kept in `runs` when it holds a motion (two postures or more),
    /// else dropped; `self` starts empty.
    fn end_into(&mut self, runs: &mut Vec<Run>) {
        let run = std::mem::take(self);
        if run.postures.len() >= 2 {
            runs.push(run);
        }
    }

    fn reversed(&self) -> Self {
        Self {
            q: self.q.iter().rev().copied().collect(),
            postures: self.postures.iter().rev().copied().collect(),
        }
    }
}

/// Fits (and clearance checks) per located run of the axis smoothing: roughing runs are many
/// and their whole-tool checks dear. On nasa-hecc-15+15's roughing (release, 2026-11-28):
/// planning 63 s without smoothing, 101 s at the shared default of 24 fits (direction
/// changes 24180 -> 11655), 53 s at 6 (-> 13365; the machine was loaded, so within noise of
/// no extra cost).
const ROUGHING_MAX_FITS: usize = 6;

/// The checks of a located run's smoothed postures ([`Locator::smooth_run_axes`]).
struct RunCheck<'a, 'b> {
    loc: &'a Locator<'b>,
    max_tilt: f64,
    /// The level normal at each posture's planar point.
    normals: Vec<Vector3<f64>>,
}

impl RunCheck<'_, '_> {
    fn clear(&self, cl: &CutterLocation) -> Option<cam_plan::Clearance> {
        clear_posture(self.loc.ctx, self.loc.fit, self.loc.fit_min, cl, 0.0)
    }
}

/// The measure of a posture is its whole-tool clearance, an end of the motion's bisection.
impl PostureCheck for RunCheck<'_, '_> {
    type Clear = f64;
    fn posture_clear(&self, index: usize, cl: &CutterLocation) -> Option<f64> {
        let within_tilt = self
            .normals
            .get(index)
            .is_some_and(|n| cl.axis.angle(n) <= self.max_tilt + 1e-9);
        if !within_tilt {
            return None;
        }
        self.clear(cl).map(|c| c.distance_mm)
    }
    fn planned_clear(&self, _: usize, cl: &CutterLocation) -> Option<f64> {
        self.clear(cl).map(|c| c.distance_mm)
    }
    fn motion_clear(
        &self,
        _: usize,
        (a, ca): (&CutterLocation, &f64),
        (b, cb): (&CutterLocation, &f64),
    ) -> bool {
        self.loc
            .ctx
            .clearance
            .segment_clearance_between((a, *ca), (b, *cb), 0.0, self.loc.seg_tol(), SEGMENT_QUERIES)
            .is_ok()
    }
}

/// What locating one level needs besides the level's plan.
pub(super) struct Locator<'a> {
    pub(super) op: &'a ChannelRoughing,
    pub(super) ctx: &'a PlanContext<'a>,
    pub(super) fit: &'a FitQuery<'a>,
    pub(super) fit_min: f64,
    pub(super) doc: f64,
    /// The whole tool against the blades alone (the blade clearance metric).
    pub(super) blades_only: &'a DesignClearance<'a>,
}

impl Locator<'_> {
    /// Motions between postures may come this far below zero clearance (the other half of the
    /// machining tolerance is the clearance query's own sampling error).
    fn seg_tol(&self) -> f64 {
        0.5 * self.ctx.tolerances.machining_tol
    }

    /// Postures along `path` (first axes: the wanted axes smoothed over the path), split where
    /// a point has none or a motion does not certify even through bridge postures.
    fn locate_path(
        &self,
        axes: &Axes<'_>,
        path: &Path2,
        out: &mut LevelCl,
    ) -> Result<Vec<Run>, PlanError> {
        let raw: Vec<Vector3<f64>> = path
            .iter()
            .map(|&q| axes.wanted(q, &axes.point_of(q).1))
            .collect();
        let smooth = smooth_axes(&raw, self.op.params.axis_smoothing);
        let mut found: Vec<Option<Posture>> = Vec::with_capacity(path.len());
        let mut prev: Option<Vector3<f64>> = None;
        for (&q, a) in path.iter().zip(&smooth) {
            // The axis follows the smoothed one from the previous posture's, turning at most
            // AXIS_RATE_RAD per point (a fallback axis is left gradually, not at once).
            let first = match prev {
                Some(p) => turned_toward(&p, a, AXIS_RATE_RAD),
                None => *a,
            };
            match self
                .op
                .posture(self.ctx, self.fit, self.fit_min, axes, q, Some(first))?
            {
                Ok(p) => {
                    prev = Some(p.0.axis.into_inner());
                    found.push(Some(p))
                }
                Err(why) => {
                    // No certified posture: the point is left uncut (the path is split
                    // there; the measured scallop shows the residue).
                    match why {
                        Blocked::Cutter => out.skipped_cutter += 1,
                        Blocked::ShankOrHolder => out.skipped_tool += 1,
                    }
                    prev = None;
                    found.push(None);
                }
            }
        }
        // The motions between consecutive postures are certified too (the axis may change
        // between them), through planned intermediate postures where needed; when that fails
        // the path is split there.
        let mut runs: Vec<Run> = Vec::new();
        let mut cur = Run::default();
        let mut mids: Vec<([f64; 2], Posture)> = Vec::new();
        for k in 0..found.len() {
            let Some(b) = found[k] else {
                cur.end_into(&mut runs);
                continue;
            };
            if let (Some(a), Some(&qa)) = (cur.postures.last().copied(), cur.q.last()) {
                mids.clear();
                let ok = self.op.bridge(
                    self.ctx,
                    self.fit,
                    self.fit_min,
                    axes,
                    (&a, qa),
                    (&b, path[k]),
                    self.seg_tol(),
                    BRIDGE_DEPTH,
                    &mut mids,
                )?;
                if ok {
                    out.bridge_postures += mids.len();
                    for (q, m) in mids.drain(..) {
                        cur.q.push(q);
                        cur.postures.push(m);
                    }
                } else {
                    out.split_motions += 1;
                    cur.end_into(&mut runs);
                }
            }
            cur.q.push(path[k]);
            cur.postures.push(b);
        }
        if cur.postures.len() >= 2 {
            runs.push(cur);
        }
        for run in &mut runs {
            self.smooth_run_axes(axes, run, &mut out.smoothing);
        }
        Ok(runs)
    }

    /// The shared axis smoothing ([`cam_plan::axis_smoothing`]) of a located run: each
    /// posture turned about its ball centre (the ball keeps touching the level at the same
    /// point), the turned postures held to the tests of [`ChannelRoughing::posture`] (the tilt
    /// limit from the level normal, the whole tool clear of the design and `fit_min` from the
    /// blades) and the motions touching them certified as in [`ChannelRoughing::bridge`]
    /// (without bridge postures: a motion that does not certify directly refuses the fit).
    fn smooth_run_axes(
        &self,
        axes: &Axes<'_>,
        run: &mut Run,
        summary: &mut cam_plan::SmoothingSummary,
    ) {
        // Only a ball's contact stays where it was when the axis turns about its centre.
        let r = match self.ctx.tool.cutter.shape {
            CutterShape::BallEnd { radius } => radius,
            CutterShape::TaperedBallEnd { ball_radius, .. } => ball_radius,
            _ => return,
        };
        let cls: Vec<CutterLocation> = run.postures.iter().map(|p| p.0).collect();
        let normals: Vec<Vector3<f64>> = run.q.iter().map(|&q| axes.point_of(q).1).collect();
        let check = RunCheck {
            loc: self,
            max_tilt: axes.max_tilt,
            normals,
        };
        let r = cam_plan::axis_smoothing::smooth_run(
            &cls,
            &cam_plan::AxisSmoothing {
                max_fits: ROUGHING_MAX_FITS,
                ..cam_plan::AxisSmoothing::ball_end(r)
            },
            &check,
        );
        summary.add(&r);
        for (p, cl) in run.postures.iter_mut().zip(&r.postures) {
            if p.0 != *cl {
                // Checked clear by `smooth_run`; its clearance is asked again for the
                // motion checks and the metrics that read it.
                if let Some(c) = check.clear(cl) {
                    *p = (*cl, c);
                }
            }
        }
    }

    /// The link on the level from `from` (planar point and posture) to `to` through the
    /// planar points `inner` (the link without its ends): certified postures at the inner
    /// points (with the axes of the lane `axes_at` finds there) and certified motions from
    /// `from` through them to `to`; the postures between the ends (bridge postures included),
    /// or `None` when a point has no posture or a motion does not certify.
    fn locate_link<'b>(
        &self,
        axes_at: &dyn Fn([f64; 2]) -> Option<Axes<'b>>,
        (qa, a): ([f64; 2], Posture),
        (qb, b): ([f64; 2], Posture),
        inner: &[[f64; 2]],
        out: &mut LevelCl,
    ) -> Result<Option<Vec<Posture>>, PlanError> {
        let mut chain: Vec<([f64; 2], Posture)> = vec![(qa, a)];
        for (k, &q) in inner.iter().enumerate() {
            let Some(axes) = axes_at(q) else {
                return Ok(None);
            };
            // First axis: the end axes interpolated along the link.
            let t = (k + 1) as f64 / (inner.len() + 1) as f64;
            let first = (a.0.axis.into_inner() * (1.0 - t) + b.0.axis.into_inner() * t)
                .try_normalize(1e-12);
            match self
                .op
                .posture(self.ctx, self.fit, self.fit_min, &axes, q, first)?
            {
                Ok(p) => chain.push((q, p)),
                Err(_) => return Ok(None),
            }
        }
        chain.push((qb, b));
        let mut postures = Vec::with_capacity(chain.len());
        let mut mids: Vec<([f64; 2], Posture)> = Vec::new();
        for w in chain.windows(2) {
            // Bridge postures belong to the lane of the motion's midpoint.
            let mid = [0.5 * (w[0].0[0] + w[1].0[0]), 0.5 * (w[0].0[1] + w[1].0[1])];
            let Some(axes) = axes_at(mid) else {
                return Ok(None);
            };
            mids.clear();
            let ok = self.op.bridge(
                self.ctx,
                self.fit,
                self.fit_min,
                &axes,
                (&w[0].1, w[0].0),
                (&w[1].1, w[1].0),
                self.seg_tol(),
                BRIDGE_DEPTH,
                &mut mids,
            )?;
            if !ok {
                return Ok(None);
            }
            out.bridge_postures += mids.len();
            postures.extend(mids.drain(..).map(|(_, m)| m));
            postures.push(w[1].1);
        }
        // The last one is `to` itself.
        postures.pop();
        Ok(Some(postures))
    }

    /// The one-way link from the end of `from` back along it and across to the start of `to`
    /// (planar `link`, ends included), lifted by the depth of cut above the level with the
    /// wanted axes, each motion certified ([`cam_plan::DesignClearance::segment_clearance`]):
    /// the rapid moves and the plunge to `to`'s start, or `None`.
    fn one_way_link(
        &self,
        axes: &Axes<'_>,
        link: &Path2,
        from: &CutterLocation,
        to: &CutterLocation,
    ) -> Result<Option<Vec<Move>>, PlanError> {
        let shape = self.ctx.tool.cutter.shape;
        let mut moves: Vec<Move> = Vec::new();
        let mut prev = *from;
        for &q in link.iter().skip(1).take(link.len().saturating_sub(2)) {
            let (p, n) = axes.point_of(q);
            let a = axes.wanted(q, &n);
            let cl = self.op.touch(&shape, &p, &n, &a, axes.level, q)?;
            let cl = CutterLocation {
                tip: cl.tip + n * self.doc,
                axis: cl.axis,
            };
            if self
                .ctx
                .clearance
                .segment_clearance(&prev, &cl, 0.0, self.seg_tol(), SEGMENT_QUERIES)
                .is_err()
            {
                return Ok(None);
            }
            prev = cl;
            moves.push(Move::rapid(cl));
        }
        if self
            .ctx
            .clearance
            .segment_clearance(&prev, to, 0.0, self.seg_tol(), SEGMENT_QUERIES)
            .is_err()
        {
            return Ok(None);
        }
        moves.push(Move {
            kind: MoveKind::Plunge,
            cl: *to,
            feed_mm_per_min: None,
        });
        Ok(Some(moves))
    }
}

/// Length (mm) of a planar polyline put on the level.
fn on_level_len(lv: &DepthLevel, p: &Path2) -> f64 {
    polyline_len(
        p.iter()
            .map(|q| lv.at_developed(q[0], q[1] / lv.radius_at(q[0])).0),
    )
}

/// A planar polyline with points at most `spacing` apart (its own points kept).
fn densified(p: &Path2, spacing: f64) -> Path2 {
    let mut out: Path2 = Vec::with_capacity(p.len());
    for w in p.windows(2) {
        let d = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
        let k = ((d / spacing.max(1e-6)).ceil() as usize).max(1);
        out.extend((0..k).map(|i| {
            let t = i as f64 / k as f64;
            [
                w[0][0] + t * (w[1][0] - w[0][0]),
                w[0][1] + t * (w[1][1] - w[0][1]),
            ]
        }));
    }
    out.extend(p.last());
    out
}

/// The ordered, oriented paths of a lane and their planned links (a straight segment where
/// the link leaves the lane), for measuring and drawing; `paths` inlet → outlet.
fn ordered_with_links(
    paths: &[Path2],
    area: &AreaPlan,
    linking: Linking,
    spacing: f64,
) -> (Vec<Path2>, Vec<Path2>) {
    let o = ordering::oriented(paths, &ordering::order(paths, &area.region, linking));
    let links = o
        .windows(2)
        .filter_map(|w| {
            ordering::link(&w[0], &w[1], &area.region, linking, spacing).or_else(|| {
                let (a, b) = (*w[0].last()?, *w[1].first()?);
                Some(densified(&vec![a, b], spacing))
            })
        })
        .collect();
    (o, links)
}

impl ChannelRoughing {
    /// Locates, orders and links every lane of `lp`, and measures the level (module docs).
    pub(super) fn locate_level(
        &self,
        loc: &Locator<'_>,
        lp: &LevelPlan,
        bounds: &[Bound],
    ) -> Result<LevelCl, PlanError> {
        let ctx = loc.ctx;
        let shape = ctx.tool.cutter.shape;
        let max_tilt = self.params.max_tilt_deg.to_radians();
        let linking = self.params.linking;
        let mut out = LevelCl {
            chunks: Vec::new(),
            tri_len: 0.0,
            iso_len: 0.0,
            channel_iso_len: 0.0,
            lane_feed_len: 0.0,
            iso_lane_feed_len: 0.0,
            count_len: 0.0,
            baseline_count_len: 0.0,
            lane_links: 0,
            lane_link_len: 0.0,
            lane_breaks: 0,
            level_links: 0,
            level_link_len: 0.0,
            dropped_pieces: 0,
            short_pieces_kept: 0,
            min_blade_clearance: f64::INFINITY,
            max_scallop: 0.0,
            paths: 0,
            skipped_cutter: 0,
            skipped_tool: 0,
            split_motions: 0,
            bridge_postures: 0,
            smoothing: cam_plan::SmoothingSummary::default(),
            sketch: Vec::new(),
        };
        let lv = &lp.level;
        let axes_of = |area: &AreaPlan| {
            lp.fields.get(area.field).map(|field| Axes {
                lv,
                field,
                bounds,
                max_tilt,
                level: area.level,
            })
        };
        // 1. Every planned path of every lane located.
        let mut lane_runs: Vec<Vec<Run>> = Vec::with_capacity(lp.areas.len());
        for area in &lp.areas {
            let mut runs = Vec::new();
            if let Some(axes) = axes_of(area) {
                for path in &area.tri {
                    runs.extend(loc.locate_path(&axes, path, &mut out)?);
                    out.paths += 1;
                }
            }
            lane_runs.push(runs);
        }
        // 2. Short pieces dropped when the level's scallop stays within the target without
        // them; kept otherwise.
        let is_short = |area: &AreaPlan, r: &Run| {
            ordering::polyline_length(&r.q) < SHORT_PIECE_INTERVALS * area.step
        };
        let n_short: usize = lp
            .areas
            .iter()
            .zip(&lane_runs)
            .map(|(a, runs)| runs.iter().filter(|r| is_short(a, r)).count())
            .sum();
        let cls_of = |keep_short: bool| -> Vec<Vec<CutterLocation>> {
            lp.areas
                .iter()
                .zip(&lane_runs)
                .flat_map(|(a, runs)| {
                    runs.iter()
                        .filter(move |r| keep_short || !is_short(a, r))
                        .map(|r| r.postures.iter().map(|p| p.0).collect())
                })
                .collect()
        };
        let scallop_of = |cls: &[Vec<CutterLocation>]| {
            let probe = ScallopProbe::new(&shape, ctx.tool.cutter.flute_length, cls, loc.doc);
            lp.areas
                .iter()
                .map(|a| probe.measure(&a.region, lv))
                .fold(0.0, f64::max)
        };
        let target = self.params.scallop_mm;
        let mut keep_short = true;
        out.max_scallop = if n_short > 0 {
            let without = scallop_of(&cls_of(false));
            if without <= target {
                keep_short = false;
                without
            } else {
                scallop_of(&cls_of(true))
            }
        } else {
            scallop_of(&cls_of(true))
        };
        if keep_short {
            out.short_pieces_kept = n_short;
        } else {
            out.dropped_pieces = n_short;
        }
        // 3. The lanes in their order on the level (module docs), each lane's kept pieces
        // ordered between its anchors and linked on the level; measurements.
        let seq = lane_sequence(lp);
        let anchors = lane_anchors(lp, &seq);
        let mut lane_runs: Vec<Option<Vec<Run>>> = lane_runs.into_iter().map(Some).collect();
        let mut sketches: Vec<Option<LaneSketch>> = vec![None; lp.areas.len()];
        let mut chunks: Vec<LaneChunk> = Vec::new();
        for (&li, &anchor) in seq.iter().zip(&anchors) {
            let area = &lp.areas[li];
            let runs: Vec<Run> = lane_runs[li]
                .take()
                .unwrap_or_default()
                .into_iter()
                .filter(|r| keep_short || !is_short(area, r))
                .collect();
            for r in &runs {
                out.tri_len += polyline_len(r.postures.iter().map(|p| p.0.tip.coords));
                for (cl, c) in &r.postures {
                    // The nearest part is a blade: that is the blade clearance; otherwise
                    // the blades alone, asked as the posture was certified (exact below
                    // the cap, [`BLADE_METRIC_BAND_MM`] above the allowance kept).
                    let blade_clear = match c.design_part {
                        cam_plan::DesignPart::Blade { .. } => c.distance_mm,
                        _ => {
                            let cap = loc.fit_min + BLADE_METRIC_BAND_MM;
                            loc.blades_only.clearance_capped(cl, cap).distance_mm
                        }
                    };
                    out.min_blade_clearance = out.min_blade_clearance.min(blade_clear);
                }
            }
            let Some(axes) = axes_of(area) else {
                continue;
            };
            let in_lane = |_: [f64; 2]| axes_of(area);
            let paths: Vec<Path2> = runs.iter().map(|r| r.q.clone()).collect();
            let steps = ordering::order_between(&paths, &area.region, linking, anchor);
            let ordered: Vec<Run> = steps
                .iter()
                .filter_map(|s| {
                    let r = runs.get(s.index)?;
                    Some(if s.reversed { r.reversed() } else { r.clone() })
                })
                .collect();
            let mut sketch = LaneSketch {
                outline: outline(area),
                ..LaneSketch::default()
            };
            let mut cur: Option<LaneChunk> = None;
            for (k, run) in ordered.iter().enumerate() {
                out.lane_feed_len += on_level_len(lv, &run.q);
                sketch.tri.push(run.q.clone());
                let (Some(&first_q), Some(&first_p)) = (run.q.first(), run.postures.first()) else {
                    continue;
                };
                if k > 0 {
                    let prev = &ordered[k - 1];
                    let planned =
                        ordering::link(&prev.q, &run.q, &area.region, linking, lp.spacing);
                    let drawn = planned.clone().unwrap_or_else(|| {
                        densified(&vec![prev.q[prev.q.len() - 1], first_q], lp.spacing)
                    });
                    out.lane_feed_len += on_level_len(lv, &drawn);
                    sketch.tri_links.push(drawn);
                    let made = match (&planned, linking, &cur) {
                        (Some(l), Linking::ZigZag, Some(c)) => loc
                            .locate_link(
                                &in_lane,
                                c.last,
                                (first_q, first_p),
                                &l[1..l.len() - 1],
                                &mut out,
                            )?
                            .map(|ps| ps.into_iter().map(|p| Move::link(p.0)).collect::<Vec<_>>()),
                        (Some(l), Linking::OneWay, Some(c)) => {
                            loc.one_way_link(&axes, l, &c.last.1 .0, &first_p.0)?
                        }
                        _ => None,
                    };
                    match (made, cur.as_mut()) {
                        (Some(moves), Some(c)) => {
                            let mut tips = vec![c.last.1 .0.tip.coords];
                            tips.extend(moves.iter().map(|m| m.cl.tip.coords));
                            if linking == Linking::ZigZag {
                                tips.push(first_p.0.tip.coords);
                            }
                            out.lane_link_len += polyline_len(tips.into_iter());
                            out.lane_links += 1;
                            c.moves.extend(moves);
                        }
                        _ => {
                            out.lane_breaks += 1;
                            chunks.extend(cur.take());
                        }
                    }
                }
                let c = cur.get_or_insert_with(|| LaneChunk {
                    moves: Vec::new(),
                    first: (first_q, first_p),
                    last: (first_q, first_p),
                });
                for (i, (cl, _)) in run.postures.iter().enumerate() {
                    // A one-way link ends with the plunge onto the run's first point.
                    let dup = i == 0 && c.moves.last().is_some_and(|m| m.cl == *cl);
                    if !dup {
                        // The move onto the first point of a run that continues the chunk
                        // ends the zig-zag link into it.
                        c.moves.push(if i == 0 && !c.moves.is_empty() {
                            Move::link(*cl)
                        } else {
                            Move::feed(*cl)
                        });
                    }
                }
                if let (Some(&q), Some(&p)) = (run.q.last(), run.postures.last()) {
                    c.last = (q, p);
                }
            }
            chunks.extend(cur);
            // The baseline over the same lane, ordered and linked by the same code.
            for path in &area.iso {
                out.iso_len += on_level_len(lv, path);
            }
            let (iso, iso_links) = ordered_with_links(&area.iso, area, linking, lp.spacing);
            out.iso_lane_feed_len += iso
                .iter()
                .chain(&iso_links)
                .map(|p| on_level_len(lv, p))
                .sum::<f64>();
            sketch.iso = iso;
            sketch.iso_links = iso_links;
            out.count_len += area.region.count_integral(area.step);
            out.baseline_count_len += area.region.baseline_count_length(area.step);
            sketches[li] = Some(sketch);
        }
        out.sketch = sketches.into_iter().flatten().collect();
        // 4. Consecutive chunks joined on the level where the straight link between them runs
        // inside the level's lanes and certifies (postures and motions as inside a lane).
        let lanes: Vec<&Region> = lp.areas.iter().map(|a| &a.region).collect();
        let step = lp
            .areas
            .iter()
            .map(|a| a.step)
            .fold(f64::INFINITY, f64::min);
        let lane_at = |q: [f64; 2]| {
            lp.areas
                .iter()
                .find(|a| inside(&a.region, q))
                .and_then(&axes_of)
        };
        let mut joined: Vec<LaneChunk> = Vec::with_capacity(chunks.len());
        for c in chunks {
            let Some(prev) = joined.last_mut() else {
                joined.push(c);
                continue;
            };
            let (a, b) = (prev.last.0, c.first.0);
            let short = (a[0] - b[0]).hypot(a[1] - b[1]) <= SHORT_JOIN_INTERVALS * step;
            let made = if linking == Linking::ZigZag
                && (short || chord_in_lanes(&lanes, a, b, lp.spacing))
            {
                // A point outside every lane (a short join across a strip where the cutter
                // does not fit) takes the axes of the lane of the nearer end.
                let at = |q: [f64; 2]| {
                    lane_at(q).or_else(|| {
                        let near_a =
                            (q[0] - a[0]).hypot(q[1] - a[1]) <= (q[0] - b[0]).hypot(q[1] - b[1]);
                        lane_at(if near_a { a } else { b })
                    })
                };
                let l = densified(&vec![a, b], lp.spacing);
                loc.locate_link(&at, prev.last, c.first, &l[1..l.len() - 1], &mut out)?
            } else {
                None
            };
            match made {
                Some(ps) => {
                    let mut tips = vec![prev.last.1 .0.tip.coords];
                    tips.extend(ps.iter().map(|p| p.0.tip.coords));
                    tips.push(c.first.1 .0.tip.coords);
                    out.level_link_len += polyline_len(tips.into_iter());
                    out.level_links += 1;
                    prev.moves.extend(ps.into_iter().map(|p| Move::link(p.0)));
                    let mut moves = c.moves;
                    // The move onto the joined chunk's first point ends the join.
                    if let Some(m) = moves.first_mut() {
                        if m.kind == MoveKind::Feed {
                            m.kind = MoveKind::Link;
                        }
                    }
                    prev.moves.extend(moves);
                    prev.last = c.last;
                }
                None => joined.push(c),
            }
        }
        out.chunks = joined
            .into_iter()
            .map(|c| Chunk {
                moves: c.moves,
                first_q: c.first.0,
                last_q: c.last.0,
            })
            .collect();
        for path in &lp.channel_iso {
            out.channel_iso_len += on_level_len(lv, path);
        }
        Ok(out)
    }
}

/// A chunk while the level is located: its moves and the planar points and postures of its
/// ends.
struct LaneChunk {
    moves: Vec<Move>,
    first: ([f64; 2], Posture),
    last: ([f64; 2], Posture),
}

/// Whether `q` lies in `region` (within its `s` range and between its boundaries, 1e-6 mm).
fn inside(region: &Region, q: [f64; 2]) -> bool {
    match (region.s.first(), region.s.last()) {
        (Some(&s0), Some(&s1)) if q[0] >= s0 - 1e-6 && q[0] <= s1 + 1e-6 => {
            let (l, r) = region.bounds(q[0]);
            q[1] >= l - 1e-6 && q[1] <= r + 1e-6
        }
        _ => false,
    }
}

/// Whether every point of the planar chord `a`–`b`, sampled at `spacing`, lies in one of
/// `lanes`.
fn chord_in_lanes(lanes: &[&Region], a: [f64; 2], b: [f64; 2], spacing: f64) -> bool {
    densified(&vec![a, b], spacing)
        .into_iter()
        .all(|q| lanes.iter().any(|r| inside(r, q)))
}

/// Longest join between two chunks of a level (in path intervals) that may leave the
/// level's lanes (a join that runs inside them may be as long as they allow).
pub(super) const SHORT_JOIN_INTERVALS: f64 = 2.0;

/// Lanes of a level above which their order is found greedily rather than over all orders.
const EXACT_LANE_ORDER: usize = 6;

/// The order of the lanes on level `lp` (module docs): the order in which the sum of the
/// gaps between consecutive lanes' outlines is least (over all orders up to
/// [`EXACT_LANE_ORDER`] lanes, nearest neighbour beyond), of the two directions the one that
/// begins with the lower lane index, reversed on every other level so that each level ends
/// in the lane the next one begins with. On a level split by a splitter: one sub-channel,
/// the area upstream of the splitter, the other sub-channel.
fn lane_sequence(lp: &LevelPlan) -> Vec<usize> {
    let n = lp.areas.len();
    let outlines: Vec<Path2> = lp.areas.iter().map(outline).collect();
    let gap = |a: usize, b: usize| {
        outlines[a]
            .iter()
            .flat_map(|p| {
                outlines[b]
                    .iter()
                    .map(move |q| (p[0] - q[0]).hypot(p[1] - q[1]))
            })
            .fold(f64::INFINITY, f64::min)
    };
    let g: Vec<Vec<f64>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| if a == b { 0.0 } else { gap(a, b) })
                .collect()
        })
        .collect();
    let cost = |seq: &[usize]| seq.windows(2).map(|w| g[w[0]][w[1]]).sum::<f64>();
    let mut best: Vec<usize> = (0..n).collect();
    if n <= EXACT_LANE_ORDER {
        let mut perm: Vec<usize> = (0..n).collect();
        let mut best_cost = cost(&perm);
        permutations(&mut perm, 0, &mut |p| {
            let c = cost(p);
            if c < best_cost - 1e-9 {
                best_cost = c;
                best = p.to_vec();
            }
        });
    } else {
        let mut used = vec![false; n];
        best.clear();
        let mut u = 0;
        used[0] = true;
        best.push(0);
        for _ in 1..n {
            let Some(v) = (0..n)
                .filter(|&v| !used[v])
                .min_by(|&a, &b| g[u][a].total_cmp(&g[u][b]))
            else {
                break;
            };
            used[v] = true;
            best.push(v);
            u = v;
        }
    }
    if best.first() > best.last() {
        best.reverse();
    }
    if lp.areas.first().is_some_and(|a| a.level % 2 == 0) {
        best.reverse();
    }
    best
}

/// Calls `f` with every order of `v[k..]` (recursive swaps).
fn permutations(v: &mut Vec<usize>, k: usize, f: &mut impl FnMut(&[usize])) {
    if k + 1 >= v.len() {
        f(v);
        return;
    }
    for i in k..v.len() {
        v.swap(k, i);
        permutations(v, k + 1, f);
        v.swap(k, i);
    }
}

/// Where each lane of `seq` begins and ends (module docs): at its junction with the lane
/// before and after it (the point of its outline nearest the neighbour's outline, averaged
/// over the points within one path interval of that distance); the first lane begins, and
/// the last ends, at the point of its outline farthest from its junction (a level with one
/// lane: at the outlet, on the left side on odd levels and on the right on even ones, ending
/// on the other side).
fn lane_anchors(lp: &LevelPlan, seq: &[usize]) -> Vec<Anchors> {
    let outlines: Vec<Path2> = seq.iter().map(|&i| outline(&lp.areas[i])).collect();
    let junction = |a: &Path2, b: &Path2, step: f64| -> Option<[f64; 2]> {
        let d = |p: [f64; 2]| {
            b.iter()
                .map(|q| (p[0] - q[0]).hypot(p[1] - q[1]))
                .fold(f64::INFINITY, f64::min)
        };
        let ds: Vec<f64> = a.iter().map(|&p| d(p)).collect();
        let m = ds.iter().copied().fold(f64::INFINITY, f64::min);
        let near: Vec<[f64; 2]> = a
            .iter()
            .zip(&ds)
            .filter(|(_, &x)| x <= m + step)
            .map(|(p, _)| *p)
            .collect();
        (!near.is_empty()).then(|| {
            let k = near.len() as f64;
            [
                near.iter().map(|p| p[0]).sum::<f64>() / k,
                near.iter().map(|p| p[1]).sum::<f64>() / k,
            ]
        })
    };
    let far = |a: &Path2, from: [f64; 2]| {
        a.iter().copied().max_by(|p, q| {
            (p[0] - from[0])
                .hypot(p[1] - from[1])
                .total_cmp(&(q[0] - from[0]).hypot(q[1] - from[1]))
        })
    };
    let n = seq.len();
    let mut out = vec![Anchors::default(); n];
    if n == 1 {
        let a = &lp.areas[seq[0]];
        let r = &a.region;
        if let (Some(&s1), Some(&l), Some(&rr)) = (r.s.last(), r.left.last(), r.right.last()) {
            let (entry, exit) = if a.level % 2 == 1 { (l, rr) } else { (rr, l) };
            out[0] = Anchors {
                entry: Some([s1, entry]),
                exit: Some([s1, exit]),
            };
        }
        return out;
    }
    for k in 0..n {
        let step = lp.areas[seq[k]].step;
        let before = (k > 0)
            .then(|| junction(&outlines[k], &outlines[k - 1], step))
            .flatten();
        let after = (k + 1 < n)
            .then(|| junction(&outlines[k], &outlines[k + 1], step))
            .flatten();
        out[k] = Anchors {
            entry: before.or_else(|| after.and_then(|j| far(&outlines[k], j))),
            exit: after.or_else(|| before.and_then(|j| far(&outlines[k], j))),
        };
    }
    out
}

/// The closed outline of a lane in the developed plane.
fn outline(area: &AreaPlan) -> Path2 {
    let r = &area.region;
    let mut o: Path2 = r.s.iter().zip(&r.left).map(|(&s, &y)| [s, y]).collect();
    o.extend(r.s.iter().zip(&r.right).rev().map(|(&s, &y)| [s, y]));
    o.extend(o.first().copied());
    o
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
