//! The printer's modal state, driven line by line: positions, modes, feed rate, overrides,
//! temperatures and fans. Each command that does something physical becomes an [`Event`].
//!
//! Semantics follow Marlin and Klipper where they agree, and are documented where they do not:
//! - `G90`/`G91` switch X, Y, Z and the extra axes; `G91` also makes E relative, and `G90`
//!   returns E to the `M82`/`M83` mode (Klipper's rule; Marlin's differs only if `G90` comes
//!   after `M83`, which slicers do not write).
//! - `G0` moves at the modal feed rate like `G1` (both firmwares, by default).
//! - `G28` sets the homed axes (all, if none named) to 0, as a move there (Marlin-style files
//!   time it as one; on Klipper it is untimed homing, see `read::At::untimed_homing`).
//! - `G10`/`G11` without `P`/`L` are firmware retraction with the `M207`/`M208` lengths.
//! - `M220` scales feed rates, `M221` scales extrusion.
//! - `M200 D<d>` (Marlin, RepRapFirmware) reads E words as cubic millimetres of filament of
//!   diameter `d` (`D0` or `S0` reads them as millimetres again, `S1` as volume with the last
//!   diameter); Cura's volumetric flavours (`;FLAVOR:Marlin(Volumetric)`, `UltiGCode`) write
//!   volume from the first line ([`MachineConfig::volumetric_diameter_mm`]). Klipper has no
//!   `M200`.

pub mod arc;
pub mod extrusion;
pub mod timeline;

use serde::Serialize;

use crate::error::Warnings;
use crate::gcode::{Code, Command, Line, Params};
pub use arc::{Arc, ArcSpec, Plane};
pub use extrusion::{infer_extrusion_mode, ExtrusionInference, ExtrusionMode, ModeSource};
pub use timeline::{FanEvent, TemperatureEvent};

/// Filament diameter `M200 S1` assumes before any `M200 D`, mm (Marlin's
/// `DEFAULT_NOMINAL_FILAMENT_DIA`).
pub const DEFAULT_VOLUMETRIC_DIAMETER_MM: f64 = 1.75;
/// Largest `M200 D` taken as a filament diameter, mm.
const MAX_FILAMENT_DIAMETER_MM: f64 = 10.0;

/// Number of tracked axes: X, Y, Z, E, A, B, C, U, V, W.
pub const AXES: usize = 10;
/// Index of each axis in a [`Pos`].
pub mod axis {
    /// X.
    pub const X: usize = 0;
    /// Y.
    pub const Y: usize = 1;
    /// Z.
    pub const Z: usize = 2;
    /// Extruder (filament mm).
    pub const E: usize = 3;
    /// A (rotary, degrees).
    pub const A: usize = 4;
    /// B (rotary, degrees).
    pub const B: usize = 5;
    /// C (rotary, degrees).
    pub const C: usize = 6;
}
/// Word letter of each axis index.
pub const AXIS_LETTERS: [u8; AXES] = *b"XYZEABCUVW";
/// The axis letters as a bit set of [`crate::gcode::Params::numbered`].
const AXIS_WORDS: u32 = {
    let mut bits = 0;
    let mut i = 0;
    while i < AXES {
        bits |= letter_bit(AXIS_LETTERS[i]);
        i += 1;
    }
    bits
};

/// The bit of an upper-case word letter in [`crate::gcode::Params::numbered`].
const fn letter_bit(letter: u8) -> u32 {
    1 << (letter - b'A')
}

/// The axis index of an axis letter (one of [`AXIS_LETTERS`]).
#[inline]
fn axis_of(letter: u8) -> usize {
    match letter {
        b'X' => axis::X,
        b'Y' => axis::Y,
        b'Z' => axis::Z,
        b'E' => axis::E,
        b'A' => axis::A,
        b'B' => axis::B,
        b'C' => axis::C,
        b'U' => 7,
        b'V' => 8,
        _ => 9,
    }
}
const LINEAR: [bool; AXES] = [
    true, true, true, true, false, false, false, true, true, true,
];

/// A position over all axes: mm for linear axes and E, degrees for A, B, C.
pub type Pos = [f64; AXES];

/// Default feed rate before any `F`, mm/s (Marlin's and Klipper's 1500 mm/min).
pub const DEFAULT_FEED_MM_S: f64 = 25.0;
/// Largest coordinate accepted, mm (or degrees): a thousand kilometres. Beyond it a value is
/// corruption, not geometry; the line is ignored with a warning so that no report or rewritten
/// file ever carries absurd coordinates, and every sum over a file stays finite.
pub const MAX_COORDINATE: f64 = 1e9;
/// Largest arc a printer runs, radius or path length, mm (10 m: beyond any printer's bed, and
/// ArcWelder's own largest radius, 9 999 mm). A longer one is garbage: it is read as a straight
/// move to its end, with a warning, so that its cost cannot grow with its size.
pub const MAX_ARC_MM: f64 = 10_000.0;
/// Slowest feed rate used for timing, mm/s: a smaller (or vanishing) feed would make times
/// infinite. Marlin's planner never goes below its `MINIMUM_PLANNER_SPEED` (0.05 mm/s) either.
pub const MIN_FEED_MM_S: f64 = 1e-3;
/// Longest dwell accepted, s (about four months).
pub const MAX_DWELL_S: f64 = 1e7;
/// Range of `M220`/`M221` factors accepted, percent.
pub const OVERRIDE_RANGE_PERCENT: std::ops::RangeInclusive<f64> = 1.0..=1000.0;
/// Heater targets accepted, °C: from "off" (negative values are read as off by firmware too)
/// to well above any hotend's maximum (high-temperature printers reach 500 °C).
pub const TEMPERATURE_RANGE_C: std::ops::RangeInclusive<f64> = -273.15..=1500.0;
/// Klipper's wait when `M84`/`M18` turns the motors off, s: `stepper_enable.py` dwells its
/// `DISABLE_STALL_TIME` (0.1 s) before and after, so that no step overlaps the change.
pub const KLIPPER_MOTORS_OFF_S: f64 = 0.2;
/// Default firmware retraction length, mm (Marlin's `RETRACT_LENGTH`).
pub const DEFAULT_RETRACT_MM: f64 = 3.0;
/// Default firmware retraction speed, mm/s (Marlin's `RETRACT_FEEDRATE`).
pub const DEFAULT_RETRACT_FEED_MM_S: f64 = 45.0;

/// The kind of a motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum MoveKind {
    /// `G0`.
    Rapid,
    /// `G1`.
    Linear,
    /// `G2`/`G3`.
    Arc(Arc),
    /// `G10`/`G11` firmware retraction or recovery (E only).
    FirmwareRetract,
    /// `G28` homing, as a straight move to 0.
    Home,
}

impl MoveKind {
    /// The arc a `G2`/`G3` runs along (`None` for every other kind).
    #[inline]
    pub fn arc(&self) -> Option<&Arc> {
        match self {
            MoveKind::Arc(a) => Some(a),
            _ => None,
        }
    }
}

/// One motion, in machine coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Move {
    /// 1-based line of the command.
    pub line: u32,
    /// Kind of motion.
    pub kind: MoveKind,
    /// Start position (E: net filament pushed so far, after flow override).
    pub from: Pos,
    /// End position.
    pub to: Pos,
    /// Requested feed rate after the `M220` override, mm/s.
    pub feed_mm_s: f64,
    /// Tool-tip path length in X, Y, Z (helix length for arcs), mm.
    pub length_mm: f64,
}

impl Move {
    /// Filament pushed (negative for retraction), mm.
    #[inline]
    pub fn extrusion(&self) -> f64 {
        self.to[axis::E] - self.from[axis::E]
    }

    /// Whether the move lays down material: it moves the tool and pushes filament.
    #[inline]
    pub fn is_extruding(&self) -> bool {
        self.length_mm > 1e-9 && self.extrusion() > 1e-12
    }

    /// The distance the feed rate applies to: the XYZ path, else the rotary axes (degrees),
    /// else the extruder (the rule of Marlin's planner).
    pub fn feed_length(&self) -> f64 {
        if self.length_mm > 1e-9 {
            return self.length_mm;
        }
        let rot = (axis::A..=axis::C)
            .map(|i| (self.to[i] - self.from[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        if rot > 1e-9 {
            rot
        } else {
            self.extrusion().abs()
        }
    }

    /// Time at the requested feed rate, ignoring acceleration, s.
    pub fn nominal_time(&self) -> f64 {
        self.feed_length() / self.feed_mm_s.max(MIN_FEED_MM_S)
    }
}

/// Which heater a temperature command addresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum Heater {
    /// A hotend (`M104`/`M109`), with its tool index.
    Hotend(u16),
    /// The bed (`M140`/`M190`).
    Bed,
    /// The chamber (`M141`/`M191`).
    Chamber,
}

/// Something physical a line does.
///
/// Events are short-lived values returned per line; boxing the large `Move` variant would cost
/// an allocation per move for no gain.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    /// A motion.
    Move(Move),
    /// `G4`: wait, s.
    Dwell(f64),
    /// A heater target; `wait` for `M109`/`M190`/`M191`.
    Temperature {
        /// Which heater.
        heater: Heater,
        /// Target, °C.
        target_c: f64,
        /// Whether the printer waits for it.
        wait: bool,
    },
    /// A part-cooling fan speed, 0..=1.
    Fan {
        /// Fan index (`P`).
        index: u16,
        /// Speed fraction.
        speed: f64,
    },
}

/// Settings of the state machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineConfig {
    /// Extrusion mode at the start of the file.
    pub extrusion: ExtrusionMode,
    /// Firmware retraction length before any `M207`, mm.
    pub retract_mm: f64,
    /// Firmware retraction speed before any `M207`, mm/s.
    pub retract_feed_mm_s: f64,
    /// Read commands as Klipper does where it differs from Marlin: `G4` takes only `P`
    /// (milliseconds; `G4 S2` is no dwell), every `G4` and `M400` empties the look-ahead
    /// (the toolhead stops there), and `M84`/`M18` waits [`KLIPPER_MOTORS_OFF_S`] when a motor
    /// was on.
    pub klipper: bool,
    /// E words are volumes (mm³) of filament of this diameter from the start of the file, mm:
    /// the file's flavour says so (Cura's volumetric flavours), not an `M200` in it.
    pub volumetric_diameter_mm: Option<f64>,
}

impl Default for MachineConfig {
    fn default() -> Self {
        Self {
            extrusion: ExtrusionMode::Absolute,
            retract_mm: DEFAULT_RETRACT_MM,
            retract_feed_mm_s: DEFAULT_RETRACT_FEED_MM_S,
            klipper: false,
            volumetric_diameter_mm: None,
        }
    }
}

/// Cross-section of filament of diameter `d`, mm² (`None` for a diameter that is no filament).
fn filament_area(d: f64) -> Option<f64> {
    (d.is_finite() && d > 0.0).then(|| core::f64::consts::PI * d * d / 4.0)
}

/// The modal state of the printer.
#[derive(Debug, Clone)]
pub struct Machine {
    /// Logical position (what G-code coordinates refer to, after `G92`).
    logical: Pos,
    /// Machine position (continuous across `G92`; E accumulates net filament after flow).
    physical: Pos,
    relative_axes: bool,
    e_mode: ExtrusionMode,
    inches: bool,
    plane: Plane,
    feed_mm_s: f64,
    speed_factor: f64,
    flow_factor: f64,
    /// E words are volumes (mm³) of filament of `volumetric_diameter_mm` (`M200`).
    volumetric: bool,
    /// The last `M200 D` diameter, mm, which `M200 S1` turns volumetric extrusion on with.
    volumetric_diameter_mm: f64,
    retracted: bool,
    retract_mm: f64,
    retract_feed_mm_s: f64,
    unretract_extra_mm: f64,
    unretract_feed_mm_s: f64,
    tool: u16,
    klipper: bool,
    /// A move has run since the start or the last `M84` (its motors are on).
    motors_on: bool,
}

impl Default for Machine {
    fn default() -> Self {
        Self::new(MachineConfig::default())
    }
}

impl Machine {
    /// A machine at the origin in the configured modes.
    pub fn new(config: MachineConfig) -> Self {
        Self {
            logical: [0.0; AXES],
            physical: [0.0; AXES],
            relative_axes: false,
            e_mode: config.extrusion,
            inches: false,
            plane: Plane::Xy,
            feed_mm_s: DEFAULT_FEED_MM_S,
            speed_factor: 1.0,
            flow_factor: 1.0,
            volumetric: config.volumetric_diameter_mm.is_some(),
            volumetric_diameter_mm: config
                .volumetric_diameter_mm
                .unwrap_or(DEFAULT_VOLUMETRIC_DIAMETER_MM),
            retracted: false,
            retract_mm: config.retract_mm,
            retract_feed_mm_s: config.retract_feed_mm_s,
            unretract_extra_mm: 0.0,
            unretract_feed_mm_s: config.retract_feed_mm_s,
            tool: 0,
            klipper: config.klipper,
            motors_on: false,
        }
    }

    /// Current machine position.
    pub fn position(&self) -> &Pos {
        &self.physical
    }

    /// Current logical (G-code) position.
    pub fn logical_position(&self) -> &Pos {
        &self.logical
    }

    /// Whether relative positioning (`G91`) is in force.
    pub fn relative_positioning(&self) -> bool {
        self.relative_axes
    }

    /// Extrusion mode in force for E words.
    pub fn extrusion_mode(&self) -> ExtrusionMode {
        if self.relative_axes {
            ExtrusionMode::Relative
        } else {
            self.e_mode
        }
    }

    /// Filament (mm) one unit of the E words stands for now: the `M221` flow factor, over the
    /// filament's cross-section where E words are volumes (`M200`). Writers of new E words
    /// divide the filament they mean by it.
    pub fn filament_per_e_unit(&self) -> f64 {
        let area = self
            .volumetric
            .then(|| filament_area(self.volumetric_diameter_mm))
            .flatten();
        area.map_or(self.flow_factor, |a| self.flow_factor / a)
    }

    /// Modal feed rate, mm/s, before the `M220` override.
    pub fn feed_mm_s(&self) -> f64 {
        self.feed_mm_s
    }

    /// Active tool.
    pub fn tool(&self) -> u16 {
        self.tool
    }

    fn unit(&self) -> f64 {
        if self.inches {
            25.4
        } else {
            1.0
        }
    }

    /// A heater target from `S` (or `R`), if it is a temperature at all: targets outside
    /// [`TEMPERATURE_RANGE_C`] are corruption and are ignored with a warning, so no energy
    /// figure can become infinite.
    fn temperature_target(
        &self,
        line_no: u32,
        p: &crate::gcode::Params,
        warnings: &mut Warnings,
    ) -> Option<f64> {
        let target = p.get(b'S').or_else(|| p.get(b'R'))?;
        if TEMPERATURE_RANGE_C.contains(&target) {
            Some(target)
        } else {
            warnings.push(
                line_no,
                format!(
                    "temperature {target:.3e} °C ignored (accepted: {} to {} °C)",
                    TEMPERATURE_RANGE_C.start(),
                    TEMPERATURE_RANGE_C.end()
                ),
            );
            None
        }
    }

    /// Applies one parsed line; `line_no` is used in warnings and events.
    pub fn apply(
        &mut self,
        line_no: u32,
        line: &Line<'_>,
        warnings: &mut Warnings,
    ) -> Option<Event> {
        match line.command {
            Command::Code(code) => self.apply_code(line_no, code, line, warnings),
            // Klipper extended commands change no motion state modelled here (limits are read
            // by the planner; SET_GCODE_OFFSET-style shifts do not change relative motion).
            Command::Extended(_) | Command::None | Command::Bare => None,
        }
    }

    fn apply_code(
        &mut self,
        line_no: u32,
        code: Code,
        line: &Line<'_>,
        warnings: &mut Warnings,
    ) -> Option<Event> {
        match code.letter {
            b'G' => {
                let event = self.apply_g(line_no, code, line, warnings);
                self.motors_on |= matches!(event, Some(Event::Move(_)));
                event
            }
            b'M' => self.apply_m(line_no, code.number, line, warnings),
            b'T' => {
                self.tool = code.number;
                None
            }
            _ => None,
        }
    }

    /// A `G` code: moves, dwells, firmware retraction and the modal settings.
    fn apply_g(
        &mut self,
        line_no: u32,
        code: Code,
        line: &Line<'_>,
        warnings: &mut Warnings,
    ) -> Option<Event> {
        let p = &line.params;
        match (code.number, code.sub) {
            (0..=3, None) => self.motion(line_no, code.number, line, warnings),
            (4, None) => dwell(line_no, p, self.klipper, warnings),
            (10, None) if !p.has(b'P') && !p.has(b'L') => self.firmware_retract(line_no, true),
            (11, None) => self.firmware_retract(line_no, false),
            (17, None) => {
                self.plane = Plane::Xy;
                None
            }
            (18, None) => {
                self.plane = Plane::Zx;
                None
            }
            (19, None) => {
                self.plane = Plane::Yz;
                None
            }
            (20, None) => {
                self.inches = true;
                None
            }
            (21, None) => {
                self.inches = false;
                None
            }
            (28, None) => self.home(line_no, line),
            (90, None) => {
                self.relative_axes = false;
                None
            }
            (91, None) => {
                self.relative_axes = true;
                None
            }
            (92, None) => {
                self.set_position(line_no, line, warnings);
                None
            }
            (5, _) => {
                warnings.push(
                    line_no,
                    "G5 Bézier moves are not modelled; the move is skipped",
                );
                None
            }
            _ => None,
        }
    }

    /// An `M` code: extrusion mode, heaters, fans, retraction settings and overrides.
    fn apply_m(
        &mut self,
        line_no: u32,
        number: u16,
        line: &Line<'_>,
        warnings: &mut Warnings,
    ) -> Option<Event> {
        let p = &line.params;
        let heater = match number {
            104 | 109 => Some(Heater::Hotend(p.get(b'T').map_or(self.tool, to_u16))),
            140 | 190 => Some(Heater::Bed),
            141 | 191 => Some(Heater::Chamber),
            _ => None,
        };
        if let Some(heater) = heater {
            let target = self.temperature_target(line_no, p, warnings)?;
            return Some(Event::Temperature {
                heater,
                target_c: target,
                wait: matches!(number, 109 | 190 | 191),
            });
        }
        match number {
            82 => self.e_mode = ExtrusionMode::Absolute,
            83 => self.e_mode = ExtrusionMode::Relative,
            106 => {
                return Some(Event::Fan {
                    index: p.get(b'P').map_or(0, to_u16),
                    speed: fan_speed(p.get(b'S').unwrap_or(255.0)),
                })
            }
            107 => {
                return Some(Event::Fan {
                    index: p.get(b'P').map_or(0, to_u16),
                    speed: 0.0,
                })
            }
            207 => {
                if let Some(s) = p.get(b'S').filter(|s| (0.0..=1000.0).contains(s)) {
                    self.retract_mm = s * self.unit();
                }
                if let Some(f) = p.get(b'F').filter(|f| *f > 0.0) {
                    self.retract_feed_mm_s = f * self.unit() / 60.0;
                }
            }
            208 => {
                if let Some(s) = p.get(b'S').filter(|s| (-1000.0..=1000.0).contains(s)) {
                    self.unretract_extra_mm = s * self.unit();
                }
                if let Some(f) = p.get(b'F').filter(|f| *f > 0.0) {
                    self.unretract_feed_mm_s = f * self.unit() / 60.0;
                }
            }
            220 | 221 => self.set_override(line_no, number, p.get(b'S'), warnings),
            200 if !self.klipper => self.set_volumetric(p.get(b'D'), p.get(b'S')),
            // Klipper's M400 waits for the queue to drain: a dwell of no time, which stops the
            // look-ahead as a heater wait does.
            400 if self.klipper => return Some(Event::Dwell(0.0)),
            // Klipper's M84/M18 stops the toolhead and, if a motor was on, waits
            // KLIPPER_MOTORS_OFF_S around turning them off.
            18 | 84 if self.klipper => {
                let on = std::mem::take(&mut self.motors_on);
                return Some(Event::Dwell(if on { KLIPPER_MOTORS_OFF_S } else { 0.0 }));
            }
            _ => {}
        }
        None
    }

    /// `M200`: a diameter `d` (`D`) over 0 reads E words as volumes of that filament, `D0`
    /// as millimetres; `S0` switches volume off and `S1` on with the last diameter (Marlin 2;
    /// RepRapFirmware takes `D` alone). A diameter past any filament's is ignored.
    fn set_volumetric(&mut self, d: Option<f64>, s: Option<f64>) {
        if let Some(d) = d.filter(|d| (0.0..=MAX_FILAMENT_DIAMETER_MM).contains(d)) {
            self.volumetric = d > 0.0;
            if self.volumetric {
                self.volumetric_diameter_mm = d;
            }
        }
        if let Some(s) = s {
            self.volumetric = s != 0.0;
        }
    }

    /// `M220 S` (speed factor) or `M221 S` (flow factor), in percent.
    fn set_override(&mut self, line_no: u32, number: u16, s: Option<f64>, warnings: &mut Warnings) {
        let Some(s) = s else { return };
        if number == 220 {
            if OVERRIDE_RANGE_PERCENT.contains(&s) {
                self.speed_factor = s / 100.0;
            } else {
                warnings.push(
                    line_no,
                    format!("M220 S{s} ignored (accepted: 1 to 1000 %)"),
                );
            }
        } else if s == 0.0 || OVERRIDE_RANGE_PERCENT.contains(&s) {
            self.flow_factor = s / 100.0;
        } else {
            warnings.push(
                line_no,
                format!("M221 S{s} ignored (accepted: 0 or 1 to 1000 %)"),
            );
        }
    }

    fn set_feed(&mut self, line_no: u32, line: &Line<'_>, warnings: &mut Warnings) {
        if let Some(f) = line.params.get(b'F') {
            if f > 0.0 {
                self.feed_mm_s = f * self.unit() / 60.0;
            } else {
                warnings.push(
                    line_no,
                    format!("feed rate F{f} is not positive; previous feed rate kept"),
                );
            }
        }
    }

    /// Sets the axes a motion command names in `target` (the logical position before it) to
    /// where the command goes; returns the first coordinate (in axis order) beyond
    /// [`MAX_COORDINATE`], if any.
    ///
    /// Only the axes the line names are checked: every other axis keeps its logical position,
    /// which is always within range (each way of setting it, here, in `G92` and in `G28`,
    /// checks or zeroes it). (`target` is filled in place: a position is 80 bytes, and a
    /// returned one is copied more than once on the per-move path.)
    fn target(&self, line: &Line<'_>, target: &mut Pos) -> Result<(), f64> {
        // The axis words present, in alphabetical order (a line names two or three of ten).
        let mut out_of_range = false;
        for (letter, v) in line.params.numbers_in(AXIS_WORDS) {
            let i = axis_of(letter);
            let v = if LINEAR[i] { v * self.unit() } else { v };
            let relative = if i == axis::E {
                self.extrusion_mode() == ExtrusionMode::Relative
            } else {
                self.relative_axes
            };
            target[i] = if relative { self.logical[i] + v } else { v };
            out_of_range |= target[i].abs() > MAX_COORDINATE;
        }
        if out_of_range {
            // Report the first in axis order.
            let named = line.params.numbered();
            for (i, letter) in AXIS_LETTERS.iter().enumerate() {
                if named & letter_bit(*letter) != 0 && target[i].abs() > MAX_COORDINATE {
                    return Err(target[i]);
                }
            }
        }
        Ok(())
    }

    /// Moves the state to `target` (logical).
    fn go_to(&mut self, target: &Pos) {
        let flow = self.filament_per_e_unit();
        for (i, ((phys, logical), t)) in self
            .physical
            .iter_mut()
            .zip(&self.logical)
            .zip(target)
            .enumerate()
        {
            let delta = t - logical;
            *phys += if i == axis::E { delta * flow } else { delta };
        }
        self.logical = *target;
    }

    fn motion(
        &mut self,
        line_no: u32,
        g: u16,
        line: &Line<'_>,
        warnings: &mut Warnings,
    ) -> Option<Event> {
        self.set_feed(line_no, line, warnings);
        if line.params.has_bare_word() {
            warnings.push(line_no, "axis word without a value ignored");
        }
        let mut target = self.logical;
        match self.target(line, &mut target) {
            Ok(()) => {}
            Err(bad) => {
                warnings.push(
                    line_no,
                    format!(
                        "coordinate {bad:e} out of range (|v| > {MAX_COORDINATE:e}); line ignored"
                    ),
                );
                return None;
            }
        }
        let mut kind = match g {
            0 => MoveKind::Rapid,
            1 => MoveKind::Linear,
            _ => match self.arc(line_no, g == 2, &target, line, warnings) {
                Some(arc) => MoveKind::Arc(arc),
                None => MoveKind::Linear,
            },
        };
        let from = self.physical;
        self.go_to(&target);
        let to = self.physical;
        let d = |i: usize| to[i] - from[i];
        let straight = (d(0).powi(2) + d(1).powi(2) + d(2).powi(2)).sqrt();
        let length_mm = match &kind {
            MoveKind::Arc(a) => {
                let (_, _, h) = a.plane.axes();
                a.length(d(h))
            }
            _ => straight,
        };
        if !length_mm.is_finite() {
            warnings.push(line_no, "move length is not finite; move skipped");
            return None;
        }
        // A move with a straight length cannot end where it started: only others need the
        // comparison of every axis.
        if straight == 0.0 && !matches!(kind, MoveKind::Arc(_)) && from == to {
            return None;
        }
        if let MoveKind::Arc(a) = &kind {
            // Klipper still cuts a helix of no planar length into pieces along its rise.
            let rise = d(a.plane.axes().2);
            if a.planar_length() <= 1e-12 && !(self.klipper && rise != 0.0) {
                kind = MoveKind::Linear;
            }
        }
        Some(Event::Move(Move {
            line: line_no,
            kind,
            from,
            to,
            feed_mm_s: self.feed_mm_s * self.speed_factor,
            length_mm,
        }))
    }

    fn arc(
        &self,
        line_no: u32,
        clockwise: bool,
        target: &Pos,
        line: &Line<'_>,
        warnings: &mut Warnings,
    ) -> Option<Arc> {
        let (a0, a1, _) = self.plane.axes();
        let (l0, l1) = self.plane.offset_letters();
        let u = self.unit();
        let p = &line.params;
        let spec = if let Some(r) = p.get(b'R') {
            ArcSpec::Radius(r * u)
        } else if p.has(l0) || p.has(l1) {
            ArcSpec::Offsets(p.get(l0).unwrap_or(0.0) * u, p.get(l1).unwrap_or(0.0) * u)
        } else {
            warnings.push(
                line_no,
                "arc without I/J/K or R; treated as a straight move",
            );
            return None;
        };
        let too_big = match spec {
            ArcSpec::Radius(r) => r.abs() > MAX_COORDINATE,
            ArcSpec::Offsets(i, j) => i.abs() > MAX_COORDINATE || j.abs() > MAX_COORDINATE,
        };
        if too_big {
            warnings.push(
                line_no,
                "arc radius or centre out of range; treated as a straight move",
            );
            return None;
        }
        // Klipper has no `P` (turns), and sweeps as `arc::klipper_sweep` says.
        let turns = match p.get(b'P') {
            Some(t) if !self.klipper => t.clamp(1.0, 1000.0) as u32,
            _ => 1,
        };
        let start = [self.logical[a0], self.logical[a1]];
        let end = [target[a0], target[a1]];
        let arc =
            Arc::new(self.plane, start, end, spec, clockwise, turns).map(|(arc, bad)| match spec {
                ArcSpec::Offsets(i, j) if self.klipper => {
                    let sweep = arc::klipper_sweep(start, end, (i, j), clockwise);
                    (Arc { sweep, ..arc }, bad)
                }
                _ => (arc, bad),
            });
        match arc {
            Ok((arc, _)) if arc.radius > MAX_ARC_MM || arc.planar_length() > MAX_ARC_MM => {
                warnings.push(
                    line_no,
                    format!(
                        "arc of radius {:.0} mm and length {:.0} mm is larger than any printer \
                         (over {MAX_ARC_MM} mm); treated as a straight move",
                        arc.radius,
                        arc.planar_length()
                    ),
                );
                None
            }
            Ok((arc, mismatch)) => {
                if mismatch {
                    warnings.push(line_no, "arc end point is not on the circle through its start; radius from the start point used");
                }
                Some(arc)
            }
            Err(reason) => {
                warnings.push(
                    line_no,
                    format!("invalid arc ({reason}); treated as a straight move"),
                );
                None
            }
        }
    }

    fn firmware_retract(&mut self, line_no: u32, retract: bool) -> Option<Event> {
        if retract == self.retracted {
            return None;
        }
        self.retracted = retract;
        let (amount, feed) = if retract {
            (-self.retract_mm, self.retract_feed_mm_s)
        } else {
            (
                self.retract_mm + self.unretract_extra_mm,
                self.unretract_feed_mm_s,
            )
        };
        let from = self.physical;
        self.physical[axis::E] += amount;
        Some(Event::Move(Move {
            line: line_no,
            kind: MoveKind::FirmwareRetract,
            from,
            to: self.physical,
            feed_mm_s: feed,
            length_mm: 0.0,
        }))
    }

    /// `G28`: the named axes (all of X, Y, Z if none) go to 0. Timed as a move to 0 at the
    /// modal feed rate, as PrusaSlicer's estimator does; real homing is slower near the switch,
    /// but its approach dominates.
    fn home(&mut self, line_no: u32, line: &Line<'_>) -> Option<Event> {
        let any = [axis::X, axis::Y, axis::Z]
            .iter()
            .any(|&i| line.params.has(AXIS_LETTERS[i]));
        let from = self.physical;
        for i in [axis::X, axis::Y, axis::Z] {
            if !any || line.params.has(AXIS_LETTERS[i]) {
                self.logical[i] = 0.0;
                self.physical[i] = 0.0;
            }
        }
        let to = self.physical;
        let d = |i: usize| to[i] - from[i];
        let length_mm = (d(0) * d(0) + d(1) * d(1) + d(2) * d(2)).sqrt();
        (length_mm > 0.0).then_some(Event::Move(Move {
            line: line_no,
            kind: MoveKind::Home,
            from,
            to,
            feed_mm_s: self.feed_mm_s * self.speed_factor,
            length_mm,
        }))
    }

    fn set_position(&mut self, line_no: u32, line: &Line<'_>, warnings: &mut Warnings) {
        let mut any = false;
        for (i, letter) in AXIS_LETTERS.iter().enumerate() {
            if let Some(v) = line.params.get(*letter) {
                let v = if LINEAR[i] { v * self.unit() } else { v };
                any = true;
                if v.abs() > MAX_COORDINATE {
                    warnings.push(
                        line_no,
                        format!("G92 {}{v} out of range; ignored", *letter as char),
                    );
                    continue;
                }
                self.logical[i] = v;
            }
        }
        if !any {
            // Bare G92 zeroes every axis (Marlin, RepRapFirmware).
            self.logical = [0.0; AXES];
        }
    }
}

/// A `G4` dwell: `S` seconds or `P` milliseconds (Klipper: only `P`, and a dwell of none is
/// still a stop); `None` for none or one out of range.
fn dwell(line_no: u32, p: &Params, klipper: bool, warnings: &mut Warnings) -> Option<Event> {
    let secs = match (p.get(b'S').filter(|_| !klipper), p.get(b'P')) {
        (Some(s), _) => s,
        (None, Some(ms)) => ms / 1000.0,
        _ => 0.0,
    };
    if !(0.0..=MAX_DWELL_S).contains(&secs) {
        warnings.push(
            line_no,
            format!("dwell of {secs} s ignored (accepted: 0 to {MAX_DWELL_S} s)"),
        );
        return None;
    }
    // Klipper's G4 waits for the look-ahead to empty even when it dwells no time (`G4 S2`,
    // `G4 P0`): the toolhead stops there.
    (secs > 0.0 || klipper).then_some(Event::Dwell(secs))
}

/// Fan speed of `M106 S`, 0..=1: RepRapFirmware accepts 0..1 fractions; Marlin and Klipper
/// take 0..255.
fn fan_speed(s: f64) -> f64 {
    let speed = if s < 1.0 || (s <= 1.0 && s.fract() != 0.0) {
        s
    } else {
        s / 255.0
    };
    speed.clamp(0.0, 1.0)
}

fn to_u16(v: f64) -> u16 {
    v.clamp(0.0, f64::from(u16::MAX)) as u16
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::parse_line;

    fn run(src: &str, config: MachineConfig) -> (Machine, Vec<Event>, Warnings) {
        let mut m = Machine::new(config);
        let mut w = Warnings::default();
        let mut events = Vec::new();
        for (i, l) in src.lines().enumerate() {
            let line = parse_line(l.as_bytes()).expect(l);
            if let Some(e) = m.apply(i as u32 + 1, &line, &mut w) {
                events.push(e);
            }
        }
        (m, events, w)
    }

    fn moves(events: &[Event]) -> Vec<Move> {
        events
            .iter()
            .filter_map(|e| {
                if let Event::Move(m) = e {
                    Some(*m)
                } else {
                    None
                }
            })
            .collect()
    }

    #[test]
    fn an_arc_larger_than_any_printer_is_a_straight_move_with_a_warning() {
        // Radius 1e8 mm: its 0.6 Gm of path would be cut into the most segments an arc gets.
        let src =
            "G1 X0 Y0 F600\nG2 X10 Y0 I5 J100000000 E1\nG2 X20 Y0 I5 J0 E1\nG3 X0 Y0 I0 J9000 P2";
        let (_, ev, w) = run(src, MachineConfig::default());
        // (The first line goes nowhere: the machine starts at 0, 0.)
        let mv = moves(&ev);
        assert!(matches!(mv[0].kind, MoveKind::Linear));
        assert_eq!(mv[0].length_mm, 10.0);
        // A bed-sized arc stays an arc; two turns of 9 m radius (113 m) do not.
        assert!(matches!(mv[1].kind, MoveKind::Arc(_)));
        assert!(matches!(mv[2].kind, MoveKind::Linear));
        let (w, _) = w.into_parts();
        let lines: Vec<u32> = w.iter().map(|w| w.line).collect();
        assert_eq!(lines, [2, 4]);
        assert!(
            w[0].message.contains("larger than any printer"),
            "{}",
            w[0].message
        );
    }

    #[test]
    fn klipper_dwells_only_on_p_and_stops_at_every_g4_and_m400() {
        let src = "G4 S2\nG4 P500\nM400";
        let dwells = |klipper| {
            let config = MachineConfig {
                klipper,
                ..MachineConfig::default()
            };
            let (_, ev, _) = run(src, config);
            ev.iter()
                .map(|e| match e {
                    Event::Dwell(s) => *s,
                    _ => f64::NAN,
                })
                .collect::<Vec<f64>>()
        };
        assert_eq!(
            dwells(false),
            [2.0, 0.5],
            "Marlin: S seconds, P ms, M400 no event"
        );
        assert_eq!(
            dwells(true),
            [0.0, 0.5, 0.0],
            "Klipper: S no dwell but a stop, P ms, M400 a stop"
        );
    }

    #[test]
    fn absolute_and_relative_positioning() {
        let (m, ev, _) = run(
            "G1 X10 Y0 F600\nG91\nG1 X5 Y5\nG90\nG1 X0 Y0",
            MachineConfig::default(),
        );
        let mv = moves(&ev);
        assert_eq!(mv.len(), 3);
        assert_eq!(mv[1].to[axis::X], 15.0);
        assert_eq!(mv[1].feed_mm_s, 10.0);
        assert!((mv[1].length_mm - 50f64.sqrt()).abs() < 1e-12);
        assert_eq!(m.position()[axis::X], 0.0);
    }

    #[test]
    fn extrusion_modes_g92_and_flow() {
        let src = "M83\nG1 X1 E1\nG1 X2 E1\nM82\nG92 E0\nG1 X3 E2\nM221 S50\nG1 X4 E4\nG91\nG1 X1 E1\nG90\nG1 X6 E5";
        let (m, ev, _) = run(src, MachineConfig::default());
        let e: Vec<f64> = moves(&ev).iter().map(Move::extrusion).collect();
        assert_eq!(e, vec![1.0, 1.0, 2.0, 1.0, 0.5, 0.0]);
        assert_eq!(m.position()[axis::E], 5.5);
    }

    /// `M200 D1.75`: a volume of π·1.75²/4 mm³ is 1 mm of filament; `D0` and `S0` read
    /// millimetres again, `S1` volume with the last diameter; Klipper has no `M200`.
    #[test]
    fn volumetric_extrusion_reads_e_as_cubic_millimetres() {
        let area = std::f64::consts::PI * 1.75 * 1.75 / 4.0;
        let src = format!(
            "M83\nM200 D1.75\nG1 X1 E{area}\nM200 D0\nG1 X2 E1\nM200 S1\nG1 X3 E{a2}\n\
             M221 S50\nG1 X4 E{area}\nM200 S0\nG1 X5 E1",
            a2 = 2.0 * area
        );
        let e = |config| {
            let (m, ev, _) = run(&src, config);
            let e: Vec<f64> = moves(&ev).iter().map(Move::extrusion).collect();
            (e, m.filament_per_e_unit())
        };
        let (marlin, unit) = e(MachineConfig::default());
        for (got, want) in marlin.iter().zip([1.0, 1.0, 2.0, 0.5, 0.5]) {
            assert!((got - want).abs() < 1e-12, "{marlin:?}");
        }
        assert_eq!(unit, 0.5);
        let klipper = MachineConfig {
            klipper: true,
            ..MachineConfig::default()
        };
        let (ignored, _) = e(klipper);
        assert!((ignored[0] - area).abs() < 1e-12, "{ignored:?}");
        // A volumetric flavour: volume from the first line, until the file says otherwise.
        let flavour = MachineConfig {
            volumetric_diameter_mm: Some(2.85),
            ..MachineConfig::default()
        };
        let (m, ev, _) = run("M83\nG1 X1 E6.379\nM200 D0\nG1 X2 E1", flavour);
        let e: Vec<f64> = moves(&ev).iter().map(Move::extrusion).collect();
        let big = std::f64::consts::PI * 2.85 * 2.85 / 4.0;
        assert!((e[0] - 6.379 / big).abs() < 1e-12 && e[1] == 1.0, "{e:?}");
        assert_eq!(m.filament_per_e_unit(), 1.0);
    }

    #[test]
    fn inches_and_feed_override() {
        let (_, ev, _) = run("G20\nM220 S200\nG1 X1 F60", MachineConfig::default());
        let mv = moves(&ev);
        assert_eq!(mv[0].to[axis::X], 25.4);
        assert!((mv[0].feed_mm_s - 2.0 * 25.4).abs() < 1e-12);
    }

    #[test]
    fn arcs_lengths_helix_and_turns() {
        let (_, ev, w) = run(
            "G1 X10 Y0 F600\nG3 X0 Y10 I-10 J0 Z2\nG2 X0 Y10 I0 J-10 P2",
            MachineConfig::default(),
        );
        assert!(w.list().is_empty(), "{:?}", w.list());
        let mv = moves(&ev);
        let quarter = 10.0 * std::f64::consts::FRAC_PI_2;
        assert!((mv[1].length_mm - quarter.hypot(2.0)).abs() < 1e-9);
        assert!((mv[2].length_mm - 2.0 * std::f64::consts::TAU * 10.0).abs() < 1e-9);
    }

    #[test]
    fn invalid_arc_becomes_a_warned_straight_move() {
        let (_, ev, w) = run("G2 X10 Y0 R1", MachineConfig::default());
        assert_eq!(w.list().len(), 1);
        assert_eq!(w.list()[0].line, 1);
        assert!(matches!(moves(&ev)[0].kind, MoveKind::Linear));
    }

    #[test]
    fn firmware_retraction_is_net_zero() {
        let (m, ev, _) = run("M207 S2 F1200\nG10\nG10\nG11", MachineConfig::default());
        let e: Vec<f64> = moves(&ev).iter().map(Move::extrusion).collect();
        assert_eq!(e, vec![-2.0, 2.0]);
        assert_eq!(m.position()[axis::E], 0.0);
        assert!((moves(&ev)[0].feed_mm_s - 20.0).abs() < 1e-12);
    }

    #[test]
    fn homing_temperatures_fans_dwell() {
        let (_, ev, _) = run(
            "G1 X5 Y5 Z5\nG28 X\nM109 S210\nM140 S60\nM106 S127.5\nM106 S0.5\nM107\nG4 P500\nG4 S2",
            MachineConfig::default(),
        );
        assert!(
            matches!(ev[1], Event::Move(Move { kind: MoveKind::Home, to, from, .. }) if to[axis::X] == 0.0 && to[axis::Y] == 5.0 && from[axis::X] == 5.0)
        );
        assert!(matches!(
            ev[2],
            Event::Temperature {
                heater: Heater::Hotend(0),
                wait: true,
                ..
            }
        ));
        assert!(matches!(
            ev[3],
            Event::Temperature {
                heater: Heater::Bed,
                wait: false,
                ..
            }
        ));
        assert!(matches!(ev[4], Event::Fan { speed, .. } if (speed - 0.5).abs() < 1e-12));
        assert!(matches!(ev[5], Event::Fan { speed, .. } if (speed - 0.5).abs() < 1e-12));
        assert!(matches!(ev[6], Event::Fan { speed, .. } if speed == 0.0));
        assert!(matches!(ev[7], Event::Dwell(s) if s == 0.5));
        assert!(matches!(ev[8], Event::Dwell(s) if s == 2.0));
    }

    #[test]
    fn extra_axes_are_tracked() {
        let (m, ev, _) = run("G1 X1 B30 C-720 U2", MachineConfig::default());
        assert_eq!(m.position()[axis::B], 30.0);
        assert_eq!(m.position()[axis::C], -720.0);
        assert_eq!(m.position()[7], 2.0);
        assert_eq!(moves(&ev).len(), 1);
    }

    #[test]
    fn bad_feed_is_warned_and_ignored() {
        let (m, _, w) = run("G1 X1 F0\nG1 X2 F-5", MachineConfig::default());
        assert_eq!(w.list().len(), 2);
        assert_eq!(m.feed_mm_s(), DEFAULT_FEED_MM_S);
    }
}
