//! Section tables: a folder of plain numeric tables, one file per meridional contour and one
//! per blade section, as design archives publish them (the NASA HECC data archive's
//! "Design-Intent Stage Coordinates" and "As-Manufactured Cold Coordinates").
//!
//! ```text
//! <folder>/…hub….txt                 x r          (tab, space or comma separated)
//! <folder>/…shroud….txt              x r
//! <folder>/…main…section_01.txt      X R·θ R      one closed loop around the section
//! <folder>/…main…section_02.txt      …            (numbered from the hub to the shroud)
//! <folder>/…splitter…section_01.txt  X R·θ R      (optional splitter row)
//! ```
//!
//! Lines that do not start with a number (column headers such as `X  R*THETA  R`) are
//! skipped; every other line must hold exactly the table's columns. `x` is the axial
//! coordinate, `r` the radius and `R·θ` the arc length at that radius, so θ = (R·θ)/R in
//! radians. File names are matched case-insensitively: the contour files contain `hub` /
//! `shroud` (or are named explicitly), a blade section file contains `main` or `splitter` and
//! ends with its section number before the extension (`section_07.txt`, `section07.csv`).
//!
//! The tables state neither their length unit nor the blade counts (the archive's read-me
//! does), so the import file gives both (`table_unit`, `blade_count`, `splitter_count`).
//!
//! **Handedness.** The archive measures θ counter-clockwise *looking aft*, i.e. looking along
//! +x, the flow direction. With z = x, a right-handed (x, y, z) frame sees θ grow clockwise
//! from that viewpoint, so the point is placed at (r cos θ, −r sin θ, x): the part keeps its
//! hand (a mirrored impeller would turn its blades against the rotation). `theta_sense =
//! "clockwise_looking_aft"` is the other convention.
//!
//! Complexity: linear in the number of table lines.

use super::error::ImportError;
use super::raw::{
    BladeRole, LengthUnit, RawBlade, RawImpeller, RawSection, SectionShape, SourceFormat,
};
use super::text::{parse_number, tokens, LineReader};
use nalgebra::{Vector2, Vector3};
use std::path::{Path, PathBuf};

/// The sense in which a table's θ grows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ThetaSense {
    /// θ grows counter-clockwise for a viewer looking along the flow (+x): NASA's convention.
    #[default]
    CounterClockwiseLookingAft,
    /// θ grows clockwise for a viewer looking along the flow.
    ClockwiseLookingAft,
}

/// What the tables themselves do not say.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TableOptions {
    /// Length unit of every table (required).
    pub unit: Option<LengthUnit>,
    /// Number of main blades (required).
    pub blade_count: Option<usize>,
    /// Number of splitters (default: `blade_count` when splitter sections are present).
    pub splitter_count: Option<usize>,
    /// Hub contour file (default: the one file of the folder whose name contains `hub`).
    pub hub_file: Option<PathBuf>,
    /// Shroud contour file (default: the one file whose name contains `shroud`).
    pub shroud_file: Option<PathBuf>,
    /// Sense of θ.
    pub theta_sense: ThetaSense,
}

/// The files a table folder is made of.
#[derive(Debug, Clone, PartialEq)]
pub struct TableFiles {
    /// Hub contour.
    pub hub: PathBuf,
    /// Shroud contour.
    pub shroud: PathBuf,
    /// Main blade sections, hub first.
    pub main: Vec<PathBuf>,
    /// Splitter sections, hub first (empty without splitters).
    pub splitter: Vec<PathBuf>,
}

fn invalid(file: &Path, field: &str, reason: impl Into<String>) -> ImportError {
    ImportError::Invalid {
        file: file.to_path_buf(),
        line: 0,
        field: field.into(),
        reason: reason.into(),
    }
}

/// The section number of a blade section file: the digits that end its stem
/// (`…section_07` → 7).
fn section_number(stem: &str) -> Option<usize> {
    let digits: String = stem
        .chars()
        .rev()
        .take_while(char::is_ascii_digit)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    digits.parse().ok()
}

/// Finds the contour and section files of the folder `dir` (see the module docs).
pub fn table_files(dir: &Path, opts: &TableOptions) -> Result<TableFiles, ImportError> {
    let entries = std::fs::read_dir(dir).map_err(|source| ImportError::Io {
        file: dir.to_path_buf(),
        source,
    })?;
    let mut hubs = Vec::new();
    let mut shrouds = Vec::new();
    let mut main: Vec<(usize, PathBuf)> = Vec::new();
    let mut splitter: Vec<(usize, PathBuf)> = Vec::new();
    for e in entries {
        let path = e
            .map_err(|source| ImportError::Io {
                file: dir.to_path_buf(),
                source,
            })?
            .path();
        if !path.is_file() {
            continue;
        }
        let Some(stem) = path.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        let lower = stem.to_ascii_lowercase();
        let ext_ok = path
            .extension()
            .and_then(|x| x.to_str())
            .is_some_and(|x| matches!(x.to_ascii_lowercase().as_str(), "txt" | "csv" | "dat"));
        if !ext_ok {
            continue;
        }
        if lower.contains("section") {
            let Some(k) = section_number(&lower) else {
                continue;
            };
            if lower.contains("splitter") {
                splitter.push((k, path));
            } else if lower.contains("main") {
                main.push((k, path));
            }
        } else if lower.contains("hub") {
            hubs.push(path);
        } else if lower.contains("shroud") {
            shrouds.push(path);
        }
    }
    let pick = |given: &Option<PathBuf>, found: Vec<PathBuf>, what: &str| {
        if let Some(p) = given {
            return Ok(p.clone());
        }
        match found.len() {
            1 => Ok(found.into_iter().next().unwrap_or_default()),
            0 => Err(invalid(
                dir,
                what,
                format!("no file whose name contains {what:?} (name it with {what}_file)"),
            )),
            _ => Err(invalid(
                dir,
                what,
                format!(
                    "{} files whose names contain {what:?}: {} (name one with {what}_file)",
                    found.len(),
                    found
                        .iter()
                        .filter_map(|p| p.file_name().and_then(|n| n.to_str()))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )),
        }
    };
    let hub = pick(&opts.hub_file, hubs, "hub")?;
    let shroud = pick(&opts.shroud_file, shrouds, "shroud")?;
    let order = |mut v: Vec<(usize, PathBuf)>, what: &str| -> Result<Vec<PathBuf>, ImportError> {
        v.sort_by_key(|(k, _)| *k);
        for w in v.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(invalid(
                    &w[1].1,
                    "section number",
                    format!("{what} section {} appears twice", w[0].0),
                ));
            }
        }
        Ok(v.into_iter().map(|(_, p)| p).collect())
    };
    let main = order(main, "main blade")?;
    let splitter = order(splitter, "splitter")?;
    if main.len() < 2 {
        return Err(invalid(
            dir,
            "main blade sections",
            format!(
                "at least 2 files whose names contain \"main\" and end with a section number \
                 are required, found {}",
                main.len()
            ),
        ));
    }
    if splitter.len() == 1 {
        return Err(invalid(
            &splitter[0],
            "splitter sections",
            "a splitter needs at least 2 sections",
        ));
    }
    Ok(TableFiles {
        hub,
        shroud,
        main,
        splitter,
    })
}

/// Reads the rows of a table of `N` columns (`what` names them), skipping header lines (lines
/// whose first token is not a number). Errors name the file and line.
pub fn read_table<const N: usize>(path: &Path, what: &str) -> Result<Vec<[f64; N]>, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_table::<N>(path, &bytes, what)
}

/// [`read_table`] on bytes held in memory; `path` names them in errors.
pub fn parse_table<const N: usize>(
    path: &Path,
    bytes: &[u8],
    what: &str,
) -> Result<Vec<[f64; N]>, ImportError> {
    let mut r = LineReader::new(path, bytes);
    let mut rows = Vec::new();
    while let Some(line) = r.next_nonblank() {
        let (no, text) = line?;
        let first_is_number = tokens(text).next().and_then(parse_number).is_some();
        if !first_is_number {
            if rows.is_empty() {
                continue; // a header
            }
            return Err(r.syntax(no, format!("{N} numbers ({what})"), text));
        }
        rows.push(r.numbers::<N>(no, text, what)?);
    }
    if rows.len() < 2 {
        return Err(r.eof(format!("at least 2 rows of {what}")));
    }
    Ok(rows)
}

/// Reads one blade section (`X R·θ R` rows) as a closed loop in mm, rotation axis +Z.
fn read_section(path: &Path, scale: f64, sense: ThetaSense) -> Result<RawSection, ImportError> {
    let rows = read_table::<3>(path, "X R*THETA R")?;
    let sign = match sense {
        ThetaSense::CounterClockwiseLookingAft => -1.0,
        ThetaSense::ClockwiseLookingAft => 1.0,
    };
    let mut pts = Vec::with_capacity(rows.len());
    for (i, [x, rt, r]) in rows.into_iter().enumerate() {
        if r <= 0.0 {
            return Err(ImportError::Invalid {
                file: path.to_path_buf(),
                line: 0,
                field: "R".into(),
                reason: format!("data row {} has radius {r}, not > 0", i + 1),
            });
        }
        let theta = rt / r;
        pts.push(Vector3::new(
            r * theta.cos() * scale,
            sign * r * theta.sin() * scale,
            x * scale,
        ));
    }
    Ok(RawSection {
        line: 1,
        span: None,
        shape: SectionShape::Loop(pts),
    })
}

/// Reads a folder of section tables into raw point data (mm, rotation axis +Z, the tables'
/// axial sense). The unit and the main blade count must be given.
pub fn read_tables(dir: &Path, opts: &TableOptions) -> Result<RawImpeller, ImportError> {
    let unit = opts.unit.ok_or_else(|| {
        invalid(
            dir,
            "table_unit",
            "section tables state no length unit: give table_unit (MM, CM, M, IN, FT, UM)",
        )
    })?;
    let count = opts.blade_count.ok_or_else(|| {
        invalid(
            dir,
            "blade_count",
            "section tables state no blade count: give blade_count",
        )
    })?;
    if count == 0 {
        return Err(invalid(dir, "blade_count", "must be at least 1"));
    }
    let files = table_files(dir, opts)?;
    let s = unit.mm();
    let contour = |p: &Path| -> Result<Vec<Vector2<f64>>, ImportError> {
        Ok(read_table::<2>(p, "x r")?
            .into_iter()
            .map(|[x, r]| Vector2::new(x * s, r * s))
            .collect())
    };
    let hub = contour(&files.hub)?;
    let shroud = contour(&files.shroud)?;
    let mut blades = vec![RawBlade {
        name: "main blade".into(),
        role: BladeRole::Main,
        count,
        sections: files
            .main
            .iter()
            .map(|p| read_section(p, s, opts.theta_sense))
            .collect::<Result<_, _>>()?,
    }];
    if !files.splitter.is_empty() {
        let n = opts.splitter_count.unwrap_or(count);
        if n == 0 {
            return Err(invalid(dir, "splitter_count", "must be at least 1"));
        }
        blades.push(RawBlade {
            name: "splitter".into(),
            role: BladeRole::Splitter,
            count: n,
            sections: files
                .splitter
                .iter()
                .map(|p| read_section(p, s, opts.theta_sense))
                .collect::<Result<_, _>>()?,
        });
    }
    Ok(RawImpeller {
        format: SourceFormat::SectionTables,
        source: dir.to_path_buf(),
        hub,
        shroud,
        blades,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_are_skipped_and_rows_counted() {
        let t = parse_table::<3>(
            Path::new("s.txt"),
            b"        X           R*THETA          R\r\n 1 2 3\r\n4,5,6\r\n",
            "X R*THETA R",
        )
        .unwrap();
        assert_eq!(t, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    }

    #[test]
    fn a_bad_row_names_its_line() {
        let e = parse_table::<2>(Path::new("hub.txt"), b"x\tr\n1\t2\n3\tx\n", "x r").unwrap_err();
        assert_eq!(e.line(), Some(3));
        let e =
            parse_table::<2>(Path::new("hub.txt"), b"x r\n1 2\nlate header\n", "x r").unwrap_err();
        assert_eq!(e.line(), Some(3));
    }

    #[test]
    fn section_numbers() {
        assert_eq!(section_number("hecc_main_blade_section_07"), Some(7));
        assert_eq!(
            section_number("mainbladecoldwithfillets_section14"),
            Some(14)
        );
        assert_eq!(section_number("main_section"), None);
    }
}
