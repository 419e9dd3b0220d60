//! Centrifugal impeller geometry as exact NURBS: hub, shroud, main and splitter blades, channels; builders, importers, ruled approximations.

pub mod import;
