//! The C math library's `atanh`, `asinh`, `frexp` and `ldexp`.
//!
//! Rust's `f64::atanh` and `f64::asinh` are written in Rust (through `ln_1p`), not the C
//! library's, and `frexp`/`ldexp` are not in `std`. The numba kernels these modules port call
//! the C library for all four, so calling the same functions keeps the results bit-for-bit
//! equal. `frexp` and `ldexp` are exact in any correct implementation; `atanh` and `asinh`
//! may differ from Rust's own by an ulp.

use std::os::raw::c_int;

mod ffi {
    use std::os::raw::c_int;
    extern "C" {
        pub fn atanh(x: f64) -> f64;
        pub fn asinh(x: f64) -> f64;
        pub fn frexp(x: f64, exp: *mut c_int) -> f64;
        pub fn ldexp(x: f64, exp: c_int) -> f64;
    }
}

/// `atanh(x)` of the C library.
#[inline]
pub fn atanh(x: f64) -> f64 {
    // SAFETY: a pure function of a double.
    unsafe { ffi::atanh(x) }
}

/// `asinh(x)` of the C library.
#[inline]
pub fn asinh(x: f64) -> f64 {
    // SAFETY: a pure function of a double.
    unsafe { ffi::asinh(x) }
}

/// `(f, e)` with `x = f·2^e`, `0.5 ≤ |f| < 1` (`(0, 0)` for zero), as Python's `math.frexp`.
#[inline]
pub fn frexp(x: f64) -> (f64, i32) {
    let mut e: c_int = 0;
    // SAFETY: `e` is a valid place for the exponent.
    let f = unsafe { ffi::frexp(x, &mut e) };
    (f, e)
}

/// `x·2^e`, exactly (rounded once where the result is subnormal), as Python's `math.ldexp`.
#[inline]
pub fn ldexp(x: f64, e: i32) -> f64 {
    // SAFETY: a pure function of a double and an int.
    unsafe { ffi::ldexp(x, e) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frexp_and_ldexp_invert_each_other() {
        for &x in &[1.0, 0.75, 3.0e-300, -7.5e200, 5e-324, 1.0e308] {
            let (f, e) = frexp(x);
            assert!((0.5..1.0).contains(&f.abs()));
            assert_eq!(ldexp(f, e), x);
        }
        assert_eq!(frexp(0.0), (0.0, 0));
    }

    #[test]
    fn atanh_and_asinh_invert_tanh_and_sinh() {
        for k in -20..=20 {
            let x = 0.1 * k as f64;
            assert!((atanh(x.tanh()) - x).abs() <= 1e-15 * (1.0 + x.abs()) * 4.0);
            assert!((asinh(x.sinh()) - x).abs() <= 1e-15 * (1.0 + x.abs()));
        }
    }
}
