//! Tessellation of a NURBS surface into a triangle mesh within a chord tolerance.
//!
//! The mesh is a tensor grid in parameter space: every knot span in `u` (and `v`) is split
//! uniformly into a number of cells chosen from bounds of the second derivatives on that span,
//! and each cell is cut into two triangles along its shorter diagonal. Because each span has
//! one count for the whole column (row) of spans, neighbouring cells share their vertices and
//! the mesh has no cracks.
//!
//! **Error bound.** For linear interpolation on a triangle whose vertices span `h_u × h_v` in
//! parameters, the deviation from the surface at the same `(u, v)` is at most
//! `(1/8)(M_uu h_u² + 2 M_uv h_u h_v + M_vv h_v²)` with `M_xy = max |S_xy|` on the cell (the
//! interpolation error is `½ Σ λ_i (x_i − x)ᵀ D²S (x_i − x)` and `Σ λ_i (u_i − u)² ≤ h_u²/4`).
//! For polynomial patches the `M` are exact bounds from the second differences of the Bézier
//! control net (convex-hull property of the second hodographs); for rational patches they are
//! estimated on a 5 × 5 sample with a factor 1.5. Every mesh is then *verified*: the surface is
//! evaluated at each triangle's centroid and edge midpoints, and spans whose triangles deviate
//! by more than the tolerance are refined (cell counts doubled) until all pass. The deviation
//! measured is parametric (triangle point vs. `S` at the same `(u, v)`), an upper bound of the
//! geometric distance from the triangle to the surface.
//!
//! Cost: O(vertices) evaluations plus the verification pass (4 evaluations per triangle).

use nalgebra::Vector3;

use crate::closest::bezier::BezierPatch;
use crate::closest::decompose_surface;
use crate::NurbsSurface;

/// Why a tessellation could not be produced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TessellateError {
    /// The chord tolerance must be finite and positive.
    #[error("`chord_tol` = {0} must be finite and > 0")]
    InvalidTolerance(f64),
    /// The tolerance would need more than [`MAX_VERTICES`] vertices.
    #[error("the tolerance needs {needed} vertices (limit {limit})")]
    TooManyVertices {
        /// Vertices the grid would have.
        needed: f64,
        /// The limit.
        limit: usize,
    },
}

/// Largest mesh produced (guards against a tolerance given in the wrong unit).
pub const MAX_VERTICES: usize = 20_000_000;

/// A triangle mesh of a surface.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Vertex positions `S(u, v)`.
    pub vertices: Vec<Vector3<f64>>,
    /// Unit surface normals `S_u × S_v` at the vertices (averaged face normals where the
    /// surface is singular, e.g. at a pole).
    pub normals: Vec<Vector3<f64>>,
    /// Surface parameters `[u, v]` of the vertices.
    pub uv: Vec<[f64; 2]>,
    /// Triangles as vertex indices, counter-clockwise seen from the normal side.
    pub triangles: Vec<[u32; 3]>,
}

/// Second-derivative bounds `(M_uu, M_uv, M_vv)` of a Bézier patch (global parameters).
fn second_bounds(b: &BezierPatch) -> (f64, f64, f64) {
    let (p, q) = (b.p, b.q);
    let du = b.u1 - b.u0;
    let dv = b.v1 - b.v0;
    if b.rational {
        let mut m = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..=4 {
            for j in 0..=4 {
                let d = b.derivs2(b.u0 + du * i as f64 / 4.0, b.v0 + dv * j as f64 / 4.0);
                m.0 = m.0.max(d.suu.norm());
                m.1 = m.1.max(d.suv.norm());
                m.2 = m.2.max(d.svv.norm());
            }
        }
        return (1.5 * m.0, 1.5 * m.1, 1.5 * m.2);
    }
    let pts: Vec<Vector3<f64>> = b.points().collect();
    let at = |i: usize, j: usize| pts[i * (q + 1) + j];
    let mut m = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..=p {
        for j in 0..=q {
            if i + 2 <= p {
                m.0 =
                    m.0.max((at(i + 2, j) - at(i + 1, j) * 2.0 + at(i, j)).norm());
            }
            if i < p && j < q {
                m.1 =
                    m.1.max((at(i + 1, j + 1) - at(i + 1, j) - at(i, j + 1) + at(i, j)).norm());
            }
            if j + 2 <= q {
                m.2 =
                    m.2.max((at(i, j + 2) - at(i, j + 1) * 2.0 + at(i, j)).norm());
            }
        }
    }
    let (pf, qf) = (p as f64, q as f64);
    (
        m.0 * pf * (pf - 1.0) / (du * du),
        m.1 * pf * qf / (du * dv),
        m.2 * qf * (qf - 1.0) / (dv * dv),
    )
}

/// Cell counts `(n_u, n_v)` for a span of size `du × dv` so that the error bound is ≤ `tol`.
fn counts(du: f64, dv: f64, m: (f64, f64, f64), tol: f64) -> (f64, f64) {
    let limit = |mxx: f64| {
        if mxx > 0.0 {
            (8.0 * tol / (3.0 * mxx)).sqrt()
        } else {
            f64::INFINITY
        }
    };
    let mut a = limit(m.0).min(du);
    let mut b = limit(m.2).min(dv);
    if m.1 > 0.0 {
        let ab = 4.0 * tol / (3.0 * m.1);
        if a * b > ab {
            let s = (ab / (a * b)).sqrt();
            a *= s;
            b *= s;
        }
    }
    ((du / a).ceil().max(1.0), (dv / b).ceil().max(1.0))
}

/// Triangle mesh of `surface` whose deviation from the surface is at most `chord_tol` (mm).
/// See the module docs for the method and the guarantee.
pub fn tessellate(surface: &NurbsSurface, chord_tol: f64) -> Result<Mesh, TessellateError> {
    if !(chord_tol.is_finite() && chord_tol > 0.0) {
        return Err(TessellateError::InvalidTolerance(chord_tol));
    }
    let (patches, ub, vb) = decompose_surface(surface);
    let (nsu, nsv) = (ub.len() - 1, vb.len() - 1);
    let mut nu = vec![1usize; nsu];
    let mut nv = vec![1usize; nsv];
    for (k, b) in patches.iter().enumerate() {
        let (a, c) = (k / nsv, k % nsv);
        let (cu, cv) = counts(b.u1 - b.u0, b.v1 - b.v0, second_bounds(b), chord_tol);
        let check = |x: f64| -> Result<usize, TessellateError> {
            if x > MAX_VERTICES as f64 {
                Err(TessellateError::TooManyVertices {
                    needed: x,
                    limit: MAX_VERTICES,
                })
            } else {
                Ok(x as usize)
            }
        };
        nu[a] = nu[a].max(check(cu)?);
        nv[c] = nv[c].max(check(cv)?);
    }
    // Every round doubles the counts of failing spans, so the loop ends by verification or
    // by the vertex limit.
    loop {
        let total =
            (nu.iter().sum::<usize>() as f64 + 1.0) * (nv.iter().sum::<usize>() as f64 + 1.0);
        if total > MAX_VERTICES as f64 {
            return Err(TessellateError::TooManyVertices {
                needed: total,
                limit: MAX_VERTICES,
            });
        }
        let mesh = build(&patches, &ub, &vb, &nu, &nv);
        let (bad_u, bad_v) = verify(&patches, &ub, &vb, &mesh, chord_tol);
        if bad_u.iter().all(|b| !b) && bad_v.iter().all(|b| !b) {
            return Ok(mesh);
        }
        for (n, bad) in nu.iter_mut().zip(&bad_u) {
            if *bad {
                *n *= 2;
            }
        }
        for (n, bad) in nv.iter_mut().zip(&bad_v) {
            if *bad {
                *n *= 2;
            }
        }
    }
}

fn grid_values(breaks: &[f64], counts: &[usize]) -> Vec<f64> {
    let mut out = Vec::with_capacity(counts.iter().sum::<usize>() + 1);
    for (s, &n) in counts.iter().enumerate() {
        let (a, b) = (breaks[s], breaks[s + 1]);
        for k in 0..n {
            out.push(a + (b - a) * k as f64 / n as f64);
        }
    }
    if let Some(&last) = breaks.last() {
        out.push(last);
    }
    out
}

fn span_of(breaks: &[f64], x: f64) -> usize {
    let n = breaks.len() - 1;
    breaks[1..n].partition_point(|&b| b <= x)
}

fn build(patches: &[BezierPatch], ub: &[f64], vb: &[f64], nu: &[usize], nv: &[usize]) -> Mesh {
    let us = grid_values(ub, nu);
    let vs = grid_values(vb, nv);
    let nsv = vb.len() - 1;
    let (cu, cv) = (us.len(), vs.len());
    let mut mesh = Mesh {
        vertices: Vec::with_capacity(cu * cv),
        normals: Vec::with_capacity(cu * cv),
        uv: Vec::with_capacity(cu * cv),
        triangles: Vec::with_capacity(2 * (cu - 1) * (cv - 1)),
    };
    let mut singular = Vec::new();
    for &u in &us {
        let a = span_of(ub, u);
        for &v in &vs {
            let b = span_of(vb, v);
            let d = patches[a * nsv + b].derivs2(u, v);
            mesh.vertices.push(d.p);
            match d.normal() {
                Some(n) => mesh.normals.push(n),
                None => {
                    singular.push(mesh.normals.len());
                    mesh.normals.push(Vector3::zeros());
                }
            }
            mesh.uv.push([u, v]);
        }
    }
    let idx = |i: usize, j: usize| (i * cv + j) as u32;
    for i in 0..cu - 1 {
        for j in 0..cv - 1 {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            let p = |k: u32| mesh.vertices[k as usize];
            let tris = if (p(a) - p(c)).norm_squared() <= (p(b) - p(d)).norm_squared() {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, b, d], [b, c, d]]
            };
            for t in tris {
                let n = (p(t[1]) - p(t[0])).cross(&(p(t[2]) - p(t[0])));
                if n.norm_squared() > 0.0 {
                    mesh.triangles.push(t);
                }
            }
        }
    }
    if !singular.is_empty() {
        let mut acc = vec![Vector3::zeros(); mesh.vertices.len()];
        for t in &mesh.triangles {
            let p = |k: u32| mesh.vertices[k as usize];
            let n = (p(t[1]) - p(t[0])).cross(&(p(t[2]) - p(t[0])));
            for &k in t {
                acc[k as usize] += n;
            }
        }
        for k in singular {
            mesh.normals[k] = acc[k].try_normalize(0.0).unwrap_or_else(Vector3::z);
        }
    }
    mesh
}

/// Spans (u columns, v rows) holding a triangle whose centroid or an edge midpoint deviates
/// from the surface by more than `tol`.
fn verify(
    patches: &[BezierPatch],
    ub: &[f64],
    vb: &[f64],
    mesh: &Mesh,
    tol: f64,
) -> (Vec<bool>, Vec<bool>) {
    let nsv = vb.len() - 1;
    let mut bad_u = vec![false; ub.len() - 1];
    let mut bad_v = vec![false; nsv];
    let eval = |u: f64, v: f64| patches[span_of(ub, u) * nsv + span_of(vb, v)].point(u, v);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|k| k as usize);
        let probes = [
            ([a, b, c], [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0]),
            ([a, b, c], [0.5, 0.5, 0.0]),
            ([a, b, c], [0.0, 0.5, 0.5]),
            ([a, b, c], [0.5, 0.0, 0.5]),
        ];
        for (ids, w) in probes {
            let mut uv = [0.0; 2];
            let mut p = Vector3::zeros();
            for (k, &id) in ids.iter().enumerate() {
                uv[0] += w[k] * mesh.uv[id][0];
                uv[1] += w[k] * mesh.uv[id][1];
                p += mesh.vertices[id] * w[k];
            }
            if (eval(uv[0], uv[1]) - p).norm() > tol {
                bad_u[span_of(ub, uv[0])] = true;
                bad_v[span_of(vb, uv[1])] = true;
            }
        }
    }
    (bad_u, bad_v)
}
