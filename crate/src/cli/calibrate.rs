//! `quietpath calibrate`: fits the thesis energy model to measurements (see
//! `quietpath::energy::calibrate`).

use std::io::{self, Write};
use std::path::Path;

use quietpath::analyze::{analyze, AnalyzeOptions};
use quietpath::energy::calibrate::{fit, parse_csv, Calibration, CalibrationError, CsvRows};
use quietpath::energy::Observation;

/// Reads the CSV at `file`, analyzes the G-code files it names (if it names files) with
/// `options`, and fits.
pub fn run(file: &Path, options: &AnalyzeOptions) -> Result<Calibration, String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let at = |e: CalibrationError| format!("{}: {e}", file.display());
    let rows = match parse_csv(&text).map_err(at)? {
        CsvRows::Terms(rows) => rows,
        CsvRows::Gcode(rows) => {
            let dir = file.parent().unwrap_or_else(|| Path::new(""));
            let mut out = Vec::with_capacity(rows.len());
            for r in rows {
                let path = dir.join(&r.path);
                let gcode_error = |message: String| CalibrationError::Gcode {
                    row: r.row,
                    path: path.display().to_string(),
                    message,
                };
                let bytes = std::fs::read(&path).map_err(|e| at(gcode_error(e.to_string())))?;
                let report =
                    analyze(&bytes, options).map_err(|e| at(gcode_error(e.to_string())))?;
                let t = report.energy.thesis;
                out.push(Observation {
                    row: r.row,
                    a: t.a,
                    b: t.b,
                    c: t.c,
                    h: t.h,
                    // The fit works in the thesis's unit, W·ms.
                    e: r.energy_j * 1e3,
                });
            }
            out
        }
    };
    fit(&rows).map_err(at)
}

/// Prints a fit as text.
pub fn print(out: &mut impl Write, path: &Path, c: &Calibration) -> io::Result<()> {
    writeln!(
        out,
        "{} ({} rows, energies in {})",
        path.display(),
        c.n,
        c.energy_unit
    )?;
    let se = &c.standard_errors;
    for (name, v, e) in [
        ("k_a_mx", c.k_a_mx, se.k_a_mx),
        ("k_a_my", c.k_a_my, se.k_a_my),
        ("k_c", c.k_c, se.k_c),
        ("k_h", c.k_h, se.k_h),
    ] {
        writeln!(out, "  {name:<8} {v:>16.9} ± {e:.3}")?;
    }
    writeln!(
        out,
        "  r2 {:.6}  adjusted {:.6}  rmse {:.1}  F {:.3} (p {:.3e})",
        c.r2, c.adjusted_r2, c.rmse, c.f_statistic, c.p_value
    )?;
    writeln!(
        out,
        "\n  {:>6} {:>16} {:>16} {:>12}",
        "row", "observed", "predicted", "residual"
    )?;
    for r in &c.residuals {
        writeln!(
            out,
            "  {:>6} {:>16.3} {:>16.3} {:>12.3}",
            r.row, r.observed, r.predicted, r.residual
        )?;
    }
    Ok(())
}
