//! The impeller: hub, shroud, main blade row, optional splitter row, fillet radius and blank.

use crate::blade::{Blade, BladeEdge, BladeSet};
use crate::error::ModelError;
use crate::revolved::RevolvedSurface;
use crate::stock::Stock;

/// Polar angle of `other`'s mid point minus that of the point of `blade`'s pressure side at the
/// nearest meridional position (z, r), reduced to [0, 2π): how far `other` sits from `blade`
/// in +θ at the same place of the channel (pressure side sampled on 61 × 21 parameters).
fn angular_offset(blade: &Blade, other: &Blade) -> f64 {
    let p = other.mid_point();
    let (z0, r0) = (p.z, p.x.hypot(p.y));
    let s = blade.pressure();
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut best = (f64::INFINITY, 0.0);
    for i in 0..=60 {
        for j in 0..=20 {
            let q = s.point(
                u0 + (u1 - u0) * i as f64 / 60.0,
                v0 + (v1 - v0) * j as f64 / 20.0,
            );
            let d = (q.z - z0).powi(2) + (q.x.hypot(q.y) - r0).powi(2);
            if d < best.0 {
                best = (d, q.y.atan2(q.x));
            }
        }
    }
    (p.y.atan2(p.x) - best.1).rem_euclid(std::f64::consts::TAU)
}

/// A centrifugal impeller in the workpiece frame (axis +Z from the hub back face toward the
/// inlet, origin on the axis at the back face; mm).
#[derive(Debug, Clone)]
pub struct Impeller {
    name: String,
    hub: RevolvedSurface,
    shroud: RevolvedSurface,
    main: BladeSet,
    splitter: Option<BladeSet>,
    fillet_radius_mm: f64,
    stock: Stock,
}

impl Impeller {
    /// Assembles and checks an impeller (the constructor for importers).
    ///
    /// Checks: non-empty name; fillet radius finite and ≥ 0; the shroud contour lies on the
    /// channel side of the hub contour (sampled at 33 meridional fractions, gap > 0); a splitter
    /// row has as many blades as the main row. A splitter row is renumbered (its reference
    /// blade turned by whole pitches) so that splitter k lies between main blades k and k+1.
    pub fn from_parts(
        name: impl Into<String>,
        hub: RevolvedSurface,
        shroud: RevolvedSurface,
        main: BladeSet,
        splitter: Option<BladeSet>,
        fillet_radius_mm: f64,
        stock: Stock,
    ) -> Result<Self, ModelError> {
        let name = name.into();
        if name.trim().is_empty() {
            return Err(ModelError::invalid("name", "must not be empty"));
        }
        if !(fillet_radius_mm.is_finite() && fillet_radius_mm >= 0.0) {
            return Err(ModelError::invalid("fillet_radius_mm", "must be >= 0"));
        }
        for k in 0..=32 {
            let m = k as f64 / 32.0;
            let s = shroud.meridional().point_at_fraction(m);
            let (_, d) = hub.meridional().closest(s);
            if d.is_nan() || d <= 0.0 {
                return Err(ModelError::Geometry(format!(
                    "shroud contour is not above the hub contour at meridional fraction {m:.3}"
                )));
            }
        }
        let splitter = match splitter {
            Some(s) => {
                if s.count() != main.count() {
                    return Err(ModelError::Geometry(format!(
                        "splitter count {} differs from main blade count {}",
                        s.count(),
                        main.count()
                    )));
                }
                let pitch = main.pitch_rad();
                let offset = angular_offset(main.blade(), s.blade());
                let k = (offset / pitch).floor();
                if k >= 1.0 {
                    Some(BladeSet::new(s.count(), s.blade().rotated(-k * pitch))?)
                } else {
                    Some(s)
                }
            }
            None => None,
        };
        Ok(Self {
            name,
            hub,
            shroud,
            main,
            splitter,
            fillet_radius_mm,
            stock,
        })
    }

    /// Name used in reports.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The hub (channel floor).
    pub fn hub(&self) -> &RevolvedSurface {
        &self.hub
    }

    /// The shroud contour surface (blade tips; channel lid).
    pub fn shroud(&self) -> &RevolvedSurface {
        &self.shroud
    }

    /// The main blade row.
    pub fn main(&self) -> &BladeSet {
        &self.main
    }

    /// The splitter row, if any.
    pub fn splitter(&self) -> Option<&BladeSet> {
        self.splitter.as_ref()
    }

    /// Blade-root fillet radius (mm).
    pub fn fillet_radius_mm(&self) -> f64 {
        self.fillet_radius_mm
    }

    /// The blank.
    pub fn stock(&self) -> &Stock {
        &self.stock
    }

    /// The same impeller on another blank (e.g. the blank after turning, [`Stock::turned`]).
    pub fn with_stock(mut self, stock: Stock) -> Self {
        self.stock = stock;
        self
    }

    /// The blank faced at the design's top and turned to the shroud contour plus
    /// `allowance_mm` over the blades' axial extent and to the hub beyond it
    /// ([`Stock::turned_to_hub_beyond_blades`], 256 contour samples): the stock five-axis
    /// milling starts from after the turning steps of a turn-mill process plan.
    pub fn turned_stock(&self, allowance_mm: f64) -> Result<Stock, ModelError> {
        let h = self.hub.meridional();
        let s = self.shroud.meridional();
        let top = [h.point_at_fraction(0.0).x, h.point_at_fraction(1.0).x]
            .into_iter()
            .chain([s.point_at_fraction(0.0).x, s.point_at_fraction(1.0).x])
            .fold(f64::NEG_INFINITY, f64::max);
        Stock::turned_to_hub_beyond_blades(
            &self.stock,
            s,
            h,
            self.blade_z_range_mm(),
            top,
            allowance_mm,
            256,
        )
    }

    /// The axial extent (z_min, z_max) of every blade (main and splitter; both sides and the
    /// faces of blunt edges), from the faces' control points: their convex hull holds the surface (positive weights), so
    /// the range holds the blades, and it is the same for every blade of a row (rotation
    /// about Z keeps z).
    pub fn blade_z_range_mm(&self) -> (f64, f64) {
        let mut sets = vec![self.main.blade()];
        if let Some(s) = &self.splitter {
            sets.push(s.blade());
        }
        let mut range = (f64::INFINITY, f64::NEG_INFINITY);
        for b in sets {
            let edges = [BladeEdge::Leading, BladeEdge::Trailing]
                .into_iter()
                .filter_map(|e| b.edge_face(e).ok().flatten());
            for face in [b.pressure().clone(), b.suction().clone()]
                .into_iter()
                .chain(edges)
            {
                for p in face.control_points() {
                    range = (range.0.min(p.z), range.1.max(p.z));
                }
            }
        }
        range
    }

    /// Every blade in +θ order: main 0, splitter 0, main 1, splitter 1, ... (main only when
    /// there are no splitters), each as its own rotated surfaces.
    pub fn blades_in_order(&self) -> Vec<Blade> {
        let mut out = Vec::new();
        for k in 0..self.main.count() {
            out.push(self.main.instance(k));
            if let Some(s) = &self.splitter {
                out.push(s.instance(k));
            }
        }
        out
    }
}
