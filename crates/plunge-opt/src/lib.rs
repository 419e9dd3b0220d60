//! Variable-axis plunge roughing of impeller channels without centre interference
//! (operation kind `plunge_roughing`; method of paper 000).
//!
//! Plunge milling removes most of a wide channel's material with axial strokes, where the
//! tool is stiffest. Plunge cutters are flat-end insert cutters whose bottom cuts only on a
//! ring near the rim: the disk of radius `r_core = radius − plunge_edge_length` does not cut.
//! With the conventional variable-axis path the cutter axis follows the channel's rulings,
//! and the non-cutting centre of a plunge can run into the layer of hub material the
//! previous plunge left (paper 000 §2). This crate plans the plunges, makes the angle between
//! hub normal and axis increase along every row by the smallest steps (paper 000 §3), sets
//! each plunge's depth and start height by the tangency of its bottom circle with hub and
//! shroud (paper 000 §4, eqs. 2–9), and measures the centre interference exactly before and
//! after.
//!
//! # Modules by idea
//! - [`rows`]: channel coordinates `(m, s)`, the section's extent ("until the cutter no
//!   longer fits"), suction-side, pressure-side and in-between rows, stations at the plunge
//!   step, blade allowance checked with [`cam_plan::DesignClearance`] (blades only, cutter,
//!   shank and holder);
//! - [`conventional_axes`]: the axis through the hub point `Mᵢ` and the isoparametric shroud
//!   point `Wᵢ`; the posture (depth, start, α) on any axis line;
//! - [`axis_optimisation`]: the W curve, its discretisation, the monotone-α walk;
//! - [`axial_depth`]: the Newton solve of eqs. 2–9, the offset floor for corner radius and
//!   allowance, the general disk-projection route;
//! - [`stock_clearance`]: shank and holder kept out of the stock (blank or turned stock)
//!   along every plunge, the whole tool along the rapids between plunges;
//! - [`interference`]: exact centre-disk travel through uncut material;
//! - [`allowance`]: the hub allowance left on the floor;
//! - [`toolpath`]: rapid / plunge / retract moves and row links;
//! - [`operation`]: the job keys, [`Operation`](cam_plan::Operation) implementation, metrics
//!   and plots.
//!
//! # Sections: one operation per section
//! The channel is roughed from the outlet toward the inlet in sections with decreasing
//! cutters (Ø30, Ø16, Ø8 on `impeller-plunge-400`). A planning context carries one tool, so a
//! job writes **one `plunge_roughing` operation per section**, each with its own `tool`:
//! - `start_fraction` (default 1 = the outlet): the meridional fraction of the hub contour
//!   where the section's rows begin. At the outlet each row begins with a lead-in plunge off
//!   the blank, placed where its centre disk's whole stroke stays out of the blank; a later
//!   section's rows begin inside what the previous section cleared, toward the outlet from
//!   its start until the first plunges' centre disks meet no material. So no row's first
//!   plunge drills with its centre. A later section starts where the
//!   previous one ended (its `section_end_fraction` metric), or a little toward the outlet
//!   from there; everything toward the outlet from its start counts as already roughed by
//!   the previous section (the interference metric's *cleared region*).
//! - `end_fraction` (default: where the cutter no longer fits between the blades with the
//!   blade allowance).
//!
//! Other keys: `w_curve_step` (1e-5), `optimise_axes` (true), `start_clearance_mm` (2),
//! `row_table_stations` (12), `first_channel` (0). From the process row: `width_of_cut_mm`
//! is the largest lateral gap between rows and `depth_of_cut_mm` the plunge step along a row
//! (at the hub and at the strokes' starts)
//! (both default to 0.8 × the cutting-edge length and must stay below it),
//! `blade_allowance_mm`, `hub_allowance_mm`, the plunge feed.
//!
//! # α: unsigned, as the paper defines it
//! α is the (unsigned) angle between the hub normal at the contact point and the axis. A
//! signed variant (lean toward the inlet positive) was tried: on hubs that turn from axial at
//! the inlet to radial at the outlet the hub normal turns toward the inlet faster than the
//! channel rulings, so a signed α falls steadily along every conventional row and "strictly
//! increasing" would need W points beyond the W curve's inlet end. With the unsigned angle,
//! conventional rows of such hubs already have increasing α where their axes lean back, and
//! the walk only lifts local dips (`tests/optimisation.rs` builds such dips). When the W
//! curve ends before α can rise, the plunge keeps its axis and `alpha_monotone` is false.
//!
//! # Metrics
//! `interference_positions_before` / `_after` (all channels), `alpha_monotone`,
//! `hub_allowance_max_mm` / `_mean_mm` (final axes; `_before_` versions for the conventional
//! axes), `plunges`, plus `plunges_per_channel`, `rows`, `stations`, `interference_share_*`,
//! `max_core_travel_*_mm`, `first_plunge_max_core_travel_mm` (the first plunge of every row:
//! its centre travel, 0 when none drills), `min_blade_clearance_mm`, `section_start_fraction`,
//! `section_end_fraction`, `axes_moved_per_channel`, `axes_kept_for_clearance_per_channel`
//! (plunges whose α-raising move would break the blade allowance, or would make the centre
//! disk run into more material than the conventional axis, keep their conventional axis),
//! `positions_skipped_for_stock_per_channel` (plunges left out because shank or holder
//! would enter the stock; every plunge of a section → an error asking for a turned stock or a
//! longer stick-out), `row_rapids_over_safety_surface_per_channel` (in-row rapids that would
//! not keep the tool out of the stock and go over the safety surface). With one operation per section these
//! are the per-section figures. Plot: α along every row, conventional and optimised.
//!
//! Dependencies: `nurbs` (W-curve interpolation), `cam-core`, `impeller-model`, `cam-plan`,
//! `nalgebra`, `serde` + `toml` (job keys), `thiserror`, `rayon` (rows, stations and
//! interference checks are independent).

pub mod allowance;
pub mod axial_depth;
pub mod axis_optimisation;
pub mod conventional_axes;
pub mod interference;
pub mod operation;
pub mod rows;
pub mod stock_clearance;
pub mod toolpath;

pub use operation::{PlungeParams, PlungeRoughing, SectionPlan};

/// The kind name in job files.
pub const KIND: &str = "plunge_roughing";

/// Builds a `plunge_roughing` operation from its job table (the registry's builder).
pub fn build(
    spec: &cam_plan::OperationSpec,
) -> Result<Box<dyn cam_plan::Operation>, cam_plan::PlanError> {
    Ok(Box::new(PlungeRoughing::from_spec(spec)?))
}

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
