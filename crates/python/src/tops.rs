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

/// The symmetry axis (3,) of a body that is a symmetric top about a fixed point (ascending
/// principal `moments` (3,) about it, their `axes` (3, 3) columns, `c` (3,) the centre of mass
/// from the point; relative tolerance `rtol`), or None (`poinsot_core::tops::symmetric_top_axis`).
#[pyfunction]
fn symmetric_top_axis(
    moments: [f64; 3],
    axes: [[f64; 3]; 3],
    c: [f64; 3],
    rtol: f64,
) -> Option<[f64; 3]> {
    tops::symmetric_top_axis(moments, &axes, c, rtol)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(symmetric_top_axis, m)?)?;
    m.add_function(wrap_pyfunction!(steady_precession_rates, m)?)?;
    m.add_function(wrap_pyfunction!(gyroscopic_precession_rate, m)?)?;
    Ok(())
}
