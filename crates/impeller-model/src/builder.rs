//! The parametric builder: from a validated [`ImpellerSpec`] to exact NURBS hub, shroud and
//! blades.
//!
//! **Camber.** At impeller meridional fraction m and span s (0 hub, 1 shroud, extended to
//! [−e, 1 + e] by the span extension e), the hub and shroud camber points are
//! P_h = (r_h cos θ_h, r_h sin θ_h, z_h) and P_s likewise, (z, r) taken at fraction m of each
//! contour and θ from the wrap-angle laws. A *ruled* camber is (1 − s) P_h + s P_s (straight
//! rulings); a *free-form* camber puts the meridional point at (1 − s)(z_h, r_h) + s (z_s, r_s)
//! and θ(m, s) on the natural cubic spline through the span laws. The camber NURBS interpolates
//! this design at NU = 161 flow samples (u, clustered at rounded edges, see
//! [`crate::thickness`]) — a cubic×linear ruled surface, or cubic×cubic through 41 span rows.
//!
//! **Sides.** With the unit camber normal n (oriented to +θ) and half thickness h = τ/2, the
//! suction side (+θ) passes through C + h n and the pressure side (−θ) through C − h n.
//! Ruled blades keep ruled sides: only the hub and shroud rows are offset, then the rulings are
//! extended by e on both ends, so the normal thickness is exact at hub and shroud and the sides
//! stay flank-millable. Free-form sides interpolate the offset grid. The impeller turns toward
//! −θ, so the pressure side faces −θ and a positive wrap angle sweeps the blade backward.
//!
//! **Reach.** Every side must run through the hub and the shroud (its bottom edge below the
//! hub, its top edge beyond the shroud), or the blade would stand apart from the hub with no
//! corner for a fillet. A strongly twisted side, offset along the camber normal, can end
//! short of them at a small extension (impeller-11+11-freeform's pressure sides stopped
//! 0.17–0.22 mm above the hub at 0.06), so the extension is doubled until
//! [`reach_shortfall`] finds nothing, up to [`MAX_SPAN_EXTENSION`]; beyond that the spec is
//! refused, naming the side, the contour and the shortfall.
//!
//! Cost: a few thousand contour evaluations and three dense LU solves of size ≤ 161 per blade.

use crate::blade::{Blade, BladeDesign, BladeKind, BladeSet, Side};
use crate::error::ModelError;
use crate::fit::{interpolate_surface, ruled_through};
use crate::impeller::Impeller;
use crate::law::Law;
use crate::meridional::MeridionalCurve;
use crate::params::{BladeKindSpec, ContourSpec, ImpellerSpec, RowLaws};
use crate::revolved::RevolvedSurface;
use crate::stock::Stock;
use crate::thickness::ThicknessLaw;
use nalgebra::{Vector2, Vector3};
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use std::f64::consts::TAU;

/// Samples along the flow for every blade surface.
pub const FLOW_SAMPLES: usize = 161;
/// Span rows of free-form surfaces.
pub const SPAN_SAMPLES: usize = 41;

/// Largest span extension the builder grows a row's extension to when a side ends short of
/// hub or shroud ([`reach_shortfall`]).
pub const MAX_SPAN_EXTENSION: f64 = 0.5;

/// Edge samples per side in [`reach_shortfall`].
const REACH_SAMPLES: usize = 200;

/// The largest distance by which a side of `blade` stops short of the hub (its bottom edge,
/// `v` at the domain's start) or of the shroud (its top edge), as (side, contour name,
/// distance mm, u), or `None` when every sampled edge point lies beyond the contour
/// ([`REACH_SAMPLES`] + 1 per edge; samples whose nearest contour point is an end of the
/// contour are skipped: beyond the ends no side is defined). Exact meridional projections.
pub fn reach_shortfall(
    blade: &Blade,
    hub: &MeridionalCurve,
    shroud: &MeridionalCurve,
) -> Option<(Side, &'static str, f64, f64)> {
    let short_of = |c: &MeridionalCurve, sign: f64, m: Vector2<f64>| -> Option<f64> {
        let (t, d, _) = c.closest_point(m);
        let (t0, t1) = c.domain();
        let end = 1e-9 * (t1 - t0);
        (t > t0 + end && t < t1 - end).then_some(sign * d)
    };
    let mut worst: Option<(Side, &'static str, f64, f64)> = None;
    for side in [Side::Pressure, Side::Suction] {
        let s = blade.side(side);
        let ((u0, u1), (v0, v1)) = s.domain();
        for (v, contour, sign, name) in [(v0, hub, 1.0, "hub"), (v1, shroud, -1.0, "shroud")] {
            for i in 0..=REACH_SAMPLES {
                let u = u0 + (u1 - u0) * i as f64 / REACH_SAMPLES as f64;
                let m = MeridionalCurve::zr_of(&s.point(u, v));
                if let Some(d) = short_of(contour, sign, m) {
                    if d >= 0.0 && worst.is_none_or(|w| d > w.2) {
                        worst = Some((side, name, d, u));
                    }
                }
            }
        }
    }
    worst
}

/// Builds the meridional contour of a spec.
pub fn contour(spec: &ContourSpec) -> Result<MeridionalCurve, ModelError> {
    match spec {
        ContourSpec::QuarterEllipse {
            inlet_zr_mm,
            outlet_zr_mm,
        } => MeridionalCurve::quarter_ellipse(*inlet_zr_mm, *outlet_zr_mm),
        ContourSpec::Bspline {
            degree,
            control_points_zr_mm,
            weights,
        } => {
            let kv = KnotVector::clamped_uniform(*degree, control_points_zr_mm.len())?;
            let ctrl = control_points_zr_mm
                .iter()
                .map(|p| Vector2::new(p[0], p[1]))
                .collect();
            MeridionalCurve::new(NurbsCurve::from_knot_vector(kv, ctrl, weights.clone())?)
        }
    }
}

/// The camber design of one blade row.
struct CamberDesign<'a> {
    hub: &'a MeridionalCurve,
    shroud: &'a MeridionalCurve,
    kind: BladeKind,
    spans: &'a [f64],
    wraps: &'a [Law],
    theta_offset: f64,
}

fn cyl(zr: Vector2<f64>, theta: f64) -> Vector3<f64> {
    Vector3::new(zr[1] * theta.cos(), zr[1] * theta.sin(), zr[0])
}

impl CamberDesign<'_> {
    fn theta(&self, m: f64, s: f64) -> Result<f64, ModelError> {
        let pts: Vec<[f64; 2]> = self
            .spans
            .iter()
            .zip(self.wraps)
            .map(|(&sk, w)| [sk, w.eval(m)])
            .collect();
        let law = Law::new(&pts).map_err(|r| ModelError::invalid("main.wrap", r))?;
        Ok(law.eval(s) + self.theta_offset)
    }

    fn point(&self, m: f64, s: f64) -> Result<Vector3<f64>, ModelError> {
        let h = self.hub.point_at_fraction(m);
        let t = self.shroud.point_at_fraction(m);
        Ok(match self.kind {
            BladeKind::Ruled => {
                let n = self.wraps.len() - 1;
                let ph = cyl(h, self.wraps[0].eval(m) + self.theta_offset);
                let ps = cyl(t, self.wraps[n].eval(m) + self.theta_offset);
                ph * (1.0 - s) + ps * s
            }
            BladeKind::FreeForm => cyl(h * (1.0 - s) + t * s, self.theta(m, s)?),
        })
    }
}

/// Unit camber normal at (u, v), oriented with `sign`.
fn camber_normal(c: &NurbsSurface, u: f64, v: f64, sign: f64) -> Result<Vector3<f64>, ModelError> {
    c.normal(u, v)
        .map(|n| n * sign)
        .ok_or_else(|| ModelError::Geometry(format!("camber surface singular at u={u}, v={v}")))
}

/// Builds one blade of a row.
fn build_blade(
    design: &CamberDesign<'_>,
    m_start: f64,
    thickness: ThicknessLaw,
    ext: f64,
) -> Result<Blade, ModelError> {
    let nu = FLOW_SAMPLES;
    let u: Vec<f64> = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    let m_local: Vec<f64> = u.iter().map(|&x| thickness.m_of_u(x)).collect();
    let m: Vec<f64> = m_local
        .iter()
        .map(|&x| m_start + (1.0 - m_start) * x)
        .collect();
    let vh = ext / (1.0 + 2.0 * ext);
    let vs = (1.0 + ext) / (1.0 + 2.0 * ext);
    let s_of_v = |v: f64| -ext + v * (1.0 + 2.0 * ext);
    let camber = match design.kind {
        BladeKind::Ruled => {
            let a = m
                .iter()
                .map(|&mi| design.point(mi, -ext))
                .collect::<Result<Vec<_>, _>>()?;
            let b = m
                .iter()
                .map(|&mi| design.point(mi, 1.0 + ext))
                .collect::<Result<Vec<_>, _>>()?;
            ruled_through(&a, &b, &u, 3)?
        }
        BladeKind::FreeForm => {
            let v: Vec<f64> = (0..SPAN_SAMPLES)
                .map(|j| j as f64 / (SPAN_SAMPLES - 1) as f64)
                .collect();
            let grid = m
                .iter()
                .map(|&mi| v.iter().map(|&vj| design.point(mi, s_of_v(vj))).collect())
                .collect::<Result<Vec<Vec<_>>, _>>()?;
            interpolate_surface(&grid, &u, &v, 3, 3)?
        }
    };
    // Orient the normal toward +θ (decided at the blade's middle).
    let pmid = camber.point(0.5, 0.5);
    let e_theta = Vector3::new(-pmid.y, pmid.x, 0.0);
    let sign = if camber_normal(&camber, 0.5, 0.5, 1.0)?.dot(&e_theta) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let (pressure, suction) = match design.kind {
        BladeKind::Ruled => {
            let mut rows = [[Vec::new(), Vec::new()], [Vec::new(), Vec::new()]];
            for (i, &ui) in u.iter().enumerate() {
                let h = 0.5 * thickness.thickness(m_local[i]);
                let mut edge = [[Vector3::zeros(); 2]; 2]; // [side][hub/shroud]
                for (k, &v) in [vh, vs].iter().enumerate() {
                    let c = camber.point(ui, v);
                    let n = camber_normal(&camber, ui, v, sign)?;
                    edge[0][k] = c - n * h; // pressure (−θ)
                    edge[1][k] = c + n * h; // suction (+θ)
                }
                for (side, e) in edge.iter().enumerate() {
                    let d = e[1] - e[0];
                    rows[side][0].push(e[0] - d * ext);
                    rows[side][1].push(e[1] + d * ext);
                }
            }
            let [p, s] = rows;
            (
                ruled_through(&p[0], &p[1], &u, 3)?,
                ruled_through(&s[0], &s[1], &u, 3)?,
            )
        }
        BladeKind::FreeForm => {
            let v: Vec<f64> = (0..SPAN_SAMPLES)
                .map(|j| j as f64 / (SPAN_SAMPLES - 1) as f64)
                .collect();
            let mut gp = Vec::with_capacity(nu);
            let mut gs = Vec::with_capacity(nu);
            for (i, &ui) in u.iter().enumerate() {
                let h = 0.5 * thickness.thickness(m_local[i]);
                let mut rp = Vec::with_capacity(v.len());
                let mut rs = Vec::with_capacity(v.len());
                for &vj in &v {
                    let c = camber.point(ui, vj);
                    let n = camber_normal(&camber, ui, vj, sign)?;
                    rp.push(c - n * h);
                    rs.push(c + n * h);
                }
                gp.push(rp);
                gs.push(rs);
            }
            (
                interpolate_surface(&gp, &u, &v, 3, 3)?,
                interpolate_surface(&gs, &u, &v, 3, 3)?,
            )
        }
    };
    Ok(
        Blade::from_sides(design.kind, pressure, suction, Some(camber))?.with_design(BladeDesign {
            thickness,
            m_start,
            span_v: (vh, vs),
        }),
    )
}

fn kind_of(k: BladeKindSpec) -> BladeKind {
    match k {
        BladeKindSpec::Ruled => BladeKind::Ruled,
        BladeKindSpec::FreeForm => BladeKind::FreeForm,
    }
}

/// Validates `spec` and builds the impeller.
pub fn build(spec: &ImpellerSpec) -> Result<Impeller, ModelError> {
    spec.validate()?;
    let hub_m = contour(&spec.hub)?;
    let shroud_m = contour(&spec.shroud)?;
    for k in 0..=32 {
        let m = k as f64 / 32.0;
        let (_, d) = hub_m.closest(shroud_m.point_at_fraction(m));
        if d.is_nan() || d <= 0.0 {
            return Err(ModelError::invalid(
                "shroud",
                format!("must lie above the hub (fails at meridional fraction {m:.3})"),
            ));
        }
    }
    let laws: RowLaws = spec.main.validate()?;
    let kind = kind_of(spec.main.kind);
    let ext = spec.main.span_extension;
    let mean_len = 0.5 * (hub_m.length_mm() + shroud_m.length_mm());
    let main_design = CamberDesign {
        hub: &hub_m,
        shroud: &shroud_m,
        kind,
        spans: &laws.spans,
        wraps: &laws.wraps_rad,
        theta_offset: 0.0,
    };
    let main_thickness = ThicknessLaw::new(
        laws.thickness.clone(),
        spec.main.leading_edge,
        spec.main.trailing_edge,
        mean_len,
    );
    let count = spec.main.count;
    let splitter_job = match &spec.splitter {
        Some(s) => {
            let table = s.validate(count)?.unwrap_or_else(|| laws.thickness.clone());
            let t = ThicknessLaw::new(
                table,
                s.leading_edge.unwrap_or(spec.main.leading_edge),
                s.trailing_edge.unwrap_or(spec.main.trailing_edge),
                mean_len * (1.0 - s.start_fraction),
            );
            Some((s.start_fraction, s.pitch_fraction * TAU / count as f64, t))
        }
        None => None,
    };
    // The sides must run through the hub and the shroud: a twisted blade's side, offset
    // along the camber normal, can end short of them where the extension is small; the
    // extension is doubled (up to MAX_SPAN_EXTENSION) until every side reaches both.
    let mut ext = ext;
    let (main_blade, splitter_blade) = loop {
        let (main_blade, splitter_blade) = rayon::join(
            || build_blade(&main_design, 0.0, main_thickness.clone(), ext),
            || {
                splitter_job
                    .as_ref()
                    .map(|(start, offset, t)| {
                        let d = CamberDesign {
                            hub: &hub_m,
                            shroud: &shroud_m,
                            kind,
                            spans: &laws.spans,
                            wraps: &laws.wraps_rad,
                            theta_offset: *offset,
                        };
                        build_blade(&d, *start, t.clone(), ext)
                    })
                    .transpose()
            },
        );
        let (main_blade, splitter_blade) = (main_blade?, splitter_blade?);
        let short = [
            Some(("main", &main_blade)),
            splitter_blade.as_ref().map(|b| ("splitter", b)),
        ]
        .into_iter()
        .flatten()
        .find_map(|(row, b)| reach_shortfall(b, &hub_m, &shroud_m).map(|s| (row, s)));
        match short {
            None => break (main_blade, splitter_blade),
            Some(_) if ext < MAX_SPAN_EXTENSION => {
                ext = (2.0 * ext).clamp(0.01, MAX_SPAN_EXTENSION);
            }
            Some((row, (side, edge, d, u))) => {
                return Err(ModelError::invalid(
                    "main.span_extension",
                    format!(
                        "the {row} blade's {side:?} side ends {d:.3} mm short of the {edge} at \
                         u = {u:.3} even extended by {MAX_SPAN_EXTENSION} of the span"
                    ),
                ));
            }
        }
    };
    let main = BladeSet::new(count, main_blade)?;
    let splitter = splitter_blade
        .map(|b| BladeSet::new(count, b))
        .transpose()?;
    let profile = spec.stock.validate()?;
    let stock_field = if spec.stock.profile_zr_mm.is_some() {
        "stock.profile_zr_mm"
    } else {
        "stock.diameter_mm"
    };
    let stock = Stock::from_profile(profile)?;
    let r_max = hub_m
        .point_at_fraction(1.0)
        .y
        .max(shroud_m.point_at_fraction(1.0).y);
    if stock.max_radius() < r_max {
        return Err(ModelError::invalid(
            stock_field,
            format!(
                "must enclose the impeller (outer radius {:.3} mm < outlet radius {r_max:.3} mm)",
                stock.max_radius()
            ),
        ));
    }
    let z_top = hub_m
        .point_at_fraction(0.0)
        .x
        .max(shroud_m.point_at_fraction(0.0).x);
    if stock.z_range().1 < z_top {
        return Err(ModelError::invalid(
            if spec.stock.profile_zr_mm.is_some() {
                "stock.profile_zr_mm"
            } else {
                "stock.height_mm"
            },
            format!(
                "must reach the inlet (top z {:.3} mm < {z_top:.3} mm)",
                stock.z_range().1
            ),
        ));
    }
    Impeller::from_parts(
        spec.name.clone(),
        RevolvedSurface::new(hub_m)?,
        RevolvedSurface::new(shroud_m)?,
        main,
        splitter,
        spec.fillet_radius_mm,
        stock,
    )
}
