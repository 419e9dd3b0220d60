//! # nurbs — B-spline and NURBS curves and surfaces
//!
//! Exact rational geometry for CAM: validated knot vectors, rational and non-rational
//! curves in any dimension (`NurbsCurve<D>`, with [`Curve2`] and [`Curve3`] aliases) and
//! tensor-product surfaces in 3D ([`NurbsSurface`]), evaluation and derivatives of any
//! order, plus the knot algorithms and constructors of *The NURBS Book* (Piegl & Tiller,
//! 2nd ed., 1997), whose algorithm numbers (A2.1, A4.2, ...) the item docs cite.
//!
//! ## Conventions
//! - **Parameters.** A degree-`p` curve with knots `u_0..=u_m` lives on the domain
//!   `[u_p, u_{m-p}]` ([`KnotVector::domain`]); [`KnotVector::clamped_uniform`] and the
//!   constructors use `[0, 1]` unless stated. Evaluation clamps parameters to the domain
//!   instead of failing. At an interior knot the right-sided span is used (derivatives of a
//!   curve that is only C^k there are right-sided above order k).
//! - **Control points** are stored in Euclidean form; weights separately (`None` for a
//!   non-rational entity). Algorithms that need it work in homogeneous space `(wP, w)`.
//! - **Surfaces**: control net `n_u × n_v`, `i` along `u`, `j` along `v`; flat storage is
//!   row-major, index `i * n_v + j`. Normals are `su × sv` normalised.
//! - **Degrees** are between 1 and [`MAX_DEGREE`] so evaluation runs on fixed stack
//!   buffers: `point`, `derivs2` and `derivs_into` never allocate.
//! - **Errors**: every constructor validates its input and returns a [`NurbsError`] naming
//!   the offending index; no public function panics on user data (slice-taking helpers such
//!   as [`KnotVector::basis_funs`] document their length preconditions).
//! - Units follow the caller (the impeller workspace uses millimetres and radians).
//!
//! ## Serialisation
//! All entities implement serde `Serialize`/`Deserialize`; deserialisation goes through a
//! plain data struct ([`NurbsCurveData`], [`NurbsSurfaceData`], [`KnotVectorData`]) and the
//! same validation as the constructors, so invalid files are rejected with a typed error.
//!
//! ## Example
//! ```
//! use nurbs::{NurbsCurve, KnotVector};
//! use nalgebra::Vector2;
//! // rational quarter circle of radius 1 (degree 2, one Bézier segment)
//! let w = std::f64::consts::FRAC_1_SQRT_2;
//! let c = NurbsCurve::<2>::new(
//!     2,
//!     vec![0., 0., 0., 1., 1., 1.],
//!     vec![Vector2::new(1., 0.), Vector2::new(1., 1.), Vector2::new(0., 1.)],
//!     Some(vec![1., w, 1.]),
//! ).unwrap();
//! assert!((c.point(0.3).norm() - 1.0).abs() < 1e-14);
//! ```

// The kernels transcribe The NURBS Book index by index; iterator rewrites would obscure that.
#![allow(clippy::needless_range_loop)]

mod arcs;
mod bezier;
mod curvature;
mod curve;
mod degree_elevation;
mod error;
mod homogeneous;
mod iso_curves;
mod kernels;
mod knot_insertion;
mod knots;
mod reparam;
mod revolution;
mod ruled;
mod surface;
mod traits;
mod transform;
mod util;

pub use bezier::BezierPatch;
pub use curvature::PrincipalCurvatures;
pub use curve::{Curve2, Curve3, NurbsCurve, NurbsCurveData};
pub use error::{Direction, NurbsError};
pub use knots::{KnotVector, KnotVectorData};
pub use surface::{NurbsSurface, NurbsSurfaceData, SurfaceDerivs2};
pub use traits::{ParametricCurve, ParametricSurface};

/// Largest supported degree. Evaluation uses stack buffers of `MAX_DEGREE + 1` entries.
pub const MAX_DEGREE: usize = 12;

/// `MAX_DEGREE + 1`: size of the fixed basis-function buffers.
pub const MAX_ORDER: usize = MAX_DEGREE + 1;

pub mod closest;
pub mod discretise;
pub mod fit;
pub mod project;
pub mod tessellate;
