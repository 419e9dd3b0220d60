//! Linking moves: retract along the tool axis to a safety surface around the impeller,
//! travel on it, approach along the tool axis.
//!
//! # Geometry
//! The safety surface bounds a capped cylinder about the impeller axis (+Z): radius `R` and
//! top plane `z = Z` (by default the blank's largest radius and top plus a clearance). A
//! retract from a tool tip `p` with axis `a` runs along `a` to the first point where the ray
//! `p + t·a` leaves the capped cylinder (closed form: the smallest `t > 0` where
//! `|xy(p + t a)| = R` or `z = Z`). The travel between an exit point `A` (axis `a`) and an
//! entry point `B` (axis `b`):
//! 1. rises vertically from `A` to the cap with the axis `a` kept: a side exit leaves along an
//!    axis with an outward radial component, and the rise keeps the tip's azimuth, so the whole
//!    tool stays outside the cylinder;
//! 2. turns the axis from `a` to +Z on the cap's rim (the interpolated axes keep `a`'s outward
//!    or upward component, so the tool stays outside the cylinder or above the cap);
//! 3. crosses the cap on the straight chord with the axis +Z (the chord of a disc stays in
//!    the disc; the tool stands above the cap);
//! 4. turns the axis from +Z to `b`, and comes down vertically to `B` — steps 2 and 1 for `B`
//!    in reverse.
//!
//! So every posture of the travel, and every posture interpolated between two of its moves
//! (tip linear, axis linear and normalised), keeps the whole tool outside the capped cylinder:
//! at least the safety clearance from the blank, and so from the design inside it (checked in
//! the tests with the clearance query).
//!
//! Cost: O(1) per retract and per travel.

use crate::{PlanError, Point3, Vector3};
use cam_core::{CutterLocation, Move, MoveKind, ToolPath};
use impeller_model::Stock;

/// Default clearance of the safety surface over the blank (mm).
pub const DEFAULT_SAFETY_CLEARANCE_MM: f64 = 10.0;

/// Two tips closer than this are one position (mm): far below any machine's resolution.
const SAME_POSTURE_MM: f64 = 1e-9;
/// Two unit axes closer than this (chord, ≈ rad) are one orientation.
const SAME_POSTURE_RAD: f64 = 1e-12;

/// The safety surface: a capped cylinder about +Z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SafetySurface {
    /// Cylinder radius (mm).
    pub radius_mm: f64,
    /// Height of the top plane (mm).
    pub top_z_mm: f64,
}

impl SafetySurface {
    /// The surface `clearance_mm` outside the blank (radius and top).
    pub fn around_stock(stock: &Stock, clearance_mm: f64) -> Result<Self, PlanError> {
        if !(clearance_mm.is_finite() && clearance_mm > 0.0) {
            return Err(PlanError::param(
                "-",
                "safety.clearance_mm",
                format!("{clearance_mm} must be finite and > 0"),
            ));
        }
        Ok(Self {
            radius_mm: stock.max_radius() + clearance_mm,
            top_z_mm: stock.z_range().1 + clearance_mm,
        })
    }

    /// Whether `p` lies strictly inside the capped cylinder.
    pub fn contains(&self, p: &Point3) -> bool {
        p.x.hypot(p.y) < self.radius_mm && p.z < self.top_z_mm
    }

    /// Distance along `a` from `p` to the surface (0 when `p` is already outside).
    pub fn exit_distance(&self, p: &Point3, a: &Vector3) -> f64 {
        if !self.contains(p) {
            return 0.0;
        }
        let mut t = f64::INFINITY;
        if a.z > 0.0 {
            t = t.min((self.top_z_mm - p.z) / a.z);
        }
        let (aa, bb) = (a.x * a.x + a.y * a.y, p.x * a.x + p.y * a.y);
        let cc = p.x * p.x + p.y * p.y - self.radius_mm * self.radius_mm;
        if aa > 0.0 {
            let disc = bb * bb - aa * cc;
            if disc >= 0.0 {
                t = t.min((-bb + disc.sqrt()) / aa);
            }
        }
        t
    }
}

/// Builds linking moves over a safety surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Linker {
    /// The safety surface.
    pub surface: SafetySurface,
    /// The blank: approaches are rapid only down to `approach_mm` outside it (see
    /// [`Linker::rapid_approach_end`]).
    blank: Option<std::sync::Arc<Stock>>,
}

/// Step (mm) at which an approach line is probed against the blank.
const BLANK_PROBE_STEP_MM: f64 = 0.25;

impl Linker {
    /// A linker over `surface` (approaches rapid down to `approach_mm` above the entry).
    pub fn new(surface: SafetySurface) -> Self {
        Self {
            surface,
            blank: None,
        }
    }

    /// A linker over `surface` whose approaches stop rapid travel `approach_mm` before the
    /// blank and feed (plunge) the rest of the way: the material an operation meets is not
    /// known to the linker (earlier operations may have left any part of the blank), so only
    /// outside the blank is a rapid known to be safe.
    pub fn with_blank(surface: SafetySurface, blank: &Stock) -> Self {
        Self {
            surface,
            blank: Some(std::sync::Arc::new(blank.clone())),
        }
    }

    /// Distance above `to` along its axis (≤ `inside`, the distance to the safety surface)
    /// where the rapid part of an approach ends: `approach_mm` above `to`, or — with a blank
    /// — the highest point of the axis line from which the tip comes within `approach_mm` of
    /// the blank (probed every 0.25 mm, the tip and four lateral and one lower point at
    /// `approach_mm`), whichever is higher. O(inside / 0.25) blank tests.
    pub fn rapid_approach_end(&self, to: &CutterLocation, inside: f64, approach_mm: f64) -> f64 {
        let a = approach_mm.clamp(0.0, inside);
        let Some(blank) = &self.blank else {
            return a;
        };
        let axis = to.axis.into_inner();
        let m = approach_mm.max(0.0);
        let probes = [
            Vector3::zeros(),
            Vector3::new(m, 0.0, 0.0),
            Vector3::new(-m, 0.0, 0.0),
            Vector3::new(0.0, m, 0.0),
            Vector3::new(0.0, -m, 0.0),
            Vector3::new(0.0, 0.0, -m),
        ];
        let near = |t: f64| {
            let p = to.tip.coords + axis * t;
            probes.iter().any(|d| blank.contains(&(p + d)))
        };
        let n = (inside / BLANK_PROBE_STEP_MM).ceil() as usize;
        for i in 0..=n {
            let t = (inside - i as f64 * BLANK_PROBE_STEP_MM).max(0.0);
            if t <= a {
                break;
            }
            if near(t) {
                return (t + BLANK_PROBE_STEP_MM).min(inside);
            }
        }
        a
    }

    /// The point where a retract from `cl` along its axis reaches the safety surface, or an
    /// error when the axis points down into the impeller and never leaves (axis with
    /// `a_z ≤ 0` inside the cylinder's radius).
    pub fn retract_point(&self, cl: &CutterLocation) -> Result<CutterLocation, PlanError> {
        let a = cl.axis.into_inner();
        let t = self.surface.exit_distance(&cl.tip, &a);
        if !t.is_finite() {
            return Err(PlanError::geometry(
                "-",
                format!("tip ({:.3}, {:.3}, {:.3})", cl.tip.x, cl.tip.y, cl.tip.z),
                "the tool axis never leaves the safety surface",
            ));
        }
        Ok(CutterLocation {
            tip: cl.tip + a * t,
            axis: cl.axis,
        })
    }

    /// Travel on the safety surface from `from` to `to` (both on or outside it), as rapid
    /// moves excluding `from` and including `to` (see the module docs for why the tool stays
    /// outside the capped cylinder on every move).
    pub fn travel(&self, from: &CutterLocation, to: &CutterLocation) -> Vec<Move> {
        let top = self.surface.top_z_mm;
        let up = |p: &Point3| Point3::new(p.x, p.y, top.max(p.z));
        let z = nalgebra::Unit::new_unchecked(Vector3::z());
        let cl = |tip: Point3, axis: nalgebra::Unit<Vector3>| CutterLocation { tip, axis };
        let postures = [
            cl(up(&from.tip), from.axis),
            cl(up(&from.tip), z),
            cl(up(&to.tip), z),
            cl(up(&to.tip), to.axis),
            *to,
        ];
        let mut moves: Vec<Move> = Vec::with_capacity(postures.len());
        let mut last = *from;
        for p in postures {
            let same = (p.tip - last.tip).norm() < SAME_POSTURE_MM
                && (p.axis.into_inner() - last.axis.into_inner()).norm() < SAME_POSTURE_RAD;
            if !same {
                moves.push(Move::rapid(p));
                last = p;
            }
        }
        // `to` is always the last move, even when it equals `from`'s last posture.
        if moves.last().is_none_or(|m| m.cl != *to) {
            if let Some(m) = moves.last_mut() {
                m.cl = *to;
            }
        }
        moves
    }

    /// The moves from the end of one cutting move at `from` to the start of the next at
    /// `to`: retract along `from`'s axis, travel, approach along `to`'s axis to the point
    /// `approach_mm` above `to` (rapid), then plunge to `to` at the plunge feed.
    pub fn link(
        &self,
        from: &CutterLocation,
        to: &CutterLocation,
        approach_mm: f64,
    ) -> Result<Vec<Move>, PlanError> {
        let out = self.retract_point(from)?;
        let inn = self.retract_point(to)?;
        let mut moves = vec![Move {
            kind: MoveKind::Retract,
            cl: out,
            feed_mm_per_min: None,
        }];
        moves.extend(self.travel(&out, &inn));
        let inside = (inn.tip - to.tip).norm();
        let above = CutterLocation {
            tip: to.tip + to.axis.into_inner() * self.rapid_approach_end(to, inside, approach_mm),
            axis: to.axis,
        };
        moves.push(Move::rapid(above));
        moves.push(Move {
            kind: MoveKind::Plunge,
            cl: *to,
            feed_mm_per_min: None,
        });
        Ok(moves)
    }

    /// Prepends the approach (from the safety surface along the first move's axis: a rapid
    /// to the surface, a rapid to `approach_mm` above the first point, and a plunge replacing
    /// a first cutting move) and appends the retract along the last move's axis, when `path`
    /// has moves and its ends lie inside the surface.
    pub fn close(&self, path: &mut ToolPath, approach_mm: f64) -> Result<(), PlanError> {
        let Some(last) = path.moves.last().copied() else {
            return Ok(());
        };
        if path
            .moves
            .first()
            .is_some_and(|m| self.surface.contains(&m.cl.tip))
        {
            self.close_start(path, approach_mm)?;
        }
        if self.surface.contains(&last.cl.tip) {
            let end = self.retract_point(&last.cl)?;
            path.moves.push(Move {
                kind: MoveKind::Retract,
                cl: end,
                feed_mm_per_min: None,
            });
        }
        Ok(())
    }

    /// The moves from `from` to the start `to` of the next path: retract along `from`'s axis
    /// to the safety surface (when `from` is inside it), [`Linker::travel`] to where `to`'s
    /// axis leaves the surface, then (when `to` is inside) a rapid to `approach_mm` above `to`
    /// along its axis and a plunge to `to`. Ends exactly at `to`.
    pub fn connect(
        &self,
        from: &CutterLocation,
        to: &CutterLocation,
        approach_mm: f64,
    ) -> Result<Vec<Move>, PlanError> {
        let out = self.retract_point(from)?;
        let inn = self.retract_point(to)?;
        let mut moves = Vec::new();
        if (out.tip - from.tip).norm() >= SAME_POSTURE_MM {
            moves.push(Move {
                kind: MoveKind::Retract,
                cl: out,
                feed_mm_per_min: None,
            });
        }
        moves.extend(self.travel(&out, &inn));
        let inside = (inn.tip - to.tip).norm();
        if inside >= SAME_POSTURE_MM {
            let a = self.rapid_approach_end(to, inside, approach_mm);
            if a < inside {
                moves.push(Move::rapid(CutterLocation {
                    tip: to.tip + to.axis.into_inner() * a,
                    axis: to.axis,
                }));
            }
            moves.push(Move {
                kind: MoveKind::Plunge,
                cl: *to,
                feed_mm_per_min: None,
            });
        }
        Ok(moves)
    }

    /// One tool path `name` (tool `tool`) of `paths` in order: each path's moves, linked to
    /// the next with [`Linker::connect`] (which replaces the next path's first move by the
    /// link arriving at it); the whole starts and ends on the safety surface (an approach
    /// along the first axis is prepended and a retract along the last appended when the path
    /// starts or ends inside it). Empty paths are skipped.
    ///
    /// Errors: a path end whose axis never leaves the safety surface.
    pub fn join(
        &self,
        name: &str,
        tool: &str,
        paths: &[ToolPath],
        approach_mm: f64,
    ) -> Result<ToolPath, PlanError> {
        let mut out = ToolPath::new(name, tool);
        for p in paths {
            let Some(first) = p.moves.first() else {
                continue;
            };
            match out.moves.last() {
                Some(last) => {
                    let link = self.connect(&last.cl, &first.cl, approach_mm)?;
                    out.moves.extend(link);
                    out.moves.extend_from_slice(&p.moves[1..]);
                }
                None => {
                    let mut head = p.clone();
                    if self.surface.contains(&first.cl.tip) {
                        self.close_start(&mut head, approach_mm)?;
                    }
                    out.moves = head.moves;
                }
            }
        }
        if let Some(last) = out.moves.last().copied() {
            if self.surface.contains(&last.cl.tip) {
                out.moves.push(Move {
                    kind: MoveKind::Retract,
                    cl: self.retract_point(&last.cl)?,
                    feed_mm_per_min: None,
                });
            }
        }
        Ok(out)
    }

    /// Prepends the approach from the safety surface along the first move's axis.
    fn close_start(&self, path: &mut ToolPath, approach_mm: f64) -> Result<(), PlanError> {
        let Some(first) = path.moves.first().copied() else {
            return Ok(());
        };
        let start = self.retract_point(&first.cl)?;
        let inside = (start.tip - first.cl.tip).norm();
        let mut head = vec![Move::rapid(start)];
        let a = self.rapid_approach_end(&first.cl, inside, approach_mm);
        if a < inside {
            head.push(Move::rapid(CutterLocation {
                tip: first.cl.tip + first.cl.axis.into_inner() * a,
                axis: first.cl.axis,
            }));
        }
        if first.kind == MoveKind::Feed {
            head.push(Move {
                kind: MoveKind::Plunge,
                cl: first.cl,
                feed_mm_per_min: None,
            });
            head.extend_from_slice(&path.moves[1..]);
        } else {
            head.extend_from_slice(&path.moves);
        }
        path.moves = head;
        Ok(())
    }
}
