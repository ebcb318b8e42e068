//! Runs both axes over the sampled trajectory: trajectory deviation (VTG eq. 15), per-layer
//! statistics and the table's acceleration signal.

use super::axis::{Axes, State};
use super::parameters::MachineDynamics;
use super::trajectory::{Command, Segment};
use super::welch::Welch;
use crate::error::{Error, ErrorKind};
use crate::progress::Progress;

/// Most simulation steps one run may take (about 55 hours of motion at 1 ms).
pub const MAX_STEPS: f64 = 2e8;
/// Steps allowed per move, and at least [`MIN_STEP_BUDGET`] in all: a real print spends well
/// under a second per move on average, so a short file that asks for days of motion (a
/// vanishing feed rate) is refused quickly instead of simulated for minutes.
pub const STEPS_PER_MOVE: f64 = 2000.0;
/// The step budget of even the smallest file (about 5.5 hours of motion at 1 ms).
pub const MIN_STEP_BUDGET: f64 = 2e7;
/// Deviations (m) and deviation velocities (m/s) below which a resting machine is taken as
/// still: 1 nm, and the speed of a 1 nm vibration at 1.6 kHz. Some modes are all but undamped
/// (the idler's), so waiting for exact zero could take minutes of simulated rest.
const STILL_M: f64 = 1e-9;
const STILL_M_S: f64 = 1e-5;

pub(super) fn still(x: &State) -> bool {
    x.iter().take(6).all(|v| v.abs() < STILL_M) && x.iter().skip(6).all(|v| v.abs() < STILL_M_S)
}

/// Running statistics of a quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Samples.
    pub count: u64,
    /// Sum.
    pub sum: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

impl Default for Stats {
    fn default() -> Self {
        Self {
            count: 0,
            sum: 0.0,
            min: f64::INFINITY,
            max: 0.0,
        }
    }
}

impl Stats {
    #[inline(always)]
    fn add(&mut self, v: f64) {
        self.count += 1;
        self.sum += v;
        self.min = self.min.min(v);
        self.max = self.max.max(v);
    }

    /// The largest raised to `v`, a peak met between samples ([`peak_between`]): the mean
    /// and the count stay those of the samples.
    #[inline]
    fn raise(&mut self, v: f64) {
        self.max = self.max.max(v);
    }

    /// Both runs' samples as one: `other`'s added to these.
    pub fn merge(&mut self, other: &Stats) {
        self.count += other.count;
        self.sum += other.sum;
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    /// Mean (0 without samples).
    pub fn mean(&self) -> f64 {
        if self.count > 0 {
            self.sum / self.count as f64
        } else {
            0.0
        }
    }

    /// Smallest (0 without samples).
    pub fn min_or_zero(&self) -> f64 {
        if self.count > 0 {
            self.min
        } else {
            0.0
        }
    }
}

/// Per-layer sums.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LayerSums {
    /// Deviation, mm.
    pub deviation: Stats,
    /// Deviation while extruding, mm (no samples in a layer that prints nothing).
    pub printing: Stats,
    /// Sum of squared acceleration samples, (m/s²)².
    pub accel_sq: f64,
    /// Acceleration samples.
    pub accel_count: u64,
}

impl LayerSums {
    /// A deviation sample `dev` (mm), taken while extruding or not.
    #[inline(always)]
    pub(super) fn add_deviation(&mut self, dev: f64, extruding: bool) {
        self.deviation.add(dev);
        if extruding {
            self.printing.add(dev);
        }
    }

    /// A peak `dev` (mm) met between samples, taken while extruding or not.
    #[inline]
    pub(super) fn raise(&mut self, dev: f64, extruding: bool) {
        self.deviation.raise(dev);
        if extruding {
            self.printing.raise(dev);
        }
    }

    /// An acceleration sample of the table (X, Y, m/s²).
    #[inline]
    pub(super) fn add_acceleration(&mut self, acc: &[f64; 2]) {
        self.accel_sq += acc[0] * acc[0] + acc[1] * acc[1];
        self.accel_count += 1;
    }
}

/// What a simulation gives.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Deviation over every sample taken during a move, mm.
    pub deviation: Stats,
    /// Where and when the largest deviation happened: X, Y (mm), time (s).
    pub max_at: [f64; 3],
    /// Deviation over the samples of extruding moves only, mm.
    pub printing: Stats,
    /// Where and when the largest deviation while extruding happened.
    pub printing_max_at: [f64; 3],
    /// Per-layer sums, by layer index.
    pub layers: Vec<LayerSums>,
    /// Steps simulated.
    pub steps: u64,
    /// Time simulated (rests skipped once the machine is still), s.
    pub simulated_s: f64,
}

/// Settings of one run.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// Interpolation period, s.
    pub ts: f64,
    /// Steps per acceleration sample.
    pub decimation: u64,
    /// Bucket of nut positions, m.
    pub bucket_m: f64,
}

impl Outcome {
    /// Nothing simulated yet, over `layers` layers.
    pub(super) fn new(layers: usize) -> Self {
        Outcome {
            deviation: Stats::default(),
            max_at: [0.0; 3],
            printing: Stats::default(),
            printing_max_at: [0.0; 3],
            layers: vec![LayerSums::default(); layers],
            steps: 0,
            simulated_s: 0.0,
        }
    }

    /// The accumulators the deviation samples of one segment go to (in layer `layer`, while
    /// extruding or not), with `counted`, its layer's sums by counting, where kept: found once
    /// for the segment.
    #[inline]
    pub(super) fn segment_sums<'a>(
        &'a mut self,
        layer: u32,
        extruding: bool,
        counted: Option<&'a mut LayerSums>,
    ) -> SegmentSums<'a> {
        SegmentSums {
            deviation: (&mut self.deviation, &mut self.max_at),
            printing: extruding.then_some((&mut self.printing, &mut self.printing_max_at)),
            layer: self.layers.get_mut(layer as usize),
            counted,
            extruding,
        }
    }

    /// An acceleration sample of the table (X, Y, m/s²) in layer `layer`.
    #[inline]
    pub(super) fn add_acceleration(&mut self, acc: &[f64; 2], layer: u32) {
        if let Some(l) = self.layers.get_mut(layer as usize) {
            l.add_acceleration(acc);
        }
    }

    /// The run of the stretch of the same timeline after this one's ([`super::split`]) added:
    /// the samples of both, each largest where it was first met.
    pub(super) fn then(&mut self, later: Outcome) {
        if later.deviation.count > 0
            && (self.deviation.count == 0 || later.deviation.max > self.deviation.max)
        {
            self.max_at = later.max_at;
        }
        if later.printing.count > 0
            && (self.printing.count == 0 || later.printing.max > self.printing.max)
        {
            self.printing_max_at = later.printing_max_at;
        }
        self.deviation.merge(&later.deviation);
        self.printing.merge(&later.printing);
        merge_layers(&mut self.layers, &later.layers);
        self.steps += later.steps;
        self.simulated_s += later.simulated_s;
    }
}

/// The accumulators of one segment's deviation samples ([`Outcome::segment_sums`]): each
/// sample and crest goes to the same sums, in the same order, as through [`Outcome`]'s own
/// methods and the counted layer's.
pub(super) struct SegmentSums<'a> {
    deviation: (&'a mut Stats, &'a mut [f64; 3]),
    /// Where the segment extrudes.
    printing: Option<(&'a mut Stats, &'a mut [f64; 3])>,
    layer: Option<&'a mut LayerSums>,
    counted: Option<&'a mut LayerSums>,
    extruding: bool,
}

impl SegmentSums<'_> {
    /// The least of the largest of every accumulator the samples go to.
    #[inline]
    fn lowest_max(&self) -> f64 {
        let file = [
            Some(&*self.deviation.0),
            self.printing.as_ref().map(|p| &*p.0),
        ];
        let layers = [self.layer.as_deref(), self.counted.as_deref()]
            .map(|l| l.map(|l| [Some(&l.deviation), self.extruding.then_some(&l.printing)]));
        (file
            .into_iter()
            .chain(layers.into_iter().flatten().flatten()))
        .flatten()
        .map(|s| s.max)
        .fold(f64::INFINITY, f64::min)
    }

    /// A deviation sample `dev` (mm) at X, Y (mm) and time `at`: counted, summed, and the
    /// largest where it is the largest yet (or the first).
    #[inline(always)]
    pub(super) fn add(&mut self, dev: f64, at: [f64; 3]) {
        let (stats, max_at) = &mut self.deviation;
        if dev > stats.max || stats.count == 0 {
            **max_at = at;
        }
        stats.add(dev);
        if let Some((stats, max_at)) = &mut self.printing {
            if dev > stats.max || stats.count == 0 {
                **max_at = at;
            }
            stats.add(dev);
        }
        if let Some(l) = &mut self.layer {
            l.add_deviation(dev, self.extruding);
        }
        if let Some(l) = &mut self.counted {
            l.add_deviation(dev, self.extruding);
        }
    }

    /// The samples `devs[i]` at `ats[i]` for `i` in `range` (from 2 on), each added where
    /// `counting`, then the crest of the sample before it between its neighbours where that
    /// is a local maximum and `crest_counts(i)`: [`SegmentSums::add`] and [`SegmentSums::raise`]
    /// in that order, sample by sample, with the same results to the bit (a test in `stream`
    /// checks it). The sums are run in locals ([`Running`]), each accumulator's samples in the
    /// same order as one by one, the counts added once, and the smallest and largest, which do
    /// not depend on the order, taken once over the run.
    #[inline]
    pub(super) fn record(
        &mut self,
        (devs, ats): (&[f64], &[[f64; 3]]),
        range: std::ops::Range<usize>,
        counting: bool,
        crest_counts: impl Fn(usize) -> bool,
    ) {
        let mut r = Running::of(self);
        for i in range {
            let dev = devs[i];
            if counting {
                for s in r.sums.iter_mut() {
                    *s += dev;
                }
                if dev > r.most || r.empty {
                    for (max, at) in r.best.iter_mut().flatten() {
                        if dev > *max || r.empty {
                            *at = ats[i];
                        }
                        *max = max.max(dev);
                    }
                    r.empty = false;
                    r.most = r.most.max(dev);
                }
                // A comparison, not `f64::min` (which also weighs NaN, in five instructions
                // where two do): the same for every sample, none of which is NaN where the
                // accumulators are not.
                if dev < r.least {
                    r.least = dev;
                }
                r.added += 1;
            }
            // The crest is found for every sample, without a branch (where three samples make
            // a local maximum is a coin toss to the branch predictor), and raised only where
            // it is one and above every accumulator's largest.
            let (y0, mid, y2) = (devs[i - 2], devs[i - 1], dev);
            let peak = peak_between(y0, mid, y2);
            if (mid >= y0) & (mid > y2) & (peak > r.most) && crest_counts(i) {
                for (max, at) in r.best.iter_mut().flatten() {
                    if peak > *max {
                        *at = ats[i - 1];
                    }
                    *max = max.max(peak);
                }
                r.most = peak;
            }
        }
        r.fold_into(self);
    }

    /// A crest `dev` (mm) met between samples near `at` ([`peak_between`]): the largest where
    /// it is above it; the count and the sums stay those of the samples.
    #[inline]
    pub(super) fn raise(&mut self, dev: f64, at: [f64; 3]) {
        let (stats, max_at) = &mut self.deviation;
        if dev > stats.max {
            **max_at = at;
        }
        stats.raise(dev);
        if let Some((stats, max_at)) = &mut self.printing {
            if dev > stats.max {
                **max_at = at;
            }
            stats.raise(dev);
        }
        if let Some(l) = &mut self.layer {
            l.raise(dev, self.extruding);
        }
        if let Some(l) = &mut self.counted {
            l.raise(dev, self.extruding);
        }
    }
}

/// What [`SegmentSums::record`] keeps while it runs through its samples.
struct Running {
    /// The sums of the file's deviation and printing figures, the layer's and the counted
    /// layer's (those not kept are summed and dropped).
    sums: [f64; 6],
    /// The largest so far of the file's two figures and where it was (what `add` and `raise`
    /// compare with), and whether the file has no sample yet.
    best: [Option<(f64, [f64; 3])>; 2],
    empty: bool,
    /// The run's smallest sample.
    least: f64,
    /// The largest of the run's samples and crests, from the least of the largest of every
    /// accumulator they go to: none of them is below it, so a sample or crest no larger leaves
    /// them all as they are and is passed over with one comparison (most are).
    most: f64,
    added: u64,
}

impl Running {
    /// Starting from the accumulators of `sums`.
    #[inline]
    fn of(sums: &SegmentSums<'_>) -> Self {
        let sums_of = |l: &Option<&mut LayerSums>| {
            l.as_ref()
                .map_or([0.0; 2], |l| [l.deviation.sum, l.printing.sum])
        };
        let printing = sums.printing.as_ref().map_or(0.0, |p| p.0.sum);
        let [ld, lp] = sums_of(&sums.layer);
        let [cd, cp] = sums_of(&sums.counted);
        Running {
            sums: [sums.deviation.0.sum, printing, ld, lp, cd, cp],
            best: [Some(&sums.deviation), sums.printing.as_ref()]
                .map(|t| t.map(|(stats, at)| (stats.max, **at))),
            empty: sums.deviation.0.count == 0,
            least: f64::INFINITY,
            most: sums.lowest_max(),
            added: 0,
        }
    }

    /// The run's figures into the accumulators of `sums`.
    #[inline]
    fn fold_into(self, sums: &mut SegmentSums<'_>) {
        let fold = |stats: &mut Stats, sum: f64| {
            stats.count += self.added;
            stats.sum = sum;
            stats.min = stats.min.min(self.least);
            stats.max = stats.max.max(self.most);
        };
        let [sd, sp, ld, lp, cd, cp] = self.sums;
        fold(sums.deviation.0, sd);
        *sums.deviation.1 = self.best[0].map_or(*sums.deviation.1, |b| b.1);
        if let (Some((stats, at)), Some(b)) = (&mut sums.printing, self.best[1]) {
            fold(stats, sp);
            **at = b.1;
        }
        let extruding = sums.extruding;
        for (l, [d, p]) in [(&mut sums.layer, [ld, lp]), (&mut sums.counted, [cd, cp])] {
            if let Some(l) = l {
                fold(&mut l.deviation, d);
                if extruding {
                    fold(&mut l.printing, p);
                }
            }
        }
    }
}

/// Per-layer sums of a later stretch of the same timeline added to `into`, layer by layer.
pub(super) fn merge_layers(into: &mut Vec<LayerSums>, later: &[LayerSums]) {
    if into.len() < later.len() {
        into.resize(later.len(), LayerSums::default());
    }
    for (l, m) in into.iter_mut().zip(later) {
        l.deviation.merge(&m.deviation);
        l.printing.merge(&m.printing);
        l.accel_sq += m.accel_sq;
        l.accel_count += m.accel_count;
    }
}

/// The peak of a deviation between three evenly spaced samples whose middle one `y1` is a
/// local maximum: the vertex of the parabola through them. Sampled every period `ts`, a
/// ringing of frequency `f` shows its crest up to `1 - cos(π f ts)` low (1.2 % at 50 Hz and
/// 1 ms, 4.9 % at 100 Hz), and by how much depends on where the samples fall. Whatever the
/// phase, the vertex is within 0.02 % of a pure ringing's crest at 50 Hz and 0.35 % at 100 Hz;
/// it is how spectrum analysers place a peak between bins.
#[inline]
pub(super) fn peak_between(y0: f64, y1: f64, y2: f64) -> f64 {
    let curvature = y0 - 2.0 * y1 + y2;
    if curvature < 0.0 {
        let offset = 0.5 * (y0 - y2) / curvature;
        y1 - 0.25 * (y0 - y2) * offset
    } else {
        y1
    }
}

/// Most jumps of the commanded velocity placed within one period ([`Jumps`]); any more (a
/// period over a run of segments shorter than an eighth of it) are spread over the period as
/// before.
pub(super) const MAX_JUMPS: usize = 8;

/// The jumps of the commanded velocity within one period, where one segment gives way to the
/// next: each with the share of the period from it to the period's end, and the jump (X, Y,
/// mm/s).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Jumps {
    count: usize,
    at: [(f64, [f64; 2]); MAX_JUMPS],
}

impl Jumps {
    /// None.
    #[inline]
    pub(super) fn clear(&mut self) {
        self.count = 0;
    }

    /// A jump `dv` a share `before_end` of the period before its end (dropped beyond
    /// [`MAX_JUMPS`]: the step then spreads it over the period).
    #[inline]
    pub(super) fn push(&mut self, before_end: f64, dv: [f64; 2]) {
        if self.count < MAX_JUMPS && (dv[0] != 0.0 || dv[1] != 0.0) {
            self.at[self.count] = (before_end, dv);
            self.count += 1;
        }
    }

    fn iter(&self) -> impl Iterator<Item = &(f64, [f64; 2])> {
        self.at[..self.count].iter()
    }
}

/// One step of both axes from the command `prev` to `next`: the velocity between them taken
/// as linear, apart from `jumps`, each placed where it happens ([`Axes::jump`]).
#[inline]
pub(super) fn step_axes(
    axes: &mut Axes,
    prev: &Command,
    next: &Command,
    jumps: &Jumps,
    ts: f64,
) -> Result<(), Error> {
    let v0 = prev.vel.map(|v| v * 1e-3);
    let mut change = core::array::from_fn(|ax| next.vel[ax] - prev.vel[ax]);
    for (_, dv) in jumps.iter() {
        change[0] -= dv[0];
        change[1] -= dv[1];
    }
    let a = change.map(|c| c * 1e-3 / ts);
    axes.step(prev.pos.map(|p| p * 1e-3), v0, a)
        .ok_or_else(model_error)?;
    for &(before_end, dv) in jumps.iter() {
        axes.jump(before_end, dv.map(|v| v * 1e-3))
            .ok_or_else(model_error)?;
    }
    Ok(())
}

/// The table's mean acceleration (X, Y, m/s²) over the `dt` since its velocity was `last_v`,
/// which becomes its velocity now (`table`: its deviation velocity now, m/s).
#[inline]
pub(super) fn table_acceleration(
    next: &Command,
    table: [f64; 2],
    last_v: &mut [f64; 2],
    dt: f64,
) -> [f64; 2] {
    let mut acc = [0.0; 2];
    for ax in 0..2 {
        let v = next.vel[ax] * 1e-3 + table[ax];
        acc[ax] = (v - last_v[ax]) / dt;
        last_v[ax] = v;
    }
    acc
}

/// Steps to the end of `segs` at period `ts` and the most steps the run may take; an error if
/// their motion would take more.
fn step_budget(segs: &[Segment], ts: f64) -> Result<(u64, f64), Error> {
    let end = segs.last().map_or(0.0, |s| s.end_s());
    // Motion time bounds the work (rests are skipped once the machine is still).
    let motion: f64 = segs.iter().map(|s| s.duration_s).sum();
    steps_to_end(motion, segs.len(), end, ts)
}

/// Steps to `end_s` at period `ts` for a trajectory of `segments` segments and `motion_s` of
/// motion, and the most steps its run may take ([`budget`]); an error if its motion would take
/// more.
pub(super) fn steps_to_end(
    motion_s: f64,
    segments: usize,
    end_s: f64,
    ts: f64,
) -> Result<(u64, f64), Error> {
    let steps = motion_s / ts;
    let budget = budget(segments);
    if steps.is_nan() || steps > budget || !end_s.is_finite() || end_s / ts > u64::MAX as f64 / 2.0
    {
        return Err(too_long());
    }
    Ok(((end_s / ts).ceil() as u64, budget))
}

/// The most steps a run of `segments` segments may take (about 5.5 hours of motion at 1 ms at
/// least, 55 hours at most).
pub(super) fn budget(segments: usize) -> f64 {
    (STEPS_PER_MOVE * segments as f64).clamp(MIN_STEP_BUDGET, MAX_STEPS)
}

pub(super) fn too_long() -> Error {
    Error::new(
        0,
        0,
        ErrorKind::InvalidOption {
            reason: "print too long to simulate at this period (over 2e8 steps, or 2000 \
                     steps a move); use a longer ts",
        },
    )
}

pub(super) fn cancelled() -> Error {
    Error::new(0, 0, ErrorKind::Cancelled)
}

fn model_error() -> Error {
    Error::new(
        0,
        0,
        ErrorKind::InvalidOption {
            reason:
                "dynamics parameters give no usable model (masses must be positive, values finite)",
        },
    )
}

/// Simulates X and Y over `segs`, pushing the table's acceleration (m/s², X and Y) into
/// `welch` every `decimation` steps (`None`: a deviation-only run, no spectrum kept).
pub fn run(
    segs: &[Segment],
    layers: usize,
    machine: &MachineDynamics,
    settings: Settings,
    welch: Option<&mut Welch>,
    progress: Progress<'_>,
) -> Result<Outcome, Error> {
    let (total, _) = step_budget(segs, settings.ts)?;
    let sizes = (Some(layers), segs.len(), Some(total));
    let mut stream = super::stream::Stream::new(machine, settings, welch, sizes);
    for s in segs {
        stream.push(*s, s.layer, progress)?;
    }
    Ok(stream.finish(progress)?.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_peak_between_samples_is_a_ringings_crest_whatever_the_phase() {
        // A parabola's vertex exactly.
        let parabola = |x: f64| 3.0 - (x - 0.3) * (x - 0.3);
        let vertex = peak_between(parabola(-1.0), parabola(0.0), parabola(1.0));
        assert!((vertex - 3.0).abs() < 1e-12, "{vertex}");
        // A 50 Hz and a 100 Hz ringing sampled every millisecond at any phase.
        for (hz, within) in [(50.0, 2.5e-4), (100.0, 3.6e-3)] {
            let step = 2.0 * std::f64::consts::PI * hz * 1e-3;
            for k in 0..=100 {
                let phase = (k as f64 / 100.0 - 0.5) * step;
                let y = |j: f64| (phase + j * step).cos();
                let crest = peak_between(y(-1.0), y(0.0), y(1.0));
                assert!(
                    (crest - 1.0).abs() < within,
                    "{hz} Hz, phase {phase}: {crest}"
                );
                assert!(crest >= y(0.0));
            }
        }
        // Not a maximum: the sample itself.
        assert_eq!(peak_between(1.0, 2.0, 3.0), 2.0);
    }
}
