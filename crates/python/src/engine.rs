//! Bindings of the rigid-body engine: one call integrates a body (or resumes a run) with any
//! registered method, in the buffers the Python layer owns (`poinsot.integrate.driver`).
//! Checks at the boundary name the argument; the GIL is released while no Python force runs;
//! an interrupt (Ctrl-C) is honoured between chunks of steps.

use std::cell::RefCell;

use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray1, PyReadwriteArray2};
use poinsot_core::drivers::{
    run_adaptive, run_fixed_native, AdaptiveState, Clock, Counters, Erk, FixedMethod, Output,
    Rk4Rigid, RkmkRigid, Sampling, Splitting, Status,
};
use poinsot_core::layout::STATE_SIZE;
use poinsot_core::observers::{FlipObserver, NoObserver, Observer};
use poinsot_core::rigid::State;
use poinsot_core::steppers::{momentum_to_velocity, velocity_to_momentum, Control, Tableau};
use poinsot_core::system::{RigidStructure, VectorField};
use poinsot_core::systems::{Rigid, TorqueFree, UserWrench};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

pub(crate) use crate::args::{body_from, forces_from, mat3_from, value_error};

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

/// Everything one call of the engine reads and writes.
pub(crate) struct Run<'a> {
    method: &'a str,
    tab: Tableau<'a>,
    clock: &'a mut [f64],
    z: &'a mut [f64],
    f: &'a mut [f64],
    dt: f64,
    control: Control,
    sampling: Sampling<'a>,
    out: Output<'a>,
    counters: &'a mut [i64],
    max_steps: u64,
}

/// The buffers of one call, as Python passes them (see `poinsot.integrate.driver`).
pub(crate) struct RunArgs<'py> {
    pub a: PyReadonlyArray2<'py, f64>,
    pub b: PyReadonlyArray1<'py, f64>,
    pub c: PyReadonlyArray1<'py, f64>,
    pub clock: PyReadwriteArray1<'py, f64>,
    pub z: PyReadwriteArray1<'py, f64>,
    pub f: PyReadwriteArray1<'py, f64>,
    pub dt: f64,
    pub control: PyReadonlyArray1<'py, f64>,
    pub t_end: f64,
    pub t_eval: PyReadonlyArray1<'py, f64>,
    pub save_every: i64,
    pub out_t: PyReadwriteArray1<'py, f64>,
    pub out_y: PyReadwriteArray2<'py, f64>,
    pub counters: PyReadwriteArray1<'py, i64>,
    pub max_steps: i64,
}

impl<'py> RunArgs<'py> {
    /// The run over these buffers, checked against the state's length `dim` and the methods
    /// the system offers.
    pub(crate) fn run<'a>(
        &'a mut self,
        method: &'a str,
        methods: &[&str],
        dim: usize,
    ) -> PyResult<Run<'a>> {
        if !methods.contains(&method) {
            return Err(value_error(format!(
                "`method` must be one of {methods:?} for this system, found {method:?}"
            )));
        }
        let (a_s, b_s, c_s) = (self.a.as_slice()?, self.b.as_slice()?, self.c.as_slice()?);
        let s = b_s.len();
        if a_s.len() != s * s || c_s.len() != s {
            return Err(value_error("the tableau must be A (s, s), B (s,), C (s,)"));
        }
        let ctl = self.control.as_slice()?;
        if ctl.len() != 7 {
            return Err(value_error("`control` must hold 7 numbers"));
        }
        let clock = self.clock.as_slice_mut()?;
        if clock.len() != 2 {
            return Err(value_error("`clock` must hold 2 numbers (t, h)"));
        }
        let z = self.z.as_slice_mut()?;
        if z.len() != dim {
            return Err(value_error(format!("`z` must hold {dim} numbers")));
        }
        let f = self.f.as_slice_mut()?;
        if f.len() != dim {
            return Err(value_error(format!("`f` must hold {dim} numbers")));
        }
        let out_t = self.out_t.as_slice_mut()?;
        let m = out_t.len();
        let out_y = self.out_y.as_slice_mut()?;
        if out_y.len() != m * dim {
            return Err(value_error(format!(
                "`out_y` must have shape (len(out_t), {dim})"
            )));
        }
        let counters = self.counters.as_slice_mut()?;
        if counters.len() != 6 {
            return Err(value_error("`counters` must hold 6 integers"));
        }
        Ok(Run {
            method,
            tab: Tableau {
                a: a_s,
                b: b_s,
                c: c_s,
            },
            clock,
            z,
            f,
            dt: self.dt,
            control: Control {
                rtol: ctl[0],
                atol: ctl[1],
                safety: ctl[2],
                min_factor: ctl[3],
                max_factor: ctl[4],
                max_step: ctl[5],
                first_step: ctl[6],
            },
            sampling: Sampling {
                t_end: self.t_end,
                t_eval: self.t_eval.as_slice()?,
                every: self.save_every.max(1) as u64,
            },
            out: Output { t: out_t, y: out_y },
            counters,
            max_steps: self.max_steps.max(0) as u64,
        })
    }
}

fn counters_in(c: &[i64]) -> Counters {
    Counters {
        n_out: c[1] as usize,
        next_sample: c[2] as usize,
        n_steps: c[3] as u64,
        n_fev: c[4] as u64,
        n_rejected: c[5] as u64,
    }
}

fn counters_out(k: &Counters, status: Status, c: &mut [i64]) {
    c[0] = status as i64;
    c[1] = k.n_out as i64;
    c[2] = k.next_sample as i64;
    c[3] = k.n_steps as i64;
    c[4] = k.n_fev as i64;
    c[5] = k.n_rejected as i64;
}

/// One chunk of `steps` of a time loop, with the run's clock and counters read before and
/// written after.
fn in_chunk(
    r: &mut Run,
    body: impl FnOnce(&mut Run, &mut Clock, &mut Counters) -> Status,
) -> Status {
    let mut clock = Clock {
        t: r.clock[0],
        h: r.clock[1],
    };
    let mut k = counters_in(r.counters);
    let status = body(r, &mut clock, &mut k);
    r.clock[0] = clock.t;
    r.clock[1] = clock.h;
    counters_out(&k, status, r.counters);
    status
}

/// One chunk of a run of any system: the adaptive method (`"dop853"`) or an explicit tableau
/// (`"erk"`).
pub(crate) fn chunk_general<S: VectorField + ?Sized, O: Observer>(
    sys: &S,
    obs: &mut O,
    r: &mut Run,
    steps: u64,
) -> Status {
    in_chunk(r, |r, clock, k| {
        if r.method == "dop853" {
            let mut st = AdaptiveState { f: r.f.to_vec() };
            let s = run_adaptive(
                sys,
                obs,
                clock,
                r.z,
                &mut st,
                &r.control,
                &r.sampling,
                &mut r.out,
                k,
                steps,
            );
            r.f.copy_from_slice(&st.f);
            s
        } else {
            let tab = r.tab;
            fixed(sys, &mut Erk::new(tab, sys.dim()), obs, clock, r, k, steps)
        }
    })
}

/// One chunk of a run of a rigid body: any method, those that use its structure included.
fn chunk<S: RigidStructure + ?Sized, O: Observer>(
    sys: &S,
    obs: &mut O,
    r: &mut Run,
    steps: u64,
) -> Status {
    match r.method {
        "rk4" => in_chunk(r, |r, clock, k| {
            fixed(sys, &mut Rk4Rigid, obs, clock, r, k, steps)
        }),
        "rkmk" => in_chunk(r, |r, clock, k| {
            let tab = r.tab;
            fixed(sys, &mut RkmkRigid::new(tab), obs, clock, r, k, steps)
        }),
        "splitting" => in_chunk(r, |r, clock, k| {
            fixed(sys, &mut Splitting, obs, clock, r, k, steps)
        }),
        _ => chunk_general(sys, obs, r, steps),
    }
}

fn fixed<S: VectorField + ?Sized, M: FixedMethod<S>, O: Observer>(
    sys: &S,
    m: &mut M,
    obs: &mut O,
    clock: &mut Clock,
    r: &mut Run,
    k: &mut Counters,
    steps: u64,
) -> Status {
    run_fixed_native(
        sys,
        m,
        obs,
        clock,
        r.z,
        r.dt,
        &r.sampling,
        &mut r.out,
        k,
        steps,
    )
}

/// The whole call: chunks of at most [`CHUNK`] steps (`one` runs a chunk, releasing the GIL
/// or not), an interrupt check between them, the run's step budget honoured.
pub(crate) fn in_chunks(
    py: Python<'_>,
    r: &mut Run,
    mut one: impl FnMut(&mut Run, u64) -> Status,
) -> PyResult<Status> {
    let mut left = r.max_steps;
    loop {
        let steps = left.min(CHUNK);
        let status = one(r, steps);
        left -= steps.min(left);
        if status != Status::Running || left == 0 {
            return Ok(status);
        }
        py.check_signals()?;
    }
}

/// A run of a rigid body; the GIL released when `release` (no Python runs inside).
fn drive<S, O>(py: Python<'_>, sys: &S, obs: &mut O, r: &mut Run, release: bool) -> PyResult<Status>
where
    S: RigidStructure + Sync + ?Sized,
    O: Observer + Send,
{
    MomentumState::enter(sys, r);
    let status = if release {
        in_chunks(py, r, |r, steps| py.detach(|| chunk(sys, obs, r, steps)))
    } else {
        in_chunks(py, r, |r, steps| chunk(sys, obs, r, steps))
    };
    MomentumState::leave(sys, r);
    status
}

/// Integrate one rigid body: see `poinsot.integrate.driver.integrate`. Returns the status.
#[pyfunction]
#[pyo3(signature = (
    body, force_kind, force_params, axes, user, method, a, b, c, clock, z, f, dt, control,
    t_end, t_eval, save_every, out_t, out_y, counters, max_steps, flips=None
))]
#[allow(clippy::too_many_arguments)]
fn integrate_rigid<'py>(
    py: Python<'py>,
    body: PyReadonlyArray1<'py, f64>,
    force_kind: PyReadonlyArray1<'py, i64>,
    force_params: PyReadonlyArray2<'py, f64>,
    axes: PyReadonlyArray2<'py, f64>,
    user: Option<Bound<'py, PyAny>>,
    method: &str,
    a: PyReadonlyArray2<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
    c: PyReadonlyArray1<'py, f64>,
    clock: PyReadwriteArray1<'py, f64>,
    z: PyReadwriteArray1<'py, f64>,
    f: PyReadwriteArray1<'py, f64>,
    dt: f64,
    control: PyReadonlyArray1<'py, f64>,
    t_end: f64,
    t_eval: PyReadonlyArray1<'py, f64>,
    save_every: i64,
    out_t: PyReadwriteArray1<'py, f64>,
    out_y: PyReadwriteArray2<'py, f64>,
    counters: PyReadwriteArray1<'py, i64>,
    max_steps: i64,
    flips: Option<(
        PyReadwriteArray1<'py, f64>,
        PyReadwriteArray1<'py, f64>,
        PyReadwriteArray1<'py, f64>,
    )>,
) -> PyResult<i64> {
    let body = body_from(body.as_slice()?)?;
    let forces = forces_from(force_kind.as_slice()?, &force_params)?;
    let axes = mat3_from(&axes, "axes")?;
    let mut args = RunArgs {
        a,
        b,
        c,
        clock,
        z,
        f,
        dt,
        control,
        t_end,
        t_eval,
        save_every,
        out_t,
        out_y,
        counters,
        max_steps,
    };
    let mut run = args.run(
        method,
        &["dop853", "rk4", "erk", "rkmk", "splitting"],
        STATE_SIZE,
    )?;
    let mut flips = flips;
    let status = match (&mut flips, user) {
        (_, Some(func)) => match c_user(&func)? {
            Some(cu) => {
                let sys = Rigid::new(body, forces, axes, Some(cu));
                drive_any(py, &sys, &mut flips, &mut run, true)?
            }
            None => {
                let sys = Rigid::new(body, forces, axes, Some(PyUser::new(py, func)));
                let status = drive_unsync(py, &sys, &mut flips, &mut run)?;
                if let Some(err) = sys.user.as_ref().and_then(|u| u.take_error()) {
                    return Err(err);
                }
                status
            }
        },
        (_, None) if forces.is_empty() && !body.has_pivot => {
            drive_any(py, &TorqueFree::new(body), &mut flips, &mut run, true)?
        }
        (_, None) => {
            let sys: Rigid = Rigid::new(body, forces, axes, None);
            drive_any(py, &sys, &mut flips, &mut run, true)?
        }
    };
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
            drive(py, sys, &mut obs, run, release)
        }
        None => drive(py, sys, &mut NoObserver, run, release),
    }
}

/// The splitting method steps the momentum state `[R, V, Q, π]`: the caller's state is
/// turned into it for the call and back at the end (once per call, not per chunk).
struct MomentumState;

impl MomentumState {
    fn enter<S: RigidStructure + ?Sized>(sys: &S, r: &mut Run) -> Self {
        if r.method == "splitting" {
            let y = r.z.to_vec();
            velocity_to_momentum(sys, &y, r.z);
        }
        MomentumState
    }
    fn leave<S: RigidStructure + ?Sized>(sys: &S, r: &mut Run) {
        if r.method == "splitting" {
            let y = momentum_to_velocity(sys, r.z);
            r.z.copy_from_slice(&y);
        }
    }
}

/// A run whose system calls Python (it holds the GIL throughout).
fn drive_unsync<S: RigidStructure + ?Sized>(
    py: Python<'_>,
    sys: &S,
    flips: &mut Flips,
    run: &mut Run,
) -> PyResult<Status> {
    MomentumState::enter(sys, run);
    let status = match flips {
        Some((first, last, count)) => {
            let mut obs = FlipObserver {
                first: first.as_slice_mut()?,
                last: last.as_slice_mut()?,
                count: count.as_slice_mut()?,
                offset: 0,
            };
            in_chunks(py, run, |r, steps| chunk(sys, &mut obs, r, steps))
        }
        None => in_chunks(py, run, |r, steps| chunk(sys, &mut NoObserver, r, steps)),
    };
    MomentumState::leave(sys, run);
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
                .extract::<PyReadonlyArray1<f64>>()
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

/// Integrate a vector field given in Python (`rhs(t, y)`, optional `project(y, t)`): the
/// adaptive method or an explicit tableau, in the buffers of `poinsot.integrate.driver`.
/// Returns the status.
#[pyfunction]
#[pyo3(signature = (
    rhs, project, method, a, b, c, clock, z, f, dt, control, t_end, t_eval, save_every, out_t,
    out_y, counters, max_steps
))]
#[allow(clippy::too_many_arguments)]
fn integrate_python<'py>(
    py: Python<'py>,
    rhs: Bound<'py, PyAny>,
    project: Option<Bound<'py, PyAny>>,
    method: &str,
    a: PyReadonlyArray2<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
    c: PyReadonlyArray1<'py, f64>,
    clock: PyReadwriteArray1<'py, f64>,
    z: PyReadwriteArray1<'py, f64>,
    f: PyReadwriteArray1<'py, f64>,
    dt: f64,
    control: PyReadonlyArray1<'py, f64>,
    t_end: f64,
    t_eval: PyReadonlyArray1<'py, f64>,
    save_every: i64,
    out_t: PyReadwriteArray1<'py, f64>,
    out_y: PyReadwriteArray2<'py, f64>,
    counters: PyReadwriteArray1<'py, i64>,
    max_steps: i64,
) -> PyResult<i64> {
    if !rhs.is_callable() {
        return Err(PyTypeError::new_err("`rhs` must be a function rhs(t, y)"));
    }
    let dim = z.as_slice()?.len();
    let mut args = RunArgs {
        a,
        b,
        c,
        clock,
        z,
        f,
        dt,
        control,
        t_end,
        t_eval,
        save_every,
        out_t,
        out_y,
        counters,
        max_steps,
    };
    let mut run = args.run(method, &["dop853", "erk"], dim)?;
    let sys = PyField {
        py,
        rhs,
        project: project.filter(|p| !p.is_none()),
        dim,
        error: RefCell::new(None),
    };
    let status = in_chunks(py, &mut run, |r, steps| {
        chunk_general(&sys, &mut NoObserver, r, steps)
    })?;
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

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(tableau, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_rigid, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_python, m)?)?;
    Ok(())
}
