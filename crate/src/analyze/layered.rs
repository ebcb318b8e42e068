//! The VTG trajectory metrics of a file and of each of its layers, at any critical angle, taken
//! on the analysis' timing side from each move's chord and [`MoveTrace`]: what `vtg` reports
//! of a rewrite, without a pass of its own over the rewritten file.

use super::toolpath::{MetricsAccumulator, MoveTrace, ToolpathMetrics};
use crate::machine::Arc;
use crate::read::{LayerSource, NO_LAYER};

/// A file's and its layers' metrics, under both layer numberings (which one holds is known at
/// the end): a few hundred bytes a layer, however many moves.
#[derive(Debug, Clone)]
pub struct LayeredMetrics {
    critical_angle_deg: f64,
    file: MetricsAccumulator,
    by_marker: Vec<MetricsAccumulator>,
    by_count: Vec<MetricsAccumulator>,
}

impl LayeredMetrics {
    /// No moves yet; turns above `critical_angle_deg` count as turning points.
    pub fn new(critical_angle_deg: f64) -> Self {
        LayeredMetrics {
            critical_angle_deg,
            file: MetricsAccumulator::new(critical_angle_deg),
            by_marker: Vec::new(),
            by_count: Vec::new(),
        }
    }

    /// One move, in file order, in `layers` (by marker, by count).
    ///
    /// Each layer's accumulator is told the file's `trace`: layers never go back in either
    /// numbering, so the moves of one layer are consecutive, and the one place a layer's own
    /// record of where the last move ended would differ, its first move, opens no path either
    /// way (nothing came before it in that layer).
    #[inline]
    pub fn push_chord(
        &mut self,
        chord: [f64; 3],
        arc: Option<&Arc>,
        feature: u32,
        (trace, layers): (MoveTrace, (u32, u32)),
    ) {
        self.file.push_chord(chord, arc, feature, trace);
        let deg = self.critical_angle_deg;
        for (list, layer) in [
            (&mut self.by_marker, layers.0),
            (&mut self.by_count, layers.1),
        ] {
            if layer == NO_LAYER {
                continue;
            }
            let i = layer as usize;
            while list.len() <= i {
                list.push(MetricsAccumulator::new(deg));
            }
            if let Some(l) = list.get_mut(i) {
                l.push_chord(chord, arc, feature, trace);
            }
        }
    }

    /// The file's metrics and its `layers` layers', numbered as `source` says.
    pub fn finish(
        self,
        source: &LayerSource,
        layers: usize,
    ) -> (ToolpathMetrics, Vec<ToolpathMetrics>) {
        let mut list = match source {
            LayerSource::Markers(_) => self.by_marker,
            _ => self.by_count,
        };
        list.truncate(layers);
        (
            self.file.finish(),
            list.iter().map(MetricsAccumulator::finish).collect(),
        )
    }
}
