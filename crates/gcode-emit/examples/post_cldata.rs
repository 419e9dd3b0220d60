//! Reads a small APT CLDATA file, posts it for a table-table (A/C trunnion) machine and prints
//! the program in every dialect.
//!
//! `cargo run -p gcode-emit --example post_cldata`
//!
//! The CL file holds a 6 mm ball end (`CUTTER/6,3,...`) moving along a short five-axis arc
//! whose tool axis leans outward from 10° to 30°. `assemble_program` turns the cutter locations
//! into joint values with the machine's inverse kinematics (solution choice, unwinding,
//! linearisation) and each dialect writes its own program text (Heidenhain ISO in the
//! controller's tool-centre-point mode, which this crate writes for it instead of joints).

use gcode_emit::{
    assemble_program, dialect_by_name, read_cl, AssembleOptions, ClReadOptions, OutputMode,
    ProgramOptions,
};
use postproc_kinematics::Machine;

const MACHINE: &str = r#"
name = "trt"
[kinematics]
type = "table-table"
tilt_axis = "A"
[axes.X]
min = -500.0
max = 500.0
[axes.Y]
min = -500.0
max = 500.0
[axes.Z]
min = -500.0
max = 500.0
[axes.A]
min = -120.0
max = 120.0
[axes.C]
mode = "continuous"
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut cl = String::from(
        "PARTNO/DEMO\nMULTAX/ON\nLOADTL/1\nCUTTER/6,3,0,3,0,0,30\nSPINDL/RPM,12000,CLW\n\
         FEDRAT/MMPM,800\n",
    );
    for i in 0..=6 {
        let s = f64::from(i) / 6.0;
        let angle = (90.0 * s).to_radians();
        let tilt = (10.0 + 20.0 * s).to_radians();
        let (x, y) = (20.0 * angle.cos(), 20.0 * angle.sin());
        // Tool axis leaning outward (radially) by `tilt`.
        let (i_, j_, k_) = (
            tilt.sin() * angle.cos(),
            tilt.sin() * angle.sin(),
            tilt.cos(),
        );
        cl.push_str(&format!("GOTO/{x:.4},{y:.4},5,{i_:.7},{j_:.7},{k_:.7}\n"));
    }
    cl.push_str("FINI\n");
    let parsed = read_cl(&cl, "demo.cls", &ClReadOptions::default())?;
    let machine = Machine::from_toml_str(MACHINE, "trt.toml")?;
    for name in ["linuxcnc", "fanuc", "sinumerik", "heidenhain"] {
        let dialect = dialect_by_name(name)?;
        // Heidenhain ISO programs are written for the controller's tool-centre-point mode
        // (tip coordinates and axis angles); the others get machine joint values.
        let mode = if name == "heidenhain" {
            OutputMode::TcpAngles
        } else {
            OutputMode::Joint
        };
        let options = AssembleOptions {
            mode,
            ..AssembleOptions::default()
        };
        let posted = assemble_program(
            "demo",
            &parsed.operations,
            &machine,
            dialect.as_ref(),
            &options,
        )?;
        let text = dialect.write(&posted.program, &ProgramOptions::default())?;
        println!(
            "===== {name}, {mode:?} output ({} lines)",
            text.lines().count()
        );
        println!("{text}");
    }
    Ok(())
}
