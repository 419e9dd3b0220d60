//! The impeller design's blade-root fillets in the verifier: the rolling-ball blend of radius
//! `R` (`Impeller::fillet_radius_mm`) between the hub and every blade side, as
//! [`impeller_model::fillet::BladeFillet`] builds it (exact sections, spine within
//! [`FILLET_TOL_MM`]).
//!
//! # Distance
//! The fillet adds material to the corner between hub and side: the design is the sharp
//! design ∪ the fillet material `F` (the corner outside every rolling ball). Outside the
//! sharp material (`sd_sharp(p) ≥ 0`) the design's signed distance is
//! `min(sd_sharp(p), R − |p − c(t)|)` where the second term is the fillet's
//! ([`impeller_model::fillet::BladeFillet::signed_distance`], defined in the arc's sector of
//! `p`'s nearest spine point `c(t)`): exact where the fillet surface is the nearest design
//! surface, and a gouge into the fillet reads its depth below the fillet surface. Inside
//! the sharp material the sharp distance is kept: the depth below the union's boundary is at
//! least the depth below the hub or the side (so it stays a safe marching bound), and a cut
//! into the hub under a fillet reads its depth below the hub surface (a lower bound).
//! The fillets are evaluated only where both the hub and the sharp blade distance are
//! within the fillets' reach (`R / sin(β/2) + R`, `β` the corner angle), and only those of
//! the blades whose angular window holds the point
//! ([`impeller_model::fillet::ImpellerFillets`]): elsewhere no fillet point can be nearer
//! than the hub or the side.
//!
//! # Surfaces
//! The fillet surface is sampled for the overcut and residual maps (grids named
//! `<blade>_fillet_<side>`, normal from the surface toward the ball centre, into the air),
//! and the hub and blade-side samples that the fillet covers (inside the filleted
//! material) are left out of their maps: there the design surface is the fillet.
//!
//! In the collision mesh: every fillet triangulated within [`FILLET_MESH_CHORD_MM`]
//! ([`impeller_model::export::fillets_mesh`], triangles facing the air), so a non-cutting
//! tool part in the corner meets the fillet as it meets hub and blades.
//!
//! Stated error: the spine fit's (≤ [`FILLET_TOL_MM`] where [`MAX_STATIONS`] allow; the
//! build reports what it reached), on top of the sharp design's. Where a side's fillet has
//! no piece (a ball that does not fit: the hub's rim beside a leading edge, an edge), the
//! corner stays sharp. Cost per distance in the reach: two certified curve projections per blade in the window.
//!
//! [`MAX_STATIONS`]: impeller_model::fillet::MAX_STATIONS

use crate::design::SurfaceGrid;
use crate::error::SimError;
use crate::impeller_design::side_name;
use cam_core::{Point3, Vector3};
use impeller_model::fillet::ImpellerFillets;
use impeller_model::{Blade, Impeller, Side};

/// Largest spine error of the verifier's fillets (mm): the model's default.
pub const FILLET_TOL_MM: f64 = impeller_model::fillet::DEFAULT_FILLET_TOL_MM;

/// Chord tolerance of the fillets' triangles in the collision mesh (mm).
pub const FILLET_MESH_CHORD_MM: f64 = 0.02;

/// Arc samples across a fillet in its surface grid.
const ARC_SAMPLES: usize = 4;

/// The fillets of an impeller's blades (module docs).
#[derive(Debug, Clone)]
pub struct DesignFillets {
    fillets: ImpellerFillets,
    /// Every blade's fillet triangulated within [`FILLET_MESH_CHORD_MM`], facing the air
    /// (for the collision mesh).
    mesh: impeller_model::export::TriMesh,
}

impl DesignFillets {
    /// The fillets of `impeller`'s rows, or `None` when its fillet radius is 0. Instances in
    /// the order of `Impeller::blades_in_order`.
    pub fn new(impeller: &Impeller) -> Result<Option<Self>, SimError> {
        let Some(fillets) = ImpellerFillets::new(impeller, FILLET_TOL_MM)
            .map_err(|e| SimError::Design(format!("blade-root fillet: {e}")))?
        else {
            return Ok(None);
        };
        let mesh = impeller_model::export::fillets_mesh(&fillets, FILLET_MESH_CHORD_MM)
            .map_err(|e| SimError::Design(format!("blade-root fillet mesh: {e}")))?;
        Ok(Some(Self { fillets, mesh }))
    }

    /// Appends every blade's fillet, triangulated within [`FILLET_MESH_CHORD_MM`] and facing
    /// the air, to a collision mesh.
    pub fn append_mesh(&self, m: &mut crate::design::TriangleMesh) {
        let base = m.vertices.len() as u32;
        m.vertices
            .extend(self.mesh.vertices.iter().map(|v| [v.x, v.y, v.z]));
        m.triangles.extend(
            self.mesh
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    /// Fillet radius (mm).
    pub fn radius(&self) -> f64 {
        self.fillets.radius()
    }

    /// Largest spine error of the fillets (mm): the design distance's stated error here.
    pub fn fit_error_mm(&self) -> f64 {
        self.fillets.fit_error_mm()
    }

    /// Beyond this distance from the hub or from the sharp blade no fillet decides the
    /// design distance (mm).
    pub fn reach_mm(&self) -> f64 {
        self.fillets.reach_mm()
    }

    /// The fillets' signed distance at `p` and the surface point deciding it, when `p` lies
    /// outside the sharp material within the reach (`hub`, `blade`: the sharp distances at
    /// `p`); `None` otherwise (module docs).
    pub fn closest(&self, p: &Point3, hub: f64, blade: f64) -> Option<(f64, Point3)> {
        let reach = self.fillets.reach_mm();
        if hub < 0.0 || blade < 0.0 || hub > reach || blade > reach {
            return None;
        }
        self.fillets
            .closest(&p.coords)
            .map(|(d, foot)| (d, Point3::from(foot)))
    }

    /// Whether the design point `p` (a hub or blade-side sample) lies under a fillet: inside
    /// the fillet material by more than 1e-6 mm.
    pub fn covers(&self, p: &Point3) -> bool {
        self.fillets
            .closest(&p.coords)
            .is_some_and(|(d, _)| d < -1e-6)
    }

    /// The fillet surface of `instance` on `side` (`blade` its rotated blade) as a map grid:
    /// `nv` stations uniform in the side's `u` (a station outside every piece is a skipped
    /// sample), [`ARC_SAMPLES`] across the arc; normals toward the ball centre.
    pub fn grid(
        &self,
        name: &str,
        instance: usize,
        blade: &Blade,
        side: Side,
        nv: usize,
    ) -> SurfaceGrid {
        let nu = ARC_SAMPLES;
        let mut g = SurfaceGrid::empty(format!("{name}_fillet_{}", side_name(side)), nu, nv);
        let Some((row, rot)) = self.fillets.instance(instance) else {
            return g;
        };
        let Some(fillet) = self.fillets.fillet(row, side) else {
            return g;
        };
        let ((u0, u1), _) = blade.side(side).domain();
        for j in 0..nv {
            let u = u0 + (u1 - u0) * (j as f64 + 0.5) / nv as f64;
            let piece = fillet.pieces().iter().find(|k| {
                let (a, b) = k.u_range();
                a <= u && u <= b
            });
            for i in 0..nu {
                match piece {
                    Some(k) => {
                        let s = k.section_at(u);
                        let p = s.arc_point((i as f64 + 0.5) / nu as f64);
                        let n = (s.centre - p) / s.radius;
                        g.points.push(Point3::from(rot * p));
                        g.normals.push(rot * n);
                    }
                    None => {
                        g.points.push(Point3::origin());
                        g.normals.push(Vector3::zeros());
                    }
                }
            }
        }
        g
    }
}
