//! The search: every (pattern, infill angle, part rotation) is run as G-code for the replaced
//! blocks through a copy of the machine and replayed through the planner and energy model for
//! the whole file ([`super::cost`]); the best by the objective is written out and analysed again.
//!
//! Infill angles are in the machine frame, as a slicer's `fill_angle`: a part turned by `θ`
//! with infill at `α` gets the pattern at `α − θ` in the part's own frame, so the generated
//! geometry is shared by every (α, θ) with the same difference (a cache keyed by it).

use std::collections::HashMap;

use std::borrow::Cow;

use super::cost::{replay, Baseline, Costs, Replacement, Replacements, Rotation};
use super::emit::{self, Habit};
use super::geom::{bbox, path_len, Path, P2};
use super::program::{self, Program};
use super::region::{self, LayerRegion};
use super::spacing::Line;
use super::{
    link, pattern, write, Best, Candidate, Choice, InfillOptions, InfillReport, Measured,
    Objective, Pattern,
};
use crate::analyze::{analyze, Report};
use crate::error::{Error, ErrorKind};
use crate::gcode::FeatureKind;
use crate::machine::axis;
use crate::progress::Progress;

/// Clearance used when the file gives no evidence of its own, mm (a 0.45 mm line with 10 %
/// overlap).
const DEFAULT_CLEARANCE_MM: f64 = 0.2;
/// Margin kept from the bed edges when a rotated part is moved back onto the bed, mm.
const BED_MARGIN_MM: f64 = 1.0;

/// Regenerates the sparse infill of `input` with the best pattern, angle and rotation.
pub fn infill(input: &[u8], options: &InfillOptions) -> Result<InfillReport, Error> {
    infill_with_progress(input, options, &mut |_| true)
}

/// A layer whose infill is regenerated.
pub(crate) struct Work {
    pub layer: usize,
    /// Blocks of the layer (the first gets all the new infill).
    pub blocks: Vec<usize>,
    pub region: LayerRegion,
    /// Extruded length of the original sparse infill, mm.
    pub target_mm: f64,
    /// Length of rectilinear lines at the file's spacing over the region, mm.
    pub nominal_mm: f64,
    /// Filament per mm of the original sparse infill of this layer.
    pub e_per_mm: f64,
    /// Nozzle position at the first block (part frame).
    pub start: P2,
    /// Nozzle position at the start of each block (part frame): where the walls before it end.
    pub starts: Vec<P2>,
    /// Points of each block's original infill (which island a new chain belongs to).
    pub anchors: Vec<Vec<P2>>,
}

pub(crate) struct Prepared<'a> {
    pub input: &'a [u8],
    pub prog: Program,
    pub before: Report,
    pub base: Baseline,
    pub habit: Habit,
    pub spacing: f64,
    pub clearance: f64,
    pub work: Vec<Work>,
    pub zone: Option<(usize, usize)>,
    pub centre: P2,
    pub bed: [f64; 4],
}

fn invalid(reason: &'static str) -> Error {
    Error::new(0, 0, ErrorKind::InvalidOption { reason })
}

/// The file has no sparse infill the search can regenerate.
fn nothing(reason: &'static str) -> Error {
    Error::new(0, 0, ErrorKind::NothingToRegenerate { reason })
}

fn prepare<'a>(input: &'a [u8], options: &InfillOptions) -> Result<Prepared<'a>, Error> {
    options.validate()?;
    let before = analyze(input, &options.analyze)?;
    let prog = program::read(input, &options.analyze)?;
    let habit = emit::habit(&prog).ok_or_else(|| nothing("the file marks no sparse infill"))?;
    let mut by_layer: Vec<Vec<usize>> = vec![Vec::new(); prog.layer_count];
    for (i, mv) in prog.moves.iter().enumerate() {
        if let Some(l) = by_layer.get_mut(mv.layer as usize) {
            l.push(i);
        }
    }
    let clearance = region::clearance(&prog, &by_layer).unwrap_or(DEFAULT_CLEARANCE_MM);
    let mut work = work_items(&prog, &by_layer, clearance);
    if work.is_empty() {
        return Err(nothing(
            "no layer has a sparse-infill region inside closed walls",
        ));
    }
    let spacing = options
        .spacing_mm
        .unwrap_or_else(|| measured_spacing(&prog, &work));
    // Each layer's target: the length of the equivalent rectilinear lines over its area.
    for w in &mut work {
        w.nominal_mm = w.region.area_mm2 / spacing;
    }
    if !(spacing.is_finite() && spacing > 0.05) {
        return Err(invalid(
            "could not measure a line spacing from the file's infill",
        ));
    }
    let zone = print_zone(&prog);
    let pts: Vec<P2> = zone
        .map(|(a, b)| {
            prog.moves[a..=b]
                .iter()
                .filter(|m| m.m.is_extruding())
                .flat_map(|m| [[m.m.from[0], m.m.from[1]], [m.m.to[0], m.m.to[1]]])
                .collect()
        })
        .unwrap_or_default();
    let b = bbox(&pts).unwrap_or([0.0; 4]);
    let centre = [0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])];
    let bed = prog.bed.unwrap_or_else(|| bed_of_moves(&prog));
    let base = Baseline::new(&before, options.analyze.energy.clone().unwrap_or_default());
    Ok(Prepared {
        input,
        prog,
        before,
        base,
        habit,
        spacing,
        clearance,
        work,
        zone,
        centre,
        bed,
    })
}

/// The layers whose sparse infill can be regenerated, in order (`by_layer`: the moves of each
/// layer).
fn work_items(prog: &Program, by_layer: &[Vec<usize>], clearance: f64) -> Vec<Work> {
    let mut blocks_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for (b, blk) in prog.blocks.iter().enumerate() {
        blocks_of.entry(blk.layer).or_default().push(b);
    }
    let mut layers: Vec<(usize, Vec<usize>)> = blocks_of.into_iter().collect();
    layers.sort_unstable_by_key(|l| l.0);
    // Each layer's region is a few boolean operations on its walls: independent, so one layer
    // a thread.
    crate::parallel::map_each(&layers, |(layer, blocks)| {
        let idx = by_layer.get(*layer)?;
        work_item(prog, *layer, blocks.clone(), idx, clearance)
    })
    .into_iter()
    .flatten()
    .collect()
}

/// Layer `layer` with sparse-infill blocks `blocks` and moves `idx` as a work item, if its
/// infill region is found and holds the file's own infill.
fn work_item(
    prog: &Program,
    layer: usize,
    blocks: Vec<usize>,
    idx: &[usize],
    clearance: f64,
) -> Option<Work> {
    let moves: Vec<_> = idx
        .iter()
        .filter_map(|&i| prog.moves.get(i).copied())
        .collect();
    let region = region::extract(&moves, clearance)?;
    let (e, l) = blocks
        .iter()
        .filter_map(|&b| prog.blocks.get(b))
        .flat_map(|b| prog.moves.get(b.first..b.end).unwrap_or(&[]))
        .filter(|m| m.m.is_extruding())
        .fold((0.0, 0.0), |(e, l), m| {
            (e + m.m.extrusion(), l + m.m.length_mm)
        });
    // Guard: the file's own sparse infill must lie in the region we found (at least 80 %
    // of its length, judged by move midpoints); otherwise the walls did not describe the
    // infill area (open or unmarked walls) and the layer is left as it is.
    let (inside_mm, all_mm) = blocks
        .iter()
        .filter_map(|&b| prog.blocks.get(b))
        .flat_map(|b| prog.moves.get(b.first..b.end).unwrap_or(&[]))
        .filter(|m| m.m.is_extruding())
        .fold((0.0, 0.0), |(i, a), m| {
            let mid = [
                0.5 * (m.m.from[axis::X] + m.m.to[axis::X]),
                0.5 * (m.m.from[axis::Y] + m.m.to[axis::Y]),
            ];
            let inside = super::geom::inside_tol(&region.region, mid, clearance);
            (
                i + if inside { m.m.length_mm } else { 0.0 },
                a + m.m.length_mm,
            )
        });
    if inside_mm < 0.8 * all_mm {
        return None;
    }
    let first = blocks.first().and_then(|&b| prog.blocks.get(b))?;
    let p = first.machine.position();
    let (starts, anchors) = block_points(prog, &blocks);
    (l > 0.0).then(|| Work {
        layer,
        start: [p[axis::X], p[axis::Y]],
        starts,
        anchors,
        blocks,
        region,
        target_mm: l,
        nominal_mm: 0.0,
        e_per_mm: e / l,
    })
}

/// Where each block starts, and up to 256 points of its original infill.
fn block_points(prog: &Program, blocks: &[usize]) -> (Vec<P2>, Vec<Vec<P2>>) {
    blocks
        .iter()
        .filter_map(|&b| prog.blocks.get(b))
        .map(|blk| {
            let p = blk.machine.position();
            let moves = prog.moves.get(blk.first..blk.end).unwrap_or(&[]);
            let step = (moves.len() / 256).max(1);
            let pts = moves
                .iter()
                .step_by(step)
                .filter(|m| m.m.is_extruding())
                .map(|m| [m.m.to[axis::X], m.m.to[axis::Y]])
                .collect();
            ([p[axis::X], p[axis::Y]], pts)
        })
        .unzip()
}

/// The line spacing of the file's sparse infill: the mean (area / length) refined by the
/// spacing of its long lines ([`super::spacing::measured`]).
fn measured_spacing(prog: &Program, work: &[Work]) -> f64 {
    let a: f64 = work.iter().map(|w| w.region.area_mm2).sum();
    let l: f64 = work.iter().map(|w| w.target_mm).sum();
    let estimate = a / l;
    let lines: Vec<Line> = work
        .iter()
        .flat_map(|w| w.blocks.iter().map(move |&b| (w.layer, b)))
        .filter_map(|(layer, b)| prog.blocks.get(b).map(|blk| (layer, blk)))
        .flat_map(|(layer, blk)| {
            prog.moves
                .get(blk.first..blk.end)
                .unwrap_or(&[])
                .iter()
                .map(move |m| (layer, m))
        })
        .filter(|(_, m)| m.m.is_extruding() && m.m.length_mm > 3.0 * estimate)
        .map(|(layer, m)| {
            let (dx, dy) = (m.m.to[0] - m.m.from[0], m.m.to[1] - m.m.from[1]);
            Line {
                layer,
                dir_deg: crate::math::atan2(dy, dx).to_degrees().rem_euclid(180.0),
                mid: [
                    0.5 * (m.m.to[0] + m.m.from[0]),
                    0.5 * (m.m.to[1] + m.m.from[1]),
                ],
            }
        })
        .collect();
    super::spacing::measured(&lines, estimate).unwrap_or(estimate)
}

/// The print: from the first to the last move of a printed feature.
fn print_zone(prog: &Program) -> Option<(usize, usize)> {
    let printed = |i: &usize| {
        prog.moves.get(*i).is_some_and(|m| {
            m.layer != u32::MAX && !matches!(m.kind, None | Some(FeatureKind::Other))
        })
    };
    let first = (0..prog.moves.len()).find(printed);
    let last = (0..prog.moves.len()).rev().find(printed);
    first.zip(last)
}

/// A bed for a file that gives none: at least 200 × 200 mm from the origin, and wherever the
/// moves go.
fn bed_of_moves(prog: &Program) -> [f64; 4] {
    let all = bbox(
        prog.moves
            .iter()
            .map(|m| [m.m.to[0], m.m.to[1]])
            .collect::<Vec<_>>()
            .iter(),
    )
    .unwrap_or([0.0; 4]);
    [
        all[0].min(0.0),
        all[1].min(0.0),
        all[2].max(200.0),
        all[3].max(200.0),
    ]
}

impl Prepared<'_> {
    /// The rotation by `deg` that keeps the print on the bed, or `None` if it cannot fit.
    fn rotation(&self, deg: f64) -> Option<Option<Rotation>> {
        let turns = deg.rem_euclid(360.0);
        if turns.abs() < 1e-9 || (turns - 360.0).abs() < 1e-9 {
            return Some(None);
        }
        if self.prog.relative_xy {
            return None;
        }
        let (first, last) = self.zone?;
        let mut r = Rotation {
            cs: super::geom::cos_sin_deg(deg),
            centre: self.centre,
            shift: [0.0, 0.0],
            first,
            last,
        };
        let pts: Vec<P2> = self.prog.moves[first..=last]
            .iter()
            .map(|m| r.apply([m.m.to[0], m.m.to[1]]))
            .collect();
        let b = bbox(&pts)?;
        let bed = [
            self.bed[0] + BED_MARGIN_MM,
            self.bed[1] + BED_MARGIN_MM,
            self.bed[2] - BED_MARGIN_MM,
            self.bed[3] - BED_MARGIN_MM,
        ];
        for k in 0..2 {
            let (lo, hi) = (b[k], b[k + 2]);
            if hi - lo > bed[k + 2] - bed[k] {
                return None;
            }
            r.shift[k] = if lo < bed[k] {
                bed[k] - lo
            } else if hi > bed[k + 2] {
                bed[k + 2] - hi
            } else {
                0.0
            };
        }
        Some(Some(r))
    }

    /// New strokes of work item `w` (part frame), `pattern` at `beta` degrees in the part
    /// frame, with the spacing corrected once so the layer's extruded length matches.
    pub(crate) fn plan_layer(&self, w: &Work, pattern: Pattern, beta: f64) -> Vec<Path> {
        let make = |s: f64| {
            if pattern.is_lines() {
                return pattern::chains(&w.region.region, pattern, beta, s, w.layer);
            }
            let rows = pattern::generate(&w.region.region, pattern, beta, s, w.layer);
            link::link(
                rows,
                w.start,
                &w.region.region,
                3.0 * s,
                0.25 * self.clearance.max(0.05),
            )
        };
        // Target: the layer's nominal length (area / S), kept within 5 % of the original's
        // own length so the material of every layer stays put (slicers print first layers
        // wider and sparser, for one). Line families have the exact pitch by construction and
        // are accepted while within 7 % of the original; curves, whose length per area is only
        // about 1/S, must also be within 3 % of the target. Otherwise the pitch is corrected by
        // the length ratio (up to six times: rows are discrete); the closest result is kept.
        let orig = w.target_mm;
        let target = w.nominal_mm.clamp(0.95 * orig, 1.05 * orig);
        let mut s = self.spacing;
        let mut best: Option<(f64, Vec<Path>)> = None;
        for _ in 0..6 {
            let strokes = make(s);
            let len: f64 = strokes.iter().map(|s| path_len(s)).sum();
            let ratio = len / target;
            let err = (ratio - 1.0).abs();
            let in_band = (len / orig - 1.0).abs() <= 0.07;
            let good = in_band && (pattern.is_lines() || err <= 0.03);
            let better = best.as_ref().is_none_or(|b| err < b.0);
            if (better || good) && !strokes.is_empty() {
                best = Some((err, strokes));
            }
            if len.is_nan() || len <= 0.0 || good {
                break;
            }
            s *= ratio.clamp(0.5, 2.0);
        }
        best.map(|b| arrange(w, b.1)).unwrap_or_default()
    }

    /// The text of every replaced block for per-work-item strokes (what the written file
    /// gets; a replay makes the motions itself through [`Prepared::lazy`]).
    pub(crate) fn texts(
        &self,
        plans: &[&Vec<Path>],
        rotation: Option<&Rotation>,
    ) -> Vec<Option<String>> {
        self.slots(plans)
            .into_iter()
            .enumerate()
            .map(|(b, slot)| {
                let (wi, k) = slot?;
                let job = self.block_job(wi, plans.get(wi)?, k, b, rotation)?;
                Some(emit::block_text(&job))
            })
            .collect()
    }

    /// The candidate's replacements made one block at a time as a replay reaches them, so
    /// its motions are never all held at once (a Hilbert candidate's run to gigabytes).
    pub(crate) fn lazy<'s>(
        &'s self,
        plans: &'s [&'s Vec<Path>],
        rotation: Option<&'s Rotation>,
    ) -> LazyCandidate<'s> {
        LazyCandidate {
            prep: self,
            slots: self.slots(plans),
            plans,
            rotation,
        }
    }

    /// For each block of the file, the (work item, group of its plan) that replaces it: every
    /// block of a work item with a plan. An empty plan keeps the layer's original infill (a
    /// per-layer choice, or nothing generated in its region): never a layer without infill.
    fn slots(&self, plans: &[&Vec<Path>]) -> Vec<Option<(usize, usize)>> {
        let mut slots = vec![None; self.prog.blocks.len()];
        for (wi, (w, plan)) in self.work.iter().zip(plans).enumerate() {
            if plan.is_empty() {
                continue;
            }
            for (k, &b) in w.blocks.iter().enumerate() {
                if let Some(s) = slots.get_mut(b) {
                    *s = Some((wi, k));
                }
            }
        }
        slots
    }

    /// What block `b` is made from: group `k` of work item `wi`'s plan (groups, one per
    /// block, separated by empty paths), the block's start and end, all turned with the part,
    /// and the file's habits at the layer's flow.
    fn block_job<'s>(
        &'s self,
        wi: usize,
        plan: &[Path],
        k: usize,
        b: usize,
        rotation: Option<&Rotation>,
    ) -> Option<emit::Job<'s>> {
        let (w, block) = (self.work.get(wi)?, self.prog.blocks.get(b)?);
        let tf = |p: P2| rotation.map_or(p, |r| r.apply(p));
        let strokes: Vec<Path> = plan
            .split(|s| s.is_empty())
            .nth(k)
            .unwrap_or(&[])
            .iter()
            .map(|s| s.iter().map(|&p| tf(p)).collect())
            .collect();
        let p = block.machine.position();
        Some(emit::Job {
            block,
            strokes,
            start: tf([p[axis::X], p[axis::Y]]),
            end: tf([block.end_physical[0], block.end_physical[1]]),
            habit: Habit {
                e_per_mm: w.e_per_mm,
                ..self.habit
            },
        })
    }
}

/// A candidate whose blocks are made when a replay asks for them ([`Prepared::lazy`]).
pub(crate) struct LazyCandidate<'s> {
    prep: &'s Prepared<'s>,
    slots: Vec<Option<(usize, usize)>>,
    plans: &'s [&'s Vec<Path>],
    rotation: Option<&'s Rotation>,
}

impl Replacements for LazyCandidate<'_> {
    fn replaced(&self, b: usize) -> bool {
        self.slots.get(b).is_some_and(Option::is_some)
    }

    fn make(&self, b: usize) -> Option<Cow<'_, Replacement>> {
        let (wi, k) = (*self.slots.get(b)?)?;
        let plan = self.plans.get(wi)?;
        let job = self.prep.block_job(wi, plan, k, b, self.rotation)?;
        Some(Cow::Owned(emit::block_motions(&job)))
    }
}

/// A layer's strokes split between its blocks and ordered from where each block starts
/// ([`link::order`]), the blocks' groups separated by an empty path.
fn arrange(w: &Work, strokes: Vec<Path>) -> Vec<Path> {
    let groups = link::split_blocks(strokes, &w.anchors);
    let mut out = Vec::new();
    for (k, g) in groups.into_iter().enumerate() {
        if k > 0 {
            out.push(Path::new());
        }
        let start = w.starts.get(k).copied().unwrap_or(w.start);
        out.extend(link::order(g, start));
    }
    out
}

pub(crate) fn score(objective: Objective, w: &super::Weights, c: &Costs, base: &Costs) -> f64 {
    let rel = |a: f64, b: f64| if b > 0.0 { a / b } else { a };
    match objective {
        Objective::Energy => c.total_j,
        Objective::Time => c.time_s,
        Objective::Length => c.length_mm,
        Objective::Weighted => {
            w.energy * rel(c.total_j, base.total_j)
                + w.time * rel(c.time_s, base.time_s)
                + w.length * rel(c.length_mm, base.length_mm)
        }
    }
}

/// [`infill`] with a progress callback (fraction of candidates costed; `false` cancels).
///
/// The original file is the reference every candidate must beat: the best candidate is
/// written, analysed as `analyze` would, and kept only if it costs less than the input on the
/// objective; otherwise the input is returned unchanged with `best.pattern = original` and a
/// message (unless [`InfillOptions::force_candidate`]).
pub fn infill_with_progress(
    input: &[u8],
    options: &InfillOptions,
    progress: Progress<'_>,
) -> Result<InfillReport, Error> {
    let _curves = pattern::curves::CurveCacheScope;
    let prep = prepare(input, options)?;
    let base_costs = replay(&prep.prog, &[] as &[Option<Replacement>], None, &prep.base);
    let (rotations, rotations_skipped) = rotations_of(&prep, options)?;
    let searched = super::rounds::search(&prep, options, &rotations, &base_costs, progress)?;
    let Some((best_score, bi)) = searched.best else {
        return Err(invalid("no candidate"));
    };
    let chosen = searched.candidates[bi].clone();
    let rotation = rotations
        .iter()
        .find(|(d, _)| *d == chosen.rotation_deg)
        .and_then(|(_, r)| *r);
    let written = write_chosen(
        &prep,
        options,
        &chosen,
        rotation.as_ref(),
        best_score,
        &base_costs,
    );
    let after = analyze(&written.output, &options.analyze)?;
    progress(1.0);
    let mut best = best_of(
        &chosen,
        &written.costs,
        prep.before.energy.total_j,
        written.layers,
    );
    let verdict = Verdict::of(options, &prep.before, &after);
    let (output, after) = if verdict.beats || options.force_candidate {
        best.message =
            (!verdict.beats).then(|| verdict.describe(&best, "written anyway (force_candidate)"));
        measured_as_written(&mut best, &prep.before, &after);
        with_estimates(options, &best, written.output, after)?
    } else {
        best = original_kept(
            &prep.before,
            verdict.describe(
                &best,
                "the original is kept (force_candidate writes it anyway)",
            ),
        );
        (input.to_vec(), prep.before.clone())
    };
    let measured = measured(&prep);
    Ok(InfillReport {
        before: prep.before,
        after,
        best,
        candidates: searched.candidates,
        candidates_skipped: searched.skipped,
        candidates_estimated: searched.estimated,
        measured,
        rotations_skipped,
        output,
    })
}

/// The rotations that keep the part on the bed, and those that do not.
#[allow(clippy::type_complexity)]
fn rotations_of(
    prep: &Prepared<'_>,
    options: &InfillOptions,
) -> Result<(Vec<(f64, Option<Rotation>)>, Vec<f64>), Error> {
    let mut rotations = Vec::new();
    let mut skipped = Vec::new();
    for &deg in &options.rotations_deg {
        match prep.rotation(deg) {
            Some(r) => rotations.push((deg, r)),
            None => skipped.push(deg),
        }
    }
    if rotations.is_empty() {
        return Err(invalid("no rotation keeps the part on the bed"));
    }
    Ok((rotations, skipped))
}

/// The chosen candidate (or its per-layer hybrid, when asked and cheaper) as G-code.
struct Written {
    output: Vec<u8>,
    costs: Costs,
    layers: Option<Vec<super::LayerChoice>>,
}

fn write_chosen(
    prep: &Prepared<'_>,
    options: &InfillOptions,
    chosen: &Candidate,
    rotation: Option<&Rotation>,
    best_score: f64,
    base_costs: &Costs,
) -> Written {
    let beta = chosen.angle_deg - chosen.rotation_deg;
    let mut plans: Vec<Vec<Path>> =
        crate::parallel::map_each(&prep.work, |w| prep.plan_layer(w, chosen.pattern, beta));
    let mut layers = None;
    let mut costs = Costs {
        time_s: chosen.time_s,
        thesis_j: chosen.thesis_j,
        total_j: chosen.total_j,
        length_mm: chosen.length_mm,
        filament_mm: chosen.filament_mm,
        infill: Default::default(),
    };
    if options.per_layer {
        if let Some((hybrid, choices, hybrid_costs)) =
            super::hybrid::per_layer(prep, options, chosen, rotation)
        {
            if score(
                options.objective,
                &options.weights,
                &hybrid_costs,
                base_costs,
            ) < best_score
            {
                plans = hybrid;
                layers = Some(choices);
                costs = hybrid_costs;
            }
        }
    }
    let refs: Vec<&Vec<Path>> = plans.iter().collect();
    let texts = prep.texts(&refs, rotation);
    let edits = write::edits(prep.input, &prep.prog, &texts, rotation);
    Written {
        output: crate::gcode::apply_edits(prep.input, &edits),
        costs,
        layers,
    }
}

/// The written file with true time estimates (when asked and the file has any), and its
/// analysis.
fn with_estimates(
    options: &InfillOptions,
    best: &Best,
    output: Vec<u8>,
    after: Report,
) -> Result<(Vec<u8>, Report), Error> {
    if !options.estimates {
        return Ok((output, after));
    }
    let note = format!(
        "infill: {} at {}° (part turned {}°)",
        best.pattern.name(),
        best.angle_deg,
        best.rotation_deg
    );
    let refreshed = crate::estimate::refresh(&output, &options.analyze, &note, Some(&after))?;
    Ok(refreshed.unwrap_or((output, after)))
}

/// Whether the written file beats the original on the objective, both as `analyze` costs
/// them: the rule that no file handed back is dearer than the one given.
struct Verdict {
    objective: Objective,
    beats: bool,
    /// The written file's score over the original's, minus one (`0.012`: 1.2 % dearer).
    change: f64,
}

impl Verdict {
    fn of(options: &InfillOptions, before: &Report, after: &Report) -> Self {
        let b = report_costs(before);
        let a = report_costs(after);
        let sb = score(options.objective, &options.weights, &b, &b);
        let sa = score(options.objective, &options.weights, &a, &b);
        Self {
            objective: options.objective,
            beats: sa < sb,
            change: if sb > 0.0 { sa / sb - 1.0 } else { 0.0 },
        }
    }

    fn describe(&self, best: &Best, outcome: &str) -> String {
        let objective = match self.objective {
            Objective::Energy => "energy",
            Objective::Time => "time",
            Objective::Length => "toolpath length",
            Objective::Weighted => "the weighted objective",
        };
        format!(
            "no candidate beats the original on {objective}: the best, {} at {}° (part turned {}°), \
             is {:+.2} % against the original; {outcome}",
            best.pattern.name(),
            best.angle_deg,
            best.rotation_deg,
            100.0 * self.change
        )
    }
}

/// `best`'s numbers as `analyze` gives them for the written file (the search's replay of a
/// candidate can differ from it in the last few tenths of a percent).
fn measured_as_written(best: &mut Best, before: &Report, after: &Report) {
    best.thesis_j = after.energy.thesis_j;
    best.total_j = after.energy.total_j;
    best.time_s = after.time_s;
    best.length_mm = after.distance_mm;
    best.saving_j = before.energy.total_j - after.energy.total_j;
    best.saving_pct = if before.energy.total_j > 0.0 {
        100.0 * best.saving_j / before.energy.total_j
    } else {
        0.0
    };
}

/// A report's numbers in the form candidates are scored in.
fn report_costs(r: &Report) -> Costs {
    Costs {
        time_s: r.time_s,
        thesis_j: r.energy.thesis_j,
        total_j: r.energy.total_j,
        length_mm: r.distance_mm,
        filament_mm: r.filament_mm,
        infill: Default::default(),
    }
}

/// The report's best when the original is kept: its own numbers, no saving.
fn original_kept(before: &Report, message: String) -> Best {
    Best {
        pattern: Choice::Original,
        angle_deg: 0.0,
        rotation_deg: 0.0,
        thesis_j: before.energy.thesis_j,
        total_j: before.energy.total_j,
        time_s: before.time_s,
        length_mm: before.distance_mm,
        saving_j: 0.0,
        saving_pct: 0.0,
        layers: None,
        message: Some(message),
    }
}

/// The report's best candidate: `chosen` with the costs `result` it was written with.
fn best_of(
    chosen: &Candidate,
    result: &Costs,
    before_j: f64,
    layers: Option<Vec<super::LayerChoice>>,
) -> Best {
    Best {
        pattern: Choice::Pattern(chosen.pattern),
        angle_deg: chosen.angle_deg,
        rotation_deg: chosen.rotation_deg,
        thesis_j: result.thesis_j,
        total_j: result.total_j,
        time_s: result.time_s,
        length_mm: result.length_mm,
        saving_j: before_j - result.total_j,
        saving_pct: if before_j > 0.0 {
            100.0 * (before_j - result.total_j) / before_j
        } else {
            0.0
        },
        layers,
        message: None,
    }
}

/// What the search measured of the file.
fn measured(prep: &Prepared<'_>) -> Measured {
    Measured {
        spacing_mm: prep.spacing,
        clearance_mm: prep.clearance,
        e_per_mm: prep.habit.e_per_mm,
        layers_regenerated: prep.work.len(),
        blocks: prep.work.iter().map(|w| w.blocks.len()).sum(),
        print_feed_mm_s: prep.habit.print_f / 60.0,
        travel_feed_mm_s: prep.habit.travel_f / 60.0,
        retract_mm: prep.habit.retract_mm,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn rect(angle: u32) -> Vec<u8> {
        let path = format!(
            "{}/tests/data/rect_infill_{angle}.gcode",
            env!("CARGO_MANIFEST_DIR")
        );
        std::fs::read(path).expect("fixture")
    }

    #[test]
    fn replay_of_the_original_is_analyze() {
        let input = rect(45);
        let prep = prepare(&input, &InfillOptions::default()).expect("prepare");
        let c = replay(&prep.prog, &[] as &[Option<Replacement>], None, &prep.base);
        let r = &prep.before;
        assert!(
            (c.time_s - r.time_s).abs() < 1e-9 * r.time_s,
            "{} vs {}",
            c.time_s,
            r.time_s
        );
        assert!((c.thesis_j - r.energy.thesis_j).abs() < 1e-9 * r.energy.thesis_j);
        assert!((c.total_j - r.energy.total_j).abs() < 1e-9 * r.energy.total_j);
        assert!((c.filament_mm - r.filament_mm).abs() < 1e-9);
        assert_eq!(prep.work.len(), 25);
        // PrusaSlicer's 20 % of a 0.45 mm line: about 2 mm.
        assert!((prep.spacing - 2.0).abs() < 0.3, "{}", prep.spacing);
    }

    /// The motions a replay costs a block with are those of its text parsed back, bit for bit:
    /// every block of the fixture, two patterns, with and without a part rotation.
    #[test]
    fn block_motions_are_the_text_parsed_back() {
        let input = rect(45);
        let prep = prepare(&input, &InfillOptions::default()).expect("prepare");
        let turned = prep.rotation(30.0).flatten();
        assert!(turned.is_some());
        let mut blocks = 0;
        for pattern in [Pattern::Rectilinear, Pattern::Hilbert] {
            for rotation in [None, turned.as_ref()] {
                for (wi, w) in prep.work.iter().enumerate() {
                    let plan = prep.plan_layer(w, pattern, 15.0);
                    for (k, &b) in w.blocks.iter().enumerate() {
                        let job = prep.block_job(wi, &plan, k, b, rotation).expect("job");
                        let text = emit::block_text(&job);
                        let parsed = emit::motions(job.block, &text, job.start);
                        assert_eq!(parsed, emit::block_motions(&job), "block {b}");
                        blocks += 1;
                    }
                }
            }
        }
        assert!(blocks >= 100, "{blocks}");
    }
}
