//! Which instruction sets the vectorised loops are compiled for (`src/isa.rs`).
//!
//! `POINSOT_ISAS` chooses, on x86-64 (elsewhere only the baseline exists):
//!
//! * `native` (the default of every profile but `dist`): the baseline and the widest of AVX2
//!   and AVX-512 that the building machine runs (with AVX2 for the loops that stop there) — a
//!   source build for this machine, compiled in two thirds of the time of `all`; moved to a
//!   machine without that copy, it runs the baseline's, with the same numbers. When
//!   cross-compiling, `native` means `all`.
//! * `all` (the default of the `dist` profile): AVX-512, AVX2 and the baseline, for a wheel
//!   that runs fast anywhere.
//! * a comma-separated list of `avx2` and `avx512` (the baseline is always there), or
//!   `baseline` alone.

use std::env;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(poinsot_avx2)");
    println!("cargo::rustc-check-cfg=cfg(poinsot_avx512)");
    println!("cargo::rerun-if-env-changed=POINSOT_ISAS");
    println!("cargo::rerun-if-changed=build.rs");
    // the `dist` profile builds under target/[TRIPLE/]dist/build/
    let out_dir = env::var("OUT_DIR").unwrap_or_default();
    let parts: Vec<&str> = out_dir.split(std::path::MAIN_SEPARATOR).collect();
    let dist = parts.windows(2).any(|w| w == ["dist", "build"]);
    let default = if dist { "all" } else { "native" };
    let wanted = env::var("POINSOT_ISAS").unwrap_or_else(|_| default.into());
    let arch = env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    let native = env::var("HOST").ok() == env::var("TARGET").ok();
    let (avx2, avx512) = match wanted.trim() {
        _ if arch != "x86_64" => (false, false),
        "all" => (true, true),
        "native" if !native => (true, true),
        "native" => host_widest(),
        "baseline" => (false, false),
        list => {
            let names: Vec<&str> = list.split(',').map(str::trim).collect();
            for name in &names {
                if !matches!(*name, "avx2" | "avx512" | "baseline") {
                    panic!(
                        "POINSOT_ISAS: unknown instruction set {name:?} (use native, all, \
                         baseline, or a list of avx2 and avx512)"
                    );
                }
            }
            (names.contains(&"avx2"), names.contains(&"avx512"))
        }
    };
    if avx2 {
        println!("cargo::rustc-cfg=poinsot_avx2");
    }
    if avx512 {
        println!("cargo::rustc-cfg=poinsot_avx512");
    }
}

/// The widest vector extension of the machine running this build: (AVX2, AVX-512), at most
/// one of them.
#[cfg(target_arch = "x86_64")]
fn host_widest() -> (bool, bool) {
    use std::arch::is_x86_feature_detected as has;
    let avx2 = has!("avx2") && has!("fma") && has!("bmi2");
    let avx512 = avx2 && has!("avx512f") && has!("avx512dq") && has!("avx512vl");
    (avx2 && !avx512, avx512)
}

#[cfg(not(target_arch = "x86_64"))]
fn host_widest() -> (bool, bool) {
    (false, false)
}
