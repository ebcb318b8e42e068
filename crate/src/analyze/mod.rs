//! `analyze`: one streaming pass over a file giving time (from the motion planner), distances,
//! filament, layers, features, temperatures, fans and energy (from [`crate::energy`]).

mod accounting;
pub(crate) mod layers;
mod pipeline;
pub mod prescan;
pub mod report;
pub mod toolpath;

use serde::Deserialize;

use crate::energy::{Accumulator, EnergyOptions};
use crate::error::{Error, ErrorKind, Warnings};
use crate::gcode::{self, classify_comment, Marker, SlicerInfo, Strictness};
use crate::machine::{self, axis, Event, ExtrusionMode, Machine, MachineConfig};
use crate::plan::{FeedUnits, JunctionModel, Limit, LimitSource, MachineProfile, Planner};
use crate::progress::Progress;
use accounting::{Accounts, TimeBook, TimeMsg, Timing};
pub use report::*;

/// Default filament diameter when the file does not declare one, mm.
pub const DEFAULT_FILAMENT_DIAMETER_MM: f64 = 1.75;
/// Default filament density (PLA), g/cm³.
pub const DEFAULT_DENSITY_G_CM3: f64 = 1.24;

/// Options of `analyze`. Every field is optional in JSON.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct AnalyzeOptions {
    /// Stop at the first malformed line instead of warning.
    pub strict: bool,
    /// Filament diameter, mm (default: from the file, else 1.75).
    pub filament_diameter_mm: Option<f64>,
    /// Filament density, g/cm³ (default: from the file, else 1.24, PLA).
    pub density_g_cm3: Option<f64>,
    /// Force the starting extrusion mode instead of inferring it.
    pub extrusion_mode: Option<ExtrusionModeOption>,
    /// Built-in machine preset (see `plan::profiles::PRESETS`); default: chosen from the file's
    /// flavour.
    pub machine: Option<String>,
    /// A whole machine profile (wins over `machine`).
    pub machine_profile: Option<MachineProfile>,
    /// Junction model; default: the profile's, or Klipper's for files that drive Klipper.
    pub junction_model: Option<JunctionModel>,
    /// Length of the segments arcs are split into, mm (default: the profile's, 1 mm).
    pub arc_segment_mm: Option<f64>,
    /// Energy model settings (coefficients, material, powers, emission factors); default:
    /// [`EnergyOptions::default`].
    pub energy: Option<EnergyOptions>,
}

/// Starting extrusion mode, as an option.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExtrusionModeOption {
    /// `M82`.
    Absolute,
    /// `M83`.
    Relative,
}

/// Bytes between two progress callbacks.
const PROGRESS_STEP: usize = 1 << 20;

/// Analyzes a G-code file.
pub fn analyze(input: &[u8], options: &AnalyzeOptions) -> Result<Report, Error> {
    analyze_with_progress(input, options, &mut |_| true)
}

/// The machine, junction model and limits a file is planned with, and why.
fn choose_machine(
    options: &AnalyzeOptions,
    pre: &prescan::Prescan,
) -> Result<(MachineProfile, JunctionModel, String), Error> {
    let klipper = pre.klipper_commands
        || pre
            .flavor
            .as_deref()
            .is_some_and(|f| f.contains("klipper") || f.contains("creality os"));
    let invalid = |reason| Error::new(0, 0, ErrorKind::InvalidOption { reason });
    let (profile, why) = if let Some(p) = &options.machine_profile {
        (
            p.clone(),
            format!("profile '{}' given in the options", p.name),
        )
    } else if let Some(name) = &options.machine {
        let p = MachineProfile::preset(name)
            .ok_or_else(|| invalid("unknown machine preset (see plan::profiles::PRESETS)"))?;
        (p, format!("preset '{name}' given in the options"))
    } else if klipper {
        (
            MachineProfile::preset("voron-klipper").ok_or_else(|| invalid("preset missing"))?,
            "the file drives Klipper".to_string(),
        )
    } else {
        (
            MachineProfile::preset("prusa-mk3s").ok_or_else(|| invalid("preset missing"))?,
            "default for Marlin-style files (classic jerk, as slicer estimators assume)"
                .to_string(),
        )
    };
    let (model, why) = match options.junction_model {
        Some(m) => (m, format!("{why}; junction model given in the options")),
        None if klipper => (JunctionModel::Klipper, why),
        None => (profile.junction, why),
    };
    Ok((profile, model, why))
}

/// What every pass over a file needs before its first line: validated options, the extrusion
/// mode, the head/tail prescan, the machine profile, junction model and starting limits.
/// Shared by [`analyze`] and by [`crate::path::extract`] so both read a file the same way.
#[derive(Debug)]
pub(crate) struct Setup {
    pub strictness: Strictness,
    pub mode: ExtrusionMode,
    pub source: machine::ModeSource,
    pub warnings: Warnings,
    pub pre: prescan::Prescan,
    pub profile: MachineProfile,
    pub model: JunctionModel,
    pub model_reason: String,
    pub limits: crate::plan::Limits,
    pub units: FeedUnits,
}

impl Setup {
    /// The machine a pass starts with: the file's extrusion mode, everything else at its
    /// power-on state.
    pub fn machine(&self) -> Machine {
        Machine::new(MachineConfig {
            extrusion: self.mode,
            ..MachineConfig::default()
        })
    }
}

/// Builds the [`Setup`] of a pass over `input`.
pub(crate) fn prepare(input: &[u8], options: &AnalyzeOptions) -> Result<Setup, Error> {
    validate_options(options)?;
    let strictness = if options.strict {
        Strictness::Strict
    } else {
        Strictness::Lenient
    };
    gcode::check_encoding(input)?;
    let inference = machine::infer_extrusion_mode(input);
    let (mode, source) = match options.extrusion_mode {
        Some(ExtrusionModeOption::Absolute) => {
            (ExtrusionMode::Absolute, machine::ModeSource::Explicit)
        }
        Some(ExtrusionModeOption::Relative) => {
            (ExtrusionMode::Relative, machine::ModeSource::Explicit)
        }
        None => (inference.mode, inference.source),
    };
    let mut warnings = Warnings::default();
    if source == machine::ModeSource::Inferred {
        warnings.push(
            0,
            format!(
                "the file never sets M82/M83 before extruding; read as {} extrusion ({} of {} E values increase)",
                if mode == ExtrusionMode::Absolute { "absolute" } else { "relative" },
                inference.increasing,
                inference.samples
            ),
        );
    }

    let pre = prescan::prescan(input);
    let (profile, model, model_reason) = choose_machine(options, &pre)?;
    let mut limits = profile.limits.clone();
    for (key, value) in &pre.limit_settings {
        limits.apply_setting(key, value);
    }
    if let Some(seg) = options.arc_segment_mm {
        limits.arc_segment_mm = Limit {
            value: seg,
            source: LimitSource::Option,
        };
    }
    let units = if pre.flavor.as_deref() == Some("reprapfirmware") {
        FeedUnits::PerMinute
    } else {
        FeedUnits::PerSecond
    };
    Ok(Setup {
        strictness,
        mode,
        source,
        warnings,
        pre,
        profile,
        model,
        model_reason,
        limits,
        units,
    })
}

/// [`analyze`] with progress reports and cancellation.
pub fn analyze_with_progress(
    input: &[u8],
    options: &AnalyzeOptions,
    progress: Progress<'_>,
) -> Result<Report, Error> {
    let setup = prepare(input, options)?;
    let mut machine = setup.machine();
    let Setup {
        strictness,
        mode,
        source,
        mut warnings,
        pre,
        profile,
        model,
        model_reason,
        limits,
        units,
    } = setup;
    let mut limits_now = limits.clone();
    let mut print_limits = None;
    let mut timing = Timing::new(
        Planner::new(limits, model),
        Accumulator::new(&options.energy.clone().unwrap_or_default(), &profile.name),
    );

    let mut info = SlicerInfo::default();
    let mut acc = Accounts::new();
    let mut next_progress = PROGRESS_STEP;

    let read = |to_timing: &mut dyn FnMut(TimeMsg)| -> Result<(), Error> {
        gcode::for_each_line(input, strictness, &mut warnings, |raw, line, warnings| {
            acc.totals.lines += 1;
            if raw.offset >= next_progress {
                next_progress = raw.offset + PROGRESS_STEP;
                if !progress(raw.offset as f64 / input.len() as f64) {
                    return Err(Error::new(raw.number, 0, ErrorKind::Cancelled));
                }
            }
            let Some(line) = line else { return Ok(()) };
            if let Some(comment) = line.comment {
                match classify_comment(comment) {
                    Some(Marker::Layer { kind, z }) => acc.layers.marker(kind, z, raw.number),
                    Some(Marker::Feature(name)) => acc.feature(name),
                    None => {
                        info.observe(comment);
                        acc.comment(comment);
                    }
                }
            }
            if limits_now.apply_command(line, units) {
                to_timing(TimeMsg::Limits(Box::new(limits_now.clone())));
                return Ok(());
            }
            // By reference: a move is a few hundred bytes, not worth a copy.
            let Some(event) = &machine.apply(raw.number, line, warnings) else {
                return Ok(());
            };
            match event {
                Event::Move(m) => {
                    if print_limits.is_none() && m.is_extruding() {
                        print_limits = Some(limits_now.clone());
                    }
                    to_timing(acc.read_move(m));
                }
                &Event::Dwell(secs) => to_timing(acc.dwell(secs)),
                &Event::Temperature {
                    heater,
                    target_c,
                    wait,
                } => {
                    to_timing(acc.temperature(raw.number, heater, target_c, wait));
                    if wait {
                        // The firmware finishes every queued move before it waits.
                        to_timing(TimeMsg::Flush);
                    }
                }
                &Event::Fan { index, speed } => to_timing(acc.fan(raw.number, index, speed)),
            }
            Ok(())
        })
    };
    pipeline::run(input.len(), &mut timing, read)?;
    timing.finish();
    progress(1.0);
    acc.merge(&timing.book);
    if let Some(m) = acc.material {
        timing.book.energy.set_material_from_file(m);
    }

    let Accounts {
        totals,
        mut features,
        travel,
        layers,
        toolpath,
        ..
    } = acc;
    let Timing { planner, book, .. } = timing;
    let TimeBook {
        energy: energy_acc,
        temperatures,
        fans,
        ..
    } = book;
    let (mut layer_list, layer_source) = layers.finish();
    let filament_mm = machine.position()[axis::E];
    let diameter = options
        .filament_diameter_mm
        .or(info.filament_diameter_mm)
        .unwrap_or(DEFAULT_FILAMENT_DIAMETER_MM);
    let density = options
        .density_g_cm3
        .or(info.filament_density_g_cm3)
        .unwrap_or(DEFAULT_DENSITY_G_CM3);
    let volume = filament_mm * std::f64::consts::PI * diameter * diameter / 4.0;
    if travel.moves > 0 {
        features.push(travel);
    }
    let time_s = planner.elapsed_s();
    let material_g = volume * density / 1000.0;
    let energy = energy_acc.finish(time_s, material_g, &temperatures, &fans);
    // Auxiliary energy is shared out by time (see `crate::energy`).
    // (Shares are taken as fractions of the total first, so a vanishing total time cannot
    // turn into an infinite rate.)
    if time_s > 0.0 {
        let share = |t: f64| energy.aux_j * (t / time_s).clamp(0.0, 1.0);
        for f in &mut features {
            f.energy_j += share(f.time_s);
        }
        for l in &mut layer_list {
            l.energy_j += share(l.time_s);
        }
    }
    let (warnings, warnings_dropped) = warnings.into_parts();
    Ok(Report {
        version: crate::VERSION.to_string(),
        file: FileInfo {
            bytes: input.len() as u64,
            lines: totals.lines,
            slicer: info.slicer,
            flavor: info.flavor.or(pre.flavor),
            slicer_time_s: pre.slicer_time_s,
        },
        time_s,
        dwell_s: totals.dwell_s,
        time_model: "planner".into(),
        machine: MachineInfo {
            profile: profile.name,
            junction_model: model,
            reason: model_reason,
            limits: print_limits.unwrap_or(limits_now),
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
        extrusion: ExtrusionInfo {
            mode,
            source,
            filament_diameter_mm: diameter,
            density_g_cm3: density,
        },
        bounds: totals.bounds,
        features,
        layer_list,
        temperatures,
        fans,
        energy,
        toolpath: toolpath.finish(),
        warnings,
        warnings_dropped,
    })
}

fn validate_options(o: &AnalyzeOptions) -> Result<(), Error> {
    let positive = |v: Option<f64>| v.is_none_or(|x| x.is_finite() && x > 0.0);
    if let Some(reason) = o.energy.as_ref().and_then(|e| e.validate().err()) {
        return Err(Error::new(0, 0, ErrorKind::InvalidOption { reason }));
    }
    if !positive(o.filament_diameter_mm)
        || !positive(o.density_g_cm3)
        || !positive(o.arc_segment_mm)
    {
        return Err(Error::new(
            0,
            0,
            ErrorKind::InvalidOption {
                reason: "filament_diameter_mm, density_g_cm3 and arc_segment_mm must be positive numbers",
            },
        ));
    }
    Ok(())
}
