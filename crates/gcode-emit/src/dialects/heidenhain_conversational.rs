//! Heidenhain TNC conversational (Klartext) output (iTNC 530 / TNC 640 / TNC7 `.h`
//! programs), beside the ISO form of [`super::HeidenhainIso`].
//!
//! - Program: `0 BEGIN PGM NAME MM` … `N END PGM NAME MM`; every line is numbered from 0 in
//!   steps of 1 (the control renumbers on load; block numbers of the options are not used);
//!   comments are `; TEXT` lines. Numbers carry an explicit sign (`X+10.5`).
//! - Tool call `TOOL CALL <n> Z S<rpm>` (tool axis Z; the TNC applies the tool length itself)
//!   on every operation (a call of the tool in the spindle only updates its data), then
//!   `M3`/`M4`/`M5` and the coolant code as blocks of their own.
//! - Straight lines `L X.. Y.. Z.. A.. C.. R0 F..` (only the words that changed; `FMAX` for
//!   rapids, which the control applies to that block only, so the modal `F` is written again
//!   after a rapid only when it changed); retract `L Z+<safe> R0 FMAX M91` (machine-based
//!   coordinates) before every tool call and at the end.
//! - Simultaneous five-axis ([`OutputMode::TcpAngles`]): rotary axes pre-positioned with
//!   `FMAX`, then `FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS` (the programmed X Y Z are the
//!   tool tip, F acts at the tip, the tool axis is interpolated on the axes' path;
//!   HEIDENHAIN recommends it over `M128`) and `FUNCTION RESET TCPM` after; with
//!   [`Tcpm::M128`] the older `M128`/`M129`.
//! - 3+2 ([`crate::Motion::Indexed`]): `PLANE SPATIAL SPA.. SPB.. SPC+0 TURN FMAX`, tips in
//!   the tilted frame, `PLANE RESET STAY`.
//! - The datum is the active preset (no work offset word).
//! - Joint (inverse-time) output is not offered, as in the ISO form.

use super::common::{op_comment, require_tcp_angles, rotary_words, spindle_code, tip_move};
use crate::dialect::{num, program_name, sanitize, At, Dialect};
use crate::program::{Feed, Motion, NcMove, NcProgram, OutputMode, ProgramOptions};
use crate::tilted_plane::TiltedPlane;
use crate::{GcodeError, NumberFormat};

/// How tool-centre-point control is switched on.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Tcpm {
    /// `FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS` / `FUNCTION RESET TCPM` (iTNC 530 and
    /// later).
    #[default]
    Function,
    /// `M128` / `M129` (older controls).
    M128,
}

/// Heidenhain conversational (Klartext) dialect.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HeidenhainConversational {
    /// How TCPM is switched on and off.
    pub tcpm: Tcpm,
}

/// Numbered lines of a conversational program.
struct Lines {
    out: String,
    next: u64,
}

impl Lines {
    fn line(&mut self, text: &str) {
        self.out.push_str(&self.next.to_string());
        self.out.push(' ');
        self.out.push_str(text);
        self.out.push('\n');
        self.next += 1;
    }
}

/// Modal `L` blocks: the coordinates that changed since the last block and the feed when it
/// changed (`FMAX` applies to its own block only).
struct LineWriter {
    linear: NumberFormat,
    angular: NumberFormat,
    feed_fmt: NumberFormat,
    last: [Option<String>; 6],
    feed: Option<String>,
}

impl LineWriter {
    fn forget_positions(&mut self) {
        self.last = Default::default();
    }

    /// Writes `mv`; `extra` words (M functions) go at the end. Returns `false` when no
    /// coordinate changed (nothing written).
    fn write(
        &mut self,
        lines: &mut Lines,
        mv: &NcMove,
        extra: &str,
        at: At<'_>,
    ) -> Result<bool, GcodeError> {
        let mut words = String::from("L");
        let mut changed = false;
        let mut word = |slot: usize, addr: &str, v: f64, fmt: NumberFormat| {
            let text = num(fmt, v, addr, at)?;
            if self.last[slot].as_deref() != Some(text.as_str()) {
                words.push(' ');
                words.push_str(addr);
                words.push_str(&text);
                self.last[slot] = Some(text);
                changed = true;
            }
            Ok::<(), GcodeError>(())
        };
        for (k, (addr, v)) in ["X", "Y", "Z"].iter().zip(mv.xyz).enumerate() {
            word(k, addr, v, self.linear)?;
        }
        for r in &mv.rotary {
            let slot = match r.letter.to_ascii_uppercase() {
                'A' => 3,
                'B' => 4,
                _ => 5,
            };
            word(slot, &r.letter.to_string(), r.deg, self.angular)?;
        }
        if !changed {
            return Ok(false);
        }
        words.push_str(" R0");
        match mv.feed {
            Feed::Rapid => words.push_str(" FMAX"),
            Feed::PerMinute(f) => {
                let text = num(self.feed_fmt, f, "F", at)?;
                if self.feed.as_deref() != Some(text.as_str()) {
                    words.push_str(" F");
                    words.push_str(&text);
                    self.feed = Some(text);
                }
            }
            Feed::InverseTime(_) => {
                return Err(GcodeError::Unsupported {
                    dialect: "heidenhain_conversational",
                    what: format!("inverse-time feed (operation `{}`)", at.op),
                })
            }
        }
        if !extra.is_empty() {
            words.push(' ');
            words.push_str(extra);
        }
        lines.line(&words);
        Ok(true)
    }
}

impl Dialect for HeidenhainConversational {
    fn name(&self) -> &'static str {
        "heidenhain_conversational"
    }
    fn extension(&self) -> &'static str {
        "h"
    }
    fn supports(&self, mode: OutputMode) -> bool {
        mode == OutputMode::TcpAngles
    }
    fn supports_indexed(&self) -> bool {
        true
    }

    fn write(&self, program: &NcProgram, o: &ProgramOptions) -> Result<String, GcodeError> {
        o.validate()?;
        let signed = |d: usize| NumberFormat {
            plus_sign: true,
            ..NumberFormat::trimmed(d)
        };
        let name = program_name(&program.name);
        let mut lines = Lines {
            out: String::new(),
            next: 0,
        };
        let mut lw = LineWriter {
            linear: signed(o.linear_decimals),
            angular: signed(o.angular_decimals),
            feed_fmt: NumberFormat::trimmed(o.feed_decimals),
            last: Default::default(),
            feed: None,
        };
        lines.line(&format!("BEGIN PGM {name} MM"));
        for h in &o.header {
            lines.line(h.trim());
        }
        let safe = format!(
            "L Z{} R0 FMAX M91",
            num(lw.linear, o.safe_z_machine, "Z", At::program())?
        );
        let (tcpm_on, tcpm_off) = match self.tcpm {
            Tcpm::Function => (
                "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS",
                "FUNCTION RESET TCPM",
            ),
            Tcpm::M128 => ("M128", "M129"),
        };
        for op in &program.operations {
            let at = At::start(&op.name);
            if o.comments {
                lines.line(&format!("; {}", sanitize(&op_comment(op), true)));
            }
            lines.line(&safe);
            let s = match op.tool.spindle {
                Some(sp) => format!(" S{}", num(NumberFormat::trimmed(0), sp.rpm, "S", at)?),
                None => String::new(),
            };
            lines.line(&format!("TOOL CALL {} Z{s}", op.tool.number));
            lines.line(spindle_code(op.tool.spindle));
            lines.line(o.coolant_codes.code(op.tool.coolant));
            lw.forget_positions();
            match &op.motion {
                Motion::Simultaneous { mode, moves } => {
                    require_tcp_angles(self.name(), *mode, &op.name, "FUNCTION TCPM")?;
                    let Some(first) = moves.first() else { continue };
                    if !first.rotary.is_empty() {
                        lines.line(&format!(
                            "L {} R0 FMAX",
                            rotary_words(first, lw.angular, at)?
                        ));
                    }
                    lines.line(tcpm_on);
                    for (i, mv) in moves.iter().enumerate() {
                        lw.write(
                            &mut lines,
                            mv,
                            "",
                            At {
                                op: &op.name,
                                block: i,
                            },
                        )?;
                    }
                    lines.line(tcpm_off);
                }
                Motion::Indexed {
                    tool_axis, tips, ..
                } => {
                    let plane = TiltedPlane::spatial_ab(tool_axis);
                    lines.line(&format!(
                        "PLANE SPATIAL SPA{} SPB{} SPC+0 TURN FMAX",
                        num(lw.angular, plane.a.to_degrees(), "SPA", at)?,
                        num(lw.angular, plane.b.to_degrees(), "SPB", at)?
                    ));
                    for (i, (p, f)) in tips.iter().enumerate() {
                        let q = plane.to_plane(p);
                        let mv = tip_move([q.x, q.y, q.z], *f);
                        lw.write(
                            &mut lines,
                            &mv,
                            "",
                            At {
                                op: &op.name,
                                block: i,
                            },
                        )?;
                    }
                    lines.line("PLANE RESET STAY");
                }
            }
            lw.forget_positions();
        }
        lines.line(&safe);
        lines.line("M5");
        lines.line(&o.coolant_codes.off);
        for f in &o.footer {
            lines.line(f.trim());
        }
        lines.line(o.program_end.as_deref().unwrap_or("M30").trim());
        lines.line(&format!("END PGM {name} MM"));
        Ok(lines.out)
    }
}
