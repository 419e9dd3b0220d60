//! Blades: pressure and suction side surfaces (with an optional camber surface), and blade
//! rows as N-fold rotational copies of a reference blade.
//!
//! Conventions (checked by [`Blade::from_sides`]): both sides are parametrised with u along the
//! flow (leading → trailing edge) and v from hub to shroud, each extended a little beyond hub
//! and shroud so that tools can cut through. The outward normal of a side points away from
//! the blade's material; which side faces the +θ direction (toward the next blade of the
//! row) is found from the geometry.

use crate::error::ModelError;
use crate::thickness::ThicknessLaw;
use nalgebra::{Rotation3, Vector3};
use nurbs::closest::SurfaceProjector;
use nurbs::NurbsSurface;
use std::f64::consts::TAU;
use std::sync::{Arc, OnceLock};

/// How a blade was designed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BladeKind {
    /// Straight rulings from hub to shroud (flank-millable).
    Ruled,
    /// Free-form ("arbitrary") blade skinned through span curves.
    FreeForm,
}

/// One side of a blade.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Pressure side.
    Pressure,
    /// Suction side.
    Suction,
}

impl Side {
    /// The other side.
    pub fn other(self) -> Self {
        match self {
            Side::Pressure => Side::Suction,
            Side::Suction => Side::Pressure,
        }
    }
}

/// The leading or the trailing edge of a blade.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BladeEdge {
    /// u = start of the side domains.
    Leading,
    /// u = end of the side domains.
    Trailing,
}

/// Design data kept by the parametric builder (absent for imported blades).
#[derive(Debug, Clone)]
pub struct BladeDesign {
    /// Thickness distribution against the blade-local meridional fraction.
    pub thickness: ThicknessLaw,
    /// Impeller meridional fraction of the blade's leading edge (0 for main blades).
    pub m_start: f64,
    /// Camber/side parameter v of the hub and of the shroud (inside the extended range).
    pub span_v: (f64, f64),
}

impl BladeDesign {
    /// Blade-local meridional fraction at surface parameter u.
    pub fn m_local(&self, u: f64) -> f64 {
        self.thickness.m_of_u(u)
    }

    /// Impeller meridional fraction at surface parameter u.
    pub fn m_global(&self, u: f64) -> f64 {
        self.m_start + (1.0 - self.m_start) * self.m_local(u)
    }

    /// Span fraction s (0 hub, 1 shroud) at surface parameter v.
    pub fn span_of_v(&self, v: f64) -> f64 {
        (v - self.span_v.0) / (self.span_v.1 - self.span_v.0)
    }

    /// Surface parameter v at span fraction s.
    pub fn v_of_span(&self, s: f64) -> f64 {
        self.span_v.0 + s * (self.span_v.1 - self.span_v.0)
    }
}

/// A blade: two side surfaces, optional camber surface.
#[derive(Debug, Clone)]
pub struct Blade {
    kind: BladeKind,
    pressure: NurbsSurface,
    suction: NurbsSurface,
    camber: Option<NurbsSurface>,
    /// +1 when the side's natural normal S_u × S_v points out of the blade, −1 otherwise.
    pressure_sign: f64,
    suction_sign: f64,
    /// The side facing +θ (toward blade k+1 of the row).
    plus_theta: Side,
    design: Option<BladeDesign>,
    /// Global closest-point structures of [pressure, suction], built on first use and shared
    /// by clones (not by rotated copies).
    projectors: Arc<OnceLock<[SurfaceProjector; 2]>>,
}

fn mid(s: &NurbsSurface) -> (f64, f64) {
    let ((u0, u1), (v0, v1)) = s.domain();
    (0.5 * (u0 + u1), 0.5 * (v0 + v1))
}

impl Blade {
    /// A blade from its two sides (and optionally its camber surface).
    ///
    /// Both sides must be parametrised u leading → trailing edge and v hub → shroud (extended a
    /// little beyond both). Checks: the sides are apart at mid-parameter (thickness > 0) and
    /// have regular normals there. Normal orientation and which side faces +θ are derived.
    pub fn from_sides(
        kind: BladeKind,
        pressure: NurbsSurface,
        suction: NurbsSurface,
        camber: Option<NurbsSurface>,
    ) -> Result<Self, ModelError> {
        let (up, vp) = mid(&pressure);
        let (us, vs) = mid(&suction);
        let pp = pressure.point(up, vp);
        let ps = suction.point(us, vs);
        let d = ps - pp;
        if d.norm() < 1e-9 {
            return Err(ModelError::Geometry(
                "blade sides coincide at mid-parameter (zero thickness)".into(),
            ));
        }
        let np = pressure.normal(up, vp).ok_or_else(|| {
            ModelError::Geometry("pressure side is singular at mid-parameter".into())
        })?;
        let ns = suction.normal(us, vs).ok_or_else(|| {
            ModelError::Geometry("suction side is singular at mid-parameter".into())
        })?;
        let pressure_sign = if np.dot(&d) > 0.0 { -1.0 } else { 1.0 };
        let suction_sign = if ns.dot(&d) > 0.0 { 1.0 } else { -1.0 };
        let c = 0.5 * (pp + ps);
        let e_theta = Vector3::new(-c.y, c.x, 0.0);
        if e_theta.norm() < 1e-12 {
            return Err(ModelError::Geometry(
                "blade mid-point lies on the axis".into(),
            ));
        }
        let plus_theta = if d.dot(&e_theta) > 0.0 {
            Side::Suction
        } else {
            Side::Pressure
        };
        Ok(Self {
            kind,
            pressure,
            suction,
            camber,
            pressure_sign,
            suction_sign,
            plus_theta,
            design: None,
            projectors: Arc::new(OnceLock::new()),
        })
    }

    /// Attaches the parametric design data (builder use).
    pub fn with_design(mut self, design: BladeDesign) -> Self {
        self.design = Some(design);
        self
    }

    /// Ruled or free-form.
    pub fn kind(&self) -> BladeKind {
        self.kind
    }

    /// The pressure side surface.
    pub fn pressure(&self) -> &NurbsSurface {
        &self.pressure
    }

    /// The suction side surface.
    pub fn suction(&self) -> &NurbsSurface {
        &self.suction
    }

    /// Either side.
    pub fn side(&self, side: Side) -> &NurbsSurface {
        match side {
            Side::Pressure => &self.pressure,
            Side::Suction => &self.suction,
        }
    }

    /// The camber (mean) surface, when known.
    pub fn camber(&self) -> Option<&NurbsSurface> {
        self.camber.as_ref()
    }

    /// Parametric design data, when built from parameters.
    pub fn design(&self) -> Option<&BladeDesign> {
        self.design.as_ref()
    }

    /// The side facing +θ (toward the next blade of its row).
    pub fn plus_theta_side(&self) -> Side {
        self.plus_theta
    }

    /// +1 or −1: the factor turning a side's natural normal S_u × S_v into the outward one.
    pub fn outward_sign(&self, side: Side) -> f64 {
        match side {
            Side::Pressure => self.pressure_sign,
            Side::Suction => self.suction_sign,
        }
    }

    /// Unit normal of `side` at (u, v) pointing out of the blade material.
    pub fn outward_normal(&self, side: Side, u: f64, v: f64) -> Option<Vector3<f64>> {
        self.side(side)
            .normal(u, v)
            .map(|n| n * self.outward_sign(side))
    }

    /// The flat face closing a blunt edge: the ruled surface between the pressure and suction
    /// isocurves at that edge, exact via `NurbsSurface::ruled`: its u runs along the edge (the
    /// sides' v mapped to [0, 1], hub to shroud), its v from the pressure (0) to the suction
    /// side (1).
    /// `None` for a rounded (closed) edge, where both isocurves coincide within 1e-9 mm.
    pub fn edge_face(&self, edge: BladeEdge) -> Result<Option<NurbsSurface>, ModelError> {
        let at = |s: &NurbsSurface| {
            let ((u0, u1), _) = s.domain();
            match edge {
                BladeEdge::Leading => u0,
                BladeEdge::Trailing => u1,
            }
        };
        let cp = self.pressure.iso_curve_at_u(at(&self.pressure))?;
        let cs = self.suction.iso_curve_at_u(at(&self.suction))?;
        let (a, b) = cp.domain();
        let (c, d) = cs.domain();
        let gap = (0..=16)
            .map(|k| {
                let t = k as f64 / 16.0;
                (cp.point(a + (b - a) * t) - cs.point(c + (d - c) * t)).norm()
            })
            .fold(0.0, f64::max);
        if gap < 1e-9 {
            return Ok(None);
        }
        Ok(Some(NurbsSurface::ruled(&cp, &cs)?))
    }

    /// A point inside the blade near its middle: the camber point at mid-parameters, or the
    /// midpoint of the two sides there.
    pub fn mid_point(&self) -> Vector3<f64> {
        if let Some(c) = &self.camber {
            let (u, v) = mid(c);
            return c.point(u, v);
        }
        let (up, vp) = mid(&self.pressure);
        let (us, vs) = mid(&self.suction);
        0.5 * (self.pressure.point(up, vp) + self.suction.point(us, vs))
    }

    /// The isoparametric curve u = const of `side` (a blade section line from hub to shroud;
    /// a straight ruling on ruled blades).
    pub fn iso_u(&self, side: Side, u: f64) -> Result<nurbs::NurbsCurve<3>, ModelError> {
        Ok(self.side(side).iso_curve_at_u(u)?)
    }

    /// The isoparametric curve v = const of `side` (a flow line from leading to trailing edge).
    pub fn iso_v(&self, side: Side, v: f64) -> Result<nurbs::NurbsCurve<3>, ModelError> {
        Ok(self.side(side).iso_curve_at_v(v)?)
    }

    /// The global closest-point structure of `side` (nurbs' `SurfaceProjector`: Bézier
    /// patches in a bounding-volume tree, Newton per candidate leaf), built on first use.
    pub fn projector(&self, side: Side) -> &SurfaceProjector {
        let p = self.projectors.get_or_init(|| {
            [
                SurfaceProjector::new(&self.pressure),
                SurfaceProjector::new(&self.suction),
            ]
        });
        match side {
            Side::Pressure => &p[0],
            Side::Suction => &p[1],
        }
    }

    /// This blade turned by `angle` (radians) about +Z (exact: control points rotate).
    pub fn rotated(&self, angle: f64) -> Blade {
        let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), angle);
        Blade {
            kind: self.kind,
            pressure: rotate_surface(&self.pressure, &rot),
            suction: rotate_surface(&self.suction, &rot),
            camber: self.camber.as_ref().map(|c| rotate_surface(c, &rot)),
            pressure_sign: self.pressure_sign,
            suction_sign: self.suction_sign,
            plus_theta: self.plus_theta,
            design: self.design.clone(),
            projectors: Arc::new(OnceLock::new()),
        }
    }
}

/// `s` with every control point rotated by `rot` (weights unchanged): exactly the rotated
/// surface, since NURBS are affinely invariant.
pub fn rotate_surface(s: &NurbsSurface, rot: &Rotation3<f64>) -> NurbsSurface {
    let ctrl: Vec<Vector3<f64>> = s.control_points().iter().map(|p| rot * p).collect();
    let w = s.weights().map(|w| w.to_vec());
    match NurbsSurface::from_flat(s.knots_u().clone(), s.knots_v().clone(), ctrl, w) {
        Ok(r) => r,
        // Rotating finite points of a valid surface cannot invalidate it.
        Err(_) => s.clone(),
    }
}

/// A blade row: `count` copies of a reference blade, copy k turned by 2πk/count about +Z.
#[derive(Debug, Clone)]
pub struct BladeSet {
    count: usize,
    blade: Blade,
}

impl BladeSet {
    /// A row of `count ≥ 1` copies of `blade`.
    pub fn new(count: usize, blade: Blade) -> Result<Self, ModelError> {
        if count == 0 {
            return Err(ModelError::invalid("count", "must be >= 1"));
        }
        Ok(Self { count, blade })
    }

    /// Number of blades in the row.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The reference blade (copy 0).
    pub fn blade(&self) -> &Blade {
        &self.blade
    }

    /// Angular pitch 2π/count (radians).
    pub fn pitch_rad(&self) -> f64 {
        TAU / self.count as f64
    }

    /// The rotation taking the reference blade to copy k.
    pub fn rotation(&self, k: usize) -> Rotation3<f64> {
        Rotation3::from_axis_angle(&Vector3::z_axis(), self.pitch_rad() * k as f64)
    }

    /// Copy k as surfaces of its own.
    pub fn instance(&self, k: usize) -> Blade {
        self.blade.rotated(self.pitch_rad() * k as f64)
    }
}

/// Where the line `c + λ n` meets `s`: Newton on S(a, b) − λ n = c in (a, b, λ), from
/// (u, v, λ0). Returns λ.
///
/// # Errors
/// [`ModelError::LineMissesSurface`] with the start point and the last residual when the
/// Jacobian is singular (line tangent to the surface) or Newton does not converge in 30 steps
/// to 1e-12 mm (1e-9 mm accepted at the end).
pub fn line_surface_intersection(
    s: &NurbsSurface,
    c: &Vector3<f64>,
    n: &Vector3<f64>,
    start: (f64, f64, f64),
) -> Result<f64, ModelError> {
    let ((u0, u1), (v0, v1)) = s.domain();
    let (mut a, mut b, mut l) = start;
    let fail = |residual_mm: f64, reason: &'static str| ModelError::LineMissesSurface {
        u: start.0,
        v: start.1,
        lambda0: start.2,
        residual_mm,
        reason,
    };
    for _ in 0..30 {
        let d = s.derivs2(a, b);
        let r = d.p - n * l - c;
        if r.norm() < 1e-12 {
            return Ok(l);
        }
        let j = nalgebra::Matrix3::from_columns(&[d.su, d.sv, -n]);
        let step = j
            .lu()
            .solve(&(-r))
            .ok_or_else(|| fail(r.norm(), "singular Jacobian (line tangent to the surface)"))?;
        a = (a + step[0]).clamp(u0, u1);
        b = (b + step[1]).clamp(v0, v1);
        l += step[2];
    }
    let r = (s.point(a, b) - n * l - c).norm();
    if r < 1e-9 {
        Ok(l)
    } else {
        Err(fail(r, "no convergence in 30 Newton steps"))
    }
}

impl Blade {
    /// Normal thickness at camber parameters (u, v): the length of the camber-normal line
    /// between the two sides (both met by [`line_surface_intersection`]). `None` without a
    /// camber surface or where the line misses a side.
    pub fn normal_thickness(&self, u: f64, v: f64) -> Option<f64> {
        let c = self.camber.as_ref()?;
        let p = c.point(u, v);
        let n = c.normal(u, v)?;
        // A missed side means "no thickness here", which this query reports as `None`.
        let a = line_surface_intersection(&self.pressure, &p, &n, (u, v, 0.0)).ok()?;
        let b = line_surface_intersection(&self.suction, &p, &n, (u, v, 0.0)).ok()?;
        Some((a - b).abs())
    }
}
