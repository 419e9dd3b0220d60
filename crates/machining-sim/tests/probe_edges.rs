//! The normal probes' through-cut overcut at an edge thinner than a dexel cell: the reading is
//! the depth of removed points on the rays read, so a ray passing beside the edge through air
//! reads nothing, while a wall really cut through still reads its depth.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Point3, Vector3};
use machining_sim::measure::probe;
use machining_sim::stock_shape::{BoxStock, StockShape};
use machining_sim::{BoxDesign, TriDexel};

/// The blank's bounds with only the material of `solid` minus the band `gap` of y (what a
/// cut left): a stock on the blank's own dexel grid.
struct Left {
    blank: BoxStock,
    solid: BoxStock,
    gap: Option<(f64, f64)>,
}

impl StockShape for Left {
    fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        self.blank.bounding_box()
    }
    fn ray_intervals(&self, d: usize, u: f64, v: f64, out: &mut Vec<(f64, f64)>) {
        let mut mine = Vec::new();
        self.solid.ray_intervals(d, u, v, &mut mine);
        let Some((g0, g1)) = self.gap else {
            out.extend(mine);
            return;
        };
        // y is coordinate 1: along y rays lose the band, across it rays in the band are empty.
        let y = match d {
            0 => Some(u),
            2 => Some(v),
            _ => None,
        };
        for (a, b) in mine {
            match y {
                Some(y) if (g0..=g1).contains(&y) => {}
                Some(_) => out.push((a, b)),
                None => {
                    if a < g0 {
                        out.push((a, b.min(g0)));
                    }
                    if b > g1 {
                        out.push((a.max(g1), b));
                    }
                }
            }
        }
    }
}

#[test]
fn a_ray_beside_a_thin_edge_reads_no_overcut_and_a_cut_through_wall_does() {
    // A plate 0.8 mm thick (x ∈ [0, 0.8]) ending at y = 5.1, on 1 mm dexels whose x rays run
    // at y = …, 4.3, 5.3: the sample at y = 4.85 on the face x = 0.8 reads membership on the
    // ray at y = 5.3, 0.2 mm beyond the edge, in air. Nothing was cut: the stock is the
    // plate. Read on the probe line, the plate's depth there (0.25 mm, capped by the edge)
    // was reported as overcut.
    let blank = BoxStock::new([-2.0, -2.2, -2.0], [3.0, 8.0, 7.0]).unwrap();
    let plate = BoxStock::new([0.0, 0.0, 0.0], [0.8, 5.1, 5.0]).unwrap();
    let design = BoxDesign {
        min: plate.min,
        max: plate.max,
        sample_spacing: 0.5,
    };
    let initial = TriDexel::from_shape(&blank, 1.0).unwrap();
    let stock = TriDexel::from_shape(
        &Left {
            blank,
            solid: plate,
            gap: None,
        },
        1.0,
    )
    .unwrap();
    let ray = stock.nearest_ray_point(0, &[0.8, 4.85, 2.5]).unwrap();
    assert!(
        (ray[1] - 5.3).abs() < 1e-9,
        "nearest x ray at y = {}",
        ray[1]
    );
    let n = Vector3::x();
    let at_edge = probe(
        &stock,
        &initial,
        &design,
        &Point3::new(0.8, 4.85, 2.5),
        &n,
        3.0,
    );
    assert_eq!(at_edge.overcut, 0.0, "read beside the edge");
    // The same plate cut through over y ∈ [1.5, 2.9]: the sample at y = 2.2 reads the rays
    // at y = 2.3 (empty, inside the design): the removed ray point 0.3 mm from the back face
    // at the probe's first step is 0.3 mm deep.
    let cut = TriDexel::from_shape(
        &Left {
            blank,
            solid: plate,
            gap: Some((1.5, 2.9)),
        },
        1.0,
    )
    .unwrap();
    let through = probe(
        &cut,
        &initial,
        &design,
        &Point3::new(0.8, 2.2, 2.5),
        &n,
        3.0,
    );
    assert!(
        (through.overcut - 0.3).abs() < 1e-9,
        "through-cut read {}",
        through.overcut
    );
}
