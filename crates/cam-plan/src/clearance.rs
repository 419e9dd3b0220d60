//! The design clearance query: how far the cutter, its shank and its holder are from the
//! design (hub, every blade, optionally the shroud contour), and which part is nearest.
//!
//! # Geometry
//! The design material is the union of the hub body and the blades:
//! - hub body: the points below the hub surface of revolution, capped by the plane of the
//!   hub's inlet end and the cylinder of its outlet radius (where the meridional distance
//!   alone would extend the body past the contour's ends); signed distance
//!   `max(d_hub, z − z_inlet, r − r_outlet)`, exact near the hub surface;
//! - blade k: the points inside both sides (each side's signed distance is positive along its
//!   outward normal) and below the shroud contour: `max(d_pressure, d_suction, d_shroud)`.
//!   Only the two instances of each row that enclose the query's polar angle are evaluated
//!   (the reference blade's angle at the nearest meridional position is tabulated), so a
//!   query costs four blade-side projections however many blades there are.
//!
//! The tool assembly is a solid of revolution of radius `ρ(h)` about its axis for heights
//! `0 ≤ h ≤ H` above the tip ([`cam_core::Cutter::assembly_radius_at`]). Its cross-section
//! at height `h` is a disc inside the ball of radius `ρ(h)` about `c(h) = tip + h·axis`, so
//! `d(c(h)) − ρ(h)` (with `d` the design's signed distance) is a lower bound of the disc's
//! clearance. The query takes the minimum over sample heights: the ball centre of ball and
//! tapered-ball ends (where the ball is the cutter's end exactly), then a grid up the
//! flutes, the shank and the holder with a step `s ≤ min(ρ/2, √(2·ρ·tol))`; between two
//! samples the union of balls misses a rim band of depth `≤ s²/(4ρ) ≤ tol/2`.
//!
//! The ball test is exact for a ball end, and conservative elsewhere: a flat bottom is
//! tested with the ball about the tip, which reaches below it, and a wide holder's ball
//! reaches down the axis by its radius. Operations whose tools touch a floor with a flat
//! bottom (plunge roughing) ask for the blades only ([`ClearanceOptions::parts`]).
//!
//! Cost: O(H / s) distance evaluations per posture (each four blade-side projections and
//! two contour projections), stopping early in [`DesignClearance::is_clear`].

use crate::{PlanError, Point3, Tool, Vector3};
use cam_core::{CutterLocation, CutterShape};
use impeller_model::query::blade_side_distance;
use impeller_model::{BladeSet, Impeller, Side};

/// Default sampling tolerance of the swept balls (mm): the largest rim band between two
/// sample heights the union of balls may miss.
pub const DEFAULT_SAMPLE_TOL_MM: f64 = 0.01;

/// A blade row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Row {
    /// The main blades.
    Main,
    /// The splitter blades.
    Splitter,
}

/// A part of the design.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignPart {
    /// The hub body.
    Hub,
    /// The shroud contour (not material: a boundary the paths of some operations respect).
    Shroud,
    /// Blade `index` of the main or splitter row.
    Blade {
        /// Main or splitter row.
        row: Row,
        /// Instance number in its row.
        index: usize,
    },
}

/// A part of the tool assembly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolPart {
    /// The fluted cutting part.
    Cutter,
    /// The shank between the flutes and the holder.
    Shank,
    /// The holder.
    Holder,
}

/// Which design parts a query measures against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PartSet {
    /// The hub body.
    pub hub: bool,
    /// Every blade.
    pub blades: bool,
    /// The shroud contour (clearance positive below it, i.e. inside the channel envelope).
    pub shroud: bool,
}

impl PartSet {
    /// Hub and blades: the design material.
    pub const MATERIAL: Self = Self {
        hub: true,
        blades: true,
        shroud: false,
    };
    /// Blades only.
    pub const BLADES: Self = Self {
        hub: false,
        blades: true,
        shroud: false,
    };
}

/// Options of a clearance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClearanceOptions {
    /// Design parts measured against.
    pub parts: PartSet,
    /// Sampling tolerance of the swept balls (mm, > 0).
    pub sample_tol_mm: f64,
}

impl Default for ClearanceOptions {
    fn default() -> Self {
        Self {
            parts: PartSet::MATERIAL,
            sample_tol_mm: DEFAULT_SAMPLE_TOL_MM,
        }
    }
}

/// The answer of a clearance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// Signed clearance (mm): positive = free by that much, negative = penetration (a lower
    /// bound of the true clearance, see the module docs).
    pub distance_mm: f64,
    /// The design part nearest to the tool.
    pub design_part: DesignPart,
    /// The tool part nearest to the design.
    pub tool_part: ToolPart,
    /// Height above the tip of the nearest sample (mm).
    pub height_mm: f64,
}

/// Tabulated polar angle of a row's reference blade over the meridional (z, r) plane.
#[derive(Debug, Clone)]
struct RowAngles {
    zr: Vec<[f64; 2]>,
    theta: Vec<f64>,
}

impl RowAngles {
    fn new(set: &BladeSet) -> Self {
        let blade = set.blade();
        let s = blade.pressure();
        let ((u0, u1), (v0, v1)) = s.domain();
        let (nu, nv) = (48, 12);
        let mut zr = Vec::with_capacity((nu + 1) * (nv + 1));
        let mut theta = Vec::with_capacity(zr.capacity());
        for i in 0..=nu {
            for j in 0..=nv {
                let p = s.point(
                    u0 + (u1 - u0) * i as f64 / nu as f64,
                    v0 + (v1 - v0) * j as f64 / nv as f64,
                );
                zr.push([p.z, p.x.hypot(p.y)]);
                theta.push(p.y.atan2(p.x));
            }
        }
        Self { zr, theta }
    }

    /// The reference blade's polar angle nearest to `p`'s meridional position.
    fn angle_near(&self, p: &Point3) -> f64 {
        let (z, r) = (p.z, p.x.hypot(p.y));
        let mut best = (f64::INFINITY, 0.0);
        for (q, t) in self.zr.iter().zip(&self.theta) {
            let d = (q[0] - z).powi(2) + (q[1] - r).powi(2);
            if d < best.0 {
                best = (d, *t);
            }
        }
        best.1
    }
}

/// Clearance of one tool against one impeller's design.
#[derive(Debug, Clone)]
pub struct DesignClearance<'a> {
    impeller: &'a Impeller,
    options: ClearanceOptions,
    /// (height, radius, tool part) of each sample.
    samples: Vec<(f64, f64, ToolPart)>,
    hub_z_max: f64,
    hub_r_max: f64,
    rows: Vec<(Row, RowAngles)>,
}

impl<'a> DesignClearance<'a> {
    /// The query of `tool` against `impeller`.
    ///
    /// Errors: invalid tool or a sampling tolerance that is not finite and > 0.
    pub fn new(
        impeller: &'a Impeller,
        tool: &Tool,
        options: ClearanceOptions,
    ) -> Result<Self, PlanError> {
        tool.validate()?;
        let tol = options.sample_tol_mm;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(PlanError::param(
                "-",
                "clearance.sample_tol_mm",
                format!("{tol} must be finite and > 0"),
            ));
        }
        let c = &tool.cutter;
        let mut samples = Vec::new();
        let (centre, grid_start) = match c.shape {
            CutterShape::BallEnd { radius } => (Some(radius), radius),
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => (Some(ball_radius), ball_radius * (1.0 - half_angle.sin())),
            CutterShape::BullNose { corner_radius, .. } => (Some(corner_radius), 0.0),
            _ => (None, 0.0),
        };
        if let Some(h) = centre.filter(|h| *h <= c.flute_length) {
            samples.push((h, c.shape.radius_at(h), ToolPart::Cutter));
        }
        let holder_len: f64 = c.holder.iter().map(|s| s.length).sum();
        let top = c.overall_length + holder_len;
        let mut h = grid_start.min(c.flute_length);
        loop {
            let rho = c.assembly_radius_at(h).unwrap_or(0.0);
            let part = if h <= c.flute_length {
                ToolPart::Cutter
            } else if h <= c.overall_length {
                ToolPart::Shank
            } else {
                ToolPart::Holder
            };
            samples.push((h, rho, part));
            if h >= top {
                break;
            }
            let nominal = rho.max(tool.nominal_radius().min(rho.max(1e-3)));
            let step = (nominal / 2.0).min((2.0 * nominal * tol).sqrt()).max(1e-3);
            // Never step over a part boundary: sample both ends of every part.
            let mut next = h + step;
            for b in [c.flute_length, c.overall_length, top] {
                if h < b && next > b {
                    next = b;
                }
            }
            h = next;
        }
        let hub = impeller.hub().meridional();
        let (t0, t1) = hub.domain();
        let (a, b) = (hub.point(t0), hub.point(t1));
        let mut rows = vec![(Row::Main, RowAngles::new(impeller.main()))];
        if let Some(s) = impeller.splitter() {
            rows.push((Row::Splitter, RowAngles::new(s)));
        }
        Ok(Self {
            impeller,
            options,
            samples,
            hub_z_max: a[0].max(b[0]),
            hub_r_max: a[1].max(b[1]),
            rows,
        })
    }

    /// The same query with other options.
    pub fn with_options(&self, options: ClearanceOptions) -> Self {
        Self {
            options,
            ..self.clone()
        }
    }

    /// The sample (height, radius) pairs along the tool axis.
    pub fn samples(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.samples.iter().map(|s| (s.0, s.1))
    }

    /// Signed distance of the hub body at `p` (negative inside).
    pub fn hub_signed_distance(&self, p: &Point3) -> f64 {
        let d = self.impeller.hub().signed_distance(&p.coords);
        let r = p.x.hypot(p.y);
        d.max(p.z - self.hub_z_max).max(r - self.hub_r_max)
    }

    /// Signed distance below the shroud contour (positive inside the channel envelope).
    pub fn shroud_signed_distance(&self, p: &Point3) -> f64 {
        -self.impeller.shroud().signed_distance(&p.coords)
    }

    /// Signed distance of the nearest blade (negative inside it) and which blade it is.
    pub fn blade_signed_distance(&self, p: &Point3) -> (f64, DesignPart) {
        let d_shroud = self.impeller.shroud().signed_distance(&p.coords);
        let mut best = (f64::INFINITY, DesignPart::Hub);
        for (row, angles) in &self.rows {
            let set = match row {
                Row::Main => self.impeller.main(),
                Row::Splitter => match self.impeller.splitter() {
                    Some(s) => s,
                    None => continue,
                },
            };
            let n = set.count();
            let pitch = set.pitch_rad();
            let rel = (p.y.atan2(p.x) - angles.angle_near(p)).rem_euclid(std::f64::consts::TAU);
            let k0 = ((rel / pitch).floor() as usize) % n;
            for k in [k0, (k0 + 1) % n] {
                let local = set.rotation(k).inverse() * p.coords;
                let (_, dp) = blade_side_distance(set.blade(), Side::Pressure, &local, None);
                let (_, ds) = blade_side_distance(set.blade(), Side::Suction, &local, None);
                let d = dp.max(ds).max(d_shroud);
                if d < best.0 {
                    best = (
                        d,
                        DesignPart::Blade {
                            row: *row,
                            index: k,
                        },
                    );
                }
            }
        }
        best
    }

    /// Signed distance of the selected design parts at `p` (negative inside material; for
    /// the shroud, negative beyond it) and the nearest part.
    pub fn design_signed_distance(&self, p: &Point3) -> (f64, DesignPart) {
        let parts = self.options.parts;
        let mut best = (f64::INFINITY, DesignPart::Hub);
        if parts.hub {
            best = (self.hub_signed_distance(p), DesignPart::Hub);
        }
        if parts.shroud {
            let d = self.shroud_signed_distance(p);
            if d < best.0 {
                best = (d, DesignPart::Shroud);
            }
        }
        if parts.blades {
            let b = self.blade_signed_distance(p);
            if b.0 < best.0 {
                best = b;
            }
        }
        best
    }

    /// The smallest clearance of the tool at `cl` (see the module docs for what it bounds).
    pub fn clearance(&self, cl: &CutterLocation) -> Clearance {
        let axis: Vector3 = cl.axis.into_inner();
        let mut best = Clearance {
            distance_mm: f64::INFINITY,
            design_part: DesignPart::Hub,
            tool_part: ToolPart::Cutter,
            height_mm: 0.0,
        };
        for &(h, rho, part) in &self.samples {
            let (d, dp) = self.design_signed_distance(&(cl.tip + axis * h));
            let c = d - rho;
            if c < best.distance_mm {
                best = Clearance {
                    distance_mm: c,
                    design_part: dp,
                    tool_part: part,
                    height_mm: h,
                };
            }
        }
        best
    }

    /// Whether the tool at `cl` keeps at least `min_clearance_mm` from the design (stops at
    /// the first sample that fails).
    pub fn is_clear(&self, cl: &CutterLocation, min_clearance_mm: f64) -> bool {
        let axis: Vector3 = cl.axis.into_inner();
        self.samples.iter().all(|&(h, rho, _)| {
            self.design_signed_distance(&(cl.tip + axis * h)).0 - rho >= min_clearance_mm
        })
    }
}
