//! A small reader for the LinuxCNC programs this crate writes (and similar straight-line
//! five-axis programs): `G0`/`G1`, `G93`/`G94`, `F`, `X Y Z A B C`, `G53` one-shot machine
//! coordinates, `N` numbers, `( )` and `;` comments, `%` lines. It returns one joint block
//! per motion block with the modal axis values resolved, so a program can be checked by
//! forward kinematics. O(file size).
//!
//! Not supported (typed error naming line and word): arcs (`G2`/`G3`), incremental mode
//! (`G91`), inch mode (`G20`), parameters and expressions (`#`, `[`), `O` words.

use crate::GcodeError;
use postproc_kinematics::{AxisId, Joints, Machine};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Motion of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GcodeMotion {
    /// `G0`.
    Rapid,
    /// `G1`.
    Linear,
}

/// Feed of a linear block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum GcodeFeed {
    /// `G94` mm/min.
    PerMinute(f64),
    /// `G93` inverse time (1/min).
    InverseTime(f64),
}

/// One motion block with every axis resolved (modal values carried over).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GcodeBlock {
    /// 1-based line.
    pub line: usize,
    /// Rapid or linear.
    pub motion: GcodeMotion,
    /// X Y Z A B C after the block (mm, degrees); `None` for an axis never programmed.
    pub axes: [Option<f64>; 6],
    /// Feed of a linear block (`None` for rapids or when no F was given yet).
    pub feed: Option<GcodeFeed>,
    /// `G53` (machine coordinates) was on this block.
    pub machine_coordinates: bool,
}

/// Reads a program file (see [`read_gcode`]).
pub fn read_gcode_file(path: &Path) -> Result<Vec<GcodeBlock>, GcodeError> {
    let text = std::fs::read_to_string(path).map_err(|source| GcodeError::Io {
        path: path.display().to_string(),
        source,
    })?;
    read_gcode(&text, &path.display().to_string())
}

/// Parses program text; `file` names the source in errors.
pub fn read_gcode(text: &str, file: &str) -> Result<Vec<GcodeBlock>, GcodeError> {
    let mut out = Vec::new();
    let mut axes: [Option<f64>; 6] = [None; 6];
    let mut motion: Option<GcodeMotion> = None;
    let mut inverse = false;
    let mut feed: Option<f64> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let err = |word: &str, reason: &str| GcodeError::GcodeParse {
            file: file.to_string(),
            line,
            word: word.to_string(),
            reason: reason.to_string(),
        };
        let body = strip_comments(raw).map_err(|r| err(raw.trim(), r))?;
        let body = body.trim();
        if body.is_empty() || body.starts_with('%') {
            continue;
        }
        let words = tokenize(body).map_err(|(w, r)| err(&w, r))?;
        let mut new_axes = axes;
        let mut has_axis = false;
        let mut g53 = false;
        let mut block_feed: Option<f64> = None;
        for (letter, value, text) in &words {
            match letter {
                'G' => {
                    let code = (value * 10.0).round() as i64;
                    match code {
                        0 => motion = Some(GcodeMotion::Rapid),
                        10 => motion = Some(GcodeMotion::Linear),
                        930 => inverse = true,
                        940 => {
                            inverse = false;
                            feed = None;
                        }
                        530 => g53 = true,
                        20 | 30 => return Err(err(text, "arcs are not supported")),
                        910 => return Err(err(text, "incremental mode is not supported")),
                        200 => return Err(err(text, "inch mode is not supported")),
                        _ => {}
                    }
                }
                'X' | 'Y' | 'Z' | 'A' | 'B' | 'C' => {
                    let k = "XYZABC".find(*letter).unwrap_or(0);
                    new_axes[k] = Some(*value);
                    has_axis = true;
                }
                'F' => {
                    if *value <= 0.0 {
                        return Err(err(text, "feed must be > 0"));
                    }
                    block_feed = Some(*value);
                }
                'O' => return Err(err(text, "O words (subroutines) are not supported")),
                _ => {}
            }
        }
        if let Some(f) = block_feed {
            feed = Some(f);
        }
        if has_axis {
            let Some(m) = motion else {
                return Err(err(body, "axis words without G0 or G1 in effect"));
            };
            let f = match m {
                GcodeMotion::Rapid => None,
                GcodeMotion::Linear if inverse => match block_feed {
                    Some(f) => Some(GcodeFeed::InverseTime(f)),
                    None => return Err(err(body, "inverse-time move without F")),
                },
                GcodeMotion::Linear => feed.map(GcodeFeed::PerMinute),
            };
            out.push(GcodeBlock {
                line,
                motion: m,
                axes: new_axes,
                feed: f,
                machine_coordinates: g53,
            });
            axes = new_axes;
        }
    }
    Ok(out)
}

/// The machine joints of a block (rotary words in degrees → radians), using the machine's
/// axis letters; `None` while one of its five axes has never been programmed. Feed it to
/// [`Machine::forward`] to verify a program.
pub fn joints_of(block: &GcodeBlock, machine: &Machine) -> Option<Joints> {
    let idx = |a: AxisId| "XYZABC".find(machine.letter(a)).and_then(|k| block.axes[k]);
    Some(Joints {
        x: idx(AxisId::X)?,
        y: idx(AxisId::Y)?,
        z: idx(AxisId::Z)?,
        tilt: idx(AxisId::Tilt)?.to_radians(),
        rotate: idx(AxisId::Rotate)?.to_radians(),
    })
}

/// Removes `( )` comments and everything after `;`.
fn strip_comments(s: &str) -> Result<String, &'static str> {
    let mut out = String::with_capacity(s.len());
    let mut depth = false;
    for c in s.chars() {
        match (depth, c) {
            (false, '(') => depth = true,
            (true, ')') => depth = false,
            (true, _) => {}
            (false, ';') => break,
            (false, ')') => return Err("unbalanced `)`"),
            (false, c) => out.push(c),
        }
    }
    if depth {
        return Err("comment not closed on its line");
    }
    Ok(out)
}

/// Splits a block into (letter, value, word text).
/// A word: letter, value, text as written.
type Word = (char, f64, String);

fn tokenize(s: &str) -> Result<Vec<Word>, (String, &'static str)> {
    let chars: Vec<char> = s.chars().filter(|c| !c.is_whitespace()).collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i].to_ascii_uppercase();
        if c == '/' && i == 0 {
            i += 1;
            continue;
        }
        if !c.is_ascii_alphabetic() {
            return Err((chars[i..].iter().collect(), "expected a word letter"));
        }
        let start = i + 1;
        let mut j = start;
        while j < chars.len() && (chars[j].is_ascii_digit() || matches!(chars[j], '.' | '+' | '-'))
        {
            j += 1;
        }
        let word: String = chars[i..j].iter().collect();
        if j < chars.len() && matches!(chars[j], '#' | '[') {
            return Err((word, "parameters and expressions are not supported"));
        }
        let num: String = chars[start..j].iter().collect();
        let value: f64 = match num.parse() {
            Ok(v) => v,
            Err(_) => return Err((word, "not a number")),
        };
        if !value.is_finite() {
            return Err((word, "not a finite number"));
        }
        out.push((c, value, word));
        i = j;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_modal_joint_blocks() {
        let text = "%\n(header)\nN10 G21 G90 G94\nN20 G0 X1 Y2 Z3 A4 C5\nN30 G93 G1 X 2 F10.5 ; inverse\nN40 Y3 F20\nN50 G94 G1 Z0 F500\nN60 G53 G0 Z0\n%\n";
        let b = read_gcode(text, "t.ngc").unwrap();
        assert_eq!(b.len(), 5);
        assert_eq!(
            b[0].axes,
            [Some(1.0), Some(2.0), Some(3.0), Some(4.0), None, Some(5.0)]
        );
        assert_eq!(b[1].axes[0], Some(2.0));
        assert_eq!(b[1].feed, Some(GcodeFeed::InverseTime(10.5)));
        assert_eq!(b[2].axes[1], Some(3.0));
        assert_eq!(b[2].feed, Some(GcodeFeed::InverseTime(20.0)));
        assert_eq!(b[3].feed, Some(GcodeFeed::PerMinute(500.0)));
        assert!(b[4].machine_coordinates && b[4].motion == GcodeMotion::Rapid);
        assert_eq!(b[4].line, 8);
    }

    #[test]
    fn unsupported_words_are_typed_errors_with_line() {
        for (text, line) in [
            ("G0 X1\nG2 X1 Y1 R1\n", 2),
            ("G91\n", 1),
            ("X1\n", 1),
            ("G0 X#1\n", 1),
            ("G0 X1..2\n", 1),
            ("G93\nG1 X1\n", 2),
            ("G0 (open\n", 1),
        ] {
            match read_gcode(text, "t") {
                Err(GcodeError::GcodeParse { line: l, .. }) => assert_eq!(l, line, "{text}"),
                other => panic!("{text}: {other:?}"),
            }
        }
    }
}
