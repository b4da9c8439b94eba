//! Bindings of the forward sensitivities of a rigid body's run (`poinsot_core::sensitivity`):
//! the augmented initial state of the directions, and the run of the augmented system in the
//! run's buffers (`poinsot.integrate.driver`). Checks at the boundary name the argument.

use crate::arrays::{Floats1, Floats2, Ints1};
use crate::engine::in_chunks;
use numpy::{IntoPyArray, PyArray1};
use poinsot_core::drivers::is_rk4;
use poinsot_core::forces::Force;
use poinsot_core::layout::{load, Body, FORCE_PARAMS, STATE_SIZE};
use poinsot_core::observers::NoObserver;
use poinsot_core::relative::{RelativeOptions, RELATIVE_STATE_SIZE};
use poinsot_core::sensitivity::{
    initial_tangents, relative_initial_tangents, RelativeSensitive, Sensitive, Start,
};
use poinsot_core::spec::Method;
use pyo3::prelude::*;

use crate::args::{body_from, forces_from, mat3_from, value_error};
use crate::relative::CarrierArg;
use crate::spec::{RunSpec, RunState};

/// The directions' starts from their codes `kinds` (p,) and `components` (p,).
fn starts_from(kinds: &[i64], components: &[i64]) -> PyResult<Vec<Start>> {
    let known = "kinds are 0 (a parameter), 1 (omega0), 2 (Q0), 3 (R0), 4 (V0), components 0, \
                 1 or 2";
    coded_starts(kinds, components, known, Start::from_code)
}

/// Directions from their codes `(kinds[j], components[j])` by `decode`, checked: one
/// component per kind, and an unknown pair refused with the direction's index and `known`.
pub(crate) fn coded_starts<T>(
    kinds: &[i64],
    components: &[i64],
    known: &str,
    decode: impl Fn(i64, i64) -> Option<T>,
) -> PyResult<Vec<T>> {
    if kinds.len() != components.len() {
        return Err(value_error(format!(
            "`components` must have one entry per direction ({}), found {}",
            kinds.len(),
            components.len()
        )));
    }
    kinds
        .iter()
        .zip(components)
        .enumerate()
        .map(|(j, (&kind, &k))| {
            decode(kind, k).ok_or_else(|| {
                value_error(format!(
                    "direction {j}: unknown start ({kind}, {k}); {known}"
                ))
            })
        })
        .collect()
}

/// The augmented initial state `[z0, S_1(0), …, S_P(0)]` (18 (1 + P),): `z0` (18,) the engine
/// state (principal frame), `axes` (3, 3) the principal axes as columns, each direction's
/// start `kinds[j]` (0 a parameter, 1 ω0, 2 the rotation vector of Q0, 3 R0, 4 V0) and
/// component `components[j]`; `omega_space`: ω0 was given in the space frame.
#[pyfunction]
#[pyo3(signature = (body, axes, z0, kinds, components, omega_space=false))]
fn sensitivity_start<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    axes: Floats2<'py>,
    z0: Floats1<'py>,
    kinds: Ints1<'py>,
    components: Ints1<'py>,
    omega_space: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let body = body_from(body.as_slice()?)?;
    let axes = mat3_from(&axes, "axes")?;
    let z0 = z0.as_slice()?;
    if z0.len() != STATE_SIZE {
        return Err(value_error(format!(
            "`z0` must hold {STATE_SIZE} numbers, found {}",
            z0.len()
        )));
    }
    let starts = starts_from(kinds.as_slice()?, components.as_slice()?)?;
    Ok(initial_tangents(&body, &axes, &load(z0), &starts, omega_space).into_pyarray(py))
}

/// The seeds `moment_seeds` (P, 3) and `force_seeds` (P, 10 k) of `P` ≥ 1 directions, for `k`
/// forces, checked, as the core takes them.
fn seeds_from(
    moment_seeds: &Floats2<'_>,
    force_seeds: &Floats2<'_>,
    nf: usize,
) -> PyResult<(Vec<[f64; 3]>, Vec<[f64; FORCE_PARAMS]>)> {
    let (ms, fs) = (moment_seeds.as_array(), force_seeds.as_array());
    let p = ms.nrows();
    if p == 0 || ms.ncols() != 3 {
        return Err(value_error(format!(
            "`moment_seeds` must have shape (P, 3) with P ≥ 1, found {:?}",
            ms.shape()
        )));
    }
    if fs.nrows() != p || fs.ncols() != nf * FORCE_PARAMS {
        return Err(value_error(format!(
            "`force_seeds` must have shape ({p}, {}), found {:?}",
            nf * FORCE_PARAMS,
            fs.shape()
        )));
    }
    let mut rows = Vec::with_capacity(p * nf);
    for j in 0..p {
        for i in 0..nf {
            rows.push(std::array::from_fn(|m| fs[[j, i * FORCE_PARAMS + m]]));
        }
    }
    let moments = (0..p)
        .map(|j| [ms[[j, 0]], ms[[j, 1]], ms[[j, 2]]])
        .collect();
    Ok((moments, rows))
}

/// The body, its built-in forces and the directions' seeds, checked.
type Lowered = (Body, Vec<Force>, Vec<[f64; 3]>, Vec<[f64; FORCE_PARAMS]>);

fn lowered(
    body: &Floats1<'_>,
    force_kind: &Ints1<'_>,
    force_params: &Floats2<'_>,
    moment_seeds: &Floats2<'_>,
    force_seeds: &Floats2<'_>,
) -> PyResult<Lowered> {
    let body = body_from(body.as_slice()?)?;
    let forces = forces_from(force_kind.as_slice()?, force_params)?;
    let (moments, rows) = seeds_from(moment_seeds, force_seeds, forces.len())?;
    Ok((body, forces, moments, rows))
}

/// Integrate a body under built-in forces with the forward sensitivities of `P` directions,
/// for at most `steps` more steps of the run `spec` (RK4, an explicit tableau or DOP853), in
/// `state` (its state the augmented `18 (1 + P)`, from `sensitivity_start`). Each direction
/// moves the principal moments by `moment_seeds[j]` (P, 3) and force `i`'s parameter row by
/// `force_seeds[j, i·10 : (i+1)·10]` (P, 10 k); `control_all`: DOP853's error control weighs
/// the sensitivities too. Returns the status (also `state.status`).
#[pyfunction]
#[pyo3(signature = (body, force_kind, force_params, moment_seeds, force_seeds, control_all, spec, state, steps))]
#[allow(clippy::too_many_arguments)]
fn integrate_sensitivities<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    moment_seeds: Floats2<'py>,
    force_seeds: Floats2<'py>,
    control_all: bool,
    spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
) -> PyResult<i64> {
    let (body, forces, moments, force_rows) = lowered(
        &body,
        &force_kind,
        &force_params,
        &moment_seeds,
        &force_seeds,
    )?;
    let p = moments.len();
    let sys = Sensitive::new(body, &forces, &moments, &force_rows, control_all);
    let state = &mut *state;
    let lie = match spec.core().method {
        Method::Rk4 | Method::Erk(_) | Method::Dop853(_) => false,
        Method::Rkmk(tab) if is_rk4(&tab) => true,
        Method::Splitting | Method::ExactSplitting(_) => true,
        other => {
            return Err(value_error(format!(
                "method {:?} has no sensitivities: they are computed with rk4, rkmk4, \
                 splitting, the exact-flow splittings, an explicit tableau or dop853",
                other.name()
            )))
        }
    };
    let mut run = state.run(&spec, STATE_SIZE * (1 + p), lie)?;
    run.convert_sensitive(&sys, true);
    let status = in_chunks(py, &mut run, steps, |r, n| {
        py.detach(|| r.chunk_sensitive(&sys, &mut NoObserver, n))
    });
    run.convert_sensitive(&sys, false);
    let status = status?;
    state.status = status;
    Ok(status as i64)
}

/// The augmented initial state `[z0, S(0)]` (33 (1 + P),) of a relative motion: `z0` (33,)
/// in the engine's frame, the starts as `sensitivity_start` takes them (1 ω_r0, 2 the
/// rotation vector of Q_r0 in the carrier frame, 3 r0, 4 v_r0).
#[pyfunction]
fn relative_sensitivity_start<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    axes: Floats2<'py>,
    z0: Floats1<'py>,
    kinds: Ints1<'py>,
    components: Ints1<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let body = body_from(body.as_slice()?)?;
    let axes = mat3_from(&axes, "axes")?;
    let z = z0.as_slice()?;
    let z: &[f64; RELATIVE_STATE_SIZE] = z.try_into().map_err(|_| {
        value_error(format!(
            "`z0` must hold {RELATIVE_STATE_SIZE} numbers, found {}",
            z.len()
        ))
    })?;
    let starts = starts_from(kinds.as_slice()?, components.as_slice()?)?;
    Ok(relative_initial_tangents(&body, &axes, z, &starts).into_pyarray(py))
}

/// Integrate a body relative to its carrier (built-in forces) with the forward sensitivities
/// of `P` directions (seeds as `integrate_sensitivities` takes them), for at most `steps`
/// more steps of the run `spec`, in `state` (its state the augmented `33 (1 + P)`).
#[pyfunction]
#[pyo3(signature = (body, force_kind, force_params, carrier, balance_transport, hold_com, moment_seeds, force_seeds, control_all, spec, state, steps))]
#[allow(clippy::too_many_arguments)]
fn integrate_relative_sensitivities<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    carrier: Bound<'py, PyAny>,
    balance_transport: bool,
    hold_com: bool,
    moment_seeds: Floats2<'py>,
    force_seeds: Floats2<'py>,
    control_all: bool,
    spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
) -> PyResult<i64> {
    let (body, forces, moments, force_rows) = lowered(
        &body,
        &force_kind,
        &force_params,
        &moment_seeds,
        &force_seeds,
    )?;
    let p = moments.len();
    let options = RelativeOptions {
        balance_transport,
        hold_com,
    };
    let carrier = CarrierArg::from(carrier)?;
    let state = &mut *state;
    let mut run = state.run(&spec, RELATIVE_STATE_SIZE * (1 + p), false)?;
    let status = match carrier.native() {
        Some(c) => {
            let sys = RelativeSensitive::new(
                body,
                &forces,
                c,
                options,
                &moments,
                &force_rows,
                control_all,
            );
            in_chunks(py, &mut run, steps, |r, n| {
                py.detach(|| r.chunk(&sys, &mut NoObserver, n))
            })?
        }
        None => {
            let c = carrier.any();
            let sys = RelativeSensitive::new(
                body,
                &forces,
                c,
                options,
                &moments,
                &force_rows,
                control_all,
            );
            in_chunks(py, &mut run, steps, |r, n| {
                r.chunk(&sys, &mut NoObserver, n)
            })?
        }
    };
    state.status = status;
    if let Some(e) = carrier.take_error() {
        return Err(e);
    }
    Ok(status as i64)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(relative_sensitivity_start, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_relative_sensitivities, m)?)?;
    m.add_function(wrap_pyfunction!(sensitivity_start, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_sensitivities, m)?)?;
    Ok(())
}
