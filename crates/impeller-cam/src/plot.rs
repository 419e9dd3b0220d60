//! Minimal inline-SVG plots for `report.html`: line charts and heat maps with labelled axes.

use std::fmt::Write as _;

const W: f64 = 560.0;
/// Height of the plot with its margins, without the legend rows below it.
const H: f64 = 320.0;
const ML: f64 = 64.0;
const MR: f64 = 16.0;
/// Right margin of a heat map: room for its colour bar and the bar's ticks.
const MR_BAR: f64 = 84.0;
const MT: f64 = 28.0;
const MB: f64 = 44.0;
/// One legend row below the plot.
const LEGEND_ROW: f64 = 15.0;
/// Colours of series whose label says nothing the report gives a colour to.
const COLOURS: [&str; 6] = [
    "#1f77b4", "#9467bd", "#2ca02c", "#8c564b", "#17becf", "#bcbd22",
];

/// One named polyline of a line chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
}

/// The colour (and dash) of a series by what it shows, the same in every plot of the report:
/// hub dark grey, shroud light grey, main blades blue, splitters purple, cutting moves red,
/// rapids and links light grey (dashed); a blade's tip edge is dashed, its hub edge solid;
/// machine axes X, Y, Z, A/B, C each their own colour, dashed before reverse-motion removal.
/// `None` for other series (they take [`COLOURS`] in order).
fn meaning(label: &str) -> Option<(&'static str, bool)> {
    // Machine axes (displacement curves): one colour per letter; dashed before reverse-motion
    // removal.
    let mut words = label.split_whitespace();
    if let Some(axis) = words.next().filter(|w| w.len() == 1) {
        let colour = match axis {
            "X" => Some("#1f77b4"),
            "Y" => Some("#2ca02c"),
            "Z" => Some("#9467bd"),
            "A" | "B" => Some("#d62728"),
            "C" => Some("#ff7f0e"),
            _ => None,
        };
        if let Some(c) = colour {
            return Some((c, label.contains("before")));
        }
    }
    let l = label.to_lowercase();
    // Per-face series (surface groups: `main pressure`, `splitter suction`, `main tip`) take
    // the palette: the row's colour alone would not tell the faces apart.
    if l.ends_with(" pressure") || l.ends_with(" suction") || l.ends_with(" tip") {
        return None;
    }
    let dashed = l.contains("tip edge");
    let colour = if l.contains("rapid") || l.contains("link") {
        return Some(("#a0a0a0", true));
    } else if l.contains("cutting moves") {
        "#d62728"
    } else if l.starts_with("hub") {
        "#444444"
    } else if l.starts_with("shroud") {
        "#9a9a9a"
    } else if l.contains("splitter") {
        "#9467bd"
    } else if l.contains("blade") {
        "#1f77b4"
    } else {
        return None;
    };
    Some((colour, dashed))
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn bounds(series: &[Series]) -> Option<(f64, f64, f64, f64)> {
    let mut it = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let &(x0, y0) = it.next()?;
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (x0, x0, y0, y0);
    for &(x, y) in it {
        xmin = xmin.min(x);
        xmax = xmax.max(x);
        ymin = ymin.min(y);
        ymax = ymax.max(y);
    }
    if xmax - xmin < 1e-12 {
        xmax = xmin + 1.0;
    }
    if ymax - ymin < 1e-12 {
        ymax = ymin + 1.0;
    }
    Some((xmin, xmax, ymin, ymax))
}

/// Round tick values covering `[lo, hi]`: steps of 1, 2 or 5 × 10ᵏ giving about `target`
/// ticks, with the number of decimals their labels need.
fn nice_ticks(lo: f64, hi: f64, target: f64) -> (Vec<f64>, usize) {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return (vec![lo], 2);
    }
    let raw = span / target;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|f| f * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let decimals = (-step.log10().floor()).clamp(0.0, 6.0) as usize;
    let first = (lo / step).ceil();
    let last = (hi / step + 1e-9).floor();
    let ticks = (first as i64..=last as i64)
        .map(|k| k as f64 * step)
        .collect();
    (ticks, decimals)
}

fn tick_label(v: f64, decimals: usize) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-4..1e6).contains(&a) {
        return format!("{v:.1e}");
    }
    let t = format!("{v:.decimals$}");
    // No "-0" / "-0.00".
    if t.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        t.trim_start_matches('-').to_string()
    } else {
        t
    }
}

/// Legend entries laid out in rows below the plot (never over the data); returns the SVG
/// and the number of rows.
fn legend(entries: &[(String, &str, bool)], top: f64) -> (String, usize) {
    let mut s = String::new();
    let (mut x, mut row) = (ML, 0usize);
    for (label, colour, dashed) in entries {
        // About 6.2 px per character at 11 px.
        let w = 26.0 + 6.2 * label.chars().count() as f64 + 14.0;
        if x + w > W - MR && x > ML {
            x = ML;
            row += 1;
        }
        let y = top + LEGEND_ROW * row as f64;
        let dash = if *dashed {
            r#" stroke-dasharray="4 3""#
        } else {
            ""
        };
        let _ = write!(
            s,
            r#"<line x1="{x:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{colour}" stroke-width="2"{dash}/><text x="{:.1}" y="{y:.1}">{}</text>"#,
            y - 4.0,
            x + 22.0,
            y - 4.0,
            x + 26.0,
            escape(label)
        );
        x += w;
    }
    (s, if entries.is_empty() { 0 } else { row + 1 })
}

/// Axes: frame, grid lines and labelled ticks at round values, axis titles.
#[allow(clippy::too_many_arguments)]
fn axes(
    s: &mut String,
    (xmin, xmax, ymin, ymax): (f64, f64, f64, f64),
    pw: f64,
    ph: f64,
    x_label: &str,
    y_label: &str,
    grid: bool,
) {
    let tx = |x: f64| ML + (x - xmin) / (xmax - xmin) * pw;
    let ty = |y: f64| MT + ph - (y - ymin) / (ymax - ymin) * ph;
    let (xt, xd) = nice_ticks(xmin, xmax, (pw / 70.0).max(2.0));
    let (yt, yd) = nice_ticks(ymin, ymax, (ph / 45.0).max(2.0));
    for &v in &xt {
        let x = tx(v);
        if grid {
            let _ = write!(
                s,
                r##"<line x1="{x:.1}" y1="{MT}" x2="{x:.1}" y2="{:.1}" stroke="#e4e4e4"/>"##,
                MT + ph
            );
        }
        let _ = write!(
            s,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#888"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            MT + ph,
            MT + ph + 4.0,
            MT + ph + 15.0,
            tick_label(v, xd)
        );
    }
    for &v in &yt {
        let y = ty(v);
        if grid {
            let _ = write!(
                s,
                r##"<line x1="{ML}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e4e4e4"/>"##,
                ML + pw
            );
        }
        let _ = write!(
            s,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{ML}" y2="{y:.1}" stroke="#888"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            ML - 4.0,
            ML - 6.0,
            y + 4.0,
            tick_label(v, yd)
        );
    }
    let _ = write!(
        s,
        r##"<rect x="{ML}" y="{MT}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>"##
    );
    let _ = write!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        ML + pw / 2.0,
        MT + ph + 32.0,
        escape(x_label)
    );
    let _ = write!(
        s,
        r#"<text x="14" y="{:.1}" text-anchor="middle" transform="rotate(-90 14 {:.1})">{}</text>"#,
        MT + ph / 2.0,
        MT + ph / 2.0,
        escape(y_label)
    );
}

fn svg_open(s: &mut String, height: f64, title: &str) {
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{height}" viewBox="0 0 {W} {height}" font-family="sans-serif" font-size="11">"#
    );
    let _ = write!(
        s,
        r#"<text x="{}" y="16" text-anchor="middle" font-size="13">{}</text>"#,
        W / 2.0,
        escape(title)
    );
}

/// A line chart with round ticks, grid lines and the legend below the plot; `equal_aspect`
/// keeps one unit the same length on both axes (geometry). Series colours follow what they
/// show ([`meaning`]), so a hub or a cutting move has one colour across the report.
pub fn line_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    equal_aspect: bool,
) -> String {
    let Some((mut xmin, mut xmax, mut ymin, mut ymax)) = bounds(series) else {
        return format!("<p><em>{}: no data</em></p>", escape(title));
    };
    let pw = W - ML - MR;
    let ph = H - MT - MB;
    if equal_aspect {
        let sx = (xmax - xmin) / pw;
        let sy = (ymax - ymin) / ph;
        let s = sx.max(sy);
        let cx = 0.5 * (xmin + xmax);
        let cy = 0.5 * (ymin + ymax);
        xmin = cx - 0.5 * s * pw;
        xmax = cx + 0.5 * s * pw;
        ymin = cy - 0.5 * s * ph;
        ymax = cy + 0.5 * s * ph;
    }
    let mut other = 0;
    let styles: Vec<(&str, bool)> = series
        .iter()
        .map(|ser| {
            meaning(&ser.label).unwrap_or_else(|| {
                other += 1;
                (COLOURS[(other - 1) % COLOURS.len()], false)
            })
        })
        .collect();
    let entries: Vec<(String, &str, bool)> = series
        .iter()
        .zip(&styles)
        .map(|(ser, &(c, d))| (ser.label.clone(), c, d))
        .collect();
    let (legend_svg, rows) = legend(&entries, H + 2.0);
    let mut s = String::new();
    svg_open(&mut s, H + LEGEND_ROW * rows as f64 + 4.0, title);
    axes(
        &mut s,
        (xmin, xmax, ymin, ymax),
        pw,
        ph,
        x_label,
        y_label,
        true,
    );
    let tx = |x: f64| ML + (x - xmin) / (xmax - xmin) * pw;
    let ty = |y: f64| MT + ph - (y - ymin) / (ymax - ymin) * ph;
    for (ser, &(colour, dashed)) in series.iter().zip(&styles) {
        let mut d = String::new();
        let mut pen_up = true;
        for &(x, y) in &ser.points {
            if !(x.is_finite() && y.is_finite()) {
                pen_up = true;
                continue;
            }
            let _ = write!(
                d,
                "{}{:.2},{:.2} ",
                if pen_up { "M" } else { "L" },
                tx(x),
                ty(y)
            );
            pen_up = false;
        }
        let dash = if dashed {
            r#" stroke-dasharray="4 3""#
        } else {
            ""
        };
        let _ = write!(
            s,
            r#"<path d="{d}" fill="none" stroke="{colour}" stroke-width="1.3"{dash}/>"#
        );
    }
    s.push_str(&legend_svg);
    s.push_str("</svg>");
    s
}

/// What a heat map's colours mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Material left outside the design: light to dark blue (as the residual of the 3D
    /// view's stock).
    Residual,
    /// Design material removed: light yellow to dark red (as the overcut of the 3D view).
    Overcut,
    /// Any other quantity: a perceptually ordered dark blue – green – yellow scale.
    Sequential,
}

impl Scale {
    fn stops(self) -> &'static [[f64; 3]] {
        match self {
            Scale::Residual => &[[0.93, 0.96, 1.0], [0.42, 0.68, 0.84], [0.03, 0.19, 0.42]],
            Scale::Overcut => &[[1.0, 0.96, 0.75], [0.99, 0.55, 0.24], [0.65, 0.0, 0.05]],
            Scale::Sequential => &[
                [0.27, 0.0, 0.33],
                [0.23, 0.32, 0.55],
                [0.13, 0.57, 0.55],
                [0.37, 0.79, 0.38],
                [0.99, 0.91, 0.14],
            ],
        }
    }

    /// The colour at `t ∈ [0, 1]` (clamped), linear between the stops.
    pub fn colour(self, t: f64) -> String {
        let stops = self.stops();
        let t = if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let x = t * (stops.len() - 1) as f64;
        let i = (x.floor() as usize).min(stops.len() - 2);
        let f = x - i as f64;
        let c: Vec<u8> = (0..3)
            .map(|k| ((stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f) * 255.0).round() as u8)
            .collect();
        format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
    }
}

/// A heat map of a grid of values (rows × columns, row 0 at the bottom, `NaN` = no data,
/// drawn light grey) from `lo` to `hi` on `scale`, with the axes' sample indices and a colour
/// bar with round ticks in `unit`.
#[allow(clippy::too_many_arguments)]
pub fn heat_map(
    title: &str,
    values: &[Vec<f64>],
    lo: f64,
    hi: f64,
    unit: &str,
    scale: Scale,
    x_label: &str,
    y_label: &str,
) -> String {
    let rows = values.len();
    let cols = values.iter().map(Vec::len).max().unwrap_or(0);
    if rows == 0 || cols == 0 {
        return format!("<p><em>{}: no data</em></p>", escape(title));
    }
    let pw = W - ML - MR_BAR;
    let ph = H - MT - MB;
    let cw = pw / cols as f64;
    let ch = ph / rows as f64;
    let mut s = String::new();
    svg_open(&mut s, H, title);
    let span = if hi > lo { hi - lo } else { 1.0 };
    for (i, row) in values.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            let fill = if v.is_finite() {
                scale.colour((v - lo) / span)
            } else {
                "#e6e6e6".to_string()
            };
            let _ = write!(
                s,
                r#"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="{fill}"/>"#,
                ML + j as f64 * cw,
                MT + (rows - 1 - i) as f64 * ch,
                cw + 0.3,
                ch + 0.3
            );
        }
    }
    // Cell centres are the sample indices.
    axes(
        &mut s,
        (-0.5, cols as f64 - 0.5, -0.5, rows as f64 - 0.5),
        pw,
        ph,
        x_label,
        y_label,
        false,
    );
    // Colour bar.
    let bx = ML + pw + 14.0;
    let bw = 14.0;
    const N: usize = 48;
    for k in 0..N {
        let t = (k as f64 + 0.5) / N as f64;
        let _ = write!(
            s,
            r#"<rect x="{bx:.1}" y="{:.2}" width="{bw}" height="{:.2}" fill="{}"/>"#,
            MT + ph * (1.0 - (k + 1) as f64 / N as f64),
            ph / N as f64 + 0.3,
            scale.colour(t)
        );
    }
    let _ = write!(
        s,
        r##"<rect x="{bx:.1}" y="{MT}" width="{bw}" height="{ph}" fill="none" stroke="#888"/>"##
    );
    let (ticks, decimals) = nice_ticks(lo, lo + span, 5.0);
    for v in ticks {
        let y = MT + ph - (v - lo) / span * ph;
        let _ = write!(
            s,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#333"/><text x="{:.1}" y="{:.1}">{}</text>"##,
            bx + bw,
            bx + bw + 4.0,
            bx + bw + 6.0,
            y + 4.0,
            tick_label(v, decimals)
        );
    }
    let _ = write!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        bx + bw / 2.0,
        MT - 6.0,
        escape(unit)
    );
    s.push_str("</svg>");
    s
}

/// A metric key as a person reads it: `max_linearisation_error_mm` → "Max linearisation
/// error (mm)". `report.json` keeps the keys.
pub fn human_label(key: &str) -> String {
    const UNITS: [(&str, &str); 8] = [
        ("_mm3", " (mm³)"),
        ("_mm2", " (mm²)"),
        ("_mm", " (mm)"),
        ("_ms", " (ms)"),
        ("_deg", " (deg)"),
        ("_rpm", " (rpm)"),
        ("_s", " (s)"),
        ("_bytes", " (bytes)"),
    ];
    let (stem, unit) = UNITS
        .iter()
        .find_map(|(suffix, unit)| key.strip_suffix(suffix).map(|stem| (stem, *unit)))
        .unwrap_or((key, ""));
    let words = stem.replace('_', " ");
    let mut c = words.chars();
    let first = c.next().map(|f| f.to_uppercase().collect::<String>());
    format!("{}{}{unit}", first.unwrap_or_default(), c.as_str())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_chart_maps_data_into_the_plot_area_and_escapes_text() {
        let svg = line_chart(
            "a<b",
            "x",
            "y",
            &[Series {
                label: "s".into(),
                points: vec![(0.0, 0.0), (1.0, 2.0)],
            }],
            false,
        );
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains("a&lt;b"));
        // First point at the lower-left corner of the plot area, last at the upper right.
        assert!(svg.contains(&format!("M{:.2},{:.2}", ML, H - MB)));
        assert!(svg.contains(&format!("L{:.2},{:.2}", W - MR, MT)));
    }

    #[test]
    fn heat_map_handles_missing_values() {
        let svg = heat_map(
            "m",
            &[vec![0.0, f64::NAN], vec![1.0, 0.5]],
            0.0,
            1.0,
            "mm",
            Scale::Overcut,
            "u",
            "v",
        );
        assert!(svg.contains("#e6e6e6"));
        // The largest value takes the scale's end colour, in a cell and atop the colour bar.
        assert!(svg.matches(&Scale::Overcut.colour(1.0)).count() >= 1);
        assert!(
            svg.contains(">0.2<") && svg.contains(">1.0<"),
            "colour bar ticks"
        );
    }

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        let (t, d) = nice_ticks(-3.7, 41.2, 5.0);
        assert_eq!(t, vec![0.0, 10.0, 20.0, 30.0, 40.0]);
        assert_eq!(d, 0);
        let (t, d) = nice_ticks(0.0, 0.0197, 5.0);
        assert_eq!(d, 3);
        assert_eq!(t.len(), 4);
        assert!((t[3] - 0.015).abs() < 1e-12, "{t:?}");
        assert_eq!(tick_label(-0.0, 2), "0.00");
    }

    #[test]
    fn legend_is_below_the_plot_and_colours_follow_meaning() {
        let ser = |label: &str| Series {
            label: label.into(),
            points: vec![(0.0, 0.0), (1.0, 1.0)],
        };
        let svg = line_chart(
            "t",
            "x",
            "y",
            &[ser("hub"), ser("cutting moves"), ser("rapids and links")],
            false,
        );
        // Legend text rows start below the plot frame (y > H − MB).
        let y: f64 = svg
            .split(">hub</text>")
            .next()
            .and_then(|a| a.rsplit("y=\"").next())
            .and_then(|t| t.split('"').next())
            .and_then(|t| t.parse().ok())
            .unwrap();
        assert!(y > H - MB, "legend at y = {y}");
        assert!(svg.contains(r##"stroke="#444444""##) && svg.contains(r##"stroke="#d62728""##));
    }

    #[test]
    fn keys_read_as_words_with_units() {
        assert_eq!(
            human_label("max_linearisation_error_mm"),
            "Max linearisation error (mm)"
        );
        assert_eq!(
            human_label("unmachinable_area_mm2"),
            "Unmachinable area (mm²)"
        );
        assert_eq!(human_label("cutting_time_s"), "Cutting time (s)");
        assert_eq!(human_label("moves"), "Moves");
    }
}
