//! The run's verdict: whether the program passed the independent verification, with the
//! limits that were in force, and what became of the program.
//!
//! A program passes when the stock simulation of the program as written finds no overcut
//! deeper than the limit (the job's `machining_tol` plus the simulation's own error bound at
//! its resolution, [`machining_sim::overcut_error_bound`]) and no collision. A program that
//! fails is withheld (removed) unless the run allows defects. The residual (material left)
//! is reported beside the verdict but does not decide it: roughing leaves stock by design.
//!
//! The verdict is one line for the terminal ([`Verdict::summary`]), a table at the top of
//! `report.html` and the `verdict` object of `report.json`.

use crate::report::Report;
use serde::Serialize;

/// Pass or fail of the verification.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Verified: no overcut beyond the limit, no collision.
    Pass,
    /// Verified: an overcut beyond the limit or a collision.
    Fail,
    /// Nothing was verified (verification disabled, nothing to machine, or no cutter known).
    NotVerified,
}

/// What became of the program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProgramState {
    /// Written to the output folder.
    Written,
    /// Posted but removed because verification failed (no `--allow-defects`).
    Withheld,
    /// Nothing to machine: no program was posted.
    None,
}

/// The verdict of a run (`verdict` in `report.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// Pass, fail or not verified (fail also when the machine cannot hold the tool paths
    /// within its travel).
    pub status: Status,
    /// Written, withheld or none.
    pub program: ProgramState,
    /// The job's `machining_tol` (mm).
    pub machining_tol_mm: f64,
    /// The overcut limit in force: `machining_tol` + the simulation's error bound (mm);
    /// `None` when nothing was verified.
    pub overcut_limit_mm: Option<f64>,
    /// Largest overcut measured (mm).
    pub max_overcut_mm: Option<f64>,
    /// Largest residual measured (mm; reported, not judged).
    pub max_residual_mm: Option<f64>,
    /// Moves with a collision (the limit is 0).
    pub collisions: Option<usize>,
    /// Dexel spacing of the simulation (mm).
    pub resolution_mm: Option<f64>,
    /// Whether operations leave the machine's travel (the program is then withheld before
    /// posting and nothing is verified; `report.post.travel` lists them).
    pub outside_travel: bool,
    /// The defects, one line each, with where they are.
    pub defects: Vec<String>,
}

impl Verdict {
    /// The verdict of `report` (after the verification gate ran) for a job whose
    /// `machining_tol` is `machining_tol_mm`.
    pub fn of(report: &Report, machining_tol_mm: f64) -> Self {
        let v = report.verification.as_ref();
        let outside_travel = !report.post.travel.is_empty();
        let status = match v {
            _ if outside_travel => Status::Fail,
            None => Status::NotVerified,
            Some(v) if v.defects.is_empty() => Status::Pass,
            Some(_) => Status::Fail,
        };
        let mut defects: Vec<String> = report
            .post
            .travel
            .iter()
            .map(|t| format!("machine {}: {}", report.post.machine, t.describe()))
            .collect();
        defects.extend(v.map(|v| v.defects.clone()).unwrap_or_default());
        let program = if report.post.written {
            ProgramState::Written
        } else if report.post.program.is_empty() {
            ProgramState::None
        } else {
            ProgramState::Withheld
        };
        Self {
            status,
            program,
            machining_tol_mm,
            overcut_limit_mm: v.map(|v| v.overcut_limit_mm),
            max_overcut_mm: v.map(|v| v.max_overcut_mm),
            max_residual_mm: v.map(|v| v.max_residual_mm),
            collisions: v.map(|v| v.collisions),
            resolution_mm: v.map(|v| v.resolution_mm),
            outside_travel,
            defects,
        }
    }

    /// `PASS`, `FAIL` or `NOT VERIFIED`.
    pub fn word(&self) -> &'static str {
        match self.status {
            Status::Pass => "PASS",
            Status::Fail => "FAIL",
            Status::NotVerified => "NOT VERIFIED",
        }
    }

    /// The verification with its limits, e.g. `verification PASS (overcut 0.0197 mm <= limit
    /// 0.1190 mm = machining_tol 0.01 mm + simulation bound at 0.25 mm resolution; 0
    /// collisions; residual 0.52 mm, not judged)`.
    pub fn verification(&self) -> String {
        match (
            self.max_overcut_mm,
            self.overcut_limit_mm,
            self.collisions,
            self.resolution_mm,
        ) {
            (Some(o), Some(limit), Some(c), Some(res)) => format!(
                "verification {} (overcut {o:.4} mm {} limit {limit:.4} mm = machining_tol {} mm \
                 + simulation bound at {res} mm resolution; {c} collision(s), limit 0; \
                 residual {:.4} mm, not judged)",
                self.word(),
                if o > limit { ">" } else { "<=" },
                self.machining_tol_mm,
                self.max_residual_mm.unwrap_or(0.0),
            ),
            _ if self.outside_travel => {
                "FAIL, not verified: the machine cannot hold the tool paths within its travel"
                    .to_string()
            }
            _ => format!("verification {}", self.word()),
        }
    }

    /// What became of the program at `path`: the path, `withheld (verification failed: …)`
    /// or `(none: nothing to machine)`.
    pub fn program_text(&self, path: &str) -> String {
        match self.program {
            ProgramState::Written => path.to_string(),
            ProgramState::Withheld if self.outside_travel => format!(
                "withheld (the machine cannot hold it within its travel: {})",
                self.defects.join("; ")
            ),
            ProgramState::Withheld => format!(
                "withheld (verification failed: {})",
                self.defects.join("; ")
            ),
            ProgramState::None => "(none: nothing to machine)".to_string(),
        }
    }

    /// The terminal's last line after `job: N operation(s), `: program and verification.
    pub fn summary(&self, program_path: &str) -> String {
        format!(
            "program {}, {}",
            self.program_text(program_path),
            self.verification()
        )
    }
}

/// A collision in a shop's words: `move 12 of rough (a rapid): the tool runs into the
/// finished part, 0.512 mm deep at (1.000, 2.000, 3.000)` (it was `RapidMove Rapid into
/// the Design`).
pub fn collision_text(c: &machining_sim::Collision) -> String {
    let what = match c.move_kind {
        cam_core::MoveKind::Rapid => "a rapid",
        cam_core::MoveKind::Feed => "a cutting move",
        cam_core::MoveKind::Link => "a link at feed",
        cam_core::MoveKind::Plunge => "a plunge",
        cam_core::MoveKind::Retract => "a retract",
    };
    let part = match c.part {
        machining_sim::PartKind::Shank => "the shank",
        machining_sim::PartKind::Holder => "the holder",
        machining_sim::PartKind::RapidMove => "the tool",
    };
    let target = match c.target {
        machining_sim::CollisionTarget::Stock => "stock not yet cut",
        machining_sim::CollisionTarget::Design => "the finished part",
    };
    format!(
        "move {} of {} ({what}): {part} runs into {target}, {:.3} mm deep at ({:.3}, {:.3}, {:.3})",
        c.move_index, c.operation, c.depth_mm, c.point[0], c.point[1], c.point[2]
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::VerificationReport;

    fn verified(defects: Vec<String>, written: bool) -> Report {
        let mut r = Report::new("j");
        r.post.program = "out/program.ngc".into();
        r.post.written = written;
        r.verification = Some(VerificationReport {
            max_overcut_mm: 0.2,
            max_residual_mm: 0.5,
            collisions: 0,
            resolution_mm: 0.25,
            overcut_limit_mm: 0.119,
            defects,
            surface_groups: Default::default(),
            source: "program".into(),
            details: serde_json::Value::Null,
        });
        r
    }

    /// A withheld program is reported as withheld with the failure, never as "nothing to
    /// machine" (the old summary said `program (none: nothing to machine)`).
    #[test]
    fn a_withheld_program_says_withheld_and_why() {
        let r = verified(vec!["overcut 0.2000 mm exceeds 0.1190 mm".into()], false);
        let v = Verdict::of(&r, 0.01);
        assert_eq!(v.status, Status::Fail);
        assert_eq!(v.program, ProgramState::Withheld);
        let s = v.summary(&r.post.program);
        assert!(
            s.starts_with(
                "program withheld (verification failed: overcut 0.2000 mm exceeds 0.1190 mm)"
            ),
            "{s}"
        );
        assert!(s.contains("verification FAIL (overcut 0.2000 mm > limit 0.1190 mm"));
        assert!(!s.contains("nothing to machine"), "{s}");
    }

    #[test]
    fn a_passing_program_names_its_path_and_the_limit_in_force() {
        let mut r = verified(Vec::new(), true);
        if let Some(v) = r.verification.as_mut() {
            v.max_overcut_mm = 0.0197;
        }
        let v = Verdict::of(&r, 0.01);
        assert_eq!((v.status, v.program), (Status::Pass, ProgramState::Written));
        assert_eq!(
            v.summary(&r.post.program),
            "program out/program.ngc, verification PASS (overcut 0.0197 mm <= limit 0.1190 mm \
             = machining_tol 0.01 mm + simulation bound at 0.25 mm resolution; 0 collision(s), \
             limit 0; residual 0.5000 mm, not judged)"
        );
    }

    #[test]
    fn a_collision_reads_in_a_shops_words() {
        let c = machining_sim::Collision {
            operation: "rough".into(),
            move_index: 12,
            move_kind: cam_core::MoveKind::Rapid,
            part: machining_sim::PartKind::RapidMove,
            target: machining_sim::CollisionTarget::Design,
            depth_mm: 0.5123,
            point: [1.0, 2.0, 3.0],
        };
        assert_eq!(
            collision_text(&c),
            "move 12 of rough (a rapid): the tool runs into the finished part, 0.512 mm deep \
             at (1.000, 2.000, 3.000)"
        );
    }

    #[test]
    fn nothing_posted_is_nothing_to_machine_and_not_verified() {
        let r = Report::new("j");
        let v = Verdict::of(&r, 0.01);
        assert_eq!(
            (v.status, v.program),
            (Status::NotVerified, ProgramState::None)
        );
        assert_eq!(
            v.summary(""),
            "program (none: nothing to machine), verification NOT VERIFIED"
        );
    }
}
