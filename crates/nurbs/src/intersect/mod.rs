//! Intersections between NURBS entities.
//!
//! [`curve_curve`]: all meeting points and overlapping pieces of two curves in a parameter
//! plane or in space (within a distance tolerance), and their global closest approach.

pub mod curve_curve;

pub use curve_curve::{
    closest_approach, intersect_curves, CurveIntersection, IntersectOptions, IntersectionPoint,
};
