//! The swept envelope as a [`nurbs::closest::PointQuery`], so that code written for any
//! shape of the point-query vocabulary (NURBS surfaces, blade sides, hub and shroud) takes a
//! cutter's swept volume too.
//!
//! Sign convention: positive outside the swept volume (the outward side of the envelope),
//! negative inside, as [`SweptEnvelope::signed_distance`]. The closest point is
//! `p − d·∇d`: outside the volume the exact foot point on the envelope (`∇d` is the unit
//! envelope normal there); inside, the point of the deepest member's surface straight out
//! from `p` (a point of the envelope whenever that member's surface is not covered by another
//! member there, the usual case for small overcuts). The hint is the minimiser's
//! [`EnvelopeParam`]. `certified` is the envelope's certificate (every part of the path not
//! searched by Newton is proven farther, within the certification slack); a query the
//! envelope cannot answer (a non-finite point, guides that meet) returns a NaN distance with
//! `certified = false`. Cost: one certified envelope distance and one gradient (a few µs).

use nurbs::closest::{PointProjection, PointQuery};

use crate::{EnvelopeParam, Point3, SweptEnvelope, Vector3};

impl PointQuery for SweptEnvelope {
    type Hint = EnvelopeParam;

    /// ```
    /// use cam_core::{CutterShape, EnvelopeOptions, GuideCurve, SphereFamily, SweptEnvelope,
    ///                Vector3};
    /// use nurbs::closest::PointQuery;
    /// // A 3 mm ball moving 50 mm along +x with a vertical axis.
    /// let shape = CutterShape::BallEnd { radius: 3.0 };
    /// let family = SphereFamily::from_shape(&shape, 25.0)?;
    /// let line = |z: f64| GuideCurve::new(1, vec![0.0, 0.0, 1.0, 1.0],
    ///     vec![Vector3::new(0.0, 0.0, z), Vector3::new(50.0, 0.0, z)], None);
    /// let env = SweptEnvelope::new(family, line(0.0)?, line(10.0)?, 0.0,
    ///                              EnvelopeOptions::default())?;
    /// // 1 mm below the tip line: outside, 1 mm away, foot point on the tip line.
    /// let a = env.query(&Vector3::new(25.0, 0.0, -1.0), None);
    /// assert!((a.signed_distance - 1.0).abs() < 1e-12 && a.certified);
    /// assert!((a.point - Vector3::new(25.0, 0.0, 0.0)).norm() < 1e-9);
    /// // 0.5 mm inside the ball's lowest point, warm-started from the previous answer.
    /// let b = env.query(&Vector3::new(26.0, 0.0, 0.5), Some(a.hint));
    /// assert!((b.signed_distance + 0.5).abs() < 1e-12);
    /// # Ok::<(), cam_core::CamError>(())
    /// ```
    fn query(&self, q: &Vector3, hint: Option<EnvelopeParam>) -> PointProjection<EnvelopeParam> {
        let p = Point3::from(*q);
        match self.signed_distance_with_gradient(&p, hint) {
            Ok((d, g)) => PointProjection {
                point: q - g.point * d.distance,
                signed_distance: d.distance,
                hint: d.param,
                certified: d.certified,
            },
            Err(_) => PointProjection {
                point: *q,
                signed_distance: f64::NAN,
                hint: hint.unwrap_or(EnvelopeParam { s: 0.0, t: 0.0 }),
                certified: false,
            },
        }
    }

    fn signed_distance(&self, q: &Vector3) -> f64 {
        SweptEnvelope::signed_distance(self, &Point3::from(*q), None)
            .map_or(f64::NAN, |d| d.distance)
    }
}
