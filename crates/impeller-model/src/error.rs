//! Typed errors of the impeller model: every message names the file, line or field at fault.

use std::path::PathBuf;

/// Everything that can go wrong while reading, validating or building an impeller.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file's extension names no supported format.
    #[error("{path}: unsupported impeller format (expected .toml, .inf, .geomTurbo or .rtzt)")]
    UnsupportedFormat {
        /// The file concerned.
        path: PathBuf,
    },
    /// The TOML text is malformed or a field has the wrong type.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line of the error (0 when unknown).
        line: usize,
        /// What the parser expected.
        message: String,
    },
    /// A parameter is out of its valid range; `field` is its dotted path (`main.count`).
    #[error("{field} {reason}")]
    Invalid {
        /// Dotted path of the parameter (`main.thickness_mm[2]`).
        field: String,
        /// What is wrong, phrased to follow the field name (`must be > 0`).
        reason: String,
    },
    /// A validation error located in a file.
    #[error("{path}:{line}: {source}")]
    InFile {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line of the offending field (0 when unknown).
        line: usize,
        /// The validation error.
        source: Box<ModelError>,
    },
    /// The assembled geometry is inconsistent (e.g. blades intersect, sides swapped).
    #[error("invalid geometry: {0}")]
    Geometry(String),
    /// A blade-design export (or an import file pointing at one) could not be imported.
    #[error(transparent)]
    Import(#[from] crate::import::ImportError),
    /// A blade side's isoparametric line u does not cross hub or shroud within the side's v
    /// range (the side is too short, or the wall does not pass between its v ends): there is
    /// no edge point at this u. `wall` is `None` when the caller passed a bare surface.
    #[error("{side:?} side of the blade: isoparametric line u = {u} does not cross the {}", wall_name(*.wall))]
    EdgeMissesWall {
        /// The blade side searched.
        side: crate::blade::Side,
        /// Hub or shroud, when known.
        wall: Option<crate::channel::Wall>,
        /// The side's u parameter at which no crossing was found.
        u: f64,
    },
    /// A blade side's edge on hub or shroud has no sample at all (`n` samples requested).
    #[error("{side:?} side of the blade does not meet the {} at any of {n} u samples", wall_name(*.wall))]
    EdgeEmpty {
        /// The blade side searched.
        side: crate::blade::Side,
        /// Hub or shroud, when known.
        wall: Option<crate::channel::Wall>,
        /// Number of u samples tried.
        n: usize,
    },
    /// A bounding side of channel `channel` does not reach contour parameter `t` of the wall
    /// (`t` lies beyond the leading or trailing edge of that blade there).
    #[error("channel {channel}: the {bound} blade's {side:?} side does not reach the {} at contour parameter t = {t}", wall_name(*.wall))]
    SectionOutOfReach {
        /// Channel index.
        channel: usize,
        /// `"left"` or `"right"`: which bounding blade misses.
        bound: &'static str,
        /// Its side that bounds the channel.
        side: crate::blade::Side,
        /// Hub or shroud, when known.
        wall: Option<crate::channel::Wall>,
        /// The wall's contour parameter.
        t: f64,
    },
    /// The hub edge of a side does not lie below its shroud edge (`v_hub >= v_shroud`): the side
    /// does not span the channel between hub and shroud.
    #[error(
        "{side:?} side of the blade: hub edge v = {v_hub} is not below shroud edge v = {v_shroud}"
    )]
    SpanInverted {
        /// The blade side.
        side: crate::blade::Side,
        /// Smallest v of the hub edge.
        v_hub: f64,
        /// Largest v of the shroud edge.
        v_shroud: f64,
    },
    /// The line `c + λ n` was not met on the surface by Newton's method started at (u, v, λ0).
    #[error("line-surface intersection from (u, v, λ) = ({u}, {v}, {lambda0}) failed: {reason} (residual {residual_mm} mm)")]
    LineMissesSurface {
        /// Start u.
        u: f64,
        /// Start v.
        v: f64,
        /// Start λ.
        lambda0: f64,
        /// Distance between line point and surface point when the iteration stopped (mm).
        residual_mm: f64,
        /// Why it stopped: singular Jacobian (line tangent to the surface) or no convergence.
        reason: &'static str,
    },
    /// An error from the NURBS kernel while building a curve or surface.
    #[error("nurbs: {0}")]
    Nurbs(#[from] nurbs::NurbsError),
}

fn wall_name(w: Option<crate::channel::Wall>) -> &'static str {
    match w {
        Some(crate::channel::Wall::Hub) => "hub",
        Some(crate::channel::Wall::Shroud) => "shroud",
        None => "wall (hub or shroud)",
    }
}

impl ModelError {
    /// Shorthand for [`ModelError::Invalid`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// This error with its unknown wall (`wall: None`) set to `wall`; other errors unchanged.
    pub fn on_wall(mut self, w: crate::channel::Wall) -> Self {
        match &mut self {
            Self::EdgeMissesWall { wall, .. }
            | Self::EdgeEmpty { wall, .. }
            | Self::SectionOutOfReach { wall, .. } => {
                wall.get_or_insert(w);
            }
            _ => {}
        }
        self
    }

    /// The dotted field path when this is (or wraps) a validation error.
    pub fn field(&self) -> Option<&str> {
        match self {
            Self::Invalid { field, .. } => Some(field),
            Self::InFile { source, .. } => source.field(),
            _ => None,
        }
    }
}
