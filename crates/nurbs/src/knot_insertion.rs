//! Knot insertion (NURBS Book A5.1), knot refinement (A5.4) and splitting, for curves and
//! for surfaces in either direction. All three leave the geometry unchanged: they work in
//! homogeneous space with convex combinations, so the new representation reproduces the
//! old one to rounding (≈1e-15 relative; tested to 1e-12).

use crate::curve::NurbsCurve;
use crate::error::{Direction, NurbsError};
use crate::homogeneous::HSpline;
use crate::knots::KnotVector;
use crate::surface::NurbsSurface;

/// Checks that every value of the sorted list `xs` lies strictly inside the domain and
/// that no knot's multiplicity would exceed the degree.
fn check_insertions(kv: &KnotVector, xs: &[f64]) -> Result<(), NurbsError> {
    let (a, b) = kv.domain();
    let p = kv.degree();
    let mut i = 0;
    while i < xs.len() {
        let x = xs[i];
        if !(x > a && x < b) {
            return Err(NurbsError::ParameterOutOfDomain {
                value: x,
                start: a,
                end: b,
            });
        }
        let mut j = i;
        while j < xs.len() && xs[j] == x {
            j += 1;
        }
        let times = j - i;
        let multiplicity = kv.multiplicity(x);
        if multiplicity + times > p {
            return Err(NurbsError::InsertionExceedsMultiplicity {
                value: x,
                times,
                multiplicity,
                degree: p,
            });
        }
        i = j;
    }
    Ok(())
}

fn sorted(xs: &[f64]) -> Vec<f64> {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    v
}

impl HSpline {
    /// Splits at interior `u` (inserted up to multiplicity `p` first): left piece on
    /// `[a, u]`, right piece on `[u, b]`, both clamped at `u`.
    pub(crate) fn split_at(&self, u: f64) -> (HSpline, HSpline) {
        let p = self.p;
        let s = self.knots.iter().filter(|&&k| k == u).count();
        let ins = self.insert(u, p - s.min(p));
        let f = ins.knots.partition_point(|&k| k < u);
        let mut left_knots = ins.knots[..f + p].to_vec();
        left_knots.push(u);
        let left_pts = ins.pts[..f * self.dim].to_vec();
        let mut right_knots = vec![u];
        right_knots.extend_from_slice(&ins.knots[f..]);
        let right_pts = ins.pts[(f - 1) * self.dim..].to_vec();
        (
            HSpline {
                p,
                knots: left_knots,
                pts: left_pts,
                dim: self.dim,
            },
            HSpline {
                p,
                knots: right_knots,
                pts: right_pts,
                dim: self.dim,
            },
        )
    }
}

impl<const D: usize> NurbsCurve<D> {
    /// Inserts the knot `u` `times` times without changing the curve (NURBS Book A5.1,
    /// O(times · p · D + n D)). `u` must lie strictly inside the domain and its
    /// multiplicity must stay `<= p`.
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<Self, NurbsError> {
        check_insertions(self.knots(), &vec![u; times])?;
        Self::from_hspline(&self.to_hspline().insert(u, times), self.is_rational())
    }

    /// Inserts all knots of `x` (any order; repeated values insert repeatedly) in one pass
    /// without changing the curve (NURBS Book A5.4, O((n + r) p D)).
    pub fn refine_knots(&self, x: &[f64]) -> Result<Self, NurbsError> {
        let x = sorted(x);
        check_insertions(self.knots(), &x)?;
        Self::from_hspline(&self.to_hspline().refine(&x), self.is_rational())
    }

    /// Splits the curve at the interior parameter `u` into a curve on `[a, u]` and one on
    /// `[u, b]` that together reproduce it (knot insertion to multiplicity `p`, A5.1;
    /// O(p² D + n D)). Both pieces are clamped at `u`.
    pub fn split(&self, u: f64) -> Result<(Self, Self), NurbsError> {
        let (a, b) = self.domain();
        if !(u > a && u < b) {
            return Err(NurbsError::ParameterOutOfDomain {
                value: u,
                start: a,
                end: b,
            });
        }
        let (l, r) = self.to_hspline().split_at(u);
        let rational = self.is_rational();
        Ok((
            Self::from_hspline(&l, rational)?,
            Self::from_hspline(&r, rational)?,
        ))
    }
}

impl NurbsSurface {
    fn knots_in(&self, dir: Direction) -> &KnotVector {
        match dir {
            Direction::U => self.knots_u(),
            Direction::V => self.knots_v(),
        }
    }

    /// Inserts the knot `u` (a `v` value when `dir` is `V`) `times` times without changing
    /// the surface (NURBS Book A5.3 = A5.1 applied to every control line along `dir`).
    pub fn insert_knot(&self, dir: Direction, u: f64, times: usize) -> Result<Self, NurbsError> {
        check_insertions(self.knots_in(dir), &vec![u; times])?;
        self.map_lines(dir, |h| h.insert(u, times))
    }

    /// Knot refinement in direction `dir` (NURBS Book A5.5 = A5.4 on every control line).
    pub fn refine_knots(&self, dir: Direction, x: &[f64]) -> Result<Self, NurbsError> {
        let x = sorted(x);
        check_insertions(self.knots_in(dir), &x)?;
        self.map_lines(dir, |h| h.refine(&x))
    }

    /// Splits the surface at the interior parameter `t` of direction `dir` into the part
    /// with parameter `<= t` and the part with parameter `>= t`.
    pub fn split(&self, dir: Direction, t: f64) -> Result<(Self, Self), NurbsError> {
        let (a, b) = self.knots_in(dir).domain();
        if !(t > a && t < b) {
            return Err(NurbsError::ParameterOutOfDomain {
                value: t,
                start: a,
                end: b,
            });
        }
        Ok((
            self.map_lines(dir, |h| h.split_at(t).0)?,
            self.map_lines(dir, |h| h.split_at(t).1)?,
        ))
    }
}
