//! Raw imported geometry: the point data of a blade-design export, converted to millimetres
//! and to a frame whose rotation axis is +Z, before any fitting.
//!
//! Coordinates stay in the file's own axial sense here (the design tools usually put the
//! inlet at low z); the model builder moves them into the workpiece frame.

use nalgebra::{Vector2, Vector3};
use std::path::PathBuf;

/// A length unit of an export file, with its size in millimetres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LengthUnit {
    /// Millimetres (`MM`).
    Millimetre,
    /// Centimetres (`CM`).
    Centimetre,
    /// Metres (`M`).
    Metre,
    /// Inches (`IN`, `INCH`).
    Inch,
    /// Feet (`FT`).
    Foot,
    /// Micrometres (`UM`, `MICRON`).
    Micrometre,
    /// Any other unit, given by its size in millimetres (AutoGrid's `units` factor).
    Scale(f64),
}

impl LengthUnit {
    /// Size of one unit in millimetres.
    pub fn mm(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1.0,
            LengthUnit::Centimetre => 10.0,
            LengthUnit::Metre => 1000.0,
            LengthUnit::Inch => 25.4,
            LengthUnit::Foot => 304.8,
            LengthUnit::Micrometre => 1e-3,
            LengthUnit::Scale(s) => s,
        }
    }

    /// Parses a unit name as TurboGrid writes it (`MM`, `CM`, `M`, `IN`, `FT`, `UM`; case
    /// insensitive, long forms accepted).
    pub fn from_name(name: &str) -> Option<Self> {
        match name.trim().to_ascii_uppercase().as_str() {
            "MM" | "MILLIMETER" | "MILLIMETRE" | "MILLIMETERS" | "MILLIMETRES" => {
                Some(Self::Millimetre)
            }
            "CM" | "CENTIMETER" | "CENTIMETRE" | "CENTIMETERS" | "CENTIMETRES" => {
                Some(Self::Centimetre)
            }
            "M" | "METER" | "METRE" | "METERS" | "METRES" => Some(Self::Metre),
            "IN" | "INCH" | "INCHES" => Some(Self::Inch),
            "FT" | "FOOT" | "FEET" => Some(Self::Foot),
            "UM" | "MICRON" | "MICRONS" | "MICROMETER" | "MICROMETRE" => Some(Self::Micrometre),
            _ => None,
        }
    }
}

/// Which design tool's format the data came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceFormat {
    /// TurboGrid curve set (`.inf` + hub, shroud and profile curve files).
    TurboGrid,
    /// NUMECA AutoGrid `.geomTurbo`.
    GeomTurbo,
    /// BladeGen meanline `rtzt` file.
    Rtzt,
    /// A folder of section tables (hub and shroud `x r`, blade sections `X R·θ R`).
    SectionTables,
}

/// Main blade or splitter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BladeRole {
    /// A full-length blade.
    Main,
    /// A splitter (part-length) blade between two main blades.
    Splitter,
}

/// How an `rtzt` thickness is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ThicknessKind {
    /// Normal to the camber line within the blade-to-blade stream surface.
    Normal,
    /// Along the circumference (Δθ·r).
    Tangential,
}

/// The points of one blade section (one span), in mm.
#[derive(Debug, Clone, PartialEq)]
pub enum SectionShape {
    /// A closed loop around the section (TurboGrid profiles); the first point may repeat as
    /// the last.
    Loop(Vec<Vector3<f64>>),
    /// Suction and pressure sides, each from leading to trailing edge (AutoGrid).
    Sides {
        /// Suction side points.
        suction: Vec<Vector3<f64>>,
        /// Pressure side points.
        pressure: Vec<Vector3<f64>>,
    },
    /// A camber (mean) line with the blade thickness at each point (BladeGen `rtzt`).
    Camber {
        /// Camber line points.
        points: Vec<Vector3<f64>>,
        /// Blade thickness at each point, mm.
        thickness: Vec<f64>,
        /// How the thickness is measured.
        kind: ThicknessKind,
    },
}

/// One blade section as read.
#[derive(Debug, Clone, PartialEq)]
pub struct RawSection {
    /// Line of the file where the section starts (for messages).
    pub line: usize,
    /// Span fraction (0 hub … 1 shroud) when the file states it.
    pub span: Option<f64>,
    /// The section's points.
    pub shape: SectionShape,
}

/// One blade (a main blade or a splitter) as read: its sections from hub to shroud.
#[derive(Debug, Clone, PartialEq)]
pub struct RawBlade {
    /// Name in the file (`main blade`, `splitter 1`, `blade 0`, ...).
    pub name: String,
    /// Main blade or splitter.
    pub role: BladeRole,
    /// Number of copies around the axis.
    pub count: usize,
    /// Sections ordered from hub to shroud.
    pub sections: Vec<RawSection>,
}

/// Everything an importer read from a blade-design export, in mm, rotation axis +Z.
#[derive(Debug, Clone, PartialEq)]
pub struct RawImpeller {
    /// The format read.
    pub format: SourceFormat,
    /// The main file (`.inf`, `.geomTurbo`, `.rtzt`).
    pub source: PathBuf,
    /// Hub meridional points (z, r), mm, in file order.
    pub hub: Vec<Vector2<f64>>,
    /// Shroud meridional points (z, r), mm, in file order.
    pub shroud: Vec<Vector2<f64>>,
    /// Main blade first, then splitters.
    pub blades: Vec<RawBlade>,
}

/// Total blade count of the rows with `role`, from `(role, count)` pairs.
pub(crate) fn blade_count(
    rows: impl Iterator<Item = (BladeRole, usize)>,
    role: BladeRole,
) -> usize {
    rows.filter(|(r, _)| *r == role).map(|(_, n)| n).sum()
}

impl RawImpeller {
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

/// A polyline of 3D points, mm.
pub type Polyline3 = Vec<Vector3<f64>>;

/// Two blade sides as point lists.
pub type SidePair = (Polyline3, Polyline3);

/// Whether `x` is a number greater than zero (false for NaN).
pub(crate) fn positive(x: f64) -> bool {
    x > 0.0
}

/// Meridional coordinates (z, r) of a point (rotation axis +Z).
pub fn meridional(p: &Vector3<f64>) -> Vector2<f64> {
    Vector2::new(p.z, p.x.hypot(p.y))
}

/// Converts cylindrical (r, θ, z) to cartesian (x, y, z).
pub fn from_cylindrical(r: f64, theta: f64, z: f64) -> Vector3<f64> {
    Vector3::new(r * theta.cos(), r * theta.sin(), z)
}

/// Splits a closed section loop into its two sides at the leading and trailing edges.
///
/// The edges are the two loop points farthest apart in the meridional (z, r) half-plane —
/// the extreme meridional positions of the section (O(n²) in the loop size, n ≈ 300).
/// Points closer than `eps` to their predecessor are merged, and the closing point is
/// dropped. Where the file marks an edge — the loop's first point (BladeGen starts loops at
/// the leading edge) or a point written twice in a row (our exporter repeats each edge
/// point) — within 2 % of the meridional chord of an extreme, the split is moved to that
/// mark, so the sides end where the writer put the edges; two adjacent marks at one edge are
/// the corners of a blunt edge face, which then belongs to neither side. Both returned sides
/// run from the
/// first edge (lower loop index) to the other; callers orient and label them. At a blunt edge
/// (one side leaves the extreme point across a flat edge face — under 25 % of the step along
/// the meridional chord, then a turn of more than 60° — while the other runs along the blade,
/// over 50 %) the face is left out of the side that crosses it. Returns `None` when the loop
/// has fewer than 4 distinct points or its meridional extent is zero.
pub fn split_loop(points: &[Vector3<f64>], eps: f64) -> Option<SidePair> {
    // Merge repeated points, remembering the marks (first point, repeated points).
    let mut pts: Vec<Vector3<f64>> = Vec::with_capacity(points.len());
    let mut marked: Vec<bool> = Vec::with_capacity(points.len());
    for p in points {
        match pts.last() {
            Some(q) if (q - p).norm() <= eps => {
                if let Some(m) = marked.last_mut() {
                    *m = true;
                }
            }
            _ => {
                marked.push(pts.is_empty());
                pts.push(*p);
            }
        }
    }
    while pts.len() > 1 {
        let (first, last) = (pts[0], pts[pts.len() - 1]);
        if (first - last).norm() <= eps {
            pts.pop();
            marked.pop();
        } else {
            break;
        }
    }
    let n = pts.len();
    if n < 4 {
        return None;
    }
    let m: Vec<Vector2<f64>> = pts.iter().map(meridional).collect();
    let (mut bi, mut bj, mut best) = (0usize, 0usize, 0.0f64);
    for i in 0..n {
        for j in (i + 1)..n {
            let d = (m[i] - m[j]).norm_squared();
            if d > best {
                best = d;
                bi = i;
                bj = j;
            }
        }
    }
    if !positive(best) {
        return None;
    }
    // Snap each extreme to the nearest mark within 2 % of the chord (along the chord).
    let chord = best.sqrt();
    let dir = (m[bj] - m[bi]) / chord;
    let snap = |e: usize, other: usize| -> usize {
        let s_e = m[e].dot(&dir);
        (0..n)
            .filter(|&k| marked[k] && k != other && (m[k].dot(&dir) - s_e).abs() <= 0.02 * chord)
            .min_by(|&a, &b| (m[a] - m[e]).norm().total_cmp(&(m[b] - m[e]).norm()))
            .unwrap_or(e)
    };
    let si = snap(bi, bj);
    let sj = snap(bj, si);
    let (bi, bj) = if si < sj { (si, sj) } else { (sj, si) };
    let mut side_a: Vec<Vector3<f64>> = pts[bi..=bj].to_vec();
    // The other way round the loop: bi backwards (wrapping) to bj.
    let mut side_b = Vec::with_capacity(n - (bj - bi) + 1);
    let mut k = bi;
    loop {
        side_b.push(pts[k]);
        if k == bj {
            break;
        }
        k = if k == 0 { n - 1 } else { k - 1 };
    }
    // Marked edge faces: two adjacent marked points at the same edge are the corners of a
    // blunt edge face (our exporter writes both corners twice); the face belongs to neither
    // side, so the side that would cross it starts or ends at its own corner.
    let near = |k: usize, e: usize| (m[k].dot(&dir) - m[e].dot(&dir)).abs() <= 0.02 * chord;
    let face_at = |k: usize, e: usize| marked[k] && marked[e] && near(k, e);
    let (next, prev) = (|k: usize| (k + 1) % n, |k: usize| (k + n - 1) % n);
    let mut handled = [false, false]; // [start, end]
    if side_a.len() > 2 && face_at(next(bi), bi) {
        side_a.remove(0);
        handled[0] = true;
    } else if side_b.len() > 2 && face_at(prev(bi), bi) {
        side_b.remove(0);
        handled[0] = true;
    }
    if side_a.len() > 2 && face_at(prev(bj), bj) {
        side_a.pop();
        handled[1] = true;
    } else if side_b.len() > 2 && face_at(next(bj), bj) {
        side_b.pop();
        handled[1] = true;
    }
    // Blunt edges: where one side leaves the edge point across a flat edge face (a step with
    // little progress along the chord, followed by a sharp turn of more than 60° into the
    // side) while the other runs along the blade, the face is not part of that side: it
    // starts (or ends) at its own corner instead. A sampled round nose turns gradually and
    // is kept.
    let d = (m[bj] - m[bi]).normalize();
    let progress = |p: &Vector3<f64>, q: &Vector3<f64>| {
        let step = (q - p).norm();
        if step > 0.0 {
            ((meridional(q) - meridional(p)).dot(&d)).abs() / step
        } else {
            1.0
        }
    };
    // Cosine of the turn at q between the steps p→q and q→r.
    let turn_cos = |p: &Vector3<f64>, q: &Vector3<f64>, r: &Vector3<f64>| {
        let (u, v) = (q - p, r - q);
        let den = u.norm() * v.norm();
        if den > 0.0 {
            u.dot(&v) / den
        } else {
            1.0
        }
    };
    for (at_start, done) in [(true, handled[0]), (false, handled[1])] {
        if done {
            continue;
        }
        // (first-step progress, turn cosine at the second point) of a side's end.
        let ends = |s: &[Vector3<f64>]| -> (f64, f64) {
            if s.len() < 3 {
                return (1.0, 1.0);
            }
            let n = s.len();
            if at_start {
                (progress(&s[0], &s[1]), turn_cos(&s[0], &s[1], &s[2]))
            } else {
                (
                    progress(&s[n - 2], &s[n - 1]),
                    turn_cos(&s[n - 3], &s[n - 2], &s[n - 1]),
                )
            }
        };
        let face = |(f, c): (f64, f64)| f < 0.25 && c < 0.5;
        let along = |(f, _): (f64, f64)| f > 0.5;
        let (ea, eb) = (ends(&side_a), ends(&side_b));
        let target = if face(ea) && along(eb) {
            Some(&mut side_a)
        } else if face(eb) && along(ea) {
            Some(&mut side_b)
        } else {
            None
        };
        if let Some(side) = target {
            if at_start {
                side.remove(0);
            } else {
                side.pop();
            }
        }
    }
    Some((side_a, side_b))
}

/// Offsets a camber line by ± half the thickness into two blade sides.
///
/// Tangential thickness t moves each point along its circle by Δθ = ±t/(2r). Normal
/// thickness moves it by ±t/2 along the unit vector of the stream surface that is normal to
/// the camber line: the circumferential direction e_θ with its component along the camber
/// tangent T removed, n = (e_θ − (e_θ·T̂)T̂)/|…| (T̂ by central differences). Both sides run
/// in the camber's order; the first is the +θ side. Returns `None` for fewer than 2 points, a
/// point on the axis, or a camber tangent along e_θ (a degenerate section).
pub fn offset_camber(
    points: &[Vector3<f64>],
    thickness: &[f64],
    kind: ThicknessKind,
) -> Option<SidePair> {
    let n = points.len();
    if n < 2 || thickness.len() != n {
        return None;
    }
    let mut plus = Vec::with_capacity(n);
    let mut minus = Vec::with_capacity(n);
    for i in 0..n {
        let p = points[i];
        let r = p.x.hypot(p.y);
        if !positive(r) {
            return None;
        }
        let half = 0.5 * thickness[i];
        let theta = p.y.atan2(p.x);
        match kind {
            ThicknessKind::Tangential => {
                let dt = half / r;
                plus.push(from_cylindrical(r, theta + dt, p.z));
                minus.push(from_cylindrical(r, theta - dt, p.z));
            }
            ThicknessKind::Normal => {
                let (a, b) = (points[i.saturating_sub(1)], points[(i + 1).min(n - 1)]);
                let t = (b - a).try_normalize(0.0)?;
                let e_theta = Vector3::new(-theta.sin(), theta.cos(), 0.0);
                let nrm = (e_theta - t * e_theta.dot(&t)).try_normalize(1e-12)?;
                plus.push(p + nrm * half);
                minus.push(p - nrm * half);
            }
        }
    }
    Some((plus, minus))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_loop_finds_edges() {
        // A thin lens in the (z, θ) plane at r = 10: z from 0 to 4.
        let mut pts = Vec::new();
        for k in 0..=8 {
            let z = 0.5 * k as f64;
            pts.push(from_cylindrical(10.0, 0.01 * (z * (4.0 - z)), z));
        }
        for k in (1..8).rev() {
            let z = 0.5 * k as f64;
            pts.push(from_cylindrical(10.0, -0.01 * (z * (4.0 - z)), z));
        }
        pts.push(pts[0]);
        let (a, b) = split_loop(&pts, 1e-12).unwrap();
        assert_eq!(a.len(), 9);
        assert_eq!(b.len(), 9);
        assert!((a[0].z).abs() < 1e-12 && (b[0].z).abs() < 1e-12);
        assert!((a[8].z - 4.0).abs() < 1e-12 && (b[8].z - 4.0).abs() < 1e-12);
    }

    #[test]
    fn marked_blunt_face_belongs_to_neither_side() {
        // Pressure side at θ = +0.01, suction at −0.01 (r = 10), LE shared, blunt TE whose
        // corners are both written twice (the exporter's convention).
        let side = |sign: f64| -> Vec<Vector3<f64>> {
            (0..=8)
                .map(|k| from_cylindrical(10.0, sign * 0.01, 0.5 * k as f64))
                .collect()
        };
        let (p, s) = (side(1.0), side(-1.0));
        let mut pts = vec![p[0]];
        pts.extend(&p[1..]);
        pts.push(p[8]);
        pts.push(s[8]);
        pts.extend(s[1..].iter().rev());
        pts.push(p[0]);
        let (a, b) = split_loop(&pts, 1e-12).unwrap();
        assert_eq!((a.len(), b.len()), (9, 9));
        assert!((a[8] - p[8]).norm() < 1e-12 || (a[8] - s[8]).norm() < 1e-12);
        assert!(
            (a[8] - b[8]).norm() > 0.1,
            "each side ends at its own corner"
        );
    }

    #[test]
    fn tangential_offset_is_exact() {
        let pts = vec![
            from_cylindrical(50.0, 0.1, 0.0),
            from_cylindrical(60.0, 0.2, 5.0),
        ];
        let (p, m) = offset_camber(&pts, &[2.0, 1.0], ThicknessKind::Tangential).unwrap();
        assert!((p[0].y.atan2(p[0].x) - (0.1 + 1.0 / 50.0)).abs() < 1e-12);
        assert!((m[1].y.atan2(m[1].x) - (0.2 - 0.5 / 60.0)).abs() < 1e-12);
        let (p, m) = offset_camber(&pts, &[2.0, 1.0], ThicknessKind::Normal).unwrap();
        assert!(((p[0] - m[0]).norm() - 2.0).abs() < 1e-12);
    }
}
