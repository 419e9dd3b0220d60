//! BladeGen meanline files (`rtzt`), as documented in the BladeGen user guide ("Meanline Data
//! File Format"): whitespace-separated values, angles in radians, no length unit in the file
//! (the caller states it).
//!
//! ```text
//! {number of blades}
//! {number of splitters}              0 = main blade only
//! for each blade (main, then splitters):
//!   {pitch fraction}                 ignored for the main blade
//!   {number of layers}
//!   [N | T]                          normal / tangential thickness (default N)
//!   for each layer (hub to shroud):
//!     {span fraction} {number of points} [a][t][b]
//!     for each point: {r} {theta} {z} {thickness}
//! ```
//!
//! Each layer is a camber line with its thickness. Points of zero thickness before the first
//! and after the last non-zero one describe the flow path beyond the blade: the hub and
//! shroud contours are the meridional traces of the main blade's first and last layers (all
//! points), and each blade section keeps only its points of non-zero thickness. Splitter θ values are taken as absolute (the pitch fraction is
//! kept for information only). Splitter count = blade count × splitters per blade.

use super::error::ImportError;
use super::raw::{
    from_cylindrical, meridional, BladeRole, LengthUnit, RawBlade, RawImpeller, RawSection,
    SectionShape, SourceFormat, ThicknessKind,
};
use super::text::{tokens, LineReader};
use nalgebra::Vector2;
use std::path::Path;

/// Parses an `rtzt` file held in memory; lengths are in `unit`.
pub fn parse_rtzt(file: &Path, bytes: &[u8], unit: LengthUnit) -> Result<RawImpeller, ImportError> {
    let mut r = LineReader::new(file, bytes);
    let s = unit.mm();
    let (no, text) = r.expect_nonblank("the number of blades")?;
    let n_blades = r.count(no, text, "number of blades")?;
    if n_blades == 0 {
        return Err(r.invalid(no, "number of blades", "must be at least 1"));
    }
    let (no, text) = r.expect_nonblank("the number of splitters")?;
    let n_splitters = r.count(no, text, "number of splitters")?;
    let mut blades = Vec::new();
    let mut hub: Vec<Vector2<f64>> = Vec::new();
    let mut shroud: Vec<Vector2<f64>> = Vec::new();
    for b in 0..=n_splitters {
        let label = if b == 0 {
            "main blade".to_string()
        } else {
            format!("splitter {b}")
        };
        let (no, text) = r.expect_nonblank(&format!("the pitch fraction of the {label}"))?;
        let pitch = r.number(no, text, "pitch fraction")?;
        if b > 0 && !(0.0..=1.0).contains(&pitch) {
            return Err(r.invalid(no, "pitch fraction", format!("{pitch} is not within 0–1")));
        }
        let (no, text) = r.expect_nonblank(&format!("the number of layers of the {label}"))?;
        let n_layers = r.count(no, text, "number of layers")?;
        if n_layers < 2 {
            return Err(r.invalid(
                no,
                "number of layers",
                format!("at least 2 required, found {n_layers}"),
            ));
        }
        let mut kind = ThicknessKind::Normal;
        if let Some(peek) = r.peek_nonblank() {
            let (_, text) = peek?;
            let t = text.trim();
            if t.eq_ignore_ascii_case("N") || t.eq_ignore_ascii_case("T") {
                kind = if t.eq_ignore_ascii_case("T") {
                    ThicknessKind::Tangential
                } else {
                    ThicknessKind::Normal
                };
                r.next_nonblank();
            }
        }
        let mut sections = Vec::new();
        let mut last_span = f64::NEG_INFINITY;
        for l in 0..n_layers {
            let what = format!(
                "layer {} of {n_layers} of the {label}: span fraction, number of points [a|t|b]",
                l + 1
            );
            let (no, text) = r.expect_nonblank(&what)?;
            let toks: Vec<&str> = tokens(text).collect();
            if toks.len() < 2 || toks.len() > 3 {
                return Err(r.syntax(no, what, text));
            }
            let span = r.number(no, toks[0], "span fraction")?;
            if !(0.0..=1.0).contains(&span) {
                return Err(r.invalid(no, "span fraction", format!("{span} is not within 0–1")));
            }
            if span <= last_span {
                return Err(r.invalid(
                    no,
                    "span fraction",
                    "layers must go from hub to shroud with increasing span",
                ));
            }
            last_span = span;
            let n_pts = r.count(no, toks[1], "number of points")?;
            if n_pts < 2 {
                return Err(r.invalid(
                    no,
                    "number of points",
                    format!("at least 2 required, found {n_pts}"),
                ));
            }
            if let Some(flag) = toks.get(2) {
                if !flag
                    .chars()
                    .all(|c| matches!(c.to_ascii_lowercase(), 'a' | 't' | 'b'))
                {
                    return Err(r.syntax(no, "layer usage flags a, t, b", text));
                }
            }
            let mut pts = Vec::new();
            let mut thick = Vec::new();
            for k in 0..n_pts {
                let (pno, ptext) = r.expect_nonblank(&format!(
                    "point {} of {n_pts} (r theta z thickness)",
                    k + 1
                ))?;
                let [rr, th, z, t] = r.numbers::<4>(pno, ptext, "r theta z thickness")?;
                if rr < 0.0 {
                    return Err(r.invalid(pno, "r", format!("{rr} is negative")));
                }
                if t < 0.0 {
                    return Err(r.invalid(pno, "thickness", format!("{t} is negative")));
                }
                pts.push(from_cylindrical(rr * s, th, z * s));
                thick.push(t * s);
            }
            if b == 0 && l == 0 {
                hub = pts.iter().map(meridional).collect();
            }
            if b == 0 && l + 1 == n_layers {
                shroud = pts.iter().map(meridional).collect();
            }
            // Keep the bladed part: the points from the first to the last non-zero thickness.
            let Some(first_nz) = thick.iter().position(|&t| t > 0.0) else {
                return Err(r.invalid(
                    no,
                    "thickness",
                    format!(
                        "layer {} of the {label} has zero thickness everywhere",
                        l + 1
                    ),
                ));
            };
            let last_nz = thick.iter().rposition(|&t| t > 0.0).unwrap_or(first_nz);
            let (lo, hi) = (first_nz, last_nz);
            if hi - lo < 1 {
                return Err(r.invalid(
                    no,
                    "thickness",
                    format!(
                        "layer {} of the {label} has fewer than 2 points of non-zero thickness",
                        l + 1
                    ),
                ));
            }
            sections.push(RawSection {
                line: no,
                span: Some(span),
                shape: SectionShape::Camber {
                    points: pts[lo..=hi].to_vec(),
                    thickness: thick[lo..=hi].to_vec(),
                    kind,
                },
            });
        }
        blades.push(RawBlade {
            name: label,
            role: if b == 0 {
                BladeRole::Main
            } else {
                BladeRole::Splitter
            },
            count: n_blades,
            sections,
        });
    }
    if let Some(extra) = r.next_nonblank() {
        let (no, text) = extra?;
        return Err(r.syntax(no, "end of file after the last layer", text));
    }
    Ok(RawImpeller {
        format: SourceFormat::Rtzt,
        source: file.to_path_buf(),
        hub,
        shroud,
        blades,
    })
}

/// Reads an `rtzt` file whose lengths are in `unit`.
pub fn read_rtzt(path: &Path, unit: LengthUnit) -> Result<RawImpeller, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_rtzt(path, &bytes, unit)
}
