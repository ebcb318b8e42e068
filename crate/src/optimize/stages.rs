//! The pipeline's stages, each kept only when it makes the file no dearer.

use super::{notes, OptimizeOptions, StageReport};
use crate::analyze::{AnalyzeOptions, Report};
use crate::error::{Error, ErrorKind};
use crate::estimate::{rewrite_and_analyze, EstimateReport};
use crate::infill::{infill_with_progress, Choice, InfillOptions};
use crate::progress::Progress;
use crate::vtg::{vtg_with_progress, VtgOptions};

/// The file so far and its analysis.
pub(super) struct Stage {
    file: Vec<u8>,
    report: Report,
}

/// Progress fractions of the optimising stages, in order (the rest is the estimates').
pub(super) fn spans(options: &OptimizeOptions) -> Vec<(f64, f64)> {
    match (options.infill.is_some(), options.vtg) {
        (true, true) => vec![(0.0, 0.5), (0.5, 0.95)],
        (true, false) | (false, true) => vec![(0.0, 0.95)],
        (false, false) => Vec::new(),
    }
}

fn pct(after: f64, before: f64) -> f64 {
    if before > 0.0 {
        100.0 * (after / before - 1.0)
    } else {
        0.0
    }
}

impl Stage {
    pub fn start(file: Vec<u8>, report: Report) -> Self {
        Self { file, report }
    }

    /// The stage report, and the candidate taken if it is no dearer in time or energy.
    fn offer(&mut self, stage: &str, file: Vec<u8>, after: Report, done: String) -> StageReport {
        let (b, a) = (&self.report, &after);
        let (dt, de) = (
            pct(a.time_s, b.time_s),
            pct(a.energy.total_j, b.energy.total_j),
        );
        let dearer = a.time_s > b.time_s || a.energy.total_j > b.energy.total_j;
        let report = StageReport {
            stage: stage.to_string(),
            applied: !dearer,
            message: if dearer {
                format!("its file would change time by {dt:+.2} % and energy by {de:+.2} %; the file before it is kept")
            } else {
                format!("{done}; time {dt:+.2} %, energy {de:+.2} %")
            },
            time_s: [b.time_s, a.time_s],
            energy_j: [b.energy.total_j, a.energy.total_j],
            lines: [b.file.lines, a.file.lines],
        };
        if !dearer {
            self.file = file;
            self.report = after;
        }
        report
    }

    /// A stage that left the file as it was, and why.
    fn unchanged(&self, stage: &str, why: String) -> StageReport {
        let r = &self.report;
        StageReport {
            stage: stage.to_string(),
            applied: false,
            message: why,
            time_s: [r.time_s; 2],
            energy_j: [r.energy.total_j; 2],
            lines: [r.file.lines; 2],
        }
    }

    /// The infill search on the file so far.
    pub fn infill(
        &mut self,
        options: &InfillOptions,
        analyze: &AnalyzeOptions,
        progress: Progress<'_>,
    ) -> Result<StageReport, Error> {
        let o = InfillOptions {
            analyze: analyze.clone(),
            estimates: false,
            ..options.clone()
        };
        let r = match infill_with_progress(&self.file, &o, progress) {
            Ok(r) => r,
            // A file without sparse infill (a vase, a solid plate) still goes through the rest
            // of the pipeline: a post-processing script runs on every file the slicer exports.
            Err(e) if matches!(e.kind, ErrorKind::NothingToRegenerate { .. }) => {
                return Ok(self.unchanged("infill", e.kind.to_string()))
            }
            Err(e) => return Err(e),
        };
        if r.best.pattern == Choice::Original {
            let why = r.best.message.unwrap_or_default();
            return Ok(self.unchanged("infill", why));
        }
        let done = format!(
            "{} at {}° (part turned {}°)",
            r.best.pattern.name(),
            r.best.angle_deg,
            r.best.rotation_deg
        );
        Ok(self.offer("infill", r.output, r.after, done))
    }

    /// VTG on the file so far.
    pub fn vtg(&mut self, o: &VtgOptions, progress: Progress<'_>) -> Result<StageReport, Error> {
        let r = vtg_with_progress(&self.file, o, progress)?;
        if let Some(why) = r.message.filter(|_| r.peak_layers_kept.is_empty()) {
            // Handed back as it was (nothing to round within the budgets, or every rewrite
            // rang more): the stage says why, as VTG does.
            return Ok(self.unchanged("vtg", why));
        }
        let turns = |rep: &Report| rep.toolpath.n_turning;
        let done = format!(
            "sharp corners {} → {} ({:+.1} %), largest deviation {:.3} mm of {} mm{}",
            turns(&self.report),
            turns(&r.after),
            pct(turns(&r.after) as f64, turns(&self.report) as f64),
            r.max_deviation_mm,
            r.tolerance_mm,
            if r.paths.arcs_written > 0 {
                ", arcs written"
            } else {
                ""
            }
        );
        Ok(self.offer("vtg", r.output, r.after, done))
    }

    /// True time estimates in the file so far, with a header naming what changed.
    pub fn estimates(
        &mut self,
        stages: &[StageReport],
        analyze: &AnalyzeOptions,
    ) -> Result<(EstimateReport, StageReport), Error> {
        let notes = notes(stages);
        let (e, after) = rewrite_and_analyze(&self.file, analyze, &notes, Some(&self.report))?;
        let done = format!(
            "{} M73 lines and {} time comments rewritten",
            e.report.progress_lines, e.report.time_comments
        );
        let report = self.offer("estimates", e.output, after, done);
        Ok((e.report, report))
    }

    /// The file and its analysis.
    pub fn finish(self) -> (Vec<u8>, Report) {
        (self.file, self.report)
    }
}
