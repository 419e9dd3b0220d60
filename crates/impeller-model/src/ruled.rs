//! Ruled and sub-ruled approximation of (free-form) blade sides (paper 001, "Generation of the
//! approximated ruled surface blade" and "Generation of the sub-ruled surface blades").
//!
//! **Ruled approximation.** For a side S(u, v) and two isoparametric lines v = a (hub edge) and
//! v = b (shroud edge), the ruled surface R(u, w) = (1 − w) S(u, a) + w S(u, b) shares both edge
//! curves exactly: each isocurve of a NURBS surface is a NURBS curve on the same u knots whose
//! homogeneous control points are Σ_j N_{j,q}(v) P^w_{ij} (NURBS Book §3.4/§4.4), so R is an
//! exact NURBS of degree (p, 1). The *deviation* of the true side from R at a true point
//! P = S(u, v) is e = (P − Q)·n_out with Q the closest point of R (hint (u, (v − a)/(b − a)))
//! and n_out R's normal oriented like the side's outward normal. e > 0 means the true blade
//! bulges out of R: machining R would cut the blade by e. Hence the "blade with thickness": R
//! machined with an allowance of `allowance_mm = max(0, max e)` along its outward normal never
//! cuts the true blade. The maximum is found on an 81 × 17 parameter grid (rayon over rows) and
//! refined by alternating golden-section searches in u and v around the best sample.
//!
//! **Sub-ruled strips.** From the shroud edge down to the hub edge, each strip [v_k+1, v_k] is
//! the widest whose ruled surface stays within `tol` (bisection on its lower bound to 0.2 % of
//! the v range, deviation sampled 41 × 5 and refined by one golden-section round). Since a strip's deviation grows with its width, this
//! greedy choice yields the fewest strips. Each strip's ruled surface and measured deviation
//! are reported.

use crate::blade::{Blade, Side};
use crate::error::ModelError;
use crate::query::closest_point;
use nalgebra::{Vector3, Vector4};
use nurbs::NurbsSurface;
use rayon::prelude::*;

/// Which way the true blade deviates from its ruled approximation at the largest deviation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeviationSide {
    /// The true side lies outside the ruled surface (machining it would cut the blade).
    Outside,
    /// The true side lies inside the ruled surface (material would be left).
    Inside,
}

/// Ruled approximation of one blade side.
#[derive(Debug, Clone)]
pub struct RuledApproximation {
    /// The approximated side.
    pub side: Side,
    /// Side parameters v of the shared hub (first) and shroud (second) edge curves.
    pub v_range: (f64, f64),
    /// The ruled surface R(u, w), w = 0 on the hub edge, 1 on the shroud edge.
    pub surface: NurbsSurface,
    /// Largest |deviation| of the true side from R (mm).
    pub max_deviation_mm: f64,
    /// Side parameters (u, v) of the largest deviation.
    pub max_deviation_at: (f64, f64),
    /// Where the true side lies at the largest deviation.
    pub deviation_side: DeviationSide,
    /// Largest outward deviation, ≥ 0: the allowance that keeps R from cutting the blade.
    pub allowance_mm: f64,
    /// Largest inward deviation, ≥ 0 (material R leaves on the blade).
    pub max_inward_mm: f64,
}

/// One sub-ruled strip.
#[derive(Debug, Clone)]
pub struct RuledStrip {
    /// Side parameters v of the strip's lower (hub-side) and upper edge.
    pub v_range: (f64, f64),
    /// Its ruled surface (w = 0 lower edge).
    pub surface: NurbsSurface,
    /// Largest |deviation| of the true side from it (mm).
    pub max_deviation_mm: f64,
}

/// The isocurve v = const of `s` as homogeneous control points on the u knots.
fn iso_v(s: &NurbsSurface, v: f64) -> Vec<Vector4<f64>> {
    let kv = s.knots_v();
    let q = kv.degree();
    let span = kv.find_span(v);
    let mut basis = vec![0.0; q + 1];
    kv.basis_funs(span, v, &mut basis);
    (0..s.n_u())
        .map(|i| {
            let mut acc = Vector4::zeros();
            for (l, &b) in basis.iter().enumerate() {
                let j = span - q + l;
                let p = s.control_point(i, j);
                let w = s.weight(i, j);
                acc += Vector4::new(p.x * w, p.y * w, p.z * w, w) * b;
            }
            acc
        })
        .collect()
}

/// The exact ruled surface between the isocurves v = a and v = b of `s`.
pub fn ruled_between_isocurves(
    s: &NurbsSurface,
    a: f64,
    b: f64,
) -> Result<NurbsSurface, ModelError> {
    let ca = iso_v(s, a);
    let cb = iso_v(s, b);
    let rational = s.is_rational();
    let mut ctrl = Vec::with_capacity(ca.len());
    let mut weights = Vec::with_capacity(ca.len());
    for (pa, pb) in ca.iter().zip(&cb) {
        ctrl.push(vec![
            Vector3::new(pa.x / pa.w, pa.y / pa.w, pa.z / pa.w),
            Vector3::new(pb.x / pb.w, pb.y / pb.w, pb.z / pb.w),
        ]);
        weights.push(vec![pa.w, pb.w]);
    }
    let (_, (v0, v1)) = s.domain();
    if !(v0..=v1).contains(&a) || !(v0..=v1).contains(&b) || a >= b {
        return Err(ModelError::Geometry(format!(
            "ruled strip v range ({a}, {b}) must be increasing inside ({v0}, {v1})"
        )));
    }
    Ok(NurbsSurface::new(
        s.degree_u(),
        1,
        s.knots_u().knots().to_vec(),
        vec![0.0, 0.0, 1.0, 1.0],
        ctrl,
        rational.then_some(weights),
    )?)
}

/// The ruled surface `r` (degree 1 in v, two rows of control points: w = 0 and w = 1) with
/// every ruling prolonged beyond both edges along its own line: the result at w′ ∈ [0, 1] is
/// `r` at w = −`below` + w′·(1 + `below` + `above`) (fractions of each ruling's length), built
/// exactly by extrapolating the two rows of homogeneous control points. The rulings are the
/// same lines, so an offset of the prolonged surface meets surfaces (depth levels) that lie
/// beyond the hub or shroud edge of `r` by up to those fractions of a ruling.
///
/// Errors: `r` is not a two-row ruled surface, a fraction is negative or not finite, or a
/// weight of a rational `r` would not stay positive.
pub fn prolong_rulings(
    r: &NurbsSurface,
    below: f64,
    above: f64,
) -> Result<NurbsSurface, ModelError> {
    if r.n_v() != 2 || r.knots_v().degree() != 1 {
        return Err(ModelError::Geometry(
            "prolonging rulings needs a ruled surface of degree 1 in v with two rows".into(),
        ));
    }
    if !(below.is_finite() && above.is_finite() && below >= 0.0 && above >= 0.0) {
        return Err(ModelError::invalid(
            "ruling prolongation",
            "must be finite and ≥ 0",
        ));
    }
    let (_, (v0, v1)) = r.domain();
    let rational = r.is_rational();
    let mut ctrl = Vec::with_capacity(r.n_u());
    let mut weights = Vec::with_capacity(r.n_u());
    for i in 0..r.n_u() {
        let h = |j: usize| {
            let p = r.control_point(i, j);
            let w = r.weight(i, j);
            Vector4::new(p.x * w, p.y * w, p.z * w, w)
        };
        let (h0, h1) = (h(0), h(1));
        let lo = h0 * (1.0 + below) - h1 * below;
        let hi = h1 * (1.0 + above) - h0 * above;
        if !(lo.w > 0.0 && hi.w > 0.0) {
            return Err(ModelError::Geometry(format!(
                "prolonged ruling {i} has a non-positive weight"
            )));
        }
        ctrl.push(vec![
            Vector3::new(lo.x / lo.w, lo.y / lo.w, lo.z / lo.w),
            Vector3::new(hi.x / hi.w, hi.y / hi.w, hi.z / hi.w),
        ]);
        weights.push(vec![lo.w, hi.w]);
    }
    Ok(NurbsSurface::new(
        r.degree_u(),
        1,
        r.knots_u().knots().to_vec(),
        vec![v0, v0, v1, v1],
        ctrl,
        rational.then_some(weights),
    )?)
}

/// Signed deviation (see module docs) of the true side at (u, v) from ruled `r` over [a, b].
fn deviation(
    blade: &Blade,
    side: Side,
    r: &NurbsSurface,
    (a, b): (f64, f64),
    u: f64,
    v: f64,
) -> f64 {
    let s = blade.side(side);
    let p = s.point(u, v);
    let w = ((v - a) / (b - a)).clamp(0.0, 1.0);
    let sp = closest_point(r, &p, Some((u, w)));
    let n = r
        .normal(sp.u, sp.v)
        .map(|n| n * blade.outward_sign(side))
        .unwrap_or_else(Vector3::zeros);
    let e = (p - sp.point).dot(&n);
    if e >= 0.0 {
        sp.distance
    } else {
        -sp.distance
    }
}

fn golden_max(mut lo: f64, mut hi: f64, iters: usize, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = hi - g * (hi - lo);
    let mut d = lo + g * (hi - lo);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iters {
        if fc > fd {
            hi = d;
            d = c;
            fd = fc;
            c = hi - g * (hi - lo);
            fc = f(c);
        } else {
            lo = c;
            c = d;
            fc = fd;
            d = lo + g * (hi - lo);
            fd = f(d);
        }
    }
    let x = 0.5 * (lo + hi);
    (x, f(x))
}

/// Extremes of the deviation over [u-domain] × [a, b]: (max e with (u,v), min e with (u,v)).
fn deviation_extremes(
    blade: &Blade,
    side: Side,
    r: &NurbsSurface,
    (a, b): (f64, f64),
    nu: usize,
    nv: usize,
    (rounds, iters): (usize, usize),
) -> ((f64, f64, f64), (f64, f64, f64)) {
    let ((u0, u1), _) = blade.side(side).domain();
    let samples: Vec<(f64, f64, f64)> = (0..nu)
        .into_par_iter()
        .flat_map_iter(|i| {
            let u = u0 + (u1 - u0) * i as f64 / (nu - 1) as f64;
            (0..nv).map(move |j| {
                let v = a + (b - a) * j as f64 / (nv - 1) as f64;
                (u, v, deviation(blade, side, r, (a, b), u, v))
            })
        })
        .collect();
    let du = (u1 - u0) / (nu - 1) as f64;
    let dv = (b - a) / (nv - 1) as f64;
    let refine = |sign: f64| {
        let best = samples
            .iter()
            .copied()
            .fold((0.0, 0.0, f64::NEG_INFINITY), |acc, s| {
                if sign * s.2 > acc.2 {
                    (s.0, s.1, sign * s.2)
                } else {
                    acc
                }
            });
        let (mut u, mut v, mut e) = best;
        for _ in 0..rounds {
            let (nu_, eu) = golden_max((u - du).max(u0), (u + du).min(u1), iters, |x| {
                sign * deviation(blade, side, r, (a, b), x, v)
            });
            if eu > e {
                u = nu_;
                e = eu;
            }
            let (nv_, ev) = golden_max((v - dv).max(a), (v + dv).min(b), iters, |y| {
                sign * deviation(blade, side, r, (a, b), u, y)
            });
            if ev > e {
                v = nv_;
                e = ev;
            }
        }
        (u, v, sign * e)
    };
    (refine(1.0), refine(-1.0))
}

/// The ruled approximation of `side` between its isocurves v = `v_range.0` (hub edge) and
/// v = `v_range.1` (shroud edge); see module docs.
pub fn ruled_approximation(
    blade: &Blade,
    side: Side,
    v_range: (f64, f64),
) -> Result<RuledApproximation, ModelError> {
    let r = ruled_between_isocurves(blade.side(side), v_range.0, v_range.1)?;
    let (hi, lo) = deviation_extremes(blade, side, &r, v_range, 81, 17, (3, 40));
    let allowance = hi.2.max(0.0);
    let inward = (-lo.2).max(0.0);
    let (at, dev_side) = if allowance >= inward {
        ((hi.0, hi.1), DeviationSide::Outside)
    } else {
        ((lo.0, lo.1), DeviationSide::Inside)
    };
    Ok(RuledApproximation {
        side,
        v_range,
        surface: r,
        max_deviation_mm: allowance.max(inward),
        max_deviation_at: at,
        deviation_side: dev_side,
        allowance_mm: allowance,
        max_inward_mm: inward,
    })
}

fn strip_deviation(
    blade: &Blade,
    side: Side,
    a: f64,
    b: f64,
) -> Result<(NurbsSurface, f64), ModelError> {
    let r = ruled_between_isocurves(blade.side(side), a, b)?;
    let (hi, lo) = deviation_extremes(blade, side, &r, (a, b), 41, 5, (1, 20));
    Ok((r, hi.2.max(0.0).max(-lo.2)))
}

/// The fewest sub-ruled strips covering `v_range` of `side`, each within `tol_mm` of its
/// ruled surface, listed from the shroud (highest v) down to the hub. Errors when `tol_mm` is
/// not positive or more than 64 strips would be needed.
pub fn sub_ruled_strips(
    blade: &Blade,
    side: Side,
    v_range: (f64, f64),
    tol_mm: f64,
) -> Result<Vec<RuledStrip>, ModelError> {
    if !(tol_mm.is_finite() && tol_mm > 0.0) {
        return Err(ModelError::invalid("tol_mm", "must be > 0"));
    }
    let (a, b) = v_range;
    let mut top = b;
    let mut strips = Vec::new();
    while top > a {
        if strips.len() >= 64 {
            return Err(ModelError::Geometry(format!(
                "more than 64 sub-ruled strips needed for tolerance {tol_mm} mm"
            )));
        }
        let (r, dev) = strip_deviation(blade, side, a, top)?;
        if dev <= tol_mm {
            strips.push(RuledStrip {
                v_range: (a, top),
                surface: r,
                max_deviation_mm: dev,
            });
            break;
        }
        // Bisection for the lowest bound whose strip meets the tolerance.
        let (mut ok, mut bad) = (top - 1e-6 * (b - a), a);
        let mut ok_strip = strip_deviation(blade, side, ok, top)?;
        for _ in 0..40 {
            let mid = 0.5 * (ok + bad);
            let s = strip_deviation(blade, side, mid, top)?;
            if s.1 <= tol_mm {
                ok = mid;
                ok_strip = s;
            } else {
                bad = mid;
            }
            if ok - bad < 2e-3 * (b - a) {
                break;
            }
        }
        strips.push(RuledStrip {
            v_range: (ok, top),
            surface: ok_strip.0,
            max_deviation_mm: ok_strip.1,
        });
        top = ok;
    }
    Ok(strips)
}

impl Blade {
    /// Side parameters v of the hub and shroud edges: the design values for parametric blades,
    /// the whole v domain of the side otherwise (for imported blades prefer
    /// [`crate::Impeller::span_v_range`], which finds the isocurves enclosing the part between
    /// hub and shroud).
    pub fn hub_shroud_v(&self, side: Side) -> (f64, f64) {
        match self.design() {
            Some(d) => d.span_v,
            None => self.side(side).domain().1,
        }
    }
}
