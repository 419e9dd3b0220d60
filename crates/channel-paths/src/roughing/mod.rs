//! Channel roughing by depth levels with triangle path planning (paper 001 §3; channel areas
//! around the splitter of paper 003).
//!
//! [`plan2d`]: isoparametric and triangle planning of one area on one level in the level's
//! developed plane; [`operation`]: the `channel_roughing` operation over all levels and
//! channels.

pub mod operation;
pub mod plan2d;

pub use operation::{
    build_channel_roughing, ChannelRoughing, ChannelRoughingParams, CHANNEL_ROUGHING,
};
