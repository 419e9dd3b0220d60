//! The parametric impeller file (TOML): schema, validation with field-naming errors, and the
//! lookup of the line a field sits on.
//!
//! ```toml
//! name = "example"
//! fillet_radius_mm = 1.0
//! [hub]                      # meridional contour (z, r) from inlet to outlet
//! type = "quarter_ellipse"   # or "bspline" with degree, control_points_zr_mm, weights
//! inlet_zr_mm = [43.0, 8.0]
//! outlet_zr_mm = [4.0, 38.5]
//! [shroud]
//! type = "quarter_ellipse"
//! inlet_zr_mm = [43.0, 22.0]
//! outlet_zr_mm = [12.0, 38.5]
//! [main]
//! count = 8
//! kind = "ruled"             # or "free_form" (three or more wrap spans)
//! thickness_mm = [[0.0, 0.8], [1.0, 0.8]]   # (blade meridional fraction, normal thickness)
//! leading_edge = "rounded"   # or "blunt"
//! trailing_edge = "blunt"
//! [[main.wrap]]              # wrap angle θ(m) in degrees at span 0 (hub) ... 1 (shroud)
//! span = 0.0
//! theta_deg = [[0.0, 0.0], [1.0, 40.0]]
//! [[main.wrap]]
//! span = 1.0
//! theta_deg = [[0.0, 0.0], [1.0, 40.0]]
//! [splitter]                 # optional; follows the main camber, shifted in θ
//! count = 8
//! start_fraction = 0.35      # of the meridional length
//! [stock]
//! diameter_mm = 80.0
//! height_mm = 45.0
//! ```
//!
//! Wrap angles are tabulated against the meridional fraction m of the impeller (0 at the
//! inlet, 1 at the outlet, arc length along the hub or shroud contour, linear between them);
//! thickness against the blade's own meridional fraction (a splitter's 0 is its leading edge).

use crate::error::ModelError;
use crate::law::Law;
use crate::thickness::EdgeShape;
use serde::{Deserialize, Serialize};

/// A whole parametric impeller file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpellerSpec {
    /// Name used in reports.
    pub name: String,
    /// Hub (blade-root) fillet radius in mm; tools must respect it.
    pub fillet_radius_mm: f64,
    /// Hub meridional contour, inlet to outlet.
    pub hub: ContourSpec,
    /// Shroud (blade-tip) meridional contour, inlet to outlet.
    pub shroud: ContourSpec,
    /// Main blades.
    pub main: BladeSpec,
    /// Splitter blades, if any.
    #[serde(default)]
    pub splitter: Option<SplitterSpec>,
    /// The blank.
    pub stock: StockSpec,
}

/// A meridional contour in the (z, r) half plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContourSpec {
    /// Exact quarter ellipse from the inlet point (tangent along −z) to the outlet point
    /// (tangent along +r); its corner is (z_outlet, r_inlet).
    QuarterEllipse {
        /// Inlet point (z, r) in mm.
        inlet_zr_mm: [f64; 2],
        /// Outlet point (z, r) in mm.
        outlet_zr_mm: [f64; 2],
    },
    /// A clamped B-spline / NURBS on a uniform knot vector through its control points.
    Bspline {
        /// Polynomial degree (1 to 5).
        degree: usize,
        /// Control points (z, r) in mm, inlet first.
        control_points_zr_mm: Vec<[f64; 2]>,
        /// Optional positive weights (rational curve).
        #[serde(default)]
        weights: Option<Vec<f64>>,
    },
}

/// Ruled or free-form blades.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BladeKindSpec {
    /// Straight rulings between hub and shroud camber curves (wrap at exactly two spans).
    Ruled,
    /// Skinned through three or more span curves.
    FreeForm,
}

/// Wrap angle at one span.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrapSpec {
    /// Span fraction: 0 at the hub, 1 at the shroud.
    pub span: f64,
    /// Wrap angle table (m, θ in degrees).
    pub theta_deg: Vec<[f64; 2]>,
}

/// The main blade row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeSpec {
    /// Number of main blades.
    pub count: usize,
    /// Ruled or free-form.
    pub kind: BladeKindSpec,
    /// Normal thickness table (blade meridional fraction, mm).
    pub thickness_mm: Vec<[f64; 2]>,
    /// Leading-edge shape.
    pub leading_edge: EdgeShape,
    /// Trailing-edge shape.
    pub trailing_edge: EdgeShape,
    /// How far blade surfaces extend beyond hub and shroud, as a fraction of the span: the
    /// least extension; the builder doubles it (up to
    /// [`crate::builder::MAX_SPAN_EXTENSION`]) while a side ends short of hub or shroud.
    #[serde(default = "default_span_extension")]
    pub span_extension: f64,
    /// Wrap angle at two (ruled) or three or more (free-form) spans, hub first.
    pub wrap: Vec<WrapSpec>,
}

fn default_span_extension() -> f64 {
    0.05
}

fn default_pitch_fraction() -> f64 {
    0.5
}

/// The splitter row: the main camber shifted by a fraction of the pitch, starting downstream.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SplitterSpec {
    /// Number of splitters (equal to the main blade count).
    pub count: usize,
    /// Meridional fraction where splitters start (their leading edge).
    pub start_fraction: f64,
    /// Angular position between main blade k (0) and k+1 (1).
    #[serde(default = "default_pitch_fraction")]
    pub pitch_fraction: f64,
    /// Thickness table (splitter meridional fraction, mm); the main table when absent.
    #[serde(default)]
    pub thickness_mm: Option<Vec<[f64; 2]>>,
    /// Leading-edge shape; the main blade's when absent.
    #[serde(default)]
    pub leading_edge: Option<EdgeShape>,
    /// Trailing-edge shape; the main blade's when absent.
    #[serde(default)]
    pub trailing_edge: Option<EdgeShape>,
}

/// The blank: a cylinder (diameter and height from z = 0) or a turned profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StockSpec {
    /// Cylinder diameter (mm).
    #[serde(default)]
    pub diameter_mm: Option<f64>,
    /// Cylinder height above the hub back face (mm).
    #[serde(default)]
    pub height_mm: Option<f64>,
    /// Outer profile (z, r) in mm, z increasing: the blank is r ≤ r(z) between first and last z.
    #[serde(default)]
    pub profile_zr_mm: Option<Vec<[f64; 2]>>,
}

fn check_finite_pos(field: &str, v: f64, allow_zero: bool) -> Result<(), ModelError> {
    if !v.is_finite() {
        return Err(ModelError::invalid(field, "must be finite"));
    }
    if allow_zero && v < 0.0 {
        return Err(ModelError::invalid(field, "must be >= 0"));
    }
    if !allow_zero && v <= 0.0 {
        return Err(ModelError::invalid(field, "must be > 0"));
    }
    Ok(())
}

fn check_fraction(field: &str, v: f64) -> Result<(), ModelError> {
    if !v.is_finite() || !(0.0..=1.0).contains(&v) {
        return Err(ModelError::invalid(field, "must lie in [0, 1]"));
    }
    Ok(())
}

fn check_zr(field: &str, p: [f64; 2]) -> Result<(), ModelError> {
    if !p[0].is_finite() || !p[1].is_finite() {
        return Err(ModelError::invalid(field, "must be finite"));
    }
    if p[1] < 0.0 {
        return Err(ModelError::invalid(field, "must have radius r >= 0"));
    }
    Ok(())
}

/// Checks that a thickness law stays positive between its table points (the cubic spline can
/// undershoot), sampled at 401 fractions.
fn check_positive_law(field: &str, law: &Law) -> Result<(), ModelError> {
    for k in 0..=400 {
        let m = k as f64 / 400.0;
        let t = law.eval(m);
        if t.is_nan() || t <= 0.0 {
            return Err(ModelError::invalid(
                field,
                format!(
                    "must stay > 0 between its points (the spline reaches {t:.4} mm at {m:.3})"
                ),
            ));
        }
    }
    Ok(())
}

/// Checks a table of (fraction, value) pairs and builds its law.
fn check_table(field: &str, table: &[[f64; 2]], positive: bool) -> Result<Law, ModelError> {
    for (i, p) in table.iter().enumerate() {
        check_fraction(&format!("{field}[{i}][0]"), p[0])?;
        if positive {
            check_finite_pos(&format!("{field}[{i}][1]"), p[1], false)?;
        } else if !p[1].is_finite() {
            return Err(ModelError::invalid(
                format!("{field}[{i}][1]"),
                "must be finite",
            ));
        }
    }
    let law = Law::new(table).map_err(|r| ModelError::invalid(field, r))?;
    if positive {
        check_positive_law(field, &law)?;
    }
    Ok(law)
}

impl ContourSpec {
    fn validate(&self, field: &str) -> Result<(), ModelError> {
        match self {
            Self::QuarterEllipse {
                inlet_zr_mm,
                outlet_zr_mm,
            } => {
                check_zr(&format!("{field}.inlet_zr_mm"), *inlet_zr_mm)?;
                check_zr(&format!("{field}.outlet_zr_mm"), *outlet_zr_mm)?;
                if (inlet_zr_mm[0] - outlet_zr_mm[0]).abs() < 1e-6 {
                    return Err(ModelError::invalid(
                        format!("{field}.outlet_zr_mm"),
                        "must differ from the inlet in z",
                    ));
                }
                if (inlet_zr_mm[1] - outlet_zr_mm[1]).abs() < 1e-6 {
                    return Err(ModelError::invalid(
                        format!("{field}.outlet_zr_mm"),
                        "must differ from the inlet in r",
                    ));
                }
            }
            Self::Bspline {
                degree,
                control_points_zr_mm,
                weights,
            } => {
                if !(1..=5).contains(degree) {
                    return Err(ModelError::invalid(
                        format!("{field}.degree"),
                        "must be 1 to 5",
                    ));
                }
                if control_points_zr_mm.len() <= *degree {
                    return Err(ModelError::invalid(
                        format!("{field}.control_points_zr_mm"),
                        format!("must hold more than degree = {degree} points"),
                    ));
                }
                for (i, p) in control_points_zr_mm.iter().enumerate() {
                    check_zr(&format!("{field}.control_points_zr_mm[{i}]"), *p)?;
                }
                if let Some(w) = weights {
                    if w.len() != control_points_zr_mm.len() {
                        return Err(ModelError::invalid(
                            format!("{field}.weights"),
                            "must have one weight per control point",
                        ));
                    }
                    for (i, &wi) in w.iter().enumerate() {
                        check_finite_pos(&format!("{field}.weights[{i}]"), wi, false)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Validated design laws of one blade row, ready for the builder.
#[derive(Debug, Clone)]
pub(crate) struct RowLaws {
    pub thickness: Law,
    pub spans: Vec<f64>,
    pub wraps_rad: Vec<Law>,
}

impl BladeSpec {
    pub(crate) fn validate(&self) -> Result<RowLaws, ModelError> {
        if self.count == 0 || self.count > 360 {
            return Err(ModelError::invalid("main.count", "must be 1 to 360"));
        }
        if !self.span_extension.is_finite() || !(0.0..=0.5).contains(&self.span_extension) {
            return Err(ModelError::invalid(
                "main.span_extension",
                "must lie in [0, 0.5]",
            ));
        }
        let thickness = check_table("main.thickness_mm", &self.thickness_mm, true)?;
        match self.kind {
            BladeKindSpec::Ruled if self.wrap.len() != 2 => {
                return Err(ModelError::invalid(
                    "main.wrap",
                    "must give exactly two spans (hub 0 and shroud 1) for ruled blades",
                ))
            }
            BladeKindSpec::FreeForm if self.wrap.len() < 3 => {
                return Err(ModelError::invalid(
                    "main.wrap",
                    "must give three or more spans for free-form blades",
                ))
            }
            _ => {}
        }
        let mut spans = Vec::new();
        let mut wraps = Vec::new();
        for (k, w) in self.wrap.iter().enumerate() {
            let f = format!("main.wrap[{k}].span");
            check_fraction(&f, w.span)?;
            if k == 0 && w.span != 0.0 {
                return Err(ModelError::invalid(f, "must be 0 (hub) for the first span"));
            }
            if k + 1 == self.wrap.len() && w.span != 1.0 {
                return Err(ModelError::invalid(
                    f,
                    "must be 1 (shroud) for the last span",
                ));
            }
            if k > 0 && w.span <= self.wrap[k - 1].span {
                return Err(ModelError::invalid(f, "must increase strictly"));
            }
            check_table(&format!("main.wrap[{k}].theta_deg"), &w.theta_deg, false)?;
            let rad: Vec<[f64; 2]> = w
                .theta_deg
                .iter()
                .map(|p| [p[0], p[1].to_radians()])
                .collect();
            spans.push(w.span);
            wraps.push(Law::new(&rad).map_err(|r| ModelError::invalid("main.wrap", r))?);
        }
        Ok(RowLaws {
            thickness,
            spans,
            wraps_rad: wraps,
        })
    }
}

impl SplitterSpec {
    pub(crate) fn validate(&self, main_count: usize) -> Result<Option<Law>, ModelError> {
        if self.count != main_count {
            return Err(ModelError::invalid(
                "splitter.count",
                format!("must equal main.count = {main_count}"),
            ));
        }
        if !self.start_fraction.is_finite()
            || self.start_fraction <= 0.0
            || self.start_fraction >= 0.95
        {
            return Err(ModelError::invalid(
                "splitter.start_fraction",
                "must lie in (0, 0.95)",
            ));
        }
        if !self.pitch_fraction.is_finite()
            || self.pitch_fraction <= 0.0
            || self.pitch_fraction >= 1.0
        {
            return Err(ModelError::invalid(
                "splitter.pitch_fraction",
                "must lie in (0, 1)",
            ));
        }
        self.thickness_mm
            .as_ref()
            .map(|t| check_table("splitter.thickness_mm", t, true))
            .transpose()
    }
}

impl StockSpec {
    /// The outer profile (z, r) of the blank, validated.
    pub(crate) fn validate(&self) -> Result<Vec<[f64; 2]>, ModelError> {
        match (&self.profile_zr_mm, self.diameter_mm, self.height_mm) {
            (Some(p), None, None) => {
                if p.len() < 2 {
                    return Err(ModelError::invalid(
                        "stock.profile_zr_mm",
                        "must hold at least two points",
                    ));
                }
                for (i, q) in p.iter().enumerate() {
                    check_zr(&format!("stock.profile_zr_mm[{i}]"), *q)?;
                    if i > 0 && q[0] <= p[i - 1][0] {
                        return Err(ModelError::invalid(
                            format!("stock.profile_zr_mm[{i}]"),
                            "must have z increasing strictly",
                        ));
                    }
                }
                Ok(p.clone())
            }
            (None, Some(d), Some(h)) => {
                check_finite_pos("stock.diameter_mm", d, false)?;
                check_finite_pos("stock.height_mm", h, false)?;
                Ok(vec![[0.0, 0.5 * d], [h, 0.5 * d]])
            }
            (None, Some(_), None) => Err(ModelError::invalid(
                "stock.height_mm",
                "is required with stock.diameter_mm",
            )),
            (None, None, Some(_)) => Err(ModelError::invalid(
                "stock.diameter_mm",
                "is required with stock.height_mm",
            )),
            _ => Err(ModelError::invalid(
                "stock",
                "must give either diameter_mm and height_mm, or profile_zr_mm",
            )),
        }
    }
}

impl ImpellerSpec {
    /// Parses TOML text (no validation).
    pub fn from_toml_str(text: &str) -> Result<Self, toml::de::Error> {
        toml::from_str(text)
    }

    /// Checks every scalar range and table; geometric consistency (shroud above hub, blades
    /// apart, stock around the blades) is checked when the impeller is built.
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.name.trim().is_empty() {
            return Err(ModelError::invalid("name", "must not be empty"));
        }
        check_finite_pos("fillet_radius_mm", self.fillet_radius_mm, true)?;
        self.hub.validate("hub")?;
        self.shroud.validate("shroud")?;
        self.main.validate()?;
        if let Some(s) = &self.splitter {
            s.validate(self.main.count)?;
        }
        self.stock.validate()?;
        Ok(())
    }
}

/// 1-based line of the TOML text where the dotted `field` (e.g. `main.wrap[1].span`) is set,
/// or where its table starts; 0 when it cannot be found.
pub fn field_line(text: &str, field: &str) -> usize {
    // Split "a.b[1].c" into (table path "a.b", occurrence 1, key "c").
    let segs: Vec<&str> = field.split('.').collect();
    let (key_seg, table_segs) = match segs.split_last() {
        Some((k, t)) => (*k, t),
        None => return 0,
    };
    let strip = |s: &str| -> (String, usize) {
        match s.find('[') {
            Some(i) => {
                let idx = s[i + 1..]
                    .split(']')
                    .next()
                    .and_then(|n| n.parse().ok())
                    .unwrap_or(0);
                (s[..i].to_string(), idx)
            }
            None => (s.to_string(), 0),
        }
    };
    let mut occurrence = 0;
    let table: Vec<String> = table_segs
        .iter()
        .map(|s| {
            let (n, i) = strip(s);
            occurrence = i;
            n
        })
        .collect();
    let table = table.join(".");
    let key = strip(key_seg).0;
    let mut seen = 0usize;
    let mut table_line = 0;
    let mut in_target = table.is_empty();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.starts_with('[') {
            let name = line
                .trim_matches(|c| c == '[' || c == ']')
                .trim()
                .to_string();
            in_target = false;
            if name == table {
                if seen == occurrence {
                    in_target = true;
                    table_line = i + 1;
                }
                seen += 1;
            } else if table.is_empty() {
                in_target = false;
            }
            // A whole table as the field ("stock"): its header line.
            if table.is_empty() && name == key {
                return i + 1;
            }
            continue;
        }
        if in_target {
            if let Some(rest) = line.strip_prefix(key.as_str()) {
                if rest.trim_start().starts_with('=') {
                    return i + 1;
                }
            }
        }
    }
    table_line
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "name = \"x\"\n[main]\ncount = 3\n[[main.wrap]]\nspan = 0.0\n[[main.wrap]]\nspan = 0.5\n[stock]\nheight_mm = 3\n";

    #[test]
    fn finds_lines_of_fields() {
        assert_eq!(field_line(TEXT, "name"), 1);
        assert_eq!(field_line(TEXT, "main.count"), 3);
        assert_eq!(field_line(TEXT, "main.wrap[1].span"), 7);
        assert_eq!(field_line(TEXT, "main.wrap[0].span"), 5);
        assert_eq!(field_line(TEXT, "stock.diameter_mm"), 8);
        assert_eq!(field_line(TEXT, "stock"), 8);
        assert_eq!(field_line(TEXT, "nothing.here"), 0);
    }
}
