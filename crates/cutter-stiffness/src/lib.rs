//! Stiffness indicator of tapered (conical) cutters by the Rayleigh–Ritz method.
//!
//! # The model
//!
//! A cutter is a cantilever beam clamped at the chuck (holder) face, `x = 0`, and loaded by a
//! transverse force `F` at the ball-centre plane, `x = L`. Its cross sections are solid
//! circles of radius `ρ(x)`; for the conical flute of the flank-milling literature
//! (Rayleigh–Ritz indicator of the conical-cutter stiffness paper, §"Stiffness of a conical
//! cutter")
//!
//! ```text
//! ρ(x) = r + (L − x)·tan θ,        I(x) = π ρ(x)⁴ / 4,
//! ```
//!
//! with `r` the bottom radius (radius at the ball-centre plane), `θ` the half taper angle and
//! `E` Young's modulus. The stiffness indicator is `k = F / w(L)`.
//!
//! [`ConicalCutter`] is parametrised like the envelope in `cam-core` (ball radius, half angle
//! in radians, length from the tool tip to the chuck face), and its gradient is taken in those
//! parameters, so an optimiser combines stiffness and distance derivatives with no chain rule
//! of its own; the beam quantities above (`r = r_ball / cos θ`, `L = length − r_ball`) are
//! derived from them ([`ConicalCutter::from_load_plane`] converts from the literature's form).
//!
//! ## Rayleigh–Ritz
//!
//! The deflection minimises the potential energy
//!
//! ```text
//! Π[w] = ½ ∫₀ᴸ E I(x) w''(x)² dx − F w(L),     w(0) = w'(0) = 0.
//! ```
//!
//! Instead of choosing trial functions for `w` and enforcing the clamp conditions, we expand
//! the *curvature* `w''` and integrate twice from the clamp, which satisfies `w(0) = w'(0) = 0`
//! identically and, by Taylor's formula with integral remainder, gives
//!
//! ```text
//! w(L) = ∫₀ᴸ (L − x) w''(x) dx.
//! ```
//!
//! The beam is cut into sections at every change of the section law (flute → shank); on each
//! section `w''` is a Legendre series `Σ cᵢ Pᵢ(ξ)` in the local coordinate `ξ ∈ [−1, 1]`.
//! Because `w''` may jump where `E I` jumps, the sections are independent in the energy, and
//!
//! ```text
//! Π(c) = ½ cᵀ K c − F fᵀ c,   K_ij = ∫ E I Pᵢ Pⱼ dx,   f_i = ∫ (L − x) Pᵢ dx,
//! c* = F K⁻¹ f,               w(L) = F fᵀ K⁻¹ f,        k = 1 / (fᵀ K⁻¹ f).
//! ```
//!
//! `E I` is a polynomial of degree 4 on each section, so Gauss–Legendre quadrature with
//! `n + 3` nodes integrates `K` and `f` exactly (rounding aside) for `n` terms per section.
//! Legendre polynomials are orthogonal in the unweighted inner product, which keeps `K` well
//! conditioned (it is diagonal for a cylinder). Since the trial space is a subspace of the
//! admissible one, the indicator approaches the exact value from above and converges
//! geometrically (the exact curvature `F (L − x) / E I(x)` is analytic on each section); the
//! default term count grows until the relative change is below 1e-10 (at most 80 terms;
//! otherwise a `NotConverged` error, never a silent value).
//!
//! ## Exact value
//!
//! The unit-load method gives the exact tip compliance of the same beam,
//! `w(L)/F = ∫₀ᴸ (L − x)² / (E I(x)) dx`. With `s = L − x` and a linear radius `ρ = α + β s`
//! on a section (`α > 0`),
//!
//! ```text
//! ∫₀^S s² / (α + β s)⁴ ds = S³ / (3 α (α + β S)³),
//! ```
//!
//! which needs no division by `β` and is therefore exact for cylinders too. For the conical
//! model this collapses to `k = 3 π E r R³ / (4 L³)` with `R = r + L tan θ`; for a cylinder,
//! `k = 3 E I / L³`.
//!
//! ## Gradient
//!
//! With `F = 1`, `w = fᵀ K⁻¹ f` and `f` independent of the shape, `∂k/∂p = (cᵀ K_p c) / w²`
//! where `K_p = ∫ E ∂I/∂p Pᵢ Pⱼ dx`, `∂I/∂r = π ρ³`, `∂I/∂θ = π ρ³ (L − x) sec² θ`; the beam
//! length enters through the scaling `x = Lξ` (see [`ConicalCutter::report`]). This is the
//! exact derivative of the Rayleigh–Ritz indicator (not a finite difference).
//!
//! Units: millimetres and N/mm² (MPa) give stiffness in N/mm.

mod beam;
mod conical;
mod error;
mod quadrature;
mod ritz;

pub use beam::{Beam, Section};
pub use conical::{cutter_beam, ConicalCutter, StiffnessReport};
pub use error::StiffnessError;
pub use ritz::{RitzOptions, RitzSolution};

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
