//! The human-readable form of an analysis report.

use std::io::{self, Write};
use std::path::Path;

use quietpath::Report;

fn duration(s: f64) -> String {
    let total = s.round() as u64;
    format!(
        "{}h{:02}m{:02}s",
        total / 3600,
        (total / 60) % 60,
        total % 60
    )
}

/// Writes a report as aligned text.
pub fn write_report(out: &mut impl Write, path: &Path, r: &Report) -> io::Result<()> {
    writeln!(out, "{}", path.display())?;
    write_summary(out, r)?;
    write_energy(out, r)?;
    write_features(out, r)?;
    write_warnings(out, r)
}

/// One `key value` row of the summary.
fn row(out: &mut dyn Write, k: &str, v: String) -> io::Result<()> {
    writeln!(out, "  {k:<22} {v}")
}

/// The file, time, moves, distance, filament, extrusion and bounds rows.
fn write_summary(out: &mut dyn Write, r: &Report) -> io::Result<()> {
    row(
        out,
        "slicer",
        r.file.slicer.clone().unwrap_or_else(|| "unknown".into()),
    )?;
    row(
        out,
        "flavor",
        r.file.flavor.clone().unwrap_or_else(|| "unknown".into()),
    )?;
    row(out, "lines", r.file.lines.to_string())?;
    row(
        out,
        "time",
        format!(
            "{} ({:.0} s, {} model)",
            duration(r.time_s),
            r.time_s,
            r.time_model
        ),
    )?;
    row(
        out,
        "moves",
        format!("{} ({} extruding)", r.moves, r.extruding_moves),
    )?;
    row(out, "layers", r.layers.to_string())?;
    row(
        out,
        "distance",
        format!(
            "{:.1} mm ({:.1} printing, {:.1} travel)",
            r.distance_mm, r.extrude_distance_mm, r.travel_distance_mm
        ),
    )?;
    row(
        out,
        "filament",
        format!("{:.1} mm, {:.2} g", r.filament_mm, r.material_g),
    )?;
    row(
        out,
        "extrusion",
        format!(
            "{:?} ({:?}), {} mm, {} g/cm³",
            r.extrusion.mode,
            r.extrusion.source,
            r.extrusion.filament_diameter_mm,
            r.extrusion.density_g_cm3
        )
        .to_lowercase(),
    )?;
    if let Some(b) = &r.bounds {
        row(
            out,
            "bounds",
            format!(
                "X {:.2}..{:.2}  Y {:.2}..{:.2}  Z {:.2}..{:.2}",
                b.min[0], b.max[0], b.min[1], b.max[1], b.min[2], b.max[2]
            ),
        )?;
    }
    Ok(())
}

/// The energy, thesis stepper and CO₂ rows.
fn write_energy(out: &mut dyn Write, r: &Report) -> io::Result<()> {
    let e = &r.energy;
    row(
        out,
        "energy",
        format!(
            "{:.1} kJ = {:.3} kWh (servo {:.1} kJ, {}; fuse {:.1} kJ; aux {:.1} kJ)",
            e.total_j / 1e3,
            e.total_kwh,
            e.servo_j / 1e3,
            match e.servo_model {
                quietpath::energy::ServoModel::Physical => "physical model",
                _ => "thesis model",
            },
            e.fuse_j / 1e3,
            e.aux_j / 1e3
        ),
    )?;
    row(
        out,
        "stepper (thesis)",
        format!(
            "{:.1} J (A {:.0}, B {:.0}, C {:.0} mm, H {:.1} s)",
            e.thesis_j, e.thesis.a, e.thesis.b, e.thesis.c, e.thesis.h
        ),
    )?;
    row(out, "CO2", format!("{:.1} g", e.co2_g))
}

/// The table of features.
fn write_features(out: &mut dyn Write, r: &Report) -> io::Result<()> {
    writeln!(
        out,
        "\n  {:<28} {:>8} {:>12} {:>12} {:>10} {:>10}",
        "feature", "moves", "distance mm", "filament mm", "time", "energy J"
    )?;
    for f in &r.features {
        writeln!(
            out,
            "  {:<28} {:>8} {:>12.1} {:>12.1} {:>10} {:>10.0}",
            f.name.chars().take(28).collect::<String>(),
            f.moves,
            f.distance_mm,
            f.filament_mm,
            duration(f.time_s),
            f.energy_j
        )?;
    }
    Ok(())
}

/// The first 20 warnings and how many more there are.
fn write_warnings(out: &mut dyn Write, r: &Report) -> io::Result<()> {
    let dropped = r.warnings_dropped;
    if !r.warnings.is_empty() {
        writeln!(out, "\n  warnings ({}):", r.warnings.len() as u64 + dropped)?;
        for w in r.warnings.iter().take(20) {
            match w.line {
                // A remark about the whole file.
                0 => writeln!(out, "    {}", w.message)?,
                line => writeln!(out, "    line {line}: {}", w.message)?,
            }
        }
        let more = r.warnings.len().saturating_sub(20) as u64 + dropped;
        if more > 0 {
            writeln!(out, "    ... and {more} more (see --json)")?;
        }
    }
    Ok(())
}
