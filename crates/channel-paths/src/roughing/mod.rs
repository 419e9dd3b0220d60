//! Channel roughing by depth levels with triangle path planning (paper 001 §3; channel areas
//! around the splitter of paper 003).
//!
//! One idea per module:
//! - [`operation`]: the `channel_roughing` operation over all levels and channels (its docs
//!   give the whole method, step by step, and the metrics);
//! - `sides`: the bounding blade sides of a level, ruled over the level's span band and
//!   offset (step 1);
//! - `level`: the areas of one level, trimmed to the lanes where the cutter fits, planned in
//!   the developed plane (steps 2–4);
//! - `fit`: where the cutter fits on a grid section, and the lanes (step 4);
//! - `axes`: the tool axes leaning with the blades, and the candidate axes (step 5);
//! - `posture`: certified postures and the motions between them (step 5);
//! - `locate`: the cutter locations of a level;
//! - `scallop`: the scallop measured on a level;
//! - `plot`: the report's plots;
//! - [`plan2d`]: isoparametric and triangle planning of one area on one level in the level's
//!   developed plane.

mod axes;
mod fit;
mod joins;
mod level;
mod locate;
pub mod operation;
pub mod ordering;
pub mod plan2d;
mod plot;
mod posture;
mod scallop;
mod sides;
pub mod triangle;

pub use operation::{
    build_channel_roughing, ChannelRoughing, ChannelRoughingParams, CHANNEL_ROUGHING,
};
