//! SVG plot of axis displacement curves (the figures of paper 004: angular and linear axis
//! positions along the tool path, before and after reverse-motion removal).

use crate::reverse_motion::DisplacementCurves;
use std::fmt::Write;

const COLORS: [&str; 5] = ["#1f77b4", "#2ca02c", "#9467bd", "#d62728", "#ff7f0e"];
const MAX_POINTS: usize = 2000;

/// An SVG document (`width × height` px) with one polyline per axis of `after` (solid) and,
/// when given, of `before` (dashed), against the cumulative tool-tip path length. Values are
/// mm for linear axes and degrees for rotary axes on one shared vertical scale, as in the
/// paper's figures; `rotary_only` plots just the two rotary axes. Long curves are thinned to
/// at most 2000 points per polyline.
pub fn displacement_svg(
    after: &DisplacementCurves,
    before: Option<&DisplacementCurves>,
    rotary_only: bool,
    width: u32,
    height: u32,
) -> String {
    let cols: Vec<usize> = if rotary_only {
        vec![3, 4]
    } else {
        (0..5).collect()
    };
    let sets: Vec<&DisplacementCurves> = before.into_iter().chain(std::iter::once(after)).collect();
    let (mut xmax, mut ymin, mut ymax) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    for c in &sets {
        xmax = xmax.max(c.path_length_mm.last().copied().unwrap_or(0.0));
        for row in &c.values {
            for &k in &cols {
                ymin = ymin.min(row[k]);
                ymax = ymax.max(row[k]);
            }
        }
    }
    if !ymin.is_finite() {
        (ymin, ymax) = (0.0, 1.0);
    }
    if ymax - ymin < 1e-9 {
        ymax = ymin + 1.0;
    }
    if xmax <= 0.0 {
        xmax = 1.0;
    }
    let (w, h) = (f64::from(width.max(100)), f64::from(height.max(80)));
    let (ml, mr, mt, mb) = (60.0, 90.0, 20.0, 40.0);
    let sx = |x: f64| ml + x / xmax * (w - ml - mr);
    let sy = |y: f64| mt + (ymax - y) / (ymax - ymin) * (h - mt - mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(
        s,
        r#"<rect x="{ml}" y="{mt}" width="{:.1}" height="{:.1}" fill="none" stroke="grey"/>"#,
        w - ml - mr,
        h - mt - mb
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">tool-tip path length (mm)</text>"#,
        (w - mr + ml) / 2.0,
        h - 8.0
    );
    for (val, y) in [(ymax, sy(ymax)), (ymin, sy(ymin))] {
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{val:.1}</text>"#,
            ml - 4.0,
            y + 4.0
        );
    }
    let _ = writeln!(s, r#"<text x="4" y="{:.1}">mm; deg</text>"#, mt + 12.0);
    for (si, c) in sets.iter().enumerate() {
        let dashed = before.is_some() && si == 0;
        let n = c.values.len().min(c.path_length_mm.len());
        let stride = n.div_ceil(MAX_POINTS).max(1);
        for &k in &cols {
            let mut pts = String::new();
            let mut i = 0;
            while i < n {
                let _ = write!(
                    pts,
                    "{:.2},{:.2} ",
                    sx(c.path_length_mm[i]),
                    sy(c.values[i][k])
                );
                i = if i + 1 == n {
                    n
                } else {
                    (i + stride).min(n - 1)
                };
            }
            let dash = if dashed {
                r#" stroke-dasharray="4 3" opacity="0.6""#
            } else {
                ""
            };
            let _ = writeln!(
                s,
                r#"<polyline fill="none" stroke="{}" stroke-width="1.2"{dash} points="{}"/>"#,
                COLORS[k],
                pts.trim_end()
            );
        }
    }
    for (row, &k) in cols.iter().enumerate() {
        let y = mt + 14.0 + 16.0 * row as f64;
        let letter = after.letters.get(k).copied().unwrap_or('?');
        let _ = writeln!(
            s,
            r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}" stroke-width="2"/><text x="{:.1}" y="{:.1}">{letter}</text>"#,
            w - mr + 8.0,
            w - mr + 28.0,
            COLORS[k],
            w - mr + 32.0,
            y + 4.0
        );
    }
    if before.is_some() {
        let y = mt + 14.0 + 16.0 * cols.len() as f64;
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{y:.1}">dashed: before</text>"#,
            w - mr + 8.0
        );
    }
    s.push_str("</svg>\n");
    s
}
