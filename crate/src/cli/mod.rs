//! The `quietpath` command-line tool: a thin shell over the library. Every subcommand's
//! `--json` output is the serde form of the same type the JS API returns.

mod allocator;
mod bench;
mod calibrate;
mod estimate;
mod infill;
mod klipper;
mod optimize;
mod output;
mod smooth;
mod table;
mod vibration;
mod vtg;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use quietpath::analyze::{analyze_with_progress, AnalyzeOptions, ExtrusionModeOption};
use quietpath::error::Warnings;
use quietpath::gcode::{self, Strictness};
use quietpath::plan::{JunctionModel, KlipperVersion, MachineProfile};

/// Quieter, cheaper 3D-printer toolpaths.
#[derive(Debug, Parser)]
#[command(name = "quietpath", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Time, distance, filament, layers and features of a G-code file.
    Analyze {
        /// G-code file to read.
        file: PathBuf,
        /// Print the report as JSON (the same object the JS API returns).
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        opts: AnalyzeArgs,
    },
    /// Parse and re-emit a file: byte-identical when nothing is changed.
    Rewrite {
        /// G-code file to read.
        file: PathBuf,
        /// Where to write (atomically: a temporary file, then a rename).
        #[arg(short, long)]
        output: PathBuf,
        /// Stop at the first malformed line instead of passing it through with a warning.
        #[arg(long)]
        strict: bool,
        /// Allow the output to replace the input file.
        #[arg(long)]
        force: bool,
    },
    /// Fit the thesis energy model's coefficients to measured energies (least squares without
    /// intercept).
    ///
    /// The CSV has rows `A,B,C,H,E` (thesis terms, energy in W·ms) or rows
    /// `gcode_path,energy_j` (each G-code file is analyzed for its terms; relative paths are
    /// resolved against the CSV's folder). A header line is optional.
    Calibrate {
        /// CSV file to read.
        file: PathBuf,
        /// Print the fit as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        opts: AnalyzeArgs,
    },
    /// Simulate the machine's axis dynamics: natural frequencies, trajectory deviation,
    /// per-layer vibration amplitude and the acceleration spectrum (Welch PSD).
    Vibration(vibration::Args),
    /// Rewrite a file as a vibration-suppressed toolpath (VTG).
    Vtg(vtg::Args),
    /// The recommended pipeline in one pass (infill when asked, VTG, arcs where the firmware
    /// runs them, true time estimates); `--in-place` as a slicer's post-processing script.
    Optimize(optimize::Args),
    /// Rewrite the time comments and M73 progress lines from quietpath's planner.
    Estimate(estimate::Args),
    /// Regenerate sparse infill, searching pattern, infill angle and part orientation.
    Infill(infill::Args),
    /// Smooth the tool orientation of a multi-axis toolpath within a tolerance cone.
    Smooth(smooth::Args),
    /// Measure parsing and analysis throughput on a file.
    Bench {
        /// G-code file to read.
        file: PathBuf,
        /// Repetitions (the best is reported).
        #[arg(long, default_value_t = 5)]
        runs: u32,
        /// Print the figures as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Arcs in a rewritten file (`--arcs`), as [`quietpath::vtg::ArcsMode`].
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum ArcsArg {
    /// Where the firmware runs them.
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

impl From<ArcsArg> for quietpath::vtg::ArcsMode {
    fn from(a: ArcsArg) -> Self {
        match a {
            ArcsArg::Auto => Self::Auto,
            ArcsArg::On => Self::On,
            ArcsArg::Off => Self::Off,
        }
    }
}

#[derive(Debug, clap::Args)]
struct AnalyzeArgs {
    /// Stop at the first malformed line instead of warning.
    #[arg(long)]
    strict: bool,
    /// Filament diameter, mm (default: from the file, else 1.75).
    #[arg(long, value_name = "MM")]
    filament_diameter: Option<f64>,
    /// Filament density, g/cm³ (default: from the file, else 1.24 for PLA).
    #[arg(long, value_name = "G_CM3")]
    density: Option<f64>,
    /// Starting extrusion mode (default: from M82/M83, else inferred from the E values).
    #[arg(long, value_enum)]
    extrusion: Option<ExtrusionArg>,
    /// Machine preset: prusa-mk3s, creality-ender3, voron-klipper, vtg-ldam-servo
    /// (default: chosen from the file's flavour).
    #[arg(long, value_name = "PRESET")]
    machine: Option<String>,
    /// Machine profile as a JSON file (the serde form of a profile; wins over --machine).
    #[arg(long, value_name = "FILE")]
    machine_file: Option<PathBuf>,
    /// Junction model (default: the profile's, or Klipper's for files that drive Klipper).
    #[arg(long, value_enum)]
    junction: Option<JunctionArg>,
    /// Length of the straight segments arcs are split into, mm (default 1).
    #[arg(long, value_name = "MM")]
    arc_segment: Option<f64>,
    /// Energy settings as a JSON file (the serde form of `EnergyOptions`: coefficients,
    /// material, powers, emission factors; every field optional).
    #[arg(long, value_name = "FILE")]
    energy: Option<PathBuf>,
    /// The printer's Klipper config (printer.cfg, includes followed): the file runs on Klipper
    /// with its [printer], [extruder], [gcode_arcs] and [firmware_retraction] settings.
    #[arg(long, value_name = "FILE")]
    klipper_config: Option<PathBuf>,
    /// A Marlin printer's own settings: the text its M503 prints (M201, M203, M204, M205…),
    /// applied before the file, over the preset and the slicer's settings block.
    #[arg(long, value_name = "FILE")]
    machine_gcode: Option<PathBuf>,
    /// How that Klipper reads max_accel_to_decel: legacy (v0.12, Creality's K1 family) or
    /// current (Klipper since 2025-08, minimum_cruise_ratio only) [default: current].
    #[arg(long, value_enum)]
    klipper_version: Option<KlipperVersionArg>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum KlipperVersionArg {
    Legacy,
    Current,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum JunctionArg {
    ClassicJerk,
    JunctionDeviation,
    Klipper,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum ExtrusionArg {
    Absolute,
    Relative,
}

impl AnalyzeArgs {
    /// Whether any analyze option was given on the command line.
    fn any(&self) -> bool {
        self.strict
            || self.filament_diameter.is_some()
            || self.density.is_some()
            || self.extrusion.is_some()
            || self.machine.is_some()
            || self.machine_file.is_some()
            || self.junction.is_some()
            || self.arc_segment.is_some()
            || self.energy.is_some()
            || self.klipper_config.is_some()
            || self.klipper_version.is_some()
            || self.machine_gcode.is_some()
    }

    /// The options given on the command line over `base` (a config file's), field by field:
    /// a flag replaces only its own setting.
    fn over(&self, base: AnalyzeOptions) -> Result<AnalyzeOptions, String> {
        let cli = self.options()?;
        Ok(AnalyzeOptions {
            strict: cli.strict || base.strict,
            filament_diameter_mm: cli.filament_diameter_mm.or(base.filament_diameter_mm),
            density_g_cm3: cli.density_g_cm3.or(base.density_g_cm3),
            extrusion_mode: cli.extrusion_mode.or(base.extrusion_mode),
            machine: cli.machine.or(base.machine),
            machine_profile: cli.machine_profile.or(base.machine_profile),
            junction_model: cli.junction_model.or(base.junction_model),
            arc_segment_mm: cli.arc_segment_mm.or(base.arc_segment_mm),
            energy: cli.energy.or(base.energy),
            klipper_config: cli.klipper_config.or(base.klipper_config),
            klipper_version: cli.klipper_version.or(base.klipper_version),
            machine_gcode: cli.machine_gcode.or(base.machine_gcode),
        })
    }

    fn options(&self) -> Result<AnalyzeOptions, String> {
        let machine_profile = match &self.machine_file {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                Some(
                    MachineProfile::from_json(&text)
                        .map_err(|e| format!("{}: {e}", path.display()))?,
                )
            }
            None => None,
        };
        let energy = match &self.energy {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                Some(serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?)
            }
            None => None,
        };
        let klipper_config = match &self.klipper_config {
            Some(path) => Some(klipper::read_config(path)?),
            None => None,
        };
        let machine_gcode = match &self.machine_gcode {
            Some(path) => Some(
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?,
            ),
            None => None,
        };
        Ok(AnalyzeOptions {
            machine_gcode,
            klipper_config,
            klipper_version: self.klipper_version.map(|v| match v {
                KlipperVersionArg::Legacy => KlipperVersion::Legacy,
                KlipperVersionArg::Current => KlipperVersion::Current,
            }),
            energy,
            machine: self.machine.clone(),
            machine_profile,
            junction_model: self.junction.map(|j| match j {
                JunctionArg::ClassicJerk => JunctionModel::ClassicJerk,
                JunctionArg::JunctionDeviation => JunctionModel::JunctionDeviation,
                JunctionArg::Klipper => JunctionModel::Klipper,
            }),
            arc_segment_mm: self.arc_segment,
            strict: self.strict,
            filament_diameter_mm: self.filament_diameter,
            density_g_cm3: self.density,
            extrusion_mode: self.extrusion.map(|e| match e {
                ExtrusionArg::Absolute => ExtrusionModeOption::Absolute,
                ExtrusionArg::Relative => ExtrusionModeOption::Relative,
            }),
        })
    }
}

/// Files at least this big get a progress bar (when stderr is a terminal).
const PROGRESS_MIN_BYTES: usize = 4 << 20;

/// Runs the CLI.
pub fn main() -> ExitCode {
    allocator::cap_arenas(quietpath::parallel::threads());
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}

fn read(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Cmd::Analyze { file, json, opts } => {
            let input = read(&file)?;
            let mut bar = output::ProgressBar::for_input(input.len());
            let options = opts.options()?;
            let report = analyze_with_progress(&input, &options, &mut |f| bar.update(f))
                .map_err(|e| format!("{}: {e}", file.display()))?;
            bar.finish();
            let mut stdout = std::io::stdout().lock();
            if json {
                output::write_json(&mut stdout, &report)?;
            } else {
                table::write_report(&mut stdout, &file, &report).map_err(|e| e.to_string())?;
            }
            stdout.flush().map_err(|e| e.to_string())
        }
        Cmd::Rewrite {
            file,
            output,
            strict,
            force,
        } => {
            let input = read(&file)?;
            let strictness = if strict {
                Strictness::Strict
            } else {
                Strictness::Lenient
            };
            let mut warnings = Warnings::default();
            gcode::for_each_line(&input, strictness, &mut warnings, |_, _, _| Ok(()))
                .map_err(|e| format!("{}: {e}", file.display()))?;
            for w in warnings.list() {
                eprintln!("warning: {}:{}: {}", file.display(), w.line, w.message);
            }
            output::write_atomically(&file, &output, force, |out| {
                gcode::write_with_edits(&input, &[] as &[gcode::Edit], out)
            })
        }
        Cmd::Calibrate { file, json, opts } => {
            let options = opts.options()?;
            let fit = calibrate::run(&file, &options)?;
            let mut stdout = std::io::stdout().lock();
            if json {
                output::write_json(&mut stdout, &fit)?;
            } else {
                calibrate::print(&mut stdout, &file, &fit).map_err(|e| e.to_string())?;
            }
            stdout.flush().map_err(|e| e.to_string())
        }
        Cmd::Vibration(args) => vibration::run(args),
        Cmd::Vtg(args) => vtg::run(args),
        Cmd::Infill(args) => infill::run(args),
        Cmd::Optimize(args) => optimize::run(args),
        Cmd::Estimate(args) => estimate::run(args),
        Cmd::Smooth(args) => smooth::run(args),
        Cmd::Bench { file, runs, json } => {
            let input = read(&file)?;
            let figures = bench::run(&input, runs.max(1)).map_err(|e| e.to_string())?;
            let mut stdout = std::io::stdout().lock();
            if json {
                output::write_json(&mut stdout, &figures)?;
            } else {
                bench::print(&mut stdout, &file, &figures).map_err(|e| e.to_string())?;
            }
            Ok(())
        }
    }
}
