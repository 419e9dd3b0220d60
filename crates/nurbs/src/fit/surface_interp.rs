//! Global surface interpolation through a rectangular grid of points (NURBS Book A9.4).

use faer::Mat;
use nalgebra::Vector3;

use super::curve_interp::basis_row;
use super::params::averaged_knots;
use super::solve::solve_lstsq;
use super::{FitError, Parametrisation};
use crate::{KnotVector, NurbsSurface};

/// Parameters for a family of point rows: each row's chord-based parameters (eqs. 9.5/9.6),
/// averaged over the rows (eq. 9.15–9.16); rows of zero length (poles) are skipped.
pub(crate) fn averaged_params(
    lines: &[Vec<Vector3<f64>>],
    method: Parametrisation,
) -> Result<Vec<f64>, FitError> {
    let len = lines.first().map_or(0, Vec::len);
    let n = len.saturating_sub(1);
    let uniform: Vec<f64> = (0..=n).map(|k| k as f64 / n.max(1) as f64).collect();
    if method == Parametrisation::Uniform {
        return Ok(uniform);
    }
    let mut sum = vec![0.0; len];
    let mut used = 0usize;
    for line in lines {
        let mut acc = vec![0.0; len];
        for k in 1..len {
            let c = (line[k] - line[k - 1]).norm();
            let c = if method == Parametrisation::Centripetal {
                c.sqrt()
            } else {
                c
            };
            acc[k] = acc[k - 1] + c;
        }
        let total = acc[n];
        if total > 0.0 {
            used += 1;
            for (s, a) in sum.iter_mut().zip(&acc) {
                *s += a / total;
            }
        }
    }
    if used == 0 {
        return Err(FitError::CoincidentPoints { index: 0 });
    }
    let mut params: Vec<f64> = sum.iter().map(|s| s / used as f64).collect();
    params[n] = 1.0;
    if let Some(index) = params.windows(2).position(|w| w[1] <= w[0]) {
        return Err(FitError::CoincidentPoints { index });
    }
    Ok(params)
}

/// Interpolates `columns.len()` families of points at the same parameters with one factored
/// system: returns, for each family, the control points of the interpolating curve.
pub(crate) fn interpolate_families<const W: usize>(
    kv: &KnotVector,
    params: &[f64],
    families: &[Vec<nalgebra::SVector<f64, W>>],
) -> Result<Vec<Vec<nalgebra::SVector<f64, W>>>, FitError> {
    let n = params.len();
    let mut a = Mat::<f64>::zeros(n, n);
    let mut row = vec![0.0; n];
    for (r, &u) in params.iter().enumerate() {
        basis_row(kv, u, 0, &mut row);
        for (c, &v) in row.iter().enumerate() {
            a[(r, c)] = v;
        }
    }
    let mut b = Mat::<f64>::zeros(n, W * families.len());
    for (f, fam) in families.iter().enumerate() {
        for (k, p) in fam.iter().enumerate() {
            for d in 0..W {
                b[(k, W * f + d)] = p[d];
            }
        }
    }
    let x = solve_lstsq(&a, &b)?;
    Ok((0..families.len())
        .map(|f| {
            (0..n)
                .map(|i| nalgebra::SVector::<f64, W>::from_fn(|d, _| x[(i, W * f + d)]))
                .collect()
        })
        .collect())
}

/// Global interpolation of a `(n+1) × (m+1)` grid `points[k][l]` (`k` along u, `l` along v)
/// by a non-rational B-spline surface of degrees `(degree_u, degree_v)` on `[0, 1]²`
/// (NURBS Book A9.4): parameters averaged over rows/columns (eqs. 9.15–9.16), knots by
/// averaging (eq. 9.8), then curve interpolation along u for every l followed by curve
/// interpolation along v of the resulting control points. Each direction factors its matrix
/// once. `S(ū_k, v̄_l) = Q_{k,l}` to round-off. O(n³ + m³ + n·m·(n+m)).
///
/// Errors: a degree of 0, fewer than `degree + 1` rows or columns, a ragged grid, non-finite
/// points, coincident averaged parameters.
pub fn interpolate_surface(
    points: &[Vec<Vector3<f64>>],
    degree_u: usize,
    degree_v: usize,
    parametrisation: Parametrisation,
) -> Result<NurbsSurface, FitError> {
    for degree in [degree_u, degree_v] {
        if degree == 0 {
            return Err(FitError::InvalidDegree { degree });
        }
    }
    let rows = points.len();
    let cols = points.first().map_or(0, Vec::len);
    if rows < degree_u + 1 {
        return Err(FitError::TooFewPoints {
            what: "grid rows (u)",
            needed: degree_u + 1,
            got: rows,
        });
    }
    for (row, line) in points.iter().enumerate() {
        if line.len() != cols {
            return Err(FitError::RaggedGrid {
                row,
                expected: cols,
                got: line.len(),
            });
        }
    }
    if cols < degree_v + 1 {
        return Err(FitError::TooFewPoints {
            what: "grid columns (v)",
            needed: degree_v + 1,
            got: cols,
        });
    }
    for (k, line) in points.iter().enumerate() {
        if let Some(l) = line.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(FitError::NonFinitePoint {
                index: k * cols + l,
            });
        }
    }
    // Lines along u (fixed l) and along v (fixed k).
    let u_lines: Vec<Vec<Vector3<f64>>> = (0..cols)
        .map(|l| points.iter().map(|row| row[l]).collect())
        .collect();
    let u_params = averaged_params(&u_lines, parametrisation)?;
    let v_params = averaged_params(points, parametrisation)?;
    let knots_u = averaged_knots(&u_params, degree_u, false);
    let knots_v = averaged_knots(&v_params, degree_v, false);
    let kv_u = KnotVector::new(degree_u, knots_u.clone())?;
    let kv_v = KnotVector::new(degree_v, knots_v.clone())?;
    // R[l][i]: control points of the u-curve through column l.
    let r = interpolate_families(&kv_u, &u_params, &u_lines)?;
    // For each i, interpolate R[·][i] along v.
    let v_lines: Vec<Vec<Vector3<f64>>> = (0..rows)
        .map(|i| (0..cols).map(|l| r[l][i]).collect())
        .collect();
    let ctrl = interpolate_families(&kv_v, &v_params, &v_lines)?;
    Ok(NurbsSurface::new(
        degree_u, degree_v, knots_u, knots_v, ctrl, None,
    )?)
}

/// Global interpolation of the grid `points[k][l]` (`k` along u, `l` along v) at given
/// parameters `u_params[k]`, `v_params[l]` (each strictly increasing, any range) by a
/// non-rational B-spline surface of degrees `(degree_u, degree_v)` on
/// `[u_params[0], u_params[n]] × [v_params[0], v_params[m]]`: knots by averaging (eq. 9.8,
/// clamped to the parameter range), then A9.4 as in [`interpolate_surface`] (one factored
/// system per direction). `S(u_params[k], v_params[l]) = points[k][l]` to round-off.
///
/// Errors: a degree of 0, fewer than `degree + 1` parameters in a direction, a grid whose size
/// is not `u_params.len() × v_params.len()` ([`FitError::RaggedGrid`]), non-finite points or
/// parameters ([`FitError::NonFinitePoint`], [`FitError::InvalidValue`]), parameters that do
/// not increase strictly ([`FitError::CoincidentPoints`] at the first offending index).
/// More rows than u parameters is an [`FitError::InvalidValue`].
pub fn interpolate_surface_at(
    points: &[Vec<Vector3<f64>>],
    u_params: &[f64],
    v_params: &[f64],
    degree_u: usize,
    degree_v: usize,
) -> Result<NurbsSurface, FitError> {
    let mut knots = Vec::with_capacity(2);
    for (degree, params, what) in [
        (degree_u, u_params, "grid rows (u)"),
        (degree_v, v_params, "grid columns (v)"),
    ] {
        if degree == 0 {
            return Err(FitError::InvalidDegree { degree });
        }
        if params.len() < degree + 1 {
            return Err(FitError::TooFewPoints {
                what,
                needed: degree + 1,
                got: params.len(),
            });
        }
        if let Some(index) = params.iter().position(|p| !p.is_finite()) {
            return Err(FitError::InvalidValue {
                field: "interpolation parameter",
                value: params[index],
                reason: "must be finite",
            });
        }
        if let Some(index) = params.windows(2).position(|w| w[1] <= w[0]) {
            return Err(FitError::CoincidentPoints { index });
        }
        let mut k = averaged_knots(params, degree, false);
        let m = k.len();
        k[..=degree].fill(params[0]);
        k[m - degree - 1..].fill(params[params.len() - 1]);
        knots.push(k);
    }
    let (rows, cols) = (u_params.len(), v_params.len());
    if points.len() < rows {
        // The first missing row has no points.
        return Err(FitError::RaggedGrid {
            row: points.len(),
            expected: cols,
            got: 0,
        });
    }
    if points.len() > rows {
        return Err(FitError::InvalidValue {
            field: "number of grid rows",
            value: points.len() as f64,
            reason: "must equal the number of u parameters",
        });
    }
    for (row, line) in points.iter().enumerate() {
        if line.len() != cols {
            return Err(FitError::RaggedGrid {
                row,
                expected: cols,
                got: line.len(),
            });
        }
        if let Some(l) = line.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(FitError::NonFinitePoint {
                index: row * cols + l,
            });
        }
    }
    let knots_v = knots.pop().unwrap_or_default();
    let knots_u = knots.pop().unwrap_or_default();
    let kv_u = KnotVector::new(degree_u, knots_u.clone())?;
    let kv_v = KnotVector::new(degree_v, knots_v.clone())?;
    let u_lines: Vec<Vec<Vector3<f64>>> = (0..cols)
        .map(|l| points.iter().map(|row| row[l]).collect())
        .collect();
    let r = interpolate_families(&kv_u, u_params, &u_lines)?;
    let v_lines: Vec<Vec<Vector3<f64>>> = (0..rows)
        .map(|i| (0..cols).map(|l| r[l][i]).collect())
        .collect();
    let ctrl = interpolate_families(&kv_v, v_params, &v_lines)?;
    Ok(NurbsSurface::new(
        degree_u, degree_v, knots_u, knots_v, ctrl, None,
    )?)
}
