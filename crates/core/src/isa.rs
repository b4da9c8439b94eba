//! The instruction set a loop runs in, chosen at run time: the crate carries a copy of each
//! vectorised loop for AVX-512, for AVX2 + FMA and for the baseline (on aarch64 the baseline
//! is NEON), and calls the widest copy the CPU can run.
//!
//! Which copies are compiled is chosen when the crate is built (`build.rs`, the environment
//! variable `POINSOT_ISAS`): `all` for a wheel that runs anywhere (the `dist` profile's
//! builds), or, by default for a source build, `native`: the baseline and the widest copy the
//! building machine runs (each copy of every loop is compiled again, and two copies compile in
//! two thirds of the time of three). A machine without the compiled copy runs the baseline's,
//! with the same numbers.
//!
//! [`multiversion!`](crate::multiversion) writes the copies: for a function whose body is an
//! `#[inline(always)]` loop, it writes a copy compiled with each instruction set's target
//! features, taking the same arguments, so that the whole loop is compiled inside each copy
//! (a closure handed to one generic copy instead lost the arguments' `noalias` and, with it,
//! the vectorisation of the RK4 lanes). Fused multiply-adds round once in every copy (in
//! software without FMA), so every copy gives the same numbers.

use std::sync::atomic::{AtomicU8, Ordering};

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

    /// Whether this build carries its copies of the vectorised loops (`POINSOT_ISAS`), those
    /// that go up to AVX-512 (the lanes).
    pub fn compiled(self) -> bool {
        self.compiled_under(Isa::Avx512)
    }

    /// Whether this build carries its copies of the loops that go up to `cap`: a loop capped
    /// at AVX2 (a single run's driver, where AVX-512 adds nothing) keeps its AVX2 copy in a
    /// build for an AVX-512 machine, whose CPU runs it (the baseline would compute its fused
    /// multiply-adds in software).
    pub fn compiled_under(self, cap: Isa) -> bool {
        let avx2 = cfg!(all(target_arch = "x86_64", poinsot_avx2));
        let avx512 = cfg!(all(target_arch = "x86_64", poinsot_avx512));
        match self {
            Isa::Baseline => true,
            Isa::Avx2 => avx2 || (cap == Isa::Avx2 && avx512),
            Isa::Avx512 => cap == Isa::Avx512 && avx512,
        }
    }

    /// Whether this CPU runs it: asked of the CPU once per process, then one load (the
    /// copies' own check, at every call of a function [`multiversion!`](crate::multiversion)
    /// wrote).
    pub fn supported(self) -> bool {
        static SUPPORTED: [AtomicU8; 3] = [const { AtomicU8::new(UNKNOWN) }; 3];
        once_per_process(&SUPPORTED[self as usize], || u8::from(self.detected())) == 1
    }

    /// Whether this CPU runs it, asked of the CPU.
    fn detected(self) -> bool {
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
                Isa::Avx2.supported()
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512dq")
                    && std::arch::is_x86_feature_detected!("avx512vl")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// Whether a loop (of the lanes, up to AVX-512) runs in this instruction set here: the
    /// build carries its copies and the CPU runs it.
    pub fn available(self) -> bool {
        self.available_under(Isa::Avx512)
    }

    /// Whether a loop capped at `cap` runs in this instruction set here.
    pub fn available_under(self, cap: Isa) -> bool {
        self.compiled_under(cap) && self.supported()
    }

    /// The widest instruction set available here to a loop capped at `cap`: found once per
    /// cap and process (the build and the CPU do not change), then one load (a free flow of
    /// the exact splittings asks at every flow).
    pub fn widest_up_to(cap: Isa) -> Isa {
        static WIDEST: [AtomicU8; 3] = [const { AtomicU8::new(UNKNOWN) }; 3];
        let widest = once_per_process(&WIDEST[cap as usize], || {
            Isa::ALL
                .into_iter()
                .rev()
                .find(|&isa| isa as u8 <= cap as u8 && isa.available_under(cap))
                .unwrap_or(Isa::Baseline) as u8
        });
        Isa::ALL[widest as usize]
    }
}

/// A slot not yet filled ([`once_per_process`]).
const UNKNOWN: u8 = u8::MAX;

/// The value in `slot`, found by `find` the first time (what the build and the CPU decide does
/// not change while the process runs; two threads finding it at once find the same).
#[inline]
fn once_per_process(slot: &AtomicU8, find: impl FnOnce() -> u8) -> u8 {
    let known = slot.load(Ordering::Relaxed);
    if known != UNKNOWN {
        return known;
    }
    let found = find();
    slot.store(found, Ordering::Relaxed);
    found
}

/// One cache line of doubles.
#[repr(C, align(64))]
pub struct Line(pub [f64; 8]);

/// Writes a function `$name` that runs `$any` (an `#[inline(always)]` loop) in the copy for
/// the widest instruction set available here up to `$cap` (`Avx512` or `Avx2`), and `$with`,
/// which runs the copy for a given [`Isa`] (the baseline's when it is not
/// [`available`](Isa::available)). Each copy is a function of the same arguments compiled
/// with its target features; copies above the cap, or left out of this build
/// ([`Isa::compiled`]), are not written at all. The AVX-512 copy realigns its frame to a
/// cache line, so that the vector registers a loop spills land on whole cache lines
/// (measured: the ensembles' RK4 lanes ran faster).
///
/// ```text
/// multiversion! {
///     /// docs
///     pub fn name, name_with [generics] (arg: Type, ...) -> Ret where [bounds]
///         => any_loop::<turbofish>, up to Avx512;
/// }
/// ```
#[macro_export]
macro_rules! multiversion {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident, $with:ident [$($gen:tt)*]
            ($($arg:ident : $ty:ty),* $(,)?) -> $ret:ty
            where [$($wh:tt)*]
            => $any:ident $(::<$($targ:tt),*>)?, up to $cap:ident;
    ) => {
        $(#[$attr])*
        #[allow(clippy::too_many_arguments)]
        $vis fn $name<$($gen)*>($($arg: $ty),*) -> $ret where $($wh)* {
            $with $(::<$($targ),*>)? ($crate::isa::Isa::widest_up_to($crate::isa::Isa::$cap),
                                      $($arg),*)
        }

        /// The same, in the copy for `isa` (the baseline's when it is not available here).
        #[allow(clippy::too_many_arguments)]
        $vis fn $with<$($gen)*>(isa: $crate::isa::Isa, $($arg: $ty),*) -> $ret where $($wh)* {
            $crate::__isa_copy_if!($cap, Avx512,
                #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2,fma,bmi2")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx512<$($gen)*>($($arg: $ty),*) -> $ret where $($wh)* {
                    let anchor = $crate::isa::Line([0.0; 8]);
                    ::std::hint::black_box(&anchor);
                    $any $(::<$($targ),*>)? ($($arg),*)
                }
                if isa == $crate::isa::Isa::Avx512
                    && isa.available_under($crate::isa::Isa::$cap) {
                    // SAFETY: the CPU has the features the copy is compiled for.
                    return unsafe { avx512 $(::<$($targ),*>)? ($($arg),*) };
                }
            );
            $crate::__isa_copy_if!($cap, Avx2,
                #[target_feature(enable = "avx2,fma,bmi2")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx2<$($gen)*>($($arg: $ty),*) -> $ret where $($wh)* {
                    $any $(::<$($targ),*>)? ($($arg),*)
                }
                if isa == $crate::isa::Isa::Avx2
                    && isa.available_under($crate::isa::Isa::$cap) {
                    // SAFETY: as above.
                    return unsafe { avx2 $(::<$($targ),*>)? ($($arg),*) };
                }
            );
            let _ = isa;
            $any $(::<$($targ),*>)? ($($arg),*)
        }
    };
}

/// `multiversion!`'s helper: the tokens after the two names when the copy `$isa` is within
/// the cap `$cap` (AVX-512 only under an `Avx512` cap; AVX2 under both).
#[doc(hidden)]
#[macro_export]
macro_rules! __isa_copy_if {
    (Avx512, Avx512, $($body:tt)*) => {
        $crate::__isa_cfg!(all(target_arch = "x86_64", poinsot_avx512), $($body)*);
    };
    (Avx2, Avx512, $($body:tt)*) => {};
    (Avx512, Avx2, $($body:tt)*) => {
        $crate::__isa_cfg!(all(target_arch = "x86_64", poinsot_avx2), $($body)*);
    };
    (Avx2, Avx2, $($body:tt)*) => {
        $crate::__isa_cfg!(
            all(target_arch = "x86_64", any(poinsot_avx2, poinsot_avx512)), $($body)*
        );
    };
}

/// `multiversion!`'s helper: an item and an `if` statement, both under `#[cfg($pred)]`.
#[doc(hidden)]
#[macro_export]
macro_rules! __isa_cfg {
    ($pred:meta, $(#[$a:meta])* unsafe fn $($rest:tt)*) => {
        $crate::__isa_cfg!(@split $pred, [$(#[$a])* unsafe fn] $($rest)*);
    };
    (@split $pred:meta, [$($item:tt)*] $body:block $($stmt:tt)*) => {
        #[cfg($pred)]
        $($item)* $body
        #[cfg($pred)]
        $($stmt)*
    };
    (@split $pred:meta, [$($item:tt)*] $next:tt $($rest:tt)*) => {
        $crate::__isa_cfg!(@split $pred, [$($item)* $next] $($rest)*);
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
            => work, up to Avx512;
    }

    /// A loop capped at AVX2 (a single run's driver) runs its AVX2 copy on a CPU with AVX2
    /// whenever the build carries a vector copy at all: the baseline would compute its fused
    /// multiply-adds in software, ten times slower.
    #[test]
    fn a_loop_capped_at_avx2_keeps_its_copy() {
        if Isa::Avx2.supported() && (Isa::Avx2.compiled() || Isa::Avx512.compiled()) {
            assert_eq!(Isa::widest_up_to(Isa::Avx2), Isa::Avx2);
            assert!(Isa::Avx2.available_under(Isa::Avx2));
        }
        assert!(!Isa::Avx512.compiled_under(Isa::Avx2));
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
