//! G-code dialects (LinuxCNC, Fanuc, Sinumerik 840D, Heidenhain ISO) and APT CLDATA
//! read/write.
//!
//! - [`cldata`]: read any CAM system's APT CL file into `cam-core` tool paths with their
//!   cutters and technology ([`read_cl`]), and write them back ([`write_cl`]).
//! - [`program`]: the NC program model ([`NcProgram`]) — blocks already carrying joint values
//!   or tool-tip coordinates — that a [`Dialect`] formats.
//! - [`dialect`]: the [`Dialect`] trait, [`dialect_by_name`] and [`write_program_file`]
//!   (temporary file + rename).
//! - [`assemble`]: CL operations + a `postproc-kinematics` machine → [`NcProgram`].
//! - [`NumberFormat`]: fixed decimals, never an exponent, `-0` printed as `0`.
//! - [`gcode_read`]: a small LinuxCNC G-code reader returning joint blocks, for verification
//!   by forward kinematics.

mod apt_cutter;
pub mod assemble;
mod atomic_write;
pub mod cldata;
pub mod dialect;
mod dialects;
mod error;
pub mod gcode_read;
mod number;
pub mod program;
pub mod tilted_plane;

pub use apt_cutter::{apt_from_cl_params, apt_to_cl_params};
pub use assemble::{assemble_program, AssembleOptions, AssembledProgram};
pub use atomic_write::write_atomic;
pub use cldata::{
    read_cl, read_cl_file, write_cl, write_cl_file, ClOperation, ClProgram, ClReadOptions,
    ClWarning, ClWriteOptions, Coolant, Spindle,
};
pub use dialect::{dialect_by_name, write_program_file, Dialect, DIALECT_NAMES};
pub use dialects::{Fanuc, HeidenhainIso, LinuxCnc, Sinumerik};
pub use error::GcodeError;
pub use gcode_read::{read_gcode, read_gcode_file, GcodeBlock, GcodeFeed, GcodeMotion};
pub use number::NumberFormat;
pub use program::{
    Feed, LineNumbers, Motion, NcMove, NcOperation, NcProgram, OutputMode, ProgramOptions,
    RotaryWord, ToolCall,
};
pub use tilted_plane::TiltedPlane;
