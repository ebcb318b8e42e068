//! `quietpath bench`: throughput of the parser and of `analyze` on one file, single thread.

use std::io::{self, Write};
use std::path::Path;
use std::time::Instant;

use quietpath::error::Warnings;
use quietpath::gcode::{self, Strictness};

/// Measured figures (best of the runs).
#[derive(Debug, serde::Serialize)]
pub struct Figures {
    /// Input size, bytes.
    pub bytes: u64,
    /// Lines in the file.
    pub lines: u64,
    /// Best parse time, s.
    pub parse_s: f64,
    /// Parse throughput, MB/s (10^6 bytes).
    pub parse_mb_s: f64,
    /// Best analyze time, s.
    pub analyze_s: f64,
    /// Analyze throughput, MB/s.
    pub analyze_mb_s: f64,
}

/// Parses (every line, every word) and analyzes `input` `runs` times each.
pub fn run(input: &[u8], runs: u32) -> Result<Figures, quietpath::Error> {
    let mut best_parse = f64::INFINITY;
    let mut lines = 0u64;
    for _ in 0..runs {
        let start = Instant::now();
        let mut n = 0u64;
        let mut words = 0u64;
        let mut warnings = Warnings::default();
        gcode::for_each_line(input, Strictness::Lenient, &mut warnings, |_, line, _| {
            n += 1;
            if let Some(l) = line {
                words += u64::from(!l.params.is_empty());
            }
            Ok(())
        })?;
        std::hint::black_box(words);
        best_parse = best_parse.min(start.elapsed().as_secs_f64());
        lines = n;
    }
    let mut best_analyze = f64::INFINITY;
    for _ in 0..runs {
        let start = Instant::now();
        std::hint::black_box(quietpath::analyze(input, &Default::default())?);
        best_analyze = best_analyze.min(start.elapsed().as_secs_f64());
    }
    let mb = input.len() as f64 / 1e6;
    Ok(Figures {
        bytes: input.len() as u64,
        lines,
        parse_s: best_parse,
        parse_mb_s: mb / best_parse,
        analyze_s: best_analyze,
        analyze_mb_s: mb / best_analyze,
    })
}

/// Prints the figures as text.
pub fn print(out: &mut impl Write, path: &Path, f: &Figures) -> io::Result<()> {
    writeln!(
        out,
        "{} ({:.1} MB, {} lines)",
        path.display(),
        f.bytes as f64 / 1e6,
        f.lines
    )?;
    writeln!(
        out,
        "  parse    {:8.1} ms  {:8.0} MB/s",
        f.parse_s * 1e3,
        f.parse_mb_s
    )?;
    writeln!(
        out,
        "  analyze  {:8.1} ms  {:8.0} MB/s",
        f.analyze_s * 1e3,
        f.analyze_mb_s
    )
}
