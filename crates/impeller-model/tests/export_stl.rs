//! Binary STL export: the file format, the chord tolerance, atomic writing.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::export::{
    mesh_fillets, mesh_parts, stl_bytes, tessellate, tessellate_compact, write_stl, ExportError,
    Part,
};
use impeller_model::fixtures::default_impeller;
use impeller_model::meridional::MeridionalCurve;
use nalgebra::Vector3;

/// The largest distance `dist` of a triangle's centroid or edge midpoint from the surface:
/// where the chord check of the tessellation samples.
fn largest_chord_deviation(
    mesh: &impeller_model::export::TriMesh,
    dist: impl Fn(&Vector3<f64>) -> f64,
) -> f64 {
    let mut worst: f64 = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        for q in [
            (a + b + c) / 3.0,
            (a + b) / 2.0,
            (b + c) / 2.0,
            (a + c) / 2.0,
        ] {
            worst = worst.max(dist(&q));
        }
    }
    worst
}

/// Every triangle's centroid and edge midpoints lie within the chord tolerance of the hub, a
/// surface of revolution whose distance is known exactly through its meridional contour.
#[test]
fn hub_triangles_within_chord_tolerance() {
    let imp = default_impeller().unwrap();
    let tol = 0.02;
    let mesh = tessellate(imp.hub().surface(), tol, "hub").unwrap();
    let m = imp.hub().meridional();
    let worst = largest_chord_deviation(&mesh, |q| m.closest(MeridionalCurve::zr_of(q)).1.abs());
    for v in &mesh.vertices {
        assert!(m.closest(MeridionalCurve::zr_of(v)).1.abs() < 1e-9);
    }
    assert!(
        worst <= tol,
        "largest chord deviation {worst} mm > {tol} mm"
    );
    // Not needlessly fine either: the deviation uses a good part of the tolerance.
    assert!(worst > 0.2 * tol, "{worst}");
}

/// With a longest edge, a blade side (ruled: its rulings are straight, so the chord alone
/// leaves slivers as long as them) is cut into triangles whose edges keep the limit (grid
/// edges within it, diagonals within √2 of it), on the same surface (vertices on it) and
/// still within the chord tolerance at edge midpoints and centroids (distance to the side
/// measured by the exact closest point); a limit that is not a positive length is an error.
#[test]
fn compact_tessellation_keeps_edges_and_chord() {
    let imp = default_impeller().unwrap();
    let side = imp.main().blade().side(impeller_model::Side::Pressure);
    let (tol, edge) = (0.05, 2.0);
    let plain = tessellate(side, tol, "side").unwrap();
    let longest = |m: &impeller_model::export::TriMesh| {
        m.triangles
            .iter()
            .flat_map(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                [(a - b).norm(), (b - c).norm(), (c - a).norm()]
            })
            .fold(0.0f64, f64::max)
    };
    assert!(longest(&plain) > 2.0 * edge, "{}", longest(&plain));
    let mesh = tessellate_compact(side, tol, edge, "side").unwrap();
    assert!(
        longest(&mesh) <= edge * 2f64.sqrt() + 1e-9,
        "{}",
        longest(&mesh)
    );
    let projector = nurbs::closest::SurfaceProjector::new(side);
    let dist = |q: &Vector3<f64>| (projector.closest_point(q).point - q).norm();
    let worst = largest_chord_deviation(&mesh, dist);
    assert!(
        worst <= tol,
        "largest chord deviation {worst} mm > {tol} mm"
    );
    for v in mesh.vertices.iter().step_by(7) {
        assert!(dist(v) < 1e-7, "{}", dist(v));
    }
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            tessellate_compact(side, tol, bad, "side"),
            Err(ExportError::Invalid { .. })
        ));
    }
}

#[test]
fn binary_stl_layout() {
    let imp = default_impeller().unwrap();
    let mesh = mesh_parts(&imp, &[Part::MainBlades], 0.05).unwrap();
    let bytes = stl_bytes(&mesh, "test");
    let n = mesh.triangles.len();
    assert!(n > 0);
    assert_eq!(bytes.len(), 84 + 50 * n);
    assert_eq!(
        u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize,
        n
    );
    // First triangle's first vertex round-trips through f32.
    let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as f64;
    let v0 = mesh.vertices[mesh.triangles[0][0] as usize];
    let read = Vector3::new(f(84 + 12), f(84 + 16), f(84 + 20));
    assert!((read - v0).norm() < 1e-4 * (1.0 + v0.norm()));
    // Normal is unit length.
    let nrm = Vector3::new(f(84), f(88), f(92));
    assert!((nrm.norm() - 1.0).abs() < 1e-5);
    // Every main blade copy is there: count × (pressure + suction) meshes of equal size.
    let one = mesh_parts(&imp, &[Part::MainBlades], 0.05)
        .unwrap()
        .triangles
        .len();
    assert_eq!(one % (2 * imp.main().count()), 0);
}

#[test]
fn whole_impeller_written_atomically() {
    let imp = default_impeller().unwrap();
    let dir = std::env::temp_dir().join(format!("impeller-stl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("impeller.stl");
    let stats = write_stl(&imp, &[Part::Impeller], 0.05, &path).unwrap();
    let len = std::fs::metadata(&path).unwrap().len() as usize;
    assert_eq!(len, 84 + 50 * stats.triangles);
    let parts = mesh_parts(
        &imp,
        &[
            Part::Hub,
            Part::MainBlades,
            Part::SplitterBlades,
            Part::Fillets,
        ],
        0.05,
    )
    .unwrap();
    assert_eq!(parts.triangles.len(), stats.triangles);
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["impeller.stl".to_string()]);
    // A folder that does not exist: an I/O error, and nothing written.
    let bad = dir.join("missing/sub/impeller.stl");
    assert!(matches!(
        write_stl(&imp, &[Part::Hub], 0.05, &bad),
        Err(ExportError::Io { .. })
    ));
    assert!(matches!(
        write_stl(&imp, &[Part::Hub], 0.0, &path),
        Err(ExportError::Invalid { .. })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn imported_centrifugal_exports_stl() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let imp = impeller_model::load(import_common::centrifugal_geomturbo()).unwrap();
    let mesh = mesh_parts(&imp, &[Part::Impeller], 0.05).unwrap();
    let r_max = mesh
        .vertices
        .iter()
        .map(|v| v.xy().norm())
        .fold(0.0, f64::max);
    // Hub trimmed 10 % beyond the 0.20 m trailing edge.
    assert!(r_max > 200.0 && r_max < 240.0, "{r_max}");
}

/// The blade-root fillets of impeller-8+8 (R = 1 mm) in the export: every vertex on the
/// fillet (the exact arc of a fitted section: within the spine's 1e-4 mm), every triangle's
/// centroid and edge midpoints within the chord tolerance, triangles facing the air (a point
/// 0.01 mm along the normal from the centroid is outside the fillet material), a fillet on
/// every blade of both rows, and in the whole-impeller export.
#[test]
fn fillets_are_exported_on_the_fillet_within_the_chord_tolerance() {
    let imp = default_impeller().unwrap();
    let tol = 0.02;
    let mesh = mesh_fillets(&imp, tol).unwrap();
    assert!(!mesh.triangles.is_empty());
    let fillets = impeller_model::fillet::ImpellerFillets::new(&imp, 1e-4)
        .unwrap()
        .unwrap();
    // The fillet's distance is not defined at a piece's first and last section (the
    // projection onto the spine lands on its end): those vertices are left out, no others.
    let dist = |q: &Vector3<f64>| fillets.closest(q).map_or(0.0, |(d, _)| d.abs());
    let undecided = mesh
        .vertices
        .iter()
        .filter(|v| fillets.closest(v).is_none())
        .count();
    assert!(
        undecided * 20 < mesh.vertices.len(),
        "{undecided} of {} vertices",
        mesh.vertices.len()
    );
    let on = mesh.vertices.iter().map(dist).fold(0.0, f64::max);
    assert!(on <= 1e-4 + 1e-9, "vertex {on} mm off the fillet");
    let chord = largest_chord_deviation(&mesh, dist);
    assert!(chord <= tol, "chord deviation {chord} mm > {tol} mm");
    let mut facing_air = 0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let n = (b - a).cross(&(c - a));
        let Some(n) = n.try_normalize(1e-15) else {
            continue;
        };
        let q = (a + b + c) / 3.0 + n * 0.01;
        if fillets.closest(&q).is_some_and(|(d, _)| d > 0.0) {
            facing_air += 1;
        } else {
            panic!("triangle at {q:?} faces into the fillet material");
        }
    }
    assert!(facing_air > mesh.triangles.len() / 2);
    // Every blade of both rows carries its fillets: 16 blades with 2 sides each.
    let n_blades = imp.main().count() + imp.splitter().map_or(0, |s| s.count());
    assert_eq!(n_blades, 16);
    let angles: std::collections::BTreeSet<i64> = mesh
        .vertices
        .iter()
        .map(|v| (v.y.atan2(v.x).to_degrees() / 5.0).floor() as i64)
        .collect();
    assert!(angles.len() > 40, "{} angular bins of 72", angles.len());
    let all = mesh_parts(&imp, &[Part::Impeller], tol).unwrap();
    let bare = mesh_parts(
        &imp,
        &[Part::Hub, Part::MainBlades, Part::SplitterBlades],
        tol,
    )
    .unwrap();
    assert_eq!(
        all.triangles.len(),
        bare.triangles.len() + mesh.triangles.len()
    );
}
