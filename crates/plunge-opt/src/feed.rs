//! Feed direction by lean: the signed α of a plunge and the row segments fed the way their
//! axes lean (paper 000 §2, Fig. 4).
//!
//! # Why the feed follows the lean
//! A flat bottom tilted by λ from the floor normal touches the floor (plus allowance) at the
//! rim point it leans toward and stands `d·tan λ` above it at distance `d` behind that point:
//! each plunge leaves a wedge on its *trailing* side when it leans toward the feed, on its
//! *leading* side when it leans back. The next plunge, a step `s` further along the feed,
//! has its non-cutting centre disk (radius `r_c`, `s + r_c < R`) inside the previous hole. On a
//! flat floor its bottom lies `s·tan λ` *above* the previous one everywhere over that disk when
//! both lean toward the feed by λ, and `s·tan λ` *below* it when both lean back (the centre
//! then cuts the wedge: the paper's "interferential phenomenon", its Fig. 13 down-step).
//! Where the lean λ₁ of one plunge and λ₂ of the next differ, the disk point farthest back,
//! `R + r_c` behind the rim contact, stays above the previous bottom when
//! `tan λ₂ ≥ tan λ₁ · (R + r_c − s)/(R + r_c)`: the lean toward the feed may fall, but by at
//! most that factor per step, and never through zero. Hence:
//!
//! - each row is cut into **segments**, maximal runs of plunges whose conventional axes lean
//!   the same way along the row ([`segments_by_lean`]);
//! - each segment is **fed toward where its axes lean** (Fig. 4's principle: "tilted in the
//!   direction of the material to be cut"), entering at its other end;
//! - the paper's W walk ([`crate::axis_optimisation`]) then only corrects the plunges that
//!   still interfere, chiefly where two segments meet and the lean falls toward zero.
//!
//! # Signed α
//! α is the paper's angle between the hub normal `n` at the contact point and the cutter axis
//! `q`, given the sign of `q · t`, where `t` is the feed direction along the row at the plunge
//! (the chord between its neighbours' centre points, projected onto the tangent plane at the
//! contact): positive when the axis leans toward the feed. The paper's monotone rule reads
//! "signed α increases along the feed"; here it is a diagnostic ([`is_increasing`]), the
//! measure of success is the exact centre interference ([`crate::interference`]).
//!
//! Cost: O(plunges) per row; no allocation beyond the output.

use crate::conventional_axes::Posture;
use cam_core::Vector3;

/// Which way a row segment is fed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feed {
    /// From the outlet toward the inlet (the paper's direction; station order).
    TowardInlet,
    /// From the inlet toward the outlet (reverse station order).
    TowardOutlet,
}

impl Feed {
    /// The other direction.
    pub fn reversed(self) -> Self {
        match self {
            Feed::TowardInlet => Feed::TowardOutlet,
            Feed::TowardOutlet => Feed::TowardInlet,
        }
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Feed::TowardInlet => "outlet → inlet",
            Feed::TowardOutlet => "inlet → outlet",
        }
    }
}

/// A run of consecutive stations of one row fed in one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Index of the row (suction side 0).
    pub row: usize,
    /// Station indices of the row (0 = outlet end) in feed order: the first is the entry.
    pub stations: Vec<usize>,
    /// The feed direction.
    pub feed: Feed,
}

impl Segment {
    /// The same stations fed the other way (the entry moves to the other end).
    pub fn reversed(&self) -> Self {
        Self {
            row: self.row,
            stations: self.stations.iter().rev().copied().collect(),
            feed: self.feed.reversed(),
        }
    }
}

/// Unit direction toward the inlet along `row` (postures in station order, outlet → inlet)
/// at plunge `i`, in the tangent plane of its contact: the chord between its neighbours'
/// centre points (one-sided at the ends). `None` for a row of one plunge or a degenerate
/// chord.
pub fn toward_inlet(row: &[Posture], i: usize) -> Option<Vector3> {
    let n = row.len();
    if n < 2 || i >= n {
        return None;
    }
    let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
    let d = row[b].centre - row[a].centre;
    let normal = row[i].contact.normal;
    (d - normal * d.dot(&normal)).try_normalize(1e-12)
}

/// The lean of plunge `i` of `row` toward the inlet (rad): `atan2(q·t, q·n)` with `t`
/// from [`toward_inlet`]; positive when the axis leans toward the inlet. 0 for a row of one
/// plunge.
pub fn lean_toward_inlet(row: &[Posture], i: usize) -> f64 {
    let Some(t) = toward_inlet(row, i) else {
        return 0.0;
    };
    let q = row[i].cl.axis.into_inner();
    q.dot(&t).atan2(q.dot(&row[i].contact.normal))
}

/// Signed α of plunge `i` of `row` (rad) when fed `feed`: the paper's α (angle between hub
/// normal and axis) with the sign of the axis' lean toward the feed direction. A plunge
/// leaning neither way (within rounding) counts as leaning toward the feed.
pub fn signed_alpha(row: &[Posture], i: usize, feed: Feed) -> f64 {
    let lean = lean_toward_inlet(row, i);
    let toward_feed = match feed {
        Feed::TowardInlet => lean,
        Feed::TowardOutlet => -lean,
    };
    if toward_feed < 0.0 {
        -row[i].alpha
    } else {
        row[i].alpha
    }
}

/// The segments of row `row_index` (postures in station order): maximal runs of equal lean
/// sign (toward the inlet: fed toward the inlet; toward the outlet: fed toward the outlet),
/// in station order. A row of one plunge is one segment fed toward the inlet.
pub fn segments_by_lean(row_index: usize, row: &[Posture]) -> Vec<Segment> {
    let mut out: Vec<Segment> = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    let mut run_feed = Feed::TowardInlet;
    for i in 0..row.len() {
        let feed = if lean_toward_inlet(row, i) >= 0.0 {
            Feed::TowardInlet
        } else {
            Feed::TowardOutlet
        };
        if !run.is_empty() && feed != run_feed {
            out.push(segment(row_index, std::mem::take(&mut run), run_feed));
        }
        run_feed = feed;
        run.push(i);
    }
    if !run.is_empty() {
        out.push(segment(row_index, run, run_feed));
    }
    out
}

/// A segment over `stations` (in station order) fed `feed`.
fn segment(row: usize, mut stations: Vec<usize>, feed: Feed) -> Segment {
    if feed == Feed::TowardOutlet {
        stations.reverse();
    }
    Segment {
        row,
        stations,
        feed,
    }
}

/// Whether `values` increase strictly (the paper's monotone rule, a diagnostic here).
pub fn is_increasing(values: &[f64]) -> bool {
    values.windows(2).all(|w| w[1] > w[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axial_depth::Contact;
    use cam_core::{CutterLocation, Point3, UnitVector3};

    /// A plunge on the flat floor z = 0 at x (the inlet toward −x), its axis leaning by
    /// `lean_deg` toward the inlet.
    fn plunge(x: f64, lean_deg: f64) -> Posture {
        let l = lean_deg.to_radians();
        let axis = UnitVector3::new_normalize(Vector3::new(-l.sin(), 0.0, l.cos()));
        let cl = CutterLocation {
            tip: Point3::new(x, 0.0, 1.0),
            axis,
        };
        Posture {
            m: 0.5 + 0.001 * x,
            s: 0.5,
            centre: Vector3::new(x, 0.0, 0.0),
            w: Vector3::new(x, 0.0, 0.0) + axis.into_inner() * 50.0,
            cl,
            start: cl,
            contact: Contact {
                t: 0.0,
                uv: (0.0, 0.0),
                point: Vector3::new(x, 0.0, 0.0),
                normal: Vector3::z(),
                iterations: 0,
            },
            alpha: l.abs(),
        }
    }

    #[test]
    fn rows_split_where_the_lean_changes_sign() {
        // Station order outlet → inlet is decreasing x; leans +8, +4, −2, −6, −9 degrees.
        let row: Vec<Posture> = [8.0, 4.0, -2.0, -6.0, -9.0]
            .iter()
            .enumerate()
            .map(|(i, &l)| plunge(-6.0 * i as f64, l))
            .collect();
        for (i, want) in [8.0f64, 4.0, -2.0, -6.0, -9.0].iter().enumerate() {
            let got = lean_toward_inlet(&row, i).to_degrees();
            assert!((got - want).abs() < 1e-9, "{i}: {got} vs {want}");
        }
        let segs = segments_by_lean(3, &row);
        assert_eq!(
            segs,
            vec![
                Segment {
                    row: 3,
                    stations: vec![0, 1],
                    feed: Feed::TowardInlet
                },
                Segment {
                    row: 3,
                    stations: vec![4, 3, 2],
                    feed: Feed::TowardOutlet
                },
            ]
        );
        // Signed α: positive toward the feed, the paper's α in size.
        assert!((signed_alpha(&row, 0, Feed::TowardInlet) - 8f64.to_radians()).abs() < 1e-12);
        assert!((signed_alpha(&row, 3, Feed::TowardInlet) + 6f64.to_radians()).abs() < 1e-12);
        assert!((signed_alpha(&row, 3, Feed::TowardOutlet) - 6f64.to_radians()).abs() < 1e-12);
        assert_eq!(segs[1].reversed().stations, vec![2, 3, 4]);
        assert!(is_increasing(&[1.0, 2.0]) && !is_increasing(&[1.0, 1.0]));
    }
}
