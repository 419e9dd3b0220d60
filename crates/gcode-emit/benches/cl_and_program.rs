//! Throughput of the text layers: reading a 100,000-point CL file and writing a 100,000-block
//! LinuxCNC program (kinematics excluded; `postproc-kinematics` benches those).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use gcode_emit::{
    read_cl, ClReadOptions, Coolant, Dialect, Feed, LinuxCnc, Motion, NcMove, NcOperation,
    NcProgram, OutputMode, ProgramOptions, RotaryWord, ToolCall,
};
use std::fmt::Write;

const N: usize = 100_000;

fn cl_text() -> String {
    let mut s = String::from("MULTAX/ON\nLOADTL/1\nCUTTER/6,3,0,3,0,0,30\nFEDRAT/MMPM,800\n");
    for i in 0..N {
        let t = i as f64 * 1e-3;
        let (si, co) = (0.3 * t.sin(), 0.3 * t.cos());
        let k = (1.0 - si * si - co * co).sqrt();
        writeln!(
            s,
            "GOTO/{:.6},{:.6},{:.6},{:.7},{:.7},{:.7}",
            40.0 * t.cos(),
            40.0 * t.sin(),
            5.0 + 0.01 * t,
            si,
            co,
            k
        )
        .unwrap();
    }
    s.push_str("FINI\n");
    s
}

fn program() -> NcProgram {
    let moves = (0..N)
        .map(|i| {
            let t = i as f64 * 1e-3;
            NcMove {
                xyz: [40.0 * t.cos(), 40.0 * t.sin(), 5.0 + 0.01 * t],
                rotary: vec![
                    RotaryWord {
                        letter: 'A',
                        deg: 20.0 * t.sin(),
                    },
                    RotaryWord {
                        letter: 'C',
                        deg: t.to_degrees(),
                    },
                ],
                tool_vector: None,
                feed: Feed::InverseTime(100.0 + t),
            }
        })
        .collect();
    NcProgram {
        name: "bench".into(),
        operations: vec![NcOperation {
            name: "op".into(),
            tool: ToolCall {
                number: 1,
                name: "T1".into(),
                spindle: None,
                coolant: Coolant::Off,
            },
            motion: Motion::Simultaneous {
                mode: OutputMode::Joint,
                moves,
            },
        }],
    }
}

fn bench(c: &mut Criterion) {
    let text = cl_text();
    let opts = ClReadOptions::default();
    c.bench_function("gcode_emit/read_cl_100k", |b| {
        b.iter(|| read_cl(&text, "bench.cls", &opts).unwrap())
    });
    let p = program();
    let o = ProgramOptions::default();
    c.bench_function("gcode_emit/write_linuxcnc_100k", |b| {
        b.iter(|| LinuxCnc::default().write(&p, &o).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
