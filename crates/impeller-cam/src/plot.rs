//! Minimal inline-SVG plots for `report.html`: line charts and heat maps with labelled axes.

use std::fmt::Write as _;

const W: f64 = 560.0;
const H: f64 = 320.0;
const ML: f64 = 64.0;
const MR: f64 = 16.0;
const MT: f64 = 28.0;
const MB: f64 = 44.0;
const COLOURS: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
];

/// One named polyline of a line chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
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

/// A line chart; `equal_aspect` keeps one unit the same length on both axes (geometry).
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
    let tx = |x: f64| ML + (x - xmin) / (xmax - xmin) * pw;
    let ty = |y: f64| MT + ph - (y - ymin) / (ymax - ymin) * ph;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="11">"#
    );
    let _ = write!(
        s,
        r#"<text x="{}" y="16" text-anchor="middle" font-size="13">{}</text>"#,
        W / 2.0,
        escape(title)
    );
    let _ = write!(
        s,
        r##"<rect x="{ML}" y="{MT}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>"##
    );
    for i in 0..=4 {
        let f = i as f64 / 4.0;
        let xv = xmin + f * (xmax - xmin);
        let yv = ymin + f * (ymax - ymin);
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            tx(xv),
            MT + ph + 14.0,
            tick(xv)
        );
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
            ML - 4.0,
            ty(yv) + 4.0,
            tick(yv)
        );
    }
    let _ = write!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        ML + pw / 2.0,
        H - 8.0,
        escape(x_label)
    );
    let _ = write!(
        s,
        r#"<text x="14" y="{:.1}" text-anchor="middle" transform="rotate(-90 14 {:.1})">{}</text>"#,
        MT + ph / 2.0,
        MT + ph / 2.0,
        escape(y_label)
    );
    for (k, ser) in series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
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
        let _ = write!(
            s,
            r#"<path d="{d}" fill="none" stroke="{colour}" stroke-width="1.3"/>"#
        );
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" fill="{colour}">{}</text>"#,
            ML + 6.0,
            MT + 14.0 + 13.0 * k as f64,
            escape(&ser.label)
        );
    }
    s.push_str("</svg>");
    s
}

/// A heat map of a grid of values (rows × columns, `NaN` = no data) with a colour scale from
/// `lo` (blue) to `hi` (red).
pub fn heat_map(title: &str, values: &[Vec<f64>], lo: f64, hi: f64, unit: &str) -> String {
    let rows = values.len();
    let cols = values.iter().map(Vec::len).max().unwrap_or(0);
    if rows == 0 || cols == 0 {
        return format!("<p><em>{}: no data</em></p>", escape(title));
    }
    let pw = W - ML - MR;
    let ph = H - MT - MB;
    let cw = pw / cols as f64;
    let ch = ph / rows as f64;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="11">"#
    );
    let _ = write!(
        s,
        r#"<text x="{}" y="16" text-anchor="middle" font-size="13">{}</text>"#,
        W / 2.0,
        escape(title)
    );
    let span = if hi > lo { hi - lo } else { 1.0 };
    for (i, row) in values.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            let fill = if v.is_finite() {
                colour((v - lo) / span)
            } else {
                "#eeeeee".to_string()
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
    let _ = write!(
        s,
        r#"<text x="{ML}" y="{:.1}">{} {unit} (blue) … {} {unit} (red)</text>"#,
        H - 8.0,
        tick(lo),
        tick(hi)
    );
    s.push_str("</svg>");
    s
}

fn colour(t: f64) -> String {
    let t = t.clamp(0.0, 1.0);
    let r = (255.0 * t).round() as u8;
    let b = (255.0 * (1.0 - t)).round() as u8;
    let g = (255.0 * (1.0 - (2.0 * t - 1.0).abs()) * 0.8).round() as u8;
    format!("#{r:02x}{g:02x}{b:02x}")
}

fn tick(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.4}")
    }
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
        let svg = heat_map("m", &[vec![0.0, f64::NAN], vec![1.0, 0.5]], 0.0, 1.0, "mm");
        assert!(svg.contains("#eeeeee"));
        assert!(svg.contains("#ff0000"));
    }
}
