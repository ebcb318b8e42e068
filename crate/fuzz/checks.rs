// The invariants the fuzz targets check, shared with `crate/tests/fuzz_regressions.rs` (which
// replays saved inputs through the same functions on stable Rust). Included with `#[path]` by
// both, so a check is written once. Every function panics when an invariant breaks.

#![allow(dead_code)]

use quietpath::analyze::{analyze as run_analyze, AnalyzeOptions};
use quietpath::gcode::{apply_edits, parse_line as parse_one, Edit, Lines};
use quietpath::plan::{JunctionModel, MachineProfile, Motion, PlannedMove, Planner};
use quietpath::ErrorKind;

/// Every line through `parse_line`: no panic, finite values, sane error columns.
pub fn parse_line(data: &[u8]) {
    for raw in Lines::new(data) {
        match parse_one(raw.text) {
            Ok(line) => {
                for (letter, value) in line.params.iter() {
                    if let Some(v) = value {
                        assert!(
                            v.is_finite(),
                            "line {}: word {} = {v}",
                            raw.number,
                            letter as char
                        );
                    }
                }
            }
            Err(e) => {
                assert!(e.column >= 1, "line {}: column 0: {e:?}", raw.number);
                assert!(
                    e.column as usize <= raw.text.len() + 1,
                    "line {}: column past the end: {e:?}",
                    raw.number
                );
            }
        }
    }
}

/// The whole input through `analyze`, lenient and strict: lenient only refuses non-text input;
/// strict, when it accepts a file, agrees with lenient; errors point inside the file; every
/// number in the report is finite.
pub fn analyze(data: &[u8]) {
    let lenient = run_analyze(data, &AnalyzeOptions::default());
    let strict = run_analyze(
        data,
        &AnalyzeOptions {
            strict: true,
            ..AnalyzeOptions::default()
        },
    );
    match &lenient {
        Ok(report) => {
            let json = serde_json::to_string(report).expect("a report always serialises");
            // serde_json writes non-finite floats as null: a null time or energy is a bug.
            let v: serde_json::Value = serde_json::from_str(&json).expect("valid JSON");
            for key in ["time_s", "distance_mm", "filament_mm", "material_g"] {
                assert!(
                    v[key].is_number(),
                    "{key} is not a finite number: {}",
                    v[key]
                );
            }
            assert!(v["energy"]["total_j"].is_number(), "energy is not finite");
            if let Ok(strict) = &strict {
                let strict_json =
                    serde_json::to_string(strict).expect("a report always serialises");
                assert_eq!(
                    json, strict_json,
                    "strict and lenient reports differ on a file strict mode accepts"
                );
            }
        }
        Err(e) => {
            assert!(
                matches!(e.kind, ErrorKind::Utf16),
                "lenient analysis failed: {e}"
            );
            assert!(strict.is_err(), "strict accepted what lenient refused");
        }
    }
    if let Err(e) = &strict {
        assert!(
            e.line as usize <= Lines::new(data).count().max(1),
            "error line {} past the end",
            e.line
        );
        assert!(!e.to_string().is_empty());
    }
}

/// Lossless rewriting: no edits give the input back byte for byte, lines concatenate to the
/// input, and an edit of one line (chosen by the first byte) leaves every other line as it was.
pub fn rewrite(data: &[u8]) {
    assert!(
        apply_edits(data, &[]) == data,
        "rewriting with no edits changed the input"
    );
    let mut concat = Vec::with_capacity(data.len());
    for raw in Lines::new(data) {
        concat.extend_from_slice(raw.text);
        concat.extend_from_slice(raw.terminator);
    }
    assert!(concat == data, "lines do not concatenate to the input");
    let Some(&first) = data.first() else { return };
    let count = Lines::new(data).count() as u32;
    let target = u32::from(first) % count.max(1) + 1;
    let edits = [Edit {
        line: target,
        replacement: b"G1 X0".to_vec(),
    }];
    let out = apply_edits(data, &edits);
    let expected: Vec<&[u8]> = Lines::new(data)
        .map(|l| {
            if l.number == target {
                &b"G1 X0"[..]
            } else {
                l.text
            }
        })
        .collect();
    let got: Vec<&[u8]> = Lines::new(&out).map(|l| l.text).collect();
    assert!(
        got == expected,
        "an edit of line {target} changed other lines"
    );
}

/// Motions decoded from bytes: 6 bytes a move (X, Y, Z, E displacement as signed bytes scaled
/// by a per-move exponent, and a feed rate), so the fuzzer explores tiny, huge, zero-length,
/// extruder-only and reversing moves. The first byte picks the junction model and preset.
fn motions(data: &[u8]) -> (JunctionModel, MachineProfile, Vec<Motion>) {
    let first = data.first().copied().unwrap_or(0);
    let model = match first % 3 {
        0 => JunctionModel::ClassicJerk,
        1 => JunctionModel::JunctionDeviation,
        _ => JunctionModel::Klipper,
    };
    let presets = quietpath::plan::profiles::PRESETS;
    let profile =
        MachineProfile::preset(presets[(first as usize / 3) % presets.len()]).expect("preset");
    let mut out = Vec::new();
    for (i, c) in data.get(1..).unwrap_or(&[]).chunks_exact(6).enumerate() {
        let scale = 10f64.powi(i32::from(c[4] % 8) - 4); // 1e-4 … 1e3 mm per unit
        let d = |b: u8| f64::from(b as i8) * scale;
        let feed = 10f64.powf(f64::from(c[5]) / 64.0 - 1.0); // 0.1 … 1e3 mm/s
        out.push(Motion {
            line: i as u32 + 1,
            delta: [d(c[0]), d(c[1]), d(c[2]) * 0.01, d(c[3]) * 0.1],
            arc: None,
            feed_mm_s: feed,
            rotary_time_s: 0.0,
        });
    }
    (model, profile, out)
}

/// The planner on arbitrary motion: every move is finalised once, in order; times are finite
/// and add up; speeds never exceed the cruise speed; each move's exit is the next one's entry;
/// no phase asks for more than the move's acceleration.
pub fn planner(data: &[u8]) {
    let (model, profile, moves) = motions(data);
    let mut planner = Planner::new(profile.limits.clone(), model);
    let mut planned: Vec<PlannedMove> = Vec::new();
    for (i, m) in moves.iter().enumerate() {
        planner.push(m, i as u64, &mut |pm| planned.push(*pm));
    }
    planner.flush(&mut |pm| planned.push(*pm));
    let mut total = 0.0;
    for w in planned.windows(2) {
        assert!(w[0].tag <= w[1].tag, "moves finalised out of order");
    }
    for (k, pm) in planned.iter().enumerate() {
        let p = &pm.profile;
        for v in [
            p.entry, p.peak, p.exit, p.accel_s, p.cruise_s, p.decel_s, pm.start_s,
        ] {
            assert!(v.is_finite() && v >= 0.0, "move {k}: {p:?}");
        }
        let tol = 1e-6 * p.peak.max(1.0);
        assert!(
            p.entry <= p.peak + tol && p.exit <= p.peak + tol,
            "move {k}: {p:?}"
        );
        assert!(
            (pm.start_s - total).abs() <= 1e-6 * total.max(1.0),
            "move {k} starts at {} not {total}",
            pm.start_s
        );
        total += pm.duration();
        // v² = v0² + 2 a d on each ramp (with the ramp's own distance).
        let up = p.peak * p.peak - p.entry * p.entry;
        assert!(
            up <= 2.0 * p.acceleration * p.accel_mm * (1.0 + 1e-6) + 1e-9,
            "move {k}: accelerates beyond a: {p:?}"
        );
        if let Some(next) = planned.get(k + 1) {
            let d = (p.exit - next.profile.entry).abs();
            assert!(
                d <= 1e-6 * p.exit.max(1.0),
                "move {k}: exit {} ≠ next entry {}",
                p.exit,
                next.profile.entry
            );
        }
    }
    assert!(
        (planner.elapsed_s() - total).abs() <= 1e-6 * total.max(1.0),
        "elapsed {} ≠ sum {total}",
        planner.elapsed_s()
    );
}
