//! Machine dynamics: the lumped-mass model of an axis drive (VTG eq. 1–15), its response
//! to the planned trajectory, trajectory deviation and acceleration spectra.
//!
//! The pipeline of [`vibration`]:
//! 1. read the file's moves with the planner's timing ([`crate::path::extract`]);
//! 2. build each axis's `M`, `C`, `K` ([`lumped`], VTG eq. 1–14) from a physical parameter set
//!    ([`parameters`]), close the position loop, and take its modes ([`modal`]);
//! 3. sample the commanded X and Y motion every `T_s` ([`trajectory`]) and integrate the model
//!    exactly ([`integrate`]: matrix exponential per nut-position bucket, [`axis`]);
//! 4. trajectory deviation `dev = ‖C − C_p‖` (VTG eq. 15) between commanded and simulated table
//!    position, over the print and per layer; the table's acceleration, averaged to the
//!    accelerometer rate `f_s`, and its Welch PSD ([`welch`]) with the top peaks.
//!
//! ```
//! let gcode = b"G21\nG90\nM83\n;LAYER_CHANGE\nG1 Z0.2 F600\nG1 X20 Y0 E1 F3000\nG1 X20 Y20 E1\n";
//! let report = quietpath::dynamics::vibration(gcode, &Default::default()).unwrap();
//! assert!(report.deviation_mm.max > 0.0);
//! assert!(!report.natural_frequencies_hz.is_empty());
//! ```

pub mod axis;
pub mod compare;
pub mod integrate;
pub mod lumped;
pub mod modal;
pub mod modal_step;
pub mod parameters;
mod sampled;
pub mod simulate;
pub mod split;
pub mod steppers;
mod stream;
mod timeline;
pub mod trajectory;
pub mod welch;

use serde::{Deserialize, Serialize};

use crate::analyze::AnalyzeOptions;
use crate::error::{Error, ErrorKind};
use crate::path::PrintPath;
use crate::progress::Progress;
pub use compare::{compare, VibrationComparison};
pub use modal::Mode;
pub use parameters::{Drive, MachineDynamics};
pub use sampled::printing_deviation_in_layers;
pub use welch::{Peak, Window};

/// Options of [`vibration`]. Every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct VibrationOptions {
    /// How the file is read and planned (machine preset, junction model...).
    pub analyze: AnalyzeOptions,
    /// Interpolation period `T_s`, ms (default 1).
    pub ts_ms: f64,
    /// Accelerometer sampling rate `f_s` for the spectrum, Hz (default 200, the VTG paper's);
    /// at most `1000 / ts_ms`. The rate used is `1 / (round(1/(f_s T_s)) T_s)`.
    pub fs_hz: f64,
    /// Welch segment length, samples (default 512, the paper's Hamming window size).
    pub window: usize,
    /// Window function (default Hamming, as in the paper).
    pub window_kind: Window,
    /// Built-in dynamics parameter set (`ldam-ball-screw`, `desktop-belt`); default: the one
    /// that goes with the machine preset ([`parameters::preset_for_machine`]).
    pub dynamics: Option<String>,
    /// A whole parameter set (wins over `dynamics`).
    pub dynamics_parameters: Option<MachineDynamics>,
    /// Travel over which the position-dependent stiffness is held constant, mm (default 5).
    pub bucket_mm: f64,
    /// Spectral peaks reported (default 5).
    pub peaks: usize,
}

impl Default for VibrationOptions {
    fn default() -> Self {
        Self {
            analyze: AnalyzeOptions::default(),
            ts_ms: 1.0,
            fs_hz: 200.0,
            window: 512,
            window_kind: Window::Hamming,
            dynamics: None,
            dynamics_parameters: None,
            bucket_mm: 5.0,
            peaks: 5,
        }
    }
}

/// Trajectory deviation statistics (VTG eq. 15), mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Deviation {
    /// Largest deviation.
    pub max: f64,
    /// Smallest deviation.
    pub min: f64,
    /// Mean deviation.
    pub mean: f64,
    /// Commanded X, Y (mm) and time (s) of the largest deviation.
    pub max_at: [f64; 3],
    /// Samples (one per `T_s` while the machine runs a move).
    pub samples: u64,
}

/// Vibration of one layer (the paper's Fig. 9c).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct LayerVibration {
    /// 0-based layer index.
    pub layer: usize,
    /// Layer height, mm.
    pub z: Option<f64>,
    /// Vibration amplitude: the largest trajectory deviation in the layer, mm.
    pub amplitude: f64,
    /// The largest deviation while extruding in the layer, mm (0 where it prints nothing): the
    /// layer's share of the printing peak, which VTG's no-dearer rule holds.
    pub printing_amplitude: f64,
    /// Mean deviation while extruding in the layer, mm (0 where it prints nothing).
    pub printing_mean: f64,
    /// Samples taken while extruding in the layer (one per `T_s`): the weight of its
    /// `printing_mean` in the file's.
    pub printing_samples: u64,
    /// Mean deviation in the layer, mm.
    pub mean: f64,
    /// RMS of the table's acceleration in the layer, m/s².
    pub acceleration_rms: f64,
}

/// Modes of one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct AxisModes {
    /// `x` or `y`.
    pub axis: &'static str,
    /// Axis position the modes are taken at (the middle of the printed area), mm.
    pub position_mm: f64,
    /// Modes by increasing frequency.
    pub modes: Vec<Mode>,
}

/// Welch PSD of the table's acceleration (X and Y spectra summed), (m/s²)²/Hz.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Psd {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Segment length, samples (the option, or the whole signal when it is shorter).
    pub window: usize,
    /// Window function.
    pub window_kind: Window,
    /// Overlap between segments, samples.
    pub overlap: usize,
    /// Segments averaged.
    pub segments: usize,
    /// Bin frequencies, Hz.
    pub freqs: Vec<f64>,
    /// Power spectral density per bin.
    pub power: Vec<f64>,
    /// Highest local maxima, highest first.
    pub peaks: Vec<Peak>,
}

/// Result of [`vibration`].
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct VibrationReport {
    /// Machine profile the file was planned with.
    pub machine: String,
    /// Dynamics parameter set.
    pub dynamics: String,
    /// Interpolation period, ms.
    pub ts_ms: f64,
    /// Natural frequencies of both axes (mechanism with its position loop), Hz, ascending.
    pub natural_frequencies_hz: Vec<f64>,
    /// Damping ratios of the same modes.
    pub damping_ratios: Vec<f64>,
    /// Modes per axis.
    pub axes: Vec<AxisModes>,
    /// Trajectory deviation over the print (every sample of every move), mm.
    pub deviation_mm: Deviation,
    /// Trajectory deviation while extruding only (what the part sees; travel left out), mm.
    pub printing_deviation_mm: Deviation,
    /// Per-layer vibration.
    pub layers: Vec<LayerVibration>,
    /// Acceleration spectrum.
    pub psd: Psd,
    /// Motion time simulated, s (rests are skipped once the machine is still).
    pub simulated_s: f64,
    /// Simulation steps.
    pub steps: u64,
}

fn invalid(reason: &'static str) -> Error {
    Error::new(0, 0, ErrorKind::InvalidOption { reason })
}

impl VibrationOptions {
    fn validate(&self) -> Result<(), Error> {
        if !(self.ts_ms.is_finite() && self.ts_ms >= 1e-3 && self.ts_ms <= 1000.0) {
            return Err(invalid("ts_ms must be between 0.001 and 1000"));
        }
        if !(self.fs_hz.is_finite() && self.fs_hz > 0.0) {
            return Err(invalid("fs_hz must be finite and positive"));
        }
        if self.fs_hz * self.ts_ms * 1e-3 > 1.0 + 1e-9 {
            return Err(invalid(
                "fs_hz must not exceed the simulation rate 1000 / ts_ms",
            ));
        }
        if !(4..=1 << 20).contains(&self.window) {
            return Err(invalid("window must be between 4 and 1048576 samples"));
        }
        if !(self.bucket_mm.is_finite() && self.bucket_mm > 0.0) {
            return Err(invalid("bucket_mm must be finite and positive"));
        }
        if self.peaks > 1000 {
            return Err(invalid("peaks must be at most 1000"));
        }
        Ok(())
    }

    /// The parameter set these options ask for, given the machine profile's name.
    pub fn machine_dynamics(&self, machine: &str) -> Result<MachineDynamics, Error> {
        if let Some(p) = &self.dynamics_parameters {
            return Ok(p.clone());
        }
        let name = self
            .dynamics
            .as_deref()
            .unwrap_or_else(|| parameters::preset_for_machine(machine));
        MachineDynamics::preset(name)
            .ok_or_else(|| invalid("unknown dynamics preset (ldam-ball-screw, desktop-belt)"))
    }
}

/// Simulates the machine's dynamics over a G-code file.
pub fn vibration(input: &[u8], options: &VibrationOptions) -> Result<VibrationReport, Error> {
    vibration_with_progress(input, options, &mut |_| true)
}

/// [`vibration`] with a progress callback (reading is the first 10 %).
pub fn vibration_with_progress(
    input: &[u8],
    options: &VibrationOptions,
    progress: Progress<'_>,
) -> Result<VibrationReport, Error> {
    options.validate()?;
    let (settings, fs) = simulation_settings(options);
    let mut welch = welch::Welch::new(options.window, fs, options.window_kind, 2);
    let (outcome, bounds, machine, file) =
        simulate_file(input, options, (settings, Some(&mut welch)), progress)?;
    let of = Simulated {
        layers: &file.layers,
        machine: &file.profile.name,
    };
    Ok(report(outcome, welch, (bounds, &machine), of, options))
}

/// [`vibration`]'s deviation over printing moves, whole and per layer, alone: the same
/// figures to the bit, without the acceleration samples, the spectrum and the modes, which
/// only the report reads (a twentieth of a simulation's time). For optimisers that judge
/// their rewrites by it, many times a run. With `expected_s` (the print's planned time,
/// about), a long print runs in two halves ([`split`]): the same figures to rounding, in
/// about two thirds of the time where there are threads (the 34 MB corpus file: 2.1 s
/// against 3.3 s).
pub fn printing_deviation(
    input: &[u8],
    options: &VibrationOptions,
    expected_s: Option<f64>,
) -> Result<(Deviation, Vec<LayerVibration>), Error> {
    options.validate()?;
    let (settings, _) = simulation_settings(options);
    let (outcome, file) = match expected_s {
        Some(about) => split::deviation_run(input, options, settings, about)?,
        None => {
            let (outcome, _, _, file) =
                simulate_file(input, options, (settings, None), &mut |_| true)?;
            (outcome, file)
        }
    };
    let deviation = Deviation::of(&outcome.printing, outcome.printing_max_at);
    Ok((deviation, layer_vibrations(&outcome, &file.layers)))
}

/// `input` read, planned and simulated at `settings` as the planner times each move (the
/// acceleration samples into `welch`, where there is one): the run's outcome, the
/// trajectory's bounds, the machine's dynamics and what the walk learnt of the file.
fn simulate_file(
    input: &[u8],
    options: &VibrationOptions,
    (settings, welch): (simulate::Settings, Option<&mut welch::Welch>),
    progress: Progress<'_>,
) -> Result<
    (
        simulate::Outcome,
        trajectory::Bounds,
        MachineDynamics,
        crate::path::Walked,
    ),
    Error,
> {
    let dynamics_for = |name: &str| options.machine_dynamics(name);
    let sim = stream::Simulating::new(dynamics_for, (settings, welch), input, progress);
    let (sim, timed, file) = timeline::of_file(input, &options.analyze, sim)?;
    if !timed {
        return Err(untimed());
    }
    let by_markers = matches!(file.layer_source, crate::read::LayerSource::Markers(_));
    let (outcome, bounds, machine) = sim.finish(file.layers.len(), by_markers)?;
    Ok((outcome, bounds, machine, file))
}

/// Simulates an already extracted, planned path (for optimisers that compare their output's
/// deviation with the original's). `options.analyze` is not used.
pub fn vibration_of_path(
    path: &PrintPath,
    options: &VibrationOptions,
    progress: Progress<'_>,
) -> Result<VibrationReport, Error> {
    options.validate()?;
    let segs = planned_segments(path)?;
    let of = Simulated {
        layers: &path.layers,
        machine: &path.profile.name,
    };
    simulated(&segs, of, options, progress)
}

/// What the simulation's report says of the file besides its trajectory.
#[derive(Clone, Copy)]
struct Simulated<'a> {
    /// Its layers (their heights).
    layers: &'a [crate::path::PathLayer],
    /// The machine preset it was planned with.
    machine: &'a str,
}

/// The report of the trajectory `segs` of the file `of`.
fn simulated(
    segs: &[trajectory::Segment],
    of: Simulated<'_>,
    options: &VibrationOptions,
    progress: Progress<'_>,
) -> Result<VibrationReport, Error> {
    let machine = options.machine_dynamics(of.machine)?;
    let (settings, fs) = simulation_settings(options);
    let mut welch = welch::Welch::new(options.window, fs, options.window_kind, 2);
    let layers = of.layers.len();
    let outcome = simulate::run(segs, layers, &machine, settings, Some(&mut welch), progress)?;
    let bounds = trajectory::Bounds::of(segs);
    Ok(report(outcome, welch, (bounds, &machine), of, options))
}

/// The report of a simulation's `outcome` and spectrum (`welch`) on a trajectory within
/// `bounds`, of `machine`.
fn report(
    outcome: simulate::Outcome,
    welch: welch::Welch,
    (bounds, machine): (trajectory::Bounds, &MachineDynamics),
    of: Simulated<'_>,
    options: &VibrationOptions,
) -> VibrationReport {
    let axes = axis_modes(bounds, machine);
    let mut all: Vec<Mode> = axes.iter().flat_map(|a| a.modes.iter().copied()).collect();
    all.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));

    let spectrum = welch.finish();
    let peaks = welch::peaks(&spectrum.freqs, &spectrum.power, options.peaks);
    let d = &outcome.deviation;
    let layers = layer_vibrations(&outcome, of.layers);
    VibrationReport {
        machine: of.machine.to_string(),
        dynamics: machine.name.clone(),
        ts_ms: options.ts_ms,
        natural_frequencies_hz: all.iter().map(|m| m.frequency_hz).collect(),
        damping_ratios: all.iter().map(|m| m.damping_ratio).collect(),
        axes,
        deviation_mm: Deviation::of(d, outcome.max_at),
        printing_deviation_mm: Deviation::of(&outcome.printing, outcome.printing_max_at),
        layers,
        psd: Psd {
            fs_hz: simulation_settings(options).1,
            window: spectrum.segment_len,
            window_kind: options.window_kind,
            overlap: spectrum.segment_len / 2,
            segments: spectrum.segments,
            freqs: spectrum.freqs,
            power: spectrum.power,
            peaks,
        },
        simulated_s: outcome.simulated_s,
        steps: outcome.steps,
    }
}

/// The commanded trajectory of a planned path, an error where it has no timing.
fn planned_segments(path: &PrintPath) -> Result<Vec<trajectory::Segment>, Error> {
    trajectory::segments(path).ok_or_else(untimed)
}

/// The error for a path extracted without the planner's timing.
fn untimed() -> Error {
    invalid("the path has no planned timing (extract it with plan = true)")
}

/// The simulation's settings for `options`, and the accelerometer rate they give, Hz.
fn simulation_settings(options: &VibrationOptions) -> (simulate::Settings, f64) {
    let ts = options.ts_ms * 1e-3;
    let decimation = ((1.0 / (options.fs_hz * ts)).round() as u64).max(1);
    let settings = simulate::Settings {
        ts,
        decimation,
        bucket_m: options.bucket_mm * 1e-3,
    };
    (settings, 1.0 / (decimation as f64 * ts))
}

impl Deviation {
    /// The figures of running statistics `stats` (mm), the largest at `max_at`.
    fn of(stats: &simulate::Stats, max_at: [f64; 3]) -> Self {
        Deviation {
            max: stats.max,
            min: stats.min_or_zero(),
            mean: stats.mean(),
            max_at,
            samples: stats.count,
        }
    }
}

/// The modes of each axis in the middle of the printed area.
fn axis_modes(bounds: trajectory::Bounds, machine: &MachineDynamics) -> Vec<AxisModes> {
    let trajectory::Bounds { lo, hi } = bounds;
    let mid = |ax: usize| {
        let m = 0.5 * (lo[ax] + hi[ax]);
        if m.is_finite() {
            m
        } else {
            0.0
        }
    };
    [("x", &machine.x), ("y", &machine.y)]
        .into_iter()
        .enumerate()
        .map(|(ax, (name, drive))| AxisModes {
            axis: name,
            position_mm: mid(ax),
            modes: axis::modes(drive, mid(ax) * 1e-3),
        })
        .collect()
}

/// The vibration of each layer with samples.
fn layer_vibrations(
    outcome: &simulate::Outcome,
    layers: &[crate::path::PathLayer],
) -> Vec<LayerVibration> {
    outcome
        .layers
        .iter()
        .enumerate()
        .filter(|(_, l)| l.deviation.count > 0)
        .map(|(i, l)| LayerVibration {
            layer: i,
            z: layers.get(i).and_then(|l| l.z),
            amplitude: l.deviation.max,
            printing_amplitude: l.printing.max,
            printing_mean: l.printing.mean(),
            printing_samples: l.printing.count,
            mean: l.deviation.mean(),
            acceleration_rms: if l.accel_count > 0 {
                (l.accel_sq / l.accel_count as f64).sqrt()
            } else {
                0.0
            },
        })
        .collect()
}

#[cfg(test)]
mod tests;
