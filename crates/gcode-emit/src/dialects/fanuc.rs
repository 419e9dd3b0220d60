//! Fanuc (Series 30i/31i-B style) output.
//!
//! - Every length, angle and feed is written with a decimal point (`X10.`): without one a
//!   Fanuc reads the value in least input increments (0.001 mm).
//! - Program: `%`, `O<number> (<NAME>)`, safe-start block `G21 G17 G90 G94 G40 G49 G80 G5x`,
//!   tool change `T<n> M6`, spindle `S.. M3`, coolant, end `M30`, `%`.
//! - Joint output ([`OutputMode::Joint`]): `G43 H<n>` tool length compensation on the first
//!   approach block, rotary moves in inverse time (`G93`, `F` on every block) and `G94` after.
//! - TCP ([`OutputMode::TcpAngles`]): tool centre point control type 1, `G43.4 H<n>` on the
//!   first approach block, X Y Z = tool tip in the workpiece frame, rotary axes as angles,
//!   F in mm/min.
//! - TCP with tool vectors ([`OutputMode::TcpVector`]): type 2, `G43.5 H<n>`, tool direction
//!   as `I J K`.
//! - 3+2 ([`crate::Motion::Indexed`]): tilted working plane `G68.2 X0 Y0 Z0 I J K` (Euler
//!   angles Z-X'-Z'' about the workpiece origin, K = 0), `G53.1` turns the rotary axes to
//!   the plane, tips in the tilted frame with `G43 H<n>` on the first approach block,
//!   `G49` and `G69` at the end.
//! - `G49` cancels compensation / TCP at the end of each operation, then `G53 G0 Z<safe>`
//!   retracts in machine coordinates before any tool change or reorientation.

use super::common::{
    footer, header, iso_style, leave_inverse_time, op_comment, preposition_rotary, retract_block,
    spindle_and_coolant, write_moves, write_tilted_tips, xy_approach,
};
use crate::dialect::{num, program_name, sanitize, At, BlockWriter, Dialect, MotionWriter};
use crate::program::{Motion, NcProgram, OutputMode, ProgramOptions};
use crate::tilted_plane::TiltedPlane;
use crate::{GcodeError, NumberFormat};

/// Fanuc dialect.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Fanuc;

fn pointed(decimals: usize) -> NumberFormat {
    NumberFormat {
        force_point: true,
        ..NumberFormat::trimmed(decimals)
    }
}

impl Dialect for Fanuc {
    fn name(&self) -> &'static str {
        "fanuc"
    }
    fn extension(&self) -> &'static str {
        "nc"
    }
    fn supports(&self, _mode: OutputMode) -> bool {
        true
    }
    fn supports_indexed(&self) -> bool {
        true
    }

    fn write(&self, program: &NcProgram, o: &ProgramOptions) -> Result<String, GcodeError> {
        o.validate()?;
        if o.program_number > 9999 {
            return Err(GcodeError::InvalidOption {
                field: "program_number",
                reason: format!("{} does not fit Fanuc's O0001..O9999", o.program_number),
            });
        }
        let style = iso_style(o, pointed, pointed);
        let mut w = BlockWriter::new(o.line_numbers, "");
        let mut mw = MotionWriter::new(style);
        w.raw("%");
        w.raw(&format!(
            "O{:04} ({})",
            o.program_number,
            program_name(&program.name)
        ));
        w.block(&format!(
            "G21 G17 G90 G94 G40 G49 G80 G{}",
            53 + o.work_offset
        ));
        header(&mut w, o);
        let safe = retract_block("G53 G0", "", o, style.linear_fmt)?;
        let mut tool: Option<u32> = None;
        for op in &program.operations {
            let at = At::start(&op.name);
            if o.comments {
                w.raw(&format!("({})", sanitize(&op_comment(op), true)));
            }
            w.block(&safe);
            if tool != Some(op.tool.number) {
                w.block(&format!("T{} M6", op.tool.number));
                tool = Some(op.tool.number);
            }
            spindle_and_coolant(&mut w, &op.tool, o, at)?;
            mw.forget_positions();
            let h = op.tool.number;
            match &op.motion {
                Motion::Simultaneous { mode, moves } => {
                    let mode = *mode;
                    let Some(first) = moves.first() else { continue };
                    preposition_rotary(&mut w, style, mode, first, at)?;
                    let prefix = match mode {
                        OutputMode::Joint => {
                            xy_approach(&mut w, style, first, at)?;
                            format!("G43 H{h}")
                        }
                        OutputMode::TcpAngles => format!("G43.4 H{h}"),
                        OutputMode::TcpVector => format!("G43.5 H{h}"),
                    };
                    write_moves(&mut w, &mut mw, &op.name, mode, moves, &prefix)?;
                    leave_inverse_time(&mut w, &mut mw);
                    w.block("G49");
                }
                Motion::Indexed {
                    tool_axis, tips, ..
                } => {
                    let plane = TiltedPlane::euler_zxz(tool_axis);
                    w.block(&format!(
                        "G68.2 X0. Y0. Z0. I{} J{} K0.",
                        num(style.angular_fmt, plane.a.to_degrees(), "I", at)?,
                        num(style.angular_fmt, plane.b.to_degrees(), "J", at)?
                    ));
                    w.block("G53.1");
                    let prefix = format!("G43 H{h}");
                    write_tilted_tips(&mut w, &mut mw, &op.name, &plane, tips, &prefix)?;
                    w.block("G49");
                    w.block("G69");
                }
            }
            mw.forget_positions();
        }
        w.block(&safe);
        footer(&mut w, o, "M30");
        w.raw("%");
        Ok(w.finish())
    }
}
