//! Conventional plunge axes (the baseline of paper 000 §2–§3 ①) and the posture of a plunge
//! on any axis line.
//!
//! The conventional axis of the plunge at channel coordinates `(m, s)` is the line through the
//! cutter-centre point `M = M(m, s)` on the hub and the isoparametric shroud point
//! `W = W(m, s)` on the shroud meridian of the same fractions ([`crate::rows::ChannelFrame`];
//! the meridian is the isocurve `RevolvedSurface::meridian` turned to W's polar angle): the
//! ruling of the channel between hub and shroud that every CAM system plunges along.
//!
//! On an axis line through `M` with unit direction `q = (W − M)/|W − M|` the plunge's
//! posture follows from two contact solves ([`crate::axial_depth`]):
//! - depth: the bottom circle (radius `R − ρ`, ρ the corner radius) touches the hub offset
//!   by `ρ + hub allowance`; the tip is `ρ` below that circle's centre;
//! - start: the same circle touches the shroud offset by `ρ` from outside; the start tip is
//!   the higher of that and the height where the bottom disk leaves the blank, plus the start
//!   clearance — the plunge starts in air.
//!
//! `α`, the angle between the hub normal at the contact point and the axis, is reported
//! signed toward the feed along every row ([`crate::feed`]).

use crate::axial_depth::{solve_contact, Contact, DepthError, RevolvedFloor};
use crate::rows::ChannelFrame;
use cam_core::{CutterLocation, Point3, UnitVector3, Vector3};
use cam_plan::PlanError;
use impeller_model::{Impeller, Stock};

/// Rim points (plus the centre) tested against the blank when finding where the bottom disk
/// leaves it: 32 keep the chord sag below 0.5 % of the radius.
pub const STOCK_EXIT_RIM_SAMPLES: usize = 32;
/// Axial search step (mm) when walking out of the blank before bisection.
pub const STOCK_EXIT_STEP_MM: f64 = 2.0;

/// One plunge: its axis line, depth, start and α.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Posture {
    /// Meridional fraction of the station.
    pub m: f64,
    /// Angular fraction of the row.
    pub s: f64,
    /// Cutter-centre point `M` (on the hub) the axis passes through.
    pub centre: Vector3,
    /// Shroud point `W` the axis passes through.
    pub w: Vector3,
    /// Tool tip at depth and unit axis.
    pub cl: CutterLocation,
    /// Tool tip at the start of the plunge (same axis).
    pub start: CutterLocation,
    /// The hub contact of the depth solve.
    pub contact: Contact,
    /// Angle between the hub normal at the contact point and the axis (rad).
    pub alpha: f64,
}

/// Builds postures for one tool.
#[derive(Debug, Clone, Copy)]
pub struct PostureBuilder<'a> {
    hub: RevolvedFloor<'a>,
    shroud: RevolvedFloor<'a>,
    circle_radius: f64,
    corner: f64,
    start_clearance_mm: f64,
    stock: &'a Stock,
    operation: &'a str,
}

impl<'a> PostureBuilder<'a> {
    /// Postures of a flat bottom of radius `radius` with corner radius `corner` (0 for a
    /// sharp flat end), leaving `hub_allowance_mm` on the hub and starting
    /// `start_clearance_mm` above shroud and blank.
    pub fn new(
        impeller: &'a Impeller,
        stock: &'a Stock,
        radius: f64,
        corner: f64,
        hub_allowance_mm: f64,
        start_clearance_mm: f64,
        operation: &'a str,
    ) -> Self {
        Self {
            hub: RevolvedFloor::offset(impeller.hub().meridional(), corner + hub_allowance_mm),
            shroud: RevolvedFloor::offset(impeller.shroud().meridional(), corner),
            circle_radius: radius - corner,
            corner,
            start_clearance_mm,
            stock,
            operation,
        }
    }

    /// The hub floor the bottom circle touches (offset by corner radius + allowance).
    pub fn hub_floor(&self) -> &RevolvedFloor<'a> {
        &self.hub
    }

    /// The posture with the conventional axis at `(m, s)`.
    pub fn conventional(
        &self,
        frame: &ChannelFrame<'_>,
        m: f64,
        s: f64,
    ) -> Result<Posture, PlanError> {
        self.through(m, s, frame.hub_point(m, s), frame.shroud_point(m, s), None)
    }

    /// The hub contact of the axis through `centre` and `w` (the depth solve only), warm
    /// started from `seed`.
    pub fn contact(
        &self,
        centre: &Vector3,
        w: &Vector3,
        seed: Option<((f64, f64), f64)>,
    ) -> Result<(Vector3, Contact), DepthError> {
        let q = (w - centre)
            .try_normalize(1e-12)
            .ok_or(DepthError::NonFinite)?;
        let c = solve_contact(
            &self.hub,
            &Point3::from(*centre),
            &q,
            self.circle_radius,
            seed,
        )?;
        Ok((q, c))
    }

    /// α of a contact: the angle between the hub normal there and the axis `q` (paper 000
    /// §3), in [0, π]. Its sign, toward or against the feed, depends on the row and the feed
    /// direction: [`crate::feed::signed_alpha`].
    pub fn alpha(&self, q: &Vector3, c: &Contact) -> f64 {
        let _ = &self.hub;
        c.normal.dot(q).clamp(-1.0, 1.0).acos()
    }

    /// The posture on the axis line through `centre` and `w` (station `(m, s)` recorded).
    pub fn through(
        &self,
        m: f64,
        s: f64,
        centre: Vector3,
        w: Vector3,
        seed: Option<((f64, f64), f64)>,
    ) -> Result<Posture, PlanError> {
        let place = || format!("plunge at meridional fraction {m:.4}, row fraction {s:.4}");
        let err =
            |e: DepthError| PlanError::geometry(self.operation, place(), format!("depth: {e}"));
        let (q, contact) = self.contact(&centre, &w, seed).map_err(err)?;
        let depth_tip = centre + q * (contact.t - self.corner);
        let top = solve_contact(
            &self.shroud,
            &Point3::from(centre),
            &q,
            self.circle_radius,
            None,
        )
        .map_err(|e| PlanError::geometry(self.operation, place(), format!("start height: {e}")))?;
        let shroud_tip = top.t - self.corner;
        let exit = self.stock_exit(&centre, &q, (contact.t - self.corner).max(shroud_tip))?;
        let start_t = shroud_tip.max(exit) + self.start_clearance_mm;
        let axis = UnitVector3::new_normalize(q);
        Ok(Posture {
            m,
            s,
            centre,
            w,
            cl: CutterLocation {
                tip: Point3::from(depth_tip),
                axis,
            },
            start: CutterLocation {
                tip: Point3::from(centre + q * start_t),
                axis,
            },
            contact,
            alpha: self.alpha(&q, &contact),
        })
    }

    /// The top of the conventional stroke on the axis line through `centre` and `w`, cheaply:
    /// the point of the line at `w` or, if that lies in the stock, where the line leaves it
    /// (walking up in [`STOCK_EXIT_STEP_MM`] steps, then bisecting to 1e-3 mm; at most the
    /// stock's extent). A proxy of the posture's start for spacing the stations (no contact
    /// solve; the start itself is that height or the disk's exit, plus the clearance).
    pub fn stroke_top(&self, centre: &Vector3, w: &Vector3) -> Vector3 {
        let d = w - centre;
        let len = d.norm();
        let Some(q) = d.try_normalize(1e-12) else {
            return *w;
        };
        let inside = |t: f64| self.stock.contains(&(centre + q * t));
        if !inside(len) {
            return *w;
        }
        let (z0, z1) = self.stock.z_range();
        let reach = (z1 - z0) + 2.0 * self.stock.max_radius();
        let top = exit_along(&inside, len, reach, 1e-3).unwrap_or(len + reach);
        centre + q * top
    }

    /// Smallest axial position `≥ from` where the bottom disk (full radius) at `centre + t·q`
    /// lies outside the blank (centre and [`STOCK_EXIT_RIM_SAMPLES`] rim points), walking up in
    /// [`STOCK_EXIT_STEP_MM`] steps then bisecting to 1e-6 mm.
    fn stock_exit(&self, centre: &Vector3, q: &Vector3, from: f64) -> Result<f64, PlanError> {
        let (e1, e2) = crate::axial_depth::perpendicular_frame(q);
        let radius = self.circle_radius + self.corner;
        let inside = |t: f64| {
            let c = centre + q * t;
            self.stock.contains(&c)
                || (0..STOCK_EXIT_RIM_SAMPLES).any(|k| {
                    let th = std::f64::consts::TAU * k as f64 / STOCK_EXIT_RIM_SAMPLES as f64;
                    self.stock
                        .contains(&(c + (e1 * th.cos() + e2 * th.sin()) * radius))
                })
        };
        if !inside(from) {
            return Ok(from);
        }
        let (z0, z1) = self.stock.z_range();
        let reach = (z1 - z0) + 2.0 * self.stock.max_radius() + 2.0 * radius;
        exit_along(&inside, from, reach, 1e-6).ok_or_else(|| {
            PlanError::geometry(
                self.operation,
                format!(
                    "plunge axis through ({:.3}, {:.3}, {:.3})",
                    centre.x, centre.y, centre.z
                ),
                "the tool axis never leaves the blank",
            )
        })
    }
}

/// The first parameter after `from` (where `inside` holds) at which `inside` fails: a walk in
/// [`STOCK_EXIT_STEP_MM`] steps, then bisection of the last step to `tol` (the result is on
/// the outside end). `None` when the walk passes `from + reach` still inside. Assumes one
/// crossing within a step. O(reach / step + log₂(step / tol)) tests.
fn exit_along(inside: &dyn Fn(f64) -> bool, from: f64, reach: f64, tol: f64) -> Option<f64> {
    let (mut lo, mut hi) = (from, from + STOCK_EXIT_STEP_MM);
    while inside(hi) {
        lo = hi;
        hi += STOCK_EXIT_STEP_MM;
        if hi - from > reach {
            return None;
        }
    }
    while hi - lo > tol {
        let mid = 0.5 * (lo + hi);
        if inside(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_along_finds_the_crossing_within_its_tolerance() {
        // Inside below 7.3: a walk from 0.5 in 2 mm steps, then bisection to 1e-6.
        let inside = |t: f64| t < 7.3;
        let t = exit_along(&inside, 0.5, 100.0, 1e-6).unwrap_or(f64::NAN);
        assert!((7.3..=7.3 + 1e-6).contains(&t), "{t}");
        // Never leaving within the reach is reported, not guessed.
        assert_eq!(exit_along(&|_| true, 0.0, 10.0, 1e-6), None);
    }
}
