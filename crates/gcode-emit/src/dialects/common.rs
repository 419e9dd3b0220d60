//! Pieces of program structure several dialects share.

use crate::dialect::{num, At, BlockWriter, MotionStyle, MotionWriter};
use crate::program::{Feed, Motion, NcMove, NcOperation, OutputMode, ProgramOptions, ToolCall};
use crate::tilted_plane::TiltedPlane;
use crate::{GcodeError, NumberFormat, Spindle};
use cam_core::Point3;

/// `G0`/`G1`, `G93`/`G94`, tool vector as `I J K`; lengths and angles formatted by
/// `positions`, feeds by `feeds`, each with the decimals the options ask for. Dialects
/// override the words their controller spells differently.
pub fn iso_style(
    o: &ProgramOptions,
    positions: fn(usize) -> NumberFormat,
    feeds: fn(usize) -> NumberFormat,
) -> MotionStyle {
    MotionStyle {
        rapid: "G0",
        linear: "G1",
        feed_modes: ("G93", "G94"),
        vector_words: ["I", "J", "K"],
        linear_fmt: positions(o.linear_decimals),
        angular_fmt: positions(o.angular_decimals),
        feed_fmt: feeds(o.feed_decimals),
        inverse_fmt: feeds(o.inverse_time_decimals),
    }
}

/// The retract block to the safe height in machine coordinates: `before Z<safe>after`
/// (each controller names machine coordinates its own way: `G53 G0`, `G00 .. M91`,
/// `G0 SUPA .. D0`).
pub fn retract_block(
    before: &str,
    after: &str,
    o: &ProgramOptions,
    fmt: NumberFormat,
) -> Result<String, GcodeError> {
    let z = num(fmt, o.safe_z_machine, "Z", At::program())?;
    Ok(format!("{before} Z{z}{after}"))
}

/// The spindle block (`S.. M3`/`M4`, integer speed, or `M5`) and the coolant block (the
/// options' code of the operation's coolant).
pub fn spindle_and_coolant(
    w: &mut BlockWriter,
    tool: &ToolCall,
    o: &ProgramOptions,
    at: At<'_>,
) -> Result<(), GcodeError> {
    w.block(&spindle_words(tool.spindle, NumberFormat::trimmed(0), at)?);
    w.block(o.coolant_codes.code(tool.coolant));
    Ok(())
}

/// The machine's own start blocks ([`ProgramOptions::header`]).
pub fn header(w: &mut BlockWriter, o: &ProgramOptions) {
    for line in &o.header {
        w.block(line.trim());
    }
}

/// The program's closing blocks: spindle and coolant off (`M5`, the off code), the machine's
/// own blocks ([`ProgramOptions::footer`]), then the end code (the options' or `default_end`).
pub fn footer(w: &mut BlockWriter, o: &ProgramOptions, default_end: &str) {
    w.block("M5");
    w.block(&o.coolant_codes.off);
    for line in &o.footer {
        w.block(line.trim());
    }
    w.block(o.program_end.as_deref().unwrap_or(default_end).trim());
}

/// Rapid of the rotary axes alone to the first move's angles, before the linear approach;
/// nothing when the move has no rotary words or in tool-vector mode (there the control
/// chooses the angles).
pub fn preposition_rotary(
    w: &mut BlockWriter,
    style: MotionStyle,
    mode: OutputMode,
    first: &NcMove,
    at: At<'_>,
) -> Result<(), GcodeError> {
    if mode != OutputMode::TcpVector && !first.rotary.is_empty() {
        w.block(&format!(
            "{} {}",
            style.rapid,
            rotary_words(first, style.angular_fmt, at)?
        ));
    }
    Ok(())
}

/// Rapid in X Y alone to the first move, so the approach that follows runs along Z.
pub fn xy_approach(
    w: &mut BlockWriter,
    style: MotionStyle,
    first: &NcMove,
    at: At<'_>,
) -> Result<(), GcodeError> {
    let fmt = style.linear_fmt;
    w.block(&format!(
        "{} X{} Y{}",
        style.rapid,
        num(fmt, first.xyz[0], "X", at)?,
        num(fmt, first.xyz[1], "Y", at)?
    ));
    Ok(())
}

/// The block leaving inverse-time mode (`G94`), if the moves written so far entered it.
pub fn leave_inverse_time(w: &mut BlockWriter, mw: &mut MotionWriter) {
    if let Some(feed_mode) = mw.leave_inverse_time() {
        w.block(feed_mode);
    }
}

/// The tips of a 3+2 operation once the control's tilted plane is active: each tip mapped
/// into the plane's frame, an X Y rapid to the first, then three-axis moves, the first
/// written block carrying `prefix`.
pub fn write_tilted_tips(
    w: &mut BlockWriter,
    mw: &mut MotionWriter,
    op_name: &str,
    plane: &TiltedPlane,
    tips: &[(Point3, Feed)],
    prefix: &str,
) -> Result<(), GcodeError> {
    let moves: Vec<_> = tips
        .iter()
        .map(|(p, f)| {
            let q = plane.to_plane(p);
            tip_move([q.x, q.y, q.z], *f)
        })
        .collect();
    if let Some(first) = moves.first() {
        xy_approach(w, mw.style(), first, At::start(op_name))?;
    }
    write_moves(w, mw, op_name, OutputMode::TcpAngles, &moves, prefix)
}

/// The spindle's direction code: `M3` clockwise, `M4` counter-clockwise, `M5` stopped.
pub fn spindle_code(sp: Option<Spindle>) -> &'static str {
    match sp {
        Some(s) if !s.clockwise => "M4",
        Some(_) => "M3",
        None => "M5",
    }
}

/// An error naming the operation unless its simultaneous moves are tool-centre-point angles
/// (`how` says how the dialect switches TCP on, e.g. `M128`).
pub fn require_tcp_angles(
    dialect: &'static str,
    mode: OutputMode,
    op_name: &str,
    how: &str,
) -> Result<(), GcodeError> {
    if mode == OutputMode::TcpAngles {
        return Ok(());
    }
    Err(GcodeError::Unsupported {
        dialect,
        what: format!("{mode:?} output (operation `{op_name}`); use TCP ({how})"),
    })
}

/// `M3`/`M4` with `S`, or `M5`.
pub fn spindle_words(
    sp: Option<Spindle>,
    fmt: NumberFormat,
    at: At<'_>,
) -> Result<String, GcodeError> {
    Ok(match sp {
        Some(s) => format!("S{} {}", num(fmt, s.rpm, "S", at)?, spindle_code(sp)),
        None => "M5".to_string(),
    })
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
