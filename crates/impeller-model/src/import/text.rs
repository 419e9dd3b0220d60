//! Line-oriented reading shared by the text importers: byte input split into lines (LF or
//! CRLF), UTF-8 checked per line, blank lines skipped on request, finite numbers parsed with
//! the line number kept for error messages.

use super::error::ImportError;
use std::path::{Path, PathBuf};

/// Longest excerpt of an offending line quoted in an error.
const EXCERPT_CHARS: usize = 60;

/// Shortens `s` to at most [`EXCERPT_CHARS`] characters for an error message.
pub(crate) fn excerpt(s: &str) -> String {
    let t = s.trim();
    if t.chars().count() <= EXCERPT_CHARS {
        t.to_string()
    } else {
        let mut out: String = t.chars().take(EXCERPT_CHARS).collect();
        out.push('…');
        out
    }
}

/// Parses one number; accepts Fortran `D` exponents (`1.5D-03`). Returns `None` when the
/// token is not a number. Non-finite values (`NaN`, `inf`) parse and are rejected by callers.
pub(crate) fn parse_number(token: &str) -> Option<f64> {
    let t = token.trim();
    if t.is_empty() {
        return None;
    }
    if let Ok(v) = t.parse::<f64>() {
        return Some(v);
    }
    if t.contains(['d', 'D']) {
        let replaced: String = t
            .chars()
            .map(|c| if c == 'd' || c == 'D' { 'E' } else { c })
            .collect();
        return replaced.parse::<f64>().ok();
    }
    None
}

/// Splits a data line into tokens: whitespace and commas separate values.
pub(crate) fn tokens(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
}

/// A cursor over the lines of one file.
#[derive(Debug)]
pub(crate) struct LineReader<'a> {
    file: PathBuf,
    lines: Vec<&'a [u8]>,
    /// Index of the next line to read (0-based).
    pos: usize,
}

impl<'a> LineReader<'a> {
    /// Splits `bytes` into lines; a trailing `\r` (CRLF files) is dropped from each line.
    pub(crate) fn new(file: &Path, bytes: &'a [u8]) -> Self {
        let mut lines: Vec<&'a [u8]> = bytes
            .split(|&b| b == b'\n')
            .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
            .collect();
        // `split` yields an empty last piece after a final newline; it is not a line.
        if lines.last().is_some_and(|l| l.is_empty()) {
            lines.pop();
        }
        Self {
            file: file.to_path_buf(),
            lines,
            pos: 0,
        }
    }

    fn decode(&self, idx: usize) -> Result<&'a str, ImportError> {
        let raw = self.lines[idx];
        std::str::from_utf8(raw).map_err(|_| ImportError::Syntax {
            file: self.file.clone(),
            line: idx + 1,
            expected: "UTF-8 text".into(),
            found: excerpt(&String::from_utf8_lossy(raw)),
        })
    }

    /// The next line (blank or not) with its 1-based number, `None` at end of file.
    pub(crate) fn next_raw(&mut self) -> Option<Result<(usize, &'a str), ImportError>> {
        if self.pos >= self.lines.len() {
            return None;
        }
        let idx = self.pos;
        self.pos += 1;
        Some(self.decode(idx).map(|s| (idx + 1, s)))
    }

    /// The next non-blank line, `None` at end of file.
    pub(crate) fn next_nonblank(&mut self) -> Option<Result<(usize, &'a str), ImportError>> {
        loop {
            match self.next_raw()? {
                Ok((_, s)) if s.trim().is_empty() => continue,
                other => return Some(other),
            }
        }
    }

    /// The next non-blank line; at end of file an error saying `expected` is returned.
    pub(crate) fn expect_nonblank(
        &mut self,
        expected: &str,
    ) -> Result<(usize, &'a str), ImportError> {
        match self.next_nonblank() {
            Some(r) => r,
            None => Err(self.eof(expected)),
        }
    }

    /// The next non-blank line without consuming it.
    pub(crate) fn peek_nonblank(&self) -> Option<Result<(usize, &'a str), ImportError>> {
        let mut i = self.pos;
        while i < self.lines.len() {
            match self.decode(i) {
                Ok(s) if s.trim().is_empty() => i += 1,
                Ok(s) => return Some(Ok((i + 1, s))),
                Err(e) => return Some(Err(e)),
            }
        }
        None
    }

    /// A syntax error at `line`.
    pub(crate) fn syntax(
        &self,
        line: usize,
        expected: impl Into<String>,
        found: &str,
    ) -> ImportError {
        ImportError::Syntax {
            file: self.file.clone(),
            line,
            expected: expected.into(),
            found: excerpt(found),
        }
    }

    /// An end-of-file error.
    pub(crate) fn eof(&self, expected: impl Into<String>) -> ImportError {
        ImportError::UnexpectedEof {
            file: self.file.clone(),
            line: self.lines.len(),
            expected: expected.into(),
        }
    }

    /// A range/consistency error at `line`.
    pub(crate) fn invalid(
        &self,
        line: usize,
        field: impl Into<String>,
        reason: impl Into<String>,
    ) -> ImportError {
        ImportError::Invalid {
            file: self.file.clone(),
            line,
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Parses exactly `N` finite numbers from `text` (line `line`); `what` names the columns,
    /// e.g. `"x y z"`.
    pub(crate) fn numbers<const N: usize>(
        &self,
        line: usize,
        text: &str,
        what: &str,
    ) -> Result<[f64; N], ImportError> {
        let mut out = [0.0; N];
        let mut n = 0usize;
        let expected = || format!("{N} numbers ({what})");
        for tok in tokens(text) {
            if n == N {
                return Err(self.syntax(line, expected(), text));
            }
            let v = parse_number(tok).ok_or_else(|| self.syntax(line, expected(), text))?;
            if !v.is_finite() {
                let field = what.split_whitespace().nth(n).unwrap_or("value");
                return Err(self.invalid(line, field, format!("{tok:?} is not a finite number")));
            }
            out[n] = v;
            n += 1;
        }
        if n != N {
            return Err(self.syntax(line, expected(), text));
        }
        Ok(out)
    }

    /// Parses one finite number that is the only token of `text`.
    pub(crate) fn number(&self, line: usize, text: &str, field: &str) -> Result<f64, ImportError> {
        let [v] = self.numbers::<1>(line, text, field)?;
        Ok(v)
    }

    /// Parses a non-negative integer count (a leading `+` is allowed: AutoGrid writes `+100`).
    pub(crate) fn count(&self, line: usize, text: &str, field: &str) -> Result<usize, ImportError> {
        let t = text.trim();
        let digits = t.strip_prefix('+').unwrap_or(t);
        digits
            .parse::<usize>()
            .map_err(|_| self.syntax(line, format!("{field} (a non-negative integer)"), text))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crlf_and_final_newline() {
        let r = &mut LineReader::new(Path::new("f"), b"a\r\n\r\nb\r\n");
        assert_eq!(r.next_nonblank().unwrap().unwrap(), (1, "a"));
        assert_eq!(r.next_nonblank().unwrap().unwrap(), (3, "b"));
        assert!(r.next_nonblank().is_none());
    }

    #[test]
    fn numbers_reject_nan_and_extra_tokens() {
        let r = LineReader::new(Path::new("f"), b"");
        assert_eq!(r.numbers::<2>(1, "1 2D-1", "a b").unwrap(), [1.0, 0.2]);
        assert!(matches!(
            r.numbers::<2>(1, "1 NaN", "a b"),
            Err(ImportError::Invalid { .. })
        ));
        assert!(matches!(
            r.numbers::<2>(1, "1 2 3", "a b"),
            Err(ImportError::Syntax { .. })
        ));
        assert!(matches!(
            r.numbers::<2>(1, "1", "a b"),
            Err(ImportError::Syntax { .. })
        ));
        assert_eq!(r.count(1, "+100", "n").unwrap(), 100);
        assert!(r.count(1, "-1", "n").is_err());
    }
}
