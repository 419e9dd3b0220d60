//! Global curve interpolation (NURBS Book A9.1, §9.2.1–9.2.2).

use faer::Mat;
use nalgebra::SVector;

use super::params::{averaged_knots, check_finite, parameters};
use super::solve::solve_lstsq;
use super::{FitError, Parametrisation};
use crate::{KnotVector, NurbsCurve};

/// Writes the `order`-th derivatives of all `n_ctrl` basis functions at `u` into `row`
/// (zero outside the `degree + 1` non-zero ones). Uses A2.1 + A2.3 of the core.
pub(crate) fn basis_row(kv: &KnotVector, u: f64, order: usize, row: &mut [f64]) {
    row.iter_mut().for_each(|r| *r = 0.0);
    let p = kv.degree();
    let span = kv.find_span(u);
    let ders = kv.ders_basis_funs(span, u, order);
    for (j, &v) in ders[order].iter().enumerate().take(p + 1) {
        if let Some(slot) = row.get_mut(span + j - p) {
            *slot = v;
        }
    }
}

/// Smallest plain interpolation solved by the banded elimination. Below it the dense QR is
/// kept: it costs little there, and it keeps every smaller fit bit for bit what it was (the
/// banded solve agrees to round-off only, and round-off in the roughing's depth levels was
/// enough to move an AutoGrid fixture's level count from 8 to 9).
pub const BANDED_MIN_POINTS: usize = 1024;

/// Solves the collocation system `Σ_i N_i^{(k_r)}(u_r) P_i = b_r` for the control points.
pub(crate) fn collocate<const D: usize>(
    kv: &KnotVector,
    n_ctrl: usize,
    rows: &[(f64, usize, SVector<f64, D>)],
) -> Result<Vec<SVector<f64, D>>, FitError> {
    // Plain interpolation (values only, as many sites as control points) of
    // `BANDED_MIN_POINTS` or more: the banded elimination ([`super::banded`]); the dense QR
    // where it declines and for smaller systems, where it costs little.
    if rows.len() == n_ctrl && n_ctrl >= BANDED_MIN_POINTS && rows.iter().all(|r| r.1 == 0) {
        let sites: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let values: Vec<SVector<f64, D>> = rows.iter().map(|r| r.2).collect();
        if let Some(x) = super::banded::solve_collocation(kv, &sites, &values) {
            return Ok(x);
        }
    }
    let mut a = Mat::<f64>::zeros(rows.len(), n_ctrl);
    let mut b = Mat::<f64>::zeros(rows.len(), D);
    let mut row = vec![0.0; n_ctrl];
    for (r, (u, order, value)) in rows.iter().enumerate() {
        basis_row(kv, *u, *order, &mut row);
        for (c, &v) in row.iter().enumerate() {
            a[(r, c)] = v;
        }
        for d in 0..D {
            b[(r, d)] = value[d];
        }
    }
    let x = solve_lstsq(&a, &b)?;
    Ok((0..n_ctrl)
        .map(|i| SVector::<f64, D>::from_fn(|d, _| x[(i, d)]))
        .collect())
}

/// Global interpolation of `points` by a non-rational B-spline curve of `degree` on [0, 1]
/// (NURBS Book A9.1).
///
/// Parameters ū_k come from `parametrisation` (eqs. 9.3/9.5/9.6); knots by averaging
/// (eq. 9.8). With `end_derivatives = Some((d0, dn))` two more control points are added and
/// the curve also satisfies `C'(0) = d0`, `C'(1) = dn` (derivatives with respect to the
/// [0, 1] parameter, §9.2.2, knots by eq. 9.22). A useful scale for the derivative
/// magnitudes is the total chord length.
///
/// Without end derivatives and with [`BANDED_MIN_POINTS`] points or more the banded system
/// is solved by elimination without pivoting (stable for this totally positive matrix,
/// [`super::banded`]), O(n·p²); otherwise, or where a pivot is too small, by column-pivoted
/// QR, O(n³). The curve passes through every
/// point to round-off (1e-12 relative for well-spaced data).
///
/// Errors: degree 0, fewer than `degree + 1` points (`degree - 1` with end derivatives, and
/// at least two), non-finite data, coincident consecutive points (chord-based
/// parametrisations).
pub fn interpolate_curve<const D: usize>(
    points: &[SVector<f64, D>],
    degree: usize,
    parametrisation: Parametrisation,
    end_derivatives: Option<(SVector<f64, D>, SVector<f64, D>)>,
) -> Result<NurbsCurve<D>, FitError> {
    if degree == 0 {
        return Err(FitError::InvalidDegree { degree });
    }
    let needed = if end_derivatives.is_some() {
        degree.saturating_sub(1).max(2)
    } else {
        degree + 1
    };
    if points.len() < needed {
        return Err(FitError::TooFewPoints {
            what: "points",
            needed,
            got: points.len(),
        });
    }
    let params = parameters(points, parametrisation)?;
    let knots = averaged_knots(&params, degree, end_derivatives.is_some());
    let n_ctrl = knots.len() - degree - 1;
    let kv = KnotVector::new(degree, knots.clone())?;
    let mut rows: Vec<(f64, usize, SVector<f64, D>)> = params
        .iter()
        .zip(points)
        .map(|(&u, q)| (u, 0, *q))
        .collect();
    if let Some((d0, dn)) = end_derivatives {
        check_finite(&[d0, dn]).map_err(|_| FitError::NonFinitePoint {
            index: points.len(),
        })?;
        rows.push((0.0, 1, d0));
        rows.push((1.0, 1, dn));
    }
    let mut ctrl = collocate(&kv, n_ctrl, &rows)?;
    // End points are interpolated exactly by a clamped curve; remove round-off.
    ctrl[0] = points[0];
    if let Some(last) = points.last() {
        ctrl[n_ctrl - 1] = *last;
    }
    Ok(NurbsCurve::new(degree, knots, ctrl, None)?)
}
