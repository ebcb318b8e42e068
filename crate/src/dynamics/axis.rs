//! One axis ready to simulate: the closed-loop model in linear units, discretised per
//! nut-position bucket.
//!
//! Simulation coordinates are those of [`lumped`](super::lumped) measured from the commanded
//! motion (so the numbers stay small over a metre of travel), with the angles turned into the
//! table travel they correspond to (`i_s θ`, m) so that every entry of the state matrix has the
//! same units and the matrix exponential is well scaled. State `x = [q̃, q̃̇]`; `q̃[3]` is the
//! table's deviation from the commanded position, m.

use nalgebra::{DMatrix, SVector};

use super::integrate::discretize;
use super::lumped::{dof, Coefficients, Mat6, Matrices, Vec6};
use super::modal::{self, state_matrix, Mode};
use super::modal_step::{product, ModalPair, ModalStepper};
use super::parameters::Drive;
use super::steppers::StepperTable;
use std::sync::Arc;

/// Simulation state of one axis.
pub type State = SVector<f64, 12>;
/// Index of the table deviation in [`State`].
pub const TABLE: usize = dof::X4;
/// Index of the table's deviation velocity in [`State`].
pub const TABLE_VELOCITY: usize = 6 + dof::X4;

/// `Φ` and `Γ` of one bucket, as plain column-major arrays (the product below unrolls and
/// vectorises), and their modal form where it exists (the step the simulation takes).
#[derive(Debug, Clone)]
pub struct Stepper {
    phi: [[f64; 12]; 12],
    gamma: [[f64; 12]; 2],
    modal: Option<ModalStepper>,
    /// The state, at the end of a period, that a jump of 1 m/s in the commanded velocity
    /// left `j / JUMP_STEPS` of a period before it ([`jump_responses`]), in the coordinates the
    /// bucket steps in (modal where it has a modal form).
    jumps: Box<[[f64; 12]; JUMP_STEPS + 1]>,
}

/// Spans of a bucket's table of jump responses over one period ([`jump_responses`]): entries
/// 1/64 of a period apart, interpolated linearly between (at 1 ms the presets' fastest modes,
/// near 4.8 kHz, turn 0.47 rad from one entry to the next).
const JUMP_STEPS: usize = 64;

impl Stepper {
    /// One period: `x ← Φ x + Γ [v, a]` (commanded velocity at the start, m/s, and
    /// acceleration over the period, m/s²), with the dense `Φ`.
    #[inline]
    pub fn step(&self, x: &State, v: f64, a: f64) -> State {
        let mut y: [f64; 12] = (*x).into();
        self.dense_step(&mut y, v, a);
        flush_to_zero(&mut y);
        State::from(y)
    }

    #[inline]
    fn dense_step(&self, x: &mut [f64; 12], v: f64, a: f64) {
        let mut y = product(&self.phi, x);
        for (r, yr) in y.iter_mut().enumerate() {
            *yr += self.gamma[0][r] * v + self.gamma[1][r] * a;
        }
        *x = y;
    }

    /// The response at the end of a period to a jump of 1 m/s in the commanded velocity a
    /// share `before_end` (0 to 1) of the period before it.
    #[inline]
    fn jump_response(&self, before_end: f64) -> [f64; 12] {
        let x = (before_end.clamp(0.0, 1.0)) * JUMP_STEPS as f64;
        let j = (x as usize).min(JUMP_STEPS - 1);
        let w = x - j as f64;
        let (r0, r1) = (&self.jumps[j], &self.jumps[j + 1]);
        core::array::from_fn(|i| r0[i] + w * (r1[i] - r0[i]))
    }

    /// Whether the bucket steps in modal coordinates.
    pub fn is_modal(&self) -> bool {
        self.modal.is_some()
    }
}

/// A decaying state would otherwise sink into subnormal numbers, which x86 handles a hundred
/// times slower (a crawl at a vanishing feed rate took minutes); 1e-200 m is zero for any
/// machine.
#[inline]
fn flush_to_zero(x: &mut [f64]) {
    for v in x {
        if v.abs() < FLUSH_TO_ZERO {
            *v = 0.0;
        }
    }
}

/// `TᵀXT` with `T = diag(1, 1, 1, 1, 1/i_s, 1/i_s)`: angles become travel.
fn to_linear(x: &Mat6, i_s: f64) -> Mat6 {
    let t = Vec6::new(1.0, 1.0, 1.0, 1.0, 1.0 / i_s, 1.0 / i_s);
    Mat6::from_fn(|r, c| x[(r, c)] * t[r] * t[c])
}

/// The closed-loop matrices in linear units and the command loads (`Tᵀ F`).
pub fn linear_model(c: &Coefficients, drive: &Drive) -> (Matrices, Vec6, Vec6) {
    let mats = c.closed_loop(drive.servo());
    let (f_v, f_a) = c.command_loads(drive.servo());
    let t = Vec6::new(1.0, 1.0, 1.0, 1.0, 1.0 / c.i_s, 1.0 / c.i_s);
    (
        Matrices {
            m: to_linear(&mats.m, c.i_s),
            c: to_linear(&mats.c, c.i_s),
            k: to_linear(&mats.k, c.i_s),
        },
        f_v.component_mul(&t),
        f_a.component_mul(&t),
    )
}

fn dyn6(m: &Mat6) -> DMatrix<f64> {
    DMatrix::from_fn(6, 6, |r, c| m[(r, c)])
}

/// Modes of the machine as it runs (mechanism and position loop) with the axis at
/// `position_m`.
pub fn modes(drive: &Drive, position_m: f64) -> Vec<Mode> {
    let c = drive.coefficients(position_m);
    let (mats, _, _) = linear_model(&c, drive);
    modal::modes(&dyn6(&mats.m), &dyn6(&mats.c), &dyn6(&mats.k))
}

/// The slowest decay rate of the machine's free motion with the axis at `position_m`, 1/s
/// ([`modal::slowest_decay`]).
pub fn slowest_decay(drive: &Drive, position_m: f64) -> Option<f64> {
    let c = drive.coefficients(position_m);
    let (mats, _, _) = linear_model(&c, drive);
    modal::slowest_decay(&dyn6(&mats.m), &dyn6(&mats.c), &dyn6(&mats.k))
}

/// Discretises the axis at `position_m` over `ts` seconds.
pub fn stepper(drive: &Drive, position_m: f64, ts: f64) -> Option<Stepper> {
    let c = drive.coefficients(position_m);
    let (mats, f_v, f_a) = linear_model(&c, drive);
    let a = state_matrix(&dyn6(&mats.m), &dyn6(&mats.c), &dyn6(&mats.k))?;
    let mut b_v = DMatrix::zeros(12, 1);
    let mut b_a = DMatrix::zeros(12, 1);
    for i in 0..6 {
        let m = mats.m[(i, i)];
        if m.is_nan() || m <= 0.0 {
            return None;
        }
        b_v[(6 + i, 0)] = f_v[i] / m;
        b_a[(6 + i, 0)] = f_a[i] / m;
    }
    let d = discretize(&a, &b_v, &b_a, ts)?;
    let modal = ModalStepper::new(&a, &d.phi, &d.gamma, [TABLE, TABLE_VELOCITY]);
    let mut jumps = Box::new(jump_responses(&a, &b_v, &b_a, ts)?);
    if let Some(m) = &modal {
        for r in jumps.iter_mut() {
            *r = m.to_modal(r);
        }
    }
    Some(Stepper {
        phi: core::array::from_fn(|c| core::array::from_fn(|r| d.phi[(r, c)])),
        gamma: core::array::from_fn(|c| core::array::from_fn(|r| d.gamma[(r, c)])),
        modal,
        jumps,
    })
}

/// The state `τ = j ts / JUMP_STEPS` after a jump of 1 m/s in the commanded velocity, from
/// rest, for `j` from 0 to [`JUMP_STEPS`]: `r(τ) = e^{Aτ} b_a + ∫₀^τ e^{As} ds b_v`. A planned
/// path's commanded velocity jumps at its corners (the junction speed turned through the
/// corner's angle), an impulse of acceleration that a period's constant acceleration would
/// spread over the whole period: the ringing it starts then depends on where the corner falls
/// between two steps (a layer's peak deviation, the layer shifted by a fraction of a
/// millisecond, moved by up to 8 %). The step adds `r(τ) Δv` for each jump instead. `r`
/// follows from one discretisation at the table's spacing `h`:
/// `r(τ + h) = Φ(h) r(τ) + Γ_v(h)`, `r(0) = b_a`.
fn jump_responses(
    a: &DMatrix<f64>,
    b_v: &DMatrix<f64>,
    b_a: &DMatrix<f64>,
    ts: f64,
) -> Option<[[f64; 12]; JUMP_STEPS + 1]> {
    let h = discretize(a, b_v, b_a, ts / JUMP_STEPS as f64)?;
    let phi: [[f64; 12]; 12] = core::array::from_fn(|c| core::array::from_fn(|r| h.phi[(r, c)]));
    let mut r: [f64; 12] = core::array::from_fn(|i| b_a[(i, 0)]);
    let mut table = [[0.0; 12]; JUMP_STEPS + 1];
    for entry in table.iter_mut() {
        *entry = r;
        r = product(&phi, &r);
        for (i, ri) in r.iter_mut().enumerate() {
            *ri += h.gamma[(i, 0)];
        }
    }
    Some(table)
}

/// State components smaller than this are set to zero every few steps (subnormal numbers
/// would slow the simulation a hundredfold).
pub const FLUSH_TO_ZERO: f64 = 1e-200;
/// Steps between two flushes of the state to zero.
const FLUSH_EVERY: u32 = 16;

/// One axis's drive discretised per bucket of nut positions ([`StepperTable`], shared with the
/// other runs on the same drive), and the bucket its state is in the coordinates of.
#[derive(Debug)]
pub struct Axis {
    /// `1 / bucket_m`: a product per step instead of a division.
    per_bucket: f64,
    table: Arc<StepperTable>,
    /// The bucket whose coordinates the axis's state is in (`usize::MAX`: none yet).
    current: usize,
}

impl Axis {
    /// Most buckets per axis.
    pub const MAX_BUCKETS: usize = 4096;

    /// `drive` simulated every `ts` seconds, with the stiffness held constant over `bucket_m`
    /// of travel.
    pub fn new(drive: Drive, ts: f64, bucket_m: f64) -> Self {
        let travel = drive.travel_m();
        let bucket_m = bucket_m.max(travel / Self::MAX_BUCKETS as f64);
        let count = ((travel / bucket_m).ceil() as usize).clamp(1, Self::MAX_BUCKETS) + 1;
        Self {
            per_bucket: 1.0 / bucket_m,
            table: StepperTable::shared(drive, ts, bucket_m, count),
            current: usize::MAX,
        }
    }

    fn bucket(&self, position_m: f64) -> usize {
        bucket_of(position_m, self.per_bucket, self.table.buckets() - 1)
    }

    /// The stepper for the axis at `position_m`, `None` if the model cannot be discretised.
    pub fn at(&self, position_m: f64) -> Option<&Stepper> {
        self.table.get(self.bucket(position_m))
    }

    /// The stepper of the bucket the state is in.
    fn current(&self) -> Option<&Stepper> {
        self.table.get(self.current)
    }

    fn modal(&self) -> Option<&ModalStepper> {
        self.current()?.modal.as_ref()
    }
}

/// The X and Y axes and their states, stepped side by side.
///
/// Where both axes' buckets have a modal form (always, on the presets), the two states step as
/// one two-lane [`ModalPair`]; a bucket change rebases only its own lane.
#[derive(Debug)]
pub struct Axes {
    axes: [Axis; 2],
    /// Row `r` of axis `l`'s state is `z[r][l]`: in the modal coordinates of its bucket where
    /// that has a modal form, else physical.
    z: [[f64; 2]; 12],
    /// The modal steps of both current buckets, where `both_modal`.
    pair: ModalPair,
    both_modal: bool,
    /// Steps since the states were last flushed to zero ([`flush_to_zero`]).
    unflushed: u32,
}

impl Axes {
    /// Both axes at rest (see [`Axis::new`]).
    pub fn new(drives: [Drive; 2], ts: f64, bucket_m: f64) -> Self {
        Self {
            axes: drives.map(|d| Axis::new(d, ts, bucket_m)),
            z: [[0.0; 2]; 12],
            pair: ModalPair::default(),
            both_modal: false,
            unflushed: 0,
        }
    }

    /// One period with the nuts at `position_m`: commanded velocities `v` (m/s) at its start
    /// and accelerations `a` (m/s²) over it. `None` if the model cannot be discretised there.
    #[inline]
    pub fn step(&mut self, position_m: [f64; 2], v: [f64; 2], a: [f64; 2]) -> Option<()> {
        for (lane, &p) in position_m.iter().enumerate() {
            let idx = self.axes[lane].bucket(p);
            if idx != self.axes[lane].current {
                self.rebase(lane, idx)?;
            }
        }
        if self.both_modal {
            self.pair.step(&mut self.z, v, a);
        } else {
            for lane in 0..2 {
                self.step_lane(lane, v[lane], a[lane])?;
            }
        }
        count_to_flush(&mut self.z, &mut self.unflushed);
        Some(())
    }

    /// Both axes' modal pair taken out for a run of steps ([`PairRun`]), where both current
    /// buckets have a modal form; [`Axes::end_run`] puts it back.
    #[inline]
    pub fn pair_run(&self) -> Option<PairRun<'_>> {
        if !self.both_modal {
            return None;
        }
        let bucket = |a: &Axis| (a.per_bucket, a.table.buckets() - 1, a.current);
        Some(PairRun {
            pair: &self.pair,
            z: self.z,
            unflushed: self.unflushed,
            buckets: [bucket(&self.axes[0]), bucket(&self.axes[1])],
        })
    }

    /// The state a [`PairRun`] stepped to, back in the axes.
    #[inline]
    pub fn end_run(&mut self, (z, unflushed): ([[f64; 2]; 12], u32)) {
        self.z = z;
        self.unflushed = unflushed;
    }

    /// A jump `dv` (m/s, X and Y) in the commanded velocities a share `before_end` (0 to 1) of
    /// the period just stepped before its end: its response added to each state
    /// (tabulated per bucket). The step itself took the velocity without the jump.
    #[inline]
    pub fn jump(&mut self, before_end: f64, dv: [f64; 2]) -> Option<()> {
        for (lane, &dv) in dv.iter().enumerate() {
            if dv != 0.0 {
                let r = self.axes[lane].current()?.jump_response(before_end);
                for (row, ri) in self.z.iter_mut().zip(r) {
                    row[lane] += ri * dv;
                }
            }
        }
        Some(())
    }

    /// Axis `lane` moves into bucket `idx`: its state into that bucket's coordinates.
    fn rebase(&mut self, lane: usize, idx: usize) -> Option<()> {
        let x = self.state(lane);
        let st = self.axes[lane].table.get(idx)?;
        let z = match &st.modal {
            Some(m) => {
                self.pair.set_lane(lane, m);
                m.to_modal(&x.into())
            }
            None => x.into(),
        };
        set_lane(&mut self.z, lane, &z);
        self.axes[lane].current = idx;
        self.both_modal = self.axes.iter().all(|a| a.modal().is_some());
        Some(())
    }

    /// One period of axis `lane` alone (a bucket without a modal form).
    fn step_lane(&mut self, lane: usize, v: f64, a: f64) -> Option<()> {
        let st = self.axes[lane].current()?;
        let mut x = lane_of(&self.z, lane);
        match &st.modal {
            Some(m) => m.step(&mut x, v, a),
            None => st.dense_step(&mut x, v, a),
        }
        set_lane(&mut self.z, lane, &x);
        Some(())
    }

    /// The physical state `[q̃, q̃̇]` of axis `lane`.
    pub fn state(&self, lane: usize) -> State {
        let x = lane_of(&self.z, lane);
        State::from(self.axes[lane].modal().map_or(x, |m| m.to_physical(&x)))
    }

    /// The tables' deviations from the commanded positions, m.
    #[inline]
    pub fn table(&self) -> [f64; 2] {
        if self.both_modal {
            self.pair.physical_rows(&self.z, 0)
        } else {
            self.rows_by_lane(0, TABLE)
        }
    }

    /// The tables' deviation velocities, m/s.
    #[inline]
    pub fn table_velocity(&self) -> [f64; 2] {
        if self.both_modal {
            self.pair.physical_rows(&self.z, 1)
        } else {
            self.rows_by_lane(1, TABLE_VELOCITY)
        }
    }

    /// Row `which` of [`ModalStepper`]'s table rows of each state on its own (`physical`: its
    /// index in the physical state), where a bucket has no modal form.
    #[cold]
    fn rows_by_lane(&self, which: usize, physical: usize) -> [f64; 2] {
        core::array::from_fn(|lane| {
            let x = lane_of(&self.z, lane);
            self.axes[lane]
                .modal()
                .map_or(x[physical], |m| m.physical_row(&x, which))
        })
    }

    /// Brings both axes to rest.
    pub fn rest(&mut self) {
        self.z = [[0.0; 2]; 12];
    }
}

/// A run of steps of both axes as one modal pair, their state held apart from [`Axes`] (in
/// registers: a step then reads no memory but the coefficients). Each step is [`Axes::step`]'s
/// for positions in the buckets the axes are in ([`PairRun::in_buckets`]), operation for
/// operation.
#[derive(Debug)]
pub struct PairRun<'a> {
    pair: &'a ModalPair,
    z: [[f64; 2]; 12],
    unflushed: u32,
    /// Each axis's `1 / bucket_m`, last bucket and current bucket.
    buckets: [(f64, usize, usize); 2],
}

impl PairRun<'_> {
    /// Whether the nuts at `position_m` are in the buckets the axes are in.
    #[inline]
    pub fn in_buckets(&self, position_m: [f64; 2]) -> bool {
        (self.buckets.iter().zip(position_m))
            .all(|(&(per_bucket, last, current), p)| bucket_of(p, per_bucket, last) == current)
    }

    /// One period: [`Axes::step`].
    #[inline]
    pub fn step(&mut self, v: [f64; 2], a: [f64; 2]) {
        self.pair.step(&mut self.z, v, a);
        count_to_flush(&mut self.z, &mut self.unflushed);
    }

    /// The tables' deviations and deviation velocities: [`Axes::table`],
    /// [`Axes::table_velocity`].
    #[inline]
    pub fn table(&self) -> [f64; 2] {
        self.pair.physical_rows(&self.z, 0)
    }

    /// See [`PairRun::table`].
    #[inline]
    pub fn table_velocity(&self) -> [f64; 2] {
        self.pair.physical_rows(&self.z, 1)
    }

    /// The state and flush count to put back ([`Axes::end_run`]).
    #[inline]
    pub fn done(self) -> ([[f64; 2]; 12], u32) {
        (self.z, self.unflushed)
    }
}

/// The bucket of a nut at `position_m`, `per_bucket` buckets a metre, the last `last`.
#[inline]
fn bucket_of(position_m: f64, per_bucket: f64, last: usize) -> usize {
    if position_m > 0.0 {
        ((position_m * per_bucket) as usize).min(last)
    } else {
        0
    }
}

/// A step taken: every [`FLUSH_EVERY`] of them the states `z` flushed to zero. Every few steps
/// is enough: a state sinks past 1e-200 only slowly, and only a component that stays
/// subnormal costs time.
#[inline]
fn count_to_flush(z: &mut [[f64; 2]; 12], unflushed: &mut u32) {
    *unflushed += 1;
    if *unflushed >= FLUSH_EVERY {
        flush_to_zero(z.as_flattened_mut());
        *unflushed = 0;
    }
}

/// Axis `lane`'s state out of the two-lane `z`.
fn lane_of(z: &[[f64; 2]; 12], lane: usize) -> [f64; 12] {
    core::array::from_fn(|r| z[r][lane])
}

/// Axis `lane`'s state into the two-lane `z`.
fn set_lane(z: &mut [[f64; 2]; 12], lane: usize, x: &[f64; 12]) {
    for (row, &v) in z.iter_mut().zip(x) {
        row[lane] = v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::parameters::MachineDynamics;

    #[test]
    fn preset_modes_are_plausible() {
        let ldam = MachineDynamics::preset("ldam-ball-screw").unwrap();
        let desk = MachineDynamics::preset("desktop-belt").unwrap();
        let lm = modes(&ldam.x, 0.5);
        let dm = modes(&desk.y, 0.1);
        assert!(lm.len() >= 4, "{lm:?}");
        assert!(dm.len() >= 4, "{dm:?}");
        // A bed-slinger's first Y mode lies in the 20–80 Hz band input shapers are tuned to.
        assert!(
            dm[0].frequency_hz > 20.0 && dm[0].frequency_hz < 80.0,
            "{dm:?}"
        );
        eprintln!("ldam x {lm:?}\ndesktop y {dm:?}");
        for m in lm.iter().chain(&dm) {
            // The screws' (motor mount's and idler's) antisymmetric mode has no damper: ζ = 0.
            assert!(m.damping_ratio >= 0.0 && m.damping_ratio < 1.0, "{m:?}");
        }
    }

    #[test]
    fn modal_steps_follow_the_dense_step_across_buckets() {
        // Back and forth over several 5 mm buckets with acceleration steps, the two axes out of
        // phase (they change buckets at different steps): each modal state (rebased at every
        // bucket change of its own axis) stays on the dense step's to rounding.
        for name in ["ldam-ball-screw", "desktop-belt"] {
            let machine = MachineDynamics::preset(name).unwrap();
            let ts = 1e-3;
            let drives = [machine.x, machine.y];
            let mut modal = Axes::new(drives, ts, 0.005);
            let dense = drives.map(|d| Axis::new(d, ts, 0.005));
            let mut pos = drives.map(|d| 0.3 * d.travel_m());
            let (mut v, mut x) = ([0.0; 2], [State::zeros(); 2]);
            let (mut largest, mut worst, mut scale) = (0.0f64, 0.0f64, 0.0f64);
            for k in 0..60_000 {
                let pattern = [2.0, 0.0, -2.0, -2.0, 0.0, 2.0];
                let a = [pattern[(k / 150) % 6], -pattern[(k / 110) % 6]];
                modal.step(pos, v, a).unwrap();
                let table = modal.table();
                for l in 0..2 {
                    assert!(dense[l].at(pos[l]).unwrap().is_modal(), "{name} at {pos:?}");
                    x[l] = dense[l].at(pos[l]).unwrap().step(&x[l], v[l], a[l]);
                    largest = largest.max(x[l][TABLE].abs());
                    worst = worst.max((table[l] - x[l][TABLE]).abs());
                    scale = scale.max(x[l].amax());
                    let diff = (modal.state(l) - x[l]).amax();
                    assert!(
                        diff <= 1e-8 * scale,
                        "{name} axis {l} step {k}: {diff} against {scale}"
                    );
                    pos[l] += v[l] * ts + 0.5 * a[l] * ts * ts;
                    v[l] += a[l] * ts;
                }
            }
            assert!(largest > 1e-7, "{name}: the table moved {largest} m");
            assert!(worst <= 1e-8 * largest, "{name}: {worst} against {largest}");
            eprintln!("{name}: table {largest:e} m, modal against dense {worst:e} m");
        }
    }

    #[test]
    fn constant_acceleration_settles_to_the_static_lag() {
        // Belt axis under a steady commanded acceleration (no feed-forward): the deviation
        // settles where the springs carry the inertia loads, x = K̃⁻¹ F̃_a a.
        let desk = MachineDynamics::preset("desktop-belt").unwrap();
        let axis = Axis::new(desk.x, 1e-3, 0.005);
        let st = axis.at(0.1).unwrap().clone();
        let mut x = State::zeros();
        for _ in 0..20_000 {
            x = st.step(&x, 0.0, 1.0);
        }
        let c = desk.x.coefficients(0.1 + 0.0025);
        let (mats, _, f_a) = linear_model(&c, &desk.x);
        let static_lag = mats.k.lu().solve(&f_a).unwrap()[TABLE];
        assert!(
            static_lag < 0.0,
            "the table lags behind an accelerating command"
        );
        // The velocity ramp inside each period adds a little viscous load.
        assert!(
            (x[TABLE] - static_lag).abs() < 0.02 * static_lag.abs(),
            "{} vs {static_lag}",
            x[TABLE]
        );
    }
}
