//! Certified seeding: subdivision of both surfaces with control-point boxes, Newton from the
//! surviving leaf pairs (module docs, step 1–2).

use nalgebra::Vector3;

use super::march::{refine, Constraint, Pt};
use super::{IntersectError, ParamBox, SsiOptions, MAX_LEAF_PAIRS};
use crate::{Direction, NurbsError, NurbsSurface};

/// Deepest subdivision level (per surface); 2^-24 of a parameter range is far below any
/// useful seed size, so this only stops degenerate inputs.
const MAX_DEPTH: usize = 24;

/// Samples per side of a leaf cell when choosing the Newton start pair (the closest pair of
/// samples of the two cells).
const LEAF_SAMPLES: usize = 3;

/// A sub-surface with its parameter box and control-point bounding box.
#[derive(Debug, Clone)]
struct Cell {
    surf: NurbsSurface,
    pbox: ParamBox,
    lo: Vector3<f64>,
    hi: Vector3<f64>,
    depth: usize,
}

impl Cell {
    fn new(surf: NurbsSurface, pbox: ParamBox, depth: usize) -> Self {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in surf.control_points() {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        Self {
            surf,
            pbox,
            lo,
            hi,
            depth,
        }
    }

    fn size(&self) -> f64 {
        (self.hi - self.lo).norm()
    }

    fn overlaps(&self, o: &Cell, slack: f64) -> bool {
        (0..3).all(|k| self.lo[k] <= o.hi[k] + slack && o.lo[k] <= self.hi[k] + slack)
    }

    /// Splits across the parameter side that is longer in space (control-net extent).
    fn split(&self) -> Result<(Cell, Cell), NurbsError> {
        let n_u = self.surf.n_u();
        let n_v = self.surf.n_v();
        let cp = |i: usize, j: usize| self.surf.control_point(i, j);
        // Control-polygon lengths along the first, middle and last lines of each direction
        // (corner-to-corner chords vanish on closed surfaces).
        let len_u = [0, n_v / 2, n_v - 1]
            .iter()
            .map(|&j| {
                (1..n_u)
                    .map(|i| (cp(i, j) - cp(i - 1, j)).norm())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        let len_v = [0, n_u / 2, n_u - 1]
            .iter()
            .map(|&i| {
                (1..n_v)
                    .map(|j| (cp(i, j) - cp(i, j - 1)).norm())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        let (dir, mid) = if len_u >= len_v {
            (Direction::U, 0.5 * (self.pbox.u.0 + self.pbox.u.1))
        } else {
            (Direction::V, 0.5 * (self.pbox.v.0 + self.pbox.v.1))
        };
        let (l, r) = self.surf.split(dir, mid)?;
        let (bl, br) = match dir {
            Direction::U => (
                ParamBox {
                    u: (self.pbox.u.0, mid),
                    v: self.pbox.v,
                },
                ParamBox {
                    u: (mid, self.pbox.u.1),
                    v: self.pbox.v,
                },
            ),
            Direction::V => (
                ParamBox {
                    u: self.pbox.u,
                    v: (self.pbox.v.0, mid),
                },
                ParamBox {
                    u: self.pbox.u,
                    v: (mid, self.pbox.v.1),
                },
            ),
        };
        Ok((
            Cell::new(l, bl, self.depth + 1),
            Cell::new(r, br, self.depth + 1),
        ))
    }
}

/// `s` restricted to `b` by knot insertion (splits only strictly inside the domain).
fn restrict(s: &NurbsSurface, b: &ParamBox) -> Result<NurbsSurface, NurbsError> {
    let mut r = s.clone();
    let inside = |t: f64, (a, z): (f64, f64)| t > a + 1e-14 * (z - a) && t < z - 1e-14 * (z - a);
    if inside(b.u.0, r.domain().0) {
        r = r.split(Direction::U, b.u.0)?.1;
    }
    if inside(b.u.1, r.domain().0) {
        r = r.split(Direction::U, b.u.1)?.0;
    }
    if inside(b.v.0, r.domain().1) {
        r = r.split(Direction::V, b.v.0)?.1;
    }
    if inside(b.v.1, r.domain().1) {
        r = r.split(Direction::V, b.v.1)?.0;
    }
    Ok(r)
}

/// Start points of the intersection: one converged Newton point per overlapping leaf pair
/// (duplicates are removed later against the traced branches). O(number of overlapping pairs
/// over all levels) splits and box tests.
pub(crate) fn seeds(
    a: &NurbsSurface,
    box_a: ParamBox,
    b: &NurbsSurface,
    box_b: ParamBox,
    opts: &SsiOptions,
) -> Result<Vec<Pt>, IntersectError> {
    let ca = Cell::new(restrict(a, &box_a)?, box_a, 0);
    let cb = Cell::new(restrict(b, &box_b)?, box_b, 0);
    let slack = opts.point_tol;
    let mut stack = vec![(ca, cb)];
    let mut leaves: Vec<(ParamBox, ParamBox)> = Vec::new();
    while let Some((x, y)) = stack.pop() {
        if !x.overlaps(&y, slack) {
            continue;
        }
        let (sx, sy) = (x.size(), y.size());
        let x_leaf = sx <= opts.seed_size || x.depth >= MAX_DEPTH;
        let y_leaf = sy <= opts.seed_size || y.depth >= MAX_DEPTH;
        if x_leaf && y_leaf {
            leaves.push((x.pbox, y.pbox));
            if leaves.len() > MAX_LEAF_PAIRS {
                return Err(IntersectError::TooManyPairs {
                    limit: MAX_LEAF_PAIRS,
                });
            }
            continue;
        }
        if !x_leaf && (sx >= sy || y_leaf) {
            let (l, r) = x.split()?;
            stack.push((l, y.clone()));
            stack.push((r, y));
        } else {
            let (l, r) = y.split()?;
            stack.push((x.clone(), l));
            stack.push((x, r));
        }
    }
    let mut out = Vec::new();
    for (pa, pb) in leaves {
        let start = closest_samples(a, &pa, b, &pb);
        if let Some(p) = refine(a, b, start, Constraint::None, opts) {
            if box_a.contains(p.x[0], p.x[1]) && box_b.contains(p.x[2], p.x[3]) {
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// The pair of samples (a `LEAF_SAMPLES`² grid in each cell, centres included) that lie
/// closest together: the Newton start of a leaf pair.
fn closest_samples(a: &NurbsSurface, pa: &ParamBox, b: &NurbsSurface, pb: &ParamBox) -> [f64; 4] {
    let grid = |p: &ParamBox| {
        let mut g = [(0.0, 0.0); LEAF_SAMPLES * LEAF_SAMPLES];
        for i in 0..LEAF_SAMPLES {
            for j in 0..LEAF_SAMPLES {
                let fu = (i as f64 + 0.5) / LEAF_SAMPLES as f64;
                let fv = (j as f64 + 0.5) / LEAF_SAMPLES as f64;
                g[i * LEAF_SAMPLES + j] =
                    (p.u.0 + fu * (p.u.1 - p.u.0), p.v.0 + fv * (p.v.1 - p.v.0));
            }
        }
        g
    };
    let ga = grid(pa);
    let gb = grid(pb);
    let qa: Vec<Vector3<f64>> = ga.iter().map(|&(u, v)| a.point(u, v)).collect();
    let qb: Vec<Vector3<f64>> = gb.iter().map(|&(u, v)| b.point(u, v)).collect();
    let (ua, va) = pa.centre();
    let (ub, vb) = pb.centre();
    let mut best = (f64::INFINITY, [ua, va, ub, vb]);
    for (i, p) in qa.iter().enumerate() {
        for (j, q) in qb.iter().enumerate() {
            let d = (p - q).norm_squared();
            if d < best.0 {
                best = (d, [ga[i].0, ga[i].1, gb[j].0, gb[j].1]);
            }
        }
    }
    best.1
}
