//! Basis functions: The NURBS Book examples 2.3 and 2.4, partition of unity and
//! non-negativity, derivative rows against finite differences.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nurbs::KnotVector;
use proptest::prelude::*;

fn ex23() -> KnotVector {
    KnotVector::new(2, vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap()
}

#[test]
fn nurbs_book_ex2_3_basis_at_five_halves() {
    let kv = ex23();
    let span = kv.find_span(2.5);
    assert_eq!(span, 4);
    let mut n = [0.0; 3];
    kv.basis_funs(span, 2.5, &mut n);
    // N_{2,2} = 1/8, N_{3,2} = 6/8, N_{4,2} = 1/8
    let expected = [0.125, 0.75, 0.125];
    for (a, b) in n.iter().zip(expected) {
        assert!((a - b).abs() < 1e-15, "{n:?}");
    }
}

#[test]
fn nurbs_book_ex2_4_derivatives_at_five_halves() {
    let kv = ex23();
    let d = kv.ders_basis_funs(4, 2.5, 3);
    let expected = [
        [0.125, 0.75, 0.125],
        [-0.5, 0.0, 0.5],
        [1.0, -2.0, 1.0],
        [0.0, 0.0, 0.0],
    ];
    for k in 0..4 {
        for j in 0..3 {
            assert!((d[k][j] - expected[k][j]).abs() < 1e-14, "k={k} {d:?}");
        }
    }
}

#[test]
fn clamped_uniform_layout() {
    let kv = KnotVector::clamped_uniform(3, 6).unwrap();
    assert_eq!(
        kv.knots(),
        &[0., 0., 0., 0., 1. / 3., 2. / 3., 1., 1., 1., 1.]
    );
    assert_eq!(kv.domain(), (0.0, 1.0));
    assert_eq!(kv.n_ctrl(), 6);
    assert!(kv.is_clamped());
    assert_eq!(kv.interior_breaks(), vec![(1. / 3., 1), (2. / 3., 1)]);
}

fn knot_vector() -> impl Strategy<Value = KnotVector> {
    (1usize..=8, 0usize..=8).prop_flat_map(|(p, n_int)| {
        (
            Just(p),
            prop::collection::vec(0.0f64..1.0, n_int),
            prop::collection::vec(1usize..=8, n_int),
        )
            .prop_map(|(p, mut int, mult)| {
                int.sort_by(f64::total_cmp);
                let mut knots = vec![0.0; p + 1];
                let mut last = 0.0;
                for (k, m) in int.iter().zip(mult) {
                    if *k > last && *k < 1.0 {
                        for _ in 0..m.min(p) {
                            knots.push(*k);
                        }
                        last = *k;
                    }
                }
                knots.extend(std::iter::repeat_n(1.0, p + 1));
                KnotVector::new(p, knots).unwrap()
            })
    })
}

proptest! {
    #[test]
    fn partition_of_unity_and_non_negative(kv in knot_vector(), t in 0.0f64..=1.0) {
        let p = kv.degree();
        let span = kv.find_span(t);
        let mut n = vec![0.0; p + 1];
        kv.basis_funs(span, t, &mut n);
        let sum: f64 = n.iter().sum();
        prop_assert!((sum - 1.0).abs() < 1e-13, "sum {sum}");
        prop_assert!(n.iter().all(|&x| x >= 0.0), "{n:?}");
        // A2.3 row 0 equals A2.2, derivative rows sum to zero (derivative of 1)
        let d = kv.ders_basis_funs(span, t, p);
        for j in 0..=p {
            prop_assert!((d[0][j] - n[j]).abs() < 1e-14);
        }
        for row in d.iter().skip(1) {
            let s: f64 = row.iter().sum();
            let scale: f64 = row.iter().map(|x| x.abs()).sum::<f64>().max(1.0);
            prop_assert!(s.abs() < 1e-10 * scale, "derivative row sum {s}");
        }
    }
}
