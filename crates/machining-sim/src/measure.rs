//! Overcut and residual maps over the design surfaces.
//!
//! **Overcut** is read at the dexel segment end points ([`crate::endpoints`]): each cut end
//! point is an exact ray–cutter intersection, and its signed distance to the design is the
//! exact depth of the cut there; the remaining error is the bound of
//! [`crate::endpoints::overcut_error_bound`] (ray spacing against the cutter curvature, plus
//! the sweep tolerance). Each end point's depth is attributed to the nearest design sample for
//! the maps. Where no end point lies inside the design — a cut through a thin wall or a whole
//! blade tip, so a ray lost all its material there — the normal probes below supply the value.
//!
//! **Residual** and the through-cut overcut are probed along the design normals through the
//! dexels. Membership along the normal line `P + t n` uses the grid whose ray direction is
//! most aligned with `n` (|n_d| ≥ 1/√3): the nearest ray is exact along its direction and the
//! lateral offset (≤ h/√2) moves a boundary of normal `n` by at most `h/√2 · tan∠(n, e_d)
//! ≤ h`, so each probed thickness is accurate to about one cell `h`. The line is marched in
//! steps of `h/2` and each material transition is refined by bisection to `h/64`.
//!
//! * probed overcut at P: if P is empty, the removed depth along `−n` is kept only when the
//!   line crosses the design (or reaches the probe depth) without meeting material — the
//!   through-cut case without end points; a line that meets material inside the design has an
//!   end point there, which is exact and replaces the probe's cell-sized estimate. The depth
//!   kept is that of the removed points on the rays read (`−sd` there), so a probe never
//!   reads more than was cut: at an edge thinner than a cell the line's own depth would credit
//!   a ray passing beside the edge;
//! * residual at P: if P is in material, the distance along `+n` to the first empty point,
//!   stopping when the line enters the design again or at the probe depth.
//!
//! The design's signed distance is evaluated only where a sphere-tracing bound does not
//! already guarantee the side (|sd| is a safe step), so thick regions cost O(1) evaluations.
//! Cost per sample: O(depth / h) membership queries of O(1) each; samples run in parallel.

use crate::design::{DesignModel, SurfaceGrid};
use crate::dexel::TriDexel;
use crate::endpoints::{endpoint_depths, pool_deepest, SampleIndex};
use cam_core::{Point3, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Overcut and residual over one design surface (row-major in v like [`SurfaceGrid`];
/// `None` for skipped samples).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceMap {
    /// Surface name.
    pub name: String,
    /// Samples along u.
    pub nu: usize,
    /// Samples along v.
    pub nv: usize,
    /// Sample points (mm).
    pub points: Vec<[f64; 3]>,
    /// Removed depth inside the design along −normal (mm).
    pub overcut_mm: Vec<Option<f64>>,
    /// Material thickness left outside the design along +normal (mm).
    pub residual_mm: Vec<Option<f64>>,
}

/// A largest value and where it occurs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Extremum {
    /// Value (mm).
    pub value_mm: f64,
    /// Surface name.
    pub surface: String,
    /// Sample index along u.
    pub i: usize,
    /// Sample index along v.
    pub j: usize,
    /// Sample point (mm).
    pub point: [f64; 3],
    /// Whether the probe depth capped the value (true thickness is at least this).
    pub capped: bool,
}

/// Probe thicknesses at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// Overcut (mm).
    pub overcut: f64,
    /// Residual (mm).
    pub residual: f64,
}

/// The grid whose rays are most aligned with `n` (`|n_d| ≥ 1/√3`), whose membership the
/// probes read along the normal line (module docs).
fn aligned_grid(n: &Vector3) -> usize {
    (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(2)
}

/// Measures overcut and residual at `p` with outward unit normal `n`, up to `max_depth` mm.
pub fn probe(
    stock: &TriDexel,
    initial: &TriDexel,
    design: &dyn DesignModel,
    p: &Point3,
    n: &Vector3,
    max_depth: f64,
) -> Probe {
    let d = aligned_grid(n);
    let occ = |t: f64| {
        let x = p + n * t;
        stock.contains_via(d, &[x.x, x.y, x.z])
    };
    // "Not removed": material now, or never material (outside the blank).
    let kept = |t: f64| {
        let x = p + n * t;
        let x = [x.x, x.y, x.z];
        stock.contains_via(d, &x) || !initial.contains_via(d, &x)
    };
    let h = stock.cell();
    let step = 0.5 * h;
    let sd = |t: f64| design.signed_distance(&(p + n * t));
    if kept(0.0) && !occ(0.0) {
        return Probe {
            overcut: 0.0,
            residual: 0.0,
        };
    }
    if occ(0.0) {
        Probe {
            overcut: 0.0,
            residual: residual_along(stock, design, p, n, max_depth),
        }
    } else {
        // Overcut: march inward while removed; the value is the deepest removed point's
        // distance inside the design, −sd, read on the rays (see below).
        let mut t = 0.0;
        let mut best: f64 = 0.0;
        let mut steps = 0usize;
        loop {
            let next = t + step;
            if next > max_depth {
                return Probe {
                    overcut: best,
                    residual: 0.0,
                };
            }
            if kept(-next) {
                // Material inside the design: a dexel ends there, and the end-point
                // measurement (exact) replaces this cell-sized estimate.
                return Probe {
                    overcut: 0.0,
                    residual: 0.0,
                };
            }
            // The depth counted is that of the point on the nearest ray where the removal
            // was read, `−sd(x′)`: that point is removed (exactly along its ray, and the
            // simulated stock never removes more than the tool), so its depth is cut depth,
            // never more. The probe line's own depth would credit the ray's lateral offset
            // (up to h/√2): at a blade edge thinner than a cell the nearest ray passes beyond
            // the edge through air, and the line read half the wall as overcut (NASA Rotor
            // 37's 0.44 mm trailing edges at 0.5 mm: 0.172 mm where the exact swept
            // envelopes give 0.0026 mm). A ray point outside the design counts nothing.
            let x = p - n * next;
            if let Some(q) = stock.nearest_ray_point(d, &[x.x, x.y, x.z]) {
                best = best.max(-design.signed_distance(&Point3::new(q[0], q[1], q[2])));
            }
            // The line's design distance is evaluated every other step (every cell) to see
            // whether it has left the design.
            steps += 1;
            if steps % 2 == 1 && sd(-next) > 0.0 {
                // Left the design (cut through a wall).
                return Probe {
                    overcut: best,
                    residual: 0.0,
                };
            }
            t = next;
        }
    }
}

/// The residual at `p` (outward unit normal `n`, up to `max_depth` mm): the distance along
/// `+n` from `p` to the first empty point of `stock`, 0 when `p` itself is empty. The line is
/// marched in steps of `h/2` and the transition refined by bisection to `h/64`; the march
/// stops where the line comes within `min(t, h)/2` of the design again (another part of the
/// design: the nearest ray may lie on either side) and reports the last unambiguous depth,
/// or at `max_depth` (capped). This is [`probe`]'s residual, without its overcut reading,
/// for callers that need the material left and not the cut depth (rest machining).
/// Cost: O(residual / h) membership queries and at most as many design evaluations.
pub fn residual_along(
    stock: &TriDexel,
    design: &dyn DesignModel,
    p: &Point3,
    n: &Vector3,
    max_depth: f64,
) -> f64 {
    let d = aligned_grid(n);
    let occ = |t: f64| {
        let x = p + n * t;
        stock.contains_via(d, &[x.x, x.y, x.z])
    };
    if !occ(0.0) {
        return 0.0;
    }
    let h = stock.cell();
    let step = 0.5 * h;
    // A line point within `h` of another part of the design boundary is ambiguous (the
    // nearest ray may lie on either side): the march stops once the design distance falls
    // below min(t, h)/2 and reports the last unambiguous depth.
    let margin = |t: f64| 0.5 * t.min(h);
    let sd = |t: f64| design.signed_distance(&(p + n * t));
    // Material at 0, none at `b`: bisect to h/64.
    let refine = |mut a: f64, mut b: f64| {
        while (b - a).abs() > h / 64.0 {
            let m = 0.5 * (a + b);
            if occ(m) {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    };
    let mut t = 0.0;
    let mut safe = 0.0;
    loop {
        let next = t + step;
        if next > max_depth {
            return max_depth;
        }
        if next > safe {
            let s = sd(next);
            if s < margin(next) {
                return t;
            }
            safe = next + (s - 0.5 * h).max(0.0);
        }
        if !occ(next) {
            return refine(t, next);
        }
        t = next;
    }
}

/// Measures every sample of every grid (parallel over samples); `initial` is the blank
/// before machining (removed = material in `initial`, none in `stock`). See [`measure`].
pub fn measure_maps(
    stock: &TriDexel,
    initial: &TriDexel,
    design: &dyn DesignModel,
    grids: &[SurfaceGrid],
    max_depth: f64,
) -> Vec<SurfaceMap> {
    measure(stock, initial, design, grids, max_depth).maps
}

/// Residual maps only (every `overcut_mm` entry `None`): [`residual_along`] at every sample
/// of every grid, parallel over samples. The residual values are bit for bit those of
/// [`measure`] (the same march); no end point is read and no blank is needed, so this costs
/// only the residual probes: O(residual / h) per sample.
pub fn measure_residual(
    stock: &TriDexel,
    design: &dyn DesignModel,
    grids: &[SurfaceGrid],
    max_depth: f64,
) -> Vec<SurfaceMap> {
    grids
        .iter()
        .map(|g| {
            let residual_mm = at_samples(g, |p, n| residual_along(stock, design, p, n, max_depth));
            SurfaceMap {
                name: g.name.clone(),
                nu: g.nu,
                nv: g.nv,
                points: g.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
                overcut_mm: vec![None; residual_mm.len()],
                residual_mm,
            }
        })
        .collect()
}

/// `f(point, unit normal)` at every sample of `g` (parallel over samples), `None` where the
/// normal is zero or not finite (a skipped sample).
fn at_samples<T: Send>(
    g: &SurfaceGrid,
    f: impl Fn(&Point3, &Vector3) -> T + Sync,
) -> Vec<Option<T>> {
    g.points
        .par_iter()
        .zip(g.normals.par_iter())
        .map(|(p, n)| {
            let len = n.norm();
            (len > 1e-12 && len.is_finite()).then(|| f(p, &(n / len)))
        })
        .collect()
}

/// Overcut/residual maps plus the deepest cut end point.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Per-surface maps (probes, with every end point's depth merged into its nearest
    /// sample).
    pub maps: Vec<SurfaceMap>,
    /// The deepest cut end point inside the design, located at the end point itself and
    /// named after its nearest sample.
    pub deepest_endpoint: Option<Extremum>,
    /// Cut end points found inside the design.
    pub endpoints_inside: usize,
}

/// Largest distance (mm) from a cut end point to the design sample it is attributed to in
/// the maps; farther end points still count in the metric and the extremum (named after the
/// nearest sample found) but colour no sample.
const ATTRIBUTION_REACH_MM: f64 = 10.0;

/// Hash-cell edge of the sample index (mm).
const SAMPLE_INDEX_CELL_MM: f64 = 1.0;

/// Overcut at the dexel end points ([`crate::endpoints`]) and the normal probes, residual
/// by the probes (see module docs). Cost: one design evaluation per cut end point plus
/// O(depth/h) per sample; parallel.
pub fn measure(
    stock: &TriDexel,
    initial: &TriDexel,
    design: &dyn DesignModel,
    grids: &[SurfaceGrid],
    max_depth: f64,
) -> Measured {
    let mut maps: Vec<SurfaceMap> = grids
        .iter()
        .map(|g| {
            let probes = at_samples(g, |p, n| probe(stock, initial, design, p, n, max_depth));
            SurfaceMap {
                name: g.name.clone(),
                nu: g.nu,
                nv: g.nv,
                points: g.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
                overcut_mm: probes.iter().map(|p| p.map(|p| p.overcut)).collect(),
                residual_mm: probes.iter().map(|p| p.map(|p| p.residual)).collect(),
            }
        })
        .collect();
    let ends = endpoint_depths(stock, initial, design);
    let endpoints_inside = ends.len();
    let pooled = pool_deepest(&ends);
    let mut deepest_endpoint = None;
    if !pooled.is_empty() {
        let index = SampleIndex::new(grids, SAMPLE_INDEX_CELL_MM, ATTRIBUTION_REACH_MM);
        let near: Vec<Option<(usize, usize)>> = pooled
            .par_iter()
            .map(|e| index.nearest(grids, &e.point))
            .collect();
        for (e, at) in pooled.iter().zip(&near) {
            let depth = e.depth_mm.min(max_depth);
            if let Some((gi, k)) = *at {
                let slot = &mut maps[gi].overcut_mm[k];
                *slot = Some(slot.unwrap_or(0.0).max(depth));
            }
        }
        // `pooled` is sorted deepest first.
        let e = &pooled[0];
        let (surface, i, j) = match near[0] {
            Some((gi, k)) => {
                let nu = grids[gi].nu.max(1);
                (grids[gi].name.clone(), k % nu, k / nu)
            }
            None => (String::new(), 0, 0),
        };
        deepest_endpoint = Some(Extremum {
            value_mm: e.depth_mm.min(max_depth),
            surface,
            i,
            j,
            point: e.point,
            capped: e.depth_mm >= max_depth,
        });
    }
    Measured {
        maps,
        deepest_endpoint,
        endpoints_inside,
    }
}

/// Largest overcut (`residual = false`) or residual over the maps.
pub fn extremum(maps: &[SurfaceMap], residual: bool, max_depth: f64) -> Option<Extremum> {
    let mut best: Option<Extremum> = None;
    for m in maps {
        let vals = if residual {
            &m.residual_mm
        } else {
            &m.overcut_mm
        };
        for (k, v) in vals.iter().enumerate() {
            let Some(v) = *v else { continue };
            if best.as_ref().is_none_or(|b| v > b.value_mm) {
                best = Some(Extremum {
                    value_mm: v,
                    surface: m.name.clone(),
                    i: k % m.nu.max(1),
                    j: k / m.nu.max(1),
                    point: m.points[k],
                    capped: v >= max_depth,
                });
            }
        }
    }
    best
}
