//! The program's cycle time in the report: [`gcode_emit::program_time`] (the written
//! program replayed in joint space with the machine file's axis speeds and accelerations,
//! its blending and tool-change time) per operation and in all.
//!
//! Each operation's row of `report.json` gets the DESIGN §4 figures from the machine's
//! limits — `link_length_mm` (tool-tip travel between cuts, rapids included),
//! `rapid_length_mm`, `air_time_s` (links at feed and rapids), `total_time_s` (cutting, air
//! and the tool change before it) — and `machine_cutting_time_s`, `link_time_s`,
//! `rapid_time_s`, `tool_change_time_s`; `cutting_time_s` stays the estimate at programmed
//! feed. The whole program's figures are `post.cycle_time`.

use crate::report::Report;
use gcode_emit::ProgramTime;
use std::fmt::Write as _;

/// Puts `time` into `report`: each operation's figures (operations in program order, as
/// [`gcode_emit::program_time`] returns them) and `post.cycle_time`.
pub fn add_cycle_time(report: &mut Report, time: ProgramTime) {
    for (row, t) in report.operations.iter_mut().zip(&time.operations) {
        row.metrics
            .number("link_length_mm", t.link_length_mm)
            .number("rapid_length_mm", t.rapid_length_mm)
            .number("air_time_s", t.air_s())
            .number("total_time_s", t.total_s)
            .number("machine_cutting_time_s", t.cutting_s)
            .number("link_time_s", t.link_s)
            .number("rapid_time_s", t.rapid_s)
            .number("tool_change_time_s", t.tool_change_s);
    }
    report.post.cycle_time = Some(time);
}

/// `h m s` of `s` seconds, e.g. `1 h 42 min 57 s`, `3 min 5 s`, `12.4 s`.
pub fn hms(s: f64) -> String {
    if !s.is_finite() {
        return format!("{s} s");
    }
    if s < 60.0 {
        return format!("{s:.1} s");
    }
    let total = s.round() as u64;
    let (h, m, sec) = (total / 3600, total % 3600 / 60, total % 60);
    if h > 0 {
        format!("{h} h {m} min {sec} s")
    } else {
        format!("{m} min {sec} s")
    }
}

/// The report's cycle-time table: one row per operation and the total (s).
pub fn html(t: &ProgramTime) -> String {
    let mut h = format!(
        "<h2>Cycle time: {}</h2><p>From the machine file's axis speeds and accelerations \
         ({} blocks; tool change {} s each).</p>\
         <table><tr><th>operation</th><th>tool</th><th>cutting (s)</th><th>links at feed (s)</th>\
         <th>rapids (s)</th><th>tool change (s)</th><th>total (s)</th><th>cutting length (mm)</th>\
         <th>rapid length (mm)</th></tr>",
        hms(t.total_s),
        t.blending,
        t.tool_change_each_s
    );
    for o in &t.operations {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>T{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td>\
             <td>{:.1}</td><td>{:.1}</td><td>{:.1}</td></tr>",
            o.name.replace('&', "&amp;").replace('<', "&lt;"),
            o.tool_number,
            o.cutting_s,
            o.link_s,
            o.rapid_s,
            o.tool_change_s,
            o.total_s,
            o.cutting_length_mm,
            o.rapid_length_mm
        );
    }
    let _ = write!(
        h,
        "<tr><th>program</th><th></th><th>{:.1}</th><th>{:.1}</th><th>{:.1}</th><th>{:.1}</th>\
         <th>{:.1}</th><th></th><th></th></tr></table>",
        t.cutting_s, t.link_s, t.rapid_s, t.tool_change_s, t.total_s
    );
    if !t.unlimited_acceleration.is_empty() {
        let axes: String = t.unlimited_acceleration.iter().collect();
        let _ = write!(
            h,
            "<p>The machine file gives no acceleration for {axes}: those axes are timed as \
             accelerating instantly.</p>"
        );
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_hours_minutes_seconds() {
        assert_eq!(hms(12.44), "12.4 s");
        assert_eq!(hms(185.0), "3 min 5 s");
        assert_eq!(hms(6177.4), "1 h 42 min 57 s");
    }
}
