//! The material the job's earlier operations leave above the design, as an operation that
//! machines what is left (rest finishing) reads it.
//!
//! The pipeline simulates the earlier operations' tool paths on the blank (the verifier's
//! tri-dexel stock, `machining-sim`) and measures the residual at the verifier's design
//! samples: map grids over the hub, every blade side, tip and fillet. This crate never depends
//! on the verifier (DESIGN §2); the pipeline hands the measured grids over as plain data in
//! [`RemainingMaterial`].

/// One design surface's sample grid with the residual measured above each sample.
#[derive(Debug, Clone, PartialEq)]
pub struct RestGrid {
    /// Surface name as in `verification_maps.json` (`hub`, `main0_pressure`,
    /// `splitter3_fillet_suction`, …).
    pub surface: String,
    /// Samples along the first grid direction.
    pub nu: usize,
    /// Samples along the second grid direction.
    pub nv: usize,
    /// Sample points on the design surface (workpiece frame, mm), row-major: index `j·nu + i`.
    pub points: Vec<[f64; 3]>,
    /// Residual (mm) above each sample: the stock's height along the surface normal (capped
    /// by the verifier); `None` where the sample is not part of the surface (under a fillet,
    /// outside a trimmed edge).
    pub residual_mm: Vec<Option<f64>>,
}

impl RestGrid {
    /// The sample at `(i, j)`.
    pub fn point(&self, i: usize, j: usize) -> Option<[f64; 3]> {
        (i < self.nu && j < self.nv)
            .then(|| self.points.get(j * self.nu + i).copied())
            .flatten()
    }

    /// The residual at `(i, j)` (`None` outside the grid or where the sample is absent).
    pub fn residual(&self, i: usize, j: usize) -> Option<f64> {
        (i < self.nu && j < self.nv)
            .then(|| self.residual_mm.get(j * self.nu + i).copied().flatten())
            .flatten()
    }

    /// The surface area (mm²) a sample stands for: the product of half the distances to its
    /// neighbours on either side in each grid direction (one-sided at the grid's borders).
    /// The grids are smooth parametrisations, so this is the area of the sample's cell to
    /// first order in the spacing. O(1).
    pub fn cell_area_mm2(&self, i: usize, j: usize) -> f64 {
        let span = |a: Option<[f64; 3]>, b: Option<[f64; 3]>, halves: f64| match (a, b) {
            (Some(a), Some(b)) => {
                let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / halves
            }
            _ => 0.0,
        };
        let along = |prev: Option<[f64; 3]>, here: Option<[f64; 3]>, next: Option<[f64; 3]>| match (
            prev.is_some(),
            next.is_some(),
        ) {
            (true, true) => span(prev, next, 2.0),
            (true, false) => span(prev, here, 1.0),
            (false, true) => span(here, next, 1.0),
            (false, false) => 0.0,
        };
        let here = self.point(i, j);
        let du = along(
            i.checked_sub(1).and_then(|i| self.point(i, j)),
            here,
            self.point(i + 1, j),
        );
        let dv = along(
            j.checked_sub(1).and_then(|j| self.point(i, j)),
            here,
            self.point(i, j + 1),
        );
        du * dv
    }
}

/// The stock the earlier operations of a job leave, measured above the design: what an
/// operation that machines the rest reads from [`crate::PlanContext::remaining`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RemainingMaterial {
    /// The operations whose cuts made this stock, in machining order.
    pub after: Vec<String>,
    /// The simulation's resolution (mm): the dexel spacing of the stock.
    pub resolution_mm: f64,
    /// The residual grids of every design surface.
    pub grids: Vec<RestGrid>,
}

impl RemainingMaterial {
    /// The largest residual over every grid (mm; 0 when none is measured).
    pub fn max_residual_mm(&self) -> f64 {
        self.grids
            .iter()
            .flat_map(|g| g.residual_mm.iter().flatten())
            .fold(0.0, |a, &b| a.max(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(nu: usize, nv: usize, du: f64, dv: f64) -> RestGrid {
        let mut points = Vec::new();
        for j in 0..nv {
            for i in 0..nu {
                points.push([i as f64 * du, j as f64 * dv, 0.0]);
            }
        }
        RestGrid {
            surface: "hub".into(),
            nu,
            nv,
            residual_mm: vec![Some(0.1); nu * nv],
            points,
        }
    }

    #[test]
    fn cell_areas_of_a_plane_grid_sum_to_its_area() {
        // On a uniform plane grid every cell, one-sided at the borders, reads du·dv.
        let g = plane(5, 4, 0.5, 0.25);
        for j in 0..4 {
            for i in 0..5 {
                assert!((g.cell_area_mm2(i, j) - 0.125).abs() < 1e-12, "({i}, {j})");
            }
        }
        assert_eq!(g.point(5, 0), None);
        assert_eq!(g.residual(0, 4), None);
        let m = RemainingMaterial {
            after: vec!["rough".into()],
            resolution_mm: 0.25,
            grids: vec![g],
        };
        assert!((m.max_residual_mm() - 0.1).abs() < 1e-15);
    }
}
