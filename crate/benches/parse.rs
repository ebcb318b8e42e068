//! Parse and analyze throughput on real slicer output.
//!
//! `cargo bench -p quietpath --bench parse` (about a minute). Inputs come from the shared corpus
//! (`../../shared/corpus` from this crate, or `$QUIETPATH_CORPUS`); a missing file is skipped
//! with a message, so the benchmark also runs on a checkout without the corpus.
//!
//! - `parse`: `gcode::for_each_line` over every line, lenient, counting parsed lines.
//! - `analyze`: the full `quietpath::analyze` report with default options.
//!
//! Throughput is reported in bytes of G-code per second.

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use std::hint::black_box;
    use std::path::PathBuf;
    use std::time::Duration;

    use criterion::{criterion_group, BenchmarkId, Criterion, SamplingMode, Throughput};
    use quietpath::analyze::{analyze, AnalyzeOptions};
    use quietpath::error::Warnings;
    use quietpath::gcode::{for_each_line, Strictness};

    /// Files benchmarked: a typical PrusaSlicer benchy (2 MB) and the 34 MB CuraEngine part.
    const FILES: [&str; 2] = [
        "prusaslicer-2.6.1_benchy_marlin2.gcode",
        "curaengine-4.13.0_extruder-idler-x2.5_large.gcode",
    ];

    fn corpus_dir() -> PathBuf {
        std::env::var_os("QUIETPATH_CORPUS")
            .map(PathBuf::from)
            .unwrap_or_else(|| {
                PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus")
            })
    }

    /// The benchmark inputs that exist, with short names for the report.
    fn inputs() -> Vec<(String, Vec<u8>)> {
        let dir = corpus_dir();
        FILES
            .iter()
            .filter_map(|name| {
                let path = dir.join(name);
                match std::fs::read(&path) {
                    Ok(data) => {
                        let short = name.split('_').next().unwrap_or(name).to_string();
                        let short = if name.contains("_large") {
                            format!("{short}-large")
                        } else {
                            short
                        };
                        Some((short, data))
                    }
                    Err(e) => {
                        eprintln!("bench parse: skipping {} ({e})", path.display());
                        None
                    }
                }
            })
            .collect()
    }

    /// Parses every line leniently; returns the number of lines that parsed.
    fn parse_all(input: &[u8]) -> u64 {
        let mut warnings = Warnings::default();
        let mut parsed = 0u64;
        let result = for_each_line(input, Strictness::Lenient, &mut warnings, |_, line, _| {
            parsed += u64::from(line.is_some());
            Ok(())
        });
        assert!(result.is_ok(), "lenient parsing failed: {result:?}");
        parsed
    }

    fn configure(
        group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
        bytes: usize,
    ) {
        group.throughput(Throughput::Bytes(bytes as u64));
        group.sample_size(10);
        // Large inputs take long per iteration: the same (small) count in every sample.
        group.sampling_mode(SamplingMode::Flat);
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(if bytes > 8 << 20 { 6 } else { 2 }));
    }

    pub fn benches(c: &mut Criterion) {
        let options = AnalyzeOptions::default();
        for (name, data) in inputs() {
            let mut group = c.benchmark_group("parse");
            configure(&mut group, data.len());
            group.bench_with_input(BenchmarkId::from_parameter(&name), &data, |b, data| {
                b.iter(|| parse_all(black_box(data)))
            });
            group.finish();

            let mut group = c.benchmark_group("analyze");
            configure(&mut group, data.len());
            group.bench_with_input(BenchmarkId::from_parameter(&name), &data, |b, data| {
                b.iter(|| analyze(black_box(data), &options).map(|r| r.moves))
            });
            group.finish();
        }
    }

    criterion_group!(parse_benches, benches);
}

#[cfg(not(target_arch = "wasm32"))]
criterion::criterion_main!(native::parse_benches);

#[cfg(target_arch = "wasm32")]
fn main() {}
