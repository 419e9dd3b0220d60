//! LinuxCNC (rs274ngc) output.
//!
//! - The machine's kinematics module decides the frame ([`KinematicsSwitch`]). With
//!   switchable kinematics (LinuxCNC's `xyzac-trt-kins` / `xyzbc-trt-kins` sample
//!   configurations, which remap `M429` to identity and `M428` to TCP) every program first
//!   selects identity kinematics: joint values are only the machine's joints when the
//!   controller is in identity kinematics, and a previous program (or an operator) may have
//!   left TCP on. With trivial kinematics (`trivkins`: the axes are the joints) there is
//!   nothing to switch and no such M code exists: a stock configuration rejects `M429`
//!   ("M-code greater than 199"), and tool-tip output cannot be written.
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
//!   pre-positioned alone before X Y, program end `M2` (or the options' code), `%`
//!   delimiters; the options' header blocks after the setup block, footer blocks before the
//!   end.
//! - Checked by running LinuxCNC's own interpreter `rs274` on our output (tests/rs274.rs).

use super::common::{
    footer, header, iso_style, leave_inverse_time, op_comment, preposition_rotary, retract_block,
    simultaneous, spindle_and_coolant, write_moves, xy_approach,
};
use crate::dialect::{program_name, sanitize, At, BlockWriter, Dialect, MotionWriter};
use crate::program::{NcProgram, OutputMode, ProgramOptions};
use crate::{GcodeError, NumberFormat};

/// How a LinuxCNC configuration's kinematics are set up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum KinematicsSwitch {
    /// Trivial kinematics (`trivkins`): the axes are the joints, nothing to switch; joint
    /// output only.
    Trivial,
    /// Switchable kinematics (`switchkins`), with the configuration's remapped M codes.
    Switchable {
        /// M code switching to tool-centre-point kinematics (`M428` in LinuxCNC's
        /// `xyzac-trt` sample configuration).
        tcp: String,
        /// M code selecting identity kinematics (`M429`): written at the start of every
        /// program and after each TCP operation.
        identity: String,
    },
}

impl KinematicsSwitch {
    /// LinuxCNC's sample switchkins configurations: `M428` TCP, `M429` identity
    /// (`configs/sim/axis/vismach/5axis/table-rotary-tilting/remap_subs`).
    pub fn sample_switchkins() -> Self {
        Self::Switchable {
            tcp: "M428".into(),
            identity: "M429".into(),
        }
    }
}

/// LinuxCNC dialect settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinuxCnc {
    /// The configuration's kinematics (default: LinuxCNC's sample switchkins configuration,
    /// [`KinematicsSwitch::sample_switchkins`]).
    pub kinematics: KinematicsSwitch,
}

impl Default for LinuxCnc {
    fn default() -> Self {
        Self {
            kinematics: KinematicsSwitch::sample_switchkins(),
        }
    }
}

impl LinuxCnc {
    /// The dialect for a trivkins configuration (no kinematics switch).
    pub fn trivial() -> Self {
        Self {
            kinematics: KinematicsSwitch::Trivial,
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
        match self.kinematics {
            KinematicsSwitch::Trivial => mode == OutputMode::Joint,
            KinematicsSwitch::Switchable { .. } => {
                matches!(mode, OutputMode::Joint | OutputMode::TcpAngles)
            }
        }
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
        let switch = match &self.kinematics {
            KinematicsSwitch::Switchable { tcp, identity } => {
                w.block(identity);
                Some((tcp.as_str(), identity.as_str()))
            }
            KinematicsSwitch::Trivial => None,
        };
        header(&mut w, o);
        let safe = retract_block("G53 G0", "", o, style.linear_fmt)?;
        let mut tool: Option<u32> = None;
        for op in &program.operations {
            let modes: &[OutputMode] = match switch {
                Some(_) => &[OutputMode::Joint, OutputMode::TcpAngles],
                None => &[OutputMode::Joint],
            };
            let (mode, moves) = simultaneous(op, self.name(), modes)?;
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
            spindle_and_coolant(&mut w, &op.tool, o, at)?;
            mw.forget_positions();
            preposition_rotary(&mut w, style, mode, first, at)?;
            if let (OutputMode::TcpAngles, Some((tcp, _))) = (mode, switch) {
                w.block(tcp);
            } else {
                xy_approach(&mut w, style, first, at)?;
            }
            write_moves(&mut w, &mut mw, &op.name, mode, moves, "")?;
            leave_inverse_time(&mut w, &mut mw);
            if let (OutputMode::TcpAngles, Some((_, identity))) = (mode, switch) {
                w.block(identity);
            }
            mw.forget_positions();
        }
        w.block(&safe);
        footer(&mut w, o, "M2");
        w.raw("%");
        Ok(w.finish())
    }
}
