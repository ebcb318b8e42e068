//! Machine profiles: the limits (and later the physical parameters) of known printers, as
//! built-in presets or JSON files.

use serde::{Deserialize, Serialize};

use super::limits::{ArcRule, JunctionModel, Limit, Limits};

/// A machine profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct MachineProfile {
    /// Short name (`prusa-mk3s`).
    pub name: String,
    /// What the machine is.
    pub description: String,
    /// Junction model its firmware uses.
    pub junction: JunctionModel,
    /// Motion limits.
    pub limits: Limits,
}

fn limits(
    feed: [f64; 4],
    accel_max: [f64; 4],
    accel: [f64; 3],
    jerk: [f64; 4],
    jd: f64,
    scv: f64,
    cruise_ratio: f64,
) -> Limits {
    let l4 = |v: [f64; 4]| v.map(Limit::profile);
    Limits {
        max_feedrate: l4(feed),
        max_acceleration: l4(accel_max),
        acceleration: Limit::profile(accel[0]),
        retract_acceleration: Limit::profile(accel[1]),
        travel_acceleration: Limit::profile(accel[2]),
        max_jerk: l4(jerk),
        junction_deviation: Limit::profile(jd),
        square_corner_velocity: Limit::profile(scv),
        minimum_cruise_ratio: Limit::profile(cruise_ratio),
        accel_to_decel: Limit::unset(),
        min_feedrate: Limit::profile(0.0),
        min_travel_feedrate: Limit::profile(0.0),
        arc_segment_mm: Limit::profile(1.0),
        arc_rule: ArcRule::ChordDeviation,
        instantaneous_corner_velocity: None,
    }
}

impl Limits {
    /// These limits with arcs cut by `rule`.
    fn with_arc_rule(self, rule: ArcRule) -> Self {
        Limits {
            arc_rule: rule,
            ..self
        }
    }
}

/// Names of the built-in presets.
pub const PRESETS: [&str; 4] = [
    "prusa-mk3s",
    "creality-ender3",
    "voron-klipper",
    "vtg-ldam-servo",
];

impl MachineProfile {
    /// A built-in preset by name.
    ///
    /// Values are the firmware defaults the machines ship with:
    /// - `prusa-mk3s`: Prusa firmware 3.x (classic jerk), normal mode, as in PrusaSlicer's
    ///   MK3S profile.
    /// - `creality-ender3`: Marlin 2 as configured by Creality for the Ender-3 (junction
    ///   deviation 0.08 mm, Marlin's default; arcs cut as upstream Marlin 2.1 cuts them).
    /// - `voron-klipper`: a Voron 2.4 on Klipper (`max_velocity 300`, `max_accel 3000`,
    ///   `square_corner_velocity 5`, `minimum_cruise_ratio 0.5`).
    /// - `vtg-ldam-servo`: the large-format ball-screw servo printer of the VTG paper (1000 ×
    ///   800 × 350 mm build volume); its limits are those of typical DC-servo ball-screw stages.
    pub fn preset(name: &str) -> Option<MachineProfile> {
        let (description, junction, limits) = match name {
            "prusa-mk3s" => (
                "Original Prusa i3 MK3S (Prusa firmware, classic jerk, normal mode)",
                JunctionModel::ClassicJerk,
                limits(
                    [200.0, 200.0, 12.0, 120.0],
                    [1000.0, 1000.0, 200.0, 5000.0],
                    [1250.0, 1250.0, 1250.0],
                    [8.0, 8.0, 0.4, 4.5],
                    0.02,
                    5.0,
                    0.5,
                ),
            ),
            "creality-ender3" => (
                "Creality Ender-3 (Marlin 2, junction deviation)",
                JunctionModel::JunctionDeviation,
                limits(
                    [500.0, 500.0, 5.0, 25.0],
                    [500.0, 500.0, 100.0, 5000.0],
                    [500.0, 500.0, 500.0],
                    [10.0, 10.0, 0.3, 5.0],
                    0.08,
                    5.0,
                    0.5,
                )
                .with_arc_rule(ArcRule::CircleSegments),
            ),
            "voron-klipper" => (
                "Voron 2.4 on Klipper (square-corner velocity)",
                JunctionModel::Klipper,
                limits(
                    [300.0, 300.0, 15.0, 120.0],
                    [3000.0, 3000.0, 350.0, 5000.0],
                    [3000.0, 3000.0, 3000.0],
                    [10.0, 10.0, 0.4, 5.0],
                    0.013,
                    5.0,
                    0.5,
                ),
            ),
            "vtg-ldam-servo" => (
                "Large-format ball-screw servo printer of the VTG paper (1000 × 800 × 350 mm)",
                JunctionModel::JunctionDeviation,
                limits(
                    [150.0, 150.0, 10.0, 60.0],
                    [800.0, 800.0, 100.0, 3000.0],
                    [500.0, 800.0, 800.0],
                    [5.0, 5.0, 0.3, 5.0],
                    0.05,
                    5.0,
                    0.5,
                ),
            ),
            _ => return None,
        };
        Some(MachineProfile {
            name: name.to_string(),
            description: description.to_string(),
            junction,
            limits,
        })
    }

    /// A profile from JSON (the serde form of [`MachineProfile`]).
    pub fn from_json(text: &str) -> Result<MachineProfile, serde_json::Error> {
        serde_json::from_str(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_exists_and_round_trips_through_json() {
        for name in PRESETS {
            let p = MachineProfile::preset(name).expect(name);
            let json = serde_json::to_string(&p).expect("json");
            assert_eq!(MachineProfile::from_json(&json).expect("parse"), p);
        }
        assert!(MachineProfile::preset("nope").is_none());
    }
}
