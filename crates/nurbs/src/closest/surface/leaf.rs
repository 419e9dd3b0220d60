//! Leaves of the surface projector: their construction (subdivision of the Bézier patches,
//! boxes, cones, bounds, samples, edge neighbours) and the leaf solve of a query (exclusion
//! tests, Newton, branch and bound where the convexity certificate fails).

use nalgebra::Vector3;

use super::bounds::{HessianBounds, VBox};
use super::cones::Cone;
use super::grad::GradSigns;
use super::tree::{Aabb, Obb};
use super::SurfaceProjector;
use crate::closest::bezier::BezierPatch;
use crate::closest::newton::{minimise, Local};

/// A piece of a Bézier patch with its bounds and starting samples.
#[derive(Debug, Clone)]
pub(crate) struct Leaf {
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
    pub patch: usize,
    pub obb: Obb,
    pub aabb: Aabb,
    pub(super) cone_u: Option<Cone>,
    pub(super) cone_v: Option<Cone>,
    pub(super) obb_half_diag: f64,
    /// May the leaf be dropped because the distance decreases towards edge
    /// `[u0, u1, v0, v1]` (edge interior to the surface and C¹ across it)?
    pub(super) exclude_towards: [bool; 4],
    /// Leaves sharing the whole edge `[u0, u1, v0, v1]` (`u32::MAX` if none).
    pub(super) edge_neighbours: [u32; 4],
    pub(super) samples: [(f64, f64, Vector3<f64>); 9],
    /// Interval data of the Hessian certificate.
    pub(super) hess: HessianBounds,
    /// Bernstein sign certificate of the distance gradient (see `grad`).
    pub(super) grad: Option<GradSigns>,
}

/// Leaves whose normals turn by more than this (cosine) are split.
pub(super) const LEAF_NORMAL_COS: f64 = 0.82;

/// Deepest leaf split per patch direction (2^3 = 8 pieces).
pub(super) const MAX_LEAF_DEPTH: usize = 3;

/// Largest ratio of a leaf's chord lengths in u and v before the long direction is split.
pub(super) const LEAF_ASPECT: f64 = 3.0;

impl SurfaceProjector {
    /// Minimises over one leaf unless it is certified not to hold a point closer than the
    /// current best. The caller has already checked that the leaf's oriented box is nearer
    /// than the best (the walk's stack entry of a leaf holds that box distance). Returns the
    /// leaf minimum and whether it is a KKT point of the whole domain.
    #[inline]
    pub(super) fn solve_leaf(
        &self,
        index: usize,
        q: &Vector3<f64>,
        best: Option<(Local, bool)>,
        cert: &CertMemo,
    ) -> Option<(Local, bool)> {
        let leaf = &self.leaves[index];
        // The convexity certificate is computed only when it is needed (skip test below or
        // before solving), after the cheaper cone tests.
        let mut certified: Option<bool> = None;
        if let Some((b, true)) = best {
            // A stationary point of the surface inside a leaf where the distance is convex
            // is that leaf's minimum.
            if b.u >= leaf.u0 && b.u <= leaf.u1 && b.v >= leaf.v0 && b.v <= leaf.v1 {
                let c = cert.certifies(self, index, q);
                certified = Some(c);
                if c {
                    return None;
                }
            }
        }
        let cq = leaf.obb.c - q;
        let max_w = cq.norm() + leaf.obb_half_diag;
        if let Some(c) = &leaf.cone_u {
            match c.sign(&leaf.obb, &cq, max_w) {
                1 if leaf.exclude_towards[0] => return None,
                -1 if leaf.exclude_towards[1] => return None,
                _ => {}
            }
        }
        if let Some(c) = &leaf.cone_v {
            match c.sign(&leaf.obb, &cq, max_w) {
                1 if leaf.exclude_towards[2] => return None,
                -1 if leaf.exclude_towards[3] => return None,
                _ => {}
            }
        }
        if let Some((b, true)) = best {
            // The best is a stationary (KKT) point inside a neighbour sharing a whole edge
            // across which the surface is C¹: if both leaves are certified convex, the
            // distance is convex on their union (a rectangle; piecewise convex and C¹), whose
            // unique minimum is then the best — nothing closer here.
            for (k, &nb) in leaf.edge_neighbours.iter().enumerate() {
                let Some(n) = self.leaves.get(nb as usize) else {
                    continue;
                };
                if !leaf.exclude_towards[k] {
                    continue;
                }
                if b.u >= n.u0 && b.u <= n.u1 && b.v >= n.v0 && b.v <= n.v1 {
                    let c = *certified.get_or_insert_with(|| leaf.hess.certifies(&leaf.obb, q));
                    if c && cert.certifies(self, nb as usize, q) {
                        return None;
                    }
                    break;
                }
            }
        }
        if let Some(g) = &leaf.grad {
            // The tighter Bernstein test of the same monotonicity, per direction (after
            // the cheaper tests above, which settle most leaves of a warm query).
            let ex = &leaf.exclude_towards;
            for dir in 0..2 {
                if ex[2 * dir] || ex[2 * dir + 1] {
                    match g.sign(dir, q) {
                        1 if ex[2 * dir] => return None,
                        -1 if ex[2 * dir + 1] => return None,
                        _ => {}
                    }
                }
            }
        }
        let patch = &self.patches[leaf.patch];
        // Start from the current best clamped into the leaf when it lies just across an
        // edge (it is then next to the leaf's own minimum), else from the nearest sample.
        let mut clamped = None;
        if let Some((b, _)) = best {
            let cu = b.u.clamp(leaf.u0, leaf.u1);
            let cv = b.v.clamp(leaf.v0, leaf.v1);
            if (cu - b.u).abs() <= 0.25 * (leaf.u1 - leaf.u0)
                && (cv - b.v).abs() <= 0.25 * (leaf.v1 - leaf.v0)
            {
                clamped = Some((cu, cv));
            }
        }
        let start = clamped.unwrap_or_else(|| {
            let mut start = (leaf.samples[0].0, leaf.samples[0].1);
            let mut d_start = f64::INFINITY;
            for (u, v, p) in &leaf.samples {
                let d = (p - q).norm_squared();
                if d < d_start {
                    d_start = d;
                    start = (*u, *v);
                }
            }
            start
        });
        let mut l = minimise(
            |u, v| patch.derivs2(u, v),
            q,
            (leaf.u0, leaf.v0),
            (leaf.u1, leaf.v1),
            start,
            self.step_tol,
        );
        if !certified.unwrap_or_else(|| leaf.hess.certifies(&leaf.obb, q)) {
            // The distance may have several minima on this leaf (query beyond a centre of
            // curvature): search the leaf by branch and bound.
            // The caller keeps this leaf's answer only when it is strictly nearer than the
            // best so far: pieces at least that far away cannot matter and are dropped too.
            let bound = best.map_or(f64::INFINITY, |(b, _)| b.d2);
            let sub = patch.sub_patch(leaf.u0, leaf.u1, leaf.v0, leaf.v1);
            self.branch_and_bound(patch, &sub, &leaf.obb.axes, q, bound, &mut l, 1);
        }
        let ((ua, ub), (va, vb)) = self.domain;
        let kkt_u = match l.active[0] {
            0 => true,
            -1 => l.u <= ua,
            _ => l.u >= ub,
        };
        let kkt_v = match l.active[1] {
            0 => true,
            -1 => l.v <= va,
            _ => l.v >= vb,
        };
        Some((l, l.converged && kkt_u && kkt_v))
    }
}

/// The convexity certificate of the last leaf asked for within one query (the leaf holding
/// the current best): the walk asks for it once when it reaches that leaf and again for each
/// neighbour that is excluded through it.
#[derive(Debug, Default)]
pub(super) struct CertMemo(std::cell::Cell<Option<(usize, bool)>>);

impl CertMemo {
    /// `leaves[index].hess.certifies(leaves[index].obb, q)` for this query's `q`.
    #[inline]
    pub(super) fn certifies(&self, p: &SurfaceProjector, index: usize, q: &Vector3<f64>) -> bool {
        if let Some((i, c)) = self.0.get() {
            if i == index {
                return c;
            }
        }
        let leaf = &p.leaves[index];
        let c = leaf.hess.certifies(&leaf.obb, q);
        self.0.set(Some((index, c)));
        c
    }
}

/// Deepest query-time subdivision of a leaf whose distance function is not certified
/// convex: the leaf itself is depth 1, so the finest pieces are 2⁻⁵ = 1/32 of the leaf per
/// direction.
pub(super) const MAX_BB_DEPTH: usize = 6;

impl SurfaceProjector {
    /// Branch and bound over de Casteljau pieces of a leaf on which the distance may have
    /// several minima: a piece is dropped when its control-net box is at least the best
    /// distance away, minimised by Newton when its Hessian certificate holds (or at the
    /// depth limit), and split into four otherwise, nearer pieces first. A piece is also
    /// dropped when its box is at least `bound` (squared) away: the caller's best answer from
    /// other leaves, which a point of this leaf must beat strictly to count. `best` then
    /// holds the leaf's minimum only where that minimum is below `bound`. Allocates the
    /// pieces' control nets; only reached for queries beyond a centre of curvature of the leaf.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn branch_and_bound(
        &self,
        patch: &BezierPatch,
        sub: &BezierPatch,
        axes: &[Vector3<f64>; 3],
        q: &Vector3<f64>,
        bound: f64,
        best: &mut Local,
        depth: usize,
    ) {
        let pts: Vec<Vector3<f64>> = sub.points().collect();
        let obb = Obb::from_points(&pts, *axes);
        if obb.dist2(q) >= best.d2.min(bound) {
            return;
        }
        if depth >= MAX_BB_DEPTH || HessianBounds::of(sub, &pts, axes).certifies(&obb, q) {
            // Start from the nearest of the corners and the centre.
            let (um, vm) = (0.5 * (sub.u0 + sub.u1), 0.5 * (sub.v0 + sub.v1));
            let mut start = (um, vm);
            let mut ds = (patch.point(um, vm) - q).norm_squared();
            for (u, v) in [
                (sub.u0, sub.v0),
                (sub.u1, sub.v0),
                (sub.u0, sub.v1),
                (sub.u1, sub.v1),
            ] {
                let d = (patch.point(u, v) - q).norm_squared();
                if d < ds {
                    ds = d;
                    start = (u, v);
                }
            }
            let l = minimise(
                |u, v| patch.derivs2(u, v),
                q,
                (sub.u0, sub.v0),
                (sub.u1, sub.v1),
                start,
                self.step_tol,
            );
            if l.d2 < best.d2 {
                *best = l;
            }
            return;
        }
        let (um, vm) = (0.5 * (sub.u0 + sub.u1), 0.5 * (sub.v0 + sub.v1));
        let mut kids: [(f64, BezierPatch); 4] = [
            (sub.u0, um, sub.v0, vm),
            (sub.u0, um, vm, sub.v1),
            (um, sub.u1, sub.v0, vm),
            (um, sub.u1, vm, sub.v1),
        ]
        .map(|(a, b, c, d)| {
            let k = sub.sub_patch(a, b, c, d);
            let mut bx = Aabb::empty();
            for p in k.points() {
                bx.add(&p);
            }
            (bx.dist2(q), k)
        });
        kids.sort_by(|x, y| x.0.total_cmp(&y.0));
        for k in &kids {
            if k.0 >= best.d2.min(bound) {
                // Sorted: the remaining pieces' boxes are no nearer.
                break;
            }
            self.branch_and_bound(patch, &k.1, axes, q, bound, best, depth + 1);
        }
    }
}

pub(super) fn lerp(a: f64, b: f64, i: usize, n: usize) -> f64 {
    if i == n {
        b
    } else {
        a + (b - a) * i as f64 / n as f64
    }
}

/// How many pieces a patch is split into in u and v so that each piece's normals turn by at
/// most ~35° (estimated on a 5×5 grid of normals per piece).
pub(super) fn leaf_split(patch: &BezierPatch) -> (usize, usize) {
    let mut su = 1;
    let mut sv = 1;
    for _ in 0..MAX_LEAF_DEPTH {
        let mut worst_u: f64 = 1.0;
        let mut worst_v: f64 = 1.0;
        for i in 0..su {
            for j in 0..sv {
                let u0 = lerp(patch.u0, patch.u1, i, su);
                let u1 = lerp(patch.u0, patch.u1, i + 1, su);
                let v0 = lerp(patch.v0, patch.v1, j, sv);
                let v1 = lerp(patch.v0, patch.v1, j + 1, sv);
                let uc = 0.5 * (u0 + u1);
                let vc = 0.5 * (v0 + v1);
                let Some(nc) = patch.derivs2(uc, vc).normal() else {
                    continue;
                };
                for k in 0..=4 {
                    let t = k as f64 / 4.0;
                    if let Some(n) = patch.derivs2(u0 + (u1 - u0) * t, vc).normal() {
                        worst_u = worst_u.min(n.dot(&nc));
                    }
                    if let Some(n) = patch.derivs2(uc, v0 + (v1 - v0) * t).normal() {
                        worst_v = worst_v.min(n.dot(&nc));
                    }
                }
            }
        }
        let mut split_u = worst_u < LEAF_NORMAL_COS;
        let mut split_v = worst_v < LEAF_NORMAL_COS;
        if !split_u && !split_v {
            // Convexity certificate for typical queries: every piece should certify queries
            // at a distance of its own size above or below any of its corners' footprints.
            let (fail_u, fail_v) = certificate_failures(patch, su, sv);
            // Elongated pieces defeat the pruning tests (the sign of the distance's gradient
            // along the short direction changes along the long one on twisted surfaces)
            // and the certificate (through the twist `S_uv` over the long extent): split
            // the long direction until the pieces' chords are within a ratio.
            let (cu, cv) = piece_chords(patch, su, sv);
            if cu > LEAF_ASPECT * cv {
                split_u = true;
            } else if cv > LEAF_ASPECT * cu {
                split_v = true;
            } else {
                split_u = fail_u;
                split_v = fail_v;
            }
        }
        if !split_u && !split_v {
            break;
        }
        if split_u {
            su *= 2;
        }
        if split_v {
            sv *= 2;
        }
    }
    (su, sv)
}

/// Largest chord lengths `(along u, along v)` of the pieces of a `su × sv` split, measured
/// through each piece's centre.
pub(super) fn piece_chords(patch: &BezierPatch, su: usize, sv: usize) -> (f64, f64) {
    let (mut cu, mut cv) = (0.0f64, 0.0f64);
    for i in 0..su {
        for j in 0..sv {
            let u0 = lerp(patch.u0, patch.u1, i, su);
            let u1 = lerp(patch.u0, patch.u1, i + 1, su);
            let v0 = lerp(patch.v0, patch.v1, j, sv);
            let v1 = lerp(patch.v0, patch.v1, j + 1, sv);
            let (uc, vc) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
            cu = cu.max((patch.point(u1, vc) - patch.point(u0, vc)).norm());
            cv = cv.max((patch.point(uc, v1) - patch.point(uc, v0)).norm());
        }
    }
    (cu, cv)
}

/// Oriented frame of a piece: `S_u` direction, binormal, normal at the centre (or the
/// coordinate axes where the surface is singular).
pub(super) fn piece_axes(patch: &BezierPatch, sub: &BezierPatch) -> [Vector3<f64>; 3] {
    let d = patch.derivs2(0.5 * (sub.u0 + sub.u1), 0.5 * (sub.v0 + sub.v1));
    match (d.su.try_normalize(0.0), d.normal()) {
        (Some(e1), Some(n)) => [e1, n.cross(&e1), n],
        _ => [Vector3::x(), Vector3::y(), Vector3::z()],
    }
}

/// Whether some piece of the `su × sv` split fails the Hessian certificate for the typical
/// queries `c ± D·n ± h₁ e₁ ± h₂ e₂` (`D` the piece's larger half extent), and in which
/// direction the parametric distortion (`|S_uu|` vs `|S_vv|` times the extent) is larger.
pub(super) fn certificate_failures(patch: &BezierPatch, su: usize, sv: usize) -> (bool, bool) {
    let (mut fu, mut fv) = (false, false);
    for i in 0..su {
        for j in 0..sv {
            let sub = patch.sub_patch(
                lerp(patch.u0, patch.u1, i, su),
                lerp(patch.u0, patch.u1, i + 1, su),
                lerp(patch.v0, patch.v1, j, sv),
                lerp(patch.v0, patch.v1, j + 1, sv),
            );
            let pts: Vec<Vector3<f64>> = sub.points().collect();
            let axes = piece_axes(patch, &sub);
            let obb = Obb::from_points(&pts, axes);
            let hess = HessianBounds::of(&sub, &pts, &axes);
            let dd = obb.h[0].max(obb.h[1]);
            let mut ok = true;
            for s in [-1.0, 1.0] {
                for t1 in [-1.0, 1.0] {
                    for t2 in [-1.0, 1.0] {
                        let q = obb.c
                            + axes[2] * (s * dd)
                            + axes[0] * (t1 * obb.h[0])
                            + axes[1] * (t2 * obb.h[1]);
                        ok &= hess.certifies(&obb, &q);
                    }
                }
            }
            if !ok {
                let mag = |b: &VBox| {
                    b.0.iter()
                        .map(|iv| iv.lo.abs().max(iv.hi.abs()))
                        .fold(0.0, f64::max)
                };
                if mag(&hess.suu) * obb.h[0] >= mag(&hess.svv) * obb.h[1] {
                    fu = true;
                } else {
                    fv = true;
                }
            }
        }
    }
    (fu, fv)
}

pub(super) fn make_leaf(
    patch: &BezierPatch,
    sub: &BezierPatch,
    index: usize,
    exclude_towards: [bool; 4],
    rational: bool,
) -> Leaf {
    let pts: Vec<Vector3<f64>> = sub.points().collect();
    let mut aabb = Aabb::empty();
    for p in &pts {
        aabb.add(p);
    }
    let axes = piece_axes(patch, sub);
    let obb = Obb::from_points(&pts, axes);
    let obb_half_diag = Vector3::new(obb.h[0], obb.h[1], obb.h[2]).norm();
    let (cone_u, cone_v) = if rational {
        let (du, dv) = super::grad::rational_tangent_coefficients(sub);
        (Cone::of(&du, &obb), Cone::of(&dv, &obb))
    } else {
        let q1 = sub.q + 1;
        let mut du = Vec::new();
        let mut dv = Vec::new();
        for i in 0..=sub.p {
            for j in 0..=sub.q {
                if i < sub.p {
                    du.push(pts[(i + 1) * q1 + j] - pts[i * q1 + j]);
                }
                if j < sub.q {
                    dv.push(pts[i * q1 + j + 1] - pts[i * q1 + j]);
                }
            }
        }
        (Cone::of(&du, &obb), Cone::of(&dv, &obb))
    };
    let hess = HessianBounds::of(sub, &pts, &obb.axes);
    let mut samples = [(0.0, 0.0, Vector3::zeros()); 9];
    for a in 0..3 {
        for b in 0..3 {
            let u = lerp(sub.u0, sub.u1, a, 2);
            let v = lerp(sub.v0, sub.v1, b, 2);
            samples[a * 3 + b] = (u, v, patch.point(u, v));
        }
    }
    Leaf {
        u0: sub.u0,
        u1: sub.u1,
        v0: sub.v0,
        v1: sub.v1,
        patch: index,
        obb,
        aabb,
        cone_u,
        cone_v,
        obb_half_diag,
        exclude_towards,
        edge_neighbours: [u32::MAX; 4],
        samples,
        hess,
        grad: GradSigns::new(sub),
    }
}

/// Records, for every leaf, the leaves that share one of its edges entirely (same edge
/// parameter and the same extent in the other direction).
pub(super) fn link_edge_neighbours(leaves: &mut [Leaf]) {
    use std::collections::HashMap;
    // Key: (direction, edge parameter, extent start, extent end) as bit patterns; value:
    // (leaf, side) pairs on that edge.
    type EdgeKey = (u8, u64, u64, u64);
    let mut edges: HashMap<EdgeKey, Vec<(usize, usize)>> = HashMap::new();
    for (i, l) in leaves.iter().enumerate() {
        let keys = [
            (
                (0u8, l.u0.to_bits(), l.v0.to_bits(), l.v1.to_bits()),
                0usize,
            ),
            ((0u8, l.u1.to_bits(), l.v0.to_bits(), l.v1.to_bits()), 1),
            ((1u8, l.v0.to_bits(), l.u0.to_bits(), l.u1.to_bits()), 2),
            ((1u8, l.v1.to_bits(), l.u0.to_bits(), l.u1.to_bits()), 3),
        ];
        for (key, side) in keys {
            edges.entry(key).or_default().push((i, side));
        }
    }
    for sharing in edges.values() {
        if let [(a, sa), (b, sb)] = sharing[..] {
            if sa != sb {
                leaves[a].edge_neighbours[sa] = b as u32;
                leaves[b].edge_neighbours[sb] = a as u32;
            }
        }
    }
}
