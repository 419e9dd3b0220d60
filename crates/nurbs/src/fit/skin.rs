//! Skinning (lofting): a surface through a sequence of section curves (NURBS Book §10.3).

use nalgebra::{SVector, Vector3};

use super::params::averaged_knots;
use super::surface_interp::{averaged_params, interpolate_families};
use super::{FitError, Parametrisation};
use crate::{KnotVector, NurbsCurve, NurbsSurface};

/// Knots of `target` (with multiplicity) that `have` lacks, for merging knot vectors.
fn missing(have: &[f64], target: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < target.len() {
        let v = target[i];
        let mut j = i;
        while j < target.len() && target[j] == v {
            j += 1;
        }
        let got = have.iter().filter(|&&k| k == v).count();
        out.extend(std::iter::repeat_n(v, (j - i).saturating_sub(got)));
        i = j;
    }
    out
}

/// Skinned surface through `sections` (the `u`-direction curves, in order along `v`):
/// `S(u, v̄_k) = C_k(u)` for every section `k` (after mapping each section to `u ∈ [0, 1]`).
///
/// Steps (NURBS Book §10.3): the sections are clamped, reparametrised to [0, 1], raised to
/// the highest degree among them (A5.9) and refined to the union of their knot vectors,
/// keeping the largest multiplicity of each value (A5.4; values are merged by exact
/// equality). The sections then share one knot vector and control-point count. Their
/// control points (homogeneous `(wP, w)` if any section is rational) are interpolated across
/// the sections with degree `degree_v` (A9.1 per control-point column, one factorisation):
/// section parameters `v̄_k` are the averages over columns of the chord-length (or
/// `parametrisation`) parameters of corresponding control points (eq. 10.8); knots in `v`
/// by averaging (eq. 9.8). The result is exact at the sections to round-off.
///
/// Errors: fewer than `degree_v + 1` sections (at least 2), degree 0, coincident
/// consecutive sections, and any core error (e.g. non-positive interpolated weights of
/// rational sections, reported as [`FitError::Nurbs`]).
pub fn skin(
    sections: &[NurbsCurve<3>],
    degree_v: usize,
    parametrisation: Parametrisation,
) -> Result<NurbsSurface, FitError> {
    if degree_v == 0 {
        return Err(FitError::InvalidDegree { degree: degree_v });
    }
    let needed = (degree_v + 1).max(2);
    if sections.len() < needed {
        return Err(FitError::TooFewPoints {
            what: "sections",
            needed,
            got: sections.len(),
        });
    }
    let p = sections.iter().map(NurbsCurve::degree).max().unwrap_or(1);
    let mut prepared = Vec::with_capacity(sections.len());
    for c in sections {
        let c = c.clamped()?.reparametrize(0.0, 1.0)?;
        let c = if c.degree() < p {
            c.elevate_degree(p - c.degree())?
        } else {
            c
        };
        prepared.push(c);
    }
    // Union of the knot vectors (max multiplicity per value).
    let mut union: Vec<f64> = prepared[0].knots().knots().to_vec();
    for c in &prepared[1..] {
        let extra = missing(&union, c.knots().knots());
        union.extend(extra);
        union.sort_by(f64::total_cmp);
    }
    let mut refined = Vec::with_capacity(prepared.len());
    for c in prepared {
        let extra = missing(c.knots().knots(), &union);
        refined.push(if extra.is_empty() {
            c
        } else {
            c.refine_knots(&extra)?
        });
    }
    let rational = refined.iter().any(NurbsCurve::is_rational);
    let n_u = refined[0].control_points().len();
    // Columns across the sections: column i holds control point i of every section.
    let columns: Vec<Vec<Vector3<f64>>> = (0..n_u)
        .map(|i| refined.iter().map(|c| c.control_points()[i]).collect())
        .collect();
    let v_params = averaged_params(&columns, parametrisation)?;
    let knots_v = averaged_knots(&v_params, degree_v, false);
    let kv = KnotVector::new(degree_v, knots_v.clone())?;
    let families: Vec<Vec<SVector<f64, 4>>> = (0..n_u)
        .map(|i| {
            refined
                .iter()
                .map(|c| {
                    let w = c.weights().map_or(1.0, |w| w[i]);
                    let pt = c.control_points()[i] * w;
                    SVector::<f64, 4>::new(pt.x, pt.y, pt.z, w)
                })
                .collect()
        })
        .collect();
    let ctrl_h = interpolate_families(&kv, &v_params, &families)?;
    let mut ctrl = Vec::with_capacity(n_u);
    let mut weights = Vec::with_capacity(n_u);
    for row in &ctrl_h {
        let mut pts = Vec::with_capacity(row.len());
        let mut ws = Vec::with_capacity(row.len());
        for h in row {
            let w = if rational { h[3] } else { 1.0 };
            let inv = if w != 0.0 { 1.0 / w } else { f64::NAN };
            pts.push(Vector3::new(h[0] * inv, h[1] * inv, h[2] * inv));
            ws.push(w);
        }
        ctrl.push(pts);
        weights.push(ws);
    }
    let knots_u = refined[0].knots().knots().to_vec();
    if rational {
        // A non-positive or non-finite weight makes the homogeneous division meaningless;
        // report it as the core's weight error on the surface.
        if let Some((index, &value)) = weights
            .iter()
            .flatten()
            .enumerate()
            .find(|(_, w)| !(w.is_finite() && **w > 0.0))
        {
            return Err(FitError::Nurbs(crate::NurbsError::InvalidWeight {
                index,
                value,
            }));
        }
    }
    Ok(NurbsSurface::new(
        p,
        degree_v,
        knots_u,
        knots_v,
        ctrl,
        if rational { Some(weights) } else { None },
    )?)
}
