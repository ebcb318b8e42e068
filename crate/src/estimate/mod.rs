//! True time estimates in a file: the slicer's time comments and `M73` progress lines
//! rewritten from our planner's clock, as klipper_estimator's `post-process` does with its own.
//!
//! Printers show the time and progress a file carries. After a rewrite (VTG, infill, smoothing)
//! those still hold the slicer's numbers for the old toolpath; [`rewrite_estimates`] puts in
//! the time the planner gives the file it is handed, at the same places: `M73 P R` / `Q S`,
//! PrusaSlicer's (and its forks') `; estimated printing time` lines, Cura's `;TIME:` and
//! `;TIME_ELAPSED:`, Simplify3D's build time, ideaMaker's and Kiri:Moto's. Every other line is
//! copied byte for byte, so the planner's time of the output is that of the input: the
//! estimates are true of the file they are written into.

mod clock;
mod format;
mod moved;

use serde::Serialize;

use crate::analyze::AnalyzeOptions;
use crate::error::Error;
use crate::gcode::{apply_edits, Edit, Lines, RawLine};
pub use clock::Clock;
use format::{At, Kind};
pub use moved::{analysis_of_refreshed, LinesMoved};

/// Comment lines quietpath writes start with this (and are replaced, not repeated, when a
/// file goes through again).
pub const HEADER_PREFIX: &str = "; quietpath ";

/// What [`rewrite_estimates`] changed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct EstimateReport {
    /// Print time by our planner, s (`analyze`'s `time_s` of the file).
    pub time_s: f64,
    /// `M73` progress lines rewritten.
    pub progress_lines: usize,
    /// Time comments rewritten.
    pub time_comments: usize,
    /// Header comment lines written (earlier quietpath headers are replaced).
    pub header_lines: usize,
}

/// A file with true estimates.
#[derive(Debug, Clone)]
pub struct Estimated {
    /// What changed.
    pub report: EstimateReport,
    /// The file.
    pub output: Vec<u8>,
    /// Where the input's lines went in it.
    pub moved: LinesMoved,
}

/// `input` with its time comments and `M73` lines rewritten from the planner's clock, and a
/// header after its first comment line: `notes` (comment text, one entry per line), then the
/// print time and the machine it was timed as.
pub fn rewrite_estimates(
    input: &[u8],
    options: &AnalyzeOptions,
    notes: &[String],
) -> Result<Estimated, Error> {
    Ok(rewrite_by_clock(input, &Clock::of(input, options)?, notes))
}

/// [`rewrite_estimates`] by `clock`, the clock of `input` ([`Clock::of`], or
/// [`Clock::from_analysis`] of its analysis).
pub fn rewrite_by_clock(input: &[u8], clock: &Clock, notes: &[String]) -> Estimated {
    let mut header = notes.to_vec();
    header.push(format!(
        "{}: print time {} by its planner ({}); M73 and time comments are its",
        crate::VERSION,
        format::dhms(clock.total_s),
        clock.machine
    ));
    let mut report = EstimateReport {
        time_s: clock.total_s,
        progress_lines: 0,
        time_comments: 0,
        header_lines: notes.len() + 1,
    };
    let mut edits = Vec::new();
    let mut first: Option<RawLine<'_>> = None;
    for line in Lines::new(input) {
        if first.is_none() {
            first = Some(line);
        }
        if line.text.starts_with(HEADER_PREFIX.as_bytes()) {
            edits.push(Edit {
                line: line.number,
                replacement: Vec::new(),
            });
            continue;
        }
        if !matches!(line.text.first(), Some(b'M' | b';')) {
            continue;
        }
        let at = At {
            elapsed_s: clock.at_line(line.number),
            total_s: clock.total_s,
            first_layer_s: clock.first_layer_s,
        };
        if let Some((kind, text)) = format::rewrite(line.text, &at) {
            match kind {
                Kind::Progress => report.progress_lines += 1,
                Kind::Comment => report.time_comments += 1,
            }
            edits.push(Edit {
                line: line.number,
                replacement: text.into_bytes(),
            });
        }
    }
    let kept = first.and_then(|first| add_header(&mut edits, &first, &header));
    Estimated {
        report,
        output: apply_edits(input, &edits),
        moved: LinesMoved::of(&edits, kept),
    }
}

/// Whether `input` carries any estimate (`M73` or a time comment) to make true.
pub fn has_estimates(input: &[u8]) -> bool {
    let at = At {
        elapsed_s: 0.0,
        total_s: 1.0,
        first_layer_s: Some(0.0),
    };
    Lines::new(input)
        .filter(|l| matches!(l.text.first(), Some(b'M' | b';')))
        .any(|l| format::rewrite(l.text, &at).is_some())
}

/// [`rewrite_estimates`], and `analyze` of the file it writes: what a job hands back (the
/// header shifts the lines, so the report is of the written file, not the one before).
/// `analysis`: `input`'s analysis with `options`, where the caller has it: the written file's
/// is read off it ([`analysis_of_refreshed`]) instead of a pass of its own.
pub fn rewrite_and_analyze(
    input: &[u8],
    options: &AnalyzeOptions,
    notes: &[String],
    analysis: Option<&crate::analyze::Report>,
) -> Result<(Estimated, crate::analyze::Report), Error> {
    let e = rewrite_estimates(input, options, notes)?;
    let after = analysis_after(&e, input, options, analysis)?;
    Ok((e, after))
}

/// The analysis of `e.output`, the file `input` (analysed as `analysis`, where given) with
/// its estimates refreshed: read off `analysis` where it can be, else a pass of its own.
fn analysis_after(
    e: &Estimated,
    input: &[u8],
    options: &AnalyzeOptions,
    analysis: Option<&crate::analyze::Report>,
) -> Result<crate::analyze::Report, Error> {
    match analysis.and_then(|a| analysis_of_refreshed(a, input, &e.output, &e.moved)) {
        Some(after) => Ok(after),
        None => crate::analyze::analyze(&e.output, options),
    }
}

/// What a rewriting job hands back: its output with true estimates and a header naming `job`,
/// and the output's analysis (read off `analysis`, `output`'s own with `options`, where given:
/// [`rewrite_and_analyze`]); `None` when the file carries no estimate to correct (nothing is
/// added then).
pub fn refresh(
    output: &[u8],
    options: &AnalyzeOptions,
    job: &str,
    analysis: Option<&crate::analyze::Report>,
) -> Result<Option<Refreshed>, Error> {
    if !has_estimates(output) {
        return Ok(None);
    }
    let (e, after) = rewrite_and_analyze(output, options, &[job.to_string()], analysis)?;
    Ok(Some((e.output, after)))
}

/// A file with its estimates refreshed, and its analysis.
pub type Refreshed = (Vec<u8>, crate::analyze::Report);

/// [`refresh`], and `beside` measured of the file it hands back (the refreshed one, else
/// `output`), side by side with the refreshed file's analysis where there are threads.
/// `clock`: the clock of `output`, where its analysis kept one (else it is planned here);
/// `analysis`: that analysis, where the caller has it, which the refreshed file's is read off
/// with its lines moved ([`analysis_of_refreshed`]) instead of a pass of its own.
pub fn refresh_beside<T>(
    output: &[u8],
    options: &AnalyzeOptions,
    (job, clock, analysis): (&str, Option<&Clock>, Option<&crate::analyze::Report>),
    beside: impl Fn(&[u8]) -> T,
) -> Result<(Option<Refreshed>, T), Error> {
    if !has_estimates(output) {
        return Ok((None, beside(output)));
    }
    let notes = [job.to_string()];
    let e = match clock {
        Some(clock) => rewrite_by_clock(output, clock, &notes),
        None => rewrite_estimates(output, options, &notes)?,
    };
    let moved = analysis.and_then(|a| analysis_of_refreshed(a, output, &e.output, &e.moved));
    let (after, measured) = match moved {
        Some(after) => (after, beside(&e.output)),
        // The pass [`analysis_after`] would make, beside `beside`.
        None => {
            let (after, measured) = crate::parallel::join(
                || crate::analyze::analyze(&e.output, options),
                || beside(&e.output),
            );
            (after?, measured)
        }
    };
    Ok((Some((e.output, after)), measured))
}

/// Puts the header after the first line when it is a comment (slicers and hosts recognise a
/// file by its first line: `; generated by PrusaSlicer`, `;FLAVOR:Marlin`), else before it.
/// Where the first line's own text goes unchanged: its line number, and its place among the
/// lines of the edit (`None`: the first line was itself replaced or removed).
fn add_header(edits: &mut Vec<Edit>, first: &RawLine<'_>, header: &[String]) -> Option<(u32, u32)> {
    let block = header
        .iter()
        .map(|h| format!("{HEADER_PREFIX}{h}"))
        .collect::<Vec<_>>()
        .join("\n");
    let existing = edits.iter().position(|e| e.line == first.number);
    let own: Vec<u8> = match existing {
        Some(i) => edits[i].replacement.clone(),
        None => first.text.to_vec(),
    };
    let unchanged = existing.is_none().then_some(first.number);
    let (replacement, place) = if own.is_empty() {
        (block.into_bytes(), None)
    } else if first.text.first() == Some(&b';') {
        ([own, b"\n".to_vec(), block.into_bytes()].concat(), Some(0))
    } else {
        let lines = 1 + block.bytes().filter(|&b| b == b'\n').count() as u32;
        (
            [block.into_bytes(), b"\n".to_vec(), own].concat(),
            Some(lines),
        )
    };
    let edit = Edit {
        line: first.number,
        replacement,
    };
    match existing {
        Some(i) => edits[i] = edit,
        None => edits.insert(0, edit),
    }
    unchanged.zip(place)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "; generated by test\n;TIME:999\nM73 P0 R17\nG28\nG1 X100 F6000\n;TIME_ELAPSED:1.0\nG1 X0\nM73 P50 R1\nG1 Y50\nM73 P100 R0\n";

    fn run(input: &[u8]) -> Estimated {
        let header = vec!["estimates by test".to_string()];
        rewrite_estimates(input, &AnalyzeOptions::default(), &header).unwrap()
    }

    #[test]
    fn estimates_follow_the_planner_and_the_last_m73_is_zero() {
        let e = run(FILE.as_bytes());
        let text = String::from_utf8(e.output.clone()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "; generated by test");
        assert_eq!(lines[1], "; quietpath estimates by test");
        assert!(lines[2].starts_with("; quietpath 0."), "{}", lines[2]);
        assert_eq!(lines[3], format!(";TIME:{}", e.report.time_s.round()));
        assert_eq!(
            lines[4],
            format!("M73 P0 R{}", (e.report.time_s / 60.0).round())
        );
        assert_eq!(lines.last().copied(), Some("M73 P100 R0"));
        assert_eq!((e.report.progress_lines, e.report.time_comments), (3, 2));
        let analyzed = crate::analyze(&e.output, &AnalyzeOptions::default()).unwrap();
        assert_eq!(analyzed.time_s, e.report.time_s);
    }

    #[test]
    fn a_second_pass_replaces_the_header() {
        let once = run(FILE.as_bytes()).output;
        let twice = run(&once).output;
        assert_eq!(once, twice);
    }
}
