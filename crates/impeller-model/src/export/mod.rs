//! Exporters: binary STL of impeller parts within a chord tolerance, and TurboGrid curve
//! files that the importer reads back. Every file is written to a temporary file and renamed.

mod atomic;
pub mod curves;
pub mod error;
pub mod stl;

pub use atomic::write_atomic;
pub use curves::{write_curves, CurveFiles, CurveSampling};
pub use error::ExportError;
pub use stl::{
    fillets_mesh, mesh_fillets, mesh_parts, stl_bytes, tessellate, tessellate_compact,
    tessellate_fillet_piece, write_stl, Part, StlStats, TriMesh,
};
