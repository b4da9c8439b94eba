//! Bindings of relative motion (`poinsot.relative`): the inertia moments on batches, the
//! carrier's motion, the absolute states, the right-hand side, and one call that integrates a
//! body relative to its carrier. A carrier is given as piecewise polynomials, as compiled
//! expressions ([`Expressions`]), as a C function by address, or as a Python callable (the
//! slow path, with the GIL held).

use std::cell::RefCell;
use std::sync::Arc;

use crate::arrays::{Floats1, Floats2, Floats3, Ints1};
use numpy::ndarray::{Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use poinsot_core::drivers::Status;
use poinsot_core::expressions::{Function, Program};
use poinsot_core::observers::NoObserver;
use poinsot_core::relative::{
    self as rel, CarrierMotion, Motion, PPoly, PPolyCarrier, Relative, RelativeOptions,
    MOTION_SIZE, RELATIVE_STATE_SIZE,
};
use poinsot_core::rigid::State;
use poinsot_core::so3::{Mat3, Vec3};
use poinsot_core::system::VectorField;
use poinsot_core::systems::{NoUser, Rigid, UserWrench};
use poinsot_jit::Jit;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

use crate::args::{body_from, forces_from, mat3_from, rows, v3, value_error};
use crate::engine::{c_user, in_chunks, CUser, PyUser, RunSpec, RunState};

/// `f(J, a_i, b_i)` for the rows of `a`, `b` (n, 3) → (n, 3).
fn pairs<'py>(
    py: Python<'py>,
    j: Floats2<'py>,
    a: Floats2<'py>,
    b: Floats2<'py>,
    names: (&str, &str),
    f: fn(&Mat3, Vec3, Vec3) -> Vec3,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let j = mat3_from(&j, "J")?;
    let a = rows(&a, 3, names.0)?;
    let b = rows(&b, 3, names.1)?;
    if a.nrows() != b.nrows() {
        return Err(value_error(format!(
            "`{}` and `{}` must have the same number of rows",
            names.0, names.1
        )));
    }
    let mut out = Array2::<f64>::zeros((a.nrows(), 3));
    for i in 0..a.nrows() {
        let m = f(&j, v3(&a, i), v3(&b, i));
        for k in 0..3 {
            out[[i, k]] = m[k];
        }
    }
    Ok(out.into_pyarray(py))
}

/// The transport inertia moments `M_e = −J ε_e + Jω_e × ω_e` (paper eq. (2)), rows (n, 3).
#[pyfunction]
fn transport_moments<'py>(
    py: Python<'py>,
    j: Floats2<'py>,
    omega_e: Floats2<'py>,
    epsilon_e: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    pairs(
        py,
        j,
        omega_e,
        epsilon_e,
        ("omega_e", "epsilon_e"),
        rel::transport_moment,
    )
}

/// The Coriolis inertia moments `M_c = 2 ω_r × (J'ω_e)` (paper eq. (5)), rows (n, 3).
#[pyfunction]
fn coriolis_moments<'py>(
    py: Python<'py>,
    j: Floats2<'py>,
    omega_r: Floats2<'py>,
    omega_e: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    pairs(
        py,
        j,
        omega_r,
        omega_e,
        ("omega_r", "omega_e"),
        rel::coriolis_moment,
    )
}

/// The Coriolis inertia moments in the three-term form (paper eq. (2)), rows (n, 3).
#[pyfunction]
fn coriolis_moments_three_term<'py>(
    py: Python<'py>,
    j: Floats2<'py>,
    omega_r: Floats2<'py>,
    omega_e: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    pairs(
        py,
        j,
        omega_r,
        omega_e,
        ("omega_r", "omega_e"),
        rel::coriolis_three_term,
    )
}

fn particles(masses: &[f64], rho: &ArrayView2<f64>) -> PyResult<Vec<Vec3>> {
    if rho.nrows() != masses.len() {
        return Err(value_error(
            "`masses` and `rho` must have the same number of rows",
        ));
    }
    Ok((0..rho.nrows()).map(|i| v3(rho, i)).collect())
}

/// The Coriolis inertia moments by their definition as a particle sum (paper eq. (6)).
#[pyfunction]
fn coriolis_moments_particles<'py>(
    py: Python<'py>,
    masses: Floats1<'py>,
    rho: Floats2<'py>,
    omega_r: Floats2<'py>,
    omega_e: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = masses.as_slice()?;
    let p = particles(m, &rows(&rho, 3, "rho")?)?;
    let a = rows(&omega_r, 3, "omega_r")?;
    let b = rows(&omega_e, 3, "omega_e")?;
    if a.nrows() != b.nrows() {
        return Err(value_error(
            "`omega_r` and `omega_e` must have the same number of rows",
        ));
    }
    let mut out = Array2::<f64>::zeros((a.nrows(), 3));
    for i in 0..a.nrows() {
        let c = rel::coriolis_particles(m, &p, v3(&a, i), v3(&b, i));
        for k in 0..3 {
            out[[i, k]] = c[k];
        }
    }
    Ok(out.into_pyarray(py))
}

/// The planar inertia tensor by its definition `Σ m ρ ρᵀ` (paper eqs (3)–(4)).
#[pyfunction]
fn planar_inertia_particles(masses: Floats1<'_>, rho: Floats2<'_>) -> PyResult<Mat3> {
    let m = masses.as_slice()?;
    let p = particles(m, &rows(&rho, 3, "rho")?)?;
    Ok(rel::planar_inertia_particles(m, &p))
}

/// A piecewise polynomial of 3-vectors from SciPy's layout: breaks (m + 1,), coefficients
/// (k + 1, m, 3).
fn ppoly(breaks: &Floats1<'_>, coeffs: &Floats3<'_>, name: &str) -> PyResult<PPoly> {
    let c = coeffs.as_array();
    let shape = c.shape();
    if shape[0] == 0 || shape[2] != 3 || shape[1] + 1 != breaks.len()? {
        return Err(value_error(format!(
            "`{name}` must have coefficients of shape (k + 1, len(breaks) − 1, 3), found {shape:?}"
        )));
    }
    PPoly::new(
        breaks.as_slice()?.to_vec(),
        c.iter().copied().collect(),
        shape[0] - 1,
    )
    .map_err(|e| value_error(format!("`{name}`: {e}")))
}

/// A carrier given by its two piecewise polynomials.
fn ppoly_carrier(spec: &Bound<'_, PyAny>) -> PyResult<PPolyCarrier> {
    let (wb, wc, ab, ac): (Floats1<'_>, Floats3<'_>, Floats1<'_>, Floats3<'_>) = spec.extract()?;
    Ok(PPolyCarrier {
        omega: ppoly(&wb, &wc, "omega_e")?,
        accel: ppoly(&ab, &ac, "origin_acceleration")?,
    })
}

/// The carrier's motions `(ω_e, ε_e, a_O)` at the times `t` (n,) → (n, 9), for a carrier
/// given as piecewise polynomials (`ε_e` their exact derivative).
#[pyfunction]
fn carrier_motions<'py>(
    py: Python<'py>,
    carrier: Bound<'py, PyAny>,
    t: Floats1<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let t = t.as_slice()?;
    let mut out = Array2::<f64>::zeros((t.len(), MOTION_SIZE));
    let mut fill = |c: &dyn CarrierMotion| {
        for (i, &s) in t.iter().enumerate() {
            let m = c.motion(s).unwrap_or([f64::NAN; MOTION_SIZE]);
            for k in 0..MOTION_SIZE {
                out[[i, k]] = m[k];
            }
        }
    };
    if let Ok(e) = carrier.cast::<Expressions>() {
        fill(&*e.borrow().check(1, MOTION_SIZE)?);
    } else {
        fill(&ppoly_carrier(&carrier)?);
    }
    Ok(out.into_pyarray(py))
}

/// The absolute states `[R, V, Q, ω]` (n, 18) of relative states (n, 33) under the carrier's
/// motions at the same times (n, 9).
#[pyfunction]
fn absolute_states<'py>(
    py: Python<'py>,
    states: Floats2<'py>,
    motions: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let y = rows(&states, RELATIVE_STATE_SIZE, "states")?;
    let m = rows(&motions, MOTION_SIZE, "motions")?;
    if y.nrows() != m.nrows() {
        return Err(value_error(
            "`states` and `motions` must have the same number of rows",
        ));
    }
    let mut out = Array2::<f64>::zeros((y.nrows(), 18));
    let mut row = vec![0.0; RELATIVE_STATE_SIZE];
    for i in 0..y.nrows() {
        for k in 0..RELATIVE_STATE_SIZE {
            row[k] = y[[i, k]];
        }
        let mut mo: Motion = [0.0; MOTION_SIZE];
        for k in 0..MOTION_SIZE {
            mo[k] = m[[i, k]];
        }
        let s = rel::absolute_state(&row, &mo);
        for k in 0..18 {
            out[[i, k]] = s[k];
        }
    }
    Ok(out.into_pyarray(py))
}

/// Expressions compiled to machine code: `Expressions(codes, values, n_inputs, n_outputs)`,
/// a postfix program over the inputs (`poinsot_core::expressions`), checked and compiled once.
#[pyclass(frozen, module = "poinsot._core")]
pub(crate) struct Expressions {
    pub(crate) function: Arc<Function>,
}

impl Expressions {
    fn check(&self, n_inputs: usize, n_outputs: usize) -> PyResult<Arc<Function>> {
        let p = self.function.program();
        if p.n_inputs != n_inputs || p.n_outputs != n_outputs {
            return Err(value_error(format!(
                "the expressions take {} inputs to {} outputs; {n_inputs} to {n_outputs} are needed",
                p.n_inputs, p.n_outputs
            )));
        }
        Ok(self.function.clone())
    }
}

#[pymethods]
impl Expressions {
    #[new]
    fn new(
        py: Python<'_>,
        codes: Ints1<'_>,
        values: Floats1<'_>,
        n_inputs: usize,
        n_outputs: usize,
    ) -> PyResult<Self> {
        let program = Program::new(codes.as_slice()?, values.as_slice()?, n_inputs, n_outputs)
            .map_err(|e| value_error(format!("the expression program is malformed: {e}")))?;
        let function = py.detach(|| Function::compile(program, &Jit));
        Ok(Expressions {
            function: Arc::new(function),
        })
    }

    /// The outputs at the rows of `inputs` (n, n_inputs) → (n, n_outputs).
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        inputs: Floats2<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p = self.function.program();
        let x = rows(&inputs, p.n_inputs, "inputs")?;
        let mut out = Array2::<f64>::zeros((x.nrows(), p.n_outputs));
        let mut arg = vec![0.0; p.n_inputs];
        let mut res = vec![0.0; p.n_outputs];
        for i in 0..x.nrows() {
            for k in 0..p.n_inputs {
                arg[k] = x[[i, k]];
            }
            self.function.eval(&arg, &mut res);
            for k in 0..p.n_outputs {
                out[[i, k]] = res[k];
            }
        }
        Ok(out.into_pyarray(py))
    }

    /// True when the expressions run as machine code (else they are interpreted).
    #[getter]
    fn machine_code(&self) -> bool {
        self.function.is_machine_code()
    }
}

/// A carrier given as a C function `int f(double t, double *out)` (`out`: the 9 numbers
/// `(ω_e, ε_e, a_O)`; non-zero return: failure), called by address.
pub(crate) struct CCarrier {
    f: extern "C" fn(f64, *mut f64) -> i32,
}

impl CarrierMotion for CCarrier {
    fn motion(&self, t: f64) -> Option<Motion> {
        let mut m = [0.0; MOTION_SIZE];
        ((self.f)(t, m.as_mut_ptr()) == 0).then_some(m)
    }
}

/// A carrier given as a Python callable `motion(t) -> 9 numbers`: the slow path. The first
/// error it raises is kept and re-raised when the run stops.
pub(crate) struct PyCarrier<'py> {
    func: Bound<'py, PyAny>,
    error: RefCell<Option<PyErr>>,
}

impl CarrierMotion for PyCarrier<'_> {
    fn motion(&self, t: f64) -> Option<Motion> {
        if self.error.borrow().is_some() {
            return None;
        }
        let result = self
            .func
            .call1((t,))
            .and_then(|r| r.extract::<Motion>())
            .map_err(|e| {
                if e.is_instance_of::<PyTypeError>(self.func.py()) {
                    PyTypeError::new_err(format!(
                        "the carrier's motion must be nine numbers (ω_e, ε_e, a_O): {e}"
                    ))
                } else {
                    e
                }
            });
        match result {
            Ok(m) => Some(m),
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                None
            }
        }
    }
}

/// The carrier as the engine evaluates it.
pub(crate) enum CarrierArg<'py> {
    PPoly(PPolyCarrier),
    Expressions(Arc<Function>),
    C(CCarrier),
    Python(PyCarrier<'py>),
}

impl<'py> CarrierArg<'py> {
    /// `carrier`: a tuple `(w_breaks, w_coeffs, a_breaks, a_coeffs)`, an [`Expressions`] of
    /// one input and nine outputs, a C function's address (int), or a Python callable.
    pub(crate) fn from(carrier: Bound<'py, PyAny>) -> PyResult<Self> {
        if let Ok(e) = carrier.cast::<Expressions>() {
            return Ok(CarrierArg::Expressions(e.borrow().check(1, MOTION_SIZE)?));
        }
        if let Ok(address) = carrier.extract::<usize>() {
            if address == 0 {
                return Err(value_error("`carrier` must be a non-null function address"));
            }
            // SAFETY: the caller promises a C function `int f(double, double *)` there.
            let f: extern "C" fn(f64, *mut f64) -> i32 = unsafe { std::mem::transmute(address) };
            return Ok(CarrierArg::C(CCarrier { f }));
        }
        if carrier.is_callable() {
            return Ok(CarrierArg::Python(PyCarrier {
                func: carrier,
                error: RefCell::new(None),
            }));
        }
        ppoly_carrier(&carrier).map(CarrierArg::PPoly).map_err(|e| {
            value_error(format!(
                "`carrier` must be piecewise polynomials (w_breaks, w_coeffs, a_breaks, \
                 a_coeffs), compiled expressions, a function address or a callable: {e}"
            ))
        })
    }

    /// The carrier when it runs without Python.
    pub(crate) fn native(&self) -> Option<&(dyn CarrierMotion + Sync)> {
        match self {
            CarrierArg::PPoly(c) => Some(c),
            CarrierArg::Expressions(f) => Some(&**f),
            CarrierArg::C(c) => Some(c),
            CarrierArg::Python(_) => None,
        }
    }

    pub(crate) fn any(&self) -> &dyn CarrierMotion {
        match self {
            CarrierArg::Python(c) => c,
            _ => self.native().expect("native"),
        }
    }

    pub(crate) fn take_error(&self) -> Option<PyErr> {
        match self {
            CarrierArg::Python(c) => c.error.borrow_mut().take(),
            _ => None,
        }
    }
}

/// The user's forces when Python runs anyway (the GIL held).
enum AnyUser<'py> {
    None,
    C(CUser),
    Python(PyUser<'py>),
}

impl UserWrench for AnyUser<'_> {
    fn wrench(&self, t: f64, y: &State) -> Option<[f64; 6]> {
        match self {
            AnyUser::None => Some([0.0; 6]),
            AnyUser::C(c) => c.wrench(t, y),
            AnyUser::Python(p) => p.wrench(t, y),
        }
    }
}

/// Everything that defines the relative system, as Python passes it.
struct SystemArgs<'py> {
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    axes: Floats2<'py>,
    user: Option<Bound<'py, PyAny>>,
    carrier: Bound<'py, PyAny>,
    options: (bool, bool),
}

/// What runs the system: `native` for a system that calls no Python (the GIL released),
/// `held` for one that does; the Python errors raised inside are re-raised after.
fn with_system<'py, C, R>(
    py: Python<'py>,
    args: SystemArgs<'py>,
    ctx: &mut C,
    native: impl FnOnce(&(dyn VectorField + Sync), &mut C) -> PyResult<R>,
    held: impl FnOnce(&dyn VectorField, &mut C) -> PyResult<R>,
) -> PyResult<R> {
    let body = body_from(args.body.as_slice()?)?;
    let forces = forces_from(args.force_kind.as_slice()?, &args.force_params)?;
    let axes = mat3_from(&args.axes, "axes")?;
    let options = RelativeOptions {
        balance_transport: args.options.0,
        hold_com: args.options.1,
    };
    let carrier = CarrierArg::from(args.carrier)?;
    let user = match args.user {
        None => AnyUser::None,
        Some(func) => match c_user(&func)? {
            Some(c) => AnyUser::C(c),
            None => AnyUser::Python(PyUser::new(py, func)),
        },
    };
    let result = match (carrier.native(), user) {
        (Some(c), AnyUser::None) => {
            let rigid: Rigid<NoUser> = Rigid::new(body, forces, axes, None);
            native(&Relative::new(rigid, c, options), ctx)
        }
        (Some(c), AnyUser::C(u)) => native(
            &Relative::new(Rigid::new(body, forces, axes, Some(u)), c, options),
            ctx,
        ),
        (_, user) => {
            let sys = Relative::new(
                Rigid::new(body, forces, axes, Some(user)),
                carrier.any(),
                options,
            );
            let r = held(&sys, ctx);
            if let Some(AnyUser::Python(p)) = sys.rigid.user.as_ref() {
                if let Some(e) = p.take_error() {
                    return Err(e);
                }
            }
            r
        }
    };
    if let Some(e) = carrier.take_error() {
        return Err(e);
    }
    result
}

/// `ẏ` (33,) of a relative state in the engine's frame: eqs (11)–(12) and the kinematics.
#[pyfunction]
#[pyo3(signature = (body, force_kind, force_params, axes, user, carrier, balance_transport, hold_com, t, y))]
#[allow(clippy::too_many_arguments)]
fn relative_rhs<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    axes: Floats2<'py>,
    user: Option<Bound<'py, PyAny>>,
    carrier: Bound<'py, PyAny>,
    balance_transport: bool,
    hold_com: bool,
    t: f64,
    y: Floats1<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let y = y.as_slice()?;
    if y.len() != RELATIVE_STATE_SIZE {
        return Err(value_error(format!(
            "`y` must hold {RELATIVE_STATE_SIZE} numbers"
        )));
    }
    let mut out = vec![0.0; RELATIVE_STATE_SIZE];
    let args = SystemArgs {
        body,
        force_kind,
        force_params,
        axes,
        user,
        carrier,
        options: (balance_transport, hold_com),
    };
    with_system(
        py,
        args,
        &mut out,
        |s, out| {
            s.rhs(t, y, out);
            Ok(())
        },
        |s, out| {
            s.rhs(t, y, out);
            Ok(())
        },
    )?;
    Ok(out.into_pyarray(py))
}

/// Integrate a body relative to its carrier (`poinsot.relative.simulate_relative`) for at
/// most `steps` more steps of the run `spec` (`"dop853"` or an explicit tableau), in `state`.
/// Returns the status (also `state.status`).
#[pyfunction]
#[pyo3(signature = (
    body, force_kind, force_params, axes, user, carrier, balance_transport, hold_com, spec,
    state, steps
))]
#[allow(clippy::too_many_arguments)]
fn integrate_relative<'py>(
    py: Python<'py>,
    body: Floats1<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats2<'py>,
    axes: Floats2<'py>,
    user: Option<Bound<'py, PyAny>>,
    carrier: Bound<'py, PyAny>,
    balance_transport: bool,
    hold_com: bool,
    spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
) -> PyResult<i64> {
    let state = &mut *state;
    let mut run = state.run(&spec, RELATIVE_STATE_SIZE, false)?;
    let system = SystemArgs {
        body,
        force_kind,
        force_params,
        axes,
        user,
        carrier,
        options: (balance_transport, hold_com),
    };
    let status: Status = with_system(
        py,
        system,
        &mut run,
        |sys, run| {
            in_chunks(py, run, steps, |r, n| {
                py.detach(|| r.chunk(sys, &mut NoObserver, n))
            })
        },
        |sys, run| in_chunks(py, run, steps, |r, n| r.chunk(sys, &mut NoObserver, n)),
    )?;
    state.status = status;
    Ok(status as i64)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Expressions>()?;
    m.add_function(wrap_pyfunction!(transport_moments, m)?)?;
    m.add_function(wrap_pyfunction!(coriolis_moments, m)?)?;
    m.add_function(wrap_pyfunction!(coriolis_moments_three_term, m)?)?;
    m.add_function(wrap_pyfunction!(coriolis_moments_particles, m)?)?;
    m.add_function(wrap_pyfunction!(planar_inertia_particles, m)?)?;
    m.add_function(wrap_pyfunction!(carrier_motions, m)?)?;
    m.add_function(wrap_pyfunction!(absolute_states, m)?)?;
    m.add_function(wrap_pyfunction!(relative_rhs, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_relative, m)?)?;
    m.add("RELATIVE_STATE_SIZE", RELATIVE_STATE_SIZE)?;
    m.add("MOTION_SIZE", MOTION_SIZE)?;
    Ok(())
}
