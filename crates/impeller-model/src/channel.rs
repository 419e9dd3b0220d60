//! Channels between blades, blade edge curves on hub and shroud, and channel widths.
//!
//! Channel k is the passage between blade k and blade k+1 of the main row (+θ order), floored
//! by the hub and closed by the shroud, with splitter k inside when there are splitters. It is
//! bounded by the side of main blade k that faces +θ (its suction side in the parametric
//! convention) and the side of main blade k+1 that faces −θ (pressure side).
//!
//! The **hub edge** of a blade side is its intersection with the hub: for each u the root in v
//! of the hub's signed distance d_hub(S(u, v)) = 0 (bracketed on 16 v samples, then
//! Illinois regula falsi to 1e-10 mm); likewise the **shroud edge**. The **channel width at
//! the hub** is the smallest distance between the hub edges of two facing sides — between
//! every pair of neighbouring blades (main–splitter, splitter–main, and main–main upstream of
//! the splitter). It is found by brute force on 121 × 121 edge samples and refined by
//! alternating golden-section searches in both curve parameters (error ≪ 1e-6 mm for smooth
//! edges). Cost O(n²) point distances plus O(n) root solves per edge.
//!
//! A **channel section** ([`Channel::section`]) gives, at one contour parameter of hub or
//! shroud, the polar angles where the bounding sides (and the splitter) meet that wall — the
//! angular extent of the channel floor or opening there.

use crate::blade::{Blade, Side};
use crate::error::ModelError;
use crate::impeller::Impeller;
use crate::revolved::RevolvedSurface;
use nalgebra::Vector3;

/// Hub or shroud.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Wall {
    /// The hub (channel floor).
    Hub,
    /// The shroud (channel lid).
    Shroud,
}

fn wall_of(imp: &Impeller, wall: Wall) -> &RevolvedSurface {
    match wall {
        Wall::Hub => imp.hub(),
        Wall::Shroud => imp.shroud(),
    }
}

/// Parameter v where the side's isoparametric line u crosses `wall`.
///
/// # Errors
/// [`ModelError::EdgeMissesWall`] (with `wall: None`, as only the surface is known here) when
/// the line does not cross from inside to outside the wall within the side's v range. Callers
/// scanning for where an edge ends treat this as a normal answer.
pub fn edge_v(
    blade: &Blade,
    side: Side,
    wall: &RevolvedSurface,
    u: f64,
) -> Result<f64, ModelError> {
    let s = blade.side(side);
    let (_, (v0, v1)) = s.domain();
    let f = |v: f64| wall.signed_distance(&s.point(u, v));
    let n = 16;
    let mut a = v0;
    let mut fa = f(a);
    for k in 1..=n {
        let b = v0 + (v1 - v0) * k as f64 / n as f64;
        let fb = f(b);
        if fa <= 0.0 && fb > 0.0 {
            // Illinois regula falsi; unconverged, the middle of the bracket left.
            let r = crate::root::illinois(|x| Some(f(x)), (a, fa), (b, fb), 1e-10, 100);
            return Ok(r.map_or(0.5 * (a + b), |r| {
                if r.converged {
                    r.x
                } else {
                    0.5 * (r.lo + r.hi)
                }
            }));
        }
        a = b;
        fa = fb;
    }
    Err(ModelError::EdgeMissesWall {
        side,
        wall: None,
        u,
    })
}

/// A blade side's intersection with hub or shroud as (u, v, point) samples at `n` values of u.
/// Values of u where the side's isoparametric line misses the wall (beyond the wall's ends) are
/// left out.
///
/// # Errors
/// [`ModelError::EdgeEmpty`] (with `wall: None`) when no sample meets the wall (or `n` is 0).
pub fn edge_curve(
    blade: &Blade,
    side: Side,
    wall: &RevolvedSurface,
    n: usize,
) -> Result<Vec<(f64, f64, Vector3<f64>)>, ModelError> {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let edge: Vec<_> = (0..n)
        .filter_map(|i| {
            let u = u0 + (u1 - u0) * i as f64 / (n.max(2) - 1) as f64;
            // A miss at one u is normal (the edge ends before the side's u end): skip it.
            edge_v(blade, side, wall, u)
                .ok()
                .map(|v| (u, v, s.point(u, v)))
        })
        .collect();
    if edge.is_empty() {
        return Err(ModelError::EdgeEmpty {
            side,
            wall: None,
            n,
        });
    }
    Ok(edge)
}

fn golden(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..60 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

/// Smallest distance (mm) between the `wall` edges of side `sa` of blade `a` and side `sb` of
/// blade `b`, with the two points; `None` when an edge misses the wall.
pub fn min_edge_distance(
    a: &Blade,
    sa: Side,
    b: &Blade,
    sb: Side,
    wall: &RevolvedSurface,
) -> Option<(f64, Vector3<f64>, Vector3<f64>)> {
    let n = 121;
    let ea = edge_curve(a, sa, wall, n).ok()?;
    let eb = edge_curve(b, sb, wall, n).ok()?;
    let mut best = (f64::INFINITY, 0, 0);
    for (i, pa) in ea.iter().enumerate() {
        for (j, pb) in eb.iter().enumerate() {
            let d = (pa.2 - pb.2).norm_squared();
            if d < best.0 {
                best = (d, i, j);
            }
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let (ua, ub) = (ea[best.1].0, eb[best.2].0);
    let ha = 1.5 / (n - 1) as f64;
    let (ua0, ua1) = (a.side(sa).domain().0 .0, a.side(sa).domain().0 .1);
    let (ub0, ub1) = (b.side(sb).domain().0 .0, b.side(sb).domain().0 .1);
    // A miss inside the search bracket only means "no candidate here" (infinite distance).
    let pa_of = |u: f64| edge_v(a, sa, wall, u).ok().map(|v| a.side(sa).point(u, v));
    let pb_of = |u: f64| edge_v(b, sb, wall, u).ok().map(|v| b.side(sb).point(u, v));
    let (mut xa, mut xb) = (ua, ub);
    let dist = |pa: Option<Vector3<f64>>, pb: Option<Vector3<f64>>| match (pa, pb) {
        (Some(p), Some(q)) => (p - q).norm(),
        _ => f64::INFINITY,
    };
    for _ in 0..4 {
        let pb = pb_of(xb);
        xa = golden(
            (xa - ha * (ua1 - ua0)).max(ua0),
            (xa + ha * (ua1 - ua0)).min(ua1),
            |u| dist(pa_of(u), pb),
        );
        let pa = pa_of(xa);
        xb = golden(
            (xb - ha * (ub1 - ub0)).max(ub0),
            (xb + ha * (ub1 - ub0)).min(ub1),
            |u| dist(pa, pb_of(u)),
        );
    }
    let (pa, pb) = (pa_of(xa)?, pb_of(xb)?);
    let refined = (pa - pb).norm();
    let coarse = best.0.sqrt();
    if refined <= coarse {
        Some((refined, pa, pb))
    } else {
        Some((coarse, ea[best.1].2, eb[best.2].2))
    }
}

/// One channel: facing sides of two neighbouring main blades, with the splitter inside.
#[derive(Debug, Clone)]
pub struct Channel {
    /// Channel index k (between main blades k and k+1).
    pub index: usize,
    /// Main blade k (its +θ side bounds the channel).
    pub left: Blade,
    /// Main blade k+1 (its −θ side bounds the channel).
    pub right: Blade,
    /// Splitter k, when the impeller has splitters.
    pub splitter: Option<Blade>,
}

/// Polar angle where `side` meets `wall` at the wall's contour parameter `t`: the u of the
/// edge point whose meridional foot is `t` is found by bisection (60 steps; the foot moves
/// monotonically with u along the flow). `None` if the side's edge does not reach `t`.
pub fn edge_angle_at(blade: &Blade, side: Side, wall: &RevolvedSurface, t: f64) -> Option<f64> {
    let s = blade.side(side);
    let ((u0, u1), _) = s.domain();
    let foot = |u: f64| {
        // Option on purpose: the bisection asks where the edge exists.
        edge_v(blade, side, wall, u).ok().map(|v| {
            let p = s.point(u, v);
            (
                wall.meridional()
                    .closest(crate::meridional::MeridionalCurve::zr_of(&p))
                    .0,
                p,
            )
        })
    };
    let (ta, _) = foot(u0)?;
    let (tb, _) = foot(u1)?;
    let increasing = tb >= ta;
    if t < ta.min(tb) || t > ta.max(tb) {
        return None;
    }
    let (mut lo, mut hi) = (u0, u1);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let (tm, _) = foot(mid)?;
        if (tm < t) == increasing {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (_, p) = foot(0.5 * (lo + hi))?;
    Some(p.y.atan2(p.x))
}

/// Angular extent of a channel on hub or shroud at one contour parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelSection {
    /// Polar angle of the left bounding side (radians).
    pub left: f64,
    /// Polar angle of the right bounding side, unwrapped so that `right > left`.
    pub right: f64,
    /// Angles of the splitter's −θ and +θ sides (unwrapped after `left`), where the splitter
    /// reaches this contour parameter.
    pub splitter: Option<(f64, f64)>,
}

impl Channel {
    /// The channel's angular extent where it meets `wall` at contour parameter `t` (the floor
    /// between the blades on the hub, or the opening on the shroud); `None` where a bounding
    /// side does not reach `t`.
    ///
    /// # Errors
    /// [`ModelError::SectionOutOfReach`] (with `wall: None`) naming the bounding blade (left or
    /// right) whose side does not reach `t`. A splitter that does not reach `t` is no error
    /// (`splitter` is `None` then).
    pub fn section(&self, wall: &RevolvedSurface, t: f64) -> Result<ChannelSection, ModelError> {
        let miss = |bound: &'static str, side: Side| ModelError::SectionOutOfReach {
            channel: self.index,
            bound,
            side,
            wall: None,
            t,
        };
        let left = edge_angle_at(&self.left, self.left_side(), wall, t)
            .ok_or_else(|| miss("left", self.left_side()))?;
        let after = |phi: f64| left + (phi - left).rem_euclid(std::f64::consts::TAU);
        let right = after(
            edge_angle_at(&self.right, self.right_side(), wall, t)
                .ok_or_else(|| miss("right", self.right_side()))?,
        );
        let splitter = self.splitter.as_ref().and_then(|s| {
            let a = edge_angle_at(s, s.plus_theta_side().other(), wall, t)?;
            let b = edge_angle_at(s, s.plus_theta_side(), wall, t)?;
            Some((after(a), after(b)))
        });
        Ok(ChannelSection {
            left,
            right,
            splitter,
        })
    }

    /// The side of the left blade bounding the channel.
    pub fn left_side(&self) -> Side {
        self.left.plus_theta_side()
    }

    /// The side of the right blade bounding the channel.
    pub fn right_side(&self) -> Side {
        self.right.plus_theta_side().other()
    }
}

impl Impeller {
    /// Channel k (k taken modulo the main blade count).
    pub fn channel(&self, k: usize) -> Channel {
        let n = self.main().count();
        let k = k % n;
        Channel {
            index: k,
            left: self.main().instance(k),
            right: self.main().instance((k + 1) % n),
            splitter: self.splitter().map(|s| s.instance(k)),
        }
    }

    /// Side parameters (v_hub, v_shroud) of the isocurves that enclose the part of `side`
    /// between hub and shroud: the smallest v of its hub edge and the largest v of its shroud
    /// edge over 41 values of u. For imported blades (no design data) this is the v range a
    /// ruled approximation ([`crate::ruled`]) should span.
    ///
    /// # Errors
    /// [`ModelError::EdgeMissesWall`] (naming hub or shroud and the u) if an edge misses its
    /// wall at one of the 41 values of u; [`ModelError::SpanInverted`] if the hub edge does not
    /// lie below the shroud edge.
    pub fn span_v_range(&self, blade: &Blade, side: Side) -> Result<(f64, f64), ModelError> {
        let ((u0, u1), _) = blade.side(side).domain();
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for i in 0..=40 {
            let u = u0 + (u1 - u0) * i as f64 / 40.0;
            lo = lo.min(edge_v(blade, side, self.hub(), u).map_err(|e| e.on_wall(Wall::Hub))?);
            hi =
                hi.max(edge_v(blade, side, self.shroud(), u).map_err(|e| e.on_wall(Wall::Shroud))?);
        }
        if lo < hi {
            Ok((lo, hi))
        } else {
            Err(ModelError::SpanInverted {
                side,
                v_hub: lo,
                v_shroud: hi,
            })
        }
    }

    /// Smallest distance between facing blade sides along `wall` (mm); every channel is the
    /// same by N-fold symmetry, so channel 0 is measured.
    ///
    /// # Errors
    /// [`ModelError::EdgeEmpty`] (naming the side and `wall`) if a facing side's edge misses
    /// the wall entirely.
    pub fn min_channel_width(&self, wall: Wall) -> Result<f64, ModelError> {
        let w = wall_of(self, wall);
        let c = self.channel(0);
        let mut pairs: Vec<(&Blade, Side, &Blade, Side)> =
            vec![(&c.left, c.left_side(), &c.right, c.right_side())];
        if let Some(s) = &c.splitter {
            pairs.push((&c.left, c.left_side(), s, s.plus_theta_side().other()));
            pairs.push((s, s.plus_theta_side(), &c.right, c.right_side()));
        }
        let widths: Vec<Result<f64, ModelError>> = {
            use rayon::prelude::*;
            pairs
                .par_iter()
                .map(|&(a, sa, b, sb)| {
                    if let Some((d, _, _)) = min_edge_distance(a, sa, b, sb, w) {
                        return Ok(d);
                    }
                    // Name the side whose edge misses (min_edge_distance only says "none").
                    for (bl, s) in [(a, sa), (b, sb)] {
                        edge_curve(bl, s, w, 121).map_err(|e| e.on_wall(wall))?;
                    }
                    Err(ModelError::Geometry(format!(
                        "channel width on the {}: the refined closest edge points of the {sa:?} \
                         and {sb:?} sides left the edges",
                        if wall == Wall::Hub { "hub" } else { "shroud" }
                    )))
                })
                .collect()
        };
        widths
            .into_iter()
            .try_fold(f64::INFINITY, |acc, x| x.map(|x| acc.min(x)))
    }
}
