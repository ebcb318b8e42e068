//! The commanded trajectory of the X and Y axes, sampled at the interpolation period `T_s`.
//!
//! Each planned move is a path (a line, or an arc) travelled with the planner's trapezoid
//! profile; the commanded position of an axis at time `t` is the point of the path at the
//! distance the profile has covered, its commanded velocity the path speed times the axis's
//! share of the path direction. Dwells and heater waits between moves are rests.
//!
//! The path extraction keeps one timing per source move; an arc is planned as many short
//! segments, and its stored timing is the last segment's. An arc's start is therefore taken
//! from the end of the move before it, and the arc is travelled with a trapezoid from that
//! move's exit speed to the last segment's exit speed at the requested feed rate (within the
//! X/Y speed limits).

use crate::machine::{axis, MoveKind};
use crate::path::{PathMove, PrintPath};
use crate::plan::Profile;

/// Where the path goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Geometry {
    /// No X/Y motion (Z-only, extruder-only moves).
    Still,
    /// A straight line: start and X/Y change per mm of path.
    Line { dir: [f64; 2] },
    /// An arc in the X-Y plane.
    Arc {
        center: [f64; 2],
        radius: f64,
        start_angle: f64,
        /// Sweep per mm of path, rad/mm.
        rate: f64,
    },
}

/// One timed piece of the trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start time, s.
    pub start_s: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Speed profile along the path.
    pub profile: Profile,
    /// Start X, Y, mm.
    pub from: [f64; 2],
    /// End X, Y, mm.
    pub to: [f64; 2],
    pub(super) geometry: Geometry,
    /// Layer index (or `path::NO_LAYER`).
    pub layer: u32,
    /// Whether the move lays down material.
    pub extruding: bool,
    /// Where it falls on the simulation's clock ([`Clock`]): set as the run takes it.
    pub(super) clock: Clock,
}

/// A segment's place on a run's clock: the step its stretch of motion set off on from rest,
/// and its start after that, s. The command at a step is evaluated from these, not from the
/// absolute time: the same moves after a rest are then sampled at the same instants, to the
/// bit, wherever in the print they fall (see `Stream::on_grid`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Clock {
    /// The step the stretch starts on.
    pub(super) from_step: u64,
    /// The segment's start after it, s.
    pub(super) after_s: f64,
}

impl Clock {
    /// Time into the segment at step `k` of period `ts`, s (negative before it starts).
    #[inline]
    pub(super) fn tau(&self, k: u64, ts: f64) -> f64 {
        // Signed: one instruction to convert where an unsigned count takes a branch (steps
        // stay far below 2⁶³, [`super::simulate::budget`]).
        let steps = (k as i64).wrapping_sub(self.from_step as i64);
        steps as f64 * ts - self.after_s
    }
}

/// Commanded state of X and Y at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Command {
    /// Position, mm.
    pub pos: [f64; 2],
    /// Velocity, mm/s.
    pub vel: [f64; 2],
}

impl Segment {
    /// Distance and speed along the path `tau` seconds into the segment.
    #[inline]
    fn along(&self, tau: f64) -> (f64, f64) {
        self.profile.at_time(tau)
    }

    /// The commanded state `tau` seconds into the segment.
    #[inline]
    pub fn command(&self, tau: f64) -> Command {
        let (s, v) = self.along(tau);
        match self.geometry {
            Geometry::Still => Command {
                pos: self.from,
                vel: [0.0; 2],
            },
            Geometry::Line { dir } => Command {
                pos: [self.from[0] + dir[0] * s, self.from[1] + dir[1] * s],
                vel: [dir[0] * v, dir[1] * v],
            },
            Geometry::Arc {
                center,
                radius,
                start_angle,
                rate,
            } => {
                let ang = start_angle + rate * s;
                let (sin, cos) = (crate::math::sin(ang), crate::math::cos(ang));
                Command {
                    pos: [center[0] + radius * cos, center[1] + radius * sin],
                    vel: [-radius * rate * sin * v, radius * rate * cos * v],
                }
            }
        }
    }

    /// End time, s.
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }
}

pub(super) fn geometry(m: &PathMove) -> Geometry {
    let dx = m.to[axis::X] - m.from[axis::X];
    let dy = m.to[axis::Y] - m.from[axis::Y];
    let len = m.length_mm;
    let usable = len.is_finite() && len > 1e-9;
    if !usable || (dx.abs() < 1e-12 && dy.abs() < 1e-12 && !matches!(m.kind, MoveKind::Arc(_))) {
        return Geometry::Still;
    }
    match m.kind {
        MoveKind::Arc(arc) if arc.plane == crate::machine::Plane::Xy => Geometry::Arc {
            center: arc.center,
            radius: arc.radius,
            start_angle: arc.start_angle,
            rate: arc.sweep / len,
        },
        _ => Geometry::Line {
            dir: [dx / len, dy / len],
        },
    }
}

/// The timed trajectory of a planned path, or `None` if the path has no planner timing.
pub fn segments(path: &PrintPath) -> Option<Vec<Segment>> {
    super::timeline::from_path(path, |_| true, path.moves.len())
}

/// The segments of [`segments`] on the layers `keep` accepts (by layer index), on the whole
/// path's timeline: the trajectory of a sample of the layers without building the rest (a 34 MB
/// file's whole trajectory takes 190 MB).
pub fn segments_where(path: &PrintPath, keep: impl Fn(u32) -> bool) -> Option<Vec<Segment>> {
    super::timeline::from_path(path, keep, 0)
}

/// The trajectory of `input` read and planned as [`crate::path::extract`] would, on the layers
/// `keep` accepts, built as the planner times each move: the file's moves are never all held
/// (a 34 MB file's take 370 MB beside its 190 MB trajectory). `None` in the first place where
/// a move has no timing; the second is what the walk learnt of the file (its layers and
/// machine).
pub fn segments_of_file(
    input: &[u8],
    options: &crate::analyze::AnalyzeOptions,
    keep: impl Fn(u32) -> bool,
) -> Result<(Option<Vec<Segment>>, crate::path::Walked), crate::error::Error> {
    super::timeline::kept_of_file(input, options, keep, 0)
}

/// Lowest and highest X and Y of a trajectory's segments, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Lowest X, Y.
    pub lo: [f64; 2],
    /// Highest X, Y.
    pub hi: [f64; 2],
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds {
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
        }
    }
}

impl Bounds {
    /// The bounds of `segs`.
    pub fn of(segs: &[Segment]) -> Self {
        let mut b = Bounds::default();
        segs.iter().for_each(|s| b.add(s));
        b
    }

    /// Widened to hold `s`'s ends.
    pub fn add(&mut self, s: &Segment) {
        for p in [s.from, s.to] {
            for (ax, &v) in p.iter().enumerate() {
                self.lo[ax] = self.lo[ax].min(v);
                self.hi[ax] = self.hi[ax].max(v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_follows_its_trapezoid() {
        let g = b"G21\nG90\nM83\nG1 X0 Y0 F6000\nG1 X30 Y40 E1 F3000\n";
        let path = crate::path::extract(g, &Default::default(), true).unwrap();
        let segs = segments(&path).unwrap();
        let last = segs.last().unwrap();
        let end = last.command(last.duration_s);
        assert!((end.pos[0] - 30.0).abs() < 1e-9 && (end.pos[1] - 40.0).abs() < 1e-9);
        let mid = last.command(0.5 * last.duration_s);
        // Direction 3:4, speed at most the 50 mm/s feed.
        assert!((mid.vel[0] * 4.0 - mid.vel[1] * 3.0).abs() < 1e-9);
        assert!(mid.vel[0].hypot(mid.vel[1]) <= 50.0 + 1e-9);
    }

    #[test]
    fn a_sample_of_layers_keeps_the_whole_timeline() {
        // The second layer starts with an arc, whose entry speed is the move before's exit.
        let g = b"G21\nG90\nM83\n;LAYER_CHANGE\n;Z:0.2\nG1 Z0.2 F600\nG1 X10 Y0 E1 F3000\n\
;LAYER_CHANGE\n;Z:0.4\nG3 X0 Y10 I-10 J0 E1 F1200\nG1 X0 Y20 E1\n";
        let path = crate::path::extract(g, &Default::default(), true).unwrap();
        let whole = segments(&path).unwrap();
        let second: Vec<Segment> = whole.iter().copied().filter(|s| s.layer == 1).collect();
        assert_eq!(second.len(), 2);
        assert!(second[0].profile.entry > 0.0, "{:?}", second[0].profile);
        assert_eq!(segments_where(&path, |layer| layer == 1).unwrap(), second);
    }

    #[test]
    fn a_klipper_homing_move_runs_from_rest_to_rest() {
        // Klipper's planner leaves `G28` untimed; the simulation runs it after the last move,
        // from rest to rest at the modal feed (50 mm/s) and the travel acceleration that
        // SET_VELOCITY_LIMIT set (2000 mm/s²): 40 mm in 40/50 + 50/2000 s.
        let g = b"SET_VELOCITY_LIMIT ACCEL=2000\nG21\nG90\nM83\nG1 Z0.2 F600\n\
G1 X10 Y0 F6000\nG1 X40 Y40 E1 F3000\nG28 X0\n";
        let options = Default::default();
        let path = crate::path::extract(g, &options, true).unwrap();
        let home = path.moves.last().unwrap();
        assert!(matches!(home.kind, crate::machine::MoveKind::Home));
        assert!(home.timing.is_none());
        let whole = segments(&path).unwrap();
        let (streamed, _) = segments_of_file(g, &options, |_| true).unwrap();
        assert_eq!(streamed.as_ref(), Some(&whole));
        let (before, last) = (&whole[whole.len() - 2], &whole[whole.len() - 1]);
        assert_eq!((last.from, last.to), ([40.0, 40.0], [0.0, 40.0]));
        assert!((last.start_s - before.end_s()).abs() < 1e-12);
        let p = last.profile;
        assert_eq!(
            (p.entry, p.peak, p.exit, p.acceleration),
            (0.0, 50.0, 0.0, 2000.0)
        );
        assert!((last.duration_s - (0.8 + 0.025)).abs() < 1e-12, "{last:?}");
        assert!(!last.extruding);
    }

    #[test]
    fn an_arc_ends_at_its_end_point() {
        let g = b"G21\nG90\nM83\nG1 X10 Y0 F6000\nG3 X0 Y10 I-10 J0 E1 F1200\n";
        let path = crate::path::extract(g, &Default::default(), true).unwrap();
        let segs = segments(&path).unwrap();
        let arc = segs.last().unwrap();
        let end = arc.command(arc.duration_s);
        assert!(
            end.pos[0].abs() < 1e-9 && (end.pos[1] - 10.0).abs() < 1e-9,
            "{end:?}"
        );
        let mid = arc.command(0.5 * arc.duration_s);
        assert!((mid.pos[0].hypot(mid.pos[1]) - 10.0).abs() < 1e-9);
    }

    #[test]
    fn an_arc_before_the_first_extrusion_waits_for_the_printing_limits() {
        // A travel arc whose feed the printing limits cap (M203 X40 before the first extrusion,
        // raised after it), layers by counting (no markers), one move never timed apart.
        let g = b"G21\nG90\nM83\nM203 X400 Y400\nG1 X10 Y0 F6000\nG3 X0 Y10 I-10 J0 F6000\n\
M203 X40 Y300\nG1 Z0.2 F600\nG1 X10 Y10 E1 F3000\nM203 X400\nG2 X20 Y0 I10 J0 E1 F6000\n\
G1 Z0.4\nG1 X0 Y0 E1\nG4 P200\nG1 X5 Y5 E1\n";
        let options = Default::default();
        let path = crate::path::extract(g, &options, true).unwrap();
        assert_eq!(path.print_limits.max_feedrate[axis::X].value, 40.0);
        let whole = segments(&path).unwrap();
        let (streamed, walked) = segments_of_file(g, &options, |_| true).unwrap();
        assert_eq!(streamed.as_ref(), Some(&whole));
        assert_eq!(walked.moves, path.moves.len());
        // The first arc's 100 mm/s feed is capped by the printing limit (40 mm/s, below the
        // planner's own peak on its firmware segments), not by the 400 mm/s in force there.
        assert!(whole[1].profile.peak < 50.0, "{:?}", whole[1].profile);
        let second = |layer: u32| layer == 1;
        let sample = segments_where(&path, second).unwrap();
        assert!(!sample.is_empty() && sample.iter().all(|s| s.layer == 1));
        assert_eq!(
            segments_of_file(g, &options, second).unwrap().0,
            Some(sample)
        );
    }
}
