//! Writing a [`ClProgram`] as APT CLDATA text that [`super::read_cl`] reads back.
//!
//! Layout per operation: `TOOL PATH/name,TOOL,tool`, `LOADTL/n` (`LOADTL/n,LENGTH,l` with the
//! gauge length), `CUTTER/d,r,e,f,a,b,h`,
//! `SPINDL/RPM,n,CLW|CCLW`, `COOLNT`, `PPRINT` comments, then `RAPID` + `GOTO` for rapid moves
//! and `FEDRAT/MMPM,f` (only when the feed changes) + `GOTO` for the others, and
//! `END-OF-PATH`; the file ends with `FINI`. Units are millimetres (`UNITS/MM`).
//!
//! Round trip: tips, axes, rapid/non-rapid, feeds (a `None` feed inherits the previous one,
//! as in the move model), tool numbers and lengths, cutters, spindle, coolant and comments read back as
//! written. `Plunge` and `Retract` moves read back as `Feed` (APT has no such kinds).
//! With `decimals = None` numbers use Rust's shortest exact representation, so positions
//! read back bit for bit (axes that are unit to rounding are kept as written).

use super::{ClProgram, Coolant};
use crate::{apt_to_cl_params, write_atomic, GcodeError, NumberFormat};
use cam_core::AptCutter;
use cam_core::MoveKind;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Options of the CL writer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ClWriteOptions {
    /// Fixed decimals for every number; `None` writes the shortest exact decimal form.
    pub decimals: Option<usize>,
}

struct Num {
    fmt: Option<NumberFormat>,
}

impl Num {
    fn f(&self, v: f64, what: &str, op: &str, block: usize) -> Result<String, GcodeError> {
        let err = || GcodeError::NonFinite {
            operation: op.to_string(),
            block,
            word: what.to_string(),
            value: v,
        };
        if !v.is_finite() {
            return Err(err());
        }
        match self.fmt {
            Some(f) => f.format(v).ok_or_else(err),
            // Display of f64 is the shortest string that parses back to the same value and
            // never uses an exponent.
            None => Ok(if v == 0.0 {
                "0".to_string()
            } else {
                format!("{v}")
            }),
        }
    }
}

/// Writes `program` as CL text.
pub fn write_cl(program: &ClProgram, options: &ClWriteOptions) -> Result<String, GcodeError> {
    let num = Num {
        fmt: options.decimals.map(NumberFormat::trimmed),
    };
    let mut out = String::new();
    let mut line = |s: &str| {
        out.push_str(s);
        out.push('\n');
    };
    if let Some(name) = &program.part_name {
        line(&format!("PARTNO {}", one_line(name)));
    }
    line("UNITS/MM");
    for op in &program.operations {
        let name = &op.path.name;
        line(&format!(
            "TOOL PATH/{},TOOL,{}",
            one_line(name).replace(',', " "),
            one_line(&op.path.tool).replace(',', " ")
        ));
        line(if op.multax { "MULTAX/ON" } else { "MULTAX/OFF" });
        match (op.tool_number, op.tool_length_mm) {
            (Some(n), Some(l)) => {
                line(&format!(
                    "LOADTL/{n},LENGTH,{}",
                    num.f(l, "LOADTL", name, 2)?
                ));
            }
            (Some(n), None) => line(&format!("LOADTL/{n}")),
            _ => {}
        }
        let apt = op.apt_cutter.or_else(|| {
            op.cutter
                .as_ref()
                .map(|c| AptCutter::from_shape(&c.shape, c.flute_length))
        });
        if let Some(apt) = apt {
            let mut s = String::from("CUTTER/");
            for (i, v) in apt_to_cl_params(&apt).iter().enumerate() {
                if i > 0 {
                    s.push(',');
                }
                s.push_str(&num.f(*v, "CUTTER", name, 0)?);
            }
            line(&s);
        }
        if let Some(sp) = op.spindle {
            line(&format!(
                "SPINDL/RPM,{},{}",
                num.f(sp.rpm, "SPINDL", name, 0)?,
                if sp.clockwise { "CLW" } else { "CCLW" }
            ));
        }
        line(match op.coolant {
            Coolant::Off => "COOLNT/OFF",
            Coolant::Flood => "COOLNT/FLOOD",
            Coolant::Mist => "COOLNT/MIST",
            Coolant::ThroughTool => "COOLNT/THRU",
        });
        for c in &op.comments {
            line(&format!("PPRINT/{}", one_line(c)));
        }
        let mut feed: Option<f64> = None;
        for (i, m) in op.path.moves.iter().enumerate() {
            if m.kind == MoveKind::Rapid {
                line("RAPID");
            } else if let Some(f) = m.feed_mm_per_min {
                if feed != Some(f) {
                    line(&format!("FEDRAT/MMPM,{}", num.f(f, "FEDRAT", name, i)?));
                    feed = Some(f);
                }
            }
            let t = m.cl.tip;
            let a = m.cl.axis;
            let mut s = String::from("GOTO/");
            for (k, v) in [t.x, t.y, t.z, a.x, a.y, a.z].iter().enumerate() {
                if k > 0 {
                    s.push(',');
                }
                s.push_str(&num.f(*v, "GOTO", name, i)?);
            }
            line(&s);
        }
        line("END-OF-PATH");
    }
    line("FINI");
    Ok(out)
}

/// Writes `program` to `path` through a temporary file in the same directory, renamed into
/// place only when complete.
pub fn write_cl_file(
    path: &Path,
    program: &ClProgram,
    options: &ClWriteOptions,
) -> Result<(), GcodeError> {
    let text = write_cl(program, options)?;
    write_atomic(path, text.as_bytes())
}

/// Removes line breaks (a CL record is one line here).
fn one_line(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}
