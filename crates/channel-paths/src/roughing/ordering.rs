//! The order and direction in which the paths of one lane are cut, and the links between
//! consecutive paths, in the developed plane of [`super::plan2d`].
//!
//! Triangle paths end at their crossings, staggered along the flow near the inlet; cut left
//! to right in zig-zag, every other turn runs along the flow from one crossing to the next
//! (about one extra path length per lane), while the nearest crossing end usually lies on
//! the other side of the lane. So the order is chosen, not fixed: a path `i` cut forward or
//! backward is a node `(i, r)`, the link from `(i, r)` to `(j, r')` costs the planar length of
//! the straight segment from the exit of the one to the entry of the other when that segment
//! stays inside the lane, and [`BREAK_MM`] more when it does not (the caller then retracts
//! over the safety surface). The order minimises the sum of link costs over the lane — an
//! open travelling-salesman path over path ends — by nearest-neighbour tours from every
//! start, improved by 2-opt (reversing a stretch of the order reverses and flips its paths;
//! the costs are symmetric, so only the two outer links change) and by moving single paths
//! (both directions) until no move shortens the links. A heuristic: the result is at most as
//! long as the best nearest-neighbour tour, and on the isoparametric baseline (parallel paths
//! of one length) it is the zig-zag.
//!
//! With [`Linking::OneWay`] every path is cut inlet → outlet and the link returns along the
//! path just cut (lifted by the caller) to its inlet end before it crosses to the next
//! start: the cost of `i → j` is then the crossing from `i`'s start to `j`'s start.
//!
//! Cost: O(n²·g) for the link costs of n paths (g grid points a segment spans), O(n³) for
//! the tours and O(n²) per improvement pass.

use super::plan2d::{Path2, Region};

/// How consecutive paths are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Linking {
    /// Each path cut in whichever direction keeps the links short; the order and the
    /// directions are chosen together (module docs). Neighbouring paths at the outlet are cut
    /// in alternate directions, as in a zig-zag.
    ZigZag,
    /// Every path cut from the inlet toward the outlet.
    OneWay,
}

/// One path of an ordered lane: its index in the planned list and whether it is cut from its
/// last point to its first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    /// Index in the planned list.
    pub index: usize,
    /// Cut backwards.
    pub reversed: bool,
}

/// Cost (mm) added to a link whose straight segment leaves the lane: such a link is a retract
/// over the safety surface and an approach, which is worth far more than any link inside a
/// lane, so the order avoids them first.
pub const BREAK_MM: f64 = 1.0e4;

/// Tolerance (mm) of the test that a link stays inside the lane.
pub const INSIDE_TOL_MM: f64 = 1e-6;

/// Largest number of improvement passes (each strictly shortens the links; the limit only
/// bounds the time on pathological inputs).
const MAX_PASSES: usize = 64;

/// Whether the straight segment `a`–`b` stays inside `region` (within [`INSIDE_TOL_MM`]) and
/// within its `s` range. Exact for the region's piecewise-linear boundaries: it is checked at
/// both ends and at every grid `s` between them. O(grid points spanned).
pub fn segment_inside(region: &Region, a: [f64; 2], b: [f64; 2]) -> bool {
    let (Some(&s0), Some(&s1)) = (region.s.first(), region.s.last()) else {
        return false;
    };
    let inside = |q: [f64; 2]| {
        if q[0] < s0 - INSIDE_TOL_MM || q[0] > s1 + INSIDE_TOL_MM {
            return false;
        }
        let (l, r) = region.bounds(q[0]);
        q[1] >= l - INSIDE_TOL_MM && q[1] <= r + INSIDE_TOL_MM
    };
    if !(inside(a) && inside(b)) {
        return false;
    }
    let (lo, hi) = if a[0] <= b[0] { (a, b) } else { (b, a) };
    let ds = hi[0] - lo[0];
    if ds <= 0.0 {
        return true;
    }
    let first = region.s.partition_point(|&s| s <= lo[0]);
    region.s[first..]
        .iter()
        .take_while(|&&s| s < hi[0])
        .all(|&s| {
            let t = (s - lo[0]) / ds;
            inside([s, lo[1] + t * (hi[1] - lo[1])])
        })
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The link costs of one lane: node `2i + r` is path `i` cut forward (`r = 0`) or backward.
struct Costs {
    n: usize,
    /// `c[u·2n + v]`: from node `u`'s exit to node `v`'s entry.
    c: Vec<f64>,
    /// From the entry anchor to node `v`'s entry, and from node `u`'s exit to the exit
    /// anchor (0 without anchor).
    enter: Vec<f64>,
    leave: Vec<f64>,
}

impl Costs {
    fn new(paths: &[Path2], region: &Region, linking: Linking, anchors: Anchors) -> Self {
        let n = paths.len();
        let ends: Vec<([f64; 2], [f64; 2])> = paths
            .iter()
            .map(|p| {
                let first = p.first().copied().unwrap_or([0.0; 2]);
                (first, p.last().copied().unwrap_or(first))
            })
            .collect();
        // Entry and exit of node u.
        let entry = |u: usize| {
            let (f, l) = ends[u / 2];
            if u.is_multiple_of(2) {
                f
            } else {
                l
            }
        };
        let exit = |u: usize| {
            let (f, l) = ends[u / 2];
            match linking {
                // One way: the link returns along the path to its start first.
                Linking::OneWay => f,
                Linking::ZigZag if u.is_multiple_of(2) => l,
                Linking::ZigZag => f,
            }
        };
        let m = 2 * n;
        let mut c = vec![0.0; m * m];
        for u in 0..m {
            for v in 0..m {
                if u / 2 == v / 2 {
                    continue;
                }
                let (a, b) = (exit(u), entry(v));
                let mut cost = dist(a, b);
                if !segment_inside(region, a, b) {
                    cost += BREAK_MM;
                }
                c[u * m + v] = cost;
            }
        }
        let enter = (0..m)
            .map(|v| anchors.entry.map_or(0.0, |a| dist(a, entry(v))))
            .collect();
        let leave = (0..m)
            .map(|u| anchors.exit.map_or(0.0, |a| dist(exit(u), a)))
            .collect();
        Self { n, c, enter, leave }
    }

    fn at(&self, u: usize, v: usize) -> f64 {
        self.c[u * 2 * self.n + v]
    }

    /// Links plus the anchor terms of a whole tour.
    fn total(&self, tour: &[usize]) -> f64 {
        let ends = match (tour.first(), tour.last()) {
            (Some(&f), Some(&l)) => self.enter[f] + self.leave[l],
            _ => 0.0,
        };
        ends + tour.windows(2).map(|w| self.at(w[0], w[1])).sum::<f64>()
    }

    /// The cost of the link into position `k` of `tour` from the one before (the entry
    /// anchor's for the first), with node `v` there.
    fn into(&self, tour: &[usize], k: usize, v: usize) -> f64 {
        if k == 0 {
            self.enter[v]
        } else {
            self.at(tour[k - 1], v)
        }
    }

    /// The cost of the link out of position `k` of `tour` to the one after (the exit
    /// anchor's for the last), with node `u` there.
    fn out_of(&self, tour: &[usize], k: usize, u: usize) -> f64 {
        if k + 1 == tour.len() {
            self.leave[u]
        } else {
            self.at(u, tour[k + 1])
        }
    }
}

/// The same path cut the other way.
fn flip(u: usize) -> usize {
    u ^ 1
}

/// Where the cutting of a lane should begin and end: the order adds the distance from the
/// entry anchor to the first path's start and from the last path's end to the exit anchor
/// to its links (so that the lane's ends lie near the neighbouring lanes it is joined to).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Anchors {
    /// Near here the first path starts.
    pub entry: Option<[f64; 2]>,
    /// Near here the last path ends.
    pub exit: Option<[f64; 2]>,
}

/// The order and directions of `paths` (each planned inlet → outlet) in `region` that keep
/// the links short (module docs). With [`Linking::OneWay`] no path is reversed. Deterministic.
pub fn order(paths: &[Path2], region: &Region, linking: Linking) -> Vec<Step> {
    order_between(paths, region, linking, Anchors::default())
}

/// [`order`] with the lane's ends drawn toward `anchors`.
pub fn order_between(
    paths: &[Path2],
    region: &Region,
    linking: Linking,
    anchors: Anchors,
) -> Vec<Step> {
    let n = paths.len();
    if n == 0 {
        return Vec::new();
    }
    let costs = Costs::new(paths, region, linking, anchors);
    let allowed = |u: usize| linking == Linking::ZigZag || u.is_multiple_of(2);
    // Nearest-neighbour tours from every allowed start; the shortest is kept.
    let mut best: Option<(f64, Vec<usize>)> = None;
    for start in (0..2 * n).filter(|&u| allowed(u)) {
        let mut used = vec![false; n];
        let mut tour = Vec::with_capacity(n);
        let mut u = start;
        used[u / 2] = true;
        tour.push(u);
        for _ in 1..n {
            let next = (0..2 * n)
                .filter(|&v| allowed(v) && !used[v / 2])
                .min_by(|&a, &b| costs.at(u, a).total_cmp(&costs.at(u, b)));
            let Some(v) = next else { break };
            used[v / 2] = true;
            tour.push(v);
            u = v;
        }
        let total = costs.total(&tour);
        if best.as_ref().is_none_or(|(t, _)| total < *t - 1e-12) {
            best = Some((total, tour));
        }
    }
    let Some((_, mut tour)) = best else {
        return Vec::new();
    };
    improve(&costs, &mut tour, linking);
    tour.into_iter()
        .map(|u| Step {
            index: u / 2,
            reversed: u % 2 == 1,
        })
        .collect()
}

/// 2-opt and single-path moves until none shortens the links (module docs).
fn improve(costs: &Costs, tour: &mut Vec<usize>, linking: Linking) {
    let n = tour.len();
    let eps = 1e-9;
    let reversing = |u: usize| match linking {
        Linking::ZigZag => flip(u),
        Linking::OneWay => u,
    };
    for _ in 0..MAX_PASSES {
        let mut improved = false;
        // 2-opt: reverse tour[a..=b]; only the links into a and out of b change (the costs
        // inside are symmetric: c(u → v) = c(flip v → flip u) for zig-zag, c(u → v) =
        // c(v → u) for one way).
        for a in 0..n {
            for b in a..n {
                let before = costs.into(tour, a, tour[a]) + costs.out_of(tour, b, tour[b]);
                let after = costs.into(tour, a, reversing(tour[b]))
                    + costs.out_of(tour, b, reversing(tour[a]));
                if after < before - eps {
                    tour[a..=b].reverse();
                    for u in &mut tour[a..=b] {
                        *u = reversing(*u);
                    }
                    improved = true;
                }
            }
        }
        // Move one path (either direction) to another place.
        for from in 0..n {
            if n < 2 {
                break;
            }
            let u = tour[from];
            let mut rest: Vec<usize> = tour.clone();
            rest.remove(from);
            let removed_gain = costs.total(tour) - costs.total(&rest);
            let mut best: Option<(f64, usize, usize)> = None;
            for to in 0..=rest.len() {
                for w in [u, reversing(u)] {
                    // The link between the neighbours at `to` (or the anchor term there) is
                    // replaced by the two links through `w`.
                    let prev = (to > 0).then(|| rest[to - 1]);
                    let next = rest.get(to).copied();
                    let add = match prev {
                        Some(p) => costs.at(p, w),
                        None => costs.enter[w],
                    } + match next {
                        Some(x) => costs.at(w, x),
                        None => costs.leave[w],
                    } - match (prev, next) {
                        (Some(p), Some(x)) => costs.at(p, x),
                        (None, Some(x)) => costs.enter[x],
                        (Some(p), None) => costs.leave[p],
                        (None, None) => 0.0,
                    };
                    if best.is_none_or(|(b, _, _)| add < b) {
                        best = Some((add, to, w));
                    }
                }
            }
            if let Some((add, to, w)) = best {
                if add < removed_gain - eps {
                    rest.insert(to, w);
                    *tour = rest;
                    improved = true;
                }
            }
        }
        if !improved {
            break;
        }
    }
}

/// The planned paths in the order of `steps`, each oriented as it is cut.
pub fn oriented(paths: &[Path2], steps: &[Step]) -> Vec<Path2> {
    steps
        .iter()
        .filter_map(|s| {
            let mut p = paths.get(s.index)?.clone();
            if s.reversed {
                p.reverse();
            }
            Some(p)
        })
        .collect()
}

/// The link from the end of the oriented path `from` to the start of `to`, with points at most
/// `spacing` apart (so that, put on the level, it follows the level): zig-zag the straight
/// segment, one way back along `from` and then straight to `to`'s start. `None` when the
/// straight part leaves `region` (the caller retracts instead). Ends included.
pub fn link(
    from: &Path2,
    to: &Path2,
    region: &Region,
    linking: Linking,
    spacing: f64,
) -> Option<Path2> {
    let (&a_end, &a_start, &b) = (from.last()?, from.first()?, to.first()?);
    let mut out: Path2 = match linking {
        Linking::ZigZag => vec![a_end],
        Linking::OneWay => from.iter().rev().copied().collect(),
    };
    let a = match linking {
        Linking::ZigZag => a_end,
        Linking::OneWay => a_start,
    };
    if !segment_inside(region, a, b) {
        return None;
    }
    let k = ((dist(a, b) / spacing.max(1e-6)).ceil() as usize).max(1);
    out.extend((1..=k).map(|i| {
        let t = i as f64 / k as f64;
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    }));
    Some(out)
}

/// Planar length of a polyline (mm).
pub fn polyline_length(p: &Path2) -> f64 {
    p.windows(2).map(|w| dist(w[0], w[1])).sum()
}

#[cfg(test)]
mod tests {
    use super::super::plan2d::isoparametric;
    use super::super::plan2d::tests::channel;
    use super::super::triangle::triangle;
    use super::*;

    fn links_of(paths: &[Path2], region: &Region, linking: Linking) -> (f64, usize) {
        let o = oriented(paths, &order(paths, region, linking));
        let mut len = 0.0;
        let mut breaks = 0;
        for w in o.windows(2) {
            match link(&w[0], &w[1], region, linking, 0.5) {
                Some(l) => len += polyline_length(&l),
                None => breaks += 1,
            }
        }
        (len, breaks)
    }

    /// The left-to-right zig-zag of the triangle paths, as the planner linked them before
    /// (every other path reversed, straight links): the reference the order must beat.
    fn zig_zag_left_to_right(paths: &[Path2]) -> f64 {
        let mut o = paths.to_vec();
        for (i, p) in o.iter_mut().enumerate() {
            if i % 2 == 1 {
                p.reverse();
            }
        }
        o.windows(2)
            .map(|w| dist(*w[0].last().unwrap(), w[1][0]))
            .sum()
    }

    /// Every path is cut exactly once, and on the triangle paths of the test channel (3 mm
    /// at the inlet to 20 mm at the outlet) the chosen order's links stay inside the lane and
    /// are at most 60 % of the left-to-right zig-zag's (measured 0.29 mm of links per mm of
    /// the zig-zag's when written).
    #[test]
    fn triangle_links_shorter_than_the_left_to_right_zig_zag() {
        let r = channel();
        let tri = triangle(&r, 1.2).unwrap();
        let steps = order(&tri, &r, Linking::ZigZag);
        let mut seen: Vec<usize> = steps.iter().map(|s| s.index).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..tri.len()).collect::<Vec<_>>());
        let (len, breaks) = links_of(&tri, &r, Linking::ZigZag);
        assert_eq!(breaks, 0);
        let before = zig_zag_left_to_right(&tri);
        assert!(len <= 0.6 * before, "{len} vs zig-zag {before}");
    }

    /// On the isoparametric baseline (parallel paths over the whole lane) the order is a
    /// zig-zag: `N − 1` links, each across the lane at one end, of the interval or less.
    #[test]
    fn baseline_order_is_a_zig_zag() {
        let r = channel();
        let step = 1.2;
        let iso = isoparametric(&r, step).unwrap();
        let o = oriented(&iso, &order(&iso, &r, Linking::ZigZag));
        for w in o.windows(2) {
            let (a, b) = (*w[0].last().unwrap(), w[1][0]);
            assert!(
                (a[0] - b[0]).abs() < 1e-9,
                "link along the flow {a:?} → {b:?}"
            );
            assert!(dist(a, b) <= step + 1e-9, "{a:?} → {b:?}");
        }
    }

    /// One way: no path is reversed, and each link returns along the path just cut.
    #[test]
    fn one_way_keeps_directions() {
        let r = channel();
        let tri = triangle(&r, 1.2).unwrap();
        let steps = order(&tri, &r, Linking::OneWay);
        assert!(steps.iter().all(|s| !s.reversed));
        let o = oriented(&tri, &steps);
        let l = link(&o[0], &o[1], &r, Linking::OneWay, 0.5).unwrap();
        assert_eq!(l[0], *o[0].last().unwrap());
        assert_eq!(*l.last().unwrap(), o[1][0]);
        assert!(polyline_length(&l) >= polyline_length(&o[0]));
    }

    /// A link across a bend of the lane leaves it: the straight segment is tested exactly
    /// against the piecewise-linear boundaries, and such a link is a break.
    #[test]
    fn links_leaving_the_lane_are_breaks() {
        // An L-shaped lane: y ∈ [0, 1] up to s = 10, then rising to y ∈ [9, 10] at s = 11.
        let r = Region {
            s: vec![0.0, 10.0, 11.0, 20.0],
            left: vec![0.0, 0.0, 9.0, 9.0],
            right: vec![1.0, 1.0, 10.0, 10.0],
        };
        assert!(segment_inside(&r, [0.5, 0.5], [9.5, 0.5]));
        assert!(!segment_inside(&r, [5.0, 0.5], [15.0, 9.5]));
        assert!(!segment_inside(&r, [5.0, 0.5], [25.0, 9.5]));
        let a: Path2 = vec![[0.0, 0.5], [5.0, 0.5]];
        let b: Path2 = vec![[15.0, 9.5], [20.0, 9.5]];
        assert!(link(&a, &b, &r, Linking::ZigZag, 1.0).is_none());
    }
}
