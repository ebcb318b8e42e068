//! Machine motion limits and where each one came from.
//!
//! Precedence, highest first: the file's own commands (`M201`, `M203`, `M204`, `M205`, `M566`,
//! Klipper's `SET_VELOCITY_LIMIT`), applied at the line where they appear, as firmware does;
//! the slicer's settings block (`; machine_max_acceleration_x = 9000,1000`, normal-mode column),
//! which describes the machine the file was sliced for; and the machine profile.

use serde::{Deserialize, Serialize};

use super::klipper_config::KlipperVersion;
use crate::gcode::Line;

/// Where a limit's current value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum LimitSource {
    /// The machine profile (preset or JSON).
    Profile,
    /// The slicer's settings block in the file.
    SlicerSettings,
    /// The printer's firmware configuration (Klipper's `printer.cfg`).
    PrinterConfig,
    /// The printer's own settings as Marlin's `M503` prints them (`--machine-gcode`).
    MachineSettings,
    /// A command in the file (`M201`…, `SET_VELOCITY_LIMIT`).
    Command,
    /// An option of the analysis.
    Option,
}

/// How junction speeds between consecutive moves are limited.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum JunctionModel {
    /// Marlin's (and Prusa firmware's) classic per-axis jerk, the logic of the thesis's
    /// Appendix A.
    ClassicJerk,
    /// Marlin 2's junction deviation, with its small-segment rule.
    JunctionDeviation,
    /// Klipper's square-corner velocity with `minimum_cruise_ratio`.
    Klipper,
}

/// How a Marlin-family firmware cuts `G2`/`G3` into straight segments (Klipper's
/// `[gcode_arcs]` cuts by its own rule, [`super::ArcCutting`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum ArcRule {
    /// Prusa's firmware: segments short enough to keep each chord within
    /// [`super::MAX_ARC_DEVIATION_MM`] of the arc and to run at least
    /// [`super::ARC_SEGMENTS_PER_SEC`], between [`super::MIN_ARC_SEGMENT_MM`] and
    /// `arc_segment_mm` ([`super::arc_segments`]).
    #[default]
    ChordDeviation,
    /// Upstream Marlin 2.1 as shipped (`MIN_ARC_SEGMENT_MM 0.1`, `MAX_ARC_SEGMENT_MM` the
    /// `arc_segment_mm`, `MIN_CIRCLE_SEGMENTS 72`, no `ARC_SEGMENTS_PER_SEC`): at least 72
    /// segments a full circle, no longer than the maximum, and where that makes them shorter
    /// than the minimum, as many of the minimum as fit ([`super::marlin_arc_segments`]).
    CircleSegments,
}

impl ArcRule {
    /// Whether it is the default (left out of reports, which then read as before it existed).
    pub fn is_default(&self) -> bool {
        *self == ArcRule::default()
    }
}

/// One limit value with its origin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Limit {
    /// The value (mm/s, mm/s², mm or a ratio).
    pub value: f64,
    /// Where it came from.
    pub source: LimitSource,
}

impl Limit {
    /// A profile value of 0, "not set".
    pub const fn unset() -> Self {
        Self::profile(0.0)
    }

    /// A profile value.
    pub const fn profile(value: f64) -> Self {
        Self {
            value,
            source: LimitSource::Profile,
        }
    }
}

/// The motion limits in force. Axis arrays are X, Y, Z, E.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Limits {
    /// Maximum feed rate per axis, mm/s (`M203`).
    pub max_feedrate: [Limit; 4],
    /// Maximum acceleration per axis, mm/s² (`M201`).
    pub max_acceleration: [Limit; 4],
    /// Acceleration for printing moves, mm/s² (`M204 P`, or `S`).
    pub acceleration: Limit,
    /// Acceleration for E-only moves, mm/s² (`M204 R`).
    pub retract_acceleration: Limit,
    /// Acceleration for travel moves, mm/s² (`M204 T`, or `S`).
    pub travel_acceleration: Limit,
    /// Classic jerk per axis, mm/s (`M205 X Y Z E`, RepRapFirmware `M566` in mm/min).
    pub max_jerk: [Limit; 4],
    /// Junction deviation, mm (`M205 J`).
    pub junction_deviation: Limit,
    /// Klipper square-corner velocity, mm/s.
    pub square_corner_velocity: Limit,
    /// Klipper `minimum_cruise_ratio`: a chain of moves is smoothed as if it sped up and
    /// braked at accel (1 − ratio). Used when `accel_to_decel` is 0.
    pub minimum_cruise_ratio: Limit,
    /// Older Klipper's `max_accel_to_decel`, mm/s², the smoothed rate itself (at most the
    /// acceleration in force); 0 when the cruise ratio applies instead. Creality's Klipper
    /// (K1 series) and the slicers written for it set it apart from the acceleration, before
    /// it (`SET_VELOCITY_LIMIT ACCEL_TO_DECEL=18000` then `M204 S20000`): as a ratio of the
    /// acceleration then in force it would mean something else.
    #[serde(default = "Limit::unset")]
    pub accel_to_decel: Limit,
    /// Minimum feed rate of printing moves, mm/s (`M205 S`).
    pub min_feedrate: Limit,
    /// Minimum feed rate of travel moves, mm/s (`M205 T`).
    pub min_travel_feedrate: Limit,
    /// Length of the straight segments arcs are split into, mm.
    pub arc_segment_mm: Limit,
    /// How a Marlin-family firmware cuts arcs into segments of at most `arc_segment_mm`.
    #[serde(default, skip_serializing_if = "ArcRule::is_default")]
    pub arc_rule: ArcRule,
    /// Klipper's `[extruder] instantaneous_corner_velocity`, mm/s: the largest step in filament
    /// speed a junction may ask of the extruder. Unset: Klipper's default,
    /// [`KLIPPER_INSTANT_CORNER_V`](super::junction::KLIPPER_INSTANT_CORNER_V) (and not in the
    /// report, which is unchanged for every file that sets no Klipper config).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instantaneous_corner_velocity: Option<Limit>,
}

/// Units of `M203`/`M566` feed rates: Marlin takes mm/s, RepRapFirmware mm/min.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedUnits {
    /// mm/s.
    PerSecond,
    /// mm/min.
    PerMinute,
}

fn set(limit: &mut Limit, value: Option<f64>, source: LimitSource) {
    if let Some(v) = value.filter(|v| v.is_finite() && *v >= 0.0) {
        *limit = Limit { value: v, source };
    }
}

impl Limits {
    /// Applies a Marlin printer's own settings, as its `M503` prints them (`echo:  M201 X1000
    /// Y1000 …`, `M203`, `M204`, `M205`; other lines, such as `M92` or `M301`, comments and a
    /// host terminal's `Send:`/`Recv:`/`ok` are skipped), before the file: they describe the machine the file runs on, where a
    /// slicer's settings block describes the one it was sliced for. Returns how many limit
    /// commands were applied, or the 1-based line and reason of a line that is not G-code.
    pub fn apply_machine_settings(
        &mut self,
        text: &str,
        units: FeedUnits,
    ) -> Result<usize, (u32, String)> {
        let mut applied = 0;
        for (i, raw) in text.lines().enumerate() {
            // As the printer prints it, or copied from a host's terminal (OctoPrint's `Recv:`).
            let mut l = raw.trim();
            while let Some(rest) = l.strip_prefix("Recv:").or_else(|| l.strip_prefix("echo:")) {
                l = rest.trim_start();
            }
            let chatter = ["ok", "Send:", "Recv:", ";", "//"];
            if l.is_empty() || chatter.iter().any(|c| l.starts_with(c)) {
                continue;
            }
            let line = crate::gcode::parse_line(l.as_bytes()).map_err(|e| {
                (
                    i as u32 + 1,
                    format!("{}, column {}: {raw}", e.kind, e.column),
                )
            })?;
            if self.apply_command(&line, units) {
                applied += 1;
            }
        }
        self.for_each_mut(|limit| {
            if limit.source == LimitSource::Command {
                limit.source = LimitSource::MachineSettings;
            }
        });
        Ok(applied)
    }

    /// Every limit, for a pass over all of them.
    fn for_each_mut(&mut self, mut f: impl FnMut(&mut Limit)) {
        let arrays = [
            &mut self.max_feedrate,
            &mut self.max_acceleration,
            &mut self.max_jerk,
        ];
        for array in arrays {
            array.iter_mut().for_each(&mut f);
        }
        for limit in [
            &mut self.acceleration,
            &mut self.retract_acceleration,
            &mut self.travel_acceleration,
            &mut self.junction_deviation,
            &mut self.square_corner_velocity,
            &mut self.minimum_cruise_ratio,
            &mut self.accel_to_decel,
            &mut self.min_feedrate,
            &mut self.min_travel_feedrate,
            &mut self.arc_segment_mm,
        ] {
            f(limit);
        }
        if let Some(l) = &mut self.instantaneous_corner_velocity {
            f(l);
        }
    }

    /// Applies a limit command; returns whether the line was one.
    ///
    /// Analysis asks this of every line: the test that rules out all other lines is inlined
    /// into the caller, the commands themselves are read out of line.
    #[inline]
    pub fn apply_command(&mut self, line: &Line<'_>, units: FeedUnits) -> bool {
        let candidate = match line.command {
            crate::gcode::Command::Code(code) => {
                code.letter == b'M' && matches!(code.number, 201 | 203 | 204 | 205 | 566)
            }
            crate::gcode::Command::Extended(_) => true,
            _ => false,
        };
        candidate && self.apply_limit_command(line, units)
    }

    /// Applies a limit command as Klipper reads it; returns whether the line was one. Klipper
    /// has no `M201`, `M203`, `M205` (its config sets those limits: the lines change nothing);
    /// its `M204` sets the toolhead's acceleration from `S`, or from the lower of `P` and `T`
    /// when both are given (`P` alone is ignored, as Klipper's `cmd_M204` does).
    /// `version`: the Klipper the file runs on, if known: v0.12 (and Creality's K1 firmware)
    /// reads `SET_VELOCITY_LIMIT ACCEL_TO_DECEL` and knows no `MINIMUM_CRUISE_RATIO`; Klipper
    /// since 2025-08 reads only the latter. Unknown: both, the one set last in force.
    #[inline]
    pub fn apply_klipper_command(
        &mut self,
        line: &Line<'_>,
        version: Option<KlipperVersion>,
    ) -> bool {
        match line.command {
            crate::gcode::Command::Code(code) if code.is(b'M', 204) => {
                let p = &line.params;
                let positive = |v: Option<f64>| v.filter(|v| *v > 0.0);
                let accel = positive(p.get(b'S'))
                    .or_else(|| Some(positive(p.get(b'P'))?.min(positive(p.get(b'T'))?)));
                set(&mut self.acceleration, accel, LimitSource::Command);
                set(&mut self.travel_acceleration, accel, LimitSource::Command);
                true
            }
            crate::gcode::Command::Extended(name)
                if name.eq_ignore_ascii_case(b"SET_VELOCITY_LIMIT") =>
            {
                self.apply_set_velocity_limit(line, version);
                true
            }
            _ => false,
        }
    }

    fn apply_limit_command(&mut self, line: &Line<'_>, units: FeedUnits) -> bool {
        if let Some(code) = line.code() {
            if code.letter != b'M' || code.sub.is_some() {
                return false;
            }
            return self.apply_m_code(code.number, line, units);
        }
        if let crate::gcode::Command::Extended(name) = line.command {
            if name.eq_ignore_ascii_case(b"SET_VELOCITY_LIMIT") {
                self.apply_set_velocity_limit(line, None);
                return true;
            }
        }
        false
    }

    /// `M201`, `M203`, `M204`, `M205` (Marlin) and `M566` (RepRapFirmware); `false` for any
    /// other M code.
    fn apply_m_code(&mut self, number: u16, line: &Line<'_>, units: FeedUnits) -> bool {
        let src = LimitSource::Command;
        let p = &line.params;
        let per_s = |v: Option<f64>| match units {
            FeedUnits::PerSecond => v,
            FeedUnits::PerMinute => v.map(|x| x / 60.0),
        };
        match number {
            201 => {
                for (i, l) in b"XYZE".iter().enumerate() {
                    set(&mut self.max_acceleration[i], p.get(*l), src);
                }
            }
            203 => {
                for (i, l) in b"XYZE".iter().enumerate() {
                    set(&mut self.max_feedrate[i], per_s(p.get(*l)), src);
                }
            }
            204 => {
                // Marlin: S sets printing and travel acceleration (legacy); P, R, T each.
                set(&mut self.acceleration, p.get(b'S'), src);
                set(&mut self.travel_acceleration, p.get(b'S'), src);
                set(&mut self.acceleration, p.get(b'P'), src);
                set(&mut self.retract_acceleration, p.get(b'R'), src);
                set(&mut self.travel_acceleration, p.get(b'T'), src);
            }
            205 => {
                for (i, l) in b"XYZE".iter().enumerate() {
                    set(&mut self.max_jerk[i], p.get(*l), src);
                }
                set(&mut self.min_feedrate, p.get(b'S'), src);
                set(&mut self.min_travel_feedrate, p.get(b'T'), src);
                set(&mut self.junction_deviation, p.get(b'J'), src);
            }
            566 => {
                // RepRapFirmware: jerk in mm/min.
                for (i, l) in b"XYZE".iter().enumerate() {
                    set(&mut self.max_jerk[i], p.get(*l).map(|v| v / 60.0), src);
                }
            }
            _ => return false,
        }
        true
    }

    /// Klipper's `SET_VELOCITY_LIMIT`, as `version` reads it (see
    /// [`Limits::apply_klipper_command`]).
    fn apply_set_velocity_limit(&mut self, line: &Line<'_>, version: Option<KlipperVersion>) {
        let src = LimitSource::Command;
        let num = |key: &str| {
            line.extended_arg(key)
                .and_then(|v| std::str::from_utf8(v).ok())
                .and_then(|v| v.parse::<f64>().ok())
        };
        if let Some(v) = num("VELOCITY") {
            // Klipper's `max_velocity`, the limit of the speed along the path; kept in the X
            // and Y slots (the planner reads it as the vector limit under Klipper's model).
            for limit in &mut self.max_feedrate[..2] {
                set(limit, Some(v), src);
            }
        }
        if let Some(a) = num("ACCEL") {
            // Klipper's toolhead acceleration: there are no per-axis X/Y limits.
            set(&mut self.acceleration, Some(a), src);
            set(&mut self.travel_acceleration, Some(a), src);
        }
        set(
            &mut self.square_corner_velocity,
            num("SQUARE_CORNER_VELOCITY"),
            src,
        );
        // Whichever of the two a file sets last is the one in force.
        let ratio = num("MINIMUM_CRUISE_RATIO").filter(|_| version != Some(KlipperVersion::Legacy));
        if let Some(ratio) = ratio {
            set(&mut self.minimum_cruise_ratio, Some(ratio), src);
            set(&mut self.accel_to_decel, Some(0.0), src);
        } else if version != Some(KlipperVersion::Current) {
            set(&mut self.accel_to_decel, num("ACCEL_TO_DECEL"), src);
        }
    }

    /// Applies one `; key = value` line of a slicer's settings block (PrusaSlicer, SuperSlicer,
    /// OrcaSlicer). Values with two columns (`9000,1000`) are normal and silent mode: the normal
    /// one is used.
    pub fn apply_setting(&mut self, key: &str, value: &str) {
        let src = LimitSource::SlicerSettings;
        let v = value
            .split(',')
            .next()
            .and_then(|s| s.trim().parse::<f64>().ok());
        let axis = |suffix: &str| match suffix {
            "x" => Some(0),
            "y" => Some(1),
            "z" => Some(2),
            "e" => Some(3),
            _ => None,
        };
        if let Some(a) = key.strip_prefix("machine_max_acceleration_") {
            match a {
                "extruding" => set(&mut self.acceleration, v, src),
                "retracting" => set(&mut self.retract_acceleration, v, src),
                "travel" => set(&mut self.travel_acceleration, v, src),
                _ => {
                    if let Some(i) = axis(a) {
                        set(&mut self.max_acceleration[i], v, src);
                    }
                }
            }
        } else if let Some(i) = key
            .strip_prefix("machine_max_feedrate_")
            // OrcaSlicer, Bambu Studio and Creality Print 5 name the same limit `machine_max_speed_`.
            .or_else(|| key.strip_prefix("machine_max_speed_"))
            .and_then(axis)
        {
            set(&mut self.max_feedrate[i], v, src);
        } else if let Some(i) = key.strip_prefix("machine_max_jerk_").and_then(axis) {
            set(&mut self.max_jerk[i], v, src);
        } else if key == "machine_min_extruding_rate" {
            set(&mut self.min_feedrate, v, src);
        } else if key == "machine_min_travel_rate" {
            set(&mut self.min_travel_feedrate, v, src);
        } else if key == "machine_max_junction_deviation" {
            set(&mut self.junction_deviation, v, src);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::profiles::MachineProfile;

    fn voron() -> Limits {
        MachineProfile::preset("voron-klipper")
            .expect("preset")
            .limits
    }

    #[test]
    fn accel_to_decel_is_a_rate_of_its_own_until_a_cruise_ratio_replaces_it() {
        // Creality Print for the K1: the rate first, then the acceleration it belongs to.
        let mut l = voron();
        for src in ["SET_VELOCITY_LIMIT ACCEL_TO_DECEL=18000", "M204 S20000"] {
            let line = crate::gcode::parse_line(src.as_bytes()).expect(src);
            assert!(l.apply_command(&line, FeedUnits::PerMinute), "{src}");
        }
        assert_eq!(l.accel_to_decel.value, 18000.0);
        assert_eq!(l.accel_to_decel.source, LimitSource::Command);
        assert_eq!(l.acceleration.value, 20000.0);
        let line =
            crate::gcode::parse_line(b"SET_VELOCITY_LIMIT MINIMUM_CRUISE_RATIO=0.3").expect("line");
        l.apply_command(&line, FeedUnits::PerMinute);
        assert_eq!(l.accel_to_decel.value, 0.0);
        assert_eq!(l.minimum_cruise_ratio.value, 0.3);
    }

    #[test]
    fn klipper_takes_m204_s_or_the_lower_of_p_and_t_and_no_m201_m203_m205() {
        let read = |src: &str| {
            let mut l = voron();
            let line = crate::gcode::parse_line(src.as_bytes()).expect(src);
            let taken = l.apply_klipper_command(&line, None);
            (taken, l)
        };
        let (taken, l) = read("M204 S4000 P1000 T500");
        assert!(taken);
        assert_eq!(
            (l.acceleration.value, l.travel_acceleration.value),
            (4000.0, 4000.0)
        );
        let (_, l) = read("M204 P1000 T1500");
        assert_eq!(
            (l.acceleration.value, l.travel_acceleration.value),
            (1000.0, 1000.0)
        );
        let (taken, l) = read("M204 P1000");
        assert!(taken);
        assert_eq!(l, voron(), "P alone is ignored");
        for src in ["M201 X100", "M203 X10", "M205 X1"] {
            assert_eq!(read(src), (false, voron()), "{src}");
        }
        let (_, l) = read("SET_VELOCITY_LIMIT ACCEL=7000");
        assert_eq!(l.acceleration.value, 7000.0);
    }

    #[test]
    fn prusa_and_orca_name_the_maximum_speeds_differently_and_both_are_read() {
        let mut prusa = voron();
        prusa.apply_setting("machine_max_feedrate_x", "500,200");
        let mut orca = voron();
        orca.apply_setting("machine_max_speed_x", "500,200");
        orca.apply_setting("machine_max_speed_e", " 50,25");
        for limits in [&prusa, &orca] {
            assert_eq!(limits.max_feedrate[0].value, 500.0, "normal-mode column");
            assert_eq!(limits.max_feedrate[0].source, LimitSource::SlicerSettings);
        }
        assert_eq!(orca.max_feedrate[3].value, 50.0);
        assert_ne!(prusa.max_feedrate[0].value, voron().max_feedrate[0].value);
        // Keys that only look alike change nothing.
        let mut other = voron();
        other.apply_setting("machine_max_speed_w", "1");
        other.apply_setting("travel_speed", "1");
        assert_eq!(other, voron());
    }
}
