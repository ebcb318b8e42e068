//! The two sides of a walk ([`super::walk`]): the reading side's fold turns each line's
//! feature, limits and machine events into [`Step`]s, and the planning side takes them in
//! order, numbering the moves, planning them when asked and telling the sink. On one thread
//! the steps go straight from one to the other; [`super::piped`] hands them over in batches.

use super::{MoveSink, PathFeature, PathMove, NO_FEATURE, NO_LAYER};
use crate::error::Error;
use crate::gcode::{feature_kind, Line, RawLine};
use crate::machine::{Event, Machine};
use crate::plan::{Limits, Motion, Planner};
use crate::read::{At, Flow, Fold};

/// What the reading side tells the planning side, in file order.
pub(super) enum Step {
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

/// Where the reading side's steps go.
pub(super) trait TakeSteps {
    /// `step`, the next in file order.
    fn take(&mut self, step: Step);
    /// Whether no more lines need reading ([`MoveSink::finished`]).
    fn finished(&self) -> bool {
        false
    }
}

/// The reading side's fold: each move, limit and wait as a [`Step`] to `to`, features named in
/// the order the file names them; the moves' motions only for a walk that plans (`plan`).
pub(super) struct Reading<T> {
    pub(super) to: T,
    plan: bool,
    features: Vec<PathFeature>,
    current_feature: u16,
}

impl<T> Reading<T> {
    pub(super) fn new(to: T, plan: bool) -> Self {
        Reading {
            to,
            plan,
            features: Vec::new(),
            current_feature: NO_FEATURE,
        }
    }
}

impl<T: TakeSteps> Fold for Reading<T> {
    fn line(&mut self, _: &RawLine<'_>, _: Option<&Line<'_>>) -> Result<Flow, Error> {
        Ok(if self.to.finished() {
            Flow::Skip
        } else {
            Flow::Read
        })
    }

    fn feature(&mut self, name: &str, _: &Machine) {
        let known = self.features.len();
        self.current_feature = feature_index(&mut self.features, name);
        if let Some(new) = self.features.get(known) {
            self.to.take(Step::Feature(new.clone()));
        }
    }

    fn limits(&mut self, limits: &Limits, _: &Machine) {
        self.to.take(Step::Limits(limits.clone()));
    }

    fn event(&mut self, _: &Line<'_>, event: &Event, at: At<'_>) -> Result<(), Error> {
        match event {
            Event::Move(m) => self.to.take(Step::Move {
                moved: path_move(m, self.current_feature),
                layers: at.layers,
                motion: (self.plan && !at.untimed_homing(m)).then(|| Motion::from(m)),
            }),
            &Event::Dwell(secs) => self.to.take(Step::Dwell(secs)),
            Event::Temperature { wait: true, .. } => self.to.take(Step::Flush),
            _ => {}
        }
        Ok(())
    }
}

/// The planning side: the planner (`None`: a walk without planning), the sink, and the
/// features and moves told so far.
pub(super) struct Planning<'s, S> {
    planner: Option<Planner>,
    sink: &'s mut S,
    features: Vec<PathFeature>,
    count: usize,
}

impl<'s, S: MoveSink> Planning<'s, S> {
    pub(super) fn new(sink: &'s mut S, planner: Option<Planner>) -> Self {
        Planning {
            planner,
            sink,
            features: Vec::new(),
            count: 0,
        }
    }

    /// The planner emptied into the sink, and what the side learnt: the features named, the
    /// moves told and the planned time, s (0 without planning).
    pub(super) fn finish(self) -> (Vec<PathFeature>, usize, f64) {
        let sink = self.sink;
        let time_s = self.planner.map_or(0.0, |mut planner| {
            planner.flush(&mut |pm| sink.timed(pm));
            planner.elapsed_s()
        });
        (self.features, self.count, time_s)
    }
}

impl<S: MoveSink> TakeSteps for Planning<'_, S> {
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
                if let Some(planner) = planner {
                    *planner.limits_mut() = limits.clone();
                }
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
                let Some(planner) = planner else { return };
                match motion {
                    Some(motion) => planner.push(&motion, index as u64, &mut |pm| sink.timed(pm)),
                    None => planner.flush(&mut |pm| sink.timed(pm)),
                }
            }
            Step::Dwell(secs) => {
                if let Some(planner) = planner {
                    planner.dwell(secs, &mut |pm| sink.timed(pm));
                }
            }
            Step::Flush => {
                if let Some(planner) = planner {
                    planner.flush(&mut |pm| sink.timed(pm));
                }
            }
        }
    }

    fn finished(&self) -> bool {
        self.sink.finished()
    }
}

/// The index of the feature named `name` in `features`, added where it is new (at most
/// [`NO_FEATURE`] of them: past that, [`NO_FEATURE`]).
fn feature_index(features: &mut Vec<PathFeature>, name: &str) -> u16 {
    match features.iter().position(|f| f.name == name) {
        Some(i) => i as u16,
        None if features.len() < NO_FEATURE as usize => {
            features.push(PathFeature {
                name: name.to_string(),
                kind: feature_kind(name),
            });
            (features.len() - 1) as u16
        }
        None => NO_FEATURE,
    }
}

/// A move as [`MoveSink::moved`] is told of it: its feature `feature`, its layer and timing
/// not known yet.
fn path_move(m: &crate::machine::Move, feature: u16) -> PathMove {
    PathMove {
        line: m.line,
        kind: m.kind,
        from: m.from,
        to: m.to,
        feed_mm_s: m.feed_mm_s,
        length_mm: m.length_mm,
        feature,
        layer: NO_LAYER,
        timing: None,
    }
}
