//! Cutter positions along a move: how the controller interpolates between two cutter
//! locations, and the sampling step that bounds the swept-volume error.
//!
//! The swept volume of a move is approximated by the union of the cutter at positions
//! `s = k/n`, `k = 1..n`, of the interpolated motion. Two error sources are bounded by the
//! sweep tolerance `tol`:
//! * scallop between consecutive positions of a surface with smallest principal radius ρ
//!   moved laterally by `Δ`: `Δ²/(8ρ)` (circle-chord sagitta), so `Δ ≤ sqrt(8 ρ tol)`;
//! * stair of a flat face (flat end, bull-nose floor, tapered flat end) moved with a
//!   component along the tool axis: the wedge left between two faces offset by `Δ` along a
//!   direction `d̂` has thickness `Δ |d̂·a| sqrt(1 − (d̂·a)²)`, so `Δ ≤ tol / (that factor)`.
//!
//! `Δ` is the largest displacement of any cutting point, bounded by `|Δtip| + H |Δaxis|`
//! with `H` the flute length, summed over 8 sub-chords of the interpolated motion.

use cam_core::{Cutter, CutterLocation, CutterShape, UnitVector3};
use std::sync::Arc;

/// Maps (operation index, move index, previous CL, target CL, s ∈ [0, 1]) to the cutter
/// location the controller reaches at fraction `s` of the move.
pub type ClInterpolator =
    dyn Fn(usize, usize, &CutterLocation, &CutterLocation, f64) -> CutterLocation + Send + Sync;

/// How the tool axis (and tip) move between two cutter locations.
#[derive(Clone, Default)]
pub enum Interpolation {
    /// Tool-centre-point control: tip linear, tool-axis vector linear then normalised.
    #[default]
    Tcp,
    /// Caller-defined motion (e.g. linear in joint angles through forward kinematics).
    Custom(Arc<ClInterpolator>),
}

impl std::fmt::Debug for Interpolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Interpolation::Tcp => f.write_str("Tcp"),
            Interpolation::Custom(_) => f.write_str("Custom(..)"),
        }
    }
}

impl Interpolation {
    /// The cutter location at fraction `s` of the move `from → to`.
    pub fn at(
        &self,
        op: usize,
        index: usize,
        from: &CutterLocation,
        to: &CutterLocation,
        s: f64,
    ) -> CutterLocation {
        match self {
            Interpolation::Tcp => tcp_at(from, to, s),
            Interpolation::Custom(f) => f(op, index, from, to, s),
        }
    }
}

/// The tool-centre-point motion from `from` to `to` at fraction `s`
/// ([`Interpolation::Tcp`]): tip linear, tool-axis vector linear then normalised (the start
/// axis for the first half of an antiparallel pair, where the blend has no direction).
pub fn tcp_at(from: &CutterLocation, to: &CutterLocation, s: f64) -> CutterLocation {
    let tip = from.tip + (to.tip - from.tip) * s;
    let a = from.axis.into_inner() * (1.0 - s) + to.axis.into_inner() * s;
    let n = a.norm();
    let axis = if n > 1e-12 {
        UnitVector3::new_unchecked(a / n)
    } else if s < 0.5 {
        from.axis
    } else {
        to.axis
    };
    CutterLocation { tip, axis }
}

/// Smallest principal radius (mm) of the cutter's cutting surface (scallop radius).
pub fn scallop_radius(shape: &CutterShape) -> f64 {
    match *shape {
        CutterShape::FlatEnd { radius } | CutterShape::BallEnd { radius } => radius,
        CutterShape::BullNose { corner_radius, .. } => corner_radius,
        CutterShape::TaperedBallEnd { ball_radius, .. } => ball_radius,
        CutterShape::TaperedFlatEnd { tip_radius, .. } => tip_radius,
    }
}

/// Whether the cutter has a flat face perpendicular to its axis.
pub fn has_flat_face(shape: &CutterShape) -> bool {
    match *shape {
        CutterShape::FlatEnd { .. } | CutterShape::TaperedFlatEnd { .. } => true,
        CutterShape::BullNose {
            radius,
            corner_radius,
        } => radius > corner_radius,
        _ => false,
    }
}

/// Points per move at which [`positions_for_move`] measures the move's displacement, at
/// fractions `k/n`, `k = 1..=n`: the end of a straight tool-centre-point move, eight points of
/// any other motion (summed as sub-chords).
pub fn sub_positions(interp: &Interpolation) -> usize {
    match interp {
        Interpolation::Tcp => 1,
        Interpolation::Custom(_) => 8,
    }
}

/// Number of positions `n >= 1` to sample the move `from → to` so the swept-volume error
/// stays below `tol` (see module docs).
pub fn positions_for_move(
    cutter: &Cutter,
    interp: &Interpolation,
    op: usize,
    index: usize,
    from: &CutterLocation,
    to: &CutterLocation,
    tol: f64,
) -> usize {
    let sub = sub_positions(interp);
    let points = (1..=sub).map(|k| interp.at(op, index, from, to, k as f64 / sub as f64));
    positions_for_displacement(
        cutter,
        from,
        to,
        sub_chord_displacement(cutter, from, points),
        tol,
    )
}

/// [`positions_for_move`] from the move's points already sampled at the fractions of
/// [`sub_positions`] (`points[k − 1]` at `k/n`): the same count without evaluating the
/// motion again.
pub fn positions_for_samples(
    cutter: &Cutter,
    from: &CutterLocation,
    to: &CutterLocation,
    points: &[CutterLocation],
    tol: f64,
) -> usize {
    let disp = sub_chord_displacement(cutter, from, points.iter().copied());
    positions_for_displacement(cutter, from, to, disp, tol)
}

/// Displacement bound `Σ |Δtip| + H |Δaxis|` (`H` the flute length) along the sub-chords
/// from `from` through `points` (module docs).
fn sub_chord_displacement(
    cutter: &Cutter,
    from: &CutterLocation,
    points: impl Iterator<Item = CutterLocation>,
) -> f64 {
    let h = cutter.flute_length;
    let mut disp = 0.0;
    let mut prev = *from;
    for cur in points {
        disp += (cur.tip - prev.tip).norm()
            + h * (cur.axis.into_inner() - prev.axis.into_inner()).norm();
        prev = cur;
    }
    disp
}

/// The number of positions for a move of displacement bound `disp` (module docs).
fn positions_for_displacement(
    cutter: &Cutter,
    from: &CutterLocation,
    to: &CutterLocation,
    disp: f64,
    tol: f64,
) -> usize {
    if !(disp.is_finite()) || disp <= 0.0 {
        return 1;
    }
    let mut step = (8.0 * scallop_radius(&cutter.shape) * tol).sqrt();
    if has_flat_face(&cutter.shape) {
        let d = to.tip - from.tip;
        let len = d.norm();
        if len > 0.0 {
            let c = (d / len).dot(&from.axis.into_inner()).abs().min(1.0);
            let f = c * (1.0 - c * c).sqrt();
            if f > 1e-9 {
                step = step.min(tol / f);
            }
        }
    }
    let n = (disp / step.max(1e-9)).ceil();
    if n.is_finite() {
        (n as usize).clamp(1, 1_000_000)
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{Point3, Vector3};

    #[test]
    fn step_respects_scallop_and_stair_bounds() {
        let ball = Cutter::new("b", CutterShape::BallEnd { radius: 2.0 }, 10.0, 2.0, 30.0).unwrap();
        let a = CutterLocation::vertical(Point3::new(0.0, 0.0, 0.0));
        let b = CutterLocation::vertical(Point3::new(10.0, 0.0, 0.0));
        // sqrt(8·2·0.01) = 0.4 mm → 25 positions for 10 mm.
        assert_eq!(
            positions_for_move(&ball, &Interpolation::Tcp, 0, 0, &a, &b, 0.01),
            25
        );
        let flat = Cutter::new("f", CutterShape::FlatEnd { radius: 2.0 }, 10.0, 2.0, 30.0).unwrap();
        let c = CutterLocation::vertical(Point3::new(10.0, 0.0, 10.0));
        // 45° ramp: factor 1/2 → step 0.02, displacement 14.14 → 708 positions.
        let n = positions_for_move(&flat, &Interpolation::Tcp, 0, 0, &a, &c, 0.01);
        assert_eq!(n, (200f64.sqrt() / 0.02).ceil() as usize);
        // Pure plunge along the axis: no stair, scallop bound only.
        let d = CutterLocation::vertical(Point3::new(0.0, 0.0, -4.0));
        assert_eq!(
            positions_for_move(&flat, &Interpolation::Tcp, 0, 0, &a, &d, 0.01),
            10
        );
        // Axis rotation counts with the flute length.
        let e =
            CutterLocation::new(Point3::new(0.0, 0.0, 0.0), Vector3::new(0.1, 0.0, 1.0)).unwrap();
        assert!(positions_for_move(&ball, &Interpolation::Tcp, 0, 0, &a, &e, 0.01) >= 3);
    }
}
