//! Shared test context: a fixture impeller and a ball-end tool with shank and holder.
#![allow(clippy::unwrap_used, clippy::expect_used, dead_code)]

use cam_core::{Cutter, CutterShape, HolderSegment, Tolerances};
use cam_plan::{ClearanceOptions, DesignClearance, Linker, Process, SafetySurface, Tool};
use impeller_model::Impeller;

pub fn fixture(name: &str) -> Impeller {
    let path = format!(
        "{}/../../fixtures/{name}/impeller.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    impeller_model::load(path).unwrap()
}

/// Ball end of radius `r`, flutes 6 mm, shank Ø3 mm, 25 mm stick-out, Ø20 × 30 mm holder.
pub fn ball_tool(r: f64) -> Tool {
    let mut cutter = Cutter::new(
        format!("ball-r{r}"),
        CutterShape::BallEnd { radius: r },
        6.0,
        1.5f64.max(r),
        25.0,
    )
    .unwrap();
    cutter.holder = vec![HolderSegment {
        bottom_radius: 10.0,
        top_radius: 10.0,
        length: 30.0,
    }];
    Tool {
        number: 7,
        cutter,
        teeth: 2,
        tool_length_mm: 80.0,
        plunge_edge_length_mm: None,
    }
}

/// The impeller-8+8 fixture's T6: tapered ball r1, 3° half angle, 20 mm flutes, Ø6 shank,
/// 35 mm stick-out, shrink-fit chuck.
pub fn tapered_t6() -> Tool {
    let mut cutter = Cutter::new(
        "T6-taper-ball-r1",
        CutterShape::TaperedBallEnd {
            ball_radius: 1.0,
            half_angle: 3f64.to_radians(),
        },
        20.0,
        3.0,
        35.0,
    )
    .unwrap();
    cutter.holder = vec![
        HolderSegment {
            bottom_radius: 10.5,
            top_radius: 13.5,
            length: 38.0,
        },
        HolderSegment {
            bottom_radius: 13.5,
            top_radius: 13.5,
            length: 42.0,
        },
    ];
    Tool {
        number: 6,
        cutter,
        teeth: 3,
        tool_length_mm: 115.0,
        plunge_edge_length_mm: None,
    }
}

pub fn process() -> Process {
    Process {
        spindle_rpm: 6000.0,
        feed_per_tooth_mm: 0.1,
        plunge_feed_per_tooth_mm: None,
        depth_of_cut_mm: Some(0.2),
        width_of_cut_mm: Some(0.5),
        blade_allowance_mm: 0.0,
        hub_allowance_mm: 0.0,
        rapid_mm_per_min: 10000.0,
    }
}

pub struct Ctx {
    pub imp: Impeller,
    pub tool: Tool,
    pub tol: Tolerances,
    pub process: Process,
    pub linker: Linker,
}

impl Ctx {
    pub fn new(name: &str, r: f64) -> Self {
        let imp = fixture(name);
        let linker = Linker::new(SafetySurface::around_stock(imp.stock(), 10.0).unwrap());
        Self {
            imp,
            tool: ball_tool(r),
            tol: Tolerances::default(),
            process: process(),
            linker,
        }
    }

    pub fn clearance(&self) -> DesignClearance<'_> {
        // Coarser sampling than the 0.01 mm default keeps the debug-profile tests fast.
        let options = ClearanceOptions {
            sample_tol_mm: 0.05,
            ..ClearanceOptions::default()
        };
        DesignClearance::new(&self.imp, &self.tool, options).unwrap()
    }
}

#[macro_export]
macro_rules! plan_ctx {
    ($c:expr, $cl:expr) => {
        cam_plan::PlanContext {
            impeller: &$c.imp,
            stock: $c.imp.stock(),
            tool: &$c.tool,
            tolerances: &$c.tol,
            process: &$c.process,
            clearance: &$cl,
            linker: &$c.linker,
            links: &cam_plan::LinkStats::default(),
            reach: None,
            remaining: None,
            progress: None,
        }
    };
}
