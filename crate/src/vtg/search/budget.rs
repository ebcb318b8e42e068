//! The file-level choice of which rewrites to write when some of them cost time or energy.
//!
//! Each path is rewritten on its own and planned on the firmware's own model before and after (see
//! [`crate::vtg::rewrite`]). Most rewrites cost nothing; on a firmware that takes sharp corners
//! faster than a fillet within the tolerance allows (Klipper with a high square-corner velocity, a
//! junction-deviation planner with a large deviation), rounding a corner costs a little time and
//! energy. Those rewrites are bought out of a budget: `Tuning::spend_share` of what the free
//! rewrites saved, plus whatever time the user allows
//! ([`crate::vtg::VtgOptions::allow_slower_pct`]), the rewrites that remove the most sharp corners
//! for their cost first: a multiple-choice knapsack, solved greedily on each path's convex hull of
//! cost against corners removed (a path may offer a free rewrite that keeps its dear corners sharp
//! and dearer ones that round some or all of them too, `Tuning::dearer_speed_shares`, each written
//! the way that costs least energy and the way that costs least time; buying a dearer one is then
//! an increment over the free one).
//!
//! Lines are the other budget. A printer's firmware reads the file a line at a time, with a
//! planner buffer of a few blocks and a serial link or SD card that carries only so many lines
//! a second (see [`crate::vtg::firmware`]); a rounded corner is walked in several steps where
//! the original had one vertex, so rounding adds lines. The file may gain no more lines than
//! [`crate::vtg::VtgOptions::allow_more_lines_pct`] allows (none by default): the rewrites that
//! save lines (a dense curve walked in longer steps, arcs) pay for those that add them, the
//! ones that remove the most sharp corners per line added first ([`free_within_lines`]), and a
//! dearer rewrite must fit what is left.

use crate::gcode::Edit;
use crate::vtg::rewrite::Rewritten;
use crate::vtg::tuning::TUNING;

/// One way of writing a path.
#[derive(Debug)]
pub(crate) struct Outcome {
    /// The edits that write it.
    pub(crate) edits: Vec<Edit>,
    /// Its counts.
    pub(crate) part: Rewritten,
    /// Time (s) and motor energy (J) it adds to the path's own (negative: saves).
    pub(crate) added: [f64; 2],
    /// Whether it costs more time or energy than the original.
    pub(crate) dearer: bool,
    /// Sharp corners it removes.
    pub(crate) corners_removed: u64,
    /// Lines it adds to the file (negative: saves).
    pub(crate) lines_added: i64,
}

impl Outcome {
    /// Whether it can stand as a path's lean rewrite ([`Offer::lean`]): it removes corners,
    /// adds no line and costs nothing.
    pub(crate) fn is_lean(&self) -> bool {
        self.corners_removed > 0 && self.lines_added <= 0 && !self.dearer
    }
}

/// The ways one path can be written.
#[derive(Debug, Default)]
pub(crate) struct Offer {
    /// One that costs nothing: written unless a dearer one is bought in its place.
    pub(crate) free: Option<Outcome>,
    /// Ones that cost time or energy; at most one is bought.
    pub(crate) dearer: Vec<Outcome>,
    /// Where the free one adds lines: one that costs nothing and adds none, the corners
    /// replaced without a line more (hairpins written as arcs) and the rest left sharp; written
    /// where the lines do not stretch to the free one.
    pub(crate) lean: Option<Outcome>,
}

impl Offer {
    /// Files `outcome` as free or dearer.
    pub(crate) fn push(&mut self, outcome: Outcome) {
        if outcome.dearer {
            self.dearer.push(outcome);
        } else if self
            .free
            .as_ref()
            .is_none_or(|f| outcome.corners_removed > f.corners_removed)
        {
            self.free = Some(outcome);
        }
    }
}

/// What may be spent: time s, motor energy J; and, when energy is not limited, the seconds a
/// joule counts for in the order of the purchases.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Budget {
    /// Time s and motor energy J that may be spent.
    pub(crate) limits: [f64; 2],
    /// Seconds a joule counts for where energy is not limited.
    pub(crate) seconds_per_joule: f64,
}

impl Budget {
    /// `Tuning::spend_share` of `saved` (time s, energy J, by the free rewrites), plus `allowed_s`
    /// of time. With time allowed, energy is not limited: the user has chosen to spend time on
    /// quiet, and energy follows time (the electronics, fans and motors run as long as the print
    /// does). It still counts in the order of the purchases, at `Tuning::energy_weight` of the
    /// print's mean power `mean_power_w`: of two ways to remove corners for about the same time,
    /// the one that costs less energy comes first, so the allowance does not raise the energy where
    /// it need not. Without time allowed, both must have been saved for anything to be spent.
    pub(crate) fn new(saved: [f64; 2], allowed_s: f64, mean_power_w: f64) -> Self {
        let share = saved.map(|x| TUNING.spend_share * x.max(0.0));
        let seconds_per_joule = if mean_power_w.is_finite() && mean_power_w > 0.0 {
            TUNING.energy_weight / mean_power_w
        } else {
            0.0
        };
        let limits = if allowed_s > 0.0 {
            [share[0] + allowed_s, f64::INFINITY]
        } else if share.iter().any(|&b| b <= 0.0) {
            [0.0, 0.0]
        } else {
            share
        };
        Self {
            limits,
            seconds_per_joule,
        }
    }

    /// The cost of adding `added` as shares of the two budgets (what it saves in one counts
    /// for it); energy without a limit counts as time at [`Budget::seconds_per_joule`].
    fn cost(&self, added: &[f64; 2]) -> f64 {
        if self.limits[1].is_infinite() {
            return (added[0] + added[1] * self.seconds_per_joule) / self.limits[0];
        }
        added[0] / self.limits[0] + added[1] / self.limits[1]
    }
}

/// One step up a path's hull: from what it had to `to`, adding `added` and removing `corners`
/// more sharp corners.
struct Step {
    path: usize,
    to: usize,
    added: [f64; 2],
    corners: u64,
    per_corner: f64,
    /// Lines it adds over what the path had.
    lines: i64,
}

/// The paths whose free rewrite fits the line budget, and the lines left for dearer ones.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LineChoice {
    /// Per offer: its free rewrite is written.
    pub(crate) keep_free: Vec<bool>,
    /// Per offer: its lean rewrite ([`Offer::lean`]) is written (its free one is not).
    pub(crate) keep_lean: Vec<bool>,
    /// Lines the dearer rewrites may still add.
    pub(crate) left: i64,
}

/// Chooses the free rewrites the file's lines allow: `allowed` more lines than the original
/// (negative: fewer), plus the lines the rewrites that save them save.
///
/// Rewrites that remove corners and add no lines are written, if the lines saved can cover
/// `-allowed` (else nothing is). Those that add lines are taken by sharp corners removed per
/// line added, most first (ties in file order), each while it fits: one that does not is
/// skipped, and smaller ones after it are still tried. Rewrites that only save lines (paths
/// written with arcs, [`super::compact`]) are drawn on as the others need their lines, the
/// largest saving first: a path is not changed for lines nothing needs. The firmware cuts an
/// arc into segments of its own, so such a path can take a little longer or cost a little
/// more energy than its chords: it is drawn only while the time and energy the rewrites
/// written so far save cover it.
pub(crate) fn free_within_lines(offers: &[Offer], allowed: i64) -> LineChoice {
    let mut keep_free = vec![false; offers.len()];
    let mut pool = Pool {
        left: allowed,
        slack: [0.0, 0.0],
    };
    let (mut adding, mut savers) = (Vec::new(), Vec::new());
    for (k, offer) in offers.iter().enumerate() {
        let Some(free) = &offer.free else { continue };
        match (free.corners_removed, free.lines_added) {
            (0, lines) if lines < 0 => savers.push((k, lines, free.added)),
            (0, _) => {}
            (_, lines) if lines <= 0 => {
                keep_free[k] = true;
                pool.take(lines, free.added);
            }
            (corners, lines) => adding.push((k, lines, corners)),
        }
    }
    let mut savers = Savers::new(savers);
    // Lines left plus those the savers not yet drawn would free: drawing a saver moves its
    // lines from one to the other, so only a rewrite taken changes it.
    let mut room = savers
        .list
        .iter()
        .fold(pool.left, |r, s| r.saturating_sub(s.1));
    // The header the estimates add (a negative `allowed`): covered now by savers that cost
    // nothing, else by those the first rewrites' savings pay for (each draw below makes room
    // for what is still owed, too); where nothing covers it, the file stays as it was.
    pool.draw(&mut savers, (0, [0.0; 2]), &mut keep_free);
    // Corners per line, compared exactly: a.corners / a.lines > b.corners / b.lines.
    adding.sort_by(|a, b| {
        (u128::from(b.2) * a.1 as u128)
            .cmp(&(u128::from(a.2) * b.1 as u128))
            .then(a.0.cmp(&b.0))
    });
    for (k, lines, _) in adding {
        if lines > room {
            continue;
        }
        let added = offers[k].free.as_ref().map_or([0.0; 2], |f| f.added);
        if pool.draw(&mut savers, (lines, added), &mut keep_free) {
            keep_free[k] = true;
            pool.take(lines, added);
            room = room.saturating_sub(lines);
        }
    }
    // The paths whose free rewrite did not fit, with their lean one where it adds no lines.
    let mut keep_lean = vec![false; offers.len()];
    for (k, offer) in offers.iter().enumerate() {
        let Some(lean) = offer.lean.as_ref().filter(|_| !keep_free[k]) else {
            continue;
        };
        if lean.is_lean() && pool.draw(&mut savers, (lean.lines_added, lean.added), &mut keep_free)
        {
            keep_lean[k] = true;
            pool.take(lean.lines_added, lean.added);
        }
    }
    if pool.left < 0 {
        return LineChoice {
            keep_free: vec![false; offers.len()],
            keep_lean: vec![false; offers.len()],
            left: allowed,
        };
    }
    LineChoice {
        keep_free,
        keep_lean,
        left: pool.left,
    }
}

impl LineChoice {
    /// The rewrite of offer `k` of `offers` the lines keep: its free one or its lean one, if
    /// either (none: it stays as it was, unless a dearer one is bought).
    pub(crate) fn kept<'o>(&self, offers: &'o [Offer], k: usize) -> Option<&'o Outcome> {
        let offer = offers.get(k)?;
        if self.keep_free.get(k).copied().unwrap_or(false) {
            offer.free.as_ref()
        } else if self.keep_lean.get(k).copied().unwrap_or(false) {
            offer.lean.as_ref()
        } else {
            None
        }
    }
}

/// What the free rewrites written so far leave: lines, and the time (s) and motor energy (J)
/// they save.
struct Pool {
    left: i64,
    slack: [f64; 2],
}

impl Pool {
    /// Writes a rewrite that adds `lines` and `added` (time s, energy J).
    fn take(&mut self, lines: i64, added: [f64; 2]) {
        self.left = self.left.saturating_sub(lines);
        self.slack = [self.slack[0] - added[0], self.slack[1] - added[1]];
    }

    /// Makes room for a rewrite that adds `lines` and `added` (time s, energy J; what it saves
    /// counts towards the savers' cost): writes savers (path, lines, cost), largest first,
    /// each if the slack pays for it, until the rewrite fits. Whether it does; if not, nothing
    /// is written.
    fn draw(
        &mut self,
        savers: &mut Savers,
        (lines, added): (i64, [f64; 2]),
        keep: &mut [bool],
    ) -> bool {
        let mut trial = Pool {
            left: self.left,
            slack: [self.slack[0] - added[0], self.slack[1] - added[1]],
        };
        let mut drawn = Vec::new();
        for k in savers.left() {
            if trial.left >= lines {
                break;
            }
            let (_, saved, cost) = savers.list[k];
            if cost[0] <= trial.slack[0].max(0.0) && cost[1] <= trial.slack[1].max(0.0) {
                trial.take(saved, cost);
                drawn.push(k);
            }
        }
        if trial.left < lines {
            return false;
        }
        for &k in drawn.iter().rev() {
            let (path, saved, cost) = savers.draw(k);
            keep[path] = true;
            self.take(saved, cost);
        }
        true
    }
}

/// The rewrites that only save lines (path, lines, cost), largest saving first, and which of
/// them are drawn. A drawn one is marked, not removed: removing each from the middle of the
/// 34 MB corpus file's 5 000 moved the rest of the list every time (0.2 s on one thread).
struct Savers {
    list: Vec<(usize, i64, [f64; 2])>,
    drawn: Vec<bool>,
    /// Every saver before this one is drawn: where [`Savers::left`] starts.
    head: usize,
}

impl Savers {
    fn new(mut list: Vec<(usize, i64, [f64; 2])>) -> Self {
        list.sort_by_key(|&(k, lines, _)| (lines, k));
        Savers {
            drawn: vec![false; list.len()],
            list,
            head: 0,
        }
    }

    /// The savers not drawn, in order.
    fn left(&self) -> impl Iterator<Item = usize> + '_ {
        (self.head..self.list.len()).filter(|&k| !self.drawn[k])
    }

    /// Draws saver `k`.
    fn draw(&mut self, k: usize) -> (usize, i64, [f64; 2]) {
        self.drawn[k] = true;
        while self.drawn.get(self.head) == Some(&true) {
            self.head += 1;
        }
        self.list[k]
    }
}

/// Chooses, for each offer, the dearer outcome to buy (`None`: the free one, or nothing): the
/// steps that remove the most sharp corners for their cost first, while they fit the budget
/// (a step that does not fit ends its path's climb; other paths' cheaper steps are still
/// tried). Ties go to file order, so the choice is the same on any number of threads. A step
/// climbs from the free rewrite where `lines` kept it, else from the original, and must also
/// fit the lines left.
pub(crate) fn choose(offers: &[Offer], budget: Budget, lines: &LineChoice) -> Vec<Option<usize>> {
    let mut choice = vec![None; offers.len()];
    if budget.limits.iter().any(|&b| b.is_nan() || b <= 0.0) {
        return choice;
    }
    let mut steps: Vec<Step> = Vec::new();
    for (path, offer) in offers.iter().enumerate() {
        let (mut added, mut corners, mut lines_added) =
            lines.kept(offers, path).map_or(([0.0, 0.0], 0, 0), |f| {
                (f.added, f.corners_removed, f.lines_added)
            });
        // The lower convex hull of cost against corners, from what the path has for free.
        loop {
            let best = offer
                .dearer
                .iter()
                .enumerate()
                .filter(|(_, o)| o.corners_removed > corners)
                .map(|(k, o)| {
                    let d = [o.added[0] - added[0], o.added[1] - added[1]];
                    let n = o.corners_removed - corners;
                    (k, d, n, budget.cost(&d) / n as f64)
                })
                .filter(|s| s.3.is_finite())
                .min_by(|a, b| a.3.total_cmp(&b.3));
            let Some((to, d, n, per_corner)) = best else {
                break;
            };
            let to_lines = offer.dearer[to].lines_added;
            steps.push(Step {
                path,
                to,
                added: d,
                corners: n,
                per_corner,
                lines: to_lines - lines_added,
            });
            added = offer.dearer[to].added;
            corners += n;
            lines_added = to_lines;
        }
    }
    // Along one path the steps' cost per corner rises (a convex hull), so in this order each
    // path's steps come in their own order.
    steps.sort_by(|a, b| {
        a.per_corner
            .total_cmp(&b.per_corner)
            .then(a.path.cmp(&b.path))
            .then(a.corners.cmp(&b.corners))
    });
    let mut left = budget.limits;
    let mut lines_left = lines.left;
    let mut stopped = vec![false; offers.len()];
    for s in steps {
        if stopped[s.path] {
            continue;
        }
        if s.added[0] <= left[0] && s.added[1] <= left[1] && s.lines <= lines_left {
            left[0] -= s.added[0];
            left[1] -= s.added[1];
            lines_left -= s.lines;
            choice[s.path] = Some(s.to);
        } else {
            stopped[s.path] = true;
        }
    }
    choice
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(added_s: f64, added_j: f64, corners: u64) -> Outcome {
        Outcome {
            edits: Vec::new(),
            part: Rewritten::default(),
            added: [added_s, added_j],
            dearer: added_s > 0.0 || added_j > 0.0,
            corners_removed: corners,
            lines_added: 0,
        }
    }

    /// [`choose`] with no limit on lines.
    fn choose_any_lines(offers: &[Offer], budget: Budget) -> Vec<Option<usize>> {
        choose(offers, budget, &free_within_lines(offers, i64::MAX / 4))
    }

    fn offer(o: Outcome) -> Offer {
        let mut offer = Offer::default();
        offer.push(o);
        offer
    }

    fn with_lines(mut o: Outcome, lines: i64) -> Outcome {
        o.lines_added = lines;
        o
    }

    #[test]
    fn lines_saved_pay_for_lines_added_most_corners_per_line_first() {
        let offers = [
            offer(with_lines(outcome(0.0, 0.0, 1), -5)), // saves 5 lines
            offer(with_lines(outcome(0.0, 0.0, 8), 4)),  // 2 corners a line: second
            offer(with_lines(outcome(0.0, 0.0, 3), 3)),  // 1 a line: no longer fits
            offer(with_lines(outcome(0.0, 0.0, 3), 1)),  // 3 a line: first
            offer(with_lines(outcome(0.0, 0.0, 2), 0)),  // adds none
        ];
        let chosen = free_within_lines(&offers, 0);
        assert_eq!(chosen.keep_free, [true, true, false, true, true]);
        assert_eq!(chosen.left, 0);
        // One more line allowed: still not the third (3 lines), so one line is left over.
        assert_eq!(free_within_lines(&offers, 1).left, 1);
        // The header needs 6 lines and only 5 are saved: nothing is written.
        let none = free_within_lines(&offers, -6);
        assert_eq!(none.keep_free, [false; 5]);
        assert_eq!(none.left, -6);
        // A dearer way that adds lines is bought only with lines left: time and energy are
        // plenty, but it adds 3 lines over the free one.
        let mut dear = offer(with_lines(outcome(-1.0, -1.0, 1), -1));
        dear.push(with_lines(outcome(-0.9, 0.2, 4), 2));
        let offers = [dear];
        let budget = || Budget::new([10.0, 10.0], 0.0, 0.0);
        let tight = free_within_lines(&offers, 0);
        assert_eq!((tight.keep_free[0], tight.left), (true, 1));
        assert_eq!(choose(&offers, budget(), &tight), [None]);
        assert_eq!(
            choose(&offers, budget(), &free_within_lines(&offers, 2)),
            [Some(0)]
        );
    }

    #[test]
    fn paths_that_only_save_lines_are_written_only_as_needed_largest_first() {
        let saver = |lines| offer(with_lines(outcome(0.0, 0.0, 0), lines));
        let offers = [
            saver(-2),
            offer(with_lines(outcome(0.0, 0.0, 6), 3)),
            saver(-4),
            saver(-1),
        ];
        // 3 lines needed: the largest saver (4) covers them, one line is left.
        let chosen = free_within_lines(&offers, 0);
        assert_eq!(chosen.keep_free, [false, true, true, false]);
        assert_eq!(chosen.left, 1);
        // Nothing needs lines: no path is changed for them.
        assert_eq!(free_within_lines(&offers[2..], 0).keep_free, [false, false]);
        // More needed than all of them save: the corners stay, and so do the savers.
        let big = [saver(-2), offer(with_lines(outcome(0.0, 0.0, 6), 8))];
        assert_eq!(free_within_lines(&big, 0).keep_free, [false, false]);
        // A rewrite that adds lines and removes no corner is never written.
        let idle = [saver(-5), offer(with_lines(outcome(-1.0, -1.0, 0), 1))];
        assert_eq!(free_within_lines(&idle, 0).keep_free, [false, false]);
    }

    #[test]
    fn dearer_rewrites_are_paid_from_half_the_savings_best_value_first() {
        // Saved 10 s and 100 J: 5 s and 50 J may be spent.
        let budget = Budget::new([10.0, 100.0], 0.0, 0.0);
        assert_eq!(budget.limits, [5.0, 50.0]);
        let offers = [
            offer(outcome(4.0, 10.0, 1)),  // 0.8 + 0.2 = 1.0 per corner
            offer(outcome(2.0, 10.0, 4)),  // 0.6 / 4 = 0.15 per corner: third
            offer(outcome(2.0, 45.0, 10)), // 1.3 / 10 = 0.13 per corner: second
            offer(outcome(0.5, 0.0, 0)),   // removes nothing: never paid
            offer(outcome(1.0, -20.0, 2)), // saves energy: -0.2 / 2 = -0.1 per corner, first
        ];
        let chosen = choose_any_lines(&offers, budget);
        // Order: #4 (1 s, -20 J; left 4 s, 70 J), #2 (2 s, 45 J; left 2 s, 25 J), #1 (2 s,
        // 10 J; left 0 s, 15 J), #0 does not fit.
        assert_eq!(chosen, [None, Some(0), Some(0), None, Some(0)]);
        let spent = offers
            .iter()
            .zip(&chosen)
            .filter_map(|(o, c)| c.map(|k| o.dearer[k].added))
            .fold([0.0, 0.0], |a, d| [a[0] + d[0], a[1] + d[1]]);
        assert!(spent[0] <= 5.0 && spent[1] <= 50.0, "{spent:?}");
    }

    #[test]
    fn nothing_is_paid_without_savings_in_both_time_and_energy() {
        for saved in [[0.0, 100.0], [10.0, 0.0], [-1.0, 100.0]] {
            let chosen = choose_any_lines(
                &[offer(outcome(0.001, 0.001, 5))],
                Budget::new(saved, 0.0, 0.0),
            );
            assert_eq!(chosen, [None], "{saved:?}");
        }
    }

    #[test]
    fn allowed_time_buys_corners_whatever_the_energy() {
        // No savings at all, 3 s allowed: energy is not limited.
        let budget = Budget::new([0.0, 0.0], 3.0, 0.0);
        assert_eq!(budget.limits, [3.0, f64::INFINITY]);
        let offers = [
            offer(outcome(2.0, 1e6, 10)), // 0.2 s per corner: first
            offer(outcome(2.0, 0.0, 4)),  // 0.5 s per corner: does not fit after the first
            offer(outcome(1.0, 5.0, 3)),  // 0.33 s per corner: second
        ];
        assert_eq!(choose_any_lines(&offers, budget), [Some(0), None, Some(0)]);
    }

    #[test]
    fn allowed_time_prefers_the_way_that_costs_less_energy_for_about_the_same_time() {
        // One path, two ways to round its 5 corners: 1 s and +100 J, or 1.2 s and -50 J; and
        // another path's 4 corners for 1.1 s and 0 J. On a print drawing 50 W, half of it: a
        // joule counts for 10 ms.
        let mut path = Offer::default();
        path.push(outcome(1.0, 100.0, 5));
        path.push(outcome(1.2, -50.0, 5));
        let offers = [path, offer(outcome(1.1, 0.0, 4))];
        let weighed = Budget::new([0.0, 0.0], 2.4, 50.0);
        assert_eq!(weighed.seconds_per_joule, TUNING.energy_weight / 50.0);
        // Per corner: 0.2 + 0.2 = 0.4 s or 0.24 - 0.1 = 0.14 s; the other 0.275 s.
        assert_eq!(choose_any_lines(&offers, weighed), [Some(1), Some(0)]);
        // Energy not counted: the faster way, and the other path still fits.
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 2.4, f64::NAN)),
            [Some(0), Some(0)]
        );
        // The time allowed still bounds what is bought: the frugal way does not fit in 1.1 s.
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 1.1, 50.0)),
            [None, Some(0)]
        );
    }

    #[test]
    fn a_dearer_variant_is_bought_as_a_step_over_the_free_one() {
        // A path that rounds 3 corners for free, or 8 for 2 s; another that rounds 5 for 3 s.
        let mut two_ways = offer(outcome(-1.0, -1.0, 3));
        two_ways.push(outcome(1.0, 0.5, 8));
        assert_eq!(two_ways.dearer.len(), 1);
        let offers = [two_ways, offer(outcome(3.0, 1.0, 5))];
        // The step over the free rewrite: 2 s for 5 more corners (0.4 s each), before the
        // other path's 0.6 s each; 2.5 s allowed buys only the first.
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 2.5, 0.0)),
            [Some(0), None]
        );
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 5.0, 0.0)),
            [Some(0), Some(0)]
        );
        // Nothing allowed: the free rewrite stays.
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 0.0, 0.0)),
            [None, None]
        );
    }

    #[test]
    fn a_path_climbs_its_hull_in_order() {
        // 2 corners for 1 s, 6 for 2 s, 7 for 5 s: the hull is 0 → 6 (1/3 s per corner) → 7
        // (3 s): the 2-corner variant is never the best step.
        let mut o = Offer::default();
        for v in [
            outcome(1.0, 0.0, 2),
            outcome(2.0, 0.0, 6),
            outcome(5.0, 0.0, 7),
        ] {
            o.push(v);
        }
        let offers = [o];
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 2.0, 0.0)),
            [Some(1)]
        );
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 4.9, 0.0)),
            [Some(1)]
        );
        assert_eq!(
            choose_any_lines(&offers, Budget::new([0.0, 0.0], 5.0, 0.0)),
            [Some(2)]
        );
    }
}
