//! Tessellation within a chord tolerance.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector3;
use nurbs::tessellate::{tessellate, Mesh, TessellateError};
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn reference() -> NurbsSurface {
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..12)
        .map(|i| {
            (0..12)
                .map(|j| {
                    let x = 100.0 * i as f64 / 11.0;
                    let y = 100.0 * j as f64 / 11.0;
                    Vector3::new(
                        x,
                        y,
                        8.0 * (x / 17.0).sin() * (y / 23.0).cos() + 0.002 * x * y,
                    )
                })
                .collect()
        })
        .collect();
    let k = KnotVector::clamped_uniform(3, 12).unwrap().knots().to_vec();
    NurbsSurface::new(3, 3, k.clone(), k, ctrl, None).unwrap()
}

/// Largest deviation between triangle points (centroid, edge midpoints, random barycentric
/// points) and the surface at the same parameters.
fn chord_error(s: &NurbsSurface, m: &Mesh) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst: f64 = 0.0;
    for t in &m.triangles {
        let [a, b, c] = t.map(|k| k as usize);
        let mut probes = vec![
            [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
        ];
        for _ in 0..3 {
            let (x, y): (f64, f64) = (rng.random(), rng.random());
            let (x, y) = if x + y > 1.0 {
                (1.0 - x, 1.0 - y)
            } else {
                (x, y)
            };
            probes.push([x, y, 1.0 - x - y]);
        }
        for w in probes {
            let u = w[0] * m.uv[a][0] + w[1] * m.uv[b][0] + w[2] * m.uv[c][0];
            let v = w[0] * m.uv[a][1] + w[1] * m.uv[b][1] + w[2] * m.uv[c][1];
            let p = m.vertices[a] * w[0] + m.vertices[b] * w[1] + m.vertices[c] * w[2];
            worst = worst.max((s.point(u, v) - p).norm());
        }
    }
    worst
}

#[test]
fn reference_surface_within_chord_tolerance() {
    let s = reference();
    for tol in [0.1, 0.01] {
        let m = tessellate(&s, tol).unwrap();
        let e = chord_error(&s, &m);
        assert!(e <= tol, "tol {tol}: error {e}");
        assert_eq!(m.vertices.len(), m.normals.len());
        assert_eq!(m.vertices.len(), m.uv.len());
        for (k, p) in m.vertices.iter().enumerate() {
            assert!((s.point(m.uv[k][0], m.uv[k][1]) - p).norm() <= 1e-12);
            assert!((m.normals[k].norm() - 1.0).abs() <= 1e-12);
        }
        // Counter-clockwise seen from the normal side.
        for t in &m.triangles {
            let [a, b, c] = t.map(|k| k as usize);
            let n = (m.vertices[b] - m.vertices[a]).cross(&(m.vertices[c] - m.vertices[a]));
            assert!(n.dot(&m.normals[a]) > 0.0);
        }
    }
    // A finer tolerance needs more triangles.
    assert!(
        tessellate(&s, 0.01).unwrap().triangles.len()
            > tessellate(&s, 0.1).unwrap().triangles.len()
    );
}

#[test]
fn rational_cylinder_within_chord_tolerance() {
    let line = NurbsCurve::<3>::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Vector3::new(20.0, 0.0, 0.0), Vector3::new(20.0, 0.0, 30.0)],
        None,
    )
    .unwrap();
    let s = NurbsSurface::revolution(&line, Vector3::zeros(), Vector3::z(), std::f64::consts::TAU)
        .unwrap();
    let tol = 0.02;
    let m = tessellate(&s, tol).unwrap();
    assert!(chord_error(&s, &m) <= tol);
    // Geometric check: triangle centroids are inside the cylinder by at most tol.
    for t in &m.triangles {
        let c = (m.vertices[t[0] as usize] + m.vertices[t[1] as usize] + m.vertices[t[2] as usize])
            / 3.0;
        let r = c.xy().norm();
        assert!(r <= 20.0 + 1e-9 && r >= 20.0 - tol, "r = {r}");
    }
}

#[test]
fn every_tessellate_error_is_reported() {
    let s = reference();
    assert_eq!(
        tessellate(&s, 0.0).unwrap_err(),
        TessellateError::InvalidTolerance(0.0)
    );
    assert!(matches!(
        tessellate(&s, 1e-12),
        Err(TessellateError::TooManyVertices { .. })
    ));
}
