//! The blade side to flank, its sample points, the facing side of the adjacent blade, and
//! the initial cutter locations (paper 002, "Initial tool path": two-point tangency, then the
//! ball end lowered onto the hub).

use crate::FlankError;
use cam_core::{CutterShape, GuideCurve, Point3, Vector3};
use cam_plan::Row;
use impeller_model::{Blade, Impeller, MeridionalCurve, RevolvedSurface, Side};
use nalgebra::Vector2;
use nurbs::fit::{interpolate_curve, Parametrisation};

/// Fixed-point rounds of the two-point tangency (contact heights depend on the tip, the tip
/// on the axis): the heights move by far less than 1e-6 mm after four rounds on every fixture.
const TANGENCY_ROUNDS: usize = 4;
/// Bisection steps lowering the ball onto the hub: the bracket is at most a few ball radii
/// wide, 50 halvings leave < 1e-12 mm.
const HUB_BISECTIONS: usize = 50;
/// Steps of `r/4` scanned down the axis for the first hub contact: 84 ball radii, the reach
/// of the former symmetric bracket search (20 widenings of 4 r).
const HUB_SCAN_STEPS: usize = 336;
/// Moves of an axis line that misses the hub towards it before giving up (one suffices when
/// the hub distance is linear near the closest approach, as beyond an end plane).
const HUB_SHIFTS: usize = 4;
/// Overlap (fraction of the ball radius) added to the gap when such a line is moved, so the
/// moved ball meets the hub transversally rather than grazing it.
const HUB_SHIFT_OVERLAP: f64 = 0.1;
/// Fine steps per along-sample of the arc-length/turning measure that places the samples
/// along the side ([`along_parameters`]).
const FINE_PER_SAMPLE: usize = 40;
/// Hub heights of the extra across rows in the fillet band, as fractions of the fillet radius
/// (overcut-only samples there: the ball end, not the flank, shapes that band).
const FILLET_BAND_ROWS: [f64; 4] = [0.2, 0.4, 0.6, 0.8];

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

impl InitialPath {
    /// The job-file spelling (`two_point`, `mid_normal`).
    pub fn as_str(self) -> &'static str {
        match self {
            InitialPath::TwoPoint => "two_point",
            InitialPath::MidNormal => "mid_normal",
        }
    }
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
    /// Prepares `side` of the impeller's main blade: accuracy samples on the design side over
    /// its whole u domain, leading and trailing edge included, and `nu × nv` clearance samples
    /// on the nearest side of a neighbouring blade facing it (the main blades next to it and
    /// the nearest splitters are candidates).
    ///
    /// The accuracy grid is `nu × (nv + 4)`: `nu` parameters along the side placed by
    /// [`along_parameters`] (half by arc length, half by turning of the normal, so the
    /// rounded leading-edge nose, where the normal turns by ~90° within a few per cent of the
    /// length, gets its share), and across `nv` rows evenly spaced in v from the hub edge to
    /// the shroud edge plus rows at 0.2, 0.4, 0.6 and 0.8 fillet radii above the hub edge
    /// (`FILLET_BAND_ROWS`), where the ball end can gouge the blade below the lowest flank
    /// row (issue 13: 0.065 mm at 0.89 mm above the hub of impeller-8+8). Samples in that
    /// band are overcut-only ([`crate::problem`]).
    /// O(nu·(nv + FINE_PER_SAMPLE)) surface evaluations.
    pub fn new(impeller: &Impeller, side: Side, nu: usize, nv: usize) -> Result<Self, FlankError> {
        Self::of_row(impeller, Row::Main, side, nu, nv)
    }

    /// [`FlankSide::new`] for the reference blade of `row` (instance 0 of the main blades or
    /// of the splitters); the facing side is searched among both neighbours of either row.
    pub fn of_row(
        impeller: &Impeller,
        row: Row,
        side: Side,
        nu: usize,
        nv: usize,
    ) -> Result<Self, FlankError> {
        if nu < 2 || nv < 2 {
            return Err(FlankError::Param(
                "sample grid needs at least 2 × 2 points".into(),
            ));
        }
        let set = crate::rows::blade_set(impeller, row)?;
        let blade = set.blade().clone();
        let v_range = match blade.design() {
            Some(_) => blade.hub_shroud_v(side),
            None => impeller.span_v_range(&blade, side).map_err(|e| {
                FlankError::Geometry(format!("{side:?} side: hub or shroud edge not found: {e}"))
            })?,
        };
        let s = blade.side(side);
        let ((u0, u1), _) = s.domain();
        let us = along_parameters(&blade, side, v_range, nu);
        let vs = across_parameters(&blade, side, v_range, nv, impeller.fillet_radius_mm());
        let mut samples = Vec::with_capacity(nu * vs.len());
        let mut sample_uv = Vec::with_capacity(nu * vs.len());
        for &u in &us {
            for &v in &vs {
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
        let candidates = crate::rows::neighbours(impeller, row);
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
            grid: (nu, vs.len()),
            sample_uv,
            adjacent,
        })
    }

    /// Appends accuracy samples at the side parameters `uv` (after the `grid`, which stays
    /// the first `nu·nv` samples). Used to add the points where a dense measurement found the
    /// written pass outside its tolerance (cutting planes). O(count) evaluations.
    pub fn add_samples(&mut self, uv: impl IntoIterator<Item = (f64, f64)>) {
        let s = self.blade.side(self.side);
        for (u, v) in uv {
            self.samples.push(Point3::from(s.point(u, v)));
            self.sample_uv.push((u, v));
        }
    }

    /// Signed distance of `p` from the hub (positive on the channel side).
    pub fn hub_distance(&self, p: &Vector3) -> f64 {
        self.hub.signed_distance(p)
    }

    /// Signed distance of the ball centre `p` from the hub body: the hub surface closed at
    /// both ends of its meridional contour by the planes through each end perpendicular to
    /// the contour's end tangent (the inlet face and the outlet rim). Equal to
    /// [`Self::hub_distance`] on the channel side and near the contour; beyond an end
    /// (e.g. the ball of a leading-edge location hanging over the hub's inlet face), where
    /// the closest contour point is the end point and the sign of [`Self::hub_distance`]
    /// flips from `+|p − end|` to `−|p − end|` across the end normal's line, it is the
    /// distance beyond the end plane instead, which is continuous there (and C¹: both sides
    /// have the end tangent as gradient on that line). The ball lowering
    /// ([`Self::initial_locations`]) and the hub-tangency rows of [`crate::problem`] use it,
    /// so neither brackets nor linearises that jump (issue 13: the mid-normal start was left
    /// on it 1.16 mm above the hub of impeller-30-narrow's leading edge). Wherever the
    /// plain distance is negative the result is the largest of it and the two signed
    /// distances beyond the end planes, which assumes the contour lies on the inner side of
    /// both end planes (so for a monotone hub contour: z and r each monotone). O(1) contour
    /// projections.
    pub fn hub_body_distance(&self, p: &Vector3) -> f64 {
        let m = self.hub.meridional();
        let zr = MeridionalCurve::zr_of(p);
        let (_, d) = m.closest(zr);
        if d >= 0.0 {
            return d;
        }
        let (t0, t1) = m.domain();
        // Unit tangent (increasing t) from the channel-side normal n = (t_r, −t_z)/|t|.
        let tangent = |t: f64| {
            let n = m.normal(t);
            Vector2::new(-n[1], n[0])
        };
        let beyond = |t: f64, out: Vector2<f64>| (zr - m.point(t)).dot(&out);
        d.max(beyond(t0, -tangent(t0))).max(beyond(t1, tangent(t1)))
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
    /// hub body ([`Self::hub_body_distance`]): the first root of `f(λ) = hub_body_distance
    /// (centre) − r` met going down the line from a height where the ball is clear of the hub
    /// (scan in steps of `r/4`, then bisection inside the step), so the ball stops where it
    /// first touches the hub, never at a later crossing or a jump.
    ///
    /// When the line misses the hub (the ball passes beyond an end of the hub, e.g. over the
    /// inlet face at a leading edge, farther than `r` from it: `f > 0` all the way down), the
    /// line is moved towards the hub, perpendicular to `a`, by the gap at its closest approach
    /// plus `HUB_SHIFT_OVERLAP·r` (so the next scan meets a transversal root), and lowered
    /// again (at most `HUB_SHIFTS` times). The returned tip is on the moved line.
    /// O(`HUB_SCAN_STEPS` + `HUB_BISECTIONS`) hub projections per try.
    fn lower_onto_hub(&self, p: &Vector3, a: &Vector3, r: f64) -> Result<Vector3, FlankError> {
        let fail = |p: &Vector3| {
            FlankError::Geometry(format!(
                "{:?} side: cannot bring the ball onto the hub near {:.2?}",
                self.side,
                p.as_slice()
            ))
        };
        let step = 0.25 * r;
        let mut p = *p;
        for _ in 0..=HUB_SHIFTS {
            let f = |lam: f64| self.hub_body_distance(&(p - a * lam + a * r)) - r;
            // A start above the hub.
            let mut top = -4.0 * r;
            let mut k = 0;
            while f(top) < 0.0 {
                top -= 4.0 * r;
                k += 1;
                if k > 20 {
                    return Err(fail(&p));
                }
            }
            let mut bracket = None;
            let (mut best_f, mut best_lam) = (f(top), top);
            for i in 1..=HUB_SCAN_STEPS {
                let lam = top + step * i as f64;
                let v = f(lam);
                if v <= 0.0 {
                    bracket = Some((lam - step, lam));
                    break;
                }
                if v < best_f {
                    (best_f, best_lam) = (v, lam);
                }
            }
            let Some((mut lo, mut hi)) = bracket else {
                // Missed: move the line towards the hub at its closest approach.
                let c = p - a * best_lam + a * r;
                let h = crate::problem::HUB_FD_STEP_MM;
                let mut g = Vector3::zeros();
                for k in 0..3 {
                    let mut dp = Vector3::zeros();
                    dp[k] = h;
                    g[k] = (self.hub_body_distance(&(c + dp)) - self.hub_body_distance(&(c - dp)))
                        / (2.0 * h);
                }
                let perp = g - a * g.dot(a);
                if perp.norm_squared() < 1e-12 {
                    return Err(fail(&p));
                }
                p -= perp * ((best_f + HUB_SHIFT_OVERLAP * r) / perp.norm_squared());
                continue;
            };
            for _ in 0..HUB_BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if f(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return Ok(p - a * (0.5 * (lo + hi)));
        }
        Err(fail(&p))
    }
}

/// `n` parameters u over the whole domain of `side` (both ends included), equidistributing
/// `½·arc/arc_total + ½·turn/turn_total`, where `arc` is the larger of the hub- and
/// shroud-edge isocurves' arc lengths and `turn` the larger turning angle of their outward
/// normals (rad). Uniform u when the side neither lengthens nor turns (degenerate input).
/// Where the normal turns fast (the rounded leading-edge nose of impeller-8+8 turns ~90° in
/// the first 12 % of u) the samples crowd; on a flat stretch they follow arc length.
/// O(n · `FINE_PER_SAMPLE`) point and normal evaluations.
pub fn along_parameters(blade: &Blade, side: Side, v_range: (f64, f64), n: usize) -> Vec<f64> {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let n = n.max(2);
    let fine = n * FINE_PER_SAMPLE;
    let at =
        |u: f64| [v_range.0, v_range.1].map(|v| (s.point(u, v), blade.outward_normal(side, u, v)));
    let mut arc = vec![0.0f64; fine + 1];
    let mut turn = vec![0.0f64; fine + 1];
    let mut prev = at(u0);
    for k in 1..=fine {
        let cur = at(u0 + (u1 - u0) * k as f64 / fine as f64);
        let mut da: f64 = 0.0;
        let mut dt: f64 = 0.0;
        for e in 0..2 {
            da = da.max((cur[e].0 - prev[e].0).norm());
            if let (Some(a), Some(b)) = (prev[e].1, cur[e].1) {
                dt = dt.max(a.dot(&b).clamp(-1.0, 1.0).acos());
            }
        }
        arc[k] = arc[k - 1] + da;
        turn[k] = turn[k - 1] + dt;
        prev = cur;
    }
    let (a_tot, t_tot) = (arc[fine], turn[fine]);
    let measure: Vec<f64> = (0..=fine)
        .map(|k| {
            let uniform = k as f64 / fine as f64;
            match (a_tot > 1e-12, t_tot > 1e-9) {
                (true, true) => 0.5 * arc[k] / a_tot + 0.5 * turn[k] / t_tot,
                (true, false) => arc[k] / a_tot,
                _ => uniform,
            }
        })
        .collect();
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    for i in 0..n {
        let target = i as f64 / (n - 1) as f64;
        while k + 1 < fine && measure[k + 1] < target {
            k += 1;
        }
        let (m0, m1) = (measure[k], measure[k + 1]);
        let f = if m1 > m0 {
            ((target - m0) / (m1 - m0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(u0 + (u1 - u0) * (k as f64 + f) / fine as f64);
    }
    out[0] = u0;
    out[n - 1] = u1;
    out
}

/// The across parameters v of the accuracy grid: `n` evenly from the hub edge to the shroud
/// edge, plus the fillet-band rows at `FILLET_BAND_ROWS` × `fillet` above the hub edge
/// (converted to v by the side's mean hub-to-shroud length), sorted. O(1) evaluations.
fn across_parameters(
    blade: &Blade,
    side: Side,
    v_range: (f64, f64),
    n: usize,
    fillet: f64,
) -> Vec<f64> {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let um = 0.5 * (u0 + u1);
    let span = (s.point(um, v_range.1) - s.point(um, v_range.0)).norm();
    let mut vs: Vec<f64> = (0..n)
        .map(|j| v_range.0 + (v_range.1 - v_range.0) * j as f64 / (n - 1) as f64)
        .collect();
    if span > 1e-9 && fillet > 0.0 {
        vs.extend(
            FILLET_BAND_ROWS
                .iter()
                .map(|f| v_range.0 + (v_range.1 - v_range.0) * (f * fillet / span).min(1.0)),
        );
    }
    // Hub edge first, whichever way v runs.
    vs.sort_by(|a, b| (a - v_range.0).abs().total_cmp(&(b - v_range.0).abs()));
    vs.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    vs
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
