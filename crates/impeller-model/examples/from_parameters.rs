//! Builds an impeller from design parameters, prints its summary and measures a point against
//! the hub and a blade side.
//!
//! `cargo run -p impeller-model --example from_parameters`
//!
//! The parameters are the schema example of `impeller_model::params`: 8 + 8 ruled blades,
//! quarter-ellipse hub and shroud contours, 0.8 mm blades, Ø80 × 45 mm stock.

use impeller_model::query::BladeSideQuery;
use impeller_model::Side;
use nurbs::closest::PointQuery;

const PARAMS: &str = r#"
name = "example"
fillet_radius_mm = 1.0
[hub]
type = "quarter_ellipse"
inlet_zr_mm = [43.0, 8.0]
outlet_zr_mm = [4.0, 38.5]
[shroud]
type = "quarter_ellipse"
inlet_zr_mm = [43.0, 22.0]
outlet_zr_mm = [12.0, 38.5]
[main]
count = 8
kind = "ruled"
thickness_mm = [[0.0, 0.8], [1.0, 0.8]]
leading_edge = "rounded"
trailing_edge = "blunt"
[[main.wrap]]
span = 0.0
theta_deg = [[0.0, 0.0], [1.0, 40.0]]
[[main.wrap]]
span = 1.0
theta_deg = [[0.0, 0.0], [1.0, 40.0]]
[splitter]
count = 8
start_fraction = 0.35
[stock]
diameter_mm = 80.0
height_mm = 45.0
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let imp = impeller_model::from_toml_str(PARAMS, "example.toml")?;
    let s = imp.summary();
    println!("impeller `{}`", s.name);
    println!(
        "  blades: {} main + {} splitter",
        s.main_blade_count, s.splitter_blade_count
    );
    println!("  blade tip diameter   {:8.3} mm", s.blade_tip_diameter_mm);
    println!("  axial height         {:8.3} mm", s.axial_height_mm);
    println!(
        "  min channel width    {:8.3} mm at the hub",
        s.min_channel_width_hub_mm
    );
    println!(
        "                       {:8.3} mm at the shroud",
        s.min_channel_width_shroud_mm
    );
    println!("  min blade thickness  {:8.3} mm", s.min_blade_thickness_mm);

    // A point 1.5 mm above the hub (along its channel-side normal) ...
    let hub = imp.hub();
    let p = hub.point(0.5, 0.3) + hub.normal(0.5, 0.3) * 1.5;
    let a = hub.query(&p, None);
    println!(
        "hub: signed distance {:.6} mm (certified: {})",
        a.signed_distance, a.certified
    );
    // ... and 0.25 mm outside the first main blade's suction side.
    let blade = imp.main().blade();
    let n = blade
        .outward_normal(Side::Suction, 0.5, 0.5)
        .ok_or("no normal at the blade's mid point")?;
    let p = blade.suction().point(0.5, 0.5) + n * 0.25;
    let a = BladeSideQuery {
        blade,
        side: Side::Suction,
    }
    .query(&p, None);
    println!("suction side: signed distance {:.6} mm", a.signed_distance);
    Ok(())
}
