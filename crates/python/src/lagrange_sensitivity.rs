//! Bindings of a constrained system's forward sensitivities (`poinsot_core::lagrange`'s
//! `LagrangeSensitive`): the model's expressions with their Jacobian compiled once
//! (`LagrangianTangent`), the augmented initial state of the directions, and the run of the
//! augmented system in the run's buffers (`poinsot.integrate.driver`). Checks at the boundary
//! name the argument.

use std::sync::Arc;

use crate::arrays::{Bools1, Floats1, Floats2, Ints1};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use poinsot_core::lagrange::{
    initial_tangents, rates_jacobian, LagrangeSensitive, LagrangeStart, Shape, Stabilization,
    Tangent,
};
use poinsot_core::observers::NoObserver;
use poinsot_jit::Jit;
use pyo3::prelude::*;

use crate::args::value_error;
use crate::engine::in_chunks;
use crate::lagrange::{check_point, checked_program};
use crate::sensitivity::coded_starts;
use crate::spec::{RunSpec, RunState};

/// A model's expressions and their Jacobian compiled once:
/// `LagrangianTangent(codes, values, n, m, nh, np, nu)`, the postfix program of
/// `[M, f, G, b, γ, g, h]` then `∂[M, f, G, b, γ, g]/∂[q, q̇, p, u]` (row-major) in
/// `[q, q̇, t, p, u]` (`poinsot_core::lagrange::Tangent`).
#[pyclass(frozen, module = "poinsot._core")]
pub(crate) struct LagrangianTangent {
    tangent: Arc<Tangent>,
}

#[pymethods]
impl LagrangianTangent {
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        codes: Ints1<'_>,
        values: Floats1<'_>,
        n: usize,
        m: usize,
        nh: usize,
        np: usize,
        nu: usize,
    ) -> PyResult<Self> {
        let shape = Shape { n, m, nh, np, nu };
        let outputs = shape.n_tangent_outputs();
        let program = checked_program(shape, &codes, &values, outputs, "tangent")?;
        let tangent = py
            .detach(|| Tangent::new(shape, program, &Jit))
            .map_err(value_error)?;
        Ok(LagrangianTangent {
            tangent: Arc::new(tangent),
        })
    }

    /// `(n, m, nh, np, nu)`.
    #[getter]
    fn sizes(&self) -> (usize, usize, usize, usize, usize) {
        let s = self.tangent.shape;
        (s.n, s.m, s.nh, s.np, s.nu)
    }

    /// The outputs `[M, f, G, b, γ, g, h, ∂[M, f, G, b, γ, g]/∂[q, q̇, p, u]]` at `(t, q, q̇)`
    /// with parameters `p` and inputs `u` (for tests: the Jacobian against SymPy's).
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q: Floats1<'py>,
        qd: Floats1<'py>,
        p: Floats1<'py>,
        u: Floats1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s = self.tangent.shape;
        let (q, v, p, u) = (q.as_slice()?, qd.as_slice()?, p.as_slice()?, u.as_slice()?);
        check_point(s, q, Some(v), p, u)?;
        let mut ev = self.tangent.evaluator();
        ev.evaluate(t, q, v, p, u);
        Ok(ev.parts.clone().into_pyarray(py))
    }

    /// The exact Jacobian of `ẏ = [q̇, q̈]` (physical multipliers, every constraint in play,
    /// constant inputs `u`) at `(t, y)`: `(∂ẏ/∂y (2n, 2n), ∂ẏ/∂p (2n, np), ∂ẏ/∂u (2n, nu))`;
    /// ValueError where the KKT system is singular or the rates are not finite.
    fn rates_jacobian<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        y: Floats1<'py>,
        p: Floats1<'py>,
        u: Floats1<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let s = self.tangent.shape;
        let (y, p, u) = (y.as_slice()?, p.as_slice()?, u.as_slice()?);
        check_point(s, y, None, p, u)?;
        let (jy, jp, ju) = rates_jacobian(&self.tangent, t, y, p, u).ok_or_else(|| {
            value_error(
                "the equations of motion cannot be differentiated here: the KKT system is \
                 singular or the rates are not finite",
            )
        })?;
        let n2 = 2 * s.n;
        let jy = Array2::from_shape_vec((n2, n2), jy).expect("2n × 2n");
        let jp = Array2::from_shape_vec((n2, s.np), jp).expect("2n × np");
        let ju = Array2::from_shape_vec((n2, s.nu), ju).expect("2n × nu");
        Ok((
            jy.into_pyarray(py),
            jp.into_pyarray(py),
            ju.into_pyarray(py),
        ))
    }
}

/// The directions' starts from their codes: `kinds[j]` 0 (a parameter), 1 (q0), 2 (q̇0), and
/// the coordinate `components[j]`.
fn starts_from(kinds: &[i64], components: &[i64], n: usize) -> PyResult<Vec<LagrangeStart>> {
    let known = format!(
        "kinds are 0 (a parameter), 1 (q0), 2 (qd0), components a coordinate's index below {n}"
    );
    coded_starts(kinds, components, &known, |kind, k| {
        let k = usize::try_from(k).ok().filter(|k| *k < n);
        match (kind, k) {
            (0, _) => Some(LagrangeStart::Parameter),
            (1, Some(k)) => Some(LagrangeStart::Coordinate(k)),
            (2, Some(k)) => Some(LagrangeStart::Velocity(k)),
            _ => None,
        }
    })
}

/// The directions' parameter seeds `seeds` (P, np), checked, row-major.
fn seeds_from(seeds: &Floats2<'_>, np: usize) -> PyResult<(Vec<f64>, usize)> {
    let a = seeds.as_array();
    if a.nrows() == 0 || a.ncols() != np {
        return Err(value_error(format!(
            "`seeds` must have shape (P, {np}) with P ≥ 1, found {:?}",
            a.shape()
        )));
    }
    Ok((a.iter().copied().collect(), a.nrows()))
}

/// The augmented initial state `[y0, S(0)]` (2n (1 + P),) of a run from the consistent state
/// `y0` (2n,) at `t0`: each direction's start (`kinds`, `components`: 0 a parameter, 1 a
/// coordinate, 2 a velocity) and parameter seeds `seeds` (P, np); the coordinates and
/// velocities the run solved for from the constraints (`free_q`, `free_v`) follow.
#[pyfunction]
#[pyo3(signature = (tangent, t0, y0, p, u, kinds, components, seeds, free_q, free_v))]
#[allow(clippy::too_many_arguments)]
fn lagrange_sensitivity_start<'py>(
    py: Python<'py>,
    tangent: &Bound<'py, LagrangianTangent>,
    t0: f64,
    y0: Floats1<'py>,
    p: Floats1<'py>,
    u: Floats1<'py>,
    kinds: Ints1<'py>,
    components: Ints1<'py>,
    seeds: Floats2<'py>,
    free_q: Bools1<'py>,
    free_v: Bools1<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let tangent = &tangent.get().tangent;
    let s = tangent.shape;
    let (y0, p, u) = (y0.as_slice()?, p.as_slice()?, u.as_slice()?);
    check_point(s, y0, None, p, u)?;
    let starts = starts_from(kinds.as_slice()?, components.as_slice()?, s.n)?;
    let (seeds, dirs) = seeds_from(&seeds, s.np)?;
    if dirs != starts.len() {
        return Err(value_error(format!(
            "`seeds` must have one row per direction ({}), found {dirs}",
            starts.len()
        )));
    }
    let (fq, fv) = (free_q.as_slice()?, free_v.as_slice()?);
    if fq.len() != s.n || fv.len() != s.n {
        return Err(value_error(format!(
            "`free_q` and `free_v` must hold {} flags each",
            s.n
        )));
    }
    let out = initial_tangents(tangent, t0, y0, p, u, &starts, &seeds, fq, fv)
        .map_err(|e| value_error(format!("`sensitivities`: {e}")))?;
    Ok(out.into_pyarray(py))
}

/// Integrate a constrained system (constant inputs `u`, every constraint in play) with the
/// forward sensitivities of `P` directions, each moving the parameters by a row of `seeds`
/// (P, np), for at most `steps` more steps of the run `spec` (RK4, an explicit tableau or
/// DOP853), in `state` (its state the augmented `2n (1 + P)`, from
/// `lagrange_sensitivity_start`); `control_all`: DOP853's error control weighs the
/// sensitivities too. Returns the status (also `state.status`).
#[pyfunction]
#[pyo3(signature = (tangent, p, u, alpha, beta, projection, seeds, control_all, spec, state, steps))]
#[allow(clippy::too_many_arguments)]
fn integrate_lagrange_sensitivities<'py>(
    py: Python<'py>,
    tangent: &Bound<'py, LagrangianTangent>,
    p: Floats1<'py>,
    u: Floats1<'py>,
    alpha: f64,
    beta: f64,
    projection: bool,
    seeds: Floats2<'py>,
    control_all: bool,
    spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
) -> PyResult<i64> {
    let tangent = tangent.get().tangent.clone();
    let s = tangent.shape;
    let (p, u) = (p.as_slice()?.to_vec(), u.as_slice()?.to_vec());
    let (seeds, dirs) = seeds_from(&seeds, s.np)?;
    let st = Stabilization {
        alpha,
        beta,
        projection,
    };
    let make = || LagrangeSensitive::new(&tangent, &p, &u, st, &seeds, dirs, control_all);
    make().map_err(value_error)?;
    let state = &mut *state;
    let mut run = state.run(&spec, 2 * s.n * (1 + dirs), false)?;
    // the system (its working memory) is made on the thread that runs the chunk
    let status = in_chunks(py, &mut run, steps, |r, n| {
        py.detach(|| r.chunk(&make().expect("checked above"), &mut NoObserver, n))
    })?;
    state.status = status;
    Ok(status as i64)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<LagrangianTangent>()?;
    m.add_function(wrap_pyfunction!(lagrange_sensitivity_start, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_lagrange_sensitivities, m)?)?;
    Ok(())
}
