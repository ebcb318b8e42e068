//! The candidates of a search costed in rounds, in parallel natively.
//!
//! A pattern's part-frame angles (machine angle minus part rotation) are taken as many at a
//! time as there are threads: the round's strokes are generated one angle a thread, each
//! compared with the geometries seen before (a repeat — concentric loops at any angle, a
//! symmetric pattern — is costed once per rotation and counted as skipped), the new (geometry,
//! rotation) pairs are replayed one a thread, and the strokes are dropped. Memory holds one
//! round's strokes, not a pattern's; the candidates, their order and the best are those a
//! sequential run gives, bit for bit. Before a round is costed whole, its keys may be ruled out
//! on a sample of layers ([`racing`]), judged against the best of the earlier patterns so that
//! the outcome does not depend on how many keys a round holds.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};

use super::cost::{replay, Costs, Replacement, Rotation};
use super::geom::Path;
use super::racing::{self, Probe};
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
    /// Candidates ruled out on a sample of layers: listed with their estimated costs.
    pub estimated: usize,
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
    /// Estimated costs of the (key, rotation index) pairs ruled out on a sample of layers.
    estimated: HashMap<(i64, usize), Costs>,
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
        estimated: 0,
    };
    let mut race = Race::new(prep, options, rotations, base_costs);
    let judge = |c: &Costs| score(options.objective, &options.weights, c, base_costs);
    let mut done = 0usize;
    for &pattern in &options.patterns {
        let (slots, keys) = slots_and_keys(options, pattern, rotations);
        let mut geometries = Geometries::default();
        // Sampling stops for the pattern at its first key that survives it: a pattern that
        // competes with the best would pay for every sample on top of its whole-file costs.
        let mut sampling = true;
        race.start_pattern();
        for round in keys.chunks(per_round) {
            if !progress(done as f64 / total as f64) {
                return Err(Error::new(0, 0, ErrorKind::Cancelled));
            }
            let wanted: Vec<(i64, usize)> = slots
                .iter()
                .filter(|s| round.iter().any(|k| k.0 == s.2))
                .map(|s| (s.2, s.1))
                .collect();
            let whole = if sampling {
                race.sample(&mut geometries, pattern, round, &wanted, &judge)
            } else {
                round.to_vec()
            };
            // A survivor and every key after it are costed whole.
            sampling &= whole.is_empty();
            geometries.round(prep, pattern, &whole, &wanted, rotations);
            race.saw(&geometries, &wanted, &judge);
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

/// A pattern's slots, (angle, rotation index, key) in the order candidates are listed, and its
/// distinct keys with their part-frame angles.
#[allow(clippy::type_complexity)]
fn slots_and_keys(
    options: &InfillOptions,
    pattern: Pattern,
    rotations: &[(f64, Option<Rotation>)],
) -> (Vec<(f64, usize, i64)>, Vec<(i64, f64)>) {
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
    (slots, keys)
}

/// What ruling candidates out needs: the samples, the original's costs at each rotation, and
/// the best exact score so far.
struct Race<'a> {
    prep: &'a Prepared<'a>,
    rotations: &'a [(f64, Option<Rotation>)],
    /// The samples, coarse first ([`racing::COARSE`], [`racing::FINE`]); none for a part too
    /// thin to sample, and a coarse one only for a tall part.
    probes: Vec<Probe>,
    /// The original's whole-file costs at each rotation.
    bases: Vec<Costs>,
    best_exact: Option<f64>,
    /// The best exact score when the current pattern started.
    threshold: Option<f64>,
}

impl<'a> Race<'a> {
    fn new(
        prep: &'a Prepared<'a>,
        options: &InfillOptions,
        rotations: &'a [(f64, Option<Rotation>)],
        base_costs: &Costs,
    ) -> Self {
        // One pattern is never sampled (nothing exact comes before it): no sample, and no
        // replays of the original at every rotation for one.
        let fine = if options.exhaustive || options.patterns.len() < 2 {
            None
        } else {
            Probe::of(prep, racing::FINE, rotations)
        };
        let mut probes = Vec::new();
        if let Some(fine) = fine {
            probes.extend(Probe::of(prep, racing::COARSE, rotations));
            probes.push(fine);
        }
        let bases = if probes.is_empty() {
            Vec::new()
        } else {
            crate::parallel::map_each(rotations, |(_, r)| match r {
                None => *base_costs,
                Some(r) => replay(
                    &prep.prog,
                    &[] as &[Option<Replacement>],
                    Some(r),
                    &prep.base,
                ),
            })
        };
        Self {
            prep,
            rotations,
            probes,
            bases,
            best_exact: None,
            threshold: None,
        }
    }

    /// Estimates the round's keys on the samples of layers and files in `g` those whose every
    /// wanted rotation is ruled out against the best exact score ([`racing`]); the keys left
    /// to cost whole (all of them before anything is exact, or without a sample).
    fn sample(
        &self,
        g: &mut Geometries,
        pattern: Pattern,
        keys: &[(i64, f64)],
        wanted: &[(i64, usize)],
        judge: &dyn Fn(&Costs) -> f64,
    ) -> Vec<(i64, f64)> {
        if self.probes.is_empty() || self.threshold.is_none() {
            return keys.to_vec();
        }
        // One sample per (key, rotation): every angle of concentric loops shares a key.
        let mut pairs: Vec<(i64, f64, usize)> = Vec::new();
        for &(key, beta) in keys {
            for &(k, ri) in wanted {
                if k == key && !pairs.iter().any(|p| (p.0, p.2) == (key, ri)) {
                    pairs.push((key, beta, ri));
                }
            }
        }
        let verdicts = self.verdicts(pattern, &pairs, judge);
        // In key order up to the first survivor, whatever the round's size: the same
        // candidates are ruled out on one thread (wasm) as on many.
        let mut left = Vec::new();
        for &(key, beta) in keys {
            let mine: Vec<(usize, &(Costs, bool))> = pairs
                .iter()
                .zip(&verdicts)
                .filter(|(p, _)| p.0 == key)
                .map(|(p, v)| (p.2, v))
                .collect();
            if left.is_empty() && !mine.is_empty() && mine.iter().all(|(_, v)| v.1) {
                for (ri, v) in mine {
                    g.estimated.insert((key, ri), v.0);
                }
            } else {
                left.push((key, beta));
            }
        }
        left
    }

    /// Each pair's estimate and whether it is ruled out: on the coarse sample first, and on
    /// the next sample for those the coarse one leaves in.
    fn verdicts(
        &self,
        pattern: Pattern,
        pairs: &[(i64, f64, usize)],
        judge: &dyn Fn(&Costs) -> f64,
    ) -> Vec<(Costs, bool)> {
        let mut verdicts: Vec<Option<(Costs, bool)>> = vec![None; pairs.len()];
        for (n, probe) in self.probes.iter().enumerate() {
            let last = n + 1 == self.probes.len();
            let open: Vec<usize> = (0..pairs.len())
                .filter(|&i| verdicts[i].is_none())
                .collect();
            let estimates = crate::parallel::map_each(&open, |&i| {
                let (_, beta, ri) = pairs[i];
                let rotation = self.rotations.get(ri).and_then(|r| r.1.as_ref());
                let base = self.bases.get(ri).copied().unwrap_or_default();
                probe.estimate(self.prep, (pattern, beta), (ri, rotation), &base)
            });
            for (&i, e) in open.iter().zip(estimates) {
                let base = self.bases.get(pairs[i].2).copied().unwrap_or_default();
                let scores = racing::Scores {
                    estimate: judge(&e.costs),
                    original: judge(&base),
                    halves: e.halves.each_ref().map(judge),
                };
                let out = racing::ruled_out(&scores, self.threshold, probe.margin);
                if out || last {
                    verdicts[i] = Some((e.costs, out));
                }
            }
        }
        verdicts
            .into_iter()
            .map(Option::unwrap_or_default)
            .collect()
    }

    /// Starts a pattern: its candidates are judged against the best exact score of the
    /// patterns before it (not of its own earlier rounds, whose size depends on the threads).
    fn start_pattern(&mut self) {
        self.threshold = self.best_exact;
    }

    /// Takes the round's exact costs into the best score so far.
    fn saw(&mut self, g: &Geometries, wanted: &[(i64, usize)], judge: &dyn Fn(&Costs) -> f64) {
        for &(key, ri) in wanted {
            let exact = g.by_key.get(&key).and_then(|&gi| g.costed.get(&(gi, ri)));
            if let Some(c) = exact {
                let s = judge(c);
                if self.best_exact.is_none_or(|b| s < b) {
                    self.best_exact = Some(s);
                }
            }
        }
    }
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
        let rotation_deg = rotations[ri].0;
        if let Some(c) = geometries.estimated.get(&(key, ri)) {
            out.estimated += 1;
            out.candidates
                .push(candidate_of(pattern, angle, rotation_deg, c, true));
            continue;
        }
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
            .push(candidate_of(pattern, angle, rotation_deg, c, false));
    }
}

fn candidate_of(
    pattern: Pattern,
    angle_deg: f64,
    rotation_deg: f64,
    c: &Costs,
    estimated: bool,
) -> Candidate {
    Candidate {
        estimated,
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
