//! # nurbs — B-spline and NURBS curves and surfaces
//!
//! Exact rational geometry for CAM: validated knot vectors, rational and non-rational
//! curves in any dimension (`NurbsCurve<D>`, with [`Curve2`] and [`Curve3`] aliases) and
//! tensor-product surfaces in 3D ([`NurbsSurface`]), evaluation and derivatives of any
//! order, plus the knot algorithms and constructors of *The NURBS Book* (Piegl & Tiller,
//! 2nd ed., 1997), whose algorithm numbers (A2.1, A4.2, ...) the item docs cite.
//!
//! ## What is here
//! | topic | items | NURBS Book |
//! |---|---|---|
//! | knot vectors, basis functions | [`KnotVector`]: `find_span`, `basis_funs`, `ders_basis_funs` | A2.1–A2.3 |
//! | curves | [`NurbsCurve`]: `point`, `derivs` (any order, rational), `derivs2` | A3.1/A3.2, A4.1/A4.2 |
//! | surfaces | [`NurbsSurface`]: `point`, `derivs2` ([`SurfaceDerivs2`]), `derivs`, `normal` | A3.5/A3.6, A4.3/A4.4 |
//! | curvature | [`NurbsSurface::principal_curvatures`], [`PrincipalCurvatures`] | §2 fundamental forms |
//! | knot insertion / refinement | `insert_knot`, `refine_knots`, `split` (curves and surfaces) | A5.1, A5.3–A5.5 |
//! | degree elevation | `elevate_degree` (curves, surfaces in `u` or `v`) | A5.9, A5.10 |
//! | Bézier decomposition | [`NurbsCurve::bezier_segments`], [`NurbsSurface::bezier_patches`] ([`BezierPatch`]) | §5.4 (via A5.4) |
//! | parametrisation | `clamped`, `reverse`, `reparametrize`, [`NurbsSurface::swap_uv`] | §5.3, §6.1 |
//! | constructors | [`NurbsCurve::circle_arc`], [`NurbsSurface::revolution`], [`NurbsSurface::ruled`] | A7.1, A8.1, §8.4 |
//! | iso curves, rigid motions | [`NurbsSurface::iso_curve_at_u`]/[`NurbsSurface::iso_curve_at_v`], `transformed`, `rotated_about_z` | §6.5 |
//! | surface–surface intersection, offset of a curve on a surface | [`surface_intersect`] | §5.8 of Patrikalakis & Maekawa |
//! | interfaces | [`ParametricCurve`], [`ParametricSurface`] | |
//! | curve–curve intersection | [`intersect::intersect_curves`], [`intersect::closest_approach`] | §5.4 bounds, subdivision + Newton |
//!
//! Every shape-preserving operation (insertion, refinement, splitting, elevation,
//! decomposition, clamping) reproduces the input to rounding; the tests check 1e-12
//! relative to the control-net size. Evaluation of degrees 1–3 runs in degree-specialised
//! kernels with precomputed reciprocal knot differences (a bicubic surface point is a few
//! tens of nanoseconds; see `benches/core_eval.rs`).
//!
//! Dependencies: `nalgebra` for the small fixed-size vectors every CAM crate of the
//! workspace already uses, `serde` for the file formats, `thiserror` for the error enum.
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
//!
//! // knot insertion leaves the curve unchanged
//! let c2 = c.insert_knot(0.5, 1).unwrap();
//! assert!((c2.point(0.3) - c.point(0.3)).norm() < 1e-14);
//!
//! // a cylinder of radius 5: revolve a segment about +Z
//! use nalgebra::Vector3;
//! use nurbs::NurbsSurface;
//! let line = NurbsCurve::<3>::new(1, vec![0., 0., 1., 1.],
//!     vec![Vector3::new(5., 0., 0.), Vector3::new(5., 0., 10.)], None).unwrap();
//! let cyl = NurbsSurface::revolution(&line, Vector3::zeros(), Vector3::z(),
//!     2.0 * std::f64::consts::PI).unwrap();
//! let d = cyl.derivs2(0.3, 0.5);
//! assert!((d.p.xy().norm() - 5.0).abs() < 1e-12);
//! let k = cyl.principal_curvatures(0.3, 0.5).unwrap();
//! assert!((k.k1.abs().max(k.k2.abs()) - 0.2).abs() < 1e-12);
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
pub mod intersect;
pub mod project;
pub mod surface_intersect;
pub mod tessellate;
