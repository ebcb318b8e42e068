//! The planner's clock at every line of a file.

use crate::analyze::AnalyzeOptions;
use crate::error::Error;
use crate::path::{extract, PrintPath};

/// When the machine reaches each line of a file, by the same planner as `analyze`.
#[derive(Debug, Clone)]
pub(crate) struct Clock {
    /// (line, start time) of every timed move, in file order.
    starts: Vec<(u32, f64)>,
    /// The file's print time, s (`analyze`'s `time_s`).
    pub total_s: f64,
    /// Time until the second layer starts, s (the whole print for a file of one layer).
    pub first_layer_s: Option<f64>,
    /// The machine it was timed as: profile name and junction model.
    pub machine: String,
}

impl Clock {
    /// Plans `input` and keeps the start time of every move.
    pub fn of(input: &[u8], options: &AnalyzeOptions) -> Result<Self, Error> {
        let path = extract(input, options, true)?;
        Ok(Self::from_path(&path))
    }

    fn from_path(path: &PrintPath) -> Self {
        let starts: Vec<(u32, f64)> = path
            .moves
            .iter()
            .filter_map(|m| m.timing.map(|t| (m.line, t.start_s)))
            .collect();
        let mut clock = Self {
            starts,
            total_s: path.time_s,
            first_layer_s: None,
            machine: format!("{}, {:?} junctions", path.profile.name, path.junction_model),
        };
        // From the start of the print, as PrusaSlicer counts it: the start code's moves (purge
        // line, wipe) print as part of the first layer.
        clock.first_layer_s = path.layers.first().map(|_| {
            path.layers
                .get(1)
                .map_or(clock.total_s, |second| clock.at_line(second.line))
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
