//! The blade-root fillets in the clearance of a ball: a lower bound of how far a sphere
//! keeps from the fillets' material, for the operations whose ball works near the corner
//! between hub and blade.
//!
//! The design clearance query ([`crate::DesignClearance`]) measures the sharp design: hub and
//! blades. The fillet of radius `R` adds material in their corner, and only there: every
//! fillet point lies within [`ImpellerFillets::reach_mm`] of both hub and blade. Inside a
//! fillet's sector a ball that touches hub and side above the fillet is clear of it, but at a
//! fillet's end (where the hub stops at its outlet rim or its inlet face, or the side at an
//! edge) a ball can hang over the end and still reach into the fillet: a Ø3 ball finishing
//! the impeller-11+11-freeform blades down to the hub cut 0.08 mm into the fillets' outlet
//! ends from centres 0.7 mm beyond the hub's rim, where hub and side alone read it clear.
//!
//! # Bound
//! For a sphere of radius `ρ` about `p`, with `d_h`, `d_b` the signed distances of hub and
//! blades at `p`, the fillet clearance is bounded below by
//! `max(max(d_h, d_b) − reach − ρ, min_k max(R − d_k, m_k) − ρ)`:
//! far from either wall the fillets cannot be reached; otherwise for every fillet `k` near
//! `p` the sphere is clear when it lies in one of the fillet's rolling balls (`d_k` the
//! distance to its spine; a rolling ball holds no material) or the lower bound `m_k` of the
//! distance to its material ([`ImpellerFillets::material_bounds`]) shows it clear. Where no
//! fillet's angular window holds `p` only the first term counts. Each term is a lower bound
//! of the true (1-Lipschitz) distance, so the motion certificates below hold.
//!
//! # Motions
//! Along a motion the ball centre follows a curve of length at most `|Δtip| + h·Δθ` (tip
//! linear, axis turned on its great circle, `h` the centre's height above the tip); with
//! clearances `f₀`, `f₁` at the ends of a piece of length `D` the true clearance stays
//! above `(f₀ + f₁ − D)/2` over it. [`FilletMargin::certify_motion`] bisects until every
//! piece clears the floor less the motion tolerance.
//!
//! Cost: one hub distance where the point is farther than the reach from the hub; else one
//! blade distance and the wedge bounds of the fillets in the point's window.

use crate::clearance::DesignClearance;
use crate::{Point3, Vector3};
use cam_core::CutterLocation;
use impeller_model::fillet::{ImpellerFillets, DEFAULT_FILLET_TOL_MM};
use impeller_model::{Impeller, ModelError};

/// How far above its cap (mm) the fillet bound is asked, so that a value reported as "at or
/// above the cap" stays there after the sphere's radius is subtracted in floating point.
const CAP_SLACK_MM: f64 = 1e-6;

/// The fillets of an impeller as a clearance bound (module docs).
#[derive(Debug, Clone)]
pub struct FilletMargin {
    fillets: ImpellerFillets,
}

impl FilletMargin {
    /// The fillets of `impeller` at the default spine tolerance, `None` when it has none
    /// (fillet radius 0).
    pub fn new(impeller: &Impeller) -> Result<Option<Self>, ModelError> {
        Ok(ImpellerFillets::new(impeller, DEFAULT_FILLET_TOL_MM)?.map(Self::from_fillets))
    }

    /// The bound over fillets already built.
    pub fn from_fillets(fillets: ImpellerFillets) -> Self {
        Self { fillets }
    }

    /// The fillets.
    pub fn fillets(&self) -> &ImpellerFillets {
        &self.fillets
    }

    /// Lower bound of the clearance of the sphere of radius `rho` about `p` from the
    /// fillets' material (module docs), given the signed hub distance `hub` at `p` and the
    /// signed blade distance, asked only where it matters. Values at or above `cap` may be
    /// returned as any value `≥ cap`.
    pub fn clearance_with(
        &self,
        p: &Vector3,
        rho: f64,
        hub: f64,
        blade: impl FnOnce() -> f64,
        cap: f64,
    ) -> f64 {
        let reach = self.fillets.reach_mm();
        let near_hub = hub - reach - rho;
        if near_hub >= cap {
            return near_hub;
        }
        let far = hub.max(blade()) - reach - rho;
        self.beyond_far(p, rho, far, cap)
    }

    /// The fillet term given `far = max(d_h, d_b) − reach − ρ`.
    fn beyond_far(&self, p: &Vector3, rho: f64, far: f64, cap: f64) -> f64 {
        if far >= cap {
            return far;
        }
        let r = self.fillets.radius();
        let mut per_fillet = f64::INFINITY;
        let mut visited = false;
        // A bound passed as "at or above the cap" must read at or above `cap` once `ρ` is
        // taken off again, whatever the rounding.
        self.fillets
            .material_bounds(p, cap + rho + CAP_SLACK_MM, |spine, material| {
                visited = true;
                per_fillet = per_fillet.min((r - spine - rho).max(material - rho));
            });
        if !visited {
            per_fillet = f64::NEG_INFINITY;
        }
        far.max(per_fillet)
    }

    /// Lower bound of the clearance of the sphere of radius `rho` about `p` from the whole
    /// design, fillets included, given the signed hub and blade distances at `p`:
    /// `min(d_h, d_b) − ρ` and the fillet term (module docs). 1-Lipschitz where the windows
    /// do not change.
    pub fn margin(&self, p: &Vector3, rho: f64, hub: f64, blade: f64) -> f64 {
        let sharp = hub.min(blade) - rho;
        let far = hub.max(blade) - self.fillets.reach_mm() - rho;
        sharp.min(self.beyond_far(p, rho, far, sharp))
    }

    /// [`Self::clearance_with`] with the distances of `design` (its hub and blade signed
    /// distances, exact).
    pub fn clearance(&self, design: &DesignClearance<'_>, p: &Vector3, rho: f64, cap: f64) -> f64 {
        let q = Point3::from(*p);
        let hub = design.hub_signed_distance(&q);
        self.clearance_with(p, rho, hub, || design.blade_signed_distance(&q).0, cap)
    }

    /// Certifies that the sphere of radius `rho` about the point `h` above the tip keeps
    /// `floor − tol` from the fillets along the motion `a → b` (tip linear, axis on its
    /// great circle at a constant rate: `CutterLocation` blends as the pass checks move),
    /// by bisection on the length bound of the module docs, at most `max_queries`
    /// evaluations. `Err(s)`: the fraction where the floor was missed or could not be
    /// certified.
    #[allow(clippy::too_many_arguments)]
    pub fn certify_motion(
        &self,
        design: &DesignClearance<'_>,
        a: &CutterLocation,
        b: &CutterLocation,
        h: f64,
        rho: f64,
        floor: f64,
        tol: f64,
        max_queries: usize,
    ) -> Result<(), f64> {
        let at = |s: f64| {
            let axis = a.axis.slerp(&b.axis, s);
            let tip = a.tip + (b.tip - a.tip) * s;
            (tip, axis)
        };
        let cap = floor + 4.0;
        let value = |s: f64| {
            let (tip, axis) = at(s);
            let c = tip.coords + axis.into_inner() * h;
            self.clearance(design, &c, rho, cap)
        };
        let length = |s0: f64, s1: f64| {
            let (t0, a0) = at(s0);
            let (t1, a1) = at(s1);
            (t1 - t0).norm() + h * a0.angle(&a1)
        };
        let (f0, f1) = (value(0.0), value(1.0));
        if f0 < floor {
            return Err(0.0);
        }
        if f1 < floor {
            return Err(1.0);
        }
        // Most motions settle as a whole (far from every fillet): no stack for them.
        if 0.5 * (f0 + f1 - length(0.0, 1.0)) >= floor - tol {
            return Ok(());
        }
        let mut queries = 2;
        let mut stack = vec![(0.0, f0, 1.0, f1)];
        while let Some((s0, f0, s1, f1)) = stack.pop() {
            if 0.5 * (f0 + f1 - length(s0, s1)) >= floor - tol {
                continue;
            }
            if queries >= max_queries {
                return Err(0.5 * (s0 + s1));
            }
            let sm = 0.5 * (s0 + s1);
            let fm = value(sm);
            queries += 1;
            if fm < floor - tol {
                return Err(sm);
            }
            stack.push((sm, fm, s1, f1));
            stack.push((s0, f0, sm, fm));
        }
        Ok(())
    }
}
