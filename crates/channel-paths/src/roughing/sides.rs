//! The bounding sides of one level: each blade side that bounds the channel, ruled over the
//! span band the level's slab reaches, pushed out by that band's deviation and offset by the
//! cutter radius plus the allowances (module docs of [`super`], step 1).

use super::operation::ChannelRoughing;
use cam_plan::{PlanContext, PlanError};
use impeller_model::levels::{offset_surface_on_level, DepthLevel};
use impeller_model::ruled::{prolong_rulings, ruled_approximation};
use impeller_model::{Blade, Impeller, Side};
use nurbs::NurbsSurface;

/// Samples along the flow of each boundary curve: the ruled blades are cubic in u with a
/// handful of spans; 61 samples keep the interpolated boundary within µm of the true one
/// (checked by the level tests of `impeller-model`).
pub(super) const BOUNDARY_SAMPLES: usize = 61;

/// A bounding side: its ruled approximation and the offset that keeps the cutter off it.
pub(super) struct Bound {
    pub(super) label: String,
    pub(super) ruled: NurbsSurface,
    pub(super) offset: f64,
}

pub(super) fn side_v_range(
    imp: &Impeller,
    blade: &Blade,
    side: Side,
) -> Result<(f64, f64), impeller_model::ModelError> {
    match blade.design() {
        Some(_) => Ok(blade.hub_shroud_v(side)),
        None => imp.span_v_range(blade, side),
    }
}

impl ChannelRoughing {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn bound(
        &self,
        ctx: &PlanContext<'_>,
        blade: &Blade,
        side: Side,
        label: &str,
        radius: f64,
        doc: f64,
        band: (&DepthLevel, Option<&DepthLevel>),
    ) -> Result<Bound, PlanError> {
        let imp = ctx.impeller;
        let full = side_v_range(imp, blade, side).map_err(|e| {
            self.geo(
                label,
                format!("blade side does not reach both hub and shroud: {e}"),
            )
        })?;
        let v = level_band(blade.side(side), full, band);
        let ruled =
            ruled_approximation(blade, side, v).map_err(|e| PlanError::model(&self.name, e))?;
        // Orient the offset along the blade's outward normal (into the channel).
        let ((u0, u1), _) = ruled.surface.domain();
        let um = 0.5 * (u0 + u1);
        let d = ruled.surface.derivs2(um, 0.5);
        let n = d.su.cross(&d.sv);
        let out = blade
            .outward_normal(side, um, 0.5 * (v.0 + v.1))
            .ok_or_else(|| self.geo(label, "blade side normal undefined"))?;
        let sign = if n.dot(&out) >= 0.0 { 1.0 } else { -1.0 };
        let delta = radius + ctx.process.blade_allowance_mm + ruled.allowance_mm;
        // The offset moves the surface by δ across its rulings, so where the blade leans from
        // the hub (or shroud) normal the offset surface's edge lies up to δ off the hub (or
        // shroud): prolong every ruling beyond both edges by δ plus one depth of cut so that
        // the offset meets the hub level and the first level below the shroud (module docs,
        // step 1).
        let shortest = (0..=BOUNDARY_SAMPLES)
            .map(|i| {
                let u = u0 + (u1 - u0) * i as f64 / BOUNDARY_SAMPLES as f64;
                (ruled.surface.point(u, 1.0) - ruled.surface.point(u, 0.0)).norm()
            })
            .fold(f64::INFINITY, f64::min);
        if !(shortest.is_finite() && shortest > 0.0) {
            return Err(self.geo(label, "ruled approximation has a degenerate ruling"));
        }
        let e = (delta + doc) / shortest;
        let ruled =
            prolong_rulings(&ruled.surface, e, e).map_err(|e| PlanError::model(&self.name, e))?;
        Ok(Bound {
            label: label.into(),
            ruled,
            offset: sign * delta,
        })
    }
}

/// The span band of a blade side that one level's slab reaches (module docs, step 1): side
/// parameters v from the lowest crossing of the side with the level `band.0` to the highest
/// with the level above `band.1` (the shroud edge for the first level), within `full` (the
/// side's hub–shroud range). A crossing that cannot be found leaves that end of `full`.
pub(super) fn level_band(
    side: &NurbsSurface,
    full: (f64, f64),
    band: (&DepthLevel, Option<&DepthLevel>),
) -> (f64, f64) {
    let ((u0, u1), _) = side.domain();
    let crossing_vs = |lv: &DepthLevel| {
        offset_surface_on_level(side, 0.0, lv, (u0, u1), BOUNDARY_SAMPLES)
            .ok()
            .map(|c| c.samples.iter().map(|&(_, v)| v).collect::<Vec<f64>>())
    };
    let lo = crossing_vs(band.0)
        .map(|vs| vs.into_iter().fold(f64::INFINITY, f64::min))
        .filter(|v| v.is_finite())
        .map_or(full.0, |v| v.max(full.0));
    let hi = band
        .1
        .and_then(crossing_vs)
        .map(|vs| vs.into_iter().fold(f64::NEG_INFINITY, f64::max))
        .filter(|v| v.is_finite())
        .map_or(full.1, |v| v.min(full.1));
    if lo < hi {
        (lo, hi)
    } else {
        full
    }
}
