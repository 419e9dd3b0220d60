//! G-code dialects (LinuxCNC, Fanuc, Sinumerik 840D, Heidenhain ISO and conversational) and
//! APT CLDATA read/write.
//!
//! - [`cldata`]: read any CAM system's APT CL file into `cam-core` tool paths with their
//!   cutters and technology ([`read_cl`]), and write them back ([`write_cl`]).
//! - [`program`]: the NC program model ([`NcProgram`]) — blocks already carrying joint values
//!   or tool-tip coordinates — that a [`Dialect`] formats.
//! - [`dialect`]: the [`Dialect`] trait, [`dialect_by_name`] and [`write_program_file`]
//!   (temporary file + rename).
//! - [`assemble`]: CL operations + a `postproc-kinematics` machine → [`NcProgram`].
//! - [`frame`]: the program frame of a machine's controller from its machine file's
//!   `[program]` table ([`ProgramFrame`]: kinematics switch, header and footer blocks, end
//!   code, block numbering, coolant codes).
//! - [`cycle_time`]: how long an assembled program runs on the machine (cutting, links,
//!   rapids, tool changes; `postproc_kinematics::cycle_time`'s model).
//! - [`NumberFormat`]: fixed decimals, never an exponent, `-0` printed as `0`.
//! - [`gcode_read`]: a small LinuxCNC G-code reader returning joint blocks, for verification
//!   by forward kinematics ([`gcode_read::joints_of`]).
//! - [`readback`]: an emitted program read back through the machine's forward kinematics
//!   with the controller's interpolation into the cutter locations a simulator sweeps
//!   ([`read_back`]), every move included.
//!
//! Work offsets: joint output ([`OutputMode::Joint`]) writes machine joint values computed
//! with the machine file's rotary centres and workpiece origin, so the controller's work
//! offset must be the machine zero those centres refer to; tool-tip output
//! ([`OutputMode::TcpAngles`], [`OutputMode::TcpVector`], 3+2 planes) writes workpiece
//! coordinates, so the work offset must hold the workpiece origin.
//!
//! ```
//! use gcode_emit::{assemble_program, read_cl, AssembleOptions, ClReadOptions, Dialect,
//!     LinuxCnc, ProgramOptions};
//! use postproc_kinematics::Machine;
//!
//! let cl = read_cl("MULTAX/ON\nLOADTL/1\nCUTTER/6,3,0,3,0,0,30\nFEDRAT/MMPM,500\n\
//!     GOTO/20,0,5,0,0,1\nGOTO/20,5,5,0,0.1736482,0.9848078\nFINI\n",
//!     "demo.cls", &ClReadOptions::default()).unwrap();
//! let machine = Machine::from_toml_str(r#"
//! name = "trt"
//! [kinematics]
//! type = "table-table"
//! tilt_axis = "A"
//! [axes.X]
//! min = -500.0
//! max = 500.0
//! [axes.Y]
//! min = -500.0
//! max = 500.0
//! [axes.Z]
//! min = -500.0
//! max = 500.0
//! [axes.A]
//! min = -120.0
//! max = 120.0
//! [axes.C]
//! mode = "continuous"
//! "#, "trt.toml").unwrap();
//! let dialect = LinuxCnc::default();
//! let posted = assemble_program("demo", &cl.operations, &machine, &dialect,
//!     &AssembleOptions::default()).unwrap();
//! let text = dialect.write(&posted.program, &ProgramOptions::default()).unwrap();
//! assert!(text.contains("G93 G1"));
//! assert!(text.trim_end().ends_with('%'));
//! ```

mod apt_cutter;
pub mod assemble;
mod atomic_write;
pub mod cldata;
pub mod cycle_time;
pub mod dialect;
mod dialects;
mod error;
pub mod frame;
pub mod gcode_read;
mod number;
pub mod program;
pub mod readback;
pub mod tilted_plane;

pub use apt_cutter::{apt_from_cl_params, apt_to_cl_params};
pub use assemble::{assemble_program, AssembleOptions, AssembledProgram};
pub use atomic_write::write_atomic;
pub use cldata::{
    read_cl, read_cl_file, write_cl, write_cl_file, ClOperation, ClProgram, ClReadOptions,
    ClWarning, ClWriteOptions, Coolant, Spindle,
};
pub use cycle_time::{program_time, OperationTime, ProgramTime};
pub use dialect::{dialect_by_name, write_program_file, Dialect, DIALECT_NAMES};
pub use dialects::{
    Fanuc, HeidenhainConversational, HeidenhainIso, KinematicsSwitch, LinuxCnc, Sinumerik, Tcpm,
};
pub use error::GcodeError;
pub use frame::ProgramFrame;
pub use gcode_read::{read_gcode, read_gcode_file, GcodeBlock, GcodeFeed, GcodeMotion};
pub use number::NumberFormat;
pub use program::{
    CoolantCodes, Feed, LineNumbers, Motion, NcMove, NcOperation, NcProgram, OutputMode,
    ProgramOptions, RotaryWord, ToolCall,
};
pub use readback::{read_back, Readback, ReadbackMode, ReadbackOptions};
pub use tilted_plane::TiltedPlane;

// Dependencies: `cam-core` and `postproc-kinematics` (the project's), `nalgebra`, `serde`,
// `thiserror`, and `toml` for the `[program]` table of machine files (line numbers of its
// keys in errors come from the parser's spans) — the workspace's chosen crates.

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
