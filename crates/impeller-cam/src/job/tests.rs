use super::*;

#[test]
fn paths_resolve_against_the_job_folder() {
    let job = Job::from_toml_str(
        "name = \"j\"\nimpeller = \"imp.toml\"\nmachine = \"../m.toml\"\n[[cl_files]]\npath = \"a.cls\"\n",
        Path::new("/x/y/job.toml"),
    )
    .unwrap();
    assert_eq!(job.impeller.unwrap(), Path::new("/x/y/imp.toml"));
    assert_eq!(job.machine.unwrap(), Path::new("/x/y/../m.toml"));
    assert_eq!(job.cl_files, vec![PathBuf::from("/x/y/a.cls")]);
    assert_eq!(job.dialect, "linuxcnc");
}

#[test]
fn errors_name_file_line_and_field() {
    let err = Job::from_toml_str("name = \"j\"\nimpeler = \"x\"\n", Path::new("job.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("job.toml:2:"), "{err}");
    assert!(err.contains("impeler"), "{err}");
    let err = Job::from_toml_str("[tolerances]\nchord_tol = -1.0\n", Path::new("job.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("job.toml:2: tolerances.chord_tol"), "{err}");
    let err = Job::from_toml_str(
        "[verification]\nresolution_mm = 0.0\n",
        Path::new("job.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("job.toml:2: verification.resolution_mm"),
        "{err}"
    );
}

#[test]
fn default_job_is_the_fixture_job_with_its_tools() {
    let job = Job::default_job().unwrap();
    assert_eq!(job.name, "impeller-8+8");
    assert_eq!(job.dialect, "linuxcnc");
    assert!(job.tools.len() >= 3, "{:?}", job.tools);
    let t5 = job.tool("T5-taper-ball-r1.5").unwrap();
    assert_eq!(t5.number, 5);
    match t5.cutter.shape {
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => {
            assert_eq!(ball_radius, 1.5);
            assert!((half_angle - 2f64.to_radians()).abs() < 1e-15);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(t5.cutter.shank_radius, 3.0);
    assert_eq!(t5.cutter.holder[0].bottom_radius, 10.5);
    let machine = job.machine.clone().unwrap();
    assert!(job.is_embedded(&machine));
    assert!(job.read_text(&machine).unwrap().contains("xyzac-trt"));
    assert_eq!(job.cl_files.len(), 1);
    assert!(job.read_text(&job.cl_files[0]).unwrap().contains("GOTO/"));
}
