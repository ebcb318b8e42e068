//! Infill regeneration and the energy-driven search over pattern, infill angle and part
//! orientation about Z (Somade 2023, "toolpath strategy": DOE of Table 4 and the case study).
//!
//! 1. `program`: the file as the planner sees it, with its sparse-infill blocks.
//! 2. `region`: per layer, where sparse infill may go (from the walls, holes included).
//! 3. [`pattern`] + `link`: new infill with the original's spacing and extrusion per mm.
//! 4. `emit`: G-code for it in the file's own habits; `cost`: every candidate costed with
//!    the real planner and energy model (the thesis stepper model, thesis eq. 24–28, and the whole
//!    `total_j`), as `analyze` would cost the rewritten file.
//! 5. `search`: angles × rotations × patterns (and per-layer hybrids); `write`: the output.

pub(crate) mod cost;
pub(crate) mod emit;
pub(crate) mod geom;
pub(crate) mod grid;
mod hybrid;
pub(crate) mod link;
mod nearest;
pub mod pattern;
pub(crate) mod program;
mod racing;
pub(crate) mod region;
mod rounds;
mod search;
pub(crate) mod spacing;
pub(crate) mod write;

use serde::{Deserialize, Serialize};

use crate::analyze::{AnalyzeOptions, Report};
use crate::error::{Error, ErrorKind};
pub use pattern::Pattern;
pub use search::{infill, infill_with_progress};

/// What the search minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// `total_j` of the whole file (servo + fuse + auxiliary).
    #[default]
    Energy,
    /// Print time.
    Time,
    /// Toolpath length (printing and travel).
    Length,
    /// `w_e·E/E₀ + w_t·t/t₀ + w_l·L/L₀` with [`InfillOptions::weights`].
    Weighted,
}

/// Weights of [`Objective::Weighted`] (each of energy, time, length relative to the original).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct Weights {
    /// Weight of `total_j / before`.
    pub energy: f64,
    /// Weight of `time_s / before`.
    pub time: f64,
    /// Weight of `length_mm / before`.
    pub length: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Self {
            energy: 1.0,
            time: 1.0,
            length: 0.0,
        }
    }
}

/// Options of [`infill`]. Every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct InfillOptions {
    /// How the file is read and costed (machine, junction model, energy).
    pub analyze: AnalyzeOptions,
    /// Infill angles to try, degrees in the machine frame (default 0, 15, …, 165).
    pub angles_deg: Vec<f64>,
    /// Part rotations about Z to try, degrees (default 0 only: the part stays where it is).
    pub rotations_deg: Vec<f64>,
    /// Patterns to try (default: the thesis's five, Table 4).
    pub patterns: Vec<Pattern>,
    /// What to minimise.
    pub objective: Objective,
    /// Weights of [`Objective::Weighted`].
    pub weights: Weights,
    /// After the search, pick pattern and angle layer by layer (the thesis's hybrid), keeping
    /// the best rotation.
    pub per_layer: bool,
    /// Rectilinear-equivalent line spacing, mm (default: measured from the file).
    pub spacing_mm: Option<f64>,
    /// Write the best candidate even when it does not beat the original on the objective
    /// (default false: the original is kept and the report says so).
    pub force_candidate: bool,
    /// Rewrite the file's time comments and `M73` lines from the planner when a candidate is
    /// written (default true; see [`crate::estimate`]).
    pub estimates: bool,
    /// Cost every candidate on the whole file (default false: a candidate whose estimate from
    /// a sample of layers is clearly worse than the best so far is listed with that estimate,
    /// `estimated: true`, and not costed whole; the DOE table sets it).
    pub exhaustive: bool,
}

impl Default for InfillOptions {
    fn default() -> Self {
        Self {
            analyze: AnalyzeOptions::default(),
            angles_deg: (0..12).map(|k| 15.0 * k as f64).collect(),
            rotations_deg: vec![0.0],
            patterns: Pattern::THESIS.to_vec(),
            objective: Objective::Energy,
            weights: Weights::default(),
            per_layer: false,
            spacing_mm: None,
            force_candidate: false,
            estimates: true,
            exhaustive: false,
        }
    }
}

/// Most candidates one search may cost.
pub const MAX_CANDIDATES: usize = 20_000;

impl InfillOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |reason| Err(Error::new(0, 0, ErrorKind::InvalidOption { reason }));
        if self.angles_deg.is_empty() || self.rotations_deg.is_empty() || self.patterns.is_empty() {
            return bad("angles, rotations and patterns must each list at least one value");
        }
        if self
            .angles_deg
            .iter()
            .chain(&self.rotations_deg)
            .any(|v| !v.is_finite())
        {
            return bad("angles and rotations must be finite numbers of degrees");
        }
        let n = self.angles_deg.len() * self.rotations_deg.len() * self.patterns.len();
        if n > MAX_CANDIDATES {
            return bad("too many candidates (angles × rotations × patterns > 20000)");
        }
        let w = self.weights;
        if [w.energy, w.time, w.length]
            .iter()
            .any(|v| !v.is_finite() || *v < 0.0)
        {
            return bad("weights must be finite and not negative");
        }
        if let Some(s) = self.spacing_mm {
            if !(s.is_finite() && (0.1..=100.0).contains(&s)) {
                return bad("spacing_mm must be between 0.1 and 100 mm");
            }
        }
        Ok(())
    }
}

/// One candidate: the whole file with this pattern, angle and rotation.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "InfillCandidate"))]
pub struct Candidate {
    /// Pattern.
    pub pattern: Pattern,
    /// Whether the costs are an estimate from a sample of layers (a candidate ruled out as
    /// clearly worse than the best; never chosen) rather than the whole file's.
    pub estimated: bool,
    /// Infill angle, degrees (machine frame).
    pub angle_deg: f64,
    /// Part rotation about Z, degrees.
    pub rotation_deg: f64,
    /// Thesis stepper energy of the whole file (thesis eq. 28), J.
    pub thesis_j: f64,
    /// Total energy of the whole file, J.
    pub total_j: f64,
    /// Print time, s.
    pub time_s: f64,
    /// Toolpath length (printing and travel), mm.
    pub length_mm: f64,
    /// Filament, mm.
    pub filament_mm: f64,
    /// Length of the new infill strokes, mm (`L_infill`, VTG eq. 25; VTG Fig. 4).
    pub infill_length_mm: f64,
    /// Turning points of the new infill (turns above 30°, VTG eq. 26's δθ; Fig. 5).
    pub infill_turning_points: u64,
    /// Mean turning angle of the new infill, degrees (VTG eq. 26; Fig. 5).
    pub infill_mean_turn_deg: f64,
}

/// A layer's choice in a per-layer (hybrid) result.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "InfillLayerChoice"))]
pub struct LayerChoice {
    /// Layer index.
    pub layer: usize,
    /// Pattern, or `original` for a layer that keeps the file's own infill (no candidate beat
    /// it on that layer).
    pub pattern: Choice,
    /// Infill angle, degrees.
    pub angle_deg: f64,
}

/// What was written: a regenerated pattern, or the original file kept as it was.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "InfillChoice"))]
#[serde(rename_all = "snake_case")]
pub enum Choice {
    /// No candidate beat the original on the objective (as `analyze` costs both files): the
    /// output is the input, byte for byte.
    Original,
    /// The regenerated pattern.
    #[serde(untagged)]
    Pattern(Pattern),
}

impl Choice {
    /// The snake_case name (`original` or the pattern's).
    pub fn name(self) -> &'static str {
        match self {
            Choice::Original => "original",
            Choice::Pattern(p) => p.name(),
        }
    }
}

/// The chosen result.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "InfillBest"))]
pub struct Best {
    /// Pattern (the most used one for a per-layer result), or `original` when the input is
    /// kept.
    pub pattern: Choice,
    /// Infill angle, degrees.
    pub angle_deg: f64,
    /// Part rotation, degrees.
    pub rotation_deg: f64,
    /// Thesis stepper energy, J.
    pub thesis_j: f64,
    /// Total energy, J.
    pub total_j: f64,
    /// Print time, s.
    pub time_s: f64,
    /// Toolpath length, mm.
    pub length_mm: f64,
    /// `before.total_j − total_j`, J.
    pub saving_j: f64,
    /// Saving in percent of `before.total_j`.
    pub saving_pct: f64,
    /// Per-layer choices when `per_layer` was asked and beat the single best.
    pub layers: Option<Vec<LayerChoice>>,
    /// Why the original was kept, or that a worse candidate was forced; `None` when the
    /// written candidate beats the original.
    pub message: Option<String>,
}

/// What the method measured from the file.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "InfillMeasured"))]
pub struct Measured {
    /// Rectilinear-equivalent line spacing, mm.
    pub spacing_mm: f64,
    /// Distance from the innermost wall's centre line to the infill line ends, mm.
    pub clearance_mm: f64,
    /// Filament per mm of infill line.
    pub e_per_mm: f64,
    /// Layers whose sparse infill is regenerated.
    pub layers_regenerated: usize,
    /// Sparse-infill blocks replaced.
    pub blocks: usize,
    /// Infill print feed, mm/s.
    pub print_feed_mm_s: f64,
    /// Travel feed, mm/s.
    pub travel_feed_mm_s: f64,
    /// Retraction length, mm (0: none).
    pub retract_mm: f64,
}

/// Result of [`infill`].
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct InfillReport {
    /// `analyze` of the input.
    pub before: Report,
    /// `analyze` of the output.
    pub after: Report,
    /// The chosen candidate.
    pub best: Best,
    /// Every candidate costed, in search order.
    pub candidates: Vec<Candidate>,
    /// Candidates not costed because their geometry is the same as an earlier one's (a
    /// concentric pattern at another angle, a rotation that gives the same strokes).
    pub candidates_skipped: usize,
    /// Candidates ruled out on a sample of layers (listed with `estimated: true`).
    pub candidates_estimated: usize,
    /// What was measured from the file.
    pub measured: Measured,
    /// Rotations skipped (the part would not fit on the bed), degrees.
    pub rotations_skipped: Vec<f64>,
    /// The rewritten G-code.
    #[serde(skip)]
    pub output: Vec<u8>,
}
