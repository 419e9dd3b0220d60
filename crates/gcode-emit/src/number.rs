//! Fixed-decimal number formatting for NC words.
//!
//! Controllers read numbers in plain decimal notation only: `1e-7` is an error on LinuxCNC
//! (`E` is a word letter) and on every other control. [`NumberFormat::format`] rounds to a
//! fixed number of decimals, never uses an exponent, prints a negative zero as `0`, and can
//! strip trailing zeros and force a decimal point (Fanuc reads `X10` as 10 least input
//! increments — 0.010 mm — unless a decimal point is written, so Fanuc output uses `X10.`).

use serde::{Deserialize, Serialize};

/// How a number is written into a program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct NumberFormat {
    /// Digits after the decimal point (correctly rounded from the exact binary value).
    pub decimals: usize,
    /// Remove trailing zeros after the decimal point (`1.500` → `1.5`).
    pub trim_zeros: bool,
    /// Keep a decimal point on integral values (`10.`), as Fanuc needs; when `false`,
    /// integral values print without a point (`10`).
    pub force_point: bool,
    /// Print a `+` sign on non-negative values (Heidenhain style `X+10`).
    pub plus_sign: bool,
}

impl NumberFormat {
    /// Fixed `decimals`, trailing zeros trimmed, no forced point, no plus sign.
    pub const fn trimmed(decimals: usize) -> Self {
        Self {
            decimals,
            trim_zeros: true,
            force_point: false,
            plus_sign: false,
        }
    }

    /// Always exactly `decimals` digits after the point.
    pub const fn fixed(decimals: usize) -> Self {
        Self {
            decimals,
            trim_zeros: false,
            force_point: false,
            plus_sign: false,
        }
    }

    /// Formats `value`; `None` if it is NaN or infinite (callers turn that into a typed
    /// error naming the word and block). O(digits).
    pub fn format(&self, value: f64) -> Option<String> {
        let mut s = String::new();
        self.write_to(value, &mut s).then_some(s)
    }

    /// Appends the formatted `value` to `out` (no allocation once `out` has capacity);
    /// returns `false` and appends nothing if the value is NaN or infinite.
    pub fn write_to(&self, value: f64, out: &mut String) -> bool {
        use std::fmt::Write;
        if !value.is_finite() {
            return false;
        }
        let start = out.len();
        // `{:.N}` never uses exponent notation for f64; it rounds the exact binary value.
        // Writing into a String cannot fail.
        let _ = write!(out, "{:.*}", self.decimals, value);
        // A value that rounds to zero prints as "-0.000"; drop the sign.
        if out[start..].starts_with('-') && out[start + 1..].bytes().all(|b| b == b'0' || b == b'.')
        {
            out.remove(start);
        }
        if self.trim_zeros && out[start..].contains('.') {
            while out.ends_with('0') {
                out.pop();
            }
            if out.ends_with('.') && !self.force_point {
                out.pop();
            }
        } else if self.force_point && !out[start..].contains('.') {
            out.push('.');
        }
        if self.plus_sign && !out[start..].starts_with('-') {
            out.insert(start, '+');
        }
        true
    }
}

impl Default for NumberFormat {
    /// Four decimals, trimmed: 0.1 µm resolution on lengths and 0.0001° on angles.
    fn default() -> Self {
        Self::trimmed(4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fixed_trimmed_and_signs() {
        let f = NumberFormat::trimmed(3);
        assert_eq!(f.format(1.5).as_deref(), Some("1.5"));
        assert_eq!(f.format(10.0).as_deref(), Some("10"));
        assert_eq!(f.format(-0.0).as_deref(), Some("0"));
        assert_eq!(f.format(-0.0004).as_deref(), Some("0"));
        assert_eq!(f.format(-0.0006).as_deref(), Some("-0.001"));
        assert_eq!(f.format(1e-20).as_deref(), Some("0"));
        assert_eq!(f.format(1.23e15).as_deref(), Some("1230000000000000"));
        assert_eq!(f.format(f64::NAN), None);
        assert_eq!(f.format(f64::INFINITY), None);
        let fanuc = NumberFormat {
            force_point: true,
            ..NumberFormat::trimmed(3)
        };
        assert_eq!(fanuc.format(10.0).as_deref(), Some("10."));
        assert_eq!(fanuc.format(-0.0).as_deref(), Some("0."));
        assert_eq!(fanuc.format(2.25).as_deref(), Some("2.25"));
        let fixed = NumberFormat::fixed(4);
        assert_eq!(fixed.format(2.0).as_deref(), Some("2.0000"));
        assert_eq!(fixed.format(-1e-9).as_deref(), Some("0.0000"));
        let hh = NumberFormat {
            plus_sign: true,
            ..NumberFormat::trimmed(3)
        };
        assert_eq!(hh.format(0.0).as_deref(), Some("+0"));
        assert_eq!(hh.format(-0.0).as_deref(), Some("+0"));
        assert_eq!(hh.format(-2.5).as_deref(), Some("-2.5"));
        assert_eq!(NumberFormat::trimmed(0).format(2.6).as_deref(), Some("3"));
    }

    proptest! {
        /// Any finite value prints without exponent and reads back within half a unit of
        /// the last decimal.
        #[test]
        fn no_exponent_and_rounds_within_half_ulp(v in -1e9f64..1e9, d in 0usize..8, trim: bool, point: bool, plus: bool) {
            let f = NumberFormat { decimals: d, trim_zeros: trim, force_point: point, plus_sign: plus };
            let s = f.format(v).unwrap();
            prop_assert!(!s.contains('e') && !s.contains('E'), "{}", s);
            prop_assert!(!s.starts_with('-') || s.bytes().any(|b| (b'1'..=b'9').contains(&b)), "{}", s);
            let back: f64 = s.parse().unwrap();
            let half = 0.5 * 10f64.powi(-(d as i32));
            // Half a unit of the last decimal, plus the binary rounding of the parse.
            prop_assert!((back - v).abs() <= half + 4.0 * f64::EPSILON * v.abs().max(1.0), "{} -> {}", v, s);
        }
    }
}
