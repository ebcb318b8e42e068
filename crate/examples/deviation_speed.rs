//! Times the dynamics model's deviation-only runs on a file (best of N runs): whole, in two
//! halves side by side, and on every eighth layer, as `vtg`'s closed loop runs them, e.g.
//! `cargo run --release --example deviation_speed -- ../shared/corpus/slic3r-pe-1.33.3_benchy_arcwelder.gcode`.

use std::time::Instant;

mod common;

use quietpath::dynamics::{printing_deviation, printing_deviation_in_layers, VibrationOptions};

fn main() {
    let Some((path, input, runs)) = common::file_and_runs("deviation_speed", 3) else {
        return;
    };
    let options = VibrationOptions::default();
    let planned_s = match quietpath::analyze(&input, &options.analyze) {
        Ok(report) => report.time_s,
        Err(e) => {
            eprintln!("{path}: {e}");
            return;
        }
    };
    let layers = match printing_deviation(&input, &options, None) {
        Ok((_, layers)) => layers.len(),
        Err(e) => {
            eprintln!("{path}: {e}");
            return;
        }
    };
    let sample: Vec<bool> = (0..layers).map(|l| l % 8 == 4).collect();
    let best = |f: &dyn Fn() -> Option<f64>| {
        let mut best = f64::INFINITY;
        let mut mean = None;
        for _ in 0..runs.max(1) {
            let t = Instant::now();
            mean = f();
            best = best.min(t.elapsed().as_secs_f64());
        }
        (best, mean)
    };
    let whole = best(&|| {
        printing_deviation(&input, &options, None)
            .ok()
            .map(|d| d.0.mean)
    });
    let halves = best(&|| {
        let d = printing_deviation(&input, &options, Some(planned_s)).ok();
        d.map(|d| d.0.mean)
    });
    let sampled = best(&|| {
        let d = printing_deviation_in_layers(&input, &options, &sample).ok();
        d.map(|d| d.mean)
    });
    for (name, (s, mean)) in [("whole", whole), ("halves", halves), ("sample", sampled)] {
        println!("{name:>7}: {s:.3} s (mean deviation {mean:?} mm)");
    }
}
