//! Where a placed cutting solid can reach along the rays of one dexel grid: for a rectangle
//! of rays (a ray, a chunk of a row, a tile), an interval along the ray direction that
//! contains every point of the solid on those rays, piece by piece of the solid's profile.
//!
//! Write a point of a placed solid of revolution as `x = t + h·a + w` (tip `t`, unit axis
//! `a`, height `h` in a piece's slab `[h₀, h₁]`, `w ⊥ a`, `|w| ≤ r(h)`). Along a coordinate
//! axis `e_k`, `|w_k| = |w·(e_k − a_k·a)| ≤ r(h)·s_k` with `s_k = √(1 − a_k²)`. A ray of the
//! grid along `d` at `(u, v)` in the rectangle `[u_a, u_b] × [v_a, v_b]` can therefore meet
//! the piece only at heights where
//!
//! * `t_v + h·a_v ∈ [v_a − r(h)·s_v, v_b + r(h)·s_v]` and the same along `u`,
//!
//! and there its coordinate along the ray lies within `r(h)·s_d` of `t_d + h·a_d`.
//!
//! * **Frustum** (`r(h) = r₀ + k·(h − h₀)`, linear): the four conditions are linear in `h`, so
//!   the heights form an interval found in closed form, and the extent along the ray is
//!   spanned by its two ends (`t_d + h·a_d ± r(h)·s_d` is linear in `h`).
//! * **Sphere** (centre `c`, radius `R`; the piece is a slab of it): the whole ball's chord,
//!   `c_d ± √(R² − dist(c_v, [v_a, v_b])² − dist(c_u, [u_a, u_b])²)`.
//! * **Torus** (bull-nose corner): the cylinder of radius `major + minor` over its slab, as
//!   a frustum.
//!
//! The solid's reach is the hull of its pieces' extents. Against the band test of
//! [`crate::removal`] (one radius, the largest, over the whole part) this follows the
//! profile: a tapered ball end of radius 1 mm whose flutes widen to 2 mm reaches only 1 mm
//! around its axis near the tip. Every bound is widened by [`crate::removal::CULL_SLACK_MM`]
//! against rounding. Cost: O(pieces) per rectangle, a few divisions per frustum.

use crate::removal::CULL_SLACK_MM;
use crate::tool_solid::{Piece, RevolvedSolid};

/// Most pieces kept apart; a solid with more is bounded by one cylinder.
const MAX_PIECES: usize = 3;

/// One piece of a placed solid, in the grid's coordinates `(u, v, d)`.
#[derive(Debug, Clone, Copy)]
enum PieceReach {
    /// The whole ball of centre `c`, squared radius `r2` (slack included).
    Ball { c: [f64; 3], r2: f64 },
    /// Radius `c0 + k·h` over heights `[h0, h1]` (slack included), tip `t`, axis `a`,
    /// `s_k = √(1 − a_k²)`.
    Cone {
        t: [f64; 3],
        a: [f64; 3],
        s: [f64; 3],
        h0: f64,
        h1: f64,
        c0: f64,
        k: f64,
    },
}

/// The reach of a placed solid along one grid's rays (see the module docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reach {
    pieces: [PieceReach; MAX_PIECES],
    n: usize,
}

/// Heights of `[lo, hi]` where `α + β·h ≤ 0`; empty when `lo > hi`.
#[inline]
fn clip_linear(alpha: f64, beta: f64, (lo, hi): (f64, f64)) -> (f64, f64) {
    if beta > 1e-12 {
        (lo, hi.min(-alpha / beta))
    } else if beta < -1e-12 {
        (lo.max(-alpha / beta), hi)
    } else if alpha <= 0.0 {
        (lo, hi)
    } else {
        (1.0, 0.0)
    }
}

/// Distance from `x` to the interval `[a, b]` (0 inside).
#[inline]
fn outside(x: f64, (a, b): (f64, f64)) -> f64 {
    (a - x).max(x - b).max(0.0)
}

impl Reach {
    /// The reach of `solid` placed at `tip` with unit `axis`, for the grid of rays along
    /// coordinate `d`.
    pub(crate) fn new(solid: &RevolvedSolid, tip: &[f64; 3], axis: &[f64; 3], d: usize) -> Self {
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        let t = [tip[ua], tip[va], tip[d]];
        let a = [axis[ua], axis[va], axis[d]];
        let s = a.map(|x| (1.0 - x * x).max(0.0).sqrt());
        let cone = |h0: f64, h1: f64, r0: f64, r1: f64| {
            let k = if h1 > h0 { (r1 - r0) / (h1 - h0) } else { 0.0 };
            PieceReach::Cone {
                t,
                a,
                s,
                h0: h0 - CULL_SLACK_MM,
                h1: h1 + CULL_SLACK_MM,
                c0: r0 - k * h0 + CULL_SLACK_MM * (1.0 + k * k).sqrt() + CULL_SLACK_MM,
                k,
            }
        };
        let pieces = solid.pieces();
        let mut out = [PieceReach::Ball {
            c: [0.0; 3],
            r2: -1.0,
        }; MAX_PIECES];
        if pieces.len() > MAX_PIECES {
            out[0] = cone(solid.h_min(), solid.h_max(), solid.r_max(), solid.r_max());
            return Self { pieces: out, n: 1 };
        }
        for (o, p) in out.iter_mut().zip(pieces) {
            *o = match *p {
                Piece::Frustum { h0, h1, r0, r1 } => cone(h0, h1, r0, r1),
                Piece::Sphere { hc, radius, .. } => {
                    let r = radius + CULL_SLACK_MM;
                    PieceReach::Ball {
                        c: [0, 1, 2].map(|k| t[k] + hc * a[k]),
                        r2: r * r,
                    }
                }
                Piece::Torus {
                    h0,
                    h1,
                    major,
                    minor,
                    ..
                } => cone(h0, h1, major + minor, major + minor),
            };
        }
        Self {
            pieces: out,
            n: pieces.len(),
        }
    }

    /// An interval along the rays containing every point of the solid on the rays with
    /// `u ∈ us`, `v ∈ vs`; `None` when the solid provably meets none of them.
    #[inline]
    pub(crate) fn extent(&self, us: (f64, f64), vs: (f64, f64)) -> Option<(f64, f64)> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for p in &self.pieces[..self.n] {
            match *p {
                PieceReach::Ball { c, r2 } => {
                    let (du, dv) = (outside(c[0], us), outside(c[1], vs));
                    let q = r2 - du * du - dv * dv;
                    if q >= 0.0 {
                        let w = q.sqrt() + CULL_SLACK_MM;
                        lo = lo.min(c[2] - w);
                        hi = hi.max(c[2] + w);
                    }
                }
                PieceReach::Cone {
                    t,
                    a,
                    s,
                    h0,
                    h1,
                    c0,
                    k,
                } => {
                    // t_k + h·a_k ≥ lo_k − (c0 + k·h)·s_k and ≤ hi_k + (c0 + k·h)·s_k for k = u, v.
                    let mut hs = (h0, h1);
                    for (j, (x0, x1)) in [(0, us), (1, vs)] {
                        hs = clip_linear(x0 - t[j] - c0 * s[j], -a[j] - k * s[j], hs);
                        hs = clip_linear(t[j] - x1 - c0 * s[j], a[j] - k * s[j], hs);
                    }
                    if hs.0 <= hs.1 {
                        for h in [hs.0, hs.1] {
                            let (x, w) = (t[2] + h * a[2], (c0 + k * h).max(0.0) * s[2]);
                            lo = lo.min(x - w - CULL_SLACK_MM);
                            hi = hi.max(x + w + CULL_SLACK_MM);
                        }
                    }
                }
            }
        }
        (lo <= hi).then_some((lo, hi))
    }
}

/// One piece of a [`Reach`] restricted to one row of rays (coordinate `v`): what stays
/// of the piece's conditions once `v` is fixed, so that each ray of the row costs a few
/// multiplications.
#[derive(Debug, Clone, Copy)]
enum RowPiece {
    /// Ball: centre `cu`, `cd`; `q0 = R² − (v − c_v)²`.
    Ball { cu: f64, cd: f64, q0: f64 },
    /// Frustum: heights `hs` allowed by the row, and the `u` and `d` terms of
    /// [`PieceReach::Cone`] with the reciprocals of the `u` conditions' slopes.
    Cone {
        hs: (f64, f64),
        tu: f64,
        au: f64,
        td: f64,
        ad: f64,
        c0: f64,
        k: f64,
        su: f64,
        sd: f64,
    },
}

/// The reach of a placed solid along the rays of one row (see [`Reach::row`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RowReach {
    pieces: [RowPiece; MAX_PIECES],
    n: usize,
    /// The interval of `u` holding every ray of the row the solid can meet.
    pub(crate) span: (f64, f64),
}

impl Reach {
    /// The reach restricted to the row of rays at coordinate `v`; `None` when the solid
    /// meets no ray of the row. Same bounds as [`Reach::extent`] with `vs = (v, v)`.
    #[inline]
    pub(crate) fn row(&self, v: f64) -> Option<RowReach> {
        let mut pieces = [RowPiece::Ball {
            cu: 0.0,
            cd: 0.0,
            q0: -1.0,
        }; MAX_PIECES];
        let mut n = 0;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &self.pieces[..self.n] {
            match *p {
                PieceReach::Ball { c, r2 } => {
                    let dv = v - c[1];
                    let q0 = r2 - dv * dv;
                    if q0 >= 0.0 {
                        let w = q0.sqrt() + CULL_SLACK_MM;
                        lo = lo.min(c[0] - w);
                        hi = hi.max(c[0] + w);
                        pieces[n] = RowPiece::Ball {
                            cu: c[0],
                            cd: c[2],
                            q0,
                        };
                        n += 1;
                    }
                }
                PieceReach::Cone {
                    t,
                    a,
                    s,
                    h0,
                    h1,
                    c0,
                    k,
                } => {
                    let mut hs = (h0, h1);
                    hs = clip_linear(v - t[1] - c0 * s[1], -a[1] - k * s[1], hs);
                    hs = clip_linear(t[1] - v - c0 * s[1], a[1] - k * s[1], hs);
                    if hs.0 <= hs.1 {
                        for h in [hs.0, hs.1] {
                            let (x, w) = (t[0] + h * a[0], (c0 + k * h).max(0.0) * s[0]);
                            lo = lo.min(x - w - CULL_SLACK_MM);
                            hi = hi.max(x + w + CULL_SLACK_MM);
                        }
                        pieces[n] = RowPiece::Cone {
                            hs,
                            tu: t[0],
                            au: a[0],
                            td: t[2],
                            ad: a[2],
                            c0,
                            k,
                            su: s[0],
                            sd: s[2],
                        };
                        n += 1;
                    }
                }
            }
        }
        (n > 0 && lo <= hi).then_some(RowReach {
            pieces,
            n,
            span: (lo, hi),
        })
    }
}

impl RowReach {
    /// An interval along the rays containing every point of the solid on the rays of the
    /// row with `u ∈ us`; `None` when it meets none of them.
    #[inline]
    pub(crate) fn extent(&self, us: (f64, f64)) -> Option<(f64, f64)> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for p in &self.pieces[..self.n] {
            match *p {
                RowPiece::Ball { cu, cd, q0 } => {
                    let du = outside(cu, us);
                    let q = q0 - du * du;
                    if q >= 0.0 {
                        let w = q.sqrt() + CULL_SLACK_MM;
                        lo = lo.min(cd - w);
                        hi = hi.max(cd + w);
                    }
                }
                RowPiece::Cone {
                    hs,
                    tu,
                    au,
                    td,
                    ad,
                    c0,
                    k,
                    su,
                    sd,
                } => {
                    let mut hs = hs;
                    hs = clip_linear(us.0 - tu - c0 * su, -au - k * su, hs);
                    hs = clip_linear(tu - us.1 - c0 * su, au - k * su, hs);
                    if hs.0 <= hs.1 {
                        for h in [hs.0, hs.1] {
                            let (x, w) = (td + h * ad, (c0 + k * h).max(0.0) * sd);
                            lo = lo.min(x - w - CULL_SLACK_MM);
                            hi = hi.max(x + w + CULL_SLACK_MM);
                        }
                    }
                }
            }
        }
        (lo <= hi).then_some((lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tool_solid::RayLocal;
    use cam_core::{Cutter, CutterShape};
    use rand::{Rng, SeedableRng};

    fn cutters() -> Vec<Cutter> {
        let mk = |s| Cutter::new("t", s, 12.0, 3.0, 30.0).unwrap();
        vec![
            mk(CutterShape::FlatEnd { radius: 2.0 }),
            mk(CutterShape::BallEnd { radius: 2.0 }),
            mk(CutterShape::BullNose {
                radius: 2.0,
                corner_radius: 0.5,
            }),
            mk(CutterShape::TaperedBallEnd {
                ball_radius: 1.0,
                half_angle: 0.05,
            }),
            mk(CutterShape::TaperedFlatEnd {
                tip_radius: 0.5,
                half_angle: 0.2,
            }),
        ]
    }

    /// Every ray interval of the solid lies inside the reach of the ray, of every
    /// rectangle holding the ray, and inside the row span of its row.
    #[test]
    fn reach_contains_every_ray_interval() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(38);
        for c in cutters() {
            let solid = RevolvedSolid::cutting_part(&c);
            for _ in 0..300 {
                let tip = [0.0; 3].map(|_| rng.random_range(-2.0..2.0));
                let mut axis = [0.0; 3].map(|_| rng.random_range(-1.0..1.0f64));
                if rng.random_bool(0.2) {
                    axis = [0.0, 0.0, 1.0];
                }
                let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
                if n < 0.1 {
                    continue;
                }
                let axis = axis.map(|x| x / n);
                for d in 0..3 {
                    let reach = Reach::new(&solid, &tip, &axis, d);
                    let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
                    for _ in 0..40 {
                        let (u, v) = (rng.random_range(-16.0..16.0), rng.random_range(-16.0..16.0));
                        let rl = RayLocal::new(d, u - tip[ua], v - tip[va], &axis);
                        let Some((s, e)) = solid.ray_hull(&rl) else {
                            continue;
                        };
                        let (s, e) = (s + tip[d], e + tip[d]);
                        let (du, dv) = (rng.random_range(0.0..3.0), rng.random_range(0.0..3.0));
                        for (us, vs) in [
                            ((u, u), (v, v)),
                            ((u - du, u + 0.5 * du), (v - 0.3 * dv, v + dv)),
                        ] {
                            let (lo, hi) = reach.extent(us, vs).expect("a ray meets the solid");
                            assert!(
                                lo <= s && e <= hi,
                                "{:?} d {d}: [{s}, {e}] outside [{lo}, {hi}]",
                                c.shape
                            );
                        }
                        let row = reach.row(v).expect("the row meets the solid");
                        let (a, b) = row.span;
                        assert!(
                            a <= u && u <= b,
                            "{:?} d {d}: u {u} outside [{a}, {b}]",
                            c.shape
                        );
                        let (lo, hi) = row.extent((u, u)).expect("the ray meets the solid");
                        assert!(
                            lo <= s && e <= hi,
                            "{:?} d {d}: row reach [{lo}, {hi}] misses [{s}, {e}]",
                            c.shape
                        );
                    }
                }
            }
        }
    }

    /// Near the tip of a tapered ball end the reach follows the ball, not the flutes' top
    /// radius.
    #[test]
    fn reach_follows_the_profile() {
        let c = Cutter::new(
            "t",
            CutterShape::TaperedBallEnd {
                ball_radius: 1.0,
                half_angle: 3f64.to_radians(),
            },
            20.0,
            3.0,
            40.0,
        )
        .unwrap();
        let solid = RevolvedSolid::cutting_part(&c);
        assert!(solid.r_max() > 1.9);
        // Vertical tool at the origin; rays along X (d = 0) at height z = v = 0.5.
        let reach = Reach::new(&solid, &[0.0; 3], &[0.0, 0.0, 1.0], 0);
        let (a, b) = reach.row(0.5).unwrap().span;
        let r = (1.0f64 - 0.25).sqrt();
        assert!((a + r).abs() < 1e-3 && (b - r).abs() < 1e-3, "[{a}, {b}]");
    }
}
