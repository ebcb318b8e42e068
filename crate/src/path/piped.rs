//! [`super::walk`] with planning, its reading (parser and machine) on a thread of its own
//! beside the planner and the sink on the caller's, as [`crate::analyze`] runs its timing side
//! beside its read side. The sink is told of the same moves, limits and timings in the same
//! order as the walk on one thread tells it, so what it makes is the same bit for bit.
//!
//! Only for a sink that takes every move ([`super::MoveSink::finished`] never true): a reader a
//! batch ahead cannot stop on the line the sink stopped at. The race's trials of the closed
//! loop read a whole file for a sample of its layers
//! ([`crate::dynamics::printing_deviation_in_layers`]): on the 34 MB corpus file the walk took
//! 0.25 s on one thread of each trial's 0.33 s. The wasm build walks on one thread.
#![cfg_attr(target_arch = "wasm32", allow(dead_code, unused_imports))]

use super::{feature_index, path_move, MoveSink, PathFeature, PathMove, Walked, NO_FEATURE};
use crate::error::Error;
use crate::gcode::Line;
use crate::machine::{Event, Machine};
use crate::plan::{Limits, Motion, Planner};
use crate::read::{AnalyzeOptions, At, Fold, Reader};

/// Steps handed over at a time.
const BATCH: usize = 1024;

/// Batches that may wait for the planner before the reader blocks.
const QUEUED_BATCHES: usize = 8;

/// Files smaller than this are walked on one thread (a thread costs more than it saves).
const THREAD_MIN_BYTES: usize = 1 << 20;

/// What the reading side tells the planning side, in file order.
enum Step {
    /// A feature named for the first time.
    Feature(PathFeature),
    /// New limits in force.
    Limits(Limits),
    /// A move, its layers by marker and by counting, and its motion for the planner (`None`:
    /// homing that takes no planned time, which empties the look-ahead).
    Move {
        moved: PathMove,
        layers: (u32, u32),
        motion: Option<Motion>,
    },
    /// A dwell, s.
    Dwell(f64),
    /// A wait that empties the look-ahead (a temperature waited for).
    Flush,
}

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
    let mut planning = Planning {
        planner: Planner::new(reader.setup.limits.clone(), reader.setup.model),
        sink,
        features: Vec::new(),
        count: 0,
    };
    let (read, reader) = std::thread::scope(|scope| {
        let (tx, rx) = sync_channel::<Vec<Step>>(QUEUED_BATCHES);
        let reading = scope.spawn(move || {
            let mut batch = Vec::with_capacity(BATCH);
            let mut fold = Reading {
                send: &mut |step| {
                    batch.push(step);
                    if batch.len() >= BATCH {
                        // Fails only where the planning side is gone (it panicked).
                        let _ = tx.send(std::mem::replace(&mut batch, Vec::with_capacity(BATCH)));
                    }
                },
                features: Vec::new(),
                current_feature: NO_FEATURE,
            };
            let read = reader.read(input, &mut fold);
            drop(fold);
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
    let Planning {
        mut planner,
        sink,
        features,
        count,
    } = planning;
    planner.flush(&mut |pm| sink.timed(pm));
    Ok(super::walked_of(
        reader,
        features,
        count,
        planner.elapsed_s(),
    ))
}

/// The reading side's fold: each move, limit and wait as a [`Step`], features named as
/// [`super::walk`]'s fold names them.
struct Reading<'s> {
    send: &'s mut dyn FnMut(Step),
    features: Vec<PathFeature>,
    current_feature: u16,
}

impl Fold for Reading<'_> {
    fn feature(&mut self, name: &str, _: &Machine) {
        let known = self.features.len();
        self.current_feature = feature_index(&mut self.features, name);
        if let Some(new) = self.features.get(known) {
            (self.send)(Step::Feature(new.clone()));
        }
    }

    fn limits(&mut self, limits: &Limits, _: &Machine) {
        (self.send)(Step::Limits(limits.clone()));
    }

    fn event(&mut self, _: &Line<'_>, event: &Event, at: At<'_>) -> Result<(), Error> {
        match event {
            Event::Move(m) => (self.send)(Step::Move {
                moved: path_move(m, self.current_feature),
                layers: at.layers,
                motion: (!at.untimed_homing(m)).then(|| Motion::from(m)),
            }),
            &Event::Dwell(secs) => (self.send)(Step::Dwell(secs)),
            Event::Temperature { wait: true, .. } => (self.send)(Step::Flush),
            _ => {}
        }
        Ok(())
    }
}

/// The planning side: the planner, the sink, and the features and moves told so far.
struct Planning<'s, S> {
    planner: Planner,
    sink: &'s mut S,
    features: Vec<PathFeature>,
    count: usize,
}

impl<S: MoveSink> Planning<'_, S> {
    /// `step` taken as [`super::walk`]'s fold takes the line it came from.
    fn take(&mut self, step: Step) {
        let Planning {
            planner,
            sink,
            features,
            count,
        } = self;
        match step {
            Step::Feature(f) => features.push(f),
            Step::Limits(limits) => {
                *planner.limits_mut() = limits.clone();
                sink.limits(&limits);
            }
            Step::Move {
                moved,
                layers,
                motion,
            } => {
                let index = *count;
                *count += 1;
                sink.moved(index, moved, layers, features);
                match motion {
                    None => planner.flush(&mut |pm| sink.timed(pm)),
                    Some(motion) => planner.push(&motion, index as u64, &mut |pm| sink.timed(pm)),
                }
            }
            Step::Dwell(secs) => planner.dwell(secs, &mut |pm| sink.timed(pm)),
            Step::Flush => planner.flush(&mut |pm| sink.timed(pm)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
