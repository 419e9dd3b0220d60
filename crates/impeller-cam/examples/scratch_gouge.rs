use gcode_emit::{read_cl_file, ClReadOptions};
use machining_sim::{DesignModel, ImpellerDesign, ImpellerSampling};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let imp = impeller_model::load(&a[1]).unwrap();
    let design = ImpellerDesign::new(&imp, ImpellerSampling::default()).unwrap();
    let cl = read_cl_file(std::path::Path::new(&a[2]), &ClReadOptions::default()).unwrap();
    let r: f64 = a[3].parse().unwrap();
    let moves = &cl.operations[0].path.moves;
    let mut worst: Vec<(f64, usize)> = moves
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, m)| {
            let p = &moves[i - 1];
            let mut w = f64::INFINITY;
            for k in 0..=10 {
                let s = k as f64 / 10.0;
                let tip = p.cl.tip + (m.cl.tip - p.cl.tip) * s;
                let ax = (p.cl.axis.into_inner() * (1.0 - s) + m.cl.axis.into_inner() * s).normalize();
                w = w.min(design.signed_distance(&(tip + ax * r)) - r);
                for h in [2.0f64, 3.0, 5.0, 8.0, 12.0] {
                    let rad = r + (h - r) * 2f64.to_radians().tan();
                    w = w.min(design.signed_distance(&(tip + ax * h)) - rad);
                }
            }
            (w, i)
        })
        .collect();
    worst.sort_by(|x, y| x.0.total_cmp(&y.0));
    for (d, i) in worst.iter().take(40).step_by(4) {
        let k = |j: usize| moves.get(j).map(|m| format!("{:?}", m.kind)).unwrap_or_default();
        println!("move {i} len {:.3} dax {:.2}deg clearance {d:.4} kinds {} [{}] {} tip {:?}", (moves[*i].cl.tip - moves[i - 1].cl.tip).norm(), moves[*i].cl.axis.angle(&moves[i - 1].cl.axis).to_degrees(), k(i.wrapping_sub(1)), k(*i), k(i + 1), moves[*i].cl.tip.coords.as_slice());
    }
    let n = worst.iter().filter(|w| w.0 < -0.05).count();
    println!("{n} of {} moves with ball penetrating > 0.05", moves.len());
}
