//! Variable-axis plunge roughing (WIP).
pub mod axial_depth;
