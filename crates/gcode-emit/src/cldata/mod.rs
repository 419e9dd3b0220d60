//! APT CLDATA (cutter-location data, ISO 3592 source form as printed by CAM systems): the
//! program model, a reader and a round-trippable writer.
//!
//! A CL file is a sequence of records `WORD/param,param,...`. A trailing `$` continues a
//! record on the next line; `$$` starts a comment. The reader understands `PARTNO`, `UNITS`,
//! `MULTAX`, `LOADTL`, `CUTTER` (1–7 parameters), `TLDATA/MILL` (NX), `TLAXIS`, `FEDRAT`, `RAPID`, `GOTO` (3 or 6 values), `FROM`,
//! `SPINDL`, `COOLNT`, `PPRINT`, `TOOL PATH` / `END-OF-PATH` (operation brackets written by
//! many CAM systems) and `FINI`; every other record is kept as a [`ClWarning`] with its line.

mod read;
mod write;

pub use read::{read_cl, read_cl_file, ClReadOptions};
pub use write::{write_cl, write_cl_file, ClWriteOptions};

use cam_core::{AptCutter, Cutter, ToolPath};
use serde::{Deserialize, Serialize};

/// Spindle state of an operation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spindle {
    /// Speed (rev/min), > 0.
    pub rpm: f64,
    /// Clockwise seen from the spindle toward the tool (M3); `false` = counter-clockwise (M4).
    pub clockwise: bool,
}

/// Coolant mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coolant {
    /// No coolant.
    #[default]
    Off,
    /// Flood coolant (M8).
    Flood,
    /// Mist (M7).
    Mist,
    /// Through-tool coolant.
    ThroughTool,
}

/// One operation of a CL program: a tool path with the tool and technology it runs with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClOperation {
    /// The moves (tip point + unit axis, mm; feeds in mm/min).
    pub path: ToolPath,
    /// Tool number from `LOADTL` (used for `T`/`H` words).
    pub tool_number: Option<u32>,
    /// The APT cutter parameters as given in the file.
    pub apt_cutter: Option<AptCutter>,
    /// The `cam-core` cutter, when the APT parameters describe a supported shape.
    pub cutter: Option<Cutter>,
    /// Spindle state, if given.
    pub spindle: Option<Spindle>,
    /// Coolant state.
    pub coolant: Coolant,
    /// `MULTAX/ON` was active (moves carry a tool axis).
    pub multax: bool,
    /// `PPRINT` texts met inside the operation, in order.
    pub comments: Vec<String>,
    /// Gauge length of the tool (spindle gauge line to tip, mm) for the kinematics of head
    /// machines: `LOADTL/n,LENGTH,l` in APT files; `None`: not given (the post options' tool
    /// length).
    pub tool_length_mm: Option<f64>,
}

impl ClOperation {
    /// An operation around `path` with no tool data, coolant off, multi-axis on.
    pub fn new(path: ToolPath) -> Self {
        Self {
            path,
            tool_number: None,
            apt_cutter: None,
            cutter: None,
            spindle: None,
            coolant: Coolant::Off,
            multax: true,
            comments: Vec::new(),
            tool_length_mm: None,
        }
    }
}

impl ClProgram {
    /// A program from tool paths with their cutters and tool numbers (spindle and coolant
    /// unset), e.g. to write the CL file of a job's operations.
    pub fn from_tool_paths(
        part_name: Option<String>,
        paths: impl IntoIterator<Item = (ToolPath, Option<Cutter>, Option<u32>)>,
    ) -> Self {
        Self {
            part_name,
            operations: paths
                .into_iter()
                .map(|(path, cutter, tool_number)| {
                    let mut op = ClOperation::new(path);
                    op.apt_cutter = cutter.as_ref().map(AptCutter::from_cutter);
                    op.cutter = cutter;
                    op.tool_number = tool_number;
                    op
                })
                .collect(),
            warnings: Vec::new(),
        }
    }
}

/// A record the reader did not use, kept so nothing is silently dropped.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClWarning {
    /// 1-based line of the record.
    pub line: usize,
    /// What was ignored and why.
    pub message: String,
}

/// A whole CL program.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ClProgram {
    /// `PARTNO` text.
    pub part_name: Option<String>,
    /// Operations in order.
    pub operations: Vec<ClOperation>,
    /// Records that were read but not used (unknown words, records after `FINI`, ...).
    pub warnings: Vec<ClWarning>,
}
