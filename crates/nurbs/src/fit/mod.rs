//! Fitting curves and surfaces to data (The NURBS Book, chapter 9).
//!
//! * [`interpolate_curve`] — global interpolation through points, optionally with end
//!   derivatives (A9.1, §9.2.1–9.2.2).
//! * [`approximate_curve`], [`approximate_curve_to_tolerance`] — least-squares approximation
//!   with fixed end points (§9.4.1).
//! * [`approximate_compatible`] — error-driven knot refinement for one or more sections
//!   sharing a knot vector, kinks kept as C⁰ knots (§9.4.1–9.4.2).
//! * [`smooth_curve`] — least squares with an added derivative energy (penalised splines).
//! * [`interpolate_surface`] — global surface interpolation through a grid (A9.4).
//! * [`skin`] — lofting a surface through section curves (§10.3).
//!
//! Dense linear algebra is done with `faer` (column-pivoted QR, rank-revealing, so a singular
//! system is reported as [`FitError::SingularSystem`] instead of producing garbage).

mod adaptive;
mod banded;
mod curve_approx;
mod curve_interp;
mod error;
mod params;
mod skin;

mod solve;
mod surface_interp;

pub use adaptive::{approximate_compatible, CompatibleFit, FitMiss, DEFAULT_KINK_ANGLE};
pub use curve_approx::{
    approximate_curve, approximate_curve_to_tolerance, smooth_curve, CurveFit, Energy,
};
pub use curve_interp::{interpolate_curve, BANDED_MIN_POINTS};
pub use error::FitError;
pub use params::{averaged_knots, parameters, Parametrisation};
pub use skin::skin;

pub use surface_interp::{interpolate_surface, interpolate_surface_at};
