//! The areas of one level (paper 003) between the offset sides, trimmed to the lanes where
//! the cutter fits, with their triangle and isoparametric paths in the developed plane
//! (module docs of [`super`], steps 2–4).

use super::axes::Axes;
use super::fit::{lanes, FitQuery, FIT_SCAN_MAX_MM};
use super::operation::ChannelRoughing;
use super::plan2d::{self, Path2, Region};
use super::sides::{Bound, BOUNDARY_SAMPLES};
use super::triangle;
use cam_core::CutterShape;
use cam_plan::{PlanContext, PlanError};
use impeller_model::levels::{offset_surface_on_level, DepthLevel};

/// Largest spacing of path points (and of the grid sections where the cutter's fit is
/// sampled) along the flow, in radii of the cutter's end (ball or tool radius), when the
/// chord rule allows more: 1 mm for the fixtures' R1.5 ends, as it was, 2 mm for an R3 end
/// on a design twice that size (the NASA HECC impeller's channels), where 1 mm points only
/// doubled the postures and motion checks of the same cut.
pub(super) const MAX_POINT_SPACING_RADII: f64 = 2.0 / 3.0;

/// Boundary of an area on one level, tabulated on the area's s grid.
pub(super) struct Tab {
    pub(super) y: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) ruled: usize,
}

/// An area of one level as bounded by the offset ruled sides, before trimming: the region
/// whose boundaries and rulings define the tool axis (module docs, step 5) of its lanes.
pub(super) struct Field {
    pub(super) region: Region,
    pub(super) left: Tab,
    pub(super) right: Tab,
}

/// One planned lane (a graph region where the cutter fits) of one area of one level.
pub(super) struct AreaPlan {
    pub(super) level: usize,
    /// Index of the area's [`Field`] in its level.
    pub(super) field: usize,
    /// Triangle paths as planned (inlet → outlet; ordered and linked when located).
    pub(super) tri: Vec<Path2>,
    /// Isoparametric baseline paths over the lane (inlet → outlet).
    pub(super) iso: Vec<Path2>,
    pub(super) region: Region,
    /// The path interval of the lane's level (mm).
    pub(super) step: f64,
}

pub(super) struct LevelPlan {
    pub(super) level: DepthLevel,
    /// The level's bounding sides (module docs, step 1).
    pub(super) bounds: Vec<Bound>,
    pub(super) fields: Vec<Field>,
    pub(super) areas: Vec<AreaPlan>,
    /// The whole-channel isoparametric baseline, clipped to the planned lanes.
    pub(super) channel_iso: Vec<Path2>,
    /// Developed area between the offset ruled sides (mm²).
    pub(super) area_mm2: f64,
    /// Developed area of the planned lanes (mm²).
    pub(super) planned_mm2: f64,
    /// Largest spacing of path points along the flow (mm); links are put on the level at it.
    pub(super) spacing: f64,
}

impl ChannelRoughing {
    /// Path interval on `level` for the tool and target scallop (module docs, step 3).
    pub(super) fn interval(
        &self,
        ctx: &PlanContext<'_>,
        level: &DepthLevel,
    ) -> Result<f64, PlanError> {
        let h = self.params.scallop_mm;
        let m = level.surface.meridional();
        let mut kappa: f64 = 0.0;
        for i in 0..=32 {
            let t = m.param_at_fraction(i as f64 / 32.0);
            let n = m.normal(t);
            let r = m.point(t)[1];
            kappa = kappa.max(n[1] / r);
        }
        let step = match ctx.tool.cutter.shape {
            CutterShape::BallEnd { radius }
            | CutterShape::TaperedBallEnd {
                ball_radius: radius,
                ..
            } => cam_core::ball_step_over(radius, kappa, h),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => cam_core::bull_nose_step_over(
                radius,
                corner_radius,
                self.params.max_tilt_deg.to_radians(),
                kappa,
                h,
            ),
            _ => unreachable_shape(),
        }
        .map_err(|e| PlanError::param(&self.name, "scallop_mm", e.to_string()))?;
        Ok(match ctx.process.width_of_cut_mm {
            Some(w) if w > 0.0 => step.min(w),
            _ => step,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn plan_level(
        &self,
        ctx: &PlanContext<'_>,
        j: usize,
        level: DepthLevel,
        bounds: Vec<Bound>,
        fit: &FitQuery<'_>,
        fit_min: f64,
        step_scale: f64,
    ) -> Result<LevelPlan, PlanError> {
        let place = |b: &Bound| format!("level {j}, {}", b.label);
        let mut curves = Vec::with_capacity(bounds.len());
        for b in &bounds {
            let ((u0, u1), _) = b.ruled.domain();
            let c = offset_surface_on_level(&b.ruled, b.offset, &level, (u0, u1), BOUNDARY_SAMPLES)
                .map_err(|e| self.geo(place(b), e.to_string()))?;
            // (s, θ, u) samples of the boundary (θ unwrapped along the curve).
            let mut tab: Vec<(f64, f64, f64)> = Vec::with_capacity(c.samples.len());
            let mut prev: Option<f64> = None;
            for &(u, v) in &c.samples {
                let d = b.ruled.derivs2(u, v);
                let nn = d.su.cross(&d.sv);
                let p = d.p + nn * (b.offset / nn.norm());
                let (s, th) = level.developed(&p);
                let th = match prev {
                    Some(pv) => {
                        pv + (th - pv + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI
                    }
                    None => th,
                };
                prev = Some(th);
                tab.push((s, th, u));
            }
            // Keep the longest run advancing from inlet to outlet (the sides' u domain
            // reaches a little past the edges, where the offset may turn back).
            let (mut best, mut start) = ((0usize, 1usize), 0usize);
            for i in 1..=tab.len() {
                if i == tab.len() || tab[i].0 <= tab[i - 1].0 {
                    if i - start > best.1 - best.0 {
                        best = (start, i);
                    }
                    start = i;
                }
            }
            if best.1 - best.0 < 4 {
                return Err(self.geo(place(b), "boundary does not advance from inlet to outlet"));
            }
            curves.push(tab[best.0..best.1].to_vec());
        }
        let step = self.interval(ctx, &level)? * step_scale;
        let spacing = (8.0 * min_radius(&level) * ctx.tolerances.chord_tol)
            .sqrt()
            .min(MAX_POINT_SPACING_RADII * end_radius(&ctx.tool.cutter.shape));
        // Areas (paper 003): without splitter one; with, upstream of its leading edge and
        // the two sub-channels.
        let s_lo = curves[0][0].0.max(curves[1][0].0);
        let s_hi = curves[0]
            .last()
            .map_or(0.0, |x| x.0)
            .min(curves[1].last().map_or(0.0, |x| x.0));
        let mut specs: Vec<(usize, usize, f64, f64)> = Vec::new();
        if curves.len() == 4 {
            let s_le = curves[2][0].0.max(curves[3][0].0).max(s_lo);
            let s_te = curves[2].last().map_or(s_hi, |x| x.0).min(s_hi);
            if s_le > s_lo + spacing {
                specs.push((0, 1, s_lo, s_le));
            }
            specs.push((0, 2, s_le, s_te));
            specs.push((3, 1, s_le, s_te));
        } else {
            specs.push((0, 1, s_lo, s_hi));
        }
        let mut areas = Vec::new();
        let mut fields: Vec<Field> = Vec::new();
        let mut area_mm2 = 0.0;
        let mut planned_mm2 = 0.0;
        for (a, b, s0, s1) in specs {
            if s1 <= s0 {
                continue;
            }
            let n = (((s1 - s0) / spacing).ceil() as usize).max(2) + 1;
            let s: Vec<f64> = (0..n)
                .map(|i| s0 + (s1 - s0) * i as f64 / (n - 1) as f64)
                .collect();
            let left = tabulate(&curves[a], &s, a, &level);
            let mut right = tabulate(&curves[b], &s, b, &level);
            unwrap_to_left(&mut right.y, &left.y, &s, &level);
            let field = Field {
                region: Region {
                    s,
                    left: left.y.clone(),
                    right: right.y.clone(),
                },
                left,
                right,
            };
            area_mm2 += trapezoid(&field.region.s, |i| {
                (field.region.right[i] - field.region.left[i]).max(0.0)
            });
            // Trim by where the cutter fits (module docs, step 4): the fitting intervals of
            // every grid section, then lanes of sections with the same number of intervals.
            let axes = Axes {
                lv: &level,
                field: &field,
                bounds: &bounds,
                max_tilt: self.params.max_tilt_deg.to_radians(),
                level: j,
            };
            let scan = (0.5 * step).min(FIT_SCAN_MAX_MM);
            let mut sections: Vec<Vec<(f64, f64)>> = Vec::with_capacity(n);
            for i in 0..n {
                sections.push(self.fit_intervals(fit, &axes, i, scan, fit_min)?);
            }
            let area_place = format!("level {j}, area {} / {}", bounds[a].label, bounds[b].label);
            for (lo, hi, lane) in lanes(&sections, &field.region) {
                let region = Region {
                    s: field.region.s[lo..hi].to_vec(),
                    left: sections[lo..hi].iter().map(|x| x[lane].0).collect(),
                    right: sections[lo..hi].iter().map(|x| x[lane].1).collect(),
                };
                planned_mm2 += trapezoid(&region.s, |i| region.right[i] - region.left[i]);
                let tri = triangle::triangle(&region, step)
                    .map_err(|e| self.geo(&area_place, e.to_string()))?;
                let iso = plan2d::isoparametric(&region, step)
                    .map_err(|e| self.geo(&area_place, e.to_string()))?;
                areas.push(AreaPlan {
                    level: j,
                    field: fields.len(),
                    tri,
                    iso,
                    region,
                    step,
                });
            }
            fields.push(field);
        }
        // The isoparametric baseline over the whole channel (module docs, metrics): paths of
        // constant fraction between the two main blades' offset sides from inlet to outlet,
        // as many as the widest section needs, kept where they run inside a planned lane.
        let mut channel_iso = Vec::new();
        if s_hi > s_lo {
            let n = (((s_hi - s_lo) / spacing).ceil() as usize).max(2) + 1;
            let s: Vec<f64> = (0..n)
                .map(|i| s_lo + (s_hi - s_lo) * i as f64 / (n - 1) as f64)
                .collect();
            let left = tabulate(&curves[0], &s, 0, &level);
            let mut right = tabulate(&curves[1], &s, 1, &level);
            unwrap_to_left(&mut right.y, &left.y, &s, &level);
            let right_y: Vec<f64> = right
                .y
                .iter()
                .zip(&left.y)
                .map(|(r, l)| r.max(*l))
                .collect();
            let whole = Region {
                s,
                left: left.y,
                right: right_y,
            };
            let paths = plan2d::isoparametric(&whole, step)
                .map_err(|e| self.geo(format!("level {j}, whole channel"), e.to_string()))?;
            let lanes: Vec<&Region> = areas.iter().map(|a| &a.region).collect();
            channel_iso = plan2d::clip_to_regions(paths, &lanes);
        }
        Ok(LevelPlan {
            level,
            bounds,
            fields,
            areas,
            channel_iso,
            area_mm2,
            planned_mm2,
            spacing,
        })
    }
}

pub(super) fn unreachable_shape() -> Result<f64, cam_core::ContactError> {
    Err(cam_core::ContactError::Invalid {
        field: "shape",
        value: f64::NAN,
        reason: "channel roughing needs a ball-end, tapered ball-end or bull-nose cutter",
    })
}

/// The radius of the cutter's end: the ball's for ball and tapered ball ends, the tool's for
/// a bull nose.
pub(super) fn end_radius(shape: &CutterShape) -> f64 {
    match *shape {
        CutterShape::BallEnd { radius }
        | CutterShape::BullNose { radius, .. }
        | CutterShape::TaperedBallEnd {
            ball_radius: radius,
            ..
        } => radius,
        _ => 0.0,
    }
}

pub(super) fn min_radius(level: &DepthLevel) -> f64 {
    let m = level.surface.meridional();
    (0..=32)
        .map(|i| m.point_at_fraction(i as f64 / 32.0)[1])
        .fold(f64::INFINITY, f64::min)
}

/// Moves each right boundary `y` by whole turns of its parallel (`2π·r(s)`) to the turn
/// nearest the left one: the channel spans less than half a turn, so a negative width then
/// means the offset boundaries cross.
pub(super) fn unwrap_to_left(right: &mut [f64], left: &[f64], s: &[f64], level: &DepthLevel) {
    let tau = std::f64::consts::TAU;
    for ((ry, ly), &si) in right.iter_mut().zip(left).zip(s) {
        let turn = tau * level.radius_at(si);
        *ry = ly + (*ry - ly + 0.5 * turn).rem_euclid(turn) - 0.5 * turn;
    }
}

/// Boundary y = r(s)·θ(s) and ruled u at each grid s (linear in the boundary's samples,
/// which are dense: the developed curve is their interpolant).
pub(super) fn tabulate(
    tab: &[(f64, f64, f64)],
    s: &[f64],
    ruled: usize,
    level: &DepthLevel,
) -> Tab {
    let mut y = Vec::with_capacity(s.len());
    let mut u = Vec::with_capacity(s.len());
    for &x in s {
        let k = tab.partition_point(|t| t.0 <= x).clamp(1, tab.len() - 1);
        let (a, b) = (tab[k - 1], tab[k]);
        let t = ((x - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
        let th = a.1 + t * (b.1 - a.1);
        y.push(level.radius_at(x) * th);
        u.push(a.2 + t * (b.2 - a.2));
    }
    Tab { y, u, ruled }
}

/// Trapezoidal integral over the grid `s` of the values `f(i)` at its points.
pub(super) fn trapezoid(s: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    (1..s.len())
        .map(|i| 0.5 * (f(i - 1) + f(i)) * (s[i] - s[i - 1]))
        .sum()
}
