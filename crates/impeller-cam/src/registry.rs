//! The operation registry: which operation kinds a job may name, and the builder of each.
//!
//! One static table of `(kind name, builder)`; adding a kind is one line in [`OPERATIONS`]
//! (the builder comes from the kind's crate, e.g. `plunge_opt::build`). The pipeline knows an
//! operation only through [`cam_plan::Operation`] and this table; [`crate::run_job_with`] and
//! [`crate::Job::from_toml_str_with`] take another table (a library user's own kinds, test
//! operations).

use cam_plan::{Builder, Operation, OperationSpec, PlanError};

/// A registry: `(kind name, builder)` rows.
pub type Registry = [(&'static str, Builder)];

/// The registered operation kinds of this release, in the order a process plan uses them.
pub static OPERATIONS: &Registry = &[
    (plunge_opt::KIND, plunge_opt::build),
    (
        channel_paths::CHANNEL_ROUGHING,
        channel_paths::build_channel_roughing,
    ),
    (
        channel_paths::HUB_FINISHING,
        channel_paths::build_hub_finishing,
    ),
    (
        flank_opt::FLANK_SEMI_FINISHING,
        flank_opt::build_flank_semi_finishing,
    ),
    (
        channel_paths::BLADE_ROOT_FINISHING,
        channel_paths::build_blade_root_finishing,
    ),
    (flank_opt::FLANK_FINISHING, flank_opt::build_flank_finishing),
    (
        flank_opt::BLADE_POINT_FINISHING,
        flank_opt::build_blade_point_finishing,
    ),
    (
        channel_paths::REST_FINISHING,
        channel_paths::build_rest_finishing,
    ),
];

/// The builder of `kind`, if registered.
pub fn builder(registry: &Registry, kind: &str) -> Option<Builder> {
    registry.iter().find(|(k, _)| *k == kind).map(|(_, b)| *b)
}

/// The registered kind names, comma-separated (for error messages).
pub fn known(registry: &Registry) -> String {
    if registry.is_empty() {
        "none registered in this release".into()
    } else {
        registry
            .iter()
            .map(|(k, _)| *k)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Builds the operation of `spec` with `registry`.
///
/// Errors: [`PlanError::UnknownKind`] when the kind is not registered; whatever the kind's
/// builder returns (usually [`PlanError::Param`] naming the key).
pub fn build(registry: &Registry, spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    match builder(registry, &spec.kind) {
        Some(b) => b(spec),
        None => Err(PlanError::UnknownKind {
            operation: spec.name.clone(),
            kind: spec.kind.clone(),
            known: known(registry),
        }),
    }
}
