//! The job file: what `impeller-cam run` machines, with which tools and operations, on which
//! machine, in which dialect. The keys are documented in `docs/job.md`.
//!
//! Paths are relative to the job file. Every error names the file, the line and the key:
//! unknown keys, wrong types, out-of-range values, unknown tools and kinds, duplicate
//! operation names, and the parameter errors of a kind's builder (a misspelt key must not be
//! silently ignored on a real machine). Lines are found in the parsed document's spans
//! ([`toml::de::DeTable`]).

use crate::error::CliError;
use crate::registry::{self, Registry};
use cam_core::{Cutter, CutterShape, HolderSegment, Tolerances};
use cam_plan::{OperationSpec, PlanError, Process, Tool};
use serde::de::{self, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Report name of the embedded default job when it has none.
pub const DEFAULT_JOB_NAME: &str = "impeller-8+8 (embedded default)";

/// Where the embedded default job pretends to live: its relative paths resolve under this
/// folder and are read from [`EMBEDDED_FILES`], never from the disk.
const EMBEDDED_JOB_PATH: &str = "<embedded>/fixtures/impeller-8+8/job.toml";

/// The embedded default job: the `impeller-8+8` fixture job.
const DEFAULT_JOB_TOML: &str = include_str!("../embedded/impeller-8+8/job.toml");

/// Files the embedded default job refers to, by resolved path.
static EMBEDDED_FILES: &[(&str, &str)] = &[
    (
        "<embedded>/fixtures/impeller-8+8/impeller.toml",
        include_str!("../embedded/impeller-8+8/impeller.toml"),
    ),
    (
        "<embedded>/fixtures/impeller-8+8/../machines/xyzac-trt.toml",
        include_str!("../embedded/machines/xyzac-trt.toml"),
    ),
    (
        "<embedded>/fixtures/impeller-8+8/../tools/impeller-8+8.toml",
        include_str!("../embedded/tools/impeller-8+8.toml"),
    ),
];

/// A parsed job with every path resolved against the job file's folder.
#[derive(Debug, Clone)]
pub struct Job {
    /// Job name (report title, program name).
    pub name: String,
    /// Impeller file; `None` = embedded default impeller.
    pub impeller: Option<PathBuf>,
    /// Machine file; `None` = embedded xyzac-trt machine.
    pub machine: Option<PathBuf>,
    /// Dialect name.
    pub dialect: String,
    /// Tolerances: `chord_tol` (design mesh and tool frusta of the clearance query, planners'
    /// polylines), `machining_tol` (planners, gouge check of reverse-motion smoothing),
    /// `linearisation_tol` (post), `stock_allowance` (default allowance of process rows).
    pub tolerances: Tolerances,
    /// The safety surface of linking moves.
    pub safety: SafetySpec,
    /// The stock the job's operations start from (`[stock]`).
    pub stock: StockStart,
    /// Verification settings.
    pub verification: VerificationSpec,
    /// Post-processing settings (`[post]`).
    pub post: PostSpec,
    /// No progress on stderr (`run --quiet`; not a job-file key).
    pub quiet: bool,
    /// Also write the machined stock's surface as `stock.stl` (`run --export-stock`; not a
    /// job-file key).
    pub export_stock: bool,
    /// Also write the tool paths as `toolpaths.gltf` (`run --export-paths`; not a job-file
    /// key).
    pub export_paths: bool,
    /// The tools (inline `[[tools]]` or a tool file).
    pub tools: Vec<Tool>,
    /// The operations in machining order (kinds checked against the registry the job was
    /// parsed with, and each built once so its parameters are checked).
    pub operations: Vec<OperationSpec>,
    /// The coolant of each operation (`[operations.process] coolant`), in the order of
    /// `operations`; steps (a pilot drill) run with their operation's.
    pub coolant: Vec<gcode_emit::Coolant>,
    /// CL files to post-process and verify.
    pub cl_files: Vec<PathBuf>,
    /// The job text and file, to name the line of a key in errors found after parsing.
    pub source: Option<JobSource>,
    embedded: &'static [(&'static str, &'static str)],
}

/// The text a job was parsed from.
#[derive(Debug, Clone)]
pub struct JobSource {
    /// The job file.
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

impl JobSource {
    /// `file:line` of the key at dotted `key` inside operation `index` (the deepest part of
    /// the path that exists; the operation's own line otherwise).
    pub fn operation_place(&self, index: usize, key: &str) -> String {
        let mut path = vec![Seg::Key("operations".into()), Seg::Index(index)];
        path.extend(key_path(key));
        let line = line_of(&self.text, &path).unwrap_or(0);
        format!("{}:{line}", self.path.display())
    }
}

/// The safety surface of the job's linking moves.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SafetySpec {
    /// Clearance of the safety surface over the blank's radius and top (mm, > 0).
    pub clearance_mm: f64,
}

impl Default for SafetySpec {
    fn default() -> Self {
        Self {
            clearance_mm: cam_plan::linking::DEFAULT_SAFETY_CLEARANCE_MM,
        }
    }
}

/// The stock a job's operations start from (`[stock]`).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StockStart {
    /// `"blank"` (the impeller file's blank, default) or `"turned"`: the blank after the
    /// turning steps of a turn-mill process plan (paper 003, Table 1, steps 1–3: facing,
    /// rough and finish turning of the outside contour), i.e. faced at the design's top and
    /// turned to the shroud contour over the blades' axial extent and to the hub beyond it,
    /// plus `turning_allowance_mm`
    /// (`impeller_model::Impeller::turned_stock`).
    pub start: StockStartKind,
    /// Material the turning leaves over the shroud contour and the top (mm, ≥ 0; default 0:
    /// finish-turned blade tips).
    pub turning_allowance_mm: f64,
}

/// Which stock a job starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StockStartKind {
    /// The impeller file's blank.
    #[default]
    Blank,
    /// The blank faced and turned to the shroud contour.
    Turned,
}

impl Default for StockStart {
    fn default() -> Self {
        Self {
            start: StockStartKind::Blank,
            turning_allowance_mm: 0.0,
        }
    }
}

/// Post-processing settings of a job (`[post]`).
#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PostSpec {
    /// Remove reverse motions of the rotary axes in imported CL data too (default `false`:
    /// they are only counted). The smoothing turns a ball end about its centre (from the
    /// file's `CUTTER` record), which keeps the contact only where the other CAM system put
    /// the contact on the ball; opt in when that holds.
    pub smooth_imported_cl: bool,
}

/// Verification settings of a job.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VerificationSpec {
    /// Run the stock simulation.
    pub enabled: bool,
    /// Dexel spacing (mm).
    pub resolution_mm: f64,
    /// How many of the deepest dexel overcut samples are re-measured on the exact swept
    /// envelopes of the tool paths (`machining_sim::crosscheck_overcut`; 0: none).
    pub crosscheck: usize,
    /// Keep the program when verification finds defects (`run --allow-defects`; not a
    /// job-file key).
    #[serde(skip)]
    pub allow_defects: bool,
}

impl Default for VerificationSpec {
    fn default() -> Self {
        Self {
            enabled: true,
            resolution_mm: 0.1,
            crosscheck: 20,
            allow_defects: false,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJob {
    name: Option<String>,
    impeller: Option<PathBuf>,
    machine: Option<PathBuf>,
    #[serde(default = "default_dialect")]
    dialect: String,
    #[serde(default)]
    tolerances: Option<RawTolerances>,
    #[serde(default)]
    safety: SafetySpec,
    #[serde(default)]
    stock: StockStart,
    #[serde(default)]
    verification: VerificationSpec,
    #[serde(default)]
    post: PostSpec,
    #[serde(default)]
    tools: Option<ToolsField>,
    #[serde(default)]
    operations: Vec<RawOperation>,
    #[serde(default)]
    cl_files: Vec<RawClFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTolerances {
    chord_tol: Option<f64>,
    machining_tol: Option<f64>,
    linearisation_tol: Option<f64>,
    stock_allowance: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawClFile {
    path: PathBuf,
}

/// A tool file: its `[[tools]]` tables.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawToolFile {
    tools: Vec<RawTool>,
}

/// `tools = "file.toml"` or `[[tools]]`.
#[derive(Debug)]
enum ToolsField {
    File(PathBuf),
    Inline(Vec<RawTool>),
}

impl<'de> Deserialize<'de> for ToolsField {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ToolsField;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a tool file name or an array of [[tools]] tables")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<ToolsField, E> {
                Ok(ToolsField::File(PathBuf::from(v)))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ToolsField, A::Error> {
                let mut tools = Vec::new();
                while let Some(t) = seq.next_element::<RawTool>()? {
                    tools.push(t);
                }
                Ok(ToolsField::Inline(tools))
            }
        }
        d.deserialize_any(V)
    }
}

/// Cutter shape names of the job file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum ShapeName {
    FlatEnd,
    BallEnd,
    BullNose,
    TaperedBallEnd,
    TaperedFlatEnd,
}

impl ShapeName {
    fn as_str(self) -> &'static str {
        match self {
            Self::FlatEnd => "flat_end",
            Self::BallEnd => "ball_end",
            Self::BullNose => "bull_nose",
            Self::TaperedBallEnd => "tapered_ball_end",
            Self::TaperedFlatEnd => "tapered_flat_end",
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTool {
    number: u32,
    name: String,
    shape: ShapeName,
    diameter_mm: Option<f64>,
    corner_radius_mm: Option<f64>,
    ball_radius_mm: Option<f64>,
    tip_diameter_mm: Option<f64>,
    half_angle_deg: Option<f64>,
    flute_length_mm: f64,
    shank_diameter_mm: f64,
    stick_out_mm: f64,
    tool_length_mm: f64,
    teeth: u32,
    plunge_edge_length_mm: Option<f64>,
    #[serde(default)]
    holder: Vec<RawHolder>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHolder {
    bottom_diameter_mm: f64,
    top_diameter_mm: f64,
    length_mm: f64,
}

/// The process row as written: allowances may be absent (then `stock_allowance` applies).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProcess {
    spindle_rpm: f64,
    feed_per_tooth_mm: f64,
    plunge_feed_per_tooth_mm: Option<f64>,
    depth_of_cut_mm: Option<f64>,
    width_of_cut_mm: Option<f64>,
    blade_allowance_mm: Option<f64>,
    hub_allowance_mm: Option<f64>,
    rapid_mm_per_min: Option<f64>,
    #[serde(default)]
    coolant: RawCoolant,
}

/// `coolant = "flood" | "mist" | "through" | "off"` of a process row (default off); the
/// machine file's `[program.coolant]` gives each one's M code.
#[derive(Debug, Default, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum RawCoolant {
    Flood,
    Mist,
    Through,
    #[default]
    Off,
}

impl From<RawCoolant> for gcode_emit::Coolant {
    fn from(c: RawCoolant) -> Self {
        match c {
            RawCoolant::Flood => Self::Flood,
            RawCoolant::Mist => Self::Mist,
            RawCoolant::Through => Self::ThroughTool,
            RawCoolant::Off => Self::Off,
        }
    }
}

/// One `[[operations]]` table: the common keys typed, the kind's own keys kept as TOML.
#[derive(Debug, Default)]
struct RawOperation {
    name: Option<String>,
    kind: Option<String>,
    tool: Option<String>,
    process: Option<RawProcess>,
    params: toml::Table,
}

impl<'de> Deserialize<'de> for RawOperation {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawOperation;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("an [[operations]] table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawOperation, A::Error> {
                let mut op = RawOperation::default();
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "name" => op.name = Some(map.next_value()?),
                        "kind" => op.kind = Some(map.next_value()?),
                        "tool" => op.tool = Some(map.next_value()?),
                        "process" => op.process = Some(map.next_value()?),
                        _ => {
                            let v: toml::Value = map.next_value()?;
                            op.params.insert(key, v);
                        }
                    }
                }
                Ok(op)
            }
        }
        d.deserialize_map(V)
    }
}

fn default_dialect() -> String {
    "linuxcnc".into()
}

/// One step of a key path: a table key or an array index.
#[derive(Debug, Clone, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// `a.b[2].c` → segments.
fn key_path(key: &str) -> Vec<Seg> {
    let mut out = Vec::new();
    for part in key.split('.').filter(|p| !p.is_empty()) {
        let mut rest = part;
        if let Some(i) = rest.find('[') {
            out.push(Seg::Key(rest[..i].to_string()));
            rest = &rest[i..];
            while let Some(end) = rest.find(']') {
                if let Ok(n) = rest[1..end].parse() {
                    out.push(Seg::Index(n));
                }
                rest = &rest[end + 1..];
                if !rest.starts_with('[') {
                    break;
                }
            }
        } else {
            out.push(Seg::Key(rest.to_string()));
        }
    }
    out
}

fn line_at(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// The line of the deepest existing element of `path` in `text` (1-based), `None` when the
/// document does not parse or not even the first key exists.
fn line_of(text: &str, path: &[Seg]) -> Option<usize> {
    use toml::de::{DeTable, DeValue};
    let doc = DeTable::parse(text).ok()?;
    let mut table: Option<&DeTable<'_>> = Some(doc.get_ref());
    let mut value: Option<&DeValue<'_>> = None;
    let mut best = None;
    for seg in path {
        match seg {
            Seg::Key(k) => {
                let t = table.take()?;
                let Some((key, v)) = t.iter().find(|(key, _)| key.get_ref() == k) else {
                    return best;
                };
                best = Some(line_at(text, key.span().start));
                value = Some(v.get_ref());
                table = v.get_ref().as_table();
            }
            Seg::Index(i) => {
                let Some(e) = value.and_then(|v| v.as_array()).and_then(|a| a.get(*i)) else {
                    return best;
                };
                // An array-of-tables element: the line of its first key (the header is the
                // line above), else the element itself.
                best = Some(match e.get_ref().as_table() {
                    Some(t) => t
                        .iter()
                        .map(|(k, _)| line_at(text, k.span().start))
                        .min()
                        .unwrap_or_else(|| line_at(text, e.span().start)),
                    None => line_at(text, e.span().start),
                });
                value = Some(e.get_ref());
                table = e.get_ref().as_table();
            }
        }
    }
    best
}

/// The dotted path of the innermost key whose key or value contains byte `offset`
/// (`operations[0].process.spindle_rpm`): every key of the document with the spans of the
/// key and of its value, the smallest span containing the offset wins. O(document size).
fn path_at(text: &str, offset: usize) -> Option<String> {
    use toml::de::{DeTable, DeValue};
    type Spans = Vec<(String, std::ops::Range<usize>)>;
    fn walk_value(v: &DeValue<'_>, path: &str, out: &mut Spans) {
        match v {
            DeValue::Table(t) => walk_table(t, path, out),
            DeValue::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    let p = format!("{path}[{i}]");
                    out.push((p.clone(), e.span()));
                    walk_value(e.get_ref(), &p, out);
                }
            }
            _ => {}
        }
    }
    fn walk_table(t: &DeTable<'_>, path: &str, out: &mut Spans) {
        for (k, v) in t.iter() {
            let p = if path.is_empty() {
                k.get_ref().to_string()
            } else {
                format!("{path}.{}", k.get_ref())
            };
            out.push((p.clone(), k.span()));
            if !matches!(v.get_ref(), DeValue::Table(_)) {
                out.push((p.clone(), v.span()));
            }
            walk_value(v.get_ref(), &p, out);
        }
    }
    let doc = DeTable::parse(text).ok()?;
    let mut spans = Spans::new();
    walk_table(doc.get_ref(), "", &mut spans);
    spans
        .into_iter()
        .filter(|(_, r)| r.start <= offset && offset < r.end.max(r.start + 1))
        .min_by_key(|(_, r)| r.end - r.start)
        .map(|(p, _)| p)
}

/// `file:line: key: reason`.
fn at(file: &Path, line: Option<usize>, key: &str, reason: impl std::fmt::Display) -> CliError {
    CliError::Message(format!(
        "{}:{}: {key}: {reason}",
        file.display(),
        line.unwrap_or(0)
    ))
}

/// A TOML (syntax or serde) error of `text` read from `file`, with the line and the key.
fn toml_error(file: &Path, text: &str, e: &toml::de::Error) -> CliError {
    let message = e.message().trim();
    let Some(span) = e.span() else {
        return CliError::Message(format!("{}: {message}", file.display()));
    };
    let line = line_at(text, span.start);
    if message == "duplicate key" {
        if let Some(hint) = duplicate_table_hint(text, line) {
            return CliError::Message(format!("{}:{line}: {hint}", file.display()));
        }
    }
    // The key: the dotted path at the error's position, completed by the key serde names
    // (an unknown or missing field) when that one is not already its last element.
    let mut key = path_at(text, span.start).unwrap_or_default();
    if let Some(named) = cam_plan::params::field_key(message) {
        if !key.ends_with(&named) {
            if !key.is_empty() {
                key.push('.');
            }
            key.push_str(&named);
        }
    }
    if key.is_empty() {
        CliError::Message(format!("{}:{line}: {message}", file.display()))
    } else {
        CliError::Message(format!("{}:{line}: {key}: {message}", file.display()))
    }
}

/// What a `duplicate key` at a table header on `line` means: the same `[a.b]` table twice,
/// most often a row table written under a singular name (`[operation.process]` after each
/// `[[operations]]`, which TOML reads as one top-level `operation` table defined again),
/// with the array-of-tables spelling the job format uses when there is one.
fn duplicate_table_hint(text: &str, line: usize) -> Option<String> {
    let header = text.lines().nth(line.checked_sub(1)?)?.trim();
    let name = header
        .strip_prefix('[')?
        .split(']')
        .next()?
        .trim()
        .trim_start_matches('[')
        .trim();
    if name.is_empty() {
        return None;
    }
    let first = name.split('.').next().unwrap_or(name).trim();
    let first_line = text
        .lines()
        .position(|l| {
            let l = l.trim();
            l.starts_with('[')
                && l.trim_start_matches('[').split(']').next().map(str::trim) == Some(name)
        })
        .map_or(0, |k| k + 1);
    let mut hint = format!(
        "the table `[{name}]` is defined again (first at line {first_line}): TOML allows a \
         table once"
    );
    const ROWS: [&str; 3] = ["operations", "tools", "cl_files"];
    if let Some(row) = ROWS.iter().find(|r| **r == format!("{first}s")) {
        let rest = name.strip_prefix(first).unwrap_or("");
        hint.push_str(&format!(
            "; the table of each `[[{row}]]` entry is written `[{row}{rest}]` (not `[{name}]`)"
        ));
    }
    Some(hint)
}

fn check_positive(
    file: &Path,
    text: &str,
    path: &[Seg],
    key: &str,
    v: f64,
) -> Result<(), CliError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(at(
            file,
            line_of(text, path),
            key,
            format!("{v} must be finite and > 0"),
        ))
    }
}

impl RawTool {
    /// The `cam_plan::Tool` of this table (diameters → radii, degrees → radians). Errors name
    /// `file`, the line and the key (`tools[i].key`).
    fn into_tool(self, file: &Path, text: &str, index: usize) -> Result<Tool, CliError> {
        let here = |key: &str| {
            let mut p = vec![Seg::Key("tools".into()), Seg::Index(index)];
            p.extend(key_path(key));
            p
        };
        let err = |key: &str, reason: String| {
            at(
                file,
                line_of(text, &here(key)),
                &format!("tools[{index}].{key}"),
                format!("tool \"{}\": {reason}", self.name),
            )
        };
        let pos = |key: &str, v: f64| {
            check_positive(file, text, &here(key), &format!("tools[{index}].{key}"), v)
        };
        let need = |key: &str, v: Option<f64>| -> Result<f64, CliError> {
            let v =
                v.ok_or_else(|| err(key, format!("shape {} needs {key}", self.shape.as_str())))?;
            pos(key, v)?;
            Ok(v)
        };
        let angle = |key: &str, v: Option<f64>| -> Result<f64, CliError> {
            let v =
                v.ok_or_else(|| err(key, format!("shape {} needs {key}", self.shape.as_str())))?;
            if !(v.is_finite() && (0.0..90.0).contains(&v)) {
                return Err(err(key, format!("{v} must be in [0, 90) degrees")));
            }
            Ok(v.to_radians())
        };
        // Keys the shape does not use are errors: every accepted key is used.
        let used: &[&str] = match self.shape {
            ShapeName::FlatEnd | ShapeName::BallEnd => &["diameter_mm"],
            ShapeName::BullNose => &["diameter_mm", "corner_radius_mm"],
            ShapeName::TaperedBallEnd => &["ball_radius_mm", "half_angle_deg"],
            ShapeName::TaperedFlatEnd => &["tip_diameter_mm", "half_angle_deg"],
        };
        for (key, v) in [
            ("diameter_mm", self.diameter_mm),
            ("corner_radius_mm", self.corner_radius_mm),
            ("ball_radius_mm", self.ball_radius_mm),
            ("tip_diameter_mm", self.tip_diameter_mm),
            ("half_angle_deg", self.half_angle_deg),
        ] {
            if v.is_some() && !used.contains(&key) {
                return Err(err(
                    key,
                    format!("not a dimension of shape {}", self.shape.as_str()),
                ));
            }
        }
        let shape = match self.shape {
            ShapeName::FlatEnd => CutterShape::FlatEnd {
                radius: 0.5 * need("diameter_mm", self.diameter_mm)?,
            },
            ShapeName::BallEnd => CutterShape::BallEnd {
                radius: 0.5 * need("diameter_mm", self.diameter_mm)?,
            },
            ShapeName::BullNose => CutterShape::BullNose {
                radius: 0.5 * need("diameter_mm", self.diameter_mm)?,
                corner_radius: need("corner_radius_mm", self.corner_radius_mm)?,
            },
            ShapeName::TaperedBallEnd => CutterShape::TaperedBallEnd {
                ball_radius: need("ball_radius_mm", self.ball_radius_mm)?,
                half_angle: angle("half_angle_deg", self.half_angle_deg)?,
            },
            ShapeName::TaperedFlatEnd => CutterShape::TaperedFlatEnd {
                tip_radius: 0.5 * need("tip_diameter_mm", self.tip_diameter_mm)?,
                half_angle: angle("half_angle_deg", self.half_angle_deg)?,
            },
        };
        if let Some(e) = self.plunge_edge_length_mm {
            if !matches!(self.shape, ShapeName::FlatEnd | ShapeName::BullNose) {
                return Err(err(
                    "plunge_edge_length_mm",
                    format!(
                        "only flat_end and bull_nose plunge cutters have one, not {}",
                        self.shape.as_str()
                    ),
                ));
            }
            pos("plunge_edge_length_mm", e)?;
        }
        pos("flute_length_mm", self.flute_length_mm)?;
        pos("shank_diameter_mm", self.shank_diameter_mm)?;
        pos("stick_out_mm", self.stick_out_mm)?;
        pos("tool_length_mm", self.tool_length_mm)?;
        let mut holder = Vec::with_capacity(self.holder.len());
        for (j, h) in self.holder.iter().enumerate() {
            for (key, v) in [
                ("bottom_diameter_mm", h.bottom_diameter_mm),
                ("top_diameter_mm", h.top_diameter_mm),
                ("length_mm", h.length_mm),
            ] {
                pos(&format!("holder[{j}].{key}"), v)?;
            }
            holder.push(HolderSegment {
                bottom_radius: 0.5 * h.bottom_diameter_mm,
                top_radius: 0.5 * h.top_diameter_mm,
                length: h.length_mm,
            });
        }
        let tool = Tool {
            number: self.number,
            cutter: Cutter {
                name: self.name.clone(),
                shape,
                flute_length: self.flute_length_mm,
                shank_radius: 0.5 * self.shank_diameter_mm,
                overall_length: self.stick_out_mm,
                holder,
            },
            teeth: self.teeth,
            tool_length_mm: self.tool_length_mm,
            plunge_edge_length_mm: self.plunge_edge_length_mm,
        };
        if let Err(e) = tool.validate() {
            // Name the job key the cross-check is about.
            let reason = match &e {
                PlanError::Tool { reason, .. } => reason.clone(),
                other => other.to_string(),
            };
            let key = [
                ("tool_length_mm", "tool_length_mm"),
                ("plunge_edge_length_mm", "plunge_edge_length_mm"),
                ("teeth", "teeth"),
                ("flute_length", "flute_length_mm"),
                ("corner_radius", "corner_radius_mm"),
            ]
            .iter()
            .find(|(needle, _)| reason.contains(needle))
            .map_or("name", |(_, key)| key);
            return Err(err(key, reason));
        }
        Ok(tool)
    }
}

impl Job {
    /// The embedded default job: `fixtures/impeller-8+8/job.toml` with its impeller, machine,
    /// tool file and CL files embedded in the binary.
    pub fn default_job() -> Result<Self, CliError> {
        Self::default_job_with(registry::OPERATIONS)
    }

    /// [`Job::default_job`] with kinds from `registry`.
    pub fn default_job_with(registry: &Registry) -> Result<Self, CliError> {
        let mut job = Self::parse(
            DEFAULT_JOB_TOML,
            Path::new(EMBEDDED_JOB_PATH),
            EMBEDDED_FILES,
            registry,
        )?;
        if job.name.is_empty() {
            job.name = DEFAULT_JOB_NAME.into();
        }
        Ok(job)
    }

    /// Reads and validates a job file. Errors name the file, the line and the key.
    pub fn from_file(path: &Path) -> Result<Self, CliError> {
        Self::from_file_with(path, registry::OPERATIONS)
    }

    /// [`Job::from_file`] with kinds from `registry`.
    pub fn from_file_with(path: &Path, registry: &Registry) -> Result<Self, CliError> {
        let text = std::fs::read_to_string(path).map_err(|source| CliError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str_with(&text, path, registry)
    }

    /// Parses job text; `path` locates relative paths and names the file in errors.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Self, CliError> {
        Self::from_toml_str_with(text, path, registry::OPERATIONS)
    }

    /// [`Job::from_toml_str`] with kinds from `registry`.
    pub fn from_toml_str_with(
        text: &str,
        path: &Path,
        registry: &Registry,
    ) -> Result<Self, CliError> {
        Self::parse(text, path, &[], registry)
    }

    /// The text of `path`: an embedded file of the default job, or the file on disk.
    pub fn read_text(&self, path: &Path) -> Result<String, CliError> {
        read_text(self.embedded, path)
    }

    /// Whether `path` is one of the files embedded in the binary (the default job's).
    pub fn is_embedded(&self, path: &Path) -> bool {
        embedded(self.embedded, path).is_some()
    }

    fn parse(
        text: &str,
        path: &Path,
        files: &'static [(&'static str, &'static str)],
        registry: &Registry,
    ) -> Result<Self, CliError> {
        let raw: RawJob = toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let resolve = |p: PathBuf| if p.is_absolute() { p } else { dir.join(p) };
        let top = |key: &str| vec![Seg::Key(key.into())];

        // Tolerances.
        let mut tolerances = Tolerances::default();
        if let Some(t) = &raw.tolerances {
            tolerances.chord_tol = t.chord_tol.unwrap_or(tolerances.chord_tol);
            tolerances.machining_tol = t.machining_tol.unwrap_or(tolerances.machining_tol);
            tolerances.linearisation_tol =
                t.linearisation_tol.unwrap_or(tolerances.linearisation_tol);
            tolerances.stock_allowance = t.stock_allowance.unwrap_or(tolerances.stock_allowance);
        }
        if let Err(e) = tolerances.validate() {
            let field = match &e {
                cam_core::CamError::NonPositive { field, .. } => *field,
                _ => "",
            };
            let line = line_of(
                text,
                &[Seg::Key("tolerances".into()), Seg::Key(field.into())],
            );
            return Err(at(path, line, &format!("tolerances.{field}"), e));
        }
        check_positive(
            path,
            text,
            &[Seg::Key("safety".into()), Seg::Key("clearance_mm".into())],
            "safety.clearance_mm",
            raw.safety.clearance_mm,
        )?;
        let ta = raw.stock.turning_allowance_mm;
        if !(ta.is_finite() && ta >= 0.0) {
            let line = line_of(
                text,
                &[
                    Seg::Key("stock".into()),
                    Seg::Key("turning_allowance_mm".into()),
                ],
            );
            return Err(at(
                path,
                line,
                "stock.turning_allowance_mm",
                format!("must be a number >= 0, got {ta}"),
            ));
        }
        let v = raw.verification;
        check_positive(
            path,
            text,
            &[
                Seg::Key("verification".into()),
                Seg::Key("resolution_mm".into()),
            ],
            "verification.resolution_mm",
            v.resolution_mm,
        )?;

        check_files(&raw, path, text, files, &resolve)?;

        // Tools.
        let tools: Vec<Tool> = match raw.tools {
            None => Vec::new(),
            Some(ToolsField::Inline(list)) => list
                .into_iter()
                .enumerate()
                .map(|(i, t)| t.into_tool(path, text, i))
                .collect::<Result<_, _>>()?,
            Some(ToolsField::File(p)) => {
                let file = resolve(p);
                let tool_text = read_text(files, &file)
                    .map_err(|e| at(path, line_of(text, &top("tools")), "tools", e))?;
                let raw: RawToolFile =
                    toml::from_str(&tool_text).map_err(|e| toml_error(&file, &tool_text, &e))?;
                raw.tools
                    .into_iter()
                    .enumerate()
                    .map(|(i, t)| t.into_tool(&file, &tool_text, i))
                    .collect::<Result<_, _>>()?
            }
        };
        for (i, t) in tools.iter().enumerate() {
            for u in &tools[..i] {
                if u.name() == t.name() || u.number == t.number {
                    return Err(CliError::Message(format!(
                        "tools[{i}]: tool \"{}\" (T{}) repeats the name or number of tool \"{}\" (T{})",
                        t.name(),
                        t.number,
                        u.name(),
                        u.number
                    )));
                }
            }
        }

        // Operations.
        let stock_allowance = tolerances.stock_allowance;
        let mut operations: Vec<OperationSpec> = Vec::with_capacity(raw.operations.len());
        let mut coolant = Vec::with_capacity(raw.operations.len());
        for (i, op) in raw.operations.into_iter().enumerate() {
            let here = |key: &str| {
                let mut p = vec![Seg::Key("operations".into()), Seg::Index(i)];
                p.extend(key_path(key));
                line_of(text, &p)
            };
            let missing = |key: &str| {
                at(
                    path,
                    here(""),
                    &format!("operations[{i}].{key}"),
                    "missing key",
                )
            };
            let name = op.name.ok_or_else(|| missing("name"))?;
            let kind = op.kind.ok_or_else(|| missing("kind"))?;
            let tool = op.tool.ok_or_else(|| missing("tool"))?;
            let p = op.process.ok_or_else(|| missing("process"))?;
            let key = |k: &str| format!("operations[{i}].{k}");
            if operations.iter().any(|o| o.name == name) {
                return Err(at(
                    path,
                    here("name"),
                    &key("name"),
                    format!("operation name \"{name}\" is used twice"),
                ));
            }
            if !tools.iter().any(|t| t.name() == tool) {
                let names: Vec<&str> = tools.iter().map(Tool::name).collect();
                return Err(at(
                    path,
                    here("tool"),
                    &key("tool"),
                    format!(
                        "operation \"{name}\": unknown tool \"{tool}\" (tools: {})",
                        if names.is_empty() {
                            "none".into()
                        } else {
                            names.join(", ")
                        }
                    ),
                ));
            }
            coolant.push(p.coolant.into());
            let process = Process {
                spindle_rpm: p.spindle_rpm,
                feed_per_tooth_mm: p.feed_per_tooth_mm,
                plunge_feed_per_tooth_mm: p.plunge_feed_per_tooth_mm,
                depth_of_cut_mm: p.depth_of_cut_mm,
                width_of_cut_mm: p.width_of_cut_mm,
                blade_allowance_mm: p.blade_allowance_mm.unwrap_or(stock_allowance),
                hub_allowance_mm: p.hub_allowance_mm.unwrap_or(stock_allowance),
                rapid_mm_per_min: p
                    .rapid_mm_per_min
                    .unwrap_or(cam_plan::process::DEFAULT_RAPID_MM_PER_MIN),
            };
            let spec = OperationSpec {
                name,
                kind,
                tool,
                process,
                params: op.params,
            };
            let located = |e: PlanError| match &e {
                PlanError::Param { key: k, .. } => at(path, here(k), &key(k), &e),
                PlanError::UnknownKind { .. } => at(path, here("kind"), &key("kind"), &e),
                _ => at(path, here("name"), &key("name"), &e),
            };
            spec.process.validate(&spec.name).map_err(located)?;
            let built = registry::build(registry, &spec).map_err(located)?;
            // Further tools the operation plans steps with (a pilot drill) are job tools.
            for st in built.step_tools() {
                if !tools.iter().any(|t| t.name() == st.tool) {
                    let names: Vec<&str> = tools.iter().map(Tool::name).collect();
                    return Err(located(PlanError::param(
                        &spec.name,
                        &st.key,
                        format!(
                            "unknown tool \"{}\" (tools: {})",
                            st.tool,
                            if names.is_empty() {
                                "none".into()
                            } else {
                                names.join(", ")
                            }
                        ),
                    )));
                }
            }
            operations.push(spec);
        }

        // A job with neither operations nor CL files used to run `0 operation(s)` and exit 0.
        if operations.is_empty() && raw.cl_files.is_empty() {
            return Err(at(
                path,
                None,
                "operations",
                "no operations: the job has no [[operations]] and no [[cl_files]], nothing to machine",
            ));
        }
        let name = raw.name.unwrap_or_else(|| {
            path.parent()
                .and_then(|p| p.file_name())
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "job".into())
        });
        Ok(Self {
            name,
            impeller: raw.impeller.map(resolve),
            machine: raw.machine.map(resolve),
            dialect: raw.dialect,
            tolerances,
            safety: raw.safety,
            stock: raw.stock,
            verification: v,
            post: raw.post,
            quiet: false,
            export_stock: false,
            export_paths: false,
            tools,
            operations,
            coolant,
            cl_files: raw.cl_files.into_iter().map(|c| resolve(c.path)).collect(),
            source: Some(JobSource {
                path: path.to_path_buf(),
                text: text.to_string(),
            }),
            embedded: files,
        })
    }

    /// The tool named `name`.
    pub fn tool(&self, name: &str) -> Option<&Tool> {
        self.tools.iter().find(|t| t.name() == name)
    }

    /// An error of operation `index` at its dotted `key`, as `file:line: key: reason`.
    pub fn operation_error(&self, index: usize, e: &PlanError) -> CliError {
        let key = match e {
            PlanError::Param { key, .. } => key.as_str(),
            _ => "",
        };
        match &self.source {
            Some(s) => CliError::Message(format!(
                "{}: operations[{index}]{}{key}: {e}",
                s.operation_place(index, key),
                if key.is_empty() { "" } else { "." }
            )),
            None => CliError::Message(e.to_string()),
        }
    }
}

/// The job's other inputs, checked before anything runs (an unknown dialect used to be found
/// after planning, leaving `toolpath.cls` behind): the dialect name; the impeller, machine
/// and CL files readable; the machine file valid (kinematics, limits and its `[program]`
/// frame, errors naming the machine file's line and key).
fn check_files(
    raw: &RawJob,
    path: &Path,
    text: &str,
    files: &'static [(&'static str, &'static str)],
    resolve: &dyn Fn(PathBuf) -> PathBuf,
) -> Result<(), CliError> {
    let top = |key: &str| line_of(text, &[Seg::Key(key.into())]);
    gcode_emit::dialect_by_name(&raw.dialect)
        .map_err(|e| at(path, top("dialect"), "dialect", e))?;
    if let Some(p) = &raw.impeller {
        read_text(files, &resolve(p.clone()))
            .map_err(|e| at(path, top("impeller"), "impeller", e))?;
    }
    if let Some(p) = &raw.machine {
        let file = resolve(p.clone());
        let machine =
            read_text(files, &file).map_err(|e| at(path, top("machine"), "machine", e))?;
        let name = file.display().to_string();
        let invalid = |e: &dyn std::fmt::Display| {
            at(
                path,
                top("machine"),
                "machine",
                format!("invalid machine file: {e}"),
            )
        };
        postproc_kinematics::Machine::from_toml_str(&machine, &name).map_err(|e| invalid(&e))?;
        gcode_emit::ProgramFrame::from_machine_toml(&machine, &name).map_err(|e| invalid(&e))?;
    }
    for (i, c) in raw.cl_files.iter().enumerate() {
        let line = line_of(
            text,
            &[
                Seg::Key("cl_files".into()),
                Seg::Index(i),
                Seg::Key("path".into()),
            ],
        );
        read_text(files, &resolve(c.path.clone()))
            .map_err(|e| at(path, line, &format!("cl_files[{i}].path"), e))?;
    }
    Ok(())
}

fn embedded(files: &'static [(&'static str, &'static str)], path: &Path) -> Option<&'static str> {
    files
        .iter()
        .find(|(p, _)| Path::new(p) == path)
        .map(|(_, t)| *t)
}

fn read_text(
    files: &'static [(&'static str, &'static str)],
    path: &Path,
) -> Result<String, CliError> {
    if let Some(t) = embedded(files, path) {
        return Ok(t.to_string());
    }
    std::fs::read_to_string(path).map_err(|source| CliError::Io {
        path: path.display().to_string(),
        source,
    })
}

#[cfg(test)]
mod tests;
