//! Importers of blade-design exports: TurboGrid curve sets, NUMECA AutoGrid `.geomTurbo`, and
//! BladeGen `rtzt` meanline files, and folders of section tables (the NASA HECC archive),
//! turned into an exact [`crate::Impeller`].
//!
//! The pipeline, one module per step:
//!
//! 1. **Parse** ([`turbogrid`], [`geomturbo`], [`rtzt`], [`tables`]) into a [`RawImpeller`]: point data
//!    in millimetres with the rotation axis along +Z, in the file's axial sense. Every
//!    malformed file is an [`ImportError`] naming the file, the line and what was expected
//!    there (CRLF and LF files alike; non-finite numbers rejected).
//! 2. **Prepare** ([`mod@prepare`]): blade sides from loops (split at the leading and trailing
//!    edges), camber lines (± half thickness) or given sides; flow direction, pressure /
//!    suction labels, the workpiece frame, contours trimmed to the bladed part.
//! 3. **Fit** ([`mod@fit`]): meridional contours and blade sides as B-splines within a stated
//!    tolerance (default [`DEFAULT_FIT_TOL_MM`] = 0.01 mm; `impeller-cam model --fit-tol`,
//!    `fit_tol_mm` in import files), knots inserted where the fit misses, data corners kept
//!    as C⁰ knots; sides skinned across the spans. The deviation reached and the data point
//!    farthest from the fit are reported per entity.
//! 4. **Assemble** ([`build`]): hub and shroud revolved exactly, blades via
//!    [`crate::Blade::from_sides`], the impeller via [`crate::Impeller::from_parts`].
//!
//! [`import_file`] runs all four by file extension; [`spec`] reads TOML files that point at an
//! export (`[import] file = ...`), which [`crate::load`] dispatches to. Achieved on the real
//! exports in `../shared/data`: Rotor 37 (36 blades, cm), the 12 + 12 centrifugal impeller
//! (metres) and the NASA HECC 15 + 15 impeller (inches, its archive tables read in place by
//! [`tables`]) all import at the default tolerance; Rotor 37 and the 12 + 12
//! impeller also within 0.001 mm.
//!
//! No new dependency: parsing is hand-written over lines (the formats are line-oriented and
//! need line numbers in errors); linear algebra uses `nalgebra` (SVD least squares, LU).

pub mod build;
pub mod error;
pub mod fit;
pub mod geomturbo;
pub mod prepare;
pub mod raw;
pub mod rtzt;
pub mod spec;
pub mod tables;
mod text;
pub mod turbogrid;

pub use build::{
    assemble, check_tolerance, import_file, import_raw, is_import_extension, read_raw,
    read_raw_with, ImportOptions, Imported,
};
pub use error::ImportError;
pub use fit::{fit, DataMiss, FittedBlade, FittedImpeller, DEFAULT_FIT_TOL_MM};
pub use geomturbo::{parse_geomturbo, read_geomturbo};
pub use prepare::{prepare, PreparedBlade, PreparedImpeller, SectionSides};
pub use raw::{
    BladeRole, LengthUnit, RawBlade, RawImpeller, RawSection, SectionShape, SourceFormat,
    ThicknessKind,
};
pub use rtzt::{parse_rtzt, read_rtzt};
pub use spec::{from_import_toml, from_import_toml_with, is_import_toml, ImportSpec};
pub use tables::{read_tables, TableOptions, ThetaSense};
pub use turbogrid::{read_turbogrid, turbogrid_from_bytes, TurboGridInf};
