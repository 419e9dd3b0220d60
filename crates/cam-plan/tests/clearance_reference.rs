//! The pruned clearance query against the exhaustive reference (every cutter sample measured
//! with the exact design distance) on random postures near the `impeller-8+8` design: in the
//! hub channels, beside the blades (inside them too) and away from everything, for the
//! fixture's tapered ball ends and a short ball end, with the part sets and options the
//! planners use. The fast answer must never exceed the reference (it is a lower bound), must
//! equal it wherever the reference lies within `EXACT_BAND_MM`, and `is_clear` must agree with
//! the reference at the thresholds the planners check.
#![allow(clippy::unwrap_used, clippy::panic)] // test code

use cam_core::{Cutter, CutterLocation, CutterShape, HolderSegment, Point3, Vector3};
use cam_plan::clearance::{DesignMesh, EXACT_BAND_MM};
use cam_plan::{ClearanceOptions, DesignClearance, PartSet, Tool};
use impeller_model::{Impeller, Side};
use std::sync::{Arc, OnceLock};

/// Sampling tolerance and mesh chord (mm): coarser than the default keeps the exhaustive
/// reference affordable in the debug profile; the pruning does not depend on it.
const TOL: f64 = 0.05;

fn impeller() -> &'static Impeller {
    static IMP: OnceLock<Impeller> = OnceLock::new();
    IMP.get_or_init(|| impeller_model::fixtures::default_impeller().unwrap())
}

fn mesh() -> Arc<DesignMesh> {
    static MESH: OnceLock<Arc<DesignMesh>> = OnceLock::new();
    MESH.get_or_init(|| Arc::new(DesignMesh::new(impeller(), TOL).unwrap()))
        .clone()
}

/// SplitMix64: a reproducible stream of uniform numbers in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / (u64::MAX as f64 + 1.0)
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    /// `a` tilted by up to `max` (rad) in a random direction.
    fn tilt(&mut self, a: Vector3, max: f64) -> Vector3 {
        let helper = if a.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = a.cross(&helper).normalize();
        let v = a.cross(&u);
        let (t, s) = (self.range(0.0, max), self.range(0.0, std::f64::consts::TAU));
        (a * t.cos() + (u * s.cos() + v * s.sin()) * t.sin()).normalize()
    }
}

fn tapered(name: &str, ball: f64, half_angle_deg: f64) -> Tool {
    let mut cutter = Cutter::new(
        name,
        CutterShape::TaperedBallEnd {
            ball_radius: ball,
            half_angle: half_angle_deg.to_radians(),
        },
        20.0,
        3.0,
        35.0,
    )
    .unwrap();
    cutter.holder = vec![
        HolderSegment {
            bottom_radius: 10.5,
            top_radius: 13.5,
            length: 38.0,
        },
        HolderSegment {
            bottom_radius: 13.5,
            top_radius: 13.5,
            length: 42.0,
        },
    ];
    Tool {
        number: 6,
        cutter,
        teeth: 3,
        tool_length_mm: 115.0,
        plunge_edge_length_mm: None,
    }
}

fn ball(r: f64) -> Tool {
    let mut cutter =
        Cutter::new("ball", CutterShape::BallEnd { radius: r }, 6.0, 2.0, 30.0).unwrap();
    cutter.holder = vec![HolderSegment {
        bottom_radius: 7.5,
        top_radius: 10.5,
        length: 38.0,
    }];
    Tool {
        number: 7,
        cutter,
        teeth: 2,
        tool_length_mm: 68.0,
        plunge_edge_length_mm: None,
    }
}

/// A random posture of one of three kinds (by `k % 3`): the tip over a hub point, the ball
/// centre beside a blade side with the axis along its ruling, or anywhere around the blank.
fn posture(rng: &mut Rng, k: usize, ball_radius: f64) -> CutterLocation {
    let imp = impeller();
    match k % 3 {
        0 => {
            let hub = imp.hub();
            let (t0, t1) = hub.meridional().domain();
            let (t, phi) = (rng.range(t0, t1), rng.range(0.0, std::f64::consts::TAU));
            let n = Vector3::from(hub.normal(t, phi));
            let p = Point3::from(hub.point(t, phi)) + n * rng.range(-0.3, 4.0);
            CutterLocation::new(p, rng.tilt(n, 35f64.to_radians())).unwrap()
        }
        1 => {
            let set = match imp.splitter() {
                Some(s) if rng.next() < 0.4 => s,
                _ => imp.main(),
            };
            let blade = set.blade();
            let side = if rng.next() < 0.5 {
                Side::Pressure
            } else {
                Side::Suction
            };
            let s = blade.side(side);
            let ((u0, u1), (v0, v1)) = s.domain();
            let (u, v) = (rng.range(u0, u1), rng.range(v0, v0 + 0.8 * (v1 - v0)));
            let Some(out) = blade.outward_normal(side, u, v) else {
                return posture(rng, k + 1, ball_radius);
            };
            let rot = set.rotation((rng.next() * set.count() as f64) as usize % set.count());
            let centre = rot * (s.point(u, v) + out * rng.range(-0.3, ball_radius + 2.5));
            let ruling = rot * (s.point(u, v1) - s.point(u, v0)).normalize();
            let axis = rng.tilt(ruling, 25f64.to_radians());
            CutterLocation::new(Point3::from(centre - axis * ball_radius), axis).unwrap()
        }
        _ => {
            let (r, a) = (rng.range(0.0, 70.0), rng.range(0.0, std::f64::consts::TAU));
            let p = Point3::new(r * a.cos(), r * a.sin(), rng.range(-10.0, 90.0));
            CutterLocation::new(p, rng.tilt(Vector3::z(), 80f64.to_radians())).unwrap()
        }
    }
}

/// Checks `count` random postures of `tool` with `options`; returns how many references
/// lay within the exact band (so that the caller can insist the check was not vacuous).
fn check(
    tool: &Tool,
    ball_radius: f64,
    options: ClearanceOptions,
    seed: u64,
    count: usize,
) -> usize {
    let q = DesignClearance::with_mesh(impeller(), mesh(), tool, options).unwrap();
    let mut rng = Rng(seed);
    let mut in_band = 0;
    let mut k = 0;
    let mut checked = 0;
    while checked < count {
        k += 1;
        let cl = posture(&mut rng, k, ball_radius);
        // The blade sides run on into the hub body, where the largest of their signed
        // distances can read a point as deep inside a blade: the exact blade distance means
        // something only outside the hub, which a tool inside it has failed already (the
        // hub alone is checked everywhere).
        let inside_hub = options.parts.blades
            && q.samples().any(|(h, _)| {
                h > options.above_mm
                    && q.hub_signed_distance(&(cl.tip + cl.axis.into_inner() * h)) < 0.0
            });
        if inside_hub {
            continue;
        }
        checked += 1;
        let fast = q.clearance(&cl);
        let reference = q.clearance_exhaustive(&cl);
        let (f, r) = (fast.distance_mm, reference.distance_mm);
        assert!(
            f <= r + 1e-9,
            "posture {k} {cl:?}: fast {fast:?} above the reference {reference:?}"
        );
        if r < EXACT_BAND_MM {
            in_band += 1;
            assert!(
                (f - r).abs() <= 1e-9,
                "posture {k} {cl:?}: fast {fast:?} differs from the reference {reference:?} \
                 within the exact band"
            );
        }
        for m in [-0.5 * TOL, 0.0, TOL, 0.3] {
            assert_eq!(
                q.is_clear(&cl, m),
                r >= m,
                "posture {k} {cl:?}: is_clear({m}) disagrees with the reference {reference:?}"
            );
            let once = q.clearance_if_clear(&cl, m);
            assert_eq!(
                once.map(|c| c.distance_mm),
                (r >= m).then_some(f),
                "posture {k} {cl:?}: clearance_if_clear({m}) is not is_clear then clearance"
            );
        }
    }
    in_band
}

#[test]
fn tapered_t6_against_hub_and_blades_matches_the_reference() {
    let n = check(
        &tapered("T6", 1.0, 3.0),
        1.0,
        ClearanceOptions {
            sample_tol_mm: TOL,
            ..ClearanceOptions::default()
        },
        6,
        400,
    );
    assert!(n >= 100, "only {n} postures within the exact band");
}

#[test]
fn tapered_t5_against_the_blades_above_its_ball_matches_the_reference() {
    // Hub finishing's blade check: blades only, the ball left out.
    let n = check(
        &tapered("T5", 1.5, 2.0),
        1.5,
        ClearanceOptions {
            parts: PartSet::BLADES,
            sample_tol_mm: TOL,
            above_mm: 1.5,
        },
        5,
        400,
    );
    assert!(n >= 60, "only {n} postures within the exact band");
}

#[test]
fn ball_end_with_the_shroud_contour_matches_the_reference() {
    let n = check(
        &ball(1.0),
        1.0,
        ClearanceOptions {
            parts: PartSet {
                hub: true,
                blades: true,
                shroud: true,
            },
            sample_tol_mm: TOL,
            above_mm: 2.0,
        },
        7,
        400,
    );
    assert!(n >= 100, "only {n} postures within the exact band");
}

#[test]
fn tapered_t6_above_twice_its_ball_matches_the_reference() {
    // Hub finishing's check of the tool above the ball against hub and blades.
    let n = check(
        &tapered("T6", 1.0, 3.0),
        1.0,
        ClearanceOptions {
            sample_tol_mm: TOL,
            above_mm: 2.0,
            ..ClearanceOptions::default()
        },
        8,
        400,
    );
    assert!(n >= 100, "only {n} postures within the exact band");
}

#[test]
fn hub_alone_matches_the_reference_everywhere() {
    // Inside the hub body too, where the distance to the contour changes sign beyond its
    // ends.
    let n = check(
        &tapered("T6", 1.0, 3.0),
        1.0,
        ClearanceOptions {
            parts: PartSet {
                hub: true,
                blades: false,
                shroud: false,
            },
            sample_tol_mm: TOL,
            above_mm: 0.0,
        },
        9,
        600,
    );
    assert!(n >= 150, "only {n} postures within the exact band");
}

#[test]
fn certified_motions_keep_the_clearance_the_reference_measures() {
    // Motions from random postures near the design: a motion certified clear must measure
    // clear along its whole length by the exhaustive reference (within the stated error of
    // the sampling and of the mesh), and a motion refused must be refused at a posture the
    // reference finds below the threshold.
    let tool = tapered("T6", 1.0, 3.0);
    let options = ClearanceOptions {
        sample_tol_mm: TOL,
        above_mm: 2.0,
        ..ClearanceOptions::default()
    };
    let q = DesignClearance::with_mesh(impeller(), mesh(), &tool, options).unwrap();
    let mut rng = Rng(11);
    let (mut clear, mut refused) = (0, 0);
    let mut k = 0;
    while (clear < 60 || refused < 12) && k < 5000 {
        k += 1;
        // Clear ends a few millimetres apart: some motions pass through a blade between.
        let a = posture(&mut rng, k % 2, 1.0);
        let axis = rng.tilt(a.axis.into_inner(), 12f64.to_radians());
        let shift = Vector3::new(
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
        );
        let b = CutterLocation::new(a.tip + shift, axis).unwrap();
        let min = rng.range(-0.02, 0.1);
        if q.clearance(&a).distance_mm < min || q.clearance(&b).distance_mm < min {
            continue;
        }
        let tol = 0.01;
        let at = |s: f64| {
            CutterLocation::new(
                a.tip + (b.tip - a.tip) * s,
                a.axis.slerp(&b.axis, s).into_inner(),
            )
            .unwrap()
        };
        match q.segment_clearance(&a, &b, min, tol, 100_000) {
            Ok(()) if clear >= 60 => {}
            Ok(()) => {
                clear += 1;
                let slack = tol + 0.5 * TOL + 2.0 * mesh().chord_mm() + 1e-9;
                for i in 0..=64 {
                    let s = f64::from(i) / 64.0;
                    let r = q.clearance_exhaustive(&at(s)).distance_mm;
                    assert!(
                        r >= min - slack,
                        "motion {k} certified at {min} but the reference reads {r} at {s}"
                    );
                }
            }
            Err(s) => {
                refused += 1;
                let r = q.clearance_exhaustive(&at(s)).distance_mm;
                assert!(
                    r < min,
                    "motion {k} refused at {s} where the reference reads {r} ≥ {min}"
                );
            }
        }
    }
    assert!(
        clear >= 60 && refused >= 12,
        "{clear} clear, {refused} refused"
    );
}

#[test]
fn pruned_blade_distance_is_the_exhaustive_one() {
    // Around the blades (inside them too) and across the channels: the projections the mesh
    // bounds leave out never hold the nearest blade.
    let q = DesignClearance::with_mesh(
        impeller(),
        mesh(),
        &tapered("T6", 1.0, 3.0),
        ClearanceOptions {
            sample_tol_mm: TOL,
            ..ClearanceOptions::default()
        },
    )
    .unwrap();
    let mut rng = Rng(12);
    let mut near = 0;
    for k in 0..600 {
        let cl = posture(&mut rng, k % 2, 1.0);
        let p = cl.tip + cl.axis.into_inner() * rng.range(0.0, 12.0);
        let (fast, part) = q.blade_signed_distance(&p);
        let (reference, reference_part) = q.blade_signed_distance_exhaustive(&p);
        assert!(
            fast == reference,
            "{p:?}: {fast} ({part:?}) vs {reference} ({reference_part:?})"
        );
        near += usize::from(reference.abs() < 1.0);
        // The threshold form (instances the mesh keeps farther than `d` not projected on)
        // answers as the exhaustive distance does, thresholds around the distance included.
        for d in [reference - 0.05, reference + 0.05, 0.3, 1.5] {
            assert_eq!(
                q.blade_distance_at_least(&p, d),
                reference >= d,
                "{p:?}: at least {d}? exhaustive {reference}"
            );
        }
    }
    assert!(near >= 100, "only {near} points within 1 mm of a blade");
}

#[test]
fn bull_nose_and_flat_end_against_the_blades_match_the_reference() {
    // Plunge roughing asks for the blades only, with flat-bottomed tools.
    for (seed, shape) in [
        (
            13,
            CutterShape::BullNose {
                radius: 1.5,
                corner_radius: 0.5,
            },
        ),
        (14, CutterShape::FlatEnd { radius: 1.5 }),
    ] {
        let mut tool = ball(1.5);
        tool.cutter.shape = shape;
        let n = check(
            &tool,
            1.5,
            ClearanceOptions {
                parts: PartSet::BLADES,
                sample_tol_mm: TOL,
                above_mm: 0.0,
            },
            seed,
            200,
        );
        assert!(
            n >= 40,
            "{shape:?}: only {n} postures within the exact band"
        );
    }
}
