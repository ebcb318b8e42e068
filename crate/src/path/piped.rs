//! [`super::walk`] with planning, its reading (parser and machine) on a thread of its own
//! beside the planner and the sink on the caller's, as [`crate::analyze`] runs its timing side
//! beside its read side: the two sides of [`super::steps`], the steps handed over in batches.
//! The sink is told of the same moves, limits and timings in the same order as the walk on one
//! thread tells it, so what it makes is the same bit for bit.
//!
//! Only for a sink that takes every move ([`super::MoveSink::finished`] never true): a reader a
//! batch ahead cannot stop on the line the sink stopped at. The race's trials of the closed
//! loop read a whole file for a sample of its layers
//! ([`crate::dynamics::printing_deviation_in_layers`]): on the 34 MB corpus file the walk took
//! 0.25 s on one thread of each trial's 0.33 s. The wasm build walks on one thread.
#![cfg_attr(target_arch = "wasm32", allow(dead_code, unused_imports))]

use super::steps::{Planning, Reading, Step, TakeSteps};
use super::{MoveSink, Walked};
use crate::error::Error;
use crate::plan::Planner;
use crate::read::{AnalyzeOptions, Reader};

/// Steps handed over at a time.
const BATCH: usize = 1024;

/// Batches that may wait for the planner before the reader blocks.
const QUEUED_BATCHES: usize = 8;

/// Files smaller than this are walked on one thread (a thread costs more than it saves).
const THREAD_MIN_BYTES: usize = 1 << 20;

/// [`super::walk`] with planning, for a sink that takes every move, the reading on a thread of
/// its own where there are threads and the file is large enough to pay for one.
pub(crate) fn walk_piped(
    input: &[u8],
    options: &AnalyzeOptions,
    sink: &mut impl MoveSink,
) -> Result<Walked, Error> {
    #[cfg(not(target_arch = "wasm32"))]
    if input.len() >= THREAD_MIN_BYTES && crate::parallel::threads() > 1 {
        return threaded(input, options, sink);
    }
    super::walk(input, options, true, sink)
}

/// [`walk_piped`] on two threads: the reader sends batches of [`Step`]s over a bounded channel.
#[cfg(not(target_arch = "wasm32"))]
fn threaded(
    input: &[u8],
    options: &AnalyzeOptions,
    sink: &mut impl MoveSink,
) -> Result<Walked, Error> {
    use std::sync::mpsc::sync_channel;
    let mut reader = Reader::new(input, options)?;
    sink.machine(&reader.setup.profile);
    sink.limits(&reader.setup.limits);
    let planner = Planner::new(reader.setup.limits.clone(), reader.setup.model);
    let mut planning = Planning::new(sink, Some(planner));
    let (read, reader) = std::thread::scope(|scope| {
        let (tx, rx) = sync_channel::<Vec<Step>>(QUEUED_BATCHES);
        let reading = scope.spawn(move || {
            let batches = Batches {
                batch: Vec::with_capacity(BATCH),
                tx,
            };
            let mut fold = Reading::new(batches, true);
            let read = reader.read(input, &mut fold);
            let Batches { batch, tx } = fold.to;
            let _ = tx.send(batch);
            (read, reader)
        });
        for batch in rx {
            batch.into_iter().for_each(|step| planning.take(step));
        }
        match reading.join() {
            Ok(done) => done,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    });
    read?;
    let (features, count, time_s) = planning.finish();
    Ok(super::walked_of(reader, features, count, time_s))
}

/// The reading side's steps gathered into batches for the planning side's thread.
#[cfg(not(target_arch = "wasm32"))]
struct Batches {
    batch: Vec<Step>,
    tx: std::sync::mpsc::SyncSender<Vec<Step>>,
}

#[cfg(not(target_arch = "wasm32"))]
impl TakeSteps for Batches {
    fn take(&mut self, step: Step) {
        self.batch.push(step);
        if self.batch.len() >= BATCH {
            let full = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH));
            // Fails only where the planning side is gone (it panicked).
            let _ = self.tx.send(full);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::{PathFeature, PathMove};
    use crate::plan::Limits;

    /// Everything a sink is told, in order.
    #[derive(Debug, Default, PartialEq)]
    struct Told {
        calls: Vec<String>,
        timed: Vec<crate::plan::PlannedMove>,
    }

    impl MoveSink for Told {
        fn moved(&mut self, index: usize, m: PathMove, layers: (u32, u32), f: &[PathFeature]) {
            let feature = f.get(m.feature as usize).map(|f| f.name.clone());
            self.calls
                .push(format!("move {index} {m:?} {layers:?} {feature:?}"));
        }
        fn timed(&mut self, pm: &crate::plan::PlannedMove) {
            self.calls.push(format!("timed {}", pm.tag));
            self.timed.push(*pm);
        }
        fn limits(&mut self, limits: &Limits) {
            self.calls
                .push(format!("limits {:?}", limits.max_acceleration));
        }
    }

    /// A file over a megabyte: homing, then layers of moves at changing accelerations and
    /// features, with a dwell and a temperature waited for now and then.
    fn file() -> String {
        let mut g = String::from("G28\nG90\nM83\nM204 S1000\n");
        for layer in 0..600 {
            g.push_str(&format!(
                ";LAYER:{layer}\nG1 Z{:.2} F600\n",
                0.2 * (layer + 1) as f64
            ));
            g.push_str(if layer % 2 == 0 {
                ";TYPE:WALL-OUTER\n"
            } else {
                ";TYPE:FILL\n"
            });
            g.push_str(&format!("M204 S{}\n", 800 + 100 * (layer % 5)));
            for k in 0..60 {
                let (x, y) = (10.0 + (k % 7) as f64 * 3.1, 10.0 + (k % 11) as f64 * 2.3);
                g.push_str(&format!(
                    "G1 X{x:.3} Y{y:.3} E0.05 F{}\n",
                    1800 + 60 * (k % 9)
                ));
            }
            if layer % 50 == 0 {
                g.push_str("G4 P200\nM109 S210\n");
            }
        }
        g
    }

    #[test]
    fn the_sink_is_told_what_the_walk_on_one_thread_tells_it() {
        let g = file();
        assert!(g.len() >= THREAD_MIN_BYTES, "{} bytes", g.len());
        let options = AnalyzeOptions::default();
        let mut one = Told::default();
        let walked = crate::path::walk(g.as_bytes(), &options, true, &mut one).unwrap();
        let mut two = Told::default();
        let piped = threaded(g.as_bytes(), &options, &mut two).unwrap();
        assert!(one.timed.len() > 20_000 && one.calls.iter().any(|c| c.starts_with("limits")));
        assert_eq!(one, two);
        assert_eq!(walked.time_s.to_bits(), piped.time_s.to_bits());
        assert_eq!(
            (walked.moves, walked.layers.len(), walked.features.len()),
            (piped.moves, piped.layers.len(), piped.features.len())
        );
    }

    #[test]
    fn an_unreadable_file_is_refused_on_either_thread_alike() {
        let mut g = file();
        g.push_str("G1 X1 Yabc E0.1\n");
        let options = AnalyzeOptions {
            strict: true,
            ..Default::default()
        };
        let one = crate::path::walk(g.as_bytes(), &options, true, &mut Told::default());
        let two = threaded(g.as_bytes(), &options, &mut Told::default());
        let (one, two) = (one.map(|w| w.moves), two.map(|w| w.moves));
        assert!(one.is_err());
        assert_eq!(
            one.map_err(|e| e.to_string()),
            two.map_err(|e| e.to_string())
        );
    }
}
