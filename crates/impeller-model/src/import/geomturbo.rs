//! NUMECA AutoGrid `.geomTurbo` files.
//!
//! The file starts with `GEOMETRY TURBO` and nests `NI_BEGIN type [name]` … `NI_END type`
//! blocks. What is read:
//! - `basic_curve` blocks (`NAME n`) holding a `zrcurve` (`ZR`, a count, then `z r` lines) or
//!   an `xyzcurve` (`XYZ`, a count, then `x y z` lines, reduced to (z, √(x²+y²)));
//! - `channel_curve hub` / `channel_curve shroud` blocks whose `VERTEX CURVE_P name t` lines
//!   name the basic curves forming hub and shroud (without them, the basic curves whose names
//!   contain `hub` / `shroud` are used);
//! - the first `NIROW` (`PERIODICITY n`) and its `NIBLADE`s (`NAME`): the first blade is the
//!   main blade, later ones are splitters. Each `NIBLADEGEOMETRY` holds `units f` (size of
//!   one file unit in metres, default 1), `number_of_blades n`, and the `suction` and
//!   `pressure` sides, each `SECTIONAL`, a section count, then per section (hub first) an
//!   optional `# section k` comment, `XYZ`, a point count and `x y z` lines from leading to
//!   trailing edge.
//!
//! Z is the rotation axis. Hub and shroud use the first blade's `units`. Other blocks and
//! keywords are skipped; later rows (a diffuser, ...) are ignored. A stray `NI_END` at top
//! level (AutoBlade writes `NI_END GEOMTURBO` without a matching begin) is accepted.

use super::error::ImportError;
use super::raw::{
    positive, BladeRole, LengthUnit, Polyline3, RawBlade, RawImpeller, RawSection, SectionShape,
    SourceFormat,
};
use super::text::{tokens, LineReader};
use nalgebra::{Vector2, Vector3};
use std::path::Path;

#[derive(Debug)]
struct Block {
    kind: String,
    name: String,
    line: usize,
}

#[derive(Debug, Default)]
struct BasicCurve {
    name: String,
    /// (z, r) in file units.
    points: Vec<Vector2<f64>>,
}

#[derive(Debug, Default)]
struct BladeData {
    name: String,
    line: usize,
    units: Option<(usize, f64)>,
    number_of_blades: Option<(usize, usize)>,
    /// (line, points) per section, file units.
    suction: Vec<(usize, Vec<Vector3<f64>>)>,
    pressure: Vec<(usize, Vec<Vector3<f64>>)>,
}

#[derive(Debug, Default)]
struct RowData {
    line: usize,
    periodicity: Option<(usize, usize)>,
    blades: Vec<BladeData>,
}

fn first_word_is(text: &str, word: &str) -> bool {
    tokens(text)
        .next()
        .is_some_and(|w| w.eq_ignore_ascii_case(word))
}

fn rest_after_first(text: &str) -> String {
    let t = text.trim();
    match t.find(char::is_whitespace) {
        Some(i) => t[i..].trim().to_string(),
        None => String::new(),
    }
}

/// Reads `n` lines of exactly `N` numbers each (after the count line).
fn read_points<const N: usize>(
    r: &mut LineReader<'_>,
    n: usize,
    what: &str,
) -> Result<Vec<[f64; N]>, ImportError> {
    let mut out = Vec::new();
    for k in 0..n {
        let (no, text) = r.expect_nonblank(&format!("point {} of {n} ({what})", k + 1))?;
        out.push(r.numbers::<N>(no, text, what)?);
    }
    Ok(out)
}

/// Reads the count line that follows `ZR` / `XYZ`.
fn read_count(r: &mut LineReader<'_>, field: &str, min: usize) -> Result<usize, ImportError> {
    let (no, text) = r.expect_nonblank(field)?;
    let n = r.count(no, text, field)?;
    if n < min {
        return Err(r.invalid(no, field, format!("at least {min} required, found {n}")));
    }
    Ok(n)
}

/// Reads one blade side after its `suction` / `pressure` keyword.
fn read_side(r: &mut LineReader<'_>, side: &str) -> Result<Vec<(usize, Polyline3)>, ImportError> {
    let (no, text) = r.expect_nonblank(&format!("SECTIONAL after `{side}`"))?;
    if !first_word_is(text, "SECTIONAL") {
        return Err(r.syntax(no, format!("SECTIONAL after `{side}`"), text));
    }
    let n_sections = read_count(r, &format!("number of {side} sections"), 2)?;
    let mut sections = Vec::new();
    for k in 0..n_sections {
        let what = format!("XYZ starting {side} section {} of {n_sections}", k + 1);
        let (no, text) = loop {
            let (no, text) = r.expect_nonblank(&what)?;
            if !text.trim().starts_with('#') {
                break (no, text);
            }
        };
        if !first_word_is(text, "XYZ") {
            return Err(r.syntax(no, what, text));
        }
        let n = read_count(
            r,
            &format!("number of points of {side} section {}", k + 1),
            2,
        )?;
        let pts = read_points::<3>(r, n, "x y z")?;
        sections.push((no, pts.into_iter().map(Vector3::from).collect()));
    }
    Ok(sections)
}

/// Parses a `.geomTurbo` file held in memory.
pub fn parse_geomturbo(file: &Path, bytes: &[u8]) -> Result<RawImpeller, ImportError> {
    let mut r = LineReader::new(file, bytes);
    let (no, text) = r.expect_nonblank("the `GEOMETRY TURBO` header")?;
    let head: Vec<String> = tokens(text).map(|t| t.to_ascii_uppercase()).collect();
    if head.len() < 2 || head[0] != "GEOMETRY" || head[1] != "TURBO" {
        return Err(r.syntax(no, "the `GEOMETRY TURBO` header", text));
    }
    let mut stack: Vec<Block> = Vec::new();
    let mut curves: Vec<BasicCurve> = Vec::new();
    let mut channel: Vec<(String, usize, String)> = Vec::new(); // (hub|shroud, line, curve)
    let mut channel_blocks: Vec<String> = Vec::new();
    let mut rows: Vec<RowData> = Vec::new();
    while let Some(line) = r.next_nonblank() {
        let (no, text) = line?;
        let t = text.trim();
        let mut toks = tokens(t);
        let first = toks.next().unwrap_or("").to_ascii_uppercase();
        if first == "NI_BEGIN" {
            let kind = toks.next().unwrap_or("").to_ascii_lowercase();
            if kind.is_empty() {
                return Err(r.syntax(no, "a block type after NI_BEGIN", text));
            }
            let name = toks.collect::<Vec<_>>().join(" ");
            match kind.as_str() {
                "basic_curve" => curves.push(BasicCurve::default()),
                "channel_curve" => channel_blocks.push(name.to_ascii_lowercase()),
                "nirow" => rows.push(RowData {
                    line: no,
                    ..Default::default()
                }),
                "niblade" => {
                    if let Some(row) = rows.last_mut() {
                        row.blades.push(BladeData {
                            line: no,
                            ..Default::default()
                        });
                    }
                }
                _ => {}
            }
            stack.push(Block {
                kind,
                name,
                line: no,
            });
            continue;
        }
        if first == "NI_END" {
            let kind = toks.next().unwrap_or("").to_ascii_lowercase();
            match stack.last() {
                None => continue, // stray top-level NI_END (AutoBlade)
                Some(top) if top.kind == kind => {
                    stack.pop();
                }
                Some(top) => {
                    return Err(r.syntax(no, format!("NI_END {}", top.kind), text));
                }
            }
            continue;
        }
        if t.starts_with('#') {
            continue;
        }
        let Some(top) = stack.last() else { continue };
        let in_first_row = rows.len() == 1;
        match top.kind.as_str() {
            "basic_curve" if first == "NAME" => {
                if let Some(c) = curves.last_mut() {
                    c.name = rest_after_first(t);
                }
            }
            "zrcurve" | "xyzcurve" | "basic_curve" if first == "ZR" || first == "XYZ" => {
                let n = read_count(&mut r, "number of curve points", 2)?;
                let pts: Vec<Vector2<f64>> = if first == "ZR" {
                    read_points::<2>(&mut r, n, "z r")?
                        .into_iter()
                        .map(|[z, rr]| Vector2::new(z, rr))
                        .collect()
                } else {
                    read_points::<3>(&mut r, n, "x y z")?
                        .into_iter()
                        .map(|[x, y, z]| Vector2::new(z, x.hypot(y)))
                        .collect()
                };
                match curves.last_mut() {
                    Some(c) if c.points.is_empty() => c.points = pts,
                    Some(_) => {
                        return Err(r.invalid(
                            no,
                            "curve",
                            "a second point list in one basic_curve",
                        ))
                    }
                    None => return Err(r.syntax(no, "ZR/XYZ inside a basic_curve block", text)),
                }
            }
            "zrcurve" | "xyzcurve" => {
                return Err(r.syntax(
                    no,
                    format!(
                        "NI_END {} (the point count says how many points follow)",
                        top.kind
                    ),
                    text,
                ));
            }
            "channel_curve" if first == "VERTEX" => {
                let rest: Vec<&str> = toks.collect();
                if rest.len() < 2 || !rest[0].eq_ignore_ascii_case("CURVE_P") {
                    return Err(r.syntax(no, "VERTEX CURVE_P curve_name parameter", text));
                }
                let which = top.name.to_ascii_lowercase();
                channel.push((which, no, rest[1].to_string()));
            }
            "nirow" if first == "PERIODICITY" && in_first_row => {
                let n = r.count(no, &rest_after_first(t), "PERIODICITY")?;
                if n == 0 {
                    return Err(r.invalid(no, "PERIODICITY", "must be at least 1"));
                }
                if let Some(row) = rows.last_mut() {
                    row.periodicity = Some((no, n));
                }
            }
            "niblade" if first == "NAME" && in_first_row => {
                if let Some(b) = rows.last_mut().and_then(|row| row.blades.last_mut()) {
                    b.name = rest_after_first(t);
                }
            }
            "nibladegeometry" if in_first_row => {
                let lower = first.to_ascii_lowercase();
                let Some(blade) = rows.last_mut().and_then(|row| row.blades.last_mut()) else {
                    continue;
                };
                match lower.as_str() {
                    "units" => {
                        let f = r.number(no, &rest_after_first(t), "units")?;
                        if !positive(f) {
                            return Err(r.invalid(
                                no,
                                "units",
                                format!("{f} is not a positive scale factor"),
                            ));
                        }
                        blade.units = Some((no, f));
                    }
                    "number_of_blades" => {
                        let n = r.count(no, &rest_after_first(t), "number_of_blades")?;
                        if n == 0 {
                            return Err(r.invalid(no, "number_of_blades", "must be at least 1"));
                        }
                        blade.number_of_blades = Some((no, n));
                    }
                    "suction" | "pressure" => {
                        let side = read_side(&mut r, &lower)?;
                        let target = if lower == "suction" {
                            &mut blade.suction
                        } else {
                            &mut blade.pressure
                        };
                        if !target.is_empty() {
                            return Err(r.invalid(no, lower.as_str(), "side given twice"));
                        }
                        *target = side;
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }
    if let Some(top) = stack.last() {
        return Err(r.eof(format!(
            "NI_END {} closing the block opened on line {}{}",
            top.kind,
            top.line,
            if top.name.is_empty() {
                String::new()
            } else {
                format!(" ({})", top.name)
            }
        )));
    }
    let Some(row) = rows.into_iter().next() else {
        return Err(r.eof("a `NI_BEGIN NIROW` block with the blades"));
    };
    let blades_with_geometry: Vec<BladeData> = row
        .blades
        .into_iter()
        .filter(|b| !(b.suction.is_empty() && b.pressure.is_empty()))
        .collect();
    if blades_with_geometry.is_empty() {
        return Err(r.invalid(
            row.line,
            "NIROW",
            "the row has no blade with suction/pressure sections",
        ));
    }
    let mm_per_unit = |b: &BladeData| b.units.map_or(1.0, |(_, f)| f) * LengthUnit::Metre.mm();
    let channel_scale = mm_per_unit(&blades_with_geometry[0]);
    let mut blades = Vec::new();
    for (k, b) in blades_with_geometry.into_iter().enumerate() {
        let count = match (row.periodicity, b.number_of_blades) {
            (Some((_, p)), Some((no, n))) if p != n => {
                return Err(r.invalid(
                    no,
                    "number_of_blades",
                    format!("{n} differs from the row's PERIODICITY {p}"),
                ))
            }
            (Some((_, p)), _) => p,
            (None, Some((_, n))) => n,
            (None, None) => {
                return Err(r.invalid(
                    b.line,
                    "PERIODICITY",
                    "neither the row's PERIODICITY nor the blade's number_of_blades is given",
                ))
            }
        };
        if b.suction.len() != b.pressure.len() {
            return Err(r.invalid(
                b.line,
                "SECTIONAL",
                format!(
                    "blade {:?}: {} suction sections but {} pressure sections",
                    b.name,
                    b.suction.len(),
                    b.pressure.len()
                ),
            ));
        }
        let s = mm_per_unit(&b);
        let sections = b
            .suction
            .into_iter()
            .zip(b.pressure)
            .map(|((line, su), (_, pr))| RawSection {
                line,
                span: None,
                shape: SectionShape::Sides {
                    suction: su.into_iter().map(|p| p * s).collect(),
                    pressure: pr.into_iter().map(|p| p * s).collect(),
                },
            })
            .collect();
        blades.push(RawBlade {
            name: if b.name.is_empty() {
                format!("blade {}", k + 1)
            } else {
                b.name
            },
            role: if k == 0 {
                BladeRole::Main
            } else {
                BladeRole::Splitter
            },
            count,
            sections,
        });
    }
    let wall = |which: &str| -> Result<Vec<Vector2<f64>>, ImportError> {
        let names: Vec<(usize, &str)> = channel
            .iter()
            .filter(|(w, _, _)| w == which)
            .map(|(_, no, n)| (*no, n.as_str()))
            .collect();
        let mut pts: Vec<Vector2<f64>> = Vec::new();
        let mut used: Vec<&str> = Vec::new();
        if channel_blocks.iter().any(|c| c == which) {
            for (no, name) in names {
                if used.contains(&name) {
                    continue;
                }
                let c = curves.iter().find(|c| c.name == name).ok_or_else(|| {
                    r.invalid(
                        no,
                        "VERTEX CURVE_P",
                        format!("no basic_curve named {name:?}"),
                    )
                })?;
                used.push(name);
                append_curve(&mut pts, &c.points);
            }
        } else {
            for c in curves
                .iter()
                .filter(|c| c.name.to_ascii_lowercase().contains(which))
            {
                append_curve(&mut pts, &c.points);
            }
        }
        if pts.len() < 2 {
            return Err(r.eof(format!(
                "a `channel_curve {which}` block naming a basic_curve with at least 2 points"
            )));
        }
        Ok(pts.into_iter().map(|p| p * channel_scale).collect())
    };
    Ok(RawImpeller {
        format: SourceFormat::GeomTurbo,
        source: file.to_path_buf(),
        hub: wall("hub")?,
        shroud: wall("shroud")?,
        blades,
    })
}

/// Appends a curve's points, dropping a first point that repeats the last one already held.
fn append_curve(out: &mut Vec<Vector2<f64>>, pts: &[Vector2<f64>]) {
    for (i, p) in pts.iter().enumerate() {
        if i == 0
            && out
                .last()
                .is_some_and(|q| (q - p).norm() <= 1e-12 * (1.0 + p.norm()))
        {
            continue;
        }
        out.push(*p);
    }
}

/// Reads a `.geomTurbo` file.
pub fn read_geomturbo(path: &Path) -> Result<RawImpeller, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_geomturbo(path, &bytes)
}
