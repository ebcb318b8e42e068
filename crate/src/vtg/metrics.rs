//! Trajectory metrics of the VTG paper (VTG eq. 24–26, 31) of a whole toolpath and of each of its
//! layers: the [`crate::analyze::toolpath`] accumulator run over the moves of a
//! [`crate::path::PrintPath`] or streamed from G-code.

use crate::analyze::toolpath::{MetricsAccumulator, ToolpathMetrics};

/// Metrics of a whole [`crate::path::PrintPath`] and of each of its layers, with critical angle
/// `critical_angle_deg`.
pub fn from_path(
    path: &crate::path::PrintPath,
    critical_angle_deg: f64,
) -> (ToolpathMetrics, Vec<ToolpathMetrics>) {
    use crate::gcode::FeatureKind;
    let mut file = MetricsAccumulator::new(critical_angle_deg);
    let mut layers: Vec<MetricsAccumulator> = Vec::with_capacity(path.layers.len());
    for m in &path.moves {
        let infill = matches!(
            path.feature_kind(m),
            Some(FeatureKind::SparseInfill | FeatureKind::SolidInfill)
        );
        let extruding = m.is_extruding();
        let feature = u32::from(m.feature);
        file.push(&m.from, &m.to, m.kind.arc(), extruding, feature, infill);
        let li = m.layer as usize;
        if m.layer != crate::path::NO_LAYER && li < path.layers.len() {
            while layers.len() <= li {
                layers.push(MetricsAccumulator::new(critical_angle_deg));
            }
            if let Some(l) = layers.get_mut(li) {
                l.push(&m.from, &m.to, m.kind.arc(), extruding, feature, infill);
            }
        }
    }
    (file.finish(), layers.iter().map(|l| l.finish()).collect())
}

/// [`MoveSink`](crate::path::MoveSink) accumulating the metrics of a file and of its layers
/// under both layer numberings (which one holds is known at the end): a few hundred bytes per
/// layer, however many moves.
struct MetricsSink {
    critical_angle_deg: f64,
    file: MetricsAccumulator,
    by_marker: Vec<MetricsAccumulator>,
    by_count: Vec<MetricsAccumulator>,
}

impl MetricsSink {
    fn layer(&mut self, marker: bool, layer: u32) -> Option<&mut MetricsAccumulator> {
        if layer == crate::path::NO_LAYER {
            return None;
        }
        let (list, i) = if marker {
            (&mut self.by_marker, layer as usize)
        } else {
            (&mut self.by_count, layer as usize)
        };
        while list.len() <= i {
            list.push(MetricsAccumulator::new(self.critical_angle_deg));
        }
        list.get_mut(i)
    }
}

impl crate::path::MoveSink for MetricsSink {
    fn moved(
        &mut self,
        _: usize,
        m: crate::path::PathMove,
        layers: (u32, u32),
        features: &[crate::path::PathFeature],
    ) {
        use crate::gcode::FeatureKind;
        let infill = matches!(
            features.get(m.feature as usize).map(|f| f.kind),
            Some(FeatureKind::SparseInfill | FeatureKind::SolidInfill)
        );
        let (extruding, feature) = (m.is_extruding(), u32::from(m.feature));
        self.file
            .push(&m.from, &m.to, m.kind.arc(), extruding, feature, infill);
        for (marker, layer) in [(true, layers.0), (false, layers.1)] {
            if let Some(l) = self.layer(marker, layer) {
                l.push(&m.from, &m.to, m.kind.arc(), extruding, feature, infill);
            }
        }
    }
}

/// What [`from_path`] gives, read straight from G-code without keeping the moves (the
/// rewritten file of a VTG run can hold ten times the input's moves).
pub fn from_input(
    input: &[u8],
    options: &crate::analyze::AnalyzeOptions,
    critical_angle_deg: f64,
) -> Result<(ToolpathMetrics, Vec<ToolpathMetrics>), crate::error::Error> {
    let mut sink = MetricsSink {
        critical_angle_deg,
        file: MetricsAccumulator::new(critical_angle_deg),
        by_marker: Vec::new(),
        by_count: Vec::new(),
    };
    let walked = crate::path::walk(input, options, false, &mut sink)?;
    let mut layers = match walked.layer_source {
        crate::analyze::LayerSource::Markers(_) => sink.by_marker,
        _ => sink.by_count,
    };
    layers.truncate(walked.layers.len());
    Ok((
        sink.file.finish(),
        layers.iter().map(MetricsAccumulator::finish).collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streamed_metrics_equal_those_of_the_kept_moves() {
        // Markers (the demo) and Z-counted layers (markers stripped), with and without an
        // empty layer and moves before the first one.
        let demo = include_bytes!("../../../www/demo/demo.gcode");
        let stripped: Vec<u8> = String::from_utf8_lossy(demo)
            .lines()
            .filter(|l| !l.starts_with(";LAYER_CHANGE"))
            .flat_map(|l| l.bytes().chain([b'\n']))
            .collect();
        let small = b"G1 X5 Y5 F3000\n;LAYER_CHANGE\n;LAYER_CHANGE\n;TYPE:Internal infill\n\
G1 X10 Y0 E0.5 F1200\nG1 X10 Y10 E0.5\nG1 X0 Y10 E0.5\n";
        for (name, g) in [
            ("demo", &demo[..]),
            ("no markers", &stripped),
            ("small", small),
        ] {
            let o = crate::analyze::AnalyzeOptions::default();
            let kept = from_path(&crate::path::extract(g, &o, false).unwrap(), 25.0);
            let streamed = from_input(g, &o, 25.0).unwrap();
            assert_eq!(streamed.0, kept.0, "{name}");
            // The kept list stops at the last layer with moves; the stream lists every layer.
            assert!(streamed.1.len() >= kept.1.len(), "{name}");
            assert_eq!(streamed.1[..kept.1.len()], kept.1[..], "{name}");
            assert!(streamed.1[kept.1.len()..].iter().all(|m| m.n_total == 0));
        }
    }

    /// Metrics of G-code read the way `analyze` reads it.
    fn of(g: &str) -> ToolpathMetrics {
        let options = crate::analyze::AnalyzeOptions::default();
        from_input(g.as_bytes(), &options, 30.0).expect("metrics").0
    }

    #[test]
    fn arcs_turn_by_their_tangents_and_count_their_length() {
        // A line, a quarter circle of radius 5 that leaves it tangentially (G3 from (10,0) to
        // (15,5), centre (10,5)), and a line leaving the arc tangentially: no corner at all,
        // where the arc's chord would show two 45° corners.
        let smooth = "M83\nG1 X0 Y0 Z0.2 F3000\nG1 X10 Y0 E1\nG3 X15 Y5 I0 J5 E1\nG1 X15 Y15 E1\n";
        let m = of(smooth);
        assert_eq!((m.n_total, m.n_corners, m.n_turning), (4, 2, 0));
        assert!(m.mean_turn_deg < 1e-3, "{}", m.mean_turn_deg);
        assert!(m.mean_chord_error_mm < 1e-9, "{}", m.mean_chord_error_mm);
        let quarter = std::f64::consts::FRAC_PI_2 * 5.0;
        assert!(
            (m.l_total_mm - (20.0 + quarter)).abs() < 1e-9,
            "{}",
            m.l_total_mm
        );
        // The same arc entered at a right angle (from below) and left backwards (its end
        // tangent points +Y; the line goes −X, a 90° turn): two turning points of 90°.
        let sharp = "M83\nG1 X10 Y-10 Z0.2 F3000\nG1 X10 Y0 E1\nG3 X15 Y5 I0 J5 E1\nG1 X5 Y5 E1\n";
        let m = of(sharp);
        assert_eq!((m.n_corners, m.n_turning), (2, 2));
        assert!((m.mean_turn_deg - 90.0).abs() < 0.01, "{}", m.mean_turn_deg);
    }
}
