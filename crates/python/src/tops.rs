//! Bindings of `poinsot_core::tops`: the heavy symmetric top's steady precessions (scalars).

use poinsot_core::tops;
use pyo3::prelude::*;

/// `[slow, fast]` steady-precession rates of a heavy symmetric top (rad/s): the roots of
/// `A cos θ Ω² − C ω₃ Ω + M g l = 0` (NaN when there is none at this θ).
#[pyfunction]
fn steady_precession_rates(a: f64, c: f64, mgl: f64, theta: f64, spin: f64) -> (f64, f64) {
    let [slow, fast] = tops::steady_precession_rates(a, c, mgl, theta, spin);
    (slow, fast)
}

/// The gyroscopic estimate `M g l / (C ω₃)` of a fast top's precession rate (rad/s).
#[pyfunction]
fn gyroscopic_precession_rate(c: f64, mgl: f64, spin: f64) -> f64 {
    tops::gyroscopic_precession_rate(c, mgl, spin)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(steady_precession_rates, m)?)?;
    m.add_function(wrap_pyfunction!(gyroscopic_precession_rate, m)?)?;
    Ok(())
}
