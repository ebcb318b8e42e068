//! Conformance of `infill`: regenerated infill against PrusaSlicer's own, and the safety
//! properties of the rewritten files (inside the part, same filament, re-parses cleanly).
//!
//! `cargo test -p quietpath-conformance --test infill -- --nocapture` prints the tables.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;

use quietpath::analyze::{analyze, AnalyzeOptions, Report};
use quietpath::infill::{infill, InfillOptions, InfillReport, Pattern};
use quietpath::path::extract;

fn data(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../crate/tests/data").join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn run(input: &[u8], patterns: &[Pattern], angles: &[f64], rotations: &[f64]) -> InfillReport {
    let options = InfillOptions {
        patterns: patterns.to_vec(),
        angles_deg: angles.to_vec(),
        rotations_deg: rotations.to_vec(),
        ..InfillOptions::default()
    };
    infill(input, &options).unwrap()
}

fn pct(a: f64, b: f64) -> f64 {
    100.0 * (a - b) / b
}

/// The candidate numbers are those `analyze` gives of the written file.
fn check_candidate_is_analyze(r: &InfillReport) {
    let after: &Report = &r.after;
    let b = &r.best;
    assert!(pct(b.time_s, after.time_s).abs() < 1e-6, "{} vs {}", b.time_s, after.time_s);
    assert!(pct(b.thesis_j, after.energy.thesis_j).abs() < 1e-6);
    assert!(pct(b.total_j, after.energy.total_j).abs() < 1e-6);
}

/// "Rectilinear at 0°" (and 90°) regenerated from PrusaSlicer's 45° slice costs within 5 % of
/// `analyze` of PrusaSlicer's own 0° (90°) slice of the same box.
#[test]
fn regenerated_rectilinear_agrees_with_prusaslicer() {
    let at45 = data("rect_infill_45.gcode");
    println!("| target | PrusaSlicer thesis J | regenerated thesis J | Δ | PrusaSlicer total J | regenerated total J | Δ | PrusaSlicer time s | regenerated time s | Δ |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for angle in [0u32, 90] {
        let slicer = analyze(&data(&format!("rect_infill_{angle}.gcode")), &AnalyzeOptions::default())
            .unwrap();
        let r = run(&at45, &[Pattern::Rectilinear], &[f64::from(angle)], &[0.0]);
        check_candidate_is_analyze(&r);
        let c = &r.candidates[0];
        let (dt, de, dtot) = (
            pct(c.time_s, slicer.time_s),
            pct(c.thesis_j, slicer.energy.thesis_j),
            pct(c.total_j, slicer.energy.total_j),
        );
        println!(
            "| {angle}° | {:.1} | {:.1} | {de:+.2} % | {:.0} | {:.0} | {dtot:+.2} % | {:.1} | {:.1} | {dt:+.2} % |",
            slicer.energy.thesis_j, c.thesis_j, slicer.energy.total_j, c.total_j, slicer.time_s, c.time_s
        );
        assert!(de.abs() < 5.0, "thesis energy at {angle}°: {de:+.2} %");
        assert!(dtot.abs() < 5.0, "total energy at {angle}°: {dtot:+.2} %");
        assert!(dt.abs() < 5.0, "time at {angle}°: {dt:+.2} %");
    }
}

/// Every new infill point lies inside the layer's outer perimeter; filament per layer within
/// 10 %; the output re-parses without warnings.
#[test]
fn new_infill_stays_inside_and_keeps_the_material() {
    let input = data("rect_infill_45.gcode");
    let r = run(&input, &Pattern::ALL, &[0.0, 30.0], &[0.0]);
    assert!(r.after.warnings.is_empty(), "{:?}", r.after.warnings);
    let before = extract(&input, &AnalyzeOptions::default(), false).unwrap();
    let after = extract(&r.output, &AnalyzeOptions::default(), false).unwrap();
    assert_eq!(before.layers.len(), after.layers.len());
    for (i, (lb, la)) in before.layers.iter().zip(&after.layers).enumerate() {
        let _ = (lb, la);
        let fil = |p: &quietpath::path::PrintPath| -> f64 {
            p.layer_moves(i)
                .iter()
                .filter(|m| m.is_extruding())
                .filter(|m| p.feature_kind(m) == Some(quietpath::gcode::FeatureKind::SparseInfill))
                .map(|m| m.extrusion())
                .sum()
        };
        let (fb, fa) = (fil(&before), fil(&after));
        if fb <= 0.0 {
            assert!(fa.abs() < 1e-9, "layer {i}: new infill where there was none");
            continue;
        }
        assert!(pct(fa, fb).abs() < 10.0, "layer {i}: {fa} vs {fb}");
        // The outer wall's extent in this layer.
        let outer: Vec<_> = before
            .layer_moves(i)
            .iter()
            .filter(|m| before.feature_kind(m) == Some(quietpath::gcode::FeatureKind::OuterWall))
            .filter(|m| m.is_extruding())
            .collect();
        let (x0, x1) = outer.iter().fold((f64::MAX, f64::MIN), |(a, b), m| (a.min(m.to[0]), b.max(m.to[0])));
        let (y0, y1) = outer.iter().fold((f64::MAX, f64::MIN), |(a, b), m| (a.min(m.to[1]), b.max(m.to[1])));
        for m in after.layer_moves(i).iter().filter(|m| m.is_extruding()) {
            for p in [m.from, m.to] {
                assert!(
                    p[0] >= x0 - 1e-6 && p[0] <= x1 + 1e-6 && p[1] >= y0 - 1e-6 && p[1] <= y1 + 1e-6,
                    "layer {i}: ({}, {}) outside [{x0}, {x1}] × [{y0}, {y1}]",
                    p[0],
                    p[1]
                );
            }
        }
    }
}
