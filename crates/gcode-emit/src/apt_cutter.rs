//! The `CUTTER` record's numbers ↔ `cam-core`'s APT 7-parameter cutter.
//!
//! CL files write `CUTTER/d,r,e,f,a,b,h` with the angles `a` (bottom angle) and `b` (side
//! taper) in degrees, and often use short forms: `CUTTER/d` (flat end) and `CUTTER/d,r`
//! (torus with `e = d/2 − r`, `f = r`; ball end when `r = d/2`). The shape mapping itself is
//! [`cam_core::AptCutter::to_shape`] (exact; unsupported combinations are typed errors).

use cam_core::AptCutter;

/// The APT cutter of a `CUTTER` record's 1–7 numbers (lengths scaled by `scale`, angles in
/// degrees converted to radians), completing the short forms. `None` for 0 or > 7 numbers.
pub fn apt_from_cl_params(p: &[f64], scale: f64) -> Option<AptCutter> {
    if p.is_empty() || p.len() > 7 {
        return None;
    }
    let d = p[0];
    let r = p.get(1).copied().unwrap_or(0.0);
    let (e, f) = if p.len() >= 4 {
        (p[2], p[3])
    } else if r > 0.0 {
        (d / 2.0 - r, r)
    } else {
        (d / 2.0, 0.0)
    };
    Some(AptCutter {
        d: d * scale,
        r: r * scale,
        e: e * scale,
        f: f * scale,
        alpha: p.get(4).copied().unwrap_or(0.0).to_radians(),
        beta: p.get(5).copied().unwrap_or(0.0).to_radians(),
        h: p.get(6).copied().unwrap_or(0.0) * scale,
    })
}

/// The seven `CUTTER` numbers of an APT cutter, angles in degrees.
pub fn apt_to_cl_params(c: &AptCutter) -> [f64; 7] {
    [
        c.d,
        c.r,
        c.e,
        c.f,
        c.alpha.to_degrees(),
        c.beta.to_degrees(),
        c.h,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::CutterShape;

    fn shape(p: &[f64]) -> CutterShape {
        let mut c = apt_from_cl_params(p, 1.0).unwrap();
        c.h = 30.0;
        c.to_shape().unwrap().0
    }

    #[test]
    fn short_forms_complete_to_seven_parameters() {
        assert_eq!(shape(&[10.0]), CutterShape::FlatEnd { radius: 5.0 });
        assert_eq!(shape(&[10.0, 5.0]), CutterShape::BallEnd { radius: 5.0 });
        assert_eq!(
            shape(&[10.0, 1.0]),
            CutterShape::BullNose {
                radius: 5.0,
                corner_radius: 1.0
            }
        );
        assert!(apt_from_cl_params(&[], 1.0).is_none());
        assert!(apt_from_cl_params(&[1.0; 8], 1.0).is_none());
    }

    #[test]
    fn every_shape_round_trips_through_cl_numbers() {
        let shapes = [
            CutterShape::FlatEnd { radius: 4.0 },
            CutterShape::BallEnd { radius: 3.0 },
            CutterShape::BullNose {
                radius: 6.0,
                corner_radius: 1.5,
            },
            CutterShape::TaperedBallEnd {
                ball_radius: 2.0,
                half_angle: 4f64.to_radians(),
            },
            CutterShape::TaperedFlatEnd {
                tip_radius: 1.5,
                half_angle: 3f64.to_radians(),
            },
        ];
        for s in shapes {
            let nums = apt_to_cl_params(&AptCutter::from_shape(&s, 25.0));
            let back = apt_from_cl_params(&nums, 1.0)
                .unwrap()
                .to_shape()
                .unwrap()
                .0;
            for h in [0.0, 0.5, 2.0, 10.0] {
                assert!((s.radius_at(h) - back.radius_at(h)).abs() < 1e-12, "{s:?}");
            }
        }
    }
}
