//! Degree elevation (NURBS Book A5.9) of curves and of surfaces in either direction. The
//! shape is unchanged (to rounding, ≈1e-15 relative; tested to 1e-12); every distinct knot's
//! multiplicity grows by the elevation `t`, so continuity is preserved.

use crate::curve::NurbsCurve;
use crate::error::{Direction, NurbsError};
use crate::surface::NurbsSurface;
use crate::MAX_DEGREE;

fn check_target(p: usize, t: usize) -> Result<(), NurbsError> {
    if p + t > MAX_DEGREE {
        return Err(NurbsError::DegreeOutOfRange {
            degree: p + t,
            max: MAX_DEGREE,
        });
    }
    Ok(())
}

impl<const D: usize> NurbsCurve<D> {
    /// Raises the degree by `t` (NURBS Book A5.9: Bézier decomposition, elevation of each
    /// segment, knot removal, in one sweep; O(n p t D)). Unclamped curves are clamped
    /// first. Fails with [`NurbsError::DegreeOutOfRange`] above [`MAX_DEGREE`].
    pub fn elevate_degree(&self, t: usize) -> Result<Self, NurbsError> {
        check_target(self.degree(), t)?;
        let h = self.to_hspline().clamped().elevate(t);
        Self::from_hspline(&h, self.is_rational())
    }
}

impl NurbsSurface {
    /// Raises the degree in direction `dir` by `t` (NURBS Book A5.10 = A5.9 applied to every
    /// control line along `dir`). Unclamped directions are clamped first.
    pub fn elevate_degree(&self, dir: Direction, t: usize) -> Result<Self, NurbsError> {
        let p = match dir {
            Direction::U => self.degree_u(),
            Direction::V => self.degree_v(),
        };
        check_target(p, t)?;
        self.map_lines(dir, |h| h.clamped().elevate(t))
    }
}
