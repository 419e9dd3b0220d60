//! From an export file to an [`Impeller`]: read, prepare, fit, assemble.
//!
//! The stock of an imported impeller is a cylinder from z = 0 to the highest contour point
//! plus `stock_margin_mm`, of radius the largest hub, shroud or blade radius plus the same
//! margin (exports carry no blank). The fillet radius is not in any export format and comes
//! from the options.

use super::error::ImportError;
use super::fit::{fit, FittedImpeller, DEFAULT_FIT_TOL_MM};
use super::geomturbo::read_geomturbo;
use super::prepare::prepare;
use super::raw::{BladeRole, LengthUnit, RawImpeller};
use super::rtzt::read_rtzt;
use super::tables::{read_tables, TableOptions};
use super::turbogrid::read_turbogrid;
use crate::blade::{Blade, BladeKind, BladeSet};
use crate::impeller::Impeller;
use crate::meridional::MeridionalCurve;
use crate::revolved::RevolvedSurface;
use crate::stock::Stock;
use nalgebra::Vector2;
use std::path::Path;

/// How an export is turned into an impeller.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// Largest allowed deviation of the fitted curves and surfaces from the data, mm.
    pub fit_tol_mm: f64,
    /// Cut hub and shroud to the bladed part widened by this fraction of its meridional
    /// length on both sides; `None` keeps the contours whole.
    pub trim_margin: Option<f64>,
    /// Extension of blade sides beyond hub and shroud, fraction of the span.
    pub span_extension: f64,
    /// Blade-root fillet radius, mm.
    pub fillet_radius_mm: f64,
    /// Radial and axial allowance of the cylindrical stock beyond the part, mm.
    pub stock_margin_mm: f64,
    /// Name of the impeller (default: the file stem).
    pub name: Option<String>,
    /// Length unit of `rtzt` files (the format has none).
    pub rtzt_unit: LengthUnit,
    /// Unit, blade counts and contour files of a folder of section tables (the tables state
    /// none of them).
    pub tables: TableOptions,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            fit_tol_mm: DEFAULT_FIT_TOL_MM,
            trim_margin: Some(0.1),
            span_extension: 0.05,
            fillet_radius_mm: 0.0,
            stock_margin_mm: 2.0,
            name: None,
            rtzt_unit: LengthUnit::Millimetre,
            tables: TableOptions::default(),
        }
    }
}

/// An imported impeller with the fitted geometry it was assembled from (fit deviations, the
/// curves for export).
#[derive(Debug, Clone)]
pub struct Imported {
    /// The impeller.
    pub impeller: Impeller,
    /// The fitted contours and blade sides with their achieved deviations.
    pub fitted: FittedImpeller,
}

/// Which importer reads `path`, by extension: `.inf` TurboGrid, `.geomturbo` AutoGrid,
/// `.rtzt` BladeGen (case-insensitive). `None` for anything else.
pub fn is_import_extension(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .as_deref(),
        Some("inf" | "geomturbo" | "rtzt")
    )
}

/// Reads an export into raw point data: a folder is read as section tables with
/// `opts.tables`, a file by its extension (see [`is_import_extension`]).
pub fn read_raw_with(path: &Path, opts: &ImportOptions) -> Result<RawImpeller, ImportError> {
    if path.is_dir() {
        return read_tables(path, &opts.tables);
    }
    read_raw(path, opts.rtzt_unit)
}

/// Reads an export into raw point data, choosing the reader by extension (see
/// [`is_import_extension`]).
pub fn read_raw(path: &Path, rtzt_unit: LengthUnit) -> Result<RawImpeller, ImportError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("inf") => read_turbogrid(path),
        Some("geomturbo") => read_geomturbo(path),
        Some("rtzt") => read_rtzt(path, rtzt_unit),
        _ => Err(ImportError::Invalid {
            file: path.to_path_buf(),
            line: 0,
            field: "file extension".into(),
            reason: "expected .inf (TurboGrid), .geomTurbo (AutoGrid) or .rtzt (BladeGen)".into(),
        }),
    }
}

/// Assembles an [`Impeller`] from fitted geometry.
pub fn assemble(fitted: &FittedImpeller, opts: &ImportOptions) -> Result<Impeller, ImportError> {
    let err = |entity: &str, e: crate::error::ModelError| ImportError::Geometry {
        file: fitted.source.clone(),
        entity: entity.to_string(),
        reason: e.to_string(),
    };
    let hub_m = MeridionalCurve::new(fitted.hub.clone()).map_err(|e| err("hub", e))?;
    let shroud_m = MeridionalCurve::new(fitted.shroud.clone()).map_err(|e| err("shroud", e))?;
    let mut main = None;
    let mut splitter = None;
    let mut r_max: f64 = 0.0;
    let mut z_max: f64 = 0.0;
    for c in [&fitted.hub, &fitted.shroud] {
        for p in c.control_points() {
            r_max = r_max.max(p[1]);
            z_max = z_max.max(p[0]);
        }
    }
    for b in &fitted.blades {
        let entity = format!("blade {:?}", b.name);
        let kind = if b.sections == 2 {
            BladeKind::Ruled
        } else {
            BladeKind::FreeForm
        };
        for s in [&b.pressure, &b.suction] {
            for p in s.control_points() {
                r_max = r_max.max(p.xy().norm());
                z_max = z_max.max(p.z);
            }
        }
        let blade = Blade::from_sides(kind, b.pressure.clone(), b.suction.clone(), None)
            .map_err(|e| err(&entity, e))?;
        let set = BladeSet::new(b.count, blade).map_err(|e| err(&entity, e))?;
        let slot = match b.role {
            BladeRole::Main => &mut main,
            BladeRole::Splitter => &mut splitter,
        };
        if slot.is_some() {
            return Err(ImportError::Geometry {
                file: fitted.source.clone(),
                entity,
                reason: "only one main blade and one splitter row per impeller are supported"
                    .into(),
            });
        }
        *slot = Some(set);
    }
    let main = main.ok_or_else(|| ImportError::Geometry {
        file: fitted.source.clone(),
        entity: "blades".into(),
        reason: "no main blade".into(),
    })?;
    let m = opts.stock_margin_mm.max(0.0);
    let stock = Stock::from_profile(vec![[0.0, r_max + m], [z_max + m, r_max + m]])
        .map_err(|e| err("stock", e))?;
    let name = opts.name.clone().unwrap_or_else(|| {
        fitted
            .source
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("imported impeller")
            .to_string()
    });
    Impeller::from_parts(
        name,
        RevolvedSurface::new(hub_m).map_err(|e| err("hub", e))?,
        RevolvedSurface::new(shroud_m).map_err(|e| err("shroud", e))?,
        main,
        splitter,
        opts.fillet_radius_mm,
        stock,
    )
    .map_err(|e| err("impeller", e))
}

/// Fails when a fitted curve or surface misses its data by more than the tolerance, naming
/// the entity, the section and data point farthest from it, and its distance.
pub fn check_tolerance(fitted: &FittedImpeller) -> Result<(), ImportError> {
    let mut entities = vec![
        ("hub".to_string(), fitted.hub_fit_mm, fitted.hub_miss, false),
        (
            "shroud".to_string(),
            fitted.shroud_fit_mm,
            fitted.shroud_miss,
            false,
        ),
    ];
    for b in &fitted.blades {
        entities.push((
            format!("blade {:?} pressure side", b.name),
            b.pressure_fit_mm,
            b.pressure_miss,
            true,
        ));
        entities.push((
            format!("blade {:?} suction side", b.name),
            b.suction_fit_mm,
            b.suction_miss,
            true,
        ));
    }
    match entities
        .into_iter()
        .find(|(_, d, _, _)| d.is_nan() || *d > fitted.tol_mm)
    {
        Some((entity, d, m, blade)) => {
            let p = m.at_mm;
            let place = if blade {
                format!(
                    "section {} (from the hub), data point {} (from the leading edge) at \
                     ({:.4}, {:.4}, {:.4}) mm",
                    m.section + 1,
                    m.point + 1,
                    p.x,
                    p.y,
                    p.z
                )
            } else {
                format!(
                    "data point {} (from the inlet) at z = {:.4} mm, r = {:.4} mm",
                    m.point + 1,
                    p.z,
                    p.y
                )
            };
            Err(ImportError::Geometry {
                file: fitted.source.clone(),
                entity,
                reason: format!(
                    "{place}: the closest fit misses it by {} mm, more than the fit \
                     tolerance {} mm (an outlier or data too sparse for a knot there; a \
                     larger tolerance — `--fit-tol`, `fit_tol_mm` — accepts it)",
                    short_mm(d),
                    short_mm(fitted.tol_mm)
                ),
            })
        }
        None => Ok(()),
    }
}

/// Fails when a fitted blade side leaves the impeller's meridional extent by more than a
/// fifth of that extent: the fit passes through every data point within tolerance, but
/// sections too irregular for one surface (a fillet flare in one section, leading edges
/// that jump between sections) can make it swing far between or beyond them. Each side is
/// sampled on a 161 × 33 grid (u × v) over its whole domain (span extension included) against the
/// hub and shroud curves sampled at 201 points: the extent is `E = max(R, Z₁ − Z₀)` with `R`
/// their largest radius and `[Z₀, Z₁]` their axial range; a side point must have
/// `r ≤ R + E/5` and `Z₀ − E/5 ≤ z ≤ Z₁ + E/5`. Cost 2·161·33 evaluations per blade.
pub fn check_extent(fitted: &FittedImpeller) -> Result<(), ImportError> {
    let (mut r_max, mut z0, mut z1) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    for c in [&fitted.hub, &fitted.shroud] {
        let (a, b) = c.domain();
        for k in 0..=200 {
            let p = c.point(a + (b - a) * k as f64 / 200.0);
            r_max = r_max.max(p[1]);
            z0 = z0.min(p[0]);
            z1 = z1.max(p[0]);
        }
    }
    let e = r_max.max(z1 - z0);
    let slack = e / 5.0;
    for b in &fitted.blades {
        for (side, s) in [("pressure", &b.pressure), ("suction", &b.suction)] {
            let ((u0, u1), (v0, v1)) = s.domain();
            let mut worst: Option<(f64, nalgebra::Vector3<f64>, f64, f64)> = None;
            for i in 0..=160 {
                for j in 0..=32 {
                    let (u, v) = (
                        u0 + (u1 - u0) * i as f64 / 160.0,
                        v0 + (v1 - v0) * j as f64 / 32.0,
                    );
                    let p = s.point(u, v);
                    let r = (p.x * p.x + p.y * p.y).sqrt();
                    let out = (r - r_max - slack)
                        .max(z0 - slack - p.z)
                        .max(p.z - z1 - slack);
                    let outside = !out.is_finite() || out > 0.0;
                    if outside && worst.is_none_or(|(w, ..)| out > w || !out.is_finite()) {
                        worst = Some((out, p, u, v));
                    }
                }
            }
            if let Some((_, p, u, v)) = worst {
                return Err(ImportError::Geometry {
                    file: fitted.source.clone(),
                    entity: format!("blade {:?} {side} side", b.name),
                    reason: format!(
                        "the fitted surface leaves the impeller: at (u, v) = ({u:.3}, \
                         {v:.3}) it reaches ({:.1}, {:.1}, {:.1}) mm (r = {:.1} mm), while hub and shroud span r ≤ {:.1} mm and \
                         z {:.1} to {:.1} mm (more than a fifth of that extent beyond them): \
                         its sections are too irregular for one surface through all of them \
                         (a fillet flare in some sections, edges that jump between sections)",
                        p.x,
                        p.y,
                        p.z,
                        (p.x * p.x + p.y * p.y).sqrt(),
                        r_max,
                        z0,
                        z1
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Fails when a fitted blade side (span extension included) stops short of the shroud or
/// of the hub by more than the fit tolerance: the impeller model has every blade run from
/// the hub through the shroud contour, its tip cut by that contour. Sections that end below
/// the shroud (a blade tip with clearance, or blades of another state than the flow path —
/// the as-manufactured cold blades of an archive next to its hot design-intent shroud) would
/// leave the blade without a tip. Each side's top and bottom edges are sampled at 161 points
/// and projected on the assembled impeller's contours (`MeridionalCurve::closest_point`,
/// certified global); samples whose nearest contour point is a contour end are skipped.
/// Cost 2·161 projections per blade side.
pub fn check_reach(fitted: &FittedImpeller, impeller: &Impeller) -> Result<(), ImportError> {
    let tol = fitted.tol_mm.max(0.0);
    // How far a meridional point lies inside the flow path from a contour: the channel side
    // of the hub, below the shroud (`RevolvedSurface::signed_distance` signs); `None` where the
    // nearest contour point is an end of the contour (beyond it no side is defined).
    let short_of = |c: &MeridionalCurve, sign: f64, m: Vector2<f64>| -> Option<f64> {
        let (t, d, _) = c.closest_point(m);
        let (t0, t1) = c.domain();
        let end = 1e-9 * (t1 - t0);
        (t > t0 + end && t < t1 - end).then_some(sign * d)
    };
    for b in &fitted.blades {
        for (side, s) in [("pressure", &b.pressure), ("suction", &b.suction)] {
            let ((u0, u1), (v0, v1)) = s.domain();
            for (edge, v, contour, sign, name) in [
                ("top", v1, impeller.shroud().meridional(), -1.0, "shroud"),
                ("bottom", v0, impeller.hub().meridional(), 1.0, "hub"),
            ] {
                let mut worst: Option<(f64, f64, Vector2<f64>)> = None;
                for i in 0..=160 {
                    let u = u0 + (u1 - u0) * i as f64 / 160.0;
                    let m = MeridionalCurve::zr_of(&s.point(u, v));
                    if let Some(d) = short_of(contour, sign, m) {
                        if d > tol && worst.is_none_or(|(w, ..)| d > w) {
                            worst = Some((d, u, m));
                        }
                    }
                }
                if let Some((d, u, m)) = worst {
                    return Err(ImportError::Geometry {
                        file: fitted.source.clone(),
                        entity: format!("blade {:?} {side} side", b.name),
                        reason: format!(
                            "its {edge} edge (span extension included) stops {d:.3} mm short of \
                             the {name} contour at (z, r) = ({:.2}, {:.2}) mm (u = {u:.3}): \
                             every blade must run from the hub through the shroud contour. The \
                             sections end inside the flow path (a blade tip with clearance, or \
                             blades of another state than the flow path, such as cold \
                             as-manufactured blades next to a hot design-intent {name}); give \
                             a {name} contour through the blades' {edge} (`{name}_file`)",
                            m.x, m.y
                        ),
                    });
                }
            }
        }
    }
    Ok(())
}

/// A length for a message: 4 decimals from 1 µm up, else 3 significant digits.
fn short_mm(x: f64) -> String {
    if x.abs() >= 1e-3 {
        format!("{x:.4}")
    } else {
        format!("{x:.3e}")
    }
}

/// Prepares, fits and assembles raw export data; fails when the fit tolerance is not met.
pub fn import_raw(raw: &RawImpeller, opts: &ImportOptions) -> Result<Imported, ImportError> {
    let prepared = prepare(raw, opts.trim_margin)?;
    let fitted = fit(&prepared, opts.fit_tol_mm, opts.span_extension)?;
    check_tolerance(&fitted)?;
    check_extent(&fitted)?;
    let impeller = assemble(&fitted, opts)?;
    // After the model's own checks (a shroud below the hub is that, not blades too short).
    check_reach(&fitted, &impeller)?;
    Ok(Imported { impeller, fitted })
}

/// Reads an export file (by extension) or a folder of section tables and turns it into an
/// impeller.
pub fn import_file(path: &Path, opts: &ImportOptions) -> Result<Imported, ImportError> {
    import_raw(&read_raw_with(path, opts)?, opts)
}
