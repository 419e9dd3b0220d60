//! Variable-axis plunge roughing of impeller channels without centre interference
//! (operation kind `plunge_roughing`; method of paper 000).
//!
//! Plunge milling removes most of a wide channel's material with axial strokes, where the
//! tool is stiffest. Plunge cutters are flat-end insert cutters whose bottom cuts only on a
//! ring near the rim: the disk of radius `r_core = radius − plunge_edge_length` does not cut.
//! A plunge whose centre disk runs into material nothing removed makes noise, vibration and
//! broken inserts (paper 000 §2). This crate plans the plunges, feeds every row segment the
//! way its axes lean and corrects what is left by the paper's W walk (§3), sets each plunge's
//! depth and start height by the tangency of its bottom circle with hub and shroud (§4, eqs.
//! 2–9), enters every segment off the blank, where something already cut, or through a
//! drilled pilot hole, and measures the centre interference before and after.
//!
//! # Modules by idea
//! - [`rows`]: channel coordinates `(m, s)`, the section's extent ("until the cutter no
//!   longer fits"), suction-side, pressure-side and in-between rows, stations at the plunge
//!   step, blade allowance checked with [`cam_plan::DesignClearance`] (blades only, cutter,
//!   shank and holder);
//! - [`fillet_clearance`]: every posture's flat end keeps the smaller allowance from the
//!   blade-root fillets (sampled rim and side, Lipschitz margin), which fill the corner the
//!   hub floor and the blade clearance leave open;
//! - [`conventional_axes`]: the axis through the hub point `Mᵢ` and the isoparametric shroud
//!   point `Wᵢ`; the posture (depth, start, α) on any axis line;
//! - [`feed`]: signed α, and the row segments fed toward where their axes lean;
//! - [`axis_optimisation`]: the W curve, its discretisation, the walk that removes what
//!   interference the feed direction leaves;
//! - [`entries`]: lead-in, cleared and pilot entries, the pilot drill;
//! - [`feed_plan`]: the section's machining order (segments, entries, pilots, walks) with the
//!   interference kept current;
//! - [`axial_depth`]: the Newton solve of eqs. 2–9, the offset floor for corner radius and
//!   allowance, the general disk-projection route;
//! - [`stock_clearance`]: shank and holder kept out of the stock (blank or turned stock)
//!   along every plunge, the whole tool along the rapids between plunges;
//! - [`interference`]: centre-disk travel through uncut material;
//! - [`allowance`]: the hub allowance left on the floor;
//! - [`toolpath`]: rapid / plunge / retract moves and segment links;
//! - [`operation`]: the job keys, [`Operation`](cam_plan::Operation) implementation (with the
//!   pilot-drilling step), metrics and plots.
//!
//! # Sections: one operation per section
//! The channel is roughed in sections with decreasing cutters (Ø30, Ø16, Ø8 on
//! `impeller-plunge-400`). A planning context carries one tool, so a job writes **one
//! `plunge_roughing` operation per section**, each with its own `tool`:
//! - `start_fraction` (default 1 = the outlet): the meridional fraction of the hub contour
//!   where the section's rows begin on their outlet side. At the outlet each row begins with
//!   a lead-in station off the blank, placed where its centre disk's whole stroke stays out of
//!   the blank. A later section (start below 1) starts where the previous one ended (its
//!   `section_end_fraction` metric) or a little toward the outlet from there, moved toward
//!   the outlet until its first plunges' centres meet nothing in the region the previous
//!   section roughed (everything toward the outlet from `start_fraction`).
//! - `end_fraction` (default: where the cutter no longer fits between the blades with the
//!   blade allowance). The hub between the inlet and the last section's end is not plunged
//!   (`unroughed_hub_length_mm`, with a note).
//!
//! # Feed direction, entries, pilots
//! Each row is split where the lean of its conventional axes along the row changes sign; each
//! segment is fed toward where its axes lean ([`feed`]: a flat bottom leaning toward the feed
//! leaves its wedge behind it; one leaning back leaves it where the next centre goes). The
//! segment's first plunge is its *entry*, which must not drill with its centre
//! ([`entries`]). Key `entry`:
//! - `"pilot"` (the default): an entry that would drill gets a pilot hole along its axis,
//!   drilled before the section with the drill of the `[pilot]` table (a job tool,
//!   `flat_end`, cutting to its centre, at least the centre disk's diameter + 1 mm and at most
//!   the cutter's diameter; keys `tool`, `spindle_rpm`, `feed_per_tooth_mm`), posted by the
//!   pipeline as its own operation `<name>-pilot` of kind `pilot_drilling`. A plunge other
//!   than an entry that no admissible W walk clears gets one too. The interference measure
//!   then ignores what earlier sections removed (an upper bound of the real travel).
//! - `"cleared"`: no drill; a segment whose lean-ward entry would drill is fed from its other
//!   end when that end does not (leaning back, corrected by the walk where it can), and the
//!   region beyond `start_fraction < 1` counts as removed by the previous section.
//! - `"lead_in"`: as `"cleared"` without trusting the previous section.
//!
//! Other keys: `w_curve_step` (1e-5), `optimise_axes` (true: walk the W of plunges that
//! still interfere), `start_clearance_mm` (2), `row_table_stations` (12), `first_channel`
//! (0). From the process row: `width_of_cut_mm` is the largest lateral gap between rows and
//! `depth_of_cut_mm` the plunge step along a row (at the hub and at the strokes' starts)
//! (both default to 0.8 × the cutting-edge length and must stay below it),
//! `blade_allowance_mm`, `hub_allowance_mm`, the plunge feed.
//!
//! # α: signed, a diagnostic
//! α is the paper's angle between the hub normal at the contact point and the axis, signed
//! positive when the axis leans toward the feed of its segment ([`feed::signed_alpha`]). The
//! paper's rule "α increases from plunge to plunge" is reported as `alpha_monotone` (per
//! segment, signed) but is not the measure of success: on `impeller-plunge-400` the Ø30 rows
//! fed inlet → outlet have signed α falling along the feed from about 36° to 2° and interfere
//! only next to where two segments meet (the hub turns the normals with the rows), and where
//! two segments meet it must fall toward zero. The walk's criterion is the interference
//! itself ([`axis_optimisation`]).
//!
//! # Metrics
//! `interference_positions_before` (conventional axes, every row fed outlet → inlet, the
//! paper's and every CAM system's plan) / `_after` (the plan; entries included; all
//! channels), `alpha_monotone` (signed, per segment) and `alpha_monotone_before`,
//! `alpha_signed_min_deg` / `_max_deg` (and `_before_` versions), `entries_per_channel`
//! with `entries_lead_in_per_channel`, `entries_cleared_per_channel`,
//! `entries_pilot_per_channel`, `entries_unhandled_per_channel`, `pilots_per_channel`,
//! `pilots_for_other_plunges_per_channel`, `pilot_diameter_mm`, `pilot_depth_mm` (deepest
//! hole in the stock; 0 without pilots), `entry_max_core_travel_mm`,
//! `hub_allowance_max_mm` / `_mean_mm` (final axes; `_before_` versions for the conventional
//! axes), `unroughed_hub_length_mm`, `plunges`, `plunges_per_channel`, `rows`, `stations`,
//! `segments_fed_toward_outlet_per_channel`, `interference_share_*`, `max_core_travel_*_mm`,
//! `min_blade_clearance_mm`, `section_start_fraction`, `section_end_fraction`,
//! `axes_moved_per_channel` (walked), `axes_moved_against_feed_per_channel`,
//! `axes_kept_for_clearance_per_channel` (still interfering: no admissible W, no pilot),
//! `positions_shifted_for_clearance_per_channel`, `positions_skipped_for_stock_per_channel`
//! (plunges left out because shank or holder would enter the stock; every plunge of a
//! section → an error asking for a turned stock or a longer stick-out),
//! `row_rapids_over_safety_surface_per_channel` (rapids between plunges of a segment that
//! would not keep the tool out of the stock and go over the safety surface). With one
//! operation per section these are the per-section figures. Plot: signed α along every row,
//! conventional (outlet → inlet) and planned. The pilot step reports `pilots`,
//! `pilots_per_channel`, `pilot_diameter_mm`, `pilot_depth_mm` and the drill's
//! `min_blade_clearance_mm`.
//!
//! Dependencies: `nurbs` (W-curve interpolation), `cam-core`, `impeller-model`, `cam-plan`,
//! `nalgebra`, `serde` + `toml` (job keys), `thiserror`, `rayon` (rows, stations and
//! interference checks are independent).

pub mod allowance;
pub mod axial_depth;
pub mod axis_optimisation;
pub mod conventional_axes;
pub mod entries;
pub mod feed;
pub mod feed_plan;
pub mod fillet_clearance;
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
