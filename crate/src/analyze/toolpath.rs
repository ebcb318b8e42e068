//! Trajectory metrics of the VTG paper (VTG eq. 24–26, 31): lengths, point counts, turning points
//! and chord error of the printed toolpath, per file and per layer.
//!
//! The paper speaks of "trajectory points" without saying which; a slicer's file makes it
//! concrete. Here a *path* is a run of consecutive extruding moves within one feature (a travel,
//! a retraction, a zero-length move or a feature change ends it); its points are the start of its
//! first move and the end of every move. Turning angles (VTG eq. 26) and chord errors (VTG eq. 31)
//! are taken at the interior points of paths only: the corner between a travel and a print is not a
//! trajectory corner. "Infill" is sparse and solid infill (the paper's Table 1 calls the majority
//! region inside the walls infill). Arcs (`G2`/`G3`) count by their end points and by their
//! length along the arc, and turn by their tangents at those points: an arc-fitted file meets
//! its lines tangentially, where its chords would show a corner of half the sweep at each end.
//!
//! The accumulator costs a handful of multiplications, one `acos` and a few square roots per
//! move. `analyze` runs it on its read side natively, and beside the planner in the browser
//! (see `analyze::apart`), from each move's chord and [`MoveTrace`]. The metrics of a kept or
//! streamed [`crate::path`] are in [`crate::vtg::metrics`].

use serde::Serialize;

use crate::machine::Arc;
use crate::math;
use crate::math::Bound;
use crate::vec3::norm;

/// Default critical angle δθ: turns above it are sharp corners (turning points), degrees.
pub const DEFAULT_CRITICAL_ANGLE_DEG: f64 = 30.0;

/// Toolpath metrics of a file or a layer (VTG eq. 24–26, 31).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct ToolpathMetrics {
    /// Printed path length `L_total`, mm (VTG eq. 24).
    pub l_total_mm: f64,
    /// Printed infill length `L_infill`, mm (VTG eq. 25).
    pub l_infill_mm: f64,
    /// Trajectory points `n_total`.
    pub n_total: u64,
    /// Infill trajectory points `n_infill`.
    pub n_infill: u64,
    /// Turning points `n_turning`: interior points turning more than the critical angle.
    pub n_turning: u64,
    /// Interior points (where a turning angle is defined).
    pub n_corners: u64,
    /// Mean turning angle ϑ over interior points, degrees (VTG eq. 26).
    pub mean_turn_deg: f64,
    /// Mean chord error `mean(e_c)` over interior points, mm (VTG eq. 31).
    pub mean_chord_error_mm: f64,
    /// Critical angle δθ used, degrees.
    pub critical_angle_deg: f64,
}

/// Streaming accumulator of [`ToolpathMetrics`]: feed it every move in file order.
#[derive(Debug, Clone)]
pub struct MetricsAccumulator {
    cos_critical: f64,
    critical_deg: f64,
    /// The open path's incoming segment and feature.
    last: Option<Open>,
    /// Where the last move pushed by position ended.
    end: PathEnd,
    l_total: f64,
    l_infill: f64,
    n_total: u64,
    n_infill: u64,
    n_turning: u64,
    n_corners: u64,
    sum_turn: f64,
    sum_chord: f64,
}

#[derive(Debug, Clone, Copy)]
struct Open {
    seg: [f64; 3],
    len: f64,
    feature: u32,
}

/// What [`MetricsAccumulator::push_chord`] needs of a move besides its chord: whether it
/// extrudes, its feature (any identifier) and whether that is infill, and whether it starts
/// where the move before it ended (see [`PathEnd`]). `analyze` sends it to its timing side
/// with each move, so the metrics can be taken there (see `analyze::apart`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MoveTrace {
    pub extruding: bool,
    pub infill: bool,
    pub joins: bool,
}

/// The end of the move before, to tell whether the next one starts there (within 1e-9 mm
/// on each axis: a path is a run of moves each starting where the last ended).
#[derive(Debug, Clone, Copy, Default)]
pub struct PathEnd([f64; 3]);

impl PathEnd {
    /// Whether the move from `from` to `to` starts where the last one ended; `to` becomes
    /// the end. Positions shorter than XYZ never join.
    #[inline]
    pub fn step(&mut self, from: &[f64], to: &[f64]) -> bool {
        let (Some(from), Some(to)) = (from.get(..3), to.get(..3)) else {
            return false;
        };
        let joins = same_point(&self.0, from);
        self.0 = [to[0], to[1], to[2]];
        joins
    }
}

impl MetricsAccumulator {
    /// A new accumulator with critical angle δθ in degrees (clamped to 0..=180).
    pub fn new(critical_angle_deg: f64) -> Self {
        let deg = if critical_angle_deg.is_finite() {
            critical_angle_deg.clamp(0.0, 180.0)
        } else {
            DEFAULT_CRITICAL_ANGLE_DEG
        };
        Self {
            cos_critical: math::cos(deg.to_radians()),
            critical_deg: deg,
            last: None,
            end: PathEnd::default(),
            l_total: 0.0,
            l_infill: 0.0,
            n_total: 0,
            n_infill: 0,
            n_turning: 0,
            n_corners: 0,
            sum_turn: 0.0,
            sum_chord: 0.0,
        }
    }

    /// One move from `from` to `to` (XYZ, mm), along `arc` if it is one. `extruding`: it lays
    /// down material; `feature`: any identifier of the feature it belongs to; `infill`: the
    /// feature is infill.
    #[inline]
    pub fn push(
        &mut self,
        from: &[f64],
        to: &[f64],
        arc: Option<&Arc>,
        extruding: bool,
        feature: u32,
        infill: bool,
    ) {
        let joins = self.end.step(from, to);
        if from.len() < 3 || to.len() < 3 {
            self.last = None;
            return;
        }
        let chord = [to[0] - from[0], to[1] - from[1], to[2] - from[2]];
        let trace = MoveTrace {
            extruding,
            infill,
            joins,
        };
        self.push_chord(chord, arc, feature, trace);
    }

    /// One move by its chord (`to − from`, XYZ, mm), for a caller that tracks the positions
    /// itself ([`PathEnd`]): the same metrics as [`Self::push`] with the same move.
    #[inline]
    pub fn push_chord(
        &mut self,
        chord: [f64; 3],
        arc: Option<&Arc>,
        feature: u32,
        trace: MoveTrace,
    ) {
        if !trace.extruding {
            self.last = None;
            return;
        }
        let chord_len = norm(chord);
        // A line is its own direction at both ends; an arc leaves and arrives along its
        // tangents, taken as long as its chord so VTG eq. 31 sees a segment of the same size.
        let (start_seg, seg, len) = match arc {
            Some(a) => {
                let rise = chord[a.plane.axes().2];
                let along = |t: f64| {
                    let d = a.tangent_at(t, rise);
                    let n = norm(d);
                    if n > 0.0 && n.is_finite() {
                        d.map(|x| x / n * chord_len)
                    } else {
                        chord
                    }
                };
                (along(0.0), along(1.0), a.length(rise))
            }
            None => (chord, chord, chord_len),
        };
        if !len.is_finite() || len <= 1e-9 || chord_len <= 1e-9 {
            self.last = None;
            return;
        }
        self.l_total += len;
        if trace.infill {
            self.l_infill += len;
        }
        let open = self.last.filter(|o| trace.joins && o.feature == feature);
        let points = if open.is_some() { 1 } else { 2 };
        self.n_total += points;
        if trace.infill {
            self.n_infill += points;
        }
        if let Some(o) = open {
            self.corner(&o.seg, o.len, &start_seg, chord_len);
        }
        self.last = Some(Open {
            seg,
            len: chord_len,
            feature,
        });
    }

    /// The running sums as words (IEEE bits for the lengths and angle sums), for sending the
    /// metrics of a file read apart back to its read side ([`Self::from_words`]).
    pub fn to_words(&self) -> [u64; 8] {
        [
            self.l_total.to_bits(),
            self.l_infill.to_bits(),
            self.n_total,
            self.n_infill,
            self.n_turning,
            self.n_corners,
            self.sum_turn.to_bits(),
            self.sum_chord.to_bits(),
        ]
    }

    /// An accumulator with critical angle `critical_angle_deg` holding the sums of
    /// [`Self::to_words`] (its open path is not carried: the file has ended).
    pub fn from_words(critical_angle_deg: f64, w: [u64; 8]) -> Self {
        Self {
            l_total: f64::from_bits(w[0]),
            l_infill: f64::from_bits(w[1]),
            n_total: w[2],
            n_infill: w[3],
            n_turning: w[4],
            n_corners: w[5],
            sum_turn: f64::from_bits(w[6]),
            sum_chord: f64::from_bits(w[7]),
            ..Self::new(critical_angle_deg)
        }
    }

    /// Turning angle (VTG eq. 26) and chord error (VTG eq. 31) at the point between segments
    /// `a`, `b`.
    #[inline]
    fn corner(&mut self, a: &[f64; 3], la: f64, b: &[f64; 3], lb: f64) {
        let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let cos = (dot / (la * lb)).clamp(-1.0, 1.0);
        self.n_corners += 1;
        if cos < self.cos_critical {
            self.n_turning += 1;
        }
        self.sum_turn += fast_acos(cos);
        self.sum_chord += chord_error(a, la, b, lb);
    }

    /// The metrics so far.
    pub fn finish(&self) -> ToolpathMetrics {
        let per = |s: f64| {
            if self.n_corners > 0 {
                s / self.n_corners as f64
            } else {
                0.0
            }
        };
        ToolpathMetrics {
            l_total_mm: self.l_total,
            l_infill_mm: self.l_infill,
            n_total: self.n_total,
            n_infill: self.n_infill,
            n_turning: self.n_turning,
            n_corners: self.n_corners,
            mean_turn_deg: per(self.sum_turn).to_degrees(),
            mean_chord_error_mm: per(self.sum_chord),
            critical_angle_deg: self.critical_deg,
        }
    }
}

/// `acos` to within 7·10⁻⁵ rad (Abramowitz & Stegun 4.4.45): a polynomial and an IEEE square
/// root, so the same on every target, and several times cheaper than libm's `acos` on the
/// analysis' per-move path. Only the mean turning angle uses it; the turning-point count
/// compares cosines exactly.
#[inline]
pub fn fast_acos(x: f64) -> f64 {
    let a = x.abs().at_most(1.0);
    let r =
        (1.0 - a).sqrt() * (1.570_728_8 + a * (-0.212_114_4 + a * (0.074_261_0 - 0.018_729_3 * a)));
    if x >= 0.0 {
        r
    } else {
        std::f64::consts::PI - r
    }
}

fn same_point(a: &[f64; 3], b: &[f64]) -> bool {
    (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9 && (a[2] - b[2]).abs() < 1e-9
}

/// VTG eq. 31: `e_c = r − sqrt(r² − (|C_{i+1} − C_i|/2)²)` with `r` the radius of the circle
/// through `C_i`, `C_{i+1}`, `C_{i+2}` (segments `a = C_{i+1} − C_i`, `b = C_{i+2} − C_{i+1}`).
/// Written as `h²/(r + sqrt(r² − h²))` to avoid cancellation; collinear points give 0.
pub fn chord_error(a: &[f64; 3], la: f64, b: &[f64; 3], lb: f64) -> f64 {
    let c = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let lc = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let twice_area = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
    if twice_area <= 1e-15 * la * lb {
        // Collinear. A reversal (c ≈ 0) has no circle either: its chord error is the half chord.
        return if lc < 1e-9 * (la + lb) { la / 2.0 } else { 0.0 };
    }
    let r = la * lb * lc / (2.0 * twice_area);
    let h = la / 2.0;
    let e = h * h / (r + (r * r - h * h).at_least(0.0).sqrt());
    if e.is_finite() {
        e
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_acos_is_close() {
        for i in 0..=2000 {
            let x = -1.0 + i as f64 / 1000.0;
            assert!((fast_acos(x) - x.acos()).abs() < 7e-5, "{x}");
        }
    }

    #[test]
    fn square_has_right_angle_corners() {
        let mut acc = MetricsAccumulator::new(30.0);
        let pts = [
            [0.0, 0.0, 0.2],
            [10.0, 0.0, 0.2],
            [10.0, 10.0, 0.2],
            [0.0, 10.0, 0.2],
        ];
        for w in pts.windows(2) {
            acc.push(&w[0], &w[1], None, true, 0, false);
        }
        let m = acc.finish();
        assert_eq!(m.n_total, 4);
        assert_eq!(m.n_corners, 2);
        assert_eq!(m.n_turning, 2);
        assert!((m.mean_turn_deg - 90.0).abs() < 1e-2);
        assert!((m.l_total_mm - 30.0).abs() < 1e-12);
        // Right angle: the circle through the three points has the diagonal as diameter.
        let r = 50f64.sqrt();
        let e = r - (r * r - 25.0).sqrt();
        assert!((m.mean_chord_error_mm - e).abs() < 1e-12);
    }

    #[test]
    fn paths_break_at_travel_and_feature() {
        let mut acc = MetricsAccumulator::new(30.0);
        acc.push(&[0.0, 0.0, 0.0], &[1.0, 0.0, 0.0], None, true, 0, true);
        acc.push(&[1.0, 0.0, 0.0], &[1.0, 1.0, 0.0], None, true, 1, false);
        acc.push(&[1.0, 1.0, 0.0], &[2.0, 1.0, 0.0], None, false, 1, false);
        acc.push(&[2.0, 1.0, 0.0], &[3.0, 1.0, 0.0], None, true, 1, false);
        let m = acc.finish();
        assert_eq!(m.n_total, 6);
        assert_eq!(m.n_infill, 2);
        assert_eq!(m.n_corners, 0);
        assert!((m.l_infill_mm - 1.0).abs() < 1e-12);
    }

    #[test]
    fn regular_polygon_chord_error_is_the_sagitta() {
        // Points on a circle of radius 5: VTG eq. 31 gives the sagitta of each chord.
        let mut acc = MetricsAccumulator::new(30.0);
        let n = 36;
        let p = |i: usize| {
            let t = i as f64 * std::f64::consts::TAU / n as f64;
            [5.0 * t.cos(), 5.0 * t.sin(), 0.0]
        };
        for i in 0..n {
            acc.push(&p(i), &p(i + 1), None, true, 0, false);
        }
        let m = acc.finish();
        let half = std::f64::consts::PI / n as f64;
        let sagitta = 5.0 * (1.0 - half.cos());
        assert!((m.mean_chord_error_mm - sagitta).abs() < 1e-9);
        assert!((m.mean_turn_deg - 10.0).abs() < 1e-2);
        assert_eq!(m.n_turning, 0);
    }

    /// Property tests (proptest is a native-only dev-dependency).
    #[cfg(not(target_arch = "wasm32"))]
    mod props {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(64))]

            /// Metrics taken as the timing side takes them (each move's chord and trace, the
            /// joins from a [`PathEnd`]) and carried back as words equal those taken by
            /// position, on moves over a coarse grid (so ends meet and points repeat), with
            /// jumps, travels, feature changes and zero-length moves.
            #[test]
            fn by_chord_and_trace_equals_by_position(
                moves in proptest::collection::vec(
                    (0u8..4, 0u8..4, 0u8..2, any::<bool>(), any::<bool>(), 0u32..3, any::<bool>()),
                    0..60,
                ),
            ) {
                let mut by_position = MetricsAccumulator::new(DEFAULT_CRITICAL_ANGLE_DEG);
                let mut by_chord = MetricsAccumulator::new(DEFAULT_CRITICAL_ANGLE_DEG);
                let mut end = PathEnd::default();
                let mut at = [0.0, 0.0, 0.2];
                for (x, y, z, jump, extruding, feature, infill) in moves {
                    let from = if jump { [f64::from(y), f64::from(x), 0.2] } else { at };
                    let to = [f64::from(x) * 2.5, f64::from(y) * 1.5, 0.2 + f64::from(z) * 0.2];
                    by_position.push(&from, &to, None, extruding, feature, infill);
                    let trace = MoveTrace { extruding, infill, joins: end.step(&from, &to) };
                    let chord = [to[0] - from[0], to[1] - from[1], to[2] - from[2]];
                    by_chord.push_chord(chord, None, feature, trace);
                    at = to;
                }
                let carried = MetricsAccumulator::from_words(DEFAULT_CRITICAL_ANGLE_DEG, by_chord.to_words());
                prop_assert_eq!(carried.finish(), by_position.finish());
            }
        }
    }
}
