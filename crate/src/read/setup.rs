//! What every pass over a file needs before its first line: validated options, the extrusion
//! mode, the head/tail prescan, the machine profile, junction model and starting limits.

use serde::Deserialize;

use super::prescan;
use crate::energy::EnergyOptions;
use crate::error::{Error, ErrorKind, Warnings};
use crate::gcode::{self, Strictness};
use crate::machine::{self, ExtrusionMode, Machine, MachineConfig};
use crate::plan::klipper_config::{self, KlipperConfig, KlipperVersion};
use crate::plan::{ArcRule, FeedUnits, JunctionModel, Limit, LimitSource, MachineProfile};

/// Options of `analyze`, and of how every other job reads its input. Every field is optional
/// in JSON.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, serde::Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct AnalyzeOptions {
    /// Stop at the first malformed line instead of warning.
    pub strict: bool,
    /// Filament diameter, mm (default: from the file, else 1.75).
    pub filament_diameter_mm: Option<f64>,
    /// Filament density, g/cm³ (default: from the file, else 1.24, PLA).
    pub density_g_cm3: Option<f64>,
    /// Force the starting extrusion mode instead of inferring it.
    pub extrusion_mode: Option<ExtrusionModeOption>,
    /// Built-in machine preset (see `plan::profiles::PRESETS`); default: chosen from the file's
    /// flavour.
    pub machine: Option<String>,
    /// A whole machine profile (wins over `machine`).
    pub machine_profile: Option<MachineProfile>,
    /// Junction model; default: the profile's, or Klipper's for files that drive Klipper.
    pub junction_model: Option<JunctionModel>,
    /// Length of the segments arcs are split into, mm (default: the profile's, 1 mm).
    pub arc_segment_mm: Option<f64>,
    /// Energy model settings (coefficients, material, powers, emission factors); default:
    /// [`EnergyOptions::default`].
    pub energy: Option<EnergyOptions>,
    /// The printer's Klipper config (`printer.cfg`): the file runs on Klipper with these
    /// limits, over the profile's. In JSON, the config's text or its parsed form.
    #[serde(deserialize_with = "klipper_config::text_or_parsed")]
    #[cfg_attr(test, ts(type = "string | KlipperConfig | null"))]
    pub klipper_config: Option<KlipperConfig>,
    /// How that Klipper reads `max_accel_to_decel` (default: current Klipper).
    pub klipper_version: Option<KlipperVersion>,
    /// A Marlin printer's own settings as its `M503` prints them (`M201`, `M203`, `M204`,
    /// `M205`…), applied before the file, over the profile's limits and the slicer's settings
    /// block. Not with `klipper_config` (a Klipper printer's settings are its config).
    pub machine_gcode: Option<String>,
}

/// Starting extrusion mode, as an option.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum ExtrusionModeOption {
    /// `M82`.
    Absolute,
    /// `M83`.
    Relative,
}

/// The machine, junction model and limits a file is planned with, and why.
fn choose_machine(
    options: &AnalyzeOptions,
    pre: &prescan::Prescan,
) -> Result<(MachineProfile, JunctionModel, String), Error> {
    let klipper = options.klipper_config.is_some()
        || pre.klipper_commands
        || pre
            .flavor
            .as_deref()
            .is_some_and(|f| f.contains("klipper") || f.contains("creality os"));
    let invalid = |reason| Error::new(0, 0, ErrorKind::InvalidOption { reason });
    let (profile, why) = if let Some(p) = &options.machine_profile {
        (
            p.clone(),
            format!("profile '{}' given in the options", p.name),
        )
    } else if let Some(name) = &options.machine {
        let p = MachineProfile::preset(name)
            .ok_or_else(|| invalid("unknown machine preset (see plan::profiles::PRESETS)"))?;
        (p, format!("preset '{name}' given in the options"))
    } else if klipper {
        let why = if options.klipper_config.is_some() {
            "a Klipper config given in the options"
        } else {
            "the file drives Klipper"
        };
        (
            MachineProfile::preset("voron-klipper").ok_or_else(|| invalid("preset missing"))?,
            why.to_string(),
        )
    } else {
        (
            MachineProfile::preset("prusa-mk3s").ok_or_else(|| invalid("preset missing"))?,
            "default for Marlin-style files (classic jerk, as slicer estimators assume)"
                .to_string(),
        )
    };
    let (model, why) = match options.junction_model {
        Some(m) => (m, format!("{why}; junction model given in the options")),
        None if klipper => (JunctionModel::Klipper, why),
        None => (profile.junction, why),
    };
    Ok((profile, model, why))
}

/// What every pass over a file needs before its first line: validated options, the extrusion
/// mode, the head/tail prescan, the machine profile, junction model and starting limits.
/// Held by the [`Reader`](super::Reader), so every pass reads a file the same way.
#[derive(Debug)]
pub(crate) struct Setup {
    pub strictness: Strictness,
    pub mode: ExtrusionMode,
    pub source: machine::ModeSource,
    pub warnings: Warnings,
    pub pre: prescan::Prescan,
    pub profile: MachineProfile,
    pub model: JunctionModel,
    pub model_reason: String,
    pub limits: crate::plan::Limits,
    pub units: FeedUnits,
    /// Firmware retraction length and speed the printer's config sets, if it does.
    pub retract: (Option<f64>, Option<f64>),
    /// The Klipper version a config was given for (it decides how `SET_VELOCITY_LIMIT`
    /// reads); `None` without a config, where the file's commands are read as they come.
    pub klipper_version: Option<KlipperVersion>,
    /// The filament diameter E words are volumes of from the first line (a volumetric
    /// flavour, [`volumetric_flavour`]), mm.
    pub volumetric: Option<f64>,
}

impl Setup {
    /// Whether the file runs on Klipper, which reads some commands its own way.
    pub fn klipper(&self) -> bool {
        self.model == JunctionModel::Klipper
    }

    /// The machine a pass starts with: the file's extrusion mode, everything else at its
    /// power-on state.
    pub fn machine(&self) -> Machine {
        let default = MachineConfig::default();
        Machine::new(MachineConfig {
            extrusion: self.mode,
            retract_mm: self.retract.0.unwrap_or(default.retract_mm),
            retract_feed_mm_s: self.retract.1.unwrap_or(default.retract_feed_mm_s),
            klipper: self.klipper(),
            volumetric_diameter_mm: self.volumetric,
        })
    }
}

/// Builds the [`Setup`] of a pass over `input`.
pub(crate) fn prepare(input: &[u8], options: &AnalyzeOptions) -> Result<Setup, Error> {
    validate_options(options)?;
    let strictness = if options.strict {
        Strictness::Strict
    } else {
        Strictness::Lenient
    };
    gcode::check_encoding(input)?;
    let inference = machine::infer_extrusion_mode(input);
    let (mode, source) = match options.extrusion_mode {
        Some(ExtrusionModeOption::Absolute) => {
            (ExtrusionMode::Absolute, machine::ModeSource::Explicit)
        }
        Some(ExtrusionModeOption::Relative) => {
            (ExtrusionMode::Relative, machine::ModeSource::Explicit)
        }
        None => (inference.mode, inference.source),
    };
    let mut warnings = Warnings::default();
    if source == machine::ModeSource::Inferred {
        warnings.push(
            0,
            format!(
                "the file never sets M82/M83 before extruding; read as {} extrusion ({} of {} E values increase)",
                if mode == ExtrusionMode::Absolute { "absolute" } else { "relative" },
                inference.increasing,
                inference.samples
            ),
        );
    }

    let pre = prescan::prescan(input);
    let (profile, model, model_reason) = choose_machine(options, &pre)?;
    let mut limits = starting_limits(options, &profile, &pre)?;
    let machine_given = options.machine_profile.is_some() || options.machine.is_some();
    if !machine_given && model != JunctionModel::Klipper {
        // The default profile's planner, with arcs cut as the file's own firmware cuts them:
        // upstream Marlin 2.1 unless the file was sliced for a Prusa printer.
        limits.arc_rule = if pre.for_prusa_printer() {
            ArcRule::ChordDeviation
        } else {
            ArcRule::CircleSegments
        };
    }
    let klipper_version = options
        .klipper_config
        .as_ref()
        .map(|_| options.klipper_version.unwrap_or_default());
    let retract = options
        .klipper_config
        .as_ref()
        .map(|c| (c.retract_length, c.retract_speed));
    if let Some(seg) = options.arc_segment_mm {
        limits.arc_segment_mm = Limit {
            value: seg,
            source: LimitSource::Option,
        };
    }
    let volumetric = volumetric_diameter(options, &pre, &mut warnings);
    let units = if pre.flavor.as_deref() == Some("reprapfirmware") {
        FeedUnits::PerMinute
    } else {
        FeedUnits::PerSecond
    };
    Ok(Setup {
        strictness,
        mode,
        source,
        warnings,
        pre,
        profile,
        model,
        model_reason,
        limits,
        units,
        retract: retract.unwrap_or_default(),
        klipper_version,
        volumetric,
    })
}

/// The filament diameter E words are volumes of from the first line, where the file's
/// flavour writes them so ([`volumetric_flavour`]): the options', else 1.75 mm, said in a
/// warning (Cura writes no diameter in these files).
fn volumetric_diameter(
    options: &AnalyzeOptions,
    pre: &prescan::Prescan,
    warnings: &mut Warnings,
) -> Option<f64> {
    volumetric_flavour(pre.flavor.as_deref()).then(|| {
        let d = options
            .filament_diameter_mm
            .unwrap_or(machine::DEFAULT_VOLUMETRIC_DIAMETER_MM);
        warnings.push(
            0,
            format!(
                "E words read as volumes (mm³) of {d} mm filament: the file's flavour is \
                 Cura's volumetric one (set another diameter with the filament diameter option)"
            ),
        );
        d
    })
}

/// Whether a file of `flavor` (its header's, lower case) writes E as volume from its first
/// line: Cura's `Marlin(Volumetric)` and `UltiGCode` flavours, which leave the printer's own
/// volumetric mode to convert it.
fn volumetric_flavour(flavor: Option<&str>) -> bool {
    flavor.is_some_and(|f| f.contains("volumetric") || f == "ultigcode")
}

/// The limits before the file's first line: Klipper's config alone when given (a slicer's
/// `machine_max_*` block describes some other machine); otherwise the profile's, then the
/// slicer's settings block (the best evidence of the printer a file without a config was
/// sliced for, Klipper or not), then the printer's own `M503` settings when given.
fn starting_limits(
    options: &AnalyzeOptions,
    profile: &MachineProfile,
    pre: &prescan::Prescan,
) -> Result<crate::plan::Limits, Error> {
    if let Some(config) = &options.klipper_config {
        return Ok(config.limits(&profile.limits, options.klipper_version.unwrap_or_default()));
    }
    let mut limits = profile.limits.clone();
    for (key, value) in &pre.limit_settings {
        limits.apply_setting(key, value);
    }
    if let Some(text) = &options.machine_gcode {
        limits
            .apply_machine_settings(text, FeedUnits::PerSecond)
            .map_err(|(line, reason)| {
                Error::new(0, 0, ErrorKind::MachineSettings { line, reason })
            })?;
    }
    Ok(limits)
}

fn validate_options(o: &AnalyzeOptions) -> Result<(), Error> {
    let positive = |v: Option<f64>| v.is_none_or(|x| x.is_finite() && x > 0.0);
    if let Some(reason) = o.energy.as_ref().and_then(|e| e.validate().err()) {
        return Err(Error::new(0, 0, ErrorKind::InvalidOption { reason }));
    }
    if !positive(o.filament_diameter_mm)
        || !positive(o.density_g_cm3)
        || !positive(o.arc_segment_mm)
    {
        return Err(Error::new(
            0,
            0,
            ErrorKind::InvalidOption {
                reason: "filament_diameter_mm, density_g_cm3 and arc_segment_mm must be positive numbers",
            },
        ));
    }
    if o.machine_gcode.is_some() && o.klipper_config.is_some() {
        return Err(Error::new(
            0,
            0,
            ErrorKind::InvalidOption {
                reason: "machine_gcode is a Marlin printer's M503 settings; a Klipper printer's are its klipper_config, give one of them",
            },
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule_of(text: &str, options: &AnalyzeOptions) -> ArcRule {
        prepare(text.as_bytes(), options)
            .expect("setup")
            .limits
            .arc_rule
    }

    #[test]
    fn arcs_are_cut_as_the_files_firmware_cuts_them() {
        let o = AnalyzeOptions::default();
        let generic = "; gcode_flavor = marlin2\nG1 X1 E1\n";
        let mk4 = "; gcode_flavor = marlin2\n; printer_model = MK4S\nG1 X1 E1\n";
        let unnamed = "; gcode_flavor = marlin2\n; printer_model = \nG1 X1 E1\n";
        assert_eq!(rule_of(generic, &o), ArcRule::CircleSegments);
        assert_eq!(rule_of(unnamed, &o), ArcRule::CircleSegments);
        assert_eq!(rule_of(mk4, &o), ArcRule::ChordDeviation);
        // A machine given keeps its own rule; Klipper cuts by its resolution (the rule unread).
        let given = AnalyzeOptions {
            machine: Some("prusa-mk3s".into()),
            ..AnalyzeOptions::default()
        };
        assert_eq!(rule_of(generic, &given), ArcRule::ChordDeviation);
        let klipper = "; gcode_flavor = klipper\nG1 X1 E1\n";
        assert_eq!(rule_of(klipper, &o), ArcRule::default());
    }
}
