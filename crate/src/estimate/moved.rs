//! The analysis of a file whose estimates were refreshed, read off the analysis of the file
//! before the refresh.
//!
//! [`super::rewrite_by_clock`] changes only comments and `M73` lines and adds a header, so the
//! refreshed file plans, prints and spends energy exactly as the file it came from: what moves
//! is where each line is. Analysing it again cost a whole pass over the file at the end of
//! every rewriting job (on the 34 MB corpus file's VTG output, 0.3 s of a 5 s run, on the run's
//! critical path). [`analysis_of_refreshed`] instead moves the line numbers of the earlier
//! analysis by the edits, and reads the refreshed header and tail again ([`prescan`]) for the
//! slicer's time estimate, the one figure the refresh changes. A conformance test compares it
//! with a fresh analysis on every corpus file and fixture.

use crate::analyze::Report;
use crate::gcode::Edit;
use crate::read::prescan::{prescan, Prescan};

/// Where the lines of a file went when [`super::rewrite_by_clock`] edited it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinesMoved {
    /// Every edited line, in file order.
    edits: Vec<Moved>,
    /// Lines added in all (negative: removed).
    added: i64,
}

/// One edited line: its number, the lines it became (0: removed), where its own text went
/// among them (`None`: replaced), and the lines added by the edits before it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Moved {
    line: u32,
    became: u32,
    own: Option<u32>,
    added_before: i64,
}

impl LinesMoved {
    /// The moves of `edits` (sorted by line), the edit of line `kept.0` keeping that line's own
    /// text as its line `kept.1` (the header written beside the first line); every other
    /// edited line is replaced or removed.
    pub(super) fn of(edits: &[Edit], kept: Option<(u32, u32)>) -> Self {
        let mut added = 0i64;
        let edits = edits
            .iter()
            .map(|e| {
                let became = if e.replacement.is_empty() {
                    0
                } else {
                    1 + e.replacement.iter().filter(|&&b| b == b'\n').count() as u32
                };
                let own = kept.filter(|k| k.0 == e.line).map(|k| k.1);
                let moved = Moved {
                    line: e.line,
                    became,
                    own,
                    added_before: added,
                };
                added += i64::from(became) - 1;
                moved
            })
            .collect();
        Self { edits, added }
    }

    /// The number line `line` has after the edits; `None` where the line was replaced or
    /// removed (what the analysis said of it may no longer hold).
    pub fn line(&self, line: u32) -> Option<u32> {
        let i = self.edits.partition_point(|m| m.line < line);
        let (before, own) = match self.edits.get(i) {
            Some(m) if m.line == line => (m.added_before, Some(m.own?)),
            Some(m) => (m.added_before, None),
            None => (self.added, None),
        };
        let moved = i64::from(line) + before + i64::from(own.unwrap_or(0));
        u32::try_from(moved).ok()
    }
}

/// The analysis of `refreshed`, the file `output` (analysed as `analysis`) with its estimates
/// refreshed by the edits `moved`: `analysis` with its lines moved, the file's size and line
/// count, and the slicer's time estimate as the refreshed file states it. `None` where that
/// would not be the analysis a fresh pass gives (then the caller analyses the file):
/// `analysis` is not of `output`, the refresh changed what the head and tail say of the
/// machine, or something the analysis reports stands on a line the refresh replaced.
pub fn analysis_of_refreshed(
    analysis: &Report,
    output: &[u8],
    refreshed: &[u8],
    moved: &LinesMoved,
) -> Option<Report> {
    if analysis.file.bytes != output.len() as u64 {
        return None;
    }
    let after = prescan(refreshed);
    let same_machine = |p: Prescan| Prescan {
        slicer_time_s: after.slicer_time_s,
        ..p
    };
    if same_machine(prescan(output)) != after {
        return None;
    }
    let mut report = analysis.clone();
    let map = |line: &mut u32| -> Option<()> {
        *line = moved.line(*line)?;
        Some(())
    };
    for l in &mut report.layer_list {
        map(&mut l.line)?;
    }
    for t in &mut report.temperatures {
        map(&mut t.line)?;
    }
    for f in &mut report.fans {
        map(&mut f.line)?;
    }
    for w in &mut report.warnings {
        map(&mut w.line)?;
    }
    report.file.bytes = refreshed.len() as u64;
    report.file.lines = u64::try_from(report.file.lines as i64 + moved.added).ok()?;
    report.file.slicer_time_s = after.slicer_time_s;
    Some(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edit(line: u32, text: &str) -> Edit {
        Edit {
            line,
            replacement: text.as_bytes().to_vec(),
        }
    }

    #[test]
    fn lines_move_by_the_lines_added_and_removed_before_them() {
        // Line 1 keeps its text first and gains two header lines; line 4 is removed; line 6
        // is replaced by one line.
        let edits = [
            edit(1, ";first\n; h1\n; h2"),
            edit(4, ""),
            edit(6, "M73 P50"),
        ];
        let moved = LinesMoved::of(&edits, Some((1, 0)));
        let got: Vec<Option<u32>> = (0..=8).map(|l| moved.line(l)).collect();
        let want = [
            Some(0),
            Some(1),
            Some(4),
            Some(5),
            None,
            Some(6),
            None,
            Some(8),
            Some(9),
        ];
        assert_eq!(got, want);
        assert_eq!(moved.added, 1);
    }

    #[test]
    fn a_header_written_before_the_first_line_moves_it_down() {
        let edits = [edit(1, "; h1\n; h2\nG28")];
        let moved = LinesMoved::of(&edits, Some((1, 2)));
        assert_eq!(moved.line(1), Some(3));
        assert_eq!(moved.line(2), Some(4));
        // A first line that was itself replaced has no place to go.
        let replaced = LinesMoved::of(&edits, None);
        assert_eq!(replaced.line(1), None);
    }

    #[test]
    fn a_file_that_starts_with_a_command_gets_the_header_above_it_and_its_lines_move() {
        use crate::analyze::{analyze, analyze_with_starts, AnalyzeOptions};
        use crate::estimate::{rewrite_by_clock, Clock};
        let file = b"G28\nM104 S200\nM73 P0 R17\nG1 X100 F6000\n;TIME_ELAPSED:1.0\nM106 S255\nG1 X0\nM73 P100 R0\n";
        let options = AnalyzeOptions::default();
        let (report, starts) = analyze_with_starts(file, &options).unwrap();
        let e = rewrite_by_clock(
            file,
            &Clock::from_analysis(&report, starts),
            &["job".into()],
        );
        assert!(e.output.starts_with(b"; quietpath job\n"));
        let moved = analysis_of_refreshed(&report, file, &e.output, &e.moved).unwrap();
        assert_eq!(moved, analyze(&e.output, &options).unwrap());
        assert_eq!(moved.temperatures[0].line, 4);
        // Not the analysis of the file it is said to be: no analysis is read off it.
        assert!(analysis_of_refreshed(&report, &e.output, &e.output, &e.moved).is_none());
    }
}
