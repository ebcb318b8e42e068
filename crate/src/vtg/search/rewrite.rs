//! Finding the extrusion paths of a file and replacing their lines.
//!
//! A path here is a run of consecutive printing `G1` moves of one feature and layer whose lines
//! follow each other with nothing between them (a comment, fan change or `F`-only line ends
//! the run, so every non-motion line stays where it was). Only paths with a turn above the
//! critical angle are rewritten: a path without sharp corners has nothing to suppress.
//!
//! Material: the new points carry the filament the original path had pushed at the same arc
//! length (the fit is parametrised by the original's arc length), so each stretch keeps its
//! filament and the path's total is unchanged. In absolute mode the block ends on the original
//! last `E` word exactly, so every later line stays valid; in relative mode the written amounts
//! are differences of rounded running totals and add up to the original total.

use super::Variant;
use crate::energy::Accumulator;
use crate::error::{Error, ErrorKind};
use crate::gcode::{apply_edits, Edit};
use crate::machine::{ExtrusionMode, MoveKind};
use crate::path::{PathMove, PrintPath};
use crate::plan::{JunctionModel, Limits, Motion, Planner, Profile};
use crate::vec3::{dot, norm, sub};
use crate::vtg::arcs::{self, Piece};
use crate::vtg::block::{self, Frame};
use crate::vtg::budget::{self, Budget, Offer, Outcome};
use crate::vtg::deviation::both_ways;
use crate::vtg::feed::Way;
use crate::vtg::feed::Written;
use crate::vtg::kinematics::KinematicLimits;
use crate::vtg::resample::WalkStats;
use crate::vtg::smooth::{share_dependence, smooth_path, Settings, SmoothPath, Smoothed};
use crate::vtg::smoothings::{Pending, Smoothing, SmoothingKey, Smoothings};
use crate::vtg::source::{MoveSource, Sources};
use crate::vtg::tuning::TUNING;
use crate::vtg::VtgOptions;

/// What the rewrite did.
#[derive(Debug, Clone, Default)]
pub(crate) struct Rewritten {
    /// The new file.
    pub(crate) output: Vec<u8>,
    /// Paths with a sharp corner (candidates).
    pub(crate) candidate_paths: u64,
    /// Of those, paths rewritten.
    pub(crate) rewritten_paths: u64,
    /// Moves replaced.
    pub(crate) replaced_moves: u64,
    /// Moves written in their place.
    pub(crate) written_moves: u64,
    /// Sharp corners the rewrites written remove, by their own count (set by
    /// [`Offers::write`]; a race's trial is not analysed, [`crate::vtg::closed_loop`]).
    pub(crate) corners_removed: u64,
    /// Segments whose feed was lowered (VTG eq. 29).
    pub(crate) lowered_segments: u64,
    /// Segments whose curvature stays above `K_cr`.
    pub(crate) above_k_cr_segments: u64,
    /// Largest measured distance of a rewritten path from its original, mm.
    pub(crate) max_deviation_mm: f64,
    /// Rewritten paths whose VTG eq. 29 feed caps were raised so they cost no time.
    pub(crate) raised_caps_paths: u64,
    /// Rewritten paths written without the VTG eq. 29 feed caps, which even raised would have made
    /// them slower than the original.
    pub(crate) uncapped_paths: u64,
    /// Rewritten paths that plan slower or cost more motor energy than the original, paid for
    /// out of what the other rewrites saved or with the time the options allow (see
    /// [`crate::vtg::budget`]).
    pub(crate) paid_paths: u64,
    /// Paths kept as they were because even rounded without caps they plan slower or cost more
    /// motor energy, and the savings elsewhere could not pay for them.
    pub(crate) kept_for_time: u64,
    /// Paths kept as they were because rounding them would add more lines than the file's
    /// line budget has left ([`budget::free_within_lines`]).
    pub(crate) kept_for_lines: u64,
    /// Algorithm 1 statistics.
    pub(crate) walk: WalkStats,
    /// The first scale of the VTG eq. 29 speeds each rewrite was tried with.
    pub(crate) feed_cap_scale: f64,
    /// Whether the walked steps were joined up to the segment budget ([`Variant::thin`]).
    pub(crate) steps_joined: bool,
    /// Whether joined segments were offered speeds for their stretch ([`Variant::stretch`]).
    pub(crate) stretch_caps: bool,
    /// Arcs (`G2`/`G3`) written.
    pub(crate) arcs_written: u64,
    /// Corners turned round keyhole loops.
    pub(crate) keyholes: u64,
    /// Paths without sharp corners written with arcs to save lines ([`super::compact`]).
    pub(crate) compacted_paths: u64,
}

/// The VTG eq. 30 limits for a file: `v_max` from the machine's X/Y feed limits (`M203`), `A_n` the
/// printing acceleration (`M204 P`, Klipper's `ACCEL`) within the X/Y acceleration limits
/// (`M201`), `T_s`, `R_n` and `δ` from the options, `J_n` from the options or else from `A_n`
/// and the machine's first natural frequency (see [`VtgOptions::normal_jerk_mm_s3`]).
///
/// `A_n` is the printing acceleration, not the `M201` maximum: it is what the user chose for
/// the quality of the print, and what junction-deviation and Klipper planners themselves hold
/// the centripetal acceleration of a curve to (`M201` is often far above it: 9000 mm/s² in
/// PrusaSlicer's MK3S profile, printing at 1250).
pub(crate) fn limits_for(path: &PrintPath, options: &VtgOptions) -> KinematicLimits {
    let l = &path.print_limits;
    let pick = |a: f64, b: f64, default: f64| {
        let v = a.min(b);
        if v.is_finite() && v > 0.0 {
            v
        } else {
            default
        }
    };
    let normal_accel_mm_s2 = pick(
        l.max_acceleration[0].value.min(l.acceleration.value),
        l.max_acceleration[1].value,
        1000.0,
    );
    let normal_jerk_mm_s3 = options
        .normal_jerk_mm_s3
        .unwrap_or_else(|| normal_accel_mm_s2 * first_mode_hz(path));
    KinematicLimits {
        v_max_mm_s: pick(l.max_feedrate[0].value, l.max_feedrate[1].value, 200.0),
        interpolation_period_s: options.interpolation_period_s,
        chord_tolerance_mm: options.tolerance_mm,
        normal_accel_mm_s2,
        normal_jerk_mm_s3,
        nozzle_radius_mm: options.nozzle_diameter_mm / 2.0,
    }
}

/// The machine's lowest natural frequency (see [`VtgOptions::normal_jerk_mm_s3`]), Hz.
pub(crate) fn first_mode_hz(path: &PrintPath) -> f64 {
    let name = crate::dynamics::parameters::preset_for_machine(&path.profile.name);
    let f1 = crate::dynamics::parameters::MachineDynamics::preset(name)
        .map_or(f64::NAN, |d| d.lowest_frequency_hz());
    if f1.is_finite() && f1 > 0.0 {
        f1
    } else {
        // No model to ask: a typical desktop frame's first mode.
        40.0
    }
}

/// Every path's ways of being written, before the file-level choice ([`budget`]).
#[derive(Debug, Default)]
pub(crate) struct Offers {
    offers: Vec<Offer>,
    /// Each offer's path: its layer, and whether it has a sharp corner.
    paths: Vec<(u32, bool)>,
    candidate_paths: u64,
    variant: Variant,
    /// Lines the file may add ([`super::allowed_lines`]).
    allowed_lines: i64,
}

/// What the offers of every variant take from the file alone: its candidate paths and the
/// firmware's segment figures. Made once a run ([`FilePaths::of`]): on the 34 MB corpus file
/// they took 80 ms, on one thread, of each of the closed loop's whole-file rewrites and race
/// trials (ten of them).
#[derive(Debug, Clone, Default)]
pub(crate) struct FilePaths {
    /// The paths worth rewriting ([`candidates`]); `None` where the path's moves and their
    /// sources do not line up, and nothing is rewritten.
    candidates: Option<Vec<(usize, usize, bool)>>,
    /// The firmware's minimum segment time, s ([`crate::vtg::firmware::SegmentBudget`]).
    min_segment_time_s: f64,
    /// The compaction's block rate ([`Settings::max_blocks_per_s`]).
    max_blocks_per_s: f64,
}

impl FilePaths {
    /// The candidate paths of `input` (read as `path`, its moves' sources `all`) and its
    /// firmware's figures, as `options` read them.
    pub(crate) fn of(input: &[u8], path: &PrintPath, all: &Sources, options: &VtgOptions) -> Self {
        let moves = &path.moves;
        let sources = &all.moves[..];
        let aligned = sources.len() == moves.len()
            && sources.iter().zip(moves).all(|(s, m)| s.line == m.line);
        let budget = crate::vtg::firmware::SegmentBudget::for_file(
            input,
            path.junction_model,
            options.min_segment_time_ms,
        );
        let lines = crate::gcode::file_lines(input).max(1);
        let cos_critical = crate::math::cos(options.critical_angle_deg.to_radians());
        FilePaths {
            candidates: aligned.then(|| candidates(moves, sources, cos_critical)),
            min_segment_time_s: budget.min_segment_time_s,
            // A fifth under what the original's lines allow: the rewrite's own are longer (an
            // arc's `I` and `J`), so the stream reads fewer of them (374 → 330 a second on the
            // 34 MB corpus file), and the compaction's bursts add a tenth
            // (`compact::BLOCK_BURST_S`).
            max_blocks_per_s: 0.8 * budget.segment_rate_hz(input.len() as f64 / lines as f64),
        }
    }
}

/// Rewrites every eligible path of `input` in every way worth offering: the free rewrite, and
/// the dearer ones (see [`budget`]); [`Offers::write`] then writes the file with the choice.
/// The paths are `file`'s candidates ([`FilePaths::of`]). Paths smoothed the same way before
/// are taken from `smoothings`, and those smoothed now kept there (within its bound). The file
/// may add `allowed_lines` lines ([`super::allowed_lines`]).
pub(crate) fn offers(
    input: &[u8],
    (path, all, file): (&PrintPath, &Sources, &FilePaths),
    (options, limits, allowed_lines): (&VtgOptions, &KinematicLimits, i64),
    (variant, kept_layers): (Variant, &[bool]),
    (smoothings, progress): (&mut Smoothings, crate::progress::Progress<'_>),
) -> Result<Offers, Error> {
    let mut out = Offers {
        variant,
        allowed_lines,
        ..Offers::default()
    };
    let moves = &path.moves;
    let Some(candidates) = file.candidates.as_ref().filter(|_| !variant.keep_original) else {
        return Ok(out);
    };
    let settings = Settings {
        min_segment_s: variant.thin.then_some(file.min_segment_time_s),
        max_blocks_per_s: file.max_blocks_per_s,
        ..file_settings(path, options, limits, variant)
    };
    let energy = Accumulator::new(
        &options.analyze.energy.clone().unwrap_or_default(),
        &path.profile.name,
    );
    // Layers kept as they are (where a rewrite rang above the original's peak).
    let candidates: Vec<(usize, usize, bool)> = (candidates.iter().copied())
        .filter(|&(i, _, _)| {
            let layer = moves.get(i).map_or(u32::MAX, |m| m.layer) as usize;
            !kept_layers.get(layer).copied().unwrap_or(false)
        })
        .collect();
    out.candidate_paths = candidates.iter().filter(|c| c.2).count() as u64;
    out.paths = candidates
        .iter()
        .map(|&(i, _, sharp)| (moves.get(i).map_or(u32::MAX, |m| m.layer), sharp))
        .collect();
    let offering = Offering {
        input,
        path,
        all,
        energy: &energy,
        smoothings,
        variant,
        settings,
        dearer: TUNING.dearer_speed_shares.map(|min_speed_share| Settings {
            min_speed_share,
            ..settings
        }),
        // Dearer variants only where they can differ from the free rewrite.
        buy_time: options.allow_slower_pct > 0.0 && settings.speed_share_matters(),
    };
    let (mut offers, pending) = offering.offer_all(&candidates, progress)?;
    if settings.arcs {
        offering.add_leans(&mut offers, &candidates, allowed_lines);
    }
    smoothings.keep_all(pending);
    out.offers = offers;
    Ok(out)
}

/// The settings every path of the file starts from: the options, the variant tried, and what
/// the file's firmware and limits say (each path then takes the limits in force where it
/// starts, [`PlanContext::settings`]).
fn file_settings(
    path: &PrintPath,
    options: &VtgOptions,
    limits: &KinematicLimits,
    variant: Variant,
) -> Settings {
    Settings {
        tolerance_mm: options.tolerance_mm,
        critical_rad: options.critical_angle_deg.to_radians(),
        limits: *limits,
        limit_feed: options.limit_feed,
        max_normal_accel_mm_s2: xy_acceleration(&path.print_limits)
            .unwrap_or(limits.normal_accel_mm_s2),
        jerk_per_accel_hz: options
            .normal_jerk_mm_s3
            .is_none()
            .then(|| first_mode_hz(path)),
        min_step_mm: if path.junction_model == JunctionModel::Klipper {
            TUNING.klipper_min_step_mm
        } else {
            TUNING.marlin_min_step_mm
        },
        classic_jerk_mm_s: (path.junction_model == JunctionModel::ClassicJerk)
            .then(|| xy_jerk(&path.print_limits)),
        feed_cap_scale: variant.feed_cap_scale,
        stretch: variant.stretch,
        // `vtg` has resolved `auto` by now.
        arcs: options.arcs == crate::vtg::ArcsMode::On,
        min_speed_share: 1.0,
        keyholes: variant.keyholes,
        arc_cutting: None,
        lean: false,
        klipper_scv_mm_s: (path.junction_model == JunctionModel::Klipper)
            .then(|| square_corner_velocity(&path.print_limits))
            .flatten(),
        min_segment_s: Some(crate::vtg::firmware::MARLIN_MIN_SEGMENT_TIME_S),
        max_blocks_per_s: f64::INFINITY,
        line: if options.inside_corners {
            crate::vtg::blend::Line::Inside
        } else {
            crate::vtg::blend::Line::Racing
        },
    }
}

/// The paths worth rewriting, as move ranges `i..j` and whether they have a sharp corner:
/// those that do, and those of at least two moves that do not (written with arcs or their
/// lines joined, they save lines: [`super::compact`]).
fn candidates(
    moves: &[PathMove],
    sources: &[MoveSource],
    cos_critical: f64,
) -> Vec<(usize, usize, bool)> {
    let mut candidates = Vec::new();
    let mut i = 0usize;
    while i < moves.len() {
        let Some(j) = path_end(moves, sources, i) else {
            i += 1;
            continue;
        };
        let run = &moves[i..j];
        if run.len() >= 2 && has_sharp_corner(run, cos_critical) {
            candidates.push((i, j, true));
        } else if run.len() >= 2 {
            candidates.push((i, j, false));
        }
        i = j;
    }
    candidates
}

/// What every path's offer is made with; one value shared by the parallel batches so each
/// path's offer is one call.
struct Offering<'a> {
    input: &'a [u8],
    path: &'a PrintPath,
    all: &'a Sources,
    energy: &'a Accumulator,
    /// Paths smoothed before, and the variant smoothing them now.
    smoothings: &'a Smoothings,
    variant: Variant,
    /// The free rewrite's settings.
    settings: Settings,
    /// The dearer variants' (`Tuning::dearer_speed_shares`).
    dearer: [Settings; 2],
    /// Whether time may be spent and the dearer variants can differ from the free one.
    buy_time: bool,
}

impl Offering<'_> {
    /// The offers of the `candidates` paths, in parallel batches: each path is independent,
    /// results are merged in file order (the same output on any number of threads), and
    /// progress and cancellation are checked between batches. With them, the smoothings made
    /// that fit beside those kept.
    fn offer_all(
        &self,
        candidates: &[(usize, usize, bool)],
        progress: crate::progress::Progress<'_>,
    ) -> Result<(Vec<Offer>, Pending), Error> {
        let mut pending = Pending::default();
        let mut offers: Vec<Offer> = Vec::with_capacity(candidates.len());
        for (b, batch) in candidates.chunks(BATCH_PATHS).enumerate() {
            if !progress((b * BATCH_PATHS) as f64 / candidates.len().max(1) as f64) {
                return Err(Error::new(0, 0, ErrorKind::Cancelled));
            }
            // One offer per path, kept in file order: sums over them are then the same to the
            // last bit as a sequential run's (the wasm build's, which the CLI's JSON must
            // equal).
            let made = crate::parallel::map_chunks(batch, |chunk| {
                chunk
                    .iter()
                    .map(|&(i, j, sharp)| self.offer(i, j, sharp))
                    .collect()
            });
            for (offer, fresh) in made {
                offers.push(offer);
                for (key, smoothing) in fresh {
                    self.smoothings.admit(&mut pending, key, smoothing);
                }
            }
        }
        Ok((offers, pending))
    }

    /// The lean rewrites ([`Offer::lean`]) of the paths whose free rewrite the line budget
    /// (`allowed_lines`) does not stretch to, in parallel: made after the offers, for those
    /// paths only (on a file whose savings pay for every path's lines, none).
    fn add_leans(
        &self,
        offers: &mut [Offer],
        candidates: &[(usize, usize, bool)],
        allowed_lines: i64,
    ) {
        let lines = budget::free_within_lines(offers, allowed_lines);
        let starved: Vec<usize> = (0..offers.len())
            .filter(|&k| {
                let adds_lines = offers[k].free.as_ref().is_none_or(|f| f.lines_added > 0);
                candidates[k].2 && !lines.keep_free[k] && adds_lines
            })
            .collect();
        let leans = crate::parallel::map_chunks(&starved, |chunk| {
            chunk
                .iter()
                .map(|&k| self.lean(candidates[k].0, candidates[k].1))
                .collect()
        });
        for (&k, lean) in starved.iter().zip(leans) {
            offers[k].lean = lean;
        }
    }

    /// The lean rewrite of moves `i..j`: only the corners replaced without a line more, at no
    /// cost in time or energy; `None` where there are none.
    fn lean(&self, i: usize, j: usize) -> Option<Outcome> {
        let (moves, sources) = (&self.path.moves, &self.all.moves[..]);
        let machine = self.context(i, j);
        let settings = Settings {
            lean: true,
            ..self.settings
        };
        let mut smooth =
            |path: &SmoothPath<'_>, s: &Settings| smooth_path(path, s).map(std::sync::Arc::new);
        let outcomes = rewrite_path(
            self.input,
            (&moves[i..j], &sources[i..j]),
            &settings,
            &machine,
            &mut smooth,
        )?;
        outcomes.into_iter().next().filter(Outcome::is_lean)
    }

    /// What the planner knows around moves `i..j`: the limits in force, the junction model, the
    /// energy model and the moves either side.
    fn context(&self, i: usize, j: usize) -> PlanContext<'_> {
        let moves = &self.path.moves;
        PlanContext {
            limits: self.all.limits_at(i),
            model: self.path.junction_model,
            energy: self.energy,
            context: [
                i.checked_sub(1).map(|k| motion_of(&moves[k])),
                moves.get(j).map(motion_of),
            ],
        }
    }

    /// The ways of writing moves `i..j`: the free rewrite, and with time to spend the dearer
    /// variants that round more corners; a path without a `sharp` corner only with arcs, as
    /// its original points lie ([`super::compact`]). With them, the smoothings made for it
    /// that were not kept before.
    fn offer(&self, i: usize, j: usize, sharp: bool) -> (Offer, Vec<(SmoothingKey, Smoothing)>) {
        let (moves, sources) = (&self.path.moves, &self.all.moves[..]);
        let machine = self.context(i, j);
        if !sharp {
            let settings = machine.settings(&self.settings);
            let compact = super::compact::compact_path(
                self.input,
                &moves[i..j],
                &sources[i..j],
                &settings,
                &machine,
            );
            let offer = Offer {
                free: compact,
                ..Offer::default()
            };
            return (offer, Vec::new());
        }
        let mut fresh = Vec::new();
        // Whether the free rewrite's smoothing is known to be every dearer one's too.
        let shared = std::cell::Cell::new(false);
        let mut write = |k: u8, s: &Settings| {
            let key = SmoothingKey::new(self.variant, k, i);
            let mut smooth = |path: &SmoothPath<'_>, settings: &Settings| {
                if let Some(kept) = self.smoothings.get(&key) {
                    return kept.clone();
                }
                let (made, depends) = share_dependence(|| smooth_path(path, settings));
                let made = made.map(std::sync::Arc::new);
                if k == 0 {
                    shared.set(!depends);
                }
                if self.smoothings.keeps_any() {
                    fresh.push((key, made.clone()));
                    if shared.get() && self.buy_time {
                        // Its dearer smoothings, kept as offering nothing more (below).
                        let dearer = (1..=self.dearer.len() as u8)
                            .map(|d| (SmoothingKey::new(self.variant, d, i), None));
                        fresh.extend(dearer);
                    }
                }
                made
            };
            let (run, src) = (&moves[i..j], &sources[i..j]);
            rewrite_path(self.input, (run, src), s, &machine, &mut smooth)
        };
        let base = write(0, &self.settings).unwrap_or_default();
        let kept = base.iter().map(|o| o.corners_removed).max().unwrap_or(0);
        // With time to spend, the variants that round the corners the firmware takes faster
        // sharp, too: first those it takes nearly as fast round.
        let mut offer = Offer::default();
        base.into_iter().for_each(|o| offer.push(o));
        // The dearer variants of a path whose smoothing does not depend on the speed share
        // would be the free rewrite's outcomes again, which the filter below drops.
        if self.buy_time && !shared.get() {
            (self.dearer.iter().zip(1..))
                .filter_map(|(s, k)| write(k, s))
                .flatten()
                .filter(|o| o.corners_removed > kept)
                .for_each(|o| offer.push(o));
        }
        (offer, fresh)
    }
}

impl Offers {
    /// The variant these offers were made for.
    pub(crate) fn variant(&self) -> Variant {
        self.variant
    }

    /// Drops the offers of the layers `kept` marks: what [`offers`] makes with them kept, to
    /// the bit, since each path's offers depend on that path alone. The closed loop's rounds
    /// that keep layers take them from the whole file's instead of rewriting every path again
    /// (on the 34 MB file, 6 s a round natively).
    pub(crate) fn keep_layers(&mut self, kept: &[bool]) {
        let keep: Vec<bool> = (self.paths.iter())
            .map(|&(layer, _)| !kept.get(layer as usize).copied().unwrap_or(false))
            .collect();
        let mut k = keep.iter();
        self.offers.retain(|_| k.next().copied().unwrap_or(true));
        let mut k = keep.iter();
        self.paths.retain(|_| k.next().copied().unwrap_or(true));
        self.candidate_paths = self.paths.iter().filter(|p| p.1).count() as u64;
    }

    /// Whether any path offers a rewrite that costs time or energy: otherwise what the budget
    /// allows changes nothing.
    pub(crate) fn has_dearer(&self) -> bool {
        self.offers.iter().any(|o| !o.dearer.is_empty())
    }

    /// Lines the file may add, as the offers were made for.
    pub(crate) fn allowed_lines(&self) -> i64 {
        self.allowed_lines
    }

    /// The file with the free rewrites `allowed_lines` more lines allow ([`budget::free_within_lines`])
    /// and the dearer ones bought with half of what those saved plus `allowed_s` of time,
    /// energy weighed at the print's `mean_power_w` where time is allowed ([`budget::choose`]).
    pub(crate) fn write(
        &self,
        input: &[u8],
        (allowed_s, allowed_lines): (f64, i64),
        mean_power_w: f64,
    ) -> Rewritten {
        let mut out = Rewritten {
            candidate_paths: self.candidate_paths,
            feed_cap_scale: self.variant.feed_cap_scale,
            steps_joined: self.variant.thin,
            stretch_caps: self.variant.stretch,
            ..Rewritten::default()
        };
        let (lines, choice) = self.choice((allowed_s, allowed_lines), mean_power_w);
        let mut edits: Vec<&Edit> = Vec::new();
        for (k, (offer, chosen)) in self.offers.iter().zip(choice).enumerate() {
            if chosen.is_some() {
                out.paid_paths += 1;
            } else {
                if offer.free.is_none() && !offer.dearer.is_empty() {
                    out.kept_for_time += 1;
                }
                if offer.free.as_ref().is_some_and(|f| f.corners_removed > 0) && !lines.keep_free[k]
                {
                    out.kept_for_lines += 1;
                }
            }
            if let Some(o) = written(&self.offers, k, chosen, &lines) {
                out.add(&o.part);
                out.corners_removed += o.corners_removed;
                edits.extend(&o.edits);
            }
        }
        out.output = apply_edits(input, edits);
        // The lines that leave the modal feed as the original did, where the next move sets
        // its own or reads it first: folded into it (`crate::vtg::feeds`).
        crate::vtg::feeds::fold_in_place(&mut out.output);
        out
    }

    /// The free rewrites `allowed_lines` more lines allow ([`budget::free_within_lines`]), and
    /// the dearer one bought for each offer, if any ([`budget::choose`]): [`Offers::write`]'s
    /// choice.
    fn choice(
        &self,
        (allowed_s, allowed_lines): (f64, i64),
        mean_power_w: f64,
    ) -> (budget::LineChoice, Vec<Option<usize>>) {
        let lines = budget::free_within_lines(&self.offers, allowed_lines);
        let free = |k: usize| lines.kept(&self.offers, k);
        let saved = (0..self.offers.len())
            .filter_map(free)
            .fold([0.0, 0.0], |s, f| [s[0] - f.added[0], s[1] - f.added[1]]);
        let budget = Budget::new(saved, allowed_s, mean_power_w);
        let choice = budget::choose(&self.offers, budget, &lines);
        (lines, choice)
    }

    /// What the rewrites [`Offers::write`] writes at `allowed` add to the file by their own
    /// costing (time s, motor energy J; each path planned alone, [`Outcome::added`]): the
    /// choice's forecast of what the whole file's analysis will measure, before the file is
    /// written.
    pub(crate) fn forecast(&self, allowed: (f64, i64), mean_power_w: f64) -> [f64; 2] {
        let (lines, choice) = self.choice(allowed, mean_power_w);
        let mut sum = [0.0, 0.0];
        for (k, chosen) in choice.into_iter().enumerate() {
            if let Some(o) = written(&self.offers, k, chosen, &lines) {
                sum = [sum[0] + o.added[0], sum[1] + o.added[1]];
            }
        }
        sum
    }
}

/// The outcome of offer `k` of `offers` the choice writes: the dearer one `chosen`, else the
/// one the `lines` keep, else none (the path stays as it was).
fn written<'o>(
    offers: &'o [Offer],
    k: usize,
    chosen: Option<usize>,
    lines: &budget::LineChoice,
) -> Option<&'o Outcome> {
    match chosen {
        Some(d) => offers.get(k)?.dearer.get(d),
        None => lines.kept(offers, k),
    }
}

/// Candidate paths per batch between progress reports.
const BATCH_PATHS: usize = 4096;

impl Rewritten {
    /// The counts of a path written with its VTG eq. 29 speeds at `scale`: raised above the
    /// settings' first scale, or dropped (`None`).
    fn at_scale(scale: Option<f64>, settings: &Settings) -> Self {
        let mut part = Rewritten::default();
        match scale {
            None if settings.limit_feed => part.uncapped_paths += 1,
            Some(k) if k > settings.feed_cap_scale => part.raised_caps_paths += 1,
            _ => {}
        }
        part
    }

    /// Adds the counts of a part of the file rewritten separately.
    fn add(&mut self, part: &Rewritten) {
        self.rewritten_paths += part.rewritten_paths;
        self.replaced_moves += part.replaced_moves;
        self.written_moves += part.written_moves;
        self.lowered_segments += part.lowered_segments;
        self.above_k_cr_segments += part.above_k_cr_segments;
        self.max_deviation_mm = self.max_deviation_mm.max(part.max_deviation_mm);
        self.raised_caps_paths += part.raised_caps_paths;
        self.uncapped_paths += part.uncapped_paths;
        self.paid_paths += part.paid_paths;
        self.kept_for_time += part.kept_for_time;
        self.kept_for_lines += part.kept_for_lines;
        self.walk.steps += part.walk.steps;
        self.walk.fluctuation_sum += part.walk.fluctuation_sum;
        self.arcs_written += part.arcs_written;
        self.keyholes += part.keyholes;
        self.compacted_paths += part.compacted_paths;
    }
}

/// End (exclusive) of the path starting at move `i`, or `None` if move `i` cannot start one.
fn path_end(moves: &[PathMove], sources: &[MoveSource], i: usize) -> Option<usize> {
    let ok = |k: usize| {
        let (m, s) = (&moves[k], &sources[k]);
        s.plain && matches!(m.kind, MoveKind::Linear) && m.is_extruding()
    };
    if !ok(i) {
        return None;
    }
    let first = &moves[i];
    let mut j = i + 1;
    while j < moves.len()
        && ok(j)
        && moves[j].feature == first.feature
        && moves[j].layer == first.layer
        && sources[j].mode == sources[i].mode
        && sources[j].line == sources[j - 1].line + 1 + sources[j].notes.lines
        && j - i < 100_000
    {
        j += 1;
    }
    Some(j)
}

fn has_sharp_corner(run: &[PathMove], cos_critical: f64) -> bool {
    let xyz = |m: &PathMove| [0, 1, 2].map(|k| m.to[k] - m.from[k]);
    run.windows(2)
        .any(|w| is_sharp(&xyz(&w[0]), &xyz(&w[1]), cos_critical))
}

/// Whether the turn from direction `a` to direction `b` (neither normalised) is above the
/// critical angle (cosine `cos_critical`); a zero-length side turns nothing.
pub(crate) fn is_sharp(a: &[f64; 3], b: &[f64; 3], cos_critical: f64) -> bool {
    let (la, lb) = (norm(a), norm(b));
    la > 0.0 && lb > 0.0 && dot(a, b) / (la * lb) < cos_critical
}

/// The X/Y acceleration ceiling of `limits` (`M201`, the lower of the two axes), if it is a
/// usable number.
fn xy_acceleration(limits: &Limits) -> Option<f64> {
    let a = &limits.max_acceleration;
    let m = a[0].value.min(a[1].value);
    (m.is_finite() && m > 0.0).then_some(m)
}

/// Klipper's square-corner velocity in `limits`, mm/s, if it is a usable number.
fn square_corner_velocity(limits: &Limits) -> Option<f64> {
    let v = limits.square_corner_velocity.value;
    (v.is_finite() && v > 0.0).then_some(v)
}

/// The X/Y jerk of a classic-jerk planner (`M205 X Y`, the lower of the two axes), mm/s.
fn xy_jerk(limits: &Limits) -> f64 {
    limits.max_jerk[0].value.min(limits.max_jerk[1].value)
}

/// The firmware a path runs on: the limits in force where it starts, the junction model, and
/// the motor energy model; and the moves just before and after the path, which are planned
/// with it.
pub(super) struct PlanContext<'a> {
    pub(super) limits: Option<&'a Limits>,
    model: JunctionModel,
    energy: &'a Accumulator,
    context: [Option<Motion>; 2],
}

/// The planner's motion for a move of the file.
fn motion_of(m: &PathMove) -> Motion {
    Motion {
        line: m.line,
        delta: [0, 1, 2, 3].map(|k| m.to[k] - m.from[k]),
        arc: m.kind.arc().copied(),
        feed_mm_s: m.feed_mm_s,
        rotary_time_s: 0.0,
    }
}

impl PlanContext<'_> {
    /// The settings for a path here: the jerk and acceleration ceilings of the limits in force.
    fn settings(&self, file: &Settings) -> Settings {
        let mut s = *file;
        if let Some(l) = self.limits {
            if let Some(a) = xy_acceleration(l) {
                s.max_normal_accel_mm_s2 = a;
            }
            if s.classic_jerk_mm_s.is_some() {
                s.classic_jerk_mm_s = Some(xy_jerk(l));
            }
            if s.klipper_scv_mm_s.is_some() {
                s.klipper_scv_mm_s = square_corner_velocity(l);
            }
            if s.arcs {
                s.arc_cutting = Some(crate::plan::ArcCutting::of(self.model, l));
            }
        }
        s
    }

    /// Time (s) the firmware takes for the polyline from `start` through `points` (filament
    /// `e` from 0 at `start`, feed `feed` per segment), and the motor energy (J) it costs:
    /// planned from rest to rest, with the moves before and after the path, so what a rewrite
    /// changes at the path's two junctions with the rest of the file is counted too (a short
    /// last step meeting the next move at an angle slows a Klipper machine down there).
    pub(super) fn cost(
        &self,
        start: [f64; 3],
        points: &[[f64; 3]],
        e: &[f64],
        feed: &[f64],
    ) -> (f64, f64) {
        self.cost_pieces(start, points, e, &arcs::lines(feed))
    }

    /// [`PlanContext::cost`] of the path written as `pieces` (lines and arcs) through `points`.
    pub(super) fn cost_pieces(
        &self,
        start: [f64; 3],
        points: &[[f64; 3]],
        e: &[f64],
        pieces: &[Piece],
    ) -> (f64, f64) {
        let Some(limits) = self.limits else {
            return (f64::NAN, f64::NAN);
        };
        let mut planner = Planner::new(limits.clone(), self.model);
        let mut energy = self.energy.clone();
        let mut joules = 0.0;
        let (mut from, mut e_from) = (start, 0.0);
        let [before, after] = &self.context;
        let path = pieces.iter().filter_map(|piece| {
            let k = piece.end.checked_sub(1)?;
            let (p, &ek) = (points.get(k)?, e.get(k)?);
            let m = Motion {
                line: 0,
                delta: [p[0] - from[0], p[1] - from[1], p[2] - from[2], ek - e_from],
                arc: piece.arc.map(|a| a.resolve(&from, p)),
                feed_mm_s: piece.feed,
                rotary_time_s: 0.0,
            };
            (from, e_from) = (*p, ek);
            Some(m)
        });
        let all = before
            .iter()
            .copied()
            .chain(path)
            .chain(after.iter().copied());
        for (k, m) in all.enumerate() {
            planner.push(&m, k as u64, &mut |pm| joules += energy.planned(pm));
        }
        planner.flush(&mut |pm| joules += energy.planned(pm));
        (planner.elapsed_s(), joules)
    }
}

/// Rewrites one path; the edits replace its first line with the new block and delete the rest.
///
/// A rewrite should cost neither time nor motor energy: the new path and the original are
/// planned on their own with the firmware's limits and costed with the energy model, and where
/// the new one is dearer its VTG eq. 29 speeds are raised step by step (each step trading a little
/// of the vibration suppression for speed), then dropped (the firmware's own cornering then
/// sets the speed). If every variant is still dearer (a machine whose planner takes sharp
/// corners faster than a fillet within the tolerance allows, such as Klipper with a high
/// square-corner velocity, gains nothing in time from rounding), the cheapest in energy is
/// returned marked dearer, for [`budget::choose`] to take or leave, and after it the fastest if
/// that is another: the lowered feeds that save motor energy cost time, and where time is what
/// buys corners the fastest way buys more of them.
fn rewrite_path(
    input: &[u8],
    (run, src): (&[PathMove], &[MoveSource]),
    file_settings: &Settings,
    machine: &PlanContext<'_>,
    smooth: &mut dyn FnMut(&SmoothPath<'_>, &Settings) -> Smoothing,
) -> Option<Vec<Outcome>> {
    let settings = &machine.settings(file_settings);
    let o = Polyline::of(run, src)?;
    let (pts, e, feed) = (&o.pts, &o.e, &o.feed);
    let path = SmoothPath {
        pts,
        e,
        feed,
        planned: if o.planned.len() == run.len() {
            &o.planned
        } else {
            &[]
        },
    };
    let smoothed = smooth(&path, settings)?;
    let original = machine.cost(pts[0], &pts[1..], &e[1..], feed);
    let costs = Costs { original };
    let (cheapest, fastest) = cheapest_and_fastest(&smoothed, pts[0], settings, machine, costs);
    let (scale, written, written_cost) = cheapest?;
    let cos_critical = crate::math::cos(settings.critical_rad);
    let draft = Draft {
        original: costs,
        sharp_before: sharp_turns(pts, cos_critical),
        cos_critical,
        input,
        run,
        src,
        pts,
        e,
        smoothed: &smoothed,
        settings,
        machine,
    };
    let added = costs.added_by(written_cost);
    let mut out =
        vec![draft.outcome(scale, &written, written_cost, added, costs.dearer(&added))?];
    if let Some((k, way, total)) = fastest.filter(|f| f.2 .0 < written_cost.0) {
        let w = smoothed.written(way, pts[0], settings);
        out.extend(draft.outcome(k, &w, total, costs.added_by(total), true));
    }
    Some(out)
}

/// An original path as the smoothing reads it: vertices (start point first), filament from
/// the path start at each vertex in E words, feed per segment, and how the planner ran each
/// move (as far as it was planned).
pub(super) struct Polyline {
    pub(super) pts: Vec<[f64; 3]>,
    pub(super) e: Vec<f64>,
    pub(super) feed: Vec<f64>,
    planned: Vec<Profile>,
}

impl Polyline {
    /// The path of `run`; `None` where its filament is not a positive, rising total.
    pub(super) fn of(run: &[PathMove], src: &[MoveSource]) -> Option<Self> {
        let (first, first_src) = (run.first()?, src.first()?);
        let xyz = |p: &crate::machine::Pos| [p[0], p[1], p[2]];
        let mut pts = Vec::with_capacity(run.len() + 1);
        pts.push(xyz(&first.from));
        pts.extend(run.iter().map(|m| xyz(&m.to)));
        // Filament from the path start at each vertex, in E words.
        let mode = first_src.mode;
        let mut e = Vec::with_capacity(pts.len());
        e.push(0.0);
        let mut sum = 0.0;
        for s in src {
            sum = match mode {
                ExtrusionMode::Relative => sum + s.e_word,
                ExtrusionMode::Absolute => s.e_word - first_src.e_before,
            };
            e.push(sum);
        }
        if sum.is_nan() || sum <= 0.0 || e.windows(2).any(|w| w[1] < w[0] - 1e-9) {
            return None;
        }
        let feed: Vec<f64> = src
            .iter()
            .zip(run)
            .map(|(s, m)| s.f_after().map_or(m.feed_mm_s, |f| f / 60.0))
            .collect();
        // How the planner ran each original move, when the path was planned.
        let planned: Vec<Profile> = run
            .iter()
            .map_while(|m| m.timing.map(|t| t.profile))
            .collect();
        Some(Polyline {
            pts,
            e,
            feed,
            planned,
        })
    }
}

/// The original path's time (s) and motor energy (J), against which a writing's are weighed.
#[derive(Clone, Copy)]
struct Costs {
    original: (f64, f64),
}

impl Costs {
    /// Time and energy a writing costing `(s, j)` adds to the original's.
    fn added_by(&self, (s, j): (f64, f64)) -> [f64; 2] {
        [s - self.original.0, j - self.original.1]
    }

    /// Whether what a writing adds makes it dearer than the original.
    fn dearer(&self, a: &[f64; 2]) -> bool {
        a[0] > self.original.0 * 1e-9 || a[1] > self.original.1 * 1e-9
    }
}

/// A writing of a smoothed path: the VTG eq. 29 speeds' scale (`None`: no caps), and the path
/// written with it (or the way it was written), with its time (s) and energy (J).
type Writing<W> = (Option<f64>, W, (f64, f64));

/// The VTG eq. 29 speeds as they are, then raised step by step, then no caps at all, each first
/// as fast as the firmware will go elsewhere, then no faster than the original: the first
/// writing that costs neither time nor energy, else the one that costs least energy; and the
/// fastest if that is not the first (to be written again at the end if it is another way).
fn cheapest_and_fastest(
    smoothed: &Smoothed,
    start: [f64; 3],
    settings: &Settings,
    machine: &PlanContext<'_>,
    costs: Costs,
) -> (Option<Writing<Written>>, Option<Writing<Way>>) {
    let cost = |w: &Written| machine.cost(start, &w.points, &w.e, &w.feed_mm_s);
    let mut cheapest: Option<Writing<Written>> = None;
    let mut fastest: Option<Writing<Way>> = None;
    // The feeds of the writings costed so far. Two writings with the same feeds are one path
    // at one cost, and every test below takes a later writing only where it is strictly
    // better, so a writing met before is skipped unplanned (on the 34 MB corpus file 22 669
    // of 146 472 writings, a sixth of the planning).
    let mut tried: Vec<Vec<f64>> = Vec::new();
    for way in super::writings(settings) {
        let k = way.scale;
        let feeds = smoothed.feeds(way);
        if tried.contains(&feeds.feed_mm_s) {
            continue;
        }
        tried.push(feeds.feed_mm_s.clone());
        let w = smoothed.written_at(feeds, start, settings);
        let total = cost(&w);
        let a = costs.added_by(total);
        if a.iter().any(|x| x.is_nan()) {
            continue;
        }
        let better = cheapest.as_ref().is_none_or(|c| {
            let b = costs.added_by(c.2);
            (a[1], a[0]) < (b[1], b[0])
        });
        let stop = !costs.dearer(&a);
        if stop {
            cheapest = Some((k, w, total));
            fastest = None;
            break;
        }
        let quicker = fastest.as_ref().is_none_or(|c| {
            let b = costs.added_by(c.2);
            (a[0], a[1]) < (b[0], b[1])
        });
        if quicker {
            fastest = Some((k, way, total));
        }
        if better {
            cheapest = Some((k, w, total));
        }
    }
    (cheapest, fastest)
}

/// A path and its smoothed form, to be written one way or another.
struct Draft<'a> {
    /// The original's cost.
    original: Costs,
    input: &'a [u8],
    run: &'a [PathMove],
    src: &'a [MoveSource],
    /// The original's vertices, start point first.
    pts: &'a [[f64; 3]],
    /// Filament from the path start at each vertex, in E words.
    e: &'a [f64],
    /// Turns above the critical angle (cosine `cos_critical`) of the original.
    sharp_before: usize,
    cos_critical: f64,
    smoothed: &'a Smoothed,
    settings: &'a Settings,
    machine: &'a PlanContext<'a>,
}

impl Draft<'_> {
    /// The pieces `written` is written in: its runs on a circle as arcs, if asked for and if the
    /// path with them still keeps the tolerance both ways (measured on the arcs themselves);
    /// their distance from the original, and what they add over it and whether that is dearer
    /// (`priced`, the lines' own, unless the arcs are written at a cost of their own,
    /// [`with_arcs`]).
    fn pieces(
        &self,
        written: &Written,
        written_cost: (f64, f64),
        priced: ([f64; 2], bool),
    ) -> (Vec<Piece>, f64, [f64; 2], bool) {
        let (added, dearer) = priced;
        let (pts, settings) = (self.pts, self.settings);
        let lines = arcs::lines(&written.feed_mm_s);
        if !settings.arcs {
            return (lines, self.smoothed.deviation_mm, added, dearer);
        }
        let all: Vec<[f64; 3]> = std::iter::once(pts[0])
            .chain(written.points.iter().copied())
            .collect();
        let costs = (written_cost, self.original.original);
        match with_arcs(&all, written, costs, pts, settings, self.machine) {
            None => (lines, self.smoothed.deviation_mm, added, dearer),
            Some((pieces, d, cost)) => {
                let deviation = self.smoothed.deviation_mm.max(d);
                let Some(cost) = cost else {
                    return (pieces, deviation, added, dearer);
                };
                // The fastest writing is filed as dearer whatever it costs (`rewrite_path`).
                let dearer_anyway = dearer && !self.original.dearer(&added);
                let added = self.original.added_by(cost);
                (
                    pieces,
                    deviation,
                    added,
                    dearer_anyway || self.original.dearer(&added),
                )
            }
        }
    }

    /// The edits and counts of the path written as `written` (VTG eq. 29 speeds at `scale`),
    /// costing `written_cost` (time s, motor energy J), `added` over the original's.
    fn outcome(
        &self,
        scale: Option<f64>,
        written: &Written,
        written_cost: (f64, f64),
        added: [f64; 2],
        dearer: bool,
    ) -> Option<Outcome> {
        let Draft {
            input,
            run,
            src,
            pts,
            e,
            sharp_before,
            cos_critical,
            smoothed,
            settings,
            ..
        } = *self;
        let (first_src, last_src) = (src.first()?, src.last()?);
        let mode = first_src.mode;
        let sum = *e.last()?;
        let mut part = Rewritten::at_scale(scale, settings);
        let removed = sharp_before.saturating_sub(sharp_turns(
            std::iter::once(&pts[0]).chain(&written.points),
            cos_critical,
        ));
        let out = &mut part;
        let notes = notes(input, src, e)?;
        let (pieces, deviation, added, dearer) =
            self.pieces(written, written_cost, (added, dearer));
        out.arcs_written += pieces.iter().filter(|p| p.arc.is_some()).count() as u64;
        let frame = Frame {
            start: pts[0],
            climbs: run.iter().any(|m| (m.to[2] - m.from[2]).abs() > 1e-9),
            mode,
            e_before: first_src.e_before,
            last_e_word: last_src.e_word,
            total_e: sum,
            f_before: first_src.f_before(),
            f_after: last_src.f_after(),
            f_after_read: !last_src.feed_overridden,
            notes,
        };
        let text = block::write(&frame, &written.points, &written.e, &pieces);
        out.rewritten_paths += 1;
        out.replaced_moves += run.len() as u64;
        out.written_moves += pieces.len() as u64;
        out.lowered_segments += written.lowered;
        out.above_k_cr_segments += smoothed.above_k_cr;
        out.keyholes += smoothed.keyholes;
        out.max_deviation_mm = out.max_deviation_mm.max(deviation);
        out.walk.steps += smoothed.stats.steps;
        out.walk.fluctuation_sum += smoothed.stats.fluctuation_sum;
        let edits = edits(src, text);
        Some(Outcome {
            lines_added: lines_added(&edits),
            edits,
            part,
            added,
            dearer,
            corners_removed: removed as u64,
        })
    }
}

/// Annotation lines between the original moves (`;WIDTH:`), each with the filament pushed
/// where it stood (`e`, from the path start): the new block writes them back in place.
pub(super) fn notes<'i>(
    input: &'i [u8],
    src: &[MoveSource],
    e: &[f64],
) -> Option<Vec<(f64, &'i str)>> {
    let mut notes = Vec::new();
    for (s, &at) in src.iter().zip(e).skip(1) {
        if s.notes.lines > 0 {
            notes.push((at, std::str::from_utf8(input.get(s.notes.range())?).ok()?));
        }
    }
    Some(notes)
}

/// The edits replacing a path's first line with the new block `text` and deleting its other
/// lines (with the annotations between them, which the block writes again).
pub(super) fn edits(src: &[MoveSource], text: String) -> Vec<Edit> {
    let mut edits = Vec::with_capacity(src.len());
    if let Some(first) = src.first() {
        edits.push(Edit {
            line: first.line,
            replacement: text.into_bytes(),
        });
    }
    for s in src.iter().skip(1) {
        edits.extend((s.line - s.notes.lines..=s.line).map(|line| Edit {
            line,
            replacement: Vec::new(),
        }));
    }
    edits
}

/// Lines `edits` add to the file (negative: remove): each replaces one line with as many as
/// its text holds, or deletes it.
pub(super) fn lines_added(edits: &[Edit]) -> i64 {
    let written: usize = edits
        .iter()
        .filter(|e| !e.replacement.is_empty())
        .map(|e| 1 + e.replacement.iter().filter(|&&b| b == b'\n').count())
        .sum();
    written as i64 - edits.len() as i64
}

/// The written path `all` (start point first; `written` after it) with its runs on a circle as
/// arcs, if there are any, the firmware cuts them at least as finely as δθ asks, the path with
/// them stays within the tolerance of the original `orig` both ways (returned: the distance),
/// and it plans no slower and costs no more motor energy than the path in lines did
/// (`lines_cost`: time s, energy J).
fn with_arcs(
    all: &[[f64; 3]],
    written: &Written,
    (lines_cost, original_cost): ((f64, f64), (f64, f64)),
    orig: &[[f64; 3]],
    settings: &Settings,
    machine: &PlanContext<'_>,
) -> Option<WithArcs> {
    let fit = TUNING.arc_share * settings.tolerance_mm;
    // The smoothing's own measurement is no bound here: the written path sits near the
    // budget, and with the arcs' offset it settled 136 of 5 158 checks on the 34 MB file.
    let near = (orig, f64::INFINITY);
    let (pieces, d) = fit_arcs((all, &written.feed_mm_s), fit, near, settings)?;
    let (s, j) = machine.cost_pieces(all[0], &written.points, &written.e, &pieces);
    let within =
        |(s_max, j_max): (f64, f64)| s <= s_max * (1.0 + 1e-9) && j <= j_max * (1.0 + 1e-9);
    if within(lines_cost) {
        return Some((pieces, d, None));
    }
    // Slower than the lines (a hairpin's arc cut into chords that turn more than the
    // polygon's sides), but no dearer than the original: still the way to write it, in
    // fewer lines, at its own cost.
    within(original_cost).then_some((pieces, d, Some((s, j))))
}

/// A path with arcs ([`with_arcs`]): its pieces, their distance from the original, mm, and
/// their own time (s) and motor energy (J) where these replace the lines' (`None`: the
/// lines' stand, the arcs costing no more).
type WithArcs = (Vec<Piece>, f64, Option<(f64, f64)>);

/// The polyline `all` (feed `feed` per segment) with its runs on a circle within `fit` as
/// arcs, where there are any, the firmware cuts them at least as finely as δθ asks, and the
/// path with them stays within the tolerance of the original `orig` both ways (returned: the
/// distance). `known_mm`: a bound of the distance between `all` and `orig` known already
/// (infinite if none; 0 for a path compacted, which is its own original): with the arcs' offset
/// it bounds the distance sought without measuring (on the 34 MB corpus file 19 858 compacting
/// checks, a seventh of the deviation measurement's time).
pub(super) fn fit_arcs(
    (all, feed): (&[[f64; 3]], &[f64]),
    fit: f64,
    (orig, known_mm): (&[[f64; 3]], f64),
    settings: &Settings,
) -> Option<(Vec<Piece>, f64)> {
    // As the planner times them ([`PlanContext::settings`]: the limits in force here).
    let cutting = settings.arc_cutting?;
    let segments = move |r: f64, len: f64, feed: f64| cutting.segments(r, (len, 0.0), feed);
    let firmware = arcs::Firmware {
        segments: &segments,
        max_turn_rad: TUNING.step_turn_share * settings.critical_rad,
    };
    let tol = settings.tolerance_mm;
    let pieces = arcs::pieces(all, feed, fit, &firmware);
    if pieces.iter().all(|p| p.arc.is_none()) {
        return None;
    }
    // The arcs' own offset from the polyline plus the polyline's distance from the original
    // bound the distance sought (the triangle inequality); where that is not within the
    // tolerance, the arcs are flattened finely and measured themselves.
    let off = arcs::offset_bound(all, &pieces);
    if known_mm + off <= tol {
        return Some((pieces, known_mm + off));
    }
    if off < tol {
        let near = both_ways(all, orig, tol / 10.0, tol - off);
        if near + off <= tol {
            return Some((pieces, near + off));
        }
    }
    let d = both_ways(
        &arcs::flatten(all, &pieces, 0.01 * tol),
        orig,
        tol / 10.0,
        tol,
    );
    (d <= tol).then_some((pieces, d))
}

/// Turns above the critical angle (cosine `cos_critical`) along the polyline through `pts`.
pub(crate) fn sharp_turns<'a>(
    pts: impl IntoIterator<Item = &'a [f64; 3]>,
    cos_critical: f64,
) -> usize {
    let mut pts = pts.into_iter();
    let (Some(mut p0), Some(mut p1)) = (pts.next(), pts.next()) else {
        return 0;
    };
    let mut count = 0;
    for p2 in pts {
        count += usize::from(is_sharp(&sub(p1, p0), &sub(p2, p1), cos_critical));
        (p0, p1) = (p1, p2);
    }
    count
}

#[cfg(test)]
mod tests {
    use crate::vtg::smoothings::Smoothings;

    /// Filament (relative E) pushed before each `;WIDTH:` line, in order, and the total.
    fn filament_at_notes(g: &str) -> (Vec<(String, f64)>, f64) {
        let mut e = 0.0;
        let mut at = Vec::new();
        for l in g.lines() {
            if l.starts_with(";WIDTH:") {
                at.push((l.to_string(), e));
            } else if let Some(w) = l.split_whitespace().find(|w| w.starts_with('E')) {
                if l.starts_with("G1 ") {
                    e += w[1..].parse::<f64>().unwrap();
                }
            }
        }
        (at, e)
    }

    /// By default the file gains no lines: a rectangle's corners, each walked in several steps,
    /// stay sharp and the file comes back as it was; allowed more lines, they are rounded, and
    /// the file has as many more as it was allowed at most.
    #[test]
    fn corners_that_add_lines_stay_sharp_unless_more_lines_are_allowed() {
        let mut src = String::from("M83\nM204 P1250\nG1 X100 Y100 F6000\nG1 Z0.2\n");
        for _ in 0..10 {
            for (x, y) in [(120, 100), (120, 110), (100, 110), (100, 100)] {
                src.push_str(&format!("G1 X{x} Y{y} E0.5 F3600\n"));
            }
        }
        let run = |allow_more_lines_pct| {
            let options = crate::vtg::VtgOptions {
                dynamics: false,
                allow_more_lines_pct,
                ..Default::default()
            };
            crate::vtg::vtg(src.as_bytes(), &options).expect("vtg")
        };
        let lines = |b: &[u8]| b.iter().filter(|&&c| c == b'\n').count();
        let kept = run(0.0);
        assert_eq!((kept.paths.rewritten, kept.paths.kept_for_lines), (0, 1));
        assert_eq!(kept.output, src.as_bytes());
        let rounded = run(1000.0);
        assert_eq!(
            (rounded.paths.rewritten, rounded.paths.kept_for_lines),
            (1, 0)
        );
        let added = lines(&rounded.output) - lines(src.as_bytes());
        assert!(added > 0 && rounded.table1.n_turning.after == 0.0);
        // Just enough lines for it (in percent of the file's 44, half a line over so the
        // budget's rounding down cannot take one off): rounded; one fewer: not.
        let percent = |lines: f64| lines / 44.0 * 100.0;
        assert_eq!(run(percent(added as f64 + 0.5)).paths.rewritten, 1);
        assert_eq!(run(percent(added as f64 - 0.5)).paths.rewritten, 0);
    }

    /// Four layers of a pentagon with sharp corners, printed at 60 mm/s.
    fn pentagon_layers() -> String {
        let mut src = String::from("M83\nM204 P1250\nG1 X100 Y100 F6000\n");
        for layer in 0..4 {
            src.push_str(&format!("G1 Z{:.1}\n", 0.2 * f64::from(layer + 1)));
            for (x, y) in [(120, 100), (130, 104), (120, 110), (100, 110), (100, 100)] {
                src.push_str(&format!("G1 X{x} Y{y} E0.5 F3600\n"));
            }
        }
        src
    }

    /// The offers for `input` as `variant` with the layers `kept` left as they are, paths
    /// smoothed before taken from `smoothings`.
    fn offers_of(
        input: &[u8],
        (variant, kept): (super::Variant, &[bool]),
        smoothings: &mut Smoothings,
    ) -> super::Offers {
        let options = crate::vtg::VtgOptions {
            dynamics: false,
            allow_more_lines_pct: 1000.0,
            ..Default::default()
        };
        let path = crate::path::extract(input, &options.analyze, true).expect("path");
        let sources = crate::vtg::source::move_sources(input, &options.analyze).expect("sources");
        let limits = super::limits_for(&path, &options);
        let at = (
            &options,
            &limits,
            super::super::allowed_lines(input, &options),
        );
        let file = super::FilePaths::of(input, &path, &sources, &options);
        super::offers(
            input,
            (&path, &sources, &file),
            at,
            (variant, kept),
            (smoothings, &mut |_| true),
        )
        .expect("offers")
    }

    /// Offers made with layers kept are the whole file's with those layers' offers dropped:
    /// the same file written, and the same candidates counted.
    #[test]
    fn offers_with_layers_kept_are_the_whole_files_less_those_layers() {
        let src = pentagon_layers();
        let input = src.as_bytes();
        let make = |kept: &[bool]| {
            offers_of(
                input,
                (super::Variant::default(), kept),
                &mut Smoothings::new(0),
            )
        };
        let write = |o: &super::Offers| o.write(input, (0.0, 1000), 1.0);
        let kept = [false, true, false, true];
        let direct = make(&kept);
        let mut filtered = make(&[]);
        assert!(filtered.offers.len() > direct.offers.len());
        filtered.keep_layers(&kept);
        assert_eq!(filtered.candidate_paths, direct.candidate_paths);
        assert_eq!(filtered.paths, direct.paths);
        let (a, b) = (write(&filtered), write(&direct));
        assert_eq!(a.output, b.output);
        assert!(a.rewritten_paths > 0 && a.output != input);
    }

    /// The closed loop's variants at another scale of the VTG eq. 29 speeds take the paths
    /// smoothed at the first from the kept smoothings, and write what smoothing them again
    /// writes; the scale still sets the speeds.
    #[test]
    fn smoothings_kept_at_one_scale_write_another_as_smoothing_again_does() {
        let src = pentagon_layers();
        let input = src.as_bytes();
        let write = |o: &super::Offers| o.write(input, (0.0, 1000), 1.0).output;
        let one = super::Variant {
            thin: false,
            ..Default::default()
        };
        let two = super::Variant {
            feed_cap_scale: 2.0,
            ..one
        };
        let mut kept = Smoothings::new(usize::MAX);
        let at_one = write(&offers_of(input, (one, &[]), &mut kept));
        let bytes = kept.bytes();
        assert!(bytes > 0);
        let from_kept = write(&offers_of(input, (two, &[]), &mut kept));
        assert_eq!(kept.bytes(), bytes, "smoothed again");
        let again = write(&offers_of(input, (two, &[]), &mut Smoothings::new(0)));
        assert_eq!(from_kept, again);
        assert_ne!(from_kept, at_one);
        // Keyholes off is another smoothing: kept beside the first.
        let no_keyholes = super::Variant {
            keyholes: false,
            ..one
        };
        offers_of(input, (no_keyholes, &[]), &mut kept);
        assert!(kept.bytes() > bytes);
    }

    #[test]
    fn paths_run_across_width_annotations_and_keep_them_in_place() {
        let mut src = String::from("M83\nM201 X1000 Y1000\nM204 P1250\nM205 X8 Y8\n");
        src.push_str("G1 X100 Y100 F6000\nG1 Z0.2\n;TYPE:Solid infill\n");
        for k in 0..6 {
            for (j, (x, y)) in [
                (120.0, 100.0),
                (120.0, 110.0),
                (100.0, 110.0),
                (100.0, 100.0),
            ]
            .into_iter()
            .enumerate()
            {
                src.push_str(&format!("G1 X{x} Y{y} E0.5 F3600\n"));
                if j % 2 == 0 {
                    src.push_str(&format!(";WIDTH:0.4{k}{j}\n"));
                }
            }
        }
        let options = crate::vtg::VtgOptions {
            dynamics: false,
            // Rounding a rectangle's corners adds lines; the line budget is tested apart.
            allow_more_lines_pct: 1000.0,
            ..Default::default()
        };
        let r = crate::vtg::vtg(src.as_bytes(), &options).expect("vtg");
        // One path, across the notes (each would otherwise cut it into pieces of two moves).
        assert_eq!((r.paths.candidates, r.paths.rewritten), (1, 1));
        assert!(r.table1.n_turning.change_pct <= -40.0);
        let out = String::from_utf8(r.output).unwrap();
        let (before, total_before) = filament_at_notes(&src);
        let (after, total_after) = filament_at_notes(&out);
        assert_eq!(before.len(), 12);
        assert!((total_after - total_before).abs() < 1e-4);
        // The same notes, in order, each where the same filament has been pushed: no later than
        // the original's vertex, and no earlier than one new step (at most 0.5 mm of filament
        // per side here; the new steps near a vertex are short).
        for ((nb, eb), (na, ea)) in before.iter().zip(&after) {
            assert_eq!(nb, na);
            assert!(*ea <= eb + 1e-4 && *ea > eb - 0.05, "{nb}: {ea} vs {eb}");
        }
    }
}
