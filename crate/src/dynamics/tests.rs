//! Tests of the `vibration` API: report fields, options, cancellation, degenerate input.

use super::*;

const SQUARE: &[u8] = b"G21\nG90\nM83\n;LAYER_CHANGE\n;Z:0.2\nG1 Z0.2 F600\n\
G1 X20 Y0 E1 F3000\nG1 X20 Y20 E1\nG1 X0 Y20 E1\nG1 X0 Y0 E1\n\
;LAYER_CHANGE\n;Z:0.4\nG1 Z0.4\nG4 P10000\nG1 X20 Y0 E1\nG1 X20 Y20 E1\n";

#[test]
fn report_fields_are_consistent() {
    let r = vibration(SQUARE, &VibrationOptions::default()).unwrap();
    assert_eq!(r.layers.len(), 2);
    assert_eq!(r.layers[1].z, Some(0.4));
    let d = r.deviation_mm;
    assert!(d.min <= d.mean && d.mean <= d.max && d.max > 0.0);
    assert!(r.layers.iter().all(|l| l.amplitude <= d.max + 1e-15));
    let p = r.printing_deviation_mm;
    assert!(p.samples > 0 && p.samples < d.samples && p.max <= d.max);
    assert_eq!(r.psd.fs_hz, 200.0);
    assert_eq!(r.natural_frequencies_hz.len(), 12);
    // Most of the 10 s dwell is skipped once the machine is still.
    assert!(
        r.simulated_s < r.deviation_mm.samples as f64 * 1e-3 + 5.0,
        "{}",
        r.simulated_s
    );
    let json = serde_json::to_value(&r).unwrap();
    for key in [
        "natural_frequencies_hz",
        "damping_ratios",
        "deviation_mm",
        "layers",
        "psd",
    ] {
        assert!(json.get(key).is_some(), "{key}");
    }
    for key in ["max", "min", "mean"] {
        assert!(json["deviation_mm"].get(key).is_some());
    }
    for key in ["fs_hz", "window", "freqs", "power", "peaks"] {
        assert!(json["psd"].get(key).is_some());
    }
    assert!(json["layers"][0].get("amplitude").is_some());
    // A file against itself changes by nothing.
    let c = compare(&r, &r);
    assert_eq!(c.mean_deviation, 0.0);
    assert!(c.layers.iter().all(|l| l.relative == 0.0));
}

#[test]
fn bad_options_are_refused() {
    let bad = [
        VibrationOptions {
            ts_ms: 0.0,
            ..Default::default()
        },
        VibrationOptions {
            ts_ms: f64::NAN,
            ..Default::default()
        },
        VibrationOptions {
            fs_hz: 2000.0,
            ..Default::default()
        },
        VibrationOptions {
            fs_hz: -1.0,
            ..Default::default()
        },
        VibrationOptions {
            window: 1,
            ..Default::default()
        },
        VibrationOptions {
            bucket_mm: 0.0,
            ..Default::default()
        },
        VibrationOptions {
            dynamics: Some("nope".into()),
            ..Default::default()
        },
    ];
    for o in bad {
        let e = vibration(SQUARE, &o).unwrap_err();
        assert!(
            matches!(e.kind, ErrorKind::InvalidOption { .. }),
            "{o:?}: {e}"
        );
    }
    let json = r#"{"ts_ms": 2, "analyze": {"machine": "vtg-ldam-servo"}, "window_kind": "hann"}"#;
    let o: VibrationOptions = serde_json::from_str(json).unwrap();
    assert_eq!(vibration(SQUARE, &o).unwrap().dynamics, "ldam-ball-screw");
    assert!(serde_json::from_str::<VibrationOptions>(r#"{"nope": 1}"#).is_err());
}

#[test]
fn cancel_and_degenerate_inputs() {
    let e = vibration_with_progress(SQUARE, &Default::default(), &mut |_| false).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Cancelled);
    // No motion at all: an empty but valid report.
    let r = vibration(b"M104 S200\n; nothing\n", &Default::default()).unwrap();
    assert_eq!(r.deviation_mm.samples, 0);
    assert!(r.psd.power.is_empty());
    // A path without timing is refused, not mis-simulated.
    let p = crate::path::extract(SQUARE, &Default::default(), false).unwrap();
    let e = vibration_of_path(&p, &Default::default(), &mut |_| true).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::InvalidOption { .. }));
    // A day-long dwell costs nothing once the machine is still.
    let dwell = b"G21\nG90\nM83\nG1 X10 Y0 E1 F3000\nG4 S86400\nG1 X0 Y0 E1\n";
    let r = vibration(dwell, &Default::default()).unwrap();
    assert!(r.simulated_s < 100.0, "{}", r.simulated_s);
    // Absurdly slow motion is bounded, not simulated for days.
    let slow = b"G21\nG90\nM83\nG1 X1000 Y0 E1 F0.001\n";
    let e = vibration(slow, &Default::default()).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::InvalidOption { .. }));
}

#[cfg(not(target_arch = "wasm32"))]
mod properties {
    use super::super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Any short sequence of moves, arcs and dwells gives a finite, ordered report.
        #[test]
        fn random_moves_give_finite_ordered_reports(
            moves in proptest::collection::vec(
                (0u8..4, -200.0f64..200.0, -200.0f64..200.0, 1200.0f64..20_000.0),
                1..12,
            )
        ) {
            let mut g = String::from("G21\nG90\nM83\n;LAYER_CHANGE\n");
            for (kind, x, y, f) in moves {
                let line = match kind {
                    0 => format!("G1 X{x:.3} Y{y:.3} E0.1 F{f:.1}\n"),
                    1 => format!("G0 X{x:.3} Y{y:.3} F{f:.1}\n"),
                    2 => format!("G2 X{x:.3} Y{y:.3} R{:.3} E0.1 F{f:.1}\n", x.abs() + y.abs() + 1.0),
                    _ => "G4 P50\n".to_string(),
                };
                g.push_str(&line);
            }
            let options = VibrationOptions { ts_ms: 5.0, ..Default::default() };
            if let Ok(r) = vibration(g.as_bytes(), &options) {
                let d = r.deviation_mm;
                prop_assert!(d.max.is_finite() && d.mean.is_finite() && d.min.is_finite());
                prop_assert!(d.min <= d.mean + 1e-12 && d.mean <= d.max + 1e-12);
                prop_assert!(r.psd.power.iter().all(|p| p.is_finite() && *p >= 0.0));
            }
        }
    }
}

#[test]
fn layers_sampled_ring_as_in_the_whole_run_when_the_machine_settles_between() {
    let options = VibrationOptions::default();
    let whole = vibration(SQUARE, &options).unwrap();
    let all = printing_deviation_in_layers(SQUARE, &options, &[true, true]).unwrap();
    let p = whole.printing_deviation_mm;
    assert_eq!((all.max, all.min, all.samples), (p.max, p.min, p.samples));
    assert_eq!(all.max_at, p.max_at);
    assert!((all.mean - p.mean).abs() <= 1e-12 * p.mean, "{all:?} {p:?}");
    // The second layer starts after a 10 s dwell: from rest in the whole run too.
    let second = printing_deviation_in_layers(SQUARE, &options, &[false, true]).unwrap();
    assert_eq!(second.max, whole.layers[1].printing_amplitude);
    assert!(second.samples > 0 && second.samples < all.samples);
    let none = printing_deviation_in_layers(SQUARE, &options, &[]).unwrap();
    assert_eq!(none.samples, 0);
}

#[test]
fn the_deviation_alone_is_the_reports_to_the_bit() {
    // Without acceleration samples the run is the same: every deviation figure, whole and per
    // layer, as `vibration` reports it (the square with its dwell, and the bundled demo).
    let demo = include_bytes!("../../../www/demo/demo.gcode");
    for input in [SQUARE, &demo[..]] {
        let options = VibrationOptions::default();
        let r = vibration(input, &options).unwrap();
        let (deviation, layers) = printing_deviation(input, &options, None).unwrap();
        assert_eq!(deviation, r.printing_deviation_mm);
        assert_eq!(layers.len(), r.layers.len());
        for (a, b) in layers.iter().zip(&r.layers) {
            assert_eq!(
                (
                    a.layer,
                    a.printing_amplitude,
                    a.printing_mean,
                    a.printing_samples
                ),
                (
                    b.layer,
                    b.printing_amplitude,
                    b.printing_mean,
                    b.printing_samples
                )
            );
            assert_eq!((a.amplitude, a.mean), (b.amplitude, b.mean));
        }
        assert!(r.layers.iter().any(|l| l.acceleration_rms > 0.0));
    }
}

/// [`SQUARE`] with its first side entered at speed, from a travel of `lead_mm` along it that
/// starts after a dwell of `dwell_ms`.
fn square_after_lead_in(lead_mm: f64, dwell_ms: f64) -> String {
    let square = std::str::from_utf8(SQUARE).unwrap();
    let (_, sides) = square.split_once("G1 Z0.2 F600\n").unwrap();
    format!(
        "G21\nG90\nM83\n;LAYER_CHANGE\n;Z:0.2\nG1 Z0.2 F600\nG1 X{} Y0 F3000\nG4 P{dwell_ms}\n\
         G1 X0 Y0\n{sides}",
        -lead_mm
    )
}

/// The printing peak, mean and each layer's printing peak of `input` at period `ts_ms`.
fn printing_figures(input: &str, ts_ms: f64) -> Vec<f64> {
    let options = VibrationOptions {
        ts_ms,
        ..Default::default()
    };
    let r = vibration(input.as_bytes(), &options).unwrap();
    let d = r.printing_deviation_mm;
    let layers = r.layers.iter().map(|l| l.printing_amplitude);
    [d.max, d.mean].into_iter().chain(layers).collect()
}

#[test]
fn the_deviation_does_not_depend_on_where_the_steps_fall() {
    // The square entered at speed from a lead-in a little longer each time (0.1 ms of travel
    // at 50 mm/s): the same corners, which the 1 ms steps meet at other instants. The corners
    // (jumps of the commanded velocity) are placed where they happen and the peaks read
    // between samples, so every figure stays within a small fraction of a 0.05 ms run's (the
    // integration and the sampling both converged). Spreading each jump over its period and
    // reading peaks on the samples moved the peak by 3 %, a layer's by 8 % and the mean by
    // 1.5 %.
    let fine = printing_figures(&square_after_lead_in(20.0, 500.0), 0.05);
    assert_eq!(fine.len(), 4);
    let runs: Vec<Vec<f64>> = (0..10)
        .map(|k| printing_figures(&square_after_lead_in(20.0 + 0.005 * k as f64, 500.0), 1.0))
        .collect();
    let names = ["peak", "mean", "first layer's peak", "second layer's peak"];
    for (i, within) in [0.01, 0.003, 0.01, 0.01].into_iter().enumerate() {
        let of = runs.iter().map(|r| r[i]);
        let (lo, hi) = of.fold((f64::MAX, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
        let what = names[i];
        assert!(
            hi / lo - 1.0 < within,
            "{what}: {lo} to {hi} over the shifts"
        );
        // Both ends near the converged figure.
        let f = fine[i];
        assert!(
            lo > f * 0.985 && hi < f * 1.005,
            "{what}: {lo} to {hi}, {f} at 0.05 ms"
        );
    }
}

#[test]
fn motion_after_a_rest_is_sampled_alike_wherever_the_rest_ends() {
    // The same square after dwells a fraction of a step apart, long enough for the machine to
    // come to rest: each stretch of motion sets off on a whole step, so the samples fall at
    // the same instants of it and every figure is the same to the bit (a layer kept as it was
    // in a rewrite rings as the original's did). On the planner's clock the first layer's
    // peak moved by 0.17 %.
    let runs: Vec<Vec<f64>> = (0..10)
        .map(|k| printing_figures(&square_after_lead_in(20.0, 10000.025 + 0.1 * k as f64), 1.0))
        .collect();
    assert_eq!(runs[0].len(), 4);
    for r in &runs[1..] {
        assert_eq!(r, &runs[0]);
    }
}
