//! Linking moves: retract along the tool axis to a safety surface around the impeller,
//! travel on it, approach along the tool axis.
//!
//! # Geometry
//! The safety surface bounds a capped cylinder about the impeller axis (+Z): radius `R` and
//! top plane `z = Z` (by default the blank's largest radius and top plus a clearance). A
//! retract from a tool tip `p` with axis `a` runs along `a` to the first point where the ray
//! `p + t·a` leaves the capped cylinder (closed form: the smallest `t > 0` where
//! `|xy(p + t a)| = R` or `z = Z`). The travel between an exit point `A` and an entry point `B`
//! rises vertically to the cap (a vertical line from a point outside the cylinder stays
//! outside it), crosses the cap on the straight chord (the cap is a plane above the blank),
//! and comes down vertically to `B`. The tool axis turns linearly (normalised) from `A`'s to
//! `B`'s on the travel; the pipeline's verification checks the swept tool between postures.
//!
//! Cost: O(1) per retract and per travel.

use crate::{PlanError, Point3, Vector3};
use cam_core::{CutterLocation, Move, MoveKind, ToolPath};
use impeller_model::Stock;

/// Default clearance of the safety surface over the blank (mm).
pub const DEFAULT_SAFETY_CLEARANCE_MM: f64 = 10.0;

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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linker {
    /// The safety surface.
    pub surface: SafetySurface,
}

impl Linker {
    /// A linker over `surface`.
    pub fn new(surface: SafetySurface) -> Self {
        Self { surface }
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
    /// moves excluding `from` and including `to`.
    pub fn travel(&self, from: &CutterLocation, to: &CutterLocation) -> Vec<Move> {
        let top = self.surface.top_z_mm;
        // Straight up (a vertical line outside the cylinder stays outside it), across the cap
        // on its chord (the cap is a plane above the blank), straight down.
        let up = |p: &Point3| Point3::new(p.x, p.y, top.max(p.z));
        let mut tips = vec![up(&from.tip), up(&to.tip), to.tip];
        tips.dedup_by(|x, y| (*x - *y).norm() < 1e-12);
        if tips.first().is_some_and(|t| (t - from.tip).norm() < 1e-12) {
            tips.remove(0);
        }
        let n = tips.len();
        let a0 = from.axis.into_inner();
        let a1 = to.axis.into_inner();
        tips.into_iter()
            .enumerate()
            .map(|(i, tip)| {
                let f = (i + 1) as f64 / n as f64;
                let axis = (a0 * (1.0 - f) + a1 * f).try_normalize(1e-12).unwrap_or(a1);
                Move::rapid(CutterLocation {
                    tip,
                    axis: nalgebra::Unit::new_unchecked(axis),
                })
            })
            .collect()
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
        let above = CutterLocation {
            tip: to.tip + to.axis.into_inner() * approach_mm.max(0.0),
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

    /// Prepends the approach (from the safety surface along the first move's axis) and
    /// appends the retract to `path` when it has moves.
    pub fn close(&self, path: &mut ToolPath, approach_mm: f64) -> Result<(), PlanError> {
        let (Some(first), Some(last)) = (path.moves.first().copied(), path.moves.last().copied())
        else {
            return Ok(());
        };
        let start = self.retract_point(&first.cl)?;
        let above = CutterLocation {
            tip: first.cl.tip + first.cl.axis.into_inner() * approach_mm.max(0.0),
            axis: first.cl.axis,
        };
        let mut head = vec![Move::rapid(start), Move::rapid(above)];
        if first.kind == MoveKind::Feed {
            head.push(Move {
                kind: MoveKind::Plunge,
                cl: first.cl,
                feed_mm_per_min: None,
            });
        }
        head.append(&mut path.moves);
        path.moves = head;
        let end = self.retract_point(&last.cl)?;
        path.moves.push(Move {
            kind: MoveKind::Retract,
            cl: end,
            feed_mm_per_min: None,
        });
        Ok(())
    }
}
