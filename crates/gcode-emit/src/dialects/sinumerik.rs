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

use super::common::{
    footer, header, iso_style, leave_inverse_time, op_comment, preposition_rotary, retract_block,
    spindle_and_coolant, write_moves, write_tilted_tips, xy_approach,
};
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
            vector_words: ["A3=", "B3=", "C3="],
            ..iso_style(o, NumberFormat::trimmed, NumberFormat::trimmed)
        };
        let ang = style.angular_fmt;
        let mut w = BlockWriter::new(o.line_numbers, "");
        let mut mw = MotionWriter::new(style);
        if o.comments {
            w.raw(&format!("; {}", program_name(&program.name)));
        }
        w.block(&format!("G17 G71 G90 G94 G40 G{}", 53 + o.work_offset));
        header(&mut w, o);
        let safe = retract_block("G0 SUPA", " D0", o, style.linear_fmt)?;
        for op in &program.operations {
            let at = At::start(&op.name);
            if o.comments {
                w.raw(&format!("; {}", sanitize(&op_comment(op), false)));
            }
            w.block(&safe);
            // D0 above cleared the offset; the tool is (re)selected with its edge every time.
            w.block(&format!("T{}", op.tool.number));
            w.block("M6");
            w.block("D1");
            spindle_and_coolant(&mut w, &op.tool, o, at)?;
            mw.forget_positions();
            match &op.motion {
                Motion::Simultaneous { mode, moves } => {
                    let Some(first) = moves.first() else { continue };
                    preposition_rotary(&mut w, style, *mode, first, at)?;
                    match mode {
                        OutputMode::Joint => xy_approach(&mut w, style, first, at)?,
                        OutputMode::TcpAngles => w.block("TRAORI"),
                        OutputMode::TcpVector => {
                            w.block("TRAORI");
                            w.block("ORIWKS");
                        }
                    }
                    write_moves(&mut w, &mut mw, &op.name, *mode, moves, "")?;
                    leave_inverse_time(&mut w, &mut mw);
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
                    write_tilted_tips(&mut w, &mut mw, &op.name, &plane, tips, "")?;
                    w.block("CYCLE800()");
                }
            }
            mw.forget_positions();
        }
        w.block(&safe);
        footer(&mut w, o, "M30");
        Ok(w.finish())
    }
}
