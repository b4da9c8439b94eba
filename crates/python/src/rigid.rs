//! Bindings of the rigid-body formulas on batches: frames, initial states, the pivot,
//! energies and momenta, particles. Shapes are checked here; `poinsot` reshapes `(..., 3)`
//! inputs to rows before calling.

use crate::arrays::{Floats1, Floats2, Floats3, Ints1};
use numpy::ndarray::{Array1, Array2, Array3, ArrayView3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadwriteArray2, PyUntypedArrayMethods};
use poinsot_core::forces::total_potential;
use poinsot_core::invariants::{angular_momentum_body, kinetic_energy, rotational_energy};
use poinsot_core::layout::{load, STATE_SIZE};
use poinsot_core::rigid::{
    self, initial_state, orthogonality_error, particle_position, particle_velocity,
    pivot_constrained,
};
use poinsot_core::so3::{Mat3, Vec3};
use poinsot_core::system::RigidStructure;
use poinsot_core::systems::{NoUser, Rigid};
use pyo3::prelude::*;

use crate::args::{body_from, forces_from, mat3_from, rows, v3, value_error};
use crate::engine::PyUser;

fn mats<'a>(a: &'a Floats3<'_>, name: &str) -> PyResult<ArrayView3<'a, f64>> {
    let v = a.as_array();
    if v.shape()[1..] != [3, 3] {
        return Err(value_error(format!(
            "`{name}` must have shape (n, 3, 3), found {:?}",
            v.shape()
        )));
    }
    Ok(v)
}

#[inline]
fn m3(a: &ArrayView3<f64>, i: usize) -> Mat3 {
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| a[[i, r, c]]))
}

fn same_rows(n: usize, m: usize, a: &str, b: &str) -> PyResult<()> {
    if n != m {
        return Err(value_error(format!(
            "`{a}` and `{b}` must have the same number of rows ({n} ≠ {m})"
        )));
    }
    Ok(())
}

/// States (n, 18) from the body frame to the principal frame of `axes` (or back).
#[pyfunction]
#[pyo3(signature = (axes, states, inverse=false))]
fn states_principal<'py>(
    py: Python<'py>,
    axes: Floats2<'py>,
    states: Floats2<'py>,
    inverse: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = mat3_from(&axes, "axes")?;
    let y = rows(&states, STATE_SIZE, "states")?;
    let mut out = Array2::<f64>::zeros((y.nrows(), STATE_SIZE));
    let mut buf = [0.0; STATE_SIZE];
    for (i, row) in y.outer_iter().enumerate() {
        let src: Vec<f64> = row.iter().copied().collect();
        if inverse {
            rigid::state_from_principal(&e, &src, &mut buf);
        } else {
            rigid::state_to_principal(&e, &src, &mut buf);
        }
        for k in 0..STATE_SIZE {
            out[[i, k]] = buf[k];
        }
    }
    Ok(out.into_pyarray(py))
}

/// Body-frame initial states (N, 18), by the rules of `poinsot.simulate`: `q` (1 or N, 3, 3),
/// `omega` (N, 3); `r`, `v` (1 or N, 3, or 0 rows: the default). With `out` (N, 18),
/// C-contiguous, they are written there and None is returned.
#[pyfunction]
#[pyo3(signature = (q, omega, r, v, com, c, pivot, has_pivot, line, out=None))]
#[allow(clippy::too_many_arguments)]
fn initial_states<'py>(
    py: Python<'py>,
    q: Floats3<'py>,
    omega: Floats2<'py>,
    r: Floats2<'py>,
    v: Floats2<'py>,
    com: [f64; 3],
    c: [f64; 3],
    pivot: [f64; 3],
    has_pivot: bool,
    line: [f64; 3],
    out: Option<PyReadwriteArray2<'py, f64>>,
) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
    let q = mats(&q, "Q")?;
    let w = rows(&omega, 3, "omega")?;
    let r = rows(&r, 3, "R")?;
    let v = rows(&v, 3, "V")?;
    let n = w.nrows();
    let mut out = out;
    let mut own = Vec::new();
    let dest: &mut [f64] = match &mut out {
        Some(a) => {
            if a.shape() != [n, STATE_SIZE] {
                return Err(value_error(format!(
                    "`out` must have shape ({n}, {STATE_SIZE}), found {:?}",
                    a.shape()
                )));
            }
            crate::ensemble::c_order(a.is_c_contiguous(), a.as_slice_mut(), "out")?
        }
        None => {
            own = vec![0.0; n * STATE_SIZE];
            &mut own[..]
        }
    };
    let pick = |len: usize, i: usize| if len > 1 { i } else { 0 };
    for (i, row) in dest.chunks_exact_mut(STATE_SIZE).enumerate() {
        let qi = m3(&q, pick(q.shape()[0], i));
        let ri = (r.nrows() > 0).then(|| v3(&r, pick(r.nrows(), i)));
        let vi = (v.nrows() > 0).then(|| v3(&v, pick(v.nrows(), i)));
        let y = initial_state(&qi, v3(&w, i), ri, vi, com, c, pivot, has_pivot, line);
        row.copy_from_slice(&y);
    }
    if out.is_some() {
        return Ok(None);
    }
    Array2::from_shape_vec((n, STATE_SIZE), own)
        .map(|a| Some(a.into_pyarray(py)))
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

/// Where the pivot is in space for an engine state: `P = R − Q c`.
#[pyfunction]
fn pivot_point(body: Floats1<'_>, state: Floats1<'_>) -> PyResult<[f64; 3]> {
    let b = body_from(body.as_slice()?)?;
    let y = state.as_slice()?;
    if y.len() != STATE_SIZE {
        return Err(value_error("`state` must hold 18 numbers"));
    }
    Ok(rigid::pivot_point(&b, &load(y)))
}

/// Engine states (n, 18) with `R, V` reset from the attitude about the pivot.
#[pyfunction]
fn project_onto_pivot<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    states: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let b = body_from(body.as_slice()?)?;
    let y = rows(&states, STATE_SIZE, "states")?;
    let mut out = y.to_owned();
    for mut row in out.outer_iter_mut() {
        let s: Vec<f64> = row.iter().copied().collect();
        let c = pivot_constrained(&b, load(&s));
        for k in 0..STATE_SIZE {
            row[k] = c[k];
        }
    }
    Ok(out.into_pyarray(py))
}

/// `(ẏ (18,), wrench (6,))` of an engine state: eqs (07)–(09) under the built-in forces and
/// the user's (a Python callable of the body-frame state, as `integrate_rigid` takes it); the
/// wrench is about the reference point, its torque in the principal frame.
#[pyfunction]
#[pyo3(signature = (body, force_kind, force_params, axes, user, t, state))]
#[allow(clippy::too_many_arguments)]
fn rigid_rates<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    axes: Floats2<'py>,
    user: Option<Bound<'py, PyAny>>,
    t: f64,
    state: Floats1<'py>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let b = body_from(body.as_slice()?)?;
    let forces = forces_from(force_kind.as_slice()?, &force_params)?;
    let axes = mat3_from(&axes, "axes")?;
    let y = state.as_slice()?;
    if y.len() != STATE_SIZE {
        return Err(value_error("`state` must hold 18 numbers"));
    }
    let y = load(y);
    let (r, w) = match user {
        Some(func) => {
            let sys = Rigid::new(b, forces, axes, Some(PyUser::new(py, func)));
            let w = sys.wrench(t, &y);
            if let Some(err) = sys.user.as_ref().and_then(|u| u.take_error()) {
                return Err(err);
            }
            (rigid::rigid_rates(&b, &y, w), w)
        }
        None => {
            let sys: Rigid<NoUser> = Rigid::new(b, forces, axes, None);
            let w = sys.wrench(t, &y);
            (rigid::rigid_rates(&b, &y, w), w)
        }
    };
    Ok((
        Array1::from(r.to_vec()).into_pyarray(py),
        Array1::from(w.to_vec()).into_pyarray(py),
    ))
}

/// `((F (3,), τ (3,)), U)`: one built-in force's wrench (force in space, torque about the
/// centre of mass, body frame) and potential at a body-frame state of a body with parameters
/// `body` (its own frame).
#[pyfunction]
fn force_wrench_potential(
    kind: i64,
    params: Floats1<'_>,
    body: Floats1<'_>,
    t: f64,
    state: Floats1<'_>,
) -> PyResult<(([f64; 3], [f64; 3]), f64)> {
    let b = body_from(body.as_slice()?)?;
    let kind = poinsot_core::forces::ForceKind::from_code(kind)
        .ok_or_else(|| value_error(format!("`kind` = {kind} is no force kind")))?;
    let p = params.as_slice()?;
    if p.len() != poinsot_core::layout::FORCE_PARAMS {
        return Err(value_error("`params` must hold FORCE_PARAMS numbers"));
    }
    let mut row = [0.0; poinsot_core::layout::FORCE_PARAMS];
    row.copy_from_slice(p);
    let y = state.as_slice()?;
    if y.len() != STATE_SIZE {
        return Err(value_error("`state` must hold 18 numbers"));
    }
    let f = poinsot_core::forces::Force { kind, p: row };
    let y = load(y);
    let w = f.wrench(&b, t, &y);
    Ok((
        ([w[0], w[1], w[2]], [w[3], w[4], w[5]]),
        f.potential(&b, t, &y),
    ))
}

/// `(parameters (BODY_SIZE,), degenerate)`: the body as the engine reads it
/// (`poinsot_core::rigid::body_parameters`).
#[pyfunction]
fn rigid_body_parameters<'py>(
    py: Python<'py>,
    mass: f64,
    moments: [f64; 3],
    axes: Floats2<'py>,
    com_offset: [f64; 3],
    inertia_com: Floats2<'py>,
    has_pivot: bool,
) -> PyResult<(Bound<'py, PyArray1<f64>>, bool)> {
    let axes = mat3_from(&axes, "axes")?;
    let a = mat3_from(&inertia_com, "inertia_com")?;
    let (p, degenerate) = rigid::body_parameters(mass, moments, &axes, com_offset, &a, has_pivot);
    Ok((Array1::from(p.to_vec()).into_pyarray(py), degenerate))
}

/// The parameter vector of a body from its parts (principal frame of the inertia about the
/// reference point): `Body::vector`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn body_vector<'py>(
    py: Python<'py>,
    mass: f64,
    moments: [f64; 3],
    com_offset: [f64; 3],
    inertia_com: Floats2<'py>,
    pivot: [f64; 3],
    has_pivot: bool,
    rotor: i32,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = mat3_from(&inertia_com, "inertia_com")?;
    let p =
        poinsot_core::layout::Body::vector(mass, moments, com_offset, &a, pivot, has_pivot, rotor);
    Ok(Array1::from(p.to_vec()).into_pyarray(py))
}

/// Total potential energy of the built-in forces at samples `t` (n,), engine states (n, 18).
#[pyfunction]
fn potential_energies<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    t: Floats1<'py>,
    states: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let b = body_from(body.as_slice()?)?;
    let forces = forces_from(force_kind.as_slice()?, &force_params)?;
    let t = t.as_slice()?;
    let y = rows(&states, STATE_SIZE, "states")?;
    same_rows(t.len(), y.nrows(), "t", "states")?;
    let out: Vec<f64> = (0..t.len())
        .map(|i| {
            let s: Vec<f64> = y.row(i).iter().copied().collect();
            total_potential(&forces, &b, t[i], &load(&s))
        })
        .collect();
    Ok(Array1::from(out).into_pyarray(py))
}

/// Kinetic energy (12), `½ Aω·ω + ½ M |V|²`, per row of `omega`, `v` (n, 3).
#[pyfunction]
fn kinetic_energies<'py>(
    py: Python<'py>,
    inertia: Floats2<'py>,
    mass: f64,
    omega: Floats2<'py>,
    v: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = mat3_from(&inertia, "inertia")?;
    let w = rows(&omega, 3, "omega")?;
    let v = rows(&v, 3, "V")?;
    same_rows(w.nrows(), v.nrows(), "omega", "V")?;
    let out: Vec<f64> = (0..w.nrows())
        .map(|i| kinetic_energy(&a, mass, v3(&w, i), v3(&v, i)))
        .collect();
    Ok(Array1::from(out).into_pyarray(py))
}

/// Rotational kinetic energy `½ ω·Aω` per row of `omega` (n, 3).
#[pyfunction]
fn rotational_energies<'py>(
    py: Python<'py>,
    inertia: Floats2<'py>,
    omega: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = mat3_from(&inertia, "inertia")?;
    let w = rows(&omega, 3, "omega")?;
    let out: Vec<f64> = (0..w.nrows())
        .map(|i| rotational_energy(&a, v3(&w, i)))
        .collect();
    Ok(Array1::from(out).into_pyarray(py))
}

/// Angular momentum per row: `A ω` (body frame) without `q`; `Q A ω` (about the centre of
/// mass, space frame) with `q` (n, 3, 3); plus `M R × V` (eq. (03), about the origin) when `r`
/// and `v` are given.
#[pyfunction]
#[pyo3(signature = (inertia, omega, q=None, mass=0.0, r=None, v=None))]
fn angular_momenta<'py>(
    py: Python<'py>,
    inertia: Floats2<'py>,
    omega: Floats2<'py>,
    q: Option<Floats3<'py>>,
    mass: f64,
    r: Option<Floats2<'py>>,
    v: Option<Floats2<'py>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = mat3_from(&inertia, "inertia")?;
    let w = rows(&omega, 3, "omega")?;
    let n = w.nrows();
    let q = q.as_ref().map(|q| mats(q, "Q")).transpose()?;
    if let Some(q) = &q {
        same_rows(n, q.shape()[0], "omega", "Q")?;
    }
    let rv = match (&r, &v) {
        (Some(r), Some(v)) => {
            let (r, v) = (rows(r, 3, "R")?, rows(v, 3, "V")?);
            same_rows(n, r.nrows(), "omega", "R")?;
            same_rows(n, v.nrows(), "omega", "V")?;
            Some((r, v))
        }
        (None, None) => None,
        _ => return Err(value_error("give both `R` and `V`, or neither")),
    };
    let mut out = Array2::<f64>::zeros((n, 3));
    for i in 0..n {
        let p = angular_momentum_body(&a, v3(&w, i));
        let mut l = match &q {
            Some(q) => {
                let qi = m3(q, i);
                [0, 1, 2].map(|j| qi[j][0] * p[0] + qi[j][1] * p[1] + qi[j][2] * p[2])
            }
            None => p,
        };
        if let Some((r, v)) = &rv {
            let c = poinsot_core::so3::cross(v3(r, i), v3(v, i));
            for j in 0..3 {
                l[j] += mass * c[j];
            }
        }
        for j in 0..3 {
            out[[i, j]] = l[j];
        }
    }
    Ok(out.into_pyarray(py))
}

/// `Q ω` per row: ω in the space frame.
#[pyfunction]
fn omega_space<'py>(
    py: Python<'py>,
    q: Floats3<'py>,
    omega: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = mats(&q, "Q")?;
    let w = rows(&omega, 3, "omega")?;
    same_rows(w.nrows(), q.shape()[0], "omega", "Q")?;
    let mut out = Array2::<f64>::zeros((w.nrows(), 3));
    for i in 0..w.nrows() {
        let qi = m3(&q, i);
        for j in 0..3 {
            out[[i, j]] = qi[j][0] * w[[i, 0]] + qi[j][1] * w[[i, 1]] + qi[j][2] * w[[i, 2]];
        }
    }
    Ok(out.into_pyarray(py))
}

/// `max |QᵀQ − I|` per matrix (n, 3, 3).
#[pyfunction]
fn orthogonality_errors<'py>(
    py: Python<'py>,
    q: Floats3<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let q = mats(&q, "Q")?;
    let out: Vec<f64> = (0..q.shape()[0])
        .map(|i| {
            let mut y = [0.0; STATE_SIZE];
            let qi = m3(&q, i);
            for r in 0..3 {
                for c in 0..3 {
                    y[6 + 3 * r + c] = qi[r][c];
                }
            }
            orthogonality_error(&y)
        })
        .collect();
    Ok(Array1::from(out).into_pyarray(py))
}

/// Particle positions `Q u + R` at every sample: `r` (n, 3), `q` (n, 3, 3), offsets `u`
/// (N, 3) → (n, N, 3); with `v` and `omega` (n, 3) the velocities `Q(ω × u) + V` instead.
#[pyfunction]
#[pyo3(signature = (r, q, u, omega=None))]
fn particle_motion<'py>(
    py: Python<'py>,
    r: Floats2<'py>,
    q: Floats3<'py>,
    u: Floats2<'py>,
    omega: Option<Floats2<'py>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let r = rows(&r, 3, "R")?;
    let q = mats(&q, "Q")?;
    let u = rows(&u, 3, "u")?;
    same_rows(r.nrows(), q.shape()[0], "R", "Q")?;
    let w = omega.as_ref().map(|w| rows(w, 3, "omega")).transpose()?;
    let (n, m) = (r.nrows(), u.nrows());
    let mut out = Array3::<f64>::zeros((n, m, 3));
    for k in 0..n {
        let qk = m3(&q, k);
        for i in 0..m {
            let p = match &w {
                Some(w) => particle_velocity(v3(&r, k), &qk, v3(w, k), v3(&u, i)),
                None => particle_position(v3(&r, k), &qk, v3(&u, i)),
            };
            for j in 0..3 {
                out[[k, i, j]] = p[j];
            }
        }
    }
    Ok(out.into_pyarray(py))
}

/// `(V, ω, residual)` of particle data by the notebook's rules (`poinsot_core::rigid`).
#[pyfunction]
fn rigid_motion_from_particles<'py>(
    py: Python<'py>,
    masses: Floats1<'py>,
    positions: Floats2<'py>,
    velocities: Floats2<'py>,
    center: [f64; 3],
    inertia_inv: Floats2<'py>,
) -> PyResult<([f64; 3], [f64; 3], Bound<'py, PyArray1<f64>>)> {
    let m = masses.as_slice()?;
    let p = rows(&positions, 3, "positions")?;
    let v = rows(&velocities, 3, "velocities")?;
    same_rows(m.len(), p.nrows(), "masses", "positions")?;
    same_rows(m.len(), v.nrows(), "masses", "velocities")?;
    let pos: Vec<Vec3> = (0..m.len()).map(|i| v3(&p, i)).collect();
    let vel: Vec<Vec3> = (0..m.len()).map(|i| v3(&v, i)).collect();
    let a = mat3_from(&inertia_inv, "inertia_inv")?;
    let mut residual = vec![0.0; m.len()];
    let (vv, w) = rigid::rigid_motion_from_particles(m, &pos, &vel, center, &a, &mut residual);
    Ok((vv, w, Array1::from(residual).into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(states_principal, m)?)?;
    m.add_function(wrap_pyfunction!(initial_states, m)?)?;
    m.add_function(wrap_pyfunction!(pivot_point, m)?)?;
    m.add_function(wrap_pyfunction!(project_onto_pivot, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_rates, m)?)?;
    m.add_function(wrap_pyfunction!(force_wrench_potential, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_body_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(body_vector, m)?)?;
    m.add_function(wrap_pyfunction!(potential_energies, m)?)?;
    m.add_function(wrap_pyfunction!(kinetic_energies, m)?)?;
    m.add_function(wrap_pyfunction!(rotational_energies, m)?)?;
    m.add_function(wrap_pyfunction!(angular_momenta, m)?)?;
    m.add_function(wrap_pyfunction!(omega_space, m)?)?;
    m.add_function(wrap_pyfunction!(orthogonality_errors, m)?)?;
    m.add_function(wrap_pyfunction!(particle_motion, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_motion_from_particles, m)?)?;
    // the layouts, for the Python package (one place: crates/core/src/layout.rs)
    use poinsot_core::layout as l;
    for (name, value) in [
        ("STATE_SIZE", l::STATE_SIZE),
        ("R_AT", l::R_AT),
        ("V_AT", l::V_AT),
        ("Q_AT", l::Q_AT),
        ("OMEGA_AT", l::OMEGA_AT),
        ("MASS", l::MASS),
        ("INV_MASS", l::INV_MASS),
        ("MOMENTS", l::MOMENTS),
        ("INV_MOMENTS", l::INV_MOMENTS),
        ("COM_OFFSET", l::COM_OFFSET),
        ("INERTIA_COM", l::INERTIA_COM),
        ("PIVOT", l::PIVOT),
        ("HAS_PIVOT", l::HAS_PIVOT),
        ("ROTOR", l::ROTOR),
        ("BODY_SIZE", l::BODY_SIZE),
        ("FORCE_PARAMS", l::FORCE_PARAMS),
    ] {
        m.add(name, value)?;
    }
    let kinds = pyo3::types::PyDict::new(m.py());
    use poinsot_core::forces::ForceKind as K;
    for (name, kind) in [
        ("gravity", K::Gravity),
        ("central_gravity", K::CentralGravity),
        ("spring", K::Spring),
        ("linear_drag", K::LinearDrag),
        ("quadratic_drag", K::QuadraticDrag),
        ("point_force", K::PointForce),
        ("torque", K::Torque),
    ] {
        kinds.set_item(name, kind as i64)?;
    }
    m.add("FORCE_KINDS", kinds)?;
    Ok(())
}
