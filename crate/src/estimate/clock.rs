//! The planner's clock at every line of a file.

use crate::analyze::{AnalyzeOptions, MoveStarts};
use crate::error::Error;
use crate::path::{walk, MoveSink, PathFeature, PathMove};
use crate::plan::PlannedMove;

/// When the machine reaches each line of a file, by the same planner as `analyze`.
#[derive(Debug, Clone, PartialEq)]
pub struct Clock {
    /// (line, start time) of every timed move, in file order.
    starts: MoveStarts,
    /// The file's print time, s (`analyze`'s `time_s`).
    pub total_s: f64,
    /// Time until the second layer starts, s (the whole print for a file of one layer).
    pub first_layer_s: Option<f64>,
    /// The machine it was timed as: profile name and junction model.
    pub machine: String,
}

impl Clock {
    /// Plans `input` and keeps the start time of every move, streaming: the moves themselves
    /// are not kept (a 34 MB file's take 367 MB, its starts 17 MB).
    pub fn of(input: &[u8], options: &AnalyzeOptions) -> Result<Self, Error> {
        let mut sink = Starts {
            starts: Vec::with_capacity(crate::gcode::command_lines(input)),
            last_tag: None,
        };
        let walked = walk(input, options, true, &mut sink)?;
        let machine = (walked.profile.name.as_str(), walked.junction_model);
        let layer_lines = walked.layers.iter().map(|l| l.line);
        Ok(Self::new(sink.starts, walked.time_s, machine, layer_lines))
    }

    /// The clock of the file `report` analyses, from the starts its planning pass kept
    /// ([`crate::analyze::analyze_with_starts`]): the same planner as [`Clock::of`], read from
    /// the same moves, so the same clock, without planning the file again.
    pub fn from_analysis(report: &crate::analyze::Report, starts: MoveStarts) -> Self {
        let machine = (
            report.machine.profile.as_str(),
            report.machine.junction_model,
        );
        let layer_lines = report.layer_list.iter().map(|l| l.line);
        Self::new(starts, report.time_s, machine, layer_lines)
    }

    /// The clock of a file planned in `total_s` with these `starts`, on `machine` (profile name
    /// and junction model), whose layers start at `layer_lines`.
    fn new(
        starts: MoveStarts,
        total_s: f64,
        (profile, model): (&str, crate::plan::JunctionModel),
        mut layer_lines: impl Iterator<Item = u32>,
    ) -> Self {
        let mut clock = Self {
            starts,
            total_s,
            first_layer_s: None,
            machine: format!("{profile}, {model:?} junctions"),
        };
        // From the start of the print, as PrusaSlicer counts it: the start code's moves (purge
        // line, wipe) print as part of the first layer.
        clock.first_layer_s = layer_lines.next().map(|_| {
            layer_lines
                .next()
                .map_or(clock.total_s, |second| clock.at_line(second))
        });
        clock
    }

    /// Time elapsed when the machine reaches line `line` (1-based): the start of the first
    /// move on or after it, or the whole print time after the last move.
    pub fn at_line(&self, line: u32) -> f64 {
        let i = self.starts.partition_point(|&(l, _)| l < line);
        self.starts.get(i).map_or(self.total_s, |&(_, t)| t)
    }
}

/// [`MoveSink`] keeping the source line and start of every timed move, in file order.
struct Starts {
    starts: Vec<(u32, f64)>,
    /// The move timed last: an arc is timed once per firmware segment, and starts at its first.
    last_tag: Option<u64>,
}

impl MoveSink for Starts {
    fn moved(&mut self, _: usize, _: PathMove, _: (u32, u32), _: &[PathFeature]) {}

    fn timed(&mut self, pm: &PlannedMove) {
        if self.last_tag != Some(pm.tag) {
            self.last_tag = Some(pm.tag);
            self.starts.push((pm.line, pm.start_s));
        }
    }
}
