//! Global B-spline interpolation of sampled design geometry (NURBS Book §9.2.1, A9.1, and the
//! tensor-product surface interpolation of §9.2.5, A9.4).
//!
//! Given points Q_k at parameters ū_k (strictly increasing) and a degree p, the knots are the
//! averages of p consecutive parameters (eq. 9.8) and the control points solve the collocation
//! system Σ_i N_{i,p}(ū_k) P_i = Q_k. The collocation matrix is factorised once (dense LU,
//! O(n³) with n ≤ a few hundred here) and reused for every row of a surface net, so a surface
//! costs one factorisation per direction plus O(n²) per row. The interpolant passes through
//! every sample exactly (to round-off); between samples its error is O(h^{p+1}).

use crate::error::ModelError;
use nalgebra::{DMatrix, Vector3};
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};

/// The clamped knot vector by averaging (NURBS Book eq. 9.8) for `params` and `degree`.
pub fn averaged_knots(params: &[f64], degree: usize) -> Result<KnotVector, ModelError> {
    let n = params.len();
    if n <= degree {
        return Err(ModelError::Geometry(format!(
            "interpolation needs more than {degree} samples, got {n}"
        )));
    }
    // One home for the averaging: the `nurbs` crate's (eq. 9.8, clamped to [0, 1]); its
    // interior knots are the same sums in the same order, so only the clamped ends change to
    // this parameter range's ends.
    let (a, b) = (params[0], params[n - 1]);
    let mut knots = nurbs::fit::averaged_knots(params, degree, false);
    let m = knots.len();
    knots[..=degree].fill(a);
    knots[m - degree - 1..].fill(b);
    Ok(KnotVector::new(degree, knots)?)
}

/// A factorised collocation system: interpolates any number of point rows at fixed parameters.
#[derive(Debug, Clone)]
pub struct Interpolator {
    knots: KnotVector,
    lu: nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
}

impl Interpolator {
    /// Sets up interpolation at `params` (strictly increasing) with `degree`.
    pub fn new(params: &[f64], degree: usize) -> Result<Self, ModelError> {
        for w in params.windows(2) {
            if w[1] <= w[0] || !w[0].is_finite() || !w[1].is_finite() {
                return Err(ModelError::Geometry(
                    "interpolation parameters must increase strictly".into(),
                ));
            }
        }
        let knots = averaged_knots(params, degree)?;
        let n = params.len();
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut basis = vec![0.0; degree + 1];
        for (k, &u) in params.iter().enumerate() {
            let span = knots.find_span(u);
            knots.basis_funs(span, u, &mut basis);
            for (l, &b) in basis.iter().enumerate() {
                a[(k, span - degree + l)] = b;
            }
        }
        Ok(Self { knots, lu: a.lu() })
    }

    /// The knot vector of every interpolant.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// Control points interpolating `points` (one per parameter).
    pub fn solve(&self, points: &[Vector3<f64>]) -> Result<Vec<Vector3<f64>>, ModelError> {
        let n = points.len();
        let mut rhs = DMatrix::<f64>::zeros(n, 3);
        for (k, p) in points.iter().enumerate() {
            for c in 0..3 {
                rhs[(k, c)] = p[c];
            }
        }
        let sol = self
            .lu
            .solve(&rhs)
            .ok_or_else(|| ModelError::Geometry("singular interpolation system".into()))?;
        Ok((0..n)
            .map(|k| Vector3::new(sol[(k, 0)], sol[(k, 1)], sol[(k, 2)]))
            .collect())
    }

    /// The interpolating curve through `points`.
    pub fn curve(&self, points: &[Vector3<f64>]) -> Result<NurbsCurve<3>, ModelError> {
        let ctrl = self.solve(points)?;
        Ok(NurbsCurve::from_knot_vector(
            self.knots.clone(),
            ctrl,
            None,
        )?)
    }
}

/// The tensor-product surface through the grid `grid[i][j]` at parameters `u[i]`, `v[j]`
/// with degrees `(pu, pv)` (NURBS Book A9.4: curves along u through each column, then along v).
pub fn interpolate_surface(
    grid: &[Vec<Vector3<f64>>],
    u: &[f64],
    v: &[f64],
    pu: usize,
    pv: usize,
) -> Result<NurbsSurface, ModelError> {
    for params in [u, v] {
        for w in params.windows(2) {
            if w[1] <= w[0] || !w[0].is_finite() || !w[1].is_finite() {
                return Err(ModelError::Geometry(
                    "interpolation parameters must increase strictly".into(),
                ));
            }
        }
    }
    for (params, degree) in [(u, pu), (v, pv)] {
        if params.len() <= degree {
            return Err(ModelError::Geometry(format!(
                "interpolation needs more than {degree} samples, got {}",
                params.len()
            )));
        }
    }
    if grid.len() != u.len() || grid.iter().any(|r| r.len() != v.len()) {
        return Err(ModelError::Geometry(
            "interpolation grid size mismatch".into(),
        ));
    }
    // One home for the algorithm: the `nurbs` crate's A9.4 at given parameters.
    nurbs::fit::interpolate_surface_at(grid, u, v, pu, pv)
        .map_err(|e| ModelError::Geometry(format!("surface interpolation: {e}")))
}

/// The ruled surface S(u, v) = (1 − v) A(u) + v B(u) between two curves interpolated through
/// `a` and `b` at the same parameters `u` (degree `pu` along u, 1 along v; exact rulings).
pub fn ruled_through(
    a: &[Vector3<f64>],
    b: &[Vector3<f64>],
    u: &[f64],
    pu: usize,
) -> Result<NurbsSurface, ModelError> {
    let iu = Interpolator::new(u, pu)?;
    let ca = iu.solve(a)?;
    let cb = iu.solve(b)?;
    let ctrl: Vec<Vec<Vector3<f64>>> = ca.into_iter().zip(cb).map(|(p, q)| vec![p, q]).collect();
    Ok(NurbsSurface::new(
        pu,
        1,
        iu.knots().knots().to_vec(),
        vec![0.0, 0.0, 1.0, 1.0],
        ctrl,
        None,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The averaging this module carried before it called `nurbs` (issue 15): the knots must
    /// stay identical (within 1e-12) on any parameter range.
    fn averaged_knots_before(params: &[f64], degree: usize) -> Vec<f64> {
        let n = params.len();
        let (a, b) = (params[0], params[n - 1]);
        let mut knots = vec![a; degree + 1];
        for j in 1..n - degree {
            let s: f64 = params[j..j + degree].iter().sum();
            knots.push(s / degree as f64);
        }
        knots.extend(std::iter::repeat_n(b, degree + 1));
        knots
    }

    #[test]
    fn averaged_knots_match_the_former_implementation() {
        for (lo, hi) in [(0.0, 1.0), (-3.5, 17.25), (2.0, 2.001)] {
            for n in [2usize, 5, 12, 40] {
                let params: Vec<f64> = (0..n)
                    .map(|i| lo + (hi - lo) * (i as f64 / (n - 1) as f64).powf(1.3))
                    .collect();
                for degree in 1..n.min(6) {
                    let new = averaged_knots(&params, degree).unwrap();
                    let old = averaged_knots_before(&params, degree);
                    assert_eq!(new.knots().len(), old.len());
                    for (x, y) in new.knots().iter().zip(&old) {
                        assert!((x - y).abs() <= 1e-12, "{x} vs {y} (n {n}, p {degree})");
                    }
                }
            }
        }
    }

    #[test]
    fn interpolant_passes_through_samples_and_reproduces_cubics() {
        let u: Vec<f64> = (0..12).map(|i| (i as f64 / 11.0).powf(1.3)).collect();
        let f = |t: f64| Vector3::new(t, t * t * t - 2.0 * t, 0.5 * t * t);
        let pts: Vec<_> = u.iter().map(|&t| f(t)).collect();
        let c = Interpolator::new(&u, 3).unwrap().curve(&pts).unwrap();
        for (&t, p) in u.iter().zip(&pts) {
            assert!((c.point(t) - p).norm() < 1e-12);
        }
        // A cubic is in the spline space: reproduced everywhere.
        for k in 0..50 {
            let t = k as f64 / 49.0;
            assert!((c.point(t) - f(t)).norm() < 1e-10);
        }
    }

    /// The tensor-product interpolation this module carried before it called `nurbs` (issue
    /// 15): LU-factored collocation along u, then along v.
    fn interpolate_surface_before(
        grid: &[Vec<Vector3<f64>>],
        u: &[f64],
        v: &[f64],
        pu: usize,
        pv: usize,
    ) -> Vec<Vec<Vector3<f64>>> {
        let iu = Interpolator::new(u, pu).unwrap();
        let iv = Interpolator::new(v, pv).unwrap();
        let mut r = vec![vec![Vector3::zeros(); v.len()]; u.len()];
        for j in 0..v.len() {
            let col: Vec<Vector3<f64>> = grid.iter().map(|row| row[j]).collect();
            for (i, c) in iu.solve(&col).unwrap().into_iter().enumerate() {
                r[i][j] = c;
            }
        }
        r.iter().map(|row| iv.solve(row).unwrap()).collect()
    }

    #[test]
    fn surface_interpolation_matches_the_former_implementation() {
        // Blade-like sizes: 100 mm, 41 × 9 samples at non-uniform parameters, shifted range.
        let u: Vec<f64> = (0..41).map(|i| 0.2 + (i as f64 / 40.0).powf(1.2)).collect();
        let v: Vec<f64> = (0..9)
            .map(|j| -1.0 + 2.5 * (j as f64 / 8.0).powf(0.9))
            .collect();
        let grid: Vec<Vec<Vector3<f64>>> = u
            .iter()
            .map(|&a| {
                v.iter()
                    .map(|&b| {
                        let (r, t) = (40.0 + 60.0 * a, 0.8 * a + 0.1 * b * b);
                        Vector3::new(r * t.cos(), r * t.sin(), 25.0 * b + 10.0 * (2.0 * a).sin())
                    })
                    .collect()
            })
            .collect();
        for (pu, pv) in [(3, 3), (3, 1), (2, 3)] {
            let new = interpolate_surface(&grid, &u, &v, pu, pv).unwrap();
            let old = interpolate_surface_before(&grid, &u, &v, pu, pv);
            let mut worst = 0.0f64;
            for (i, row) in old.iter().enumerate() {
                for (j, p) in row.iter().enumerate() {
                    worst = worst.max((new.control_point(i, j) - p).norm());
                }
            }
            assert!(
                worst <= 1e-12,
                "control points differ by {worst:e} mm ({pu}, {pv})"
            );
        }
    }

    #[test]
    fn surface_interpolation_hits_grid() {
        let u: Vec<f64> = (0..7).map(|i| i as f64 / 6.0).collect();
        let v: Vec<f64> = (0..5).map(|i| i as f64 / 4.0).collect();
        let grid: Vec<Vec<Vector3<f64>>> = u
            .iter()
            .map(|&a| {
                v.iter()
                    .map(|&b| Vector3::new(a, b, (3.0 * a).sin() * b * b))
                    .collect()
            })
            .collect();
        let s = interpolate_surface(&grid, &u, &v, 3, 3).unwrap();
        for (i, &a) in u.iter().enumerate() {
            for (j, &b) in v.iter().enumerate() {
                assert!((s.point(a, b) - grid[i][j]).norm() < 1e-12);
            }
        }
    }
}
