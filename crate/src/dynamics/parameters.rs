//! Physical parameters of an axis drive and the machine presets.
//!
//! Two drive families map onto the same six coordinates `q = [x1, x2, x3, x4, θM, θS]` of the
//! VTG paper's lumped-mass model (section 2.1, Fig. 2):
//!
//! - [`BallScrew`]: the paper's drive. Servo motor → flexible coupling → ball screw held by a
//!   fixed bearing → nut on the slave pedestal → flexure hinges → working table. Masses, inertias
//!   and stiffnesses follow VTG eq. 1–9; the screw's axial and torsional stiffness fall as the nut
//!   moves away from the coupling (VTG eq. 5–6).
//! - [`Belt`]: the usual desktop printer. Stepper rotor (θM) → motor shaft (torsion) → GT2 pulley
//!   (θS) → belt → carriage (x3) → toolhead or bed on its mount (x4); x1/x2 are the motor mount
//!   and the idler moving on the frame. The belt plays the nut's part: its stiffness
//!   `EA·(1/l₁ + 1/l₂)` (two spans in parallel) varies with the carriage position.
//!
//! Each drive is closed by its [`ServoLoop`]: a closed-loop servo's position loop (a PD on the
//! motor angle with velocity and acceleration feed-forward), or an open-loop stepper's magnetic
//! stiffness (same form, no feed-forward).
//!
//! Default material values (steel ball screws, THK *General Catalog*, "Ball Screw: axial
//! rigidity of the screw shaft"; ISO 3408-5): E = 206 GPa, G = 79.4 GPa, ρ = 7850 kg/m³.
//! Component values are typical catalogue figures, documented field by field; they are not
//! measurements of one machine and should be replaced by the machine's own where known.

use serde::{Deserialize, Serialize};

/// Young's modulus of screw steel, Pa (THK: 2.06 × 10⁵ N/mm²).
pub const STEEL_E_PA: f64 = 206e9;
/// Shear modulus of screw steel, Pa (E / (2(1 + ν)) with ν = 0.3).
pub const STEEL_G_PA: f64 = 79.4e9;
/// Density of steel, kg/m³.
pub const STEEL_DENSITY: f64 = 7850.0;

/// The position loop that drives the motor: torque
/// `τ = K_p (θ_c − θ_M) + K_d (θ̇_c − θ̇_M) + feed-forward`, where `θ_c` is the commanded position
/// over the transmission ratio. The feed-forward supplies `k_v` of the torque that moves the rigid
/// axis against its viscous damping at the commanded speed and `k_a` of the torque that
/// accelerates its inertia.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(deny_unknown_fields)]
pub struct ServoLoop {
    /// Position gain `K_p`, N·m/rad (for a stepper: holding torque × rotor teeth).
    pub stiffness_nm_per_rad: f64,
    /// Velocity gain `K_d`, N·m·s/rad.
    pub damping_nms_per_rad: f64,
    /// Velocity feed-forward `k_v`, 0..=1.
    pub velocity_feedforward: f64,
    /// Acceleration (torque) feed-forward `k_a`, 0..=1.
    pub acceleration_feedforward: f64,
}

impl ServoLoop {
    /// A loop tuned to `bandwidth_hz` with damping ratio `zeta` on the rigid axis of inertia
    /// `inertia` (kg·m² seen by the motor): `K_p = J ω²`, `K_d = 2 ζ J ω`.
    pub fn tuned(inertia: f64, bandwidth_hz: f64, zeta: f64, kv: f64, ka: f64) -> Self {
        let w = 2.0 * core::f64::consts::PI * bandwidth_hz;
        Self {
            stiffness_nm_per_rad: inertia * w * w,
            damping_nms_per_rad: 2.0 * zeta * inertia * w,
            velocity_feedforward: kv,
            acceleration_feedforward: ka,
        }
    }
}

/// A ball-screw drive (VTG eq. 1–9).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(deny_unknown_fields)]
pub struct BallScrew {
    /// Screw radius `r_s`, m.
    pub screw_radius_m: f64,
    /// Screw length `l_s`, m.
    pub screw_length_m: f64,
    /// Lead (table travel per screw turn), m; the transmission ratio is `i_s = lead / 2π`.
    pub lead_m: f64,
    /// Screw material density `ρ`, kg/m³.
    pub density_kg_m3: f64,
    /// Young's modulus `E`, Pa.
    pub youngs_modulus_pa: f64,
    /// Shear modulus `G`, Pa.
    pub shear_modulus_pa: f64,
    /// Motor rotor mass `m_r` (VTG eq. 1), kg.
    pub rotor_mass_kg: f64,
    /// Coupling mass `m_c` (VTG eq. 1), kg.
    pub coupling_mass_kg: f64,
    /// Coupling inertia `J_c` (VTG eq. 3), kg·m².
    pub coupling_inertia_kg_m2: f64,
    /// Motor rotor inertia `J_M`, kg·m².
    pub motor_inertia_kg_m2: f64,
    /// Slave pedestal (nut block, slider) mass `m_3`, kg.
    pub pedestal_mass_kg: f64,
    /// Working table (what the axis carries) mass `m_4`, kg.
    pub table_mass_kg: f64,
    /// Axial stiffness of the fixed bearing `k_zn` (VTG eq. 8), N/m.
    pub bearing_stiffness_n_m: f64,
    /// Torsional stiffness of the coupling `k_zt` (VTG eq. 9), N·m/rad.
    pub coupling_stiffness_nm_rad: f64,
    /// Nut reference stiffness without preload `k_c` (VTG eq. 7), N/m.
    pub nut_reference_stiffness_n_m: f64,
    /// Nut preload `F_z` (VTG eq. 7), N.
    pub preload_n: f64,
    /// Dynamic load rating `C_a` (VTG eq. 7), N.
    pub dynamic_load_rating_n: f64,
    /// Axial stiffness of one flexure hinge between pedestal and table `k_mw`, N/m.
    pub hinge_stiffness_n_m: f64,
    /// Damping coefficient of the nut `C_mn` (VTG eq. 13), N·s/m.
    pub nut_damping_ns_m: f64,
    /// Damping coefficient of one flexure hinge `C_mw` (VTG eq. 13), N·s/m.
    pub hinge_damping_ns_m: f64,
    /// Distance from coupling to nut at axis position 0, m (`l_n = offset + position`).
    pub nut_offset_m: f64,
    /// Position loop.
    pub servo: ServoLoop,
}

/// A belt drive of a desktop printer, mapped onto the same coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(deny_unknown_fields)]
pub struct Belt {
    /// Pulley pitch radius (the transmission ratio `i_s`), m.
    pub pulley_radius_m: f64,
    /// Belt specific stiffness `EA`, N (force per unit strain).
    pub belt_ea_n: f64,
    /// Length of the belt loop's two straight spans together, m.
    pub span_length_m: f64,
    /// Span between pulley and carriage at axis position 0, m (`l₁ = offset + position`).
    pub span_offset_m: f64,
    /// Motor rotor inertia `J_M`, kg·m².
    pub motor_inertia_kg_m2: f64,
    /// Pulley inertia `J_S`, kg·m².
    pub pulley_inertia_kg_m2: f64,
    /// Torsional stiffness of the motor shaft between rotor and pulley, N·m/rad.
    pub shaft_stiffness_nm_rad: f64,
    /// Motor and mount mass moving with the frame along the belt (x1), kg.
    pub motor_mount_mass_kg: f64,
    /// Idler mass (x2), kg.
    pub idler_mass_kg: f64,
    /// Stiffness of the motor mount and of the idler mount along the belt, N/m.
    pub mount_stiffness_n_m: f64,
    /// Carriage (belt clamp, wheels or bearing blocks) mass `m_3`, kg.
    pub carriage_mass_kg: f64,
    /// Toolhead (X) or bed (Y) mass on the carriage `m_4`, kg.
    pub payload_mass_kg: f64,
    /// Stiffness of one of the two payload mounts `k_mw`, N/m.
    pub mount_hinge_stiffness_n_m: f64,
    /// Guide damping on the carriage `C_mn`, N·s/m.
    pub carriage_damping_ns_m: f64,
    /// Damping of one payload mount `C_mw`, N·s/m.
    pub payload_damping_ns_m: f64,
    /// Stepper (or servo) loop.
    pub servo: ServoLoop,
}

/// One axis drive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum Drive {
    /// Ball screw and servo motor.
    BallScrew(BallScrew),
    /// Belt and stepper.
    Belt(Belt),
}

/// The drives of the X and Y axes (Z moves only between layers and is taken as rigid).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(deny_unknown_fields)]
pub struct MachineDynamics {
    /// Short name.
    pub name: String,
    /// X drive.
    pub x: Drive,
    /// Y drive.
    pub y: Drive,
}

/// Names of the built-in parameter sets.
pub const PRESETS: [&str; 2] = ["ldam-ball-screw", "desktop-belt"];

/// The parameter set that goes with a machine preset of `plan::profiles`: the VTG paper's
/// servo printer gets ball screws, every other preset belts and steppers.
pub fn preset_for_machine(machine: &str) -> &'static str {
    if machine == "vtg-ldam-servo" {
        "ldam-ball-screw"
    } else {
        "desktop-belt"
    }
}

impl MachineDynamics {
    /// A built-in parameter set by name (see [`PRESETS`]).
    pub fn preset(name: &str) -> Option<Self> {
        let (x, y) = match name {
            "ldam-ball-screw" => (
                ldam_axis(1.2, 2.0, 8.0, 2.6e-5),
                ldam_axis(1.0, 3.0, 22.0, 8.7e-5),
            ),
            "desktop-belt" => (desktop_axis(0.15, 0.35, 0.42), desktop_axis(0.3, 1.2, 0.47)),
            _ => return None,
        };
        Some(Self {
            name: name.to_string(),
            x,
            y,
        })
    }
}

impl MachineDynamics {
    /// The lowest natural frequency of the X and Y drives as they run (mechanism and position
    /// loop), over the travel (the screws' stiffness changes with the nut's position), Hz.
    pub fn lowest_frequency_hz(&self) -> f64 {
        let mut lowest = f64::INFINITY;
        for drive in [&self.x, &self.y] {
            for position_m in [0.05, 0.25, 0.5] {
                for mode in super::axis::modes(drive, position_m) {
                    lowest = lowest.min(mode.frequency_hz);
                }
            }
        }
        lowest
    }
}

/// An axis of the VTG paper's 1000 × 800 × 350 mm printer: a 20 mm ball screw with 10 mm lead
/// (HIWIN/THK 2010 class: `C_a` = 10 kN, nut rigidity 300 N/µm, preload 5 % of `C_a`), a pair of
/// 20 mm ball-screw support bearings (400–750 N/µm in NSK's BSN tables; 500 N/µm here), a
/// bellows coupling (5000 N·m/rad, 0.12 kg, 2 × 10⁻⁵ kg·m²) and an AC servo (`motor_inertia`:
/// 0.26 × 10⁻⁴ kg·m² for 400 W on X, 0.87 × 10⁻⁴ for 750 W on Y). Moving masses match the
/// energy model's `ServoProfile` (10 kg on X, 25 kg on Y). The servo is tuned to a 40 Hz
/// position bandwidth (ζ = 0.7) with velocity feed-forward on and torque feed-forward off, the
/// usual factory setting of servo drives.
fn ldam_axis(screw_length_m: f64, pedestal: f64, table: f64, motor_inertia: f64) -> Drive {
    let mut d = BallScrew {
        screw_radius_m: 0.010,
        screw_length_m,
        lead_m: 0.010,
        density_kg_m3: STEEL_DENSITY,
        youngs_modulus_pa: STEEL_E_PA,
        shear_modulus_pa: STEEL_G_PA,
        rotor_mass_kg: 0.6,
        coupling_mass_kg: 0.12,
        coupling_inertia_kg_m2: 2e-5,
        motor_inertia_kg_m2: motor_inertia,
        pedestal_mass_kg: pedestal,
        table_mass_kg: table,
        bearing_stiffness_n_m: 500e6,
        coupling_stiffness_nm_rad: 5000.0,
        nut_reference_stiffness_n_m: 300e6,
        preload_n: 500.0,
        dynamic_load_rating_n: 10e3,
        hinge_stiffness_n_m: 50e6,
        nut_damping_ns_m: 1000.0,
        hinge_damping_ns_m: 500.0,
        nut_offset_m: 0.1,
        servo: ServoLoop::tuned(0.0, 0.0, 0.0, 0.0, 0.0),
    };
    let inertia = super::lumped::rigid_inertia_ball_screw(&d);
    d.servo = ServoLoop::tuned(inertia, 40.0, 0.7, 1.0, 0.0);
    Drive::BallScrew(d)
}

/// An axis of a bed-slinger desktop printer (Ender-3 class): GT2 belt on a 20-tooth pulley
/// (pitch radius 6.37 mm), NEMA 17 stepper (rotor 54 g·cm², holding torque 0.44 N·m, 50 rotor
/// teeth: magnetic stiffness ≈ 22 N·m/rad), 5 mm motor shaft (20 mm free length: 243 N·m/rad).
/// Belt `EA` = 10 kN: a 6 mm glass-fibre GT2 belt stretches at most 1 % under 98 N (FarmBot's
/// acceptance test), in line with the nominal stiffness measured by Wang et al., "Nominal
/// Stiffness Evaluation and Regression Analysis of GT-2 Rubber-Fiberglass Timing Belts" (2018).
/// With these values the first modes fall at 40–70 Hz, where input-shaper measurements put
/// them on such printers. `carriage` and `payload` are the moving masses (X: carriage and
/// toolhead; Y: bed carriage and bed).
fn desktop_axis(carriage: f64, payload: f64, span_m: f64) -> Drive {
    let mut b = Belt {
        pulley_radius_m: 20.0 * 0.002 / (2.0 * core::f64::consts::PI),
        belt_ea_n: 10e3,
        span_length_m: span_m,
        span_offset_m: 0.02,
        motor_inertia_kg_m2: 5.4e-6,
        pulley_inertia_kg_m2: 3e-7,
        shaft_stiffness_nm_rad: 243.0,
        motor_mount_mass_kg: 0.4,
        idler_mass_kg: 0.05,
        mount_stiffness_n_m: 5e6,
        carriage_mass_kg: carriage,
        payload_mass_kg: payload,
        mount_hinge_stiffness_n_m: 2e6,
        carriage_damping_ns_m: 4.0,
        payload_damping_ns_m: 4.0,
        servo: ServoLoop::tuned(0.0, 0.0, 0.0, 0.0, 0.0),
    };
    let inertia = super::lumped::rigid_inertia_belt(&b);
    // Open-loop stepper: magnetic spring, light damping (ζ ≈ 0.1 of the rotor mode), no
    // feed-forward.
    let k = 22.0;
    b.servo = ServoLoop {
        stiffness_nm_per_rad: k,
        damping_nms_per_rad: 2.0 * 0.1 * (k * inertia).sqrt(),
        velocity_feedforward: 0.0,
        acceleration_feedforward: 0.0,
    };
    Drive::Belt(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_exist_and_round_trip() {
        for name in PRESETS {
            let p = MachineDynamics::preset(name).expect(name);
            let json = serde_json::to_string(&p).expect("json");
            let back: MachineDynamics = serde_json::from_str(&json).expect("parse");
            // serde_json's default float parsing may move the last bit once; then it is stable.
            let again: MachineDynamics =
                serde_json::from_str(&serde_json::to_string(&back).expect("json")).expect("parse");
            assert_eq!(again, back);
            assert_eq!(back.name, p.name);
        }
        assert!(MachineDynamics::preset("nope").is_none());
        assert_eq!(preset_for_machine("vtg-ldam-servo"), "ldam-ball-screw");
        assert_eq!(preset_for_machine("prusa-mk3s"), "desktop-belt");
    }
}
