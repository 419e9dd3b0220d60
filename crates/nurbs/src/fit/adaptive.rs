//! Error-driven least-squares approximation of one or more *compatible* point sequences
//! (sections sharing one knot vector), with kinks in the data kept as C⁰ knots.
//!
//! The knot vector is not chosen from the point count alone (eq. 9.69's quantiles, which
//! spread knots evenly over the data and so cannot serve one dense region such as a blade's
//! leading edge without wasting knots everywhere else): it is *refined where the fit misses*,
//! the strategy of NURBS Book §9.4.1's closing remarks and of Piegl & Tiller's
//! error-bounded approximation (§9.4.2): start from the fewest knots, fit, and insert a knot
//! in every span whose data deviate more than the tolerance, splitting the span's data at
//! their median parameter so both halves keep data (Schoenberg–Whitney), until every data
//! point is within the tolerance or no span that misses can be split further.
//!
//! **Kinks.** A data point where the polyline's tangent turns by more than `kink_angle`
//! (angle between the chords before and after it) is a corner of the data. A C² cubic cannot
//! follow a corner; more knots only ring around it. Each kink becomes an interior knot of
//! full multiplicity p (the curve is C⁰ there and passes through a control point at the
//! corner). When every section has the same number of kinks, the parameters of each section
//! are remapped piecewise linearly so that the j-th kink of every section falls on one
//! parameter (their mean): the shared knot vector then carries each corner once.
//!
//! **Parameters.** Chord length per section (eq. 9.5); when every section has the same point
//! count and its kinks at the same indices, one averaged parameter per index (points of
//! equal index then lie on one iso-parametric line across the sections, as ruled blade
//! exports intend).
//!
//! **Solve.** Per section and per refinement, least squares with both end points fixed
//! (eqs. 9.63–9.67) by rank-revealing QR ([`super::solve`]); a rank-deficient system after a
//! refinement undoes it and refines the worst span alone, then freezes that span. So does a
//! regular but ill-conditioned one whose curve swings away from its data between two data
//! points (farther from their chord than the chord is long, [`FitError::Swing`]): the data
//! points alone do not see it.
//!
//! Cost: O(R · Σ_k m_k n²) for R refinement rounds (R ≈ log₂ of the final knot count when
//! misses are spread, more when they concentrate), m_k points per section, n control points.

use nalgebra::SVector;

use super::params::{check_finite, parameters};
use super::solve::solve_lstsq;
use super::{FitError, Parametrisation};
use crate::{KnotVector, NurbsCurve};
use faer::Mat;

/// Default corner angle of the data, radians (45°): a smooth curve sampled so coarsely that
/// its tangent turns by more than 45° between two chords is not resolved by its samples
/// anyway, while real corners (a blunt trailing edge face, a hub meeting a diffuser wall) turn
/// by 60–90°.
pub const DEFAULT_KINK_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

/// Two parameters closer than this (relative to the [0, 1] domain) are one knot: below it a
/// knot span holds no data that could tell the two apart.
const KNOT_MERGE_TOL: f64 = 1e-12;

/// The data point of a fit that lies farthest from its curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitMiss {
    /// Index of the section (0-based, in the order given).
    pub section: usize,
    /// Index of the point within its section (0-based).
    pub point: usize,
    /// Its distance from the curve at its parameter, in the data's length unit.
    pub distance: f64,
}

/// Compatible curves fitted to sections: one knot vector, each section's control points.
#[derive(Debug, Clone)]
pub struct CompatibleFit<const D: usize> {
    /// The shared clamped knot vector on [0, 1].
    pub knots: KnotVector,
    /// Control points of each section's curve (same count for all).
    pub ctrl: Vec<Vec<SVector<f64, D>>>,
    /// The data parameters used, per section.
    pub params: Vec<Vec<f64>>,
    /// Parameters of the C⁰ knots put at kinks of the data.
    pub kinks: Vec<f64>,
    /// The worst data point (an upper bound of every point's distance from its curve).
    pub worst: FitMiss,
}

impl<const D: usize> CompatibleFit<D> {
    /// Largest deviation of any data point from its curve at its parameter.
    pub fn max_error(&self) -> f64 {
        self.worst.distance
    }

    /// Section `k`'s curve.
    pub fn curve(&self, k: usize) -> Result<NurbsCurve<D>, FitError> {
        let ctrl = self.ctrl.get(k).ok_or(FitError::TooFewPoints {
            what: "sections",
            needed: k + 1,
            got: self.ctrl.len(),
        })?;
        Ok(NurbsCurve::from_knot_vector(
            self.knots.clone(),
            ctrl.clone(),
            None,
        )?)
    }
}

/// Interior indices of `points` where the tangent turns by more than `angle` at that point
/// alone: the turns at both neighbours are less than half of `angle`. A sampled smooth curve
/// turns gradually (a coarsely sampled leading-edge circle turns by a large angle at
/// several consecutive points, which is not a corner); a corner turns at one point.
fn kink_indices<const D: usize>(points: &[SVector<f64, D>], angle: f64) -> Vec<usize> {
    let turn = |k: usize| -> f64 {
        if k == 0 || k + 1 >= points.len() {
            return 0.0;
        }
        let a = points[k] - points[k - 1];
        let b = points[k + 1] - points[k];
        let d = a.norm() * b.norm();
        if d > 0.0 {
            (a.dot(&b) / d).clamp(-1.0, 1.0).acos()
        } else {
            0.0
        }
    };
    (1..points.len().saturating_sub(1))
        .filter(|&k| turn(k) > angle && turn(k - 1) < 0.5 * angle && turn(k + 1) < 0.5 * angle)
        .collect()
}

/// Piecewise-linear map of `u` taking the breakpoints `from` onto `to` (both increasing, with
/// 0 and 1 at the ends).
fn remap(u: f64, from: &[f64], to: &[f64]) -> f64 {
    let j = from.partition_point(|&b| b <= u).clamp(1, from.len() - 1);
    let (a, b) = (from[j - 1], from[j]);
    let t = if b > a { (u - a) / (b - a) } else { 0.0 };
    to[j - 1] + t * (to[j] - to[j - 1])
}

/// Least squares with both end points fixed on `kv`; the control points and each point's
/// deviation.
fn lsq_fixed_ends<const D: usize>(
    points: &[SVector<f64, D>],
    params: &[f64],
    kv: &KnotVector,
    row: &mut Vec<f64>,
) -> Result<(Vec<SVector<f64, D>>, Vec<f64>), FitError> {
    let m = points.len();
    let n = kv.n_ctrl();
    let (q0, qm) = (points[0], points[m - 1]);
    let mut ctrl = vec![q0; n];
    ctrl[n - 1] = qm;
    if n > 2 {
        let unknowns = n - 2;
        let rows = m.saturating_sub(2);
        let mut a = Mat::<f64>::zeros(rows, unknowns);
        let mut rhs = Mat::<f64>::zeros(rows, D);
        row.resize(n, 0.0);
        for k in 1..m - 1 {
            super::curve_interp::basis_row(kv, params[k], 0, row);
            for c in 0..unknowns {
                a[(k - 1, c)] = row[c + 1];
            }
            let fixed = points[k] - q0 * row[0] - qm * row[n - 1];
            for d in 0..D {
                rhs[(k - 1, d)] = fixed[d];
            }
        }
        let x = solve_lstsq(&a, &rhs)?;
        for (i, c) in ctrl.iter_mut().enumerate().skip(1).take(unknowns) {
            *c = SVector::<f64, D>::from_fn(|d, _| x[(i - 1, d)]);
        }
    }
    let curve = NurbsCurve::from_knot_vector(kv.clone(), ctrl.clone(), None)?;
    let errs: Vec<f64> = params
        .iter()
        .zip(points)
        .map(|(&u, q)| (curve.point(u) - q).norm())
        .collect();
    check_swing(&curve, points, params, &errs)?;
    Ok((ctrl, errs))
}

/// How far (relative to the chord `|Q_{i+1} − Q_i|`) the fitted curve's point halfway (in
/// parameter) between two consecutive data points may lie from their chord. A curve that
/// follows its data deviates by about the sagitta `|ΔQ|²·κ/8`, a small fraction of `|ΔQ|`
/// wherever the data resolve the curve (a circle sampled every 90° still stays within
/// `0.21·|ΔQ|`); beyond one chord length the curve swings.
const SWING_CHORDS: f64 = 1.0;

/// [`FitError::Swing`] when the curve's point halfway between two consecutive data
/// parameters lies farther from the segment between the two points than [`SWING_CHORDS`]
/// chords plus the curve's deviations `errs` at the two points (a coarse fit that misses
/// its data may lie that far off anyway), and more than `1e-9` of the data's extent. Least
/// squares with fixed ends bounds
/// the deviation *at* the data only: a knot span that a section's data barely reach (the
/// knots are shared by every section, refined where any section misses) leaves an
/// ill-conditioned system whose solution can swing metres away between two points
/// millimetres apart while every data point stays within tolerance. O(m) evaluations.
fn check_swing<const D: usize>(
    curve: &NurbsCurve<D>,
    points: &[SVector<f64, D>],
    params: &[f64],
    errs: &[f64],
) -> Result<(), FitError> {
    let extent = points
        .iter()
        .map(|q| (q - points[0]).norm())
        .fold(0.0, f64::max);
    for (i, (w, u)) in points.windows(2).zip(params.windows(2)).enumerate() {
        let (a, b) = (w[0], w[1]);
        let c = curve.point(0.5 * (u[0] + u[1]));
        let ab = b - a;
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            ((c - a).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let deviation = (c - (a + ab * t)).norm();
        let allowed = SWING_CHORDS * len2.sqrt() + errs[i] + errs[i + 1];
        // NaN (a curve evaluated to nothing) counts as a swing.
        if deviation.is_nan() || deviation > allowed.max(1e-9 * extent) {
            return Err(FitError::Swing {
                point: i,
                deviation,
            });
        }
    }
    Ok(())
}

/// One fit of every section on `kv`: control points, per-point deviations, worst point.
type Trial<const D: usize> = (Vec<Vec<SVector<f64, D>>>, Vec<Vec<f64>>, FitMiss);

fn fit_all<const D: usize>(
    sections: &[Vec<SVector<f64, D>>],
    params: &[Vec<f64>],
    kv: &KnotVector,
) -> Result<Trial<D>, FitError> {
    let mut row = Vec::new();
    let mut ctrls = Vec::with_capacity(sections.len());
    let mut errs = Vec::with_capacity(sections.len());
    let mut worst = FitMiss {
        section: 0,
        point: 0,
        distance: 0.0,
    };
    for (s, (pts, u)) in sections.iter().zip(params).enumerate() {
        let (c, e) = lsq_fixed_ends(pts, u, kv, &mut row)?;
        for (i, &d) in e.iter().enumerate() {
            if !d.is_finite() {
                return Err(FitError::NonFinitePoint { index: i });
            }
            if d > worst.distance {
                worst = FitMiss {
                    section: s,
                    point: i,
                    distance: d,
                };
            }
        }
        ctrls.push(c);
        errs.push(e);
    }
    Ok((ctrls, errs, worst))
}

/// Error-driven least-squares fit of compatible sections (see the module docs): one clamped
/// knot vector of `degree` (lowered to the smallest section's point count − 1) shared by
/// every section, each section's curve through its first and last point, interior knots
/// inserted where the data miss by more than `tol`, kinks (tangent turning by more than
/// `kink_angle`, radians) kept as knots of full multiplicity.
///
/// Returns the fit that meets `tol` at every data parameter, or — when some span that
/// misses cannot be split (it holds too few data, or splitting makes a section's system
/// singular) — the closest fit found, whose [`CompatibleFit::worst`] names the section, the
/// point and its distance so that the caller can report it.
///
/// Errors: no section, a section with fewer than 2 points, non-finite or consecutive
/// coincident points, `degree` 0, `tol` or `kink_angle` not positive and finite, or no
/// regular system even without interior knots.
///
/// When the kinks' C⁰ knots leave some section's system rank deficient (corners closer
/// together than that section's data can resolve), the fit is made without kink knots.
pub fn approximate_compatible<const D: usize>(
    sections: &[Vec<SVector<f64, D>>],
    degree: usize,
    tol: f64,
    kink_angle: f64,
) -> Result<CompatibleFit<D>, FitError> {
    match fit_refined(sections, degree, tol, Some(kink_angle)) {
        Err(FitError::SingularSystem { .. } | FitError::Swing { .. }) => {
            fit_refined(sections, degree, tol, None)
        }
        r => r,
    }
}

/// [`approximate_compatible`] with kinks detected at `kink_angle`, or ignored when `None`.
fn fit_refined<const D: usize>(
    sections: &[Vec<SVector<f64, D>>],
    degree: usize,
    tol: f64,
    kink_angle: Option<f64>,
) -> Result<CompatibleFit<D>, FitError> {
    if degree == 0 {
        return Err(FitError::InvalidDegree { degree });
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(FitError::InvalidValue {
            field: "tol",
            value: tol,
            reason: "must be finite and > 0",
        });
    }
    if let Some(a) = kink_angle.filter(|a| !(a.is_finite() && *a > 0.0)) {
        return Err(FitError::InvalidValue {
            field: "kink_angle",
            value: a,
            reason: "must be finite and > 0 (radians)",
        });
    }
    if sections.is_empty() {
        return Err(FitError::TooFewPoints {
            what: "sections",
            needed: 1,
            got: 0,
        });
    }
    let m_min = sections.iter().map(Vec::len).min().unwrap_or(0);
    if m_min < 2 {
        return Err(FitError::TooFewPoints {
            what: "points in a section",
            needed: 2,
            got: m_min,
        });
    }
    for s in sections {
        check_finite(s)?;
    }
    let p = degree.min(m_min - 1);
    let mut params: Vec<Vec<f64>> = sections
        .iter()
        .map(|s| parameters(s, Parametrisation::ChordLength))
        .collect::<Result<_, _>>()?;
    let kink_idx: Vec<Vec<usize>> = sections
        .iter()
        .map(|s| kink_angle.map_or_else(Vec::new, |a| kink_indices(s, a)))
        .collect();
    // Kinks aligned across sections when their counts agree, else all of them kept.
    let n_k = kink_idx[0].len();
    let mut kinks: Vec<f64>;
    if kink_idx.iter().all(|k| k.len() == n_k) {
        kinks = (0..n_k)
            .map(|j| {
                kink_idx
                    .iter()
                    .zip(&params)
                    .map(|(k, u)| u[k[j]])
                    .sum::<f64>()
                    / sections.len() as f64
            })
            .collect();
        let to: Vec<f64> = std::iter::once(0.0)
            .chain(kinks.iter().copied())
            .chain([1.0])
            .collect();
        for (u, k) in params.iter_mut().zip(&kink_idx) {
            let from: Vec<f64> = std::iter::once(0.0)
                .chain(k.iter().map(|&i| u[i]))
                .chain([1.0])
                .collect();
            for x in u.iter_mut() {
                *x = remap(*x, &from, &to);
            }
            for (j, &i) in k.iter().enumerate() {
                // Exactly on the knot, whatever the rounding of the map.
                u[i] = to[j + 1];
            }
        }
    } else {
        kinks = kink_idx
            .iter()
            .zip(&params)
            .flat_map(|(k, u)| k.iter().map(|&i| u[i]))
            .collect();
        kinks.sort_by(f64::total_cmp);
        kinks.dedup_by(|a, b| (*a - *b).abs() <= KNOT_MERGE_TOL);
    }
    let m0 = params[0].len();
    if params.iter().all(|u| u.len() == m0) && kink_idx.iter().all(|k| *k == kink_idx[0]) {
        let avg: Vec<f64> = (0..m0)
            .map(|i| params.iter().map(|u| u[i]).sum::<f64>() / params.len() as f64)
            .collect();
        for u in &mut params {
            u.clone_from(&avg);
        }
    }
    // Interior knots: kinks of multiplicity p, plus the refinements.
    let mut extra: Vec<f64> = Vec::new();
    let build = |extra: &[f64]| -> Result<KnotVector, FitError> {
        let mut interior: Vec<f64> = kinks
            .iter()
            .flat_map(|&k| std::iter::repeat_n(k, p))
            .chain(extra.iter().copied())
            .collect();
        interior.sort_by(f64::total_cmp);
        let mut knots = vec![0.0; p + 1];
        knots.extend(interior);
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        Ok(KnotVector::new(p, knots)?)
    };
    // All data parameters merged, sorted: where spans may be split.
    let mut all: Vec<f64> = params.iter().flatten().copied().collect();
    all.sort_by(f64::total_cmp);
    let mut kv = build(&extra)?;
    let (mut ctrl, mut errs, mut worst) = fit_all(sections, &params, &kv)?;
    let mut best = (kv.clone(), ctrl.clone(), worst);
    let mut frozen: Vec<(f64, f64)> = Vec::new();
    // Every round adds at least one knot or freezes one span; both are bounded by the data.
    let max_rounds = 2 * all.len() + 2;
    for _ in 0..max_rounds {
        if worst.distance <= tol {
            break;
        }
        // Worst deviation per distinct span.
        let breaks: Vec<f64> = {
            let mut b: Vec<f64> = kv.knots()[p..kv.knots().len() - p].to_vec();
            b.dedup();
            b
        };
        let mut span_err = vec![0.0_f64; breaks.len() - 1];
        for (u, e) in params.iter().zip(&errs) {
            for (&x, &d) in u.iter().zip(e) {
                let j = breaks
                    .partition_point(|&b| b <= x)
                    .clamp(1, breaks.len() - 1)
                    - 1;
                span_err[j] = span_err[j].max(d);
            }
        }
        // Split parameter of each missing span: the median of its data strictly inside.
        let mut splits: Vec<(f64, f64)> = Vec::new(); // (error, knot)
        for (j, &e) in span_err.iter().enumerate() {
            let (a, b) = (breaks[j], breaks[j + 1]);
            if e <= tol || frozen.iter().any(|&(fa, fb)| fa == a && fb == b) {
                continue;
            }
            let lo = all.partition_point(|&x| x <= a + KNOT_MERGE_TOL);
            let hi = all.partition_point(|&x| x < b - KNOT_MERGE_TOL);
            if hi <= lo + 1 {
                frozen.push((a, b));
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            // Between two neighbouring data parameters, so both halves hold data.
            let k = 0.5 * (all[mid - 1].max(a) + all[mid]);
            if k - a > KNOT_MERGE_TOL && b - k > KNOT_MERGE_TOL {
                splits.push((e, k));
            } else {
                frozen.push((a, b));
            }
        }
        if splits.is_empty() {
            break;
        }
        splits.sort_by(|x, y| y.0.total_cmp(&x.0));
        let mut trial = extra.clone();
        trial.extend(splits.iter().map(|s| s.1));
        let next = build(&trial).and_then(|k| fit_all(sections, &params, &k).map(|f| (k, f)));
        let accepted = match next {
            Ok(x) => Some((trial, x)),
            Err(_) => {
                // Singular with every split: try the worst span's split alone.
                let mut one = extra.clone();
                one.push(splits[0].1);
                match build(&one).and_then(|k| fit_all(sections, &params, &k).map(|f| (k, f))) {
                    Ok(x) => Some((one, x)),
                    Err(_) => {
                        let k = splits[0].1;
                        let j = breaks
                            .partition_point(|&b| b <= k)
                            .clamp(1, breaks.len() - 1);
                        frozen.push((breaks[j - 1], breaks[j]));
                        None
                    }
                }
            }
        };
        if let Some((e, (k, (c, r, w)))) = accepted {
            extra = e;
            kv = k;
            ctrl = c;
            errs = r;
            worst = w;
            if worst.distance < best.2.distance {
                best = (kv.clone(), ctrl.clone(), worst);
            }
        }
    }
    // Nested spline spaces make the last fit the best in the least-squares sense; the best
    // in the largest deviation is returned.
    let (knots, ctrl, worst) = best;
    Ok(CompatibleFit {
        knots,
        ctrl,
        params,
        kinks,
        worst,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// Data on the x axis every 1 (x = 0..4) and a cubic through them whose control points
    /// reach y = ±1000 in one span: every data point is on the curve, the curve swings far
    /// between two of them, which only the swing check sees.
    #[test]
    fn a_curve_that_passes_its_data_but_swings_between_them_is_refused() {
        let kv = KnotVector::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0],
        )
        .unwrap();
        let data: Vec<Vector2<f64>> = (0..=4).map(|i| Vector2::new(i as f64, 0.0)).collect();
        let params = [0.0, 0.25, 0.5, 0.75, 1.0];
        let straight: Vec<Vector2<f64>> = (0..7)
            .map(|i| Vector2::new(4.0 * i as f64 / 6.0, 0.0))
            .collect();
        let c = NurbsCurve::from_knot_vector(kv.clone(), straight.clone(), None).unwrap();
        let errs: Vec<f64> = params
            .iter()
            .zip(&data)
            .map(|(&u, q)| (c.point(u) - q).norm())
            .collect();
        assert!(check_swing(&c, &data, &params, &errs).is_ok());
        // The first span's inner control points pushed up and down by 1000·B₂(¼) and
        // −1000·B₁(¼): their effect B₁y₁ + B₂y₂ vanishes at the one data parameter inside that
        // span; u = 0 and the C⁰ knot u = ½ sit on unchanged control points.
        let mut bent = straight;
        let (b1, b2) = {
            let mut row = vec![0.0; kv.n_ctrl()];
            crate::fit::curve_interp::basis_row(&kv, 0.25, 0, &mut row);
            (row[1], row[2])
        };
        bent[1].y = 1000.0 * b2;
        bent[2].y = -1000.0 * b1;
        let c = NurbsCurve::from_knot_vector(kv, bent, None).unwrap();
        let errs: Vec<f64> = params
            .iter()
            .zip(&data)
            .map(|(&u, q)| (c.point(u) - q).norm())
            .collect();
        assert!(errs.iter().all(|e| *e < 1e-9), "{errs:?}");
        match check_swing(&c, &data, &params, &errs) {
            Err(FitError::Swing { point, deviation }) => {
                assert!(point <= 1 && deviation > 10.0, "{point} {deviation}")
            }
            other => panic!("{other:?}"),
        }
    }
}
