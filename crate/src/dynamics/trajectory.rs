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
enum Geometry {
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
    geometry: Geometry,
    /// Layer index (or `path::NO_LAYER`).
    pub layer: u32,
    /// Whether the move lays down material.
    pub extruding: bool,
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
    fn along(&self, tau: f64) -> (f64, f64) {
        self.profile.at_time(tau)
    }

    /// The commanded state `tau` seconds into the segment.
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

fn geometry(m: &PathMove) -> Geometry {
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
    timeline(path, |_| true, path.moves.len())
}

/// The segments of [`segments`] whose moves `keep` accepts, on the whole path's timeline: the
/// trajectory of a sample of the layers without building the rest (a 34 MB file's whole
/// trajectory takes 190 MB).
pub fn segments_where(path: &PrintPath, keep: impl Fn(&PathMove) -> bool) -> Option<Vec<Segment>> {
    timeline(path, keep, 0)
}

/// [`segments_where`], its list made with room for `capacity` segments.
fn timeline(
    path: &PrintPath,
    keep: impl Fn(&PathMove) -> bool,
    capacity: usize,
) -> Option<Vec<Segment>> {
    let mut out: Vec<Segment> = Vec::with_capacity(capacity);
    // The last segment on the timeline, kept or not: an arc starts at its exit speed.
    let mut last: Option<Segment> = None;
    let mut cursor = 0.0f64; // end of the last segment on our timeline
    let mut planned_end = 0.0f64; // end of the last move on the planner's timeline
    for m in &path.moves {
        let t = m.timing?;
        let duration = t.duration_s;
        if !duration.is_finite() || !t.start_s.is_finite() {
            continue;
        }
        let (start, profile) = if matches!(m.kind, MoveKind::Arc(_)) {
            // The planner times an arc as straight firmware segments; the simulation follows the
            // true arc with one trapezoid, starting where the previous move ended.
            let entry = last
                .as_ref()
                .filter(|s| (s.end_s() - cursor).abs() < 1e-12)
                .map_or(0.0, |s| s.profile.exit);
            let a = t.profile.acceleration;
            // The requested feed within the machine's X/Y speed limits (an arc's direction
            // turns, so the lower of the two bounds it).
            let limits = &path.print_limits.max_feedrate;
            let axis_max = limits[axis::X].value.min(limits[axis::Y].value);
            let feed = if axis_max > 0.0 {
                m.feed_mm_s.min(axis_max)
            } else {
                m.feed_mm_s
            };
            let cruise = feed.max(t.profile.peak);
            (
                cursor,
                Profile::new(m.length_mm, entry, cruise, t.profile.exit, a),
            )
        } else {
            let gap = (t.start_s - planned_end).max(0.0);
            (cursor + gap, t.profile)
        };
        planned_end = planned_end.max(t.start_s + duration);
        let duration = profile.duration();
        if !(duration.is_finite() && duration > 0.0) {
            continue;
        }
        let seg = Segment {
            start_s: start,
            duration_s: duration,
            profile,
            from: [m.from[axis::X], m.from[axis::Y]],
            to: [m.to[axis::X], m.to[axis::Y]],
            geometry: geometry(m),
            layer: m.layer,
            extruding: m.is_extruding(),
        };
        cursor = seg.end_s();
        if keep(m) {
            out.push(seg);
        }
        last = Some(seg);
    }
    Some(out)
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
        assert_eq!(segments_where(&path, |m| m.layer == 1).unwrap(), second);
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
}
