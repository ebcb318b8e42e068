//! Algorithm 1 of the VTG paper: walk the fitted curve with the second-order Taylor interpolator
//! (VTG eq. 27) and correct each step with Newton's method so consecutive points are exactly `L_i`
//! apart.
//!
//! The paper leaves `L_i` open; here it is what a CAM interpolator would pick: the longest step
//! whose chord stays within the chord tolerance of the curve (sagitta `L²κ/8 ≤ δ`) and turns by
//! at most a fraction of the critical angle (`κ·L ≤ θ_step`, so a rounded corner is walked in
//! several gentle turns instead of one sharp one). It is first guessed from the curvature
//! sampled ahead ([`CurvatureIndex::longest_step`]), then checked on the stretch the step
//! covers; where it does not hold, halved and bisected until it does. Line 2 of Algorithm 1
//! has `⟨C', C'⟩` where VTG eq. 27 has `⟨C', C''⟩`; VTG eq. 27 is used. Line 5's `F` is the
//! step error `‖C(u) − P_i‖ − L_i`, and the damping `φ` of the paper scales the Newton step.
//! Points are taken on the curve (`P_{i+1} = C(u_{i+1})`), which line 11 also gives once
//! Newton has converged.

use crate::vec3::{dot, norm, sub};
use crate::vtg::bspline::{Curve, Eval};

/// Settings of the walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Walk {
    /// Chord tolerance between the curve and each step's chord, mm.
    pub(crate) chord_tol_mm: f64,
    /// Largest turn a step may cover, rad.
    pub(crate) max_turn_rad: f64,
    /// Longest step, mm.
    pub(crate) max_step_mm: f64,
    /// Shortest step, mm: below it the written coordinates' rounding (0.001 mm) would turn the
    /// direction of a segment by more than a couple of degrees. Where the curve is tighter than
    /// this step allows, the step is taken anyway (the turn is then sharper than asked).
    pub(crate) min_step_mm: f64,
    /// Newton damping φ (1 = plain Newton).
    pub(crate) phi: f64,
    /// Newton stops when `|‖C(u) − P_i‖ − L_i| ≤ newton_tol_mm`.
    pub(crate) newton_tol_mm: f64,
}

/// One interpolated point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sample {
    /// Curve parameter.
    pub(crate) u: f64,
    /// `C(u)`.
    pub(crate) p: [f64; 3],
    /// Largest curvature of the curve over the step that ends here, 1/mm.
    pub(crate) kappa: f64,
    /// Mean curvature over that step (turn of the tangent over the chord), 1/mm: what the
    /// feed rate of the written segment must respect.
    pub(crate) mean_kappa: f64,
    /// Mean curvature over the stretch of the curve the written segment stands for (the
    /// tangent's turn over its length), 1/mm: `mean_kappa` until steps are joined.
    pub(crate) stretch_kappa: f64,
    /// The step `L_i` asked for (0 for the first point and the shortened last step).
    pub(crate) step_mm: f64,
}

/// Steps walked, and the Newton error (VTG eq. 28's speed fluctuation in mm).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct WalkStats {
    /// Steps taken.
    pub(crate) steps: u64,
    /// Sum of `|L_i − ‖P_{i+1} − P_i‖| / L_i` (VTG eq. 28) over full steps.
    pub(crate) fluctuation_sum: f64,
}

/// Walks `curve` from start to end. Returns the points (first = `C(start)`, last = `C(end)`)
/// or `None` if the walk does not converge (degenerate curve).
pub(crate) fn walk_curve(curve: &Curve, w: &Walk, stats: &mut WalkStats) -> Option<Vec<Sample>> {
    let (u_start, u_end) = (curve.start(), curve.end());
    if u_end.is_nan() || u_start.is_nan() || u_end <= u_start {
        return None;
    }
    let first = curve.eval(u_start);
    let mut out = vec![Sample {
        u: u_start,
        p: first.p,
        kappa: first.curvature(),
        mean_kappa: 0.0,
        stretch_kappa: 0.0,
        step_mm: 0.0,
    }];
    let end = curve.eval(u_end);
    let walker = Walker {
        curve,
        w,
        index: CurvatureIndex::new(curve),
        u_end,
        end_p: end.p,
        end_kappa: Some(end.curvature()),
    };
    let mut u = u_start;
    let mut p = first.p;
    // Bounded: each accepted step advances u by at least a minimum amount.
    let max_points = 200_000usize;
    // The curve at the current point: the last step's solve evaluated it there already.
    let mut e = first;
    while out.len() < max_points {
        let (un, pn, k, step, next) = walker.step(u, &p, &e)?;
        if step > 0.0 {
            let got = norm(sub(pn, p));
            stats.fluctuation_sum += ((step - got) / step).abs();
        }
        stats.steps += 1;
        let next = next.unwrap_or_else(|| curve.eval(un));
        let t1 = next.d1;
        let mean_kappa = mean_curvature(&e.d1, &t1, norm(sub(pn, p)));
        out.push(Sample {
            u: un,
            p: pn,
            kappa: k,
            mean_kappa,
            stretch_kappa: mean_kappa,
            step_mm: step,
        });
        if un >= u_end {
            return Some(out);
        }
        (u, p, e) = (un, pn, next);
    }
    None
}

/// Mean curvature of a stretch: the turn of the tangent from `t0` to `t1` over the chord
/// length (0 where either is degenerate).
fn mean_curvature(t0: &[f64; 3], t1: &[f64; 3], chord: f64) -> f64 {
    let (n0, n1) = (norm(t0), norm(t1));
    if n0 > 0.0 && n1 > 0.0 && chord > 0.0 {
        crate::math::acos((dot(t0, t1) / (n0 * n1)).clamp(-1.0, 1.0)) / chord
    } else {
        0.0
    }
}

/// A step of the walk: the parameter and point reached, the largest curvature over the step,
/// the step `L_i` asked for (0: the end, reached by a shorter or longer last step) and the
/// curve there, as the step's solve evaluated it (`None`: not evaluated there).
type Step = (f64, [f64; 3], f64, f64, Option<Eval>);

/// One curve being walked, with what every step reads: split from [`walk`] so choosing a step
/// (try, shrink, lengthen by bisection, stretch to the end) reads apart from recording it.
struct Walker<'c> {
    curve: &'c Curve,
    w: &'c Walk,
    index: CurvatureIndex,
    u_end: f64,
    end_p: [f64; 3],
    end_kappa: Option<f64>,
}

impl Walker<'_> {
    /// Largest curvature on `[a, b]`, given the curvature at the ends where known.
    fn max_curvature(&self, a: f64, b: f64, ends: [Option<f64>; 2]) -> f64 {
        self.index.max_with_ends(self.curve, a, b, ends)
    }

    /// The next step from `u` (point `p`, curve `e` there); `None` if none converges.
    fn step(&self, u: f64, p: &[f64; 3], e: &Eval) -> Option<Step> {
        let w = self.w;
        let (accepted, too_long) = self.shrink(u, p, e);
        let accepted = self.lengthen(u, p, e, accepted, too_long);
        let (mut un, mut pn, k, mut step, mut next) = accepted?;
        // Do not leave a sliver before the end: stretch this step to it instead (it is then
        // the last, shorter-or-longer step to the end, not a full `L_i`, as the end step is).
        if un < self.u_end
            && norm(sub(self.end_p, pn)) < w.min_step_mm
            && (self.u_end - un) * norm(e.d1) < 2.0 * w.min_step_mm
        {
            un = self.u_end;
            pn = self.end_p;
            step = 0.0;
            next = None;
        }
        Some((un, pn, k, step, next))
    }

    /// The first step that fits, from the longest the curvature at `u` allows, shrunk to what
    /// the curvature met on the way allows; and the shortest step tried that did not fit.
    fn shrink(&self, u: f64, p: &[f64; 3], e: &Eval) -> (Option<Step>, Option<f64>) {
        let (w, curve, u_end) = (self.w, self.curve, self.u_end);
        let kappa = e.curvature();
        // No longer than what is left of the curve (a closed loop ends near its start).
        let left = (u_end - u) * norm(e.d1) * 1.05;
        let (guess, mut sure) = match self.index.longest_step(u, p, kappa, w) {
            Some((guess, sure)) => (guess, Some(sure)),
            None => (step_for(kappa, w), None),
        };
        let mut step = guess.min(left).max(w.min_step_mm);
        let remaining = norm(sub(self.end_p, p));
        // The shortest step tried that did not fit.
        let mut too_long: Option<f64> = None;
        for _ in 0..40 {
            // The end is near along the curve, not just in space (a closed loop ends where it
            // started).
            if remaining <= step && (u_end - u) * norm(e.d1) <= 1.5 * step + 1e-9 {
                // Try the end point as the next point: the turn and sagitta of the stretch are
                // judged on its length along the curve, not on the chord, which is nothing at
                // all when a closed loop comes back to its start.
                let k = self.max_curvature(u, u_end, [Some(kappa), self.end_kappa]);
                let along = arc_length(curve, u, u_end);
                if remaining >= 0.5 * along && fits(k, along, w) {
                    return (Some((u_end, self.end_p, k, 0.0, None)), too_long);
                }
            }
            let floor = step <= w.min_step_mm;
            if let Some((un, at)) = newton(curve, u, e, p, step, w) {
                if un < u_end {
                    let k = self.max_curvature(u, un, [Some(kappa), Some(at.curvature())]);
                    if floor || fits(k, step, w) {
                        return (Some((un, at.p, k, step, Some(at))), too_long);
                    }
                }
            }
            too_long = Some(step);
            // Shrink to what the curvature met on the way allows (at least halving).
            let k = self.max_curvature(
                u,
                (u + 2.0 * step / norm(e.d1).max(1e-9)).min(u_end),
                [Some(kappa), None],
            );
            if floor {
                break;
            }
            // The surer step from the curvature samples, if the guess was longer.
            if let Some(s) = sure.take().filter(|&s| s < step) {
                step = s.max(w.min_step_mm);
                continue;
            }
            step = (0.5 * step)
                .min(step_for(k, w).max(0.25 * step))
                .max(w.min_step_mm);
        }
        (None, too_long)
    }

    /// The longest step that fits lies between the one accepted and the shortest that did
    /// not: a straight run up to a corner is then one step, not a series of ever shorter
    /// ones whose junctions the firmware would have to plan.
    fn lengthen(
        &self,
        u: f64,
        p: &[f64; 3],
        e: &Eval,
        mut accepted: Option<Step>,
        too_long: Option<f64>,
    ) -> Option<Step> {
        let (w, u_end) = (self.w, self.u_end);
        let kappa = e.curvature();
        if let (Some((_, _, _, ok, Some(_))), Some(mut bad)) = (accepted, too_long) {
            let mut ok = ok;
            for _ in 0..BISECTIONS {
                if bad - ok <= BISECT_RESOLUTION * ok {
                    break;
                }
                let mid = 0.5 * (ok + bad);
                let fitted = newton(self.curve, u, e, p, mid, w)
                    .filter(|(un, _)| *un < u_end)
                    .map(|(un, at)| {
                        let k = self.max_curvature(u, un, [Some(kappa), Some(at.curvature())]);
                        (un, at, k)
                    })
                    .filter(|(_, _, k)| fits(*k, mid, w));
                match fitted {
                    Some((un, at, k)) => {
                        accepted = Some((un, at.p, k, mid, Some(at)));
                        ok = mid;
                    }
                    None => bad = mid,
                }
            }
        }
        accepted
    }
}

/// Length of the curve between parameters `a` and `b`, as a polyline through 16 points on it
/// (only used for the last step, which is short or checked to be nearly straight).
fn arc_length(curve: &Curve, a: f64, b: f64) -> f64 {
    let mut prev = curve.eval(a).p;
    let mut sum = 0.0;
    for i in 1..=16 {
        let p = curve.eval(a + (b - a) * i as f64 / 16.0).p;
        sum += norm(sub(p, prev));
        prev = p;
    }
    sum
}

/// Bisections between the longest step found to fit and the shortest that did not.
const BISECTIONS: usize = 12;
/// Bisection stops when the bracket is this fraction of the step.
const BISECT_RESOLUTION: f64 = 0.02;

/// The step the chord tolerance and the turn allow at curvature `kappa`.
fn step_for(kappa: f64, w: &Walk) -> f64 {
    if kappa <= 1e-9 {
        return w.max_step_mm;
    }
    let chord = (8.0 * w.chord_tol_mm / kappa).sqrt();
    let turn = w.max_turn_rad / kappa;
    chord.min(turn).min(w.max_step_mm)
}

fn fits(kappa: f64, step: f64, w: &Walk) -> bool {
    kappa * step * step <= 8.0 * w.chord_tol_mm * 1.0001 && kappa * step <= w.max_turn_rad * 1.0001
}

/// Largest curvature of a curve over parameter intervals, sampled at the ends of the interval
/// and at fixed points of every knot span it touches (each span is one cubic, so its curvature
/// varies smoothly; sampling by span never steps over a short, tight span). The spans' samples
/// are computed once: a long step over many spans costs only table reads, and a partly
/// covered span its samples inside the interval and the curvature at the interval's ends.
#[derive(Debug, Clone)]
pub(crate) struct CurvatureIndex {
    /// Distinct knots.
    breaks: Vec<f64>,
    /// Curvature of span `i` (`breaks[i]..breaks[i+1]`) at `SPAN_SAMPLES` equally spaced
    /// points, ends included.
    samples: Vec<[f64; SPAN_SAMPLES]>,
    /// The curve's points there.
    points: Vec<[[f64; 3]; SPAN_SAMPLES]>,
    /// Largest of each span's samples.
    span_max: Vec<f64>,
}

/// Samples per span (its ends included).
const SPAN_SAMPLES: usize = 6;

/// The parameter of sample `j` of the span `s0..s1`: where [`CurvatureIndex::new`] evaluates
/// it and where its lookups place it, one formula for both.
#[inline]
fn sample_param(s0: f64, s1: f64, j: usize) -> f64 {
    s0 + (s1 - s0) * (j as f64 / (SPAN_SAMPLES - 1) as f64)
}

impl CurvatureIndex {
    /// Samples every span of `curve`.
    pub(crate) fn new(curve: &Curve) -> Self {
        let mut breaks: Vec<f64> = Vec::new();
        for &k in curve.knots() {
            if breaks.last().is_none_or(|&b| k > b) {
                breaks.push(k);
            }
        }
        let spans = breaks.len().saturating_sub(1);
        let mut samples: Vec<[f64; SPAN_SAMPLES]> = Vec::with_capacity(spans);
        let mut points = Vec::with_capacity(spans);
        // A span's last sample is the next one's first wherever the two parameters are the
        // same to the bit (nearly always): evaluated once, a sixth of the index's evaluations.
        let mut last: Option<(f64, Eval)> = None;
        // Inside a span the curve is one cubic: its samples there are the first one's Taylor
        // polynomial, a fifth of the cost of evaluating each (the index was two thirds of the
        // walk's evaluations).
        for w in breaks.windows(2) {
            let u: [f64; SPAN_SAMPLES] = std::array::from_fn(|j| sample_param(w[0], w[1], j));
            let first = match last {
                Some((at, e)) if at.to_bits() == u[0].to_bits() => e,
                _ => curve.eval(u[0]),
            };
            let jerk = curve.third_derivative(u[0]);
            let e: [Eval; SPAN_SAMPLES] = std::array::from_fn(|i| match (i, jerk) {
                (0, _) => first,
                (i, Some(j)) if i < SPAN_SAMPLES - 1 => first.ahead(&j, u[i] - u[0]),
                _ => curve.eval(u[i]),
            });
            last = Some((u[SPAN_SAMPLES - 1], e[SPAN_SAMPLES - 1]));
            samples.push(std::array::from_fn(|i| e[i].curvature()));
            points.push(std::array::from_fn(|i| e[i].p));
        }
        let span_max = samples
            .iter()
            .map(|s| s.iter().copied().fold(0.0, f64::max))
            .collect();
        Self {
            breaks,
            samples,
            points,
            span_max,
        }
    }

    /// The longest step from `p` (parameter `u`, curvature `kappa` there) that the sampled
    /// curvature ahead allows, and a second try; `None` when no sample ahead stops the step
    /// (the end decides). The samples are met in order, each raising the largest curvature
    /// seen, until one lies farther from `p` than the step that curvature allows. The step
    /// ends between it and the last sample that fitted: where the curvature taken as rising
    /// linearly between the two allows exactly the step (the guess), or where the failing
    /// sample's curvature allows it (the second try, surer where the curvature rises faster
    /// than that, and taken only if shorter than the guess). Both are checked as any step is:
    /// on a corner they spare the halving and bisection that would otherwise find that
    /// length.
    pub(crate) fn longest_step(
        &self,
        u: f64,
        p: &[f64; 3],
        kappa: f64,
        w: &Walk,
    ) -> Option<(f64, f64)> {
        let first = self.breaks.partition_point(|&k| k <= u).saturating_sub(1);
        let (mut k_max, mut reached) = (kappa, 0.0f64);
        // `step_for(k_max)`, worked out again only where a sample raises `k_max`.
        let mut allowed_max = step_for(k_max, w);
        for i in first..self.samples.len() {
            for j in 0..SPAN_SAMPLES {
                // Past the first span every sample is past `u` (`breaks[first + 1] > u`).
                if i == first && self.sample_at(i, j) <= u {
                    continue;
                }
                let sample = self.samples[i][j];
                let (k_before, k_here) = (k_max, k_max.max(sample));
                let chord = norm(sub(self.points[i][j], *p));
                let allowed = if sample > k_max {
                    step_for(k_here, w)
                } else {
                    allowed_max
                };
                if chord > allowed {
                    let sure = allowed.max(reached);
                    return Some((crossing([reached, chord], [k_before, k_here], w), sure));
                }
                (k_max, reached, allowed_max) = (k_here, chord, allowed);
            }
        }
        None
    }

    /// The parameter of sample `j` of span `i`, as the lookups place it.
    #[inline]
    fn sample_at(&self, i: usize, j: usize) -> f64 {
        sample_param(self.breaks[i], self.breaks[i + 1], j)
    }

    /// Largest curvature on `[a, b]`.
    #[cfg(all(test, not(target_arch = "wasm32")))]
    pub(crate) fn max(&self, curve: &Curve, a: f64, b: f64) -> f64 {
        self.max_with_ends(curve, a, b, [None, None])
    }

    /// [`Self::max`] given the curvature at `a` and/or `b` where the caller has already
    /// evaluated the curve there (the walk has, at its current point and at the Newton
    /// solution): the same figure without evaluating again.
    pub(crate) fn max_with_ends(
        &self,
        curve: &Curve,
        a: f64,
        b: f64,
        ends: [Option<f64>; 2],
    ) -> f64 {
        // Spans: i such that breaks[i] < b and breaks[i+1] > a.
        let first = self.breaks.partition_point(|&k| k <= a).saturating_sub(1);
        let mut best = 0.0f64;
        let mut partial = false;
        let mut i = first;
        while i + 1 < self.breaks.len() {
            let (s0, s1) = (self.breaks[i], self.breaks[i + 1]);
            if s0 >= b {
                break;
            }
            if a <= s0 && b >= s1 {
                best = best.max(self.span_max.get(i).copied().unwrap_or(0.0));
            } else {
                partial = true;
                for (k, &c) in self.samples.get(i).into_iter().flatten().enumerate() {
                    let at = self.sample_at(i, k);
                    if at >= a && at <= b {
                        best = best.max(c);
                    }
                }
            }
            i += 1;
        }
        if partial {
            let [ka, kb] = ends;
            best = best
                .max(ka.unwrap_or_else(|| curve.eval(a).curvature()))
                .max(kb.unwrap_or_else(|| curve.eval(b).curvature()));
        }
        best
    }
}

/// The step `L` in `[a, b]` that the curvature allows exactly, the curvature rising linearly
/// from `k[0]` at `a` to `k[1]` at `b` (`a` fits, `b` does not): bisected to a thousandth
/// of the bracket, from below.
fn crossing([mut a, mut b]: [f64; 2], k: [f64; 2], w: &Walk) -> f64 {
    let (from, span) = (a, b - a);
    if span <= 0.0 {
        return a;
    }
    for _ in 0..10 {
        let mid = 0.5 * (a + b);
        let k_mid = k[0] + (k[1] - k[0]) * (mid - from) / span;
        if mid <= step_for(k_mid, w) {
            a = mid;
        } else {
            b = mid;
        }
    }
    a
}

/// VTG eq. 27 predictor and Newton corrector: `u` past `u_i` with `‖C(u) − P_i‖ = L`; `e` is the
/// curve at `u_i`. Returns `u` and the curve there.
fn newton(
    curve: &Curve,
    ui: f64,
    e: &Eval,
    pi: &[f64; 3],
    step: f64,
    w: &Walk,
) -> Option<(f64, Eval)> {
    let s = norm(e.d1);
    if s < 1e-12 {
        return None;
    }
    // VTG eq. 27.
    let mut u = ui + step / s - dot(e.d1, e.d2) * step * step / (2.0 * s.powi(4));
    if u.is_nan() || u <= ui {
        u = ui + step / s;
    }
    for _ in 0..30 {
        let c = curve.eval(u);
        let v = sub(c.p, pi);
        let dist = norm(v);
        let f = dist - step;
        if f.abs() <= w.newton_tol_mm {
            return Some((u, c));
        }
        if dist < 1e-12 {
            return None;
        }
        let fp = dot(v, c.d1) / dist;
        if fp.is_nan() || fp <= 1e-12 {
            return None;
        }
        let mut next = u - w.phi * f / fp;
        // Keep the walk moving forward.
        if next <= ui {
            next = 0.5 * (ui + u);
        }
        if next > curve.end() + (u - ui) {
            next = curve.end() + (u - ui);
        }
        u = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtg::blend;
    use crate::vtg::fit::fit;

    #[test]
    fn walks_a_corner_in_gentle_equal_steps() {
        let pts = [[0.0, 0.0, 0.2], [10.0, 0.0, 0.2], [10.0, 10.0, 0.2]];
        let (d, u) = blend::samples(
            &pts,
            &blend::plan(&pts, 0.05, 0.0, blend::Line::Racing),
            2.0,
        );
        let f = fit(&d, &u, 0.02).unwrap();
        let w = Walk {
            chord_tol_mm: 0.01,
            max_turn_rad: 20f64.to_radians(),
            max_step_mm: 1e3,
            min_step_mm: 0.02,
            phi: 1.0,
            newton_tol_mm: 1e-7,
        };
        let mut st = WalkStats::default();
        let s = walk_curve(&f.curve, &w, &mut st).unwrap();
        assert!(s.len() >= 5, "{}", s.len());
        for pair in s.windows(2) {
            let got = norm(sub(pair[1].p, pair[0].p));
            if pair[1].step_mm > 0.0 {
                assert!((got - pair[1].step_mm).abs() <= 1e-7);
            }
        }
        assert_eq!(s.last().unwrap().p, [10.0, 10.0, 0.2]);
    }

    /// On a circle (a quarter of radius `R` as an exact rational cubic: the quadratic arc with
    /// weights 1, √2/2, 1 raised by one degree) the curvature is `1/R` everywhere: the first
    /// guess is the step that curvature allows (the chord bound `√(8δR)` here, under the turn
    /// bound `θR`), and the walk takes steps of that length.
    #[test]
    fn the_first_guess_on_a_circle_is_the_step_its_curvature_allows() {
        let r = 10.0;
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let w1 = (1.0 + 2.0 * h) / 3.0;
        let ctrl = vec![
            [r, 0.0, 0.2],
            [r, r * 2.0 * h / (3.0 * w1), 0.2],
            [r * 2.0 * h / (3.0 * w1), r, 0.2],
            [0.0, r, 0.2],
        ];
        let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let curve = Curve::rational(knots, ctrl, vec![1.0, w1, w1, 1.0]);
        for u in [0.0, 0.3, 0.7, 1.0] {
            let e = curve.eval(u);
            assert!((e.p[0].hypot(e.p[1]) - r).abs() < 1e-9);
            assert!((e.curvature() - 1.0 / r).abs() < 1e-9);
        }
        let w = Walk {
            chord_tol_mm: 0.01,
            max_turn_rad: 0.5,
            max_step_mm: 1e4,
            min_step_mm: 0.03,
            phi: 1.0,
            newton_tol_mm: 1e-7,
        };
        let expected = (8.0 * w.chord_tol_mm * r).sqrt();
        assert!(expected < w.max_turn_rad * r);
        let index = CurvatureIndex::new(&curve);
        let e = curve.eval(curve.start());
        let (guess, sure) = index
            .longest_step(curve.start(), &e.p, e.curvature(), &w)
            .unwrap();
        assert!(
            (guess - expected).abs() < 0.02 * expected,
            "{guess} vs {expected}"
        );
        assert!(
            (sure - expected).abs() < 0.02 * expected,
            "{sure} vs {expected}"
        );
        let mut st = WalkStats::default();
        let s = walk_curve(&curve, &w, &mut st).unwrap();
        for x in &s[1..s.len() - 1] {
            assert!(
                (x.step_mm - expected).abs() < 0.03 * expected,
                "{}",
                x.step_mm
            );
        }
    }

    /// Property tests (proptest is a native-only dev-dependency).
    #[cfg(not(target_arch = "wasm32"))]
    mod props {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(48))]

            /// On random polylines: every interpolated point lies on the fitted curve, every full
            /// step equals `L_i` within the Newton tolerance, and where a step was accepted by the
            /// curvature test its curvature bound holds.
            #[test]
            fn walk_invariants(
                raw in proptest::collection::vec((-20.0f64..20.0, -20.0f64..20.0), 3..9),
            ) {
                let mut pts: Vec<[f64; 3]> = Vec::new();
                for (x, y) in raw {
                    let p = [x, y, 0.2];
                    if pts.last().is_none_or(|q: &[f64; 3]| norm(sub(p, q)) > 0.5) {
                        pts.push(p);
                    }
                }
                prop_assume!(pts.len() >= 3);
                let (d, u) = blend::samples(&pts, &blend::plan(&pts, 0.06, 0.0, blend::Line::Racing), 3.0);
                let Some(f) = fit(&d, &u, 0.02) else { return Ok(()) };
                let w = Walk {
                    chord_tol_mm: 0.03,
                    max_turn_rad: 0.45,
                    max_step_mm: 1e4,
                    min_step_mm: 0.03,
                    phi: 1.0,
                    newton_tol_mm: 1e-7,
                };
                let mut st = WalkStats::default();
                let Some(s) = walk_curve(&f.curve, &w, &mut st) else { return Ok(()) };
                let index = CurvatureIndex::new(&f.curve);
                for x in &s {
                    let on = f.curve.eval(x.u).p;
                    prop_assert!(norm(sub(on, x.p)) < 1e-12);
                }
                for pair in s.windows(2) {
                    let (a, b) = (&pair[0], &pair[1]);
                    prop_assert!(b.u > a.u);
                    if b.step_mm > 0.0 {
                        let got = norm(sub(b.p, a.p));
                        prop_assert!((got - b.step_mm).abs() <= 1e-7, "{} vs {}", got, b.step_mm);
                        if b.step_mm > w.min_step_mm {
                            // Accepted by the test, not forced by the step floor.
                            let k = index.max(&f.curve, a.u, b.u);
                            prop_assert!(k * b.step_mm <= w.max_turn_rad * 1.0001);
                            prop_assert!(k * b.step_mm * b.step_mm <= 8.0 * w.chord_tol_mm * 1.0001);
                        }
                    }
                }
            }
        }
    }
}
