//! Relative change of vibration between two files (the VTG paper's Fig. 9d and Table 2).

use serde::Serialize;

use super::VibrationReport;

/// Relative change `(after − before) / before` of one layer's amplitude.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LayerChange {
    /// 0-based layer index.
    pub layer: usize,
    /// Amplitude before, mm.
    pub before: f64,
    /// Amplitude after, mm.
    pub after: f64,
    /// Relative change (−0.1 = 10 % lower); 0 when `before` is 0.
    pub relative: f64,
}

/// How vibration changed from one file to another.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VibrationComparison {
    /// Relative change of the largest deviation.
    pub max_deviation: f64,
    /// Relative change of the smallest deviation.
    pub min_deviation: f64,
    /// Relative change of the mean deviation.
    pub mean_deviation: f64,
    /// Per-layer relative change of the amplitude, for layers present in both.
    pub layers: Vec<LayerChange>,
}

fn relative(before: f64, after: f64) -> f64 {
    if before != 0.0 && before.is_finite() && after.is_finite() {
        (after - before) / before
    } else {
        0.0
    }
}

/// Relative change from `before` to `after`.
pub fn compare(before: &VibrationReport, after: &VibrationReport) -> VibrationComparison {
    let (b, a) = (&before.deviation_mm, &after.deviation_mm);
    let layers = before
        .layers
        .iter()
        .filter_map(|lb| {
            let la = after.layers.iter().find(|l| l.layer == lb.layer)?;
            Some(LayerChange {
                layer: lb.layer,
                before: lb.amplitude,
                after: la.amplitude,
                relative: relative(lb.amplitude, la.amplitude),
            })
        })
        .collect();
    VibrationComparison {
        max_deviation: relative(b.max, a.max),
        min_deviation: relative(b.min, a.min),
        mean_deviation: relative(b.mean, a.mean),
        layers,
    }
}
