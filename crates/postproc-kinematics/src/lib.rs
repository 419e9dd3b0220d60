//! Five-axis machine kinematics for CAM post-processing: machine descriptions (table-table
//! trunnions compatible with LinuxCNC `xyzac-trt` / `xyzbc-trt`, head-table turn-milling
//! centres, head-head fork heads), inverse and forward kinematics with solution choice by
//! limits and continuity, singularity handling and unwinding, path post-processing with
//! reverse-motion detection, linearisation control and inverse-time feeds.
//!
//! Units: mm and radians in code; degrees only in machine files and in
//! [`Machine::axis_words`]. A cutter location is the tool tip plus the unit tool axis
//! (tip → spindle), in the workpiece frame.
//!
//! Joint output convention: for table-table machines X Y Z are the tool-tip coordinates in the
//! machine frame with tool length compensation active (the tool length does not enter the
//! rotary transform — exactly LinuxCNC's `xyzac-trt` / `xyzbc-trt` relation between joints
//! and world with G43); for head machines X Y Z are the tip position the machine would have at
//! zero head angles, so pivot length plus tool length enter the transform. Rotary senses
//! follow LinuxCNC's `conventional_directions` for table-table machines and explicit
//! `tilt_sign` / `rotary_sign` for head machines (see [`machine`]).
//!
//! Modules: [`machine`] (description and TOML file), [`kinematics`] (forward / inverse,
//! solution choice), [`post`] (path post-processing and metrics), [`cycle_time`] (block
//! times from the axis speed and acceleration limits), [`reverse_motion`]
//! (detection and removal, paper 004), [`rotary_motion`] (reversals inside cuts vs at links,
//! angular steps and accelerations at the programmed feed), [`bspline_fit`] (least-squares cubic B-spline used by
//! the smoothing), [`linearise`] (joint-interpolation error and subdivision), [`feed`]
//! (inverse-time feed), [`plot`] (SVG displacement curves).
//!
//! Dependencies: `cam-core` (cutter locations, moves), `nalgebra` (vectors; SVD least squares
//! of the small B-spline systems), `serde` + `toml` (machine files with spans for line
//! numbers), `thiserror` (errors), `rayon` (segment deviations evaluated in parallel) — the
//! workspace's chosen crates.
//!
//! ```
//! use postproc_kinematics::{Machine, post_locations, PostOptions};
//! use cam_core::{CutterLocation, Point3, Vector3};
//! let m = Machine::from_toml_str(r#"
//! name = "demo"
//! [kinematics]
//! type = "table-table"
//! tilt_axis = "A"
//! [axes.X]
//! min = -500.0
//! max = 500.0
//! [axes.Y]
//! min = -500.0
//! max = 500.0
//! [axes.Z]
//! min = -500.0
//! max = 500.0
//! [axes.A]
//! min = -120.0
//! max = 120.0
//! [axes.C]
//! mode = "continuous"
//! "#, "demo.toml").unwrap();
//! let cl = CutterLocation::new(Point3::new(10.0, 0.0, 5.0), Vector3::new(0.0, 0.5, 1.0)).unwrap();
//! let j = m.inverse(&cl, 50.0, None).unwrap();
//! let back = m.forward(&j, 50.0);
//! assert!((back.tip - cl.tip).norm() < 1e-9);
//! let posted = post_locations(&m, &[cl], &PostOptions::default()).unwrap();
//! assert_eq!(posted.blocks.len(), 1);
//! ```

pub mod banded_lsq;
pub mod bspline_fit;
pub mod cycle_time;
pub mod error;
pub mod feed;
pub mod joints;
pub mod kinematics;
pub mod linearise;
pub mod machine;
pub mod plot;
pub mod post;
pub mod reverse_motion;
pub mod rotary_motion;

pub use cycle_time::{BlockProfile, CycleTimeError, MotionTimer};
pub use error::{KinematicsError, MachineError, PostError};
pub use joints::{AxisId, Joints};
pub use kinematics::{wrap_pi, LIMIT_SLACK};
pub use machine::{
    AxisSpec, Blending, HeadHead, HeadTable, Kinematics, Machine, RotaryMode, TableTable, TiltAxis,
};
pub use post::{
    is_reconfiguration, post_locations, post_path, post_path_checked, post_tool_path,
    swinging_rapids, LimitPolicy, PostMetrics, PostOptions, PostedBlock, PostedPath,
};
pub use reverse_motion::{
    AccessibilityChecker, DisplacementCurves, ReverseMotionOptions, ReverseMotionReport,
};
pub use rotary_motion::{AxisReversals, ReversalSplit, RotarySmoothness};

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
