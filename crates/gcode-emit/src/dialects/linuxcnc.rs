//! LinuxCNC (rs274ngc) output.
//!
//! - Every program first selects identity kinematics with the configuration's M code
//!   (`M429` by default, [`LinuxCnc::tcp_off`]): joint values are only the machine's joints
//!   when the controller is in identity kinematics, and a previous program (or an operator)
//!   may have left TCP on. A configuration without switchable kinematics maps this M code
//!   to an empty remap subroutine.
//! - Joint output ([`OutputMode::Joint`]) for trivial/identity kinematics: X Y Z A/B C are
//!   the machine's joints, tool length compensation by `G43 H<tool>`, moves that turn a
//!   rotary axis in inverse time (`G93`, an `F` on every block), back to `G94` after.
//! - Tool-tip output ([`OutputMode::TcpAngles`]) for a machine running LinuxCNC's switchable
//!   `xyzac-trt-kins` / `xyzbc-trt-kins`: the kinematics are switched to TCP with the
//!   configuration's remapped M code (`M428` in LinuxCNC's sample configurations) after the
//!   rotary axes are pre-positioned, and back to identity (`M429`) at the operation's end;
//!   X Y Z are then the tool tip in the workpiece frame and F is mm/min at the tip.
//!   LinuxCNC has no `G43.4`; TCP is a kinematics switch.
//! - Retract between operations with `G53 G0 Z<safe>` (machine coordinates), rotary axes
//!   pre-positioned alone before X Y, program end `M2` (or `M30`), `%` delimiters.
//! - Checked by running LinuxCNC's own interpreter `rs274` on our output (tests/rs274.rs).

use super::common::{
    iso_style, leave_inverse_time, op_comment, preposition_rotary, retract_block, simultaneous,
    spindle_and_coolant, write_moves, xy_approach,
};
use crate::dialect::{program_name, sanitize, At, BlockWriter, Dialect, MotionWriter};
use crate::program::{NcProgram, OutputMode, ProgramOptions};
use crate::{GcodeError, NumberFormat};

/// LinuxCNC dialect settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinuxCnc {
    /// M code switching the kinematics to tool-centre-point (`M428` in LinuxCNC's
    /// `xyzac-trt` sample configuration).
    pub tcp_on: String,
    /// M code selecting identity kinematics (`M429`): written at the start of every program
    /// and after each TCP operation.
    pub tcp_off: String,
    /// Program end code (`M2` or `M30`).
    pub program_end: String,
}

impl Default for LinuxCnc {
    fn default() -> Self {
        Self {
            tcp_on: "M428".into(),
            tcp_off: "M429".into(),
            program_end: "M2".into(),
        }
    }
}

impl Dialect for LinuxCnc {
    fn name(&self) -> &'static str {
        "linuxcnc"
    }
    fn extension(&self) -> &'static str {
        "ngc"
    }
    fn supports(&self, mode: OutputMode) -> bool {
        matches!(mode, OutputMode::Joint | OutputMode::TcpAngles)
    }
    fn supports_indexed(&self) -> bool {
        false
    }

    fn write(&self, program: &NcProgram, o: &ProgramOptions) -> Result<String, GcodeError> {
        o.validate()?;
        let style = iso_style(o, NumberFormat::trimmed, NumberFormat::trimmed);
        let mut w = BlockWriter::new(o.line_numbers, "");
        let mut mw = MotionWriter::new(style);
        w.raw("%");
        if o.comments {
            w.raw(&format!("({})", program_name(&program.name)));
        }
        w.block(&format!("G21 G17 G90 G94 G40 G49 G{}", 53 + o.work_offset));
        // Identity kinematics before any motion (see module docs).
        w.block(&self.tcp_off);
        let safe = retract_block("G53 G0", "", o, style.linear_fmt)?;
        let mut tool: Option<u32> = None;
        for op in &program.operations {
            let (mode, moves) =
                simultaneous(op, self.name(), &[OutputMode::Joint, OutputMode::TcpAngles])?;
            let Some(first) = moves.first() else { continue };
            let at = At::start(&op.name);
            if o.comments {
                w.raw(&format!("({})", sanitize(&op_comment(op), false)));
            }
            w.block(&safe);
            if tool != Some(op.tool.number) {
                w.block(&format!("T{} M6", op.tool.number));
                w.block(&format!("G43 H{}", op.tool.number));
                tool = Some(op.tool.number);
            }
            spindle_and_coolant(&mut w, &op.tool, at)?;
            mw.forget_positions();
            preposition_rotary(&mut w, style, mode, first, at)?;
            if mode == OutputMode::TcpAngles {
                w.block(&self.tcp_on);
            } else {
                xy_approach(&mut w, style, first, at)?;
            }
            write_moves(&mut w, &mut mw, &op.name, mode, moves, "")?;
            leave_inverse_time(&mut w, &mut mw);
            if mode == OutputMode::TcpAngles {
                w.block(&self.tcp_off);
            }
            mw.forget_positions();
        }
        w.block(&safe);
        w.block("M5 M9");
        w.block(&self.program_end);
        w.raw("%");
        Ok(w.finish())
    }
}
