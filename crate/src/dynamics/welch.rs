//! Power spectral density by Welch's method, as `scipy.signal.welch` computes it with
//! `detrend='constant'`, `return_onesided=True`, `scaling='density'`, `average='mean'`:
//!
//! - segments of `n` samples overlapping by `n/2` (only whole segments; a signal shorter than
//!   one segment is taken as one segment of its own length, as scipy does);
//! - each segment: mean removed, multiplied by the window `w`, real FFT `X_k`;
//! - `P_k = |X_k|² / (f_s Σ w²)`, doubled for every bin but DC (and Nyquist when `n` is even),
//!   so that `Σ P_k Δf` (`Δf = f_s/n`) is the signal's variance (Parseval);
//! - the average of `P_k` over the segments.
//!
//! The estimator streams: samples are pushed one at a time and only one segment is kept, so a
//! whole print (millions of samples) takes `O(n)` memory.

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};
use serde::{Deserialize, Serialize};

/// Window function applied to each segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "SpectrumWindow"))]
#[serde(rename_all = "snake_case")]
pub enum Window {
    /// Hamming, `0.54 − 0.46 cos(2πk/n)` (periodic, scipy's `get_window('hamming', n)`); the
    /// VTG paper's choice.
    #[default]
    Hamming,
    /// Hann, `0.5 − 0.5 cos(2πk/n)` (periodic); scipy's default.
    Hann,
    /// No window.
    Rectangular,
}

impl Window {
    /// The `n` window values (periodic form, as scipy's `get_window` with `fftbins=True`).
    pub fn values(self, n: usize) -> Vec<f64> {
        let two_pi = 2.0 * core::f64::consts::PI;
        (0..n)
            .map(|k| {
                let c = crate::math::cos(two_pi * k as f64 / n as f64);
                match self {
                    Window::Hamming => 0.54 - 0.46 * c,
                    Window::Hann => 0.5 - 0.5 * c,
                    Window::Rectangular => 1.0,
                }
            })
            .collect()
    }
}

/// A streaming Welch estimator over several channels whose spectra are summed (the PSD of a
/// vector signal: the sum of its components' PSDs).
pub struct Welch {
    n: usize,
    channels: usize,
    fs: f64,
    window: Vec<f64>,
    /// Ring of the last `n` samples per channel (channel-major).
    buffer: Vec<f64>,
    /// Samples pushed since the start.
    pushed: usize,
    /// Samples pushed since the last segment was taken.
    since_segment: usize,
    sum: Vec<f64>,
    segments: usize,
    fft: Arc<dyn RealToComplex<f64>>,
    input: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    kind: Window,
}

impl std::fmt::Debug for Welch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Welch")
            .field("n", &self.n)
            .field("fs", &self.fs)
            .field("segments", &self.segments)
            .finish()
    }
}

/// An estimated spectrum.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Spectrum {
    /// Bin frequencies `k f_s / n`, Hz.
    pub freqs: Vec<f64>,
    /// Power spectral density per bin, (signal unit)²/Hz.
    pub power: Vec<f64>,
    /// Segments averaged.
    pub segments: usize,
    /// Segment length, samples.
    pub segment_len: usize,
}

impl Welch {
    /// An estimator with segments of `n ≥ 2` samples at `fs` Hz over `channels ≥ 1` channels.
    pub fn new(n: usize, fs: f64, window: Window, channels: usize) -> Self {
        let n = n.max(2);
        let channels = channels.max(1);
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
        let spectrum = fft.make_output_vec();
        let scratch = fft.make_scratch_vec();
        Self {
            n,
            channels,
            fs,
            window: window.values(n),
            buffer: vec![0.0; n * channels],
            pushed: 0,
            since_segment: 0,
            sum: vec![0.0; n / 2 + 1],
            segments: 0,
            input: vec![0.0; n],
            spectrum,
            scratch,
            fft,
            kind: window,
        }
    }

    /// Adds one sample per channel (extra values are ignored, missing ones are zero).
    pub fn push(&mut self, sample: &[f64]) {
        let slot = self.pushed % self.n;
        for ch in 0..self.channels {
            self.buffer[ch * self.n + slot] = sample.get(ch).copied().unwrap_or(0.0);
        }
        self.pushed += 1;
        self.since_segment += 1;
        let step = self.n - self.n / 2;
        if self.pushed >= self.n && (self.pushed == self.n || self.since_segment >= step) {
            self.since_segment = 0;
            let start = self.pushed % self.n; // oldest sample of the ring
            let (n, fs) = (self.n, self.fs);
            let window = std::mem::take(&mut self.window);
            let mut sum = std::mem::take(&mut self.sum);
            for ch in 0..self.channels {
                let ring = &self.buffer[ch * n..(ch + 1) * n];
                let seg: Vec<f64> = (0..n).map(|i| ring[(start + i) % n]).collect();
                accumulate(
                    &seg,
                    &window,
                    fs,
                    &*self.fft,
                    &mut self.input,
                    &mut self.spectrum,
                    &mut self.scratch,
                    &mut sum,
                );
            }
            self.window = window;
            self.sum = sum;
            self.segments += 1;
        }
    }

    /// The averaged spectrum. With fewer samples than one segment, the samples pushed so far
    /// make one segment of their own length (scipy's behaviour); with fewer than 2, the
    /// spectrum is empty.
    pub fn finish(&self) -> Spectrum {
        if self.segments > 0 {
            return Spectrum {
                freqs: freqs(self.n, self.fs),
                power: self.sum.iter().map(|p| p / self.segments as f64).collect(),
                segments: self.segments,
                segment_len: self.n,
            };
        }
        if self.pushed < 2 {
            return Spectrum::default();
        }
        let m = self.pushed;
        let mut short = Welch::new(m, self.fs, self.kind, self.channels);
        for i in 0..m {
            let s: Vec<f64> = (0..self.channels)
                .map(|ch| self.buffer[ch * self.n + i])
                .collect();
            short.push(&s);
        }
        short.finish()
    }
}

fn freqs(n: usize, fs: f64) -> Vec<f64> {
    (0..=n / 2).map(|k| k as f64 * fs / n as f64).collect()
}

#[allow(clippy::too_many_arguments)]
fn accumulate(
    seg: &[f64],
    window: &[f64],
    fs: f64,
    fft: &dyn RealToComplex<f64>,
    input: &mut [f64],
    spectrum: &mut [Complex<f64>],
    scratch: &mut [Complex<f64>],
    sum: &mut [f64],
) {
    let n = seg.len();
    let mean = seg.iter().sum::<f64>() / n as f64;
    for ((x, s), w) in input.iter_mut().zip(seg).zip(window) {
        *x = (s - mean) * w;
    }
    if fft.process_with_scratch(input, spectrum, scratch).is_err() {
        return;
    }
    let scale = 1.0 / (fs * window.iter().map(|w| w * w).sum::<f64>());
    let last = spectrum.len() - 1;
    for (k, (p, x)) in sum.iter_mut().zip(spectrum.iter()).enumerate() {
        let one_sided = if k == 0 || (n % 2 == 0 && k == last) {
            1.0
        } else {
            2.0
        };
        *p += x.norm_sqr() * scale * one_sided;
    }
}

/// A spectral peak.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Peak {
    /// Frequency, Hz.
    pub hz: f64,
    /// Power spectral density at the peak.
    pub power: f64,
}

/// The `count` highest local maxima of `power` (bins higher than both neighbours; DC is left
/// out), highest first.
pub fn peaks(freqs: &[f64], power: &[f64], count: usize) -> Vec<Peak> {
    let mut out: Vec<Peak> = (1..power.len())
        .filter(|&i| {
            let left = power[i - 1];
            let right = power.get(i + 1).copied().unwrap_or(f64::NEG_INFINITY);
            power[i] > left && power[i] >= right && power[i] > 0.0
        })
        .filter_map(|i| {
            Some(Peak {
                hz: *freqs.get(i)?,
                power: power[i],
            })
        })
        .collect();
    out.sort_by(|a, b| b.power.total_cmp(&a.power));
    out.truncate(count);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn welch(x: &[f64], n: usize, fs: f64, w: Window) -> Spectrum {
        let mut e = Welch::new(n, fs, w, 1);
        for &v in x {
            e.push(&[v]);
        }
        e.finish()
    }

    #[test]
    fn sine_peaks_at_its_frequency_with_the_closed_form_power() {
        // A = 2 at f0 = 25 Hz, exactly bin 64 of a 512-point segment at 200 Hz.
        let (fs, n, a, f0) = (200.0, 512, 2.0, 25.0);
        let x: Vec<f64> = (0..20_000)
            .map(|i| a * (2.0 * core::f64::consts::PI * f0 * i as f64 / fs).sin())
            .collect();
        let s = welch(&x, n, fs, Window::Hamming);
        let p = peaks(&s.freqs, &s.power, 3);
        assert!((p[0].hz - f0).abs() < 1e-9);
        // A bin-centred sine: X_k0 = (A/2) Σw (the mean over a whole number of periods is 0),
        // so P_k0 = 2 (A Σw / 2)² / (fs Σw²) = A² (Σw)² / (2 fs Σw²).
        let w = Window::Hamming.values(n);
        let sw: f64 = w.iter().sum();
        let sw2: f64 = w.iter().map(|v| v * v).sum();
        let expected = a * a * sw * sw / (2.0 * fs * sw2);
        assert!(
            (p[0].power - expected).abs() < 1e-9 * expected,
            "{} vs {expected}",
            p[0].power
        );
        // Parseval: Σ P Δf is the variance A²/2.
        let df = fs / n as f64;
        let total: f64 = s.power.iter().sum::<f64>() * df;
        assert!((total - a * a / 2.0).abs() < 1e-3 * a * a / 2.0, "{total}");
        // Segments: floor((N − n) / (n/2)) + 1.
        assert_eq!(s.segments, (20_000 - n) / (n / 2) + 1);
    }

    #[test]
    fn matches_the_scipy_density_definition_term_by_term() {
        // Direct DFT of each segment, by the textbook formula, against the FFT estimator.
        let (fs, n) = (100.0, 16);
        let x: Vec<f64> = (0..40)
            .map(|i| ((i * 7919) % 23) as f64 * 0.1 - 1.0 + 0.05 * i as f64)
            .collect();
        let w = Window::Hann.values(n);
        let sw2: f64 = w.iter().map(|v| v * v).sum();
        let mut expected = vec![0.0; n / 2 + 1];
        let mut count = 0;
        let mut start = 0;
        while start + n <= x.len() {
            let seg = &x[start..start + n];
            let mean = seg.iter().sum::<f64>() / n as f64;
            for (k, e) in expected.iter_mut().enumerate() {
                let (mut re, mut im) = (0.0, 0.0);
                for (j, v) in seg.iter().enumerate() {
                    let ang = -2.0 * core::f64::consts::PI * (k * j) as f64 / n as f64;
                    re += (v - mean) * w[j] * ang.cos();
                    im += (v - mean) * w[j] * ang.sin();
                }
                let factor = if k == 0 || k == n / 2 { 1.0 } else { 2.0 };
                *e += factor * (re * re + im * im) / (fs * sw2);
            }
            count += 1;
            start += n / 2;
        }
        let s = welch(&x, n, fs, Window::Hann);
        assert_eq!(s.segments, count);
        for (k, (got, e)) in s.power.iter().zip(&expected).enumerate() {
            let e = e / count as f64;
            assert!((got - e).abs() < 1e-12 * (1.0 + e), "bin {k}: {got} vs {e}");
            assert!((s.freqs[k] - k as f64 * fs / n as f64).abs() < 1e-12);
        }
    }

    #[test]
    fn short_signals_use_one_short_segment() {
        let s = welch(&[1.0, -1.0, 1.0, -1.0], 512, 200.0, Window::Rectangular);
        assert_eq!(s.segments, 1);
        assert_eq!(s.freqs.len(), 3);
        // Alternating ±1: all power at Nyquist, variance 1 = P Δf with Δf = 50 Hz.
        assert!((s.power[2] * 50.0 - 1.0).abs() < 1e-12);
        assert!(welch(&[1.0], 512, 200.0, Window::Hamming).power.is_empty());
    }

    #[test]
    fn channels_add() {
        let x: Vec<f64> = (0..3000).map(|i| (i as f64 * 0.3).sin()).collect();
        let one = welch(&x, 256, 200.0, Window::Hamming);
        let mut two = Welch::new(256, 200.0, Window::Hamming, 2);
        for &v in &x {
            two.push(&[v, v]);
        }
        let two = two.finish();
        for (a, b) in one.power.iter().zip(&two.power) {
            assert!((2.0 * a - b).abs() < 1e-12 * (1.0 + b));
        }
    }
}
