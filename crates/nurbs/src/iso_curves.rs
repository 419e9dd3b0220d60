//! Iso-parametric curves of a surface: `S(u0, ·)` and `S(·, v0)` as exact NURBS curves.

use nalgebra::Vector3;

use crate::curve::NurbsCurve;
use crate::error::Direction;
use crate::error::NurbsError;
use crate::knots::{basis_funs_fixed, clamp_param, find_span};
use crate::surface::NurbsSurface;

impl NurbsSurface {
    /// The curve `v ↦ S(u, v)` at fixed `u` (clamped to the domain): degree, knots and
    /// domain of the `v` direction, control points
    /// `Q_j = Σ_i N_{i,p}(u) w_ij P_ij / Σ_i N_{i,p}(u) w_ij` (homogeneous blending of the
    /// rows, NURBS Book §6.5). Exact; O(p n_v).
    pub fn iso_curve_at_u(&self, u: f64) -> Result<NurbsCurve<3>, NurbsError> {
        self.iso_curve(Direction::U, u)
    }

    /// The curve `u ↦ S(u, v)` at fixed `v` (clamped to the domain), along `u`.
    pub fn iso_curve_at_v(&self, v: f64) -> Result<NurbsCurve<3>, NurbsError> {
        self.iso_curve(Direction::V, v)
    }

    /// Iso curve with the parameter of direction `fixed` held at `t`.
    fn iso_curve(&self, fixed: Direction, t: f64) -> Result<NurbsCurve<3>, NurbsError> {
        let (kv_fixed, kv_free, n_free) = match fixed {
            Direction::U => (self.knots_u(), self.knots_v(), self.n_v()),
            Direction::V => (self.knots_v(), self.knots_u(), self.n_u()),
        };
        let p = kv_fixed.degree();
        let k = kv_fixed.knots();
        let t = clamp_param(k, p, t);
        let span = find_span(k, p, t);
        let n = basis_funs_fixed(k, p, span, t);
        let mut ctrl = Vec::with_capacity(n_free);
        let mut weights = Vec::with_capacity(n_free);
        for f in 0..n_free {
            let mut q = Vector3::zeros();
            let mut w = 0.0;
            for (a, &b) in n.iter().enumerate().take(p + 1) {
                let idx = span - p + a;
                let (i, j) = match fixed {
                    Direction::U => (idx, f),
                    Direction::V => (f, idx),
                };
                let wij = self.weight(i, j);
                q += self.control_point(i, j) * (b * wij);
                w += b * wij;
            }
            ctrl.push(q / w);
            weights.push(w);
        }
        NurbsCurve::from_knot_vector(kv_free.clone(), ctrl, self.is_rational().then_some(weights))
    }
}
