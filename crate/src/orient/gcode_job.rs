//! Smoothing multi-axis G-code.

use super::core::{self, RunSettings};
use super::kinematics::{Kinematics, Pose};
use super::metrics::Sample;
use super::program::{self, Frame, MotionLine, Run};
use super::schedule;
use super::summary::{self, Counts};
use super::words;
use super::{Coordinates, InputFormat, SmoothOptions, SmoothReport};
use crate::error::{Error, ErrorKind, Warning};
use crate::gcode::{self, Edit};
use crate::path::{self, PathMove};
use crate::progress::Progress;
use crate::vec3;

pub(super) fn run(
    input: &[u8],
    options: &SmoothOptions,
    progress: Progress<'_>,
) -> Result<SmoothReport, Error> {
    let frame = Frame {
        kin: &options.kinematics,
        coordinates: options.coordinates,
    };
    summary::tick(progress, 0.0)?;
    let read = path::extract(input, &options.analyze, true)?;
    let moves = &read.moves;
    check_rotary(frame.kin, moves)?;
    let mut warnings = read.warnings.clone();
    summary::tick(progress, 0.3)?;
    let lines = program::motion_lines(input, &options.analyze)?;
    let line_of = program::line_of_moves(moves, &lines);
    let runs = program::runs(&frame, moves, &line_of, options.max_gap_mm);

    let decimals = usize::from(options.decimals);
    let half = vec3::rad(0.5 * options.cone_deg);
    let settings = run_settings(options, half, decimals);
    // The rotary rates are measured on the tool tip's schedule, the same before and after.
    let timed = schedule::tip_timed(input, &frame, moves, &lines, options);
    let before: Vec<Vec<Sample>> = runs
        .iter()
        .map(|r| program::samples(&frame, &timed, r))
        .collect();
    warnings.extend(summary::short_run_warning(&before, true, options));
    let (smoothed, corrected) = smooth_runs(&before, frame.kin, &settings, progress)?;
    warnings.extend(summary::unsmoothed_warning(
        &before,
        &smoothed,
        frame.kin,
        &settings,
        options.max_gap_mm,
    ));

    let writer = Writer {
        input,
        frame,
        decimals,
        half,
    };
    let (edits, after_est) = writer.edits(moves, &line_of, &runs, &before, &smoothed);
    summary::tick(progress, 0.65)?;
    let output = gcode::apply_edits(input, &edits);

    let back = read_back(&output, options, moves, &runs, &before);
    let (after, planned_time_after_s) = back.unwrap_or_else(|| {
        warnings.push(Warning {
            line: 0,
            message: "the output could not be re-read move for move; after-metrics use the input's timing".into(),
        });
        (after_est, read.time_s)
    });
    let done = Done {
        motion_lines: lines.len(),
        corrected,
        changed: edits.len(),
        output,
        planned_time_before_s: read.time_s,
        planned_time_after_s,
    };
    finish(options, &before, &after, warnings, done, progress)
}

/// Refuses a file whose rotary axes never leave zero: a 3-axis toolpath has a constant tool
/// vector, and smoothing it would report a success that did nothing.
fn check_rotary(kin: &Kinematics, moves: &[PathMove]) -> Result<(), Error> {
    if program::has_rotary_motion(kin, moves) {
        return Ok(());
    }
    let [first, second] = kin.model.rotary_letters();
    Err(Error::new(
        0,
        0,
        ErrorKind::NoRotaryMotion { first, second },
    ))
}

/// The smoothing settings for a cone of half-angle `half` (rad) written with `decimals`
/// places.
fn run_settings(options: &SmoothOptions, half: f64, decimals: usize) -> RunSettings {
    // Writing the angles with `decimals` places moves each by at most half a unit of the last
    // place; aiming that much inside the cone keeps the written vector inside it.
    let margin = vec3::rad(libm::pow(10.0, -(decimals as f64)));
    RunSettings {
        filter: options.filter,
        window: options.window,
        half_angle: (half - margin).max(0.0),
        singular_angle: vec3::rad(options.singular_deg.unwrap_or(6.0)),
    }
}

/// Every run smoothed, and how many samples the cone corrected.
fn smooth_runs(
    before: &[Vec<Sample>],
    kin: &Kinematics,
    settings: &RunSettings,
    progress: Progress<'_>,
) -> Result<(Vec<Vec<Sample>>, usize), Error> {
    let mut smoothed = Vec::with_capacity(before.len());
    let mut corrected = 0usize;
    for (i, run) in before.iter().enumerate() {
        if i % 256 == 0 {
            summary::tick(progress, 0.3 + 0.3 * i as f64 / before.len().max(1) as f64)?;
        }
        let out = core::smooth_run(run, kin, settings, true);
        corrected += out.corrected;
        smoothed.push(out.samples);
    }
    Ok((smoothed, corrected))
}

/// Writes smoothed poses into the motion lines of the input.
struct Writer<'a> {
    input: &'a [u8],
    /// Kinematic model and coordinate convention.
    frame: Frame<'a>,
    /// Decimal places of the written words.
    decimals: usize,
    /// Half-angle of the cone the written vector must stay in, rad.
    half: f64,
}

impl Writer<'_> {
    /// The edits that write the `smoothed` samples of `runs` (sampled `before`), and the
    /// samples as written (what the output will read back as).
    fn edits(
        &self,
        moves: &[PathMove],
        line_of: &[Option<&MotionLine>],
        runs: &[Run],
        before: &[Vec<Sample>],
        smoothed: &[Vec<Sample>],
    ) -> (Vec<Edit>, Vec<Vec<Sample>>) {
        let kin = self.frame.kin;
        // Where each move's new pose is: (run, sample index).
        let mut slot: Vec<Option<(usize, usize)>> = vec![None; moves.len()];
        for (r, run) in runs.iter().enumerate() {
            for (k, &mi) in run.iter().enumerate() {
                if let Some(s) = slot.get_mut(mi) {
                    *s = Some((r, k + 1));
                }
            }
        }
        let mut edits: Vec<Edit> = Vec::new();
        let mut after_est: Vec<Vec<Sample>> = before.to_vec();
        // Axes whose modal value in the output differs from the input's (X, Y, Z, rotary ×2):
        // a later line that leaves such a word out would inherit the wrong value, so it gets
        // all its words written out.
        let mut dirty = [false; 5];
        for (mi, m) in moves.iter().enumerate() {
            let Some(line) = line_of.get(mi).copied().flatten() else {
                continue;
            };
            let offsets = line.offsets;
            let omits = program::omitted(line, kin);
            let force = omits.iter().zip(&dirty).any(|(o, d)| *o && *d);
            let slot_here = slot.get(mi).copied().flatten();
            let pose = match slot_here
                .and_then(|(r, k)| Some((r, k, before.get(r)?.get(k)?, smoothed.get(r)?.get(k)?)))
            {
                Some((r, k, orig, new)) => {
                    let (pose, sample) = self.written_pose(orig, new, &offsets);
                    if let Some(s) = after_est.get_mut(r).and_then(|x| x.get_mut(k)) {
                        *s = sample;
                    }
                    pose
                }
                None if force => program::pose(kin, &m.to),
                None => {
                    for (d, o) in dirty.iter_mut().zip(&omits) {
                        *d &= *o;
                    }
                    continue;
                }
            };
            let fmt = program::WordFormat {
                kin,
                offsets: &offsets,
                decimals: self.decimals,
                rewrite_xyz: self.frame.coordinates == Coordinates::Machine,
            };
            match program::edit_for(self.input, line, &fmt, &m.to, &pose, force) {
                Some(e) => {
                    edits.push(e);
                    dirty = program::differs(&fmt, &m.to, &pose);
                }
                None => {
                    for (d, o) in dirty.iter_mut().zip(&omits) {
                        *d &= *o;
                    }
                }
            }
        }
        (edits, after_est)
    }

    /// The pose written for the smoothed sample `new` of the original `orig` (rounded as
    /// written; the original orientation where rounding would leave the cone), and the sample
    /// it gives.
    fn written_pose(
        &self,
        orig: &Sample,
        new: &Sample,
        offsets: &program::Offsets,
    ) -> (Pose, Sample) {
        let kin = self.frame.kin;
        let [r0, r1] = kin.model.rotary_axes();
        let xyz_axes = [
            crate::machine::axis::X,
            crate::machine::axis::Y,
            crate::machine::axis::Z,
        ];
        let q =
            |v: f64, ax: usize| words::rounded(v + offsets.of(ax), self.decimals) - offsets.of(ax);
        let mut rot = [q(new.rot[0], r0), q(new.rot[1], r1)];
        let mut v = kin.tool_vector(rot);
        if vec3::angle(v, orig.v) > self.half {
            // Rounding pushed it out after all: keep the original orientation here.
            rot = orig.rot;
            v = orig.v;
        }
        let xyz = self.frame.xyz_for(orig.p, rot);
        let xyz = [0, 1, 2].map(|k| {
            q(
                xyz.get(k).copied().unwrap_or(0.0),
                xyz_axes.get(k).copied().unwrap_or(0),
            )
        });
        let pose = Pose { xyz, rot };
        let sample = Sample {
            p: self.frame.tip(&pose),
            v,
            rot,
            dt: orig.dt,
            profile: orig.profile,
        };
        (pose, sample)
    }
}

/// Reads the output back: the "after" samples measured on what was written, and its planned
/// time. The rotary rates use the input's schedule for both (see
/// `SmoothReport::planned_time_after_s`). `None` if it does not read back move for move.
fn read_back(
    output: &[u8],
    options: &SmoothOptions,
    moves: &[PathMove],
    runs: &[Run],
    before: &[Vec<Sample>],
) -> Option<(Vec<Vec<Sample>>, f64)> {
    let frame = Frame {
        kin: &options.kinematics,
        coordinates: options.coordinates,
    };
    let back = path::extract(output, &options.analyze, true).ok()?;
    if back.moves.len() != moves.len()
        || !back.moves.iter().zip(moves).all(|(a, b)| a.line == b.line)
    {
        return None;
    }
    let after = runs
        .iter()
        .zip(before)
        .map(|(r, b)| {
            let mut s = program::samples(&frame, &back.moves, r);
            for (x, y) in s.iter_mut().zip(b) {
                x.dt = y.dt;
                x.profile = y.profile;
            }
            s
        })
        .collect();
    Some((after, back.time_s))
}

/// What the smoothing did, for the report.
struct Done {
    motion_lines: usize,
    corrected: usize,
    changed: usize,
    output: Vec<u8>,
    planned_time_before_s: f64,
    planned_time_after_s: f64,
}

/// The report from the samples before and after.
fn finish(
    options: &SmoothOptions,
    before: &[Vec<Sample>],
    after: &[Vec<Sample>],
    warnings: Vec<Warning>,
    done: Done,
    progress: Progress<'_>,
) -> Result<SmoothReport, Error> {
    summary::tick(progress, 0.95)?;
    let mut report = summary::assemble(
        options,
        Counts {
            format: InputFormat::Gcode,
            motion_lines: done.motion_lines,
            corrected: done.corrected,
            changed: done.changed,
            skip_first: true,
        },
        before,
        after,
        warnings,
        done.output,
    );
    report.planned_time_before_s = done.planned_time_before_s;
    report.planned_time_after_s = done.planned_time_after_s;
    summary::tick(progress, 1.0)?;
    Ok(report)
}
