//! The blade side to flank, its sample points, the facing side of the adjacent blade, and
//! the initial cutter locations (paper 002, "Initial tool path": two-point tangency, then the
//! ball end lowered onto the hub).

use crate::FlankError;
use cam_core::{CutterShape, GuideCurve, Point3, Vector3};
use impeller_model::{Blade, Impeller, RevolvedSurface, Side};
use nurbs::fit::{interpolate_curve, Parametrisation};

/// Fixed-point rounds of the two-point tangency (contact heights depend on the tip, the tip
/// on the axis): the heights move by far less than 1e-6 mm after four rounds on every fixture.
const TANGENCY_ROUNDS: usize = 4;
/// Bisection steps lowering the ball onto the hub: the bracket is at most a few ball radii
/// wide, 50 halvings leave < 1e-12 mm.
const HUB_BISECTIONS: usize = 50;
/// Fraction of the u domain trimmed at the leading and trailing edges for the accuracy
/// samples (the rounded edges are not flanked).
const EDGE_TRIM: f64 = 0.02;

/// How the initial cutter locations are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialPath {
    /// The axis tangent to the cutter at the hub-edge and shroud-edge points of each ruling
    /// (two-point tangency), the ball then lowered onto the hub (paper 002).
    TwoPoint,
    /// The axis parallel to the ruling, offset along the normal at the ruling's midpoint by
    /// the cutter radius there, the ball then lowered onto the hub (a second, cruder start).
    MidNormal,
}

/// One blade side prepared for flank milling.
#[derive(Debug, Clone)]
pub struct FlankSide {
    /// The design blade.
    pub blade: Blade,
    /// The side flanked.
    pub side: Side,
    /// Side parameters v of the hub and shroud edges.
    pub v_range: (f64, f64),
    /// Hub surface.
    pub hub: RevolvedSurface,
    /// Accuracy sample points of the design side, `nu × nv` row-major along u.
    pub samples: Vec<Point3>,
    /// Grid of the samples (along the path, along the rulings).
    pub grid: (usize, usize),
    /// `(u, v)` of each sample.
    pub sample_uv: Vec<(f64, f64)>,
    /// Clearance sample points on the facing side of the adjacent blade.
    pub adjacent: Vec<Point3>,
}

impl FlankSide {
    /// Prepares `side` of the impeller's main blade: `nu × nv` accuracy samples on the design
    /// side between the hub and shroud edges (edges trimmed by [`EDGE_TRIM`] of u), and
    /// `nu × nv` clearance samples on the nearest side of a neighbouring blade facing it (the
    /// main blades next to it and the nearest splitters are candidates).
    /// O(nu·nv) surface evaluations.
    pub fn new(impeller: &Impeller, side: Side, nu: usize, nv: usize) -> Result<Self, FlankError> {
        if nu < 2 || nv < 2 {
            return Err(FlankError::Param(
                "sample grid needs at least 2 × 2 points".into(),
            ));
        }
        let set = impeller.main();
        let blade = set.blade().clone();
        let v_range = match blade.design() {
            Some(_) => blade.hub_shroud_v(side),
            None => impeller.span_v_range(&blade, side).map_err(|e| {
                FlankError::Geometry(format!("{side:?} side: hub or shroud edge not found: {e}"))
            })?,
        };
        let s = blade.side(side);
        let ((u0, u1), _) = s.domain();
        let (ua, ub) = (u0 + EDGE_TRIM * (u1 - u0), u1 - EDGE_TRIM * (u1 - u0));
        let mut samples = Vec::with_capacity(nu * nv);
        let mut sample_uv = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            let u = ua + (ub - ua) * i as f64 / (nu - 1) as f64;
            for j in 0..nv {
                let v = v_range.0 + (v_range.1 - v_range.0) * j as f64 / (nv - 1) as f64;
                samples.push(Point3::from(s.point(u, v)));
                sample_uv.push((u, v));
            }
        }
        // The facing side: of the two neighbours' sides, the one nearest to the point one
        // millimetre out of the side's middle.
        let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v_range.0 + v_range.1));
        let n_mid = blade.outward_normal(side, um, vm).ok_or_else(|| {
            FlankError::Geometry(format!("{side:?} side: no normal at its middle"))
        })?;
        let probe = s.point(um, vm) + n_mid;
        let count = set.count();
        let mut candidates: Vec<Blade> = [1, count.saturating_sub(1)]
            .into_iter()
            .filter(|&k| k > 0 && k < count)
            .map(|k| set.instance(k))
            .collect();
        // Splitters sit between main blades: the nearest one may face the side.
        if let Some(sp) = impeller.splitter() {
            let n = sp.count();
            candidates.extend([0, n.saturating_sub(1)].into_iter().map(|k| sp.instance(k)));
        }
        let mut best: Option<(f64, Blade, Side)> = None;
        for other in candidates {
            for os in [Side::Pressure, Side::Suction] {
                let sp = impeller_model::query::closest_point(other.side(os), &probe, None);
                if best.as_ref().is_none_or(|b| sp.distance < b.0) {
                    best = Some((sp.distance, other.clone(), os));
                }
            }
        }
        let mut adjacent = Vec::new();
        if let Some((_, other, os)) = best {
            let o = other.side(os);
            let ((a0, a1), _) = o.domain();
            let (w0, w1) = other.hub_shroud_v(os);
            for i in 0..nu {
                let u = a0 + (a1 - a0) * i as f64 / (nu - 1) as f64;
                for j in 0..nv {
                    let v = w0 + (w1 - w0) * j as f64 / (nv - 1) as f64;
                    adjacent.push(Point3::from(o.point(u, v)));
                }
            }
        }
        Ok(Self {
            blade,
            side,
            v_range,
            hub: impeller.hub().clone(),
            samples,
            grid: (nu, nv),
            sample_uv,
            adjacent,
        })
    }

    /// Signed distance of `p` from the hub (positive on the channel side).
    pub fn hub_distance(&self, p: &Vector3) -> f64 {
        self.hub.signed_distance(p)
    }

    /// Initial cutter locations for `shape` at `n` rulings evenly spaced in u: ball centres
    /// `P0` and upper axis points `P1 = P0 + a·upper` (see [`InitialPath`]); `upper` is the
    /// largest contact height of the shroud edge above the ball centre. O(n · (rounds +
    /// bisections)) point evaluations.
    pub fn initial_locations(
        &self,
        shape: &CutterShape,
        n: usize,
        how: InitialPath,
    ) -> Result<(Vec<Vector3>, Vec<Vector3>), FlankError> {
        let r = ball_radius(shape);
        let s = self.blade.side(self.side);
        let ((u0, u1), _) = s.domain();
        let mut centres = Vec::with_capacity(n);
        let mut axes = Vec::with_capacity(n);
        let mut upper: f64 = 0.0;
        for i in 0..n {
            let u = u0 + (u1 - u0) * i as f64 / (n - 1).max(1) as f64;
            let (a_pt, b_pt) = (s.point(u, self.v_range.0), s.point(u, self.v_range.1));
            let normal = |v: f64| {
                self.blade.outward_normal(self.side, u, v).ok_or_else(|| {
                    FlankError::Geometry(format!("{:?} side: no normal at u = {u:.4}", self.side))
                })
            };
            let (na, nb) = (normal(self.v_range.0)?, normal(self.v_range.1)?);
            let (mut h_a, mut h_b) = (r, r + (b_pt - a_pt).norm());
            let mut tip = a_pt;
            let mut axis = (b_pt - a_pt).normalize();
            for _ in 0..TANGENCY_ROUNDS {
                let (pa, pb) = match how {
                    InitialPath::TwoPoint => (
                        a_pt + na * member_radius(shape, h_a),
                        b_pt + nb * member_radius(shape, h_b),
                    ),
                    InitialPath::MidNormal => {
                        let vm = 0.5 * (self.v_range.0 + self.v_range.1);
                        let nm = normal(vm)?;
                        let off = nm * member_radius(shape, 0.5 * (h_a + h_b));
                        (a_pt + off, b_pt + off)
                    }
                };
                let d = pb - pa;
                if d.norm() < 1e-9 {
                    return Err(FlankError::Geometry(format!(
                        "{:?} side: degenerate ruling at u = {u:.4}",
                        self.side
                    )));
                }
                axis = d.normalize();
                tip = self.lower_onto_hub(&pa, &axis, r)?;
                h_a = (pa - tip).dot(&axis);
                h_b = (pb - tip).dot(&axis);
            }
            upper = upper.max(h_b - r);
            centres.push(tip + axis * r);
            axes.push(axis);
        }
        let upper = upper.max(r);
        let tops = centres
            .iter()
            .zip(&axes)
            .map(|(c, a)| c + a * upper)
            .collect();
        Ok((centres, tops))
    }

    /// Tip on the line `p − λ·a` whose ball (radius `r`, centre tip + r·a) is tangent to the
    /// hub: bisection on `λ` of `hub_distance(centre) − r` (decreasing in λ as the ball goes
    /// down into the hub).
    fn lower_onto_hub(&self, p: &Vector3, a: &Vector3, r: f64) -> Result<Vector3, FlankError> {
        let f = |lam: f64| self.hub_distance(&(p - a * lam + a * r)) - r;
        let (mut lo, mut hi) = (-4.0 * r, 4.0 * r);
        let mut k = 0;
        while f(lo) < 0.0 || f(hi) > 0.0 {
            lo -= 4.0 * r;
            hi += 4.0 * r;
            k += 1;
            if k > 20 {
                return Err(FlankError::Geometry(format!(
                    "{:?} side: cannot bring the ball onto the hub near {:.2?}",
                    self.side,
                    p.as_slice()
                )));
            }
        }
        for _ in 0..HUB_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(p - a * (0.5 * (lo + hi)))
    }
}

/// Radius of the cutter's sphere-family member centred on the axis at height `c` above the
/// tip: `r + (c − r)·sin θ` for a tapered ball (the ball itself below `c = r`). A surface
/// tangent to the cutter at a point whose normal meets the axis at height `c` lies exactly
/// this far from that axis point (sphere_family module of cam-core), which is why the
/// two-point tangency offsets the contact points by it along their normals.
pub fn member_radius(shape: &CutterShape, c: f64) -> f64 {
    match *shape {
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => ball_radius + (c - ball_radius).max(0.0) * half_angle.sin(),
        other => ball_radius(&other),
    }
}

/// Ball radius of a ball or tapered ball end (the radius of the tip sphere).
pub fn ball_radius(shape: &CutterShape) -> f64 {
    match *shape {
        CutterShape::BallEnd { radius } => radius,
        CutterShape::TaperedBallEnd { ball_radius, .. } => ball_radius,
        CutterShape::BullNose { corner_radius, .. } => corner_radius,
        CutterShape::FlatEnd { radius }
        | CutterShape::TaperedFlatEnd {
            tip_radius: radius, ..
        } => radius,
    }
}

/// The two guide curves through the cutter locations: cubic interpolation with uniform
/// parameters, so both guides share knots and location `i` sits at `s = i/(n − 1)`.
pub fn guides_through(
    p0: &[Vector3],
    p1: &[Vector3],
) -> Result<(GuideCurve, GuideCurve), FlankError> {
    let fit = |pts: &[Vector3]| -> Result<GuideCurve, FlankError> {
        let c = interpolate_curve(pts, 3.min(pts.len() - 1), Parametrisation::Uniform, None)
            .map_err(|e| FlankError::Geometry(format!("guide interpolation: {e}")))?;
        Ok(GuideCurve::from_curve(&c)?)
    };
    Ok((fit(p0)?, fit(p1)?))
}
