//! Siemens Sinumerik 840D (sl) output.
//!
//! - Program: comment header, `G17 G71 G90 G94 G40 G5x` (`G71` = metric on Sinumerik),
//!   tool change `T<n>` / `M6` / `D1` (edge 1 activates the length offset), `S.. M3`,
//!   coolant, end `M30`. Comments start with `;`.
//! - Retract between operations: `G0 SUPA Z<safe> D0` (machine coordinates, offsets
//!   suppressed).
//! - Joint output ([`OutputMode::Joint`]): rotary moves in inverse time `G93`, `G94` after.
//! - TCP ([`OutputMode::TcpAngles`]): `TRAORI` after pre-positioning the rotary axes, X Y Z =
//!   tool tip, rotary axes as machine angles, F mm/min; `TRAFOOF` at the operation's end.
//! - TCP with vectors ([`OutputMode::TcpVector`]): `TRAORI` + `ORIWKS`, orientation as the
//!   unit tool vector `A3= B3= C3=` in the workpiece frame.
//! - 3+2 ([`crate::Motion::Indexed`]): `CYCLE800(_FR, _TC, _ST, _MODE, _X0, _Y0, _Z0, _A, _B,
//!   _C, _X1, _Y1, _Z1, _DIR, _FR_I, _DMODE)` with mode 57 (axis by axis, rotations X then Y then Z
//!   about the rotated axes), `_FR = 0` (we retract before), `_ST = 0` (new plane), the
//!   swivel data record named in [`Sinumerik::swivel_record`], `_DIR` from the sign of the
//!   first rotary angle; tips are written in the tilted frame; `CYCLE800()` resets the
//!   plane at the operation's end.

use super::common::{coolant_word, op_comment, rotary_words, spindle_words, tip_move, write_moves};
use crate::dialect::{
    num, program_name, sanitize, At, BlockWriter, Dialect, MotionStyle, MotionWriter,
};
use crate::program::{Motion, NcProgram, OutputMode, ProgramOptions};
use crate::tilted_plane::TiltedPlane;
use crate::{GcodeError, NumberFormat};

/// Sinumerik 840D dialect settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sinumerik {
    /// Name of the swivel data record (`_TC`) used by `CYCLE800`.
    pub swivel_record: String,
}

impl Default for Sinumerik {
    fn default() -> Self {
        Self {
            swivel_record: "TC1".into(),
        }
    }
}

impl Dialect for Sinumerik {
    fn name(&self) -> &'static str {
        "sinumerik"
    }
    fn extension(&self) -> &'static str {
        "mpf"
    }
    fn supports(&self, _mode: OutputMode) -> bool {
        true
    }
    fn supports_indexed(&self) -> bool {
        true
    }

    fn write(&self, program: &NcProgram, o: &ProgramOptions) -> Result<String, GcodeError> {
        o.validate()?;
        let style = MotionStyle {
            rapid: "G0",
            linear: "G1",
            feed_modes: ("G93", "G94"),
            vector_words: ["A3=", "B3=", "C3="],
            linear_fmt: NumberFormat::trimmed(o.linear_decimals),
            angular_fmt: NumberFormat::trimmed(o.angular_decimals),
            feed_fmt: NumberFormat::trimmed(o.feed_decimals),
            inverse_fmt: NumberFormat::trimmed(o.inverse_time_decimals),
        };
        let lin = style.linear_fmt;
        let ang = style.angular_fmt;
        let mut w = BlockWriter::new(o.line_numbers, "");
        let mut mw = MotionWriter::new(style);
        if o.comments {
            w.raw(&format!("; {}", program_name(&program.name)));
        }
        w.block(&format!("G17 G71 G90 G94 G40 G{}", 53 + o.work_offset));
        let at0 = At {
            op: "program",
            block: 0,
        };
        let safe = format!("G0 SUPA Z{} D0", num(lin, o.safe_z_machine, "Z", at0)?);
        for op in &program.operations {
            let at = At {
                op: &op.name,
                block: 0,
            };
            if o.comments {
                w.raw(&format!("; {}", sanitize(&op_comment(op), false)));
            }
            w.block(&safe);
            // D0 above cleared the offset; the tool is (re)selected with its edge every time.
            w.block(&format!("T{}", op.tool.number));
            w.block("M6");
            w.block("D1");
            w.block(&spindle_words(
                op.tool.spindle,
                NumberFormat::trimmed(0),
                at,
            )?);
            w.block(coolant_word(op.tool.coolant));
            mw.forget_positions();
            match &op.motion {
                Motion::Simultaneous { mode, moves } => {
                    let Some(first) = moves.first() else { continue };
                    if *mode != OutputMode::TcpVector && !first.rotary.is_empty() {
                        w.block(&format!("G0 {}", rotary_words(first, ang, at)?));
                    }
                    match mode {
                        OutputMode::Joint => w.block(&format!(
                            "G0 X{} Y{}",
                            num(lin, first.xyz[0], "X", at)?,
                            num(lin, first.xyz[1], "Y", at)?
                        )),
                        OutputMode::TcpAngles => w.block("TRAORI"),
                        OutputMode::TcpVector => {
                            w.block("TRAORI");
                            w.block("ORIWKS");
                        }
                    }
                    write_moves(&mut w, &mut mw, &op.name, *mode, moves, "")?;
                    if let Some(g94) = mw.leave_inverse_time() {
                        w.block(g94);
                    }
                    if *mode != OutputMode::Joint {
                        w.block("TRAFOOF");
                    }
                }
                Motion::Indexed {
                    tool_axis,
                    rotary,
                    tips,
                } => {
                    let plane = TiltedPlane::axis_by_axis_xy(tool_axis);
                    let dir = if rotary.first().is_some_and(|r| r.deg < 0.0) {
                        -1
                    } else {
                        1
                    };
                    w.block(&format!(
                        "CYCLE800(0,\"{}\",0,57,0,0,0,{},{},0,0,0,0,{},0,0)",
                        sanitize(&self.swivel_record, false).replace('"', ""),
                        num(ang, plane.a.to_degrees(), "_A", at)?,
                        num(ang, plane.b.to_degrees(), "_B", at)?,
                        dir
                    ));
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
                    write_moves(&mut w, &mut mw, &op.name, OutputMode::TcpAngles, &moves, "")?;
                    w.block("CYCLE800()");
                }
            }
            mw.forget_positions();
        }
        w.block(&safe);
        w.block("M5");
        w.block("M9");
        w.block("M30");
        Ok(w.finish())
    }
}
