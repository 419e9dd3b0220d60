//! Reading APT CLDATA text into a [`ClProgram`].
//!
//! Two passes in one sweep: physical lines are joined into logical records (`$`
//! continuation, `$$` comments), then each record updates a small modal state machine
//! (units, feed, tool axis, tool, spindle, coolant, `RAPID` for the next move only) and
//! appends moves to the open operation. O(file size). Every malformed number names the file,
//! the record's first line, the record word and the 1-based parameter index.

use super::{ClOperation, ClProgram, ClWarning, Coolant, Spindle};
use crate::{apt_from_cl_params, GcodeError};
use cam_core::{
    AptCutter, Cutter, CutterLocation, Move, MoveKind, Point3, ToolPath, UnitVector3, Vector3,
};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Millimetres per inch (`UNITS/INCHES`, `FEDRAT/IPM`).
const MM_PER_INCH: f64 = 25.4;

/// A tool axis whose given length differs from 1 by more than this is reported (it is
/// normalised either way).
pub const AXIS_UNIT_TOL: f64 = 1e-3;

/// Options of the CL reader.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClReadOptions {
    /// Flute length given to a cutter whose `CUTTER` record has no height `h`, as a multiple
    /// of its diameter (a warning says so when it is used).
    pub default_flute_length_per_diameter: f64,
}

impl Default for ClReadOptions {
    fn default() -> Self {
        Self {
            default_flute_length_per_diameter: 3.0,
        }
    }
}

/// Reads a CL file from disk (see [`read_cl`]).
pub fn read_cl_file(path: &Path, options: &ClReadOptions) -> Result<ClProgram, GcodeError> {
    let bytes = std::fs::read(path).map_err(|source| GcodeError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|e| GcodeError::ClParse {
        file: path.display().to_string(),
        line: 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        record: "-".into(),
        field: 0,
        reason: "file is not valid UTF-8".into(),
    })?;
    read_cl(&text, &path.display().to_string(), options)
}

/// Parses CL text. `file` names the source in errors and warnings.
///
/// Returns the program (operations with their tool paths, cutters and technology) and the
/// warnings for records that were not used; or the first malformed record as
/// [`GcodeError::ClParse`].
pub fn read_cl(text: &str, file: &str, options: &ClReadOptions) -> Result<ClProgram, GcodeError> {
    let mut reader = Reader::new(file, *options);
    // Editors on Windows may start the file with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut pending: Option<(usize, String)> = None;
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        last_line = line;
        let keep_dollars = {
            let head = raw.trim_start().to_ascii_uppercase();
            pending.is_none() && (head.starts_with("PPRINT") || head.starts_with("PARTNO"))
        };
        let mut content = raw;
        if !keep_dollars {
            if let Some(p) = content.find("$$") {
                content = &content[..p];
            }
        }
        let content = content.trim_end();
        let (body, continues) = match content.strip_suffix('$') {
            Some(b) if !keep_dollars => (b, true),
            _ => (content, false),
        };
        match pending.as_mut() {
            Some((_, acc)) => acc.push_str(body.trim_start()),
            None => pending = Some((line, body.to_string())),
        }
        if !continues {
            if let Some((start, rec)) = pending.take() {
                reader.record(start, &rec)?;
            }
        }
    }
    if let Some((start, _)) = pending {
        return Err(reader.err(
            start,
            "$",
            0,
            format!("continuation `$` but the file ends at line {last_line}"),
        ));
    }
    Ok(reader.finish())
}

/// Modal state of the reader.
struct Reader<'a> {
    file: &'a str,
    options: ClReadOptions,
    program: ClProgram,
    scale: f64,
    multax: bool,
    axis: UnitVector3,
    feed: Option<f64>,
    rapid_next: bool,
    tool_number: Option<u32>,
    tool_length: Option<f64>,
    apt_cutter: Option<AptCutter>,
    cutter: Option<Cutter>,
    spindle: Option<Spindle>,
    coolant: Coolant,
    current: Option<ClOperation>,
    pending_name: Option<String>,
    pending_comments: Vec<String>,
    op_counter: usize,
    finished: bool,
    last_line: usize,
}

impl<'a> Reader<'a> {
    fn new(file: &'a str, options: ClReadOptions) -> Self {
        Self {
            file,
            options,
            program: ClProgram::default(),
            scale: 1.0,
            multax: false,
            axis: Vector3::z_axis(),
            feed: None,
            rapid_next: false,
            tool_number: None,
            tool_length: None,
            apt_cutter: None,
            cutter: None,
            spindle: None,
            coolant: Coolant::Off,
            current: None,
            pending_name: None,
            pending_comments: Vec::new(),
            op_counter: 0,
            finished: false,
            last_line: 0,
        }
    }

    fn err(
        &self,
        line: usize,
        record: &str,
        field: usize,
        reason: impl Into<String>,
    ) -> GcodeError {
        GcodeError::ClParse {
            file: self.file.to_string(),
            line,
            record: record.to_string(),
            field,
            reason: reason.into(),
        }
    }

    fn warn(&mut self, line: usize, message: impl Into<String>) {
        self.program.warnings.push(ClWarning {
            line,
            message: message.into(),
        });
    }

    fn num(&self, line: usize, word: &str, params: &[&str], i: usize) -> Result<f64, GcodeError> {
        let Some(s) = params.get(i) else {
            return Err(self.err(line, word, i + 1, "missing value"));
        };
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.err(line, word, i + 1, format!("`{s}` is not a finite number"))),
            Err(_) => Err(self.err(line, word, i + 1, format!("`{s}` is not a number"))),
        }
    }

    fn tool_name(&self) -> String {
        match self.tool_number {
            Some(n) => format!("T{n}"),
            None => "tool".to_string(),
        }
    }

    /// Closes the open operation (dropping it with a warning if it has no moves).
    fn close(&mut self, line: usize) {
        if let Some(op) = self.current.take() {
            if op.path.moves.is_empty() {
                self.warn(
                    line,
                    format!("operation `{}` has no moves; dropped", op.path.name),
                );
            } else {
                self.program.operations.push(op);
            }
        }
    }

    /// The open operation, created from the modal state if none is open or if the tool or
    /// technology changed since it was opened.
    fn open(&mut self, line: usize) -> &mut ClOperation {
        let stale = self.current.as_ref().is_some_and(|op| {
            op.tool_number != self.tool_number
                || op.tool_length_mm != self.tool_length
                || op.apt_cutter != self.apt_cutter
                || op.spindle != self.spindle
                || op.coolant != self.coolant
        });
        if stale {
            let moves = self.current.as_ref().map_or(0, |op| op.path.moves.len());
            if moves == 0 {
                let tool = match &self.cutter {
                    Some(c) => c.name.clone(),
                    None => self.tool_name(),
                };
                if let Some(op) = self.current.as_mut() {
                    op.tool_number = self.tool_number;
                    op.tool_length_mm = self.tool_length;
                    op.apt_cutter = self.apt_cutter;
                    op.cutter.clone_from(&self.cutter);
                    op.spindle = self.spindle;
                    op.coolant = self.coolant;
                    op.path.tool = tool;
                }
            } else {
                // Same operation continues with new technology: split it.
                let name = self.current.as_ref().map(|op| op.path.name.clone());
                self.close(line);
                self.pending_name = name.map(|n| format!("{n}.{}", self.op_counter + 1));
            }
        }
        if self.current.is_none() {
            self.op_counter += 1;
            let name = self
                .pending_name
                .take()
                .unwrap_or_else(|| format!("op{}", self.op_counter));
            let tool = match &self.cutter {
                Some(c) => c.name.clone(),
                None => self.tool_name(),
            };
            let mut op = ClOperation::new(ToolPath::new(name, tool));
            op.tool_number = self.tool_number;
            op.tool_length_mm = self.tool_length;
            op.apt_cutter = self.apt_cutter;
            op.cutter.clone_from(&self.cutter);
            op.spindle = self.spindle;
            op.coolant = self.coolant;
            op.multax = self.multax;
            op.comments = std::mem::take(&mut self.pending_comments);
            self.current = Some(op);
        }
        // Both branches above leave `current` set.
        self.current
            .get_or_insert_with(|| ClOperation::new(ToolPath::new("op", "tool")))
    }

    fn record(&mut self, line: usize, rec: &str) -> Result<(), GcodeError> {
        self.last_line = line;
        let text = rec.trim();
        if text.is_empty() {
            return Ok(());
        }
        let (word_raw, rest) = match text.find('/') {
            Some(p) => (text[..p].trim(), Some(&text[p + 1..])),
            None => (text, None),
        };
        let upper = word_raw.to_ascii_uppercase();
        // `PARTNO name` has no slash.
        let (word, rest) = if rest.is_none() && upper.starts_with("PARTNO") {
            ("PARTNO".to_string(), Some(&word_raw[6..]))
        } else {
            (upper, rest)
        };
        if self.finished {
            self.warn(line, format!("record `{word}` after FINI ignored"));
            return Ok(());
        }
        let params: Vec<&str> =
            rest.map_or_else(Vec::new, |r| r.split(',').map(str::trim).collect());
        let w = word.as_str();
        match w {
            "PARTNO" => {
                self.program.part_name = Some(rest.unwrap_or("").trim().to_string());
            }
            "PPRINT" => {
                let text = rest.unwrap_or("").trim().to_string();
                match self.current.as_mut() {
                    Some(op) => op.comments.push(text),
                    None => self.pending_comments.push(text),
                }
            }
            "UNITS" => match params.first().map(|s| s.to_ascii_uppercase()).as_deref() {
                Some("MM") => self.scale = 1.0,
                Some("INCHES") | Some("INCH") => self.scale = MM_PER_INCH,
                _ => return Err(self.err(line, w, 1, "expected MM or INCHES")),
            },
            "MULTAX" => match params.first().map(|s| s.to_ascii_uppercase()).as_deref() {
                None | Some("ON") | Some("") => self.multax = true,
                Some("OFF") => self.multax = false,
                _ => return Err(self.err(line, w, 1, "expected ON or OFF")),
            },
            "LOADTL" => {
                let v = self.num(line, w, &params, 0)?;
                if v < 0.0 || v.fract() != 0.0 || v > f64::from(u32::MAX) {
                    return Err(self.err(
                        line,
                        w,
                        1,
                        format!("tool number {v} is not a non-negative integer"),
                    ));
                }
                // `LOADTL/n,LENGTH,l` (ISO 4343) gives the gauge length; other modifiers are
                // not used.
                let mut length = None;
                let mut ignored = Vec::new();
                let mut i = 1;
                while i < params.len() {
                    if params[i].eq_ignore_ascii_case("LENGTH") {
                        let l = self.num(line, w, &params, i + 1)? * self.scale;
                        if l <= 0.0 {
                            return Err(self.err(
                                line,
                                w,
                                i + 2,
                                format!("tool length {l} must be > 0"),
                            ));
                        }
                        length = Some(l);
                        i += 2;
                    } else {
                        ignored.push(params[i]);
                        i += 1;
                    }
                }
                if !ignored.is_empty() {
                    self.warn(
                        line,
                        format!(
                            "LOADTL parameters after the tool number ignored: {}",
                            ignored.join(",")
                        ),
                    );
                }
                if self
                    .current
                    .as_ref()
                    .is_some_and(|op| !op.path.moves.is_empty())
                {
                    self.close(line);
                }
                self.tool_number = Some(v as u32);
                self.tool_length = length;
                if let Some(c) = self.cutter.as_mut() {
                    c.name = format!("T{}", v as u32);
                }
            }
            "CUTTER" => {
                let mut vals = Vec::with_capacity(params.len());
                for i in 0..params.len() {
                    vals.push(self.num(line, w, &params, i)?);
                }
                let apt = apt_from_cl_params(&vals, self.scale).ok_or_else(|| {
                    self.err(
                        line,
                        w,
                        0,
                        format!("expected 1 to 7 numbers, found {}", vals.len()),
                    )
                })?;
                self.set_cutter(line, w, apt)?;
            }
            "TLDATA" => {
                // NX: TLDATA/MILL,d,r,length,taper,tip_angle (angles in degrees).
                if !params
                    .first()
                    .is_some_and(|p| p.eq_ignore_ascii_case("MILL"))
                {
                    self.warn(
                        line,
                        format!(
                            "TLDATA/{} ignored: only MILL tools are read",
                            params.join(",")
                        ),
                    );
                    return Ok(());
                }
                let mut v = [0.0; 5];
                for (k, slot) in v.iter_mut().enumerate() {
                    if k + 1 < params.len() {
                        *slot = self.num(line, w, &params, k + 1)?;
                    } else if k == 0 {
                        return Err(self.err(line, w, 2, "missing diameter"));
                    }
                }
                let (d, r) = (v[0], v[1]);
                let e = if r > 0.0 { d / 2.0 - r } else { d / 2.0 };
                let apt = AptCutter {
                    d: d * self.scale,
                    r: r * self.scale,
                    e: e * self.scale,
                    f: r * self.scale,
                    alpha: v[4].to_radians(),
                    beta: v[3].to_radians(),
                    h: v[2] * self.scale,
                };
                self.set_cutter(line, w, apt)?;
            }
            "FEDRAT" => {
                let mut value = None;
                let mut factor = self.scale;
                for (i, p) in params.iter().enumerate() {
                    match p.to_ascii_uppercase().as_str() {
                        "MMPM" => factor = 1.0,
                        "IPM" => factor = MM_PER_INCH,
                        "MMPR" | "IPR" => {
                            return Err(self.err(
                                line,
                                w,
                                i + 1,
                                "feed per revolution is not supported; give mm/min",
                            ))
                        }
                        _ => value = Some(self.num(line, w, &params, i)?),
                    }
                }
                let Some(v) = value else {
                    return Err(self.err(line, w, 1, "missing feed value"));
                };
                if v <= 0.0 {
                    return Err(self.err(line, w, 1, format!("feed {v} must be > 0")));
                }
                self.feed = Some(v * factor);
            }
            "RAPID" => self.rapid_next = true,
            "TLAXIS" => {
                if params.len() != 3 || params.iter().any(|p| p.parse::<f64>().is_err()) {
                    self.warn(
                        line,
                        format!(
                            "TLAXIS/{} not understood; tool axis unchanged",
                            params.join(",")
                        ),
                    );
                } else {
                    let v = Vector3::new(
                        self.num(line, w, &params, 0)?,
                        self.num(line, w, &params, 1)?,
                        self.num(line, w, &params, 2)?,
                    );
                    self.axis = self.unit_axis(line, w, v, 1)?;
                }
            }
            "GOTO" | "FROM" => {
                if params.len() != 3 && params.len() != 6 {
                    return Err(self.err(
                        line,
                        w,
                        0,
                        format!("expected 3 or 6 values, found {}", params.len()),
                    ));
                }
                let mut v = [0.0; 6];
                for (i, slot) in v.iter_mut().enumerate().take(params.len()) {
                    *slot = self.num(line, w, &params, i)?;
                }
                let tip = Point3::new(v[0], v[1], v[2]) * self.scale;
                if params.len() == 6 {
                    self.axis = self.unit_axis(line, w, Vector3::new(v[3], v[4], v[5]), 4)?;
                }
                if !(tip.x.is_finite() && tip.y.is_finite() && tip.z.is_finite()) {
                    return Err(self.err(line, w, 1, "coordinate overflows after unit conversion"));
                }
                let cl = CutterLocation {
                    tip,
                    axis: self.axis,
                };
                let rapid = std::mem::take(&mut self.rapid_next) || w == "FROM";
                let feed = self.feed;
                let op = self.open(line);
                op.path.moves.push(Move {
                    kind: if rapid {
                        MoveKind::Rapid
                    } else {
                        MoveKind::Feed
                    },
                    cl,
                    feed_mm_per_min: if rapid { None } else { feed },
                });
            }
            "SPINDL" => {
                let mut rpm = None;
                let mut clockwise = self.spindle.is_none_or(|s| s.clockwise);
                let mut off = false;
                for (i, p) in params.iter().enumerate() {
                    match p.to_ascii_uppercase().as_str() {
                        "RPM" => {}
                        "CLW" => clockwise = true,
                        "CCLW" => clockwise = false,
                        "OFF" => off = true,
                        "ON" => rpm = rpm.or(self.spindle.map(|s| s.rpm)),
                        "SFM" | "SMM" => {
                            return Err(self.err(
                                line,
                                w,
                                i + 1,
                                "constant surface speed is not supported; give RPM",
                            ))
                        }
                        _ => rpm = Some(self.num(line, w, &params, i)?),
                    }
                }
                if off {
                    self.spindle = None;
                } else {
                    let Some(rpm) = rpm else {
                        return Err(self.err(line, w, 1, "missing spindle speed"));
                    };
                    if rpm <= 0.0 {
                        return Err(self.err(
                            line,
                            w,
                            1,
                            format!("spindle speed {rpm} must be > 0"),
                        ));
                    }
                    self.spindle = Some(Spindle { rpm, clockwise });
                }
            }
            "COOLNT" => {
                self.coolant = match params.first().map(|s| s.to_ascii_uppercase()).as_deref() {
                    Some("ON") | Some("FLOOD") => Coolant::Flood,
                    Some("MIST") => Coolant::Mist,
                    Some("THRU") | Some("THROUGH") | Some("TAPKUL") => Coolant::ThroughTool,
                    Some("OFF") => Coolant::Off,
                    _ => return Err(self.err(line, w, 1, "expected ON, FLOOD, MIST, THRU or OFF")),
                }
            }
            "TOOL PATH" => {
                self.close(line);
                let name = params.first().copied().unwrap_or("").trim();
                self.pending_name = (!name.is_empty()).then(|| name.to_string());
            }
            "END-OF-PATH" => self.close(line),
            "FINI" => {
                self.close(line);
                self.finished = true;
            }
            "CIRCLE" => self.warn(
                line,
                "CIRCLE record ignored: the arc's end point is reached by a straight move",
            ),
            _ => self.warn(
                line,
                format!(
                    "unknown record `{}` ignored",
                    text.chars().take(60).collect::<String>()
                ),
            ),
        }
        Ok(())
    }

    /// Validates an APT cutter from `CUTTER` or `TLDATA`, completes a missing height and sets
    /// the modal cutter (a warning keeps unsupported shapes as APT numbers only).
    fn set_cutter(&mut self, line: usize, w: &str, mut apt: AptCutter) -> Result<(), GcodeError> {
        if apt.d <= 0.0 {
            return Err(self.err(line, w, 1, "diameter must be > 0"));
        }
        if apt.h <= 0.0 {
            apt.h = self.options.default_flute_length_per_diameter * apt.d;
            self.warn(
                line,
                format!(
                    "{w} has no height; flute length set to {} × diameter",
                    self.options.default_flute_length_per_diameter
                ),
            );
        }
        let name = self.tool_name();
        let cutter = apt.to_shape().and_then(|(shape, h)| {
            // Shank continues the flute profile; stick-out = flute length (the CL file
            // carries no holder data).
            Cutter::new(name, shape, h, shape.radius_at(h), h)
        });
        match cutter {
            Ok(c) => self.cutter = Some(c),
            Err(reason) => {
                self.warn(line, format!("{w} kept as APT parameters only: {reason}"));
                self.cutter = None;
            }
        }
        self.apt_cutter = Some(apt);
        Ok(())
    }

    fn unit_axis(
        &mut self,
        line: usize,
        w: &str,
        v: Vector3,
        field: usize,
    ) -> Result<UnitVector3, GcodeError> {
        let n = v.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(self.err(
                line,
                w,
                field,
                format!(
                    "tool axis ({}, {}, {}) is not a non-zero vector",
                    v.x, v.y, v.z
                ),
            ));
        }
        if (n - 1.0).abs() > AXIS_UNIT_TOL {
            self.warn(line, format!("{w} tool axis has length {n}; normalised"));
        }
        // An axis that is unit to rounding is kept as given, so written axes read back
        // bit for bit.
        if (n - 1.0).abs() <= 4.0 * f64::EPSILON {
            return Ok(UnitVector3::new_unchecked(v));
        }
        Ok(UnitVector3::new_unchecked(v / n))
    }

    fn finish(mut self) -> ClProgram {
        self.close(self.last_line);
        self.program
    }
}
