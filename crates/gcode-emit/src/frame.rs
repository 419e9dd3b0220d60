//! The program frame a machine's controller expects, from the `[program]` table of the
//! machine file (`postproc_kinematics::Machine` keeps that table for this module):
//!
//! ```toml
//! [program]
//! kinematics = "trivial"         # LinuxCNC: "trivial" (trivkins: the axes are the joints,
//!                                # no kinematics switch) | "switchable" (switchkins)
//! tcp_code = "M428"              # switchable: the remapped M code selecting TCP kinematics
//! identity_code = "M429"         # switchable: the one selecting identity kinematics
//! header = ["G64 P0.005"]        # blocks after the setup block
//! footer = ["G53 G0 Y0"]         # blocks before the end code
//! program_end = "M30"            # default: the dialect's (LinuxCNC M2, others M30)
//! block_numbers = { start = 10, step = 10, wrap = 99999 }   # or false (no numbers)
//! [program.coolant]              # M codes per coolant state (defaults shown)
//! flood = "M8"
//! mist = "M7"
//! through = "M8"
//! off = "M9"
//! ```
//!
//! Every key is optional; an unknown key or a value of the wrong type is an error naming the
//! file, the line and the key. Without `kinematics` a LinuxCNC program selects identity
//! kinematics with `M429` first (LinuxCNC's sample switchkins configurations); a trivkins
//! configuration rejects that code, so its machine file says `kinematics = "trivial"`.

use crate::dialect::{dialect_by_name, Dialect};
use crate::program::{CoolantCodes, LineNumbers, ProgramOptions};
use crate::{GcodeError, KinematicsSwitch, LinuxCnc};
use serde::Deserialize;
use toml::Spanned;

/// A machine's program frame (see the module docs).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ProgramFrame {
    /// LinuxCNC kinematics (`None`: not given, the dialect's default).
    pub kinematics: Option<KinematicsSwitch>,
    /// Blocks after the setup block.
    pub header: Vec<String>,
    /// Blocks before the end code.
    pub footer: Vec<String>,
    /// Program end code (`None`: the dialect's).
    pub program_end: Option<String>,
    /// Block numbering: `None` not given (the caller's), `Some(None)` off.
    pub block_numbers: Option<Option<LineNumbers>>,
    /// Coolant M codes.
    pub coolant_codes: CoolantCodes,
}

#[derive(Debug, Deserialize)]
struct RawFile {
    program: Option<Spanned<RawFrame>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFrame {
    kinematics: Option<Spanned<String>>,
    tcp_code: Option<Spanned<String>>,
    identity_code: Option<Spanned<String>>,
    #[serde(default)]
    header: Vec<String>,
    #[serde(default)]
    footer: Vec<String>,
    program_end: Option<String>,
    block_numbers: Option<Spanned<RawNumbers>>,
    coolant: Option<RawCoolant>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum RawNumbers {
    Switch(bool),
    Numbers {
        start: u32,
        step: u32,
        wrap: Option<u32>,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCoolant {
    flood: Option<String>,
    mist: Option<String>,
    through: Option<String>,
    off: Option<String>,
}

fn line_at(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

impl ProgramFrame {
    /// The frame of the machine file `text` (`file` names it in errors); the default frame
    /// when the file has no `[program]` table. Only that table is read: the rest of the file
    /// is `postproc_kinematics::Machine`'s.
    pub fn from_machine_toml(text: &str, file: &str) -> Result<Self, GcodeError> {
        let err = |line: usize, field: &str, message: String| GcodeError::Frame {
            file: file.to_string(),
            line,
            field: field.to_string(),
            message,
        };
        let raw: RawFile = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(0, |s| line_at(text, s.start));
            let message = e.message().trim().to_string();
            let field = match message.split('`').nth(1) {
                Some(k) if message.starts_with("unknown field") => format!("program.{k}"),
                _ => "program".to_string(),
            };
            err(line, &field, message)
        })?;
        let Some(frame) = raw.program else {
            return Ok(Self::default());
        };
        let frame = frame.into_inner();
        let code = |v: &Option<Spanned<String>>, default: &str| -> String {
            v.as_ref()
                .map_or(default.to_string(), |s| s.get_ref().trim().to_string())
        };
        let kinematics = match &frame.kinematics {
            None => None,
            Some(k) => Some(match k.get_ref().as_str() {
                "trivial" => {
                    for (key, v) in [
                        ("tcp_code", &frame.tcp_code),
                        ("identity_code", &frame.identity_code),
                    ] {
                        if let Some(v) = v {
                            return Err(err(
                                line_at(text, v.span().start),
                                &format!("program.{key}"),
                                "trivial kinematics have no kinematics switch; remove the key \
                                 or say kinematics = \"switchable\""
                                    .into(),
                            ));
                        }
                    }
                    KinematicsSwitch::Trivial
                }
                "switchable" => KinematicsSwitch::Switchable {
                    tcp: code(&frame.tcp_code, "M428"),
                    identity: code(&frame.identity_code, "M429"),
                },
                other => {
                    return Err(err(
                        line_at(text, k.span().start),
                        "program.kinematics",
                        format!("must be \"trivial\" or \"switchable\", got \"{other}\""),
                    ))
                }
            }),
        };
        if kinematics.is_none() {
            if let Some(v) = frame.tcp_code.as_ref().or(frame.identity_code.as_ref()) {
                return Err(err(
                    line_at(text, v.span().start),
                    "program.kinematics",
                    "M codes of a kinematics switch need kinematics = \"switchable\"".into(),
                ));
            }
        }
        let block_numbers = match &frame.block_numbers {
            None => None,
            Some(b) => {
                let line = line_at(text, b.span().start);
                match b.get_ref() {
                    RawNumbers::Switch(false) => Some(None),
                    RawNumbers::Switch(true) => Some(Some(LineNumbers::new(10, 10))),
                    RawNumbers::Numbers { start, step, wrap } => {
                        if *step == 0 {
                            return Err(err(
                                line,
                                "program.block_numbers.step",
                                "must be > 0".into(),
                            ));
                        }
                        if let Some(w) = wrap {
                            if *w < start.saturating_add(*step) {
                                return Err(err(
                                    line,
                                    "program.block_numbers.wrap",
                                    format!("{w} leaves no room after start {start} + step {step}"),
                                ));
                            }
                        }
                        Some(Some(LineNumbers {
                            start: *start,
                            step: *step,
                            wrap: *wrap,
                        }))
                    }
                }
            }
        };
        let mut coolant_codes = CoolantCodes::default();
        if let Some(c) = frame.coolant {
            for (slot, v) in [
                (&mut coolant_codes.flood, c.flood),
                (&mut coolant_codes.mist, c.mist),
                (&mut coolant_codes.through, c.through),
                (&mut coolant_codes.off, c.off),
            ] {
                if let Some(v) = v {
                    *slot = v.trim().to_string();
                }
            }
        }
        let out = Self {
            kinematics,
            header: frame.header,
            footer: frame.footer,
            program_end: frame.program_end,
            block_numbers,
            coolant_codes,
        };
        // The same checks as the options the frame goes into, with the file named.
        let mut probe = ProgramOptions::default();
        out.apply(&mut probe);
        probe.validate().map_err(|e| match e {
            GcodeError::InvalidOption { field, reason } => {
                let key = field.replace("coolant_codes", "coolant");
                let needle = key.split('.').next_back().unwrap_or(&key).to_string();
                let line = text
                    .lines()
                    .position(|l| l.trim_start().starts_with(&needle))
                    .map_or(0, |i| i + 1);
                err(line, &format!("program.{key}"), reason)
            }
            other => other,
        })?;
        Ok(out)
    }

    /// Puts the frame into `options` (header, footer, end code, coolant codes, block numbers
    /// when given).
    pub fn apply(&self, options: &mut ProgramOptions) {
        options.header.clone_from(&self.header);
        options.footer.clone_from(&self.footer);
        options.program_end.clone_from(&self.program_end);
        options.coolant_codes = self.coolant_codes.clone();
        if let Some(n) = self.block_numbers {
            options.line_numbers = n;
        }
    }

    /// The dialect `name` ([`dialect_by_name`]) set up for this machine: LinuxCNC with the
    /// frame's kinematics switch.
    pub fn dialect(&self, name: &str) -> Result<Box<dyn Dialect>, GcodeError> {
        let d = dialect_by_name(name)?;
        match (&self.kinematics, d.name()) {
            (Some(k), "linuxcnc") => Ok(Box::new(LinuxCnc {
                kinematics: k.clone(),
            })),
            _ => Ok(d),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const BASE: &str = "name = \"m\"\n[kinematics]\ntype = \"table-table\"\n";

    #[test]
    fn a_file_without_the_table_has_the_default_frame() {
        let f = ProgramFrame::from_machine_toml(BASE, "m.toml").unwrap();
        assert_eq!(f, ProgramFrame::default());
        let d = f.dialect("linuxcnc").unwrap();
        assert_eq!(d.name(), "linuxcnc");
    }

    /// The LinuxCNC sample machine is set up for a trivkins configuration: no switch.
    #[test]
    fn the_embedded_machine_is_trivkins() {
        let text = include_str!("../embedded/machines/xyzac-trt.toml");
        let f = ProgramFrame::from_machine_toml(text, "xyzac-trt.toml").unwrap();
        assert_eq!(f.kinematics, Some(KinematicsSwitch::Trivial));
        let d = f.dialect("linuxcnc").unwrap();
        assert!(!d.supports(crate::OutputMode::TcpAngles));
    }

    #[test]
    fn every_key_is_read() {
        let text = format!(
            "{BASE}[program]\nkinematics = \"switchable\"\ntcp_code = \"M128\"\n\
             identity_code = \"M129\"\nheader = [\"G64 P0.01\"]\nfooter = [\"G0 Y0\"]\n\
             program_end = \"M30\"\nblock_numbers = {{ start = 1, step = 1, wrap = 9999 }}\n\
             [program.coolant]\nthrough = \"M88\"\n"
        );
        let f = ProgramFrame::from_machine_toml(&text, "m.toml").unwrap();
        assert_eq!(
            f.kinematics,
            Some(KinematicsSwitch::Switchable {
                tcp: "M128".into(),
                identity: "M129".into()
            })
        );
        assert_eq!(f.header, ["G64 P0.01"]);
        assert_eq!(f.footer, ["G0 Y0"]);
        assert_eq!(f.program_end.as_deref(), Some("M30"));
        assert_eq!(
            f.block_numbers,
            Some(Some(LineNumbers {
                start: 1,
                step: 1,
                wrap: Some(9999)
            }))
        );
        assert_eq!(f.coolant_codes.through, "M88");
        assert_eq!(f.coolant_codes.flood, "M8");
        let text = format!("{BASE}[program]\nblock_numbers = false\n");
        let f = ProgramFrame::from_machine_toml(&text, "m.toml").unwrap();
        assert_eq!(f.block_numbers, Some(None));
    }

    #[test]
    fn errors_name_file_line_and_key() {
        for (body, key, line) in [
            ("kinematics = \"trivkins\"\n", "program.kinematics", 5),
            (
                "kinematics = \"trivial\"\ntcp_code = \"M428\"\n",
                "program.tcp_code",
                6,
            ),
            ("tcp_code = \"M428\"\n", "program.kinematics", 5),
            ("coolant_on = \"M8\"\n", "program.coolant_on", 5),
            (
                "block_numbers = { start = 10, step = 10, wrap = 15 }\n",
                "program.block_numbers.wrap",
                5,
            ),
            ("header = [\"G64\\nM3\"]\n", "program.header", 5),
        ] {
            let text = format!("{BASE}[program]\n{body}");
            let e = ProgramFrame::from_machine_toml(&text, "m.toml")
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with(&format!("m.toml:{line}: field `{key}`")),
                "{body}: {e}"
            );
        }
    }
}
