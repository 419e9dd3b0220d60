//! Entries: how the first plunge of every row segment gets into the stock.
//!
//! A flat plunge cutter's centre does not cut, so a plunge whose centre disk would run
//! through material nothing removed cannot enter virgin stock at depth (paper 000 is silent
//! on it; a shop drills a pilot hole or enters where something already cut). Every segment
//! ([`crate::feed::Segment`]) starts with an *entry* plunge, which is one of
//! ([`EntryKind`]):
//! - **lead-in**: its centre disk's stroke passes through no stock at all (the lead-in station
//!   beyond the outlet, [`crate::rows`]);
//! - **cleared**: it passes only through material removed before it — by earlier plunges of
//!   the section (the neighbouring row's entry, the other segment of the row), by a pilot
//!   hole, or by an earlier section when the job declares that region cleared;
//! - **pilot**: a pilot hole is drilled first along the entry plunge's axis, from its start
//!   to its depth, with a flat-bottom drill at least [`PILOT_RADIAL_MARGIN_MM`] wider in
//!   radius than the non-cutting centre disk and no wider than the cutter (so it removes
//!   nothing the plunge would not). The drilled cylinder counts as removed in the
//!   interference measure ([`crate::interference::Material::drilled`]), and the hole is
//!   posted as its own operation step with the drill ([`cam_plan::PlannedStep`]);
//! - **unhandled**: none of these: its centre runs through material, and it counts as an
//!   interfering plunge.
//!
//! The section's `entry` key ([`EntryMode`]) declares which of them it may use.

use crate::conventional_axes::Posture;
use crate::interference::Stroke;
use cam_core::CutterShape;
use cam_plan::{PlanError, Process, Tool};
use serde::Deserialize;

/// Radial margin (mm) of a pilot hole over the non-cutting centre disk: the drill is at least
/// `2 × (r_core + 0.5)` mm in diameter, so the centre disk clears the hole's wall by 0.5 mm
/// (positioning of two tools and the drill's run-out stay well inside it).
pub const PILOT_RADIAL_MARGIN_MM: f64 = 0.5;

/// Which entries a section may use (job key `entry`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EntryMode {
    /// Entries at a lead-in off the blank or inside what the section's own earlier plunges
    /// removed; a segment whose lean-ward entry lies in virgin stock is fed from its other
    /// end when that one is such an entry (leaning back), else its entry is unhandled.
    LeadIn,
    /// As `lead_in`, and the region toward the outlet from `start_fraction < 1` counts as
    /// cleared by the previous section (the measure then trusts that section).
    Cleared,
    /// As `lead_in`, and every other entry into virgin stock gets a pilot hole (needs the
    /// `[pilot]` table). The default: no centre then runs through material nothing removed.
    Pilot,
}

impl EntryMode {
    /// The key's value as written in the job.
    pub fn name(self) -> &'static str {
        match self {
            EntryMode::LeadIn => "lead_in",
            EntryMode::Cleared => "cleared",
            EntryMode::Pilot => "pilot",
        }
    }
}

/// How one entry got in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntryKind {
    /// Its centre's stroke passes through no stock.
    LeadIn,
    /// Its centre's stroke passes only through material removed before it.
    Cleared,
    /// A pilot hole was drilled for it.
    Pilot,
    /// Its centre runs through material nothing removed.
    Unhandled,
}

/// The pilot drill of a section (job table `[operations.pilot]`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PilotParams {
    /// The drill: a `flat_end` tool of the job (a flat-bottom drill), cutting to its centre.
    pub tool: String,
    /// Spindle speed of the drilling (rev/min).
    pub spindle_rpm: f64,
    /// Feed per tooth of the drilling (mm); the drilling feed is `n · f_z · z`.
    pub feed_per_tooth_mm: f64,
}

impl PilotParams {
    /// Checks the numbers; errors name the key.
    pub fn validate(&self, operation: &str) -> Result<(), PlanError> {
        for (key, v) in [
            ("pilot.spindle_rpm", self.spindle_rpm),
            ("pilot.feed_per_tooth_mm", self.feed_per_tooth_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::param(
                    operation,
                    key,
                    format!("{v} must be finite and > 0"),
                ));
            }
        }
        if self.tool.trim().is_empty() {
            return Err(PlanError::param(
                operation,
                "pilot.tool",
                "name a drill of the job's tools",
            ));
        }
        Ok(())
    }

    /// The drilling's process row: the section's, with the drill's speed and its feed as the
    /// plunge feed (every drilling move is a plunge along the axis).
    pub fn process(&self, section: &Process) -> Process {
        Process {
            spindle_rpm: self.spindle_rpm,
            feed_per_tooth_mm: self.feed_per_tooth_mm,
            plunge_feed_per_tooth_mm: Some(self.feed_per_tooth_mm),
            depth_of_cut_mm: None,
            width_of_cut_mm: None,
            ..*section
        }
    }
}

/// The radius of pilot drill `tool` for plunges of a cutter of radius `radius` whose centre
/// disk has radius `core`: a flat end (a flat-bottom drill) that cuts to its centre, with
/// `core + PILOT_RADIAL_MARGIN_MM ≤ r ≤ radius`. Errors name the tool and the reason.
pub fn pilot_radius(
    tool: &Tool,
    radius: f64,
    core: f64,
    operation: &str,
) -> Result<f64, PlanError> {
    let CutterShape::FlatEnd { radius: r } = tool.cutter.shape else {
        return Err(PlanError::tool(
            operation,
            tool.name(),
            "a pilot drill must be flat_end (a flat-bottom drill: its hole's bottom is the \
             plunge's bottom plane)",
        ));
    };
    if tool.plunge_edge_length_mm.is_some_and(|e| e < r) {
        return Err(PlanError::tool(
            operation,
            tool.name(),
            "a pilot drill must cut to its centre (no plunge_edge_length_mm below its radius)",
        ));
    }
    let need = core + PILOT_RADIAL_MARGIN_MM;
    if r < need - 1e-12 || r > radius + 1e-12 {
        return Err(PlanError::tool(
            operation,
            tool.name(),
            format!(
                "pilot diameter {:.3} mm must lie between the centre disk's diameter plus \
                 {:.1} mm ({:.3} mm) and the plunge cutter's diameter ({:.3} mm)",
                2.0 * r,
                2.0 * PILOT_RADIAL_MARGIN_MM,
                2.0 * need,
                2.0 * radius
            ),
        ));
    }
    Ok(r)
}

/// The removal of the pilot hole drilled for entry plunge `p` with a drill of radius `r`:
/// along the plunge's axis from its start to its depth (the drill's tip at the plunge's tip).
pub fn pilot_stroke(p: &Posture, r: f64) -> Stroke {
    Stroke {
        start: p.start.tip,
        end: p.cl.tip,
        axis: p.cl.axis.into_inner(),
        radius: r,
        core_radius: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::Cutter;

    fn tool(shape: CutterShape, edge: Option<f64>) -> Tool {
        Tool {
            number: 1,
            cutter: Cutter::new("drill", shape, 80.0, 4.0, 140.0).expect("cutter"),
            teeth: 2,
            tool_length_mm: 200.0,
            plunge_edge_length_mm: edge,
        }
    }

    #[test]
    fn a_pilot_drill_is_a_centre_cutting_flat_end_between_the_core_and_the_cutter() {
        // Ø30 cutter with a Ø14 centre disk: Ø15 to Ø30 drills fit.
        let ok = |d: f64| {
            pilot_radius(
                &tool(CutterShape::FlatEnd { radius: 0.5 * d }, None),
                15.0,
                7.0,
                "op",
            )
        };
        assert_eq!(ok(16.0).ok(), Some(8.0));
        assert_eq!(ok(15.0).ok(), Some(7.5));
        assert!(ok(14.5).is_err(), "less than 0.5 mm of radial margin");
        assert!(ok(31.0).is_err(), "wider than the cutter");
        // Not a flat bottom, or not cutting to its centre.
        assert!(pilot_radius(
            &tool(CutterShape::BallEnd { radius: 8.0 }, None),
            15.0,
            7.0,
            "op"
        )
        .is_err());
        assert!(pilot_radius(
            &tool(CutterShape::FlatEnd { radius: 8.0 }, Some(3.0)),
            15.0,
            7.0,
            "op"
        )
        .is_err());
    }
}
