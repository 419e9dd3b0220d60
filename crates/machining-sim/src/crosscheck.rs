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

use crate::error::SimError;
use crate::simulate::Report;
use cam_core::{
    Cutter, CutterLocation, EnvelopeOptions, GuideCurve, MoveKind, Point3, SphereFamily,
    SweptEnvelope, ToolPath,
};
use serde::{Deserialize, Serialize};

/// The swept envelopes of a set of tool paths.
#[derive(Debug, Clone)]
pub struct Envelopes {
    envelopes: Vec<SweptEnvelope>,
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
        let mut envelopes = Vec::new();
        for (cutter, path) in ops {
            let mut run: Vec<CutterLocation> = Vec::new();
            for (k, mv) in path.moves.iter().enumerate() {
                if mv.kind == MoveKind::Rapid {
                    if !run.is_empty() {
                        envelopes.push(envelope_of(cutter, &run)?);
                        run.clear();
                    }
                    continue;
                }
                if run.is_empty() && k > 0 {
                    run.push(path.moves[k - 1].cl);
                }
                run.push(mv.cl);
            }
            if !run.is_empty() {
                envelopes.push(envelope_of(cutter, &run)?);
            }
        }
        Ok(Self { envelopes })
    }

    /// Signed distance from `p` to the union of the envelopes (negative inside).
    pub fn signed_distance(&self, p: &Point3) -> Result<f64, SimError> {
        let mut best = f64::INFINITY;
        for e in &self.envelopes {
            best = best.min(
                e.signed_distance(p, None)
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

/// Cross-checks the `max_points` samples of `report` with the largest dexel overcut.
pub fn crosscheck_overcut(
    report: &Report,
    ops: &[(Cutter, ToolPath)],
    max_points: usize,
) -> Result<Vec<CrossCheckPoint>, SimError> {
    let env = Envelopes::new(ops)?;
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
    let mut out = Vec::with_capacity(cands.len());
    for (v, m, k) in cands {
        let map = &report.maps[m];
        let p = map.points[k];
        let d = env.signed_distance(&Point3::new(p[0], p[1], p[2]))?;
        out.push(CrossCheckPoint {
            surface: map.name.clone(),
            i: k % map.nu.max(1),
            j: k / map.nu.max(1),
            point: p,
            dexel_overcut_mm: v,
            envelope_overcut_mm: (-d).max(0.0),
        });
    }
    Ok(out)
}
