//! `report.json` (fixed metric names, read by regressions and dashboards) and `report.html`
//! (the same figures for a person, with inline SVG plots).

use crate::error::CliError;
use crate::pipeline::JobOperation;
use crate::plot::{heat_map, human_label, line_chart, Scale, Series};
use cam_core::MoveKind;
use cam_plan::{PlotKind, PlotSeries};
use impeller_model::{Impeller, Side};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// One operation's figures (DESIGN §4: `moves`, `path_length_mm`, `cutting_time_s`,
/// `plan_ms`) and the kind's own metrics, flattened into the same JSON object so that
/// `cargo xtask regress` reads `operations.<name>.<metric>`.
#[derive(Debug, Clone, Serialize)]
pub struct OperationReport {
    /// Operation name.
    pub name: String,
    /// Operation kind (`cl_import` for CL data read from a file).
    pub kind: String,
    /// Tool name.
    pub tool: String,
    /// Number of moves.
    pub moves: usize,
    /// Tool-tip travel, rapids included (mm).
    pub path_length_mm: f64,
    /// Estimated machining time (s).
    pub cutting_time_s: f64,
    /// Planning time (ms).
    pub plan_ms: f64,
    /// The kind's own metrics (names of DESIGN §4; numbers, counts, booleans, texts).
    #[serde(flatten)]
    pub metrics: cam_plan::Metrics,
}

/// Post-processing figures summed over the operations.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PostReport {
    /// Machine name.
    pub machine: String,
    /// Dialect name.
    pub dialect: String,
    /// Program file written (empty when there was nothing to post).
    pub program: String,
    /// Whether a program was written.
    pub written: bool,
    /// NC blocks.
    pub blocks: usize,
    /// Rotary direction reversals before smoothing.
    pub reverse_motions_before: usize,
    /// Rotary direction reversals after smoothing.
    pub reverse_motions_after: usize,
    /// Of `reverse_motions_before`, the reversals inside a cut (what paper 004 removes;
    /// [`postproc_kinematics::rotary_motion`]).
    pub reverse_motions_cutting_before: usize,
    /// Of `reverse_motions_after`, the reversals inside a cut.
    pub reverse_motions_cutting_after: usize,
    /// Of `reverse_motions_cutting_after`, the reversals of C within 1° of the pole, where the
    /// tool axis no longer determines C ([`postproc_kinematics::rotary_motion`]).
    #[serde(default)]
    pub reverse_motions_cutting_near_pole: usize,
    /// Summed over the operations: the reversals inside cuts that neither lie at the pole nor
    /// are covered by the count of direction changes the operation's planner kept with a
    /// reason ([`PostOperationReport::reverse_motions_cutting_unaccounted`]).
    #[serde(default)]
    pub reverse_motions_cutting_unaccounted: usize,
    /// Of `reverse_motions_before`, the reversals at path ends and links (harmless).
    pub reverse_motions_links_before: usize,
    /// Of `reverse_motions_after`, the reversals at path ends and links.
    pub reverse_motions_links_after: usize,
    /// Largest deviation of the tool tip or the flute top from the intended motion between
    /// cutting blocks (mm).
    pub max_linearisation_error_mm: f64,
    /// The same between the blocks of rapid moves (mm): they cut nothing; the verification
    /// of the written program checks what their real motion sweeps.
    pub max_rapid_linearisation_error_mm: f64,
    /// Blocks outside the machine limits.
    pub limit_violations: usize,
    /// Cutting moves between which the rotary axes change solution branch (e.g. the tilt sign)
    /// instead of following the intended tool-axis sweep: the tool swings away from the
    /// planned orientations there (a retract and re-approach is needed).
    pub reconfigurations: usize,
    /// The same figures per simultaneous operation, with the reverse-motion removal details.
    pub operations: Vec<PostOperationReport>,
    /// The program's running time from the machine's limits (`null` without a program).
    pub cycle_time: Option<gcode_emit::ProgramTime>,
    /// Operations whose blocks leave the machine's travel (the program is then not posted;
    /// empty when every block lies within the travel).
    pub travel: Vec<crate::travel::TravelViolations>,
}

/// Post-processing figures of one simultaneous operation.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PostOperationReport {
    /// Operation name.
    pub name: String,
    /// NC blocks.
    pub blocks: usize,
    /// Rotary direction reversals before smoothing.
    pub reverse_motions_before: usize,
    /// Rotary direction reversals after smoothing.
    pub reverse_motions_after: usize,
    /// Largest deviation of the tool tip or the flute top from the intended motion between
    /// cutting blocks (mm).
    pub max_linearisation_error_mm: f64,
    /// The same between the blocks of rapid moves (mm): they cut nothing; the verification
    /// of the written program checks what their real motion sweeps.
    pub max_rapid_linearisation_error_mm: f64,
    /// Blocks outside the machine limits.
    pub limit_violations: usize,
    /// Cutting moves with a change of solution branch (see [`PostReport::reconfigurations`]).
    pub reconfigurations: usize,
    /// Whether reverse-motion removal ran (it does not without a cutter to check against).
    pub reverse_motion_removal: bool,
    /// Cutting runs whose rotary angles were smoothed.
    pub smoothed_runs: usize,
    /// Cutting runs kept as they were (change too large, outside the limits, or a changed
    /// posture failed the gouge check).
    pub kept_runs: usize,
    /// Runs made accessible by turning C by a constant offset.
    pub c_repaired_runs: usize,
    /// Source move indices of the first inaccessible posture of each kept run.
    pub inaccessible_blocks: Vec<usize>,
    /// Largest change of a rotary angle by the smoothing (deg).
    pub max_angle_change_deg: f64,
    /// Largest movement of the cutter's contact caused by the smoothed postures (mm): the
    /// bound of the surface deviation the smoothing introduces (ball ends turn about their
    /// centre: 0).
    pub max_contact_shift_mm: f64,
    /// Runs kept unsmoothed because the contact would have moved more than allowed.
    pub runs_kept_for_contact: usize,
    /// Runs kept unsmoothed because a changed posture or motion failed the gouge check or
    /// the axis limits.
    pub runs_kept_for_clearance: usize,
    /// Runs kept unsmoothed because no reversal-free fit stays within the angle limit.
    pub runs_kept_for_angle_limit: usize,
    /// Of `reverse_motions_before`, the reversals inside a cut.
    pub reverse_motions_cutting_before: usize,
    /// Of `reverse_motions_after`, the reversals inside a cut.
    pub reverse_motions_cutting_after: usize,
    /// Of `reverse_motions_before`, the reversals at path ends and links.
    pub reverse_motions_links_before: usize,
    /// Of `reverse_motions_after`, the reversals at path ends and links.
    pub reverse_motions_links_after: usize,
    /// Reversals inside cuts after smoothing, of the tilting axis.
    pub reverse_motions_cutting_tilt: usize,
    /// The same of C.
    pub reverse_motions_cutting_rotate: usize,
    /// Of `reverse_motions_cutting_rotate`, those within 1° of the pole.
    #[serde(default)]
    pub reverse_motions_cutting_near_pole: usize,
    /// The direction changes of the tool-axis angles that the operation's planner left inside
    /// its cutting runs, each with a reason (the operation's `axis_reversals_after`, split by
    /// reason in its `axis_reversals_kept_*`; `null` when the planner does not smooth its
    /// axes, as for imported CL data).
    pub reverse_motions_kept_by_planner: Option<usize>,
    /// The reversals inside cuts that the post finds beyond those near the pole and those the
    /// planner kept: `max(0, cutting_after − near_pole − kept_by_planner)` (all of the ones
    /// away from the pole when the planner keeps no count). On a table-table or head-table
    /// machine whose C turns about the impeller axis the machine's tilt and C follow the
    /// planner's polar angle and azimuth, so each reversal the post counts is one of the
    /// planner's or lies at the pole (where C is not determined by the tool axis); a positive
    /// figure is a reversal nothing explains (a join the planner did not mark as a link, a
    /// post that changed the motion, another kinematic chain).
    pub reverse_motions_cutting_unaccounted: usize,
    /// Smallest reversing step of the reversals inside cuts (deg; 0 without one).
    pub reversal_step_min_deg: f64,
    /// Largest reversing step of the reversals inside cuts (deg).
    pub reversal_step_max_deg: f64,
    /// Largest step of a rotary axis between consecutive cutting blocks (deg).
    pub max_rotary_step_deg: f64,
    /// Largest angular acceleration of the tilting axis at the programmed feed (deg/s²).
    pub max_tilt_acceleration_deg_per_s2: f64,
    /// The same of C.
    pub max_rotate_acceleration_deg_per_s2: f64,
    /// The machine's acceleration limit of the tilting axis (deg/s²; `null` when its file
    /// gives none).
    pub tilt_acceleration_limit_deg_per_s2: Option<f64>,
    /// The same of C.
    pub rotate_acceleration_limit_deg_per_s2: Option<f64>,
    /// Blocks at which the acceleration at programmed feed exceeds a rotary axis' limit (the
    /// machine slows the feed there: see the cycle time).
    pub blocks_over_rotary_acceleration_limit: usize,
}

impl PostOperationReport {
    /// Sets [`Self::reverse_motions_kept_by_planner`] from the planned operation's metrics
    /// (`axis_reversals_after`) and the unaccounted reversals from it.
    pub fn account_with(&mut self, planned: Option<&cam_plan::Metrics>) {
        self.reverse_motions_kept_by_planner = planned
            .and_then(|m| m.get("axis_reversals_after"))
            .and_then(|v| v.as_f64())
            .map(|v| v as usize);
        let away = self
            .reverse_motions_cutting_after
            .saturating_sub(self.reverse_motions_cutting_near_pole);
        self.reverse_motions_cutting_unaccounted =
            away.saturating_sub(self.reverse_motions_kept_by_planner.unwrap_or(0));
    }

    /// The figures of one posted operation.
    pub fn of(p: &gcode_emit::assemble::PostedOperation) -> Self {
        let m = &p.metrics;
        let mut r = Self {
            name: p.name.clone(),
            blocks: m.blocks,
            reverse_motions_before: m.reverse_motions_before,
            reverse_motions_after: m.reverse_motions_after,
            max_linearisation_error_mm: m.max_linearisation_error_mm,
            max_rapid_linearisation_error_mm: m.max_rapid_linearisation_error_mm,
            limit_violations: m.limit_violations,
            reconfigurations: m.reconfigurations,
            reverse_motion_removal: p.reverse_motion_removal,
            reverse_motions_cutting_before: m.reverse_motions_cutting_before,
            reverse_motions_cutting_after: m.reverse_motions_cutting_after,
            reverse_motions_links_before: m.reverse_motions_links_before,
            reverse_motions_links_after: m.reverse_motions_links_after,
            reverse_motions_cutting_tilt: m.reversals.tilt.cutting,
            reverse_motions_cutting_rotate: m.reversals.rotate.cutting,
            reverse_motions_cutting_near_pole: m.reversals.rotate.cutting_near_pole,
            reversal_step_min_deg: m.reversals.cutting_steps().0.to_degrees(),
            reversal_step_max_deg: m.reversals.cutting_steps().1.to_degrees(),
            max_rotary_step_deg: m.rotary.max_step.to_degrees(),
            max_tilt_acceleration_deg_per_s2: m.rotary.max_acceleration_tilt.to_degrees(),
            max_rotate_acceleration_deg_per_s2: m.rotary.max_acceleration_rotate.to_degrees(),
            tilt_acceleration_limit_deg_per_s2: m.rotary.limit_tilt.map(f64::to_degrees),
            rotate_acceleration_limit_deg_per_s2: m.rotary.limit_rotate.map(f64::to_degrees),
            blocks_over_rotary_acceleration_limit: m.rotary.blocks_over_limit,
            ..Self::default()
        };
        if let Some(rm) = &p.reverse_motion {
            r.smoothed_runs = rm.runs_changed;
            r.kept_runs = rm.runs_kept;
            r.c_repaired_runs = rm.c_repaired_runs;
            // Block source indices count the approach move first; report CL move indices.
            r.inaccessible_blocks = rm
                .inaccessible_blocks
                .iter()
                .map(|i| i.saturating_sub(1))
                .collect();
            r.max_angle_change_deg = rm.max_angle_change_deg;
            r.max_contact_shift_mm = rm.max_contact_shift_mm;
            r.runs_kept_for_contact = rm.runs_kept_for_contact;
            r.runs_kept_for_clearance = rm.runs_kept_for_clearance;
            r.runs_kept_for_angle_limit = rm.runs_kept_for_angle_limit;
        }
        r
    }
}

/// Verification figures.
#[derive(Debug, Clone, Serialize)]
pub struct VerificationReport {
    /// Largest depth of removed design material (mm).
    pub max_overcut_mm: f64,
    /// Largest thickness of material left outside the design (mm).
    pub max_residual_mm: f64,
    /// Moves with a shank/holder collision or a rapid through material.
    pub collisions: usize,
    /// Dexel spacing used (mm).
    pub resolution_mm: f64,
    /// The overcut a correct program may show: the job's `machining_tol` plus the
    /// simulation's own overcut error bound at this resolution
    /// ([`machining_sim::overcut_error_bound`]) (mm).
    pub overcut_limit_mm: f64,
    /// What makes the program defective (overcut above the limit, collisions), one line each;
    /// empty when the program passed.
    pub defects: Vec<String>,
    /// Residual distribution per surface group (blade sides and tips of each row, hub).
    pub surface_groups: BTreeMap<String, crate::surface_groups::GroupResidual>,
    /// What was simulated: `program` (the written LinuxCNC program read back through the
    /// machine's kinematics with joint interpolation, every block) or `cutter_locations`
    /// (the posted cutter locations, for dialects the reader does not cover).
    pub source: String,
    /// Locations of the extrema, collision list, simulation statistics.
    pub details: serde_json::Value,
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Job name.
    pub job: String,
    /// `impeller-cam` version.
    pub version: String,
    /// Impeller summary.
    pub impeller: serde_json::Value,
    /// Operations in program order.
    pub operations: Vec<OperationReport>,
    /// Post-processing.
    pub post: PostReport,
    /// Verification (`null` when nothing was verified).
    pub verification: Option<VerificationReport>,
    /// Pass or fail with the limits in force, and what became of the program (`null` until
    /// the run's verification gate has run).
    pub verdict: Option<crate::verdict::Verdict>,
    /// Wall-clock time per stage (ms).
    pub timings_ms: BTreeMap<String, f64>,
    /// What was skipped and why, and reader warnings.
    pub notes: Vec<String>,
    /// The setup sheet's section ([`crate::setup`]), also written as `setup.html`.
    #[serde(skip)]
    pub setup: String,
    /// The interactive 3D view's scene ([`crate::view3d`]).
    #[serde(skip)]
    pub view: crate::view3d::Scene,
    #[serde(skip)]
    plots: Vec<String>,
    #[serde(skip)]
    post_plots: Vec<String>,
    #[serde(skip)]
    operation_plots: Vec<String>,
}

impl Report {
    /// An empty report for job `name`.
    pub fn new(name: &str) -> Self {
        Self {
            job: name.to_string(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            impeller: serde_json::Value::Null,
            operations: Vec::new(),
            post: PostReport::default(),
            verification: None,
            verdict: None,
            timings_ms: BTreeMap::new(),
            notes: Vec::new(),
            setup: String::new(),
            view: crate::view3d::Scene::default(),
            plots: Vec::new(),
            post_plots: Vec::new(),
            operation_plots: Vec::new(),
        }
    }

    /// Meridional view (hub and shroud contours, blade hub and shroud edges in (z, r)) and
    /// the top view of all blades at hub and shroud.
    pub fn set_geometry_plots(&mut self, imp: &Impeller) {
        const N: usize = 80;
        let contour = |m: &impeller_model::MeridionalCurve| -> Vec<(f64, f64)> {
            let (t0, t1) = m.domain();
            (0..=N)
                .map(|i| {
                    let p = m.point(t0 + (t1 - t0) * i as f64 / N as f64);
                    (p.x, p.y)
                })
                .collect()
        };
        let mut merid = vec![
            Series {
                label: "hub".into(),
                points: contour(imp.hub().meridional()),
            },
            Series {
                label: "shroud".into(),
                points: contour(imp.shroud().meridional()),
            },
        ];
        let mut top = Vec::new();
        let sets =
            std::iter::once(("main", imp.main())).chain(imp.splitter().map(|s| ("splitter", s)));
        for (label, set) in sets {
            let side = set.blade().side(Side::Pressure);
            let ((u0, u1), (v0, v1)) = side.domain();
            let edge = |v: f64| -> Vec<cam_core::Vector3> {
                (0..=N)
                    .map(|i| side.point(u0 + (u1 - u0) * i as f64 / N as f64, v))
                    .collect()
            };
            let (hub_edge, tip_edge) = (edge(v0), edge(v1));
            let zr = |pts: &[cam_core::Vector3]| -> Vec<(f64, f64)> {
                pts.iter().map(|p| (p.z, p.x.hypot(p.y))).collect()
            };
            merid.push(Series {
                label: format!("{label} blade, hub edge"),
                points: zr(&hub_edge),
            });
            merid.push(Series {
                label: format!("{label} blade, tip edge"),
                points: zr(&tip_edge),
            });
            // Top view: every instance of the blade's tip edge, separated by NaN gaps.
            let mut pts = Vec::new();
            for k in 0..set.count() {
                let rot = set.rotation(k);
                for p in &tip_edge {
                    let q = rot * p;
                    pts.push((q.x, q.y));
                }
                pts.push((f64::NAN, f64::NAN));
            }
            top.push(Series {
                label: format!("{label} blades (tip edge)"),
                points: pts,
            });
        }
        self.plots.push(line_chart(
            "Meridional view",
            "z (mm)",
            "r (mm)",
            &merid,
            true,
        ));
        self.plots
            .push(line_chart("Top view", "x (mm)", "y (mm)", &top, true));
    }

    /// The paths of one operation over the impeller — top view (x, y) with the blades' tip
    /// edges, meridional view (z, r) with the hub and shroud contours; cutting moves and
    /// rapids/links as separate series — then the operation's own plots.
    pub fn add_operation_plots(&mut self, imp: &Impeller, op: &JobOperation) {
        let path = &op.cl.path;
        let mut h = format!("<h3>{} ({})</h3>", esc(&path.name), esc(&op.kind));
        // At most this many points per series keeps a report of long paths small; the
        // decimation keeps every k-th tip and both ends of each run.
        const MAX_POINTS: usize = 6000;
        let step = (path.moves.len() / MAX_POINTS).max(1);
        let mut cut_xy = Vec::new();
        let mut cut_zr = Vec::new();
        let mut link_xy = Vec::new();
        let mut link_zr = Vec::new();
        let mut prev: Option<(bool, cam_core::Point3)> = None;
        for (i, m) in path.moves.iter().enumerate() {
            let cutting = !matches!(m.kind, MoveKind::Rapid | MoveKind::Retract);
            let p = m.cl.tip;
            let (xy, zr, other_xy, other_zr) = if cutting {
                (&mut cut_xy, &mut cut_zr, &mut link_xy, &mut link_zr)
            } else {
                (&mut link_xy, &mut link_zr, &mut cut_xy, &mut cut_zr)
            };
            let changed = prev.is_some_and(|(c, _)| c != cutting);
            if changed {
                // Start the new run at the previous tip, and break the other series.
                if let Some((_, q)) = prev {
                    xy.push((f64::NAN, f64::NAN));
                    zr.push((f64::NAN, f64::NAN));
                    xy.push((q.x, q.y));
                    zr.push((q.z, q.x.hypot(q.y)));
                }
                other_xy.push((f64::NAN, f64::NAN));
                other_zr.push((f64::NAN, f64::NAN));
            }
            let last = i + 1 == path.moves.len();
            let run_end = path
                .moves
                .get(i + 1)
                .is_some_and(|n| matches!(n.kind, MoveKind::Rapid | MoveKind::Retract) == cutting);
            if i % step == 0 || changed || last || run_end {
                xy.push((p.x, p.y));
                zr.push((p.z, p.x.hypot(p.y)));
            }
            prev = Some((cutting, p));
        }
        let (mut top, mut merid) = self.outline(imp);
        top.push(Series {
            label: "cutting moves".into(),
            points: cut_xy,
        });
        top.push(Series {
            label: "rapids and links".into(),
            points: link_xy,
        });
        merid.push(Series {
            label: "cutting moves".into(),
            points: cut_zr,
        });
        merid.push(Series {
            label: "rapids and links".into(),
            points: link_zr,
        });
        h.push_str(&line_chart(
            &format!("{}: top view", path.name),
            "x (mm)",
            "y (mm)",
            &top,
            true,
        ));
        h.push_str(&line_chart(
            &format!("{}: meridional view", path.name),
            "z (mm)",
            "r (mm)",
            &merid,
            true,
        ));
        for plot in &op.plots {
            h.push_str(&render_plot(plot));
        }
        self.operation_plots.push(h);
    }

    /// Outlines drawn under an operation's paths: every blade's tip edge (top view); hub and
    /// shroud contours (meridional view).
    fn outline(&self, imp: &Impeller) -> (Vec<Series>, Vec<Series>) {
        const N: usize = 60;
        let contour = |m: &impeller_model::MeridionalCurve| -> Vec<(f64, f64)> {
            let (t0, t1) = m.domain();
            (0..=N)
                .map(|i| {
                    let p = m.point(t0 + (t1 - t0) * i as f64 / N as f64);
                    (p.x, p.y)
                })
                .collect()
        };
        let merid = vec![
            Series {
                label: "hub".into(),
                points: contour(imp.hub().meridional()),
            },
            Series {
                label: "shroud".into(),
                points: contour(imp.shroud().meridional()),
            },
        ];
        let mut pts = Vec::new();
        let sets = std::iter::once(imp.main()).chain(imp.splitter());
        for set in sets {
            let side = set.blade().side(Side::Pressure);
            let ((u0, u1), (_, v1)) = side.domain();
            let edge: Vec<cam_core::Vector3> = (0..=N)
                .map(|i| side.point(u0 + (u1 - u0) * i as f64 / N as f64, v1))
                .collect();
            for k in 0..set.count() {
                let rot = set.rotation(k);
                for p in &edge {
                    let q = rot * p;
                    pts.push((q.x, q.y));
                }
                pts.push((f64::NAN, f64::NAN));
            }
        }
        let top = vec![Series {
            label: "blades (tip edge)".into(),
            points: pts,
        }];
        (top, merid)
    }

    /// Axis displacement curves of one posted operation against the tool-tip path length
    /// (paper 004's figures): the rotary axes alone, then all five axes; dashed = before
    /// reverse-motion removal, solid = after.
    pub fn add_displacement_plots(&mut self, p: &gcode_emit::assemble::PostedOperation) {
        let before = p.reverse_motion_removal.then_some(&p.before);
        let caption = if p.reverse_motion_removal {
            format!(
                "{}: axis displacements before (dashed) and after (solid) reverse-motion \
                 removal — reverse motions {} → {}",
                p.name, p.metrics.reverse_motions_before, p.metrics.reverse_motions_after
            )
        } else {
            format!(
                "{}: axis displacements (no reverse-motion removal) — reverse motions {}",
                p.name, p.metrics.reverse_motions_before
            )
        };
        let mut h = format!("<h3>{}</h3>", esc(&caption));
        for rotary_only in [true, false] {
            let cols: &[usize] = if rotary_only {
                &[3, 4]
            } else {
                &[0, 1, 2, 3, 4]
            };
            let mut series = Vec::new();
            for (curves, when) in before
                .map(|b| (b, " before removal"))
                .into_iter()
                .chain([(&p.after, "")])
            {
                // At most 2000 points per curve (every k-th block, and the last).
                let n = curves.values.len().min(curves.path_length_mm.len());
                let step = n.div_ceil(2000).max(1);
                for &k in cols {
                    let letter = curves.letters.get(k).copied().unwrap_or('?');
                    series.push(Series {
                        label: format!("{letter}{when}"),
                        points: (0..n)
                            .filter(|i| i % step == 0 || i + 1 == n)
                            .map(|i| (curves.path_length_mm[i], curves.values[i][k]))
                            .collect(),
                    });
                }
            }
            h.push_str(&line_chart(
                if rotary_only {
                    "Rotary axes"
                } else {
                    "All axes (linear in mm, rotary in deg)"
                },
                "tool-tip path length (mm)",
                if rotary_only {
                    "angle (deg)"
                } else {
                    "position (mm; deg)"
                },
                &series,
                false,
            ));
        }
        self.post_plots.push(h);
    }

    /// Heat maps of overcut and residual on the surfaces where each is largest (at most
    /// three surfaces each), after the residual distribution of every surface group.
    pub fn add_map_plots(&mut self, maps: &[machining_sim::SurfaceMap]) {
        let curves = crate::surface_groups::exceedance_curves(maps, 100);
        if !curves.is_empty() {
            let series: Vec<Series> = curves
                .into_iter()
                .map(|(label, points)| Series {
                    label: label.replace('_', " "),
                    points,
                })
                .collect();
            self.plots.push(line_chart(
                "Residual per surface group (share of points above)",
                "residual (mm)",
                "points above (%)",
                &series,
                false,
            ));
        }
        let worst = |m: &machining_sim::SurfaceMap, residual: bool| -> f64 {
            let v = if residual {
                &m.residual_mm
            } else {
                &m.overcut_mm
            };
            v.iter().flatten().fold(0.0, |a: f64, &b| a.max(b))
        };
        for residual in [false, true] {
            let mut order: Vec<&machining_sim::SurfaceMap> = maps
                .iter()
                .filter(|m| worst(m, residual) > 0.0 && m.nu > 0 && m.nv > 0)
                .collect();
            order.sort_by(|a, b| worst(b, residual).total_cmp(&worst(a, residual)));
            for m in order.into_iter().take(3) {
                let v = if residual {
                    &m.residual_mm
                } else {
                    &m.overcut_mm
                };
                // Samples are stored v-major (index j·nu + i); rows of the plot are v.
                let grid: Vec<Vec<f64>> = (0..m.nv)
                    .map(|j| {
                        (0..m.nu)
                            .map(|i| v.get(j * m.nu + i).copied().flatten().unwrap_or(f64::NAN))
                            .collect()
                    })
                    .collect();
                let title = format!(
                    "{} on {}",
                    if residual { "Residual" } else { "Overcut" },
                    m.name
                );
                self.plots.push(heat_map(
                    &title,
                    &grid,
                    0.0,
                    worst(m, residual),
                    "mm",
                    if residual {
                        Scale::Residual
                    } else {
                        Scale::Overcut
                    },
                    "u sample (along the flow)",
                    "v sample",
                ));
            }
        }
    }

    /// Writes `report.json` and `report.html` into `dir` (each through a temporary file).
    pub fn write(&self, dir: &Path) -> Result<(), CliError> {
        let json = serde_json::to_string_pretty(self)
            .map_err(|e| CliError::Message(format!("cannot format report: {e}")))?;
        write(&dir.join("report.json"), json.as_bytes())?;
        write(&dir.join("report.html"), self.html().as_bytes())
    }

    /// The table of rotary reversals inside cuts per operation, with what explains them: the
    /// pole, and the direction changes the operation's planner kept, by reason.
    fn reversal_table(&self, h: &mut String) {
        h.push_str(
            "<h3>Rotary reversals inside cuts</h3><p>Counted on the posted blocks (both rotary \
             axes); a reversal across a link, plunge, retract or rapid is at a path end or \
             link. Each one inside a cut lies at the pole (the tool axis within 1° of C, which \
             it no longer determines) or is one the operation's planner kept, by reason; \
             <em>unaccounted</em> counts the rest.</p><table><tr><th>operation</th>\
             <th>inside cuts</th><th>at path ends and links</th><th>at the pole</th>",
        );
        for (i, r) in cam_plan::KeptReason::ALL.iter().enumerate() {
            let prefix = if i == 0 { "planner kept: " } else { "" };
            let _ = write!(h, "<th>{prefix}{}</th>", r.name().replace('_', " "));
        }
        h.push_str("<th>unaccounted</th><th>steps (deg)</th></tr>");
        for o in &self.post.operations {
            let planned = self.operations.iter().find(|p| p.name == o.name);
            let kept: String = cam_plan::KeptReason::ALL
                .iter()
                .map(|r| {
                    let v = planned
                        .and_then(|p| p.metrics.get(&r.metric()))
                        .and_then(|v| v.as_f64());
                    v.map_or_else(|| "<td>–</td>".to_string(), |v| format!("<td>{v}</td>"))
                })
                .collect();
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td>{kept}<td>{}</td><td>{}</td></tr>",
                esc(&o.name),
                o.reverse_motions_cutting_after,
                o.reverse_motions_links_after,
                o.reverse_motions_cutting_near_pole,
                o.reverse_motions_cutting_unaccounted,
                if o.reverse_motions_cutting_after > 0 {
                    format!(
                        "{:.4}–{:.4}",
                        o.reversal_step_min_deg, o.reversal_step_max_deg
                    )
                } else {
                    "–".to_string()
                },
            );
        }
        h.push_str("</table>");
    }

    fn html(&self) -> String {
        let mut h = String::new();
        let _ = write!(
            h,
            "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{0} — impeller-cam report</title>\
             <style>body{{font-family:sans-serif;max-width:1200px;margin:2em auto}}\
             table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}\
             th{{background:#f3f3f3}}td:first-child{{text-align:left}}{2}</style></head><body>\
             <h1>{0}</h1><p>impeller-cam {1}</p>",
            esc(&self.job),
            esc(&self.version),
            crate::view3d::CSS
        );
        if let Some(v) = &self.verdict {
            verdict_html(&mut h, v, &self.post.program);
        }
        h.push_str(&self.view.html());
        h.push_str(&self.setup);
        h.push_str("<h2>Impeller</h2>");
        table_of_object(&mut h, &self.impeller);
        for svg in &self.plots {
            h.push_str(svg);
        }
        h.push_str("<h2>Operations</h2>");
        if self.operations.is_empty() {
            h.push_str("<p>No operation.</p>");
        } else {
            h.push_str("<table><tr><th>name</th><th>kind</th><th>tool</th><th>moves</th><th>path length (mm)</th><th>cutting time (s)</th><th>plan (ms)</th></tr>");
            for o in &self.operations {
                let _ = write!(
                    h,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td></tr>",
                    esc(&o.name),
                    esc(&o.kind),
                    esc(&o.tool),
                    o.moves,
                    o.path_length_mm,
                    o.cutting_time_s,
                    o.plan_ms
                );
            }
            h.push_str("</table>");
            for o in self.operations.iter().filter(|o| !o.metrics.0.is_empty()) {
                let _ = write!(h, "<h3>{}: metrics</h3>", esc(&o.name));
                table_of_object(
                    &mut h,
                    &serde_json::to_value(&o.metrics).unwrap_or_default(),
                );
            }
            for p in &self.operation_plots {
                h.push_str(p);
            }
        }
        h.push_str("<h2>Post-processing</h2>");
        let mut post = serde_json::to_value(&self.post).unwrap_or_default();
        if let Some(m) = post.as_object_mut() {
            m.remove("operations");
            m.remove("cycle_time");
        }
        table_of_object(&mut h, &post);
        if !self.post.operations.is_empty() {
            h.push_str("<table><tr><th>operation</th><th>blocks</th><th>reverse motions before</th><th>after</th><th>removal</th><th>smoothed runs</th><th>kept runs</th><th>max angle change (deg)</th><th>max linearisation error (mm)</th><th>rapids (mm)</th><th>limit violations</th></tr>");
            for o in &self.post.operations {
                let _ = write!(
                    h,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.5}</td><td>{:.5}</td><td>{}</td></tr>",
                    esc(&o.name),
                    o.blocks,
                    o.reverse_motions_before,
                    o.reverse_motions_after,
                    if o.reverse_motion_removal { "checked" } else { "off" },
                    o.smoothed_runs,
                    o.kept_runs,
                    o.max_angle_change_deg,
                    o.max_linearisation_error_mm,
                    o.max_rapid_linearisation_error_mm,
                    o.limit_violations
                );
            }
            h.push_str("</table>");
            self.reversal_table(&mut h);
        }
        if let Some(t) = &self.post.cycle_time {
            h.push_str(&crate::cycle::html(t));
        }
        for svg in &self.post_plots {
            h.push_str(svg);
        }
        h.push_str("<h2>Verification</h2>");
        match &self.verification {
            Some(v) => {
                let _ = write!(
                    h,
                    "<table><tr><th>max overcut (mm)</th><th>overcut limit (mm)</th><th>max residual (mm)</th><th>collisions</th><th>resolution (mm)</th></tr>\
                     <tr><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td><td>{}</td><td>{}</td></tr></table>",
                    v.max_overcut_mm, v.overcut_limit_mm, v.max_residual_mm, v.collisions, v.resolution_mm
                );
                if !v.surface_groups.is_empty() {
                    h.push_str(
                        "<table><tr><th>surface group</th><th>points</th><th>residual &gt; 0.05 mm</th>\
                         <th>&gt; 0.1 mm</th><th>&gt; 0.2 mm</th><th>p90 (mm)</th><th>max (mm)</th>\
                         <th>max overcut (mm)</th></tr>",
                    );
                    for (name, g) in &v.surface_groups {
                        let _ = write!(
                            h,
                            "<tr><td>{}</td><td>{}</td><td>{:.1} %</td><td>{:.1} %</td><td>{:.1} %</td>\
                             <td>{:.4}</td><td>{:.4}</td><td>{:.4}</td></tr>",
                            esc(name),
                            g.points,
                            100.0 * g.share_above_0_05_mm,
                            100.0 * g.share_above_0_1_mm,
                            100.0 * g.share_above_0_2_mm,
                            g.p90_mm,
                            g.max_mm,
                            g.max_overcut_mm
                        );
                    }
                    h.push_str("</table>");
                }
            }
            None => h.push_str("<p>Nothing was verified.</p>"),
        }
        h.push_str("<h2>Timings (ms)</h2>");
        table_of_object(
            &mut h,
            &serde_json::to_value(&self.timings_ms).unwrap_or_default(),
        );
        if !self.notes.is_empty() {
            h.push_str("<h2>Notes</h2><ul>");
            for n in &self.notes {
                let _ = write!(h, "<li>{}</li>", esc(n));
            }
            h.push_str("</ul>");
        }
        h.push_str("</body></html>\n");
        h
    }
}

/// An operation's own plot as inline SVG.
fn render_plot(plot: &cam_plan::Plot) -> String {
    match &plot.kind {
        PlotKind::Lines {
            x_label,
            y_label,
            series,
            equal_aspect,
        } => {
            let series: Vec<Series> = series
                .iter()
                .map(|s: &PlotSeries| Series {
                    label: s.label.clone(),
                    points: s.points.iter().map(|p| (p[0], p[1])).collect(),
                })
                .collect();
            line_chart(&plot.title, x_label, y_label, &series, *equal_aspect)
        }
        PlotKind::HeatMap { values, unit } => {
            let finite = values.iter().flatten().filter(|v| v.is_finite());
            let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
            let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
            heat_map(
                &plot.title,
                values,
                lo,
                hi,
                unit,
                Scale::Sequential,
                "column",
                "row",
            )
        }
    }
}

/// The verdict at the top of the report: PASS / FAIL / NOT VERIFIED, the program, the limits
/// in force and the defects.
fn verdict_html(h: &mut String, v: &crate::verdict::Verdict, program: &str) {
    let colour = match v.status {
        crate::verdict::Status::Pass => "#1a7f37",
        crate::verdict::Status::Fail => "#cf222e",
        crate::verdict::Status::NotVerified => "#9a6700",
    };
    let _ = write!(
        h,
        "<h2 id=\"verdict\" style=\"color:{colour}\">Verdict: {}</h2><p>Program: {}</p><p>{}</p>",
        v.word(),
        esc(&v.program_text(program)),
        esc(&v.verification())
    );
    if !v.defects.is_empty() {
        h.push_str("<ul>");
        for d in &v.defects {
            let _ = write!(h, "<li>{}</li>", esc(d));
        }
        h.push_str("</ul>");
    }
}

fn table_of_object(h: &mut String, v: &serde_json::Value) {
    if let serde_json::Value::Object(m) = v {
        h.push_str("<table>");
        for (k, v) in m {
            let text = match v {
                serde_json::Value::Number(n) => match n.as_f64() {
                    Some(f) if n.is_f64() => format!("{f:.4}"),
                    _ => n.to_string(),
                },
                serde_json::Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            let _ = write!(
                h,
                "<tr><td title=\"{}\">{}</td><td>{}</td></tr>",
                esc(k),
                esc(&human_label(k)),
                esc(&text)
            );
        }
        h.push_str("</table>");
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    gcode_emit::write_atomic(path, bytes).map_err(|e| CliError::Message(e.to_string()))
}
