//! Property tests: malformed parametric files never panic; random valid designs build blades
//! with the designed thickness, the documented side order and N-fold symmetry.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::{from_toml_str, Side};
use proptest::prelude::*;

const SAMPLES: [&str; 5] = [
    include_str!("../../../fixtures/impeller-8+8/impeller.toml"),
    include_str!("../../../fixtures/impeller-5-freeform/impeller.toml"),
    include_str!("../../../fixtures/impeller-11+11-freeform/impeller.toml"),
    include_str!("../../../fixtures/impeller-30-narrow/impeller.toml"),
    include_str!("../../../fixtures/impeller-plunge-400/impeller.toml"),
];

#[derive(Debug, Clone)]
enum Mutation {
    Truncate(usize),
    Flip(usize, u8),
    /// Replace the n-th number with a special value.
    Number(usize, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Flip(i, b)),
        (
            any::<usize>(),
            prop::sample::select(vec![
                "nan", "-inf", "inf", "-1.0", "0", "1e300", "-0.0", "7"
            ])
        )
            .prop_map(|(i, s)| Mutation::Number(i, s)),
    ]
}

fn apply(text: &str, m: &Mutation) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    match *m {
        Mutation::Truncate(i) => bytes.truncate(i % (bytes.len() + 1)),
        Mutation::Flip(i, b) => {
            let k = i % bytes.len();
            bytes[k] ^= b.max(1);
        }
        Mutation::Number(i, s) => {
            // Positions of numbers (a digit not preceded by a digit, letter, '.' or '_').
            let starts: Vec<usize> = (0..bytes.len())
                .filter(|&k| {
                    bytes[k].is_ascii_digit()
                        && (k == 0
                            || !(bytes[k - 1].is_ascii_alphanumeric()
                                || bytes[k - 1] == b'.'
                                || bytes[k - 1] == b'_'
                                || bytes[k - 1] == b'+'))
                })
                .collect();
            if !starts.is_empty() {
                let a = starts[i % starts.len()];
                let mut e = a;
                while e < bytes.len() && (bytes[e].is_ascii_digit() || bytes[e] == b'.') {
                    e += 1;
                }
                bytes.splice(a..e, s.bytes());
            }
        }
    }
    bytes
}

proptest! {
    #[test]
    fn mutated_files_give_a_model_or_a_typed_error(k in 0usize..5, m in mutation()) {
        let bytes = apply(SAMPLES[k], &m);
        let text = String::from_utf8_lossy(&bytes);
        if let Ok(imp) = from_toml_str(&text, "mutated.toml") {
            // Whatever builds is a usable model.
            prop_assert!(imp.main().count() >= 1);
            let b = imp.main().blade();
            let p = b.pressure().point(0.5, 0.5);
            prop_assert!(p.iter().all(|c| c.is_finite()));
        }
    }

    #[test]
    fn random_ruled_designs_have_designed_thickness_and_order(
        count in 3usize..24,
        wrap_hub in 0.0f64..50.0,
        wrap_shroud in 0.0f64..50.0,
        t0 in 0.3f64..2.0,
        t1 in 0.3f64..2.0,
        rounded in any::<bool>(),
        split in any::<bool>(),
    ) {
        let edge = if rounded { "rounded" } else { "blunt" };
        let splitter = if split {
            format!("[splitter]\ncount = {count}\nstart_fraction = 0.4\n")
        } else {
            String::new()
        };
        let text = format!(
            "name = \"random\"\nfillet_radius_mm = 1.0\n\
             [hub]\ntype = \"quarter_ellipse\"\ninlet_zr_mm = [60.0, 15.0]\noutlet_zr_mm = [8.0, 80.0]\n\
             [shroud]\ntype = \"quarter_ellipse\"\ninlet_zr_mm = [60.0, 40.0]\noutlet_zr_mm = [20.0, 80.0]\n\
             [main]\ncount = {count}\nkind = \"ruled\"\nthickness_mm = [[0.0, {t0}], [1.0, {t1}]]\n\
             leading_edge = \"{edge}\"\ntrailing_edge = \"blunt\"\n\
             [[main.wrap]]\nspan = 0.0\ntheta_deg = [[0.0, 0.0], [1.0, {wrap_hub}]]\n\
             [[main.wrap]]\nspan = 1.0\ntheta_deg = [[0.0, 0.0], [1.0, {wrap_shroud}]]\n\
             {splitter}[stock]\ndiameter_mm = 170.0\nheight_mm = 62.0\n"
        );
        let imp = from_toml_str(&text, "random.toml").unwrap();
        let b = imp.main().blade();
        let d = b.design().unwrap();
        // Thickness at the interpolation sections of the hub and shroud rows.
        for i in 1..=10 {
            let u = i as f64 / 10.0;
            for s in [0.0, 1.0] {
                let t = b.normal_thickness(u, d.v_of_span(s)).unwrap();
                let want = d.thickness.thickness(d.m_local(u));
                prop_assert!((t - want).abs() < 1e-6, "u {u} s {s}: {t} vs {want}");
            }
        }
        // The suction side faces +θ, toward the next blade.
        prop_assert_eq!(b.plus_theta_side(), Side::Suction);
        // N-fold symmetry: blade k is blade 0 turned by k pitches.
        let k = count - 1;
        let p0 = b.suction().point(0.3, 0.6);
        let pk = imp.main().instance(k).suction().point(0.3, 0.6);
        prop_assert!((imp.main().rotation(k) * p0 - pk).norm() < 1e-9);
    }
}

proptest! {
    /// The natural cubic spline passes through its table and is C¹ at interior points.
    #[test]
    fn laws_interpolate_their_tables(ys in prop::collection::vec(-50.0f64..50.0, 1..8)) {
        let n = ys.len();
        let table: Vec<[f64; 2]> = ys
            .iter()
            .enumerate()
            .map(|(i, &y)| [if n == 1 { 0.0 } else { i as f64 / (n - 1) as f64 }, y])
            .collect();
        let law = impeller_model::law::Law::new(&table).unwrap();
        for p in &table {
            prop_assert!((law.eval(p[0]) - p[1]).abs() < 1e-9);
        }
        for p in table.iter().skip(1).take(n.saturating_sub(2)) {
            let (_, a) = law.eval_d(p[0] - 1e-9);
            let (_, b) = law.eval_d(p[0] + 1e-9);
            prop_assert!((a - b).abs() < 1e-4 * (1.0 + a.abs()));
        }
    }

    /// Closest points on a quarter-ellipse contour: no sample of the contour is closer, and the
    /// signed distance changes sign across the curve.
    #[test]
    fn contour_closest_point_is_global(
        zi in 30.0f64..60.0, ri in 5.0f64..20.0, zo in 0.0f64..10.0, ro in 30.0f64..80.0,
        qz in -10.0f64..70.0, qr in 0.0f64..90.0,
    ) {
        let c = impeller_model::MeridionalCurve::quarter_ellipse([zi, ri], [zo, ro]).unwrap();
        let q = nalgebra::Vector2::new(qz, qr);
        let (t, d) = c.closest(q);
        let samples: Vec<_> = (0..=2000).map(|k| c.point(k as f64 / 2000.0)).collect();
        let best = samples
            .iter()
            .map(|p| (p - q).norm())
            .fold(f64::INFINITY, f64::min);
        // The nearest sample lies within half the largest sample spacing of the true closest
        // point (the curve is smooth), so the dense distance can exceed the global minimum by
        // at most that much.
        let spacing = samples
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .fold(0.0, f64::max);
        prop_assert!(d.abs() <= best + 1e-9, "{} > {best}", d.abs());
        prop_assert!(best - d.abs() <= 0.5 * spacing + 1e-9, "{best} vs {}", d.abs());
        let n = c.normal(t);
        if d.abs() > 1e-6 && t > 1e-9 && t < 1.0 - 1e-9 {
            prop_assert!(((q - c.point(t)).dot(&n) > 0.0) == (d > 0.0));
        }
    }
}
