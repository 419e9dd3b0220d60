//! Importers of blade-design exports: TurboGrid curve sets, NUMECA AutoGrid `.geomTurbo`, and
//! BladeGen `rtzt` meanline files.
//!
//! Each importer reads its format into a [`RawImpeller`]: point data in millimetres with the
//! rotation axis along +Z, still in the file's axial sense and not yet fitted. Every failure
//! is an [`ImportError`] naming the file, the line and what was expected there.

pub mod build;
pub mod error;
pub mod fit;
pub mod geomturbo;
pub mod prepare;
pub mod raw;
pub mod rtzt;
pub mod spec;
mod text;
pub mod turbogrid;

pub use build::{
    assemble, check_tolerance, import_file, import_raw, is_import_extension, read_raw,
    ImportOptions, Imported,
};
pub use error::ImportError;
pub use fit::{fit, FittedBlade, FittedImpeller, DEFAULT_FIT_TOL_MM};
pub use geomturbo::{parse_geomturbo, read_geomturbo};
pub use prepare::{prepare, PreparedBlade, PreparedImpeller, SectionSides};
pub use raw::{
    BladeRole, LengthUnit, RawBlade, RawImpeller, RawSection, SectionShape, SourceFormat,
    ThicknessKind,
};
pub use rtzt::{parse_rtzt, read_rtzt};
pub use spec::{from_import_toml, is_import_toml, ImportSpec};
pub use turbogrid::{read_turbogrid, turbogrid_from_bytes, TurboGridInf};
