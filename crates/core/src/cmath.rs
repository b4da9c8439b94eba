//! The C math library's `atanh`, `asinh`, `frexp` and `ldexp`.
//!
//! Rust's `f64::atanh` and `f64::asinh` are written in Rust (through `ln_1p`), not the C
//! library's, and `frexp`/`ldexp` are not in `std`. The elliptic and torque-free modules call
//! the C library's for all four, as the Python engine they were ported from did, which keeps
//! their results bit-for-bit equal to it. `frexp` and `ldexp` are exact in any correct
//! implementation; `atanh` and `asinh` may differ from Rust's own by an ulp.

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

/// `(f, e)` with `x = f·2^e`, `0.5 ≤ |f| < 1` (`(0, 0)` for zero), as Python's `math.frexp`:
/// read off the bits for a normal `x`, the C library otherwise.
#[inline(always)]
pub fn frexp(x: f64) -> (f64, i32) {
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    if biased != 0 && biased != 0x7ff {
        // x = 1.m · 2^(biased − 1023) = 0.1m · 2^(biased − 1022)
        let f = f64::from_bits((bits & !(0x7ff << 52)) | (1022 << 52));
        return (f, biased - 1022);
    }
    let mut e: c_int = 0;
    // SAFETY: `e` is a valid place for the exponent.
    let f = unsafe { ffi::frexp(x, &mut e) };
    (f, e)
}

/// `x·2^e`, exactly (rounded once where the result is subnormal), as Python's `math.ldexp`:
/// a product by the power of two where both it and the result are normal (then exact), the C
/// library otherwise.
#[inline(always)]
pub fn ldexp(x: f64, e: i32) -> f64 {
    if (-1022..=1023).contains(&e) {
        let y = x * f64::from_bits(((e + 1023) as u64) << 52);
        if y.is_normal() || y == 0.0 && x == 0.0 {
            return y;
        }
    }
    // SAFETY: a pure function of a double and an int.
    unsafe { ffi::ldexp(x, e) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bit-level forms equal the C library's on normal, subnormal and extreme arguments.
    #[test]
    fn the_fast_forms_equal_the_c_library() {
        let xs = [
            1.0, 0.75, -3.0, 3.0e-300, -7.5e200, 5e-324, 2.2e-308, 1.0e308, 0.0, -0.0,
        ];
        for &x in &xs {
            let mut e: c_int = 0;
            // SAFETY: as in `frexp`.
            let f = unsafe { ffi::frexp(x, &mut e) };
            assert_eq!(frexp(x), (f, e), "{x}");
            for k in [-1100, -1074, -1022, -600, -1, 0, 1, 500, 1023, 1100] {
                // SAFETY: as in `ldexp`.
                let want = unsafe { ffi::ldexp(x, k) };
                let got = ldexp(x, k);
                assert!(got.to_bits() == want.to_bits(), "{x} {k}: {got} {want}");
            }
        }
    }

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
