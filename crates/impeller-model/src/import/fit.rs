//! Exact geometry from prepared export points: meridional contours and blade sides as
//! non-rational B-splines fitted within a stated tolerance.
//!
//! - **Hub and shroud**: the meridional (z, r) points are approximated by a cubic B-spline
//!   with fixed end points, chord-length parameters, knots inserted where the fit misses the
//!   data (`nurbs::fit::approximate_compatible`, NURBS Book §9.4.1–9.4.2).
//! - **Blade sides**: all sections of one side are fitted *compatibly* by the same function:
//!   one clamped cubic knot vector shared by every section; chord-length parameters per
//!   section, or their average per index when all sections have the same point count (points
//!   of equal index then lie on one iso-parametric line across the span, as AutoGrid's ruled
//!   sides intend); least squares with fixed leading- and trailing-edge points
//!   (eqs. 9.63–9.67); knots inserted at the median data parameter of every span that misses
//!   the tolerance, so a finely sampled leading edge gets knots where it needs them; data
//!   corners (tangent turning by more than `nurbs::fit::DEFAULT_KINK_ANGLE` = 45°) kept as
//!   knots of full multiplicity, aligned across sections. A fit that cannot meet the
//!   tolerance (a span too sparse to split) is still returned with its worst data point
//!   ([`DataMiss`]) and [`super::build::check_tolerance`] rejects it naming that point.
//!   The compatible section curves are then skinned (§10.3): the control points of each
//!   index are interpolated across the sections at averaged chord-length parameters v̄_k
//!   with knots by averaging (eq. 9.8), degree min(3, sections − 1). The surface reproduces
//!   each section curve exactly at v = v̄_k, so its deviation from the data points is the
//!   section fit's (reported per side). u runs from leading to trailing edge, v from hub
//!   to shroud.
//!
//! Cost: O(m·n²) per least-squares solve (m data points, n control points), O(log n) rounds
//! of refinement per side; skinning O(K³ + n·K) for K sections.

use super::error::ImportError;
use super::prepare::PreparedImpeller;
use super::raw::{positive, BladeRole};
use nalgebra::{DMatrix, Vector2, Vector3};
use nurbs::fit::{approximate_compatible, averaged_knots, FitMiss, DEFAULT_KINK_ANGLE};
use nurbs::{Curve2, KnotVector, NurbsSurface};
use rayon::prelude::*;
use std::path::PathBuf;

/// Default fit tolerance, mm.
pub const DEFAULT_FIT_TOL_MM: f64 = 0.01;

/// A shared knot vector, each section's control points, and the worst data point.
type CompatibleFit = (KnotVector, Vec<Vec<Vector3<f64>>>, DataMiss);

/// The data point that lies farthest from its fitted curve or surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DataMiss {
    /// Section index, 0-based from the hub (0 for hub and shroud contours).
    pub section: usize,
    /// Point index within the section, 0-based from the leading edge (contours: from the
    /// inlet end).
    pub point: usize,
    /// The point, mm, workpiece frame (contours: (0, r, z), the meridional plane y–z).
    pub at_mm: Vector3<f64>,
    /// Its distance from the fit at its parameter, mm (an upper bound of its distance from
    /// the curve or surface).
    pub distance_mm: f64,
}

impl DataMiss {
    fn new(m: FitMiss, at: impl Fn(usize, usize) -> Vector3<f64>) -> Self {
        Self {
            section: m.section,
            point: m.point,
            at_mm: at(m.section, m.point),
            distance_mm: m.distance,
        }
    }
}

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
    /// The pressure-side data point farthest from the surface.
    pub pressure_miss: DataMiss,
    /// The suction-side data point farthest from the surface.
    pub suction_miss: DataMiss,
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
    /// The hub data point farthest from its curve.
    pub hub_miss: DataMiss,
    /// The shroud data point farthest from its curve.
    pub shroud_miss: DataMiss,
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

/// Fits all `sections` (each LE → TE) with one shared knot vector within `tol`
/// (`nurbs::fit::approximate_compatible`: error-driven knots, kinks as C⁰ knots): returns
/// the knot vector, each section's control points and the worst data point.
fn fit_compatible(sections: &[Vec<Vector3<f64>>], tol: f64) -> Result<CompatibleFit, String> {
    let f = approximate_compatible(sections, DEGREE, tol, DEFAULT_KINK_ANGLE)
        .map_err(|e| e.to_string())?;
    let miss = DataMiss::new(f.worst, |s, i| sections[s][i]);
    Ok((f.knots, f.ctrl, miss))
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

/// Fits a meridional contour within `tol` (error-driven knots, kinks such as a hub meeting
/// a diffuser wall kept as C⁰ knots).
fn fit_contour(points: &[Vector2<f64>], tol: f64) -> Result<(Curve2, DataMiss), String> {
    let data = [points.to_vec()];
    let f = approximate_compatible(&data, DEGREE, tol, DEFAULT_KINK_ANGLE)
        .map_err(|e| e.to_string())?;
    let curve = f.curve(0).map_err(|e| e.to_string())?;
    let miss = DataMiss::new(f.worst, |_, i| Vector3::new(0.0, points[i].y, points[i].x));
    Ok((curve, miss))
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
    let (hub, hub_miss) = fit_contour(&prepared.hub, tol_mm).map_err(|e| err("hub".into(), e))?;
    let (shroud, shroud_miss) =
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
            let ((pressure, pressure_miss), (suction, suction_miss)) = (p?, s?);
            Ok(FittedBlade {
                name: b.name.clone(),
                role: b.role,
                count: b.count,
                sections: b.sections.len(),
                pressure,
                suction,
                pressure_fit_mm: pressure_miss.distance_mm,
                suction_fit_mm: suction_miss.distance_mm,
                pressure_miss,
                suction_miss,
            })
        })
        .collect::<Result<Vec<_>, ImportError>>()?;
    Ok(FittedImpeller {
        source: prepared.source.clone(),
        hub,
        shroud,
        blades,
        hub_fit_mm: hub_miss.distance_mm,
        shroud_fit_mm: shroud_miss.distance_mm,
        hub_miss,
        shroud_miss,
        tol_mm,
    })
}
