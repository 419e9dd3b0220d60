//! Linking that knows the machine: rapids on which the machine would swing are routed over
//! the safety surface.
//!
//! The planners link their moves without knowing the machine: between two plunges of a
//! plunge-roughing row, for example, the tool travels at rapid from one plunge start to the
//! next, a few millimetres above the blank. On the machine a rapid is joint-interpolated. When
//! the posture choice of the post ([`postproc_kinematics::post_path`]) changes the solution
//! branch on such a rapid (a tilt-sign flip where the tool axis passes near the rotary axis'
//! singular direction, a limit forcing the other branch) or unwinds a continuous rotary axis,
//! the post cannot linearise the move ([`postproc_kinematics::swinging_rapids`]) and the tool
//! sweeps an arc as large as the pivot plus tool length: on a head-head machine one such rapid
//! between two plunges of `impeller-plunge-400` turned C by 308° and took the Ø30 cutter 30 mm
//! deep through the blank.
//!
//! [`reroute_swinging_rapids`] posts the operation once without linearisation (the same
//! posture choice as the real post: the same machine, tool length, chaining and options),
//! finds those rapids and replaces each one that starts or ends inside the safety surface by
//! the linker's detour ([`cam_plan::Linker::connect`]): retract along the tool axis to the
//! safety surface, travel over it (where the axis turns through +Z, the rotary axis' pole on
//! the fixture machines, so the swing happens with the tool above the blank), approach along
//! the next axis. A swinging approach that already starts on the surface is fed instead (see
//! [`reroute_swinging_rapids`]). The detour changes the postures after it, so the check is repeated
//! (at most [`MAX_RELINK_PASSES`] passes) until no such rapid is left inside the surface.
//!
//! Cost per pass: one post without linearisation, O(n) inverse kinematics plus one sweep
//! continuation per large rotary step.

use cam_core::{CutterLocation, Move, MoveKind, ToolPath};
use cam_plan::Linker;
use postproc_kinematics::{post_path, swinging_rapids, Joints, LimitPolicy, Machine, PostOptions};

/// Most posting passes of [`reroute_swinging_rapids`] (each pass reroutes every swinging
/// rapid it finds; a detour can only move a later branch change, and the plunge-400 job needs
/// two).
pub const MAX_RELINK_PASSES: usize = 4;

/// What [`reroute_swinging_rapids`] did to one operation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MachineLinks {
    /// Rapids replaced by a detour over the safety surface, or approaches from it fed so that
    /// the swing happens on the surface.
    pub rerouted: usize,
    /// Swinging rapids still inside the safety surface after the last pass (their ends allow
    /// no retract along the tool axis, or the passes ran out).
    pub remaining: usize,
    /// Swinging rapids with both ends on or outside the safety surface after the last pass.
    /// They are left as they are: a detour would start and end where they do. A rotate axis
    /// about the impeller axis keeps a tool outside the capped cylinder outside it, but a
    /// tilting axis (A or B) swings the part about a horizontal line, which can bring the tool
    /// into it. The verification judges their joint motion where it reads the program back
    /// (LinuxCNC); for the other dialects it simulates the posted cutter locations.
    pub on_surface: usize,
    /// The last posture of the operation as posted (the next operation starts from it).
    pub last: Option<Joints>,
    /// The blocks of the operation as posted that leave the machine's travel.
    pub travel: Option<crate::travel::TravelViolations>,
}

/// Errors of [`reroute_swinging_rapids`].
#[derive(Debug, thiserror::Error)]
pub enum MachineLinkError {
    /// The post rejected a move (an unreachable orientation).
    #[error("operation {operation}: posting to find swinging rapids: {source}")]
    Post {
        /// The operation.
        operation: String,
        /// The post's error.
        source: postproc_kinematics::PostError,
    },
}

/// Distance (mm) from the safety surface within which a tip counts as on it: the linker puts
/// its exit points on the surface up to rounding (1e-14 mm inside it on impeller-8+8).
pub const ON_SURFACE_MM: f64 = 1e-6;

/// Whether the tip of `cl` lies inside the safety surface of `linker` by more than
/// [`ON_SURFACE_MM`].
fn inside_surface(linker: &Linker, cl: &CutterLocation) -> bool {
    let s = &linker.surface;
    let p = cl.tip;
    s.radius_mm - p.x.hypot(p.y) > ON_SURFACE_MM && s.top_z_mm - p.z > ON_SURFACE_MM
}

/// The moves the post sees for `path` (the approach and retract `retract_mm` along the tool
/// axis that [`gcode_emit::assemble`] adds at the operation's ends, then the path).
fn framed(path: &ToolPath, retract_mm: f64) -> Vec<Move> {
    let lift = |cl: &CutterLocation| CutterLocation {
        tip: cl.tip + cl.axis.into_inner() * retract_mm,
        axis: cl.axis,
    };
    let (Some(first), Some(last)) = (path.moves.first(), path.moves.last()) else {
        return Vec::new();
    };
    let mut moves = Vec::with_capacity(path.moves.len() + 2);
    moves.push(Move::rapid(lift(&first.cl)));
    moves.extend_from_slice(&path.moves);
    moves.push(Move::rapid(lift(&last.cl)));
    moves
}

/// Replaces every rapid of `path` on which `machine` would swing (see the module docs) and
/// that starts or ends inside the safety surface of `linker` by the detour over the surface
/// ([`Linker::connect`], approach `approach_mm` above the next posture); a rapid that already
/// starts on the surface (an approach) becomes a plunge-feed move instead, so the post's
/// posture group — whose branch it chooses at the group's first rapid — begins at the rapid
/// that reaches the surface and the swing happens there (a rotate axis turns the part about
/// Z, which keeps a tool outside the capped cylinder outside it; a swing of the tilting axis
/// there is counted in [`MachineLinks::on_surface`]); `post` are the
/// options of the real post (tool length, initial posture, unwinding), `retract_mm` the
/// approach/retract distance the assembly adds at the operation's ends. A rapid whose ends
/// allow no retract along the tool axis is left and counted in
/// [`MachineLinks::remaining`].
///
/// Errors: the post rejects a move (unreachable orientation).
pub fn reroute_swinging_rapids(
    path: &mut ToolPath,
    machine: &Machine,
    post: &PostOptions,
    retract_mm: f64,
    linker: &Linker,
    approach_mm: f64,
) -> Result<MachineLinks, MachineLinkError> {
    let mut options = post.clone();
    options.linearisation_tol = None;
    options.reverse_motion = None;
    options.limit_policy = LimitPolicy::Report;
    let mut out = MachineLinks::default();
    for pass in 0..MAX_RELINK_PASSES {
        let moves = framed(path, retract_mm);
        if moves.is_empty() {
            return Ok(out);
        }
        let posted =
            post_path(machine, &moves, &options).map_err(|source| MachineLinkError::Post {
                operation: path.name.clone(),
                source,
            })?;
        out.last = posted.blocks.last().map(|b| b.joints);
        // Source index k of the framed moves is path move k − 1; the framing rapids (k = 1:
        // from the lift to the first move is part of the path's own approach; the last lift)
        // are the assembly's, at the operation's ends.
        let inside = |i: usize| {
            path.moves
                .get(i)
                .is_some_and(|m| inside_surface(linker, &m.cl))
        };
        let (flagged, on_surface): (Vec<usize>, Vec<usize>) = swinging_rapids(machine, &posted)
            .into_iter()
            .filter_map(|k| k.checked_sub(1))
            .filter(|&i| i >= 1 && i < path.moves.len())
            .partition(|&i| inside(i - 1) || inside(i));
        if flagged.is_empty() || pass + 1 == MAX_RELINK_PASSES {
            out.remaining = flagged.len();
            out.on_surface = on_surface.len();
            out.travel =
                crate::travel::TravelViolations::of(&path.name, path.moves.len(), &posted.blocks);
            return Ok(out);
        }
        let mut rebuilt: Vec<Move> = Vec::with_capacity(path.moves.len() + 8 * flagged.len());
        let mut next = flagged.iter().copied().peekable();
        for (i, m) in path.moves.iter().enumerate() {
            if next.peek() == Some(&i) {
                next.next();
                let from = path.moves[i - 1].cl;
                if !inside_surface(linker, &from) {
                    // The rapid already starts on the safety surface: the swing belongs to the
                    // posture group of the moves after it (the post chooses a group's branch
                    // at its first rapid). Fed, this approach joins that group, which then
                    // starts with the rapid reaching the surface: the swing happens there.
                    rebuilt.push(Move {
                        kind: MoveKind::Plunge,
                        cl: m.cl,
                        feed_mm_per_min: None,
                    });
                    out.rerouted += 1;
                    continue;
                }
                if let Ok(detour) = linker.connect(&from, &m.cl, approach_mm) {
                    rebuilt.extend(detour);
                    out.rerouted += 1;
                    continue;
                }
            }
            rebuilt.push(*m);
        }
        path.moves = rebuilt;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use cam_core::{MoveKind, Point3};
    use cam_plan::SafetySurface;

    fn headhead() -> Machine {
        Machine::from_file(format!(
            "{}/testdata/headhead-ac.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    }

    /// Two plunges 2 mm above a Ø406 × 130 blank whose axes lie 5° from the vertical at
    /// C = 170° and C = 190° on the head-head machine, posted with unwinding: the rapid
    /// between them swings C by 340° (the impeller-plunge-400 defect). Rerouted, the path
    /// goes over the safety surface there (a retract to it, the travel on it) and posting it
    /// again finds no swinging rapid inside the surface; the postures of the plunges are
    /// kept.
    #[test]
    fn swinging_rapid_between_plunges_goes_over_the_safety_surface() {
        let m = headhead();
        let at = |c_deg: f64, x: f64| {
            let axis = m
                .tool_axis(5f64.to_radians(), c_deg.to_radians())
                .into_inner();
            CutterLocation::new(Point3::new(x, -100.0, 132.0), axis).unwrap()
        };
        let depth = |cl: CutterLocation| {
            CutterLocation::new(cl.tip - cl.axis.into_inner() * 100.0, cl.axis.into_inner())
                .unwrap()
        };
        let (a, b) = (at(170.0, 0.0), at(190.0, 5.0));
        let mut path = ToolPath::new("plunge", "d30");
        path.moves = vec![
            Move::rapid(a),
            Move::feed(depth(a)),
            Move::feed(a),
            Move::rapid(b),
            Move::feed(depth(b)),
            Move::feed(b),
        ];
        let original = path.clone();
        let surface = SafetySurface {
            radius_mm: 213.0,
            top_z_mm: 140.0,
        };
        let linker = Linker::new(surface);
        let options = PostOptions {
            tool_length: 210.0,
            linearisation_tol: Some(0.005),
            linearise_rapids: true,
            unwind_on_rapid: true,
            // The head stands on the branch of the first plunge (as after the plunges
            // before it).
            initial: Some(m.joints_for_angles(
                &a.tip,
                210.0,
                5f64.to_radians(),
                170f64.to_radians(),
            )),
            ..PostOptions::default()
        };
        let links = reroute_swinging_rapids(&mut path, &m, &options, 10.0, &linker, 2.0).unwrap();
        assert_eq!(links.rerouted, 1);
        assert_eq!(links.remaining, 0);
        // The detour reaches the safety surface between the plunges.
        let on_surface = path.moves[3..path.moves.len() - 2]
            .iter()
            .any(|m| !surface.contains(&m.cl.tip));
        assert!(on_surface);
        assert_eq!(path.moves[3].kind, MoveKind::Retract);
        // Every cutting posture is kept, in order.
        let feeds = |p: &ToolPath| -> Vec<CutterLocation> {
            p.moves
                .iter()
                .filter(|m| m.kind == MoveKind::Feed)
                .map(|m| m.cl)
                .collect()
        };
        assert_eq!(feeds(&path), feeds(&original));
        // Posted again: no swinging rapid inside the safety surface.
        let mut again = path.clone();
        let check = reroute_swinging_rapids(&mut again, &m, &options, 10.0, &linker, 2.0).unwrap();
        assert_eq!(check.rerouted, 0);
        assert_eq!(again.moves.len(), path.moves.len());
        // Without unwinding the rapid is no swing: nothing changes.
        let mut kept = original.clone();
        let options = PostOptions {
            unwind_on_rapid: false,
            ..options
        };
        let links = reroute_swinging_rapids(&mut kept, &m, &options, 10.0, &linker, 2.0).unwrap();
        assert_eq!(links.rerouted, 0);
        assert_eq!(kept.moves.len(), original.moves.len());
    }

    /// A rapid between two postures outside the safety surface on which the table-table
    /// machine changes branch (A limited to [−100°, 50°]: an axis 60° from +Z is reached
    /// only at A = −60° with C turned by 180°, from A = 40°): no detour can help (it would
    /// start and end where the rapid does), so it is left and counted on the surface, not
    /// as left inside it.
    #[test]
    fn a_swinging_rapid_outside_the_surface_is_counted_there() {
        let m = Machine::from_file(format!(
            "{}/../../fixtures/machines/xyzac-trt.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let cl = |a_deg: f64, x: f64| {
            let axis = m
                .tool_axis(a_deg.to_radians(), 30f64.to_radians())
                .into_inner();
            CutterLocation::new(Point3::new(x, 0.0, 40.0), axis).unwrap()
        };
        let mut path = ToolPath::new("flip", "t");
        path.moves = vec![
            Move::rapid(cl(40.0, 0.0)),
            Move::feed(cl(40.0, 1.0)),
            Move::rapid(cl(60.0, 5.0)),
            Move::feed(cl(60.0, 6.0)),
        ];
        let original = path.clone();
        // A blank far below: every posture is outside the surface.
        let linker = Linker::new(SafetySurface {
            radius_mm: 1.0,
            top_z_mm: 10.0,
        });
        let options = PostOptions {
            linearisation_tol: None,
            ..PostOptions::default()
        };
        let links = reroute_swinging_rapids(&mut path, &m, &options, 10.0, &linker, 2.0).unwrap();
        assert_eq!(
            (links.rerouted, links.remaining, links.on_surface),
            (0, 0, 1)
        );
        assert_eq!(path.moves, original.moves);
    }

    /// An approach from the safety surface (rounding puts the linker's exit points up to
    /// 1e-14 mm inside it) whose rapid swings C by 340°: a detour would repeat the same
    /// approach, so it is fed instead; posted again, the swing is on no rapid inside the
    /// surface.
    #[test]
    fn swinging_approach_from_the_safety_surface_is_fed() {
        let m = headhead();
        let axis = |c_deg: f64| {
            m.tool_axis(5f64.to_radians(), c_deg.to_radians())
                .into_inner()
        };
        let surface = SafetySurface {
            radius_mm: 213.0,
            top_z_mm: 140.0,
        };
        let linker = Linker::new(surface);
        let on = CutterLocation::new(Point3::new(0.0, -100.0, 140.0 - 1e-14), axis(170.0)).unwrap();
        let above = CutterLocation::new(Point3::new(0.0, -100.0, 134.0), axis(190.0)).unwrap();
        let entry = CutterLocation::new(Point3::new(0.0, -100.0, 132.0), axis(190.0)).unwrap();
        let mut path = ToolPath::new("approach", "d30");
        path.moves = vec![
            Move::rapid(on),
            Move::rapid(above),
            Move::feed(entry),
            Move::feed(CutterLocation::new(Point3::new(2.0, -100.0, 100.0), axis(190.0)).unwrap()),
        ];
        let options = PostOptions {
            tool_length: 210.0,
            linearisation_tol: None,
            unwind_on_rapid: true,
            initial: Some(m.joints_for_angles(
                &on.tip,
                210.0,
                5f64.to_radians(),
                170f64.to_radians(),
            )),
            ..PostOptions::default()
        };
        let links = reroute_swinging_rapids(&mut path, &m, &options, 10.0, &linker, 2.0).unwrap();
        assert_eq!((links.rerouted, links.remaining), (1, 0));
        assert_eq!(path.moves.len(), 4);
        assert_eq!(path.moves[1].kind, MoveKind::Plunge);
        assert_eq!(path.moves[1].cl, above);
    }
}
