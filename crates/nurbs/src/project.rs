//! Projection of a point onto a surface along a given direction (line / ray – surface
//! intersection), nearest hit first.
//!
//! Method: the line `q + t·d` is tested against every leaf of a [`SurfaceProjector`] (oriented
//! box, slab test); a leaf that may be hit is subdivided by de Casteljau while its control
//! net, seen along `d`, still surrounds the line (convex-hull property: if the 2D box of the
//! net's projection on the plane ⟂ `d` misses the origin, the piece cannot be hit). Pieces
//! that are small (≤ 1/16 of the leaf per direction) or nearly flat along the line are
//! solved by Newton's method on the two equations `(S(u,v) − q)·e₁ = (S(u,v) − q)·e₂ = 0`
//! (`e₁, e₂ ⟂ d`), from the piece's centre; a root counts when it lies in the piece's
//! parameter box. Roots found twice on shared edges are merged.
//!
//! Tolerance: a hit satisfies `|(S − q) × d| ≤ 1e-12·(1 + size)` mm. Lines tangent to the
//! surface (double roots) converge linearly and may be reported once, twice or, if the line
//! only grazes within round-off, not at all. Cost: a few µs per query on smooth surfaces;
//! allocates only for the list of hits.

use nalgebra::Vector3;

use crate::closest::bezier::BezierPatch;
use crate::closest::SurfaceProjector;

/// Why a projection could not be attempted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectError {
    /// The direction is zero or not finite, or the point is not finite.
    #[error("invalid projection input: {0}")]
    InvalidInput(&'static str),
}

/// Which intersections count as the projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RayMode {
    /// Only forward hits `t ≥ 0`; the nearest is the smallest `t`.
    Forward,
    /// The whole line; the nearest is the smallest `|t|`.
    Line,
}

/// An intersection of the line `q + t·d` (`d` normalised) with the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Surface parameter `u`.
    pub u: f64,
    /// Surface parameter `v`.
    pub v: f64,
    /// `S(u, v)`.
    pub point: Vector3<f64>,
    /// Signed distance along the unit direction from `q` to the hit (mm).
    pub t: f64,
}

/// Deepest subdivision of a leaf (1/16 of the leaf per direction).
const MAX_DEPTH: usize = 4;

impl SurfaceProjector {
    /// All intersections of the line through `q` with direction `dir` (any length), sorted by
    /// `t`, restricted to `t ≥ 0` in [`RayMode::Forward`]. See the module docs.
    pub fn intersect_line(
        &self,
        q: &Vector3<f64>,
        dir: &Vector3<f64>,
        mode: RayMode,
    ) -> Result<Vec<RayHit>, ProjectError> {
        if !q.iter().all(|c| c.is_finite()) {
            return Err(ProjectError::InvalidInput("point is not finite"));
        }
        let d = match dir.try_normalize(0.0) {
            Some(d) if d.iter().all(|c| c.is_finite()) => d,
            _ => {
                return Err(ProjectError::InvalidInput(
                    "direction is zero or not finite",
                ))
            }
        };
        let e1 = d
            .cross(&if d.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            })
            .normalize();
        let e2 = d.cross(&e1);
        let frame = Frame { q: *q, d, e1, e2 };
        let size = self
            .nodes
            .first()
            .map_or(0.0, |n| (n.aabb.max - n.aabb.min).norm());
        let tol = 1e-12 * (1.0 + size.min(1e6));
        let mut hits: Vec<RayHit> = Vec::new();
        for leaf in &self.leaves {
            if !line_hits_obb(&frame, &leaf.obb, mode) {
                continue;
            }
            let patch = &self.patches[leaf.patch];
            let sub = patch.sub_patch(leaf.u0, leaf.u1, leaf.v0, leaf.v1);
            self.recurse(patch, &sub, &frame, mode, 0, tol, &mut hits);
        }
        hits.sort_by(|a, b| a.t.total_cmp(&b.t));
        hits.dedup_by(|a, b| (a.point - b.point).norm() <= 1e3 * tol);
        Ok(hits)
    }

    /// The nearest intersection of the line through `q` along `dir` (see [`RayMode`]), or
    /// `None` if the line misses the surface.
    pub fn project_along(
        &self,
        q: &Vector3<f64>,
        dir: &Vector3<f64>,
        mode: RayMode,
    ) -> Result<Option<RayHit>, ProjectError> {
        let hits = self.intersect_line(q, dir, mode)?;
        Ok(hits
            .into_iter()
            .min_by(|a, b| a.t.abs().total_cmp(&b.t.abs())))
    }

    #[allow(clippy::too_many_arguments)]
    fn recurse(
        &self,
        patch: &BezierPatch,
        sub: &BezierPatch,
        f: &Frame,
        mode: RayMode,
        depth: usize,
        tol: f64,
        hits: &mut Vec<RayHit>,
    ) {
        // Projection of the control net on the plane ⟂ d (convex hull test).
        let (mut amin, mut amax, mut bmin, mut bmax, mut tmax) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        );
        let mut extent: f64 = 0.0;
        for p in sub.points() {
            let w = p - f.q;
            let (a, b) = (w.dot(&f.e1), w.dot(&f.e2));
            amin = amin.min(a);
            amax = amax.max(a);
            bmin = bmin.min(b);
            bmax = bmax.max(b);
            tmax = tmax.max(w.dot(&f.d));
            extent = extent.max(w.norm());
        }
        let pad = tol + 1e-12 * extent;
        if amin > pad || amax < -pad || bmin > pad || bmax < -pad {
            return;
        }
        if mode == RayMode::Forward && tmax < -pad {
            return;
        }
        let flat = {
            let c = sub.derivs2(0.5 * (sub.u0 + sub.u1), 0.5 * (sub.v0 + sub.v1));
            c.normal().is_some_and(|n| n.dot(&f.d).abs() > 0.5)
        };
        if depth >= MAX_DEPTH || (flat && depth >= 1) {
            if let Some(h) = newton_line(patch, sub, f, tol) {
                if mode == RayMode::Line || h.t >= -tol {
                    hits.push(h);
                }
            }
            if depth >= MAX_DEPTH || flat {
                return;
            }
        }
        let um = 0.5 * (sub.u0 + sub.u1);
        let vm = 0.5 * (sub.v0 + sub.v1);
        for (ua, ub) in [(sub.u0, um), (um, sub.u1)] {
            for (va, vb) in [(sub.v0, vm), (vm, sub.v1)] {
                let child = sub.sub_patch(ua, ub, va, vb);
                self.recurse(patch, &child, f, mode, depth + 1, tol, hits);
            }
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Frame {
    q: Vector3<f64>,
    d: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
}

/// Slab test of the line against an oriented box.
fn line_hits_obb(f: &Frame, obb: &crate::closest::surface_bounds::Obb, mode: RayMode) -> bool {
    let mut t0 = f64::NEG_INFINITY;
    let mut t1 = f64::INFINITY;
    if mode == RayMode::Forward {
        t0 = 0.0;
    }
    let rel = f.q - obb.c;
    for k in 0..3 {
        let o = rel.dot(&obb.axes[k]);
        let dk = f.d.dot(&obb.axes[k]);
        let h = obb.h[k] * (1.0 + 1e-9) + 1e-9;
        if dk.abs() < 1e-300 {
            if o.abs() > h {
                return false;
            }
        } else {
            let a = (-h - o) / dk;
            let b = (h - o) / dk;
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// Newton on `((S − q)·e₁, (S − q)·e₂) = 0` from the centre of `sub`, evaluated on `patch`;
/// a root inside `sub`'s box (closed, with a relative slack of 1e-9) is returned.
fn newton_line(patch: &BezierPatch, sub: &BezierPatch, f: &Frame, tol: f64) -> Option<RayHit> {
    let (mut u, mut v) = (0.5 * (sub.u0 + sub.u1), 0.5 * (sub.v0 + sub.v1));
    let (pu0, pu1, pv0, pv1) = (patch.u0, patch.u1, patch.v0, patch.v1);
    for _ in 0..40 {
        let e = patch.derivs2(u, v);
        let w = e.p - f.q;
        let (fa, fb) = (w.dot(&f.e1), w.dot(&f.e2));
        if fa.hypot(fb) <= tol {
            let su = 1e-9 * (sub.u1 - sub.u0);
            let sv = 1e-9 * (sub.v1 - sub.v0);
            if u >= sub.u0 - su && u <= sub.u1 + su && v >= sub.v0 - sv && v <= sub.v1 + sv {
                return Some(RayHit {
                    u,
                    v,
                    point: e.p,
                    t: w.dot(&f.d),
                });
            }
            return None;
        }
        let (a11, a12) = (e.su.dot(&f.e1), e.sv.dot(&f.e1));
        let (a21, a22) = (e.su.dot(&f.e2), e.sv.dot(&f.e2));
        let det = a11 * a22 - a12 * a21;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let du = (-fa * a22 + fb * a12) / det;
        let dv = (-fb * a11 + fa * a21) / det;
        u = (u + du).clamp(pu0, pu1);
        v = (v + dv).clamp(pv0, pv1);
    }
    None
}
