//! Where time goes: planned moves are finalised by the look-ahead some moves after they were
//! read, so each move carries a sequence number, and the feature and layers it belongs to wait
//! in a queue (bounded by the planner's window) until its time is known. Temperature and fan
//! events wait the same way for the time at which they happen.

use std::collections::{HashMap, VecDeque};

use super::layers::LayerTracker;
use super::report::{Bounds, FanEvent, FeatureSummary, TemperatureEvent};
use crate::energy::Accumulator;
use crate::gcode::feature_kind;
use crate::machine::{Heater, Move};
use crate::plan::PlannedMove;

/// Feature slot of travel moves.
pub const TRAVEL: u32 = u32::MAX;

/// Totals that do not depend on timing.
#[derive(Debug, Default)]
pub struct Totals {
    pub moves: u64,
    pub extruding_moves: u64,
    pub distance_mm: f64,
    pub extrude_distance_mm: f64,
    pub travel_distance_mm: f64,
    pub retractions: u64,
    pub lines: u64,
    pub bounds: Option<Bounds>,
}

#[derive(Debug, Clone, Copy)]
enum Pending {
    Temperature {
        line: u32,
        heater: Heater,
        target_c: f64,
        wait: bool,
    },
    Fan {
        line: u32,
        index: u16,
        speed: f64,
    },
}

/// Everything the analysis accumulates.
#[derive(Debug)]
pub struct Accounts {
    pub totals: Totals,
    pub features: Vec<FeatureSummary>,
    feature_names: HashMap<String, usize>,
    current_feature: Option<usize>,
    pub travel: FeatureSummary,
    pub layers: LayerTracker,
    /// (move sequence number, feature slot, layers) of moves not yet finalised.
    tags: VecDeque<(u64, u32, (u32, u32))>,
    /// Events waiting for their time: (moves read before them, event).
    pending: VecDeque<(u64, Pending)>,
    pub temperatures: Vec<TemperatureEvent>,
    pub fans: Vec<FanEvent>,
    /// Energy models, fed every planned move and dwell.
    pub energy: Accumulator,
    moves_read: u64,
}

impl Accounts {
    pub fn new(energy: Accumulator) -> Self {
        Self {
            totals: Totals::default(),
            features: Vec::new(),
            feature_names: HashMap::new(),
            current_feature: None,
            travel: summary("travel", None),
            layers: LayerTracker::new(),
            tags: VecDeque::new(),
            pending: VecDeque::new(),
            temperatures: Vec::new(),
            fans: Vec::new(),
            energy,
            moves_read: 0,
        }
    }

    /// The slicer names the feature that follows.
    pub fn feature(&mut self, name: &str) {
        self.current_feature = Some(self.feature_index(name));
    }

    fn feature_index(&mut self, name: &str) -> usize {
        if let Some(&i) = self.feature_names.get(name) {
            return i;
        }
        self.feature_names
            .insert(name.to_string(), self.features.len());
        self.features.push(summary(name, Some(name)));
        self.features.len() - 1
    }

    /// A move was read; returns its sequence number (the planner's tag).
    pub fn read_move(&mut self, m: &Move) -> u64 {
        account_move(m, &mut self.totals);
        let slot = if m.is_extruding() {
            let i = match self.current_feature {
                Some(i) => i,
                None => {
                    let i = self.feature_index("unmarked");
                    self.current_feature = Some(i);
                    i
                }
            };
            u32::try_from(i).unwrap_or(TRAVEL - 1)
        } else {
            TRAVEL
        };
        let s = self.slot(slot);
        s.moves += 1;
        s.distance_mm += m.length_mm;
        s.filament_mm += m.extrusion();
        self.layers.motion(m);
        let seq = self.moves_read;
        self.tags.push_back((seq, slot, self.layers.current()));
        self.moves_read += 1;
        seq
    }

    fn slot(&mut self, slot: u32) -> &mut FeatureSummary {
        match self.features.get_mut(slot as usize) {
            Some(f) if slot != TRAVEL => f,
            _ => &mut self.travel,
        }
    }

    /// A move's plan is final.
    pub fn planned(&mut self, pm: &PlannedMove) {
        let joules = self.energy.planned(pm);
        self.stamp_until(pm.tag, pm.start_s);
        while self.tags.front().is_some_and(|t| t.0 < pm.tag) {
            self.tags.pop_front();
        }
        let Some(&(_, slot, layers)) = self.tags.front() else {
            return;
        };
        let d = pm.duration();
        let s = self.slot(slot);
        s.time_s += d;
        s.energy_j += joules;
        self.layers.add_time_energy(layers, d, joules);
    }

    /// Time passing outside moves (a dwell), charged to the current layer.
    pub fn dwell(&mut self, secs: f64) {
        let joules = self.energy.dwell(secs);
        let current = self.layers.current();
        self.layers.add_time_energy(current, secs, joules);
    }

    /// A heater target; timed when the moves before it are planned.
    pub fn temperature(&mut self, line: u32, heater: Heater, target_c: f64, wait: bool) {
        self.pending.push_back((
            self.moves_read,
            Pending::Temperature {
                line,
                heater,
                target_c,
                wait,
            },
        ));
    }

    /// A fan speed; timed when the moves before it are planned.
    pub fn fan(&mut self, line: u32, index: u16, speed: f64) {
        self.pending
            .push_back((self.moves_read, Pending::Fan { line, index, speed }));
    }

    /// Stamps events that come before move `seq` with `time_s`.
    fn stamp_until(&mut self, seq: u64, time_s: f64) {
        while let Some(&(before, event)) = self.pending.front() {
            if before > seq {
                break;
            }
            self.pending.pop_front();
            match event {
                Pending::Temperature {
                    line,
                    heater,
                    target_c,
                    wait,
                } => {
                    self.temperatures.push(TemperatureEvent {
                        line,
                        time_s,
                        heater,
                        target_c,
                        wait,
                    });
                }
                Pending::Fan { line, index, speed } => self.fans.push(FanEvent {
                    line,
                    time_s,
                    index,
                    speed,
                }),
            }
        }
    }

    /// Stamps every waiting event with `time_s` (after a flush: all moves before are done).
    pub fn stamp_all(&mut self, time_s: f64) {
        self.stamp_until(u64::MAX, time_s);
    }
}

fn summary(name: &str, kind_of: Option<&str>) -> FeatureSummary {
    FeatureSummary {
        name: name.to_string(),
        kind: kind_of.map(feature_kind),
        moves: 0,
        distance_mm: 0.0,
        filament_mm: 0.0,
        time_s: 0.0,
        energy_j: 0.0,
    }
}

fn account_move(m: &Move, totals: &mut Totals) {
    totals.moves += 1;
    totals.distance_mm += m.length_mm;
    if m.is_extruding() {
        totals.extruding_moves += 1;
        totals.extrude_distance_mm += m.length_mm;
        let b = totals.bounds.get_or_insert(Bounds {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        });
        for p in [&m.from, &m.to] {
            for ((lo, hi), v) in b.min.iter_mut().zip(b.max.iter_mut()).zip(&p[..3]) {
                *lo = lo.min(*v);
                *hi = hi.max(*v);
            }
        }
    } else {
        totals.travel_distance_mm += m.length_mm;
        if m.extrusion() < -1e-12 {
            totals.retractions += 1;
        }
    }
}
