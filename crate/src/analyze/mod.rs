//! `analyze`: one streaming pass over a file giving time (from the motion planner), distances,
//! filament, layers, features, temperatures, fans and energy (from [`crate::energy`]).

mod accounting;
pub mod apart;
pub mod layered;
mod pipeline;
pub mod report;
pub mod toolpath;
mod wire;

use crate::error::{Error, ErrorKind};
use crate::gcode::{Line, RawLine, SlicerInfo};
use crate::machine::{axis, Event, Machine};
use crate::plan::segments::{SegmentCounter, SegmentCounts};
use crate::plan::Limits;
use crate::progress::Progress;
pub use crate::read::{prescan, AnalyzeOptions, ExtrusionModeOption};
use crate::read::{At, Flow, Fold, Reader, Setup};
pub use accounting::MoveStarts;
pub use accounting::TimedMove;
use accounting::{Accounts, TimeBook, TimeMsg};
pub use report::*;
use toolpath::ToolpathMetrics;

/// Default filament diameter when the file does not declare one, mm.
pub const DEFAULT_FILAMENT_DIAMETER_MM: f64 = 1.75;
/// Default filament density (PLA), g/cm³.
pub const DEFAULT_DENSITY_G_CM3: f64 = 1.24;

/// Bytes between two progress callbacks.
const PROGRESS_STEP: usize = 1 << 20;

/// Analyzes a G-code file.
pub fn analyze(input: &[u8], options: &AnalyzeOptions) -> Result<Report, Error> {
    analyze_with_progress(input, options, &mut |_| true)
}

/// The read side of `analyze`: counts what each line says and sends what needs timing on.
struct Tally<'a> {
    acc: &'a mut Accounts,
    info: &'a mut SlicerInfo,
    to_timing: &'a mut dyn FnMut(TimeMsg),
    progress: Progress<'a>,
    input_len: usize,
    next_progress: usize,
    /// The moves counted against the segment budget, when asked ([`Keep::min_segment_s`]).
    segments: Option<SegmentCounter>,
}

impl<'a> Tally<'a> {
    /// A tally of a file of `input_len` bytes that hands the timing side its messages.
    fn new(
        acc: &'a mut Accounts,
        info: &'a mut SlicerInfo,
        to_timing: &'a mut dyn FnMut(TimeMsg),
        progress: Progress<'a>,
        input_len: usize,
    ) -> Self {
        Tally {
            acc,
            info,
            to_timing,
            progress,
            input_len,
            next_progress: PROGRESS_STEP,
            segments: None,
        }
    }
}

impl Fold for Tally<'_> {
    fn line(&mut self, raw: &RawLine<'_>, _: Option<&Line<'_>>) -> Result<Flow, Error> {
        self.acc.totals.lines += 1;
        if raw.offset >= self.next_progress {
            self.next_progress = raw.offset + PROGRESS_STEP;
            if !(self.progress)(raw.offset as f64 / self.input_len as f64) {
                return Err(Error::new(raw.number, 0, ErrorKind::Cancelled));
            }
        }
        Ok(Flow::Read)
    }

    fn feature(&mut self, name: &str, _: &Machine) {
        self.acc.feature(name);
    }

    fn comment(&mut self, comment: &[u8]) {
        self.info.observe(comment);
        self.acc.comment(comment);
    }

    fn limits(&mut self, limits: &Limits, _: &Machine) {
        (self.to_timing)(TimeMsg::Limits(Box::new(limits.clone())));
    }

    fn event(&mut self, _: &Line<'_>, event: &Event, at: At<'_>) -> Result<(), Error> {
        let to_timing = &mut self.to_timing;
        if let (Event::Move(m), Some(segments)) = (event, &mut self.segments) {
            segments.moved(m.is_extruding(), m.length_mm);
        }
        match event {
            Event::Move(m) if at.untimed_homing(m) => {
                self.acc.totals.homing_count += 1;
                to_timing(TimeMsg::Flush);
            }
            Event::Move(m) => to_timing(self.acc.read_move(m, at.layers)),
            &Event::Dwell(secs) => to_timing(self.acc.dwell(secs, at.layers)),
            &Event::Temperature {
                heater,
                target_c,
                wait,
            } => {
                to_timing(self.acc.temperature(at.line, heater, target_c, wait));
                if wait {
                    // The firmware finishes every queued move before it waits.
                    to_timing(TimeMsg::Flush);
                }
            }
            &Event::Fan { index, speed } => to_timing(self.acc.fan(at.line, index, speed)),
        }
        Ok(())
    }
}

/// [`analyze`] with progress reports and cancellation.
pub fn analyze_with_progress(
    input: &[u8],
    options: &AnalyzeOptions,
    progress: Progress<'_>,
) -> Result<Report, Error> {
    analyze_timed(input, options, progress, Keep::default()).map(|(report, _)| report)
}

/// [`analyze`], and the line and planned start of every timed move: the clock its time
/// estimates are written from ([`crate::estimate`]), from the same planning pass.
pub fn analyze_with_starts(
    input: &[u8],
    options: &AnalyzeOptions,
) -> Result<(Report, MoveStarts), Error> {
    let keep = Keep {
        starts: true,
        min_segment_s: None,
        layer_metrics_deg: None,
        timed_moves: false,
    };
    let (report, kept) = analyze_keeping(input, options, keep)?;
    Ok((report, kept.starts.unwrap_or_default()))
}

/// What [`analyze_keeping`] keeps of its pass besides the report: what a rewrite's later steps
/// would otherwise plan the file again for.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Keep {
    /// Every timed move's line and start ([`MoveStarts`]).
    pub starts: bool,
    /// The segments counted against this minimum segment time, s ([`SegmentCounts`]).
    pub min_segment_s: Option<f64>,
    /// The file's and its layers' trajectory metrics at this critical angle, degrees
    /// ([`layered::LayeredMetrics`]).
    pub layer_metrics_deg: Option<f64>,
    /// Every timed move ([`TimedMove`]).
    pub timed_moves: bool,
}

/// What [`analyze_keeping`] kept.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Kept {
    /// Every timed move's line and start, where [`Keep::starts`] asked.
    pub starts: Option<MoveStarts>,
    /// The segment counts, where [`Keep::min_segment_s`] asked.
    pub segments: Option<SegmentCounts>,
    /// The file's metrics and its layers', where [`Keep::layer_metrics_deg`] asked.
    pub layer_metrics: Option<(ToolpathMetrics, Vec<ToolpathMetrics>)>,
    /// Every timed move, where [`Keep::timed_moves`] asked.
    pub timed_moves: Option<Vec<TimedMove>>,
}

/// [`analyze`], keeping what `keep` asks of the same pass.
pub fn analyze_keeping(
    input: &[u8],
    options: &AnalyzeOptions,
    keep: Keep,
) -> Result<(Report, Kept), Error> {
    analyze_timed(input, options, &mut |_| true, keep)
}

/// [`analyze_with_progress`], keeping what `keep` asks.
fn analyze_timed(
    input: &[u8],
    options: &AnalyzeOptions,
    progress: Progress<'_>,
    keep: Keep,
) -> Result<(Report, Kept), Error> {
    let mut reader = Reader::new(input, options)?;
    let mut timing = wire::TimingSetup::of(&reader, options).timing();
    if keep.starts {
        timing = timing.keeping_starts(crate::gcode::command_lines(input));
    }
    if let Some(min_segment_s) = keep.min_segment_s {
        timing = timing.counting_segments(min_segment_s);
    }
    if let Some(deg) = keep.layer_metrics_deg {
        timing = timing.keeping_layer_metrics(deg);
    }
    if keep.timed_moves {
        timing = timing.keeping_timed_moves(crate::gcode::command_lines(input));
    }
    let mut info = SlicerInfo::default();
    let mut acc = Accounts::new();
    let mut moves = None;
    pipeline::run(input.len(), &mut timing, |to_timing| {
        let mut tally = Tally::new(&mut acc, &mut info, to_timing, &mut *progress, input.len());
        tally.segments = keep.min_segment_s.map(SegmentCounter::new);
        let read = reader.read(input, &mut tally);
        moves = tally.segments.take();
        read
    })?;
    timing.finish();
    progress(1.0);
    let time_s = timing.planner.elapsed_s();
    let layered = timing.book.layered.take();
    let mut kept = Kept {
        starts: timing.book.starts.take().map(|(starts, _)| starts),
        segments: (moves.as_ref().zip(timing.book.segments.as_ref()))
            .map(|(moves, blocks)| SegmentCounter::merged(moves, blocks)),
        layer_metrics: None,
        timed_moves: timing.book.timed.take().map(|(timed, _)| timed),
    };
    let report = report(input, options, reader, acc, (time_s, timing.book), info);
    kept.layer_metrics = layered.map(|l| l.finish(&report.layer_source, report.layers as usize));
    Ok((report, kept))
}

/// The report of a file read into `reader` and `acc`, from the timing side's planned time and
/// book.
fn report(
    input: &[u8],
    options: &AnalyzeOptions,
    mut reader: Reader,
    mut acc: Accounts,
    (time_s, mut book): (f64, TimeBook),
    info: SlicerInfo,
) -> Report {
    acc.merge(&mut book, &mut reader.layers);
    let Accounts {
        totals,
        mut features,
        travel,
        toolpath,
        ..
    } = acc;
    let TimeBook {
        energy: energy_acc,
        temperatures,
        fans,
        ..
    } = book;
    let limits = reader.limits_in_force().clone();
    let Reader {
        setup,
        machine,
        layers,
        ..
    } = reader;
    let (mut layer_list, layer_source) = layers.finish();
    let filament_mm = machine.position()[axis::E];
    let (extrusion, volume, material_g) = extrusion(options, &info, &setup, filament_mm);
    if travel.moves > 0 {
        features.push(travel);
    }
    let energy = energy_acc.finish(time_s, material_g, &temperatures, &fans);
    share_aux_energy(energy.aux_j, time_s, &mut features, &mut layer_list);
    let (warnings, warnings_dropped) = setup.warnings.into_parts();
    Report {
        version: crate::VERSION.to_string(),
        file: FileInfo {
            bytes: input.len() as u64,
            lines: totals.lines,
            slicer: info.slicer,
            flavor: info.flavor.or(setup.pre.flavor),
            slicer_time_s: setup.pre.slicer_time_s,
        },
        time_s,
        dwell_s: totals.dwell_s,
        homing_count: totals.homing_count,
        time_model: "planner".into(),
        machine: MachineInfo {
            profile: setup.profile.name,
            junction_model: setup.model,
            reason: setup.model_reason,
            limits,
        },
        moves: totals.moves,
        extruding_moves: totals.extruding_moves,
        layers: layer_list.len() as u64,
        layer_source,
        distance_mm: totals.distance_mm,
        extrude_distance_mm: totals.extrude_distance_mm,
        travel_distance_mm: totals.travel_distance_mm,
        filament_mm,
        filament_volume_mm3: volume,
        material_g,
        retractions: totals.retractions,
        extrusion,
        bounds: totals.bounds,
        features,
        layer_list,
        temperatures,
        fans,
        energy,
        toolpath: toolpath.finish(),
        warnings,
        warnings_dropped,
    }
}

/// The extrusion settings used (the file's mode, and the filament's diameter and density from
/// the options, else the file, else the defaults), and the volume (mm³) and mass (g) of
/// `filament_mm` of that filament.
fn extrusion(
    options: &AnalyzeOptions,
    info: &SlicerInfo,
    setup: &Setup,
    filament_mm: f64,
) -> (ExtrusionInfo, f64, f64) {
    let diameter = options
        .filament_diameter_mm
        .or(info.filament_diameter_mm)
        .unwrap_or(DEFAULT_FILAMENT_DIAMETER_MM);
    let density = options
        .density_g_cm3
        .or(info.filament_density_g_cm3)
        .unwrap_or(DEFAULT_DENSITY_G_CM3);
    let volume = filament_mm * std::f64::consts::PI * diameter * diameter / 4.0;
    let info = ExtrusionInfo {
        mode: setup.mode,
        source: setup.source,
        filament_diameter_mm: diameter,
        density_g_cm3: density,
    };
    (info, volume, volume * density / 1000.0)
}

/// Shares auxiliary energy out to features and layers by time (see [`crate::energy`]). Shares
/// are taken as fractions of the total first, so a vanishing total time cannot turn into an
/// infinite rate.
fn share_aux_energy(
    aux_j: f64,
    time_s: f64,
    features: &mut [FeatureSummary],
    layers: &mut [LayerSummary],
) {
    if time_s > 0.0 {
        let share = |t: f64| aux_j * (t / time_s).clamp(0.0, 1.0);
        for f in features {
            f.energy_j += share(f.time_s);
        }
        for l in layers {
            l.energy_j += share(l.time_s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn klipper_homing_is_counted_not_timed_and_marlin_times_it_as_a_move() {
        let json = |r: &Report| serde_json::to_string(r).expect("json");
        // SET_VELOCITY_LIMIT: the file drives Klipper.
        let klipper = b"SET_VELOCITY_LIMIT ACCEL=3000\nG1 X50 F6000\nG28\nG1 X10\n";
        let r = analyze(klipper, &AnalyzeOptions::default()).expect("analysis");
        assert_eq!((r.homing_count, r.moves), (1, 2));
        assert!(json(&r).contains("\"homing_count\":1"));
        let marlin = b"G1 X50 F6000\nG28\nG1 X10\n";
        let m = analyze(marlin, &AnalyzeOptions::default()).expect("analysis");
        assert_eq!((m.homing_count, m.moves), (0, 3));
        assert!(!json(&m).contains("homing_count"), "absent when none");
        // Homing is a stop: the two moves on Klipper each run from rest to rest.
        assert!(r.time_s < m.time_s, "{} {}", r.time_s, m.time_s);
    }
}
