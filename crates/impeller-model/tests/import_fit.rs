//! Exact geometry fitted from the real exports and our samples: tolerances met, sizes as
//! stated in each SOURCE.txt.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::import::{
    fit, prepare, read_geomturbo, read_rtzt, read_turbogrid, FittedImpeller, LengthUnit,
    PreparedImpeller, DEFAULT_FIT_TOL_MM,
};

fn fitted(p: &PreparedImpeller) -> FittedImpeller {
    let f = fit(p, DEFAULT_FIT_TOL_MM, 0.0).unwrap();
    eprintln!(
        "{}: hub {:.2e} shroud {:.2e} mm ({} / {} ctrl)",
        p.source.display(),
        f.hub_fit_mm,
        f.shroud_fit_mm,
        f.hub.control_points().len(),
        f.shroud.control_points().len()
    );
    for b in &f.blades {
        eprintln!(
            "  {}: pressure {:.2e} mm ({}x{} ctrl), suction {:.2e} mm ({}x{} ctrl)",
            b.name,
            b.pressure_fit_mm,
            b.pressure.n_u(),
            b.pressure.n_v(),
            b.suction_fit_mm,
            b.suction.n_u(),
            b.suction.n_v()
        );
    }
    f
}

#[test]
fn rotor37_fits_within_tolerance() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_turbogrid(&import_common::rotor37_inf()).unwrap();
    let p = prepare(&raw, None).unwrap();
    let f = fitted(&p);
    assert!(f.max_fit_mm() <= DEFAULT_FIT_TOL_MM, "{}", f.max_fit_mm());
}

#[test]
fn centrifugal_fits_within_tolerance() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_geomturbo(&import_common::centrifugal_geomturbo()).unwrap();
    let p = prepare(&raw, None).unwrap();
    let f = fitted(&p);
    assert!(f.max_fit_mm() <= DEFAULT_FIT_TOL_MM, "{}", f.max_fit_mm());
}

#[test]
fn rtzt_sample_fits() {
    let raw = read_rtzt(
        &import_common::sample("sample-6+6.rtzt"),
        LengthUnit::Millimetre,
    )
    .unwrap();
    let f = fitted(&prepare(&raw, None).unwrap());
    assert!(f.max_fit_mm() <= DEFAULT_FIT_TOL_MM);
}

/// Independent check of the reported deviation: every data point of every section lies
/// within the fit tolerance of its fitted side surface (global closest point).
#[test]
fn centrifugal_data_points_lie_on_fitted_sides() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_geomturbo(&import_common::centrifugal_geomturbo()).unwrap();
    let p = prepare(&raw, None).unwrap();
    let f = fit(&p, DEFAULT_FIT_TOL_MM, 0.0).unwrap();
    for (pb, fb) in p.blades.iter().zip(&f.blades) {
        for (surf, reported, pick) in [
            (&fb.pressure, fb.pressure_fit_mm, 0usize),
            (&fb.suction, fb.suction_fit_mm, 1usize),
        ] {
            let proj = nurbs::closest::SurfaceProjector::new(surf);
            let mut worst: f64 = 0.0;
            for s in &pb.sections {
                let pts = if pick == 0 { &s.pressure } else { &s.suction };
                for q in pts.iter().step_by(3) {
                    worst = worst.max(proj.closest_point(q).distance);
                }
            }
            assert!(
                worst <= reported + 1e-9,
                "{}: {worst} > {reported}",
                fb.name
            );
            assert!(worst <= DEFAULT_FIT_TOL_MM);
        }
    }
}
