//! Shared proptest strategies for the core tests: random valid curves and surfaces with
//! well-separated knots (gaps ≥ 1/(4 n) of the domain) so finite differences are meaningful.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::{SVector, Vector3};
use nurbs::{NurbsCurve, NurbsSurface};
use proptest::prelude::*;

/// Clamped knot vector on [a, b] with `n_ctrl` control points, interior gaps drawn from
/// `gaps` (relative sizes in [1, 4]) and optional interior multiplicities.
pub fn knots_from(degree: usize, n_ctrl: usize, gaps: &[f64], a: f64, b: f64) -> Vec<f64> {
    let n_int = n_ctrl - degree - 1;
    let g = &gaps[..=n_int];
    let total: f64 = g.iter().sum();
    let mut knots = vec![a; degree + 1];
    let mut acc = 0.0;
    for gi in &g[..n_int] {
        acc += gi;
        knots.push(a + (b - a) * acc / total);
    }
    knots.extend(std::iter::repeat_n(b, degree + 1));
    knots
}

/// Clamped knot vector on [a, b] with `spans` non-empty spans of relative sizes `gaps` and
/// interior multiplicities `mult` (each clipped to `degree`).
pub fn knots_with_mult(degree: usize, gaps: &[f64], mult: &[usize], a: f64, b: f64) -> Vec<f64> {
    let total: f64 = gaps.iter().sum();
    let mut knots = vec![a; degree + 1];
    let mut acc = 0.0;
    for (gi, m) in gaps[..gaps.len() - 1].iter().zip(mult) {
        acc += gi;
        let k = a + (b - a) * acc / total;
        knots.extend(std::iter::repeat_n(k, (*m).clamp(1, degree)));
    }
    knots.extend(std::iter::repeat_n(b, degree + 1));
    knots
}

/// Random valid curve: degree 1..=5, 1..=5 spans, interior multiplicities 1..=degree
/// (multiplicity > 1 with probability ~1/4), control points in [-10, 10]³, weights in
/// [0.5, 2] when rational.
pub fn curve3(rational: bool) -> impl Strategy<Value = NurbsCurve<3>> {
    (1usize..=5, 1usize..=5).prop_flat_map(move |(p, spans)| {
        let max_ctrl = p + 1 + (spans - 1) * p;
        (
            Just(p),
            prop::collection::vec(1.0f64..4.0, spans),
            prop::collection::vec(prop_oneof![3 => Just(1usize), 1 => 2usize..=5], spans),
            prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), max_ctrl),
            prop::collection::vec(0.5f64..2.0, max_ctrl),
            -3.0f64..3.0,
            0.5f64..4.0,
        )
            .prop_map(move |(p, gaps, mult, pts, w, a, len)| {
                let knots = knots_with_mult(p, &gaps, &mult, a, a + len);
                let n = knots.len() - p - 1;
                let ctrl = pts[..n]
                    .iter()
                    .map(|c| SVector::<f64, 3>::from(*c))
                    .collect();
                let w = w[..n].to_vec();
                NurbsCurve::new(p, knots, ctrl, rational.then_some(w)).unwrap()
            })
    })
}

pub fn curve2(rational: bool) -> impl Strategy<Value = NurbsCurve<2>> {
    curve3(rational).prop_map(|c| {
        let ctrl = c
            .control_points()
            .iter()
            .map(|p| SVector::<f64, 2>::new(p.x, p.y))
            .collect();
        NurbsCurve::new(
            c.degree(),
            c.knots().knots().to_vec(),
            ctrl,
            c.weights().map(|w| w.to_vec()),
        )
        .unwrap()
    })
}

pub fn surface(rational: bool) -> impl Strategy<Value = NurbsSurface> {
    (1usize..=4, 1usize..=4, 0usize..=3, 0usize..=3).prop_flat_map(move |(p, q, eu, ev)| {
        let (nu, nv) = (p + 1 + eu, q + 1 + ev);
        (
            Just((p, q, nu, nv)),
            prop::collection::vec(1.0f64..4.0, nu),
            prop::collection::vec(1.0f64..4.0, nv),
            prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), nu * nv),
            prop::collection::vec(0.5f64..2.0, nu * nv),
        )
            .prop_map(move |((p, q, nu, nv), gu, gv, pts, w)| {
                let ku = knots_from(p, nu, &gu, 0.0, 1.0);
                let kv = knots_from(q, nv, &gv, -1.0, 1.5);
                let net: Vec<Vec<Vector3<f64>>> = (0..nu)
                    .map(|i| (0..nv).map(|j| Vector3::from(pts[i * nv + j])).collect())
                    .collect();
                let wn: Vec<Vec<f64>> = (0..nu)
                    .map(|i| (0..nv).map(|j| w[i * nv + j]).collect())
                    .collect();
                NurbsSurface::new(p, q, ku, kv, net, rational.then_some(wn)).unwrap()
            })
    })
}

/// Largest distance between two curves sampled at `n` parameters on their common domain.
pub fn curve_distance<const D: usize>(a: &NurbsCurve<D>, b: &NurbsCurve<D>, n: usize) -> f64 {
    let (u0, u1) = a.domain();
    (0..=n)
        .map(|k| {
            let u = u0 + (u1 - u0) * k as f64 / n as f64;
            (a.point(u) - b.point(u)).norm()
        })
        .fold(0.0, f64::max)
}

/// Largest distance between two surfaces on an `n × n` grid of the first one's domain.
pub fn surface_distance(a: &NurbsSurface, b: &NurbsSurface, n: usize) -> f64 {
    let ((u0, u1), (v0, v1)) = a.domain();
    let mut d: f64 = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            let u = u0 + (u1 - u0) * i as f64 / n as f64;
            let v = v0 + (v1 - v0) * j as f64 / n as f64;
            d = d.max((a.point(u, v) - b.point(u, v)).norm());
        }
    }
    d
}

/// Size of a curve's control polygon (for relative tolerances).
pub fn curve_scale<const D: usize>(c: &NurbsCurve<D>) -> f64 {
    c.control_points()
        .iter()
        .map(|p| p.norm())
        .fold(1.0, f64::max)
}

pub fn surface_scale(s: &NurbsSurface) -> f64 {
    s.control_points()
        .iter()
        .map(|p| p.norm())
        .fold(1.0, f64::max)
}
