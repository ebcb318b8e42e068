//! A Klipper `printer.cfg`, read for what bears on motion: `[printer]`, `[extruder]`,
//! `[gcode_arcs]` and `[firmware_retraction]`, following `[include …]` as Klipper does.
//!
//! The format is Klipper's (Python's `configparser` as Klipper sets it up): `[section]` headers,
//! `key: value` or `key = value`, comments after `#` or `;` (inline ones after whitespace),
//! indented continuation lines (G-code macros), and the `#*#` lines of an auto-saved
//! `SAVE_CONFIG` block, which Klipper reads as config too. A section given twice (in two
//! included files, say) is merged, the later value winning. Sections that do not bear on
//! motion are skipped unread; a bad value in one that does is an error with file and line.

use serde::{Deserialize, Serialize};

use super::limits::{Limit, LimitSource, Limits};

/// How a reader follows `[include pattern]`: given the pattern and the including file's name,
/// the files it names as `(name, text)`, in Klipper's order (sorted glob matches).
pub type Include<'a> = dyn FnMut(&str, &str) -> Result<Vec<(String, String)>, String> + 'a;

/// Includes nested deeper than this are taken for a cycle Klipper would also refuse.
const MAX_INCLUDE_DEPTH: usize = 32;

/// A problem in a config file, with where it is.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{file}:{line}: {reason}")]
pub struct KlipperConfigError {
    /// The file, as it was named to the reader.
    pub file: String,
    /// 1-based line (0: the file as a whole).
    pub line: u32,
    /// What is wrong.
    pub reason: String,
}

/// What Klipper's version does with `max_accel_to_decel`: older Klipper (v0.12, and the
/// firmware of Creality's K1 family) takes it as an absolute rate; current Klipper (since
/// 2025-08) ignores it and smooths with `minimum_cruise_ratio` only.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum KlipperVersion {
    /// v0.12 and earlier: `max_accel_to_decel` (default half of `max_accel`).
    Legacy,
    /// Klipper since 2025-08: `minimum_cruise_ratio` (default 0.5).
    #[default]
    Current,
}

/// The motion settings of a Klipper config. `None`: not in the file (Klipper's default then
/// applies, or the profile's where Klipper has none).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct KlipperConfig {
    /// `[printer] kinematics`.
    pub kinematics: Option<String>,
    /// `[printer] max_velocity`, mm/s.
    pub max_velocity: Option<f64>,
    /// `[printer] max_accel`, mm/s².
    pub max_accel: Option<f64>,
    /// `[printer] minimum_cruise_ratio`.
    pub minimum_cruise_ratio: Option<f64>,
    /// `[printer] max_accel_to_decel`, mm/s² (older Klipper).
    pub max_accel_to_decel: Option<f64>,
    /// `[printer] square_corner_velocity`, mm/s.
    pub square_corner_velocity: Option<f64>,
    /// `[printer] max_z_velocity`, mm/s.
    pub max_z_velocity: Option<f64>,
    /// `[printer] max_z_accel`, mm/s².
    pub max_z_accel: Option<f64>,
    /// `[extruder] max_extrude_only_velocity`, mm/s.
    pub max_extrude_only_velocity: Option<f64>,
    /// `[extruder] max_extrude_only_accel`, mm/s².
    pub max_extrude_only_accel: Option<f64>,
    /// `[extruder] instantaneous_corner_velocity`, mm/s.
    pub instantaneous_corner_velocity: Option<f64>,
    /// `[extruder] nozzle_diameter`, mm.
    pub nozzle_diameter: Option<f64>,
    /// `[extruder] filament_diameter`, mm.
    pub filament_diameter: Option<f64>,
    /// `[gcode_arcs] resolution`, mm (the section present without it: Klipper's 1 mm).
    pub arc_resolution: Option<f64>,
    /// `[firmware_retraction] retract_length`, mm.
    pub retract_length: Option<f64>,
    /// `[firmware_retraction] retract_speed`, mm/s.
    pub retract_speed: Option<f64>,
    /// `[firmware_retraction] unretract_extra_length`, mm.
    pub unretract_extra_length: Option<f64>,
    /// `[firmware_retraction] unretract_speed`, mm/s.
    pub unretract_speed: Option<f64>,
}

/// One `key: value` of a section that bears on motion, with where it was read.
struct Entry<'t> {
    section: &'t str,
    key: &'t str,
    value: &'t str,
}

impl KlipperConfig {
    /// Reads a config given as text, named `file` in errors. `include(pattern, from)` returns
    /// the files an `[include pattern]` in file `from` names, as `(name, text)` in Klipper's
    /// order (sorted glob matches); it is not called for a config without includes.
    pub fn parse(
        file: &str,
        text: &str,
        include: &mut Include<'_>,
    ) -> Result<Self, KlipperConfigError> {
        let mut config = Self::default();
        let mut stack = vec![file.to_string()];
        config.read(file, text, include, &mut stack)?;
        Ok(config)
    }

    /// Reads a config that includes nothing (the JS API's text, a test's).
    pub fn parse_text(text: &str) -> Result<Self, KlipperConfigError> {
        Self::parse("printer.cfg", text, &mut |pattern, _| {
            Err(format!(
                "[include {pattern}] cannot be followed here: pass the included text in place"
            ))
        })
    }

    fn read(
        &mut self,
        file: &str,
        text: &str,
        include: &mut Include<'_>,
        stack: &mut Vec<String>,
    ) -> Result<(), KlipperConfigError> {
        let error = |line: u32, reason: String| KlipperConfigError {
            file: file.to_string(),
            line,
            reason,
        };
        let mut section = "";
        for (number, raw) in config_lines(text) {
            let line = strip_comment(raw);
            if line.trim().is_empty() || raw.starts_with([' ', '\t']) {
                // Blank, or a continuation line (a macro's body): nothing for motion.
                continue;
            }
            let line = line.trim();
            if let Some(header) = line.strip_prefix('[') {
                let name = header
                    .strip_suffix(']')
                    .ok_or_else(|| error(number, format!("section header '{line}' lacks ']'")))?
                    .trim();
                if let Some(pattern) = name.strip_prefix("include ") {
                    self.include(file, pattern.trim(), number, include, stack)?;
                    section = "";
                } else {
                    section = name;
                    if name == "gcode_arcs" {
                        // Klipper's resolution when the section is there without the key (a
                        // `resolution` read later replaces it).
                        self.arc_resolution.get_or_insert(1.0);
                    }
                }
                continue;
            }
            let Some((key, value)) = line.split_once([':', '=']) else {
                return Err(error(
                    number,
                    format!("'{line}' is neither a section nor a key"),
                ));
            };
            let entry = Entry {
                section,
                key: key.trim(),
                value: value.trim(),
            };
            self.set(&entry).map_err(|reason| error(number, reason))?;
        }
        Ok(())
    }

    /// Follows an `[include pattern]` of `file`.
    fn include(
        &mut self,
        file: &str,
        pattern: &str,
        line: u32,
        include: &mut Include<'_>,
        stack: &mut Vec<String>,
    ) -> Result<(), KlipperConfigError> {
        let error = |reason: String| KlipperConfigError {
            file: file.to_string(),
            line,
            reason,
        };
        let files = include(pattern, file).map_err(error)?;
        for (name, text) in files {
            if stack.contains(&name) || stack.len() >= MAX_INCLUDE_DEPTH {
                return Err(error(format!(
                    "[include {pattern}] includes {name} in a cycle"
                )));
            }
            stack.push(name.clone());
            self.read(&name, &text, include, stack)?;
            stack.pop();
        }
        Ok(())
    }

    /// Takes one key of a section that bears on motion; other sections and keys are skipped.
    fn set(&mut self, e: &Entry<'_>) -> Result<(), String> {
        let slot = match (e.section, e.key) {
            ("printer", "kinematics") => {
                self.kinematics = Some(e.value.to_string());
                return Ok(());
            }
            ("printer", "max_velocity") => &mut self.max_velocity,
            ("printer", "max_accel") => &mut self.max_accel,
            ("printer", "minimum_cruise_ratio") => &mut self.minimum_cruise_ratio,
            ("printer", "max_accel_to_decel") => &mut self.max_accel_to_decel,
            ("printer", "square_corner_velocity") => &mut self.square_corner_velocity,
            ("printer", "max_z_velocity") => &mut self.max_z_velocity,
            ("printer", "max_z_accel") => &mut self.max_z_accel,
            ("extruder", "max_extrude_only_velocity") => &mut self.max_extrude_only_velocity,
            ("extruder", "max_extrude_only_accel") => &mut self.max_extrude_only_accel,
            ("extruder", "instantaneous_corner_velocity") => {
                &mut self.instantaneous_corner_velocity
            }
            ("extruder", "nozzle_diameter") => &mut self.nozzle_diameter,
            ("extruder", "filament_diameter") => &mut self.filament_diameter,
            ("gcode_arcs", "resolution") => &mut self.arc_resolution,
            ("firmware_retraction", "retract_length") => &mut self.retract_length,
            ("firmware_retraction", "retract_speed") => &mut self.retract_speed,
            ("firmware_retraction", "unretract_extra_length") => &mut self.unretract_extra_length,
            ("firmware_retraction", "unretract_speed") => &mut self.unretract_speed,
            _ => return Ok(()),
        };
        *slot = Some(number(e)?);
        Ok(())
    }

    /// The limits this config gives a Klipper machine, over `base` (the profile's) where the
    /// config is silent and Klipper has no default of its own. `max_velocity` and `max_accel`
    /// are the toolhead's, as `SET_VELOCITY_LIMIT` sets them.
    pub fn limits(&self, base: &Limits, version: KlipperVersion) -> Limits {
        let mut l = base.clone();
        let put = |limit: &mut Limit, value: Option<f64>| {
            if let Some(value) = value {
                *limit = Limit {
                    value,
                    source: LimitSource::PrinterConfig,
                };
            }
        };
        for i in 0..2 {
            put(&mut l.max_feedrate[i], self.max_velocity);
            put(&mut l.max_acceleration[i], self.max_accel);
        }
        put(&mut l.acceleration, self.max_accel);
        put(&mut l.travel_acceleration, self.max_accel);
        put(&mut l.max_feedrate[2], self.max_z_velocity);
        put(&mut l.max_acceleration[2], self.max_z_accel);
        put(&mut l.max_feedrate[3], self.max_extrude_only_velocity);
        put(&mut l.max_acceleration[3], self.max_extrude_only_accel);
        put(&mut l.retract_acceleration, self.max_extrude_only_accel);
        // Klipper's own default is 5 mm/s; the config's wins.
        put(
            &mut l.square_corner_velocity,
            self.square_corner_velocity.or(Some(5.0)),
        );
        put(&mut l.arc_segment_mm, self.arc_resolution);
        if let Some(value) = self.instantaneous_corner_velocity {
            l.instantaneous_corner_velocity = Some(Limit {
                value,
                source: LimitSource::PrinterConfig,
            });
        }
        let accel = self.max_accel.unwrap_or(l.acceleration.value);
        match version {
            KlipperVersion::Current => {
                put(
                    &mut l.minimum_cruise_ratio,
                    self.minimum_cruise_ratio.or(Some(0.5)),
                );
                put(&mut l.accel_to_decel, Some(0.0));
            }
            KlipperVersion::Legacy => {
                put(
                    &mut l.accel_to_decel,
                    self.max_accel_to_decel.or(Some(accel * 0.5)),
                );
            }
        }
        l
    }
}

/// Deserializes an optional config given as its text (the JS API's `klipper_config`) or in
/// its parsed form (what the CLI reads from disk, includes followed).
pub(crate) fn text_or_parsed<'de, D>(de: D) -> Result<Option<KlipperConfig>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Given {
        Text(String),
        Parsed(Box<KlipperConfig>),
    }
    match Option::<Given>::deserialize(de)? {
        None => Ok(None),
        Some(Given::Parsed(config)) => Ok(Some(*config)),
        Some(Given::Text(text)) => KlipperConfig::parse_text(&text)
            .map(Some)
            .map_err(serde::de::Error::custom),
    }
}

/// The lines of a config with their 1-based numbers, the `#*#` lines of an auto-saved block
/// read as config (Klipper's `SAVE_CONFIG` writes its overrides there).
fn config_lines(text: &str) -> impl Iterator<Item = (u32, &str)> {
    text.lines().enumerate().map(|(i, line)| {
        let line = match line.strip_prefix("#*#") {
            // The block's own header is a comment.
            Some(saved) if saved.contains("SAVE_CONFIG") => "",
            Some(saved) => saved.trim_start(),
            None => line,
        };
        (u32::try_from(i + 1).unwrap_or(u32::MAX), line)
    })
}

/// A line without its comment: a `#` or `;` at the start, or after whitespace.
fn strip_comment(line: &str) -> &str {
    let bytes = line.as_bytes();
    let cut = bytes.iter().enumerate().position(|(i, &b)| {
        (b == b'#' || b == b';') && (i == 0 || bytes[i - 1].is_ascii_whitespace())
    });
    cut.map_or(line, |i| &line[..i])
}

/// A value that must be a finite, non-negative number.
fn number(e: &Entry<'_>) -> Result<f64, String> {
    match e.value.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "[{}] {}: '{}' is not a non-negative number",
            e.section, e.key, e.value
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::MachineProfile;

    const CFG: &str = "\
[mcu]
serial: /tmp/klipper_host_mcu

[printer]
kinematics: cartesian
max_velocity: 500   # mm/s
max_accel = 3000
square_corner_velocity: 5
minimum_cruise_ratio: 0.5
max_z_velocity: 15
max_z_accel: 350

[extruder]
max_extrude_only_velocity: 120
max_extrude_only_accel: 1500
nozzle_diameter: 0.400
filament_diameter: 1.750

[gcode_macro START_PRINT]
gcode:
    G28
    M83 ; relative
  max_accel: 1

[gcode_arcs]
resolution: 0.1

#*# <---------------------- SAVE_CONFIG ---------------------->
#*# [printer]
#*# max_accel = 4000
";

    #[test]
    fn motion_sections_are_read_and_the_saved_block_wins() {
        let c = KlipperConfig::parse_text(CFG).unwrap();
        assert_eq!(c.kinematics.as_deref(), Some("cartesian"));
        assert_eq!(c.max_velocity, Some(500.0));
        assert_eq!(
            c.max_accel,
            Some(4000.0),
            "SAVE_CONFIG's value, not 3000 nor the macro's 1"
        );
        assert_eq!(c.max_z_accel, Some(350.0));
        assert_eq!(c.max_extrude_only_velocity, Some(120.0));
        assert_eq!(c.filament_diameter, Some(1.75));
        assert_eq!(c.arc_resolution, Some(0.1));
        assert_eq!(c.retract_length, None);
        let bare = KlipperConfig::parse_text("[gcode_arcs]\n[printer]\nmax_accel: 1\n").unwrap();
        assert_eq!(
            bare.arc_resolution,
            Some(1.0),
            "Klipper's default resolution"
        );
        assert_eq!(
            KlipperConfig::parse_text("[printer]\n")
                .unwrap()
                .arc_resolution,
            None
        );
    }

    #[test]
    fn limits_follow_the_config_and_the_version() {
        let c = KlipperConfig::parse_text(CFG).unwrap();
        let base = MachineProfile::preset("voron-klipper").unwrap().limits;
        let l = c.limits(&base, KlipperVersion::Current);
        assert_eq!(l.acceleration.value, 4000.0);
        assert_eq!(l.acceleration.source, LimitSource::PrinterConfig);
        assert_eq!(l.max_feedrate[2].value, 15.0);
        assert_eq!(l.arc_segment_mm.value, 0.1);
        assert_eq!(
            (l.minimum_cruise_ratio.value, l.accel_to_decel.value),
            (0.5, 0.0)
        );
        let legacy = c.limits(&base, KlipperVersion::Legacy);
        assert_eq!(
            legacy.accel_to_decel.value, 2000.0,
            "half of max_accel by default"
        );
    }

    #[test]
    fn includes_are_followed_and_a_cycle_is_an_error() {
        let mut files = |pattern: &str, _: &str| -> Result<Vec<(String, String)>, String> {
            match pattern {
                "limits/*.cfg" => Ok(vec![
                    ("limits/a.cfg".into(), "[printer]\nmax_accel: 7000\n".into()),
                    (
                        "limits/b.cfg".into(),
                        "[printer]\nmax_velocity: 300\n".into(),
                    ),
                ]),
                "loop.cfg" => Ok(vec![("loop.cfg".into(), "[include loop.cfg]\n".into())]),
                _ => Err(format!("no file {pattern}")),
            }
        };
        let text = "[printer]\nmax_accel: 1000\n[include limits/*.cfg]\n";
        let c = KlipperConfig::parse("printer.cfg", text, &mut files).unwrap();
        assert_eq!((c.max_accel, c.max_velocity), (Some(7000.0), Some(300.0)));
        let e = KlipperConfig::parse("printer.cfg", "[include loop.cfg]\n", &mut files);
        let e = e.unwrap_err();
        assert_eq!((e.file.as_str(), e.line), ("loop.cfg", 1));
        assert!(e.reason.contains("cycle"), "{e}");
        let e = KlipperConfig::parse("printer.cfg", "\n[include nope.cfg]\n", &mut files);
        assert_eq!(e.unwrap_err().line, 2);
    }

    #[test]
    fn a_bad_value_names_its_file_and_line() {
        let e = KlipperConfig::parse_text("[printer]\nmax_accel: fast\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert_eq!(
            e.to_string(),
            "printer.cfg:2: [printer] max_accel: 'fast' is not a non-negative number"
        );
        // A bad value where motion does not look is not our business.
        assert!(KlipperConfig::parse_text("[fan]\nmax_power: loud\n").is_ok());
    }
}
