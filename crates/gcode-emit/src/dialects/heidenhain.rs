//! Heidenhain TNC output in ISO format (iTNC 530 / TNC 640 "DIN/ISO" programs).
//!
//! Chosen over conversational (Klartext) because the rest of the toolkit writes G-code and
//! the ISO form keeps one motion model; the TNC's five-axis functions are available in both.
//! - Program: `%NAME G71 *` (G71 = mm), every block numbered and ended with ` *` — comment
//!   blocks too (`N20 ;TEXT *`) — last block `N99999999 %NAME G71 *`. Numbers carry an
//!   explicit sign (`X+10.5`).
//! - Tool call `T<n> G17 S<rpm>` (tool axis Z; the TNC applies the tool length itself, there
//!   is no `G43`), `M3`/`M4`, coolant `M8`/`M7`, `M9`, `M5`, end `M30`.
//! - Retract between operations `G00 Z+<safe> M91` (`M91`: machine-based coordinates).
//! - Simultaneous five-axis ([`OutputMode::TcpAngles`]): rotary axes pre-positioned, then
//!   `M128` (TCPM: the programmed X Y Z are the tool tip, F acts at the tip), `M129` after.
//! - 3+2 ([`crate::Motion::Indexed`]): `PLANE SPATIAL SPA.. SPB.. SPC+0 TURN FMAX` (spatial
//!   angles about the fixed machine axes in the order A, B, C), tips in the tilted frame,
//!   `PLANE RESET STAY` at the end.
//! - The datum is the active preset: no `G54` (in TNC ISO `G54` is a datum *shift*).
//! - Joint (inverse-time) output is not offered: TNC feeds rotary moves in deg/min or
//!   through M116/M128, not `G93`.

use super::common::{
    footer, header, iso_style, op_comment, preposition_rotary, require_tcp_angles, retract_block,
    spindle_code, write_moves, write_tilted_tips,
};
use crate::dialect::{
    num, program_name, sanitize, At, BlockWriter, Dialect, MotionStyle, MotionWriter,
};
use crate::program::{LineNumbers, Motion, NcProgram, OutputMode, ProgramOptions};
use crate::tilted_plane::TiltedPlane;
use crate::{GcodeError, NumberFormat};

/// Heidenhain ISO dialect.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HeidenhainIso;

fn signed(decimals: usize) -> NumberFormat {
    NumberFormat {
        plus_sign: true,
        ..NumberFormat::trimmed(decimals)
    }
}

impl Dialect for HeidenhainIso {
    fn name(&self) -> &'static str {
        "heidenhain"
    }
    fn extension(&self) -> &'static str {
        "i"
    }
    fn supports(&self, mode: OutputMode) -> bool {
        mode == OutputMode::TcpAngles
    }
    fn supports_indexed(&self) -> bool {
        true
    }

    fn write(&self, program: &NcProgram, o: &ProgramOptions) -> Result<String, GcodeError> {
        o.validate()?;
        let style = MotionStyle {
            rapid: "G00",
            linear: "G01",
            ..iso_style(o, signed, NumberFormat::trimmed)
        };
        let ang = style.angular_fmt;
        let name = program_name(&program.name);
        let numbers = o.line_numbers.unwrap_or(LineNumbers::new(10, 10));
        let mut w = BlockWriter::new(Some(numbers), " *");
        let mut mw = MotionWriter::new(style);
        w.raw(&format!("%{name} G71 *"));
        w.block("G17 G90 G40");
        header(&mut w, o);
        let safe = retract_block("G00", " M91", o, style.linear_fmt)?;
        let mut tool: Option<u32> = None;
        for op in &program.operations {
            let at = At::start(&op.name);
            if o.comments {
                w.block(&format!(";{}", sanitize(&op_comment(op), true)));
            }
            w.block(&safe);
            if tool != Some(op.tool.number) {
                let s = match op.tool.spindle {
                    Some(sp) => format!(" S{}", num(NumberFormat::trimmed(0), sp.rpm, "S", at)?),
                    None => String::new(),
                };
                w.block(&format!("T{} G17{s}", op.tool.number));
                tool = Some(op.tool.number);
            } else if let Some(sp) = op.tool.spindle {
                w.block(&format!(
                    "S{}",
                    num(NumberFormat::trimmed(0), sp.rpm, "S", at)?
                ));
            }
            w.block(spindle_code(op.tool.spindle));
            w.block(o.coolant_codes.code(op.tool.coolant));
            mw.forget_positions();
            match &op.motion {
                Motion::Simultaneous { mode, moves } => {
                    require_tcp_angles(self.name(), *mode, &op.name, "M128")?;
                    let Some(first) = moves.first() else { continue };
                    preposition_rotary(&mut w, style, *mode, first, at)?;
                    w.block("M128");
                    write_moves(&mut w, &mut mw, &op.name, *mode, moves, "")?;
                    w.block("M129");
                }
                Motion::Indexed {
                    tool_axis, tips, ..
                } => {
                    let plane = TiltedPlane::spatial_ab(tool_axis);
                    w.block(&format!(
                        "PLANE SPATIAL SPA{} SPB{} SPC+0 TURN FMAX",
                        num(ang, plane.a.to_degrees(), "SPA", at)?,
                        num(ang, plane.b.to_degrees(), "SPB", at)?
                    ));
                    write_tilted_tips(&mut w, &mut mw, &op.name, &plane, tips, "")?;
                    w.block("PLANE RESET STAY");
                }
            }
            mw.forget_positions();
        }
        w.block(&safe);
        footer(&mut w, o, "M30");
        w.raw(&format!("N99999999 %{name} G71 *"));
        Ok(w.finish())
    }
}
