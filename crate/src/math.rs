//! Portable floating-point functions: the same bits on every target.
//!
//! A native build would take `atan2`, `sin`, `cos` and `hypot` from the platform's C library
//! while the wasm build uses Rust's port of musl's libm; the two differ in the last bits, and the
//! CLI's JSON would then differ from the browser's. Every transcendental function in quietpath
//! goes through this module (the pure-Rust `libm` crate), so reports are identical everywhere.
//! `sqrt` and the arithmetic operators are correctly rounded by IEEE 754 and need no wrapper.

/// Four-quadrant arctangent of `y / x`, radians.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}

/// Sine, radians.
#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
}

/// Tangent, radians.
#[inline]
pub fn tan(x: f64) -> f64 {
    libm::tan(x)
}

/// Cosine, radians.
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}

/// `sqrt(x² + y²)` without undue overflow.
#[inline]
pub fn hypot(x: f64, y: f64) -> f64 {
    libm::hypot(x, y)
}

/// Arccosine, radians.
#[inline]
pub fn acos(x: f64) -> f64 {
    libm::acos(x)
}

/// `f64::max` and `f64::min` as a compare and a select.
///
/// In wasm, Rust's `max`/`min` become calls to `fmax`/`fmin` (the `f64.max` instruction
/// propagates NaN, Rust's `max` does not), and on the analysis' per-move path those calls cost
/// 7 % of `analyze` in the browser. These give the same result for every input the hot paths
/// see (a NaN argument is ignored, as with `f64::max`; only the sign of a zero result may
/// differ) and compile to two comparisons everywhere.
pub trait Bound {
    /// The larger of `self` and `other`.
    fn at_least(self, other: f64) -> f64;
    /// The smaller of `self` and `other`.
    fn at_most(self, other: f64) -> f64;
}

impl Bound for f64 {
    #[inline(always)]
    fn at_least(self, other: f64) -> f64 {
        if self > other || other.is_nan() {
            self
        } else {
            other
        }
    }

    #[inline(always)]
    fn at_most(self, other: f64) -> f64 {
        if self < other || other.is_nan() {
            self
        } else {
            other
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Bound;

    #[test]
    fn bounds_agree_with_std_max_and_min() {
        let values = [
            -1e300,
            -2.5,
            -0.0,
            0.0,
            1e-300,
            3.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for a in values {
            for b in values {
                let same = |x: f64, y: f64| (x.is_nan() && y.is_nan()) || x == y;
                assert!(same(a.at_least(b), a.max(b)), "{a} at_least {b}");
                assert!(same(a.at_most(b), a.min(b)), "{a} at_most {b}");
            }
        }
    }
}
