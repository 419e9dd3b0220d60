//! The verification driver: sweep every operation through the stock, collect collisions, then
//! measure overcut and residual over the design surfaces.
//!
//! Each move is sampled at the positions of [`crate::motion::positions_for_move`] (sweep
//! tolerance default `h/4` for cell `h`), except that runs of feed blocks that stay within a
//! quarter of that tolerance of one straight chord get positions spaced along the run as a
//! whole, on the actual motion ([`crate::merge`]: the swept volume is under-read by at most
//! the tolerance either way, never over-read);
//! positions are applied in batches with
//! [`crate::removal::apply_batch`] (parallel over ray rows, exact sequential semantics, rays
//! culled where provably untouched), and each batch's shank/holder placements are checked
//! against the design mesh in parallel over contiguous chunks, skipping the pieces whose
//! cached clearance proves them clear ([`crate::collision::DesignCollider::check_cached`],
//! same result as the full check). A rapid move never cuts; any contact of the tool with material
//! during a rapid is a collision. The first move of a tool path is a single position.

use crate::collision::{ClearanceCache, DesignCollider, PartShapes};
use crate::design::DesignModel;
use crate::dexel::TriDexel;
use crate::endpoints::overcut_error_bound;
use crate::error::SimError;
use crate::measure::{extremum, measure, measure_residual, Extremum, SurfaceMap};
use crate::merge::{run_step, CuttingReach, Run};
use crate::motion::{
    has_flat_face, positions_for_move, positions_for_samples, scallop_radius, sub_positions,
    Interpolation,
};
use crate::removal::{apply_batch, PartKind, Placement, ToolBody};
use cam_core::{Cutter, MoveKind, ToolPath};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Instant;

/// Positions per sequential chunk of the design collision checks (chunks run in parallel;
/// inside a chunk the clearance caches carry over from position to position).
const DESIGN_CHUNK: usize = 256;

/// Options of [`simulate`] / [`cut`].
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// Largest swept-volume error between sampled positions (mm); default: cell / 4.
    pub sweep_tol_mm: Option<f64>,
    /// How the controller moves between cutter locations.
    pub interpolation: Interpolation,
    /// Check shank/holder against stock and design (rapids are always checked).
    pub check_collisions: bool,
    /// Material overlap (mm, along a ray) below which a contact is not reported; default:
    /// twice the sweep tolerance (the scallops left between sampled positions).
    pub collision_tol_mm: Option<f64>,
    /// Largest thickness measured by the overcut/residual probes (mm).
    pub probe_depth_mm: f64,
    /// Positions per batch.
    pub batch_positions: usize,
    /// Space the positions of runs of short feed blocks along the run as a whole when the
    /// run stays within a quarter of the sweep tolerance of one straight chord
    /// ([`crate::merge`]); the under-read bound is unchanged and nothing is over-read.
    pub merge_blocks: bool,
    /// Print progress on stderr (lines every 2 s; see also `on_progress`).
    pub progress: bool,
    /// Called after every batch of positions and when the measurement starts, instead of
    /// the stderr lines (e.g. to drive a progress bar).
    pub on_progress: Option<ProgressSink>,
}

/// Where the simulation is (see [`SimOptions::on_progress`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimProgress<'a> {
    /// Removing material: moves simulated so far (of all operations) and the operation.
    Cutting {
        /// Operation name.
        operation: &'a str,
        /// Moves done (all operations).
        done_moves: usize,
        /// Moves in all operations.
        total_moves: usize,
    },
    /// Measuring overcut and residual over the design surfaces.
    Measuring,
}

/// A progress callback of the simulation.
#[derive(Clone)]
pub struct ProgressSink(pub std::sync::Arc<dyn Fn(SimProgress<'_>) + Send + Sync>);

impl std::fmt::Debug for ProgressSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressSink(..)")
    }
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            sweep_tol_mm: None,
            interpolation: Interpolation::Tcp,
            check_collisions: true,
            collision_tol_mm: None,
            probe_depth_mm: 3.0,
            batch_positions: 4096,
            merge_blocks: true,
            progress: false,
            on_progress: None,
        }
    }
}

/// The verification metrics with the names fixed by DESIGN.md §4.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Largest overcut over all design samples (mm).
    pub max_overcut_mm: f64,
    /// Largest residual over all design samples (mm).
    pub max_residual_mm: f64,
    /// Number of moves with at least one collision.
    pub collisions: usize,
    /// How much `max_overcut_mm` may under-read the true overcut (mm): ray spacing against
    /// the cutter curvature plus the sweep tolerance
    /// ([`crate::endpoints::overcut_error_bound`]) plus the design model's stated error
    /// ([`crate::DesignModel::model_error_mm`]).
    pub overcut_error_bound_mm: f64,
}

/// What a colliding part hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CollisionTarget {
    /// The in-process stock.
    Stock,
    /// The design part.
    Design,
}

/// A collision of one part during one move (deepest contact over the move's positions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Collision {
    /// Operation (tool path) name.
    pub operation: String,
    /// Move index within the tool path.
    pub move_index: usize,
    /// Kind of the move.
    pub move_kind: MoveKind,
    /// Part of the tool.
    pub part: PartKind,
    /// What it hit.
    pub target: CollisionTarget,
    /// Depth (mm): longest material overlap along a dexel ray (stock) or parry's
    /// penetration depth (design).
    pub depth_mm: f64,
    /// Where (mm).
    pub point: [f64; 3],
}

/// Counters and timings.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SimStats {
    /// Moves simulated.
    pub moves: usize,
    /// Cutter positions applied.
    pub positions: usize,
    /// Dexel cell size (mm).
    pub resolution_mm: f64,
    /// Sweep tolerance used (mm).
    pub sweep_tol_mm: f64,
    /// Rays in the three grids.
    pub rays: usize,
    /// Stock memory after the simulation (bytes).
    pub stock_memory_bytes: usize,
    /// Material removed (mm³).
    pub removed_volume_mm3: f64,
    /// Material removed by each operation, in program order (mm³; the three grids' mean,
    /// as `removed_volume_mm3`). A finishing operation that removes far more than its
    /// allowance band holds is cutting material an earlier operation should have taken (a
    /// finishing ball slotting through an unroughed channel touches no shank or holder and
    /// is no collision): the figure a programmer compares.
    pub removed_volume_by_operation_mm3: Vec<f64>,
    /// Wall-clock time of the removal and stock collision checks (ms).
    pub removal_ms: f64,
    /// Wall-clock time of the design collision checks (ms).
    pub design_collision_ms: f64,
    /// Wall-clock time of the overcut/residual measurement (ms).
    pub measure_ms: f64,
    /// Cut dexel end points found inside the design (each an exact overcut reading).
    pub endpoints_inside_design: usize,
}

/// Outcome of sweeping the tool paths through the stock.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CutOutcome {
    /// Collisions, sorted by operation, move, part.
    pub collisions: Vec<Collision>,
    /// Counters.
    pub stats: SimStats,
}

/// Full verification report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// DESIGN metric names.
    pub metrics: Metrics,
    /// Where the largest overcut is.
    pub max_overcut: Option<Extremum>,
    /// Where the largest residual is.
    pub max_residual: Option<Extremum>,
    /// Collisions per move.
    pub collisions: Vec<Collision>,
    /// Counters and timings.
    pub stats: SimStats,
    /// Per-surface maps.
    pub maps: Vec<SurfaceMap>,
}

type Key = (usize, usize, PartKind, CollisionTarget);

struct Acc {
    map: BTreeMap<Key, (f64, [f64; 3])>,
}

impl Acc {
    fn add(&mut self, key: Key, depth: f64, point: [f64; 3]) {
        let e = self.map.entry(key).or_insert((f64::NEG_INFINITY, point));
        if depth > e.0 {
            *e = (depth, point);
        }
    }
}

/// Sweeps the tool paths through the stock (and checks the design mesh for shank/holder
/// collisions when `design` is given). Each operation is a cutter with its tool path.
pub fn cut(
    stock: &mut TriDexel,
    design: Option<&dyn DesignModel>,
    ops: &[(Cutter, ToolPath)],
    options: &SimOptions,
) -> Result<CutOutcome, SimError> {
    let cell = stock.cell();
    let tol = options.sweep_tol_mm.unwrap_or(cell / 4.0);
    if !(tol.is_finite() && tol > 0.0) {
        return Err(SimError::InvalidOption {
            name: "sweep_tol_mm",
            value: tol,
            reason: "must be finite and > 0",
        });
    }
    let ctol = options.collision_tol_mm.unwrap_or(2.0 * tol);
    if !(ctol.is_finite() && ctol >= 0.0) {
        return Err(SimError::InvalidOption {
            name: "collision_tol_mm",
            value: ctol,
            reason: "must be finite and >= 0",
        });
    }
    let mut bodies = Vec::with_capacity(ops.len());
    for (cutter, path) in ops {
        cutter
            .validate()
            .map_err(|source| SimError::InvalidCutter {
                operation: path.name.clone(),
                source,
            })?;
        bodies.push(ToolBody::new(cutter));
    }
    let collider = match design {
        Some(d) if options.check_collisions => Some(DesignCollider::new(&d.triangle_mesh())?),
        _ => None,
    };
    let shapes: Vec<(PartShapes, PartShapes)> = bodies
        .iter()
        .map(|b| (PartShapes::new(b, false), PartShapes::new(b, true)))
        .collect();

    let mut acc = Acc {
        map: BTreeMap::new(),
    };
    let mut stats = SimStats {
        resolution_mm: cell,
        sweep_tol_mm: tol,
        rays: stock.ray_count(),
        removed_volume_by_operation_mm3: vec![0.0; ops.len()],
        ..SimStats::default()
    };
    let cap = options.batch_positions.max(1);
    let mut batch: Vec<Placement> = Vec::with_capacity(cap);
    let mut meta: Vec<(usize, usize)> = Vec::with_capacity(cap);
    let total_moves: usize = ops.iter().map(|(_, p)| p.moves.len()).sum();
    let mut last_report = Instant::now();
    let start = Instant::now();
    let mut design_ms = 0.0;

    let flush = |batch: &mut Vec<Placement>,
                 meta: &mut Vec<(usize, usize)>,
                 stock: &mut TriDexel,
                 acc: &mut Acc,
                 stats: &mut SimStats,
                 design_ms: &mut f64| {
        if batch.is_empty() {
            return;
        }
        let out = apply_batch(stock, &bodies, batch, options.check_collisions, ctol);
        stats.removed_volume_mm3 += out.removed_volume;
        // Every batch holds one operation's positions (flushed at each operation's end).
        if let Some(&(op, _)) = meta.first() {
            if let Some(v) = stats.removed_volume_by_operation_mm3.get_mut(op) {
                *v += out.removed_volume;
            }
        }
        stats.positions += batch.len();
        for h in out.hits {
            let (op, mv) = meta[h.placement];
            acc.add((op, mv, h.part, CollisionTarget::Stock), h.depth, h.point);
        }
        if let (Some(collider), Some(design)) = (&collider, design) {
            let t = Instant::now();
            // Contiguous chunks in parallel, positions in order inside a chunk so that the
            // clearance caches can skip pieces proven clear (exact, see `check_cached`).
            let hits: Vec<(usize, crate::collision::DesignHit)> = batch
                .par_chunks(DESIGN_CHUNK)
                .enumerate()
                .flat_map_iter(|(c, chunk)| {
                    let mut caches = vec![ClearanceCache::new(); 2 * shapes.len()];
                    let mut found = Vec::new();
                    for (k, pl) in chunk.iter().enumerate() {
                        let (parts, slot) = if pl.rapid {
                            (&shapes[pl.tool].1, 2 * pl.tool + 1)
                        } else {
                            (&shapes[pl.tool].0, 2 * pl.tool)
                        };
                        let Some(cache) = caches.get_mut(slot) else {
                            continue;
                        };
                        for h in collider.check_cached(design, parts, &pl.tip, &pl.axis, cache) {
                            found.push((c * DESIGN_CHUNK + k, h));
                        }
                    }
                    found
                })
                .collect();
            for (k, h) in hits {
                let (op, mv) = meta[k];
                acc.add((op, mv, h.part, CollisionTarget::Design), h.depth, h.point);
            }
            *design_ms += t.elapsed().as_secs_f64() * 1e3;
        }
        batch.clear();
        meta.clear();
    };

    let mut done_moves = 0usize;
    // Deviation budget of a run of blocks sampled as a whole (`merge`: the rest of the
    // tolerance spaces its positions).
    let budget = if options.merge_blocks {
        0.25 * tol
    } else {
        -1.0
    };
    // The points of a block the run measures: those `positions_for_move` measures too (so
    // a one-block run reuses them), at least the middle and the end.
    let sub = sub_positions(&options.interpolation).max(2);
    let mut run = Run::default();
    let mut samples: Vec<cam_core::CutterLocation> = Vec::with_capacity(sub);
    for (oi, (cutter, path)) in ops.iter().enumerate() {
        let reach = CuttingReach::of(cutter);
        let budget = if has_flat_face(&cutter.shape) {
            -1.0
        } else {
            budget
        };
        // Positions of the pending run of blocks (one block: its own positions, as the
        // controller moves; several: spaced along the run, on the motion).
        let emit = |run: &mut Run, batch: &mut Vec<Placement>, meta: &mut Vec<(usize, usize)>| {
            match (run.start, run.blocks.as_slice()) {
                (Some(from), &[(mi, _, cl, _)]) => {
                    let n = if run.samples().len() == sub_positions(&options.interpolation) {
                        positions_for_samples(cutter, &from, &cl, run.samples(), tol)
                    } else {
                        positions_for_move(cutter, &options.interpolation, oi, mi, &from, &cl, tol)
                    };
                    push_move(
                        batch,
                        meta,
                        &options.interpolation,
                        (oi, mi),
                        (&from, &cl),
                        n,
                        false,
                    );
                }
                (Some(_), [.., (_, _, end, _)]) => {
                    let step = run_step(scallop_radius(&cutter.shape), tol, run.deviation_mm)
                        .unwrap_or(f64::INFINITY)
                        .max(1e-9);
                    let n = ((run.displacement_mm() / step).ceil() as usize).clamp(1, 1_000_000);
                    let end = *end;
                    for (mi, a, b, f) in run.positions(n) {
                        let c = if f >= 1.0 {
                            b
                        } else {
                            options.interpolation.at(oi, mi, &a, &b, f)
                        };
                        batch.push(placement(&c, oi, false));
                        meta.push((oi, mi));
                    }
                    debug_assert!(batch
                        .last()
                        .is_some_and(|p| p.tip == [end.tip.x, end.tip.y, end.tip.z]));
                }
                _ => {}
            }
            run.clear();
        };
        for (mi, mv) in path.moves.iter().enumerate() {
            let cl = mv.cl;
            let finite =
                cl.tip.iter().all(|x| x.is_finite()) && cl.axis.iter().all(|x| x.is_finite());
            if !finite {
                return Err(SimError::NonFiniteMove {
                    operation: path.name.clone(),
                    index: mi,
                });
            }
            let rapid = mv.kind == MoveKind::Rapid;
            if mi == 0 {
                emit(&mut run, &mut batch, &mut meta);
                batch.push(placement(&cl, oi, rapid));
                meta.push((oi, mi));
            } else {
                let from = path.moves[mi - 1].cl;
                if rapid {
                    emit(&mut run, &mut batch, &mut meta);
                    let n =
                        positions_for_move(cutter, &options.interpolation, oi, mi, &from, &cl, tol);
                    push_move(
                        &mut batch,
                        &mut meta,
                        &options.interpolation,
                        (oi, mi),
                        (&from, &cl),
                        n,
                        true,
                    );
                } else {
                    samples.clear();
                    samples.extend((1..=sub).map(|k| {
                        options
                            .interpolation
                            .at(oi, mi, &from, &cl, k as f64 / sub as f64)
                    }));
                    if !run.try_extend(&reach, mi, cl, &samples, budget) {
                        emit(&mut run, &mut batch, &mut meta);
                        run.begin(&reach, from, mi, cl, &samples);
                    }
                }
            }
            done_moves += 1;
            if batch.len() >= cap {
                flush(
                    &mut batch,
                    &mut meta,
                    stock,
                    &mut acc,
                    &mut stats,
                    &mut design_ms,
                );
                if let Some(sink) = &options.on_progress {
                    (sink.0)(SimProgress::Cutting {
                        operation: &path.name,
                        done_moves,
                        total_moves,
                    });
                } else if options.progress && last_report.elapsed().as_secs_f64() > 2.0 {
                    eprintln!(
                        "verify: {}: {done_moves}/{total_moves} moves, {} positions, {:.1} s",
                        path.name,
                        stats.positions,
                        start.elapsed().as_secs_f64()
                    );
                    last_report = Instant::now();
                }
            }
        }
        emit(&mut run, &mut batch, &mut meta);
        // The operation's last positions: batches never mix operations, so each one's removed
        // volume is its own (the removal does not depend on where batches end); nothing is
        // left for after the last operation.
        flush(
            &mut batch,
            &mut meta,
            stock,
            &mut acc,
            &mut stats,
            &mut design_ms,
        );
    }
    if let (Some(sink), Some((_, last))) = (&options.on_progress, ops.last()) {
        (sink.0)(SimProgress::Cutting {
            operation: &last.name,
            done_moves,
            total_moves,
        });
    }
    stats.moves = done_moves;
    stats.removal_ms = start.elapsed().as_secs_f64() * 1e3 - design_ms;
    stats.design_collision_ms = design_ms;
    stats.stock_memory_bytes = stock.memory_bytes();

    let collisions = acc
        .map
        .into_iter()
        .map(|((op, mv, part, target), (depth, point))| Collision {
            operation: ops[op].1.name.clone(),
            move_index: mv,
            move_kind: ops[op].1.moves[mv].kind,
            part,
            target,
            depth_mm: depth,
            point,
        })
        .collect();
    Ok(CutOutcome { collisions, stats })
}

/// The placement of tool `tool` at `c`.
fn placement(c: &cam_core::CutterLocation, tool: usize, rapid: bool) -> Placement {
    Placement {
        tip: [c.tip.x, c.tip.y, c.tip.z],
        axis: [c.axis.x, c.axis.y, c.axis.z],
        tool,
        rapid,
    }
}

/// The `n` positions of move `mi` of operation `oi` from `from` to `to` as the controller
/// moves (fractions `k/n`, the last exactly `to`), with their (operation, move) labels.
fn push_move(
    batch: &mut Vec<Placement>,
    meta: &mut Vec<(usize, usize)>,
    interp: &Interpolation,
    (oi, mi): (usize, usize),
    (from, to): (&cam_core::CutterLocation, &cam_core::CutterLocation),
    n: usize,
    rapid: bool,
) {
    for k in 1..=n {
        let c = if k == n {
            *to
        } else {
            interp.at(oi, mi, from, to, k as f64 / n as f64)
        };
        batch.push(placement(&c, oi, rapid));
        meta.push((oi, mi));
    }
}

/// Number of distinct (operation, move) pairs with a collision.
pub fn colliding_moves(collisions: &[Collision]) -> usize {
    let mut keys: Vec<(&str, usize)> = collisions
        .iter()
        .map(|c| (c.operation.as_str(), c.move_index))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    keys.len()
}

/// Refuses a probe depth that is not finite and positive.
fn check_probe_depth(options: &SimOptions) -> Result<(), SimError> {
    if options.probe_depth_mm.is_finite() && options.probe_depth_mm > 0.0 {
        return Ok(());
    }
    Err(SimError::InvalidOption {
        name: "probe_depth_mm",
        value: options.probe_depth_mm,
        reason: "must be finite and > 0",
    })
}

/// The material the tool paths leave: sweeps them through `stock` (modified in place to the
/// final stock) and measures the residual over the design's surface samples
/// ([`crate::measure::measure_residual`]); no overcut is read and no collision is reported
/// (shank and holder are not checked against the design, the removal's checks of rapids
/// against the stock are dropped: callers that need a verdict use [`simulate`]). The
/// removal is [`simulate`]'s, so the final stock and the residual maps are bit for bit
/// those of [`simulate`] with the same options; what it saves is the overcut reading (one
/// design evaluation per cut dexel end point), the collision checks and the copy of the
/// blank. What a rest operation plans from.
pub fn simulate_residual(
    stock: &mut TriDexel,
    design: &dyn DesignModel,
    ops: &[(Cutter, ToolPath)],
    options: &SimOptions,
) -> Result<Vec<SurfaceMap>, SimError> {
    check_probe_depth(options)?;
    let options = SimOptions {
        check_collisions: false,
        ..options.clone()
    };
    cut(stock, None, ops, &options)?;
    if let Some(sink) = &options.on_progress {
        (sink.0)(SimProgress::Measuring);
    }
    let grids = design.surface_grids();
    Ok(measure_residual(
        stock,
        design,
        &grids,
        options.probe_depth_mm,
    ))
}

/// Verifies tool paths against a design: sweeps them through `stock` (modified in place to
/// the final stock), checks collisions, and measures overcut and residual maps over the
/// design's surface samples. A copy of the initial stock is kept for the measurement
/// (memory ×2 during `simulate`).
pub fn simulate(
    stock: &mut TriDexel,
    design: &dyn DesignModel,
    ops: &[(Cutter, ToolPath)],
    options: &SimOptions,
) -> Result<Report, SimError> {
    check_probe_depth(options)?;
    let initial = stock.clone();
    let outcome = cut(stock, Some(design), ops, options)?;
    let t = Instant::now();
    if let Some(sink) = &options.on_progress {
        (sink.0)(SimProgress::Measuring);
    } else if options.progress {
        eprintln!("verify: measuring overcut and residual over the design surfaces");
    }
    let grids = design.surface_grids();
    let measured = measure(stock, &initial, design, &grids, options.probe_depth_mm);
    let maps = measured.maps;
    let probed = extremum(&maps, false, options.probe_depth_mm);
    let max_overcut = match (probed, measured.deepest_endpoint) {
        (Some(p), Some(e)) => Some(if e.value_mm >= p.value_mm { e } else { p }),
        (p, e) => e.or(p),
    };
    let max_residual = extremum(&maps, true, options.probe_depth_mm);
    let mut stats = outcome.stats;
    stats.measure_ms = t.elapsed().as_secs_f64() * 1e3;
    stats.endpoints_inside_design = measured.endpoints_inside;
    let metrics = Metrics {
        max_overcut_mm: max_overcut.as_ref().map_or(0.0, |e| e.value_mm),
        max_residual_mm: max_residual.as_ref().map_or(0.0, |e| e.value_mm),
        collisions: colliding_moves(&outcome.collisions),
        overcut_error_bound_mm: overcut_error_bound(
            stats.resolution_mm,
            stats.sweep_tol_mm,
            ops.iter().map(|(c, _)| c),
        ) + design.model_error_mm(),
    };
    Ok(Report {
        metrics,
        max_overcut,
        max_residual,
        collisions: outcome.collisions,
        stats,
        maps,
    })
}
