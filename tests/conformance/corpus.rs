//! Every real file in the shared corpus parses, analyzes and round-trips, and the analysis
//! agrees with what the slicers themselves wrote (layer markers, filament summaries).
#![allow(clippy::unwrap_used)]

use quietpath::analyze::{analyze, AnalyzeOptions, ExtrusionModeOption, LayerSource};
use quietpath::error::Warnings;
use quietpath::gcode::{apply_edits, for_each_line, Edit, Lines, Strictness};
use quietpath::machine::{ExtrusionMode, ModeSource};
use quietpath_conformance::{corpus, fixtures_dir, CorpusFile};

fn file(name_prefix: &str) -> CorpusFile {
    corpus()
        .into_iter()
        .find(|f| f.name.starts_with(name_prefix))
        .unwrap_or_else(|| panic!("no corpus file starting with {name_prefix}"))
}

#[test]
fn corpus_is_complete_and_matches_its_provenance() {
    let files = corpus();
    assert_eq!(files.len(), 19, "SOURCES.md lists 19 files");
    for f in &files {
        let bytes = f.read();
        assert_eq!(
            bytes.len() as u64,
            f.bytes,
            "{}: size differs from SOURCES.md",
            f.name
        );
        let lines = Lines::new(&bytes).count() as u64;
        assert!(
            lines.abs_diff(f.lines) <= 1,
            "{}: {lines} lines, SOURCES.md says {}",
            f.name,
            f.lines
        );
    }
}

#[test]
fn every_file_parses_strictly_without_warnings() {
    for f in corpus() {
        let bytes = f.read();
        let mut warnings = Warnings::default();
        let mut parsed = 0u64;
        for_each_line(&bytes, Strictness::Strict, &mut warnings, |_, line, _| {
            parsed += u64::from(line.is_some());
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{}: {e}", f.name));
        assert!(
            warnings.list().is_empty(),
            "{}: {:?}",
            f.name,
            warnings.list()
        );
        assert!(parsed.abs_diff(f.lines) <= 1, "{}", f.name);
        let strict = AnalyzeOptions {
            strict: true,
            ..AnalyzeOptions::default()
        };
        analyze(&bytes, &strict).unwrap_or_else(|e| panic!("{}: {e}", f.name));
    }
}

#[test]
fn every_file_round_trips_byte_identically() {
    for f in corpus() {
        let bytes = f.read();
        assert!(
            apply_edits(&bytes, &[]) == bytes,
            "{}: rewrite without edits differs",
            f.name
        );
    }
}

#[test]
fn edits_replace_whole_lines_and_leave_the_rest_untouched() {
    for f in corpus().iter().filter(|f| f.bytes < 4_000_000) {
        let bytes = f.read();
        let lines: Vec<_> = Lines::new(&bytes).collect();
        // Replace every 97th line that starts with G1 by a canonical re-spelling.
        let edits: Vec<Edit> = lines
            .iter()
            .filter(|l| l.text.starts_with(b"G1 ") && l.number % 97 == 0)
            .map(|l| Edit {
                line: l.number,
                replacement: [b"G1 ; was: ".as_slice(), l.text].concat(),
            })
            .collect();
        assert!(
            !edits.is_empty() || f.name.starts_with("multiaxis"),
            "{}: nothing to edit",
            f.name
        );
        let out = apply_edits(&bytes, &edits);
        let out_lines: Vec<_> = Lines::new(&out).collect();
        assert_eq!(out_lines.len(), lines.len(), "{}", f.name);
        let mut edit = edits.iter().peekable();
        for (a, b) in lines.iter().zip(&out_lines) {
            assert_eq!(a.terminator, b.terminator, "{}:{}", f.name, a.number);
            if edit.peek().is_some_and(|e| e.line == a.number) {
                assert_eq!(b.text, edit.next().unwrap().replacement.as_slice());
            } else {
                assert_eq!(a.text, b.text, "{}:{} changed", f.name, a.number);
            }
        }
    }
}

#[test]
fn layer_counts_match_the_slicers_own_markers() {
    for f in corpus() {
        let report = analyze(&f.read(), &AnalyzeOptions::default()).unwrap();
        match f.marker_layers {
            Some(expected) => {
                assert!(
                    matches!(report.layer_source, LayerSource::Markers(_)),
                    "{}",
                    f.name
                );
                assert!(
                    report.layers.abs_diff(expected) <= 1,
                    "{}: {} layers, the slicer marked {expected}",
                    f.name,
                    report.layers
                );
            }
            None => {
                assert_eq!(report.layer_source, LayerSource::ZChanges, "{}", f.name);
                if f.z_extruding < 1000 {
                    // Planar files: one layer per distinct printing height.
                    assert!(
                        report.layers.abs_diff(f.z_extruding) <= 1,
                        "{}: {} layers vs {} heights",
                        f.name,
                        report.layers,
                        f.z_extruding
                    );
                } else {
                    // Continuous-Z files must not explode into one layer per Z value. (The 5-axis file is
                    // counted in machine coordinates, where the rotary table adds turns.)
                    assert!(
                        report.layers >= 10 && report.layers * 10 < f.z_extruding,
                        "{}: {} layers from {} distinct heights",
                        f.name,
                        report.layers,
                        f.z_extruding
                    );
                }
            }
        }
    }
}

#[test]
fn continuous_z_vases_count_revolutions_not_points() {
    // Independent count: the winding of the printed path around the part's centre.
    let bytes = file("fullcontrol").read();
    let r = analyze(&bytes, &AnalyzeOptions::default()).unwrap();
    let b = r.bounds.unwrap();
    let centre = [(b.min[0] + b.max[0]) / 2.0, (b.min[1] + b.max[1]) / 2.0];
    let (mut x, mut y, mut winding) = (0.0f64, 0.0f64, 0.0f64);
    let mut prev_angle: Option<f64> = None;
    for raw in Lines::new(&bytes) {
        let line = quietpath::gcode::parse_line(raw.text).unwrap();
        let p = &line.params;
        if !matches!(line.code(), Some(c) if c.is(b'G', 1)) {
            continue;
        }
        x = p.get(b'X').unwrap_or(x);
        y = p.get(b'Y').unwrap_or(y);
        if p.get(b'E').is_some_and(|e| e > 0.0) {
            let a = (y - centre[1]).atan2(x - centre[0]);
            if let Some(pa) = prev_angle {
                let d = (a - pa + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                winding += d;
            }
            prev_angle = Some(a);
        } else {
            prev_angle = None;
        }
    }
    let revolutions = winding.abs() / std::f64::consts::TAU;
    assert!(revolutions > 50.0, "{revolutions}");
    assert!(
        (r.layers as f64 - revolutions).abs() <= 0.05 * revolutions,
        "{} layers for {revolutions:.1} revolutions",
        r.layers
    );
}

/// Filament totals the slicers wrote in their summaries, with the flow override (`M221`) the
/// file applies, which the slicers' own count leaves out.
#[test]
fn filament_matches_the_slicers_summaries() {
    let cases: [(&str, f64, f64); 9] = [
        ("superslicer-2.3.56", 264.59, 1.0),
        ("prusaslicer-2.7.4_screw", 1706.22, 1.0),
        ("prusaslicer-2.7.4_spiral", 2996.07, 1.0),
        ("prusaslicer-2.6.1_benchy", 4282.06, 0.95),
        ("slic3r-pe-1.33.3", 4913.4, 1.0),
        ("simplify3d-5.1.2", 291.4, 1.0),
        ("kisslicer-2.0.6", 305.09, 1.0),
        ("crealityprint-4.3.8", 2007.59, 1.0),
        ("crealityprint-5", 3775.18, 1.0),
    ];
    for (name, slicer_mm, flow) in cases {
        let r = analyze(&file(name).read(), &AnalyzeOptions::default()).unwrap();
        let expected = slicer_mm * flow;
        assert!(
            (r.filament_mm - expected).abs() <= 0.01 * expected,
            "{name}: {} mm of filament, the slicer says {expected}",
            r.filament_mm
        );
    }
}

#[test]
fn absolute_extrusion_is_detected_when_the_file_never_says() {
    let legacy = file("cura-legacy-15.x").read();
    let r = analyze(&legacy, &AnalyzeOptions::default()).unwrap();
    assert_eq!(
        (r.extrusion.mode, r.extrusion.source),
        (ExtrusionMode::Absolute, ModeSource::Inferred)
    );
    assert!(
        r.filament_mm > 1_000.0 && r.filament_mm < 100_000.0,
        "{} mm",
        r.filament_mm
    );
    assert!(r.warnings.iter().any(|w| w.message.contains("M82/M83")));
    // Read the wrong way, the same file claims kilometres of filament.
    let wrong = AnalyzeOptions {
        extrusion_mode: Some(ExtrusionModeOption::Relative),
        ..AnalyzeOptions::default()
    };
    let bad = analyze(&legacy, &wrong).unwrap();
    assert!(
        bad.filament_mm > 100.0 * r.filament_mm,
        "{} mm",
        bad.filament_mm
    );

    // Kiri:Moto relies on its start macro for relative E; its own summary says 225.03 mm.
    let kiri = analyze(&file("kirimoto").read(), &AnalyzeOptions::default()).unwrap();
    assert_eq!(
        (kiri.extrusion.mode, kiri.extrusion.source),
        (ExtrusionMode::Relative, ModeSource::Inferred)
    );
    assert!(
        (kiri.filament_mm - 225.03).abs() < 0.05 * 225.03,
        "{} mm",
        kiri.filament_mm
    );
}

#[test]
fn every_report_is_sane_and_serialises() {
    for f in corpus() {
        let r = analyze(&f.read(), &AnalyzeOptions::default()).unwrap();
        let json = serde_json::to_value(&r).unwrap_or_else(|e| panic!("{}: {e}", f.name));
        for key in [
            "time_s",
            "moves",
            "layers",
            "distance_mm",
            "filament_mm",
            "material_g",
            "energy",
            "toolpath",
            "warnings",
        ] {
            assert!(json.get(key).is_some(), "{}: report lacks {key}", f.name);
        }
        assert!(r.time_s > 0.0 && r.time_s.is_finite(), "{}", f.name);
        assert!(r.moves > 1000, "{}: {} moves", f.name, r.moves);
        assert!(
            r.distance_mm > r.extrude_distance_mm && r.extrude_distance_mm > 0.0,
            "{}",
            f.name
        );
        assert!(
            (r.extrude_distance_mm + r.travel_distance_mm - r.distance_mm).abs()
                < 1e-6 * r.distance_mm
        );
        let feature_sum: f64 = r.features.iter().map(|x| x.distance_mm).sum();
        assert!(
            (feature_sum - r.distance_mm).abs() < 1e-6 * r.distance_mm,
            "{}",
            f.name
        );
        let b = r.bounds.unwrap();
        assert!((0..3).all(|i| b.min[i] <= b.max[i]), "{}", f.name);
        assert!(
            r.material_g > 0.1 && r.material_g < 2000.0,
            "{}: {} g",
            f.name,
            r.material_g
        );
        assert!(
            !r.temperatures.is_empty()
                || f.name.starts_with("multiaxis")
                || f.name.starts_with("fullcontrol")
                || f.name.starts_with("kiri"),
            "{}: no temperatures",
            f.name
        );
    }
}

#[test]
fn the_slicer_is_recognised() {
    for (name, slicer) in [
        ("prusaslicer-2.6.1", "PrusaSlicer 2.6.1"),
        ("superslicer", "SuperSlicer 2.3.56"),
        ("cura-4.10", "Cura_SteamEngine 4.10.0"),
        ("simplify3d", "Simplify3D(R) Version 5.1.2"),
        ("kirimoto", "Kiri:Moto 3.0"),
        ("kisslicer", "KISSlicer"),
        ("ideamaker", "ideaMaker 4.2.0"),
        ("crealityprint-4.3.4", "Creality Print 4.3.4"),
        ("slic3r-pe", "Slic3r 1.33.3-prusa3d"),
    ] {
        let r = analyze(&file(name).read(), &AnalyzeOptions::default()).unwrap();
        let got = r.file.slicer.unwrap_or_default();
        assert!(got.starts_with(slicer), "{name}: slicer {got:?}");
    }
}

/// The playground plans a file in a second worker, with the moves and results passed as
/// bytes: the report must be `analyze`'s to the bit on every file (arcs, dwells, Klipper
/// limits, temperature and fan events, 5-axis moves), and with a Klipper config applied.
#[test]
fn analyze_with_the_timing_side_apart_gives_the_same_report() {
    use quietpath::analyze::apart::{read_apart, report_apart, TimingApart};
    let klipper = AnalyzeOptions {
        machine: Some("voron-klipper".into()),
        ..AnalyzeOptions::default()
    };
    for f in corpus() {
        let input = f.read();
        for options in [AnalyzeOptions::default(), klipper.clone()] {
            let mut timing = TimingApart::new();
            let mut batches = 0;
            let side = read_apart(&input, &options, &mut |_| true, &mut |batch| {
                batches += 1;
                timing.feed(batch).unwrap();
            })
            .unwrap();
            let report = report_apart(&input, &options, side, &timing.finish().unwrap()).unwrap();
            let whole = analyze(&input, &options).unwrap();
            assert_eq!(
                serde_json::to_string(&report).unwrap(),
                serde_json::to_string(&whole).unwrap(),
                "{}",
                f.name
            );
            assert!(batches >= 1, "{}", f.name);
        }
    }
}

/// The clock an analysis keeps of its planning pass (what `vtg` refreshes a rewrite's time
/// estimates from) is, to the bit, the clock a planning walk of the file gives, on every file
/// of the corpus: the estimates written from either are the same.
#[test]
fn the_analysis_keeps_the_clock_a_planning_walk_gives() {
    use quietpath::analyze::analyze_with_starts;
    use quietpath::estimate::Clock;
    let options = AnalyzeOptions::default();
    for f in corpus() {
        let bytes = f.read();
        let walked = Clock::of(&bytes, &options).unwrap();
        let (report, starts) = analyze_with_starts(&bytes, &options).unwrap();
        let kept = Clock::from_analysis(&report, starts);
        assert!(kept == walked, "{}: the clocks differ", f.name);
    }
}

/// The firmware figures an analysis counts in its own pass (what `vtg` reports of the original
/// and of the file it hands back) are, to the bit, those a planning walk of the file counts, on
/// every file of the corpus and at two minimum segment times.
#[test]
fn the_analysis_counts_the_firmware_figures_a_planning_walk_gives() {
    use quietpath::plan::JunctionModel;
    use quietpath::vtg::firmware::{analysed_figures, figures, SegmentBudget};
    let options = AnalyzeOptions::default();
    for f in corpus() {
        let bytes = f.read();
        for ms in [None, Some(50.0)] {
            let budget = SegmentBudget::for_file(&bytes, JunctionModel::ClassicJerk, ms);
            let walked = figures(&bytes, &options, &budget).unwrap();
            let (report, counted) = analysed_figures(&bytes, &options, &budget).unwrap();
            assert_eq!(counted, walked, "{} at {ms:?} ms", f.name);
            assert_eq!(
                report.extruding_moves, walked.printing_segments,
                "{}",
                f.name
            );
        }
    }
}

/// The analysis of a file with its estimates refreshed, read off the analysis before the
/// refresh with its lines moved (what `vtg` hands back instead of analysing its output again),
/// is, to the bit, a fresh analysis of the refreshed file: on every corpus file and fixture,
/// refreshed once (the header added) and again (the first header replaced).
#[test]
fn the_refreshed_file_s_analysis_is_the_earlier_one_with_its_lines_moved() {
    use quietpath::analyze::analyze_with_starts;
    use quietpath::estimate::{analysis_of_refreshed, has_estimates, rewrite_by_clock, Clock};
    let options = AnalyzeOptions::default();
    let files = corpus_and_fixtures();
    let mut refreshed = 0;
    for (name, bytes) in files {
        let mut file = bytes;
        for round in 0..2 {
            if !has_estimates(&file) {
                break;
            }
            let (report, starts) = analyze_with_starts(&file, &options).unwrap();
            let clock = Clock::from_analysis(&report, starts);
            let e = rewrite_by_clock(&file, &clock, &["a job".to_string()]);
            let moved = analysis_of_refreshed(&report, &file, &e.output, &e.moved);
            let fresh = analyze(&e.output, &options).unwrap();
            assert!(moved.as_ref() == Some(&fresh), "{name}, round {round}");
            refreshed += 1;
            file = e.output;
        }
    }
    assert!(refreshed >= 40, "{refreshed} refreshes");
}

/// Every corpus file and fixture, by name, fixtures last.
fn corpus_and_fixtures() -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = corpus()
        .iter()
        .map(|f| (f.name.clone(), f.read()))
        .collect();
    let mut fixtures: Vec<_> = std::fs::read_dir(fixtures_dir().join("gcode"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    fixtures.sort();
    files.extend(
        fixtures
            .iter()
            .map(|p| (p.display().to_string(), std::fs::read(p).unwrap())),
    );
    files
}

/// The path and its moves' sources read in one pass, the path unplanned and then timed from
/// the analysis' planning pass (what `vtg` reads of every file it rewrites), are, to the bit,
/// the planned path of `path::extract` and the sources of `move_sources`, on every corpus file
/// and fixture, with the default machine and with Klipper's (whose homing the planner does
/// not time): pairing the two folds changes neither, and the analysis plans what the path's
/// own planning would.
#[test]
fn the_path_and_its_sources_read_in_one_pass_are_those_of_two() {
    use quietpath::analyze::{analyze_keeping, Keep};
    use quietpath::path::extract;
    use quietpath::vtg::source::{move_sources, path_and_sources};
    let klipper = AnalyzeOptions {
        machine: Some("voron-klipper".into()),
        ..AnalyzeOptions::default()
    };
    // Debug prints a NaN feed as NaN on both sides (`==` would call them different).
    let same =
        |a: &dyn std::fmt::Debug, b: &dyn std::fmt::Debug| format!("{a:?}") == format!("{b:?}");
    let mut annotated = 0;
    for (name, bytes) in &corpus_and_fixtures() {
        // Klipper's machine on the smaller files only: the 34 MB file takes seconds a pass.
        let machines = if bytes.len() < 8 << 20 { 2 } else { 1 };
        for options in [AnalyzeOptions::default(), klipper.clone()]
            .iter()
            .take(machines)
        {
            let (mut path, sources) = path_and_sources(bytes, options, false).unwrap();
            let keep = Keep {
                timed_moves: true,
                ..Keep::default()
            };
            let (report, kept) = analyze_keeping(bytes, options, keep).unwrap();
            path.set_timing(&kept.timed_moves.unwrap(), report.time_s);
            let alone = extract(bytes, options, true).unwrap();
            assert_eq!(path.moves.len(), alone.moves.len(), "{name}");
            for (k, (a, b)) in path.moves.iter().zip(&alone.moves).enumerate() {
                assert!(same(a, b), "{name}: move {k}");
            }
            assert!(same(&path.layers, &alone.layers), "{name}: layers");
            assert!(same(&path.features, &alone.features), "{name}: features");
            assert!(same(&path.warnings, &alone.warnings), "{name}: warnings");
            assert_eq!(path.time_s.to_bits(), alone.time_s.to_bits(), "{name}");
            let apart = move_sources(bytes, options).unwrap();
            assert_eq!(sources.moves.len(), apart.moves.len(), "{name}");
            for (k, (a, b)) in sources.moves.iter().zip(&apart.moves).enumerate() {
                assert!(same(a, b), "{name}: source {k}");
            }
            assert_eq!(sources.limits, apart.limits, "{name}: limits");
            annotated += usize::from(sources.moves.iter().any(|s| !s.notes.range().is_empty()));
        }
    }
    // The pairing matters where the sources fold skips lines: files with `;WIDTH:` notes.
    assert!(annotated >= 4, "{annotated} files with annotations");
}

/// The trajectory metrics an analysis takes on its timing side (what `vtg` reports of each
/// rewrite) are, to the bit, those of a pass of their own over the file
/// (`vtg::metrics::from_input`), for the file and every layer, at two critical angles: on
/// every corpus file and fixture, and on rewrites with arcs and with lines.
#[test]
fn the_analysis_takes_the_trajectory_metrics_a_pass_of_their_own_gives() {
    use quietpath::analyze::{analyze_keeping, Keep};
    use quietpath::vtg::metrics::from_input;
    use quietpath::vtg::{vtg, ArcsMode, VtgOptions};
    let options = AnalyzeOptions::default();
    let mut files = corpus_and_fixtures();
    let fixtures = files.len() - corpus().len();
    // Rewrites of the small fixtures: arcs and rounded corners the slicers never write.
    let mut rewrites = Vec::new();
    for (name, bytes) in files.iter().rev().take(fixtures) {
        if bytes.len() < 2 << 20 {
            for arcs in [ArcsMode::On, ArcsMode::Off] {
                let o = VtgOptions {
                    arcs,
                    dynamics: false,
                    ..VtgOptions::default()
                };
                let out = vtg(bytes, &o).unwrap().output;
                rewrites.push((format!("{name} rewritten, {arcs:?}"), out));
            }
        }
    }
    files.extend(rewrites);
    let bits = |m: &quietpath::analyze::toolpath::ToolpathMetrics| format!("{m:?}");
    for (name, bytes) in &files {
        for deg in [30.0, 12.5] {
            let keep = Keep {
                layer_metrics_deg: Some(deg),
                ..Keep::default()
            };
            let (report, kept) = analyze_keeping(bytes, &options, keep).unwrap();
            let (file, layers) = kept.layer_metrics.unwrap();
            let (own_file, own_layers) = from_input(bytes, &options, deg).unwrap();
            assert_eq!(bits(&file), bits(&own_file), "{name} at {deg}°");
            assert_eq!(layers.len(), own_layers.len(), "{name} at {deg}°");
            for (l, (a, b)) in layers.iter().zip(&own_layers).enumerate() {
                assert_eq!(bits(a), bits(b), "{name} at {deg}°, layer {l}");
            }
            assert!(layers.len() as u64 <= report.layers, "{name}");
        }
    }
    assert!(files.len() >= 40, "{} files", files.len());
    let with_arcs = (files.iter())
        .filter(|(n, b)| n.ends_with("On") && b.windows(3).any(|w| w == b"\nG2" || w == b"\nG3"))
        .count();
    assert!(with_arcs >= 3, "{with_arcs} rewrites with arcs");
}
