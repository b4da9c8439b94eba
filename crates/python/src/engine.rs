//! Bindings of the rigid-body engine: one call integrates a body (or resumes a run) with any
//! registered method, in the buffers the Python layer owns (`poinsot.integrate.driver`).
//! Checks at the boundary name the argument; the GIL is released while no Python force runs;
//! an interrupt (Ctrl-C) is honoured between chunks of steps.

use std::cell::RefCell;

use crate::arrays::{Floats1, Floats2, Ints1};
use numpy::PyReadwriteArray1;
use poinsot_core::drivers::Status;
use poinsot_core::layout::STATE_SIZE;
use poinsot_core::observers::{FlipObserver, NoObserver, Observer};
use poinsot_core::rigid::State;
use poinsot_core::system::{RigidStructure, VectorField};
use poinsot_core::systems::{Rigid, TorqueFree, UserWrench};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

pub(crate) use crate::args::{body_from, forces_from, mat3_from, value_error};
pub(crate) use crate::spec::{Run, RunSpec, RunState};

/// Steps per chunk between two checks for an interrupt.
const CHUNK: u64 = 1 << 16;

/// Forces given as a Python callable `user(t, y) -> (Fx, Fy, Fz, τx, τy, τz)` of the time and
/// the body-frame state: the slow path (the GIL is held for the whole run). The first error it
/// raises is kept and re-raised when the run stops.
pub(crate) struct PyUser<'py> {
    py: Python<'py>,
    func: Bound<'py, PyAny>,
    error: RefCell<Option<PyErr>>,
}

impl<'py> PyUser<'py> {
    pub(crate) fn new(py: Python<'py>, func: Bound<'py, PyAny>) -> Self {
        PyUser {
            py,
            func,
            error: RefCell::new(None),
        }
    }
    pub(crate) fn take_error(&self) -> Option<PyErr> {
        self.error.borrow_mut().take()
    }
}

impl UserWrench for PyUser<'_> {
    fn wrench(&self, t: f64, y: &State) -> Option<[f64; 6]> {
        if self.error.borrow().is_some() {
            return None;
        }
        let y = numpy::PyArray1::from_slice(self.py, y);
        let result = self
            .func
            .call1((t, y))
            .and_then(|r| r.extract::<[f64; 6]>())
            .map_err(|e| {
                if e.is_instance_of::<PyTypeError>(self.py) {
                    PyTypeError::new_err(format!(
                        "a force callable must return six numbers (Fx, Fy, Fz, τx, τy, τz): {e}"
                    ))
                } else {
                    e
                }
            });
        match result {
            Ok(w) => Some(w),
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                None
            }
        }
    }
}

/// A C function `int f(double t, const double *y, double *out)` (`y` the body-frame state,
/// `out` the six numbers of the wrench; non-zero return: failure), called by address: a numba
/// `cfunc`, a ctypes function, a symjit function.
pub(crate) struct CUser {
    pub(crate) f: extern "C" fn(f64, *const f64, *mut f64) -> i32,
}

impl UserWrench for CUser {
    #[inline(always)]
    fn wrench(&self, t: f64, y: &State) -> Option<[f64; 6]> {
        let mut out = [0.0; 6];
        ((self.f)(t, y.as_ptr(), out.as_mut_ptr()) == 0).then_some(out)
    }
}

/// The whole call: chunks of at most [`CHUNK`] steps (`one` runs a chunk, releasing the GIL
/// or not), an interrupt check between them, at most `steps` steps in all.
pub(crate) fn in_chunks(
    py: Python<'_>,
    r: &mut Run,
    steps: u64,
    mut one: impl FnMut(&mut Run, u64) -> Status,
) -> PyResult<Status> {
    let mut left = steps;
    loop {
        let now = left.min(CHUNK);
        let status = one(r, now);
        left -= now.min(left);
        if status != Status::Running || left == 0 {
            return Ok(status);
        }
        py.check_signals()?;
    }
}

/// A run of a rigid body, at most `steps` steps; the GIL released when `release` (no Python
/// runs inside).
fn drive<S, O>(
    py: Python<'_>,
    sys: &S,
    obs: &mut O,
    r: &mut Run,
    steps: u64,
    release: bool,
) -> PyResult<Status>
where
    S: RigidStructure + Sync + ?Sized,
    O: Observer + Send,
{
    r.enter(sys);
    let status = if release {
        in_chunks(py, r, steps, |r, n| {
            py.detach(|| r.chunk_rigid(sys, obs, n))
        })
    } else {
        in_chunks(py, r, steps, |r, n| r.chunk_rigid(sys, obs, n))
    };
    r.leave(sys);
    status
}

/// Integrate one rigid body (`body`, its forces `force_kind` (k,), `force_params` (k, P) and
/// principal `axes`, the user's forces `user`: a callable, a C function's address or None)
/// for at most `steps` more steps of the run `spec`, in `state` (see
/// `poinsot.integrate.driver.integrate`); `flips`: three (1,) arrays of an observer of the
/// flips of ω. Returns the status (also `state.status`).
#[pyfunction]
#[pyo3(signature = (body, force_kind, force_params, axes, user, spec, state, steps, flips=None))]
#[allow(clippy::too_many_arguments)]
fn integrate_rigid<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    axes: Floats2<'py>,
    user: Option<Bound<'py, PyAny>>,
    spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
    flips: Option<(
        PyReadwriteArray1<'py, f64>,
        PyReadwriteArray1<'py, f64>,
        PyReadwriteArray1<'py, f64>,
    )>,
) -> PyResult<i64> {
    let body = body_from(body.as_slice()?)?;
    let forces = forces_from(force_kind.as_slice()?, &force_params)?;
    let axes = mat3_from(&axes, "axes")?;
    let state = &mut *state;
    let mut run = state.run(&spec, STATE_SIZE, true)?;
    let mut flips = flips;
    let status = match (&mut flips, user) {
        (_, Some(func)) => match c_user(&func)? {
            Some(cu) => {
                let sys = Rigid::new(body, forces, axes, Some(cu));
                drive_any(py, &sys, &mut flips, &mut run, steps, true)?
            }
            None => {
                let sys = Rigid::new(body, forces, axes, Some(PyUser::new(py, func)));
                let status = drive_unsync(py, &sys, &mut flips, &mut run, steps)?;
                if let Some(err) = sys.user.as_ref().and_then(|u| u.take_error()) {
                    return Err(err);
                }
                status
            }
        },
        (_, None) if forces.is_empty() && !body.has_pivot => {
            let sys = TorqueFree::new(body);
            drive_any(py, &sys, &mut flips, &mut run, steps, true)?
        }
        (_, None) => {
            let sys: Rigid = Rigid::new(body, forces, axes, None);
            drive_any(py, &sys, &mut flips, &mut run, steps, true)?
        }
    };
    state.status = status;
    Ok(status as i64)
}

/// The user's forces as a C function when `func` is an address (an int), else `None` (a
/// Python callable).
pub(crate) fn c_user(func: &Bound<'_, PyAny>) -> PyResult<Option<CUser>> {
    let Ok(address) = func.extract::<usize>() else {
        return Ok(None);
    };
    if address == 0 {
        return Err(value_error("`user` must be a non-null function address"));
    }
    // SAFETY: the caller promises a C function of this signature at `address`
    // (poinsot.forces.CustomForce checks the ctypes/cfunc signature).
    let f: extern "C" fn(f64, *const f64, *mut f64) -> i32 =
        unsafe { std::mem::transmute(address) };
    Ok(Some(CUser { f }))
}

type Flips<'py> = Option<(
    PyReadwriteArray1<'py, f64>,
    PyReadwriteArray1<'py, f64>,
    PyReadwriteArray1<'py, f64>,
)>;

fn drive_any<S: RigidStructure + Sync + ?Sized>(
    py: Python<'_>,
    sys: &S,
    flips: &mut Flips,
    run: &mut Run,
    steps: u64,
    release: bool,
) -> PyResult<Status> {
    match flips {
        Some((first, last, count)) => {
            let mut obs = FlipObserver {
                first: first.as_slice_mut()?,
                last: last.as_slice_mut()?,
                count: count.as_slice_mut()?,
                offset: 0,
            };
            drive(py, sys, &mut obs, run, steps, release)
        }
        None => drive(py, sys, &mut NoObserver, run, steps, release),
    }
}

/// A run whose system calls Python (it holds the GIL throughout).
fn drive_unsync<S: RigidStructure + ?Sized>(
    py: Python<'_>,
    sys: &S,
    flips: &mut Flips,
    run: &mut Run,
    steps: u64,
) -> PyResult<Status> {
    run.enter(sys);
    let status = match flips {
        Some((first, last, count)) => {
            let mut obs = FlipObserver {
                first: first.as_slice_mut()?,
                last: last.as_slice_mut()?,
                count: count.as_slice_mut()?,
                offset: 0,
            };
            in_chunks(py, run, steps, |r, n| r.chunk_rigid(sys, &mut obs, n))
        }
        None => in_chunks(py, run, steps, |r, n| {
            r.chunk_rigid(sys, &mut NoObserver, n)
        }),
    };
    run.leave(sys);
    status
}

/// A vector field given in Python: `rhs(t, y) -> ẏ` and, optionally, `project(y, t) -> y`
/// onto the system's constraint manifold. The slow path: the GIL is held for the whole run;
/// the first error a callable raises is kept and re-raised when the run stops.
struct PyField<'py> {
    py: Python<'py>,
    rhs: Bound<'py, PyAny>,
    project: Option<Bound<'py, PyAny>>,
    dim: usize,
    error: RefCell<Option<PyErr>>,
}

impl PyField<'_> {
    fn call(&self, f: &Bound<'_, PyAny>, args: (f64, &[f64]), swap: bool, out: &mut [f64]) {
        if self.error.borrow().is_some() {
            out.fill(f64::NAN);
            return;
        }
        let y = numpy::PyArray1::from_slice(self.py, args.1);
        let result = if swap {
            f.call1((y, args.0))
        } else {
            f.call1((args.0, y))
        };
        let values = result.and_then(|r| {
            let a = r
                .extract::<Floats1<'_>>()
                .map(|a| a.as_slice().map(|s| s.to_vec()));
            match a {
                Ok(Ok(v)) => Ok(v),
                _ => r.extract::<Vec<f64>>(),
            }
        });
        match values {
            Ok(v) if v.len() == self.dim => out.copy_from_slice(&v),
            Ok(v) => {
                *self.error.borrow_mut() = Some(PyTypeError::new_err(format!(
                    "the right-hand side must return {} numbers, found {}",
                    self.dim,
                    v.len()
                )));
                out.fill(f64::NAN);
            }
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                out.fill(f64::NAN);
            }
        }
    }
}

impl VectorField for PyField<'_> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        self.call(&self.rhs, (t, y), false, out);
    }
    fn project(&self, t: f64, y: &mut [f64]) -> bool {
        let Some(p) = &self.project else {
            return false;
        };
        let y0 = y.to_vec();
        self.call(p, (t, &y0), true, y);
        true
    }
    fn failed(&self) -> bool {
        self.error.borrow().is_some()
    }
}

/// Integrate a vector field given in Python (`rhs(t, y)`, optional `project(y, t)`) for at
/// most `steps` more steps of the run `spec` (the adaptive method or an explicit tableau), in
/// `state`. Returns the status (also `state.status`).
#[pyfunction]
#[pyo3(signature = (rhs, project, spec, state, steps))]
fn integrate_python<'py>(
    py: Python<'py>,
    rhs: Bound<'py, PyAny>,
    project: Option<Bound<'py, PyAny>>,
    spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
) -> PyResult<i64> {
    if !rhs.is_callable() {
        return Err(PyTypeError::new_err("`rhs` must be a function rhs(t, y)"));
    }
    let state = &mut *state;
    let dim = state.z.len();
    let mut run = state.run(&spec, dim, false)?;
    let sys = PyField {
        py,
        rhs,
        project: project.filter(|p| !p.is_none()),
        dim,
        error: RefCell::new(None),
    };
    let status = in_chunks(py, &mut run, steps, |r, n| {
        r.chunk(&sys, &mut NoObserver, n)
    })?;
    state.status = status;
    if let Some(err) = sys.error.borrow_mut().take() {
        return Err(err);
    }
    Ok(status as i64)
}

/// The Butcher tableau `(A (s, s), B (s,), C (s,))` of a built-in method: `"rk4"` or
/// `"dop853"` (its 12 stages; the dense output's stay in the core).
#[pyfunction]
fn tableau<'py>(
    py: Python<'py>,
    name: &str,
) -> PyResult<(
    Bound<'py, numpy::PyArray2<f64>>,
    Bound<'py, numpy::PyArray1<f64>>,
    Bound<'py, numpy::PyArray1<f64>>,
)> {
    use numpy::ndarray::{Array1, Array2};
    use numpy::IntoPyArray;
    use poinsot_core::tableaux as t;
    let (a, b, c): (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) = match name {
        "rk4" => (
            t::RK4_A.iter().map(|r| r.to_vec()).collect(),
            t::RK4_B.to_vec(),
            t::RK4_C.to_vec(),
        ),
        "dop853" => {
            let s = t::DOP853_STAGES;
            (
                t::DOP853_A[..s].iter().map(|r| r[..s].to_vec()).collect(),
                t::DOP853_B.to_vec(),
                t::DOP853_C[..s].to_vec(),
            )
        }
        _ => {
            return Err(value_error(format!(
                "no built-in tableau {name:?} (\"rk4\", \"dop853\")"
            )))
        }
    };
    let s = b.len();
    let a = Array2::from_shape_vec((s, s), a.concat()).expect("square tableau");
    Ok((
        a.into_pyarray(py),
        Array1::from(b).into_pyarray(py),
        Array1::from(c).into_pyarray(py),
    ))
}

/// The composition `(flows, kicks, kick_first)` of a built-in exact-flow splitting: `"strang"`,
/// `"bm4"` or `"bm6"` (`poinsot_core::tableaux`): the flows' and the kicks' fractions of a
/// step in the order they run, kick first or flow first.
#[pyfunction]
fn composition<'py>(
    py: Python<'py>,
    name: &str,
) -> PyResult<(
    Bound<'py, numpy::PyArray1<f64>>,
    Bound<'py, numpy::PyArray1<f64>>,
    bool,
)> {
    match poinsot_core::tableaux::composition(name) {
        Some((first, flows, kicks)) => Ok((
            numpy::PyArray1::from_slice(py, flows),
            numpy::PyArray1::from_slice(py, kicks),
            first,
        )),
        None => Err(value_error(format!(
            "no built-in composition {name:?} (\"strang\", \"bm4\", \"bm6\")"
        ))),
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(tableau, m)?)?;
    m.add_function(wrap_pyfunction!(composition, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_rigid, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_python, m)?)?;
    Ok(())
}
