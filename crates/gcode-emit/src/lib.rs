//! G-code dialects (LinuxCNC, Fanuc, Sinumerik 840D, Heidenhain) and APT CLDATA read/write.

mod apt_cutter;
mod atomic_write;
pub mod cldata;
mod error;
mod number;

pub use apt_cutter::{apt_from_cl_params, apt_to_cl_params};
pub use atomic_write::write_atomic;
pub use cldata::{
    read_cl, read_cl_file, write_cl, write_cl_file, ClOperation, ClProgram, ClReadOptions,
    ClWarning, ClWriteOptions, Coolant, Spindle,
};
pub use error::GcodeError;
pub use number::NumberFormat;
