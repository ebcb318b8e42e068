//! The print path as a list: every move of a file with its feature, layer and (optionally) the
//! planner's timing.
//!
//! `analyze` streams and keeps only sums; the optimisers (VTG, infill regeneration) and the
//! dynamics simulation need the moves themselves, in order, grouped by layer and feature. This
//! module reads a file exactly as `analyze` does (same extrusion-mode inference, prescan,
//! machine profile and limits, see [`crate::analyze`](mod@crate::analyze)) and keeps each move.
//!
//! ```
//! let gcode = b";LAYER_CHANGE\n;TYPE:Internal infill\nG1 X10 Y0 E0.5 F1200\nG1 X10 Y10 E0.5\n";
//! let path = quietpath::path::extract(gcode, &Default::default(), true).unwrap();
//! assert_eq!(path.moves.len(), 2);
//! assert_eq!(path.layers.len(), 1);
//! assert_eq!(path.feature_kind(&path.moves[0]), Some(quietpath::gcode::FeatureKind::SparseInfill));
//! assert!(path.moves[1].timing.is_some());
//! ```

mod geometry;
mod piped;
mod steps;

pub use geometry::{DrawPoint, LayerGeometry, SegmentKind, ARC_CHORD_DEG, TOOL_FLOATS};
pub(crate) use piped::walk_piped;
use steps::{Planning, Reading};

use serde::Serialize;

use crate::error::{Error, Warning};
use crate::gcode::FeatureKind;
use crate::machine::{ExtrusionMode, MoveKind, Pos};
use crate::plan::{JunctionModel, Limits, MachineProfile, PlannedMove, Planner, Profile};
use crate::read::{AnalyzeOptions, LayerSource};
use crate::read::{Both, Fold, Reader};

/// Feature index of moves before the file names any feature.
pub const NO_FEATURE: u16 = u16::MAX;
/// Layer index of moves before the first layer.
pub const NO_LAYER: u32 = crate::read::NO_LAYER;

/// When and how fast the machine runs one move (from the motion planner).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MoveTiming {
    /// Time the move starts, s from the start of the file.
    pub start_s: f64,
    /// Time the whole move takes, s (for an arc: all the straight segments the firmware splits
    /// it into).
    pub duration_s: f64,
    /// Speed profile along the path (for an arc: its last segment's).
    pub profile: Profile,
}

/// One move of the file, in machine coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PathMove {
    /// 1-based source line.
    pub line: u32,
    /// `G0`, `G1`, `G2`/`G3` (with its arc), firmware retraction, homing.
    pub kind: MoveKind,
    /// Start position (E: net filament so far).
    pub from: Pos,
    /// End position.
    pub to: Pos,
    /// Requested feed rate, mm/s.
    pub feed_mm_s: f64,
    /// Tool-tip path length, mm.
    pub length_mm: f64,
    /// Index into [`PrintPath::features`], or [`NO_FEATURE`].
    pub feature: u16,
    /// Index into [`PrintPath::layers`], or [`NO_LAYER`].
    pub layer: u32,
    /// The planner's timing, when asked for.
    pub timing: Option<MoveTiming>,
}

impl PathMove {
    /// Filament pushed (negative for a retraction), mm.
    pub fn extrusion(&self) -> f64 {
        self.to[crate::machine::axis::E] - self.from[crate::machine::axis::E]
    }

    /// Whether the move lays down material.
    pub fn is_extruding(&self) -> bool {
        self.length_mm > 1e-9 && self.extrusion() > 1e-12
    }
}

/// A layer: its height and the range of moves in it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathLayer {
    /// Height, mm (from the marker, else the first extrusion).
    pub z: Option<f64>,
    /// 1-based line where the layer starts.
    pub line: u32,
    /// Moves of the layer: `moves[first..end]`.
    pub first: usize,
    /// One past the layer's last move.
    pub end: usize,
}

/// A named feature (`;TYPE:` and equivalents) and what kind it is.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathFeature {
    /// The slicer's name.
    pub name: String,
    /// The normalised kind.
    pub kind: FeatureKind,
}

/// Every move of a file, with layers and features.
#[derive(Debug, Clone, Serialize)]
pub struct PrintPath {
    /// Moves in file order.
    pub moves: Vec<PathMove>,
    /// Layers in order; moves before the first layer belong to none.
    pub layers: Vec<PathLayer>,
    /// How layers were counted.
    pub layer_source: LayerSource,
    /// Features named in the file.
    pub features: Vec<PathFeature>,
    /// Machine profile the file is planned with.
    pub profile: MachineProfile,
    /// Junction model.
    pub junction_model: JunctionModel,
    /// Limits in force at the first extrusion (after the file's own commands).
    pub print_limits: Limits,
    /// Extrusion mode at the start of the file.
    pub extrusion_mode: ExtrusionMode,
    /// Total planned time, s (0 without planning).
    pub time_s: f64,
    /// Warnings met while reading.
    pub warnings: Vec<Warning>,
}

impl PrintPath {
    /// The kind of a move's feature, if the file named one.
    pub fn feature_kind(&self, m: &PathMove) -> Option<FeatureKind> {
        self.features.get(m.feature as usize).map(|f| f.kind)
    }

    /// The moves of layer `i`.
    pub fn layer_moves(&self, i: usize) -> &[PathMove] {
        self.layers
            .get(i)
            .map_or(&[][..], |l| &self.moves[l.first..l.end])
    }
}

/// Where [`walk`] delivers the moves it reads, one at a time in file order.
pub trait MoveSink {
    /// A move was read: `index` is its position in file order, `layers` the layer it belongs to
    /// by marker and by counting (which one the file uses is known only at the end, in
    /// [`Walked::layer_source`]), `features` the features named so far (`m.feature` indexes it).
    fn moved(&mut self, index: usize, m: PathMove, layers: (u32, u32), features: &[PathFeature]);
    /// The planner has timed move `pm.tag` (only when planning; several calls for the segments
    /// of one arc).
    fn timed(&mut self, _pm: &PlannedMove) {}
    /// The limits in force changed (and once before the first move, with the file's starting
    /// limits).
    fn limits(&mut self, _limits: &Limits) {}
    /// The machine the file is read for, once, before the first move.
    fn machine(&mut self, _profile: &MachineProfile) {}
    /// Whether the sink wants no more moves: the walk then leaves the rest of the file's lines
    /// unread, and what it learnt covers only what it read.
    fn finished(&self) -> bool {
        false
    }
}

/// What [`walk`] learns of a file besides its moves.
#[derive(Debug, Clone)]
pub struct Walked {
    /// Layers in order, with their heights and first lines (no move ranges).
    pub layers: Vec<PathLayer>,
    /// How layers were counted.
    pub layer_source: LayerSource,
    /// Features named in the file.
    pub features: Vec<PathFeature>,
    /// Machine profile the file is planned with.
    pub profile: MachineProfile,
    /// Junction model.
    pub junction_model: JunctionModel,
    /// Limits in force at the first extrusion.
    pub print_limits: Limits,
    /// Extrusion mode at the start of the file.
    pub extrusion_mode: ExtrusionMode,
    /// Total planned time, s (0 without planning).
    pub time_s: f64,
    /// Warnings met while reading.
    pub warnings: Vec<Warning>,
    /// Moves read.
    pub moves: usize,
}

impl Walked {
    /// The layer a move belongs to, from the pair [`MoveSink::moved`] was given.
    pub fn layer_of(&self, layers: (u32, u32)) -> u32 {
        match self.layer_source {
            LayerSource::Markers(_) => layers.0,
            _ => layers.1,
        }
    }
}

/// Reads every move of `input` the way [`crate::analyze::analyze`] does and hands each to
/// `sink`, keeping nothing itself: memory stays bounded whatever the file's size (what a sink
/// keeps is its own business). With `plan`, the planner's timing follows through
/// [`MoveSink::timed`].
pub fn walk(
    input: &[u8],
    options: &AnalyzeOptions,
    plan: bool,
    sink: &mut impl MoveSink,
) -> Result<Walked, Error> {
    walk_also(input, options, plan, sink, |_| ()).map(|(walked, ())| walked)
}

/// [`walk`], with the fold `also` makes from the pass's reader fed by the same pass (told of
/// each line after the walk): a caller that needs the moves and something else of the file
/// reads and parses it once.
pub(crate) fn walk_also<F: Fold>(
    input: &[u8],
    options: &AnalyzeOptions,
    plan: bool,
    sink: &mut impl MoveSink,
    also: impl FnOnce(&Reader) -> F,
) -> Result<(Walked, F), Error> {
    let mut reader = Reader::new(input, options)?;
    let mut also = also(&reader);
    sink.machine(&reader.setup.profile);
    sink.limits(&reader.setup.limits);
    let planner = plan.then(|| Planner::new(reader.setup.limits.clone(), reader.setup.model));
    let mut fold = Reading::new(Planning::new(sink, planner), plan);
    reader.read(input, &mut Both(&mut fold, &mut also))?;
    let (features, count, time_s) = fold.to.finish();
    let walked = walked_of(reader, features, count, time_s);
    Ok((walked, also))
}

/// What a walk learnt: the `reader`'s layers, machine and warnings once it has read the file,
/// with the `features` named, the `count` of moves and the planned time `time_s`.
fn walked_of(reader: Reader, features: Vec<PathFeature>, count: usize, time_s: f64) -> Walked {
    let print_limits = reader.limits_in_force().clone();
    let Reader { setup, layers, .. } = reader;
    let (summaries, layer_source) = layers.finish();
    let layers = summaries
        .iter()
        .map(|s| PathLayer {
            z: s.z,
            line: s.line,
            first: 0,
            end: 0,
        })
        .collect();
    let (warnings, _) = setup.warnings.into_parts();
    Walked {
        layers,
        layer_source,
        features,
        profile: setup.profile,
        junction_model: setup.model,
        print_limits,
        extrusion_mode: setup.mode,
        time_s,
        warnings,
        moves: count,
    }
}

impl PrintPath {
    /// The timing of a path read without planning, from the moves an analysis of the same
    /// file timed ([`crate::analyze::Keep::timed_moves`]) and its planned time `time_s`: what
    /// [`extract`] with planning gives, from a planning pass that ran anyway. Each timed move
    /// is the next move of its line (a line makes at most one move; a move the planner does
    /// not time, Klipper's homing, keeps none).
    pub fn set_timing(&mut self, timed: &[crate::analyze::TimedMove], time_s: f64) {
        let mut moves = self.moves.iter_mut();
        for t in timed {
            let Some(m) = moves.find(|m| m.line == t.line) else {
                break;
            };
            m.timing = Some(MoveTiming {
                start_s: t.start_s,
                duration_s: t.end_s - t.start_s,
                profile: t.profile,
            });
        }
        self.time_s = time_s;
    }
}

/// [`MoveSink`] keeping every move (for [`extract`]).
struct Collect {
    moves: Vec<PathMove>,
    layer_pairs: Vec<(u32, u32)>,
}

impl MoveSink for Collect {
    fn moved(&mut self, _: usize, m: PathMove, layers: (u32, u32), _: &[PathFeature]) {
        self.moves.push(m);
        self.layer_pairs.push(layers);
    }

    fn timed(&mut self, pm: &PlannedMove) {
        if let Some(m) = self.moves.get_mut(pm.tag as usize) {
            let end = pm.start_s + pm.duration();
            let start_s = m.timing.map_or(pm.start_s, |t| t.start_s);
            m.timing = Some(MoveTiming {
                start_s,
                duration_s: end - start_s,
                profile: pm.profile,
            });
        }
    }
}

/// Reads every move of `input` the way [`crate::analyze::analyze`] does and keeps them all. With
/// `plan`, each move also gets the planner's timing (look-ahead over the whole file, limit
/// commands applied where they appear, dwells and heater waits flushing the queue as firmware
/// does). [`walk`] reads the same moves without keeping them.
pub fn extract(input: &[u8], options: &AnalyzeOptions, plan: bool) -> Result<PrintPath, Error> {
    extract_also(input, options, plan, |_| ()).map(|(path, ())| path)
}

/// [`extract`], with the fold `also` makes from the pass's reader fed by the same pass (see
/// [`walk_also`]).
pub(crate) fn extract_also<F: Fold>(
    input: &[u8],
    options: &AnalyzeOptions,
    plan: bool,
    also: impl FnOnce(&Reader) -> F,
) -> Result<(PrintPath, F), Error> {
    let expected = crate::gcode::command_lines(input);
    let mut kept = Collect {
        moves: Vec::with_capacity(expected),
        layer_pairs: Vec::with_capacity(expected),
    };
    let (walked, also) = walk_also(input, options, plan, &mut kept, also)?;
    let Collect {
        mut moves,
        layer_pairs,
    } = kept;
    for (m, &pair) in moves.iter_mut().zip(&layer_pairs) {
        m.layer = walked.layer_of(pair);
    }
    let Walked {
        mut layers,
        layer_source,
        features,
        profile,
        junction_model,
        print_limits,
        extrusion_mode,
        time_s,
        warnings,
        ..
    } = walked;
    // Moves are in file order and layer indices never decrease (moves before the first layer
    // have none), so each layer is one range.
    let mut seen = vec![false; layers.len()];
    for (i, m) in moves.iter().enumerate() {
        let Some(layer) = layers.get_mut(m.layer as usize) else {
            continue;
        };
        let k = m.layer as usize;
        if !seen[k] {
            seen[k] = true;
            layer.first = i;
        }
        layer.end = i + 1;
    }
    // A layer without moves (two markers in a row) is an empty range where the next one starts.
    let mut next = moves.len();
    for (layer, seen) in layers.iter_mut().zip(&seen).rev() {
        if *seen {
            next = layer.first;
        } else {
            layer.first = next;
            layer.end = next;
        }
    }
    let path = PrintPath {
        moves,
        layers,
        layer_source,
        features,
        profile,
        junction_model,
        print_limits,
        extrusion_mode,
        time_s,
        warnings,
    };
    Ok((path, also))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &[u8] =
        b"G21\nG90\nM83\nG1 X5 Y5 F3000\n;LAYER_CHANGE\n;Z:0.2\nG1 Z0.2 F600\n;TYPE:Perimeter\n\
G1 X10 Y0 E0.5 F1200\nG1 X10 Y10 E0.5\n;TYPE:Internal infill\nG1 X0 Y10 E0.5\n\
;LAYER_CHANGE\n;Z:0.4\nG1 Z0.4\nG1 X0 Y0 E0.5\n";

    #[test]
    fn moves_layers_and_features_follow_the_file() {
        let p = extract(SAMPLE, &AnalyzeOptions::default(), false).unwrap();
        // The travel comes before the first layer: it belongs to none.
        assert_eq!(p.moves.len(), 7);
        assert_eq!(p.moves[0].layer, NO_LAYER);
        assert_eq!(p.layers.len(), 2);
        assert_eq!((p.layers[0].first, p.layers[0].end), (1, 5));
        assert_eq!((p.layers[1].first, p.layers[1].end), (5, 7));
        assert_eq!(p.feature_kind(&p.moves[2]), Some(FeatureKind::InnerWall));
        assert_eq!(p.feature_kind(&p.moves[4]), Some(FeatureKind::SparseInfill));
        assert_eq!(p.moves[1].feature, NO_FEATURE);
        assert!(p.moves.iter().all(|m| m.timing.is_none()));
    }

    #[test]
    fn planned_time_equals_analyze() {
        let p = extract(SAMPLE, &AnalyzeOptions::default(), true).unwrap();
        let r = crate::analyze::analyze(SAMPLE, &AnalyzeOptions::default()).unwrap();
        assert!(
            (p.time_s - r.time_s).abs() < 1e-12,
            "{} vs {}",
            p.time_s,
            r.time_s
        );
        let sum: f64 = p.moves.iter().map(|m| m.timing.unwrap().duration_s).sum();
        assert!((sum - r.time_s).abs() < 1e-9);
        // Consecutive moves start when the previous one ends (no dwell in the sample).
        for w in p.moves.windows(2) {
            let (a, b) = (w[0].timing.unwrap(), w[1].timing.unwrap());
            assert!((a.start_s + a.duration_s - b.start_s).abs() < 1e-9);
        }
    }

    #[test]
    fn an_arc_is_timed_from_its_first_segment_to_its_last() {
        let gcode = b"M83\nG1 X10 Y0 F3000\nG3 X10 Y20 I0 J10 E2 F1200\nG1 X0 Y20 E1\n";
        let p = extract(gcode, &AnalyzeOptions::default(), true).unwrap();
        let r = crate::analyze::analyze(gcode, &AnalyzeOptions::default()).unwrap();
        let t: Vec<MoveTiming> = p.moves.iter().map(|m| m.timing.unwrap()).collect();
        assert_eq!(t.len(), 3);
        // Half a circle of radius 10 in 1 mm segments: much longer than its last segment.
        assert!(t[1].duration_s > 10.0 * t[1].profile.duration());
        assert!((t[0].start_s + t[0].duration_s - t[1].start_s).abs() < 1e-9);
        assert!((t[1].start_s + t[1].duration_s - t[2].start_s).abs() < 1e-9);
        assert!((t[2].start_s + t[2].duration_s - r.time_s).abs() < 1e-9);
    }
}
