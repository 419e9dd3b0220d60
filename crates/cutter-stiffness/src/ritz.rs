//! Rayleigh–Ritz solution of the clamped beam with a Legendre series for the curvature on
//! each section (see the crate docs for the derivation).

use crate::beam::{inertia, Beam};
use crate::error::StiffnessError;
use crate::quadrature::{gauss_legendre, legendre_values};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// How many terms the Ritz expansion uses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RitzOptions {
    /// Terms per section; `None` grows the count from 2 until the relative change of the
    /// indicator is below `rel_tol` (or `max_terms` is reached).
    pub terms: Option<usize>,
    /// Convergence tolerance of the adaptive term count (relative change of k).
    pub rel_tol: f64,
    /// Largest adaptive term count.
    pub max_terms: usize,
}

impl Default for RitzOptions {
    fn default() -> Self {
        Self {
            terms: None,
            rel_tol: 1e-10,
            max_terms: 80,
        }
    }
}

/// A Ritz solution for a unit load.
#[derive(Debug, Clone, PartialEq)]
pub struct RitzSolution {
    /// Stiffness indicator `k = 1 / w(L)` (N/mm).
    pub stiffness: f64,
    /// Terms per section used.
    pub terms: usize,
    /// Curvature coefficients per section (unit load).
    coefficients: Vec<DVector<f64>>,
}

/// Quadrature data of one section: physical nodes, weights (already scaled by the section
/// half-length) and Legendre values `P_i(ξ_q)` column by column.
struct SectionRule {
    x: Vec<f64>,
    w: Vec<f64>,
    p: DMatrix<f64>, // terms × nodes
}

fn section_rules(beam: &Beam, terms: usize) -> Vec<(SectionRule, f64, f64, f64, f64)> {
    // n terms → integrand degree 4 + 2(n − 1) ≤ 2m − 1 with m = n + 2; one more for margin.
    let (xi, wi) = gauss_legendre(terms + 3);
    beam.spans()
        .map(|(x0, x1, sec)| {
            let half = 0.5 * (x1 - x0);
            let mid = 0.5 * (x1 + x0);
            let mut p = DMatrix::zeros(terms, xi.len());
            let mut col = vec![0.0; terms];
            for (q, &xq) in xi.iter().enumerate() {
                legendre_values(xq, &mut col);
                for (i, v) in col.iter().enumerate() {
                    p[(i, q)] = *v;
                }
            }
            let rule = SectionRule {
                x: xi.iter().map(|t| mid + half * t).collect(),
                w: wi.iter().map(|w| w * half).collect(),
                p,
            };
            (rule, x0, x1, sec.radius_clamp_side, sec.radius_load_side)
        })
        .collect()
}

fn radius(x: f64, x0: f64, x1: f64, r0: f64, r1: f64) -> f64 {
    r0 + (x - x0) / (x1 - x0) * (r1 - r0)
}

/// `K = Σ_q w_q g(x_q) P(ξ_q) P(ξ_q)ᵀ` for a weight function `g`.
fn weighted_gram(rule: &SectionRule, g: impl Fn(f64) -> f64) -> DMatrix<f64> {
    let n = rule.p.nrows();
    let mut k = DMatrix::zeros(n, n);
    for q in 0..rule.x.len() {
        let wq = rule.w[q] * g(rule.x[q]);
        let col = rule.p.column(q);
        k.ger(wq, &col, &col, 1.0);
    }
    k
}

/// Solves the Ritz problem with `terms` Legendre terms per section. O(S·n³) for S sections.
fn solve_fixed(beam: &Beam, terms: usize) -> Result<RitzSolution, StiffnessError> {
    let l = beam.length();
    let e = beam.youngs_modulus;
    let mut compliance = 0.0;
    let mut coefficients = Vec::new();
    for (rule, x0, x1, r0, r1) in section_rules(beam, terms) {
        let k = weighted_gram(&rule, |x| e * inertia(radius(x, x0, x1, r0, r1)));
        let mut f = DVector::zeros(terms);
        for q in 0..rule.x.len() {
            f.axpy(rule.w[q] * (l - rule.x[q]), &rule.p.column(q), 1.0);
        }
        let chol = k
            .cholesky()
            .ok_or(StiffnessError::NotPositiveDefinite { terms })?;
        let c = chol.solve(&f);
        compliance += f.dot(&c);
        coefficients.push(c);
    }
    Ok(RitzSolution {
        stiffness: 1.0 / compliance,
        terms,
        coefficients,
    })
}

impl RitzSolution {
    /// Rayleigh–Ritz stiffness indicator of `beam`.
    ///
    /// With `options.terms = Some(n)` it uses `n ≥ 2` terms per section; otherwise it adds
    /// terms until two successive changes of the indicator are both below `rel_tol` relative (the
    /// convergence is geometric, typically 6–15 terms for taper ratios up to 12), and
    /// returns [`StiffnessError::NotConverged`] if `max_terms` is reached first.
    pub fn solve(beam: &Beam, options: &RitzOptions) -> Result<Self, StiffnessError> {
        if let Some(n) = options.terms {
            if !(2..=200).contains(&n) {
                return Err(StiffnessError::InvalidParameter {
                    field: "terms",
                    value: n as f64,
                    reason: "must be between 2 and 200",
                });
            }
            return solve_fixed(beam, n);
        }
        // A single added term can be (nearly) orthogonal to the remaining error, so one small
        // change is not convergence: two successive changes below `rel_tol` are required
        // (e.g. r_c = 4.153, θ = 4.60°, L = 91.2 mm stalled 1.2 % above the exact value).
        let mut prev = solve_fixed(beam, 2)?;
        let mut change = f64::INFINITY;
        let mut small = 0;
        for n in 3..=options.max_terms.max(4) {
            let next = solve_fixed(beam, n)?;
            change = (next.stiffness - prev.stiffness).abs() / next.stiffness;
            prev = next;
            small = if change < options.rel_tol {
                small + 1
            } else {
                0
            };
            if small >= 2 {
                return Ok(prev);
            }
        }
        Err(StiffnessError::NotConverged {
            terms: prev.terms,
            rel_tol: options.rel_tol,
            change,
        })
    }

    /// Derivative of the indicator with respect to a shape parameter `p`, given
    /// `dI/dp` as a function of `x`: `∂k/∂p = k² Σ cᵀ (∫ E ∂I/∂p Pᵢ Pⱼ dx) c` (unit load).
    /// Exact for the discrete Ritz model.
    pub fn derivative(&self, beam: &Beam, d_inertia: impl Fn(f64) -> f64) -> f64 {
        let e = beam.youngs_modulus;
        let mut sum = 0.0;
        for ((rule, ..), c) in section_rules(beam, self.terms)
            .into_iter()
            .zip(&self.coefficients)
        {
            let kp = weighted_gram(&rule, |x| e * d_inertia(x));
            sum += c.dot(&(kp * c));
        }
        self.stiffness * self.stiffness * sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::beam::Section;

    #[test]
    fn cylinder_is_exact_with_two_terms() {
        let beam = Beam::new(
            vec![Section {
                length: 50.0,
                radius_clamp_side: 2.5,
                radius_load_side: 2.5,
            }],
            200e3,
        )
        .unwrap();
        let sol = RitzSolution::solve(
            &beam,
            &RitzOptions {
                terms: Some(2),
                ..Default::default()
            },
        )
        .unwrap();
        let k = 3.0 * 200e3 * inertia(2.5) / 50f64.powi(3);
        assert!((sol.stiffness / k - 1.0).abs() < 1e-12);
    }

    #[test]
    fn ritz_bounds_the_exact_value_from_above_and_converges() {
        let beam = Beam::new(
            vec![
                Section {
                    length: 20.0,
                    radius_clamp_side: 5.0,
                    radius_load_side: 5.0,
                },
                Section {
                    length: 30.0,
                    radius_clamp_side: 4.0,
                    radius_load_side: 1.5,
                },
            ],
            600e3,
        )
        .unwrap();
        let exact = beam.exact_stiffness();
        let mut last = f64::INFINITY;
        for n in 2..12 {
            let k = RitzSolution::solve(
                &beam,
                &RitzOptions {
                    terms: Some(n),
                    ..Default::default()
                },
            )
            .unwrap()
            .stiffness;
            assert!(k >= exact * (1.0 - 1e-12), "n={n}: {k} < {exact}");
            assert!(k <= last * (1.0 + 1e-12), "not monotone at n={n}");
            last = k;
        }
        let k = RitzSolution::solve(&beam, &RitzOptions::default())
            .unwrap()
            .stiffness;
        assert!((k / exact - 1.0).abs() < 1e-9, "{k} vs {exact}");
    }

    #[test]
    fn non_convergence_is_an_error_not_a_silent_value() {
        let beam = Beam::new(
            vec![Section {
                length: 40.0,
                radius_clamp_side: 8.0,
                radius_load_side: 1.0,
            }],
            600e3,
        )
        .unwrap();
        let opts = RitzOptions {
            rel_tol: 1e-15,
            max_terms: 4,
            ..Default::default()
        };
        assert!(matches!(
            RitzSolution::solve(&beam, &opts),
            Err(StiffnessError::NotConverged { terms: 4, .. })
        ));
    }

    #[test]
    fn term_count_is_validated() {
        let beam = Beam::new(
            vec![Section {
                length: 1.0,
                radius_clamp_side: 1.0,
                radius_load_side: 1.0,
            }],
            1.0,
        )
        .unwrap();
        let opts = RitzOptions {
            terms: Some(1),
            ..Default::default()
        };
        assert!(matches!(
            RitzSolution::solve(&beam, &opts),
            Err(StiffnessError::InvalidParameter { field: "terms", .. })
        ));
    }
}
