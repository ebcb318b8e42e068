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
