//! What the emitted point-milling passes leave on a band: residual (scallop) and overcut
//! over a dense grid of the side, measured against the swept balls.
//!
//! Between two postures the ball centre moves on the straight chord, so the ball sweeps a
//! *capsule* (the points within `R` of the chord). At a grid point `P` of the side with
//! outward normal `n`:
//! - **overcut** = `max(R − dist(P, chord))` over the capsules (how deep a ball reached
//!   below the side there; exact point–segment distances);
//! - **residual** = the entry parameter `t ≥ 0` of the normal ray `P + t·n` into the nearest
//!   capsule (exact: the infinite cylinder about the chord between its end planes, and the
//!   two end spheres), the thickness of material the balls left above `P` along `n` (less
//!   the allowance: the balls run `a` off the side).
//!
//! Only the balls (the cutting end) are measured: the pass planner keeps the flutes above
//! them off the side by the axis tilt. Capsules are bucketed in a uniform grid of cells of
//! `2R` so a point meets only the few capsules near it; points are measured in parallel.
//! Residuals are capped at `cap_mm` (a point no ball comes near reads the cap).
//!
//! Complexity: O(points · capsules per cell neighbourhood).

use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::HashMap;

/// Entry parameter `t` of the ray `o + t·d` (unit `d`) into the capsule of radius `r` about
/// the segment `a–b`, for a ray starting outside it; `None` when it misses or the capsule
/// lies behind (`t < 0`).
pub fn ray_capsule_entry(
    o: &Vector3<f64>,
    d: &Vector3<f64>,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    r: f64,
) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut keep = |t: f64| {
        if t >= 0.0 && best.is_none_or(|x| t < x) {
            best = Some(t);
        }
    };
    // End spheres.
    for c in [a, b] {
        let oc = o - c;
        let bq = d.dot(&oc);
        let cq = oc.norm_squared() - r * r;
        let h = bq * bq - cq;
        if h >= 0.0 {
            keep(-bq - h.sqrt());
        }
    }
    // Cylinder body between the end planes.
    let ba = b - a;
    let baba = ba.norm_squared();
    if baba > 1e-24 {
        let oa = o - a;
        let bard = ba.dot(d);
        let baoa = ba.dot(&oa);
        let rdoa = d.dot(&oa);
        let oaoa = oa.norm_squared();
        let qa = baba - bard * bard;
        let qb = baba * rdoa - baoa * bard;
        let qc = baba * oaoa - baoa * baoa - r * r * baba;
        if qa > 1e-18 {
            let h = qb * qb - qa * qc;
            if h >= 0.0 {
                let t = (-qb - h.sqrt()) / qa;
                let y = baoa + t * bard;
                if y > 0.0 && y < baba {
                    keep(t);
                }
            }
        }
    }
    best
}

/// Distance of `p` from the segment `a–b`.
pub fn segment_distance(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// The swept balls of a set of ball-centre polylines, bucketed for point queries.
#[derive(Debug)]
pub struct SweptBalls {
    r: f64,
    cell: f64,
    segments: Vec<(Vector3<f64>, Vector3<f64>)>,
    grid: HashMap<(i64, i64, i64), Vec<u32>>,
}

impl SweptBalls {
    /// The capsules of radius `r` along each polyline of `runs` (a single point makes a
    /// ball).
    pub fn new(runs: &[Vec<Vector3<f64>>], r: f64) -> Self {
        let cell = (2.0 * r).max(0.5);
        let mut segments = Vec::new();
        for run in runs {
            match run.len() {
                0 => {}
                1 => segments.push((run[0], run[0])),
                _ => segments.extend(run.windows(2).map(|w| (w[0], w[1]))),
            }
        }
        let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
        let key = |x: f64| (x / cell).floor() as i64;
        for (k, (a, b)) in segments.iter().enumerate() {
            let lo = a.inf(b).add_scalar(-r);
            let hi = a.sup(b).add_scalar(r);
            for i in key(lo.x)..=key(hi.x) {
                for j in key(lo.y)..=key(hi.y) {
                    for l in key(lo.z)..=key(hi.z) {
                        grid.entry((i, j, l)).or_default().push(k as u32);
                    }
                }
            }
        }
        Self {
            r,
            cell,
            segments,
            grid,
        }
    }

    /// (residual capped at `cap`, overcut) at `p` with outward unit normal `n`.
    pub fn measure(&self, p: &Vector3<f64>, n: &Vector3<f64>, cap: f64) -> (f64, f64) {
        let key = |x: f64| (x / self.cell).floor() as i64;
        let q = p + n * cap;
        let lo = p.inf(&q);
        let hi = p.sup(&q);
        let mut residual = cap;
        let mut overcut = 0.0f64;
        let mut seen: Vec<u32> = Vec::new();
        for i in key(lo.x)..=key(hi.x) {
            for j in key(lo.y)..=key(hi.y) {
                for l in key(lo.z)..=key(hi.z) {
                    let Some(list) = self.grid.get(&(i, j, l)) else {
                        continue;
                    };
                    for &k in list {
                        if seen.contains(&k) {
                            continue;
                        }
                        seen.push(k);
                        let (a, b) = &self.segments[k as usize];
                        let d = segment_distance(p, a, b);
                        if d < self.r {
                            overcut = overcut.max(self.r - d);
                            residual = 0.0;
                        } else if let Some(t) = ray_capsule_entry(p, n, a, b, self.r) {
                            residual = residual.min(t);
                        }
                    }
                }
            }
        }
        (residual, overcut)
    }

    /// [`SweptBalls::measure`] at many points, in parallel.
    pub fn measure_all(
        &self,
        points: &[(Vector3<f64>, Vector3<f64>)],
        cap: f64,
    ) -> Vec<(f64, f64)> {
        points
            .par_iter()
            .map(|(p, n)| self.measure(p, n, cap))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capsule_entry_closed_forms() {
        let (a, b) = (Vector3::new(0.0, 0.0, 5.0), Vector3::new(10.0, 0.0, 5.0));
        // Straight up into the body from below: the body's lowest line is z = 5 − 2.
        let t = ray_capsule_entry(&Vector3::new(4.0, 0.0, 0.0), &Vector3::z(), &a, &b, 2.0);
        assert!((t.unwrap() - 3.0).abs() < 1e-12);
        // Beyond the end: the end sphere, at x = 11: z = 5 − √(4 − 1).
        let t = ray_capsule_entry(&Vector3::new(11.0, 0.0, 0.0), &Vector3::z(), &a, &b, 2.0);
        assert!((t.unwrap() - (5.0 - 3f64.sqrt())).abs() < 1e-12);
        // A miss, and a capsule behind the ray.
        assert!(
            ray_capsule_entry(&Vector3::new(13.0, 0.0, 0.0), &Vector3::z(), &a, &b, 2.0).is_none()
        );
        assert!(
            ray_capsule_entry(&Vector3::new(4.0, 0.0, 9.0), &Vector3::z(), &a, &b, 2.0).is_none()
        );
        // Along the axis from outside: the first end sphere.
        let t = ray_capsule_entry(&Vector3::new(-5.0, 0.0, 5.0), &Vector3::x(), &a, &b, 2.0);
        assert!((t.unwrap() - 3.0).abs() < 1e-12);
    }

    /// Two parallel passes of balls over the plane z = 0 (centres at z = R): the cusp midway
    /// is R − √(R² − w²/4), the residual under a centre 0, and a ball pushed 0.1 mm into the
    /// plane reads 0.1 mm of overcut.
    #[test]
    fn scallop_between_two_passes_on_a_plane() {
        let (r, w) = (2.0, 1.0);
        let run = |y: f64, z: f64| vec![Vector3::new(0.0, y, z), Vector3::new(20.0, y, z)];
        let balls = SweptBalls::new(&[run(0.0, r), run(w, r)], r);
        let (res, over) = balls.measure(&Vector3::new(10.0, 0.5 * w, 0.0), &Vector3::z(), 1.0);
        let cusp = r - (r * r - w * w / 4.0).sqrt();
        assert!((res - cusp).abs() < 1e-12 && over == 0.0, "{res} {cusp}");
        let (res, _) = balls.measure(&Vector3::new(10.0, 0.0, 0.0), &Vector3::z(), 1.0);
        assert!(res.abs() < 1e-12);
        let deep = SweptBalls::new(&[run(0.0, r - 0.1)], r);
        let (res, over) = deep.measure(&Vector3::new(10.0, 0.0, 0.0), &Vector3::z(), 1.0);
        assert!(res == 0.0 && (over - 0.1).abs() < 1e-12);
        // Far from every ball: the cap.
        let (res, _) = balls.measure(&Vector3::new(10.0, 30.0, 0.0), &Vector3::z(), 1.0);
        assert_eq!(res, 1.0);
    }
}
