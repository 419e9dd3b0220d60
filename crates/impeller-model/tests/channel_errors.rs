//! The typed errors of the channel and blade queries (issue 15): what failed and where.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::blade::line_surface_intersection;
use impeller_model::channel::{edge_curve, edge_v, Wall};
use impeller_model::meridional::MeridionalCurve;
use impeller_model::revolved::RevolvedSurface;
use impeller_model::{fixtures, ModelError, Side};

/// A wall far above the impeller: no blade side crosses it.
fn far_wall() -> RevolvedSurface {
    RevolvedSurface::new(MeridionalCurve::quarter_ellipse([5000.0, 10.0], [4990.0, 20.0]).unwrap())
        .unwrap()
}

#[test]
fn edge_v_names_the_side_and_parameter_it_missed() {
    let imp = fixtures::default_impeller().unwrap();
    let blade = imp.main().blade();
    assert!(edge_v(blade, Side::Pressure, imp.hub(), 0.5).is_ok());
    let e = edge_v(blade, Side::Pressure, &far_wall(), 0.5).unwrap_err();
    assert!(
        matches!(e, ModelError::EdgeMissesWall { side: Side::Pressure, wall: None, u } if u == 0.5),
        "{e:?}"
    );
    let msg = e.on_wall(Wall::Shroud).to_string();
    assert!(
        msg.contains("Pressure") && msg.contains("u = 0.5") && msg.contains("shroud"),
        "{msg}"
    );
}

#[test]
fn edge_curve_fails_only_when_no_sample_meets_the_wall() {
    let imp = fixtures::default_impeller().unwrap();
    let blade = imp.main().blade();
    assert!(!edge_curve(blade, Side::Suction, imp.hub(), 21)
        .unwrap()
        .is_empty());
    let e = edge_curve(blade, Side::Suction, &far_wall(), 21).unwrap_err();
    assert!(
        matches!(
            e,
            ModelError::EdgeEmpty {
                side: Side::Suction,
                n: 21,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn section_names_the_channel_and_bounding_blade() {
    let imp = fixtures::default_impeller().unwrap();
    let c = imp.channel(2);
    let (a, b) = imp.hub().meridional().domain();
    assert!(c.section(imp.hub(), 0.5 * (a + b)).is_ok());
    let t = a - 10.0 * (b - a);
    let e = c.section(imp.hub(), t).unwrap_err();
    assert!(
        matches!(
            e,
            ModelError::SectionOutOfReach {
                channel: 2,
                bound: "left",
                ..
            }
        ),
        "{e:?}"
    );
    assert!(
        e.to_string().starts_with("channel 2: the left blade's"),
        "{e}"
    );
}

#[test]
fn span_and_width_succeed_on_the_default_impeller() {
    let imp = fixtures::default_impeller().unwrap();
    let blade = imp.main().blade();
    let (lo, hi) = imp.span_v_range(blade, Side::Pressure).unwrap();
    assert!(lo < hi);
    assert!(imp.min_channel_width(Wall::Hub).unwrap() > 0.0);
}

#[test]
fn line_parallel_to_a_side_reports_its_start_and_residual() {
    let imp = fixtures::default_impeller().unwrap();
    let s = imp.main().blade().side(Side::Pressure);
    let d = s.derivs2(0.5, 0.5);
    let nrm = d.su.cross(&d.sv).normalize();
    let c = d.p + nrm * 50.0;
    let e = line_surface_intersection(s, &c, &d.su.normalize(), (0.5, 0.5, 0.0)).unwrap_err();
    match e {
        ModelError::LineMissesSurface {
            u, v, residual_mm, ..
        } => {
            assert_eq!((u, v), (0.5, 0.5));
            assert!(residual_mm > 1e-9);
        }
        other => panic!("{other:?}"),
    }
}
