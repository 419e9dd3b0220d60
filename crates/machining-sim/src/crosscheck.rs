//! Cross-check of the dexel overcut against an independent computation: the signed distance
//! from design points to the union of the swept envelopes of the tool paths, computed with
//! `cam_core::SweptEnvelope` (paper 002's sphere-swept envelope: each cutter as an exact
//! sphere family, its axis moving between two guides).
//!
//! Each maximal run of non-rapid moves becomes one envelope whose guides are the degree-1
//! B-splines through the tips (`P0`) and through `tip + L·axis` (`P1`, `L` the flute length):
//! the tip moves linearly and the axis direction is the normalised linear blend of the end
//! axes, i.e. the [`crate::Interpolation::Tcp`] motion. The envelope's depth at a point,
//! `max(0, −d)`, is the depth of the point inside the deepest cutter member, which equals the
//! overcut below a design surface point where the gouge floor is the nearest envelope point
//! (the usual case for small gouges); it must agree with the dexel overcut within the dexel
//! resolution. Cost per point: O(positions) seeds + Newton per envelope.

use crate::design::DesignModel;
use crate::error::SimError;
use crate::simulate::Report;
use cam_core::{
    Cutter, CutterLocation, EnvelopeOptions, GuideCurve, MoveKind, Point3, SphereFamily,
    SweptEnvelope, ToolPath,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The swept envelopes of a set of tool paths, each with an axis-aligned box that holds it
/// (the box of its guide points, which holds the linear guides, grown by more than the
/// largest member sphere of the cutter reaches beyond them).
#[derive(Debug, Clone)]
pub struct Envelopes {
    envelopes: Vec<(SweptEnvelope, [f64; 6])>,
}

/// The box of the tips and flute tops of `cls`, grown by `pad`.
fn box_of(cls: &[CutterLocation], flute: f64, pad: f64) -> [f64; 6] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for c in cls {
        for q in [c.tip.coords, c.tip.coords + c.axis.into_inner() * flute] {
            for k in 0..3 {
                b[k] = b[k].min(q[k] - pad);
                b[k + 3] = b[k + 3].max(q[k] + pad);
            }
        }
    }
    b
}

/// Distance from `p` to the box `b` (0 inside).
fn box_distance(b: &[f64; 6], p: &Point3) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let e = (b[k] - p[k]).max(p[k] - b[k + 3]).max(0.0);
        d2 += e * e;
    }
    d2.sqrt()
}

fn envelope_of(cutter: &Cutter, cls: &[CutterLocation]) -> Result<SweptEnvelope, SimError> {
    let mut cls = cls.to_vec();
    if cls.len() == 1 {
        cls.push(cls[0]);
    }
    let n = cls.len();
    let mut knots = vec![0.0];
    knots.extend((0..n).map(|k| k as f64));
    knots.push((n - 1) as f64);
    let l = cutter.flute_length;
    let p0 = cls.iter().map(|c| c.tip.coords).collect();
    let p1 = cls
        .iter()
        .map(|c| c.tip.coords + c.axis.into_inner() * l)
        .collect();
    let err = SimError::Envelope;
    let g0 = GuideCurve::new(1, knots.clone(), p0, None).map_err(err)?;
    let g1 = GuideCurve::new(1, knots, p1, None).map_err(err)?;
    let family = SphereFamily::from_cutter(cutter).map_err(err)?;
    SweptEnvelope::new(family, g0, g1, 0.0, EnvelopeOptions::default()).map_err(err)
}

impl Envelopes {
    /// One envelope per run of cutting moves of every operation.
    pub fn new(ops: &[(Cutter, ToolPath)]) -> Result<Self, SimError> {
        Self::new_where(ops, |_| true)
    }

    /// The envelopes of the runs whose box holds at least one of `points`: enough for the
    /// depth `max(0, −d)` of those points (a run whose box does not hold a point cannot hold
    /// it), at the cost of building only those envelopes. The distance of a point outside
    /// every kept box is not that of the whole union.
    pub fn around(ops: &[(Cutter, ToolPath)], points: &[Point3]) -> Result<Self, SimError> {
        Self::new_where(ops, |b| points.iter().any(|p| box_distance(b, p) == 0.0))
    }

    /// The runs of cutting moves (with their boxes) are collected in order, and the kept
    /// runs' envelopes are built in parallel (rayon; independent, order kept).
    fn new_where(
        ops: &[(Cutter, ToolPath)],
        keep: impl Fn(&[f64; 6]) -> bool,
    ) -> Result<Self, SimError> {
        let mut runs: Vec<(&Cutter, Vec<CutterLocation>, [f64; 6])> = Vec::new();
        for (cutter, path) in ops {
            let mut run: Vec<CutterLocation> = Vec::new();
            // A member tangent to a cone of half angle α at radius R sits R·tan α above that
            // height with radius R / cos α, so it reaches R (tan α + 1 / cos α) ≤ 2.42 R beyond
            // the guide point for α ≤ 45°.
            let pad = 2.5 * cutter.max_cutting_radius() + 1.0;
            let l = cutter.flute_length;
            let mut close = |run: &mut Vec<CutterLocation>| {
                let b = box_of(run, l, pad);
                if keep(&b) {
                    runs.push((cutter, std::mem::take(run), b));
                }
                run.clear();
            };
            for (k, mv) in path.moves.iter().enumerate() {
                if mv.kind == MoveKind::Rapid {
                    if !run.is_empty() {
                        close(&mut run);
                    }
                    continue;
                }
                if run.is_empty() && k > 0 {
                    run.push(path.moves[k - 1].cl);
                }
                run.push(mv.cl);
            }
            if !run.is_empty() {
                close(&mut run);
            }
        }
        let envelopes = runs
            .par_iter()
            .map(|(cutter, run, b)| Ok((envelope_of(cutter, run)?, *b)))
            .collect::<Result<Vec<_>, SimError>>()?;
        Ok(Self { envelopes })
    }

    /// Signed distance from `p` to the union of the envelopes (negative inside). Envelopes
    /// whose box is farther from `p` than the best distance found so far are skipped: their
    /// distance is at least the box's. Exact as the envelopes' own query; cost O(envelopes)
    /// box tests plus one envelope query per envelope whose box is near `p`.
    pub fn signed_distance(&self, p: &Point3) -> Result<f64, SimError> {
        let mut near: Vec<(f64, usize)> = self
            .envelopes
            .iter()
            .enumerate()
            .map(|(i, (_, b))| (box_distance(b, p), i))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best = f64::INFINITY;
        for (d_box, i) in near {
            if d_box >= best {
                break;
            }
            best = best.min(
                self.envelopes[i]
                    .0
                    .signed_distance(p, None)
                    .map_err(SimError::Envelope)?
                    .distance,
            );
        }
        Ok(best)
    }
}

/// One cross-checked design sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossCheckPoint {
    /// Surface name.
    pub surface: String,
    /// Sample index along u.
    pub i: usize,
    /// Sample index along v.
    pub j: usize,
    /// Sample point (mm).
    pub point: [f64; 3],
    /// Overcut measured on the dexels (mm).
    pub dexel_overcut_mm: f64,
    /// Depth inside the swept envelopes, `max(0, −d)` (mm).
    pub envelope_overcut_mm: f64,
}

/// Cross-checks the `max_points` samples of `report` with the largest dexel overcut, building
/// only the envelopes of runs that can reach them ([`Envelopes::around`]).
pub fn crosscheck_overcut(
    report: &Report,
    ops: &[(Cutter, ToolPath)],
    max_points: usize,
) -> Result<Vec<CrossCheckPoint>, SimError> {
    let mut cands: Vec<(f64, usize, usize)> = Vec::new();
    for (m, map) in report.maps.iter().enumerate() {
        for (k, v) in map.overcut_mm.iter().enumerate() {
            if let Some(v) = v {
                cands.push((*v, m, k));
            }
        }
    }
    cands.sort_by(|a, b| b.0.total_cmp(&a.0));
    cands.truncate(max_points);
    let points: Vec<Point3> = cands
        .iter()
        .map(|&(_, m, k)| {
            let p = report.maps[m].points[k];
            Point3::new(p[0], p[1], p[2])
        })
        .collect();
    let env = Envelopes::around(ops, &points)?;
    // Independent points, in parallel (order kept).
    cands
        .par_iter()
        .map(|&(v, m, k)| {
            let map = &report.maps[m];
            let p = map.points[k];
            let d = env.signed_distance(&Point3::new(p[0], p[1], p[2]))?;
            Ok(CrossCheckPoint {
                surface: map.name.clone(),
                i: k % map.nu.max(1),
                j: k / map.nu.max(1),
                point: p,
                dexel_overcut_mm: v,
                envelope_overcut_mm: (-d).max(0.0),
            })
        })
        .collect()
}

/// The cross-check of one overcut location `e` read inside the design (a cut end point: on
/// the swept envelope's boundary, `−sd(e)` below the design surface).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossCheckLocation {
    /// The location read (mm).
    pub point: [f64; 3],
    /// Its depth inside the design, `max(0, −sd(e))` (mm).
    pub design_depth_mm: f64,
    /// The design surface point above it, `e − sd(e)·∇sd/|∇sd|` (mm).
    pub surface_point: [f64; 3],
    /// Depth of that surface point inside the swept envelopes, `max(0, −d)` (mm): the
    /// overcut there for a ball-ended cutter (the ball's depth below the surface point
    /// above its deepest point), a lower bound for sharper cutter shapes.
    pub envelope_overcut_mm: f64,
}

/// Re-measures the overcut read at `e` on the exact swept envelopes of `ops`: projects `e`
/// onto the design surface along the design distance's gradient (central differences of
/// `design.signed_distance`, step 10⁻³ mm) and takes that surface point's depth inside the
/// envelopes ([`Envelopes::around`]). Where the dexel reading attributes an end point's
/// depth to the nearest map sample (up to a sample spacing away), this measures at the cut
/// itself. Cost: 7 design distance queries and the envelopes of the runs near the point.
pub fn crosscheck_location(
    design: &dyn DesignModel,
    ops: &[(Cutter, ToolPath)],
    e: [f64; 3],
) -> Result<CrossCheckLocation, SimError> {
    let p = Point3::new(e[0], e[1], e[2]);
    let sd = design.signed_distance(&p);
    let h = 1e-3;
    let mut g = [0.0; 3];
    for (k, gk) in g.iter_mut().enumerate() {
        let mut a = p;
        let mut b = p;
        a[k] += h;
        b[k] -= h;
        *gk = (design.signed_distance(&a) - design.signed_distance(&b)) / (2.0 * h);
    }
    let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    let q = if norm > 1e-9 && sd.is_finite() {
        Point3::new(
            p.x - sd * g[0] / norm,
            p.y - sd * g[1] / norm,
            p.z - sd * g[2] / norm,
        )
    } else {
        p
    };
    let env = Envelopes::around(ops, &[q])?;
    let d = env.signed_distance(&q)?;
    Ok(CrossCheckLocation {
        point: e,
        design_depth_mm: (-sd).max(0.0),
        surface_point: [q.x, q.y, q.z],
        envelope_overcut_mm: (-d).max(0.0),
    })
}
