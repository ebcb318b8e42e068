//! Conformance of `vtg` on real slicer output: every PrusaSlicer slice of ours and every corpus
//! file but the 34 MB one (its speed test is in the README) and the 5-axis toolpath (whose
//! lines carry rotary axes and are left alone).
//!
//! Each rewrite is checked independently of the optimiser: both files are read back as moves
//! ([`quietpath::path::extract`]) and every printing move of the output, sampled finely, must
//! lie within the tolerance of the original's printing moves of the same layer. Filament is
//! conserved to 0.5 %, and every line that is not a replaced move is kept. With the defaults
//! no file gets more lines, sharp corners, energy or simulated ringing, or more than 1 % more
//! time. With lines allowed (`allow_more_lines_pct`), as the issue asks of the stages: sharp
//! corners (turns over 30°) fall by at least 40 %, the modelled energy falls, the print time
//! rises by at most 1 % and the simulated mean deviation falls. Where a file cannot meet one of
//! these, it is named below with the reason, and what does hold for it is asserted.
//!
//! `cargo test -p quietpath-conformance vtg:: -- --nocapture` prints the table.
#![allow(clippy::unwrap_used)]

use quietpath::gcode::{parse_line, Lines};
use quietpath::path::extract;
use quietpath::vtg::deviation::file_deviation;
use quietpath::vtg::{vtg, ArcsMode, VtgOptions};
use std::path::PathBuf;

use quietpath_conformance::{corpus, corpus_dir, fixtures_dir};

/// Lines that are not `G0`–`G3` moves, in order.
/// The lines that are not moves, without the header quietpath writes when it rewrites the
/// file's time estimates (`; quietpath …`).
fn non_motion_lines(bytes: &[u8]) -> Vec<Vec<u8>> {
    Lines::new(bytes)
        .filter(|l| {
            !l.text
                .starts_with(quietpath::estimate::HEADER_PREFIX.as_bytes())
        })
        .filter(|l| {
            parse_line(l.text).map_or(true, |p| {
                !p.code()
                    .is_some_and(|c| c.letter == b'G' && c.number <= 3 && c.sub.is_none())
            })
        })
        .map(|l| l.text.to_vec())
        .collect()
}

/// What one rewrite did, in percent of the original.
#[derive(Debug)]
struct Outcome {
    name: String,
    max_deviation_mm: f64,
    turning_pct: f64,
    energy_pct: f64,
    time_pct: f64,
    mean_deviation_pct: f64,
    filament_pct: f64,
    kept_for_time: u64,
    arcs_written: u64,
    rewritten: u64,
    /// Why the original was handed back, if it was.
    kept: Option<String>,
    /// Layers kept as they were by the peak rule (the rest rewritten).
    peak_layers_kept: usize,
    lines_in: usize,
    lines: usize,
    /// The report's warning that the rewrite's peak segment rate is over the firmware's budget
    /// (and over the original's).
    over_segment_budget: Option<String>,
}

fn check(bytes: &[u8], name: &str, options: &VtgOptions) -> Outcome {
    let r = vtg(bytes, options).unwrap();
    let tol = options.tolerance_mm;
    match &r.message {
        // Handed back unchanged, and said why.
        Some(message) if r.peak_layers_kept.is_empty() => {
            assert!(
                r.output == bytes,
                "{name}: {message}, but the output differs"
            );
            eprintln!("{name}: {message}");
        }
        // Some layers kept as they were, the rest rewritten, and said why.
        Some(message) => {
            assert!(
                r.output != bytes,
                "{name}: {message}, but nothing rewritten"
            );
            eprintln!("{name}: {message}");
        }
        None => {
            assert!(r.peak_layers_kept.is_empty(), "{name}: layers kept, unsaid");
            // A file that comes back as it was says why (a variant that rewrote nothing once
            // came back as the quietest rewrite, silently).
            assert!(r.output != bytes, "{name}: handed back unchanged, unsaid");
        }
    }
    // The no-dearer rule on the dynamics model: neither the mean nor the peak rises. The model
    // runs on every file here (a Klipper file homing at its end once left it unrun, and the
    // rewrite unchecked).
    assert!(
        r.table2.deviation.is_some() || !options.dynamics,
        "{name}: the dynamics model did not run"
    );
    if let Some(d) = &r.table2.deviation {
        assert!(
            d.max_mm.after <= d.max_mm.before && d.mean_mm.after <= d.mean_mm.before,
            "{name}: simulated deviation {d:?}"
        );
    }
    assert!(
        r.max_deviation_mm <= tol,
        "{name}: reported deviation {}",
        r.max_deviation_mm
    );
    // Independent measurement on the two files (coordinates are written to 0.001 mm).
    let before = extract(bytes, &options.analyze, false).unwrap();
    let after = extract(&r.output, &options.analyze, false).unwrap();
    let measured = file_deviation(&before, &after, tol / 10.0);
    assert!(
        measured <= tol + 0.001,
        "{name}: measured deviation {measured} over {tol}"
    );
    // Filament conserved (to 0.5 %; in practice to rounding).
    let (fb, fa) = (r.before.filament_mm, r.after.filament_mm);
    assert!(
        ((fa - fb) / fb).abs() < 0.005,
        "{name}: filament {fb} -> {fa}"
    );
    // Every non-motion line is kept, in order.
    assert_eq!(
        non_motion_lines(bytes)
            .into_iter()
            .filter(|l| !l.is_empty())
            .count(),
        non_motion_lines(&r.output)
            .into_iter()
            .filter(|l| !l.is_empty())
            .count(),
        "{name}: non-motion lines"
    );
    assert_eq!(r.before.layers, r.after.layers, "{name}: layers");
    Outcome {
        name: name.to_string(),
        max_deviation_mm: measured,
        turning_pct: r.table1.n_turning.change_pct,
        energy_pct: r.table2.energy_j.change_pct,
        time_pct: r.table2.time_s.change_pct,
        mean_deviation_pct: r
            .table2
            .deviation
            .as_ref()
            .map_or(f64::NAN, |d| d.mean_mm.change_pct),
        filament_pct: (fa - fb) / fb * 100.0,
        kept_for_time: r.paths.kept_for_time,
        arcs_written: r.paths.arcs_written,
        rewritten: r.paths.rewritten,
        kept: r.message.clone().filter(|_| r.peak_layers_kept.is_empty()),
        peak_layers_kept: r.peak_layers_kept.len(),
        lines_in: bytes.split(|&b| b == b'\n').count(),
        lines: r.output.split(|&b| b == b'\n').count(),
        over_segment_budget: r.firmware.as_ref().and_then(|f| f.warning.clone()),
    }
}

fn options(tolerance_mm: f64, limit_feed: bool) -> VtgOptions {
    VtgOptions {
        tolerance_mm,
        limit_feed,
        ..rounding()
    }
}

/// The defaults but for the line budget: as many more lines as rounding every corner asks
/// for. What the stages achieve on their own; the default runs of [`check_all`] hold the
/// budget.
fn rounding() -> VtgOptions {
    VtgOptions {
        allow_more_lines_pct: 1000.0,
        ..VtgOptions::default()
    }
}

/// The Creality K1 benchy.
const K1_BENCHY: &str = "crealityprint-4.3.4_k1_benchy_m83_arcs.gcode";
/// The Creality K1C benchy.
const K1C_BENCHY: &str = "crealityprint-5_k1c_benchy_klipper_exclude-object.gcode";

/// Runs `vtg` on each file twice and checks every criterion, printing a table row for each run:
/// with the defaults, the promises every rewrite keeps (no more lines than the original, no
/// slower than 1 %, no dearer in energy, no more ringing, no more sharp corners); with lines
/// allowed ([`rounding`]), what the stages achieve (sharp corners −40 % or better, energy and
/// ringing down, time within 1 %), except on files handed back unchanged because every
/// rewrite raised the simulated mean or peak deviation, at most half of them.
fn check_all(files: &[(String, PathBuf)]) {
    let mut failures = Vec::new();
    let mut kept = 0;
    eprintln!(
        "{:<62} {:>8} {:>8} {:>7} {:>8} {:>8} {:>7} {:>9}",
        "file", "run", "lines %", "dev mm", "turns %", "energy %", "time %", "mean dev %"
    );
    for (name, path) in files {
        let bytes = std::fs::read(path).unwrap();
        for (run, options) in [("default", VtgOptions::default()), ("rounding", rounding())] {
            let o = check(&bytes, name, &options);
            eprintln!(
                "{:<62} {:>8} {:>+8.1} {:>7.3} {:>8.1} {:>8.2} {:>7.2} {:>9.1}",
                o.name,
                run,
                (o.lines as f64 / o.lines_in as f64 - 1.0) * 100.0,
                o.max_deviation_mm,
                o.turning_pct,
                o.energy_pct,
                o.time_pct,
                o.mean_deviation_pct,
            );
            let failed = if run == "default" {
                fails(&o, &DEFAULT_BARS)
            } else if o
                .kept
                .as_deref()
                .is_some_and(|m| m.contains("dynamics model"))
            {
                kept += 1;
                Vec::new()
            } else {
                fails(&o, &ROUNDING_BARS)
            };
            failures.extend(failed.into_iter().map(|f| format!("{name} ({run}): {f}")));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    // Handed back because every rewrite raised the simulated mean or peak deviation (the
    // no-dearer rule; `check` verified the output is the input): at most half the files (1 of
    // the 17 corpus files, none of the fixtures, on 2026-11-28: see the method's line budget).
    assert!(
        2 * kept <= files.len(),
        "{kept} of {} files kept",
        files.len()
    );
}

/// The bars one run of [`check_all`] is held to.
struct Bars {
    /// Largest change in sharp corners, %.
    corners_pct: f64,
    /// Energy and simulated mean deviation must fall (not only not rise).
    must_fall: bool,
    /// Lines may not grow, nor the peak segment rate past the firmware's budget; otherwise
    /// something must be rewritten.
    lines_kept: bool,
}

/// What the defaults promise on every file: not more lines, sharp corners, energy or
/// simulated mean deviation than the original, at most 1 % more time, and a peak segment rate
/// within the firmware's budget wherever the original's was.
const DEFAULT_BARS: Bars = Bars {
    corners_pct: 0.0,
    must_fall: false,
    lines_kept: true,
};

/// What the stages achieve with lines allowed: sharp corners −40 % or better, energy and
/// simulated mean deviation down, time within 1 %.
const ROUNDING_BARS: Bars = Bars {
    corners_pct: -40.0,
    must_fall: true,
    lines_kept: false,
};

/// The bars `o` misses, named (a NaN misses every one).
fn fails(o: &Outcome, bars: &Bars) -> Vec<String> {
    let down = |x: f64| if bars.must_fall { x < 0.0 } else { x <= 0.0 };
    let at_most = |x: f64, bar: f64| x <= bar;
    let mut fail = Vec::new();
    if bars.lines_kept && o.lines > o.lines_in {
        fail.push(format!("{} lines from {}", o.lines, o.lines_in));
    }
    if let Some(warning) = o.over_segment_budget.as_ref().filter(|_| bars.lines_kept) {
        fail.push(warning.clone());
    }
    if !bars.lines_kept && o.rewritten == 0 {
        fail.push("nothing rewritten".to_string());
    }
    // Layers the peak rule kept as they were keep their corners: there the corners must fall,
    // by whatever the other layers give.
    let corners_bar = if o.peak_layers_kept > 0 && bars.corners_pct < 0.0 {
        -1e-9
    } else {
        bars.corners_pct
    };
    if !at_most(o.turning_pct, corners_bar) {
        fail.push(format!("sharp corners {:+.1} %", o.turning_pct));
    }
    if !down(o.energy_pct) {
        fail.push(format!("energy {:+.2} %", o.energy_pct));
    }
    if !at_most(o.time_pct, 1.0) {
        fail.push(format!("time {:+.2} %", o.time_pct));
    }
    if !down(o.mean_deviation_pct) {
        fail.push(format!(
            "simulated mean deviation {:+.1} %",
            o.mean_deviation_pct
        ));
    }
    fail
}

/// Our PrusaSlicer slices (tests/fixtures/gcode).
fn fixture_files() -> Vec<(String, PathBuf)> {
    let mut v: Vec<(String, PathBuf)> = std::fs::read_dir(fixtures_dir().join("gcode"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "gcode"))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), p))
        .collect();
    v.sort();
    assert!(v.len() >= 14, "{} fixtures", v.len());
    v
}

/// The corpus, but for the 34 MB file and the 5-axis toolpath; `part` of two halves.
fn corpus_files(part: usize) -> Vec<(String, PathBuf)> {
    let all: Vec<_> = corpus()
        .into_iter()
        .filter(|f| !f.name.contains("_large") && !f.name.starts_with("multiaxis"))
        .map(|f| (f.name.clone(), f.path()))
        .collect();
    assert_eq!(all.len(), 17);
    all.into_iter()
        .enumerate()
        .filter(|(i, _)| i % 2 == part)
        .map(|(_, f)| f)
        .collect()
}

#[test]
fn every_fixture_meets_the_criteria() {
    check_all(&fixture_files());
}

#[test]
fn corpus_first_half_meets_the_criteria() {
    check_all(&corpus_files(0));
}

#[test]
fn corpus_second_half_meets_the_criteria() {
    check_all(&corpus_files(1));
}

/// Where the first rewrite rings more than the original, the whole-file variants race on every
/// eighth layer of a file of 512 kB and 64 layers or more; the race only picks what to write
/// whole, and on the corpus files that take it the result keeps the rule and rounds at least
/// as many corners as trying each variant whole in turn (which stops at the first that keeps
/// it). The fabtotum file's rewrites are few: the sample cannot judge its variants, which are
/// then written whole (its 1.5× variant rings 0.01 % less), the same file both ways. The K1 SE
/// accessory kept 27 layers as they were either way until motion after a rest set off on a
/// whole step (2026-12-06); now two variants with the steps as walked keep the rule whole,
/// and the race writes the one quieter on the sample (without keyholes: sharp corners −10.5 %,
/// where trying each whole stops at the first, with them: −10.2 %). (The CuraEngine puzzle
/// was a third until the model placed each corner's jump of the commanded velocity where it
/// happens, 2026-11-29: its first rewrite now keeps the rule.)
#[test]
fn racing_the_variants_writes_what_trying_each_whole_writes() {
    for name in [
        "crealityprint-4.3.8_k1se_accessory_m82_arcs_exclude-object",
        "cura-legacy-15.x_fabtotum_socket-screwdriver",
    ] {
        let bytes = std::fs::read(corpus_dir().join(format!("{name}.gcode"))).unwrap();
        assert!(bytes.len() >= 512 << 10, "{name} is too small to race");
        let raced = vtg(&bytes, &VtgOptions::default()).unwrap();
        let whole = vtg(
            &bytes,
            &VtgOptions {
                exhaustive: true,
                ..VtgOptions::default()
            },
        )
        .unwrap();
        let (r, w) = (&raced.table2.deviation, &whole.table2.deviation);
        for d in [r, w] {
            let d = d.as_ref().unwrap();
            let kept = d.max_mm.after <= d.max_mm.before && d.mean_mm.after <= d.mean_mm.before;
            assert!(kept, "{name}: {r:?} {w:?}");
        }
        let corners = |v: &quietpath::vtg::VtgReport| v.table1.n_turning.after;
        assert!(corners(&raced) <= corners(&whole), "{name}: {r:?} {w:?}");
        let variant_of = |v: &quietpath::vtg::VtgReport| {
            (
                v.paths.feed_cap_scale,
                v.paths.steps_joined,
                v.message.is_some(),
            )
        };
        let tried = variant_of(&whole) != (1.0, true, false);
        assert!(
            tried,
            "{name}: the first rewrite kept the rule; no variant was tried"
        );
    }
}

/// The race ranks the variants on the sample; a sample is not the file, so more than one
/// variant that keeps the rule there (the two quietest there, since 2026-12-07) is written
/// whole in turn, until one keeps it on the whole file. On the
/// ribbed tube (not tuned on) the first variant passed on the sample and rang more whole; a
/// race that wrote only that one handed the original back, where trying each whole rounds a
/// quarter of the corners. Since the model places each corner's jump of the commanded velocity
/// where it happens (2026-11-29) its first rewrite kept the rule and no variant was raced; since
/// motion after a rest sets off on a whole step (2026-12-06) its first rewrite rings 2 % over
/// the peak in one layer, no variant keeps the rule on the sample, and five layers are kept as
/// they were. The test holds the outcome only: rewritten, not handed back, half its corners
/// rounded; the race's choice is unit-tested
/// (`closed_loop::tests::the_race_writes_whole_the_two_variants_quietest_on_the_sample_that_pass_there`).
#[test]
fn the_race_writes_whole_the_variants_that_pass_on_the_sample() {
    let path = fixtures_dir().join("race/prusaslicer-2.5.0_ribbed_tube_gyroid.gcode");
    let bytes = std::fs::read(path).unwrap();
    let r = vtg(&bytes, &VtgOptions::default()).unwrap();
    let rewritten = r
        .message
        .as_deref()
        .is_none_or(|m| m.starts_with("kept ") && m.contains("layer(s) as they were"));
    assert!(rewritten, "{:?}", r.message);
    let d = r.table2.deviation.unwrap();
    assert!(d.mean_mm.after < d.mean_mm.before, "{d:?}");
    assert!(d.max_mm.after <= d.max_mm.before, "{d:?}");
    assert!(
        r.table1.n_turning.change_pct <= -20.0,
        "{:?}",
        r.table1.n_turning
    );
    assert!(r.table2.time_s.after <= r.table2.time_s.before * 1.01);
    assert!(r.table2.energy_j.after <= r.table2.energy_j.before);
}

/// The star at a 0.05 mm tolerance: its fillets, run at the eq. 29 speeds, leave the machine
/// ringing a little more than the sharp corners did; the dynamics model sees it, and `vtg`
/// rewrites the file again (steps as walked, or from faster speeds) and keeps the quietest
/// rewrite, which rings less than the original.
#[test]
fn the_dynamics_model_closes_the_loop() {
    let bytes =
        std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_star_fast_jerk15.gcode"))
            .unwrap();
    let tight = VtgOptions {
        tolerance_mm: 0.05,
        ..rounding()
    };
    let open = vtg(
        &bytes,
        &VtgOptions {
            dynamics: false,
            ..tight.clone()
        },
    )
    .unwrap();
    assert_eq!(open.paths.feed_cap_scale, 1.0);
    let model = quietpath::dynamics::VibrationOptions::default();
    let mean = |b: &[u8]| {
        quietpath::dynamics::vibration(b, &model)
            .unwrap()
            .printing_deviation_mm
            .mean
    };
    let (before, open_loop) = (mean(&bytes), mean(&open.output));
    assert!(open_loop > before, "{open_loop} vs {before}");
    let closed = vtg(&bytes, &tight).unwrap();
    assert!(!closed.paths.steps_joined || closed.paths.feed_cap_scale > 1.0);
    let d = closed.table2.deviation.as_ref().unwrap();
    assert_eq!(d.mean_mm.before, before);
    assert_eq!(d.mean_mm.after, mean(&closed.output));
    assert!(d.mean_mm.after < before);
    // Corners rounded, faster and cheaper than the original. (Not compared with the open
    // loop's time any more: that one joins its steps up to the segment budget, the retries
    // write them as walked, so the two differ in more than their speeds.) The first retry
    // that keeps the rule is kept: since 2026-11-28 (rounding in the fit and the deviation
    // check) that is the steps as walked at the eq. 29 speeds, −37 % of the sharp corners
    // (mean deviation −3.7 %, peak −27 %), where it had been the speeds ×1.5, −47 % (mean
    // −0.4 %, peak −19 %): at this tolerance, not the default, short of the 40 % bar.
    assert!(closed.table1.n_turning.change_pct <= -30.0);
    assert!(open.paths.steps_joined && !closed.paths.steps_joined);
    assert!(closed.table2.time_s.change_pct < 0.0);
    assert!(closed.table2.energy_j.change_pct < 0.0);
}

/// Where a variant keeps the no-dearer rule, the closed loop tries the stretch twins
/// (`Variant::rivals`) for more rounded corners. On the thesis teardrop and oval the first
/// rewrite rings more than the original: its joined segments run at their tightest step's
/// speed, so on classic jerk its capped writings cost time and it takes its fillets uncapped.
/// A twin keeps the rule, by default, and rounds more than the variant that passed before it
/// (2026-12-07: the teardrop −18.2 → −29.3 %, the oval −61.5 → −69.5 %).
#[test]
fn a_stretch_twin_rounds_more_corners_where_a_variant_keeps_the_rule() {
    for (name, bar) in [
        ("prusaslicer-2.5.0_thesis_teardrop.gcode", -25.0),
        ("prusaslicer-2.5.0_thesis_oval.gcode", -65.0),
    ] {
        let bytes = std::fs::read(fixtures_dir().join("gcode").join(name)).unwrap();
        let r = vtg(&bytes, &VtgOptions::default()).unwrap();
        assert!(r.paths.stretch_caps, "{name}");
        let d = r.table2.deviation.as_ref().unwrap();
        assert!(d.mean_mm.after <= d.mean_mm.before, "{name}: {d:?}");
        assert!(d.max_mm.after <= d.max_mm.before, "{name}: {d:?}");
        let corners = r.table1.n_turning.change_pct;
        assert!(corners <= bar, "{name}: {corners} %");
        assert!(r.after.file.lines <= r.before.file.lines, "{name}");
        assert!(r.table2.time_s.change_pct <= 0.0, "{name}");
    }
}

/// Where a rewrite raises the mean deviation, the closed loop's first round keeps the layers
/// that raised it most until the mean is back at the original's, not under it by a margin: a
/// layer kept quiet leaves less ringing in the rewritten layer after it, which the per-layer
/// figures miss, so the margin kept layers the file did not need kept (2026-12-07: the
/// fabtotum 322 → 299 layers kept, −14.3 → −19.5 %; the Marlin 2 benchy 19 → 14 layers,
/// −49.8 → −51.6 %). The rule still holds on both.
#[test]
fn the_first_mean_round_keeps_only_the_layers_the_mean_needs() {
    for (name, most_layers, bar) in [
        (
            "cura-legacy-15.x_fabtotum_socket-screwdriver.gcode",
            310,
            -18.0,
        ),
        ("prusaslicer-2.6.1_benchy_marlin2.gcode", 16, -51.0),
    ] {
        let bytes = std::fs::read(corpus_dir().join(name)).unwrap();
        let r = vtg(&bytes, &VtgOptions::default()).unwrap();
        let d = r.table2.deviation.as_ref().unwrap();
        assert!(d.mean_mm.after <= d.mean_mm.before, "{name}: {d:?}");
        assert!(d.max_mm.after <= d.max_mm.before, "{name}: {d:?}");
        let kept = r.peak_layers_kept.len();
        assert!(
            (1..=most_layers).contains(&kept),
            "{name}: {kept} layers kept"
        );
        let corners = r.table1.n_turning.change_pct;
        assert!(corners <= bar, "{name}: {corners} %");
        assert!(r.after.file.lines <= r.before.file.lines, "{name}");
    }
}

/// The progress `vtg` reports never goes back, and ends at 1: on a file whose closed loop
/// keeps layers as they were over its rounds (the K1 SE accessory) and on one where it tries
/// its variants and hands the original back (the star). Each attempt of the loop used to
/// report over a twentieth of the job from where it started, and the next started below where
/// the last had reached: a progress bar went back from 99 % to 95 %.
#[test]
fn vtg_s_progress_never_goes_back() {
    let files = [
        corpus_dir().join("crealityprint-4.3.8_k1se_accessory_m82_arcs_exclude-object.gcode"),
        fixtures_dir().join("gcode/prusaslicer-2.5.0_star_fast_jerk15.gcode"),
    ];
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        let mut seen: Vec<f64> = Vec::new();
        let report = quietpath::vtg::vtg_with_progress(&bytes, &VtgOptions::default(), &mut |f| {
            seen.push(f);
            true
        })
        .unwrap();
        let name = path.display();
        // The closed loop ran: the file's rewrite was simulated and judged.
        assert!(report.table2.deviation.is_some(), "{name}");
        let back = seen.windows(2).find(|w| w[1] < w[0]);
        assert!(back.is_none(), "{name}: {back:?}");
        assert!(seen.iter().all(|f| (0.0..=1.0).contains(f)), "{name}");
        assert_eq!(seen.last(), Some(&1.0), "{name}");
    }
}

/// `inside_corners` keeps every corner on the inside line: on the thesis triangle, whose infill
/// tips the racing line rounds with room to spare and the inside line only within loops or not
/// at all, fewer sharp corners go; both stay within the tolerance. Geometry alone, without the
/// dynamics model: its verdict on the inside line is a tie (the quietest rewrite's simulated
/// peak within 0.3 % of the original's, either side of it as the walk's steps change by a
/// few hundredths of a millimetre), and the rule it keeps has tests of its own.
#[test]
fn inside_corners_round_fewer_than_the_racing_line() {
    let bytes = std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_thesis_triangle.gcode"))
        .unwrap();
    let run = |inside_corners| {
        vtg(
            &bytes,
            &VtgOptions {
                inside_corners,
                dynamics: false,
                ..rounding()
            },
        )
        .unwrap()
    };
    let (racing, inside) = (run(false), run(true));
    for r in [&racing, &inside] {
        assert!(r.max_deviation_mm <= 0.1, "{}", r.max_deviation_mm);
        assert!(r.table1.n_turning.change_pct < 0.0);
    }
    assert!(
        racing.table1.n_turning.after * 2.0 < inside.table1.n_turning.after,
        "{} vs {}",
        racing.table1.n_turning.after,
        inside.table1.n_turning.after
    );
}

/// With `arcs`, runs on a circle are written as `G2`/`G3` where the firmware would cut them at
/// least as finely as the walk did and they cost nothing: fewer lines, every criterion still
/// met (the deviation is measured on the arcs themselves).
#[test]
fn arcs_cut_lines_and_keep_every_criterion() {
    for (name, path) in [
        (
            "prusaslicer-2.6.1_benchy_marlin2.gcode",
            corpus_dir().join("prusaslicer-2.6.1_benchy_marlin2.gcode"),
        ),
        (
            "prusaslicer-2.5.0_cube_marlin2_defaults.gcode",
            fixtures_dir().join("gcode/prusaslicer-2.5.0_cube_marlin2_defaults.gcode"),
        ),
        (
            "crealityprint-4.3.8_k1se_accessory_m82_arcs_exclude-object.gcode",
            corpus_dir().join("crealityprint-4.3.8_k1se_accessory_m82_arcs_exclude-object.gcode"),
        ),
    ] {
        let bytes = std::fs::read(path).unwrap();
        // Every variant tried whole, so both runs keep the first that passes: raced on a sample
        // of layers, the benchy's two runs pick different variants (without arcs one that
        // rounds fewer corners and rings less), and their lines do not compare.
        let with = |arcs| VtgOptions {
            arcs,
            exhaustive: true,
            ..rounding()
        };
        let lines = check(&bytes, name, &with(ArcsMode::Off)).lines;
        let o = check(&bytes, name, &with(ArcsMode::On));
        assert!(o.arcs_written > 0, "{name}: no arcs");
        assert!(
            o.lines < lines,
            "{name}: {} lines, {lines} without arcs",
            o.lines
        );
        assert!(o.turning_pct <= -40.0, "{name}: {}", o.turning_pct);
        assert!(o.energy_pct < 0.0 && o.time_pct <= 1.0, "{name}: {o:?}");
        assert!(o.mean_deviation_pct < 0.0, "{name}: {o:?}");
    }
}

/// The vase's thin walls end in wedge tips that turn back by 135–150° in 0.07 mm steps, too
/// tight to fillet in Marlin-sized steps: turned round keyhole loops instead, they are what
/// takes the file past 40 %. Without the loops (the scales the dynamics model tries last) the
/// corners fall by only about a quarter.
#[test]
fn keyholes_turn_the_thin_wall_tips() {
    let bytes =
        std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_vase_marlin-legacy_absE.gcode"))
            .unwrap();
    let report = vtg(&bytes, &rounding()).unwrap();
    assert!(report.paths.keyholes > 100, "{}", report.paths.keyholes);
    let o = check(&bytes, "vase", &rounding());
    assert!(o.turning_pct <= -40.0, "{o:?}");
    assert!(o.max_deviation_mm <= 0.1, "{o:?}");
    assert!(o.filament_pct.abs() <= 0.5, "{o:?}");
    // The sharp turns over 120° that are left: the loops took most of them.
    let sharp_tips = |b: &[u8]| {
        quietpath::vtg::metrics::from_input(b, &Default::default(), 120.0)
            .unwrap()
            .0
            .n_turning
    };
    let (before, after) = (sharp_tips(&bytes), sharp_tips(&report.output));
    assert!(
        (after as f64) < 0.6 * before as f64,
        "turns over 120°: {before} -> {after}"
    );
}

#[test]
fn a_tighter_tolerance_is_kept() {
    let bytes =
        std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_vase_marlin-legacy_absE.gcode"))
            .unwrap();
    let o = check(&bytes, "vase", &options(0.05, true));
    assert!(o.turning_pct < 0.0, "{}", o.turning_pct);
}

#[test]
fn keeping_the_feed_rounds_corners_without_costing_time() {
    let mut kept = 0;
    for name in [
        "slic3r-1.3.1-dev_multi-object.gcode",
        "cura-4.10.0_multi-object.gcode",
    ] {
        let bytes = std::fs::read(corpus_dir().join(name)).unwrap();
        let o = check(&bytes, name, &options(0.1, false));
        if o.kept.is_some() {
            // The rule on the simulated deviation: checked by `check`, and by the other file.
            kept += 1;
            continue;
        }
        assert!(o.turning_pct <= -40.0, "{name}: {}", o.turning_pct);
        assert!(o.time_pct <= 1.0, "{name}: {}", o.time_pct);
    }
    assert!(kept < 2, "both files handed back unchanged");
}

/// The default allows the 1 % of print time the issue permits
/// ([`quietpath::vtg::DEFAULT_ALLOW_SLOWER_PCT`]), and two files need it: Klipper at a
/// square-corner velocity of 50–100 mm/s takes sharp corners faster than any rounded corner
/// within 0.1 mm, so rounding them costs time. With nothing allowed (never slower) the K1 and
/// K1C benchies keep most of their corners sharp: paths are kept for time, the corners fall
/// short of 40 %, and the prints still get no slower and cheaper. Within the 1 % every bar holds
/// (`corpus_*_meets_the_criteria`), the rewrite buying the corners that cost least first.
/// Every corner rounded is a trade the default does not make: far past 40 %, more than 1 %
/// slower.
///
/// Never slower, the K1 benchy may come back unchanged instead: since the speed changes of
/// 2026-11-28 (rounding in the fit and the deviation check, not the method) its quietest
/// rewrite lowers the dynamics model's mean deviation 4.9 % but raises its peak 0.1 %, at the
/// same travel of layer 22, and keeping layers 20–22 as they were raises it further (the
/// machine enters them ringing differently). The no-dearer rule then hands the file back.
#[test]
fn klipper_benchies_spend_the_default_time_on_corners() {
    for name in [K1_BENCHY, K1C_BENCHY] {
        let bytes = std::fs::read(corpus_dir().join(name)).unwrap();
        let with = |pct: f64| VtgOptions {
            allow_slower_pct: pct,
            ..rounding()
        };
        let never_slower = check(&bytes, name, &with(0.0));
        let default = check(&bytes, name, &rounding());
        eprintln!("{name}\n  0 % {never_slower:?}\n  default {default:?}");
        assert!(never_slower.turning_pct > -40.0, "{never_slower:?}");
        assert!(never_slower.time_pct <= 0.05, "{never_slower:?}");
        if handed_back(&never_slower) {
            assert_eq!(
                never_slower.lines, never_slower.lines_in,
                "{never_slower:?}"
            );
            assert_eq!(never_slower.turning_pct, 0.0, "{never_slower:?}");
        } else {
            assert!(never_slower.turning_pct < 0.0, "{never_slower:?}");
            assert!(never_slower.kept_for_time > 0, "{never_slower:?}");
            assert!(never_slower.energy_pct < 0.0, "{never_slower:?}");
        }
        assert!(default.turning_pct <= -40.0, "{default:?}");
        assert!(default.energy_pct < 0.0, "{default:?}");
        assert!(default.time_pct <= 1.0, "allowance overrun {default:?}");
        assert!(
            default.mean_deviation_pct < never_slower.mean_deviation_pct,
            "{default:?}"
        );
        assert!(
            default.turning_pct < never_slower.turning_pct - 20.0,
            "{default:?}"
        );
    }
    let bytes = std::fs::read(corpus_dir().join(K1C_BENCHY)).unwrap();
    let all = check(
        &bytes,
        K1C_BENCHY,
        &VtgOptions {
            allow_slower_pct: 100.0,
            ..rounding()
        },
    );
    assert!(all.turning_pct <= -80.0, "{all:?}");
    assert!(all.time_pct > 1.0, "{all:?}");
}

/// Whether `vtg` handed the file back unchanged: no rewrite kept the dynamics model's
/// no-dearer rule.
fn handed_back(o: &Outcome) -> bool {
    o.kept
        .as_deref()
        .is_some_and(|m| m.starts_with("kept the original"))
}

/// The K1 benchy falls short of 40 % when it may not get slower (see
/// [`klipper_benchies_spend_the_default_time_on_corners`]), but it needs very little time to
/// get there. The rewrite buys the corners that cost least first. With
/// a tenth of a percent of the print time allowed, every bar of the issue holds at once: sharp
/// corners −40 % or better, energy falls, time within 1 %, less ringing. The tolerance and
/// filament are checked by `check` as for every file.
#[test]
fn k1_meets_every_bar_with_a_tenth_of_a_percent_of_time() {
    let bytes = std::fs::read(corpus_dir().join(K1_BENCHY)).unwrap();
    let options = VtgOptions {
        allow_slower_pct: 0.1,
        ..rounding()
    };
    let o = check(&bytes, K1_BENCHY, &options);
    eprintln!("{o:?}");
    assert!(o.turning_pct <= -40.0, "{o:?}");
    assert!(o.energy_pct < 0.0, "{o:?}");
    assert!(o.time_pct <= 1.0, "{o:?}");
    assert!(o.mean_deviation_pct < 0.0, "{o:?}");
}

/// Printing moves of `bytes` (`G1` lines with X or Y and a positive E word, relative or
/// absolute by `M82`/`M83`, and arcs, each one move as long as its arc) and how many are
/// shorter than 0.1 mm, read straight from the text.
fn printing_segments(bytes: &[u8]) -> (u64, u64) {
    let (mut x, mut y, mut e, mut absolute) = (0.0f64, 0.0f64, 0.0f64, true);
    let (mut n, mut short) = (0u64, 0u64);
    for line in String::from_utf8_lossy(bytes).lines() {
        let code = line.split(';').next().unwrap_or("").trim();
        let mut words = code.split_whitespace();
        let head = words.next().unwrap_or("");
        match head {
            "M82" => absolute = true,
            "M83" => absolute = false,
            "G92" => {
                for w in words {
                    if let Some(v) = w.strip_prefix('E') {
                        e = v.parse().unwrap_or(e);
                    }
                }
            }
            "G0" | "G1" | "G2" | "G3" => {
                let (mut nx, mut ny, mut de, mut ij) = (x, y, 0.0, [0.0f64; 2]);
                for w in words {
                    let (k, v) = w.split_at(1);
                    let v: f64 = v.parse().unwrap_or(f64::NAN);
                    match k {
                        "X" => nx = v,
                        "Y" => ny = v,
                        "I" => ij[0] = v,
                        "J" => ij[1] = v,
                        "E" if absolute => {
                            de = v - e;
                            e = v;
                        }
                        "E" => de = v,
                        _ => {}
                    }
                }
                let len = if head == "G2" || head == "G3" {
                    // One move of the file, as long as its arc (centre at the offsets).
                    let (cx, cy) = (x + ij[0], y + ij[1]);
                    let a0 = (y - cy).atan2(x - cx);
                    let mut sweep = (ny - cy).atan2(nx - cx) - a0;
                    let tau = std::f64::consts::TAU;
                    if head == "G3" && sweep <= 0.0 {
                        sweep += tau;
                    }
                    if head == "G2" && sweep >= 0.0 {
                        sweep -= tau;
                    }
                    ij[0].hypot(ij[1]) * sweep.abs()
                } else {
                    (nx - x).hypot(ny - y)
                };
                if de > 0.0 && len > 0.0 {
                    n += 1;
                    short += u64::from(len < 0.1);
                }
                (x, y) = (nx, ny);
            }
            _ => {}
        }
    }
    (n, short)
}

/// The firmware figures of the report are those of the written file, read back from its text;
/// and the segment budget works: joining steps as far as the tolerance allows (0 ms) writes no
/// more lines than joining them only up to 1 ms at their feed, each rewrite still measured
/// within the tolerance, and the teardrop's rewrite stays under 1.5 times its lines (the walk
/// alone wrote 2.5 times: 3506 → 8929; joined, 4768: the rest is what its corners demand,
/// see `docs/method/vtg.md#segment-budget`).
#[test]
fn the_segment_budget_joins_steps_and_the_report_counts_the_written_file() {
    let name = "prusaslicer-2.5.0_thesis_teardrop.gcode";
    let bytes = std::fs::read(fixtures_dir().join("gcode").join(name)).unwrap();
    let with = |ms: f64| VtgOptions {
        min_segment_time_ms: Some(ms),
        dynamics: false,
        ..rounding()
    };
    let run = |ms: f64| {
        let o = with(ms);
        let r = vtg(&bytes, &o).unwrap();
        let before = extract(&bytes, &o.analyze, false).unwrap();
        let after = extract(&r.output, &o.analyze, false).unwrap();
        let measured = file_deviation(&before, &after, o.tolerance_mm / 10.0);
        assert!(measured <= o.tolerance_mm + 0.001, "{ms} ms: {measured}");
        r
    };
    let (fine, coarse) = (run(1.0), run(0.0));
    for r in [&fine, &coarse] {
        let f = r.firmware.as_ref().unwrap();
        let lines = r.output.split(|&b| b == b'\n').count() as u64
            - u64::from(r.output.last() == Some(&b'\n'));
        assert_eq!(f.after.lines, lines);
        assert_eq!(f.after.bytes, r.output.len() as u64);
        let (n, short) = printing_segments(&r.output);
        assert_eq!(
            (f.after.printing_segments, f.after.segments_under_0_1mm),
            (n, short)
        );
        let (n0, short0) = printing_segments(&bytes);
        assert_eq!(
            (f.before.printing_segments, f.before.segments_under_0_1mm),
            (n0, short0)
        );
        assert!(f.after.peak_segments_per_s > 0.0);
    }
    let (a, b) = (
        &fine.firmware.unwrap().after,
        &coarse.firmware.unwrap().after,
    );
    eprintln!("1 ms: {a:?}\n0 ms: {b:?}");
    assert!(
        b.lines <= a.lines,
        "{} lines at 0 ms, {} at 1 ms",
        b.lines,
        a.lines
    );
    let lines_in = bytes.split(|&c| c == b'\n').count() as f64;
    let default = vtg(
        &bytes,
        &VtgOptions {
            dynamics: false,
            ..rounding()
        },
    )
    .unwrap();
    let lines_out = default.output.split(|&c| c == b'\n').count() as f64;
    assert!(
        lines_out <= 1.5 * lines_in,
        "{lines_out} lines out of {lines_in}"
    );
    assert!(b.segments_under_0_1mm <= a.segments_under_0_1mm);
}

/// The 34 MB CuraEngine file with the defaults and the dynamics model on: the quietest variant
/// raises the simulated mean deviation (by 4.6 % on 2026-11-27), and the file comes back
/// rewritten with the layers that raised it most, and any that rang above the original's
/// peak, kept as they were. `check` verifies the tolerance on the written file, the filament,
/// the lines that are not moves and the no-dearer rule on both deviation figures; here, also
/// the rest of the defaults' promises. About a minute in release, several in a debug build:
/// `cargo test --release -p quietpath-conformance vtg:: -- --ignored --nocapture`
/// (`make bench`).
#[test]
#[ignore = "a minute in release: run with --ignored (make bench)"]
fn the_34_mb_file_keeps_the_layers_that_raised_the_mean() {
    let file = corpus()
        .into_iter()
        .find(|f| f.name.contains("_large"))
        .unwrap();
    let bytes = std::fs::read(file.path()).unwrap();
    let t0 = std::time::Instant::now();
    let o = check(&bytes, &file.name, &VtgOptions::default());
    eprintln!("{o:?} in {:.1} s", t0.elapsed().as_secs_f64());
    assert!(o.kept.is_none(), "handed back: {:?}", o.kept);
    assert!(
        o.peak_layers_kept > 0,
        "no layer kept: the loop was not taken"
    );
    let failed = fails(&o, &DEFAULT_BARS);
    assert!(failed.is_empty(), "{failed:?}");
    assert!(
        o.turning_pct <= -40.0,
        "sharp corners {:+.1} %",
        o.turning_pct
    );
}
