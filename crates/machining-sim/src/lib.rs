//! Independent verification of five-axis programs: tri-dexel stock simulation, overcut and
//! residual maps over the design surfaces, and shank/holder collisions.
//!
//! The crate shares no planning code with the path generators: it only reads cutters
//! (`cam_core::Cutter`), cutter locations / tool paths and a [`DesignModel`].
//!
//! Pipeline: [`TriDexel::from_shape`] samples the blank ([`BoxStock`], [`RevolvedStock`]);
//! [`simulate()`] sweeps every move's cutter through the stock ([`removal`]) and checks the
//! non-cutting parts against the stock in process (on the dexels, exact along each ray) and
//! against the design mesh (parry BVH, [`collision`]); [`endpoints`] reads the overcut at
//! the dexel segment end points (exact ray–cutter intersections: the depth of every cut end
//! point inside the design, within `Metrics::overcut_error_bound_mm` =
//! sweep tolerance + ¾·h²/ρ of the truth) and [`measure`] probes the finished stock along
//! design normals for the residual and for through-cuts where no end point is left;
//! [`surface_mesh`] extracts an STL of the final stock; [`crosscheck`] compares the dexel
//! overcut with cam-core's swept envelopes.
//! [`ImpellerDesign`] makes an `impeller_model::Impeller` a [`DesignModel`].
//!
//! Figures (blank of the 77 mm fixture impeller, Ø79 × 44 mm; `examples/removal_100k.rs`,
//! release, 2 shared cores): at 0.1 mm the three grids hold 1,327,392 rays in 31.9 MB
//! (24 bytes per ray inline, 46.3 MB after 100,000 five-axis moves); at 0.2 mm 334,671 rays
//! in 8.0 MB — memory and work per cutter position scale as O(h⁻²) per direction. 100,000
//! moves of a tapered ball end (204,777 positions) take 14.2 s CPU at 0.1 mm (3.2 s at
//! 0.2 mm); the full `simulate` against the impeller (design collisions and 55,680 surface
//! samples) adds 1.0 s and 3.0 s; peak RSS 125 MB.
//!
//! ```
//! use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath};
//! use machining_sim::{simulate, BoxDesign, BoxStock, SimOptions, TriDexel};
//!
//! // A 20 × 20 × 10 mm block at 0.25 mm; the design is its lower 6 mm.
//! let blank = BoxStock::new([0.0, 0.0, 0.0], [20.0, 20.0, 10.0])?;
//! let mut stock = TriDexel::from_shape(&blank, 0.25)?;
//! let design = BoxDesign { min: [0.0, 0.0, 0.0], max: [20.0, 20.0, 6.0], sample_spacing: 1.0 };
//! let cutter = Cutter::new("f6", CutterShape::FlatEnd { radius: 3.0 }, 20.0, 3.0, 40.0)?;
//! let mut path = ToolPath::new("plunge", "f6");
//! for (kind, z) in [(MoveKind::Rapid, 15.0), (MoveKind::Plunge, 5.5), (MoveKind::Retract, 15.0)] {
//!     let cl = CutterLocation::vertical(Point3::new(10.0, 10.0, z));
//!     path.moves.push(Move { kind, cl, feed_mm_per_min: None });
//! }
//! let report = simulate(&mut stock, &design, &[(cutter, path)], &SimOptions::default())?;
//! // The plunge went 0.5 mm below the design's top face.
//! assert!((report.metrics.max_overcut_mm - 0.5).abs() < 0.25);
//! assert_eq!(report.metrics.collisions, 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Dependencies: parry3d-f64 (workspace choice) for the BVH over the design mesh; rayon for
//! the per-row parallelism.

pub mod collision;
pub mod crosscheck;
mod cull;
pub mod design;
mod design_memo;
pub mod dexel;
pub mod endpoints;
pub mod error;
pub mod export;
pub mod fillet_design;
pub mod impeller_design;
pub mod measure;
pub mod merge;
pub mod motion;
mod reach;
pub mod removal;
pub mod simulate;
pub mod stock_shape;
pub mod surface_mesh;
pub mod synthetic;
pub mod tool_solid;
mod witness;

pub use crosscheck::{
    crosscheck_location, crosscheck_overcut, CrossCheckLocation, CrossCheckPoint, Envelopes,
};
pub use design::{BoxDesign, CylinderDesign, DesignModel, SurfaceGrid, TriangleMesh, UnionDesign};
pub use dexel::{DexelGrid, GridGeometry, Segments, TriDexel};
pub use endpoints::{overcut_error_bound, EndpointDepth};
pub use error::SimError;
pub use impeller_design::{blank_of, ImpellerDesign, ImpellerSampling};
pub use measure::{Extremum, Measured, SurfaceMap};
pub use motion::Interpolation;
pub use removal::PartKind;
pub use simulate::{
    cut, simulate, simulate_residual, Collision, CollisionTarget, CutOutcome, Metrics,
    ProgressSink, Report, SimOptions, SimProgress, SimStats,
};
pub use stock_shape::{BoxStock, RevolvedStock, StockShape};
pub use surface_mesh::{extract_surface, write_stl, StockMesh};

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
