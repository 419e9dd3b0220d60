//! From raw export data to blade sides and flow-path contours in the workpiece frame, still as
//! points: the geometric decisions every importer shares.
//!
//! 1. **Sides.** Closed loops are split at their extreme meridional positions
//!    ([`split_loop`]); camber lines are offset by ± half the thickness ([`offset_camber`]);
//!    AutoGrid sides are taken as given.
//! 2. **Flow direction.** On the main blade's hub section the outlet is the end with the
//!    larger radius (centrifugal impellers, and compressor hubs, grow in radius along the
//!    flow); when both ends have radii within 0.1 % of the meridional chord, the end with the
//!    larger z in the file is the outlet. Every section is then ordered leading edge → trailing
//!    edge along that direction.
//! 3. **Pressure and suction.** Where the file does not say, each section's sides are first
//!    put in the same order (the side at larger mean θ first); then the suction side is the
//!    convex one: the camber line (mean θ of both sides) bulges away from its LE–TE chord in the
//!    (meridional fraction, θ) plane towards the suction side. The bulge is sampled at 25, 50
//!    and 75 % of the chord on every section and summed, weighted by its size.
//! 4. **Workpiece frame.** If the inlet lies at lower z than the outlet, the data are turned
//!    by π about the x axis ((x, y, z) → (x, −y, −z), a rotation, so no side changes hand);
//!    hub and shroud point lists are ordered from their inlet end and, on request, trimmed to
//!    the bladed part plus a margin; then z is shifted so the hub's outlet end (the back face
//!    of a centrifugal impeller) lies at z = 0 — except for data already in the workpiece
//!    frame (not turned, no hub point below z = 0), which keep their z.

use super::error::ImportError;
use super::raw::{
    blade_count, meridional, offset_camber, positive, split_loop, BladeRole, Polyline3,
    RawImpeller, SectionShape,
};
use nalgebra::{Vector2, Vector3};
use std::path::PathBuf;

/// Largest coordinate magnitude accepted, mm.
const MAX_COORD_MM: f64 = 1e9;

/// One blade section's two sides, each from leading to trailing edge, mm, workpiece frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionSides {
    /// Span fraction if the file gave one.
    pub span: Option<f64>,
    /// Pressure side points.
    pub pressure: Vec<Vector3<f64>>,
    /// Suction side points.
    pub suction: Vec<Vector3<f64>>,
}

/// A blade's sections from hub to shroud.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedBlade {
    /// Name in the file.
    pub name: String,
    /// Main blade or splitter.
    pub role: BladeRole,
    /// Number of copies around the axis.
    pub count: usize,
    /// Sections, hub first.
    pub sections: Vec<SectionSides>,
}

/// An export reduced to flow-path contours and blade sides in the workpiece frame (mm,
/// +Z from the hub's back end toward the inlet).
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedImpeller {
    /// The main file read.
    pub source: PathBuf,
    /// Hub meridional points (z, r), inlet end first.
    pub hub: Vec<Vector2<f64>>,
    /// Shroud meridional points (z, r), inlet end first.
    pub shroud: Vec<Vector2<f64>>,
    /// Main blade first, then splitters.
    pub blades: Vec<PreparedBlade>,
    /// Whether the data were turned by π about x (the file's inlet was at low z).
    pub flipped: bool,
    /// Shift added to z after the turn (puts the hub's outlet end at z = 0), mm.
    pub z_shift: f64,
}

impl PreparedImpeller {
    /// Number of main blades.
    pub fn main_blade_count(&self) -> usize {
        blade_count(
            self.blades.iter().map(|b| (b.role, b.count)),
            BladeRole::Main,
        )
    }

    /// Number of splitter blades.
    pub fn splitter_blade_count(&self) -> usize {
        blade_count(
            self.blades.iter().map(|b| (b.role, b.count)),
            BladeRole::Splitter,
        )
    }
}

/// Sides of one section before orientation: (first, second, labelled) where `labelled`
/// means the first is known to be the suction side.
type Pair = (Polyline3, Polyline3, bool);

/// Drops consecutive points closer than `eps` (repeated points break parametrisation).
fn dedup(points: Vec<Vector3<f64>>, eps: f64) -> Vec<Vector3<f64>> {
    let mut out: Vec<Vector3<f64>> = Vec::with_capacity(points.len());
    for p in points {
        if out.last().is_some_and(|q| (q - p).norm() <= eps) {
            continue;
        }
        out.push(p);
    }
    out
}

fn wrap_angle(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let mut x = a % t;
    if x > std::f64::consts::PI {
        x -= t;
    } else if x < -std::f64::consts::PI {
        x += t;
    }
    x
}

/// θ of `p` relative to `theta0`, in (−π, π].
fn rel_theta(p: &Vector3<f64>, theta0: f64) -> f64 {
    wrap_angle(p.y.atan2(p.x) - theta0)
}

/// Meridional chord fraction of `p` on the section chord `le → te`.
fn chord_fraction(p: &Vector3<f64>, le: &Vector2<f64>, d: &Vector2<f64>) -> f64 {
    (meridional(p) - le).dot(d) / d.norm_squared()
}

/// Relative θ of a side where it first crosses chord fraction `s0` (linear interpolation).
fn theta_at(
    side: &[Vector3<f64>],
    s0: f64,
    le: &Vector2<f64>,
    d: &Vector2<f64>,
    th0: f64,
) -> Option<f64> {
    for w in side.windows(2) {
        let (sa, sb) = (chord_fraction(&w[0], le, d), chord_fraction(&w[1], le, d));
        if (sa - s0) * (sb - s0) <= 0.0 && sa != sb {
            let t = (s0 - sa) / (sb - sa);
            let (ta, tb) = (rel_theta(&w[0], th0), rel_theta(&w[1], th0));
            return Some(ta + t * (tb - ta));
        }
    }
    None
}

/// Mean θ of side `a` minus mean θ of side `b` (both relative to `a`'s first point), from
/// their points at equal index fractions.
fn mean_theta_offset(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    let Some(p0) = a.first() else { return 0.0 };
    let th0 = p0.y.atan2(p0.x);
    let n = 32;
    (0..=n)
        .map(|k| {
            let f = k as f64 / n as f64;
            let pa = &a[((a.len() - 1) as f64 * f).round() as usize];
            let pb = &b[((b.len() - 1) as f64 * f).round() as usize];
            rel_theta(pa, th0) - rel_theta(pb, th0)
        })
        .sum()
}

/// Weighted vote that the first side of an oriented section is the suction (convex) side:
/// positive = first is suction.
fn convexity_vote(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    let (Some(a0), Some(a1), Some(b0), Some(b1)) = (a.first(), a.last(), b.first(), b.last())
    else {
        return 0.0;
    };
    let le_p = (a0 + b0) * 0.5;
    let te_p = (a1 + b1) * 0.5;
    let le = meridional(&le_p);
    let d = meridional(&te_p) - le;
    if !positive(d.norm_squared()) {
        return 0.0;
    }
    let th0 = le_p.y.atan2(le_p.x);
    let th_te = rel_theta(&te_p, th0);
    let mut vote = 0.0;
    for s0 in [0.25, 0.5, 0.75] {
        let (Some(ta), Some(tb)) = (theta_at(a, s0, &le, &d, th0), theta_at(b, s0, &le, &d, th0))
        else {
            continue;
        };
        let camber = 0.5 * (ta + tb);
        let bulge = camber - s0 * th_te;
        // The first side is convex (suction) when it lies on the bulge's side of the camber.
        vote += bulge * (ta - camber);
    }
    vote
}

/// Cumulative arc length of a polyline.
fn arc_lengths(wall: &[Vector2<f64>]) -> Vec<f64> {
    let mut s = vec![0.0; wall.len()];
    for k in 1..wall.len() {
        s[k] = s[k - 1] + (wall[k] - wall[k - 1]).norm();
    }
    s
}

/// Arc length of the point of `wall` closest to `q`.
fn project_arc(wall: &[Vector2<f64>], s: &[f64], q: &Vector2<f64>) -> f64 {
    let mut best = (f64::INFINITY, 0.0);
    for k in 1..wall.len() {
        let (a, b) = (wall[k - 1], wall[k]);
        let d = b - a;
        let t = ((q - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        let dist = (a + d * t - q).norm();
        if dist < best.0 {
            best = (dist, s[k - 1] + t * (s[k] - s[k - 1]));
        }
    }
    best.1
}

/// Point of `wall` at arc length `at` (linear between points).
fn point_at_arc(wall: &[Vector2<f64>], s: &[f64], at: f64) -> Vector2<f64> {
    let k = s.partition_point(|&x| x < at).clamp(1, wall.len() - 1);
    let t = ((at - s[k - 1]) / (s[k] - s[k - 1])).clamp(0.0, 1.0);
    wall[k - 1] + (wall[k] - wall[k - 1]) * t
}

/// Keeps the part of a contour polyline between the blade edges projected on it, widened on
/// both sides by `margin` × the bladed arc length (clipped to the contour's own ends). The new
/// end points are interpolated on the polyline.
fn trim_contour(wall: &[Vector2<f64>], edges: &[Vector2<f64>], margin: f64) -> Vec<Vector2<f64>> {
    let s = arc_lengths(wall);
    let total = s[s.len() - 1];
    let proj: Vec<f64> = edges.iter().map(|q| project_arc(wall, &s, q)).collect();
    let lo = proj.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = proj.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return wall.to_vec();
    }
    let a = (lo - margin * (hi - lo)).max(0.0);
    let b = (hi + margin * (hi - lo)).min(total);
    let mut out = vec![point_at_arc(wall, &s, a)];
    out.extend(
        wall.iter()
            .zip(&s)
            .filter(|(_, &x)| x > a && x < b)
            .map(|(p, _)| *p),
    );
    out.push(point_at_arc(wall, &s, b));
    out
}

/// Reduces raw export data to sides and contours in the workpiece frame (see the module
/// docs for the rules). With `trim_margin = Some(f)` the hub and shroud contours are cut to
/// the bladed part widened by f × its meridional length on each side (inlet ducts and
/// vaneless diffusers are not part of the machined impeller); `None` keeps them whole.
/// Errors name the blade and section that cannot be split or oriented.
pub fn prepare(
    raw: &RawImpeller,
    trim_margin: Option<f64>,
) -> Result<PreparedImpeller, ImportError> {
    let geom_err = |entity: String, reason: &str| ImportError::Geometry {
        file: raw.source.clone(),
        entity,
        reason: reason.to_string(),
    };
    // Coordinates beyond 10⁹ mm are corrupt data, not an impeller; rejecting them keeps
    // every later computation finite.
    let sane = |v: f64| v.is_finite() && v.abs() <= MAX_COORD_MM;
    if let Some(p) = raw
        .hub
        .iter()
        .chain(&raw.shroud)
        .find(|p| !(sane(p.x) && sane(p.y)))
    {
        return Err(geom_err(
            "hub/shroud".into(),
            &format!("coordinate {p:?} mm is not finite or beyond 1e9 mm"),
        ));
    }
    for b in &raw.blades {
        for s in &b.sections {
            let pts: Vec<&Vector3<f64>> = match &s.shape {
                SectionShape::Loop(p) => p.iter().collect(),
                SectionShape::Sides { suction, pressure } => {
                    suction.iter().chain(pressure).collect()
                }
                SectionShape::Camber {
                    points, thickness, ..
                } => {
                    if thickness.iter().any(|&t| !sane(t)) {
                        return Err(geom_err(
                            format!("blade {:?} section at line {}", b.name, s.line),
                            "thickness is not finite or beyond 1e9 mm",
                        ));
                    }
                    points.iter().collect()
                }
            };
            if pts.iter().any(|p| !p.iter().all(|&v| sane(v))) {
                return Err(geom_err(
                    format!("blade {:?} section at line {}", b.name, s.line),
                    "a coordinate is not finite or beyond 1e9 mm",
                ));
            }
        }
    }
    // Length scale for "same point" tests: 1e-9 of the flow path's size.
    let size = raw
        .hub
        .iter()
        .chain(&raw.shroud)
        .map(|p| p.norm())
        .fold(0.0f64, f64::max)
        .max(1.0);
    let eps = 1e-9 * size;
    // 1. Sides.
    let mut blades_pairs: Vec<Vec<(Option<f64>, Pair)>> = Vec::new();
    for b in &raw.blades {
        let mut secs = Vec::new();
        for (k, s) in b.sections.iter().enumerate() {
            let entity = || format!("blade {:?} section {} (line {})", b.name, k + 1, s.line);
            let pair: Pair = match &s.shape {
                SectionShape::Loop(pts) => {
                    let (a, c) = split_loop(pts, eps).ok_or_else(|| {
                        geom_err(
                            entity(),
                            "the loop has fewer than 4 distinct points or no meridional extent",
                        )
                    })?;
                    (a, c, false)
                }
                SectionShape::Sides { suction, pressure } => {
                    (suction.clone(), pressure.clone(), true)
                }
                SectionShape::Camber {
                    points,
                    thickness,
                    kind,
                } => {
                    let (a, c) = offset_camber(points, thickness, *kind).ok_or_else(|| {
                        geom_err(
                            entity(),
                            "the camber line touches the axis or runs along the circumference",
                        )
                    })?;
                    (a, c, false)
                }
            };
            let (a, c, lab) = pair;
            let (a, c) = (dedup(a, eps), dedup(c, eps));
            if a.len() < 2 || c.len() < 2 {
                return Err(geom_err(
                    entity(),
                    "a side has fewer than 2 distinct points",
                ));
            }
            secs.push((s.span, (a, c, lab)));
        }
        if secs.len() < 2 {
            return Err(geom_err(
                format!("blade {:?}", b.name),
                "fewer than 2 sections",
            ));
        }
        blades_pairs.push(secs);
    }
    // 2. Flow direction from the main blade's hub section.
    let Some(((_, (a, _, _)), main)) = blades_pairs
        .first()
        .and_then(|secs| secs.first())
        .zip(raw.blades.first())
    else {
        return Err(geom_err("blades".into(), "the export holds no blade"));
    };
    let (start, end) = (meridional(&a[0]), meridional(&a[a.len() - 1]));
    let chord = (end - start).norm();
    if !positive(chord - eps) {
        return Err(geom_err(
            format!("blade {:?} hub section", main.name),
            "leading and trailing edges coincide",
        ));
    }
    let (inlet, outlet) = if (end.y - start.y).abs() > 1e-3 * chord {
        if end.y > start.y {
            (start, end)
        } else {
            (end, start)
        }
    } else if end.x >= start.x {
        (start, end)
    } else {
        (end, start)
    };
    let flow = outlet - inlet;
    let flip = inlet.x < outlet.x;
    // 3. Orientation and labels.
    let mut blades = Vec::new();
    for (b, secs) in raw.blades.iter().zip(blades_pairs) {
        let mut oriented: Vec<(Option<f64>, Polyline3, Polyline3, bool)> = Vec::new();
        for (span, (mut a, mut c, lab)) in secs {
            let along = (meridional(&a[a.len() - 1]) - meridional(&a[0])).dot(&flow);
            if along < 0.0 {
                a.reverse();
            }
            let along = (meridional(&c[c.len() - 1]) - meridional(&c[0])).dot(&flow);
            if along < 0.0 {
                c.reverse();
            }
            // Unlabelled sides: make the first one the +θ side of its section, so the
            // convexity vote below compares like with like across sections.
            if !lab && mean_theta_offset(&a, &c) < 0.0 {
                std::mem::swap(&mut a, &mut c);
            }
            oriented.push((span, a, c, lab));
        }
        let first_is_suction = if oriented.iter().all(|o| o.3) {
            true
        } else {
            let vote: f64 = oriented
                .iter()
                .map(|(_, a, c, _)| convexity_vote(a, c))
                .sum();
            vote >= 0.0
        };
        let turn = |p: Vector3<f64>| {
            if flip {
                Vector3::new(p.x, -p.y, -p.z)
            } else {
                p
            }
        };
        let sections = oriented
            .into_iter()
            .map(|(span, a, c, _)| {
                let (suction, pressure) = if first_is_suction { (a, c) } else { (c, a) };
                SectionSides {
                    span,
                    pressure: pressure.into_iter().map(turn).collect(),
                    suction: suction.into_iter().map(turn).collect(),
                }
            })
            .collect();
        blades.push(PreparedBlade {
            name: b.name.clone(),
            role: b.role,
            count: b.count,
            sections,
        });
    }
    // 4. Frame: turn the contours, order them from the inlet, trim, shift z.
    let turn2 = |p: &Vector2<f64>| if flip { Vector2::new(-p.x, p.y) } else { *p };
    let mut hub: Vec<Vector2<f64>> = raw.hub.iter().map(turn2).collect();
    let mut shroud: Vec<Vector2<f64>> = raw.shroud.iter().map(turn2).collect();
    let inlet_wp = turn2(&inlet);
    for (wall, name) in [(&mut hub, "hub"), (&mut shroud, "shroud")] {
        let d_first = (wall[0] - inlet_wp).norm();
        let d_last = (wall[wall.len() - 1] - inlet_wp).norm();
        if d_last < d_first {
            wall.reverse();
        }
        let pts: Vec<Vector2<f64>> = std::mem::take(wall);
        for p in pts {
            if wall
                .last()
                .is_some_and(|q: &Vector2<f64>| (q - p).norm() <= eps)
            {
                continue;
            }
            wall.push(p);
        }
        if wall.len() < 2 {
            return Err(geom_err(name.into(), "fewer than 2 distinct points"));
        }
    }
    if let Some(margin) = trim_margin {
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(geom_err(
                "trim margin".into(),
                "must be a finite fraction >= 0",
            ));
        }
        for (wall, first_section) in [(&mut hub, true), (&mut shroud, false)] {
            let edges: Vec<Vector2<f64>> = blades
                .iter()
                .filter_map(|b| {
                    if first_section {
                        b.sections.first()
                    } else {
                        b.sections.last()
                    }
                })
                .flat_map(|s| {
                    [
                        meridional(&s.pressure[0]),
                        meridional(&s.pressure[s.pressure.len() - 1]),
                    ]
                })
                .collect();
            *wall = trim_contour(wall, &edges, margin);
        }
    }
    // The hub's outlet end marks the back face (robust to fitted contours that overshoot),
    // unless the data are already in the workpiece frame: inlet toward +Z and no hub point
    // below z = 0 (our own exports, parametric designs with a disk below the hub).
    let Some(z_end) = hub.last().map(|p| p.x) else {
        return Err(geom_err("hub".into(), "no points"));
    };
    let in_frame = !flip && hub.iter().all(|p| p.x >= -eps);
    let z_shift = if in_frame { 0.0 } else { -z_end };
    for p in hub.iter_mut().chain(shroud.iter_mut()) {
        p.x += z_shift;
    }
    for b in &mut blades {
        for s in &mut b.sections {
            for p in s.pressure.iter_mut().chain(s.suction.iter_mut()) {
                p.z += z_shift;
            }
        }
    }
    Ok(PreparedImpeller {
        source: raw.source.clone(),
        hub,
        shroud,
        blades,
        flipped: flip,
        z_shift,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_angle_range() {
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-15);
    }
}
