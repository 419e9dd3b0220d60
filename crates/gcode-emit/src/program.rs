//! The NC program model that dialects write: operations of blocks that already carry the
//! values a controller needs (joint values or tool-tip coordinates, rotary angles in degrees,
//! tool vectors, feeds), so a dialect is pure formatting and program structure.

use crate::{Coolant, Spindle};
use cam_core::{Point3, UnitVector3};
use serde::{Deserialize, Serialize};

/// What the X Y Z words and the orientation words of a simultaneous operation mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutputMode {
    /// Machine joint values: X Y Z are the machine's linear axes (tool tip with tool length
    /// compensation `G43` active, for table-table machines), rotary words are axis angles.
    /// Moves that turn a rotary axis use inverse-time feed (`G93`).
    Joint,
    /// Tool-centre-point control: X Y Z are the tool tip in the workpiece frame, rotary words
    /// are machine axis angles, the controller does the kinematics; feed in mm/min at the tip.
    TcpAngles,
    /// Tool-centre-point control with the tool direction as a unit vector in the workpiece
    /// frame instead of axis angles (Sinumerik `A3= B3= C3=`, Fanuc `G43.5` `I J K`).
    TcpVector,
}

/// A rotary axis word: address letter (`A`, `B` or `C`) and angle in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotaryWord {
    /// Address letter.
    pub letter: char,
    /// Angle (degrees).
    pub deg: f64,
}

/// Feed of a block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Feed {
    /// Rapid traverse (`G0`).
    Rapid,
    /// Linear feed at this rate (mm/min).
    PerMinute(f64),
    /// Linear move to be completed in `1/value` minutes (inverse-time `G93` `F` word).
    InverseTime(f64),
}

/// One motion block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NcMove {
    /// X Y Z values (mm): joint values or tool tip, per the operation's mode.
    pub xyz: [f64; 3],
    /// Rotary axis words (degrees), in the order they are written.
    pub rotary: Vec<RotaryWord>,
    /// Unit tool direction in the workpiece frame (used by [`OutputMode::TcpVector`] and by
    /// the 3+2 plane definitions).
    pub tool_vector: Option<[f64; 3]>,
    /// Feed.
    pub feed: Feed,
}

/// How an operation's moves are to be run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Motion {
    /// Simultaneous five-axis motion in the given mode.
    Simultaneous {
        /// Meaning of the words.
        mode: OutputMode,
        /// The blocks.
        moves: Vec<NcMove>,
    },
    /// 3+2 positioning: the working plane is tilted so its Z axis is `tool_axis`, then the
    /// tool tips (workpiece frame; the dialect transforms them into the tilted plane) are
    /// run as three-axis moves.
    Indexed {
        /// The fixed tool axis (workpiece frame).
        tool_axis: UnitVector3,
        /// The machine's rotary angles for that axis (used for the preferred direction and
        /// for the pre-positioning of the axes).
        rotary: Vec<RotaryWord>,
        /// Tool tips (workpiece frame) with their feeds.
        tips: Vec<(Point3, Feed)>,
    },
}

/// Tool and technology of an operation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToolCall {
    /// Tool (pocket) number; also the length offset register.
    pub number: u32,
    /// Tool name (for comments).
    pub name: String,
    /// Spindle speed and direction (`None` = spindle off).
    pub spindle: Option<Spindle>,
    /// Coolant.
    pub coolant: Coolant,
}

/// One operation of a program.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NcOperation {
    /// Operation name (written as a comment).
    pub name: String,
    /// Tool and technology.
    pub tool: ToolCall,
    /// The motion.
    pub motion: Motion,
}

/// A whole program, ready for a dialect.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NcProgram {
    /// Program name (letters, digits, `_`; dialects sanitise it).
    pub name: String,
    /// Operations in order.
    pub operations: Vec<NcOperation>,
}

/// Block numbering.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct LineNumbers {
    /// First number.
    pub start: u32,
    /// Increment.
    pub step: u32,
    /// Largest number the control reads (e.g. 99999 on a Fanuc with five-digit sequence
    /// numbers): numbering starts again at `start` after it. `None`: no limit.
    pub wrap: Option<u32>,
}

impl LineNumbers {
    /// `start`, `start + step`, ... without a limit.
    pub const fn new(start: u32, step: u32) -> Self {
        Self {
            start,
            step,
            wrap: None,
        }
    }
}

/// The M codes of each coolant state (the program frame of a machine may change them, e.g.
/// through-tool coolant on `M88`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CoolantCodes {
    /// Flood coolant (`M8`).
    pub flood: String,
    /// Mist (`M7`).
    pub mist: String,
    /// Through-tool coolant (`M8` unless the machine says otherwise).
    pub through: String,
    /// Coolant off (`M9`).
    pub off: String,
}

impl Default for CoolantCodes {
    fn default() -> Self {
        Self {
            flood: "M8".into(),
            mist: "M7".into(),
            through: "M8".into(),
            off: "M9".into(),
        }
    }
}

impl CoolantCodes {
    /// The code of `c`.
    pub fn code(&self, c: crate::Coolant) -> &str {
        match c {
            crate::Coolant::Off => &self.off,
            crate::Coolant::Flood => &self.flood,
            crate::Coolant::Mist => &self.mist,
            crate::Coolant::ThroughTool => &self.through,
        }
    }
}

/// Options shared by every dialect.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProgramOptions {
    /// Block numbers (`None` = none; dialects that require them, Heidenhain, always number).
    pub line_numbers: Option<LineNumbers>,
    /// Decimals of linear words (mm).
    pub linear_decimals: usize,
    /// Decimals of rotary words (degrees) and of tool-vector components.
    pub angular_decimals: usize,
    /// Decimals of mm/min feeds.
    pub feed_decimals: usize,
    /// Decimals of inverse-time feeds (1/min).
    pub inverse_time_decimals: usize,
    /// Work offset 1..=6 (`G54`..`G59`).
    pub work_offset: u8,
    /// Machine-coordinate Z (mm) the spindle retracts to before any tool change or
    /// reorientation between operations, and at the program end.
    pub safe_z_machine: f64,
    /// Program number for controls that number programs (Fanuc `O`).
    pub program_number: u32,
    /// Write operation and tool comments.
    pub comments: bool,
    /// Blocks written after the program's setup block (the machine's own start sequence).
    pub header: Vec<String>,
    /// Blocks written before the program end code.
    pub footer: Vec<String>,
    /// Program end code (`M30`, `M2`); `None`: the dialect's (LinuxCNC `M2`, others `M30`).
    pub program_end: Option<String>,
    /// M codes of the coolant states.
    pub coolant_codes: CoolantCodes,
}

impl Default for ProgramOptions {
    fn default() -> Self {
        Self {
            line_numbers: Some(LineNumbers::new(10, 10)),
            linear_decimals: 4,
            angular_decimals: 4,
            feed_decimals: 1,
            inverse_time_decimals: 4,
            work_offset: 1,
            safe_z_machine: 0.0,
            program_number: 1000,
            comments: true,
            header: Vec::new(),
            footer: Vec::new(),
            program_end: None,
            coolant_codes: CoolantCodes::default(),
        }
    }
}

impl ProgramOptions {
    /// Checks ranges.
    pub fn validate(&self) -> Result<(), crate::GcodeError> {
        let bad = |field, reason: String| Err(crate::GcodeError::InvalidOption { field, reason });
        if !(1..=6).contains(&self.work_offset) {
            return bad(
                "work_offset",
                format!("{} is not in 1..=6 (G54..G59)", self.work_offset),
            );
        }
        if !self.safe_z_machine.is_finite() {
            return bad("safe_z_machine", "must be finite".into());
        }
        if let Some(n) = self.line_numbers {
            if n.step == 0 {
                return bad("line_numbers.step", "must be > 0".into());
            }
            if let Some(w) = n.wrap {
                if w < n.start.saturating_add(n.step) {
                    return bad(
                        "line_numbers.wrap",
                        format!(
                            "{w} leaves no room after the first number {} (step {})",
                            n.start, n.step
                        ),
                    );
                }
            }
        }
        let codes = &self.coolant_codes;
        for (field, text) in self
            .header
            .iter()
            .map(|t| ("header", t))
            .chain(self.footer.iter().map(|t| ("footer", t)))
            .chain(self.program_end.iter().map(|t| ("program_end", t)))
            .chain([
                ("coolant_codes.flood", &codes.flood),
                ("coolant_codes.mist", &codes.mist),
                ("coolant_codes.through", &codes.through),
                ("coolant_codes.off", &codes.off),
            ])
        {
            if text.contains(['\n', '\r']) || text.trim().is_empty() {
                return bad(
                    field,
                    format!("{text:?} must be one non-empty line (one block each)"),
                );
            }
        }
        for (field, d) in [
            ("linear_decimals", self.linear_decimals),
            ("angular_decimals", self.angular_decimals),
            ("feed_decimals", self.feed_decimals),
            ("inverse_time_decimals", self.inverse_time_decimals),
        ] {
            if d > 9 {
                return bad(
                    field,
                    format!("{d} decimals is more than any control reads (max 9)"),
                );
            }
        }
        Ok(())
    }
}
