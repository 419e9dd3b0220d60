//! Curve files in the TurboGrid format, the same the importer reads ([`crate::import::turbogrid`]):
//! an `.inf` file, `hub.curve`, `shroud.curve`, and one profile file per blade of a set
//! (`main.curve`, `splitter.curve`), cartesian `x y z` in millimetres, rotation axis Z, in
//! the workpiece frame.
//!
//! - Hub and shroud: `n_contour` points at equal meridional arc-length fractions of the
//!   contours, placed at θ = 0 (y = 0).
//! - Blades: sections at `n_spans` span fractions s_k = k/(n_spans − 1) between the blade's
//!   edges on hub and shroud: at each of `n_chord` cosine-spaced values of u (clustered at
//!   the leading and trailing edges) the side's isoparametric line is cut with hub and shroud
//!   (v_h(u), v_s(u), found as in [`crate::channel::edge_v`]; the side's own v limits when it
//!   does not reach a wall) and the point at v_h + s·(v_s − v_h) is taken. Each profile is a
//!   closed loop: pressure side LE → TE, then suction side TE → LE, ending on its first point;
//!   the pressure side's TE point is written twice, which marks the trailing edge for the
//!   importer (the loop's first point marks the leading edge); where the sides end apart (a
//!   blunt edge) the suction side's end point is written twice too, marking the edge face.
//!   Blades whose sides are of degree 1 across the span (ruled) get exactly two sections, hub
//!   and shroud, so they are re-imported as ruled blades; a free-form blade is resampled, so
//!   the re-imported
//!   surface differs from it by the interpolation error between sections (measured in the
//!   round-trip test).
//!
//! Files are written to temporary files and renamed.

use super::atomic::write_atomic;
use super::error::ExportError;
use crate::blade::{Blade, Side};
use crate::channel::edge_v;
use crate::impeller::Impeller;
use crate::meridional::MeridionalCurve;
use nalgebra::Vector3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Sampling of an exported curve set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveSampling {
    /// Points on each of hub and shroud.
    pub n_contour: usize,
    /// Points along each blade side per section.
    pub n_chord: usize,
    /// Sections per blade (hub to shroud).
    pub n_spans: usize,
}

impl Default for CurveSampling {
    fn default() -> Self {
        Self {
            n_contour: 201,
            n_chord: 151,
            n_spans: 21,
        }
    }
}

/// Names of the files written.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveFiles {
    /// The `.inf` file.
    pub inf: PathBuf,
    /// Hub, shroud and profile files.
    pub curves: Vec<PathBuf>,
}

fn contour_text(m: &MeridionalCurve, n: usize) -> String {
    let mut s = String::new();
    for k in 0..n {
        let p = m.point_at_fraction(k as f64 / (n - 1) as f64);
        let _ = writeln!(s, "{:18.10} {:18.10} {:18.10}", p.y, 0.0, p.x);
    }
    s
}

/// One side's section points at span `span` (LE → TE).
fn side_section(
    imp: &Impeller,
    blade: &Blade,
    side: Side,
    span: f64,
    n: usize,
) -> Vec<Vector3<f64>> {
    let s = blade.side(side);
    let ((u0, u1), (v0, v1)) = s.domain();
    (0..n)
        .map(|i| {
            let t = 0.5 * (1.0 - (std::f64::consts::PI * i as f64 / (n - 1) as f64).cos());
            let u = u0 + (u1 - u0) * t;
            // Where the side misses a wall its own v limit stands in (see module docs).
            let vh = edge_v(blade, side, imp.hub(), u).unwrap_or(v0);
            let vs = edge_v(blade, side, imp.shroud(), u).unwrap_or(v1);
            s.point(u, vh + span * (vs - vh))
        })
        .collect()
}

fn profile_text(imp: &Impeller, blade: &Blade, sampling: &CurveSampling) -> String {
    let mut out = String::new();
    // Sides of degree 1 across the span are ruled: hub and shroud sections are exact.
    let ruled = blade.pressure().degree_v() == 1 && blade.suction().degree_v() == 1;
    let n_spans = if ruled { 2 } else { sampling.n_spans };
    for k in 0..n_spans {
        let span = k as f64 / (n_spans - 1) as f64;
        let _ = writeln!(out, "# Profile {} at {:.4}%", k + 1, 100.0 * span);
        let p = side_section(imp, blade, Side::Pressure, span, sampling.n_chord);
        let s = side_section(imp, blade, Side::Suction, span, sampling.n_chord);
        // The loop starts at the leading edge and writes the trailing edge point twice: the
        // importer splits at these marks. At a blunt edge (sides ending apart) the suction
        // side's corner is written twice as well, marking the edge face between them.
        let apart = |a: &Vector3<f64>, b: &Vector3<f64>| (a - b).norm() > 1e-6;
        let (p_le, p_te) = (p[0], p[p.len() - 1]);
        let (s_le, s_te) = (s[0], s[s.len() - 1]);
        let mut loop_pts = p.clone();
        loop_pts.push(p_te);
        if apart(&s_te, &p_te) {
            loop_pts.push(s_te);
        }
        loop_pts.extend(s.iter().rev());
        if apart(&s_le, &p_le) {
            loop_pts.push(s_le);
        }
        loop_pts.push(p_le);
        for q in loop_pts {
            let _ = writeln!(out, "{:18.10} {:18.10} {:18.10}", q.x, q.y, q.z);
        }
        out.push('\n');
    }
    out
}

/// Writes the impeller as a TurboGrid curve set into `dir` (created if missing), named
/// `<stem>.inf`, `hub.curve`, `shroud.curve`, `main.curve` and, with splitters,
/// `splitter.curve`.
pub fn write_curves(
    imp: &Impeller,
    dir: &Path,
    stem: &str,
    sampling: &CurveSampling,
) -> Result<CurveFiles, ExportError> {
    if sampling.n_contour < 2 || sampling.n_chord < 4 || sampling.n_spans < 2 {
        return Err(ExportError::Invalid {
            field: "curve sampling",
            reason: "needs at least 2 contour points, 4 chord points and 2 spans".into(),
        });
    }
    std::fs::create_dir_all(dir).map_err(|source| ExportError::Io {
        file: dir.to_path_buf(),
        source,
    })?;
    let mut files: Vec<(String, String)> = vec![
        (
            "hub.curve".into(),
            contour_text(imp.hub().meridional(), sampling.n_contour),
        ),
        (
            "shroud.curve".into(),
            contour_text(imp.shroud().meridional(), sampling.n_contour),
        ),
        (
            "main.curve".into(),
            profile_text(imp, imp.main().blade(), sampling),
        ),
    ];
    if let Some(sp) = imp.splitter() {
        files.push((
            "splitter.curve".into(),
            profile_text(imp, sp.blade(), sampling),
        ));
    }
    let mut inf = String::new();
    let _ = writeln!(
        inf,
        "!======  impeller-cam curve export: {}  ========",
        imp.name()
    );
    let _ = writeln!(inf, "Axis of Rotation: Z");
    let _ = writeln!(inf, "Number of Blade Sets: {}", imp.main().count());
    let _ = writeln!(
        inf,
        "Number of Blades Per Set: {}",
        if imp.splitter().is_some() { 2 } else { 1 }
    );
    let _ = writeln!(inf, "Geometry Units: MM");
    let _ = writeln!(inf, "Coordinate Type: Cartesian");
    let _ = writeln!(inf, "Hub Data File: hub.curve");
    let _ = writeln!(inf, "Shroud Data File: shroud.curve");
    let _ = writeln!(inf, "Profile Data File: main.curve");
    if imp.splitter().is_some() {
        let _ = writeln!(inf, "Blade 1 Profile Data File: splitter.curve");
    }
    let mut curves = Vec::new();
    for (name, text) in &files {
        let p = dir.join(name);
        write_atomic(&p, text.as_bytes())?;
        curves.push(p);
    }
    let inf_path = dir.join(format!("{stem}.inf"));
    write_atomic(&inf_path, inf.as_bytes())?;
    Ok(CurveFiles {
        inf: inf_path,
        curves,
    })
}
