//! `analyze`: one streaming pass over a file giving time, distances, filament, layers,
//! features, temperatures and fans.

mod layers;
pub mod report;

use std::collections::HashMap;

use serde::Deserialize;

use crate::error::{Error, ErrorKind, Warnings};
use crate::gcode::{self, classify_comment, feature_kind, Marker, SlicerInfo, Strictness};
use crate::machine::{self, axis, Event, ExtrusionMode, Machine, MachineConfig, Move};
use layers::LayerTracker;
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

/// Progress callback: receives the fraction done (0..=1); returning `false` cancels the job.
pub type Progress<'p> = &'p mut dyn FnMut(f64) -> bool;

/// Bytes between two progress callbacks.
const PROGRESS_STEP: usize = 1 << 20;

/// Analyzes a G-code file.
pub fn analyze(input: &[u8], options: &AnalyzeOptions) -> Result<Report, Error> {
    analyze_with_progress(input, options, &mut |_| true)
}

#[derive(Debug, Default)]
struct Totals {
    time_s: f64,
    moves: u64,
    extruding_moves: u64,
    distance_mm: f64,
    extrude_distance_mm: f64,
    travel_distance_mm: f64,
    retractions: u64,
    lines: u64,
    bounds: Option<Bounds>,
}

/// [`analyze`] with progress reports and cancellation.
pub fn analyze_with_progress(
    input: &[u8],
    options: &AnalyzeOptions,
    progress: Progress<'_>,
) -> Result<Report, Error> {
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

    let mut machine = Machine::new(MachineConfig {
        extrusion: mode,
        ..MachineConfig::default()
    });
    let mut info = SlicerInfo::default();
    let mut totals = Totals::default();
    let mut layer_tracker = LayerTracker::new();
    let mut features: Vec<FeatureSummary> = Vec::new();
    let mut feature_names: HashMap<String, usize> = HashMap::new();
    let mut current_feature: Option<usize> = None;
    let mut travel = FeatureSummary {
        name: "travel".into(),
        kind: None,
        moves: 0,
        distance_mm: 0.0,
        filament_mm: 0.0,
        time_s: 0.0,
    };
    let mut temperatures = Vec::new();
    let mut fans = Vec::new();
    let mut next_progress = PROGRESS_STEP;

    gcode::for_each_line(input, strictness, &mut warnings, |raw, line, warnings| {
        totals.lines += 1;
        if raw.offset >= next_progress {
            next_progress = raw.offset + PROGRESS_STEP;
            if !progress(raw.offset as f64 / input.len() as f64) {
                return Err(Error::new(raw.number, 0, ErrorKind::Cancelled));
            }
        }
        let Some(line) = line else { return Ok(()) };
        if let Some(comment) = line.comment {
            match classify_comment(comment) {
                Some(Marker::Layer { kind, z }) => {
                    layer_tracker.marker(kind, z, raw.number);
                }
                Some(Marker::Feature(name)) => {
                    current_feature = Some(feature_index(&mut features, &mut feature_names, name));
                }
                None => info.observe(comment),
            }
        }
        let Some(event) = machine.apply(raw.number, line, warnings) else {
            return Ok(());
        };
        match event {
            Event::Move(m) => {
                let t = m.nominal_time();
                account_move(&m, t, &mut totals);
                let summary = if m.is_extruding() {
                    let i = match current_feature {
                        Some(i) => i,
                        None => {
                            let i = feature_index(&mut features, &mut feature_names, "unmarked");
                            current_feature = Some(i);
                            i
                        }
                    };
                    &mut features[i]
                } else {
                    &mut travel
                };
                summary.moves += 1;
                summary.distance_mm += m.length_mm;
                summary.filament_mm += m.extrusion();
                summary.time_s += t;
                layer_tracker.motion(&m, t);
            }
            Event::Dwell(s) => {
                totals.time_s += s;
                layer_tracker.dwell(s);
            }
            Event::Temperature {
                heater,
                target_c,
                wait,
            } => temperatures.push(TemperatureEvent {
                line: raw.number,
                time_s: totals.time_s,
                heater,
                target_c,
                wait,
            }),
            Event::Fan { index, speed } => fans.push(FanEvent {
                line: raw.number,
                time_s: totals.time_s,
                index,
                speed,
            }),
            Event::Home(_) => {}
        }
        Ok(())
    })?;
    progress(1.0);

    let (layer_list, layer_source) = layer_tracker.finish();
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
    let (warnings, warnings_dropped) = warnings.into_parts();
    Ok(Report {
        version: crate::VERSION.to_string(),
        file: FileInfo {
            bytes: input.len() as u64,
            lines: totals.lines,
            slicer: info.slicer,
            flavor: info.flavor,
        },
        time_s: totals.time_s,
        time_model: "nominal".into(),
        moves: totals.moves,
        extruding_moves: totals.extruding_moves,
        layers: layer_list.len() as u64,
        layer_source,
        distance_mm: totals.distance_mm,
        extrude_distance_mm: totals.extrude_distance_mm,
        travel_distance_mm: totals.travel_distance_mm,
        filament_mm,
        filament_volume_mm3: volume,
        material_g: volume * density / 1000.0,
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
        energy: Energy::default(),
        toolpath: Toolpath::default(),
        warnings,
        warnings_dropped,
    })
}

fn validate_options(o: &AnalyzeOptions) -> Result<(), Error> {
    let positive = |v: Option<f64>| v.is_none_or(|x| x.is_finite() && x > 0.0);
    if !positive(o.filament_diameter_mm) || !positive(o.density_g_cm3) {
        return Err(Error::new(
            0,
            0,
            ErrorKind::InvalidOption {
                reason: "filament_diameter_mm and density_g_cm3 must be positive numbers",
            },
        ));
    }
    Ok(())
}

fn feature_index(
    features: &mut Vec<FeatureSummary>,
    index: &mut HashMap<String, usize>,
    name: &str,
) -> usize {
    if let Some(&i) = index.get(name) {
        return i;
    }
    index.insert(name.to_string(), features.len());
    features.push(FeatureSummary {
        name: name.to_string(),
        kind: Some(feature_kind(name)),
        moves: 0,
        distance_mm: 0.0,
        filament_mm: 0.0,
        time_s: 0.0,
    });
    features.len() - 1
}

fn account_move(m: &Move, t: f64, totals: &mut Totals) {
    totals.moves += 1;
    totals.time_s += t;
    totals.distance_mm += m.length_mm;
    if m.is_extruding() {
        totals.extruding_moves += 1;
        totals.extrude_distance_mm += m.length_mm;
        let b = totals.bounds.get_or_insert(Bounds {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        });
        for p in [&m.from, &m.to] {
            for ((lo, hi), v) in b.min.iter_mut().zip(b.max.iter_mut()).zip(&p[..3]) {
                *lo = lo.min(*v);
                *hi = hi.max(*v);
            }
        }
    } else {
        totals.travel_distance_mm += m.length_mm;
        if m.extrusion() < -1e-12 {
            totals.retractions += 1;
        }
    }
}
