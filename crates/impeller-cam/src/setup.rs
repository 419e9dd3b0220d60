//! The setup sheet: what the machine operator needs beside the program — the part and the
//! stock assumed, where the work offset (G54) sits relative to the machine's rotary centres,
//! every tool with its holder, stick-out, gauge length, speed and feeds, the operations in
//! order with their times, the machine and dialect, the total cycle time and the
//! verification verdict. Written as `setup.html` and as a section of `report.html`.
//!
//! Every figure is read from the job, the machine file, the planned operations and the
//! report (cycle time from [`crate::cycle`], verdict from [`crate::verdict`]); nothing is
//! entered by hand.

use crate::cycle::hms;
use crate::pipeline::JobOperation;
use crate::report::Report;
use cam_core::CutterShape;
use cam_plan::Tool;
use impeller_model::Impeller;
use postproc_kinematics::{Kinematics, Machine};
use std::fmt::Write as _;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// `ball Ø3 mm, taper 2.0°` and the like.
fn shape(tool: &Tool) -> String {
    match tool.cutter.shape {
        CutterShape::FlatEnd { radius } => format!("flat end Ø{}", 2.0 * radius),
        CutterShape::BallEnd { radius } => format!("ball end Ø{}", 2.0 * radius),
        CutterShape::BullNose {
            radius,
            corner_radius,
        } => format!("bull nose Ø{} r{}", 2.0 * radius, corner_radius),
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => format!(
            "tapered ball end Ø{} tip, {:.2}° half angle",
            2.0 * ball_radius,
            half_angle.to_degrees()
        ),
        CutterShape::TaperedFlatEnd {
            tip_radius,
            half_angle,
        } => format!(
            "tapered flat end Ø{} tip, {:.2}° half angle",
            2.0 * tip_radius,
            half_angle.to_degrees()
        ),
    }
}

/// The holder: its frusta bottom to top as `Ø a→b × l`.
fn holder(tool: &Tool) -> String {
    if tool.cutter.holder.is_empty() {
        return "none given".into();
    }
    tool.cutter
        .holder
        .iter()
        .map(|h| {
            format!(
                "Ø{}→{} × {}",
                2.0 * h.bottom_radius,
                2.0 * h.top_radius,
                h.length
            )
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

/// Where the workpiece origin (the work offset, G54) sits relative to the rotary centres.
fn work_offset(machine: &Machine) -> String {
    let o = machine.workpiece_origin();
    let v = |x: f64, y: f64, z: f64| format!("({x:.3}, {y:.3}, {z:.3}) mm");
    let at = format!(
        "Work offset (G54) = the impeller's axis at the hub's back face (+Z toward the inlet), \
         at machine {} with the rotary axes at 0",
        v(o.x, o.y, o.z)
    );
    match machine.kinematics() {
        Kinematics::TableTable(k) => {
            let c = k.rot_point;
            let t = c + k.offset;
            format!(
                "{at}; relative to the C-axis centre {} (machine {}), relative to the {}-axis \
                 centre {} (machine {}).",
                v(o.x - c.x, o.y - c.y, o.z - c.z),
                v(c.x, c.y, c.z),
                k.tilt_axis.letter(),
                v(o.x - t.x, o.y - t.y, o.z - t.z),
                v(t.x, t.y, t.z)
            )
        }
        Kinematics::HeadTable(k) => {
            let c = k.rot_point;
            format!(
                "{at}; relative to the C-axis point {} (machine {}); head pivot {} mm above \
                 the gauge line.",
                v(o.x - c.x, o.y - c.y, o.z - c.z),
                v(c.x, c.y, c.z),
                k.pivot_length
            )
        }
        Kinematics::HeadHead(k) => format!(
            "{at}; the table does not turn; head pivot {} mm above the gauge line.",
            k.pivot_length
        ),
    }
}

/// The setup sheet's HTML section (no document frame) for the run in `report`.
pub fn section(
    impeller: &Impeller,
    machine: &Machine,
    tools: &[Tool],
    operations: &[JobOperation],
    report: &Report,
) -> String {
    let mut h = String::from("<h2 id=\"setup\">Setup sheet</h2>");
    let s = impeller.summary();
    let stock = impeller.stock();
    let (z0, z1) = stock.z_range();
    let _ = write!(
        h,
        "<table><tr><td>part</td><td>{} ({} main + {} splitter blades, tip Ø{:.2} mm, axial \
         height {:.2} mm)</td></tr><tr><td>stock</td><td>revolved blank Ø{:.2} mm max, z {:.2} \
         to {:.2} mm</td></tr><tr><td>machine</td><td>{} ({})</td></tr><tr><td>dialect</td>\
         <td>{}</td></tr><tr><td>program</td><td>{}</td></tr><tr><td>work offset</td><td>{}</td>\
         </tr>",
        esc(&report.job),
        s.main_blade_count,
        s.splitter_blade_count,
        s.blade_tip_diameter_mm,
        s.axial_height_mm,
        2.0 * stock.max_radius(),
        z0,
        z1,
        esc(machine.name()),
        machine.kinematics().kind_name(),
        esc(&report.post.dialect),
        esc(&report
            .verdict
            .as_ref()
            .map(|v| v.program_text(&report.post.program))
            .unwrap_or_else(|| report.post.program.clone())),
        esc(&work_offset(machine))
    );
    let time = report.post.cycle_time.as_ref();
    if let Some(t) = time {
        let _ = write!(
            h,
            "<tr><td>cycle time</td><td>{} (cutting {}, links and rapids {}, tool changes {})</td></tr>",
            hms(t.total_s),
            hms(t.cutting_s),
            hms(t.link_s + t.rapid_s),
            hms(t.tool_change_s)
        );
    }
    if let Some(v) = &report.verdict {
        let _ = write!(
            h,
            "<tr><td>verification</td><td>{}</td></tr>",
            esc(&v.verification())
        );
    }
    h.push_str("</table>");

    // Tools in order of first use.
    let mut used: Vec<u32> = Vec::new();
    for op in operations {
        if let Some(n) = op.cl.tool_number {
            if !used.contains(&n) {
                used.push(n);
            }
        }
    }
    h.push_str(
        "<h3>Tools</h3><table><tr><th>T</th><th>name</th><th>shape (mm)</th><th>flute length (mm)\
         </th><th>shank Ø (mm)</th><th>holder (mm)</th><th>stick-out (mm)</th><th>gauge length \
         (mm)</th><th>teeth</th><th>operations</th><th>time</th></tr>",
    );
    for n in &used {
        let Some(tool) = tools.iter().find(|t| t.number == *n).or_else(|| {
            operations
                .iter()
                .find(|o| o.cl.tool_number == Some(*n))
                .and_then(|o| o.tool.as_ref())
        }) else {
            continue;
        };
        let ops: Vec<&JobOperation> = operations
            .iter()
            .filter(|o| o.cl.tool_number == Some(*n))
            .collect();
        let names: Vec<&str> = ops.iter().map(|o| o.cl.path.name.as_str()).collect();
        let seconds: f64 = time.map_or(0.0, |t| {
            t.operations
                .iter()
                .filter(|o| o.tool_number == *n)
                .map(|o| o.total_s)
                .sum()
        });
        let _ =
            write!(
            h,
            "<tr><td>T{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            tool.number,
            esc(tool.name()),
            esc(&shape(tool)),
            tool.cutter.flute_length,
            2.0 * tool.cutter.shank_radius,
            esc(&holder(tool)),
            tool.cutter.overall_length,
            tool.tool_length_mm,
            tool.teeth,
            esc(&names.join(", ")),
            if time.is_some() { hms(seconds) } else { "—".into() }
        );
    }
    h.push_str("</table>");

    h.push_str(
        "<h3>Operations</h3><table><tr><th>#</th><th>operation</th><th>kind</th><th>T</th>\
         <th>spindle (rpm)</th><th>feed (mm/min)</th><th>plunge feed (mm/min)</th><th>time</th></tr>",
    );
    for (i, op) in operations.iter().enumerate() {
        let rpm = op.cl.spindle.as_ref().map(|s| format!("{:.0}", s.rpm));
        let t = time
            .and_then(|t| t.operations.get(i))
            .map(|t| hms(t.total_s));
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>T{}</td><td>{}</td><td>{:.0}</td>\
             <td>{:.0}</td><td>{}</td></tr>",
            i + 1,
            esc(&op.cl.path.name),
            esc(&op.kind),
            op.cl.tool_number.unwrap_or_default(),
            rpm.unwrap_or_else(|| "—".into()),
            op.rates.feed_mm_per_min,
            op.rates.plunge_mm_per_min,
            t.unwrap_or_else(|| "—".into())
        );
    }
    h.push_str("</table>");
    h
}

/// The section as a whole document (`setup.html`).
pub fn document(job: &str, section: &str) -> String {
    format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{0} — setup sheet</title>\
         <style>body{{font-family:sans-serif;max-width:1200px;margin:2em auto}}\
         table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #ccc;padding:3px 8px}}\
         th{{background:#f3f3f3}}</style></head><body><h1>{0}</h1>{1}</body></html>\n",
        esc(job),
        section
    )
}
