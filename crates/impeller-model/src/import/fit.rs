//! Exact geometry from prepared export points: meridional contours and blade sides as
//! non-rational B-splines fitted within a stated tolerance.
//!
//! - **Hub and shroud**: the meridional (z, r) points are approximated by a cubic B-spline
//!   with fixed end points and the fewest control points whose deviation at the data
//!   parameters is within `tol` (`nurbs::fit::approximate_curve_to_tolerance`, NURBS Book
//!   §9.4.1, chord-length parameters).
//! - **Blade sides**: all sections of one side are fitted *compatibly* — chord-length
//!   parameters per section, or, when all sections have the same number of points, their
//!   average (points of equal index then lie on one iso-parametric line across the span, as
//!   AutoGrid's ruled sides intend) — one clamped cubic
//!   knot vector shared by every section, knots at quantiles of the merged chord-length
//!   parameters of all sections (the idea of eq. 9.69: every span holds data), least squares
//!   with fixed leading- and trailing-edge points (§9.4.1, eqs. 9.63–9.67) solved by SVD —
//!   with the control count doubled and then bisected until every section is within `tol`
//!   (at most the point count of the smallest section, where the fit interpolates: sparse or
//!   noisy data then are followed exactly, wiggles included; if every larger system is
//!   singular the closest fit is returned and [`super::build::check_tolerance`] rejects it).
//!   The compatible section curves are then skinned (§10.3): the control points of each
//!   index are interpolated across the sections at averaged chord-length parameters v̄_k
//!   with knots by averaging (eq. 9.8), degree min(3, sections − 1). The surface reproduces
//!   each section curve exactly at v = v̄_k, so its deviation from the data points is the
//!   section fit's (reported per side). u runs from leading to trailing edge, v from hub
//!   to shroud.
//!
//! Cost: O(m·n²) per least-squares solve (m data points, n control points), O(log m) solves
//! per side; skinning O(K³ + n·K) for K sections.

use super::error::ImportError;
use super::prepare::PreparedImpeller;
use super::raw::{positive, BladeRole};
use nalgebra::{DMatrix, Vector2, Vector3};
use nurbs::fit::{approximate_curve_to_tolerance, averaged_knots, Parametrisation};
use nurbs::{Curve2, KnotVector, NurbsCurve, NurbsSurface};
use rayon::prelude::*;
use std::path::PathBuf;

/// Default fit tolerance, mm.
pub const DEFAULT_FIT_TOL_MM: f64 = 0.01;

/// A shared knot vector, each section's control points, and the largest deviation (mm).
type CompatibleFit = (KnotVector, Vec<Vec<Vector3<f64>>>, f64);

/// Degree of fitted curves along the flow and along the meridian.
const DEGREE: usize = 3;

/// One fitted blade (a main blade or a splitter), one copy.
#[derive(Debug, Clone)]
pub struct FittedBlade {
    /// Name in the file.
    pub name: String,
    /// Main blade or splitter.
    pub role: BladeRole,
    /// Number of copies around the axis.
    pub count: usize,
    /// Number of data sections (2: a ruled blade, hub and shroud sections).
    pub sections: usize,
    /// Pressure side, u leading → trailing edge, v hub → shroud.
    pub pressure: NurbsSurface,
    /// Suction side, same parametrisation.
    pub suction: NurbsSurface,
    /// Largest deviation of the pressure-side data from the surface, mm.
    pub pressure_fit_mm: f64,
    /// Largest deviation of the suction-side data from the surface, mm.
    pub suction_fit_mm: f64,
}

/// An export turned into exact geometry in the workpiece frame.
#[derive(Debug, Clone)]
pub struct FittedImpeller {
    /// The main file read.
    pub source: PathBuf,
    /// Hub meridional curve (z, r), inlet → outlet.
    pub hub: Curve2,
    /// Shroud meridional curve (z, r), inlet → outlet.
    pub shroud: Curve2,
    /// Main blade first, then splitters.
    pub blades: Vec<FittedBlade>,
    /// Largest hub data deviation, mm.
    pub hub_fit_mm: f64,
    /// Largest shroud data deviation, mm.
    pub shroud_fit_mm: f64,
    /// The tolerance asked for, mm.
    pub tol_mm: f64,
}

impl FittedImpeller {
    /// Largest deviation of any data point from its fitted curve or surface, mm.
    pub fn max_fit_mm(&self) -> f64 {
        self.blades
            .iter()
            .flat_map(|b| [b.pressure_fit_mm, b.suction_fit_mm])
            .chain([self.hub_fit_mm, self.shroud_fit_mm])
            .fold(0.0, f64::max)
    }
}

/// Chord-length parameters on [0, 1] (points must be distinct consecutively).
fn chord_params(points: &[Vector3<f64>]) -> Option<Vec<f64>> {
    let mut acc = vec![0.0; points.len()];
    for k in 1..points.len() {
        acc[k] = acc[k - 1] + (points[k] - points[k - 1]).norm();
    }
    let total = *acc.last()?;
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    Some(acc.into_iter().map(|a| a / total).collect())
}

/// Clamped knot vector of `degree` with `n_ctrl` control points whose interior knots are
/// quantiles of the sorted parameters `all` (so each span holds data).
fn quantile_knots(
    all: &[f64],
    degree: usize,
    n_ctrl: usize,
) -> Result<KnotVector, nurbs::NurbsError> {
    let mut knots = vec![0.0; degree + 1];
    let n_int = n_ctrl - degree - 1;
    for j in 1..=n_int {
        let q = j as f64 / (n_int + 1) as f64;
        let pos = q * (all.len() - 1) as f64;
        let lo = pos.floor() as usize;
        let hi = (lo + 1).min(all.len() - 1);
        let t = pos - lo as f64;
        knots.push(all[lo] * (1.0 - t) + all[hi] * t);
    }
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    KnotVector::new(degree, knots)
}

/// Least squares with both end points interpolated, on the given knot vector; returns the
/// control points and the largest deviation at the data parameters, or `None` when the
/// system is rank deficient.
fn lsq_fixed_ends(
    points: &[Vector3<f64>],
    params: &[f64],
    kv: &KnotVector,
) -> Option<(Vec<Vector3<f64>>, f64)> {
    let m = points.len();
    let n = kv.n_ctrl();
    let p = kv.degree();
    let (q0, qm) = (points[0], points[m - 1]);
    let mut ctrl = vec![q0; n];
    ctrl[n - 1] = qm;
    if n > 2 {
        if m < n {
            return None;
        }
        let rows = m - 2;
        let cols = n - 2;
        let mut a = DMatrix::<f64>::zeros(rows, cols);
        let mut b = DMatrix::<f64>::zeros(rows, 3);
        let mut nb = [0.0; 16];
        for k in 1..m - 1 {
            let u = params[k];
            let span = kv.find_span(u);
            kv.basis_funs(span, u, &mut nb);
            let mut rhs = points[k];
            for (j, &nj) in nb.iter().enumerate().take(p + 1) {
                let idx = span - p + j;
                if idx == 0 {
                    rhs -= q0 * nj;
                } else if idx == n - 1 {
                    rhs -= qm * nj;
                } else {
                    a[(k - 1, idx - 1)] = nj;
                }
            }
            for d in 0..3 {
                b[(k - 1, d)] = rhs[d];
            }
        }
        if !(a.iter().all(|x| x.is_finite()) && b.iter().all(|x| x.is_finite())) {
            return None;
        }
        // Bounded iterations: never loops on pathological input.
        let svd = a.try_svd(true, true, f64::EPSILON, 10_000)?;
        let smax = svd.singular_values.max();
        let smin = svd.singular_values.min();
        if !(smax > 0.0 && smin > 1e-10 * smax) {
            return None;
        }
        let x = svd.solve(&b, 0.0).ok()?;
        for i in 0..cols {
            ctrl[i + 1] = Vector3::new(x[(i, 0)], x[(i, 1)], x[(i, 2)]);
        }
    }
    let curve = NurbsCurve::<3>::from_knot_vector(kv.clone(), ctrl.clone(), None).ok()?;
    let err = params
        .iter()
        .zip(points)
        .map(|(&u, q)| (curve.point(u) - q).norm())
        .fold(0.0, f64::max);
    err.is_finite().then_some((ctrl, err))
}

/// Fits all `sections` (each LE → TE) with one shared knot vector within `tol`: returns the
/// knot vector, each section's control points and the largest deviation.
fn fit_compatible(sections: &[Vec<Vector3<f64>>], tol: f64) -> Result<CompatibleFit, String> {
    let mut params: Vec<Vec<f64>> = sections
        .iter()
        .map(|s| chord_params(s).ok_or_else(|| "a section has zero length".to_string()))
        .collect::<Result<_, _>>()?;
    // Sections of equal point counts correspond point by point (AutoGrid sides, our own
    // exports): one averaged parameter per index keeps those correspondences as the
    // iso-parametric lines across the span (NURBS Book eq. 9.16's averaging).
    let m0 = params[0].len();
    if params.iter().all(|p| p.len() == m0) {
        let avg: Vec<f64> = (0..m0)
            .map(|i| params.iter().map(|p| p[i]).sum::<f64>() / params.len() as f64)
            .collect();
        for p in &mut params {
            p.clone_from(&avg);
        }
    }
    let m_min = sections.iter().map(Vec::len).min().unwrap_or(0);
    if m_min < 2 {
        return Err("a section has fewer than 2 points".into());
    }
    let degree = DEGREE.min(m_min - 1);
    let mut all: Vec<f64> = params.iter().flatten().copied().collect();
    all.sort_by(f64::total_cmp);
    let attempt = |n: usize| -> Option<CompatibleFit> {
        let kv = quantile_knots(&all, degree, n).ok()?;
        let mut ctrls = Vec::with_capacity(sections.len());
        let mut worst: f64 = 0.0;
        for (s, u) in sections.iter().zip(&params) {
            let (c, e) = lsq_fixed_ends(s, u, &kv)?;
            worst = worst.max(e);
            ctrls.push(c);
        }
        Some((kv, ctrls, worst))
    };
    let (lo_n, hi_max) = (degree + 1, m_min);
    // The closest non-singular fit seen, returned when the tolerance cannot be met.
    let mut closest: Option<CompatibleFit> = None;
    let mut try_n = |n: usize| -> Option<CompatibleFit> {
        let r = attempt(n);
        if let Some(f) = &r {
            if closest.as_ref().is_none_or(|c| f.2 < c.2) {
                closest = Some(f.clone());
            }
        }
        r.filter(|f| f.2 <= tol)
    };
    if let Some(f) = try_n(lo_n) {
        return Ok(f);
    }
    let (mut lo, mut hi) = (lo_n, (2 * lo_n).min(hi_max));
    let mut best = loop {
        if let Some(f) = try_n(hi) {
            break f;
        }
        if hi == hi_max {
            return closest.ok_or_else(|| {
                "no compatible fit of the sections exists (singular system)".into()
            });
        }
        lo = hi;
        hi = (2 * hi).min(hi_max);
    };
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        match try_n(mid) {
            Some(f) => {
                hi = mid;
                best = f;
            }
            None => lo = mid,
        }
    }
    Ok(best)
}

/// Skins compatible section control nets (`ctrls[k][i]`, section k) into a surface, u along
/// the sections, v across them (NURBS Book §10.3).
fn skin(kv_u: &KnotVector, ctrls: &[Vec<Vector3<f64>>]) -> Result<NurbsSurface, String> {
    let k_sec = ctrls.len();
    let n = kv_u.n_ctrl();
    if k_sec < 2 {
        return Err("fewer than 2 sections".into());
    }
    // Averaged chord-length parameters across sections.
    let mut vbar = vec![0.0; k_sec];
    #[allow(clippy::needless_range_loop)] // i indexes the same control point in every section
    for i in 0..n {
        let d: Vec<f64> = (1..k_sec)
            .map(|k| (ctrls[k][i] - ctrls[k - 1][i]).norm())
            .collect();
        let total: f64 = d.iter().sum();
        if !positive(total) {
            return Err("two sections coincide".into());
        }
        let mut acc = 0.0;
        for k in 1..k_sec {
            acc += d[k - 1];
            vbar[k] += acc / total / n as f64;
        }
    }
    vbar[k_sec - 1] = 1.0;
    for k in 1..k_sec {
        if !positive(vbar[k] - vbar[k - 1]) {
            return Err("section parameters are not increasing".into());
        }
    }
    let q = DEGREE.min(k_sec - 1);
    let knots_v = averaged_knots(&vbar, q, false);
    let kv_v = KnotVector::new(q, knots_v.clone()).map_err(|e| e.to_string())?;
    let mut mat = DMatrix::<f64>::zeros(k_sec, k_sec);
    let mut nb = [0.0; 16];
    for (k, &v) in vbar.iter().enumerate() {
        let span = kv_v.find_span(v);
        kv_v.basis_funs(span, v, &mut nb);
        for j in 0..=q {
            mat[(k, span - q + j)] = nb[j];
        }
    }
    let lu = mat.lu();
    let mut net = vec![vec![Vector3::zeros(); k_sec]; n];
    for (i, row) in net.iter_mut().enumerate() {
        let mut b = DMatrix::<f64>::zeros(k_sec, 3);
        for k in 0..k_sec {
            for d in 0..3 {
                b[(k, d)] = ctrls[k][i][d];
            }
        }
        let x = lu.solve(&b).ok_or("singular skinning system")?;
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = Vector3::new(x[(j, 0)], x[(j, 1)], x[(j, 2)]);
        }
    }
    NurbsSurface::new(kv_u.degree(), q, kv_u.knots().to_vec(), knots_v, net, None)
        .map_err(|e| e.to_string())
}

/// Fits a meridional contour within `tol`.
fn fit_contour(points: &[Vector2<f64>], tol: f64) -> Result<(Curve2, f64), String> {
    let degree = DEGREE.min(points.len().saturating_sub(1)).max(1);
    let fit = approximate_curve_to_tolerance(points, degree, tol, Parametrisation::ChordLength)
        .map_err(|e| e.to_string())?;
    Ok((fit.curve, fit.max_error))
}

/// Extends compatible section nets beyond the first and last section by `ext` × the span
/// (linear extrapolation of the section curves: C_ext(u) = C_0(u) + e·(C_0(u) − C_1(u)),
/// exact for ruled blades). The spacing between neighbouring sections is taken as 1/(K−1) of
/// the span.
fn extend_sections(ctrls: &mut Vec<Vec<Vector3<f64>>>, ext: f64) {
    let k = ctrls.len();
    if ext <= 0.0 || k < 2 {
        return;
    }
    let e = ext * (k - 1) as f64;
    let out = |a: &[Vector3<f64>], b: &[Vector3<f64>]| -> Vec<Vector3<f64>> {
        a.iter().zip(b).map(|(p, q)| p + (p - q) * e).collect()
    };
    let first = out(&ctrls[0], &ctrls[1]);
    let last = out(&ctrls[k - 1], &ctrls[k - 2]);
    if k == 2 {
        ctrls[0] = first;
        ctrls[1] = last;
    } else {
        ctrls.insert(0, first);
        ctrls.push(last);
    }
}

/// Turns prepared points into exact geometry within `tol_mm` (see the module docs), blade
/// sides extended beyond hub and shroud by `span_extension` × the span (0 keeps them at the
/// first and last section). A fit that cannot meet the tolerance (data with a kink, too few
/// points) is still returned; its achieved deviation is in the result, so callers compare
/// it with the tolerance.
pub fn fit(
    prepared: &PreparedImpeller,
    tol_mm: f64,
    span_extension: f64,
) -> Result<FittedImpeller, ImportError> {
    let err = |entity: String, reason: String| ImportError::Geometry {
        file: prepared.source.clone(),
        entity,
        reason,
    };
    if !(span_extension.is_finite() && (0.0..=0.5).contains(&span_extension)) {
        return Err(err(
            "span extension".into(),
            format!("{span_extension} is not a fraction within 0–0.5"),
        ));
    }
    if !(tol_mm.is_finite() && tol_mm > 0.0) {
        return Err(err(
            "fit tolerance".into(),
            format!("{tol_mm} mm is not a positive length"),
        ));
    }
    let (hub, hub_fit_mm) = fit_contour(&prepared.hub, tol_mm).map_err(|e| err("hub".into(), e))?;
    let (shroud, shroud_fit_mm) =
        fit_contour(&prepared.shroud, tol_mm).map_err(|e| err("shroud".into(), e))?;
    // Every side of every blade is fitted independently (rayon).
    let fit_side = |b: &super::prepare::PreparedBlade, pressure: bool| {
        let secs: Vec<Vec<Vector3<f64>>> = b
            .sections
            .iter()
            .map(|s| {
                if pressure {
                    s.pressure.clone()
                } else {
                    s.suction.clone()
                }
            })
            .collect();
        let entity = || {
            let name = if pressure { "pressure" } else { "suction" };
            format!("blade {:?} {name} side", b.name)
        };
        let (kv, mut ctrls, e) = fit_compatible(&secs, tol_mm).map_err(|r| err(entity(), r))?;
        extend_sections(&mut ctrls, span_extension);
        let surf = skin(&kv, &ctrls).map_err(|r| err(entity(), r))?;
        Ok::<_, ImportError>((surf, e))
    };
    let blades = prepared
        .blades
        .par_iter()
        .map(|b| {
            let (p, s) = rayon::join(|| fit_side(b, true), || fit_side(b, false));
            let ((pressure, pressure_fit_mm), (suction, suction_fit_mm)) = (p?, s?);
            Ok(FittedBlade {
                name: b.name.clone(),
                role: b.role,
                count: b.count,
                sections: b.sections.len(),
                pressure,
                suction,
                pressure_fit_mm,
                suction_fit_mm,
            })
        })
        .collect::<Result<Vec<_>, ImportError>>()?;
    Ok(FittedImpeller {
        source: prepared.source.clone(),
        hub,
        shroud,
        blades,
        hub_fit_mm,
        shroud_fit_mm,
        tol_mm,
    })
}
