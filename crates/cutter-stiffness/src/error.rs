//! Typed errors of the stiffness model.

/// What was wrong with a stiffness query.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StiffnessError {
    /// A dimension or material constant is out of range.
    #[error("`{field}` = {value}: {reason}")]
    InvalidParameter {
        /// Name of the parameter (e.g. `half_angle`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        reason: &'static str,
    },
    /// The beam has no sections.
    #[error("the beam has no sections")]
    EmptyBeam,
    /// The Ritz stiffness matrix is not positive definite (degenerate geometry or too many
    /// terms for double precision).
    #[error("Rayleigh-Ritz stiffness matrix is not positive definite with {terms} terms")]
    NotPositiveDefinite {
        /// Terms per section used.
        terms: usize,
    },
    /// The adaptive Ritz expansion did not converge within its largest term count.
    #[error("Rayleigh-Ritz indicator did not converge to {rel_tol:e} within {terms} terms (last relative change {change:e})")]
    NotConverged {
        /// Terms reached.
        terms: usize,
        /// Requested relative tolerance.
        rel_tol: f64,
        /// Last relative change of the indicator.
        change: f64,
    },
    /// The cutter shape has no conical-beam model (only ball-ended and flat cutters do).
    #[error("cutter `{0}`: shape not supported by the stiffness model")]
    UnsupportedCutter(String),
    /// An invalid cutter was given.
    #[error(transparent)]
    Cutter(#[from] cam_core::CamError),
}

pub(crate) fn check(
    field: &'static str,
    value: f64,
    ok: bool,
    reason: &'static str,
) -> Result<(), StiffnessError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(StiffnessError::InvalidParameter {
            field,
            value,
            reason,
        })
    }
}
