//! The analysis report: the JSON contract shared by the CLI (`analyze --json`), the JS API and
//! the playground. Field names are stable; new fields are added, never renamed.

use serde::Serialize;

use crate::error::Warning;
use crate::gcode::FeatureKind;
use crate::machine::{ExtrusionMode, ModeSource};
pub use crate::read::{LayerSource, LayerSummary};

/// Everything `analyze` says about a file.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Report {
    /// quietpath version that made the report.
    pub version: String,
    /// Facts about the file itself.
    pub file: FileInfo,
    /// Estimated print time, s (the planned moves, plus dwells).
    pub time_s: f64,
    /// Time spent in dwells (`G4`), s: included in `time_s`. (PrusaSlicer's estimate leaves
    /// dwells out, so comparisons with it subtract this.)
    pub dwell_s: f64,
    /// Homings (`G28`) on Klipper, left out of `time_s` and of the moves: how long homing
    /// takes depends on the printer, and no file tells. Each stops the toolhead. Absent when
    /// there are none (and on Marlin-style files, where `G28` is timed as a move to 0).
    #[serde(skip_serializing_if = "is_zero")]
    #[cfg_attr(test, ts(optional, as = "Option<_>"))]
    pub homing_count: u64,
    /// How `time_s` was computed (`planner`: firmware look-ahead with the junction model below).
    pub time_model: String,
    /// The machine the file was planned for.
    pub machine: MachineInfo,
    /// Motion commands that moved something (XYZ, rotary axes or the extruder).
    pub moves: u64,
    /// Of those, moves that laid down material.
    pub extruding_moves: u64,
    /// Layers printed.
    pub layers: u64,
    /// How layers were counted.
    pub layer_source: LayerSource,
    /// Tool-tip path length, mm (printing and travel).
    pub distance_mm: f64,
    /// Path length while extruding, mm.
    pub extrude_distance_mm: f64,
    /// Path length without extruding, mm.
    pub travel_distance_mm: f64,
    /// Net filament pushed into the nozzle, mm (retractions cancel their recoveries).
    pub filament_mm: f64,
    /// Filament volume, mm³.
    pub filament_volume_mm3: f64,
    /// Filament mass, g.
    pub material_g: f64,
    /// Retraction moves (E going back), including firmware retraction.
    pub retractions: u64,
    /// Extrusion settings used.
    pub extrusion: ExtrusionInfo,
    /// Bounding box of the printed (extruded) path, or `null` if nothing was extruded.
    pub bounds: Option<Bounds>,
    /// Per-feature totals, in order of first appearance; travel last.
    pub features: Vec<FeatureSummary>,
    /// Per-layer totals.
    pub layer_list: Vec<LayerSummary>,
    /// Heater targets over time.
    pub temperatures: Vec<TemperatureEvent>,
    /// Part-cooling fan speeds over time.
    pub fans: Vec<FanEvent>,
    /// Energy models (filled by the energy module).
    pub energy: Energy,
    /// Toolpath metrics (filled by the VTG module).
    pub toolpath: Toolpath,
    /// Problems found, with their line numbers (at most 1000; see `warnings_dropped`).
    pub warnings: Vec<Warning>,
    /// Warnings counted beyond the ones listed.
    pub warnings_dropped: u64,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// Facts about the input file.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct FileInfo {
    /// Size, bytes.
    pub bytes: u64,
    /// Number of lines.
    pub lines: u64,
    /// Slicer that wrote it, from its header.
    pub slicer: Option<String>,
    /// Firmware flavour declared in the file.
    pub flavor: Option<String>,
    /// The slicer's own print-time estimate written in the file, s.
    pub slicer_time_s: Option<f64>,
}

/// The machine a file was planned for.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct MachineInfo {
    /// Profile name.
    pub profile: String,
    /// Junction model used.
    pub junction_model: crate::plan::JunctionModel,
    /// Why this profile and model.
    pub reason: String,
    /// Limits in force at the first printing move, each with where it came from.
    pub limits: crate::plan::Limits,
}

/// Extrusion settings used for filament and mass.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct ExtrusionInfo {
    /// Mode the file starts in.
    pub mode: ExtrusionMode,
    /// Where that mode came from.
    pub source: ModeSource,
    /// Filament diameter, mm.
    pub filament_diameter_mm: f64,
    /// Filament density, g/cm³.
    pub density_g_cm3: f64,
}

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Bounds {
    /// Minimum X, Y, Z, mm.
    pub min: [f64; 3],
    /// Maximum X, Y, Z, mm.
    pub max: [f64; 3],
}

/// Totals for one printed feature (as named by the slicer), or for travel.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct FeatureSummary {
    /// Name as the slicer wrote it (`travel` for non-printing moves, `unmarked` when the file
    /// names no features).
    pub name: String,
    /// Canonical kind (`null` for travel).
    pub kind: Option<FeatureKind>,
    /// Moves.
    pub moves: u64,
    /// Path length, mm.
    pub distance_mm: f64,
    /// Net filament, mm.
    pub filament_mm: f64,
    /// Time, s (same model as `time_s`).
    pub time_s: f64,
    /// Energy of its moves, J: their `E_servo` plus the share of `E_aux` of their time (see
    /// [`crate::energy`]).
    pub energy_j: f64,
}

pub use crate::energy::Energy;
pub use crate::machine::{FanEvent, TemperatureEvent};

/// Toolpath metrics of the VTG paper (VTG eq. 24–26, 31), see [`super::toolpath`].
pub type Toolpath = super::toolpath::ToolpathMetrics;
