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

use super::common::{coolant_word, op_comment, rotary_words, spindle_words, tip_move, write_moves};
use crate::dialect::{
    num, program_name, sanitize, At, BlockWriter, Dialect, MotionStyle, MotionWriter,
};
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
        let style = MotionStyle {
            rapid: "G0",
            linear: "G1",
            feed_modes: ("G93", "G94"),
            vector_words: ["I", "J", "K"],
            linear_fmt: pointed(o.linear_decimals),
            angular_fmt: pointed(o.angular_decimals),
            feed_fmt: pointed(o.feed_decimals),
            inverse_fmt: pointed(o.inverse_time_decimals),
        };
        let lin = style.linear_fmt;
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
        let at0 = At {
            op: "program",
            block: 0,
        };
        let safe = format!("G53 G0 Z{}", num(lin, o.safe_z_machine, "Z", at0)?);
        let mut tool: Option<u32> = None;
        for op in &program.operations {
            let at = At {
                op: &op.name,
                block: 0,
            };
            if o.comments {
                w.raw(&format!("({})", sanitize(&op_comment(op), true)));
            }
            w.block(&safe);
            if tool != Some(op.tool.number) {
                w.block(&format!("T{} M6", op.tool.number));
                tool = Some(op.tool.number);
            }
            w.block(&spindle_words(
                op.tool.spindle,
                NumberFormat::trimmed(0),
                at,
            )?);
            w.block(coolant_word(op.tool.coolant));
            mw.forget_positions();
            match &op.motion {
                Motion::Simultaneous { mode, moves } => {
                    let mode = *mode;
                    let Some(first) = moves.first() else { continue };
                    if mode != OutputMode::TcpVector && !first.rotary.is_empty() {
                        w.block(&format!(
                            "G0 {}",
                            rotary_words(first, style.angular_fmt, at)?
                        ));
                    }
                    let h = op.tool.number;
                    let prefix = match mode {
                        OutputMode::Joint => {
                            w.block(&format!(
                                "G0 X{} Y{}",
                                num(lin, first.xyz[0], "X", at)?,
                                num(lin, first.xyz[1], "Y", at)?
                            ));
                            format!("G43 H{h}")
                        }
                        OutputMode::TcpAngles => format!("G43.4 H{h}"),
                        OutputMode::TcpVector => format!("G43.5 H{h}"),
                    };
                    write_moves(&mut w, &mut mw, &op.name, mode, moves, &prefix)?;
                    if let Some(g94) = mw.leave_inverse_time() {
                        w.block(g94);
                    }
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
                    let moves: Vec<_> = tips
                        .iter()
                        .map(|(p, f)| {
                            let q = plane.to_plane(p);
                            tip_move([q.x, q.y, q.z], *f)
                        })
                        .collect();
                    if let Some(first) = moves.first() {
                        w.block(&format!(
                            "G0 X{} Y{}",
                            num(lin, first.xyz[0], "X", at)?,
                            num(lin, first.xyz[1], "Y", at)?
                        ));
                    }
                    let prefix = format!("G43 H{}", op.tool.number);
                    write_moves(
                        &mut w,
                        &mut mw,
                        &op.name,
                        OutputMode::TcpAngles,
                        &moves,
                        &prefix,
                    )?;
                    w.block("G49");
                    w.block("G69");
                    mw.forget_positions();
                    continue;
                }
            }
            w.block("G49");
            mw.forget_positions();
        }
        w.block(&safe);
        w.block("M5");
        w.block("M9");
        w.block("M30");
        w.raw("%");
        Ok(w.finish())
    }
}
