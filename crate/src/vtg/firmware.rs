//! What the firmware can take: the segment budget of a machine, and how a file measures
//! against it (lines, bytes, short segments, the peak segment rate over any second of planned
//! time).
//!
//! VTG's Algorithm 1 walks a curve for a servo controller that takes a point every
//! interpolation period; a printer's firmware reads G-code lines instead, and has a budget
//! for them:
//!
//! - **Marlin** (and Prusa firmware, which keeps Marlin 1's planner) keeps
//!   `BLOCK_BUFFER_SIZE` = 16 blocks in its planner (Marlin's `Configuration_adv.h`; 32–64
//!   on some 32-bit boards) and, when fewer than half of them are queued, stretches every
//!   block shorter than `min_segment_time` (`M205 B`, in µs; `DEFAULT_MINSEGMENTTIME`
//!   20000 µs) to last that long: a file whose segments come faster than the firmware reads
//!   them slows down and stutters. Reading is bounded by the link: a host streaming over
//!   115200-baud serial (Prusa's and most boards' USB rate; 8N1 framing, 10 bits a byte)
//!   delivers 11 520 bytes/s, so at `b` bytes per line at most `11520 / b` lines/s.
//! - **Klipper** has no minimum segment time (its look-ahead plans every move as it is) and
//!   reads the file on the host; its budget is the host's G-code processing and the
//!   host-to-MCU link, which we take to be no tighter than Marlin's serial stream (an
//!   estimate, not a documented figure). The same 20 ms target keeps a rewrite from asking
//!   more of that link than the original did.
//!
//! The rewrite keeps written segments at or above `v · min_segment_time` wherever the
//! tolerance allows (`vtg/stages/thin.rs`), and the report measures both files against the budget
//! ([`FirmwareReport`]).

use serde::{Deserialize, Serialize};

use crate::path::PathFeature;
use crate::plan::segments::{SegmentCounter, SegmentCounts};
use crate::plan::JunctionModel;

/// Marlin's `DEFAULT_MINSEGMENTTIME` (`Configuration_adv.h`), s: `M205 B` sets it in µs.
pub const MARLIN_MIN_SEGMENT_TIME_S: f64 = 0.020;
/// Marlin's `BLOCK_BUFFER_SIZE` (`Configuration_adv.h`), blocks.
pub const MARLIN_BLOCK_BUFFER: u32 = 16;
/// Bytes per second a 115200-baud serial link delivers (8N1: 10 bits a byte).
pub const SERIAL_BYTES_PER_S: f64 = 11_520.0;

/// The segment budget of the machine a file runs on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct SegmentBudget {
    /// Shortest time a segment may last before the firmware slows it when its buffer runs
    /// low, s (Marlin's `M205 B`; [`MARLIN_MIN_SEGMENT_TIME_S`] by default). On Klipper,
    /// which has none, the same value is the rewrite's target.
    pub min_segment_time_s: f64,
    /// Where `min_segment_time_s` came from: `"file"` (`M205 B`), `"option"` or `"default"`.
    pub min_segment_time_source: String,
    /// Planner blocks the firmware buffers (Marlin's `BLOCK_BUFFER_SIZE`; 0 on Klipper, which
    /// plans on the host).
    pub block_buffer: u32,
    /// Bytes per second the firmware reads (a 115200-baud serial stream by default).
    pub stream_bytes_per_s: f64,
}

impl SegmentBudget {
    /// The budget of a machine with planner `model`, with the file's own `M205 B` (the last
    /// one in the file) over the default and `min_segment_time_ms` from the options over
    /// both.
    pub fn for_file(input: &[u8], model: JunctionModel, min_segment_time_ms: Option<f64>) -> Self {
        let (time, source) = min_segment_time(input, min_segment_time_ms);
        Self {
            min_segment_time_s: time,
            min_segment_time_source: source.to_string(),
            block_buffer: if model == JunctionModel::Klipper {
                0
            } else {
                MARLIN_BLOCK_BUFFER
            },
            stream_bytes_per_s: SERIAL_BYTES_PER_S,
        }
    }

    /// Segments per second the firmware can read at `bytes_per_line` bytes a line.
    pub fn segment_rate_hz(&self, bytes_per_line: f64) -> f64 {
        if bytes_per_line > 0.0 {
            self.stream_bytes_per_s / bytes_per_line
        } else {
            f64::INFINITY
        }
    }
}

/// The minimum segment time of a machine running `input`, s ([`SegmentBudget::for_file`]), and
/// where it came from.
fn min_segment_time(input: &[u8], min_segment_time_ms: Option<f64>) -> (f64, &'static str) {
    match (min_segment_time_ms, m205_b_us(input)) {
        (Some(ms), _) => (ms / 1000.0, "option"),
        (None, Some(us)) => (us / 1e6, "file"),
        (None, None) => (MARLIN_MIN_SEGMENT_TIME_S, "default"),
    }
}

/// [`SegmentBudget::min_segment_time_s`] of `input`'s budget, without its planner model.
pub fn min_segment_time_s(input: &[u8], min_segment_time_ms: Option<f64>) -> f64 {
    min_segment_time(input, min_segment_time_ms).0
}

/// The value of the last `M205 B` word (µs) in `input`, if any. Only the lines with `205` in
/// them are read word by word: a search for the digits skips the rest (a run reads the budget
/// of its input twice; splitting every line of the 34 MB corpus file into words took 0.1 s).
fn m205_b_us(input: &[u8]) -> Option<f64> {
    let mut found = None;
    let mut read_to = 0usize;
    for hit in memchr::memmem::find_iter(input, b"205") {
        if hit < read_to {
            continue;
        }
        let start = memchr::memrchr(b'\n', &input[..hit]).map_or(0, |i| i + 1);
        let end = memchr::memchr(b'\n', &input[hit..]).map_or(input.len(), |i| hit + i);
        read_to = end;
        if let Some(v) = line_m205_b_us(&input[start..end]) {
            found = Some(v);
        }
    }
    found
}

/// The last valid `B` word (µs) of `line` when its first word is `M205`.
fn line_m205_b_us(line: &[u8]) -> Option<f64> {
    let code = line.split(|&b| b == b';').next().unwrap_or(&[]);
    let mut words = code
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty());
    if !words
        .next()
        .is_some_and(|w| w.eq_ignore_ascii_case(b"M205"))
    {
        return None;
    }
    let mut found = None;
    for w in words {
        if let Some((b'B' | b'b', v)) = w.split_first() {
            let v = std::str::from_utf8(v)
                .ok()
                .and_then(|v| v.parse::<f64>().ok());
            if let Some(v) = v.filter(|v| v.is_finite() && *v >= 0.0) {
                found = Some(v);
            }
        }
    }
    found
}

/// How one file measures against the budget.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct FirmwareFigures {
    /// Lines of the file.
    pub lines: u64,
    /// Bytes of the file.
    pub bytes: u64,
    /// Moves that print (`G1` with extrusion, `G2`/`G3`).
    pub printing_segments: u64,
    /// Printing segments shorter than 0.1 mm.
    pub segments_under_0_1mm: u64,
    /// Printing segments whose planned time is under the minimum segment time.
    pub segments_under_min_time: u64,
    /// Most moves the planner runs in any 1 s of planned time.
    pub peak_segments_per_s: f64,
    /// Segments per second the firmware reads at this file's mean bytes per move line.
    pub budget_segments_per_s: f64,
}

/// Both files against the machine's budget, for the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct FirmwareReport {
    /// The budget they are measured against.
    pub budget: SegmentBudget,
    /// The original.
    pub before: FirmwareFigures,
    /// The rewrite.
    pub after: FirmwareFigures,
    /// Set when the rewrite's peak segment rate exceeds the budget where the original's did
    /// not, or exceeds it by more.
    pub warning: Option<String>,
}

impl FirmwareReport {
    /// The report of `before` and `after` against `budget`, with its warning.
    pub fn new(budget: SegmentBudget, before: FirmwareFigures, after: FirmwareFigures) -> Self {
        let over = |f: &FirmwareFigures| f.peak_segments_per_s > f.budget_segments_per_s;
        let warning = (over(&after) && after.peak_segments_per_s > before.peak_segments_per_s)
            .then(|| {
                format!(
                    "the rewrite peaks at {:.0} segments/s, over the {:.0}/s the firmware reads \
                     (the original: {:.0}/s)",
                    after.peak_segments_per_s,
                    after.budget_segments_per_s,
                    before.peak_segments_per_s
                )
            });
        Self {
            budget,
            before,
            after,
            warning,
        }
    }
}

/// Counts what [`figures`] reports while the moves stream past.
struct FiguresSink(SegmentCounter);

impl crate::path::MoveSink for FiguresSink {
    fn moved(&mut self, _: usize, m: crate::path::PathMove, _: (u32, u32), _: &[PathFeature]) {
        self.0.moved(m.is_extruding(), m.length_mm);
    }

    fn timed(&mut self, pm: &crate::plan::PlannedMove) {
        self.0.timed(pm);
    }
}

/// How `input` measures against `budget`: lines, bytes, short printing segments, and the most
/// planned blocks (every move the planner runs, an arc's segments each) that start within any
/// 1 s of planned time, read with the planner as [`crate::analyze::analyze`] plans.
pub fn figures(
    input: &[u8],
    options: &crate::analyze::AnalyzeOptions,
    budget: &SegmentBudget,
) -> Result<FirmwareFigures, crate::error::Error> {
    let mut sink = FiguresSink(SegmentCounter::new(budget.min_segment_time_s));
    crate::path::walk(input, options, true, &mut sink)?;
    Ok(FirmwareFigures::of(input, sink.0.counts(), budget))
}

/// [`crate::analyze::analyze`] of `input`, and its [`figures`] counted in the same pass
/// ([`crate::analyze::analyze_keeping`]): the same figures, without a planning walk of their own.
pub fn analysed_figures(
    input: &[u8],
    options: &crate::analyze::AnalyzeOptions,
    budget: &SegmentBudget,
) -> Result<(crate::analyze::Report, FirmwareFigures), crate::error::Error> {
    let keep = crate::analyze::Keep {
        starts: false,
        min_segment_s: Some(budget.min_segment_time_s),
        layer_metrics_deg: None,
        timed_moves: false,
    };
    let (report, kept) = crate::analyze::analyze_keeping(input, options, keep)?;
    let counts = kept.segments.unwrap_or_default();
    Ok((report, FirmwareFigures::of(input, counts, budget)))
}

impl FirmwareFigures {
    /// The figures of `input`, whose segments `counts` counted, against `budget`.
    pub fn of(input: &[u8], counts: SegmentCounts, budget: &SegmentBudget) -> Self {
        let lines = crate::gcode::file_lines(input);
        let bytes = input.len() as u64;
        Self {
            lines,
            bytes,
            printing_segments: counts.printing_segments,
            segments_under_0_1mm: counts.segments_under_0_1mm,
            segments_under_min_time: counts.segments_under_min_time,
            peak_segments_per_s: counts.peak_segments_per_s,
            budget_segments_per_s: budget.segment_rate_hz(bytes as f64 / lines.max(1) as f64),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_s_m205_b_sets_the_minimum_segment_time_and_the_option_wins() {
        let src = b"M205 X8 Y8\nM205 B30000 ; 30 ms\nG1 X1 E1\n";
        let b = SegmentBudget::for_file(src, JunctionModel::ClassicJerk, None);
        assert!((b.min_segment_time_s - 0.03).abs() < 1e-12);
        assert_eq!(b.min_segment_time_source, "file");
        assert_eq!(b.block_buffer, MARLIN_BLOCK_BUFFER);
        let d = SegmentBudget::for_file(b"G1 X1\n", JunctionModel::Klipper, None);
        assert_eq!(d.min_segment_time_s, MARLIN_MIN_SEGMENT_TIME_S);
        assert_eq!(d.block_buffer, 0);
        let o = SegmentBudget::for_file(src, JunctionModel::ClassicJerk, Some(10.0));
        assert!((o.min_segment_time_s - 0.01).abs() < 1e-12);
        assert_eq!(o.min_segment_time_source, "option");
        // A comment is not a word.
        assert_eq!(m205_b_us(b"M205 X8 ; B5\n"), None);
    }

    proptest::proptest! {
        /// The search for `205` finds what reading every line finds.
        #[test]
        fn the_search_reads_what_every_line_says(
            parts in proptest::collection::vec(
                proptest::sample::select(vec![
                    "M205", "m205", "G1", " ", "\t", "\n", "\r\n", ";", "B", "b", "X", "205",
                    "2", "0", "5", ".", "-", "E0.2051", "B20000", "B-1", "inf", "\n\n",
                ]),
                0..60,
            ),
        ) {
            let text: String = parts.concat();
            let input = text.as_bytes();
            let every_line = input
                .split(|&b| b == b'\n')
                .filter_map(line_m205_b_us)
                .next_back();
            proptest::prop_assert_eq!(m205_b_us(input), every_line, "{:?}", text);
        }
    }

    #[test]
    fn figures_count_lines_short_segments_and_the_peak_rate() {
        // 200 printing segments of 0.05 mm at 10 mm/s (5 ms each, 200 a second), then one long.
        let mut g = String::from("M83\nG1 X0 Y0 Z0.2 F600\n");
        for i in 1..=200 {
            g.push_str(&format!("G1 X{:.3} Y0 E0.002\n", 0.05 * i as f64));
        }
        g.push_str("G1 X60 Y0 E2\n");
        let o = crate::analyze::AnalyzeOptions::default();
        let b = SegmentBudget::for_file(g.as_bytes(), JunctionModel::ClassicJerk, None);
        let f = figures(g.as_bytes(), &o, &b).expect("figures");
        assert_eq!(f.lines, g.lines().count() as u64);
        assert_eq!(f.bytes, g.len() as u64);
        assert_eq!(f.printing_segments, 201);
        assert_eq!(f.segments_under_0_1mm, 200);
        assert!(
            f.segments_under_min_time >= 199,
            "{}",
            f.segments_under_min_time
        );
        // 10 mm in about a second: close to 200 blocks start within one second.
        assert!(
            f.peak_segments_per_s > 150.0 && f.peak_segments_per_s <= 203.0,
            "{}",
            f.peak_segments_per_s
        );
        let report = FirmwareReport::new(b.clone(), FirmwareFigures::default(), f.clone());
        assert_eq!(
            report.warning.is_some(),
            f.peak_segments_per_s > f.budget_segments_per_s
        );
    }
}
