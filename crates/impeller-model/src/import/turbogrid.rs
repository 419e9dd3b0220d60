//! TurboGrid curve sets: an `.inf` file naming the hub, shroud and profile curve files.
//!
//! The `.inf` file holds `Key: value` lines (comments start with `!` or `#`):
//!
//! | key | value |
//! |---|---|
//! | `Axis of Rotation` | `X`, `Y` or `Z` (required) |
//! | `Number of Blade Sets` | number of main blades N (required) |
//! | `Number of Blades Per Set` | 1 + splitters per main blade (default 1) |
//! | `Geometry Units` | `MM`, `CM`, `M`, `IN`, `FT`, `UM` (required) |
//! | `Coordinate Type` | `Cartesian` (default) or `Cylindrical` |
//! | `Angle Units` | `Radians` (default) or `Degrees` (cylindrical files only) |
//! | `Hub Data File`, `Shroud Data File` | file names, relative to the `.inf` (required) |
//! | `Profile Data File` | the main blade's profile file (= `Blade 0 Profile Data File`) |
//! | `Blade k Profile Data File` | profile file of blade k of a set (k ≥ 1: splitters) |
//!
//! Other keys TurboGrid writes (edge treatments, ...) are ignored. Curve files hold one point
//! per line, `x y z` (cartesian) or `r θ z` (cylindrical, z along the rotation axis); a
//! profile file holds one closed loop per span, each introduced by `# Profile k [at s%]`,
//! hub first. Cartesian coordinates are permuted cyclically so the rotation axis becomes +Z
//! (X: (x,y,z) → (y,z,x); Y: → (z,x,y)), which keeps the frame right-handed.

use super::error::ImportError;
use super::raw::{
    from_cylindrical, meridional, BladeRole, LengthUnit, RawBlade, RawImpeller, RawSection,
    SectionShape, SourceFormat,
};
use super::text::{tokens, LineReader};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// Rotation axis named in the `.inf` file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// The x axis.
    X,
    /// The y axis.
    Y,
    /// The z axis.
    Z,
}

/// How curve-file points are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoordinateType {
    /// `x y z`.
    Cartesian,
    /// `r θ z` (θ in the `.inf`'s angle unit).
    Cylindrical,
}

/// The contents of a TurboGrid `.inf` file.
#[derive(Debug, Clone, PartialEq)]
pub struct TurboGridInf {
    /// Rotation axis.
    pub axis: Axis,
    /// Number of blade sets (main blades).
    pub blade_sets: usize,
    /// Blades per set (1 + number of splitters per main blade).
    pub blades_per_set: usize,
    /// Length unit of all curve files.
    pub units: LengthUnit,
    /// Cartesian or cylindrical points.
    pub coordinates: CoordinateType,
    /// Whether cylindrical θ is in degrees (else radians).
    pub degrees: bool,
    /// Hub curve file name.
    pub hub_file: String,
    /// Shroud curve file name.
    pub shroud_file: String,
    /// Profile file of each blade of a set, main blade first.
    pub profile_files: Vec<String>,
}

fn norm_key(k: &str) -> String {
    k.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_ascii_lowercase()
}

impl TurboGridInf {
    /// Parses an `.inf` file. Errors name the line and key.
    pub fn parse(file: &Path, bytes: &[u8]) -> Result<Self, ImportError> {
        let mut r = LineReader::new(file, bytes);
        let mut axis = None;
        let mut sets = None;
        let mut per_set = None;
        let mut units = None;
        let mut coordinates = None;
        let mut degrees = None;
        let mut hub = None;
        let mut shroud = None;
        let mut profiles: Vec<(usize, usize, String)> = Vec::new(); // (blade index, line, name)
        while let Some(line) = r.next_nonblank() {
            let (no, text) = line?;
            let t = text.trim();
            if t.starts_with('!') || t.starts_with('#') {
                continue;
            }
            let Some((key, value)) = t.split_once(':') else {
                return Err(r.syntax(no, "a `Key: value` line", text));
            };
            let key_n = norm_key(key);
            let value = value.trim();
            let dup = |set: bool| -> Result<(), ImportError> {
                if set {
                    Err(r.invalid(no, key.trim(), "given twice"))
                } else {
                    Ok(())
                }
            };
            match key_n.as_str() {
                "axis of rotation" => {
                    dup(axis.is_some())?;
                    axis = Some(match value.to_ascii_uppercase().as_str() {
                        "X" => Axis::X,
                        "Y" => Axis::Y,
                        "Z" => Axis::Z,
                        _ => return Err(r.syntax(no, "Axis of Rotation: X, Y or Z", text)),
                    });
                }
                "number of blade sets" | "number of blades per set" => {
                    let n = r.count(no, value, key.trim())?;
                    if n == 0 {
                        return Err(r.invalid(no, key.trim(), "must be at least 1"));
                    }
                    if key_n == "number of blade sets" {
                        dup(sets.is_some())?;
                        sets = Some(n);
                    } else {
                        dup(per_set.is_some())?;
                        per_set = Some(n);
                    }
                }
                "geometry units" => {
                    dup(units.is_some())?;
                    units = Some(LengthUnit::from_name(value).ok_or_else(|| {
                        r.syntax(no, "Geometry Units: MM, CM, M, IN, FT or UM", text)
                    })?);
                }
                "coordinate type" | "coordinate system" => {
                    dup(coordinates.is_some())?;
                    coordinates = Some(match value.to_ascii_lowercase().as_str() {
                        "cartesian" => CoordinateType::Cartesian,
                        "cylindrical" => CoordinateType::Cylindrical,
                        _ => {
                            return Err(r.syntax(
                                no,
                                "Coordinate Type: Cartesian or Cylindrical",
                                text,
                            ))
                        }
                    });
                }
                "angle units" => {
                    dup(degrees.is_some())?;
                    degrees = Some(match value.to_ascii_lowercase().as_str() {
                        "radians" | "rad" => false,
                        "degrees" | "deg" => true,
                        _ => return Err(r.syntax(no, "Angle Units: Radians or Degrees", text)),
                    });
                }
                "hub data file" | "shroud data file" | "profile data file" => {
                    if value.is_empty() {
                        return Err(r.syntax(no, format!("{}: FILE NAME", key.trim()), text));
                    }
                    match key_n.as_str() {
                        "hub data file" => {
                            dup(hub.is_some())?;
                            hub = Some(value.to_string());
                        }
                        "shroud data file" => {
                            dup(shroud.is_some())?;
                            shroud = Some(value.to_string());
                        }
                        _ => profiles.push((0, no, value.to_string())),
                    }
                }
                k if k.starts_with("blade ")
                    && (k.ends_with(" profile data file") || k.ends_with(" data file")) =>
                {
                    let idx_text = k
                        .trim_start_matches("blade ")
                        .split_whitespace()
                        .next()
                        .unwrap_or("");
                    let idx =
                        r.count(no, idx_text, "blade index in `Blade k Profile Data File`")?;
                    if value.is_empty() {
                        return Err(r.syntax(no, format!("{}: FILE NAME", key.trim()), text));
                    }
                    profiles.push((idx, no, value.to_string()));
                }
                _ => {}
            }
        }
        let missing = |what: &str| r.eof(format!("a `{what}` line"));
        let axis = axis.ok_or_else(|| missing("Axis of Rotation: X|Y|Z"))?;
        let blade_sets = sets.ok_or_else(|| missing("Number of Blade Sets: N"))?;
        let units = units.ok_or_else(|| missing("Geometry Units: UNIT"))?;
        let hub_file = hub.ok_or_else(|| missing("Hub Data File: NAME"))?;
        let shroud_file = shroud.ok_or_else(|| missing("Shroud Data File: NAME"))?;
        let blades_per_set = per_set.unwrap_or(1);
        let mut profile_files = vec![None; blades_per_set];
        for (idx, no, name) in profiles {
            let Some(slot) = profile_files.get_mut(idx) else {
                return Err(r.invalid(
                    no,
                    "profile data file",
                    format!("blade index {idx} but only {blades_per_set} blade(s) per set"),
                ));
            };
            if slot.is_some() {
                return Err(r.invalid(no, "profile data file", format!("blade {idx} given twice")));
            }
            *slot = Some(name);
        }
        let profile_files = profile_files
            .into_iter()
            .enumerate()
            .map(|(k, f)| {
                f.ok_or_else(|| {
                    if k == 0 {
                        missing("Profile Data File: NAME")
                    } else {
                        missing(&format!("Blade {k} Profile Data File: NAME"))
                    }
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            axis,
            blade_sets,
            blades_per_set,
            units,
            coordinates: coordinates.unwrap_or(CoordinateType::Cartesian),
            degrees: degrees.unwrap_or(false),
            hub_file,
            shroud_file,
            profile_files,
        })
    }

    /// The point in mm, rotation axis +Z, of one data line's three numbers.
    fn point(&self, v: [f64; 3]) -> Vector3<f64> {
        let s = self.units.mm();
        match self.coordinates {
            CoordinateType::Cylindrical => {
                let theta = if self.degrees {
                    v[1].to_radians()
                } else {
                    v[1]
                };
                from_cylindrical(v[0] * s, theta, v[2] * s)
            }
            CoordinateType::Cartesian => {
                let [x, y, z] = v;
                let p = match self.axis {
                    Axis::Z => [x, y, z],
                    Axis::X => [y, z, x],
                    Axis::Y => [z, x, y],
                };
                Vector3::new(p[0] * s, p[1] * s, p[2] * s)
            }
        }
    }

    fn columns(&self) -> &'static str {
        match self.coordinates {
            CoordinateType::Cartesian => "x y z",
            CoordinateType::Cylindrical => "r theta z",
        }
    }
}

fn is_comment(t: &str) -> bool {
    t.starts_with('#') || t.starts_with('!')
}

/// Parses a hub or shroud curve file: one point per line, at least 2 points; returns the
/// points in mm with the rotation axis +Z.
pub fn parse_curve(
    file: &Path,
    bytes: &[u8],
    inf: &TurboGridInf,
) -> Result<Vec<Vector3<f64>>, ImportError> {
    let mut r = LineReader::new(file, bytes);
    let mut pts = Vec::new();
    while let Some(line) = r.next_nonblank() {
        let (no, text) = line?;
        if is_comment(text.trim()) {
            continue;
        }
        pts.push(inf.point(r.numbers::<3>(no, text, inf.columns())?));
    }
    if pts.len() < 2 {
        return Err(r.eof(format!(
            "at least 2 curve points ({}), found {}",
            inf.columns(),
            pts.len()
        )));
    }
    Ok(pts)
}

/// Parses a profile file: sections introduced by `# Profile k [at s%]`, hub first, each a
/// closed loop of at least 4 points; at least 2 sections.
pub fn parse_profiles(
    file: &Path,
    bytes: &[u8],
    inf: &TurboGridInf,
) -> Result<Vec<RawSection>, ImportError> {
    let mut r = LineReader::new(file, bytes);
    let mut sections: Vec<RawSection> = Vec::new();
    let mut current: Option<(usize, Option<f64>, Vec<Vector3<f64>>)> = None;
    let finish = |r: &LineReader<'_>,
                  cur: (usize, Option<f64>, Vec<Vector3<f64>>),
                  out: &mut Vec<RawSection>|
     -> Result<(), ImportError> {
        let (line, span, pts) = cur;
        if pts.len() < 4 {
            return Err(r.invalid(
                line,
                "profile",
                format!(
                    "a closed section loop needs at least 4 points, found {}",
                    pts.len()
                ),
            ));
        }
        out.push(RawSection {
            line,
            span,
            shape: SectionShape::Loop(pts),
        });
        Ok(())
    };
    while let Some(line) = r.next_nonblank() {
        let (no, text) = line?;
        let t = text.trim();
        if is_comment(t) {
            let body = t.trim_start_matches(['#', '!']).trim();
            let mut toks = tokens(body);
            if toks
                .next()
                .is_some_and(|w| w.eq_ignore_ascii_case("profile"))
            {
                let k = toks.next().unwrap_or("");
                r.count(no, k, "profile number in `# Profile k`")?;
                let mut span = None;
                if let Some(at) = toks.next() {
                    if !at.eq_ignore_ascii_case("at") {
                        return Err(r.syntax(no, "`# Profile k` or `# Profile k at s%`", text));
                    }
                    let s = toks.next().unwrap_or("");
                    let v = s
                        .strip_suffix('%')
                        .and_then(super::text::parse_number)
                        .ok_or_else(|| {
                            r.syntax(no, "a span percentage after `at` (e.g. 20%)", text)
                        })?;
                    if !(0.0..=100.0).contains(&v) {
                        return Err(r.invalid(
                            no,
                            "profile span",
                            format!("{v}% is not within 0–100%"),
                        ));
                    }
                    span = Some(v / 100.0);
                }
                if let Some(cur) = current.take() {
                    finish(&r, cur, &mut sections)?;
                }
                current = Some((no, span, Vec::new()));
            }
            continue;
        }
        let p = inf.point(r.numbers::<3>(no, text, inf.columns())?);
        match current.as_mut() {
            Some((_, _, pts)) => pts.push(p),
            None => return Err(r.syntax(no, "a `# Profile 1` line before the first point", text)),
        }
    }
    if let Some(cur) = current.take() {
        finish(&r, cur, &mut sections)?;
    }
    if sections.len() < 2 {
        return Err(r.eof(format!(
            "at least 2 profiles (`# Profile k` sections), found {}",
            sections.len()
        )));
    }
    Ok(sections)
}

/// One file of a curve set in memory: its path (for messages and relative names) and bytes.
pub type FileBytes<'a> = (&'a Path, &'a [u8]);

/// Builds the raw impeller of a curve set whose files are already in memory. `profiles`
/// holds one profile file per blade of a set, main blade first (as listed in the `.inf`).
pub fn turbogrid_from_bytes(
    inf_file: FileBytes<'_>,
    hub: FileBytes<'_>,
    shroud: FileBytes<'_>,
    profiles: &[FileBytes<'_>],
) -> Result<RawImpeller, ImportError> {
    let inf = TurboGridInf::parse(inf_file.0, inf_file.1)?;
    from_parsed_inf(&inf, inf_file.0, hub, shroud, profiles)
}

fn from_parsed_inf(
    inf: &TurboGridInf,
    inf_path: &Path,
    hub: FileBytes<'_>,
    shroud: FileBytes<'_>,
    profiles: &[FileBytes<'_>],
) -> Result<RawImpeller, ImportError> {
    if profiles.len() != inf.blades_per_set {
        return Err(ImportError::Invalid {
            file: inf_path.to_path_buf(),
            line: 0,
            field: "Number of Blades Per Set".into(),
            reason: format!(
                "{} blade(s) per set but {} profile file(s) given",
                inf.blades_per_set,
                profiles.len()
            ),
        });
    }
    let hub_pts = parse_curve(hub.0, hub.1, inf)?;
    let shroud_pts = parse_curve(shroud.0, shroud.1, inf)?;
    let mut blades = Vec::with_capacity(profiles.len());
    for (k, (path, bytes)) in profiles.iter().enumerate() {
        let sections = parse_profiles(path, bytes, inf)?;
        blades.push(RawBlade {
            name: if k == 0 {
                "main blade".into()
            } else {
                format!("splitter {k}")
            },
            role: if k == 0 {
                BladeRole::Main
            } else {
                BladeRole::Splitter
            },
            count: inf.blade_sets,
            sections,
        });
    }
    Ok(RawImpeller {
        format: SourceFormat::TurboGrid,
        source: inf_path.to_path_buf(),
        hub: hub_pts.iter().map(meridional).collect(),
        shroud: shroud_pts.iter().map(meridional).collect(),
        blades,
    })
}

fn read(path: &Path) -> Result<Vec<u8>, ImportError> {
    std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        source,
    })
}

/// Reads a TurboGrid curve set from its `.inf` file; the curve files are looked up relative to
/// the `.inf` file's folder.
pub fn read_turbogrid(inf_path: &Path) -> Result<RawImpeller, ImportError> {
    let inf_bytes = read(inf_path)?;
    let inf = TurboGridInf::parse(inf_path, &inf_bytes)?;
    let dir = inf_path.parent().unwrap_or(Path::new("."));
    let hub_path: PathBuf = dir.join(&inf.hub_file);
    let shroud_path: PathBuf = dir.join(&inf.shroud_file);
    let hub = read(&hub_path)?;
    let shroud = read(&shroud_path)?;
    let profile_paths: Vec<PathBuf> = inf.profile_files.iter().map(|f| dir.join(f)).collect();
    let profile_bytes = profile_paths
        .iter()
        .map(|p| read(p))
        .collect::<Result<Vec<_>, _>>()?;
    let profiles: Vec<FileBytes<'_>> = profile_paths
        .iter()
        .zip(&profile_bytes)
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    from_parsed_inf(
        &inf,
        inf_path,
        (&hub_path, &hub),
        (&shroud_path, &shroud),
        &profiles,
    )
}
