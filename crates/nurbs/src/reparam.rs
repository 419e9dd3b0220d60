//! Parametrisation changes that keep the geometry: clamping, reversal, linear
//! reparametrisation to a new domain, swapping a surface's parameters.

use crate::curve::NurbsCurve;
use crate::error::{Direction, NurbsError};
use crate::homogeneous::HSpline;
use crate::knots::KnotVector;
use crate::surface::NurbsSurface;

/// Knots mapped affinely from `[a, b]` to `[c, d]`, with the end knots set exactly.
fn map_knots(knots: &[f64], (a, b): (f64, f64), (c, d): (f64, f64)) -> Vec<f64> {
    let s = (d - c) / (b - a);
    knots
        .iter()
        .map(|&k| {
            if k == a {
                c
            } else if k == b {
                d
            } else {
                c + (k - a) * s
            }
        })
        .collect()
}

fn check_domain(c: f64, d: f64) -> Result<(), NurbsError> {
    if !(c.is_finite() && d.is_finite() && c < d) {
        return Err(NurbsError::EmptyDomain { start: c, end: d });
    }
    Ok(())
}

fn reversed_knots(knots: &[f64], (a, b): (f64, f64)) -> Vec<f64> {
    knots
        .iter()
        .rev()
        .map(|&k| {
            if k == a {
                b
            } else if k == b {
                a
            } else {
                a + b - k
            }
        })
        .collect()
}

impl<const D: usize> NurbsCurve<D> {
    /// The same curve with a clamped knot vector (end knots of multiplicity `p + 1`, the
    /// curve interpolates its end control points). Exact: knot insertion at the domain ends
    /// (A5.1), then the knots and points outside the domain are dropped. Returns a clone if
    /// already clamped.
    pub fn clamped(&self) -> Result<Self, NurbsError> {
        if self.knots().is_clamped() {
            return Ok(self.clone());
        }
        Self::from_hspline(&self.to_hspline().clamped(), self.is_rational())
    }

    /// The reversed curve `C'(u) = C(a + b − u)` on the same domain `[a, b]` (knots
    /// `u'_i = a + b − u_{m−i}`, control points and weights in reverse order; O(n)).
    pub fn reverse(&self) -> Result<Self, NurbsError> {
        let kv = KnotVector::new(
            self.degree(),
            reversed_knots(self.knots().knots(), self.domain()),
        )?;
        let ctrl = self.control_points().iter().rev().copied().collect();
        let w = self.weights().map(|w| w.iter().rev().copied().collect());
        Self::from_knot_vector(kv, ctrl, w)
    }

    /// Linear reparametrisation onto `[c, d]`: `C'(c + (u − a)(d − c)/(b − a)) = C(u)`.
    /// Only the knots change (O(m)); derivatives scale by `(b − a)/(d − c)` per order.
    pub fn reparametrize(&self, c: f64, d: f64) -> Result<Self, NurbsError> {
        check_domain(c, d)?;
        let kv = KnotVector::new(
            self.degree(),
            map_knots(self.knots().knots(), self.domain(), (c, d)),
        )?;
        Self::from_knot_vector(
            kv,
            self.control_points().to_vec(),
            self.weights().map(<[f64]>::to_vec),
        )
    }
}

impl NurbsSurface {
    /// The same surface with clamped knot vectors in both directions (see
    /// [`NurbsCurve::clamped`]).
    pub fn clamped(&self) -> Result<Self, NurbsError> {
        let mut s = self.clone();
        if !s.knots_u().is_clamped() {
            s = s.map_lines(Direction::U, HSpline::clamped)?;
        }
        if !s.knots_v().is_clamped() {
            s = s.map_lines(Direction::V, HSpline::clamped)?;
        }
        Ok(s)
    }

    /// Reverses the direction `dir`: `S'(u, v) = S(a + b − u, v)` for `U` (or the same in
    /// `v`). Flips the normal.
    pub fn reverse(&self, dir: Direction) -> Result<Self, NurbsError> {
        let (n_u, n_v) = (self.n_u(), self.n_v());
        let (ku, kv) = match dir {
            Direction::U => (
                KnotVector::new(
                    self.degree_u(),
                    reversed_knots(self.knots_u().knots(), self.knots_u().domain()),
                )?,
                self.knots_v().clone(),
            ),
            Direction::V => (
                self.knots_u().clone(),
                KnotVector::new(
                    self.degree_v(),
                    reversed_knots(self.knots_v().knots(), self.knots_v().domain()),
                )?,
            ),
        };
        let src = |i: usize, j: usize| match dir {
            Direction::U => (n_u - 1 - i) * n_v + j,
            Direction::V => i * n_v + (n_v - 1 - j),
        };
        let ctrl = (0..n_u * n_v)
            .map(|k| self.control_points()[src(k / n_v, k % n_v)])
            .collect();
        let w = self
            .weights()
            .map(|w| (0..n_u * n_v).map(|k| w[src(k / n_v, k % n_v)]).collect());
        NurbsSurface::from_flat(ku, kv, ctrl, w)
    }

    /// Linear reparametrisation of direction `dir` onto `[c, d]` (knots only).
    pub fn reparametrize(&self, dir: Direction, c: f64, d: f64) -> Result<Self, NurbsError> {
        check_domain(c, d)?;
        let (ku, kv) = match dir {
            Direction::U => (
                KnotVector::new(
                    self.degree_u(),
                    map_knots(self.knots_u().knots(), self.knots_u().domain(), (c, d)),
                )?,
                self.knots_v().clone(),
            ),
            Direction::V => (
                self.knots_u().clone(),
                KnotVector::new(
                    self.degree_v(),
                    map_knots(self.knots_v().knots(), self.knots_v().domain(), (c, d)),
                )?,
            ),
        };
        NurbsSurface::from_flat(
            ku,
            kv,
            self.control_points().to_vec(),
            self.weights().map(<[f64]>::to_vec),
        )
    }

    /// Exchanges the parameters: `S'(v, u) = S(u, v)` (transposed net; flips the normal).
    pub fn swap_uv(&self) -> Result<Self, NurbsError> {
        let (n_u, n_v) = (self.n_u(), self.n_v());
        let idx = |k: usize| (k % n_u) * n_v + k / n_u;
        let ctrl = (0..n_u * n_v)
            .map(|k| self.control_points()[idx(k)])
            .collect();
        let w = self
            .weights()
            .map(|w| (0..n_u * n_v).map(|k| w[idx(k)]).collect());
        NurbsSurface::from_flat(self.knots_v().clone(), self.knots_u().clone(), ctrl, w)
    }
}
