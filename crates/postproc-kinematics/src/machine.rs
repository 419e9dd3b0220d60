//! Machine descriptions: kinematic structure, axis travel and modes, home position; read from
//! TOML with validation errors that name the file, the line and the field.
//!
//! File format (all lengths mm, all angles degrees, speeds mm/min or deg/min):
//!
//! ```toml
//! name = "LinuxCNC xyzac-trt"
//! description = "..."        # optional
//! safe_z = 100.0              # optional: machine Z for retracts before reorientation
//! singularity_tol_deg = 1e-5  # optional: tool axis this close to C counts as singular
//! tool_change_s = 6.0         # optional: tool change time, chip to chip (s), for cycle time
//! blending = "parabolic"      # optional: "parabolic" (default, continuous path) | "exact_stop"
//! [kinematics]
//! type = "table-table"        # "table-table" | "head-table" | "head-head"
//! tilt_axis = "A"             # "A" (about X) or "B" (about Y); the other rotary axis is C (about Z)
//! x_rot_point = 0.0           # table-table / head-table: a point of the C axis (machine frame)
//! y_rot_point = 0.0
//! z_rot_point = 0.0
//! y_offset = 20.0             # table-table: tilt-axis centre relative to the C-axis centre
//! z_offset = 10.0
//! conventional_directions = false   # table-table, LinuxCNC meaning
//! # head-table / head-head: pivot_length, spindle_direction = [0,0,1], tilt_sign, rotary_sign
//! [workpiece]
//! origin = [0.0, 0.0, 0.0]    # workpiece-frame origin in the machine frame at zero rotary angles
//! [axes.X]
//! min = -200.0
//! max = 200.0
//! max_speed = 6000.0
//! max_acceleration = 300.0    # optional: mm/s² (linear) or deg/s² (rotary), for cycle time
//! # ... Y, Z likewise; rotary axes: mode = "limited" (min/max) or "continuous"
//! [home]                      # optional per axis (default 0, which must lie in the travel)
//! X = 0.0
//! # ...
//! [program]                   # optional: the controller's program frame, read by `gcode-emit`
//! # (kinematics switch, header/footer, coolant codes, block numbers); kept as given here
//! ```
//!
//! Unknown keys are rejected. Errors carry the file name, the 1-based line and the dotted
//! field path ([`MachineError`]).

use crate::error::MachineError;
use crate::joints::{AxisId, Joints};
use cam_core::{Point3, UnitVector3, Vector3};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

/// The tilting rotary axis: A rotates about X, B about Y.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TiltAxis {
    /// Rotation about the X direction.
    A,
    /// Rotation about the Y direction.
    B,
}

impl TiltAxis {
    /// Axis letter.
    pub fn letter(self) -> char {
        match self {
            TiltAxis::A => 'A',
            TiltAxis::B => 'B',
        }
    }
    /// Unit direction of the rotation axis.
    pub fn direction(self) -> Vector3 {
        match self {
            TiltAxis::A => Vector3::x(),
            TiltAxis::B => Vector3::y(),
        }
    }
}

/// Table-table (trunnion) machine compatible with LinuxCNC's `xyzac-trt` / `xyzbc-trt`
/// kinematics: the tilting table (A or B) carries the rotary table C; the spindle is vertical
/// (+Z). Parameters keep LinuxCNC's names, meaning and sign conventions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableTable {
    /// A (`xyzac-trt`) or B (`xyzbc-trt`).
    pub tilt_axis: TiltAxis,
    /// Centre of rotation of the C axis relative to machine zero (mm) — LinuxCNC
    /// `x-rot-point`, `y-rot-point`, `z-rot-point`.
    pub rot_point: Point3,
    /// Centre of rotation of the tilting axis relative to the C-axis centre (mm) — LinuxCNC
    /// `x-offset` (B only), `y-offset` (A only), `z-offset`.
    pub offset: Vector3,
    /// LinuxCNC `conventional-directions`: `false` (LinuxCNC's default) makes the world pose
    /// `P = rot_point + Rz(−c)·(offset + R(−a)·(J − rot_point − offset))`; `true` flips both
    /// rotation signs.
    pub conventional_directions: bool,
}

/// Head-table machine (e.g. a B-C turn-milling centre): the spindle head swivels about the
/// tilt axis with a pivot length, the table turns about C.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadTable {
    /// Swivel axis of the head (B in the published turn-mill case).
    pub tilt_axis: TiltAxis,
    /// Distance from the swivel pivot to the spindle gauge line (mm); the tool length adds to
    /// it.
    pub pivot_length: f64,
    /// Tool axis (tip → spindle) in the machine frame at zero head angle.
    pub spindle_direction: UnitVector3,
    /// A point of the C axis (machine frame at zero angles, mm).
    pub rot_point: Point3,
    /// `+1`: a positive head angle turns the tool axis right-handed about the tilt axis.
    pub tilt_sign: f64,
    /// `+1`: a positive C angle turns the tool orientation relative to the workpiece
    /// right-handed about +Z (i.e. the table itself turns left-handed, ISO 841); `−1` when the
    /// table itself turns right-handed for positive C.
    pub rotary_sign: f64,
}

/// Head-head machine: a fork head with a C axis about Z carrying the tilt axis (A or B), with
/// the pivot on the tilt axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadHead {
    /// Tilt axis of the fork.
    pub tilt_axis: TiltAxis,
    /// Distance from the tilt pivot to the spindle gauge line (mm).
    pub pivot_length: f64,
    /// Tool axis (tip → spindle) at zero angles.
    pub spindle_direction: UnitVector3,
    /// `+1`: a positive tilt angle turns the tool right-handed about the tilt axis.
    pub tilt_sign: f64,
    /// `+1`: a positive C angle turns the head right-handed about +Z.
    pub rotary_sign: f64,
}

/// Kinematic structure of the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kinematics {
    /// Trunnion table (LinuxCNC `xyzac-trt` / `xyzbc-trt`).
    TableTable(TableTable),
    /// Swivel head + rotary table.
    HeadTable(HeadTable),
    /// Fork head (C + A/B).
    HeadHead(HeadHead),
}

impl Kinematics {
    /// The tilt axis.
    pub fn tilt_axis(&self) -> TiltAxis {
        match self {
            Kinematics::TableTable(k) => k.tilt_axis,
            Kinematics::HeadTable(k) => k.tilt_axis,
            Kinematics::HeadHead(k) => k.tilt_axis,
        }
    }
    /// Kind name as in the file.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Kinematics::TableTable(_) => "table-table",
            Kinematics::HeadTable(_) => "head-table",
            Kinematics::HeadHead(_) => "head-head",
        }
    }
}

/// How a rotary axis may move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RotaryMode {
    /// Finite travel `[min, max]` (rad); a range wider than 360° is allowed.
    Limited {
        /// Lower limit (rad).
        min: f64,
        /// Upper limit (rad).
        max: f64,
    },
    /// Endless rotation: the inverse picks the equivalent angle nearest the previous one and
    /// the post-processor may unwind the axis on rapid moves.
    Continuous,
}

/// Travel, speed and acceleration of one axis (mm, mm/min, mm/s² for linear axes; rad,
/// rad/min, rad/s² for rotary axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSpec {
    /// Axis letter.
    pub letter: char,
    /// Travel.
    pub mode: RotaryMode,
    /// Largest speed (mm/min or rad/min); `None` = unlimited.
    pub max_speed: Option<f64>,
    /// Largest acceleration (mm/s² or rad/s²; LinuxCNC's `MAX_ACCELERATION`); `None` = not
    /// given (the cycle time then ignores this axis' acceleration and says so).
    pub max_acceleration: Option<f64>,
}

impl AxisSpec {
    /// Limits `(min, max)`, infinite for continuous axes.
    pub fn limits(&self) -> (f64, f64) {
        match self.mode {
            RotaryMode::Limited { min, max } => (min, max),
            RotaryMode::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
    /// `true` when `v` lies within the limits (with `slack`).
    pub fn contains(&self, v: f64, slack: f64) -> bool {
        let (lo, hi) = self.limits();
        v >= lo - slack && v <= hi + slack
    }
}

/// A validated five-axis machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    pub(crate) name: String,
    pub(crate) description: String,
    pub(crate) kinematics: Kinematics,
    pub(crate) workpiece_origin: Vector3,
    pub(crate) axes: [AxisSpec; 5],
    pub(crate) home: Joints,
    pub(crate) safe_z: Option<f64>,
    pub(crate) singularity_tol: f64,
    pub(crate) tool_change_s: Option<f64>,
    pub(crate) blending: Blending,
}

/// How the controller runs consecutive motion blocks (for the cycle time,
/// [`crate::cycle_time`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Blending {
    /// Continuous path (LinuxCNC `G64`): a block starts while the one before it decelerates
    /// (parabolic blending; LinuxCNC blends every move that turns a rotary axis this way),
    /// each block planned at half the acceleration limits so the overlap stays within them.
    #[default]
    Parabolic,
    /// Exact stop (`G61.1`): every block starts and ends at rest.
    ExactStop,
}

impl Machine {
    /// Reads and validates a machine file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, MachineError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| MachineError::Io {
            file: file.clone(),
            message: e.to_string(),
        })?;
        Self::from_toml_str(&text, &file)
    }

    /// Parses and validates a machine description; `file` names the source in errors.
    pub fn from_toml_str(text: &str, file: &str) -> Result<Self, MachineError> {
        let raw: RawMachine = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
            MachineError::Syntax {
                file: file.to_string(),
                line,
                column,
                message: e.message().trim().to_string(),
            }
        })?;
        Validator { text, file }.machine(raw)
    }

    /// Machine name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Free-text description.
    pub fn description(&self) -> &str {
        &self.description
    }
    /// Kinematic structure.
    pub fn kinematics(&self) -> &Kinematics {
        &self.kinematics
    }
    /// Workpiece-frame origin in the machine frame at zero rotary angles (mm).
    pub fn workpiece_origin(&self) -> Vector3 {
        self.workpiece_origin
    }
    /// Sets the workpiece-frame origin (mm) — the fixture offset of a job.
    pub fn set_workpiece_origin(&mut self, origin: Vector3) {
        self.workpiece_origin = origin;
    }
    /// Axis specification.
    pub fn axis(&self, axis: AxisId) -> &AxisSpec {
        &self.axes[axis_index(axis)]
    }
    /// Axis letter (X, Y, Z, A/B, C).
    pub fn letter(&self, axis: AxisId) -> char {
        self.axis(axis).letter
    }
    /// Home / safe position.
    pub fn home(&self) -> Joints {
        self.home
    }
    /// Machine Z (joint value, mm) to retract to before reorientations, if given.
    pub fn safe_z(&self) -> Option<f64> {
        self.safe_z
    }
    /// The safe retract height (machine Z, mm) a post must use, or an error naming the
    /// missing machine-file key `safe_z`: a post never invents one (machine Z0 may be the
    /// table on one machine and the top of travel on another).
    pub fn require_safe_z(&self) -> Result<f64, crate::PostError> {
        self.safe_z.ok_or_else(|| crate::PostError::InvalidOption {
            field: "safe_z",
            message: format!(
                "machine `{}` has no `safe_z` (the machine Z to retract to before tool \
                 changes and reorientations); add it to the machine file",
                self.name
            ),
        })
    }
    /// Angle (rad) between tool axis and C axis below which the pose counts as singular and
    /// the previous C is held.
    pub fn singularity_tol(&self) -> f64 {
        self.singularity_tol
    }
    /// Whether the tool axis `axis` (workpiece frame) lies within [`Self::singularity_tol`]
    /// of the C axis (the workpiece's ±Z), where C is free.
    pub fn is_singular(&self, axis: &UnitVector3) -> bool {
        axis.x.hypot(axis.y) < self.singularity_tol.sin()
    }
    /// Tool change time, chip to chip (s), when the file gives one (`tool_change_s`).
    pub fn tool_change_s(&self) -> Option<f64> {
        self.tool_change_s
    }
    /// How the controller runs consecutive motion blocks (`blending`).
    pub fn blending(&self) -> Blending {
        self.blending
    }
    /// Whether the tool length enters the kinematics: on head-table and head-head machines
    /// the head turns about a pivot above the spindle, so the gauge length (spindle gauge
    /// line to tip) moves the tip; on table-table machines the controller's tool length
    /// compensation takes it along the fixed spindle axis.
    pub fn tool_length_matters(&self) -> bool {
        !matches!(self.kinematics, Kinematics::TableTable(_))
    }

    /// The five axis words of a block for a program: letter and value, mm for linear axes,
    /// **degrees** for rotary axes, in order X Y Z tilt C.
    pub fn axis_words(&self, j: &Joints) -> [(char, f64); 5] {
        let v = j.to_array();
        std::array::from_fn(|i| {
            let a = AxisId::ALL[i];
            let val = if a.is_rotary() {
                v[i].to_degrees()
            } else {
                v[i]
            };
            (self.axes[i].letter, val)
        })
    }

    /// Checks every axis against its travel; the error names the first violated axis (values
    /// in mm / degrees). `slack` is in mm for linear axes and rad for rotary ones.
    pub fn check_limits(&self, j: &Joints, slack: f64) -> Result<(), crate::KinematicsError> {
        for a in AxisId::ALL {
            let spec = self.axis(a);
            let v = j.get(a);
            if !spec.contains(v, slack) {
                let (lo, hi) = spec.limits();
                let f = |x: f64| if a.is_rotary() { x.to_degrees() } else { x };
                return Err(crate::KinematicsError::OutOfLimits {
                    axis: spec.letter,
                    value: f(v),
                    min: f(lo),
                    max: f(hi),
                });
            }
        }
        Ok(())
    }
}

pub(crate) fn axis_index(a: AxisId) -> usize {
    match a {
        AxisId::X => 0,
        AxisId::Y => 1,
        AxisId::Z => 2,
        AxisId::Tilt => 3,
        AxisId::Rotate => 4,
    }
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let upto = &text[..offset.min(text.len())];
    let line = upto.matches('\n').count() + 1;
    let col = upto.rfind('\n').map_or(upto.len(), |p| upto.len() - p - 1) + 1;
    (line, col)
}

// ---------------------------------------------------------------------------------------
// Raw file structures (serde) and validation.

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMachine {
    name: String,
    #[serde(default)]
    description: String,
    kinematics: RawKinematics,
    #[serde(default)]
    workpiece: RawWorkpiece,
    axes: BTreeMap<Spanned<String>, RawAxis>,
    #[serde(default)]
    home: BTreeMap<Spanned<String>, Spanned<f64>>,
    safe_z: Option<Spanned<f64>>,
    singularity_tol_deg: Option<Spanned<f64>>,
    tool_change_s: Option<Spanned<f64>>,
    blending: Option<Spanned<String>>,
    /// The program frame (`gcode-emit` reads and checks it from the same file).
    #[serde(rename = "program")]
    _program: Option<toml::Table>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawWorkpiece {
    origin: Option<Spanned<[f64; 3]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawKinematics {
    #[serde(rename = "type")]
    kind: Spanned<String>,
    tilt_axis: Spanned<String>,
    x_rot_point: Option<Spanned<f64>>,
    y_rot_point: Option<Spanned<f64>>,
    z_rot_point: Option<Spanned<f64>>,
    x_offset: Option<Spanned<f64>>,
    y_offset: Option<Spanned<f64>>,
    z_offset: Option<Spanned<f64>>,
    conventional_directions: Option<Spanned<bool>>,
    pivot_length: Option<Spanned<f64>>,
    spindle_direction: Option<Spanned<[f64; 3]>>,
    tilt_sign: Option<Spanned<i64>>,
    rotary_sign: Option<Spanned<i64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxis {
    mode: Option<Spanned<String>>,
    min: Option<Spanned<f64>>,
    max: Option<Spanned<f64>>,
    max_speed: Option<Spanned<f64>>,
    max_acceleration: Option<Spanned<f64>>,
}

struct Validator<'a> {
    text: &'a str,
    file: &'a str,
}

impl Validator<'_> {
    fn err<T>(
        &self,
        span: Option<std::ops::Range<usize>>,
        field: &str,
        msg: impl Into<String>,
    ) -> Result<T, MachineError> {
        Err(MachineError::Invalid {
            file: self.file.to_string(),
            line: span.map_or(0, |s| line_col(self.text, s.start).0),
            field: field.to_string(),
            message: msg.into(),
        })
    }

    fn finite(&self, v: &Spanned<f64>, field: &str) -> Result<f64, MachineError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            self.err(Some(v.span()), field, "must be a finite number")
        }
    }

    fn opt_f(
        &self,
        v: &Option<Spanned<f64>>,
        field: &str,
        default: f64,
    ) -> Result<f64, MachineError> {
        match v {
            Some(s) => self.finite(s, field),
            None => Ok(default),
        }
    }

    fn forbid<T>(
        &self,
        v: &Option<Spanned<T>>,
        field: &str,
        kind: &str,
    ) -> Result<(), MachineError> {
        match v {
            Some(s) => self.err(
                Some(s.span()),
                field,
                format!("not used by kinematics type `{kind}`"),
            ),
            None => Ok(()),
        }
    }

    fn sign(&self, v: &Option<Spanned<i64>>, field: &str) -> Result<f64, MachineError> {
        match v {
            None => Ok(1.0),
            Some(s) => match *s.get_ref() {
                1 => Ok(1.0),
                -1 => Ok(-1.0),
                other => self.err(
                    Some(s.span()),
                    field,
                    format!("must be 1 or -1, got {other}"),
                ),
            },
        }
    }

    fn unit3(
        &self,
        v: &Option<Spanned<[f64; 3]>>,
        field: &str,
        default: Vector3,
    ) -> Result<UnitVector3, MachineError> {
        let Some(s) = v else {
            return Ok(UnitVector3::new_normalize(default));
        };
        let a = *s.get_ref();
        let w = Vector3::new(a[0], a[1], a[2]);
        let n = w.norm();
        if !(n.is_finite() && n > 1e-12) {
            return self.err(Some(s.span()), field, "must be a non-zero finite vector");
        }
        Ok(UnitVector3::new_unchecked(w / n))
    }

    fn kinematics(&self, k: &RawKinematics) -> Result<Kinematics, MachineError> {
        let tilt_axis = match k.tilt_axis.get_ref().as_str() {
            "A" | "a" => TiltAxis::A,
            "B" | "b" => TiltAxis::B,
            other => {
                return self.err(
                    Some(k.tilt_axis.span()),
                    "kinematics.tilt_axis",
                    format!("must be \"A\" or \"B\", got \"{other}\""),
                )
            }
        };
        let kind = k.kind.get_ref().as_str();
        let rot_point = || -> Result<Point3, MachineError> {
            Ok(Point3::new(
                self.opt_f(&k.x_rot_point, "kinematics.x_rot_point", 0.0)?,
                self.opt_f(&k.y_rot_point, "kinematics.y_rot_point", 0.0)?,
                self.opt_f(&k.z_rot_point, "kinematics.z_rot_point", 0.0)?,
            ))
        };
        let pivot = |kind: &str| -> Result<f64, MachineError> {
            match &k.pivot_length {
                None => self.err(
                    Some(k.kind.span()),
                    "kinematics.pivot_length",
                    format!("required for `{kind}`"),
                ),
                Some(s) => {
                    let v = self.finite(s, "kinematics.pivot_length")?;
                    if v < 0.0 {
                        self.err(Some(s.span()), "kinematics.pivot_length", "must be >= 0")
                    } else {
                        Ok(v)
                    }
                }
            }
        };
        match kind {
            "table-table" => {
                self.forbid(&k.pivot_length, "kinematics.pivot_length", kind)?;
                self.forbid(&k.spindle_direction, "kinematics.spindle_direction", kind)?;
                self.forbid(&k.tilt_sign, "kinematics.tilt_sign", kind)?;
                self.forbid(&k.rotary_sign, "kinematics.rotary_sign", kind)?;
                match tilt_axis {
                    TiltAxis::A => self.forbid(
                        &k.x_offset,
                        "kinematics.x_offset",
                        "table-table with tilt_axis A (xyzac-trt)",
                    )?,
                    TiltAxis::B => self.forbid(
                        &k.y_offset,
                        "kinematics.y_offset",
                        "table-table with tilt_axis B (xyzbc-trt)",
                    )?,
                }
                Ok(Kinematics::TableTable(TableTable {
                    tilt_axis,
                    rot_point: rot_point()?,
                    offset: Vector3::new(
                        self.opt_f(&k.x_offset, "kinematics.x_offset", 0.0)?,
                        self.opt_f(&k.y_offset, "kinematics.y_offset", 0.0)?,
                        self.opt_f(&k.z_offset, "kinematics.z_offset", 0.0)?,
                    ),
                    conventional_directions: k
                        .conventional_directions
                        .as_ref()
                        .is_some_and(|s| *s.get_ref()),
                }))
            }
            "head-table" | "head-head" => {
                self.forbid(&k.x_offset, "kinematics.x_offset", kind)?;
                self.forbid(&k.y_offset, "kinematics.y_offset", kind)?;
                self.forbid(&k.z_offset, "kinematics.z_offset", kind)?;
                self.forbid(
                    &k.conventional_directions,
                    "kinematics.conventional_directions",
                    kind,
                )?;
                let pivot_length = pivot(kind)?;
                let spindle_direction = self.unit3(
                    &k.spindle_direction,
                    "kinematics.spindle_direction",
                    Vector3::z(),
                )?;
                // The tilt must be able to change the tool axis' angle with Z.
                let kdir = tilt_axis.direction();
                let along = spindle_direction.dot(&kdir).abs();
                if along > 1.0 - 1e-9 {
                    return self.err(
                        k.spindle_direction.as_ref().map(|s| s.span()),
                        "kinematics.spindle_direction",
                        "must not be parallel to the tilt axis",
                    );
                }
                let tilt_sign = self.sign(&k.tilt_sign, "kinematics.tilt_sign")?;
                let rotary_sign = self.sign(&k.rotary_sign, "kinematics.rotary_sign")?;
                if kind == "head-table" {
                    Ok(Kinematics::HeadTable(HeadTable {
                        tilt_axis,
                        pivot_length,
                        spindle_direction,
                        rot_point: rot_point()?,
                        tilt_sign,
                        rotary_sign,
                    }))
                } else {
                    self.forbid(&k.x_rot_point, "kinematics.x_rot_point", kind)?;
                    self.forbid(&k.y_rot_point, "kinematics.y_rot_point", kind)?;
                    self.forbid(&k.z_rot_point, "kinematics.z_rot_point", kind)?;
                    Ok(Kinematics::HeadHead(HeadHead {
                        tilt_axis,
                        pivot_length,
                        spindle_direction,
                        tilt_sign,
                        rotary_sign,
                    }))
                }
            }
            other => self.err(
                Some(k.kind.span()),
                "kinematics.type",
                format!(
                    "must be \"table-table\", \"head-table\" or \"head-head\", got \"{other}\""
                ),
            ),
        }
    }

    fn axis(
        &self,
        letter: char,
        raw: Option<&RawAxis>,
        rotary: bool,
    ) -> Result<AxisSpec, MachineError> {
        let base = format!("axes.{letter}");
        let Some(raw) = raw else {
            return self.err(None, &base, "missing axis section");
        };
        let conv = |v: f64| if rotary { v.to_radians() } else { v };
        let max_speed = match &raw.max_speed {
            None => None,
            Some(s) => {
                let v = self.finite(s, &format!("{base}.max_speed"))?;
                if v <= 0.0 {
                    return self.err(Some(s.span()), &format!("{base}.max_speed"), "must be > 0");
                }
                Some(conv(v))
            }
        };
        let max_acceleration = match &raw.max_acceleration {
            None => None,
            Some(s) => {
                let field = format!("{base}.max_acceleration");
                let v = self.finite(s, &field)?;
                if v <= 0.0 {
                    return self.err(Some(s.span()), &field, "must be > 0");
                }
                Some(conv(v))
            }
        };
        let mode_name = raw
            .mode
            .as_ref()
            .map(|m| m.get_ref().as_str())
            .unwrap_or("limited");
        let mode = match mode_name {
            "continuous" if rotary => {
                if let Some(s) = raw.min.as_ref().or(raw.max.as_ref()) {
                    return self.err(
                        Some(s.span()),
                        &format!("{base}.min"),
                        "continuous axes have no limits",
                    );
                }
                RotaryMode::Continuous
            }
            "limited" => {
                let min = match &raw.min {
                    Some(s) => (self.finite(s, &format!("{base}.min"))?, s.span()),
                    None => {
                        return self.err(
                            None,
                            &format!("{base}.min"),
                            "required for a limited axis",
                        )
                    }
                };
                let max = match &raw.max {
                    Some(s) => (self.finite(s, &format!("{base}.max"))?, s.span()),
                    None => {
                        return self.err(
                            None,
                            &format!("{base}.max"),
                            "required for a limited axis",
                        )
                    }
                };
                if min.0 >= max.0 {
                    return self.err(
                        Some(max.1),
                        &format!("{base}.max"),
                        format!("must exceed min ({} >= {})", min.0, max.0),
                    );
                }
                RotaryMode::Limited {
                    min: conv(min.0),
                    max: conv(max.0),
                }
            }
            other => {
                let span = raw.mode.as_ref().map(|m| m.span());
                let allowed = if rotary {
                    "\"limited\" or \"continuous\""
                } else {
                    "\"limited\""
                };
                return self.err(
                    span,
                    &format!("{base}.mode"),
                    format!("must be {allowed}, got \"{other}\""),
                );
            }
        };
        Ok(AxisSpec {
            letter,
            mode,
            max_speed,
            max_acceleration,
        })
    }

    fn machine(&self, raw: RawMachine) -> Result<Machine, MachineError> {
        let kinematics = self.kinematics(&raw.kinematics)?;
        let tl = kinematics.tilt_axis().letter();
        let letters = ['X', 'Y', 'Z', tl, 'C'];
        for key in raw.axes.keys() {
            let name = key.get_ref();
            let ok = name.chars().count() == 1 && name.chars().all(|c| letters.contains(&c));
            if !ok {
                return self.err(
                    Some(key.span()),
                    &format!("axes.{name}"),
                    format!("unknown axis for this machine (expected X, Y, Z, {tl}, C)"),
                );
            }
        }
        let mut axes = [AxisSpec {
            letter: 'X',
            mode: RotaryMode::Continuous,
            max_speed: None,
            max_acceleration: None,
        }; 5];
        for (i, l) in letters.iter().enumerate() {
            axes[i] = self.axis(*l, raw.axes.get(l.to_string().as_str()), i >= 3)?;
        }
        let workpiece_origin = match &raw.workpiece.origin {
            None => Vector3::zeros(),
            Some(s) => {
                let a = *s.get_ref();
                if !a.iter().all(|v| v.is_finite()) {
                    return self.err(Some(s.span()), "workpiece.origin", "must be finite");
                }
                Vector3::new(a[0], a[1], a[2])
            }
        };
        let mut home = Joints::default();
        for (key, v) in &raw.home {
            let key = key.get_ref();
            let field = format!("home.{key}");
            let Some(i) = letters
                .iter()
                .position(|l| key.len() == 1 && key.starts_with(*l))
            else {
                return self.err(
                    Some(v.span()),
                    &field,
                    format!("unknown axis (expected X, Y, Z, {tl}, C)"),
                );
            };
            let x = self.finite(v, &field)?;
            let val = if i >= 3 { x.to_radians() } else { x };
            if !axes[i].contains(val, 1e-12) {
                return self.err(Some(v.span()), &field, "outside the axis limits");
            }
            home.set(AxisId::ALL[i], val);
        }
        for i in 0..AxisId::ALL.len() {
            if !raw.home.contains_key(letters[i].to_string().as_str())
                && !axes[i].contains(0.0, 0.0)
            {
                return self.err(
                    None,
                    &format!("home.{}", letters[i]),
                    "required: 0 lies outside the axis limits",
                );
            }
        }
        let safe_z = match &raw.safe_z {
            None => None,
            Some(s) => {
                let v = self.finite(s, "safe_z")?;
                if !axes[2].contains(v, 1e-12) {
                    return self.err(Some(s.span()), "safe_z", "outside the Z limits");
                }
                Some(v)
            }
        };
        let singularity_tol = match &raw.singularity_tol_deg {
            None => 1e-7,
            Some(s) => {
                let v = self.finite(s, "singularity_tol_deg")?;
                if !(v > 0.0 && v < 10.0) {
                    return self.err(Some(s.span()), "singularity_tol_deg", "must lie in (0, 10)");
                }
                v.to_radians()
            }
        };
        let tool_change_s = match &raw.tool_change_s {
            None => None,
            Some(s) => {
                let v = self.finite(s, "tool_change_s")?;
                if v < 0.0 {
                    return self.err(Some(s.span()), "tool_change_s", "must be >= 0");
                }
                Some(v)
            }
        };
        let blending = match &raw.blending {
            None => Blending::Parabolic,
            Some(s) => match s.get_ref().as_str() {
                "parabolic" => Blending::Parabolic,
                "exact_stop" => Blending::ExactStop,
                other => {
                    return self.err(
                        Some(s.span()),
                        "blending",
                        format!("must be \"parabolic\" or \"exact_stop\", got \"{other}\""),
                    )
                }
            },
        };
        if raw.name.trim().is_empty() {
            return self.err(None, "name", "must not be empty");
        }
        Ok(Machine {
            name: raw.name,
            description: raw.description,
            kinematics,
            workpiece_origin,
            axes,
            home,
            safe_z,
            singularity_tol,
            tool_change_s,
            blending,
        })
    }
}
