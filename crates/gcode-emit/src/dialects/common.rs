//! Pieces of program structure several dialects share.

use crate::dialect::{num, At, BlockWriter, MotionWriter};
use crate::program::{Feed, Motion, NcMove, NcOperation, OutputMode};
use crate::{Coolant, GcodeError, NumberFormat, Spindle};

/// `M3`/`M4` with `S`, or `M5`.
pub fn spindle_words(
    sp: Option<Spindle>,
    fmt: NumberFormat,
    at: At<'_>,
) -> Result<String, GcodeError> {
    Ok(match sp {
        Some(s) => format!(
            "S{} {}",
            num(fmt, s.rpm, "S", at)?,
            if s.clockwise { "M3" } else { "M4" }
        ),
        None => "M5".to_string(),
    })
}

/// Coolant M word (`M7` mist, `M8` flood and through-tool, `M9` off).
pub fn coolant_word(c: Coolant) -> &'static str {
    match c {
        Coolant::Off => "M9",
        Coolant::Mist => "M7",
        Coolant::Flood | Coolant::ThroughTool => "M8",
    }
}

/// The rotary words of a move, formatted (`A10 C-20`).
pub fn rotary_words(mv: &NcMove, fmt: NumberFormat, at: At<'_>) -> Result<String, GcodeError> {
    let mut out = Vec::with_capacity(mv.rotary.len());
    for r in &mv.rotary {
        let a = r.letter.to_string();
        out.push(format!("{a}{}", num(fmt, r.deg, &a, at)?));
    }
    Ok(out.join(" "))
}

/// Simultaneous moves of an operation, or an error naming the operation if it is indexed
/// (for dialects without a tilted-plane function) or in a mode the dialect lacks.
pub fn simultaneous<'a>(
    op: &'a NcOperation,
    dialect: &'static str,
    supported: &[OutputMode],
) -> Result<(OutputMode, &'a [NcMove]), GcodeError> {
    match &op.motion {
        Motion::Simultaneous { mode, moves } if supported.contains(mode) => Ok((*mode, moves)),
        Motion::Simultaneous { mode, .. } => Err(GcodeError::Unsupported {
            dialect,
            what: format!("{mode:?} output (operation `{}`)", op.name),
        }),
        Motion::Indexed { .. } => Err(GcodeError::Unsupported {
            dialect,
            what: format!("3+2 tilted-plane output (operation `{}`)", op.name),
        }),
    }
}

/// Writes the moves of a simultaneous operation; the first written block carries `prefix`.
pub fn write_moves(
    w: &mut BlockWriter,
    mw: &mut MotionWriter,
    op_name: &str,
    mode: OutputMode,
    moves: &[NcMove],
    prefix: &str,
) -> Result<(), GcodeError> {
    let mut prefix = prefix;
    for (i, mv) in moves.iter().enumerate() {
        let at = At {
            op: op_name,
            block: i,
        };
        if mw.write(w, mv, mode, prefix, at)? {
            prefix = "";
        }
    }
    Ok(())
}

/// A rapid move to the given tip (3-axis), used inside tilted planes.
pub fn tip_move(xyz: [f64; 3], feed: Feed) -> NcMove {
    NcMove {
        xyz,
        rotary: Vec::new(),
        tool_vector: None,
        feed,
    }
}

/// `name - T<n>` (plus the tool name when it says more than the number).
pub fn op_comment(op: &NcOperation) -> String {
    let t = format!("T{}", op.tool.number);
    if op.tool.name.is_empty() || op.tool.name == t {
        format!("{} - {t}", op.name)
    } else {
        format!("{} - {t} {}", op.name, op.tool.name)
    }
}
