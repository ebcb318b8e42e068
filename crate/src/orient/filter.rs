//! Smoothing filters on a sequence of unit orientation vectors (section 3.2 of the paper).
//!
//! - Moving average, CIRP eq. 3: `T_S,m = (1/n) Σ_{i=0}^{n−1} b_{m−i}`, a backward-running (causal)
//!   window, component by component, then renormalised to a unit vector.
//! - Median: the component-wise median of the window (the paper sorts the entries by size),
//!   renormalised.
//! - Zero phase: the causal filters lag behind the path (the orientation changes late). The
//!   moving average is made zero-phase as Matlab's `filtfilt` does: run forward, then backward
//!   over the result, after padding both ends with an odd reflection (`2 b₀ − b_k`) so the ends
//!   are not pulled toward a constant. The composite is a centred triangular average of width
//!   `2n − 1`, exactly symmetric. A running median has no linear phase to cancel and a second
//!   backward median pass is not symmetric, so the zero-phase median is the centred window
//!   (`m − h … m + h`, `h = n / 2`), truncated at the ends: no lag by construction.
//!
//! Windows are counted in points or, since point spacing varies along real paths, in path
//! length (`--window-mm`): the causal window holds the points up to `W` mm back along the path,
//! the centred median `W/2` mm each way.

use serde::{Deserialize, Serialize};

use crate::vec3::{self, V3};

/// Which filter smooths the orientation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "kebab-case")]
pub enum FilterKind {
    /// Forward-backward moving average (the paper's choice for both parts).
    #[default]
    ZeroPhaseMovingAverage,
    /// Centred median.
    ZeroPhaseMedian,
    /// Causal moving average, CIRP eq. 3 (lags behind the path).
    MovingAverage,
    /// Causal median.
    Median,
}

/// Filter window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "SmoothWindow"))]
#[serde(rename_all = "snake_case")]
pub enum Window {
    /// A number of points.
    Points(usize),
    /// A length of path, mm.
    Millimetres(f64),
}

impl Default for Window {
    fn default() -> Self {
        Window::Points(15)
    }
}

/// Largest number of points one median window holds (bounds the work on hostile windows).
pub const MAX_MEDIAN_POINTS: usize = 1001;
/// Largest window in points.
pub const MAX_WINDOW_POINTS: usize = 1_000_000;

impl Window {
    /// Checks the window.
    pub fn validate(&self) -> Result<(), &'static str> {
        match *self {
            Window::Points(n) if n == 0 || n > MAX_WINDOW_POINTS => {
                Err("window must hold between 1 and 1 000 000 points")
            }
            Window::Millimetres(w) if !(w.is_finite() && w > 0.0 && w <= 1e6) => {
                Err("window length must be finite, positive and at most 1e6 mm")
            }
            _ => Ok(()),
        }
    }
}

/// For each index `m`, the first index of its backward window `[start, m]`.
fn backward_starts(s: &[f64], window: Window) -> Vec<usize> {
    match window {
        Window::Points(n) => (0..s.len()).map(|m| (m + 1).saturating_sub(n)).collect(),
        Window::Millimetres(w) => {
            let mut out = Vec::with_capacity(s.len());
            let mut j = 0usize;
            for (m, &sm) in s.iter().enumerate() {
                while j < m && sm - s.get(j).copied().unwrap_or(sm) > w {
                    j += 1;
                }
                out.push(j);
            }
            out
        }
    }
}

/// Causal moving average over `[start(m), m]` with prefix sums.
fn causal_average(v: &[V3], s: &[f64], window: Window) -> Vec<V3> {
    let starts = backward_starts(s, window);
    let mut prefix = Vec::with_capacity(v.len() + 1);
    let mut acc = [0.0; 3];
    prefix.push(acc);
    for x in v {
        acc = vec3::add(acc, *x);
        prefix.push(acc);
    }
    starts
        .iter()
        .enumerate()
        .map(|(m, &j)| {
            let (hi, lo) = (
                prefix.get(m + 1).copied().unwrap_or(acc),
                prefix.get(j).copied().unwrap_or([0.0; 3]),
            );
            let count = (m + 1 - j.min(m)) as f64;
            vec3::scale(vec3::sub(hi, lo), 1.0 / count)
        })
        .collect()
}

/// Component-wise median of `v[lo..=hi]`.
fn median_of(v: &[V3], lo: usize, hi: usize, buf: &mut Vec<f64>) -> V3 {
    let hi = hi.min(v.len().saturating_sub(1));
    let lo = lo.max(hi.saturating_sub(MAX_MEDIAN_POINTS - 1)).min(hi);
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        buf.clear();
        buf.extend(v.get(lo..=hi).unwrap_or(&[]).iter().map(|x| x[k]));
        let n = buf.len();
        if n == 0 {
            continue;
        }
        let mid = n / 2;
        buf.select_nth_unstable_by(mid, f64::total_cmp);
        let upper = buf.get(mid).copied().unwrap_or(0.0);
        *o = if n % 2 == 1 {
            upper
        } else {
            let lower = buf
                .get(..mid)
                .and_then(|l| l.iter().copied().max_by(f64::total_cmp))
                .unwrap_or(upper);
            0.5 * (lower + upper)
        };
    }
    out
}

fn causal_median(v: &[V3], s: &[f64], window: Window) -> Vec<V3> {
    let starts = backward_starts(s, window);
    let mut buf = Vec::new();
    starts
        .iter()
        .enumerate()
        .map(|(m, &j)| median_of(v, j, m, &mut buf))
        .collect()
}

fn centred_median(v: &[V3], s: &[f64], window: Window) -> Vec<V3> {
    let n = v.len();
    let mut buf = Vec::new();
    let mut out = Vec::with_capacity(n);
    match window {
        Window::Points(w) => {
            let h = w / 2;
            for m in 0..n {
                // Truncated symmetrically at the ends so the window stays centred.
                let reach = h.min(m).min(n - 1 - m);
                out.push(median_of(v, m - reach, m + reach, &mut buf));
            }
        }
        Window::Millimetres(w) => {
            let half = 0.5 * w;
            let (mut lo, mut hi) = (0usize, 0usize);
            for m in 0..n {
                let sm = s.get(m).copied().unwrap_or(0.0);
                while lo < m && sm - s.get(lo).copied().unwrap_or(sm) > half {
                    lo += 1;
                }
                hi = hi.max(m);
                while hi + 1 < n && s.get(hi + 1).copied().unwrap_or(sm) - sm <= half {
                    hi += 1;
                }
                let reach = (m - lo).min(hi - m);
                out.push(median_of(v, m - reach, m + reach, &mut buf));
            }
        }
    }
    out
}

/// Points of padding needed at one end for a window (reflection length).
fn pad_len(s: &[f64], window: Window, from_end: bool) -> usize {
    let n = s.len();
    if n < 2 {
        return 0;
    }
    match window {
        Window::Points(w) => w.saturating_sub(1).min(n - 1),
        Window::Millimetres(w) => {
            let (first, last) = (
                s.first().copied().unwrap_or(0.0),
                s.last().copied().unwrap_or(0.0),
            );
            let mut k = 0usize;
            while k < n - 1 {
                let d = if from_end {
                    last - s.get(n - 2 - k).copied().unwrap_or(last)
                } else {
                    s.get(k + 1).copied().unwrap_or(first) - first
                };
                k += 1;
                if d >= w {
                    break;
                }
            }
            k
        }
    }
}

/// Forward-backward moving average with odd-reflection padding (`filtfilt`).
fn zero_phase_average(v: &[V3], s: &[f64], window: Window) -> Vec<V3> {
    let n = v.len();
    let (Some(&v0), Some(&vn), Some(&s0), Some(&sn)) = (v.first(), v.last(), s.first(), s.last())
    else {
        return Vec::new();
    };
    let pl = pad_len(s, window, false);
    let pr = pad_len(s, window, true);
    let mut pv = Vec::with_capacity(n + pl + pr);
    let mut ps = Vec::with_capacity(n + pl + pr);
    for k in (1..=pl).rev() {
        let (vk, sk) = (
            v.get(k).copied().unwrap_or(v0),
            s.get(k).copied().unwrap_or(s0),
        );
        pv.push(vec3::sub(vec3::scale(v0, 2.0), vk));
        ps.push(2.0 * s0 - sk);
    }
    pv.extend_from_slice(v);
    ps.extend_from_slice(s);
    for k in 1..=pr {
        let i = n - 1 - k;
        let (vk, sk) = (
            v.get(i).copied().unwrap_or(vn),
            s.get(i).copied().unwrap_or(sn),
        );
        pv.push(vec3::sub(vec3::scale(vn, 2.0), vk));
        ps.push(2.0 * sn - sk);
    }
    let forward = renormalised(&causal_average(&pv, &ps, window), &pv);
    let mut rev: Vec<V3> = forward.into_iter().rev().collect();
    let rs: Vec<f64> = ps.iter().rev().map(|x| -x).collect();
    rev = causal_average(&rev, &rs, window);
    rev.reverse();
    rev.into_iter().skip(pl).take(n).collect()
}

/// Unit vectors of `filtered`, falling back to `original` where the filter cancels out.
fn renormalised(filtered: &[V3], original: &[V3]) -> Vec<V3> {
    filtered
        .iter()
        .zip(original)
        .map(|(f, o)| {
            vec3::normalize(*f)
                .or_else(|| vec3::normalize(*o))
                .unwrap_or([0.0, 0.0, 1.0])
        })
        .collect()
}

/// Smooths unit vectors `v` at path positions `s` (cumulative length, mm, non-decreasing).
/// Returns unit vectors, one per input.
pub fn smooth(v: &[V3], s: &[f64], kind: FilterKind, window: Window) -> Vec<V3> {
    if v.len() != s.len() || v.len() < 2 {
        return v.to_vec();
    }
    let raw = match kind {
        FilterKind::MovingAverage => causal_average(v, s, window),
        FilterKind::Median => causal_median(v, s, window),
        FilterKind::ZeroPhaseMedian => centred_median(v, s, window),
        FilterKind::ZeroPhaseMovingAverage => zero_phase_average(v, s, window),
    };
    renormalised(&raw, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_angle(a: f64) -> V3 {
        [crate::math::sin(a), 0.0, crate::math::cos(a)]
    }

    fn step(n: usize) -> (Vec<V3>, Vec<f64>) {
        let v = (0..n)
            .map(|i| unit_angle(if i < n / 2 { 0.0 } else { 0.6 }))
            .collect();
        (v, (0..n).map(|i| i as f64 * 0.2).collect())
    }

    #[test]
    fn constant_signal_is_unchanged() {
        let v = vec![unit_angle(0.3); 40];
        let s: Vec<f64> = (0..40).map(f64::from).collect();
        for kind in [
            FilterKind::MovingAverage,
            FilterKind::Median,
            FilterKind::ZeroPhaseMedian,
            FilterKind::ZeroPhaseMovingAverage,
        ] {
            for w in [Window::Points(7), Window::Millimetres(3.5)] {
                let out = smooth(&v, &s, kind, w);
                for o in out {
                    assert!(vec3::norm(vec3::sub(o, v[0])) < 1e-12, "{kind:?} {w:?}");
                }
            }
        }
    }

    #[test]
    fn causal_average_lags_zero_phase_does_not() {
        let (v, s) = step(200);
        let causal = smooth(&v, &s, FilterKind::MovingAverage, Window::Points(21));
        let zero = smooth(
            &v,
            &s,
            FilterKind::ZeroPhaseMovingAverage,
            Window::Points(21),
        );
        let midpoint = |out: &[V3]| {
            out.iter()
                .position(|o| libm::atan2(o[0], o[2]) >= 0.3)
                .unwrap_or(0)
        };
        // Step between 99 and 100: zero phase crosses half way there, causal 10 points late.
        assert!((99..=100).contains(&midpoint(&zero)), "{}", midpoint(&zero));
        assert!(midpoint(&causal) >= 108, "{}", midpoint(&causal));
    }

    #[test]
    fn window_in_millimetres_matches_points_on_even_spacing() {
        let (v, s) = step(100);
        let a = smooth(
            &v,
            &s,
            FilterKind::ZeroPhaseMovingAverage,
            Window::Points(11),
        );
        let b = smooth(
            &v,
            &s,
            FilterKind::ZeroPhaseMovingAverage,
            Window::Millimetres(2.0 + 1e-9),
        );
        for (x, y) in a.iter().zip(&b) {
            assert!(vec3::norm(vec3::sub(*x, *y)) < 1e-12);
        }
    }

    #[test]
    fn median_removes_a_spike() {
        let mut v = vec![unit_angle(0.0); 30];
        v[15] = unit_angle(1.0);
        let s: Vec<f64> = (0..30).map(f64::from).collect();
        let out = smooth(&v, &s, FilterKind::ZeroPhaseMedian, Window::Points(5));
        assert!(vec3::norm(vec3::sub(out[15], v[0])) < 1e-15);
    }
}
