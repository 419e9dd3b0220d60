//! The tool paths as a glTF 2.0 file (`toolpaths.gltf`, written by `run --export-paths`) so
//! the same paths open in other viewers (Blender, three.js editor, any glTF viewer).
//!
//! One node per operation, each with a mesh of up to two `LINES` primitives (mode 1): the
//! cutting moves (plunge and feed) in the operation's colour of the 3D view
//! ([`crate::view3d::OP_COLOURS`]) and the links and rapids in grey. Each move from the
//! previous tool tip to its own is one line segment. Positions are the tool tips in the
//! workpiece frame in millimetres, `f32`; a root node scales them to glTF's metres (0.001)
//! and turns the workpiece's +Z up onto glTF's +Y up (−90° about X). The buffer is embedded
//! as a base64 data URI (one self-contained file). O(moves).

use crate::pipeline::JobOperation;
use cam_core::MoveKind;
use serde_json::{json, Value};

/// The glTF document of the operations' tool paths.
pub fn toolpaths(operations: &[JobOperation]) -> Value {
    let mut buffer: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (vec![], vec![], vec![], vec![]);
    let mut materials = vec![json!({
        "name": "links and rapids",
        "pbrMetallicRoughness": { "baseColorFactor": [0.6, 0.6, 0.6, 1.0] },
    })];
    for (k, op) in operations.iter().enumerate() {
        let path = &op.cl.path;
        let (mut cut, mut link) = (Vec::new(), Vec::new());
        for w in path.moves.windows(2) {
            let seg = if matches!(w[1].kind, MoveKind::Plunge | MoveKind::Feed) {
                &mut cut
            } else {
                &mut link
            };
            for m in w {
                seg.push([m.cl.tip.x as f32, m.cl.tip.y as f32, m.cl.tip.z as f32]);
            }
        }
        let colour = crate::view3d::OP_COLOURS[k % crate::view3d::OP_COLOURS.len()];
        materials.push(json!({
            "name": format!("{} cutting moves", path.name),
            "pbrMetallicRoughness": { "baseColorFactor": rgba(colour) },
        }));
        let material = materials.len() - 1;
        let mut primitives = Vec::new();
        for (points, material) in [(cut, material), (link, 0)] {
            if points.is_empty() {
                continue;
            }
            let offset = buffer.len();
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for p in &points {
                for c in 0..3 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                    buffer.extend_from_slice(&p[c].to_le_bytes());
                }
            }
            views.push(json!({
                "buffer": 0,
                "byteOffset": offset,
                "byteLength": buffer.len() - offset,
                "target": 34962,
            }));
            accessors.push(json!({
                "bufferView": views.len() - 1,
                "componentType": 5126,
                "count": points.len(),
                "type": "VEC3",
                "min": lo,
                "max": hi,
            }));
            primitives.push(json!({
                "attributes": { "POSITION": accessors.len() - 1 },
                "mode": 1,
                "material": material,
            }));
        }
        if primitives.is_empty() {
            continue;
        }
        meshes.push(json!({ "name": path.name, "primitives": primitives }));
        nodes.push(json!({ "name": path.name, "mesh": meshes.len() - 1 }));
    }
    let children: Vec<usize> = (1..=nodes.len()).collect();
    let s = std::f64::consts::FRAC_1_SQRT_2;
    nodes.insert(
        0,
        json!({
            "name": "workpiece (mm, Z up)",
            "rotation": [-s, 0.0, 0.0, s],
            "scale": [0.001, 0.001, 0.001],
            "children": children,
        }),
    );
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": concat!("impeller-cam ", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": nodes,
        "materials": materials,
    });
    if !meshes.is_empty() {
        doc["meshes"] = json!(meshes);
        doc["accessors"] = json!(accessors);
        doc["bufferViews"] = json!(views);
        doc["buffers"] = json!([{
            "byteLength": buffer.len(),
            "uri": format!(
                "data:application/octet-stream;base64,{}",
                crate::view3d::base64(&buffer)
            ),
        }]);
    }
    doc
}

/// `#rrggbb` as linear RGBA factors (glTF colours are linear: sRGB decoded).
fn rgba(hex: &str) -> [f64; 4] {
    let c = |i: usize| {
        let v = f64::from(u8::from_str_radix(hex.get(i..i + 2).unwrap_or("80"), 16).unwrap_or(128))
            / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    [c(1), c(3), c(5), 1.0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{CutterLocation, Move, Point3, ToolPath, Vector3};

    /// Every segment's end points come back from the buffer as the moves' tips (f32), cutting
    /// and link moves apart, with accessor counts, bounds and the buffer length consistent.
    #[test]
    fn toolpath_lines_decode_to_the_moves() {
        let cl =
            |x: f64, z: f64| CutterLocation::new(Point3::new(x, 1.5, z), Vector3::z()).unwrap();
        let mv = |kind, x, z| Move {
            kind,
            cl: cl(x, z),
            feed_mm_per_min: None,
        };
        let mut path = ToolPath::new("op", "T1");
        path.moves = vec![
            mv(MoveKind::Rapid, 0.0, 50.0),
            mv(MoveKind::Plunge, 0.0, 10.0),
            mv(MoveKind::Feed, 5.0, 10.0),
            mv(MoveKind::Feed, 9.25, 11.0),
            mv(MoveKind::Retract, 9.25, 50.0),
        ];
        let op = JobOperation {
            cl: gcode_emit::ClOperation::new(path),
            kind: "test".into(),
            tool: None,
            rates: cam_core::Rates::default(),
            plan_ms: 0.0,
            metrics: cam_plan::Metrics::default(),
            plots: Vec::new(),
        };
        let doc = toolpaths(std::slice::from_ref(&op));
        // Cutting: plunge, feed, feed (3 segments); links: the retract (1 segment); in order.
        let tips = [
            [0.0f32, 1.5, 50.0],
            [0.0, 1.5, 10.0],
            [5.0, 1.5, 10.0],
            [9.25, 1.5, 11.0],
            [9.25, 1.5, 50.0],
        ];
        let order = [0, 1, 1, 2, 2, 3, 3, 4];
        let bytes: Vec<u8> = order
            .iter()
            .flat_map(|&i| tips[i].iter().flat_map(|c| c.to_le_bytes()))
            .collect();
        let uri = doc["buffers"][0]["uri"].as_str().unwrap();
        assert_eq!(
            uri.strip_prefix("data:application/octet-stream;base64,"),
            Some(crate::view3d::base64(&bytes).as_str())
        );
        assert_eq!(doc["buffers"][0]["byteLength"], bytes.len());
        assert_eq!(doc["accessors"][0]["count"], 6);
        assert_eq!(doc["accessors"][1]["count"], 2);
        assert_eq!(doc["bufferViews"][1]["byteOffset"], 6 * 12);
        assert_eq!(doc["accessors"][0]["max"][0], 9.25);
        assert_eq!(doc["meshes"][0]["primitives"][1]["material"], 0);
    }
}
