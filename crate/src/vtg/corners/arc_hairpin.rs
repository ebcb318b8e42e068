//! Hairpins written as one arc: where the firmware runs `G2`/`G3` and cuts a hairpin's arc
//! into chords that each turn less than the walk's steps may, the two corners and the
//! connector between them are written as one arc in place of the connector, and the file
//! keeps its line count.
//!
//! A hairpin fitted and walked with the rest of its path ([`super::hairpin::Hairpins`]) is
//! written as a dozen steps at feeds that each follow VTG eq. 29, so on a file held to its
//! line budget (every straight-walled part: nothing else in it saves lines) it is never
//! bought. Written as one arc it costs no line: the legs end where the arc starts, and the
//! arc stands where the connector stood. Its speed is the firmware's, as on any arc: the
//! planner slows at each chord junction, which for a circle holds the centripetal
//! acceleration to about the planner's acceleration (Marlin's small-segment rule, Klipper's
//! centripetal limit), the same bound VTG eq. 29 sets with `A_n`.
//!
//! How finely the firmware cuts it decides whether the corners are gone: upstream Marlin 2.1
//! cuts a 0.225 mm half circle into 7 chords of 25.7°, under the critical angle; Prusa's
//! firmware into 4 of 45°, which are sharp corners again, and Klipper's 1 mm resolution
//! into one chord. Only the first is proposed ([`crate::plan::ArcCutting`]).

use super::hairpin::{self, Hairpin};
use super::{CornerKind, Cost, Proposal, Replacement, Site};
use crate::vec3::{norm, sub};
use crate::vtg::deviation::both_ways;
use crate::vtg::smooth::{Settings, SmoothPath};
use crate::vtg::tuning::TUNING;

/// The corner kind of two sharp corners across a short connector, written as one arc where
/// the firmware's chords of it turn less than the walk's steps may.
pub(crate) struct ArcHairpins;

impl CornerKind for ArcHairpins {
    /// Only in a path's lean rewrite: the free one fits its hairpins with the path
    /// ([`hairpin::Hairpins`]), walked at VTG eq. 29's speeds; and only on a path with two sharp
    /// corners across a short connector (a scan of its points, before any corner is weighed).
    fn applies(&self, path: &SmoothPath<'_>, s: &Settings) -> bool {
        s.lean && s.arc_cutting.is_some() && has_hairpin(path.pts, s.critical_rad)
    }

    fn adds_no_lines(&self) -> bool {
        true
    }

    fn asks_about(&self, site: &Site<'_>, i: usize) -> bool {
        let m = site.marks;
        i >= 1 && i + 2 < m.sharp.len() && !m.pinned[i] && m.sharp[i] && m.sharp[i + 1]
    }

    fn propose(&self, site: &Site<'_>, i: usize) -> Option<Proposal> {
        let (path, s) = (site.path, site.settings);
        let cutting = s.arc_cutting?;
        let pts = path.pts;
        // Room for the 3-decimal rounding of written coordinates.
        let budget = s.tolerance_mm - 0.001;
        let pin = hairpin::find(
            pts,
            i,
            budget,
            TUNING.arc_min_radius_mm,
            hairpin::rooms(pts, i)?,
        )?;
        if pin.before_mm < 0.0 || pin.after_mm < 0.0 {
            return None;
        }
        let sweep = sweep_of(&pin)?;
        // As the arcs stage writes it: at the slowest of the feeds it stands for.
        let feed = path
            .feed
            .get(i - 1..=i + 1)?
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let chords = cutting.segments(pin.radius_mm, (pin.radius_mm * sweep, 0.0), feed);
        if chords == 0 || sweep / chords as f64 > TUNING.step_turn_share * s.critical_rad {
            return None;
        }
        let (first, last) = (*pin.arc.first()?, *pin.arc.last()?);
        let original = [first, pts[i], pts[i + 1], last];
        let deviation = both_ways(&pin.arc, &original, s.tolerance_mm / 10.0, budget);
        (deviation <= budget).then_some(Proposal {
            replacement: Replacement::Written(pin, deviation),
            cost: Cost::Unweighed,
        })
    }
}

/// The angle the arc of `pin` sweeps, rad: the sum of the angles its polygon's sides (chords
/// of one circle) subtend.
fn sweep_of(pin: &Hairpin) -> Option<f64> {
    let r = pin.radius_mm;
    (r > 0.0).then(|| {
        pin.arc
            .windows(2)
            .map(|w| 2.0 * (norm(sub(w[1], w[0])) / (2.0 * r)).min(1.0).asin())
            .sum()
    })
}

/// Whether `pts` turns by more than `critical_rad` at two consecutive points a connector of at
/// most `Tuning::hairpin_max_connector_mm` apart.
fn has_hairpin(pts: &[[f64; 3]], critical_rad: f64) -> bool {
    let cos_critical = crate::math::cos(critical_rad);
    let sharp = |k: usize| {
        crate::vtg::rewrite::is_sharp(
            &sub(pts[k], pts[k - 1]),
            &sub(pts[k + 1], pts[k]),
            cos_critical,
        )
    };
    (1..pts.len().saturating_sub(2)).any(|k| {
        norm(sub(pts[k + 1], pts[k])) <= TUNING.hairpin_max_connector_mm && sharp(k) && sharp(k + 1)
    })
}

#[cfg(test)]
mod tests {
    use crate::vtg::{vtg, VtgOptions};

    /// Three layers of zig-zag infill, 20 lines 20 mm long and 0.45 mm apart, each layer one
    /// path with 19 hairpins, for the printer `model` (none: a generic Marlin 2 file).
    fn zigzag(model: Option<&str>) -> String {
        let mut g = String::from("; gcode_flavor = marlin2\n");
        if let Some(m) = model {
            g += &format!("; printer_model = {m}\n");
        }
        g += "M83\nM204 P1000\n";
        for layer in 0..3 {
            g += &format!(
                "G1 Z{:.2} F600\nG1 X100 Y100 F9000\nG1 F2400\n",
                0.2 * (layer + 1) as f64
            );
            let mut y = 100.0;
            for k in 0..20 {
                let x = if k % 2 == 0 { 120.0 } else { 100.0 };
                g += &format!("G1 X{x:.3} Y{y:.3} E0.4\n");
                y += 0.45;
                g += &format!("G1 X{x:.3} Y{y:.3} E0.009\n");
            }
            g += "G1 E-0.8 F2100\n";
        }
        g
    }

    fn run(g: &str) -> crate::vtg::VtgReport {
        let options = VtgOptions {
            dynamics: false,
            ..VtgOptions::default()
        };
        vtg(g.as_bytes(), &options).expect("vtg")
    }

    fn arcs(output: &[u8]) -> usize {
        String::from_utf8_lossy(output)
            .lines()
            .filter(|l| l.starts_with("G2 ") || l.starts_with("G3 "))
            .count()
    }

    /// Upstream Marlin 2.1 cuts each hairpin's half circle (radius 0.225 mm) into 7 chords of
    /// 25.7°: every hairpin is written as one arc, the file keeps its line count, and only the
    /// last corner of each path, no hairpin, stays sharp (each path's free rewrite, which walks
    /// it too, needs lines the file does not have).
    #[test]
    fn hairpins_become_arcs_without_a_line_more() {
        let g = zigzag(None);
        let r = run(&g);
        assert_eq!(arcs(&r.output), 3 * 19);
        let f = r.firmware.as_ref().expect("firmware");
        assert!(f.after.lines <= f.before.lines, "{:?}", f);
        assert_eq!(r.table1.n_turning.before, 3.0 * 39.0);
        assert_eq!(r.table1.n_turning.after, 3.0);
        assert!(r.table2.time_s.after <= r.table2.time_s.before);
        assert!(r.table2.energy_j.after <= r.table2.energy_j.before);
        assert!(r.max_deviation_mm <= 0.1, "{}", r.max_deviation_mm);
    }

    /// Prusa's firmware cuts the same half circle into 4 chords of 45°, sharp corners again:
    /// no hairpin is written as an arc, and with no line to spare the file is kept.
    #[test]
    fn not_where_the_firmware_cuts_them_coarsely() {
        let r = run(&zigzag(Some("MK4S")));
        assert_eq!(arcs(&r.output), 0);
        assert_eq!(r.table1.n_turning.after, r.table1.n_turning.before);
    }
}
