//! `poinsot._core`: thin bindings of `poinsot-core`. Arguments are checked here (names in the
//! errors), array arguments in any layout and real dtype are made contiguous in one place
//! (`arrays`), the GIL is released around every computation, and nothing here holds physics.

#![allow(clippy::needless_range_loop, clippy::type_complexity)]

use pyo3::prelude::*;

mod args;
mod arrays;
mod engine;
mod ensemble;
mod exact;
mod geometry;
mod gyrostat;
mod lagrange;
mod lagrange_run;
mod lagrange_sensitivity;
mod relative;
mod rigid;
mod sensitivity;
mod spec;
mod tops;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", poinsot_core::version::VERSION)?;
    // the instruction sets this build carries copies of the vectorised loops for
    // (crates/core/build.rs, POINSOT_ISAS), and the one an ensemble runs in here
    let isas: Vec<&str> = poinsot_core::isa::Isa::ALL
        .into_iter()
        .filter(|isa| isa.compiled())
        .map(|isa| isa.name())
        .collect();
    m.add("COMPILED_ISAS", isas)?;
    m.add(
        "ISA",
        poinsot_core::isa::Isa::widest_up_to(poinsot_core::isa::Isa::Avx512).name(),
    )?;
    engine::register(m)?;
    spec::register(m)?;
    for (name, status) in [
        ("RUNNING", poinsot_core::drivers::Status::Running),
        ("FINISHED", poinsot_core::drivers::Status::Finished),
        ("NONFINITE", poinsot_core::drivers::Status::NonFinite),
        (
            "STEP_TOO_SMALL",
            poinsot_core::drivers::Status::StepTooSmall,
        ),
        ("OUTPUT_FULL", poinsot_core::drivers::Status::OutputFull),
        (
            "CALLBACK_FAILED",
            poinsot_core::drivers::Status::CallbackFailed,
        ),
        ("TERMINATED", poinsot_core::drivers::Status::Terminated),
    ] {
        m.add(name, status as i64)?;
    }
    rigid::register(m)?;
    sensitivity::register(m)?;
    relative::register(m)?;
    geometry::register(m)?;
    exact::register(m)?;
    ensemble::register(m)?;
    lagrange::register(m)?;
    lagrange_sensitivity::register(m)?;
    gyrostat::register(m)?;
    tops::register(m)?;
    Ok(())
}
