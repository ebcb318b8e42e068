//! What must be known before the first move is planned: the firmware flavour, whether the file
//! drives Klipper, the slicer's machine-limit settings (PrusaSlicer writes its settings block at
//! the end of the file) and the slicer's own time estimate. Only the head and the tail of the
//! file are read, so the cost does not grow with the file.

use crate::gcode::{parse_line, Command, Lines};

/// Bytes read at each end of the file.
const WINDOW: usize = 512 * 1024;

/// Facts gathered before planning.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Prescan {
    /// Declared flavour (`marlin2`, `klipper`, `reprapfirmware`…), lower case.
    pub flavor: Option<String>,
    /// The file uses Klipper extended commands (`SET_VELOCITY_LIMIT`, `EXCLUDE_OBJECT_*`, macros).
    pub klipper_commands: bool,
    /// `; key = value` machine-limit settings of the slicer's settings block.
    pub limit_settings: Vec<(String, String)>,
    /// The slicer's own print-time estimate, s.
    pub slicer_time_s: Option<f64>,
    /// The printer model the slicer's profile names (PrusaSlicer's `printer_model`).
    pub printer_model: Option<String>,
}

impl Prescan {
    /// Whether the file was sliced for one of Prusa's printers (PrusaSlicer's `printer_model`
    /// of the MINI, MK2 to MK4, XL or CORE One families), whose firmware cuts arcs by chord
    /// deviation ([`crate::plan::ArcRule::ChordDeviation`]).
    pub fn for_prusa_printer(&self) -> bool {
        self.printer_model.as_deref().is_some_and(|m| {
            let m = m.to_ascii_uppercase();
            ["MK2", "MK3", "MK4", "MINI", "XL", "COREONE", "IX"]
                .iter()
                .any(|family| m.starts_with(family))
        })
    }
}

/// Reads the head and tail of `input`.
pub fn prescan(input: &[u8]) -> Prescan {
    let mut p = Prescan::default();
    let head_end = input.len().min(WINDOW);
    let tail_start = input.len().saturating_sub(WINDOW).max(head_end);
    // Start the tail at a line boundary.
    let tail_start = input[tail_start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(input.len(), |i| tail_start + i + 1);
    let mut cura_time = None;
    let mut cura_elapsed = None;
    for part in [&input[..head_end], &input[tail_start.min(input.len())..]] {
        for raw in Lines::new(part) {
            let Ok(line) = parse_line(raw.text) else {
                continue;
            };
            if let Command::Extended(_) = line.command {
                p.klipper_commands = true;
            }
            let Some(comment) = line.comment else {
                continue;
            };
            let Ok(c) = std::str::from_utf8(comment) else {
                continue;
            };
            let c = c.trim();
            if let Some((key, value)) = c.split_once(" = ") {
                let key = key.trim();
                if key.starts_with("machine_max_") || key.starts_with("machine_min_") {
                    p.limit_settings
                        .push((key.to_string(), value.trim().to_string()));
                } else if key == "gcode_flavor" {
                    p.flavor
                        .get_or_insert_with(|| value.trim().to_ascii_lowercase());
                } else if key == "printer_model" && !value.trim().is_empty() {
                    p.printer_model
                        .get_or_insert_with(|| value.trim().to_string());
                } else if key == "estimated printing time (normal mode)" {
                    p.slicer_time_s = parse_duration(value);
                }
            } else if let Some(v) = c.strip_prefix("FLAVOR:") {
                p.flavor
                    .get_or_insert_with(|| v.trim().to_ascii_lowercase());
            } else if let Some(v) = c.strip_prefix("TIME_ELAPSED:") {
                cura_elapsed = v.trim().parse::<f64>().ok();
            } else if let Some(v) = c.strip_prefix("TIME:") {
                cura_time = cura_time.or(v.trim().parse::<f64>().ok());
            } else if let Some(v) = c.strip_prefix("Print Time:") {
                p.slicer_time_s = p.slicer_time_s.or(v.trim().parse::<f64>().ok());
            } else if let Some(v) = c.strip_prefix("--- print time:") {
                p.slicer_time_s = p.slicer_time_s.or(v
                    .trim()
                    .trim_end_matches("---")
                    .trim()
                    .trim_end_matches('s')
                    .parse()
                    .ok());
            }
        }
    }
    // Cura: the last elapsed time is the engine's own total; `;TIME:` can be a placeholder.
    p.slicer_time_s = p.slicer_time_s.or(cura_elapsed).or(cura_time);
    p
}

/// Parses `1d 2h 3m 4s`-style durations (PrusaSlicer), in seconds.
pub fn parse_duration(s: &str) -> Option<f64> {
    let mut total = 0.0;
    let mut any = false;
    for part in s.split_whitespace() {
        let (num, unit) = part.split_at(part.find(|c: char| c.is_ascii_alphabetic())?);
        let v: f64 = num.parse().ok()?;
        total += v * match unit {
            "d" => 86400.0,
            "h" => 3600.0,
            "m" => 60.0,
            "s" => 1.0,
            _ => return None,
        };
        any = true;
    }
    any.then_some(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations() {
        assert_eq!(parse_duration("1h 6m 40s"), Some(4000.0));
        assert_eq!(parse_duration("31m 3s"), Some(1863.0));
        assert_eq!(parse_duration("1d 0h 0m 1s"), Some(86401.0));
        assert_eq!(parse_duration("soon"), None);
    }

    #[test]
    fn settings_flavour_and_estimates() {
        let src = b";FLAVOR:Marlin\n;TIME:6666\nG1 X1\n;TIME_ELAPSED:10.5\n;TIME_ELAPSED:24439.7\n; machine_max_jerk_x = 8,8\n";
        let p = prescan(src);
        assert_eq!(p.flavor.as_deref(), Some("marlin"));
        assert_eq!(p.slicer_time_s, Some(24439.7));
        assert_eq!(
            p.limit_settings,
            vec![("machine_max_jerk_x".to_string(), "8,8".to_string())]
        );
        assert!(!p.klipper_commands);
        let p = prescan(
            b"SET_VELOCITY_LIMIT ACCEL=500\n; estimated printing time (normal mode) = 7m 19s\n",
        );
        assert!(p.klipper_commands);
        assert_eq!(p.slicer_time_s, Some(439.0));
    }
}
