//! The [`Dialect`] trait, the registry of built-in dialects, and the block-level helpers
//! dialects share (block numbering, number formatting with error context, modal motion
//! words).

use crate::program::{Feed, LineNumbers, NcMove, NcProgram, OutputMode, ProgramOptions};
use crate::{write_atomic, GcodeError, NumberFormat};
use std::path::Path;

/// A controller dialect: turns an [`NcProgram`] into program text.
///
/// Implement it to support another controller; [`write_program_file`] writes any dialect's
/// output atomically.
pub trait Dialect: std::fmt::Debug {
    /// Short name used on the command line (`linuxcnc`, `fanuc`, ...).
    fn name(&self) -> &'static str;
    /// Usual file extension, without the dot.
    fn extension(&self) -> &'static str;
    /// Whether simultaneous operations in `mode` can be written.
    fn supports(&self, mode: OutputMode) -> bool;
    /// Whether 3+2 (indexed) operations can be written as a tilted working plane.
    fn supports_indexed(&self) -> bool;
    /// The whole program text.
    fn write(&self, program: &NcProgram, options: &ProgramOptions) -> Result<String, GcodeError>;
}

/// Names accepted by [`dialect_by_name`].
pub const DIALECT_NAMES: [&str; 5] = [
    "linuxcnc",
    "fanuc",
    "sinumerik",
    "heidenhain",
    "heidenhain_conversational",
];

/// A built-in dialect with its default settings, by name (case-insensitive).
pub fn dialect_by_name(name: &str) -> Result<Box<dyn Dialect>, GcodeError> {
    match name.to_ascii_lowercase().as_str() {
        "linuxcnc" => Ok(Box::new(crate::LinuxCnc::default())),
        "fanuc" => Ok(Box::new(crate::Fanuc)),
        "sinumerik" => Ok(Box::new(crate::Sinumerik::default())),
        "heidenhain" => Ok(Box::new(crate::HeidenhainIso)),
        "heidenhain_conversational" => Ok(Box::new(crate::HeidenhainConversational::default())),
        _ => Err(GcodeError::UnknownDialect {
            name: name.to_string(),
            valid: DIALECT_NAMES.join(", "),
        }),
    }
}

/// Writes `program` in `dialect` to `path` through a temporary file in the same directory,
/// renamed into place only when complete.
pub fn write_program_file(
    path: &Path,
    dialect: &dyn Dialect,
    program: &NcProgram,
    options: &ProgramOptions,
) -> Result<(), GcodeError> {
    let text = dialect.write(program, options)?;
    write_atomic(path, text.as_bytes())
}

/// Collects blocks, numbering them if asked.
#[derive(Debug)]
pub struct BlockWriter {
    out: String,
    numbers: Option<LineNumbers>,
    next: u64,
    suffix: &'static str,
}

impl BlockWriter {
    /// A writer numbering blocks per `numbers` and ending each block with `suffix`
    /// (Heidenhain ISO: `" *"`).
    pub fn new(numbers: Option<LineNumbers>, suffix: &'static str) -> Self {
        Self {
            out: String::new(),
            next: numbers.map_or(0, |n| u64::from(n.start)),
            numbers,
            suffix,
        }
    }

    /// Appends a numbered block (numbers start again at `start` after `wrap`).
    pub fn block(&mut self, words: &str) {
        if let Some(n) = self.numbers {
            if n.wrap.is_some_and(|w| self.next > u64::from(w)) {
                self.next = u64::from(n.start);
            }
            self.out.push('N');
            self.out.push_str(&self.next.to_string());
            self.out.push(' ');
            self.next += u64::from(n.step);
        }
        self.out.push_str(words);
        self.out.push_str(self.suffix);
        self.out.push('\n');
    }

    /// Appends a line as is (no number, no suffix).
    pub fn raw(&mut self, line: &str) {
        self.out.push_str(line);
        self.out.push('\n');
    }

    /// The text.
    pub fn finish(self) -> String {
        self.out
    }
}

/// Where a value is being written, for error messages.
#[derive(Debug, Clone, Copy)]
pub struct At<'a> {
    /// Operation name.
    pub op: &'a str,
    /// Block index in the operation.
    pub block: usize,
}

impl<'a> At<'a> {
    /// The program-level blocks (header, retract, end).
    pub const fn program() -> At<'static> {
        At {
            op: "program",
            block: 0,
        }
    }

    /// The blocks that set up operation `op` before its first move.
    pub const fn start(op: &'a str) -> Self {
        Self { op, block: 0 }
    }
}

/// Formats `v` with `fmt` or returns [`GcodeError::NonFinite`] naming the word and block.
pub fn num(fmt: NumberFormat, v: f64, word: &str, at: At<'_>) -> Result<String, GcodeError> {
    fmt.format(v).ok_or_else(|| GcodeError::NonFinite {
        operation: at.op.to_string(),
        block: at.block,
        word: word.to_string(),
        value: v,
    })
}

/// Keeps only characters every control accepts in a comment or name; parentheses and
/// semicolons become spaces or brackets.
pub fn sanitize(text: &str, upper: bool) -> String {
    let s: String = text
        .chars()
        .map(|c| match c {
            '(' => '[',
            ')' => ']',
            ';' | '*' | '%' | '\n' | '\r' | '\t' => ' ',
            c if c.is_ascii() && !c.is_ascii_control() => c,
            _ => '_',
        })
        .collect();
    if upper {
        s.to_ascii_uppercase()
    } else {
        s
    }
}

/// A program name reduced to `[A-Z0-9_]` (non-empty).
pub fn program_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "PROGRAM".into()
    } else {
        s
    }
}

/// Words and number styles of a G-code-like dialect's motion blocks.
#[derive(Debug, Clone, Copy)]
pub struct MotionStyle {
    /// Rapid code (`G0` / `G00`).
    pub rapid: &'static str,
    /// Linear feed code (`G1` / `G01`).
    pub linear: &'static str,
    /// Inverse-time and per-minute feed mode codes (`G93`, `G94`).
    pub feed_modes: (&'static str, &'static str),
    /// Address of the three tool-vector components (`I J K`, `A3= B3= C3=`).
    pub vector_words: [&'static str; 3],
    /// Linear number format.
    pub linear_fmt: NumberFormat,
    /// Angular and vector number format.
    pub angular_fmt: NumberFormat,
    /// mm/min feed format.
    pub feed_fmt: NumberFormat,
    /// Inverse-time feed format.
    pub inverse_fmt: NumberFormat,
}

/// Modal motion writer: emits the motion code and the axis words that changed; inverse-time
/// `F` on every `G93` block (as LinuxCNC and Fanuc require), mm/min `F` when it changes.
/// Reuses its buffers: no allocation per block once warmed up, except the block text.
#[derive(Debug)]
pub struct MotionWriter {
    style: MotionStyle,
    motion: Option<bool>,
    /// Last written value of X Y Z A B C and the three vector words.
    last: [Option<String>; 9],
    feed: Option<String>,
    inverse: bool,
    value: String,
    axes: String,
}

/// Slot of a rotary letter in [`MotionWriter::last`]; other letters are always written.
fn rotary_slot(letter: char) -> Option<usize> {
    match letter.to_ascii_uppercase() {
        'A' => Some(3),
        'B' => Some(4),
        'C' => Some(5),
        _ => None,
    }
}

impl MotionWriter {
    /// A writer with no modal state.
    pub fn new(style: MotionStyle) -> Self {
        Self {
            style,
            motion: None,
            last: Default::default(),
            feed: None,
            inverse: false,
            value: String::new(),
            axes: String::new(),
        }
    }

    /// Forgets the last positions and motion code (after a tool change, a kinematics switch
    /// or a move written by other means), so the next block states every word.
    pub fn forget_positions(&mut self) {
        self.motion = None;
        for l in &mut self.last {
            *l = None;
        }
    }

    /// The words and number formats this writer uses.
    pub fn style(&self) -> MotionStyle {
        self.style
    }

    /// `true` while inverse-time mode is active.
    pub fn inverse_time_active(&self) -> bool {
        self.inverse
    }

    /// The block that leaves inverse-time mode, if it is active.
    pub fn leave_inverse_time(&mut self) -> Option<&'static str> {
        if self.inverse {
            self.inverse = false;
            self.feed = None;
            Some(self.style.feed_modes.1)
        } else {
            None
        }
    }

    /// Formats `v` into the scratch value and appends `addr value` to the axis words if it
    /// differs from the last value written in `slot`.
    fn axis_word(
        &mut self,
        slot: Option<usize>,
        addr: &str,
        v: f64,
        fmt: NumberFormat,
        at: At<'_>,
    ) -> Result<(), GcodeError> {
        self.value.clear();
        if !fmt.write_to(v, &mut self.value) {
            return Err(GcodeError::NonFinite {
                operation: at.op.to_string(),
                block: at.block,
                word: addr.to_string(),
                value: v,
            });
        }
        if let Some(k) = slot {
            match &mut self.last[k] {
                Some(prev) if *prev == self.value => return Ok(()),
                Some(prev) => prev.clone_from(&self.value),
                none => *none = Some(self.value.clone()),
            }
        }
        if !self.axes.is_empty() {
            self.axes.push(' ');
        }
        self.axes.push_str(addr);
        self.axes.push_str(&self.value);
        Ok(())
    }

    /// Writes one move; `prefix` words (e.g. `G43.4 H3`) go right after the motion code.
    /// Returns `false` (and writes nothing) when no axis word changed and no prefix is given.
    pub fn write(
        &mut self,
        w: &mut BlockWriter,
        mv: &NcMove,
        mode: OutputMode,
        prefix: &str,
        at: At<'_>,
    ) -> Result<bool, GcodeError> {
        let st = self.style;
        self.axes.clear();
        for (k, (addr, v)) in ["X", "Y", "Z"].iter().zip(mv.xyz).enumerate() {
            self.axis_word(Some(k), addr, v, st.linear_fmt, at)?;
        }
        if mode == OutputMode::TcpVector {
            let Some(t) = mv.tool_vector else {
                return Err(GcodeError::MissingToolVector {
                    operation: at.op.to_string(),
                    block: at.block,
                });
            };
            for (k, (addr, v)) in st.vector_words.iter().zip(t).enumerate() {
                self.axis_word(Some(6 + k), addr, v, st.angular_fmt, at)?;
            }
        } else {
            let mut letter = [0u8; 4];
            for r in &mv.rotary {
                let addr: &str = r.letter.encode_utf8(&mut letter);
                self.axis_word(rotary_slot(r.letter), addr, r.deg, st.angular_fmt, at)?;
            }
        }
        if self.axes.is_empty() && prefix.is_empty() {
            return Ok(false);
        }
        let mut block = String::with_capacity(self.axes.len() + 32);
        let word = |block: &mut String, w: &str| {
            if !block.is_empty() {
                block.push(' ');
            }
            block.push_str(w);
        };
        let rapid = matches!(mv.feed, Feed::Rapid);
        match mv.feed {
            Feed::InverseTime(_) if !self.inverse => {
                word(&mut block, st.feed_modes.0);
                self.inverse = true;
                self.feed = None;
            }
            Feed::PerMinute(_) if self.inverse => {
                word(&mut block, st.feed_modes.1);
                self.inverse = false;
                self.feed = None;
            }
            _ => {}
        }
        if self.motion != Some(rapid) {
            word(&mut block, if rapid { st.rapid } else { st.linear });
            self.motion = Some(rapid);
        }
        if !prefix.is_empty() {
            word(&mut block, prefix);
        }
        if !self.axes.is_empty() {
            word(&mut block, &self.axes);
        }
        match mv.feed {
            Feed::Rapid => {}
            Feed::PerMinute(f) => {
                let s = num(st.feed_fmt, f, "F", at)?;
                if self.feed.as_deref() != Some(s.as_str()) {
                    word(&mut block, &format!("F{s}"));
                    self.feed = Some(s);
                }
            }
            Feed::InverseTime(f) => {
                // A slow block has a small 1/min value: keep at least four significant
                // digits (up to 9 decimals) so it never prints as F0.
                let mut fmt = st.inverse_fmt;
                if f > 0.0 && f.is_finite() {
                    let need = (4.0 - f.log10().floor() - 1.0).clamp(0.0, 9.0) as usize;
                    fmt.decimals = fmt.decimals.max(need);
                }
                word(&mut block, &format!("F{}", num(fmt, f, "F", at)?));
            }
        }
        w.block(&block);
        Ok(true)
    }
}
