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

use crate::{DesignClearance, PlanError, Point3, Vector3};
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
    /// `approach_mm`), whichever is higher. O(inside / 0.25) blank tests. This looks at the
    /// tip only; [`Linker::rapid_approach_end_enveloped`] keeps the whole tool away.
    pub fn rapid_approach_end(&self, to: &CutterLocation, inside: f64, approach_mm: f64) -> f64 {
        self.rapid_approach_end_along(to, &to.axis.into_inner(), inside, approach_mm, None)
    }

    /// [`Linker::rapid_approach_end`] for an approach along the unit direction `dir` (the
    /// tool keeps `to`'s axis); with `envelope`, [`Linker::rapid_approach_end_enveloped`].
    pub fn rapid_approach_end_along(
        &self,
        to: &CutterLocation,
        dir: &Vector3,
        inside: f64,
        approach_mm: f64,
        envelope: Option<&ToolEnvelope>,
    ) -> f64 {
        let a = approach_mm.clamp(0.0, inside);
        let Some(blank) = &self.blank else {
            return a;
        };
        if let Some(env) = envelope {
            return rapid_end_enveloped(blank, env, to, dir, inside, approach_mm);
        }
        let axis = *dir;
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

    /// Where the rapid part of an approach to `to` along the unit direction `dir` ends, for
    /// the whole tool (flutes, shank, holder: `envelope`): the rapid runs from `inside`
    /// (the safety surface) down the line as long as every ball of the envelope keeps
    /// `approach_mm` from the blank, and never below `approach_mm` above `to`. Returns the
    /// distance above `to` where it ends (`inside` when the tool is already that near the
    /// blank on the safety surface: no rapid inside it).
    ///
    /// Sphere tracing on `g(t) = min_k (d_blank(c_k(t)) − ρ_k) − approach_mm`: `g` is
    /// 1-Lipschitz in `t` (every ball centre moves at unit speed), so the tool moved by up to
    /// `g(t)` keeps `approach_mm` from the blank; the rapid stops where `g` falls below
    /// [`RAPID_TRACE_STOP_MM`]. So every posture of the rapid keeps at least `approach_mm`
    /// from the blank, and so from the design inside it. Exact up to the envelope's cover
    /// ([`ToolEnvelope`]); O(inside / 0.05) steps at most, each O(balls × profile points).
    pub fn rapid_approach_end_enveloped(
        &self,
        to: &CutterLocation,
        dir: &Vector3,
        inside: f64,
        approach_mm: f64,
        envelope: &ToolEnvelope,
    ) -> f64 {
        self.rapid_approach_end_along(to, dir, inside, approach_mm, Some(envelope))
    }

    /// The point where a retract from `cl` along its axis reaches the safety surface, or an
    /// error when the axis points down into the impeller and never leaves (axis with
    /// `a_z ≤ 0` inside the cylinder's radius).
    pub fn retract_point(&self, cl: &CutterLocation) -> Result<CutterLocation, PlanError> {
        self.leave(cl, &cl.axis.into_inner())
    }

    /// Where a move from `cl` along `dir` reaches the safety surface ([`Linker::exit_point`]);
    /// `cl` itself when it already lies on or outside the surface.
    fn leave(&self, cl: &CutterLocation, dir: &Vector3) -> Result<CutterLocation, PlanError> {
        if !self.surface.contains(&cl.tip) {
            return Ok(*cl);
        }
        self.exit_point(cl, dir).ok_or_else(|| no_exit(cl))
    }

    /// The point where a straight move from `cl` along the unit direction `dir` (the tool
    /// keeping `cl`'s axis) reaches the safety surface, when that move leaves it with the
    /// whole tool outside ([`Linker::leaves_clear`]); `None` otherwise.
    pub fn exit_point(&self, cl: &CutterLocation, dir: &Vector3) -> Option<CutterLocation> {
        let t = self.surface.exit_distance(&cl.tip, dir);
        if !t.is_finite() {
            return None;
        }
        let out = CutterLocation {
            tip: cl.tip + dir * t,
            axis: cl.axis,
        };
        self.leaves_clear(&out).then_some(out)
    }

    /// Whether the tool at `cl`, whose tip lies on the safety surface, stands wholly outside
    /// the capped cylinder: on the cap with an axis that does not point down (`a_z ≥ 0`), or on
    /// the side with an axis that does not point inward (`xy(p)·xy(a) ≥ 0`; then
    /// `|xy(p + t·a)|² = R² + 2t·xy(p)·xy(a) + t²|xy(a)|² ≥ R²` for every `t ≥ 0`). The travel
    /// from such a posture keeps the whole tool outside (module docs).
    pub fn leaves_clear(&self, cl: &CutterLocation) -> bool {
        let a = cl.axis.into_inner();
        let p = cl.tip;
        let eps = 1e-9 * (1.0 + self.surface.top_z_mm.abs() + self.surface.radius_mm);
        let on_cap = p.z >= self.surface.top_z_mm - eps;
        let on_side = p.x.hypot(p.y) >= self.surface.radius_mm - eps;
        (on_cap && a.z >= -1e-12) || (on_side && p.x * a.x + p.y * a.y >= -1e-12)
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
        self.close_with(path, approach_mm, |cl| cl.axis.into_inner(), None)
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
        self.connect_along(
            (from, &from.axis.into_inner()),
            (to, &to.axis.into_inner()),
            approach_mm,
        )
    }

    /// [`Linker::connect`] with the retract from `from` along the unit direction `out_dir`
    /// and the approach to `to` along `in_dir` (the tool keeps its axis on both; directions
    /// from [`Linker::exit_direction`]). Ends exactly at `to`.
    pub fn connect_along(
        &self,
        (from, out_dir): (&CutterLocation, &Vector3),
        (to, in_dir): (&CutterLocation, &Vector3),
        approach_mm: f64,
    ) -> Result<Vec<Move>, PlanError> {
        self.connect_enveloped((from, out_dir), (to, in_dir), approach_mm, None)
    }

    /// [`Linker::connect_along`] whose approach ends its rapid part where the whole tool
    /// (`envelope`) comes within `approach_mm` of the blank
    /// ([`Linker::rapid_approach_end_enveloped`]); the tip alone without an envelope.
    pub fn connect_enveloped(
        &self,
        (from, out_dir): (&CutterLocation, &Vector3),
        (to, in_dir): (&CutterLocation, &Vector3),
        approach_mm: f64,
        envelope: Option<&ToolEnvelope>,
    ) -> Result<Vec<Move>, PlanError> {
        let out = self.leave(from, out_dir)?;
        let inn = self.leave(to, in_dir)?;
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
            let a = self.rapid_approach_end_along(to, in_dir, inside, approach_mm, envelope);
            if a < inside {
                moves.push(Move::rapid(CutterLocation {
                    tip: to.tip + in_dir * a,
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

    /// The direction in which the tool leaves `cl` (and, reversed, approaches it) keeping its
    /// axis: the tool axis when that straight move keeps the design clearance `check` asks
    /// for, otherwise the first clear one of the axis turned toward +Z and toward the radial
    /// direction outward by 15°, 30°, 45°, 60°, 75° and 90° (axis first, then in that order).
    /// A direction qualifies when the move reaches the safety surface with the tool wholly
    /// outside ([`Linker::leaves_clear`]) and [`DesignClearance::segment_clearance`]
    /// certifies the whole move at least `min(c₀, floor_mm) − tol_mm` from the design (`c₀`
    /// the clearance at `cl`: a move that starts at a contact may stay at it, never go
    /// deeper), within `max_queries` clearance queries.
    ///
    /// Returns the direction and whether it was certified; when none is, the tool axis
    /// (`false`). Cost: at most 13 candidates × `max_queries` clearance queries; 2–20 for a
    /// move that leaves the design.
    pub fn exit_direction(&self, cl: &CutterLocation, check: &LinkCheck<'_>) -> (Vector3, bool) {
        let a = cl.axis.into_inner();
        if check
            .profile
            .is_some_and(|top| self.axis_retract_is_clear(cl, top, check))
        {
            return (a, true);
        }
        let c0 = check.clearance.clearance(cl).distance_mm;
        let floor = c0.min(check.floor_mm) - check.tol_mm.max(0.0);
        let radial = Vector3::new(cl.tip.x, cl.tip.y, 0.0)
            .try_normalize(1e-9)
            .unwrap_or_else(Vector3::z);
        let mut candidates = vec![a];
        for u in [Vector3::z(), radial] {
            for deg in [15.0f64, 30.0, 45.0, 60.0, 75.0, 90.0] {
                candidates.push(turned_toward(&a, &u, deg.to_radians()));
            }
        }
        for d in candidates {
            let Some(out) = self.exit_point(cl, &d) else {
                continue;
            };
            let c1 = check.clearance.clearance(&out).distance_mm;
            if check
                .clearance
                .segment_clearance_between(
                    (cl, c0),
                    (&out, c1),
                    floor + check.tol_mm.max(0.0),
                    check.tol_mm.max(0.0),
                    check.max_queries,
                )
                .is_ok()
            {
                return (d, true);
            }
        }
        (a, false)
    }

    /// [`Linker::link`] with the retract from `from` and the approach to `to` along
    /// directions that keep the design clearance of `check` ([`Linker::exit_direction`]);
    /// path ends that could not be certified are counted in `check.stats`.
    pub fn link_checked(
        &self,
        from: &CutterLocation,
        to: &CutterLocation,
        approach_mm: f64,
        check: &LinkCheck<'_>,
    ) -> Result<Vec<Move>, PlanError> {
        let out_dir = self.checked_direction(from, check);
        let in_dir = self.checked_direction(to, check);
        let envelope = check.cutter.map(ToolEnvelope::of);
        self.connect_enveloped(
            (from, &out_dir),
            (to, &in_dir),
            approach_mm,
            envelope.as_ref(),
        )
    }

    /// [`Linker::close`] with the approach to the first move and the retract from the last
    /// along directions that keep the design clearance of `check`.
    pub fn close_checked(
        &self,
        path: &mut ToolPath,
        approach_mm: f64,
        check: &LinkCheck<'_>,
    ) -> Result<(), PlanError> {
        let envelope = check.cutter.map(ToolEnvelope::of);
        self.close_with(
            path,
            approach_mm,
            |cl| self.checked_direction(cl, check),
            envelope.as_ref(),
        )
    }

    /// Appends the retract from the last move and prepends the approach to the first, each
    /// along `dir` of that posture, where they lie inside the safety surface.
    fn close_with(
        &self,
        path: &mut ToolPath,
        approach_mm: f64,
        dir: impl Fn(&CutterLocation) -> Vector3,
        envelope: Option<&ToolEnvelope>,
    ) -> Result<(), PlanError> {
        let (Some(first), Some(last)) = (path.moves.first().copied(), path.moves.last().copied())
        else {
            return Ok(());
        };
        if self.surface.contains(&last.cl.tip) {
            let end = self
                .exit_point(&last.cl, &dir(&last.cl))
                .ok_or_else(|| no_exit(&last.cl))?;
            path.moves.push(Move {
                kind: MoveKind::Retract,
                cl: end,
                feed_mm_per_min: None,
            });
        }
        if self.surface.contains(&first.cl.tip) {
            self.close_start_along(path, &dir(&first.cl), approach_mm, envelope)?;
        }
        Ok(())
    }

    /// [`Linker::exit_direction`], counting the outcome in `check.stats`.
    fn checked_direction(&self, cl: &CutterLocation, check: &LinkCheck<'_>) -> Vector3 {
        if !self.surface.contains(&cl.tip) {
            return cl.axis.into_inner();
        }
        let (d, ok) = self.exit_direction(cl, check);
        check.stats.count(ok, d.dot(&cl.axis) < 1.0 - 1e-12);
        d
    }

    /// Whether a retract from `from` to `to` along `from`'s tool axis (the tool keeping its
    /// axis) sweeps no stock, for a tool whose radius never shrinks from the tip up
    /// (`profile = (h_top, r_top)` from [`widening_profile`]). Moved by `t` along its own
    /// axis, such a tool covers nothing its start posture does not, except the cylinder of
    /// radius `r_top` from `h_top` to `h_top + t` above the tip (the argument of
    /// [`Linker::exit_direction`]); the start posture's own volume holds no stock where the
    /// tool was just cutting. So the retract cuts nothing when that cylinder lies outside the
    /// blank: its axis is probed every 1 mm, and each probe must keep `r_top + 1 mm` from the
    /// blank's bounding capped cylinder (above its top or beyond its largest radius). `false`
    /// without a blank, or when `to` is not along the axis. O(t) tests.
    pub fn retract_sweeps_no_stock(
        &self,
        from: &CutterLocation,
        to: &Point3,
        (h_top, r_top): (f64, f64),
    ) -> bool {
        let Some(blank) = &self.blank else {
            return false;
        };
        let a = from.axis.into_inner();
        let d = to - from.tip;
        let t = d.dot(&a);
        if !(t >= 0.0 && (d - a * t).norm() <= SAME_POSTURE_MM * (1.0 + t)) {
            return false;
        }
        let (z_top, r_max) = (blank.z_range().1, blank.max_radius());
        let step = 1.0;
        let margin = r_top + step;
        let n = (t / step).ceil() as usize;
        (0..=n).all(|i| {
            let c = from.tip + a * (h_top + t * i as f64 / n.max(1) as f64);
            c.z - margin > z_top || c.x.hypot(c.y) - margin > r_max
        })
    }

    /// Whether the retract of `cl` along its own axis to the safety surface is certified by
    /// the shape of the tool alone: for a tool whose radius never shrinks from the tip up
    /// ([`LinkCheck::profile`] = `(h_top, r_top)`), the tool moved by `t` along its axis
    /// covers nothing the tool at `cl` does not, except a cylinder of radius `r_top` from
    /// `h_top` to `h_top + t` above the tip. That cylinder is clear when every point of its
    /// axis, sampled every 1 mm, is farther than `r_top + 1 mm` from the design (the signed
    /// distance is 1-Lipschitz, so the 1 mm covers the points between samples). Then the move
    /// is never closer to the design than the cutting posture itself. O(t) distance queries.
    fn axis_retract_is_clear(
        &self,
        cl: &CutterLocation,
        (h_top, r_top): (f64, f64),
        check: &LinkCheck<'_>,
    ) -> bool {
        let a = cl.axis.into_inner();
        let Some(out) = self.exit_point(cl, &a) else {
            return false;
        };
        let t = (out.tip - cl.tip).norm();
        let step = 1.0;
        let n = (t / step).ceil() as usize;
        (0..=n).all(|i| {
            let q = cl.tip + a * (h_top + t * i as f64 / n.max(1) as f64);
            check.clearance.design_signed_distance(&q).0 > r_top + step
        })
    }

    /// [`Linker::join`] with every retract and approach along a direction that keeps the
    /// design clearance of `check` ([`Linker::exit_direction`]; path ends in parallel;
    /// outcomes counted in `check.stats`).
    pub fn join_checked(
        &self,
        name: &str,
        tool: &str,
        paths: &[ToolPath],
        approach_mm: f64,
        check: &LinkCheck<'_>,
    ) -> Result<ToolPath, PlanError> {
        use rayon::prelude::*;
        let paths: Vec<&ToolPath> = paths.iter().filter(|p| !p.moves.is_empty()).collect();
        let ends: Vec<(Vector3, Vector3)> = paths
            .par_iter()
            .map(|p| {
                let first = &p.moves[0].cl;
                let last = &p.moves[p.moves.len() - 1].cl;
                (
                    self.checked_direction(first, check),
                    self.checked_direction(last, check),
                )
            })
            .collect();
        let envelope = check.cutter.map(ToolEnvelope::of);
        self.join_with(name, tool, &paths, &ends, approach_mm, envelope.as_ref())
    }

    /// `paths` (none empty) joined in order, the approach to each path's first move and the
    /// retract from its last along the directions `ends[i]` (the join of [`Linker::join`]).
    fn join_with(
        &self,
        name: &str,
        tool: &str,
        paths: &[&ToolPath],
        ends: &[(Vector3, Vector3)],
        approach_mm: f64,
        envelope: Option<&ToolEnvelope>,
    ) -> Result<ToolPath, PlanError> {
        let mut out = ToolPath::new(name, tool);
        let mut last_dir = Vector3::z();
        for (p, (in_dir, end_dir)) in paths.iter().zip(ends) {
            let first = p.moves[0];
            if let Some(last) = out.moves.last() {
                let link = self.connect_enveloped(
                    (&last.cl, &last_dir),
                    (&first.cl, in_dir),
                    approach_mm,
                    envelope,
                )?;
                out.moves.extend(link);
                out.moves.extend_from_slice(&p.moves[1..]);
            } else {
                let mut head = (*p).clone();
                if self.surface.contains(&first.cl.tip) {
                    // Only the approach: the retract follows the last path.
                    self.close_start_along(&mut head, in_dir, approach_mm, envelope)?;
                }
                out.moves = head.moves;
            }
            last_dir = *end_dir;
        }
        if let Some(last) = out.moves.last().copied() {
            if self.surface.contains(&last.cl.tip) {
                out.moves.push(Move {
                    kind: MoveKind::Retract,
                    cl: self
                        .exit_point(&last.cl, &last_dir)
                        .ok_or_else(|| no_exit(&last.cl))?,
                    feed_mm_per_min: None,
                });
            }
        }
        Ok(out)
    }

    /// Prepends the approach from the safety surface along `dir` to the first move (a plunge
    /// replacing a first cutting move).
    fn close_start_along(
        &self,
        path: &mut ToolPath,
        dir: &Vector3,
        approach_mm: f64,
        envelope: Option<&ToolEnvelope>,
    ) -> Result<(), PlanError> {
        let Some(first) = path.moves.first().copied() else {
            return Ok(());
        };
        let start = self
            .exit_point(&first.cl, dir)
            .ok_or_else(|| no_exit(&first.cl))?;
        let inside = (start.tip - first.cl.tip).norm();
        let mut head = vec![Move::rapid(start)];
        let a = self.rapid_approach_end_along(&first.cl, dir, inside, approach_mm, envelope);
        if a < inside {
            head.push(Move::rapid(CutterLocation {
                tip: first.cl.tip + dir * a,
                axis: first.cl.axis,
            }));
        }
        if matches!(first.kind, MoveKind::Feed | MoveKind::Link) {
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
        let paths: Vec<&ToolPath> = paths.iter().filter(|p| !p.moves.is_empty()).collect();
        let ends: Vec<(Vector3, Vector3)> = paths
            .iter()
            .map(|p| {
                (
                    p.moves[0].cl.axis.into_inner(),
                    p.moves[p.moves.len() - 1].cl.axis.into_inner(),
                )
            })
            .collect();
        self.join_with(name, tool, &paths, &ends, approach_mm, None)
    }
}

/// What a checked linker keeps: the design clearance query of the operation's tool, the
/// clearance its retracts and approaches keep (`floor_mm`: the operation's smallest
/// allowance; a move starting closer may stay as close, never closer), the certification
/// tolerance and the query budget per direction tried ([`Linker::exit_direction`]).
#[derive(Debug, Clone, Copy)]
pub struct LinkCheck<'a> {
    /// The operation's clearance query.
    pub clearance: &'a DesignClearance<'a>,
    /// `(h_top, r_top)`, the height and radius of the tool's top, when its radius never
    /// shrinks from the tip up ([`widening_profile`]): then a retract along the axis is
    /// certified by the tool's shape ([`Linker::exit_direction`]).
    pub profile: Option<(f64, f64)>,
    /// Where the outcomes are counted.
    pub stats: &'a LinkStats,
    /// Clearance to keep (mm).
    pub floor_mm: f64,
    /// Certification tolerance (mm).
    pub tol_mm: f64,
    /// Clearance queries per direction tried.
    pub max_queries: usize,
    /// The operation's tool: with it, the rapid part of every approach ends where the whole
    /// tool comes within the approach distance of the blank
    /// ([`Linker::rapid_approach_end_enveloped`]); without it, where the tip does.
    pub cutter: Option<&'a cam_core::Cutter>,
}

/// Clearance queries per retract direction tried by default (a move leaving the design
/// needs 2–20).
pub const DEFAULT_LINK_QUERIES: usize = 40;

/// `a` turned toward the unit vector `u` by `angle` (rad) in their common plane, stopping at
/// `u`; `u` when the two are parallel or opposite.
fn turned_toward(a: &Vector3, u: &Vector3, angle: f64) -> Vector3 {
    let perp = u - a * a.dot(u);
    match perp.try_normalize(1e-9) {
        Some(e) => {
            let along = a.dot(u).clamp(-1.0, 1.0).acos();
            let t = angle.min(along);
            a * t.cos() + e * t.sin()
        }
        None => *u,
    }
}

fn no_exit(cl: &CutterLocation) -> PlanError {
    PlanError::geometry(
        "-",
        format!("tip ({:.3}, {:.3}, {:.3})", cl.tip.x, cl.tip.y, cl.tip.z),
        "no move from here (along the tool axis, or the direction the link check chose) \
         reaches the safety surface with the tool outside it",
    )
}

/// Counts of checked retracts and approaches (shared by the threads of one operation).
#[derive(Debug, Default)]
pub struct LinkStats {
    uncertified: std::sync::atomic::AtomicUsize,
    turned: std::sync::atomic::AtomicUsize,
}

impl LinkStats {
    fn count(&self, certified: bool, off_axis: bool) {
        use std::sync::atomic::Ordering::Relaxed;
        if !certified {
            self.uncertified.fetch_add(1, Relaxed);
        } else if off_axis {
            self.turned.fetch_add(1, Relaxed);
        }
    }

    /// Retracts/approaches no direction tried could certify (left along the tool axis).
    pub fn uncertified(&self) -> usize {
        self.uncertified.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Retracts/approaches moved off the tool axis to keep the clearance.
    pub fn turned(&self) -> usize {
        self.turned.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// `(h_top, r_top)` of `cutter` when the radius of the whole assembly (flutes, shank,
/// holder) never decreases from the tip up (checked at 64 heights of the fluted part and at
/// every part boundary, 1e-9 mm slack), `None` otherwise (e.g. a neck thinner than the ball).
pub fn widening_profile(cutter: &cam_core::Cutter) -> Option<(f64, f64)> {
    let slack = 1e-9;
    let l = cutter.flute_length;
    let mut prev = cutter.shape.radius_at(0.0);
    for i in 1..=64 {
        let r = cutter.shape.radius_at(l * i as f64 / 64.0);
        if r < prev - slack {
            return None;
        }
        prev = r;
    }
    let mut h = cutter.overall_length;
    if cutter.overall_length > l {
        if cutter.shank_radius < prev - slack {
            return None;
        }
        prev = cutter.shank_radius;
    }
    for seg in &cutter.holder {
        if seg.bottom_radius < prev - slack || seg.top_radius < seg.bottom_radius - slack {
            return None;
        }
        prev = seg.top_radius;
        h += seg.length;
    }
    Some((h.max(l), prev))
}

/// Where a sphere-traced rapid approach stops (mm): the rapid ends once the tool's margin
/// over the approach distance falls below this (it bounds the trace to `inside / 0.05`
/// steps while a tool slides parallel to the blank).
pub const RAPID_TRACE_STOP_MM: f64 = 0.05;

/// Balls that cover a tool assembly (flutes, shank, holder) along its axis, for distance
/// tests of a whole posture: ball `k` is centred `h_k` above the tip on the axis and has
/// radius `ρ_k`.
///
/// A ball or tapered-ball end's ball is one of them, exactly (it holds the tool up to the
/// ball's equator, or to the cone's tangency `R(1 − sin α)`). The rest of the assembly is
/// cut into slabs at most [`ToolEnvelope::STEP_MM`] long; over a slab `[h₀, h₁]` the
/// assembly lies in the cylinder of radius `r̄` = its largest radius there and half-height
/// `(h₁ − h₀)/2`, which lies in the ball about the slab's middle of radius
/// `√(r̄² + ((h₁ − h₀)/2)²)`. `r̄` is exact: every cutter shape's radius is non-decreasing
/// from the tip up over the flutes (half angles ≥ 0), the shank is a cylinder and each holder
/// segment a frustum, so a slab's largest radius is at one of its ends or at a part boundary
/// inside it (read on both sides). So the balls cover the tool. They overreach it sideways
/// by at most `√(r̄² + 0.25) − r̄ ≤ 0.5 mm`, and along the axis, at a flat face (a flat end's
/// tip, the shoulder of shank or holder), by up to that face's radius. O(length / step)
/// balls.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolEnvelope {
    balls: Vec<(f64, f64)>,
}

impl ToolEnvelope {
    /// Longest slab of the cover (mm).
    pub const STEP_MM: f64 = 1.0;

    /// The cover of `cutter`'s whole assembly.
    pub fn of(cutter: &cam_core::Cutter) -> Self {
        let mut bounds = vec![0.0, cutter.flute_length, cutter.overall_length];
        let mut top = cutter.overall_length;
        for seg in &cutter.holder {
            top += seg.length;
            bounds.push(top);
        }
        let mut balls = Vec::new();
        // The end's own ball, and the height from which slabs cover the rest.
        let start = match cutter.shape {
            cam_core::CutterShape::BallEnd { radius } => {
                balls.push((radius, radius));
                radius
            }
            cam_core::CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => {
                balls.push((ball_radius, ball_radius));
                ball_radius * (1.0 - half_angle.sin())
            }
            _ => 0.0,
        }
        .clamp(0.0, top);
        let radius = |h: f64| cutter.assembly_radius_at(h.clamp(0.0, top)).unwrap_or(0.0);
        let n = ((top - start) / Self::STEP_MM).ceil().max(1.0) as usize;
        let slab = |k: usize| start + (top - start) * k as f64 / n as f64;
        balls.extend((0..n).map(|k| {
            let (h0, h1) = (slab(k), slab(k + 1));
            let mut r = radius(h0).max(radius(h1));
            for &b in &bounds {
                if b >= h0 && b <= h1 {
                    r = r.max(radius(b)).max(radius(b + 1e-9)).max(radius(b - 1e-9));
                }
            }
            let half = 0.5 * (h1 - h0);
            (0.5 * (h0 + h1), r.hypot(half))
        }));
        Self { balls }
    }

    /// The balls `(height of the centre above the tip, radius)`.
    pub fn balls(&self) -> &[(f64, f64)] {
        &self.balls
    }

    /// The smallest distance from the tool at tip `tip`, axis `axis` to the blank, less the
    /// balls' radii: a lower bound of the true gap (≤ 0 when a ball reaches the blank).
    pub fn blank_gap(&self, blank: &Stock, tip: &Point3, axis: &Vector3) -> f64 {
        let (z_top, r_max) = (blank.z_range().1, blank.max_radius());
        let mut gap = f64::INFINITY;
        for &(h, rho) in &self.balls {
            let c = tip + axis * h;
            // The blank lies under its top and within its largest radius: a ball beyond
            // those by more than the gap found cannot lower it.
            let coarse = (c.z - z_top).max(c.x.hypot(c.y) - r_max) - rho;
            if coarse >= gap {
                continue;
            }
            gap = gap.min(blank.distance_to(&c.coords) - rho);
        }
        gap
    }
}

/// [`Linker::rapid_approach_end_enveloped`]'s trace.
fn rapid_end_enveloped(
    blank: &Stock,
    envelope: &ToolEnvelope,
    to: &CutterLocation,
    dir: &Vector3,
    inside: f64,
    approach_mm: f64,
) -> f64 {
    let floor = approach_mm.clamp(0.0, inside);
    let axis = to.axis.into_inner();
    let mut t = inside;
    while t > floor {
        let g = envelope.blank_gap(blank, &(to.tip + dir * t), &axis) - approach_mm.max(0.0);
        if g < RAPID_TRACE_STOP_MM {
            return t;
        }
        t -= g;
    }
    floor
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // test code
    use super::*;
    use cam_core::{Cutter, CutterShape, HolderSegment};

    #[test]
    fn the_envelope_covers_every_point_of_the_tool_and_hugs_a_ball_end() {
        // Surface points every 0.01 mm of height (the axis frame is irrelevant: balls lie on
        // the axis, so a point at height h and radius r is covered iff some ball has
        // (h − h_k)² + r² ≤ ρ_k²), and the axis itself for the end faces.
        let shapes = [
            CutterShape::FlatEnd { radius: 3.0 },
            CutterShape::BallEnd { radius: 2.0 },
            CutterShape::BullNose {
                radius: 4.0,
                corner_radius: 1.0,
            },
            CutterShape::TaperedBallEnd {
                ball_radius: 1.5,
                half_angle: 3f64.to_radians(),
            },
            CutterShape::TaperedFlatEnd {
                tip_radius: 1.0,
                half_angle: 5f64.to_radians(),
            },
        ];
        for shape in shapes {
            let mut c = Cutter::new("t", shape, 12.3, 4.0, 40.7).unwrap();
            c.holder = vec![
                HolderSegment {
                    bottom_radius: 10.5,
                    top_radius: 13.5,
                    length: 38.2,
                },
                HolderSegment {
                    bottom_radius: 13.5,
                    top_radius: 13.5,
                    length: 41.9,
                },
            ];
            let env = ToolEnvelope::of(&c);
            let top = 40.7 + 38.2 + 41.9;
            let n = (top / 0.01) as usize;
            for i in 0..=n {
                let h = top * i as f64 / n as f64;
                let r = c.assembly_radius_at(h.min(top - 1e-9)).unwrap();
                for rr in [0.0, r] {
                    let inside = env
                        .balls()
                        .iter()
                        .any(|&(hk, rho)| (h - hk).powi(2) + rr * rr <= rho * rho + 1e-12);
                    assert!(inside, "{shape:?}: ({h}, {rr}) outside the envelope");
                }
            }
            // A ball end's lowest point is the envelope's: no overreach below the tip.
            if let CutterShape::BallEnd { .. } | CutterShape::TaperedBallEnd { .. } = shape {
                let lowest = env
                    .balls()
                    .iter()
                    .map(|&(hk, rho)| hk - rho)
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    lowest.abs() < 1e-12,
                    "{shape:?}: reaches {lowest} below the tip"
                );
            }
        }
    }
}
