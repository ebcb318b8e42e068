//! The candidates of a search costed in rounds, in parallel natively.
//!
//! A pattern's part-frame angles (machine angle minus part rotation) are taken as many at a
//! time as there are threads: the round's strokes are generated one angle a thread, each
//! compared with the geometries seen before (a repeat — concentric loops at any angle, a
//! symmetric pattern — is costed once per rotation and counted as skipped), the new (geometry,
//! rotation) pairs are replayed one a thread, and the strokes are dropped. Memory holds one
//! round's strokes, not a pattern's; the candidates, their order and the best are those a
//! sequential run gives, bit for bit.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};

use super::cost::{replay, Costs, Rotation};
use super::geom::Path;
use super::search::{score, Prepared};
use super::{Candidate, InfillOptions, Pattern};
use crate::error::{Error, ErrorKind};
use crate::progress::Progress;

/// Every (pattern, angle, rotation) costed.
pub(crate) struct Searched {
    pub candidates: Vec<Candidate>,
    /// Score and index of the best candidate.
    pub best: Option<(f64, usize)>,
    /// Candidates whose geometry repeated an earlier one's: listed with its costs, not replayed.
    pub skipped: usize,
}

/// Key of a part-frame angle (millidegrees in [0, 360)); every angle of concentric loops,
/// which do not depend on it, shares key 0.
fn angle_key(pattern: Pattern, beta: f64) -> i64 {
    if pattern == Pattern::Concentric {
        return 0;
    }
    (beta.rem_euclid(360.0) * 1000.0).round() as i64 % 360_000
}

/// A fingerprint of a geometry's strokes: equal strokes give equal fingerprints, and two
/// different stroke sets share one with odds of 2⁻⁶⁴, so the strokes need not be kept to
/// recognise a repeat.
fn fingerprint(plans: &[Vec<Path>]) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for layer in plans {
        layer.len().hash(&mut h);
        for path in layer {
            path.len().hash(&mut h);
            for p in path {
                p[0].to_bits().hash(&mut h);
                p[1].to_bits().hash(&mut h);
            }
        }
    }
    h.finish()
}

/// One pattern's geometries: which key maps to which geometry, and the costs of each
/// (geometry, rotation index) replayed.
#[derive(Default)]
struct Geometries {
    by_key: HashMap<i64, usize>,
    fingerprints: Vec<u64>,
    costed: HashMap<(usize, usize), Costs>,
}

impl Geometries {
    /// Generates the strokes of the round's keys, files each under its geometry and costs the
    /// (geometry, rotation) pairs of `wanted` not costed before.
    fn round(
        &mut self,
        prep: &Prepared<'_>,
        pattern: Pattern,
        keys: &[(i64, f64)],
        wanted: &[(i64, usize)],
        rotations: &[(f64, Option<Rotation>)],
    ) {
        let plans: Vec<Vec<Vec<Path>>> = crate::parallel::map_each(keys, |&(_, beta)| {
            prep.work
                .iter()
                .map(|w| prep.plan_layer(w, pattern, beta))
                .collect()
        });
        let mut holder: HashMap<usize, usize> = HashMap::new();
        for (k, plan) in plans.iter().enumerate() {
            let f = fingerprint(plan);
            let g = match self.fingerprints.iter().position(|&x| x == f) {
                Some(g) => g,
                None => {
                    self.fingerprints.push(f);
                    self.fingerprints.len() - 1
                }
            };
            self.by_key.insert(keys[k].0, g);
            holder.entry(g).or_insert(k);
        }
        let mut jobs: Vec<(usize, usize, usize)> = Vec::new();
        for &(key, ri) in wanted {
            let Some(&g) = self.by_key.get(&key) else {
                continue;
            };
            let fresh =
                !self.costed.contains_key(&(g, ri)) && !jobs.iter().any(|j| (j.0, j.2) == (g, ri));
            if let (true, Some(&k)) = (fresh, holder.get(&g)) {
                jobs.push((g, k, ri));
            }
        }
        let costs = crate::parallel::map_each(&jobs, |&(_, k, ri)| {
            let refs: Vec<&Vec<Path>> = plans[k].iter().collect();
            let rotation = rotations.get(ri).and_then(|r| r.1.as_ref());
            replay(
                &prep.prog,
                &prep.lazy(&refs, rotation),
                rotation,
                &prep.base,
            )
        });
        for (&(g, _, ri), c) in jobs.iter().zip(costs) {
            self.costed.insert((g, ri), c);
        }
    }
}

/// Every (pattern, angle, rotation) costed against `base_costs`, with the score and index of
/// the best; `progress` hears the fraction of angles done after each round (`false` cancels).
pub(crate) fn search(
    prep: &Prepared<'_>,
    options: &InfillOptions,
    rotations: &[(f64, Option<Rotation>)],
    base_costs: &Costs,
    progress: Progress<'_>,
) -> Result<Searched, Error> {
    let per_round = crate::parallel::threads().max(1);
    let total = options.patterns.len() * options.angles_deg.len() * rotations.len();
    let mut out = Searched {
        candidates: Vec::with_capacity(total),
        best: None,
        skipped: 0,
    };
    let mut done = 0usize;
    for &pattern in &options.patterns {
        // (angle, rotation index, key) in the order candidates are listed.
        let slots: Vec<(f64, usize, i64)> = options
            .angles_deg
            .iter()
            .flat_map(|&a| {
                rotations
                    .iter()
                    .enumerate()
                    .map(move |(ri, r)| (a, ri, angle_key(pattern, a - r.0)))
            })
            .collect();
        let mut keys: Vec<(i64, f64)> = Vec::new();
        for &(a, ri, key) in &slots {
            if !keys.iter().any(|k| k.0 == key) {
                keys.push((key, a - rotations[ri].0));
            }
        }
        let mut geometries = Geometries::default();
        for round in keys.chunks(per_round) {
            if !progress(done as f64 / total as f64) {
                return Err(Error::new(0, 0, ErrorKind::Cancelled));
            }
            let wanted: Vec<(i64, usize)> = slots
                .iter()
                .filter(|s| round.iter().any(|k| k.0 == s.2))
                .map(|s| (s.2, s.1))
                .collect();
            geometries.round(prep, pattern, round, &wanted, rotations);
            done += wanted.len();
        }
        list(
            &mut out,
            options,
            pattern,
            &slots,
            &geometries,
            rotations,
            base_costs,
        );
    }
    Ok(out)
}

/// Appends a pattern's candidates in slot order, counting repeats and keeping the best.
fn list(
    out: &mut Searched,
    options: &InfillOptions,
    pattern: Pattern,
    slots: &[(f64, usize, i64)],
    geometries: &Geometries,
    rotations: &[(f64, Option<Rotation>)],
    base_costs: &Costs,
) {
    let mut seen: Vec<(usize, usize)> = Vec::new();
    for &(angle, ri, key) in slots {
        let Some(&g) = geometries.by_key.get(&key) else {
            continue;
        };
        let Some(c) = geometries.costed.get(&(g, ri)) else {
            continue;
        };
        if seen.contains(&(g, ri)) {
            out.skipped += 1;
        } else {
            seen.push((g, ri));
        }
        let s = score(options.objective, &options.weights, c, base_costs);
        if out.best.is_none_or(|(b, _)| s < b) {
            out.best = Some((s, out.candidates.len()));
        }
        out.candidates
            .push(candidate_of(pattern, angle, rotations[ri].0, c));
    }
}

fn candidate_of(pattern: Pattern, angle_deg: f64, rotation_deg: f64, c: &Costs) -> Candidate {
    Candidate {
        pattern,
        angle_deg,
        rotation_deg,
        thesis_j: c.thesis_j,
        total_j: c.total_j,
        time_s: c.time_s,
        length_mm: c.length_mm,
        filament_mm: c.filament_mm,
        infill_length_mm: c.infill.l_total_mm,
        infill_turning_points: c.infill.n_turning,
        infill_mean_turn_deg: c.infill.mean_turn_deg,
    }
}
