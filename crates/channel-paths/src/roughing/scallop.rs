//! The scallop measured on a level: rays along the level normal from a grid of every lane to
//! the first cutter position of the level (module docs of [`super`], metrics).

use super::plan2d::Region;
use cam_core::{CutterLocation, CutterShape};
use impeller_model::levels::DepthLevel;
use nalgebra::{Unit, Vector3};

/// Grid of scallop measurement per area and level (along × across the flow).
pub(super) const SCALLOP_GRID: (usize, usize) = (40, 16);

/// Cutter positions per ball radius along each cut in the scallop measurement (see
/// `measure_scallop`: the discrete positions' cusps read at most ~0.002 mm above the swept
/// cutter's scallop at this density for the fixtures' 0.5 mm targets).
pub(super) const SCALLOP_DENSIFY: f64 = 16.0;

/// Whether `x` lies inside the cutter at `cl` (solid of revolution up to the flute length).
pub(super) fn inside(
    profile: &cam_core::RadiusProfile,
    flute: f64,
    cl: &CutterLocation,
    x: &Vector3<f64>,
) -> bool {
    let a = cl.axis.into_inner();
    let d = x - cl.tip.coords;
    let h = d.dot(&a);
    if !(0.0..=flute).contains(&h) {
        return false;
    }
    (d - a * h).norm() <= profile.radius_at(h)
}

/// The cutter locations of one level, densified along their runs and bucketed in space,
/// for [`ScallopProbe::measure`].
pub(super) struct ScallopProbe {
    pub(super) shape: CutterShape,
    pub(super) flute: f64,
    pub(super) cap: f64,
    /// The ball radius (0 for a flat end).
    pub(super) reach: f64,
    /// The distance within which a location can hold a point of a probe ray: `2·reach + cap`.
    pub(super) radius: f64,
    pub(super) dense: Vec<CutterLocation>,
    /// Indices into `dense` by cubic cell of side `radius` (the 27 cells around a point's
    /// cell hold every location within `radius` of it).
    pub(super) cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl ScallopProbe {
    /// The locations of `runs` (each a sequence of consecutive locations joined by cutting
    /// motions), densified to `reach / SCALLOP_DENSIFY`, for rays of length `cap`. O(dense).
    pub(super) fn new(
        shape: &CutterShape,
        flute: f64,
        runs: &[Vec<CutterLocation>],
        cap: f64,
    ) -> Self {
        let reach = super::level::end_radius(shape);
        // Densify consecutive locations to `reach / SCALLOP_DENSIFY`: the union of discrete
        // cutters under-reads the swept one between them, so that a point at lateral distance
        // `d` from the path is reached only as if `√(d² + (a/2)²)` away for spacing `a`. At a
        // quarter radius this read up to 0.018 mm above a 0.5 mm scallop of a ball R1.5 (the
        // cusps of the discrete balls); at a sixteenth it is below 0.002 mm.
        let mut dense: Vec<CutterLocation> = Vec::new();
        for cls in runs {
            for w in cls.windows(2) {
                let d = (w[1].tip - w[0].tip).norm();
                let k = ((d * SCALLOP_DENSIFY / reach).ceil() as usize).clamp(1, 256);
                for i in 0..k {
                    let t = i as f64 / k as f64;
                    let axis = w[0].axis.into_inner() * (1.0 - t) + w[1].axis.into_inner() * t;
                    dense.push(CutterLocation {
                        tip: w[0].tip + (w[1].tip - w[0].tip) * t,
                        axis: Unit::new_normalize(axis),
                    });
                }
            }
            if let Some(l) = cls.last() {
                dense.push(*l);
            }
        }
        let radius = 2.0 * reach + cap;
        let mut cells: std::collections::HashMap<[i64; 3], Vec<u32>> =
            std::collections::HashMap::new();
        if radius > 0.0 && radius.is_finite() {
            for (i, c) in dense.iter().enumerate() {
                if let Some(key) = Self::cell(&c.tip.coords, radius) {
                    cells.entry(key).or_default().push(i as u32);
                }
            }
        }
        Self {
            shape: *shape,
            flute,
            cap,
            reach,
            radius,
            dense,
            cells,
        }
    }

    /// The cell of `p` (`None` for a point too far out to bucket).
    pub(super) fn cell(p: &Vector3<f64>, side: f64) -> Option<[i64; 3]> {
        let k = |x: f64| {
            let c = (x / side).floor();
            (c.abs() < 1e15).then_some(c as i64)
        };
        Some([k(p.x)?, k(p.y)?, k(p.z)?])
    }

    /// Whether the cutter at `c` can hold a point of the segment `x0`–`x1`: its axis from the
    /// tip to the flute top passes within `r_max` of the segment.
    pub(super) fn may_hold(
        &self,
        c: &CutterLocation,
        x0: &Vector3<f64>,
        x1: &Vector3<f64>,
        r_max: f64,
    ) -> bool {
        let top = c.tip + c.axis.into_inner() * self.flute;
        let (x0, x1) = (cam_core::Point3::from(*x0), cam_core::Point3::from(*x1));
        cam_core::path::segment_segment_distance(&x0, &x1, &c.tip, &top) <= r_max
    }

    /// Largest scallop over a grid of the lane `region` (its machinable region) of level
    /// `lv`: from each grid point, the distance along the level normal to the first cutter
    /// position, at most `cap`: the ray is marched at a quarter of the ball radius and the
    /// first entry bisected (40 steps); a cutter crossed by the ray over less than a march
    /// step may be missed, which only reads more. O(grid · (cap / step) · dense locations
    /// near the point).
    pub(super) fn measure(&self, region: &Region, lv: &DepthLevel) -> f64 {
        if self.dense.is_empty() {
            return 0.0;
        }
        let (reach, cap) = (self.reach, self.cap);
        let (ns, ny) = SCALLOP_GRID;
        let (s0, s1) = (region.s[0], region.s[region.s.len() - 1]);
        let profile = self.shape.profile();
        let mut near: Vec<&CutterLocation> = Vec::new();
        let mut bracket: Vec<&CutterLocation> = Vec::new();
        // The widest radius of the cutting end (its profile does not narrow upward), with a
        // margin over the rounding of `inside`.
        let r_max = profile.radius_at(self.flute).max(profile.radius_at(0.0));
        let r_max = r_max + 1e-9 * (1.0 + r_max);
        let mut worst: f64 = 0.0;
        for i in 0..=ns {
            let s = s0 + (s1 - s0) * i as f64 / ns as f64;
            let (l, r) = region.bounds(s);
            for j in 0..=ny {
                let y = l + (r - l) * j as f64 / ny as f64;
                let (p, n) = lv.at_developed(s, y / lv.radius_at(s));
                near.clear();
                let within = |c: &&CutterLocation| (c.tip.coords - p).norm() <= self.radius;
                match Self::cell(&p, self.radius).filter(|_| !self.cells.is_empty()) {
                    Some([x, y, z]) => {
                        for dx in -1..=1 {
                            for dy in -1..=1 {
                                for dz in -1..=1 {
                                    if let Some(ids) = self.cells.get(&[x + dx, y + dy, z + dz]) {
                                        near.extend(
                                            ids.iter()
                                                .filter_map(|&k| self.dense.get(k as usize))
                                                .filter(within),
                                        );
                                    }
                                }
                            }
                        }
                    }
                    None => near.extend(self.dense.iter().filter(within)),
                }
                // Only a cutter whose axis (tip to flute top) passes within its widest radius
                // of a stretch of the ray can hold a point of it: the march looks at those of
                // the whole ray, the bisection at those of its bracket (the same answers as
                // testing every nearby cutter, with fewer tests).
                near.retain(|c| self.may_hold(c, &p, &(p + n * cap), r_max));
                let hit = |t: f64| {
                    let x = p + n * t;
                    near.iter().any(|c| inside(&profile, self.flute, c, &x))
                };
                if hit(0.0) {
                    continue;
                }
                // March up the ray at a quarter radius to the first position inside a cutter
                // (a ray may pass above or beside the cutters: the cap alone does not tell),
                // then bisect between the last miss and the first hit.
                let step = (0.25 * reach).max(1e-3).min(cap);
                let mut lo = 0.0;
                let mut first_hit = None;
                while lo < cap {
                    let t = (lo + step).min(cap);
                    if hit(t) {
                        first_hit = Some(t);
                        break;
                    }
                    lo = t;
                }
                let Some(mut hi) = first_hit else {
                    worst = worst.max(cap);
                    continue;
                };
                bracket.clear();
                bracket.extend(
                    near.iter()
                        .filter(|c| self.may_hold(c, &(p + n * lo), &(p + n * hi), r_max)),
                );
                let hit = |t: f64| {
                    let x = p + n * t;
                    bracket.iter().any(|c| inside(&profile, self.flute, c, &x))
                };
                for _ in 0..40 {
                    let m = 0.5 * (lo + hi);
                    if hit(m) {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                worst = worst.max(hi);
            }
        }
        worst
    }
}
