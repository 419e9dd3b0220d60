//! The machining order of one section: row segments fed by lean, their entries (lead-in,
//! cleared, pilot), and the W walk of the plunges that still interfere — with the centre
//! interference of every plunge kept current while the plan changes.
//!
//! # Steps
//! 1. Rows in order (suction side first); each row's segments ([`crate::feed::segments_by_lean`])
//!    in station order, each fed toward where its axes lean.
//! 2. Entries, in that order, measured against the stock minus the plunges planned so far,
//!    the pilot holes and a declared cleared region ([`crate::interference::travel_after`]):
//!    an entry that would *drill* — run its centre more than
//!    [`crate::axis_optimisation::WALK_GIVE_UP_MM`] through material — gets a pilot hole with
//!    `entry = "pilot"`; with the other modes its segment is fed from its other end if that
//!    end does not drill (against its lean), else it stays as it is. Other entries are
//!    lead-in (their centre's stroke meets no stock) or cleared entries.
//! 3. Every plunge's travel is measured (in parallel). Then, in machining order, the first
//!    plunge whose travel exceeds [`PLAN_TRAVEL_TARGET_MM`] is corrected: by the smallest
//!    admissible W walk that brings it within the target
//!    ([`crate::axis_optimisation::walk`]); failing that, with `entry = "pilot"`, by a pilot
//!    hole along its axis; otherwise it stays (an unhandled entry, or a kept plunge). After
//!    each change only the later plunges it can affect ([`crate::interference::may_affect`],
//!    old and new stroke) are measured again, so the travels always describe the current
//!    plan. A plunge is corrected at most once, and corrections go forward in machining
//!    order (a change affects only later plunges), so the loop ends.
//!
//! The result is the plan with its per-plunge travels in machining order, measured on the
//! final plan.
//!
//! Cost: one travel measurement per plunge, plus per correction O(log moved steps + W travel
//! / stride) travel measurements of the walked plunge and one of each plunge it can affect.

use crate::axis_optimisation::{fit_w_curve, walk, Verdict, WCurve, WalkGoal, WALK_GIVE_UP_MM};
use crate::conventional_axes::{Posture, PostureBuilder};
use crate::entries::{pilot_stroke, EntryKind, EntryMode};
use crate::feed::{segments_by_lean, Segment};
use crate::interference::{may_affect, travel_after, Material, Stroke, INTERFERENCE_TRAVEL_TOL_MM};
use cam_plan::PlanError;
use rayon::prelude::*;

/// The travel (mm) the plan aims every plunge at: half the interference tolerance
/// ([`INTERFERENCE_TRAVEL_TOL_MM`]), so that what the measure's sampling can miss between its
/// rim samples (at most 0.005 mm, [`crate::interference::RIM_SAMPLE_SPACING_MM`]) stays
/// within the tolerance.
pub const PLAN_TRAVEL_TARGET_MM: f64 = 0.5 * INTERFERENCE_TRAVEL_TOL_MM;

/// One segment as planned.
#[derive(Debug, Clone)]
pub struct PlannedSegment {
    /// Row, stations in feed order, feed direction.
    pub segment: Segment,
    /// Final postures in feed order.
    pub postures: Vec<Posture>,
    /// How its first plunge gets in.
    pub entry: EntryKind,
    /// Discrete W steps each plunge was walked and whether toward the feed (`None`:
    /// conventional axis).
    pub walked: Vec<Option<(usize, bool)>>,
}

/// The plan of one section.
#[derive(Debug, Clone)]
pub struct FeedPlan {
    /// Segments in machining order.
    pub segments: Vec<PlannedSegment>,
    /// Postures a pilot hole is drilled for (entries, and plunges no admissible W clears),
    /// in drilling order.
    pub pilots: Vec<Posture>,
    /// How many of the pilots are for plunges other than entries.
    pub interior_pilots: usize,
    /// Centre travel through material of every plunge, machining order (mm).
    pub travel: Vec<f64>,
    /// Plunges other than entries that interfere, found no admissible clean W and got no
    /// pilot (modes other than `pilot`).
    pub kept: usize,
}

impl FeedPlan {
    /// The final postures per row in station order (outlet → inlet), with each plunge's
    /// feed direction.
    pub fn rows(&self, rows: usize) -> Vec<Vec<(usize, Posture, crate::feed::Feed)>> {
        let mut out: Vec<Vec<(usize, Posture, crate::feed::Feed)>> = vec![Vec::new(); rows];
        for s in &self.segments {
            for (k, p) in s.segment.stations.iter().zip(&s.postures) {
                if let Some(r) = out.get_mut(s.segment.row) {
                    r.push((*k, *p, s.segment.feed));
                }
            }
        }
        for r in &mut out {
            r.sort_by_key(|e| e.0);
        }
        out
    }
}

/// What the feed plan needs.
pub struct FeedInput<'a> {
    /// Conventional postures per row, station order (outlet → inlet).
    pub rows: &'a [Vec<Posture>],
    /// Cutter radius (mm).
    pub radius: f64,
    /// Non-cutting centre disk radius (mm).
    pub core: f64,
    /// The section's entry mode.
    pub mode: EntryMode,
    /// Pilot drill radius (pilot mode).
    pub pilot_radius: Option<f64>,
    /// Stock and cleared region the strokes run through (no pilot holes: they are added
    /// here).
    pub material: Material<'a>,
    /// Walk interfering plunges' W (paper 000 §3).
    pub optimise: bool,
    /// W-curve parameter step.
    pub w_step: f64,
    /// Posture builder of the section's tool.
    pub builder: &'a PostureBuilder<'a>,
    /// Whether a moved posture keeps the blade allowance and the stock clearance.
    pub admissible: &'a (dyn Fn(&Posture) -> bool + Sync),
    /// Operation name (errors).
    pub operation: &'a str,
}

impl std::fmt::Debug for FeedInput<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FeedInput")
            .field("rows", &self.rows.len())
            .field("radius", &self.radius)
            .field("core", &self.core)
            .field("mode", &self.mode)
            .field("pilot_radius", &self.pilot_radius)
            .field("optimise", &self.optimise)
            .field("w_step", &self.w_step)
            .field("operation", &self.operation)
            .finish_non_exhaustive()
    }
}

/// The stroke of one plunge of a cutter of radius `radius` with centre disk `core`.
pub fn stroke(p: &Posture, radius: f64, core: f64) -> Stroke {
    Stroke {
        start: p.start.tip,
        end: p.cl.tip,
        axis: p.cl.axis.into_inner(),
        radius,
        core_radius: core,
    }
}

/// One plunge of the plan, flattened: its segment, its place in it, and its stroke.
#[derive(Debug, Clone, Copy)]
struct Slot {
    segment: usize,
    index: usize,
}

/// Plans the section's machining order (see the module docs).
pub fn plan_feed(input: &FeedInput<'_>) -> Result<FeedPlan, PlanError> {
    let (radius, core) = (input.radius, input.core);
    let tol = PLAN_TRAVEL_TARGET_MM;
    let mut segments: Vec<PlannedSegment> = Vec::new();
    let mut done: Vec<Stroke> = Vec::new();
    let mut pilots: Vec<Posture> = Vec::new();
    let mut pilot_strokes: Vec<Stroke> = Vec::new();
    let pilot_of = |p: &Posture| -> Result<Stroke, PlanError> {
        let r = input.pilot_radius.ok_or_else(|| {
            PlanError::param(
                input.operation,
                "pilot",
                "a plunge needs a pilot hole and no pilot drill was given to plan with (name it \
                 in [pilot] and plan with Operation::plan_with_steps), or choose entry = \
                 \"lead_in\" or \"cleared\"",
            )
        })?;
        Ok(pilot_stroke(p, r))
    };
    // Steps 1–2: segments and entries in machining order.
    for (j, row) in input.rows.iter().enumerate() {
        for seg in segments_by_lean(j, row) {
            let material = Material {
                drilled: &pilot_strokes,
                ..input.material
            };
            let entry_travel = |s: &Segment| {
                travel_after(&stroke(&row[s.stations[0]], radius, core), &done, &material)
            };
            let through_stock = |s: &Segment| {
                travel_after(
                    &stroke(&row[s.stations[0]], radius, core),
                    &[],
                    &Material::stock(input.material.stock),
                )
            };
            let classify = |s: &Segment| {
                if through_stock(s) <= tol {
                    EntryKind::LeadIn
                } else {
                    EntryKind::Cleared
                }
            };
            // An entry that would drill (more than WALK_GIVE_UP_MM through material) gets its
            // pilot now; one that only touches a leftover is left to the corrections below.
            let drills = |t: f64| t > WALK_GIVE_UP_MM;
            let (seg, kind) = if !drills(entry_travel(&seg)) {
                let k = classify(&seg);
                (seg, k)
            } else if input.mode == EntryMode::Pilot {
                let p = row[seg.stations[0]];
                pilot_strokes.push(pilot_of(&p)?);
                pilots.push(p);
                (seg, EntryKind::Pilot)
            } else {
                let other = seg.reversed();
                if other.stations.len() > 1 && !drills(entry_travel(&other)) {
                    let k = classify(&other);
                    (other, k)
                } else {
                    (seg, EntryKind::Unhandled)
                }
            };
            let postures: Vec<Posture> = seg.stations.iter().map(|&k| row[k]).collect();
            done.extend(postures.iter().map(|p| stroke(p, radius, core)));
            segments.push(PlannedSegment {
                walked: vec![None; postures.len()],
                segment: seg,
                postures,
                entry: kind,
            });
        }
    }
    let slots: Vec<Slot> = segments
        .iter()
        .enumerate()
        .flat_map(|(s, seg)| {
            (0..seg.postures.len()).map(move |i| Slot {
                segment: s,
                index: i,
            })
        })
        .collect();
    // Step 3: every travel, then the corrections in machining order.
    let measure = |k: usize, done: &[Stroke], pilots: &[Stroke]| {
        let material = Material {
            drilled: pilots,
            ..input.material
        };
        travel_after(&done[k], &done[..k], &material)
    };
    let mut travel: Vec<f64> = (0..done.len())
        .into_par_iter()
        .map(|k| measure(k, &done, &pilot_strokes))
        .collect();
    let curves: Vec<Option<WCurve>> = if input.optimise {
        input
            .rows
            .iter()
            .map(|r| fit_w_curve(r, input.w_step, input.operation))
            .collect::<Result<_, _>>()?
    } else {
        vec![None; input.rows.len()]
    };
    let mut tried = vec![false; done.len()];
    let mut kept = 0;
    let mut interior_pilots = 0;
    while let Some(k) = (0..done.len()).find(|&k| travel[k] > tol && !tried[k]) {
        tried[k] = true;
        let Slot { segment, index } = slots[k];
        let seg = &segments[segment];
        let p = seg.postures[index];
        let station = seg.segment.stations[index];
        let row = seg.segment.row;
        // W may travel the cutting-edge length beyond the previous plunge's W (an entry's
        // own): further, the centre leaves the previous hole whatever the axis.
        let reach = (radius - core)
            + if index > 0 {
                (p.w - seg.postures[index - 1].w).norm()
            } else {
                0.0
            };
        let feed = seg.segment.feed;
        let walked = curves.get(row).and_then(Option::as_ref).and_then(|curve| {
            let judge = |q: &Posture| {
                if !(input.admissible)(q) {
                    return Verdict::Inadmissible;
                }
                let material = Material {
                    drilled: &pilot_strokes,
                    ..input.material
                };
                Verdict::Travel(travel_after(
                    &stroke(q, radius, core),
                    &done[..k],
                    &material,
                ))
            };
            let goal = WalkGoal {
                reach_mm: reach,
                tol,
            };
            walk(input.builder, curve, &p, station, feed, goal, &judge)
        });
        let changed: Vec<Stroke> = match walked {
            Some(w) => {
                let old = done[k];
                segments[segment].postures[index] = w.posture;
                segments[segment].walked[index] = Some((w.steps, w.toward_feed));
                done[k] = stroke(&w.posture, radius, core);
                // The old stroke's removal is gone: what it could affect is re-measured too.
                vec![old, done[k]]
            }
            None if input.mode == EntryMode::Pilot => {
                // No admissible axis clears it: a pilot hole along its own axis does.
                let pilot = pilot_of(&p)?;
                pilot_strokes.push(pilot);
                pilots.push(p);
                if index == 0 {
                    segments[segment].entry = EntryKind::Pilot;
                } else {
                    interior_pilots += 1;
                }
                vec![pilot]
            }
            None => {
                if index == 0 {
                    segments[segment].entry = EntryKind::Unhandled;
                } else {
                    kept += 1;
                }
                continue;
            }
        };
        let later: Vec<usize> = (k..done.len())
            .filter(|&j| changed.iter().any(|c| may_affect(&done[j], c)))
            .collect();
        let again: Vec<(usize, f64)> = later
            .par_iter()
            .map(|&j| (j, measure(j, &done, &pilot_strokes)))
            .collect();
        for (j, t) in again {
            travel[j] = t;
        }
    }
    Ok(FeedPlan {
        segments,
        pilots,
        interior_pilots,
        travel,
        kept,
    })
}
