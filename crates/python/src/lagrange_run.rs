//! One run of a constrained system's model (`integrate_lagrange`, the engine of
//! `poinsot.lagrange`'s `NativeProblem`): its inputs (constants, compiled expressions, or a
//! Python callable: the slow path), its events (compiled expressions, Python callables, the
//! release of one-sided constraints) located inside the core's time loop, and the call, in
//! chunks between looks for an interrupt, the GIL released unless Python runs inside.

use std::cell::RefCell;
use std::sync::Arc;

use crate::arrays::{Bools1, Floats1, Ints2};
use numpy::{PyArray1, PyUntypedArrayMethods};
use poinsot_core::drivers::Status;
use poinsot_core::events::{Crossing, Watch};
use poinsot_core::expressions::Function;
use poinsot_core::lagrange::{
    Callbacks, CompiledInputs, Constant, Inputs, LagrangeEvents, Lagrangian, Model, NoCallbacks,
    Source, Stabilization,
};
use poinsot_core::observers::NoObserver;
use poinsot_core::system::VectorField;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::args::value_error;
use crate::engine::{in_chunks, Run, RunSpec, RunState};
use crate::relative::Expressions;

use crate::lagrange::{mask, slice_len, LagrangianModel};

/// Inputs given as a Python callable `u(t, q, qd) -> (nu,)`: the slow path (the GIL is held).
/// The first error it raises is kept and re-raised when the run stops.
struct PyInputs<'py> {
    py: Python<'py>,
    func: Bound<'py, PyAny>,
    count: usize,
    error: RefCell<Option<PyErr>>,
}

impl Inputs for PyInputs<'_> {
    fn count(&self) -> usize {
        self.count
    }
    fn values(&self, t: f64, q: &[f64], v: &[f64], u: &mut [f64]) -> bool {
        if self.error.borrow().is_some() {
            return false;
        }
        let q = numpy::PyArray1::from_slice(self.py, q);
        let v = numpy::PyArray1::from_slice(self.py, v);
        let result = self
            .func
            .call1((t, q, v))
            .and_then(|r| r.extract::<Vec<f64>>());
        match result {
            Ok(x) if x.len() == self.count => {
                u.copy_from_slice(&x);
                true
            }
            Ok(x) => {
                *self.error.borrow_mut() = Some(PyTypeError::new_err(format!(
                    "the inputs function must return {} numbers, found {}",
                    self.count,
                    x.len()
                )));
                false
            }
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                false
            }
        }
    }
}

/// Event functions given as Python callables `g(t, y) -> float` (the slow path: the GIL is
/// held). The first error one raises is kept and re-raised when the run stops.
struct PyEventCallbacks<'py> {
    py: Python<'py>,
    funcs: Vec<Bound<'py, PyAny>>,
    /// Per callable: its index among the run's events (named in errors).
    events: Vec<usize>,
    error: RefCell<Option<PyErr>>,
}

impl Callbacks for &PyEventCallbacks<'_> {
    fn value(&self, k: usize, t: f64, y: &[f64]) -> Option<f64> {
        if self.error.borrow().is_some() {
            return None;
        }
        let y = numpy::PyArray1::from_slice(self.py, y);
        let value = self.funcs[k].call1((t, y)).and_then(|r| {
            r.extract::<f64>().map_err(|_| {
                let kind = r.get_type().name().map_or("?".into(), |n| n.to_string());
                PyTypeError::new_err(format!(
                    "`events[{}]` must return a number, found {kind}",
                    self.events[k]
                ))
            })
        });
        match value {
            Ok(v) => Some(v),
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                None
            }
        }
    }
}

/// A run's events as the bindings receive them (see `integrate_lagrange`), checked.
struct EventSpec {
    sources: Vec<Source>,
    expressions: Option<Arc<Function>>,
    terminal: Vec<bool>,
    direction: Vec<f64>,
    spacing: f64,
}

/// The events' tuple `(expressions, sources, callables, terminal, direction, spacing, log)`:
/// the spec, the callables and the log (a list the crossings are appended to).
type EventsArg<'py> = (
    Option<Bound<'py, Expressions>>,
    Ints2<'py>,
    Vec<Bound<'py, PyAny>>,
    Bools1<'py>,
    Floats1<'py>,
    f64,
    Bound<'py, PyList>,
);

fn event_spec<'py>(
    arg: EventsArg<'py>,
) -> PyResult<(EventSpec, Vec<Bound<'py, PyAny>>, Bound<'py, PyList>)> {
    let (expressions, sources, callables, terminal, direction, spacing, log) = arg;
    let shape = sources.shape();
    if shape.len() != 2 || shape[1] != 2 {
        return Err(value_error("event `sources` must have shape (k, 2)"));
    }
    let raw = sources.as_slice()?;
    let mut out = Vec::with_capacity(shape[0]);
    for (i, pair) in raw.chunks(2).enumerate() {
        let (kind, index) = (pair[0], pair[1]);
        if index < 0 {
            return Err(value_error(format!("event {i}: negative index {index}")));
        }
        let index = index as usize;
        out.push(match kind {
            0 => Source::Expression(index),
            1 if index < callables.len() => Source::Callback(index),
            1 => {
                return Err(value_error(format!(
                    "event {i} is callable {index}, and {} are given",
                    callables.len()
                )))
            }
            2 => Source::Release(index),
            _ => {
                return Err(value_error(format!(
                    "event {i}: kind {kind} is not 0 (expression), 1 (callable) or 2 (release)"
                )))
            }
        });
    }
    let terminal = terminal.as_slice()?.to_vec();
    let direction = direction.as_slice()?.to_vec();
    if terminal.len() != out.len() || direction.len() != out.len() {
        return Err(value_error(format!(
            "events: {} sources, {} terminal flags and {} directions",
            out.len(),
            terminal.len(),
            direction.len()
        )));
    }
    if spacing.is_nan() || spacing <= 0.0 {
        return Err(value_error(format!(
            "the events' detection spacing must be positive, found {spacing}"
        )));
    }
    let spec = EventSpec {
        sources: out,
        expressions: expressions.map(|e| e.get().function.clone()),
        terminal,
        direction,
        spacing,
    };
    Ok((spec, callables, log))
}

/// One chunk of a run of `sys`, watching `spec`'s events (with `callbacks` for the callable
/// ones): its status and the zeros found.
fn chunk_watched<I: Inputs, C: Callbacks>(
    sys: &Lagrangian<'_, I>,
    spec: Option<&EventSpec>,
    callbacks: C,
    r: &mut Run,
    steps: u64,
) -> (Status, Vec<Crossing>) {
    let Some(spec) = spec else {
        return (r.chunk(sys, &mut NoObserver, steps), Vec::new());
    };
    let events = LagrangeEvents::new(sys, &spec.sources, spec.expressions.as_deref(), callbacks)
        .expect("checked before the run");
    let mut watch = Watch::new(
        &events,
        &spec.terminal,
        &spec.direction,
        spec.spacing,
        sys.dim(),
    );
    let status = r.chunk(sys, &mut watch, steps);
    (status, watch.log)
}

/// The whole run with the GIL released per chunk (no Python inside): `make` builds the
/// system on the worker's side of the release.
fn run_released<'m, I: Inputs>(
    py: Python<'_>,
    run: &mut Run,
    steps: u64,
    make: impl Fn() -> Lagrangian<'m, I> + Sync,
    spec: Option<&EventSpec>,
    found: &mut Vec<Crossing>,
) -> PyResult<Status> {
    in_chunks(py, run, steps, |r, steps| {
        let (status, log) = py.detach(|| chunk_watched(&make(), spec, NoCallbacks, r, steps));
        found.extend(log);
        status
    })
}

/// The whole run with the GIL held (an input or an event is a Python callable).
fn run_held<I: Inputs>(
    py: Python<'_>,
    run: &mut Run,
    steps: u64,
    sys: &Lagrangian<'_, I>,
    spec: Option<&EventSpec>,
    callbacks: &PyEventCallbacks<'_>,
    found: &mut Vec<Crossing>,
) -> PyResult<Status> {
    in_chunks(py, run, steps, |r, steps| {
        let (status, log) = chunk_watched(sys, spec, callbacks, r, steps);
        found.extend(log);
        status
    })
}

/// Integrate one run of a model (see `poinsot.integrate.driver`): parameters `p`, inputs
/// `inputs` (an array of constants, an `Expressions` of `[t, q, q̇]`, or a Python callable
/// `(t, q, qd) -> (nu,)`, the slow path), Baumgarte's gains, `projection` and the constraints
/// in play `active`. Returns the status.
///
/// `events`, optional: `(expressions, sources, callables, terminal, direction, spacing,
/// log)`, the run's events located inside the time loop (`poinsot_core::events`):
/// `expressions` an `Expressions` of `[q, q̇, t]` (or None); `sources` (k, 2) rows
/// `(kind, index)`: kind 0 output `index` of the expressions, 1 callable `index` of
/// `callables` (`g(t, y) -> float`, the slow path), 2 the multiplier of constraint `index`
/// (in play); per event a `terminal` flag and a `direction`; `spacing` the largest distance
/// between detection points (∞: the step ends); each zero is appended to the list `log` as
/// `(event, t, y)`. A terminal zero ends the run there with the status `TERMINATED`.
#[pyfunction]
#[pyo3(signature = (
    model, p, inputs, alpha, beta, projection, active, run_spec, state, steps, events=None
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate_lagrange<'py>(
    py: Python<'py>,
    model: &Bound<'py, LagrangianModel>,
    p: Floats1<'py>,
    inputs: Bound<'py, PyAny>,
    alpha: f64,
    beta: f64,
    projection: bool,
    active: Option<Bools1<'py>>,
    run_spec: PyRef<'py, RunSpec>,
    mut state: PyRefMut<'py, RunState>,
    steps: u64,
    events: Option<EventsArg<'py>>,
) -> PyResult<i64> {
    let model = model.get().model.clone();
    let s = model.shape;
    let p = p.as_slice()?.to_vec();
    slice_len(&p, s.np, "p")?;
    let active = mask(active, s.m)?;
    let state = &mut *state;
    let mut run = state.run(&run_spec, 2 * s.n, false)?;
    let (spec, callables, log) = match events {
        Some(arg) => {
            let (spec, callables, log) = event_spec(arg)?;
            (Some(spec), callables, Some(log))
        }
        None => (None, Vec::new(), None),
    };
    let callbacks = PyEventCallbacks::new(py, callables, spec.as_ref());
    let call = Call {
        py,
        model: &model,
        p: &p,
        st: Stabilization {
            alpha,
            beta,
            projection,
        },
        active,
        spec: spec.as_ref(),
        callbacks: &callbacks,
        steps,
    };
    call.check_events()?;
    let mut found = Vec::new();
    let status = call.run(inputs, &mut run, &mut found)?;
    if let Some(err) = callbacks.error.borrow_mut().take() {
        return Err(err);
    }
    if let Some(log) = log {
        for c in found {
            log.append((c.event, c.t, PyArray1::from_vec(py, c.y)))?;
        }
    }
    state.status = status;
    Ok(status as i64)
}

impl<'py> PyEventCallbacks<'py> {
    /// The callables `funcs` of the events `spec`, each named in errors by its index among
    /// the events.
    fn new(py: Python<'py>, funcs: Vec<Bound<'py, PyAny>>, spec: Option<&EventSpec>) -> Self {
        let events = spec.map_or(Vec::new(), |e| {
            let mut at = vec![0; funcs.len()];
            for (i, source) in e.sources.iter().enumerate() {
                if let Source::Callback(k) = *source {
                    at[k] = i;
                }
            }
            at
        });
        PyEventCallbacks {
            py,
            funcs,
            events,
            error: RefCell::new(None),
        }
    }
}

/// One `integrate_lagrange` call, its arguments checked: the model, its parameters, the
/// stabilisation and the constraints in play, the events (their Python callables in
/// `callbacks`) and the steps the call may take.
struct Call<'a, 'py> {
    py: Python<'py>,
    model: &'a Model,
    p: &'a [f64],
    st: Stabilization,
    active: Option<Vec<bool>>,
    spec: Option<&'a EventSpec>,
    callbacks: &'a PyEventCallbacks<'py>,
    steps: u64,
}

impl<'py> Call<'_, 'py> {
    /// The system with the inputs `inputs`.
    fn system<I: Inputs>(&self, inputs: I) -> PyResult<Lagrangian<'_, I>> {
        let active = self.active.clone();
        Lagrangian::new(self.model, self.p, inputs, self.st, active).map_err(value_error)
    }

    /// The events checked against the system (no inputs), once, before the run.
    fn check_events(&self) -> PyResult<()> {
        let no_u = vec![0.0; self.model.shape.nu];
        let sys = self.system(Constant(&no_u))?;
        if let Some(e) = self.spec {
            LagrangeEvents::new(&sys, &e.sources, e.expressions.as_deref(), NoCallbacks)
                .map_err(value_error)?;
        }
        Ok(())
    }

    /// Whether an event is a Python callable: the run then holds the GIL.
    fn slow_events(&self) -> bool {
        self.spec
            .is_some_and(|e| e.sources.iter().any(|x| matches!(x, Source::Callback(_))))
    }

    /// The run with the inputs `inputs`: an array of constants, compiled expressions or a
    /// Python callable (each checked); the zeros of the events into `found`.
    fn run(
        &self,
        inputs: Bound<'py, PyAny>,
        run: &mut Run,
        found: &mut Vec<Crossing>,
    ) -> PyResult<Status> {
        if let Ok(u) = inputs.extract::<Floats1<'py>>() {
            let u = u.as_slice()?.to_vec(); // a copy: the run may release the GIL
            self.run_constant(run, &u, found)
        } else if let Ok(e) = inputs.cast::<Expressions>() {
            self.run_compiled(run, &e.get().function, found)
        } else if inputs.is_callable() {
            self.run_callable(run, inputs, found)
        } else {
            Err(PyTypeError::new_err(
                "`inputs` must be an array of numbers, compiled expressions or a callable (t, q, qd)",
            ))
        }
    }

    /// The run with constant inputs `u`: the GIL released unless an event is a callable.
    fn run_constant(
        &self,
        run: &mut Run,
        u: &[f64],
        found: &mut Vec<Crossing>,
    ) -> PyResult<Status> {
        self.system(Constant(u))?;
        let (py, steps, spec) = (self.py, self.steps, self.spec);
        if self.slow_events() {
            let sys = self.system(Constant(u))?;
            return run_held(py, run, steps, &sys, spec, self.callbacks, found);
        }
        let (model, p, st, active) = (self.model, self.p, self.st, &self.active);
        let make =
            || Lagrangian::new(model, p, Constant(u), st, active.clone()).expect("checked above");
        run_released(py, run, steps, make, spec, found)
    }

    /// The run with inputs compiled from expressions of `[t, q, q̇]` (their sizes checked):
    /// the GIL released unless an event is a callable.
    fn run_compiled(
        &self,
        run: &mut Run,
        function: &Function,
        found: &mut Vec<Crossing>,
    ) -> PyResult<Status> {
        let s = self.model.shape;
        let fp = function.program();
        if fp.n_inputs != 1 + 2 * s.n || fp.n_outputs != s.nu {
            return Err(value_error(format!(
                "the inputs' expressions take {} values to {}; [t, q, qd] ({}) to {} are needed",
                fp.n_inputs,
                fp.n_outputs,
                1 + 2 * s.n,
                s.nu
            )));
        }
        let (model, p, st, active) = (self.model, self.p, self.st, &self.active);
        let make = || {
            Lagrangian::new(model, p, CompiledInputs::new(function), st, active.clone())
                .expect("sizes checked above")
        };
        let (py, steps, spec) = (self.py, self.steps, self.spec);
        if self.slow_events() {
            run_held(py, run, steps, &make(), spec, self.callbacks, found)
        } else {
            run_released(py, run, steps, make, spec, found)
        }
    }

    /// The run with inputs from the Python callable `func` (the slow path: the GIL held);
    /// the first error it raised is raised after the run.
    fn run_callable(
        &self,
        run: &mut Run,
        func: Bound<'py, PyAny>,
        found: &mut Vec<Crossing>,
    ) -> PyResult<Status> {
        let sys = self.system(PyInputs {
            py: self.py,
            func,
            count: self.model.shape.nu,
            error: RefCell::new(None),
        })?;
        let status = run_held(
            self.py,
            run,
            self.steps,
            &sys,
            self.spec,
            self.callbacks,
            found,
        )?;
        if let Some(err) = sys.inputs.error.borrow_mut().take() {
            return Err(err);
        }
        Ok(status)
    }
}
