//! Depth levels between hub and shroud, and where a (blade or offset-blade) surface meets a
//! level: the channel boundary on that level as NURBS curves.
//!
//! **Level surfaces.** A depth level is a surface of revolution about +Z whose meridional
//! contour lies between the shroud and the hub contours. Three constructions
//! ([`LevelSpacing`]), each at meridional fraction `m` of the reference contour(s):
//!
//! * `FromShroud(d)`: the shroud contour moved by `d` mm into the channel, `C(m) = S(m) − d·N_S(m)`
//!   (`N_S` the shroud's channel-side normal, which points out of the channel);
//! * `FromHub(d)`: the hub contour moved by `d` mm into the channel, `C(m) = H(m) + d·N_H(m)`;
//! * `Interpolated { fraction, hub_offset }`: the blend `(1 − f)·S(m) + f·H'(m)` at equal
//!   meridional fractions between the shroud (`f = 0`) and the hub contour offset by
//!   `hub_offset` (`f = 1`) — levels at equal fractions split the channel depth evenly at
//!   every `m`, and the last one follows the hub at the allowance.
//!
//! The exact contour is sampled at [`LEVEL_SAMPLES`] fractions and interpolated by a cubic
//! NURBS (chord-length parameters, NURBS Book §9.2.1); the largest distance between the fit
//! and the exact construction at the midpoints between samples is reported as
//! [`DepthLevel::fit_deviation_mm`]. Cost O(LEVEL_SAMPLES) contour evaluations plus one
//! banded interpolation solve.
//!
//! **Boundary on a level.** For a surface `S(u, v)` (a blade side or its ruled approximation,
//! u along the flow, v hub → shroud) offset by `δ` along its unit normal `n` (sign chosen by
//! the caller, e.g. the blade's outward side), `O(u, v) = S + δ·n`, the boundary is the curve
//! `O(u, v*(u))` with `v*(u)` the root of the level's signed meridional distance
//! `d_L(O(u, v)) = 0` (bracketed on [`ROOT_BRACKETS`] v samples, Illinois regula falsi to
//! [`ROOT_TOL_MM`]). It is sampled at `n` values of u and interpolated as a cubic NURBS both in
//! space and in the level's *developed plane* `(s, θ)` — `s` the arc length along the level
//! contour from the inlet (mm) and `θ` the polar angle, unwrapped along the curve — so that
//! planners can offset and intersect boundaries in a plane. Cost O(n·ROOT_BRACKETS) offset
//! evaluations plus O(n·iterations) for the roots.

use crate::error::ModelError;
use crate::impeller::Impeller;
use crate::meridional::MeridionalCurve;
use crate::revolved::RevolvedSurface;
use nalgebra::{Vector2, Vector3};
use nurbs::fit::{interpolate_curve, Parametrisation};
use nurbs::{Curve2, Curve3, NurbsSurface};

/// Samples of a level contour: 97 points resolve the hub/shroud contours of the fixtures
/// (a few Bézier pieces each) to well under 1 µm, checked by `fit_deviation_mm`.
pub const LEVEL_SAMPLES: usize = 97;

/// v brackets of the boundary root search, as in [`crate::channel::edge_v`].
pub const ROOT_BRACKETS: usize = 16;

/// Root tolerance of the boundary search (mm of meridional distance): far below machining
/// tolerances.
pub const ROOT_TOL_MM: f64 = 1e-9;

/// A root is accepted when the offset point lies this close to the level (mm): the solve
/// reaches [`ROOT_TOL_MM`]; a larger residual means the bracket straddled a contour end.
pub const ROOT_ACCEPT_MM: f64 = 1e-6;

/// How a depth level is placed between hub and shroud (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LevelSpacing {
    /// The shroud contour moved into the channel by this many mm.
    FromShroud(f64),
    /// The hub contour moved into the channel by this many mm.
    FromHub(f64),
    /// Blend between the shroud (`fraction = 0`) and the hub contour moved into the channel by
    /// `hub_offset` mm (`fraction = 1`).
    Interpolated {
        /// Position between shroud (0) and offset hub (1).
        fraction: f64,
        /// Offset of the hub end of the blend (mm), e.g. the roughing allowance.
        hub_offset: f64,
    },
}

/// A depth level: its construction and its surface of revolution.
#[derive(Debug, Clone)]
pub struct DepthLevel {
    /// How it was constructed.
    pub spacing: LevelSpacing,
    /// The level surface (its meridional contour runs inlet → outlet).
    pub surface: RevolvedSurface,
    /// Largest distance between the fitted contour and the exact construction (mm).
    pub fit_deviation_mm: f64,
}

fn exact_level_point(imp: &Impeller, spacing: LevelSpacing, m: f64) -> Vector2<f64> {
    let hub = imp.hub().meridional();
    let shroud = imp.shroud().meridional();
    match spacing {
        LevelSpacing::FromShroud(d) => {
            let t = shroud.param_at_fraction(m);
            shroud.point(t) - shroud.normal(t) * d
        }
        LevelSpacing::FromHub(d) => {
            let t = hub.param_at_fraction(m);
            hub.point(t) + hub.normal(t) * d
        }
        LevelSpacing::Interpolated {
            fraction,
            hub_offset,
        } => {
            let ts = shroud.param_at_fraction(m);
            let th = hub.param_at_fraction(m);
            let h = hub.point(th) + hub.normal(th) * hub_offset;
            shroud.point(ts) * (1.0 - fraction) + h * fraction
        }
    }
}

/// Builds the depth level of `spacing` (module docs).
///
/// Errors: non-finite values, an interpolation fraction outside [0, 1], a contour reaching
/// r ≤ 0, or a failed fit.
pub fn depth_level(imp: &Impeller, spacing: LevelSpacing) -> Result<DepthLevel, ModelError> {
    let bad = |v: f64| !v.is_finite();
    match spacing {
        LevelSpacing::FromShroud(d) | LevelSpacing::FromHub(d) if bad(d) => {
            return Err(ModelError::invalid("level offset", "must be finite"));
        }
        LevelSpacing::Interpolated {
            fraction,
            hub_offset,
        } if bad(fraction) || bad(hub_offset) || !(0.0..=1.0).contains(&fraction) => {
            return Err(ModelError::invalid(
                "level fraction",
                "must be finite and in [0, 1] with a finite hub offset",
            ));
        }
        _ => {}
    }
    let n = LEVEL_SAMPLES;
    let pts: Vec<Vector2<f64>> = (0..n)
        .map(|i| exact_level_point(imp, spacing, i as f64 / (n - 1) as f64))
        .collect();
    if let Some(p) = pts.iter().find(|p| p[1].is_nan() || p[1] <= 0.0) {
        return Err(ModelError::Geometry(format!(
            "depth level {spacing:?} reaches r = {:.4} mm at z = {:.4} mm",
            p[1], p[0]
        )));
    }
    let curve = interpolate_curve(&pts, 3, Parametrisation::ChordLength, None)
        .map_err(|e| ModelError::Geometry(format!("depth level {spacing:?}: fit failed: {e}")))?;
    let contour = MeridionalCurve::new(curve)?;
    // Fit check at the midpoints between samples (exact construction vs. fitted contour).
    let mut dev: f64 = 0.0;
    for i in 0..n - 1 {
        let m = (i as f64 + 0.5) / (n - 1) as f64;
        let p = exact_level_point(imp, spacing, m);
        dev = dev.max(contour.closest(p).1.abs());
    }
    Ok(DepthLevel {
        spacing,
        surface: RevolvedSurface::new(contour)?,
        fit_deviation_mm: dev,
    })
}

impl DepthLevel {
    /// Signed distance of `p` from the level along its meridional normal (positive toward the
    /// shroud side, i.e. the hub-like channel-side normal of the contour).
    pub fn signed_distance(&self, p: &Vector3<f64>) -> f64 {
        self.surface.closest(p).2
    }

    /// Developed coordinates `(s, θ)` of a point near the level: arc length (mm) of its
    /// meridional foot along the level contour from the inlet, and its polar angle (−π, π].
    pub fn developed(&self, p: &Vector3<f64>) -> (f64, f64) {
        let m = self.surface.meridional();
        let (t, _) = m.closest(MeridionalCurve::zr_of(p));
        (m.arc_length_at(t), p.y.atan2(p.x))
    }

    /// The point of the level at developed coordinates `(s, θ)` with its unit normal (the
    /// contour's channel-side normal turned to θ).
    pub fn at_developed(&self, s: f64, theta: f64) -> (Vector3<f64>, Vector3<f64>) {
        let m = self.surface.meridional();
        let t = m.param_at_fraction(s / m.length_mm());
        (self.surface.point(t, theta), self.surface.normal(t, theta))
    }

    /// Radius of the level contour at arc length `s` (mm).
    pub fn radius_at(&self, s: f64) -> f64 {
        let m = self.surface.meridional();
        m.point(m.param_at_fraction(s / m.length_mm()))[1]
    }

    /// Length of the level contour (mm).
    pub fn length_mm(&self) -> f64 {
        self.surface.meridional().length_mm()
    }
}

/// A curve where an (offset) surface meets a depth level.
#[derive(Debug, Clone)]
pub struct LevelCurve {
    /// The curve in space.
    pub space: Curve3,
    /// The curve in the level's developed plane: x = s (mm along the contour), y = θ (rad,
    /// unwrapped).
    pub developed: Curve2,
    /// Surface parameters u of the first and last sample.
    pub u_range: (f64, f64),
    /// The samples: (u, v) surface parameters.
    pub samples: Vec<(f64, f64)>,
}

/// Point of `S + δ·sign·n̂` at (u, v); `None` where the normal vanishes.
fn offset_point(s: &NurbsSurface, u: f64, v: f64, offset: f64) -> Option<Vector3<f64>> {
    let d = s.derivs2(u, v);
    let n = d.su.cross(&d.sv);
    let l = n.norm();
    (l > 0.0 && l.is_finite()).then(|| d.p + n * (offset / l))
}

fn level_root(
    s: &NurbsSurface,
    level: &DepthLevel,
    u: f64,
    offset: f64,
) -> Option<(f64, Vector3<f64>)> {
    let (_, (v0, v1)) = s.domain();
    let f = |v: f64| offset_point(s, u, v, offset).map(|p| (level.signed_distance(&p), p));
    let (mut a, (mut fa, _)) = (v0, f(v0)?);
    for k in 1..=ROOT_BRACKETS {
        let b = v0 + (v1 - v0) * k as f64 / ROOT_BRACKETS as f64;
        let (fb, pb) = f(b)?;
        if fa == 0.0 {
            return Some((a, f(a)?.1));
        }
        if (fa < 0.0) != (fb < 0.0) || fb == 0.0 {
            if fb == 0.0 {
                return Some((b, pb));
            }
            let x =
                crate::root::illinois(|x| f(x).map(|v| v.0), (a, fa), (b, fb), ROOT_TOL_MM, 200)?.x;
            // A sign change across the end of the open contour is no crossing: accept only a
            // converged root whose meridional foot lies inside the contour.
            let (fx, px) = f(x)?;
            let m = level.surface.meridional();
            let (t, _) = m.closest(MeridionalCurve::zr_of(&px));
            let (ta, tb) = m.domain();
            let inside = t > ta + 1e-9 * (tb - ta) && t < tb - 1e-9 * (tb - ta);
            return (fx.abs() < ROOT_ACCEPT_MM && inside).then_some((x, px));
        }
        a = b;
        fa = fb;
    }
    None
}

/// Where `surface` offset by `offset` mm along its normal `su × sv` (negative: against it)
/// meets `level`, sampled at `n ≥ 4` values of u over `u_range` and interpolated (module
/// docs). Samples where the offset surface misses the level are skipped; the curve is built
/// from the longest run of consecutive hits.
///
/// Errors: fewer than 4 consecutive samples meet the level; a failed fit.
pub fn offset_surface_on_level(
    surface: &NurbsSurface,
    offset: f64,
    level: &DepthLevel,
    u_range: (f64, f64),
    n: usize,
) -> Result<LevelCurve, ModelError> {
    let n = n.max(4);
    let hits: Vec<Option<(f64, f64, Vector3<f64>)>> = (0..n)
        .map(|i| {
            let u = u_range.0 + (u_range.1 - u_range.0) * i as f64 / (n - 1) as f64;
            level_root(surface, level, u, offset).map(|(v, p)| (u, v, p))
        })
        .collect();
    // Longest run of consecutive hits.
    let (mut best, mut cur) = ((0, 0), (0, 0));
    for (i, h) in hits.iter().enumerate() {
        if h.is_some() {
            if cur.1 == 0 {
                cur.0 = i;
            }
            cur.1 += 1;
            if cur.1 > best.1 {
                best = cur;
            }
        } else {
            cur.1 = 0;
        }
    }
    if best.1 < 4 {
        return Err(ModelError::Geometry(format!(
            "offset surface ({offset:.4} mm) meets the depth level at only {} consecutive of \
             {n} samples",
            best.1
        )));
    }
    let run: Vec<(f64, f64, Vector3<f64>)> = hits[best.0..best.0 + best.1]
        .iter()
        .flatten()
        .copied()
        .collect();
    let space_pts: Vec<Vector3<f64>> = run.iter().map(|h| h.2).collect();
    let mut dev_pts = Vec::with_capacity(run.len());
    let mut prev: Option<f64> = None;
    for h in &run {
        let (s, th) = level.developed(&h.2);
        let th = match prev {
            Some(p) => {
                p + (th - p + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI
            }
            None => th,
        };
        prev = Some(th);
        dev_pts.push(Vector2::new(s, th));
    }
    let fit_err = |e: nurbs::fit::FitError| {
        ModelError::Geometry(format!("boundary on depth level: fit failed: {e}"))
    };
    let space =
        interpolate_curve(&space_pts, 3, Parametrisation::ChordLength, None).map_err(fit_err)?;
    let developed =
        interpolate_curve(&dev_pts, 3, Parametrisation::ChordLength, None).map_err(fit_err)?;
    Ok(LevelCurve {
        space,
        developed,
        u_range: (run[0].0, run[run.len() - 1].0),
        samples: run.iter().map(|h| (h.0, h.1)).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::default_impeller;

    #[test]
    fn levels_lie_at_their_construction() {
        let imp = default_impeller().unwrap();
        // FromHub(d): every sampled point of the level is d from the hub.
        for (sp, want) in [
            (LevelSpacing::FromHub(0.5), 0.5),
            (LevelSpacing::FromShroud(1.5), -1.5),
        ] {
            let lv = depth_level(&imp, sp).unwrap();
            assert!(lv.fit_deviation_mm < 1e-4, "{}", lv.fit_deviation_mm);
            let m = lv.surface.meridional();
            for i in 1..20 {
                let t = m.param_at_fraction(i as f64 / 20.0);
                let p = lv.surface.point(t, 0.3);
                let d = match sp {
                    LevelSpacing::FromHub(_) => imp.hub().signed_distance(&p),
                    _ => imp.shroud().signed_distance(&p),
                };
                assert!((d - want).abs() < 1e-3, "{sp:?}: {d}");
            }
        }
        // Interpolated at 0 is the shroud, at 1 the hub offset.
        let lv = depth_level(
            &imp,
            LevelSpacing::Interpolated {
                fraction: 1.0,
                hub_offset: 0.3,
            },
        )
        .unwrap();
        let m = lv.surface.meridional();
        for i in 1..10 {
            let p = lv.surface.point(m.param_at_fraction(i as f64 / 10.0), 1.0);
            assert!((imp.hub().signed_distance(&p) - 0.3).abs() < 1e-3);
        }
        assert!(depth_level(
            &imp,
            LevelSpacing::Interpolated {
                fraction: 1.5,
                hub_offset: 0.0
            }
        )
        .is_err());
    }

    #[test]
    fn boundary_curve_lies_on_level_at_the_offset() {
        let imp = default_impeller().unwrap();
        let lv = depth_level(
            &imp,
            LevelSpacing::Interpolated {
                fraction: 0.5,
                hub_offset: 0.0,
            },
        )
        .unwrap();
        let blade = imp.main().blade();
        let side = blade.plus_theta_side();
        let s = blade.side(side);
        let ((u0, u1), _) = s.domain();
        let off = 2.0 * blade.outward_sign(side);
        let c = offset_surface_on_level(s, off, &lv, (u0, u1), 41).unwrap();
        let (a, b) = c.space.domain();
        for i in 0..=50 {
            let p = c.space.point(a + (b - a) * i as f64 / 50.0);
            // On the level, and 2 mm outside the blade side.
            assert!(
                lv.signed_distance(&p).abs() < 5e-3,
                "{}",
                lv.signed_distance(&p)
            );
            let q = nurbs::closest::closest_point_on_surface(s, &p);
            assert!(
                (q.distance - 2.0).abs() < 5e-3,
                "i {i}: {} boundary {}",
                q.distance,
                q.on_boundary
            );
        }
        // Developed curve maps back to the same points.
        let (da, db) = c.developed.domain();
        let d = c.developed.point(0.5 * (da + db));
        let (p, _) = lv.at_developed(d[0], d[1]);
        let q = nurbs::closest::closest_point_on_surface(s, &p);
        assert!((q.distance - 2.0).abs() < 5e-3);
    }
}
