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
            // Speed is continuous from block to block, but for the one jump classic-jerk
            // firmware makes: a junction set above a slow block's nominal speed by the
            // safe-speed rule, where the block runs at its own speed to its end and the next
            // starts faster. Never a jump down.
            let (exit, entry) = (p.exit, next.profile.entry);
            let continuous = (exit - entry).abs() <= 1e-6 * exit.max(1.0);
            let up_from_cruise = entry > exit && (exit - p.peak).abs() <= tol;
            assert!(
                continuous || up_from_cruise,
                "move {k}: exit {exit} ≠ next entry {entry} ({p:?})"
            );
        }
    }
    assert!(
        (planner.elapsed_s() - total).abs() <= 1e-6 * total.max(1.0),
        "elapsed {} ≠ sum {total}",
        planner.elapsed_s()
    );
}

/// A time estimate line (`M73`, a slicer's time comment) as one placeholder: the rewriting jobs
/// write true estimates into them, so their text changes while their place does not.
fn estimate_or(text: &[u8]) -> &[u8] {
    if quietpath::estimate::has_estimates(text) {
        b"<estimate>"
    } else {
        text
    }
}

/// What every rewriting job must give: a file that re-parses in strict mode where the input
/// did, with every number finite and every coordinate and feed rate it computed sane (a word
/// carried over from an input motion line is the input's business), and every non-motion line
/// of the input kept, in order.
fn check_rewritten(input: &[u8], output: &[u8], what: &str) {
    use quietpath::gcode::Command;
    let sane = |letter: u8, v: f64| match letter {
        b'F' => v > 0.0 && v < 1e7,
        b'X' | b'Y' | b'Z' | b'E' | b'A' | b'B' | b'C' | b'I' | b'J' | b'K' | b'R' => {
            v.abs() <= quietpath::machine::MAX_COORDINATE
        }
        _ => true,
    };
    let input_ok = run_analyze(
        input,
        &AnalyzeOptions {
            strict: true,
            ..AnalyzeOptions::default()
        },
    )
    .is_ok();
    let mut kept_in: Vec<&[u8]> = Vec::new();
    // Words of the input's motion lines: a job that rewrites a line carries its other words
    // over (the smoother changes B and C and keeps the line's F, whatever it is).
    let mut input_words: std::collections::HashSet<(u8, u64)> = Default::default();
    // Every input line: an output line found here was copied, not written.
    let mut input_lines: std::collections::HashSet<&[u8]> = Default::default();
    for raw in Lines::new(input) {
        input_lines.insert(raw.text);
        if let Ok(l) = parse_one(raw.text) {
            let motion = matches!(l.command, Command::Code(c) if c.letter == b'G' && c.number <= 3);
            if !motion && !raw.text.is_empty() {
                kept_in.push(estimate_or(raw.text));
            }
            if motion {
                for (letter, value) in l.params.iter() {
                    if let Some(v) = value {
                        input_words.insert((letter, v.to_bits()));
                    }
                }
            }
        }
    }
    // Lines the job copied unchanged are the input's business (a hostile input may hold
    // absurd values the job rightly leaves alone); lines it wrote must be sane.
    let written = |text: &[u8]| !input_lines.contains(text);
    let mut kept_out: Vec<&[u8]> = Vec::new();
    for raw in Lines::new(output) {
        match parse_one(raw.text) {
            Ok(l) => {
                let motion =
                    matches!(l.command, Command::Code(c) if c.letter == b'G' && c.number <= 3);
                if motion && written(raw.text) {
                    for (letter, value) in l.params.iter() {
                        if let Some(v) = value {
                            let copied = input_words.contains(&(letter, v.to_bits()));
                            assert!(
                                v.is_finite() && (sane(letter, v) || copied),
                                "{what}: output line {}: {}={v}",
                                raw.number,
                                letter as char
                            );
                        }
                    }
                } else if !raw.text.is_empty() {
                    kept_out.push(estimate_or(raw.text));
                }
            }
            Err(e) => assert!(
                !input_ok,
                "{what}: output line {} does not parse: {e:?}",
                raw.number
            ),
        }
    }
    if input_ok {
        // Non-motion lines are kept in order (an optimiser may add its own comments).
        let mut it = kept_out.iter();
        for line in &kept_in {
            assert!(
                it.any(|o| o == line),
                "{what}: lost or reordered line {:?}",
                String::from_utf8_lossy(line)
            );
        }
    }
}

/// Infill regeneration on arbitrary input.
pub fn infill(data: &[u8]) {
    use quietpath::infill::{infill as run, InfillOptions};
    if let Ok(r) = run(data, &InfillOptions::default()) {
        check_rewritten(data, &r.output, "infill");
        // Never a dearer file (the default objective is energy); a kept original is the input.
        assert!(
            r.after.energy.total_j <= r.before.energy.total_j,
            "infill: {} J written for {} J",
            r.after.energy.total_j,
            r.before.energy.total_j
        );
        if r.best.pattern == quietpath::infill::Choice::Original {
            assert!(
                r.output == data,
                "infill: original kept but the output differs"
            );
        }
    }
}

/// Orientation smoothing on arbitrary input: the cone invariant always holds.
pub fn smooth(data: &[u8]) {
    use quietpath::orient::{smooth as run, SmoothOptions};
    let o = SmoothOptions::default();
    if let Ok(r) = run(data, &o) {
        assert!(
            r.max_angle_to_original_deg <= o.cone_deg / 2.0 + 1e-9,
            "smooth: {} over half the cone",
            r.max_angle_to_original_deg
        );
        check_rewritten(data, &r.output, "smooth");
    }
}

/// The dynamics report on arbitrary input: finite numbers.
pub fn vibration(data: &[u8]) {
    use quietpath::dynamics::{vibration as run, VibrationOptions};
    if let Ok(r) = run(data, &VibrationOptions::default()) {
        let json = serde_json::to_string(&r).expect("serialises");
        let v: serde_json::Value = serde_json::from_str(&json).expect("valid JSON");
        for key in ["max", "min", "mean"] {
            assert!(
                v["deviation_mm"][key].is_number(),
                "vibration: deviation {key} not finite: {json:.300}"
            );
        }
        assert!(
            v["psd"]["power"]
                .as_array()
                .is_some_and(|p| p.iter().all(|x| x.is_number())),
            "vibration: PSD not finite"
        );
    }
}

/// VTG on arbitrary input: Ok (with a sane output that stays within its measured tolerance)
/// or a typed error. (The dynamics rows are skipped: `vibration` is checked on its own.)
pub fn vtg(data: &[u8]) {
    use quietpath::vtg::{vtg as run, VtgOptions};
    // Lines allowed, so every corner the tolerance allows is rewritten; then the defaults,
    // which must add no line.
    for allow_more_lines_pct in [1000.0, 0.0] {
        let options = VtgOptions {
            dynamics: false,
            allow_more_lines_pct,
            ..VtgOptions::default()
        };
        let Ok(r) = run(data, &options) else { continue };
        check_rewritten(data, &r.output, "vtg");
        assert!(
            r.max_deviation_mm.is_finite() && r.max_deviation_mm <= r.tolerance_mm * 1.01 + 1e-9,
            "vtg: deviation {} over tolerance {}",
            r.max_deviation_mm,
            r.tolerance_mm
        );
        // Lines as the reader (and the firmware) counts them: a last line's own terminator
        // adds none, as the rewrite of a path that ends an unterminated file writes one.
        let lines = |b: &[u8]| Lines::new(b).count();
        assert!(
            allow_more_lines_pct > 0.0 || lines(&r.output) <= lines(data),
            "vtg: {} lines from {}",
            lines(&r.output),
            lines(data)
        );
    }
}
