//! Shank and holder clearance against the stock (the blank or turned stock, an envelope of
//! revolution), for plunges and for the rapids between them.
//!
//! The blade check of [`crate::rows`] keeps cutter, shank and holder off the blades; the
//! stock around and above the channels is not part of the design. A plunge cutter drills its
//! own hole: during a plunge from its start to its depth, the part of the tool inside the
//! cylinder the cutting part has swept (radius `R` of the cutter, from the current tip up to
//! the start's tip plus the flute length) meets no material. Every other point of the tool —
//! the shank above that hole, and the holder wherever it is wider than the cutter — must stay
//! outside the stock. Near the inlet of a blank that was not turned, the plunge axes lie
//! almost radially and the stroke from outside the blank to the hub is longer than the
//! stick-out: the holder would enter the blank (the verifier measured 540 holder contacts on
//! `impeller-plunge-400` before this check). Between two plunges of a row the whole tool
//! travels at rapid from one start to the next: all of it must stay outside the stock.
//!
//! The stock is [`impeller_model::Stock`] as given to the planner: it contains every point of
//! the material any earlier operation leaves, so a tool outside it is outside the remaining
//! material (conservative where earlier sections already cut).
//!
//! # Sampling and tolerance
//! The tool surface is sampled on rings every [`HEIGHT_STEP_MM`] along the axis with points
//! at most [`RING_STEP_MM`] apart (plus the holder's bottom face on rings every
//! [`RING_STEP_MM`]); every surface point lies within `g = ½·√(HEIGHT_STEP_MM² +
//! RING_STEP_MM²)` of a sample. Samples are pushed outward by [`STOCK_CLEARANCE_MM`] + `g`
//! and tested with [`Stock::contains`]: a tool that passes keeps at least
//! [`STOCK_CLEARANCE_MM`] from the stock laterally (the ring offset) up to the profile's
//! curvature between samples. A plunge is checked at postures along its stroke every
//! [`STROKE_STEP_MM`] (both ends included), a rapid at its ends and midpoints every
//! [`STROKE_STEP_MM`].
//!
//! Cost: O(tool surface / (HEIGHT_STEP_MM · RING_STEP_MM)) stock tests per posture, each
//! O(log profile points).

use crate::conventional_axes::Posture;
use cam_core::{Cutter, CutterLocation, Point3, Vector3};
use impeller_model::Stock;

/// Clearance (mm) kept between shank or holder and the stock.
pub const STOCK_CLEARANCE_MM: f64 = 1.0;
/// Axial spacing (mm) of the sampled rings.
pub const HEIGHT_STEP_MM: f64 = 1.0;
/// Largest spacing (mm) of the samples on a ring (and between the rings of the holder's
/// bottom face).
pub const RING_STEP_MM: f64 = 1.0;
/// Spacing (mm) of the postures checked along a plunge or a rapid.
pub const STROKE_STEP_MM: f64 = 5.0;

/// One sampled ring of the tool: height above the tip and radius.
#[derive(Debug, Clone, Copy)]
struct Ring {
    h: f64,
    radius: f64,
}

/// The shank and holder (and cutting part) of one tool as sample rings, against one stock.
#[derive(Debug, Clone)]
pub struct StockClearance<'a> {
    stock: &'a Stock,
    cutter_radius: f64,
    flute_length: f64,
    rings: Vec<Ring>,
    offset: f64,
}

impl<'a> StockClearance<'a> {
    /// The check of `cutter` (flat bottom radius `cutter_radius`) against `stock`.
    pub fn new(stock: &'a Stock, cutter: &Cutter, cutter_radius: f64) -> Self {
        let mut rings = Vec::new();
        let mut push_part = |h0: f64, h1: f64, r: &dyn Fn(f64) -> f64| {
            if h1 <= h0 {
                return;
            }
            let n = ((h1 - h0) / HEIGHT_STEP_MM).ceil().max(1.0) as usize;
            for i in 0..=n {
                let h = h0 + (h1 - h0) * i as f64 / n as f64;
                rings.push(Ring { h, radius: r(h) });
            }
        };
        let l = cutter.flute_length;
        push_part(0.0, l, &|h| cutter.shape.radius_at(h));
        push_part(l.min(cutter.overall_length), cutter.overall_length, &|_| {
            cutter.shank_radius
        });
        let mut h = cutter.overall_length;
        let mut bottom_face = None;
        for seg in &cutter.holder {
            let (b, t, len) = (seg.bottom_radius, seg.top_radius, seg.length);
            if bottom_face.is_none() {
                bottom_face = Some((h, b));
            }
            push_part(h, h + len, &|x| b + (t - b) * ((x - h) / len.max(1e-12)));
            h += len;
        }
        // The holder's bottom face: rings from the shank out to the holder's radius.
        if let Some((h0, b)) = bottom_face {
            let inner = cutter.shank_radius.min(b);
            let n = ((b - inner) / RING_STEP_MM).ceil() as usize;
            for i in 0..n {
                rings.push(Ring {
                    h: h0,
                    radius: inner + (b - inner) * i as f64 / n.max(1) as f64,
                });
            }
        }
        let g = 0.5 * HEIGHT_STEP_MM.hypot(RING_STEP_MM);
        Self {
            stock,
            cutter_radius,
            flute_length: l,
            rings,
            offset: STOCK_CLEARANCE_MM + g,
        }
    }

    /// Whether the tool at `cl` keeps the clearance from the stock at every sample except
    /// those inside the hole the cutter has drilled: points within the cutter radius up to
    /// `hole_mm` above the tip (`None`: no hole, the whole tool is checked).
    fn posture_clear(&self, cl: &CutterLocation, hole_mm: Option<f64>) -> bool {
        let a = cl.axis.into_inner();
        let (e1, e2) = crate::axial_depth::perpendicular_frame(&a);
        self.rings.iter().all(|ring| {
            if hole_mm.is_some_and(|top| ring.h <= top && ring.radius <= self.cutter_radius) {
                return true;
            }
            let rho = ring.radius + self.offset;
            let n = ((std::f64::consts::TAU * rho / RING_STEP_MM).ceil() as usize).max(8);
            let c: Point3 = cl.tip + a * ring.h;
            (0..n).all(|k| {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                let p: Vector3 = c.coords + (e1 * th.cos() + e2 * th.sin()) * rho;
                !self.stock.contains(&p)
            })
        })
    }

    /// Whether a plunge from `p.start` to `p.cl` keeps shank and holder out of the stock:
    /// at postures every [`STROKE_STEP_MM`] along the stroke, every tool point outside the
    /// hole drilled so far (cutter radius, up to the start's tip plus the flute length).
    pub fn plunge_clear(&self, p: &Posture) -> bool {
        let d = p.start.tip - p.cl.tip;
        let len = d.norm();
        let n = (len / STROKE_STEP_MM).ceil().max(1.0) as usize;
        (0..=n).all(|i| {
            let s = i as f64 / n as f64;
            let cl = CutterLocation {
                tip: p.cl.tip + d * s,
                axis: p.cl.axis,
            };
            // From here the hole reaches up to the start's tip plus the flute length.
            let hole = (1.0 - s) * len + self.flute_length;
            self.posture_clear(&cl, Some(hole))
        })
    }

    /// Whether the straight rapid from `a` to `b` (tip linear, axis interpolated and
    /// normalised) keeps the whole tool out of the stock, checked at its ends and every
    /// [`STROKE_STEP_MM`] between.
    pub fn rapid_clear(&self, a: &CutterLocation, b: &CutterLocation) -> bool {
        let n = ((b.tip - a.tip).norm() / STROKE_STEP_MM).ceil().max(1.0) as usize;
        (0..=n).all(|i| {
            let s = i as f64 / n as f64;
            let axis = a.axis.into_inner() * (1.0 - s) + b.axis.into_inner() * s;
            let Some(axis) = nalgebra::Unit::try_new(axis, 1e-12) else {
                return false;
            };
            let cl = CutterLocation {
                tip: a.tip + (b.tip - a.tip) * s,
                axis,
            };
            self.posture_clear(&cl, None)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{CutterShape, HolderSegment, UnitVector3};

    fn cutter() -> Cutter {
        let mut c = Cutter::new(
            "d16",
            CutterShape::FlatEnd { radius: 8.0 },
            30.0,
            7.5,
            140.0,
        )
        .expect("valid cutter");
        c.holder = vec![HolderSegment {
            bottom_radius: 16.0,
            top_radius: 16.0,
            length: 40.0,
        }];
        c
    }

    fn cl(tip: [f64; 3], axis: [f64; 3]) -> CutterLocation {
        CutterLocation {
            tip: Point3::new(tip[0], tip[1], tip[2]),
            axis: UnitVector3::new_normalize(Vector3::new(axis[0], axis[1], axis[2])),
        }
    }

    /// A radial plunge into a Ø406 × 130 cylinder from 2 mm outside its side to r = 40 is
    /// 165 mm long: the holder (140 mm above the tip) enters the blank by 25 mm. The same
    /// plunge 100 mm long keeps it outside; a vertical one from 2 mm above the top is clear.
    #[test]
    fn holder_of_a_long_radial_plunge_enters_the_blank() {
        let stock = Stock::cylinder(406.0, 130.0).expect("stock");
        let c = cutter();
        let check = StockClearance::new(&stock, &c, 8.0);
        let posture = |depth_r: f64, start_r: f64| Posture {
            m: 0.0,
            s: 0.5,
            centre: Vector3::new(depth_r, 0.0, 100.0),
            w: Vector3::new(start_r, 0.0, 100.0),
            cl: cl([depth_r, 0.0, 100.0], [1.0, 0.0, 0.0]),
            start: cl([start_r, 0.0, 100.0], [1.0, 0.0, 0.0]),
            contact: crate::axial_depth::Contact {
                t: 0.0,
                uv: (0.0, 0.0),
                point: Vector3::zeros(),
                normal: Vector3::z(),
                iterations: 0,
            },
            alpha: 0.0,
        };
        assert!(!check.plunge_clear(&posture(40.0, 205.0)));
        assert!(check.plunge_clear(&posture(105.0, 205.0)));
        let vertical = Posture {
            cl: cl([100.0, 0.0, 30.0], [0.0, 0.0, 1.0]),
            start: cl([100.0, 0.0, 132.0], [0.0, 0.0, 1.0]),
            ..posture(105.0, 205.0)
        };
        assert!(check.plunge_clear(&vertical));
    }

    /// A rapid 2 mm above the top with the axis vertical is clear; tilted by 45° the
    /// cutter's rim (radius 8) dips 3.7 mm into the blank and the rapid is not.
    #[test]
    fn rapid_above_the_top_with_a_tilted_axis_is_not_clear() {
        let stock = Stock::cylinder(406.0, 130.0).expect("stock");
        let check = StockClearance::new(&stock, &cutter(), 8.0);
        let up = [0.0, 0.0, 1.0];
        assert!(check.rapid_clear(&cl([0.0, 0.0, 132.0], up), &cl([6.0, 0.0, 132.0], up)));
        let tilted = [1.0, 0.0, 1.0];
        assert!(!check.rapid_clear(
            &cl([0.0, 0.0, 132.0], tilted),
            &cl([6.0, 0.0, 132.0], tilted)
        ));
        // The same posture with the clearance plus the sampling band to spare is clear.
        let z = 130.0 + 8.0 * std::f64::consts::FRAC_1_SQRT_2 + check.offset + 0.01;
        assert!(check.rapid_clear(&cl([0.0, 0.0, z], tilted), &cl([6.0, 0.0, z], tilted)));
    }
}
