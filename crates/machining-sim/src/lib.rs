//! Independent verification of five-axis programs: tri-dexel stock simulation, overcut and
//! residual maps over the design surfaces, and shank/holder collisions.
//!
//! The crate shares no planning code with the path generators: it only reads cutters
//! (`cam_core::Cutter`), cutter locations / tool paths and a [`DesignModel`].
//!
//! Pipeline: [`TriDexel::from_shape`] samples the blank ([`BoxStock`], [`RevolvedStock`]);
//! [`simulate`] sweeps every move's cutter through the stock ([`removal`]) and checks the
//! non-cutting parts against the stock in process and against the design mesh
//! ([`collision`]); [`measure`] probes the finished stock along design normals for overcut and
//! residual; [`surface_mesh`] extracts an STL of the final stock.
//!
//! Dependencies: parry3d-f64 (workspace choice) for the BVH over the design mesh; rayon for
//! the per-row parallelism.

pub mod collision;
pub mod design;
pub mod dexel;
pub mod error;
pub mod export;
pub mod impeller_design;
pub mod measure;
pub mod motion;
pub mod removal;
pub mod simulate;
pub mod stock_shape;
pub mod surface_mesh;
pub mod tool_solid;

pub use design::{BoxDesign, CylinderDesign, DesignModel, SurfaceGrid, TriangleMesh, UnionDesign};
pub use dexel::{DexelGrid, Segments, TriDexel};
pub use error::SimError;
pub use impeller_design::{blank_of, ImpellerDesign, ImpellerSampling};
pub use measure::{Extremum, SurfaceMap};
pub use motion::Interpolation;
pub use removal::PartKind;
pub use simulate::{
    cut, simulate, Collision, CollisionTarget, CutOutcome, Metrics, Report, SimOptions, SimStats,
};
pub use stock_shape::{BoxStock, RevolvedStock, StockShape};
pub use surface_mesh::{extract_surface, write_stl, StockMesh};
