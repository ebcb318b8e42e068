//! Counting layers: by the slicer's markers when the file has them, else by Z.
//!
//! Both counts are kept during the single pass (a file's markers may start late), and the
//! marker count wins if there is one. Without markers a new layer starts when extrusion happens
//! at a new Z on a flat move after Z changed on a travel, as planar slicers print. On
//! continuous-Z moves (spiral vase, FullControl designs, non-planar paths) every point has its
//! own Z, so a layer is one turn of the path instead: a new layer starts each time the printing
//! direction has turned through a full 360°. A helix is then as many layers as it has turns,
//! not one layer per point.

use serde::Serialize;

use crate::gcode::LayerMarkerKind;
use crate::machine::{axis, Move};
use std::f64::consts::TAU;

/// How the layer count was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case", tag = "method", content = "marker")]
pub enum LayerSource {
    /// From the slicer's own layer-change comments.
    Markers(LayerMarkerKind),
    /// From changes of Z while extruding (no markers in the file).
    ZChanges,
}

/// Totals for one layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct LayerSummary {
    /// 0-based layer index.
    pub index: u64,
    /// Z of the layer, mm (the marker's, else the first extrusion's).
    pub z: Option<f64>,
    /// 1-based line where the layer starts.
    pub line: u32,
    /// Moves in the layer.
    pub moves: u64,
    /// Path length while extruding, mm.
    pub extrude_distance_mm: f64,
    /// Path length of travel, mm.
    pub travel_distance_mm: f64,
    /// Net filament, mm.
    pub filament_mm: f64,
    /// Time, s.
    pub time_s: f64,
    /// Energy, J: `E_servo` of its moves and dwells plus the share of `E_aux` of its time.
    pub energy_j: f64,
}

/// Layer index meaning "before the first layer".
pub const NO_LAYER: u32 = u32::MAX;

/// Smallest Z difference that counts as a new layer on flat moves, mm.
const Z_EPS: f64 = 1e-4;

#[derive(Debug, Default)]
struct Count {
    layers: Vec<LayerSummary>,
}

impl Count {
    fn start(&mut self, line: u32, z: Option<f64>) {
        let index = self.layers.len() as u64;
        self.layers.push(LayerSummary {
            index,
            z,
            line,
            moves: 0,
            extrude_distance_mm: 0.0,
            travel_distance_mm: 0.0,
            filament_mm: 0.0,
            time_s: 0.0,
            energy_j: 0.0,
        });
    }

    fn add(&mut self, m: &Move) {
        if let Some(l) = self.layers.last_mut() {
            l.moves += 1;
            if m.is_extruding() {
                l.extrude_distance_mm += m.length_mm;
                if l.z.is_none() {
                    l.z = Some(m.to[axis::Z]);
                }
            } else {
                l.travel_distance_mm += m.length_mm;
            }
            l.filament_mm += m.extrusion();
        }
    }

    fn current(&self) -> u32 {
        u32::try_from(self.layers.len()).map_or(NO_LAYER, |n| n.wrapping_sub(1))
    }

    fn add_time_energy(&mut self, index: u32, secs: f64, joules: f64) {
        if let Some(l) = self.layers.get_mut(index as usize) {
            l.time_s += secs;
            l.energy_j += joules;
        }
    }
}

/// Tracks layers from markers and from Z at once.
#[derive(Debug)]
pub struct LayerTracker {
    marker_kind: Option<LayerMarkerKind>,
    by_marker: Count,
    by_z: Count,
    z_layer: Option<f64>,
    z_last: Option<f64>,
    /// XY direction of the last printing move (None after a travel).
    direction: Option<[f64; 2]>,
    /// Signed turning of the printing direction since the layer started, radians.
    turned: f64,
}

impl LayerTracker {
    /// An empty tracker.
    pub fn new() -> Self {
        Self {
            marker_kind: None,
            by_marker: Count::default(),
            by_z: Count::default(),
            z_layer: None,
            z_last: None,
            direction: None,
            turned: 0.0,
        }
    }

    /// A layer marker at `line`. Markers of a family other than the file's first are ignored.
    pub fn marker(&mut self, kind: LayerMarkerKind, z: Option<f64>, line: u32) {
        match self.marker_kind {
            None => self.marker_kind = Some(kind),
            Some(k) if k != kind => return,
            _ => {}
        }
        self.by_marker.start(line, z);
    }

    /// A move (its time comes later, from the planner, through [`LayerTracker::add_time_energy`]).
    pub fn motion(&mut self, m: &Move) {
        if m.is_extruding() {
            let z = m.to[axis::Z];
            let z_start = m.from[axis::Z];
            let dx = m.to[axis::X] - m.from[axis::X];
            let dy = m.to[axis::Y] - m.from[axis::Y];
            let direction = (dx * dx + dy * dy > 1e-18).then_some([dx, dy]);
            let new_layer = match (self.z_layer, self.z_last) {
                (Some(zl), Some(last)) => {
                    if (z - z_start).abs() <= Z_EPS {
                        // Flat move: a new layer if Z changed off the print (on a travel) to a
                        // new height, as planar slicers do between layers.
                        (z_start - last).abs() > Z_EPS && (z - zl).abs() > Z_EPS
                    } else {
                        // Continuous Z: a new layer after each full turn of the path.
                        if let (Some(p), Some(d)) = (self.direction, direction) {
                            // Signed angle between the two directions, in (-π, π].
                            self.turned += crate::math::atan2(
                                p[0] * d[1] - p[1] * d[0],
                                p[0] * d[0] + p[1] * d[1],
                            );
                        }
                        self.turned.abs() >= TAU
                    }
                }
                _ => true,
            };
            if direction.is_some() {
                self.direction = direction;
            }
            self.z_last = Some(z);
            if new_layer {
                self.turned = 0.0;
                self.z_layer = Some(z);
                self.by_z.start(m.line, Some(z));
            }
        } else if m.length_mm > 1e-9 {
            self.direction = None;
        }
        self.by_marker.add(m);
        self.by_z.add(m);
    }

    /// The current layer in each count ([`NO_LAYER`] before the first).
    pub fn current(&self) -> (u32, u32) {
        (self.by_marker.current(), self.by_z.current())
    }

    /// Adds time and energy to a layer of each count, as given by [`LayerTracker::current`].
    pub fn add_time_energy(&mut self, (by_marker, by_z): (u32, u32), secs: f64, joules: f64) {
        self.by_marker.add_time_energy(by_marker, secs, joules);
        self.by_z.add_time_energy(by_z, secs, joules);
    }

    /// The layer list and how it was counted.
    pub fn finish(self) -> (Vec<LayerSummary>, LayerSource) {
        match self.marker_kind {
            Some(kind) => (self.by_marker.layers, LayerSource::Markers(kind)),
            None => (self.by_z.layers, LayerSource::ZChanges),
        }
    }
}
