//! Built-in fixture impellers (the TOML files under `fixtures/` of the repository).

use crate::error::ModelError;
use crate::impeller::Impeller;

/// TOML text of `fixtures/impeller-8+8/impeller.toml`: 8 + 8 blades, Ø77 mm, 43 mm high,
/// 0.8 mm blades, 1 mm fillet — the embedded default of `impeller-cam run`.
pub const IMPELLER_8_8_TOML: &str = include_str!("../embedded/impeller-8+8/impeller.toml");

/// The default impeller (`impeller-8+8`).
pub fn default_impeller() -> Result<Impeller, ModelError> {
    crate::from_toml_str(IMPELLER_8_8_TOML, "fixtures/impeller-8+8/impeller.toml")
}
