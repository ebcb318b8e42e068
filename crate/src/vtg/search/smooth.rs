//! One extrusion path through the VTG pipeline: blend its corners, fit (within tolerance), walk
//! the curve with Algorithm 1, spread the path's filament over the new points, cap the feed
//! where the curvature is above `K_cr`, and check the result against the original polyline.
//! The feed each new segment is then written with is [`crate::vtg::feed`]'s business.
//!
//! The tolerance is shared: the corner blends ([`crate::vtg::blend`]) may use `Tuning::blend_share`
//! of it, the fit's residuals `Tuning::fit_share` and the chords of the walk `Tuning::chord_share`
//! (together a little more than all of it: they seldom peak at the same point). If the measured
//! deviation still exceeds the tolerance, the blends are made smaller and the path tried again; a
//! path that cannot be rounded within the tolerance is kept as it was.

use crate::plan::Profile;
use crate::vec3::{dot, norm, sub};
use crate::vtg::blend;
use crate::vtg::bspline::{arc_lengths, segment_at};
use crate::vtg::corners::{CornerKind, Cost, Marks, Replacement, Site};
use crate::vtg::deviation::both_ways;
use crate::vtg::feed::StepSpeed;
use crate::vtg::fit::fit;
use crate::vtg::hairpin::{self, Hairpin};
use crate::vtg::kinematics::KinematicLimits;
use crate::vtg::resample::{walk_curve, Sample, Walk, WalkStats};
use crate::vtg::thin::{thin, Followed, Thin};
use crate::vtg::tuning::TUNING;

/// Settings for [`smooth_path`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// Tolerance, mm.
    pub(crate) tolerance_mm: f64,
    /// Critical angle δθ, rad.
    pub(crate) critical_rad: f64,
    /// Kinematic limits (VTG eq. 29–30).
    pub(crate) limits: KinematicLimits,
    /// Lower the feed where the curvature is above what the limits allow (VTG eq. 29).
    pub(crate) limit_feed: bool,
    /// The machine's X/Y acceleration limit (`M201`), mm/s²: the ceiling of `A_n`. Where the
    /// original's planned moves are known, `A_n` of a stretch is the acceleration the firmware
    /// used there (files change it per feature), within this.
    pub(crate) max_normal_accel_mm_s2: f64,
    /// `f₁` when `J_n` follows `A_n` (`J_n = A_n f₁`, the default), Hz; `None` keeps
    /// `limits.normal_jerk_mm_s3` everywhere.
    pub(crate) jerk_per_accel_hz: Option<f64>,
    /// Shortest interpolation step, mm (`Tuning::klipper_min_step_mm` or
    /// `Tuning::marlin_min_step_mm`).
    pub(crate) min_step_mm: f64,
    /// The per-axis jerk of a classic-jerk firmware, mm/s (`None` on junction-deviation and
    /// Klipper planners): rising feeds are then ramped, since such a planner counts a rise of
    /// the feed from one block to the next as jerk against the new block's full speed.
    pub(crate) classic_jerk_mm_s: Option<f64>,
    /// The first scale of the VTG eq. 29 speeds a rewrite is tried with (1: the speeds as they
    /// are); [`crate::vtg::vtg`] raises it where the dynamics model finds the rewrite at 1
    /// rings more than the original.
    pub(crate) feed_cap_scale: f64,
    /// Offer each scale of the VTG eq. 29 speeds a second time with joined segments capped for
    /// the mean curvature of their stretch ([`crate::vtg::feed::Way::stretch`]).
    pub(crate) stretch: bool,
    /// Write runs of new points that lie on a circle as arcs (`G2`/`G3`, [`crate::vtg::arcs`]).
    pub(crate) arcs: bool,
    /// How the firmware cuts arcs into chords, under the limits in force where the path starts,
    /// where arcs are written (`None` elsewhere): what the arcs stage writes an arc for only
    /// where its chords turn gently enough, and hairpins are written as one arc each by
    /// ([`crate::vtg::corners::arc_hairpin::ArcHairpins`]).
    pub(crate) arc_cutting: Option<crate::plan::ArcCutting>,
    /// Replace only the corners a kind replaces without adding a line (hairpins written as
    /// arcs), and leave the rest of the path as it is: the path's lean rewrite, for where the
    /// line budget does not stretch to its free one ([`crate::vtg::search::budget::Offer::lean`]).
    pub(crate) lean: bool,
    /// The slowest a rounded corner may be run, as a share of the firmware's speed through the
    /// sharp one: 1 rounds only the corners the machine runs round at least as fast (the free
    /// rewrite); below 1, the dearer variants of a path that
    /// [`crate::vtg::VtgOptions::allow_slower_pct`] may buy (0 rounds every corner it can).
    pub(crate) min_speed_share: f64,
    /// Turn single corners too tight to fillet round a [`crate::vtg::corners::keyhole`] loop
    /// where one fits.
    pub(crate) keyholes: bool,
    /// Which side of its corners a path may be rounded on ([`blend::Line`]).
    pub(crate) line: blend::Line,
    /// Klipper's square-corner velocity, mm/s, on a Klipper machine (`None` elsewhere): its
    /// sharp corners are then turned as polygons placed for its look-ahead
    /// ([`crate::vtg::corners::klipper`]).
    pub(crate) klipper_scv_mm_s: Option<f64>,
    /// The firmware's minimum segment time, s ([`crate::vtg::firmware::SegmentBudget`]):
    /// walked steps are joined up to `v · t_min` where the tolerance allows
    /// ([`crate::vtg::thin`]); `None`: written as walked.
    pub(crate) min_segment_s: Option<f64>,
    /// Planned blocks a second the firmware reads ([`crate::vtg::firmware::SegmentBudget`]):
    /// a path written with fewer lines must not have its arcs cut into more than this, or
    /// than its original lines made ([`crate::vtg::search::compact`]).
    pub(crate) max_blocks_per_s: f64,
}

/// A rewritten path: the new geometry, and what the feed of each new segment is made of.
#[derive(Debug, Clone, Default)]
pub(crate) struct Smoothed {
    /// New points after the start point (the last equals the original end).
    pub(crate) points: Vec<[f64; 3]>,
    /// Filament pushed from the path start to each point, mm.
    pub(crate) e: Vec<f64>,
    /// The speed terms of the segment ending at each point.
    pub(crate) steps: Vec<StepSpeed>,
    /// Segments whose curvature stays above `K_cr`.
    pub(crate) above_k_cr: u64,
    /// Measured largest distance to the original polyline, mm.
    pub(crate) deviation_mm: f64,
    /// Walk statistics (VTG eq. 28).
    pub(crate) stats: WalkStats,
    /// Corners turned round a keyhole loop.
    pub(crate) keyholes: u64,
}

/// A path to rewrite: its points, and what the original asks of each stretch.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SmoothPath<'a> {
    /// The polyline.
    pub(crate) pts: &'a [[f64; 3]],
    /// Filament pushed from the path start to each point, mm (from 0).
    pub(crate) e: &'a [f64],
    /// Feed of segment `i` (from `pts[i]` to `pts[i+1]`), mm/s.
    pub(crate) feed: &'a [f64],
    /// How the firmware's planner runs each original segment (empty when not known): the
    /// VTG eq. 29 feed cap never asks for less than the speed the machine had at the same place on
    /// the original. At that speed the sharp corner is a step in velocity and the rounded one a
    /// finite acceleration, so capping below it would only cost time (on a Klipper machine
    /// with a high square-corner velocity, VTG eq. 29's normal-jerk term would slow every corner
    /// down, and even at a classic-jerk corner the machine is back at speed within a few
    /// tenths of a millimetre on either side of the vertex).
    pub(crate) planned: &'a [Profile],
}

impl<'a> SmoothPath<'a> {
    /// Whether the arrays agree with each other.
    fn consistent(&self) -> bool {
        let n = self.pts.len();
        self.e.len() == n
            && self.feed.len() + 1 == n
            && (self.planned.is_empty() || self.planned.len() + 1 == n)
    }

    /// The piece from point `a` to point `b` (both included).
    fn piece(&self, a: usize, b: usize) -> Option<SmoothPath<'a>> {
        Some(SmoothPath {
            pts: self.pts.get(a..=b)?,
            e: self.e.get(a..=b)?,
            feed: self.feed.get(a..b)?,
            planned: if self.planned.is_empty() {
                &[]
            } else {
                self.planned.get(a..b)?
            },
        })
    }
}

/// Rewrites `path`; `None`: keep it.
///
/// Corners too sharp to be rounded within the tolerance in steps that each turn less than the
/// critical angle are kept as they are: the path is split there and each piece is fitted on its
/// own with its ends pinned (rounding such a corner would only trade one sharp turn for
/// several). Pieces without a sharp corner, and pieces that cannot be fitted within the
/// tolerance, keep their original points.
///
/// On the racing line, corners too tight for an inside fillet may be rounded by the wider
/// racing-line one, which the fit and walk do not always manage to follow in steps under δθ
/// (it then stays sharp): where that happened, the path is also rounded on the inside line
/// (with its hairpins and keyholes) and the one left with fewer sharp turns is kept.
pub(crate) fn smooth_path(path: &SmoothPath<'_>, s: &Settings) -> Option<Smoothed> {
    let written = written_as_they_are(path, s);
    if written.is_empty() {
        // A lean rewrite is its written replacements alone: without any, there is none.
        if s.lean {
            return None;
        }
        return super::smooth_cut(path, s, &[]);
    }
    let pins: Vec<Hairpin> = written.iter().map(|t| t.pin.clone()).collect();
    let mut sub = hairpin::substitute(path.pts, path.e, path.feed, path.planned, &pins);
    // A polygon's sides are run as the firmware will: no ceiling below the legs' own peak
    // (the substitute's profiles are the original's speeds near the corner).
    for (&start, pin) in sub.starts.iter().zip(&pins) {
        let sides = pin.arc.len() - 1;
        for j in 0..sides {
            let leg = if 2 * j < sides { pin.at - 1 } else { pin.at };
            if let (Some(slot), Some(p)) = (sub.planned.get_mut(start + j), path.planned.get(leg)) {
                *slot = *p;
            }
        }
    }
    // The polygons are written as they are: the path is cut at their two ends.
    let cuts: Vec<usize> = sub
        .starts
        .iter()
        .zip(&pins)
        .flat_map(|(&k, p)| [k, k + p.arc.len() - 1])
        .collect();
    let replaced = SmoothPath {
        pts: &sub.pts,
        e: &sub.e,
        feed: &sub.feed,
        planned: &sub.planned,
    };
    let mut out = if s.lean {
        // The replacements in place, the rest as it was.
        let mut kept = Smoothed::default();
        kept.keep(&replaced);
        kept
    } else {
        super::smooth_cut(&replaced, s, &cuts)?
    };
    for t in &written {
        out.deviation_mm = out.deviation_mm.max(t.deviation_mm);
    }
    Some(out)
}

/// A replacement the search took: the kind that proposed it (asked again on retries), its
/// points, and their measured deviation where they are written as they are (mm; 0 where they
/// are fitted with the path, whose deviation the walk measures).
#[derive(Clone)]
struct Taken {
    kind: &'static dyn CornerKind,
    pin: Hairpin,
    deviation_mm: f64,
}

/// The corners of `path` replaced by the kinds whose replacements are written as they are
/// ([`super::WRITTEN_KINDS`]), asked about each sharp corner that its own fillet does not
/// round at no loss of speed.
fn written_as_they_are(path: &SmoothPath<'_>, s: &Settings) -> Vec<Taken> {
    let kinds: Vec<&'static dyn CornerKind> = super::WRITTEN_KINDS
        .into_iter()
        .filter(|k| k.applies(path, s) && (k.adds_no_lines() || !s.lean))
        .collect();
    if kinds.is_empty() || path.pts.len() < 3 || !path.consistent() {
        return Vec::new();
    }
    // Corners a fillet already rounds at no loss of speed keep the fillet: the fitted curve
    // rings less than a polygon of the largest turns.
    let free = Settings {
        min_speed_share: 1.0,
        ..*s
    };
    let arc = arc_lengths(path.pts);
    let blends = blends_on(path.pts, s, s.line);
    let mut marks = Marks::classify(path, &arc, &free, &blend::Fillets(&blends));
    ask(&kinds, path, &arc, s, &mut marks)
}

/// [`smooth_path`] on the line `s` asks for, with the kinds fitted with the path
/// ([`super::FITTED_KINDS`]); and whether the racing line made a corner roundable that the
/// inside fillet could not round.
pub(super) fn smooth_on(
    path: &SmoothPath<'_>,
    s: &Settings,
    forced: &[usize],
) -> (Option<Smoothed>, bool) {
    let pts = path.pts;
    if pts.len() < 3 || !path.consistent() {
        return (None, false);
    }
    let arc = arc_lengths(pts);
    let blends = blends_on(pts, s, s.line);
    let mut marks = Marks::classify(path, &arc, s, &blend::Fillets(&blends));
    let rescued = rescued(pts, s, &marks);
    let pins = ask(&super::FITTED_KINDS, path, &arc, s, &mut marks);
    let cuts = marks.cuts(&pins, &arc, forced);
    match smooth_pieces(path, s, &cuts, &marks.sharp, &pins) {
        Some((out, changed)) => ((changed || !forced.is_empty()).then_some(out), rescued),
        None => (None, rescued),
    }
}

/// The blends of every corner of `pts` within the blend share of the tolerance, on `line`.
fn blends_on(pts: &[[f64; 3]], s: &Settings, line: blend::Line) -> Vec<blend::Blend> {
    blend::plan(
        pts,
        TUNING.blend_share * s.tolerance_mm,
        s.limits.critical_curvature(),
        line,
    )
}

/// Whether the racing line made a sharp corner of `pts` roundable that the inside fillet could
/// not round (never on the inside line itself).
fn rescued(pts: &[[f64; 3]], s: &Settings, marks: &Marks) -> bool {
    if s.line == blend::Line::Inside {
        return false;
    }
    let inside = blends_on(pts, s, blend::Line::Inside);
    (1..pts.len() - 1).any(|i| marks.sharp[i] && !marks.tight[i] && !inside[i].roundable(s))
}

/// Asks each of `kinds` in turn about every corner of `path` it asks about, and takes the
/// proposals the search [`accepts`]; the corners they replace are marked as replaced. The
/// replacements taken, in the order of their corners.
fn ask(
    kinds: &[&'static dyn CornerKind],
    path: &SmoothPath<'_>,
    arc: &[f64],
    s: &Settings,
    marks: &mut Marks,
) -> Vec<Taken> {
    let n = path.pts.len();
    let blend_tol_mm = TUNING.blend_share * s.tolerance_mm;
    let mut taken: Vec<Taken> = Vec::new();
    for &kind in kinds {
        let known = kind.known_cost(s);
        for i in 1..n - 1 {
            let before = path.planned.get(i - 1);
            let site = Site {
                path,
                arc,
                settings: s,
                marks,
                blend_tol_mm,
            };
            if !kind.asks_about(&site, i) || known.is_some_and(|c| !accepts(&c, before, s)) {
                continue;
            }
            let proposal = kind
                .propose(&site, i)
                .filter(|p| accepts(&p.cost, before, s));
            let (pin, deviation_mm) = match proposal.map(|p| p.replacement) {
                Some(Replacement::Fitted(pin)) => (pin, 0.0),
                Some(Replacement::Written(pin, d)) => (pin, d),
                Some(Replacement::Fillet) | None => continue,
            };
            for k in i..i + pin.corners {
                if let Some(m) = marks.pinned.get_mut(k) {
                    *m = true;
                }
            }
            taken.push(Taken {
                kind,
                pin,
                deviation_mm,
            });
        }
    }
    taken.sort_by_key(|t| t.pin.at);
    taken
}

impl Marks {
    /// Each corner of `path` (arc lengths `arc`): sharp, and whether `fillets` round it alone.
    fn classify(
        path: &SmoothPath<'_>,
        arc: &[f64],
        s: &Settings,
        fillets: &blend::Fillets,
    ) -> Self {
        let pts = path.pts;
        let cos_critical = crate::math::cos(s.critical_rad);
        let n = pts.len();
        let mut m = Marks {
            sharp: vec![false; n],
            alone: vec![true; n],
            degenerate: vec![false; n],
            tight: vec![false; n],
            pinned: vec![false; n],
        };
        for i in 1..n - 1 {
            let a = sub(pts[i], pts[i - 1]);
            let b = sub(pts[i + 1], pts[i]);
            let (la, lb) = (norm(a), norm(b));
            if la <= 0.0 || lb <= 0.0 {
                m.degenerate[i] = true;
                continue;
            }
            let cos = (dot(a, b) / (la * lb)).clamp(-1.0, 1.0);
            m.sharp[i] = cos < cos_critical;
        }
        for i in 1..n - 1 {
            let site = Site {
                path,
                arc,
                settings: s,
                marks: &m,
                blend_tol_mm: TUNING.blend_share * s.tolerance_mm,
            };
            if !fillets.asks_about(&site, i) {
                continue;
            }
            let fillet = fillets.propose(&site, i);
            m.tight[i] = fillet.is_none();
            m.alone[i] = fillet.is_some_and(|p| accepts(&p.cost, path.planned.get(i - 1), s));
        }
        m
    }

    /// The points the path is cut at (its ends included): corners kept sharp (no longer
    /// counted as sharp), either side of a keyhole, and `forced`.
    fn cuts(&mut self, pins: &[Taken], arc: &[f64], forced: &[usize]) -> Vec<usize> {
        let n = self.sharp.len();
        let mut cuts = vec![0usize];
        for i in 1..n - 1 {
            if self.degenerate[i] || (self.sharp[i] && !self.alone[i] && !self.pinned[i]) {
                cuts.push(i);
                self.sharp[i] = false;
            }
        }
        // A keyhole is fitted on its own, between the original points either side of the
        // stretch it replaces (on its straight legs): the rest of a long side need not be
        // fitted again.
        let spans: Vec<(f64, f64)> = pins.iter().map(|t| t.pin.span(arc)).collect();
        let free = |j: usize| {
            j > 0
                && j + 1 < n
                && !self.sharp[j]
                && !self.pinned[j]
                && spans.iter().all(|&(u0, u1)| arc[j] <= u0 || arc[j] >= u1)
        };
        for (t, &(u0, u1)) in pins.iter().zip(&spans).filter(|(t, _)| t.pin.corners == 1) {
            let at = t.pin.at;
            let before = (0..at).rev().find(|&j| arc[j] <= u0);
            let after = (at + 1..n).find(|&j| arc[j] >= u1);
            cuts.extend(before.into_iter().chain(after).filter(|&j| free(j)));
        }
        cuts.extend(forced.iter().filter(|&&j| j < n));
        cuts.push(n - 1);
        cuts.sort_unstable();
        cuts.dedup();
        cuts
    }
}

/// Each piece between two `cuts` smoothed on its own (or kept) and joined; and whether any was
/// rewritten. `None` when a cut falls outside the path.
fn smooth_pieces(
    path: &SmoothPath<'_>,
    s: &Settings,
    cuts: &[usize],
    sharp: &[bool],
    pins: &[Taken],
) -> Option<(Smoothed, bool)> {
    let mut out = Smoothed::default();
    let mut changed = false;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let piece = path.piece(a, b)?;
        let has_sharp = sharp.get(a + 1..b).is_some_and(|v| v.iter().any(|&x| x));
        let here: Vec<Taken> = pins
            .iter()
            .filter(|t| t.pin.at > a && t.pin.at < b)
            .map(|t| {
                let mut t = t.clone();
                t.pin.at -= a;
                t
            })
            .collect();
        let keyholes = here.iter().filter(|t| t.pin.corners == 1).count() as u64;
        let mut done =
            smooth_piece(&piece, s, has_sharp, &here).map(|p| Smoothed { keyholes, ..p });
        if done.is_none() && keyholes > 0 {
            // A loop the fit or the walk could not keep within the tolerance: the piece
            // again without keyholes, its tight corners kept sharp.
            let plain = Settings {
                keyholes: false,
                ..*s
            };
            done = super::smooth_cut(&piece, &plain, &[]);
        }
        match done {
            Some(p) => {
                changed = true;
                out.append(p);
            }
            None => out.keep(&piece),
        }
    }
    Some((out, changed))
}

impl Smoothed {
    /// Appends a rewritten piece.
    fn append(&mut self, p: Smoothed) {
        self.points.extend(p.points);
        self.e.extend(p.e);
        self.steps.extend(p.steps);
        self.above_k_cr += p.above_k_cr;
        self.deviation_mm = self.deviation_mm.max(p.deviation_mm);
        self.stats.steps += p.stats.steps;
        self.stats.fluctuation_sum += p.stats.fluctuation_sum;
        self.keyholes += p.keyholes;
    }

    /// Appends a piece kept as it was, its segments at their own feeds and planned peaks.
    fn keep(&mut self, piece: &SmoothPath<'_>) {
        self.points.extend(piece.pts.iter().skip(1).copied());
        self.e.extend(piece.e.iter().skip(1).copied());
        self.steps
            .extend(piece.feed.iter().enumerate().map(|(k, &f)| {
                let planned = piece.planned.get(k);
                StepSpeed {
                    programmed: f,
                    limit: f64::INFINITY,
                    stretch_limit: f64::INFINITY,
                    floor: 0.0,
                    ceiling: planned.map_or(f64::INFINITY, |p| p.peak),
                    accel: planned.map_or(0.0, |p| p.acceleration),
                }
            }));
    }
}

/// Whether rounding a corner on a curve of the largest curvature `curvature` (a fillet's, or a
/// keyhole's loop) leaves the machine at least as fast through it, given how the
/// firmware ran the original move `before` that ends at the corner (unknown: assume it does).
///
/// A junction-deviation or Klipper planner takes a sharp corner as if it were an arc (Klipper's
/// of radius `jd sin(θ/2) / (1 − sin(θ/2))`, `jd = scv² (√2 − 1) / a`), and holds a real curve
/// of radius `r` to `√(a r)`. Where the square-corner velocity is high (Creality's K1 profiles
/// set 50–100 mm/s) that virtual arc is larger than any fillet the tolerance allows, and the
/// fillet would only slow the machine down: such a corner is kept, unless the settings let a
/// rounded corner run slower ([`Settings::min_speed_share`] of the sharp one's speed: the
/// dearer variants time may be spent on). (A classic-jerk planner has no such rule: the feed
/// written on the fillet is never below the original's speed.)
fn pays(curvature: f64, before: Option<&Profile>, s: &Settings) -> bool {
    let Some(p) = before.filter(|_| s.speed_share_matters()) else {
        return true;
    };
    let a = p.acceleration.min(s.max_normal_accel_mm_s2);
    let on_fillet = (a / curvature).sqrt();
    at_share(on_fillet, p.exit, s)
}

/// Whether the search takes a replacement costing `cost` at a corner the firmware reached on
/// the original move `before` (see [`crate::vtg::corners::Cost`]).
fn accepts(cost: &Cost, before: Option<&Profile>, s: &Settings) -> bool {
    match *cost {
        Cost::Curvature(k) => pays(k, before, s),
        Cost::Planned {
            slowest_mm_s,
            sharp_mm_s,
        } => at_share(slowest_mm_s, sharp_mm_s, s),
        Cost::Unweighed => true,
    }
}

/// Whether `speed` is at least [`Settings::min_speed_share`] of `sharp`, noting where one of
/// `Tuning::dearer_speed_shares` would have decided otherwise ([`share_dependence`]).
fn at_share(speed: f64, sharp: f64, s: &Settings) -> bool {
    let taken = speed >= s.min_speed_share * sharp;
    if (TUNING.dearer_speed_shares.iter()).any(|&d| (speed >= d * sharp) != taken) {
        SHARE_DECIDED.set(true);
    }
    taken
}

std::thread_local! {
    /// Whether a corner was decided by [`at_share`] since [`share_dependence`] began in a way
    /// one of the dearer speed shares would not have.
    static SHARE_DECIDED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// `f`'s result, and whether any corner it weighed would have been decided otherwise at one
/// of `Tuning::dearer_speed_shares`. Where none would, a smoothing at the dearer shares is the
/// same to the bit ([`Settings::min_speed_share`] is read nowhere else), so its dearer
/// variants offer nothing the free rewrite does not and need not be made (most paths of the
/// corpus's Klipper files, whose corners are all slow or all fast). A flag of the thread's:
/// each path is smoothed on one thread, and the decisions are made deep in the corner search.
pub(crate) fn share_dependence<R>(f: impl FnOnce() -> R) -> (R, bool) {
    let outer = SHARE_DECIDED.replace(false);
    let result = f();
    let depends = SHARE_DECIDED.get();
    SHARE_DECIDED.set(outer || depends);
    (result, depends)
}

impl Settings {
    /// Whether [`Settings::min_speed_share`] can change which corners are rounded: only where
    /// the firmware takes a sharp corner as a virtual arc that a fillet must keep up with (see
    /// `pays`); a classic-jerk planner's corners all pay already.
    pub(crate) fn speed_share_matters(&self) -> bool {
        self.classic_jerk_mm_s.is_none()
    }
}

/// One piece between kept corners, with its hairpins (`at` counted in the piece) as found with
/// the full blend share of the tolerance.
fn smooth_piece(
    path: &SmoothPath<'_>,
    s: &Settings,
    has_sharp: bool,
    pins: &[Taken],
) -> Option<Smoothed> {
    if path.pts.len() < 3 || !has_sharp {
        return None;
    }
    let e0 = *path.e.first()?;
    let e: Vec<f64> = path.e.iter().map(|x| x - e0).collect();
    let from_zero = SmoothPath { e: &e, ..*path };
    for share in super::blend_shares() {
        let tol = share * s.tolerance_mm;
        let done = if pins.is_empty() {
            attempt(&from_zero, path.pts, s, tol)
        } else {
            with_hairpins(&from_zero, s, tol, pins, share < TUNING.blend_share)
        };
        if let Some(mut r) = done {
            for x in &mut r.e {
                *x += e0;
            }
            return Some(r);
        }
    }
    None
}

/// [`attempt`] on `path` with its replacements `pins` spliced in, checked against the
/// original; with `again`, each kind is asked for its replacement again within the smaller
/// `blend_tol` ([`CornerKind::again`]: hairpins are found anew, keyholes kept).
fn with_hairpins(
    path: &SmoothPath<'_>,
    s: &Settings,
    blend_tol: f64,
    pins: &[Taken],
    again: bool,
) -> Option<Smoothed> {
    let pts = path.pts;
    let pins: Vec<Hairpin> = if again {
        pins.iter()
            .map(|t| t.kind.again(pts, &t.pin, blend_tol, s))
            .collect::<Option<_>>()?
    } else {
        pins.iter().map(|t| t.pin.clone()).collect()
    };
    let sub = hairpin::substitute(pts, path.e, path.feed, path.planned, &pins);
    let replaced = SmoothPath {
        pts: &sub.pts,
        e: &sub.e,
        feed: &sub.feed,
        planned: &sub.planned,
    };
    attempt(&replaced, pts, s, blend_tol)
}

/// Blend, fit, walk `path` (filament from 0) with blends within `blend_tol`, and check the
/// result against the polyline `original` (the same path, or the one it stands for).
fn attempt(
    path: &SmoothPath<'_>,
    original: &[[f64; 3]],
    s: &Settings,
    blend_tol: f64,
) -> Option<Smoothed> {
    let Walked {
        samples: walked,
        mut points,
        deviation_mm: deviation,
        stats,
    } = walk_within(path, original, s, blend_tol)?;
    let total_e = *path.e.last()?;
    let mut out = Smoothed {
        deviation_mm: deviation,
        stats,
        ..Smoothed::default()
    };
    let o = Original {
        arc: arc_lengths(path.pts),
        path,
        s,
    };
    let k_cr = s.limits.critical_curvature();
    let (e, feed) = (path.e, path.feed);
    let mut seg = 0usize;
    let mut u_prev = 0.0;
    for x in walked.iter().skip(1) {
        // The original segment this parameter (an arc length of the original) falls in.
        while seg + 1 < feed.len() && o.arc.get(seg + 1).is_some_and(|&a| a <= x.u) {
            seg += 1;
        }
        let (a0, a1) = (o.arc.get(seg).copied()?, o.arc.get(seg + 1).copied()?);
        let t = if a1 > a0 {
            ((x.u - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (e0, e1) = (e.get(seg).copied()?, e.get(seg + 1).copied()?);
        let local = o.limits_at(seg);
        let mut step = StepSpeed {
            programmed: feed.get(seg).copied()?,
            limit: f64::INFINITY,
            stretch_limit: f64::INFINITY,
            floor: 0.0,
            ceiling: o.top(u_prev, x.u),
            accel: local.normal_accel_mm_s2,
        };
        if x.mean_kappa > k_cr {
            out.above_k_cr += 1;
            if s.limit_feed {
                step.limit = local.feed_limit(x.mean_kappa);
                // Set whatever the settings' `stretch`: the smoothing cache hands a path
                // smoothed for one variant to its stretch twin.
                if x.stretch_kappa > k_cr {
                    step.stretch_limit = local.feed_limit(x.stretch_kappa);
                }
                step.floor = o.speed(u_prev).min(o.speed(x.u));
            }
        }
        u_prev = x.u;
        out.e.push(e0 + (e1 - e0) * t);
        out.steps.push(step);
    }
    points.remove(0);
    if let Some(last) = out.e.last_mut() {
        *last = total_e;
    }
    out.points = points;
    Some(out)
}

/// The blended, fitted and walked curve of `path` with its ends pinned to the original's,
/// its points, their deviation from `original` and the walk's statistics; `None` when the
/// fit or walk fails or the deviation exceeds the tolerance. Apart from [`attempt`] so the
/// geometry (VTG eq. 18–28) reads apart from the feeds given to it.
fn walk_within(
    path: &SmoothPath<'_>,
    original: &[[f64; 3]],
    s: &Settings,
    blend_tol: f64,
) -> Option<Walked> {
    let pts = path.pts;
    let tol = s.tolerance_mm;
    // Room for the 3-decimal rounding of written coordinates.
    let budget = tol - 0.001;
    let k_cr = s.limits.critical_curvature();
    let blends = blend::plan(pts, blend_tol, k_cr, s.line);
    let (data, params) = blend::samples(pts, &blends, TUNING.straight_spacing_mm);
    let f = fit(&data, &params, TUNING.fit_share * tol)?;
    let w = Walk {
        chord_tol_mm: TUNING.chord_share * tol,
        max_turn_rad: TUNING.step_turn_share * s.critical_rad,
        max_step_mm: 1e4,
        min_step_mm: s.min_step_mm,
        phi: 1.0,
        newton_tol_mm: 1e-7,
    };
    let mut stats = WalkStats::default();
    let walked = walk_curve(&f.curve, &w, &mut stats)?;
    let mut points: Vec<[f64; 3]> = walked.iter().map(|x| x.p).collect();
    // Pin the ends to the original ones exactly.
    if let (Some(first), Some(p0)) = (points.first_mut(), pts.first()) {
        *first = *p0;
    }
    if let (Some(last), Some(pn)) = (points.last_mut(), pts.last()) {
        *last = *pn;
    }
    let (walked, points) = thinned(path, walked, points, s, &w, budget);
    // Both ways: the new path stays near the old, and the old is covered by the new.
    let deviation = both_ways(&points, original, tol / 10.0, budget);
    if deviation.is_nan() || deviation > budget {
        return None;
    }
    Some(Walked {
        samples: walked,
        points,
        deviation_mm: deviation,
        stats,
    })
}

/// The walked samples and their points thinned to the firmware's segment budget
/// ([`thin`]): Algorithm 1's `L_i` lengthened up to `v · t_min` where the tolerance and the
/// turn allow. A joined segment carries the largest curvature of the steps it joins, so its
/// VTG eq. 29 feed cap is no higher than theirs.
fn thinned(
    path: &SmoothPath<'_>,
    walked: Vec<Sample>,
    points: Vec<[f64; 3]>,
    s: &Settings,
    w: &Walk,
    budget: f64,
) -> (Vec<Sample>, Vec<[f64; 3]>) {
    let Some(min_segment_s) = s.min_segment_s else {
        return (walked, points);
    };
    // Paths that climb (vase mode) keep their steps: each point's Z is written, and joining
    // them changes the heights a reader counts layers by (the FullControl ripple vase read
    // back with another layer count).
    let z0 = points.first().map_or(0.0, |p| p[2]);
    if points.iter().any(|p| (p[2] - z0).abs() > 1e-9) {
        return (walked, points);
    }
    let arc = arc_lengths(path.pts);
    let segments = crate::vtg::deviation::Segments::new(path.pts);
    let followed = Followed {
        pts: path.pts,
        arc: &arc,
        feed: path.feed,
        segments: &segments.0,
    };
    let t = Thin {
        budget_mm: budget,
        max_turn_rad: w.max_turn_rad,
        min_segment_s,
        step_mm: s.tolerance_mm / 10.0,
    };
    let u: Vec<f64> = walked.iter().map(|x| x.u).collect();
    let mut keep = thin(&points, &u, &followed, &t);
    // Still more points than the original had: join as far as the tolerance and the turn
    // allow, whatever the segment time (the rewrite needs no more lines than it replaces
    // unless its corners demand them).
    if keep.len() > path.pts.len() && t.min_segment_s > 0.0 {
        let longest = Thin {
            min_segment_s: 0.0,
            ..t
        };
        keep = thin(&points, &u, &followed, &longest);
    }
    if keep.len() == points.len() {
        return (walked, points);
    }
    let mut samples = Vec::with_capacity(keep.len());
    let mut kept = Vec::with_capacity(keep.len());
    let mut from = 0usize;
    for &k in &keep {
        let (Some(x), Some(p)) = (walked.get(k), points.get(k)) else {
            return (walked, points);
        };
        let mut x = *x;
        for y in walked.get(from + 1..k).unwrap_or(&[]) {
            x.kappa = x.kappa.max(y.kappa);
            x.mean_kappa = x.mean_kappa.max(y.mean_kappa);
        }
        x.stretch_kappa = stretch_curvature(&walked, &points, from, k);
        samples.push(x);
        kept.push(*p);
        from = k;
    }
    (samples, kept)
}

/// The mean curvature of the walked steps `from + 1 ..= to` joined as one segment: their
/// tangent's turn (each step's mean curvature times its chord) over their length, 1/mm.
fn stretch_curvature(walked: &[Sample], points: &[[f64; 3]], from: usize, to: usize) -> f64 {
    let (mut turn, mut length) = (0.0, 0.0);
    for j in from + 1..=to {
        let (Some(y), Some(a), Some(b)) = (walked.get(j), points.get(j - 1), points.get(j)) else {
            continue;
        };
        let l = norm(sub(*b, *a));
        turn += y.mean_kappa * l;
        length += l;
    }
    if length > 0.0 {
        turn / length
    } else {
        walked.get(to).map_or(0.0, |y| y.mean_kappa)
    }
}

/// What [`walk_within`] gives: the walk's samples, their points with the ends pinned, the
/// measured deviation (mm) and the walk's statistics.
struct Walked {
    samples: Vec<Sample>,
    points: Vec<[f64; 3]>,
    deviation_mm: f64,
    stats: WalkStats,
}

/// What the original asked at each arc length of a path: the planned speeds and the limits
/// that bound the feed of the new points laid over it.
struct Original<'p, 'a> {
    /// Arc length at each original point.
    arc: Vec<f64>,
    path: &'p SmoothPath<'a>,
    s: &'p Settings,
}

impl Original<'_, '_> {
    /// The original segment at arc length `u`.
    fn segment(&self, u: f64) -> usize {
        segment_at(&self.arc, u, self.path.feed.len())
    }

    /// The original's planned speed at arc length `u`.
    fn speed(&self, u: f64) -> f64 {
        let seg = self.segment(u);
        self.path
            .planned
            .get(seg)
            .map_or(0.0, |p| p.speed_at(u - self.arc[seg]))
    }

    /// The original's highest planned speed between arc lengths `u0 ≤ u1`.
    fn top(&self, u0: f64, u1: f64) -> f64 {
        (self.segment(u0)..=self.segment(u1))
            .map(|k| {
                self.path.planned.get(k).map_or(f64::INFINITY, |p| {
                    p.max_speed_between(u0 - self.arc[k], u1 - self.arc[k])
                })
            })
            .fold(0.0, f64::max)
    }

    /// The limits of original segment `seg`: `A_n` the acceleration the firmware ran it with.
    fn limits_at(&self, seg: usize) -> KinematicLimits {
        let s = self.s;
        let mut l = s.limits;
        if let Some(p) = self.path.planned.get(seg).filter(|p| p.acceleration > 0.0) {
            l.normal_accel_mm_s2 = p.acceleration.min(s.max_normal_accel_mm_s2);
            if let Some(f1) = s.jerk_per_accel_hz {
                l.normal_jerk_mm_s3 = l.normal_accel_mm_s2 * f1;
            }
        }
        l
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A joined segment's stretch curvature is its steps' turn over their length: a 9 mm
    /// straight step and a 1 mm step turning 0.5 rad (mean curvature 0.5/mm) give 0.05/mm,
    /// a tenth of the curved step's; a segment of one step keeps that step's.
    #[test]
    fn a_joined_segments_stretch_curvature_is_its_turn_over_its_length() {
        let sample = |mean_kappa: f64| Sample {
            u: 0.0,
            p: [0.0; 3],
            kappa: mean_kappa,
            mean_kappa,
            stretch_kappa: mean_kappa,
            step_mm: 0.0,
        };
        let walked = [sample(0.0), sample(0.0), sample(0.5)];
        let points = [[0.0, 0.0, 0.2], [9.0, 0.0, 0.2], [10.0, 0.0, 0.2]];
        assert!((stretch_curvature(&walked, &points, 0, 2) - 0.05).abs() < 1e-12);
        assert_eq!(stretch_curvature(&walked, &points, 1, 2), 0.5);
        assert_eq!(stretch_curvature(&walked, &points, 0, 1), 0.0);
    }

    /// Turns over the critical angle of `settings()` (30°) along `start` then `points`.
    fn sharp_turns_from(start: [f64; 3], points: &[[f64; 3]]) -> usize {
        let cos = settings().critical_rad.cos();
        crate::vtg::rewrite::sharp_turns(std::iter::once(&start).chain(points), cos)
    }

    /// The settings the tests rewrite with: 0.1 mm, 30°, VTG eq. 29 speeds from scale 1.
    pub(crate) fn settings() -> Settings {
        Settings {
            tolerance_mm: 0.1,
            critical_rad: 30f64.to_radians(),
            limits: KinematicLimits {
                v_max_mm_s: 200.0,
                interpolation_period_s: 0.001,
                chord_tolerance_mm: 0.1,
                normal_accel_mm_s2: 1000.0,
                normal_jerk_mm_s3: 1e5,
                nozzle_radius_mm: 0.2,
            },
            limit_feed: true,
            max_normal_accel_mm_s2: 1000.0,
            jerk_per_accel_hz: None,
            min_step_mm: TUNING.klipper_min_step_mm,
            classic_jerk_mm_s: None,
            feed_cap_scale: 1.0,
            stretch: false,
            arcs: false,
            min_speed_share: 1.0,
            keyholes: true,
            line: blend::Line::Racing,
            klipper_scv_mm_s: None,
            arc_cutting: None,
            lean: false,
            min_segment_s: Some(0.0),
            max_blocks_per_s: f64::INFINITY,
        }
    }

    /// A corner pays when the machine runs round the fillet at least as fast as it left the
    /// sharp corner, or at least the settings' share of that speed.
    #[test]
    fn a_dearer_variant_rounds_corners_down_to_its_share_of_the_sharp_speed() {
        let before = Profile {
            entry: 100.0,
            peak: 100.0,
            exit: 50.0,
            acceleration: 5000.0,
            ..Profile::default()
        };
        // √(1000 mm/s² × 1.6 mm) = 40 mm/s on the fillet: 80 % of the 50 mm/s corner
        // (the settings' 1000 mm/s² X/Y limit is below the 5000 the move used).
        let curvature = 1.0 / 1.6;
        let with = |min_speed_share| Settings {
            min_speed_share,
            ..settings()
        };
        assert!(!pays(curvature, Some(&before), &with(1.0)));
        assert!(pays(curvature, Some(&before), &with(0.79)));
        assert!(!pays(curvature, Some(&before), &with(0.81)));
        assert!(pays(curvature, Some(&before), &with(0.0)));
        // Where the sharp corner's speed is not known, rounding is assumed to pay.
        assert!(pays(curvature, None, &with(1.0)));
        // A classic-jerk planner has no virtual arc to compete with.
        let classic = Settings {
            classic_jerk_mm_s: Some(8.0),
            ..with(1.0)
        };
        assert!(pays(curvature, Some(&before), &classic));
    }

    /// A path whose corners are all decided alike at every dearer speed share is smoothed to
    /// the same bits at those shares (what lets the dearer variants be left out); one whose
    /// corner is declined at the free share and taken at a dearer one is told apart.
    #[test]
    fn a_smoothing_that_no_dearer_share_would_decide_otherwise_is_theirs() {
        let pts = [[0.0, 0.0, 0.2], [10.0, 0.0, 0.2], [10.0, 10.0, 0.2]];
        let (e, feed) = ([0.0, 0.4, 0.8], [50.0, 50.0]);
        let planned = |exit| Profile {
            entry: 50.0,
            peak: 50.0,
            exit,
            acceleration: 1000.0,
            ..Profile::default()
        };
        let at = |exit, min_speed_share| {
            let planned = [planned(exit), planned(exit)];
            let path = SmoothPath {
                pts: &pts,
                e: &e,
                feed: &feed,
                planned: &planned,
            };
            let s = Settings {
                min_speed_share,
                ..settings()
            };
            share_dependence(|| smooth_path(&path, &s).map(|r| r.points))
        };
        // Slow into the corner (5 mm/s): every fillet keeps up at any share.
        let (free, depends) = at(5.0, 1.0);
        assert!(!depends && free.is_some());
        for &share in &TUNING.dearer_speed_shares {
            assert_eq!(at(5.0, share).0, free);
        }
        // Fast into it (500 mm/s): kept sharp at the free share, rounded at a dearer one.
        let (free, depends) = at(500.0, 1.0);
        assert!(depends);
        let dearest = TUNING.dearer_speed_shares.into_iter().fold(1.0, f64::min);
        assert_ne!(at(500.0, dearest).0, free);
    }

    /// A right angle between long legs is walked on the racing line: out past the first leg,
    /// round a circle about 2.4 times the inside fillet's, and back, within the tolerance.
    #[test]
    fn a_right_angle_is_walked_on_the_racing_line() {
        let pts = [[0.0, 0.0, 0.2], [10.0, 0.0, 0.2], [10.0, 10.0, 0.2]];
        let e = [0.0, 0.4, 0.8];
        let feed = [50.0, 50.0];
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        // The tightest circle through three consecutive points, and how far the path strays
        // outside the first leg.
        let shape = |line| {
            let s = Settings { line, ..settings() };
            let r = smooth_path(&path, &s).expect("rounded");
            let mut all = vec![pts[0]];
            all.extend_from_slice(&r.points);
            assert!(both_ways(&all, &pts, 1e-3, 0.0) <= 0.1);
            assert_eq!(sharp_turns_from(pts[0], &r.points), 0);
            let tightest = all
                .windows(3)
                .filter_map(|w| crate::vtg::arcs::circle_through(&w[0], &w[1], &w[2]))
                .map(|(_, r)| r)
                .fold(f64::INFINITY, f64::min);
            let outside = all.iter().map(|p| -p[1]).fold(0.0, f64::max);
            (tightest, outside)
        };
        let (inside_r, inside_out) = shape(blend::Line::Inside);
        let (racing_r, racing_out) = shape(blend::Line::Racing);
        assert!(inside_out < 0.02, "{inside_out}");
        assert!(racing_out > 0.06, "{racing_out}");
        assert!(racing_r > 2.0 * inside_r, "{racing_r} vs {inside_r}");
    }

    #[test]
    fn square_loop_is_rounded() {
        let pts = [
            [121.557, 101.617, 0.2],
            [121.557, 101.557, 0.2],
            [128.443, 101.557, 0.2],
            [128.443, 108.443, 0.2],
            [121.557, 108.443, 0.2],
            [121.557, 101.617, 0.2],
        ];
        let mut e = vec![0.0];
        for w in pts.windows(2) {
            let l = crate::vec3::norm(crate::vec3::sub(w[1], w[0]));
            e.push(e.last().unwrap() + 0.03 * l);
        }
        let feed = vec![20.0; pts.len() - 1];
        let s = settings();
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        let r = smooth_path(&path, &s).expect("smoothed");
        assert!(r.deviation_mm <= 0.1);
        // Filament is conserved and the end is the original end.
        assert!((r.e.last().unwrap() - e.last().unwrap()).abs() < 1e-12);
        assert_eq!(r.points.last(), pts.last());
        // The square's three roundable corners are rounded: fewer sharp turns than before
        // (the first corner, 0.06 mm from the start, is kept).
        let sharp = sharp_turns_from(pts[0], &r.points);
        assert!(sharp < 4, "{sharp}");
    }

    /// The tip of a thin wedge (136°, legs of 0.07 mm steps), too tight to fillet in Marlin's
    /// 0.06 mm steps: with keyholes it is turned round a loop, every turn of the new path is
    /// under the critical angle, and it stays within the tolerance with the filament kept;
    /// without, the tip is kept sharp.
    #[test]
    fn a_wedge_tip_is_turned_round_a_keyhole() {
        let half = 22f64.to_radians();
        let leg = |k: usize, side: f64| {
            let d = 0.07 * k as f64;
            [10.0 + d * half.cos(), 10.0 + side * d * half.sin(), 0.2]
        };
        let mut pts: Vec<[f64; 3]> = (1..=20).rev().map(|k| leg(k, 1.0)).collect();
        pts.push(leg(0, 1.0));
        pts.extend((1..=20).map(|k| leg(k, -1.0)));
        let e: Vec<f64> = (0..pts.len()).map(|k| 0.002 * k as f64).collect();
        let feed = vec![30.0; pts.len() - 1];
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        let s = Settings {
            min_step_mm: TUNING.marlin_min_step_mm,
            ..settings()
        };
        let r = smooth_path(&path, &s).expect("keyhole");
        assert_eq!(r.keyholes, 1);
        assert_eq!(sharp_turns_from(pts[0], &r.points), 0);
        let mut all = vec![pts[0]];
        all.extend_from_slice(&r.points);
        let d = both_ways(&all, &pts, 1e-3, 0.0);
        assert!(d <= 0.1, "{d}");
        assert!((r.e.last().unwrap() - e.last().unwrap()).abs() < 1e-12);
        assert!(r.e.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(r.points.last(), pts.last());
        let plain = Settings {
            keyholes: false,
            ..s
        };
        let kept = smooth_path(&path, &plain).map_or(pts[1..].to_vec(), |r| r.points);
        assert_eq!(sharp_turns_from(pts[0], &kept), 1);
    }

    /// Infill turning back at the wall (a hairpin) is rounded with keyholes on or off: the
    /// variant without them (the closed loop's last resort) handles hairpins the same way.
    #[test]
    fn hairpins_are_rounded_with_or_without_keyholes() {
        // Lines 0.28 mm apart joined square to them: each 90° corner has too little of the
        // connector to be filleted alone in Marlin's steps.
        let pts = [
            [10.0, 0.0, 0.2],
            [0.0, 0.0, 0.2],
            [0.0, 0.28, 0.2],
            [10.0, 0.28, 0.2],
        ];
        let e = [0.0, 0.4, 0.4112, 0.8112];
        let feed = [40.0; 3];
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        let on = Settings {
            min_step_mm: TUNING.marlin_min_step_mm,
            ..settings()
        };
        let off = Settings {
            keyholes: false,
            ..on
        };
        let a = smooth_path(&path, &on).expect("rounded");
        let b = smooth_path(&path, &off).expect("rounded");
        assert_eq!(a.points, b.points);
        assert_eq!((a.keyholes, b.keyholes), (0, 0));
        assert!(a.deviation_mm <= 0.1);
        // Round as one turn: no step of it turns by the critical angle, and none is empty.
        assert_eq!(sharp_turns_from(pts[0], &a.points), 0);
        assert!(a.points.windows(2).all(|w| w[0] != w[1]) && a.points[0] != pts[0]);
    }

    /// Ten layers of a 20 mm square at 200 mm/s on a Klipper machine with a square-corner
    /// velocity of 50 mm/s: every corner costs time and energy to round.
    fn klipper_square() -> String {
        let mut src = String::from(
            "SET_VELOCITY_LIMIT ACCEL=5000 ACCEL_TO_DECEL=2500 SQUARE_CORNER_VELOCITY=50\nM83\n",
        );
        src.push_str("G1 X60 Y50 F30000\nG1 Z0.2\nG1 F12000\n");
        for _ in 0..10 {
            for (x, y) in [(70.0, 50.0), (70.0, 70.0), (50.0, 70.0), (50.0, 50.0)] {
                let e = if x == 70.0 && y == 50.0 { 0.3 } else { 0.6 };
                src.push_str(&format!("G1 X{x} Y{y} E{e}\n"));
            }
        }
        src.push_str("G1 X60 Y50 E0.3\n");
        src
    }

    /// The same square with time allowed but no more energy (the default): the time is spent
    /// only while the file's energy does not rise, so fewer corners go than with energy allowed,
    /// and the energy, as `analyze` measures the written file, is not higher.
    #[test]
    fn klipper_square_time_allowance_buys_no_energy_by_default() {
        let src = klipper_square();
        let options = |energy_pct: f64| crate::vtg::VtgOptions {
            dynamics: false,
            allow_slower_pct: 10.0,
            allow_more_energy_pct: energy_pct,
            allow_more_lines_pct: 1000.0,
            ..Default::default()
        };
        let guarded = crate::vtg::vtg(src.as_bytes(), &options(0.0)).expect("vtg");
        let free = crate::vtg::vtg(src.as_bytes(), &options(10.0)).expect("vtg");
        let e = &guarded.table2.energy_j;
        assert!(e.after <= e.before, "{e:?}");
        assert!(free.table2.energy_j.after > free.table2.energy_j.before);
        assert!(
            guarded.table1.n_turning.after > free.table1.n_turning.after,
            "{:?} {:?}",
            guarded.table1.n_turning,
            free.table1.n_turning
        );
    }

    /// On a Klipper machine whose square-corner velocity takes sharp corners fast (the K1's
    /// 50 mm/s at 5000 mm/s²), every corner of a square costs time to round; the polygons placed
    /// for its look-ahead cost about 3.5 ms a corner through the real planner, where a fillet
    /// fitted and walked cost 5.6 ms and a circle on the racing line 4.5 ms. Bought with the
    /// time allowed, all 40 corners go.
    #[test]
    fn klipper_square_corners_are_bought_as_polygons() {
        let src = klipper_square();
        let options = crate::vtg::VtgOptions {
            dynamics: false,
            allow_slower_pct: 10.0,
            // Every corner here costs time and energy: the energy guard is tested apart.
            allow_more_energy_pct: 10.0,
            // Rounding a rectangle's corners adds lines; the line budget is tested apart.
            allow_more_lines_pct: 1000.0,
            ..Default::default()
        };
        let r = crate::vtg::vtg(src.as_bytes(), &options).expect("vtg");
        assert_eq!(r.table1.n_turning.before, 40.0);
        assert_eq!(r.table1.n_turning.after, 0.0, "{:?}", r.table1.n_turning);
        assert!(r.max_deviation_mm <= 0.1, "{}", r.max_deviation_mm);
        let t = &r.table2.time_s;
        let per_corner_ms = (t.after - t.before) / 40.0 * 1e3;
        eprintln!("{per_corner_ms} ms a corner");
        assert!(
            per_corner_ms > 0.0 && per_corner_ms < 4.0,
            "{per_corner_ms}"
        );
    }

    /// On a classic-jerk machine the rewritten corners are no slower than the sharp ones and
    /// the ramps leave no junction stalled, with the real planner.
    #[test]
    fn classic_jerk_rectangle_is_not_slower_through_the_planner() {
        let mut src = String::from("M83\nM201 X1000 Y1000\nM204 P1250\nM205 X8 Y8\n");
        src.push_str("G1 X100 Y100 F6000\nG1 Z0.2\n");
        for _ in 0..10 {
            for (x, y) in [
                (120.0, 100.0),
                (120.0, 110.0),
                (100.0, 110.0),
                (100.0, 100.0),
            ] {
                src.push_str(&format!("G1 X{x} Y{y} E0.5 F3600\n"));
            }
        }
        let options = crate::vtg::VtgOptions {
            dynamics: false,
            // Rounding a rectangle's corners adds lines; the line budget is tested apart.
            allow_more_lines_pct: 1000.0,
            ..Default::default()
        };
        let r = crate::vtg::vtg(src.as_bytes(), &options).expect("vtg");
        assert!(r.paths.rewritten > 0);
        assert!(
            r.table1.n_turning.change_pct <= -40.0,
            "{:?}",
            r.table1.n_turning
        );
        let t = &r.table2.time_s;
        assert!(t.after <= t.before * 1.01, "{t:?}");
    }
}
