//! The recommended pipeline in one pass: infill search when asked, VTG, arcs where the
//! firmware runs them, and true time estimates in the file handed back.
//!
//! Each stage works on the previous stage's file and is kept only if it makes the file no
//! dearer in time and energy, as `analyze` costs both (the project's rule: a user never gets a
//! worse file back); a stage that cannot improve the file says why and passes it on unchanged.
//! The time comments and `M73` lines are then rewritten from the planner's clock
//! ([`crate::estimate`]), so printers show the time of the toolpath they run.

mod stages;

use serde::{Deserialize, Serialize};

use crate::analyze::{analyze, AnalyzeOptions, Report};
use crate::error::Error;
use crate::estimate::EstimateReport;
use crate::infill::InfillOptions;
use crate::progress::Progress;
pub use crate::vtg::ArcsMode;
use crate::vtg::VtgOptions;
use stages::Stage;

/// Options of [`optimize`]. Every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct OptimizeOptions {
    /// How the file is read and the machine it runs on; every stage uses these.
    pub analyze: AnalyzeOptions,
    /// Run the infill search first with these options (default: off). Its `analyze` is
    /// replaced by the one above.
    pub infill: Option<InfillOptions>,
    /// Run VTG (default true).
    pub vtg: bool,
    /// VTG's options (default: VTG's). Its `analyze`, `arcs` and `allow_slower_pct` are
    /// replaced by this pipeline's.
    pub vtg_options: VtgOptions,
    /// Print time VTG may add to round corners, percent (default 0: the pipeline never
    /// trades time for corners; every stage must also leave the file no slower).
    pub allow_slower_pct: f64,
    /// Arcs in VTG's output: `auto` (default) writes them where the firmware runs them.
    pub arcs: ArcsMode,
    /// Rewrite the time comments and `M73` lines (default true).
    pub estimates: bool,
}

impl Default for OptimizeOptions {
    fn default() -> Self {
        Self {
            analyze: AnalyzeOptions::default(),
            infill: None,
            vtg: true,
            vtg_options: VtgOptions::default(),
            allow_slower_pct: 0.0,
            arcs: ArcsMode::Auto,
            estimates: true,
        }
    }
}

/// One stage's outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "OptimizeStage"))]
pub struct StageReport {
    /// `infill`, `vtg` or `estimates`.
    pub stage: String,
    /// Whether the stage's file was kept.
    pub applied: bool,
    /// What it did, or why its file was not kept.
    pub message: String,
    /// Print time before and after the stage, s.
    pub time_s: [f64; 2],
    /// Total energy before and after the stage, J.
    pub energy_j: [f64; 2],
    /// Lines before and after the stage.
    pub lines: [u64; 2],
}

/// Result of [`optimize`].
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct OptimizeReport {
    /// `analyze` of the input.
    pub before: Report,
    /// `analyze` of the output.
    pub after: Report,
    /// Each stage in order.
    pub stages: Vec<StageReport>,
    /// The estimates written, when asked.
    pub estimates: Option<EstimateReport>,
    /// The optimised file.
    #[serde(skip)]
    pub output: Vec<u8>,
}

/// [`optimize_with_progress`] without progress.
pub fn optimize(input: &[u8], options: &OptimizeOptions) -> Result<OptimizeReport, Error> {
    optimize_with_progress(input, options, &mut |_| true)
}

/// Runs the pipeline on `input`; `progress` gets the fraction done (`false` cancels).
pub fn optimize_with_progress(
    input: &[u8],
    options: &OptimizeOptions,
    progress: Progress<'_>,
) -> Result<OptimizeReport, Error> {
    let before = analyze(input, &options.analyze)?;
    let mut current = Stage::start(input.to_vec(), before.clone());
    let mut stages = Vec::new();
    let spans = stages::spans(options);
    let mut span = spans.iter();
    if let Some(infill) = &options.infill {
        let (a, b) = span.next().copied().unwrap_or((0.0, 1.0));
        let mut p = |f: f64| progress(a + (b - a) * f);
        stages.push(current.infill(infill, &options.analyze, &mut p)?);
    }
    if options.vtg {
        let (a, b) = span.next().copied().unwrap_or((0.0, 1.0));
        let mut p = |f: f64| progress(a + (b - a) * f);
        let vtg = VtgOptions {
            analyze: options.analyze.clone(),
            arcs: options.arcs.resolved(input, &before, &options.analyze),
            allow_slower_pct: options.allow_slower_pct,
            // The pipeline writes the estimates once, at its end.
            estimates: false,
            ..options.vtg_options.clone()
        };
        stages.push(current.vtg(&vtg, &mut p)?);
    }
    let mut estimates = None;
    if options.estimates {
        let (report, stage) = current.estimates(&stages, &options.analyze)?;
        estimates = Some(report);
        stages.push(stage);
    }
    progress(1.0);
    let (output, after) = current.finish();
    Ok(OptimizeReport {
        before,
        after,
        stages,
        estimates,
        output,
    })
}

/// The header notes that say what quietpath changed in a file.
pub(crate) fn notes(stages: &[StageReport]) -> Vec<String> {
    stages
        .iter()
        .map(|s| {
            format!(
                "{}: {}{}",
                s.stage,
                if s.applied { "" } else { "not applied: " },
                s.message
            )
        })
        .collect()
}
