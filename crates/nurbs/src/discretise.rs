//! Arc length of curves and discretisation of curves into points: by arc-length step, by
//! parameter step and by chord tolerance.
//!
//! Arc length is `∫ |C'(u)| du`, integrated per knot span (where the curve is smooth) by
//! adaptive 8-point Gauss–Legendre: a piece is accepted when its two halves agree with the
//! whole to the requested tolerance, otherwise both halves are refined. For polynomial and
//! rational pieces the integrand is analytic, so convergence is very fast (a rational
//! quarter circle reaches 1e-15 relative after one or two levels).

use nalgebra::SVector;

use crate::NurbsCurve;

/// Why a length or discretisation could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DiscretiseError {
    /// A step or tolerance was not finite and positive.
    #[error("`{field}` = {value} must be finite and > 0")]
    InvalidValue {
        /// Name of the argument.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// The parameter interval lies outside the curve's domain or is reversed.
    #[error("parameter interval [{a}, {b}] is not inside the domain [{lo}, {hi}]")]
    InvalidInterval {
        /// Start requested.
        a: f64,
        /// End requested.
        b: f64,
        /// Domain start.
        lo: f64,
        /// Domain end.
        hi: f64,
    },
    /// The step would produce more than [`MAX_POINTS`] points.
    #[error("the requested step would produce {count} points (limit {limit})")]
    TooManyPoints {
        /// Points that would be produced.
        count: f64,
        /// The limit ([`MAX_POINTS`]).
        limit: usize,
    },
}

/// Largest number of points a discretisation may produce (guards against a step given in
/// the wrong unit exhausting memory).
pub const MAX_POINTS: usize = 10_000_000;

/// 8-point Gauss–Legendre nodes on [-1, 1].
pub(crate) const GL8_X: [f64; 8] = [
    -0.960_289_856_497_536_2,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_2,
];
/// 8-point Gauss–Legendre weights.
pub(crate) const GL8_W: [f64; 8] = [
    0.101_228_536_290_376_3,
    0.222_381_034_453_374_5,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Maximum bisection depth of the adaptive quadrature and chord refinement.
const MAX_DEPTH: usize = 40;

/// A point of a discretised curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveSample<const D: usize> {
    /// Curve parameter.
    pub u: f64,
    /// `C(u)`.
    pub point: SVector<f64, D>,
}

fn check_positive(field: &'static str, value: f64) -> Result<(), DiscretiseError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(DiscretiseError::InvalidValue { field, value })
    }
}

fn speed<const D: usize>(curve: &NurbsCurve<D>, u: f64) -> f64 {
    curve.derivs(u, 1).get(1).map_or(0.0, |d| d.norm())
}

/// 8-point Gauss–Legendre estimate of the length of `C` over `[a, b]`.
fn gl8<const D: usize>(curve: &NurbsCurve<D>, a: f64, b: f64) -> f64 {
    let (xs, ws) = (&GL8_X, &GL8_W);
    let half = 0.5 * (b - a);
    let mid = 0.5 * (a + b);
    xs.iter()
        .zip(ws)
        .map(|(x, w)| w * speed(curve, mid + half * x))
        .sum::<f64>()
        * half
}

/// Adaptive refinement of `[a, b]` whose 8-point estimate is `whole`; pushes accepted
/// pieces `(end parameter, length)` onto `out`.
fn adapt<const D: usize>(
    curve: &NurbsCurve<D>,
    a: f64,
    b: f64,
    whole: f64,
    tol: f64,
    depth: usize,
    out: &mut Vec<(f64, f64)>,
) {
    let m = 0.5 * (a + b);
    let left = gl8(curve, a, m);
    let right = gl8(curve, m, b);
    // The tolerance cannot go below the round-off of the estimates themselves.
    let tol = tol.max(16.0 * f64::EPSILON * whole.abs());
    if (left + right - whole).abs() <= tol || depth >= MAX_DEPTH || m <= a || m >= b {
        out.push((m, left));
        out.push((b, right));
    } else {
        adapt(curve, a, m, left, 0.5 * tol, depth + 1, out);
        adapt(curve, m, b, right, 0.5 * tol, depth + 1, out);
    }
}

/// Cumulative arc-length table of a curve, for lengths and for the inverse map length →
/// parameter.
///
/// Built by adaptive Gauss–Legendre per knot span (see the module docs) to the absolute
/// tolerance `tol` (mm) on the total length. Inversion `s ↦ u` is Newton's method on
/// `s(u) − s* = 0` (`s'(u) = |C'(u)|`) safeguarded by bisection inside the table piece, to
/// `1e-14` relative. Memory O(pieces).
#[derive(Debug, Clone)]
pub struct ArcLengthTable<'a, const D: usize> {
    curve: &'a NurbsCurve<D>,
    /// `(u_i, s_i)`, strictly increasing in `u`, `s_0 = 0`.
    nodes: Vec<(f64, f64)>,
}

impl<'a, const D: usize> ArcLengthTable<'a, D> {
    /// Builds the table over the whole domain with absolute tolerance `tol` (mm).
    pub fn new(curve: &'a NurbsCurve<D>, tol: f64) -> Result<Self, DiscretiseError> {
        let (lo, hi) = curve.domain();
        Self::between(curve, lo, hi, tol)
    }

    /// Builds the table over `[a, b]` ⊆ domain.
    pub fn between(
        curve: &'a NurbsCurve<D>,
        a: f64,
        b: f64,
        tol: f64,
    ) -> Result<Self, DiscretiseError> {
        check_positive("tol", tol)?;
        let (lo, hi) = curve.domain();
        if !(a.is_finite() && b.is_finite() && lo <= a && a <= b && b <= hi) {
            return Err(DiscretiseError::InvalidInterval { a, b, lo, hi });
        }
        let mut breaks = vec![a];
        for &k in curve.knots().knots() {
            if k > a && k < b && breaks.last().is_some_and(|&l| k > l) {
                breaks.push(k);
            }
        }
        breaks.push(b);
        let spans = (breaks.len() - 1).max(1) as f64;
        let mut pieces = Vec::new();
        for w in breaks.windows(2) {
            if w[1] > w[0] {
                let whole = gl8(curve, w[0], w[1]);
                adapt(curve, w[0], w[1], whole, tol / spans, 0, &mut pieces);
            }
        }
        let mut nodes = Vec::with_capacity(pieces.len() + 1);
        nodes.push((a, 0.0));
        let mut s = 0.0;
        for (u, len) in pieces {
            s += len;
            nodes.push((u, s));
        }
        Ok(Self { curve, nodes })
    }

    /// Total length of the tabulated interval.
    pub fn length(&self) -> f64 {
        self.nodes.last().map_or(0.0, |n| n.1)
    }

    /// Arc length from the start of the table to parameter `u` (clamped to the interval).
    pub fn length_at(&self, u: f64) -> f64 {
        let (first, last) = (self.nodes[0], self.nodes[self.nodes.len() - 1]);
        let u = u.clamp(first.0, last.0);
        let i = self.nodes.partition_point(|n| n.0 <= u).saturating_sub(1);
        let (u0, s0) = self.nodes[i];
        if u <= u0 {
            return s0;
        }
        s0 + gl8(self.curve, u0, u)
    }

    /// Parameter at which the arc length from the start equals `s` (clamped to
    /// `[0, length]`).
    pub fn param_at_length(&self, s: f64) -> f64 {
        let total = self.length();
        let s = s.clamp(0.0, total);
        let i = self
            .nodes
            .partition_point(|n| n.1 < s)
            .clamp(1, self.nodes.len() - 1);
        let (ua, sa) = self.nodes[i - 1];
        let (ub, sb) = self.nodes[i];
        if sb <= sa {
            return ua;
        }
        let (mut lo, mut hi) = (ua, ub);
        let mut u = ua + (ub - ua) * (s - sa) / (sb - sa);
        for _ in 0..60 {
            let f = sa + gl8(self.curve, ua, u) - s;
            if f > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            let d = speed(self.curve, u);
            let mut next = if d > 0.0 { u - f / d } else { 0.5 * (lo + hi) };
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - u).abs() <= 1e-14 * (1.0 + u.abs()) {
                return next;
            }
            u = next;
        }
        u
    }
}

/// Length of the whole curve to absolute tolerance `tol` (mm). See [`ArcLengthTable`].
pub fn arc_length<const D: usize>(curve: &NurbsCurve<D>, tol: f64) -> Result<f64, DiscretiseError> {
    Ok(ArcLengthTable::new(curve, tol)?.length())
}

/// Length of `C` over `[a, b]` ⊆ domain to absolute tolerance `tol` (mm).
pub fn arc_length_between<const D: usize>(
    curve: &NurbsCurve<D>,
    a: f64,
    b: f64,
    tol: f64,
) -> Result<f64, DiscretiseError> {
    Ok(ArcLengthTable::between(curve, a, b, tol)?.length())
}

fn count_for(span: f64, step: f64) -> Result<usize, DiscretiseError> {
    let count = (span / step).ceil().max(1.0);
    if count > MAX_POINTS as f64 {
        return Err(DiscretiseError::TooManyPoints {
            count,
            limit: MAX_POINTS,
        });
    }
    Ok(count as usize)
}

/// Points at equal arc-length spacing `L/n` with `n = ⌈L/step⌉` (so the spacing is ≤ `step`
/// and both end points are included). Lengths to 1e-9 relative of `L` (table tolerance);
/// O(n · log pieces) Newton inversions.
pub fn discretise_by_arc_length<const D: usize>(
    curve: &NurbsCurve<D>,
    step: f64,
) -> Result<Vec<CurveSample<D>>, DiscretiseError> {
    check_positive("step", step)?;
    let table = ArcLengthTable::new(curve, 1e-12)?;
    let total = table.length();
    let n = count_for(total, step)?;
    let (lo, hi) = curve.domain();
    Ok((0..=n)
        .map(|k| {
            let u = match k {
                0 => lo,
                k if k == n => hi,
                k => table.param_at_length(total * k as f64 / n as f64),
            };
            CurveSample {
                u,
                point: curve.point(u),
            }
        })
        .collect())
}

/// Points at equal parameter spacing `(b−a)/n`, `n = ⌈(b−a)/step⌉` (both ends included).
pub fn discretise_by_parameter<const D: usize>(
    curve: &NurbsCurve<D>,
    step: f64,
) -> Result<Vec<CurveSample<D>>, DiscretiseError> {
    check_positive("step", step)?;
    let (lo, hi) = curve.domain();
    let n = count_for(hi - lo, step)?;
    Ok((0..=n)
        .map(|k| {
            let u = if k == n {
                hi
            } else {
                lo + (hi - lo) * k as f64 / n as f64
            };
            CurveSample {
                u,
                point: curve.point(u),
            }
        })
        .collect())
}

/// Distance from `p` to the segment `[a, b]` in any dimension (to `a` when the segment is a
/// point). O(D).
pub fn point_segment_distance<const D: usize>(
    p: &SVector<f64, D>,
    a: &SVector<f64, D>,
    b: &SVector<f64, D>,
) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Polyline whose deviation from the curve is at most `chord_tol` (mm).
///
/// Every knot span is first split into `degree + 1` equal pieces (so each piece turns by a
/// bounded amount); a piece `[u0, u1]` is then bisected while any of the curve points at
/// `u0 + (u1−u0)·{1/4, 1/2, 3/4}` lies farther than `chord_tol` from the chord. The check is
/// by sampling (three points per piece, on pieces of at most a fraction of a knot span), which
/// is reliable for the smooth pieces of a NURBS; the returned points include all knots.
pub fn discretise_by_chord<const D: usize>(
    curve: &NurbsCurve<D>,
    chord_tol: f64,
) -> Result<Vec<CurveSample<D>>, DiscretiseError> {
    check_positive("chord_tol", chord_tol)?;
    let (lo, hi) = curve.domain();
    let mut breaks = vec![lo];
    for &k in curve.knots().knots() {
        if k > lo && k < hi && breaks.last().is_some_and(|&l| k > l) {
            breaks.push(k);
        }
    }
    breaks.push(hi);
    let pieces = curve.degree() + 1;
    let mut out = vec![CurveSample {
        u: lo,
        point: curve.point(lo),
    }];
    for w in breaks.windows(2) {
        for k in 0..pieces {
            let a = w[0] + (w[1] - w[0]) * k as f64 / pieces as f64;
            let b = if k + 1 == pieces {
                w[1]
            } else {
                w[0] + (w[1] - w[0]) * (k + 1) as f64 / pieces as f64
            };
            refine_chord(curve, a, b, chord_tol, 0, &mut out)?;
        }
    }
    Ok(out)
}

fn refine_chord<const D: usize>(
    curve: &NurbsCurve<D>,
    a: f64,
    b: f64,
    tol: f64,
    depth: usize,
    out: &mut Vec<CurveSample<D>>,
) -> Result<(), DiscretiseError> {
    let pa = out.last().map_or_else(|| curve.point(a), |s| s.point);
    let pb = curve.point(b);
    let bad = depth < MAX_DEPTH
        && [0.25, 0.5, 0.75].iter().any(|t| {
            let p = curve.point(a + (b - a) * t);
            point_segment_distance(&p, &pa, &pb) > tol
        });
    if bad {
        let m = 0.5 * (a + b);
        refine_chord(curve, a, m, tol, depth + 1, out)?;
        refine_chord(curve, m, b, tol, depth + 1, out)?;
    } else {
        if out.len() >= MAX_POINTS {
            return Err(DiscretiseError::TooManyPoints {
                count: out.len() as f64 + 1.0,
                limit: MAX_POINTS,
            });
        }
        out.push(CurveSample { u: b, point: pb });
    }
    Ok(())
}
