//! The design model the simulation is checked against: a solid given by its signed distance,
//! sampled surfaces with outward normals, and a triangle mesh for collision queries; plus
//! analytic designs (box, Z cylinder, union) for tests and simple parts.

use cam_core::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// A grid of sample points on one design surface, with unit normals pointing out of the
/// design material (toward where material must be removed). Row-major in `v`:
/// `index = j * nu + i`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceGrid {
    /// Surface name (e.g. `blade_0_pressure`, `hub`).
    pub name: String,
    /// Samples along u.
    pub nu: usize,
    /// Samples along v.
    pub nv: usize,
    /// Sample points (mm).
    pub points: Vec<Point3>,
    /// Unit outward normals; a zero vector marks a sample to skip (degenerate normal).
    pub normals: Vec<Vector3>,
}

impl SurfaceGrid {
    /// A grid of `nu × nv` samples with nothing sampled yet (room reserved for them).
    pub fn empty(name: String, nu: usize, nv: usize) -> Self {
        Self {
            name,
            nu,
            nv,
            points: Vec::with_capacity(nu * nv),
            normals: Vec::with_capacity(nu * nv),
        }
    }
}

/// Indexed triangle mesh (mm).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// What the simulation needs of the design (the part that must remain after machining).
pub trait DesignModel: Sync {
    /// Signed distance (mm) from `p` to the design boundary, negative inside the material
    /// that must remain. Must be accurate near the surface (within the simulation
    /// resolution / 10) and never exceed the true distance in magnitude elsewhere (it is
    /// used as a safe marching bound).
    fn signed_distance(&self, p: &Point3) -> f64;
    /// Sample grids on the surfaces where overcut and residual are reported.
    fn surface_grids(&self) -> Vec<SurfaceGrid>;
    /// Closed triangle mesh of the design boundary for collision queries.
    fn triangle_mesh(&self) -> TriangleMesh;
    /// How far this model's surface may lie from the design it stands for (mm): a fitted
    /// surface's stated fit error (a blade-root fillet's spine), added to the overcut error
    /// bound ([`crate::endpoints::overcut_error_bound`]). Default 0 (exact models).
    fn model_error_mm(&self) -> f64 {
        0.0
    }
    /// Whether `p` is inside the design material.
    fn contains(&self, p: &Point3) -> bool {
        self.signed_distance(p) < 0.0
    }
    /// Depth (mm) of the inside point `p` below the one design surface through which a cut
    /// reached it, entering the design at `entry` (a point on that surface). Where walls are
    /// thin the distance to the nearest boundary (−signed distance) is capped by half the
    /// wall, while the cut's depth below the face it entered is not; designs made of
    /// several faces return the signed distance to the face nearest `entry`, negated.
    /// Default: `−signed_distance(p)` (right for designs whose walls are thicker than any
    /// overcut).
    fn depth_below(&self, p: &Point3, entry: &Point3) -> f64 {
        let _ = entry;
        -self.signed_distance(p)
    }
}

/// Axis-aligned box design.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoxDesign {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
    /// Spacing of the surface samples (mm).
    pub sample_spacing: f64,
}

impl DesignModel for BoxDesign {
    fn signed_distance(&self, p: &Point3) -> f64 {
        let mut q = [0.0; 3];
        for k in 0..3 {
            let c = 0.5 * (self.min[k] + self.max[k]);
            let e = 0.5 * (self.max[k] - self.min[k]);
            q[k] = (p[k] - c).abs() - e;
        }
        let outside = q.iter().map(|x| x.max(0.0).powi(2)).sum::<f64>().sqrt();
        let inside = q[0].max(q[1]).max(q[2]).min(0.0);
        outside + inside
    }

    fn surface_grids(&self) -> Vec<SurfaceGrid> {
        let mut out = Vec::new();
        let names = ["x", "y", "z"];
        for d in 0..3 {
            for (side, sign) in [("min", -1.0), ("max", 1.0)] {
                let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
                let nu = samples(self.max[ua] - self.min[ua], self.sample_spacing);
                let nv = samples(self.max[va] - self.min[va], self.sample_spacing);
                let mut g = SurfaceGrid::empty(format!("{}_{side}", names[d]), nu, nv);
                let mut n = Vector3::zeros();
                n[d] = sign;
                for j in 0..nv {
                    for i in 0..nu {
                        let mut p = Point3::origin();
                        p[d] = if sign < 0.0 { self.min[d] } else { self.max[d] };
                        p[ua] = lerp(self.min[ua], self.max[ua], i, nu);
                        p[va] = lerp(self.min[va], self.max[va], j, nv);
                        g.points.push(p);
                        g.normals.push(n);
                    }
                }
                out.push(g);
            }
        }
        out
    }

    fn triangle_mesh(&self) -> TriangleMesh {
        let (a, b) = (self.min, self.max);
        let vertices = (0..8)
            .map(|k| {
                [
                    if k & 1 == 0 { a[0] } else { b[0] },
                    if k & 2 == 0 { a[1] } else { b[1] },
                    if k & 4 == 0 { a[2] } else { b[2] },
                ]
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriangleMesh {
            vertices,
            triangles,
        }
    }
}

/// Solid cylinder about the Z axis (a hub-like design).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CylinderDesign {
    /// Radius (mm).
    pub radius: f64,
    /// Bottom height.
    pub z0: f64,
    /// Top height.
    pub z1: f64,
    /// Spacing of the surface samples (mm).
    pub sample_spacing: f64,
}

impl DesignModel for CylinderDesign {
    fn signed_distance(&self, p: &Point3) -> f64 {
        let dr = (p.x * p.x + p.y * p.y).sqrt() - self.radius;
        let c = 0.5 * (self.z0 + self.z1);
        let dz = (p.z - c).abs() - 0.5 * (self.z1 - self.z0);
        let outside = (dr.max(0.0).powi(2) + dz.max(0.0).powi(2)).sqrt();
        outside + dr.max(dz).min(0.0)
    }

    fn surface_grids(&self) -> Vec<SurfaceGrid> {
        let circ = std::f64::consts::TAU * self.radius;
        let nu = samples(circ, self.sample_spacing).max(8);
        let nv = samples(self.z1 - self.z0, self.sample_spacing);
        let mut side = SurfaceGrid {
            name: "side".into(),
            nu,
            nv,
            points: Vec::new(),
            normals: Vec::new(),
        };
        for j in 0..nv {
            for i in 0..nu {
                let t = std::f64::consts::TAU * i as f64 / nu as f64;
                let n = Vector3::new(t.cos(), t.sin(), 0.0);
                side.points.push(Point3::new(
                    self.radius * n.x,
                    self.radius * n.y,
                    lerp(self.z0, self.z1, j, nv),
                ));
                side.normals.push(n);
            }
        }
        let nr = samples(self.radius, self.sample_spacing);
        let mut top = SurfaceGrid {
            name: "top".into(),
            nu,
            nv: nr,
            points: Vec::new(),
            normals: Vec::new(),
        };
        for j in 0..nr {
            let r = self.radius * (j as f64 + 0.5) / nr as f64;
            for i in 0..nu {
                let t = std::f64::consts::TAU * i as f64 / nu as f64;
                top.points
                    .push(Point3::new(r * t.cos(), r * t.sin(), self.z1));
                top.normals.push(Vector3::z());
            }
        }
        vec![side, top]
    }

    fn triangle_mesh(&self) -> TriangleMesh {
        let n = 64u32;
        let mut m = TriangleMesh::default();
        // Circumscribed polygon so the mesh contains the cylinder.
        let r = self.radius / (std::f64::consts::PI / f64::from(n)).cos();
        for z in [self.z0, self.z1] {
            for i in 0..n {
                let t = std::f64::consts::TAU * f64::from(i) / f64::from(n);
                m.vertices.push([r * t.cos(), r * t.sin(), z]);
            }
        }
        m.vertices.push([0.0, 0.0, self.z0]);
        m.vertices.push([0.0, 0.0, self.z1]);
        let (cb, ct) = (2 * n, 2 * n + 1);
        for i in 0..n {
            let k = (i + 1) % n;
            m.triangles.push([i, k, n + k]);
            m.triangles.push([i, n + k, n + i]);
            m.triangles.push([cb, k, i]);
            m.triangles.push([ct, n + i, n + k]);
        }
        m
    }
}

/// Union of designs: signed distance = minimum; surface samples of each part that do not lie
/// inside another part (by more than `1e-9` mm); meshes concatenated.
#[derive(Debug, Clone, Default)]
pub struct UnionDesign<D> {
    /// The parts.
    pub parts: Vec<D>,
}

impl<D: DesignModel> DesignModel for UnionDesign<D> {
    fn signed_distance(&self, p: &Point3) -> f64 {
        self.parts
            .iter()
            .map(|d| d.signed_distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    fn surface_grids(&self) -> Vec<SurfaceGrid> {
        let mut out = Vec::new();
        for (k, part) in self.parts.iter().enumerate() {
            for mut g in part.surface_grids() {
                for (p, n) in g.points.iter().zip(g.normals.iter_mut()) {
                    let buried = self
                        .parts
                        .iter()
                        .enumerate()
                        .any(|(o, other)| o != k && other.signed_distance(p) < -1e-9);
                    if buried {
                        *n = Vector3::zeros();
                    }
                }
                g.name = format!("part{k}_{}", g.name);
                out.push(g);
            }
        }
        out
    }

    fn model_error_mm(&self) -> f64 {
        self.parts
            .iter()
            .map(|p| p.model_error_mm())
            .fold(0.0, f64::max)
    }

    fn triangle_mesh(&self) -> TriangleMesh {
        let mut m = TriangleMesh::default();
        for part in &self.parts {
            let pm = part.triangle_mesh();
            let base = m.vertices.len() as u32;
            m.vertices.extend(pm.vertices);
            m.triangles.extend(
                pm.triangles
                    .iter()
                    .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
            );
        }
        m
    }
}

fn samples(len: f64, spacing: f64) -> usize {
    let s = if spacing.is_finite() && spacing > 0.0 {
        spacing
    } else {
        1.0
    };
    ((len / s).ceil() as usize + 1).clamp(2, 100_000)
}

fn lerp(a: f64, b: f64, i: usize, n: usize) -> f64 {
    if n <= 1 {
        0.5 * (a + b)
    } else {
        a + (b - a) * i as f64 / (n - 1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_signed_distance_is_exact() {
        let b = BoxDesign {
            min: [0.0, 0.0, 0.0],
            max: [2.0, 4.0, 6.0],
            sample_spacing: 1.0,
        };
        assert!((b.signed_distance(&Point3::new(1.0, 1.0, 1.0)) + 1.0).abs() < 1e-12);
        assert!((b.signed_distance(&Point3::new(3.0, 5.0, 3.0)) - 2f64.sqrt()).abs() < 1e-12);
        let g = b.surface_grids();
        assert_eq!(g.len(), 6);
        for grid in &g {
            for p in &grid.points {
                assert!(b.signed_distance(p).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn union_hides_buried_samples() {
        let u = UnionDesign {
            parts: vec![
                BoxDesign {
                    min: [0.0, 0.0, 0.0],
                    max: [10.0, 10.0, 2.0],
                    sample_spacing: 1.0,
                },
                BoxDesign {
                    min: [4.0, 0.0, 1.0],
                    max: [6.0, 10.0, 8.0],
                    sample_spacing: 1.0,
                },
            ],
        };
        let grids = u.surface_grids();
        // The plate's bottom face (z = 1) is inside the base: all its normals are zeroed.
        let bottom = grids.iter().find(|g| g.name == "part1_z_min").unwrap();
        for (p, n) in bottom.points.iter().zip(&bottom.normals) {
            if p.y > 0.0 && p.y < 10.0 {
                assert_eq!(n.norm(), 0.0, "{p:?}");
            }
        }
        let top = grids.iter().find(|g| g.name == "part1_z_max").unwrap();
        assert!(top.normals.iter().all(|n| n.norm() == 1.0));
    }
}
