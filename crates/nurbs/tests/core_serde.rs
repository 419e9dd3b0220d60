//! serde: round trips of knot vectors, curves and surfaces, and rejection of invalid data
//! on deserialisation (validation runs through the same constructors).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::{Vector2, Vector3};
use nurbs::{KnotVector, NurbsCurve, NurbsError, NurbsSurface};

fn quarter_circle() -> NurbsCurve<2> {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![
            Vector2::new(1., 0.),
            Vector2::new(1., 1.),
            Vector2::new(0., 1.),
        ],
        Some(vec![1., w, 1.]),
    )
    .unwrap()
}

#[test]
fn curve_round_trip() {
    let c = quarter_circle();
    let json = serde_json::to_string(&c).unwrap();
    let back: NurbsCurve<2> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, c);
    // non-rational curves omit the weights field
    let line = NurbsCurve::<3>::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::zeros(), Vector3::new(1., 2., 3.)],
        None,
    )
    .unwrap();
    let json = serde_json::to_string(&line).unwrap();
    assert!(!json.contains("weights"), "{json}");
    assert_eq!(serde_json::from_str::<NurbsCurve<3>>(&json).unwrap(), line);
}

#[test]
fn surface_and_knot_vector_round_trip() {
    let s = NurbsSurface::new(
        1,
        2,
        vec![0., 0., 1., 1.],
        vec![0., 0., 0., 1., 1., 1.],
        vec![
            vec![
                Vector3::new(0., 0., 0.),
                Vector3::new(0., 1., 1.),
                Vector3::new(0., 2., 0.),
            ],
            vec![
                Vector3::new(1., 0., 0.),
                Vector3::new(1., 1., 1.),
                Vector3::new(1., 2., 0.),
            ],
        ],
        Some(vec![vec![1., 0.5, 1.], vec![1., 2., 1.]]),
    )
    .unwrap();
    let json = serde_json::to_string(&s).unwrap();
    let back: NurbsSurface = serde_json::from_str(&json).unwrap();
    assert_eq!(back, s);
    let kv = KnotVector::clamped_uniform(3, 7).unwrap();
    let back: KnotVector = serde_json::from_str(&serde_json::to_string(&kv).unwrap()).unwrap();
    assert_eq!(back, kv);
}

#[test]
fn invalid_data_is_rejected() {
    // decreasing knot
    let bad =
        r#"{"degree":1,"knots":[0,0,0.5,0.4,1,1],"control_points":[[0,0],[1,0],[2,0],[3,1]]}"#;
    let err = serde_json::from_str::<NurbsCurve<2>>(bad).unwrap_err();
    assert!(err.to_string().contains("knot 3"), "{err}");
    // negative weight
    let bad = r#"{"degree":1,"knots":[0,0,1,1],"control_points":[[0,0],[1,0]],"weights":[1,-1]}"#;
    let err = serde_json::from_str::<NurbsCurve<2>>(bad).unwrap_err();
    assert!(err.to_string().contains("weight 1"), "{err}");
    // knot count does not match
    let bad = r#"{"degree":2,"knots":[0,0,0,1,1,1,1],"control_points":[[0,0],[1,0],[2,0]]}"#;
    assert!(serde_json::from_str::<NurbsCurve<2>>(bad).is_err());
    // knot vector with degree 0
    assert!(serde_json::from_str::<KnotVector>(r#"{"degree":0,"knots":[0,1]}"#).is_err());
    // ragged surface net
    let bad = r#"{"degree_u":1,"degree_v":1,"knots_u":[0,0,1,1],"knots_v":[0,0,1,1],
        "control_points":[[[0,0,0],[0,1,0]],[[1,0,0]]]}"#;
    let err = serde_json::from_str::<NurbsSurface>(bad).unwrap_err();
    assert!(err.to_string().contains("row 1"), "{err}");
}

#[test]
fn error_source_chain_names_direction() {
    let err = NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., f64::NAN, 1., 1.],
        vec![vec![Vector3::zeros(); 3]; 2],
        None,
    )
    .unwrap_err();
    assert!(err.to_string().starts_with("knot vector in v"), "{err}");
    match err {
        NurbsError::SurfaceKnots { source, .. } => {
            assert!(matches!(
                *source,
                NurbsError::NonFiniteKnot { index: 2, .. }
            ))
        }
        other => panic!("unexpected {other:?}"),
    }
}
