//! `E_aux` (VTG eq. 16): everything that is neither the X/Y drives nor melting, integrated over
//! the print's timeline of heater targets and fan speeds.
//!
//! - A heater holding target `T` draws `h·(T − T_ambient)` (Newton cooling with a loss
//!   coefficient `h`, W/K) from the time its target is set until it changes; a target of 0 turns
//!   it off.
//! - Raising a target costs the heat capacity times the rise (`C·ΔT`), from the previous
//!   target or from ambient if the heater was off (it is assumed to have cooled down). This
//!   covers the warm-up that `M190`/`M109` wait for, which the motion planner does not time.
//! - A fan at PWM duty `s` draws `s·P_fan` (electrical power roughly follows the duty cycle).
//! - The electronics (board, driver logic, display, heat-break fan, power-supply losses) draw a
//!   constant `P_idle` for the whole print.
//!
//! Defaults describe an i3-style desktop printer (a 24 V heat bed of about 250 × 210 mm with a
//! steel sheet, a V6-style hotend, a 5015 blower); they are estimates chosen so that such a
//! printer printing PLA (215/60 °C) draws about 50–80 W in total, the range published
//! measurements of desktop printers report. Replace them with the machine's measured values.

use serde::{Deserialize, Serialize};

use crate::machine::{FanEvent, Heater, TemperatureEvent};

/// Powers and heat capacities of the auxiliary systems.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct AuxPowers {
    /// Bed heat loss per kelvin above ambient, W/K (0.9: about 32 W holding 60 °C).
    pub bed_w_per_k: f64,
    /// Bed heat capacity (aluminium plate and steel sheet, about 0.4 + 0.3 kg), J/K.
    pub bed_heat_capacity_j_per_k: f64,
    /// Hotend heat loss per kelvin above ambient, W/K (0.065: about 12 W holding 215 °C).
    pub hotend_w_per_k: f64,
    /// Hotend heat capacity (heater block, nozzle, cartridge), J/K.
    pub hotend_heat_capacity_j_per_k: f64,
    /// Heated-chamber loss per kelvin above ambient, W/K.
    pub chamber_w_per_k: f64,
    /// Heated-chamber heat capacity (air, walls), J/K.
    pub chamber_heat_capacity_j_per_k: f64,
    /// Power of each part-cooling fan at full speed, W (a 24 V, 0.1 A blower).
    pub fan_w: f64,
    /// Constant draw of the electronics while printing, W.
    pub electronics_w: f64,
}

impl Default for AuxPowers {
    fn default() -> Self {
        Self {
            bed_w_per_k: 0.9,
            bed_heat_capacity_j_per_k: 500.0,
            hotend_w_per_k: 0.065,
            hotend_heat_capacity_j_per_k: 15.0,
            chamber_w_per_k: 2.0,
            chamber_heat_capacity_j_per_k: 3000.0,
            fan_w: 2.4,
            electronics_w: 8.0,
        }
    }
}

impl AuxPowers {
    /// Whether every value is finite and non-negative.
    pub fn is_valid(&self) -> bool {
        [
            self.bed_w_per_k,
            self.bed_heat_capacity_j_per_k,
            self.hotend_w_per_k,
            self.hotend_heat_capacity_j_per_k,
            self.chamber_w_per_k,
            self.chamber_heat_capacity_j_per_k,
            self.fan_w,
            self.electronics_w,
        ]
        .iter()
        .all(|v| v.is_finite() && *v >= 0.0)
    }

    fn loss_and_capacity(&self, heater: Heater) -> (f64, f64) {
        match heater {
            Heater::Bed => (self.bed_w_per_k, self.bed_heat_capacity_j_per_k),
            Heater::Hotend(_) => (self.hotend_w_per_k, self.hotend_heat_capacity_j_per_k),
            Heater::Chamber => (self.chamber_w_per_k, self.chamber_heat_capacity_j_per_k),
        }
    }
}

/// `E_aux` by system, J.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct AuxReport {
    /// Bed holding its targets, J.
    pub bed_j: f64,
    /// Hotends holding their targets, J.
    pub hotend_j: f64,
    /// Chamber holding its target, J.
    pub chamber_j: f64,
    /// Warming heaters up to raised targets, J.
    pub heat_up_j: f64,
    /// Part-cooling fans, J.
    pub fan_j: f64,
    /// Electronics, J.
    pub electronics_j: f64,
}

impl AuxReport {
    /// Sum of the parts, J.
    pub fn total_j(&self) -> f64 {
        self.bed_j
            + self.hotend_j
            + self.chamber_j
            + self.heat_up_j
            + self.fan_j
            + self.electronics_j
    }
}

/// Integrates the auxiliary powers over `[0, end_s]`. Events must be in time order (as the
/// report lists them); events after `end_s` count at `end_s`.
pub fn aux_energy(
    p: &AuxPowers,
    ambient_c: f64,
    temperatures: &[TemperatureEvent],
    fans: &[FanEvent],
    end_s: f64,
) -> AuxReport {
    let end_s = end_s.max(0.0);
    let mut r = AuxReport {
        electronics_j: p.electronics_w * end_s,
        ..AuxReport::default()
    };
    // Heaters: (heater, target, since).
    let mut heaters: Vec<(Heater, f64, f64)> = Vec::new();
    for ev in temperatures {
        let t = ev.time_s.clamp(0.0, end_s);
        let (loss, capacity) = p.loss_and_capacity(ev.heater);
        let target = ev.target_c.max(0.0);
        let i = match heaters.iter().position(|h| h.0 == ev.heater) {
            Some(i) => i,
            None => {
                heaters.push((ev.heater, 0.0, t));
                heaters.len() - 1
            }
        };
        let (heater, old, since) = heaters[i];
        add_holding(
            &mut r,
            heater,
            loss * (old - ambient_c).max(0.0) * (t - since),
        );
        let from = if old > ambient_c { old } else { ambient_c };
        r.heat_up_j += capacity * (target - from).max(0.0);
        heaters[i] = (heater, target, t);
    }
    for (heater, target, since) in heaters {
        let (loss, _) = p.loss_and_capacity(heater);
        add_holding(
            &mut r,
            heater,
            loss * (target - ambient_c).max(0.0) * (end_s - since),
        );
    }
    // Fans: (index, speed, since).
    let mut running: Vec<(u16, f64, f64)> = Vec::new();
    for ev in fans {
        let t = ev.time_s.clamp(0.0, end_s);
        match running.iter_mut().find(|f| f.0 == ev.index) {
            Some(f) => {
                r.fan_j += p.fan_w * f.1 * (t - f.2);
                f.1 = ev.speed.clamp(0.0, 1.0);
                f.2 = t;
            }
            None => running.push((ev.index, ev.speed.clamp(0.0, 1.0), t)),
        }
    }
    for (_, speed, since) in running {
        r.fan_j += p.fan_w * speed * (end_s - since);
    }
    r
}

fn add_holding(r: &mut AuxReport, heater: Heater, joules: f64) {
    let joules = joules.max(0.0);
    match heater {
        Heater::Bed => r.bed_j += joules,
        Heater::Hotend(_) => r.hotend_j += joules,
        Heater::Chamber => r.chamber_j += joules,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(time_s: f64, heater: Heater, target_c: f64) -> TemperatureEvent {
        TemperatureEvent {
            line: 1,
            time_s,
            heater,
            target_c,
            wait: false,
        }
    }

    #[test]
    fn timeline_by_hand() {
        let p = AuxPowers::default();
        let temps = [
            temp(0.0, Heater::Bed, 60.0),
            temp(0.0, Heater::Hotend(0), 215.0),
            temp(100.0, Heater::Bed, 0.0),
        ];
        let fans = [
            FanEvent {
                line: 1,
                time_s: 10.0,
                index: 0,
                speed: 0.5,
            },
            FanEvent {
                line: 1,
                time_s: 110.0,
                index: 0,
                speed: 1.0,
            },
        ];
        let r = aux_energy(&p, 25.0, &temps, &fans, 200.0);
        assert!((r.bed_j - 0.9 * 35.0 * 100.0).abs() < 1e-9);
        assert!((r.hotend_j - 0.065 * 190.0 * 200.0).abs() < 1e-9);
        assert!((r.heat_up_j - (500.0 * 35.0 + 15.0 * 190.0)).abs() < 1e-9);
        assert!((r.fan_j - 2.4 * (0.5 * 100.0 + 1.0 * 90.0)).abs() < 1e-9);
        assert!((r.electronics_j - 8.0 * 200.0).abs() < 1e-9);
    }
}
