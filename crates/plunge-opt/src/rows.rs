//! Sections and rows: where the plunges of one channel go.
//!
//! # Channel coordinates
//! A point of the channel floor is named by `(m, s)`: `m` the meridional fraction of the hub
//! contour (0 at the inlet, 1 at the outlet; beyond 1 the contour continues along its outlet
//! tangent, off the part) and `s ∈ [0, 1]` the angular fraction across the channel between
//! the bounding blade sides where they meet the hub (`s = 0` the left side — the suction side
//! of a parametric impeller — `s = 1` the right, pressure side). The same `(m, s)` on the
//! shroud (its own meridional fraction, the angles where the sides meet the shroud) is the
//! *isoparametric* shroud point `W(m, s)` of paper 000 §3 ①. The angles are tabulated at
//! [`FRAME_STATIONS`] fractions and interpolated linearly (the positions built from them are
//! re-checked exactly with the clearance query, so the interpolation only shapes the rows);
//! beyond the outlet the angles continue linearly.
//!
//! # Rows
//! A row is a function `s(m)`. The suction-side row keeps the blade allowance to the left
//! blade, the pressure-side row to the right one: at each table station the largest
//! (smallest) `s` where the cutter, posed with its conventional axis at its depth, keeps
//! `blade_allowance + CLEARANCE_MARGIN_MM` from every blade (cutter, shank and holder,
//! [`cam_plan::DesignClearance`] with blades only — the flat bottom touches the floor by
//! design) is found by bisection. Rows in between are spaced evenly in `s` between the two side
//! rows, as many as needed for the widest station's lateral gap to stay within the width of
//! cut (the radial engagement, below the cutting-edge length). The section ends where the
//! cutter no longer fits: the first station, going toward the inlet, where the channel middle
//! `s = ½` is not clear (refined by bisection on `m`).
//!
//! Stations along the rows go from the section's outlet end toward the inlet: each next `m`
//! is the one where the largest hub-point distance over all rows equals the plunge step
//! (bisection). A section starting at the outlet begins with a lead-in station beyond it,
//! where the core disk lies outside the blank, so the first plunge of every row cuts with its
//! edge ring only.
//!
//! Cost: `FRAME_STATIONS × 4` channel-section angle searches once; per table station
//! `2 × SIDE_BISECTIONS` clearance queries (rayon over stations).

use crate::axial_depth::{Floor, RevolvedFloor};
use crate::conventional_axes;
use cam_plan::{DesignClearance, PlanError};
use impeller_model::{Impeller, RevolvedSurface};
use rayon::prelude::*;

/// Stations of the channel-angle table over the hub contour: 64 intervals keep the linear
/// interpolation of the blade-edge angles within ~1e-4 rad on impeller blades.
pub const FRAME_STATIONS: usize = 65;
/// Bisection steps on `s` for a side row: 2⁻¹³ of the channel width (≈ 0.012 mm on 100 mm,
/// well inside [`CLEARANCE_MARGIN_MM`]).
pub const SIDE_BISECTIONS: usize = 12;
/// Sampling tolerance (mm) of the clearance query while placing rows: coarse (a tenth of the
/// samples of the default 0.01 mm) because the query is the planner's dominant cost; the band
/// it may miss (half of it) stays inside [`CLEARANCE_MARGIN_MM`].
pub const ROW_SEARCH_SAMPLE_TOL_MM: f64 = 0.5;
/// Sampling tolerance (mm) of the final check of every position; a position passes when its
/// clearance is at least the blade allowance plus half of this (the band the query may miss),
/// which makes the check a proof of the allowance.
pub const FINAL_CHECK_SAMPLE_TOL_MM: f64 = 0.1;
/// Extra clearance (mm) kept over the blade allowance when placing side rows: half the
/// search query's sampling band ([`ROW_SEARCH_SAMPLE_TOL_MM`] / 2 = 0.25 mm, what its swept
/// balls may miss) plus 0.05 mm for the linear interpolation of `s(m)` between stations.
pub const CLEARANCE_MARGIN_MM: f64 = 0.3;
/// Bisection steps on `m` for station spacing and the section end (2⁻³⁰ of the range).
pub const M_BISECTIONS: usize = 30;
/// Smallest advance of a station spaced by its strokes' starts, as a fraction of the advance
/// the hub spacing allows: below it the start points jump between the stations (see
/// [`stations`]) and the hub spacing is kept.
pub const MIN_STATION_ADVANCE: f64 = 0.05;
/// Margin (mm) by which the lead-in plunge's core disk clears the blank radius.
pub const LEAD_IN_MARGIN_MM: f64 = 1.0;

/// Tabulated channel angles at one meridional fraction.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FrameRow {
    m: f64,
    hub: (f64, f64),
    shroud: (f64, f64),
}

/// The channel coordinates `(m, s)` of channel 0 on hub and shroud.
#[derive(Debug, Clone)]
pub struct ChannelFrame<'a> {
    impeller: &'a Impeller,
    rows: Vec<FrameRow>,
}

/// The linear continuation through `a` and `b` (angles unwrapped from `b`) at fraction `m`.
fn extrapolate(a: &FrameRow, b: &FrameRow, m: f64) -> FrameRow {
    let f = (m - b.m) / (b.m - a.m);
    let near =
        |x: f64, y: f64| x - std::f64::consts::TAU * ((x - y) / std::f64::consts::TAU).round();
    let lin = |x: f64, y: f64| {
        let x = near(x, y);
        y + f * (y - x)
    };
    FrameRow {
        m,
        hub: (lin(a.hub.0, b.hub.0), lin(a.hub.1, b.hub.1)),
        shroud: (lin(a.shroud.0, b.shroud.0), lin(a.shroud.1, b.shroud.1)),
    }
}

fn contour_param(wall: &RevolvedSurface, m: f64) -> f64 {
    let c = wall.meridional();
    let (a, b) = c.domain();
    if m > 1.0 {
        b + (m - 1.0) * (b - a)
    } else if m < 0.0 {
        a + m * (b - a)
    } else {
        c.param_at_fraction(m)
    }
}

impl<'a> ChannelFrame<'a> {
    /// Tabulates channel 0 of `impeller`. Errors when a bounding blade side misses the hub
    /// or shroud at some station (the blades must span the contours from inlet to outlet).
    pub fn new(impeller: &'a Impeller, operation: &str) -> Result<Self, PlanError> {
        let channel = impeller.channel(0);
        let stations: Vec<f64> = (0..FRAME_STATIONS)
            .map(|k| k as f64 / (FRAME_STATIONS - 1) as f64)
            .collect();
        let rows: Vec<Option<FrameRow>> = stations
            .par_iter()
            .map(|&m| {
                // Stay a hair inside the contour ends where edge searches are bracketed.
                let mm = m.clamp(1e-6, 1.0 - 1e-6);
                // A station beyond a blade's end is normal here (filled in below): `.ok()`.
                let h = channel
                    .section(
                        impeller.hub(),
                        impeller.hub().meridional().param_at_fraction(mm),
                    )
                    .ok()?;
                let s = channel
                    .section(
                        impeller.shroud(),
                        impeller.shroud().meridional().param_at_fraction(mm),
                    )
                    .ok()?;
                Some(FrameRow {
                    m,
                    hub: (h.left, h.right),
                    shroud: (s.left, s.right),
                })
            })
            .collect();
        // Blades may stop a little short of the contour ends: stations there take the
        // linear continuation of the nearest two valid ones; a gap inside is an error.
        let valid: Vec<usize> = (0..rows.len()).filter(|&k| rows[k].is_some()).collect();
        let (Some(&first), Some(&last)) = (valid.first(), valid.last()) else {
            return Err(PlanError::geometry(
                operation,
                "channel 0",
                "the bounding blade sides do not meet the hub and the shroud",
            ));
        };
        if valid.len() < 2 || last - first + 1 != valid.len() {
            let k = (first..=last).find(|&k| rows[k].is_none()).unwrap_or(last);
            return Err(PlanError::geometry(
                operation,
                format!("channel 0 at meridional fraction {:.3}", stations[k]),
                "a bounding blade side does not meet the hub or the shroud there",
            ));
        }
        let mut out: Vec<FrameRow> = rows.iter().flatten().copied().collect();
        for k in (0..first).rev() {
            out.insert(0, extrapolate(&out[1], &out[0], stations[k]));
        }
        for &m in &stations[last + 1..] {
            let n = out.len();
            out.push(extrapolate(&out[n - 2], &out[n - 1], m));
        }
        // Unwrap angles continuously along m.
        for k in 1..out.len() {
            let prev = out[k - 1];
            let fix = |a: f64, b: f64| {
                b - std::f64::consts::TAU * ((b - a) / std::f64::consts::TAU).round()
            };
            out[k].hub.0 = fix(prev.hub.0, out[k].hub.0);
            out[k].hub.1 =
                out[k].hub.0 + (out[k].hub.1 - out[k].hub.0).rem_euclid(std::f64::consts::TAU);
            out[k].shroud.0 = fix(prev.shroud.0, out[k].shroud.0);
            out[k].shroud.1 = out[k].shroud.0
                + (out[k].shroud.1 - out[k].shroud.0).rem_euclid(std::f64::consts::TAU);
        }
        // The shroud angles continue the hub ones (same branch).
        for r in &mut out {
            let d = r.shroud.0 - r.hub.0;
            let shift = std::f64::consts::TAU * (d / std::f64::consts::TAU).round();
            r.shroud.0 -= shift;
            r.shroud.1 -= shift;
        }
        Ok(Self {
            impeller,
            rows: out,
        })
    }

    /// The impeller.
    pub fn impeller(&self) -> &'a Impeller {
        self.impeller
    }

    /// (left, right) angles on hub and shroud at fraction `m` (linear between stations,
    /// continued linearly beyond both ends).
    fn angles(&self, m: f64) -> ((f64, f64), (f64, f64)) {
        let n = self.rows.len();
        let k = ((m * (n - 1) as f64).floor() as isize).clamp(0, n as isize - 2) as usize;
        let (a, b) = (self.rows[k], self.rows[k + 1]);
        let f = (m - a.m) / (b.m - a.m);
        let lerp = |x: f64, y: f64| x + f * (y - x);
        (
            (lerp(a.hub.0, b.hub.0), lerp(a.hub.1, b.hub.1)),
            (lerp(a.shroud.0, b.shroud.0), lerp(a.shroud.1, b.shroud.1)),
        )
    }

    /// Hub contour parameter and polar angle of `(m, s)`.
    pub fn hub_uv(&self, m: f64, s: f64) -> (f64, f64) {
        let (h, _) = self.angles(m);
        (contour_param(self.impeller.hub(), m), h.0 + s * (h.1 - h.0))
    }

    /// The hub point `M(m, s)`.
    pub fn hub_point(&self, m: f64, s: f64) -> cam_core::Vector3 {
        let (u, v) = self.hub_uv(m, s);
        RevolvedFloor::new(self.impeller.hub().meridional())
            .eval(u, v)
            .p
    }

    /// The isoparametric shroud point `W(m, s)`.
    pub fn shroud_point(&self, m: f64, s: f64) -> cam_core::Vector3 {
        let (_, w) = self.angles(m);
        let u = contour_param(self.impeller.shroud(), m);
        RevolvedFloor::new(self.impeller.shroud().meridional())
            .eval(u, w.0 + s * (w.1 - w.0))
            .p
    }

    /// Hub channel width (mm, along the parallel circle) at fraction `m`.
    pub fn hub_width(&self, m: f64) -> f64 {
        let (h, _) = self.angles(m);
        let r = self.hub_point(m, 0.5);
        r.x.hypot(r.y) * (h.1 - h.0)
    }
}

/// The rows of one section: side-row tables and the number of rows.
#[derive(Debug, Clone)]
pub struct SectionRows {
    /// Table stations `m` (decreasing: outlet → inlet) with the side rows' `s` there.
    table: Vec<(f64, f64, f64)>,
    /// Number of rows (≥ 1; 1 when the side rows coincide).
    pub count: usize,
    /// Meridional fraction of the section's outlet end.
    pub start: f64,
    /// Meridional fraction of the section's inlet end.
    pub end: f64,
}

impl SectionRows {
    /// `s` of row `j` at fraction `m` (rows from the suction side, `j = 0`, to the pressure
    /// side, `j = count − 1`).
    pub fn s(&self, j: usize, m: f64) -> f64 {
        let t = &self.table;
        // Table is ordered by decreasing m; clamp beyond both ends.
        let (lo, hi) = if m >= t[0].0 {
            (t[0].1, t[0].2)
        } else if m <= t[t.len() - 1].0 {
            (t[t.len() - 1].1, t[t.len() - 1].2)
        } else {
            let k = t.partition_point(|e| e.0 > m).clamp(1, t.len() - 1);
            let (a, b) = (t[k - 1], t[k]);
            let f = (m - a.0) / (b.0 - a.0);
            (a.1 + f * (b.1 - a.1), a.2 + f * (b.2 - a.2))
        };
        if self.count <= 1 {
            0.5 * (lo + hi)
        } else {
            lo + (hi - lo) * j as f64 / (self.count - 1) as f64
        }
    }
}

/// What the row planner needs besides the frame.
#[derive(Debug, Clone, Copy)]
pub struct RowSettings<'a> {
    /// Clearance query of the operation's tool, blades only.
    pub blades: &'a DesignClearance<'a>,
    /// The posture builder (tool, allowances, clearance heights).
    pub posture: &'a conventional_axes::PostureBuilder<'a>,
    /// Blade allowance (mm).
    pub blade_allowance_mm: f64,
    /// Largest lateral distance between neighbouring rows (mm).
    pub width_of_cut_mm: f64,
    /// Table stations over the section.
    pub stations: usize,
    /// Operation name (errors).
    pub operation: &'a str,
}

/// Whether the conventional posture at `(m, s)` exists and keeps the blade allowance plus
/// [`CLEARANCE_MARGIN_MM`] (the query stops at the first failing sample).
fn is_clear(frame: &ChannelFrame<'_>, set: &RowSettings<'_>, m: f64, s: f64) -> bool {
    set.posture.conventional(frame, m, s).is_ok_and(|p| {
        set.blades
            .is_clear(&p.cl, set.blade_allowance_mm + CLEARANCE_MARGIN_MM)
    })
}

/// Whether the cutter fits at fraction `m` (the channel middle is clear).
fn fits(frame: &ChannelFrame<'_>, set: &RowSettings<'_>, m: f64) -> bool {
    is_clear(frame, set, m, 0.5)
}

/// The side rows' `s` at `m`: (suction, pressure), by bisection from the channel middle.
fn side_rows_at(frame: &ChannelFrame<'_>, set: &RowSettings<'_>, m: f64) -> Option<(f64, f64)> {
    let mut out = [0.0; 2];
    for (k, (blocked, free)) in [(0.0, 0.5), (1.0, 0.5)].into_iter().enumerate() {
        let (mut b, mut f) = (blocked, free);
        if is_clear(frame, set, m, b) {
            out[k] = b;
            continue;
        }
        for _ in 0..SIDE_BISECTIONS {
            let mid = 0.5 * (b + f);
            if is_clear(frame, set, m, mid) {
                f = mid;
            } else {
                b = mid;
            }
        }
        out[k] = f;
    }
    Some((out[0], out[1]))
}

/// Plans the rows of a section from `start` toward the inlet, ending at `end` or, when
/// `None`, where the cutter no longer fits. Errors when the cutter does not fit at the start.
pub fn plan_rows(
    frame: &ChannelFrame<'_>,
    set: &RowSettings<'_>,
    start: f64,
    end: Option<f64>,
) -> Result<SectionRows, PlanError> {
    let top = start.min(1.0);
    if !fits(frame, set, top) {
        return Err(PlanError::geometry(
            set.operation,
            format!("section start (meridional fraction {top:.4})"),
            "the cutter does not fit between the blades with the blade allowance there",
        ));
    }
    let end = match end {
        Some(e) => e,
        None => {
            // Walk the table stations toward the inlet, then bisect the first misfit.
            let n = set.stations.max(2);
            let mut last_fit = top;
            let mut misfit = None;
            for k in 1..=n {
                let m = top * (1.0 - k as f64 / n as f64);
                if fits(frame, set, m) {
                    last_fit = m;
                } else {
                    misfit = Some(m);
                    break;
                }
            }
            match misfit {
                None => last_fit,
                Some(mut lo) => {
                    let mut hi = last_fit;
                    for _ in 0..M_BISECTIONS {
                        let mid = 0.5 * (lo + hi);
                        if fits(frame, set, mid) {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                        if hi - lo < 1e-6 {
                            break;
                        }
                    }
                    hi
                }
            }
        }
    };
    if end >= top || end.is_nan() {
        return Err(PlanError::geometry(
            set.operation,
            format!("section {top:.4} → {end:.4}"),
            "the section is empty (its inlet end is not below its outlet end)",
        ));
    }
    let n = set.stations.max(2);
    let ms: Vec<f64> = (0..=n)
        .map(|k| top + (end - top) * k as f64 / n as f64)
        .collect();
    let sides: Vec<Option<(f64, f64)>> = ms
        .par_iter()
        .map(|&m| side_rows_at(frame, set, m))
        .collect();
    let mut table = Vec::with_capacity(ms.len());
    let mut widest: f64 = 0.0;
    for (m, s) in ms.iter().zip(sides) {
        let Some((a, b)) = s else {
            return Err(PlanError::geometry(
                set.operation,
                format!("meridional fraction {m:.4}"),
                "no conventional posture of the cutter exists there",
            ));
        };
        let (a, b) = if a <= b {
            (a, b)
        } else {
            (0.5 * (a + b), 0.5 * (a + b))
        };
        widest = widest.max((b - a) * frame.hub_width(*m));
        table.push((*m, a, b));
    }
    let count = (widest / set.width_of_cut_mm).ceil() as usize + 1;
    Ok(SectionRows {
        table,
        count: count.max(1),
        start,
        end,
    })
}

/// The stations of a section (outlet → inlet): consecutive plunges of every row at most
/// `step_mm` apart both at the hub and at the start of their strokes (`start_point(j, m)`:
/// where row `j`'s plunge at `m` starts, `None` when unknown). A plunge's centre disk stays
/// inside the previous plunge's hole along the whole stroke when both ends are that close
/// (the distance between corresponding points of two lines is convex along them, so its
/// largest value is at an end; `step_mm` is below the cutting-edge length `R − r_core`).
/// Where the axes turn between stations (near-radial strokes at the inlet), the start points
/// spread further than the hub points and set the spacing; where they jump (the stroke's top
/// moves to another face of a non-convex stock) the hub spacing is kept
/// ([`MIN_STATION_ADVANCE`]). The start points come from `start_point`, a cheap proxy (e.g.
/// [`crate::conventional_axes::PostureBuilder::stroke_top`]).
///
/// The first station is the first meridional fraction `m ≥ start` (start clamped to the
/// outlet, 1), in steps of 0.01 toward the outlet (beyond it along the hub's tangent
/// extension), where `first_clear(m)` holds: the caller's test that no row's first plunge
/// drills with its non-cutting centre (see
/// [`crate::operation::PlungeRoughing::plan_section`]); at most 2 beyond the start.
pub fn stations(
    frame: &ChannelFrame<'_>,
    rows: &SectionRows,
    step_mm: f64,
    first_clear: &dyn Fn(f64) -> bool,
    start_point: &dyn Fn(usize, f64) -> Option<cam_core::Vector3>,
) -> Vec<f64> {
    let mut first = rows.start.min(1.0);
    let mut guard = 0;
    while !first_clear(first) && guard < 200 {
        first += 0.01;
        guard += 1;
    }
    // The points of station `m` (hub and stroke start per row), computed once per station.
    let points = |m: f64| -> Vec<(cam_core::Vector3, Option<cam_core::Vector3>)> {
        (0..rows.count)
            .map(|j| (frame.hub_point(m, rows.s(j, m)), start_point(j, m)))
            .collect()
    };
    // Largest distance from station `a`'s points to station `b`'s, at the hub only or at
    // the hub and the stroke starts (a posture solve per row: done only where it matters).
    let dist = |a: &[(cam_core::Vector3, Option<cam_core::Vector3>)], b: f64, tops: bool| {
        a.iter()
            .enumerate()
            .map(|(j, (hub, top))| {
                let d_hub = (hub - frame.hub_point(b, rows.s(j, b))).norm();
                let d_top = match (tops, top) {
                    (true, Some(x)) => start_point(j, b).map_or(0.0, |y| (x - y).norm()),
                    _ => 0.0,
                };
                d_hub.max(d_top)
            })
            .fold(0.0, f64::max)
    };
    let bisect = |here: &[(cam_core::Vector3, Option<cam_core::Vector3>)],
                  (mut lo, mut hi): (f64, f64),
                  tops: bool| {
        for _ in 0..M_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if dist(here, mid, tops) > step_mm {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    };
    let mut out = vec![first];
    let mut m = first;
    while m > rows.end {
        let here = points(m);
        if dist(&here, rows.end, true) <= step_mm {
            out.push(rows.end);
            break;
        }
        // The hub spacing first; where the stroke starts spread further, the bisection
        // again between that station and this one with both (the full distance is never
        // below the hub distance, so the station moves toward this one).
        let mut next = bisect(&here, (rows.end, m), false);
        if dist(&here, next, true) > step_mm {
            // Where the stroke start jumps (the axis line leaves a non-convex stock at
            // another face) no spacing satisfies it: keep the hub spacing there.
            let closer = bisect(&here, (next, m), true);
            if m - closer > MIN_STATION_ADVANCE * (m - next) {
                next = closer;
            }
        }
        m = next;
        out.push(m);
    }
    out
}
