//! Bad input: the validation variants of `NurbsError` are reached here; the operation
//! errors are reached in the tests of their operations: `ParameterOutOfDomain`,
//! `InsertionExceedsMultiplicity` (and `DegreeOutOfRange`, `EmptyDomain` from operations)
//! in `core_knot_ops.rs`, `InvalidGeometry` in `core_constructors.rs`, `SurfaceKnots` also
//! in `core_serde.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::{Vector2, Vector3};
use nurbs::{Direction, KnotVector, NurbsCurve, NurbsError, NurbsSurface, MAX_DEGREE};

fn line2(knots: Vec<f64>, pts: usize, w: Option<Vec<f64>>) -> Result<NurbsCurve<2>, NurbsError> {
    let ctrl = (0..pts).map(|i| Vector2::new(i as f64, 0.0)).collect();
    NurbsCurve::new(1, knots, ctrl, w)
}

#[test]
fn degree_out_of_range() {
    assert_eq!(
        KnotVector::new(0, vec![0., 1.]),
        Err(NurbsError::DegreeOutOfRange {
            degree: 0,
            max: MAX_DEGREE
        })
    );
    assert!(matches!(
        KnotVector::new(MAX_DEGREE + 1, vec![0.; 40]),
        Err(NurbsError::DegreeOutOfRange { .. })
    ));
    assert!(matches!(
        KnotVector::clamped_uniform(0, 4),
        Err(NurbsError::DegreeOutOfRange { .. })
    ));
}

#[test]
fn too_few_knots() {
    assert_eq!(
        KnotVector::new(2, vec![0., 0., 0., 1., 1.]),
        Err(NurbsError::TooFewKnots {
            len: 5,
            degree: 2,
            min: 6
        })
    );
    assert!(matches!(
        KnotVector::clamped_uniform(3, 3),
        Err(NurbsError::TooFewKnots { .. })
    ));
}

#[test]
fn non_finite_knot() {
    assert!(matches!(
        KnotVector::new(1, vec![0., 0., f64::INFINITY, 1., 1.]),
        Err(NurbsError::NonFiniteKnot { index: 2, .. })
    ));
}

#[test]
fn decreasing_knot() {
    assert_eq!(
        KnotVector::new(1, vec![0., 0., 0.7, 0.5, 1., 1.]),
        Err(NurbsError::DecreasingKnot {
            index: 3,
            value: 0.5,
            previous: 0.7
        })
    );
}

#[test]
fn knot_multiplicity() {
    // interior multiplicity p + 1 = 3 for p = 2
    assert_eq!(
        KnotVector::new(2, vec![0., 0., 0., 0.5, 0.5, 0.5, 1., 1., 1.]),
        Err(NurbsError::KnotMultiplicity {
            index: 3,
            value: 0.5,
            multiplicity: 3,
            max: 2
        })
    );
    // end multiplicity p + 2
    assert!(matches!(
        KnotVector::new(1, vec![0., 0., 0., 1., 1.]),
        Err(NurbsError::KnotMultiplicity {
            index: 0,
            multiplicity: 3,
            max: 2,
            ..
        })
    ));
}

#[test]
fn empty_domain() {
    // unclamped vector whose domain [u_p, u_{m-p}] collapses
    assert_eq!(
        KnotVector::new(2, vec![0., 1., 2., 2., 3., 4.]),
        Err(NurbsError::EmptyDomain {
            start: 2.0,
            end: 2.0
        })
    );
}

#[test]
fn knot_count_mismatch() {
    assert_eq!(
        line2(vec![0., 0., 0.5, 1., 1.], 2, None).unwrap_err(),
        NurbsError::KnotCountMismatch {
            n_knots: 5,
            n_ctrl: 2,
            degree: 1,
            expected: 4
        }
    );
}

#[test]
fn length_mismatch() {
    assert!(matches!(
        line2(vec![0., 0., 1., 1.], 2, Some(vec![1.0])),
        Err(NurbsError::LengthMismatch {
            expected: 2,
            got: 1,
            ..
        })
    ));
    let ku = KnotVector::clamped_uniform(1, 2).unwrap();
    assert!(matches!(
        NurbsSurface::from_flat(ku.clone(), ku.clone(), vec![Vector3::zeros(); 3], None),
        Err(NurbsError::LengthMismatch {
            expected: 4,
            got: 3,
            ..
        })
    ));
    assert!(matches!(
        NurbsSurface::from_flat(
            ku.clone(),
            ku,
            vec![Vector3::zeros(); 4],
            Some(vec![1.0; 2])
        ),
        Err(NurbsError::LengthMismatch {
            expected: 4,
            got: 2,
            ..
        })
    ));
    let k = vec![0., 0., 1., 1.];
    let net = vec![vec![Vector3::zeros(); 2]; 2];
    assert!(matches!(
        NurbsSurface::new(
            1,
            1,
            k.clone(),
            k.clone(),
            net.clone(),
            Some(vec![vec![1.0; 2]])
        ),
        Err(NurbsError::LengthMismatch {
            expected: 2,
            got: 1,
            ..
        })
    ));
    let err = NurbsSurface::new(1, 1, k.clone(), k, net, Some(vec![vec![1.0; 2], vec![1.0]]))
        .unwrap_err();
    assert!(err.to_string().contains("weight row 1"), "{err}");
}

#[test]
fn non_finite_control_point() {
    let err = NurbsCurve::<3>::new(
        1,
        vec![0., 0., 0.5, 1., 1.],
        vec![
            Vector3::zeros(),
            Vector3::new(0., f64::NAN, 0.),
            Vector3::zeros(),
        ],
        None,
    )
    .unwrap_err();
    assert_eq!(err, NurbsError::NonFiniteControlPoint { index: 1 });
}

#[test]
fn invalid_weight() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = line2(vec![0., 0., 0.5, 1., 1.], 3, Some(vec![1.0, 1.0, bad])).unwrap_err();
        assert!(
            matches!(err, NurbsError::InvalidWeight { index: 2, .. }),
            "{err}"
        );
    }
}

#[test]
fn surface_errors() {
    let k = vec![0., 0., 1., 1.];
    let mut net = vec![vec![Vector3::zeros(); 2]; 2];
    net[1][0].z = f64::NEG_INFINITY;
    assert_eq!(
        NurbsSurface::new(1, 1, k.clone(), k.clone(), net, None).unwrap_err(),
        NurbsError::NonFiniteSurfaceControlPoint { i: 1, j: 0 }
    );
    let net = vec![vec![Vector3::zeros(); 2]; 2];
    let err = NurbsSurface::new(
        1,
        1,
        k.clone(),
        k.clone(),
        net.clone(),
        Some(vec![vec![1.0, 1.0], vec![1.0, 0.0]]),
    )
    .unwrap_err();
    assert_eq!(
        err,
        NurbsError::InvalidSurfaceWeight {
            i: 1,
            j: 1,
            value: 0.0
        }
    );
    // a third row: too many points for the u knots
    let mut net3 = net.clone();
    net3.push(vec![Vector3::zeros(); 2]);
    match NurbsSurface::new(1, 1, k.clone(), k.clone(), net3, None).unwrap_err() {
        NurbsError::SurfaceKnots {
            direction: Direction::U,
            source,
        } => {
            assert!(matches!(
                *source,
                NurbsError::KnotCountMismatch { n_ctrl: 3, .. }
            ))
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(matches!(
        NurbsSurface::new(1, 3, k.clone(), k, net, None),
        Err(NurbsError::SurfaceKnots {
            direction: Direction::V,
            ..
        })
    ));
}
