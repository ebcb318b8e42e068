//! Calibrating the thesis model: ordinary least squares without intercept of measured energies
//! on the terms `A`, `B`, `C`, `H`, as the thesis derives thesis eq. 28 from its Table 3.
//!
//! The fit uses a Householder QR factorisation of the (column-scaled) design matrix, never the
//! normal equations, whose condition number is the square of the data's (the columns here
//! differ by four orders of magnitude).
//!
//! Fit quality follows the conventions for regression through the origin (those of Excel's
//! `LINEST` with `const = FALSE`, which the thesis used): `r2 = 1 − SS_res / Σ y²` (uncentred),
//! `adjusted_r2 = 1 − (1 − r2)·n / (n − p)`, `f_statistic = (SS_reg / p) / (SS_res / (n − p))`
//! with `SS_reg = Σ ŷ²`, `p_value` its upper tail, `standard_error = √(SS_res / (n − p))`,
//! `rmse = √(SS_res / n)`.
//!
//! Energies are in the thesis's unit, W·ms, so the coefficients plug into
//! [`ThesisCoefficients`] as they are; rows given in joules are scaled by 1000.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::thesis::ThesisCoefficients;

/// Number of fitted coefficients.
pub const P: usize = 4;

/// One observation: the terms of a print and its measured energy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(deny_unknown_fields)]
pub struct Observation {
    /// Where it came from (1-based line of the CSV, or position in a list), for errors and
    /// residuals.
    #[serde(default)]
    #[cfg_attr(test, ts(optional, as = "Option<_>"))]
    pub row: usize,
    /// `A`, (mm/s)².
    pub a: f64,
    /// `B`, (mm/s)².
    pub b: f64,
    /// `C`, mm.
    pub c: f64,
    /// `H`, s.
    pub h: f64,
    /// Measured energy, W·ms.
    pub e: f64,
}

/// A row naming a G-code file and the energy measured while printing it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GcodeRow {
    /// 1-based line of the CSV.
    pub row: usize,
    /// Path as written (relative paths are resolved by the caller).
    pub path: String,
    /// Measured energy, J.
    pub energy_j: f64,
}

/// The rows of a calibration CSV, in one of its two forms.
#[derive(Debug, Clone, PartialEq)]
pub enum CsvRows {
    /// `A,B,C,H,E` with `E` in W·ms.
    Terms(Vec<Observation>),
    /// `gcode_path,energy_j`.
    Gcode(Vec<GcodeRow>),
}

/// Why a calibration failed. Rows are 1-based lines of the CSV (or positions in a list).
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum CalibrationError {
    /// No data rows.
    #[error("no data rows")]
    Empty,
    /// A row with the wrong number of fields.
    #[error("row {row}: expected {expected} fields, found {found}")]
    Columns {
        /// Row.
        row: usize,
        /// What was expected.
        expected: &'static str,
        /// Fields found.
        found: usize,
    },
    /// A field that is not a number.
    #[error("row {row}, column {column}: {text:?} is not a number")]
    InvalidNumber {
        /// Row.
        row: usize,
        /// 1-based column.
        column: usize,
        /// The field.
        text: String,
    },
    /// A number that is infinite, NaN or negative.
    #[error("row {row}, column {column}: {value} is not a finite, non-negative number")]
    OutOfRange {
        /// Row.
        row: usize,
        /// 1-based column.
        column: usize,
        /// The value.
        value: f64,
    },
    /// An empty G-code path.
    #[error("row {row}: empty G-code path")]
    EmptyPath {
        /// Row.
        row: usize,
    },
    /// A G-code file that could not be read or analyzed.
    #[error("row {row}: {path}: {message}")]
    Gcode {
        /// Row.
        row: usize,
        /// Path as resolved.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// Fewer rows than the fit and its statistics need.
    #[error("need at least {needed} rows to fit 4 coefficients with statistics, found {found}")]
    TooFewRows {
        /// Rows needed.
        needed: usize,
        /// Rows found.
        found: usize,
    },
    /// The terms do not determine the coefficients (a column is zero, or columns are
    /// proportional).
    #[error("the A, B, C, H columns are linearly dependent (rank {rank} of 4); vary the prints")]
    RankDeficient {
        /// Numerical rank.
        rank: usize,
    },
}

/// One row's fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Residual {
    /// Row (as in the input).
    pub row: usize,
    /// Measured energy, W·ms.
    pub observed: f64,
    /// Energy the fit predicts, W·ms.
    pub predicted: f64,
    /// `observed − predicted`, W·ms.
    pub residual: f64,
}

/// The fitted coefficients and the quality of the fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "CalibrationFit"))]
pub struct Calibration {
    /// `k_a·m_x`, W·ms per (mm/s)².
    pub k_a_mx: f64,
    /// `k_a·m_y`, W·ms per (mm/s)².
    pub k_a_my: f64,
    /// `k_c`, W·ms per mm.
    pub k_c: f64,
    /// `k_h`, W·ms per s.
    pub k_h: f64,
    /// Standard errors of the four coefficients, same units.
    pub standard_errors: ThesisCoefficients,
    /// Uncentred coefficient of determination (regression through the origin).
    pub r2: f64,
    /// `r2` adjusted for the degrees of freedom, `1 − (1 − r2)·n/(n − 4)`.
    pub adjusted_r2: f64,
    /// Root-mean-square residual, W·ms.
    pub rmse: f64,
    /// Standard error of the regression, `√(SS_res/(n − 4))`, W·ms.
    pub standard_error: f64,
    /// F statistic of the regression (4 and n − 4 degrees of freedom).
    pub f_statistic: f64,
    /// Probability of an F at least this large if all coefficients were zero (4 and n − 4
    /// degrees of freedom). Excel's regression tool, with a zero constant, takes n − 5 for the
    /// second: the thesis's 8.48532·10⁻⁸ is `f_upper_tail(1388.57, 4, 5)`.
    pub p_value: f64,
    /// Observations.
    pub n: usize,
    /// Unit of the energies and residuals.
    pub energy_unit: &'static str,
    /// Per-row fit.
    pub residuals: Vec<Residual>,
}

impl Calibration {
    /// The coefficients, ready for [`super::EnergyOptions::thesis`].
    pub fn coefficients(&self) -> ThesisCoefficients {
        ThesisCoefficients {
            k_a_mx: self.k_a_mx,
            k_a_my: self.k_a_my,
            k_c: self.k_c,
            k_h: self.k_h,
        }
    }
}

fn split_fields(line: &str, sep: char) -> Vec<&str> {
    line.split(sep)
        .map(|f| {
            let f = f.trim();
            f.strip_prefix('"')
                .and_then(|g| g.strip_suffix('"'))
                .unwrap_or(f)
                .trim()
        })
        .collect()
}

fn number(row: usize, column: usize, text: &str) -> Result<f64, CalibrationError> {
    let v: f64 = text.parse().map_err(|_| CalibrationError::InvalidNumber {
        row,
        column,
        text: text.to_string(),
    })?;
    if !v.is_finite() || v < 0.0 {
        return Err(CalibrationError::OutOfRange {
            row,
            column,
            value: v,
        });
    }
    Ok(v)
}

/// Parses a calibration CSV: rows `A,B,C,H,E` (E in W·ms) or rows `gcode_path,energy_j`, with
/// an optional header line. Fields may be separated by commas, semicolons or tabs and quoted
/// with `"`; blank lines and lines starting with `#` are skipped.
pub fn parse_csv(text: &str) -> Result<CsvRows, CalibrationError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut sep = ',';
    let mut form: Option<usize> = None;
    let mut terms = Vec::new();
    let mut gcode = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let row = i + 1;
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let first = form.is_none();
        if first {
            sep = [',', ';', '\t']
                .into_iter()
                .find(|&c| trimmed.contains(c))
                .unwrap_or(',');
        }
        let fields = split_fields(trimmed, sep);
        let width = match form {
            Some(w) => w,
            None if fields.len() == 5 || fields.len() == 2 => fields.len(),
            None => {
                return Err(CalibrationError::Columns {
                    row,
                    expected: "5 (A,B,C,H,E) or 2 (gcode_path,energy_j)",
                    found: fields.len(),
                })
            }
        };
        form = Some(width);
        if fields.len() != width {
            return Err(CalibrationError::Columns {
                row,
                expected: if width == 5 {
                    "5 (A,B,C,H,E)"
                } else {
                    "2 (gcode_path,energy_j)"
                },
                found: fields.len(),
            });
        }
        if width == 5 {
            if first && fields.iter().any(|f| f.parse::<f64>().is_err()) {
                continue; // header
            }
            let mut v = [0.0; 5];
            for (k, f) in fields.iter().enumerate() {
                v[k] = number(row, k + 1, f)?;
            }
            terms.push(Observation {
                row,
                a: v[0],
                b: v[1],
                c: v[2],
                h: v[3],
                e: v[4],
            });
        } else {
            if first && fields[1].parse::<f64>().is_err() {
                continue; // header
            }
            if fields[0].is_empty() {
                return Err(CalibrationError::EmptyPath { row });
            }
            gcode.push(GcodeRow {
                row,
                path: fields[0].to_string(),
                energy_j: number(row, 2, fields[1])?,
            });
        }
    }
    match form {
        Some(5) if !terms.is_empty() => Ok(CsvRows::Terms(terms)),
        Some(2) if !gcode.is_empty() => Ok(CsvRows::Gcode(gcode)),
        _ => Err(CalibrationError::Empty),
    }
}

/// Ordinary least squares of `e` on `a`, `b`, `c`, `h` without intercept.
pub fn fit(rows: &[Observation]) -> Result<Calibration, CalibrationError> {
    check_rows(rows)?;
    let n = rows.len();
    let x = DMatrix::from_fn(n, P, |i, j| {
        let r = &rows[i];
        [r.a, r.b, r.c, r.h][j]
    });
    let y = DVector::from_iterator(n, rows.iter().map(|r| r.e));
    let LeastSquares { beta, r_inv, scale } = solve(&x, &y)?;

    let predicted = &x * DVector::from_column_slice(&beta);
    let residual = &y - &predicted;
    let ss_res = residual.norm_squared();
    let ss_tot = y.norm_squared();
    let ss_reg = predicted.norm_squared();
    let df = (n - P) as f64;
    let r2 = if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else {
        0.0
    };
    let sigma2 = ss_res / df;
    // Covariance of the coefficients: σ²·(RᵀR)⁻¹, in scaled units.
    let se: Vec<f64> = (0..P)
        .map(|j| (sigma2 * r_inv.row(j).norm_squared()).sqrt() / scale[j])
        .collect();
    let f_statistic = if ss_res > 0.0 {
        (ss_reg / P as f64) / sigma2
    } else {
        f64::INFINITY
    };
    let p_value = if f_statistic.is_finite() {
        f_upper_tail(f_statistic, P as f64, df)
    } else {
        0.0
    };
    Ok(Calibration {
        k_a_mx: beta[0],
        k_a_my: beta[1],
        k_c: beta[2],
        k_h: beta[3],
        standard_errors: ThesisCoefficients {
            k_a_mx: se[0],
            k_a_my: se[1],
            k_c: se[2],
            k_h: se[3],
        },
        r2,
        adjusted_r2: 1.0 - (1.0 - r2) * n as f64 / df,
        rmse: (ss_res / n as f64).sqrt(),
        standard_error: sigma2.sqrt(),
        // JSON has no infinity: a perfect fit reports the largest finite F.
        f_statistic: if f_statistic.is_finite() {
            f_statistic
        } else {
            f64::MAX
        },
        p_value,
        n,
        energy_unit: "W·ms",
        residuals: rows
            .iter()
            .zip(predicted.iter())
            .map(|(r, &p)| Residual {
                row: r.row,
                observed: r.e,
                predicted: p,
                residual: r.e - p,
            })
            .collect(),
    })
}

/// Enough rows for the fit, every value finite and non-negative.
fn check_rows(rows: &[Observation]) -> Result<(), CalibrationError> {
    let n = rows.len();
    if n == 0 {
        return Err(CalibrationError::Empty);
    }
    if n <= P {
        return Err(CalibrationError::TooFewRows {
            needed: P + 1,
            found: n,
        });
    }
    for r in rows {
        for (column, v) in [r.a, r.b, r.c, r.h, r.e].into_iter().enumerate() {
            if !v.is_finite() || v < 0.0 {
                return Err(CalibrationError::OutOfRange {
                    row: r.row,
                    column: column + 1,
                    value: v,
                });
            }
        }
    }
    Ok(())
}

/// A least-squares fit, in the units of the data.
struct LeastSquares {
    /// The coefficients.
    beta: Vec<f64>,
    /// The inverse of the `R` of the scaled columns' QR decomposition (the covariance is
    /// `σ²·(RᵀR)⁻¹` in scaled units).
    r_inv: DMatrix<f64>,
    /// Norms the columns were scaled by.
    scale: Vec<f64>,
}

/// The least-squares fit of `y` on the columns of `x`.
fn solve(x: &DMatrix<f64>, y: &DVector<f64>) -> Result<LeastSquares, CalibrationError> {
    // Scale columns to unit norm: the rank test is then relative, and the triangular solve
    // works on numbers of one magnitude.
    let scale: Vec<f64> = (0..P).map(|j| x.column(j).norm()).collect();
    if let Some(j) = scale.iter().position(|&s| s == 0.0 || !s.is_finite()) {
        return Err(CalibrationError::RankDeficient { rank: j.min(P - 1) });
    }
    let mut xs = x.clone();
    for (j, s) in scale.iter().enumerate() {
        xs.column_mut(j).unscale_mut(*s);
    }
    let qr = xs.qr();
    let r = qr.r();
    let rank = (0..P).filter(|&j| r[(j, j)].abs() > 1e-10).count();
    if rank < P {
        return Err(CalibrationError::RankDeficient { rank });
    }
    let mut qty = y.clone();
    qr.q_tr_mul(&mut qty);
    let qty = qty.rows(0, P).into_owned();
    let beta_scaled = r
        .solve_upper_triangular(&qty)
        .ok_or(CalibrationError::RankDeficient { rank })?;
    let beta: Vec<f64> = (0..P).map(|j| beta_scaled[j] / scale[j]).collect();
    let r_inv = r
        .solve_upper_triangular(&DMatrix::identity(P, P))
        .ok_or(CalibrationError::RankDeficient { rank })?;
    Ok(LeastSquares { beta, r_inv, scale })
}

/// `P(F > f)` for an F distribution with `d1` and `d2` degrees of freedom:
/// `I_x(d2/2, d1/2)` with `x = d2 / (d2 + d1·f)`.
pub fn f_upper_tail(f: f64, d1: f64, d2: f64) -> f64 {
    if f <= 0.0 {
        return 1.0;
    }
    regularized_beta(d2 / (d2 + d1 * f), d2 / 2.0, d1 / 2.0)
}

/// The regularised incomplete beta function `I_x(a, b)` (continued fraction, modified Lentz).
fn regularized_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = libm::lgamma(a + b) - libm::lgamma(a) - libm::lgamma(b)
        + a * libm::log(x)
        + b * libm::log(1.0 - x);
    let front = libm::exp(ln_front);
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(x, a, b) / a
    } else {
        1.0 - front * beta_fraction(1.0 - x, b, a) / b
    }
}

fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut c = 1.0;
    let mut d = 1.0 - (a + b) * x / (a + 1.0);
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
        d = 1.0 + aa * d;
        d = if d.abs() < TINY { TINY } else { d };
        c = 1.0 + aa / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
        d = 1.0 + aa * d;
        d = if d.abs() < TINY { TINY } else { d };
        c = 1.0 + aa / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_data_is_recovered() {
        let k = [0.1, 0.2, 70.0, 800.0];
        let rows: Vec<Observation> = (0..8)
            .map(|i| {
                let i = f64::from(i);
                let (a, b, c, h) = (
                    1e6 + 3e5 * i,
                    2e6 + 1e5 * i * i,
                    2e4 + 700.0 * i * i * i,
                    50.0 * (i + 1.0),
                );
                Observation {
                    row: 0,
                    a,
                    b,
                    c,
                    h,
                    e: k[0] * a + k[1] * b + k[2] * c + k[3] * h,
                }
            })
            .collect();
        let cal = fit(&rows).expect("fit");
        let got = [cal.k_a_mx, cal.k_a_my, cal.k_c, cal.k_h];
        for (g, w) in got.iter().zip(k) {
            assert!((g - w).abs() < 1e-9 * w, "{g} vs {w}");
        }
        assert!(cal.r2 > 1.0 - 1e-12);
    }

    #[test]
    fn f_tail_matches_known_values() {
        // F(1, 1): P(F > 1) = 0.5. F(4, 6) at 4.53 is the 5 % critical value.
        assert!((f_upper_tail(1.0, 1.0, 1.0) - 0.5).abs() < 1e-12);
        assert!((f_upper_tail(4.533677, 4.0, 6.0) - 0.05).abs() < 1e-6);
    }

    #[test]
    fn proportional_columns_are_rank_deficient() {
        let rows: Vec<Observation> = (1..7)
            .map(|i| {
                let i = f64::from(i);
                Observation {
                    row: 0,
                    a: i,
                    b: 2.0 * i,
                    c: i * i,
                    h: 1.0,
                    e: i,
                }
            })
            .collect();
        assert!(matches!(
            fit(&rows),
            Err(CalibrationError::RankDeficient { rank: 3 })
        ));
    }

    #[test]
    fn csv_errors_carry_the_row() {
        let e = parse_csv("A,B,C,H,E\n1,2,3,4,5\n1,2,x,4,5\n").expect_err("bad number");
        assert_eq!(
            e,
            CalibrationError::InvalidNumber {
                row: 3,
                column: 3,
                text: "x".into()
            }
        );
        let e = parse_csv("1,2,3,4,5\n1,2,3,4\n").expect_err("short row");
        assert!(matches!(
            e,
            CalibrationError::Columns {
                row: 2,
                found: 4,
                ..
            }
        ));
        let e = parse_csv("gcode_path,energy_j\na.gcode,-3\n").expect_err("negative");
        assert!(matches!(
            e,
            CalibrationError::OutOfRange {
                row: 2,
                column: 2,
                ..
            }
        ));
        assert_eq!(parse_csv("# nothing\n\n"), Err(CalibrationError::Empty));
        match parse_csv("gcode_path;energy_j\n\"a b.gcode\";12.5\n").expect("gcode rows") {
            CsvRows::Gcode(rows) => {
                assert_eq!(rows[0].path, "a b.gcode");
                assert_eq!(rows[0].row, 2);
            }
            CsvRows::Terms(_) => panic!("wrong form"),
        }
    }
}
