//! The thesis's hybrid: a pattern and angle chosen layer by layer.
//!
//! Each (pattern, angle) is replayed once at the chosen rotation with the planner and energy
//! model, summing per replaced block its servo energy and its time; a layer's cost is
//! `servo J + (auxiliary power) × time`, the auxiliary power being the original file's average
//! (`aux_j / time_s`). Each layer takes its cheapest option, and the assembled hybrid is replayed
//! as a whole for its true numbers (junction coupling between layers and the fuse energy of the
//! material included); the caller keeps it only if it beats the single best.
//!
//! The original infill of each layer is one of its options, costed by the same replay: a layer
//! that no candidate beats keeps its own infill (`pattern: "original"` in its choice).

use super::cost::{replay, replay_blocks, Costs, Replacement, Rotation};
use super::geom::Path;
use super::search::Prepared;
use super::{Candidate, Choice, InfillOptions, LayerChoice};

/// A layer's best so far: cost, pattern (or the original), angle, strokes (empty: the
/// original's blocks are kept).
type Slot = (f64, Choice, f64, Vec<Path>);

/// The per-layer plans, choices and whole-file costs of the hybrid.
pub(crate) fn per_layer(
    prep: &Prepared<'_>,
    options: &InfillOptions,
    chosen: &Candidate,
    rotation: Option<&Rotation>,
) -> Option<(Vec<Vec<Path>>, Vec<LayerChoice>, Costs)> {
    let aux_w = if prep.before.time_s > 0.0 {
        prep.before.energy.aux_j / prep.before.time_s
    } else {
        0.0
    };
    let n = prep.work.len();
    let mut per_block = Vec::new();
    // The original layers first: every block as the file has it.
    let original: Vec<Option<Replacement>> = vec![None; prep.prog.blocks.len()];
    replay_blocks(
        &prep.prog,
        original.as_slice(),
        rotation,
        &prep.base,
        Some(&mut per_block),
    );
    let layer_cost = |w: &super::search::Work, per_block: &[[f64; 2]]| -> f64 {
        w.blocks
            .iter()
            .filter_map(|&b| per_block.get(b))
            .map(|[j, t]| j + aux_w * t)
            .sum()
    };
    // (cost, pattern, angle, plan) per work item.
    let mut best: Vec<Option<Slot>> = prep
        .work
        .iter()
        .map(|w| Some((layer_cost(w, &per_block), Choice::Original, 0.0, Vec::new())))
        .collect();
    for &pattern in &options.patterns {
        for &angle in &options.angles_deg {
            let beta = angle - chosen.rotation_deg;
            let plans: Vec<Vec<Path>> = prep
                .work
                .iter()
                .map(|w| prep.plan_layer(w, pattern, beta))
                .collect();
            let refs: Vec<&Vec<Path>> = plans.iter().collect();
            replay_blocks(
                &prep.prog,
                &prep.lazy(&refs, rotation),
                rotation,
                &prep.base,
                Some(&mut per_block),
            );
            for ((w, plan), slot) in prep.work.iter().zip(plans).zip(best.iter_mut()) {
                let cost = layer_cost(w, &per_block);
                if !plan.is_empty() && slot.as_ref().is_none_or(|s| cost < s.0) {
                    *slot = Some((cost, Choice::Pattern(pattern), angle, plan));
                }
            }
        }
    }
    let mut plans = Vec::with_capacity(n);
    let mut choices = Vec::with_capacity(n);
    for (w, slot) in prep.work.iter().zip(best) {
        let (_, pattern, angle_deg, plan) = slot?;
        plans.push(plan);
        choices.push(LayerChoice {
            layer: w.layer,
            pattern,
            angle_deg,
        });
    }
    let refs: Vec<&Vec<Path>> = plans.iter().collect();
    let costs = replay(
        &prep.prog,
        &prep.lazy(&refs, rotation),
        rotation,
        &prep.base,
    );
    Some((plans, choices, costs))
}
