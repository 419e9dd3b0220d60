//! A cutter as the union (and its surface as the envelope) of a one-parameter family of
//! spheres centred on the tool axis.
//!
//! # Geometry
//!
//! Work in the cutter frame: height `z` along the axis above the tip, radial distance `w` from
//! the axis. A sphere of the family has its centre on the axis at height `c(t)` and radius
//! `ρ(t)`. The envelope of the family is the surface of revolution swept by its
//! *characteristic circles*: differentiating `|x − c(t)·a|² = ρ(t)²` in `t` gives
//! `(z − c)·c' = −ρ·ρ'`, so the sphere touches the envelope on the circle at height
//! `z = c − ρρ'/c'` with radius `ρ·√(1 − (ρ'/c')²)` (an envelope exists where `|ρ'| < |c'|`).
//! With `c` itself as the parameter and `ρ = ρ₀ + k·c`, `|k| < 1`, the envelope is the cone of
//! half angle `asin k`; `k = 0` gives a cylinder.
//!
//! Because the *solid* cutter is the union of the balls of its family, the distance from a
//! point to the cutter is `min_t (|p − c(t)a| − ρ(t))` — exact for points outside. This is the
//! formulation of Zhu et al. used for flank-milling optimisation (paper 002 in
//! `shared/papers`, §"Representation of cutter swept envelope as sphere-swept surface").
//!
//! Each family here is a short list of [`SpherePiece`]s, every coefficient affine in a local
//! parameter `τ ∈ [0, 1]`; the global family parameter is `t = piece index + τ ∈ [0, n]`.
//! A piece may also carry a *disc radius* `e(τ)`: its member is then the set of spheres of
//! radius `ρ` centred on the disc of radius `e` perpendicular to the axis at height `c`
//! (a disc ⊕ ball, i.e. a filled torus). Minimising over the disc is closed form
//! (`√((z−c)² + max(w−e, 0)²) − ρ`), so such a member is still a family of spheres, just
//! with the radial position of the centre eliminated analytically. This is how sharp and
//! toroidal edges are represented — explicitly, not as a small-radius approximation:
//!
//! | cutter | pieces `(c, e, ρ)` | exact? |
//! |---|---|---|
//! | ball end `r` | `(c, 0, r)`, `c ∈ [r, L]` | yes: hemisphere + cylinder |
//! | tapered ball `r, θ` | `(c, 0, r + (c − r)·sin θ)`, `c ∈ [r, c_top]` | yes: ball + tangent cone (the sphere at `c` touches the cone `R(z) = r cos θ + (z − r(1 − sin θ)) tan θ`, whose distance from the axis point `(0, c)` is `r + (c − r) sin θ`) |
//! | bull nose `R, r_c` | `(c, R − r_c, r_c)`, `c ∈ [r_c, L]` | yes: filled torus at the bottom, cylinder above |
//! | tapered flat `R₀, θ` (flat end: `θ = 0`) | A: `(τ t_A, R₀(1 − τ), τ t_A)`, `t_A = R₀ cos θ/(1 − sin θ)`; B: `(c, 0, R₀ cos θ + c sin θ)`, `c ∈ [t_A, c_top]` | yes: piece A are the maximal inscribed disc ⊕ balls touching both the flat bottom and the cone (their centre rims run along the bisector of the bottom corner, slope `(1 − sin θ)/cos θ`); at `τ = 0` the member is the flat bottom disc itself (ρ = 0), so the sharp edge is exact; piece B are the axis-centred spheres tangent to the cone |
//!
//! `L` is the flute length: `c_top` is chosen so the characteristic circle of the last member
//! lies at height `L` (`c_top = (L + r sin θ (1 − sin θ))/cos²θ` for the tapered ball,
//! `(L + R₀ sin θ cos θ)/cos²θ` for the tapered flat end). The union is exactly the cutter
//! from the tip up to height `L`; above `L` the last member closes the solid with its own cap
//! (a half ball / rounded disc) instead of a flat cut — irrelevant for flank contact, stated
//! here so nobody relies on the top.
//!
//! # Sign inside
//!
//! `min_t (dist(p, member t))` is negative inside the union. It is then minus the depth of `p`
//! inside the *deepest single member*, which is a lower bound of the true depth below the
//! cutter surface; it equals the true depth wherever the nearest surface point lies on a
//! member whose normal passes through `p`'s member — in particular everywhere inside a ball
//! end or tapered ball end (their medial axis is the tool axis), but not near the flat bottom
//! of a flat end or bull nose, where the depth is under-estimated.
//!
//! # Shape derivatives
//!
//! Every coefficient of every piece is a closed-form function of the shape parameters
//! ([`SphereFamily::shape_param_names`]), so each piece also stores the partial derivatives of
//! its six coefficients. With `τ` held fixed (fixed bounds `[0, 1]`), the envelope theorem
//! turns these into the first-order change of the distance.

use crate::{CamError, Cutter, CutterShape};

/// One member of a sphere family: spheres of radius `radius` centred on the disc of radius
/// `disc_radius` perpendicular to the axis at height `height` above the tip (a plain sphere
/// when `disc_radius = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweptSphere {
    /// Centre height above the tip (mm).
    pub height: f64,
    /// Radius of the centre disc (mm), 0 for a plain sphere.
    pub disc_radius: f64,
    /// Sphere radius (mm).
    pub radius: f64,
}

impl SweptSphere {
    /// Signed distance from the point at radial distance `w >= 0` and height `z` (cutter frame)
    /// to this member: `√((z − c)² + max(w − e, 0)²) − ρ`. O(1).
    pub fn signed_distance(&self, w: f64, z: f64) -> f64 {
        let dz = z - self.height;
        let dw = (w - self.disc_radius).max(0.0);
        (dz * dz + dw * dw).sqrt() - self.radius
    }
}

/// A piece of a sphere family: height `c`, disc radius `e` and sphere radius `ρ` affine in
/// `τ ∈ [0, 1]` (`x(τ) = x[0] + τ·x[1]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePiece {
    /// `[c(0), c(1) − c(0)]`.
    pub height: [f64; 2],
    /// `[e(0), e(1) − e(0)]`.
    pub disc_radius: [f64; 2],
    /// `[ρ(0), ρ(1) − ρ(0)]`.
    pub radius: [f64; 2],
    /// `d_shape[k]` = `∂(height[0], height[1], disc[0], disc[1], radius[0], radius[1]) / ∂q_k`
    /// for the family's shape parameters `q_k`.
    pub d_shape: [[f64; 6]; 2],
}

impl SpherePiece {
    /// The member at local parameter `tau`.
    pub fn at(&self, tau: f64) -> SweptSphere {
        SweptSphere {
            height: self.height[0] + tau * self.height[1],
            disc_radius: self.disc_radius[0] + tau * self.disc_radius[1],
            radius: self.radius[0] + tau * self.radius[1],
        }
    }

    /// True when every member is a plain sphere (no disc).
    pub fn is_sphere(&self) -> bool {
        self.disc_radius[0] == 0.0 && self.disc_radius[1] == 0.0
    }

    /// Minimum over `τ ∈ [0, 1]` of the member distance from `(w, z)`: `(τ*, value)`.
    /// Exact and closed form, O(1):
    ///
    /// - where `e(τ) < w` (the point is beyond the disc rim) the distance is
    ///   `|A + τB| − ρ(τ)` with `A = (w − e₀, z − c₀)`, `B = (−e₁, −c₁)`: convex in `τ`; its
    ///   stationary point solves `u·B = ρ₁|u|`, `u = A + τB`, i.e. with `b = |B|`,
    ///   `x = A·B/b + τb = (ρ₁/b)·A⊥/√(1 − (ρ₁/b)²)` (`A⊥` the part of `A` normal to `B`);
    ///   for a plain sphere piece this is `c* = z + k·w/√(1 − k²)`, `k = ρ₁/c₁`;
    /// - where `e(τ) >= w` (the point is over the disc) it is `|z − c(τ)| − ρ(τ)`, piecewise
    ///   linear with a kink where `c = z`, so its minimum is at an end of that interval or at
    ///   the kink.
    ///
    /// `e` is affine, so `[0, 1]` splits into at most one interval of each kind.
    pub fn min_over_tau(&self, w: f64, z: f64) -> (f64, f64) {
        let eval = |tau: f64| (tau, self.at(tau).signed_distance(w, z));
        let better = |a: (f64, f64), b: (f64, f64)| if b.1 < a.1 { b } else { a };
        let (e0, e1) = (self.disc_radius[0], self.disc_radius[1]);
        // Interval where the point is beyond the rim (rim) and over the disc (flat).
        let (rim, flat) = if e1 == 0.0 {
            if w > e0 {
                ((0.0, 1.0), None)
            } else {
                ((1.0, 0.0), Some((0.0, 1.0)))
            }
        } else {
            let tw = ((w - e0) / e1).clamp(0.0, 1.0); // e(tw) = w
            if e1 < 0.0 {
                ((tw, 1.0), (tw > 0.0).then_some((0.0, tw)))
            } else {
                ((0.0, tw), (tw < 1.0).then_some((tw, 1.0)))
            }
        };
        let mut best = (0.0, f64::INFINITY);
        if rim.0 <= rim.1 {
            best = better(best, eval(self.rim_argmin(w, z, rim.0, rim.1)));
        }
        if let Some((lo, hi)) = flat {
            best = better(better(best, eval(lo)), eval(hi));
            let h1 = self.height[1];
            if h1 != 0.0 {
                best = better(best, eval(((z - self.height[0]) / h1).clamp(lo, hi)));
            }
        }
        best
    }

    /// Minimiser over `[lo, hi]` of the convex `|A + τB| − (ρ₀ + τρ₁)` (see
    /// [`Self::min_over_tau`]).
    fn rim_argmin(&self, w: f64, z: f64, lo: f64, hi: f64) -> f64 {
        let a = [w - self.disc_radius[0], z - self.height[0]];
        let bv = [-self.disc_radius[1], -self.height[1]];
        let b = (bv[0] * bv[0] + bv[1] * bv[1]).sqrt();
        let r1 = self.radius[1];
        if b <= f64::EPSILON * (1.0 + a[0].abs() + a[1].abs()) {
            return if r1 > 0.0 { hi } else { lo };
        }
        let k = r1 / b;
        if k >= 1.0 {
            return hi;
        }
        if k <= -1.0 {
            return lo;
        }
        let a_par = (a[0] * bv[0] + a[1] * bv[1]) / b;
        let a_perp = (a[0] * bv[1] - a[1] * bv[0]).abs() / b;
        let x = k * a_perp / (1.0 - k * k).sqrt();
        ((x - a_par) / b).clamp(lo, hi)
    }
}

/// A cutter as a piecewise family of (disc-swept) spheres; see the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereFamily {
    pieces: Vec<SpherePiece>,
    param_names: &'static [&'static str],
}

impl SphereFamily {
    /// Builds the exact family of a cutting shape whose side envelope reaches height
    /// `flute_length` (module docs give the formulas). Errors: invalid shape or flute length.
    pub fn from_shape(shape: &CutterShape, flute_length: f64) -> Result<Self, CamError> {
        shape.validate()?;
        let l = flute_length;
        if !(l.is_finite() && l > 0.0) {
            return Err(CamError::InvalidCutter {
                field: "flute_length",
                value: l,
                reason: "must be finite and > 0",
            });
        }
        let fam = match *shape {
            CutterShape::BallEnd { radius } => Self {
                pieces: vec![tapered_ball(radius, 0.0, l)],
                param_names: &["radius"],
            },
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => Self {
                pieces: vec![tapered_ball(ball_radius, half_angle, l)],
                param_names: &["ball_radius", "half_angle"],
            },
            CutterShape::BullNose {
                radius,
                corner_radius: rc,
            } => {
                let up = l > rc;
                let piece = SpherePiece {
                    height: [rc, if up { l - rc } else { 0.0 }],
                    disc_radius: [radius - rc, 0.0],
                    radius: [rc, 0.0],
                    d_shape: [
                        [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
                        [1.0, if up { -1.0 } else { 0.0 }, -1.0, 0.0, 1.0, 0.0],
                    ],
                };
                Self {
                    pieces: vec![piece],
                    param_names: &["radius", "corner_radius"],
                }
            }
            CutterShape::FlatEnd { radius } => Self {
                pieces: tapered_flat(radius, 0.0, l),
                param_names: &["radius"],
            },
            CutterShape::TaperedFlatEnd {
                tip_radius,
                half_angle,
            } => Self {
                pieces: tapered_flat(tip_radius, half_angle, l),
                param_names: &["tip_radius", "half_angle"],
            },
        };
        Ok(fam)
    }

    /// A user-defined family (any cutter of revolution whose solid is a union of
    /// (disc-swept) spheres): `pieces` in increasing parameter, `param_names` naming the
    /// shape parameters their `d_shape` rows differentiate (at most 2; may be empty).
    ///
    /// Errors ([`CamError::InvalidCutter`]): no pieces, more than two parameter names,
    /// non-finite coefficients, or a negative radius or disc radius at either end of a piece.
    pub fn new(
        pieces: Vec<SpherePiece>,
        param_names: &'static [&'static str],
    ) -> Result<Self, CamError> {
        let bad = |field, value, reason| {
            Err(CamError::InvalidCutter {
                field,
                value,
                reason,
            })
        };
        if pieces.is_empty() {
            return bad("sphere_family.pieces", 0.0, "needs at least one piece");
        }
        if param_names.len() > 2 {
            return bad(
                "sphere_family.param_names",
                param_names.len() as f64,
                "at most two shape parameters",
            );
        }
        for p in &pieces {
            let all = [p.height, p.disc_radius, p.radius]
                .into_iter()
                .flatten()
                .chain(p.d_shape.iter().flatten().copied());
            for v in all {
                if !v.is_finite() {
                    return bad("sphere_family.coefficient", v, "must be finite");
                }
            }
            for tau in [0.0, 1.0] {
                let m = p.at(tau);
                if m.radius < 0.0 || m.disc_radius < 0.0 {
                    return bad(
                        "sphere_family.radius",
                        m.radius.min(m.disc_radius),
                        "radius and disc radius must be >= 0",
                    );
                }
            }
        }
        Ok(Self {
            pieces,
            param_names,
        })
    }

    /// The family of a cutter's fluted part (shape and flute length).
    pub fn from_cutter(cutter: &Cutter) -> Result<Self, CamError> {
        Self::from_shape(&cutter.shape, cutter.flute_length)
    }

    /// The pieces, in increasing global parameter.
    pub fn pieces(&self) -> &[SpherePiece] {
        &self.pieces
    }

    /// Global parameter range `[0, number of pieces]`.
    pub fn param_range(&self) -> (f64, f64) {
        (0.0, self.pieces.len() as f64)
    }

    /// Names of the shape parameters, in the order of [`SpherePiece::d_shape`] (radians for
    /// angles).
    pub fn shape_param_names(&self) -> &'static [&'static str] {
        self.param_names
    }

    /// Splits a global parameter `t` into (piece index, local `τ`), clamping to the range.
    pub fn split(&self, t: f64) -> (usize, f64) {
        let n = self.pieces.len();
        let t = t.clamp(0.0, n as f64);
        let i = (t.floor() as usize).min(n - 1);
        (i, t - i as f64)
    }

    /// The member at global parameter `t`.
    pub fn member(&self, t: f64) -> SweptSphere {
        let (i, tau) = self.split(t);
        self.pieces[i].at(tau)
    }

    /// Signed distance from the point at radial distance `w` and height `z` (cutter frame) to
    /// the cutter, as the minimum over the family, with the global parameter of the minimiser.
    /// O(pieces).
    pub fn signed_distance(&self, w: f64, z: f64) -> (f64, f64) {
        let mut best = (f64::INFINITY, 0.0);
        for (i, piece) in self.pieces.iter().enumerate() {
            let (tau, d) = piece.min_over_tau(w, z);
            if d < best.0 {
                best = (d, i as f64 + tau);
            }
        }
        best
    }
}

/// Tapered ball `r, θ` (ball end when `θ = 0`) up to flute length `l`.
fn tapered_ball(r: f64, theta: f64, l: f64) -> SpherePiece {
    let (s, co) = theta.sin_cos();
    if l <= r * (1.0 - s) {
        // Flutes end on the ball: the ball alone.
        return SpherePiece {
            height: [r, 0.0],
            disc_radius: [0.0, 0.0],
            radius: [r, 0.0],
            d_shape: [[1.0, 0.0, 0.0, 0.0, 1.0, 0.0], [0.0; 6]],
        };
    }
    let one_m_s2 = 1.0 - s * s;
    let c_top = l / one_m_s2 + r * s / (1.0 + s);
    let h1 = c_top - r;
    let h1_r = -1.0 / (1.0 + s);
    let h1_th = co * (2.0 * l * s / (one_m_s2 * one_m_s2) + r / ((1.0 + s) * (1.0 + s)));
    SpherePiece {
        height: [r, h1],
        disc_radius: [0.0, 0.0],
        radius: [r, s * h1],
        d_shape: [
            [1.0, h1_r, 0.0, 0.0, 1.0, s * h1_r],
            [0.0, h1_th, 0.0, 0.0, 0.0, co * h1 + s * h1_th],
        ],
    }
}

/// Tapered flat end `R₀, θ` (flat end when `θ = 0`) up to flute length `l`.
fn tapered_flat(r0: f64, theta: f64, l: f64) -> Vec<SpherePiece> {
    let (s, co) = theta.sin_cos();
    let t_a = r0 * co / (1.0 - s);
    let t_a_r = co / (1.0 - s);
    let t_a_th = r0 / (1.0 - s);
    let mut out = vec![SpherePiece {
        height: [0.0, t_a],
        disc_radius: [r0, -r0],
        radius: [0.0, t_a],
        d_shape: [
            [0.0, t_a_r, 1.0, -1.0, 0.0, t_a_r],
            [0.0, t_a_th, 0.0, 0.0, 0.0, t_a_th],
        ],
    }];
    if l > r0 * co {
        let num = l + r0 * s * co;
        let c_top = num / (co * co);
        let h1 = c_top - t_a;
        let h1_r = s / co - t_a_r;
        let c_top_th = r0 * (co * co - s * s) / (co * co) + 2.0 * s * num / (co * co * co);
        let h1_th = c_top_th - t_a_th;
        out.push(SpherePiece {
            height: [t_a, h1],
            disc_radius: [0.0, 0.0],
            radius: [t_a, s * h1],
            d_shape: [
                [t_a_r, h1_r, 0.0, 0.0, t_a_r, s * h1_r],
                [t_a_th, h1_th, 0.0, 0.0, t_a_th, co * h1 + s * h1_th],
            ],
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact signed distance to the 2-D profile region (w >= 0) below the flute length, by
    /// dense sampling of the boundary polyline; sign from `radius_at`.
    fn profile_distance(shape: &CutterShape, w: f64, z: f64, l: f64) -> f64 {
        let n = 20000;
        let mut best = f64::INFINITY;
        // Bottom face (radius at h = 0) and side.
        let r0 = shape.radius_at(0.0);
        for i in 0..=n {
            let x = r0 * i as f64 / n as f64;
            best = best.min(((w - x).powi(2) + z * z).sqrt());
            let h = l * i as f64 / n as f64;
            let r = shape.radius_at(h);
            best = best.min(((w - r).powi(2) + (z - h).powi(2)).sqrt());
        }
        let inside = z >= 0.0 && z <= l && w <= shape.radius_at(z);
        if inside {
            -best
        } else {
            best
        }
    }

    fn shapes() -> Vec<CutterShape> {
        vec![
            CutterShape::BallEnd { radius: 3.0 },
            CutterShape::TaperedBallEnd {
                ball_radius: 3.0,
                half_angle: 0.1,
            },
            CutterShape::BullNose {
                radius: 5.0,
                corner_radius: 1.5,
            },
            CutterShape::FlatEnd { radius: 4.0 },
            CutterShape::TaperedFlatEnd {
                tip_radius: 2.0,
                half_angle: 0.15,
            },
        ]
    }

    #[test]
    fn family_distance_is_exact_outside_the_cutter() {
        let l = 20.0;
        for shape in shapes() {
            let fam = SphereFamily::from_shape(&shape, l).unwrap();
            for i in 0..40 {
                let z = -3.0 + 0.4 * i as f64; // up to 12.6 < L − margin
                for j in 0..12 {
                    let w = 0.5 * j as f64;
                    let exact = profile_distance(&shape, w, z, l);
                    let (d, _) = fam.signed_distance(w, z);
                    if exact > 0.0 {
                        assert!(
                            (d - exact).abs() < 2e-3,
                            "{shape:?} w={w} z={z}: {d} vs {exact}"
                        );
                    } else if exact < -1e-3 {
                        assert!(d < 0.0, "{shape:?} inside w={w} z={z}: {d}");
                        assert!(d >= exact - 2e-3, "depth is a lower bound: {d} {exact}");
                    }
                }
            }
        }
    }

    #[test]
    fn user_families_are_validated() {
        let ball = SphereFamily::from_shape(&CutterShape::BallEnd { radius: 2.0 }, 10.0).unwrap();
        let own = SphereFamily::new(ball.pieces().to_vec(), &["radius"]).unwrap();
        assert_eq!(own, ball);
        assert!(SphereFamily::new(Vec::new(), &[]).is_err());
        let mut p = ball.pieces()[0];
        p.radius = [1.0, -2.0];
        assert!(matches!(
            SphereFamily::new(vec![p], &[]),
            Err(CamError::InvalidCutter {
                field: "sphere_family.radius",
                ..
            })
        ));
        assert!(SphereFamily::new(ball.pieces().to_vec(), &["a", "b", "c"]).is_err());
    }

    #[test]
    fn ball_and_tapered_ball_depth_is_exact() {
        let shape = CutterShape::TaperedBallEnd {
            ball_radius: 3.0,
            half_angle: 0.1,
        };
        let fam = SphereFamily::from_shape(&shape, 20.0).unwrap();
        for &(w, z) in &[(0.5, 1.0), (2.0, 5.0), (1.0, 12.0), (3.2, 10.0)] {
            let exact = profile_distance(&shape, w, z, 20.0);
            let (d, _) = fam.signed_distance(w, z);
            assert!(exact < 0.0 && (d - exact).abs() < 2e-3, "{d} vs {exact}");
        }
    }

    #[test]
    fn side_envelope_reaches_the_flute_length() {
        for shape in shapes() {
            let l = 17.0;
            let fam = SphereFamily::from_shape(&shape, l).unwrap();
            // A point just outside the side at height L is at distance ≈ the radial gap.
            // The foot of the normal lies below the point, inside the enveloped part.
            let r = shape.radius_at(l - 1.0);
            let (d, _) = fam.signed_distance(r + 0.5, l - 1.0);
            let cos = match shape {
                CutterShape::TaperedBallEnd { half_angle, .. }
                | CutterShape::TaperedFlatEnd { half_angle, .. } => half_angle.cos(),
                _ => 1.0,
            };
            assert!((d - 0.5 * cos).abs() < 1e-9, "{shape:?}: {d}");
        }
    }

    #[test]
    fn shape_derivatives_match_finite_differences() {
        let l = 20.0;
        let build = |shape: CutterShape| SphereFamily::from_shape(&shape, l).unwrap();
        type Mk = fn(f64, f64) -> CutterShape;
        let makers: [(Mk, f64, f64); 3] = [
            (
                |a, b| CutterShape::TaperedBallEnd {
                    ball_radius: a,
                    half_angle: b,
                },
                3.0,
                0.07,
            ),
            (
                |a, b| CutterShape::TaperedFlatEnd {
                    tip_radius: a,
                    half_angle: b,
                },
                2.5,
                0.12,
            ),
            (
                |a, b| CutterShape::BullNose {
                    radius: a,
                    corner_radius: b,
                },
                5.0,
                1.5,
            ),
        ];
        for (mk, a, b) in makers {
            let f0 = build(mk(a, b));
            let h = 1e-6;
            for k in 0..2 {
                let (pa, pb) = if k == 0 { (h, 0.0) } else { (0.0, h) };
                let fp = build(mk(a + pa, b + pb));
                let fm = build(mk(a - pa, b - pb));
                for (i, piece) in f0.pieces().iter().enumerate() {
                    let coef = |p: &SpherePiece| {
                        [
                            p.height[0],
                            p.height[1],
                            p.disc_radius[0],
                            p.disc_radius[1],
                            p.radius[0],
                            p.radius[1],
                        ]
                    };
                    let (cp, cm) = (coef(&fp.pieces()[i]), coef(&fm.pieces()[i]));
                    for j in 0..6 {
                        let fd = (cp[j] - cm[j]) / (2.0 * h);
                        let an = piece.d_shape[k][j];
                        assert!(
                            (fd - an).abs() < 1e-6 * (1.0 + an.abs()),
                            "{k} {i} {j}: {fd} vs {an}"
                        );
                    }
                }
            }
        }
    }
}
