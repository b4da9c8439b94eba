//! The instruction set a loop runs in, chosen at run time: one wheel carries a copy of each
//! vectorised loop for AVX-512, for AVX2 + FMA and for the baseline (on aarch64 the baseline
//! is NEON), and calls the widest copy the CPU can run.
//!
//! [`multiversion!`](crate::multiversion) writes the copies: for a function whose body is an
//! `#[inline(always)]` loop, it writes a copy compiled with each instruction set's target
//! features, taking the same arguments, so that the whole loop is compiled inside each copy
//! (a closure handed to one generic copy instead lost the arguments' `noalias` and, with it,
//! the vectorisation of the RK4 lanes). Fused multiply-adds round once in every copy (in
//! software without FMA), so every copy gives the same numbers.

/// An instruction set the crate carries a copy of each vectorised loop for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The target's baseline (SSE2 on x86-64, NEON on aarch64).
    Baseline,
    /// AVX2 with FMA and BMI2: four doubles a vector.
    Avx2,
    /// AVX-512 (F, DQ, VL) with the above: eight doubles a vector.
    Avx512,
}

impl Isa {
    /// Every instruction set, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Baseline, Isa::Avx2, Isa::Avx512];

    /// Its name, lower case.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Baseline => "baseline",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// Whether this CPU runs it.
    pub fn available(self) -> bool {
        match self {
            Isa::Baseline => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
                    && std::arch::is_x86_feature_detected!("bmi2")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                Isa::Avx2.available()
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512dq")
                    && std::arch::is_x86_feature_detected!("avx512vl")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The widest instruction set of this CPU, at most `cap`.
    pub fn widest_up_to(cap: Isa) -> Isa {
        Isa::ALL
            .into_iter()
            .rev()
            .find(|&isa| isa as u8 <= cap as u8 && isa.available())
            .unwrap_or(Isa::Baseline)
    }
}

/// One cache line of doubles.
#[repr(C, align(64))]
pub struct Line(pub [f64; 8]);

/// Writes a function `$name` that runs `$any` (an `#[inline(always)]` loop) in the copy for
/// the widest instruction set of this CPU up to `$cap`, and `$with`, which runs the copy for
/// a given [`Isa`] (the baseline when the CPU lacks it: check [`Isa::available`]). Each copy
/// is a function of the same arguments compiled with its target features. The AVX-512 copy
/// realigns its frame to a cache line, so that the vector registers a loop spills land on
/// whole cache lines (measured: the ensembles' RK4 lanes ran faster).
///
/// ```text
/// multiversion! {
///     /// docs
///     pub fn name, name_with [generics] (arg: Type, ...) -> Ret where [bounds]
///         => any_loop::<turbofish>, up to Isa::Avx512;
/// }
/// ```
#[macro_export]
macro_rules! multiversion {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident, $with:ident [$($gen:tt)*]
            ($($arg:ident : $ty:ty),* $(,)?) -> $ret:ty
            where [$($wh:tt)*]
            => $any:ident $(::<$($targ:tt),*>)?, up to $cap:expr;
    ) => {
        $(#[$attr])*
        #[allow(clippy::too_many_arguments)]
        $vis fn $name<$($gen)*>($($arg: $ty),*) -> $ret where $($wh)* {
            $with $(::<$($targ),*>)? ($crate::isa::Isa::widest_up_to($cap), $($arg),*)
        }

        /// The same, in the copy for `isa` (the baseline's when this CPU does not run it).
        #[allow(clippy::too_many_arguments)]
        $vis fn $with<$($gen)*>(isa: $crate::isa::Isa, $($arg: $ty),*) -> $ret where $($wh)* {
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2,fma,bmi2")]
            #[allow(clippy::too_many_arguments)]
            unsafe fn avx512<$($gen)*>($($arg: $ty),*) -> $ret where $($wh)* {
                let anchor = $crate::isa::Line([0.0; 8]);
                ::std::hint::black_box(&anchor);
                $any $(::<$($targ),*>)? ($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma,bmi2")]
            #[allow(clippy::too_many_arguments)]
            unsafe fn avx2<$($gen)*>($($arg: $ty),*) -> $ret where $($wh)* {
                $any $(::<$($targ),*>)? ($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            if isa.available() {
                match isa {
                    // SAFETY: the CPU has the features the copy is compiled for.
                    $crate::isa::Isa::Avx512 => {
                        return unsafe { avx512 $(::<$($targ),*>)? ($($arg),*) };
                    }
                    // SAFETY: as above.
                    $crate::isa::Isa::Avx2 => {
                        return unsafe { avx2 $(::<$($targ),*>)? ($($arg),*) };
                    }
                    $crate::isa::Isa::Baseline => {}
                }
            }
            let _ = isa;
            $any $(::<$($targ),*>)? ($($arg),*)
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fused multiply-adds and a division, in a loop each copy vectorises.
    #[inline(always)]
    fn work(xs: &[f64], out: &mut [f64]) -> usize {
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = x.mul_add(1.0 / 3.0, -x * x).mul_add(x, 0.1) / (1.0 + x * x);
        }
        xs.len()
    }

    crate::multiversion! {
        fn work_widest, work_with [] (xs: &[f64], out: &mut [f64]) -> usize where []
            => work, up to Isa::Avx512;
    }

    #[test]
    fn every_copy_gives_the_same_numbers() {
        let xs: Vec<f64> = (0..1000).map(|i| 0.37 * i as f64 - 91.0).collect();
        let mut base = vec![0.0; xs.len()];
        work(&xs, &mut base);
        for isa in Isa::ALL {
            let mut got = vec![0.0; xs.len()];
            assert_eq!(work_with(isa, &xs, &mut got), xs.len());
            assert!(
                got.iter()
                    .zip(&base)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{}",
                isa.name()
            );
        }
        let mut got = vec![0.0; xs.len()];
        work_widest(&xs, &mut got);
        assert_eq!(got, base);
        assert!(Isa::widest_up_to(Isa::Avx512).available());
        assert!(Isa::widest_up_to(Isa::Avx2) as u8 <= Isa::Avx2 as u8);
        assert_eq!(Isa::widest_up_to(Isa::Baseline), Isa::Baseline);
    }
}
