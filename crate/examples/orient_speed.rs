//! Times `quietpath::orient::smooth` on a file (best of N runs), e.g.
//! `cargo run --release --example orient_speed -- ../shared/corpus/multiaxis-xyzbc_zhang-ral2021_model1.gcode`.

use std::time::Instant;

mod common;

fn main() {
    let Some((path, input, runs)) = common::file_and_runs("orient_speed", 7) else {
        return;
    };
    let options = quietpath::orient::SmoothOptions::default();
    let mut best = f64::INFINITY;
    let mut extract_best = f64::INFINITY;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let _ = quietpath::path::extract(&input, &options.analyze, true);
        extract_best = extract_best.min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        match quietpath::orient::smooth(&input, &options) {
            Ok(r) => std::hint::black_box(r.output.len()),
            Err(e) => {
                eprintln!("{path}: {e}");
                return;
            }
        };
        best = best.min(t.elapsed().as_secs_f64());
    }
    let lines = input.iter().filter(|&&b| b == b'\n').count();
    println!(
        "{path}: {lines} lines, smooth best {:.1} ms (one read+plan pass {:.1} ms; smooth reads and plans twice)",
        best * 1e3,
        extract_best * 1e3
    );
}
