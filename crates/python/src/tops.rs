//! Bindings of `poinsot_core::tops`: the heavy symmetric top's steady precessions (scalars).

use numpy::ndarray::{Array1, Array2, Array3, Array4};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArray4};
use poinsot_core::heavy_top;
use poinsot_core::tops;
use pyo3::prelude::*;

use crate::args::{rows, value_error};
use crate::arrays::{Floats1, Floats2};

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

/// The heavy symmetric top in closed form (`poinsot_core::heavy_top`), for `N` motions of
/// one top `(A, C, M g l)`: `angles` (N, 3) the initial z-x-z Euler angles `(ψ₀, θ₀, φ₀)` of
/// the axis frame relative to the space frame with z up, `rates` (N, 3) their rates, `t`
/// (n,). Returns `(motion (N, n, 6): [ψ, θ, φ, ψ̇, θ̇, φ̇], summary (N, 9): [u₁, u₂, u₃,
/// nutation period, mean precession rate, ω₃, m, θ_min, θ_max])`. The error names the argument whose
/// values are not finite or not positive.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn heavy_top_motions<'py>(
    py: Python<'py>,
    a: f64,
    c: f64,
    mgl: f64,
    angles: Floats2<'py>,
    rates: Floats2<'py>,
    t: Floats1<'py>,
) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray2<f64>>)> {
    check_constants(a, c, mgl)?;
    let angles = rows(&angles, 3, "angles")?;
    let rates = rows(&rates, 3, "rates")?;
    let t = t.as_slice()?;
    let n = angles.nrows();
    if rates.nrows() != n {
        return Err(value_error(format!(
            "`rates` must have one row per row of `angles` ({n}), found {}",
            rates.nrows()
        )));
    }
    for (name, x) in [("angles", &angles), ("rates", &rates)] {
        if let Some(i) = x
            .rows()
            .into_iter()
            .position(|r| !r.iter().all(|v| v.is_finite()))
        {
            return Err(value_error(format!("`{name}[{i}]` must be finite")));
        }
    }
    check_times(t)?;
    let mut motion = Array3::<f64>::zeros((n, t.len(), 6));
    let mut summary = Array2::<f64>::zeros((n, heavy_top::SUMMARY_SIZE));
    py.detach(|| {
        for i in 0..n {
            let row = |x: &numpy::ndarray::ArrayView2<f64>| [x[[i, 0]], x[[i, 1]], x[[i, 2]]];
            let top = heavy_top::TopMotion::new(a, c, mgl, row(&angles), row(&rates));
            for (k, &tk) in t.iter().enumerate() {
                for (j, v) in top.at(tk).into_iter().enumerate() {
                    motion[[i, k, j]] = v;
                }
            }
            for (j, v) in top.summary().into_iter().enumerate() {
                summary[[i, j]] = v;
            }
        }
    });
    Ok((motion.into_pyarray(py), summary.into_pyarray(py)))
}

/// `A`, `C` and `M g l`, each finite and positive.
fn check_constants(a: f64, c: f64, mgl: f64) -> PyResult<()> {
    for (name, v) in [("A", a), ("C", c), ("mgl", mgl)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(value_error(format!(
                "`{name}` must be a positive number, found {v}"
            )));
        }
    }
    Ok(())
}

/// Every time finite.
fn check_times(t: &[f64]) -> PyResult<()> {
    if let Some(k) = t.iter().position(|v| !v.is_finite()) {
        return Err(value_error(format!(
            "`t[{k}]` must be finite, found {}",
            t[k]
        )));
    }
    Ok(())
}

/// The exact derivatives of one heavy top's closed form (`poinsot_core::heavy_top::TopTangent`)
/// along the directions `(A, C, M g l, ψ₀, θ₀, φ₀, ψ̇₀, θ̇₀, φ̇₀)`: from the initial `angles`
/// (3,) and `rates` (3,), at the times `t` (n,), `(motion (n, 6), ∂motion (n, 6, 9), summary
/// (4,): [u₁, u₂, nutation period, mean precession rate], ∂summary (4, 9), the axis frame's
/// attitude (n, 3, 3) and its derivatives (n, 3, 3, 9), ω in the axis frame (n, 3) and its
/// derivatives (n, 3, 9))`. A ValueError where the closed form has no derivatives (no
/// nutation, the axis reaching the vertical).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn heavy_top_derivatives<'py>(
    py: Python<'py>,
    a: f64,
    c: f64,
    mgl: f64,
    angles: [f64; 3],
    rates: [f64; 3],
    t: Floats1<'py>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray4<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
)> {
    check_constants(a, c, mgl)?;
    for (name, x) in [("angles", angles), ("rates", rates)] {
        if !x.iter().all(|v| v.is_finite()) {
            return Err(value_error(format!("`{name}` must be finite")));
        }
    }
    let t = t.as_slice()?;
    check_times(t)?;
    let tangent = heavy_top::TopTangent::new(a, c, mgl, angles, rates).map_err(value_error)?;
    let dirs = heavy_top::TOP_DIRECTIONS;
    let mut motion = Array2::<f64>::zeros((t.len(), 6));
    let mut d = Array3::<f64>::zeros((t.len(), 6, dirs));
    let mut q = Array3::<f64>::zeros((t.len(), 3, 3));
    let mut dq = Array4::<f64>::zeros((t.len(), 3, 3, dirs));
    let mut w = Array2::<f64>::zeros((t.len(), 3));
    let mut dw = Array3::<f64>::zeros((t.len(), 3, dirs));
    for (k, &tk) in t.iter().enumerate() {
        let (value, rows) = tangent.at(tk);
        for (i, (v, row)) in value.iter().zip(&rows).enumerate() {
            motion[[k, i]] = *v;
            for (j, x) in row.iter().enumerate() {
                d[[k, i, j]] = *x;
            }
        }
        let (qv, qd, wv, wd) = tangent.attitude_at(tk);
        for r in 0..3 {
            w[[k, r]] = wv[r];
            for j in 0..dirs {
                dw[[k, r, j]] = wd[r][j];
            }
            for c in 0..3 {
                q[[k, r, c]] = qv[r][c];
                for j in 0..dirs {
                    dq[[k, r, c, j]] = qd[r][c][j];
                }
            }
        }
    }
    let (summary, ds) = tangent.summary();
    let ds = Array2::from_shape_fn((4, dirs), |(i, j)| ds[i][j]);
    Ok((
        motion.into_pyarray(py),
        d.into_pyarray(py),
        Array1::from(summary.to_vec()).into_pyarray(py),
        ds.into_pyarray(py),
        q.into_pyarray(py),
        dq.into_pyarray(py),
        w.into_pyarray(py),
        dw.into_pyarray(py),
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(heavy_top_motions, m)?)?;
    m.add_function(wrap_pyfunction!(heavy_top_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(symmetric_top_axis, m)?)?;
    m.add_function(wrap_pyfunction!(steady_precession_rates, m)?)?;
    m.add_function(wrap_pyfunction!(gyroscopic_precession_rate, m)?)?;
    Ok(())
}
