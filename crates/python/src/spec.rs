//! A run as the bindings take it: a [`RunSpec`], built and checked once (the method, parsed
//! from its name with its tableau or controller, the step, the sampling, the budget), and a
//! [`RunState`], the run's own buffers (clock, state, samples, counters), resumed call after
//! call. Every `integrate_*` entry point takes `(system..., spec, state, steps)`.

use crate::arrays::{Floats1, Floats2};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use poinsot_core::drivers::{Clock, Counters, Output, Sampling, Status};
use poinsot_core::exact_splitting::Composition;
pub(crate) use poinsot_core::run::Run;
use poinsot_core::spec::{self, Method, MethodData};
use poinsot_core::steppers::{Control, Tableau};
use pyo3::prelude::*;

use crate::args::value_error;

/// What a run is, checked once: `RunSpec(method, *, t_end, dt=0, tableau=None,
/// composition=None, rtol=1e-10, atol=1e-12, safety=0.9, min_factor=0.2, max_factor=10,
/// max_step=inf, first_step=0, t_eval=None, save_every=1, max_steps=2**62)`. `method` is a
/// kind of the registry (`"dop853"`, `"erk"`, `"rk4"`, `"rkmk"`, `"splitting"`,
/// `"exact-splitting"`); `tableau` `(A (s, s), B (s,), C (s,))` for `"erk"` and `"rkmk"`;
/// `composition` `(flows, kicks, kick_first)` for `"exact-splitting"` (fractions of a step,
/// in the order they run); the controller's numbers for `"dop853"` (`first_step` 0: chosen
/// automatically); `dt` the step of the fixed-step methods; samples at `t_eval`
/// (increasing) or, without it, every `save_every`-th step; at most `max_steps` steps.
#[pyclass(frozen, module = "poinsot._core")]
pub struct RunSpec {
    method: String,
    a: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    flows: Vec<f64>,
    kicks: Vec<f64>,
    kick_first: Option<bool>,
    control: Control,
    dt: f64,
    t_end: f64,
    t_eval: Vec<f64>,
    save_every: u64,
    max_steps: u64,
}

impl RunSpec {
    /// The run as the core takes it (checked when built, so it cannot fail).
    pub(crate) fn core(&self) -> spec::RunSpec<'_> {
        self.checked().expect("checked when built")
    }

    fn checked(&self) -> Result<spec::RunSpec<'_>, String> {
        let tableau = Tableau {
            a: &self.a,
            b: &self.b,
            c: &self.c,
        };
        let composition = match self.kick_first {
            Some(first) => Some(Composition::new(first, &self.flows, &self.kicks)?),
            None => None,
        };
        let data = MethodData {
            tableau,
            composition,
            control: self.control,
        };
        let method = Method::parse(&self.method, data)?;
        let sampling = Sampling {
            t_end: self.t_end,
            t_eval: &self.t_eval,
            every: self.save_every,
        };
        spec::RunSpec::new(method, self.dt, sampling, self.max_steps)
    }
}

#[pymethods]
impl RunSpec {
    #[new]
    #[pyo3(signature = (
        method, *, t_end, dt=0.0, tableau=None, composition=None, rtol=1e-10, atol=1e-12, safety=0.9,
        min_factor=0.2, max_factor=10.0, max_step=f64::INFINITY, first_step=0.0, t_eval=None,
        save_every=1, max_steps=1u64 << 62
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        method: String,
        t_end: f64,
        dt: f64,
        tableau: Option<(Floats2<'_>, Floats1<'_>, Floats1<'_>)>,
        composition: Option<(Floats1<'_>, Floats1<'_>, bool)>,
        rtol: f64,
        atol: f64,
        safety: f64,
        min_factor: f64,
        max_factor: f64,
        max_step: f64,
        first_step: f64,
        t_eval: Option<Floats1<'_>>,
        save_every: u64,
        max_steps: u64,
    ) -> PyResult<Self> {
        let (a, b, c) = match tableau {
            Some((a, b, c)) => (
                a.as_array().iter().copied().collect(),
                b.as_array().to_vec(),
                c.as_array().to_vec(),
            ),
            None => (Vec::new(), Vec::new(), Vec::new()),
        };
        let (flows, kicks, kick_first) = match composition {
            Some((f, k, first)) => (f.as_array().to_vec(), k.as_array().to_vec(), Some(first)),
            None => (Vec::new(), Vec::new(), None),
        };
        let spec = RunSpec {
            method,
            a,
            b,
            c,
            flows,
            kicks,
            kick_first,
            control: Control {
                rtol,
                atol,
                safety,
                min_factor,
                max_factor,
                max_step,
                first_step,
            },
            dt,
            t_end,
            t_eval: t_eval.map(|t| t.as_array().to_vec()).unwrap_or_default(),
            save_every,
            max_steps,
        };
        spec.checked().map_err(value_error)?;
        Ok(spec)
    }

    /// The method's kind.
    #[getter]
    fn method(&self) -> &str {
        &self.method
    }

    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    #[getter]
    fn t_end(&self) -> f64 {
        self.t_end
    }

    /// The sample times (empty: every `save_every`-th step).
    #[getter]
    fn t_eval<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.t_eval)
    }

    #[getter]
    fn save_every(&self) -> u64 {
        self.save_every
    }

    #[getter]
    fn max_steps(&self) -> u64 {
        self.max_steps
    }

    fn __repr__(&self) -> String {
        format!(
            "RunSpec({:?}, t_end={}, dt={}, samples={}, max_steps={})",
            self.method,
            self.t_end,
            self.dt,
            self.t_eval.len(),
            self.max_steps
        )
    }
}

/// What a run has done so far, by name.
#[pyclass(frozen, get_all, module = "poinsot._core")]
#[derive(Clone, Copy)]
pub struct RunStats {
    /// Samples written.
    pub samples: usize,
    /// Steps taken (accepted).
    pub steps: u64,
    /// Evaluations of the vector field.
    pub evaluations: u64,
    /// Steps rejected by the controller.
    pub rejected: u64,
}

#[pymethods]
impl RunStats {
    fn __repr__(&self) -> String {
        format!(
            "RunStats(samples={}, steps={}, evaluations={}, rejected={})",
            self.samples, self.steps, self.evaluations, self.rejected
        )
    }
}

/// A run's buffers, owned here and resumed call after call: `RunState(t0, y0, capacity)`, the
/// state `y0` (any array of floats; the system's internal state) at `t0`, room for
/// `capacity` samples (:meth:`grow` doubles it).
#[pyclass(module = "poinsot._core")]
pub struct RunState {
    pub(crate) clock: Clock,
    pub(crate) z: Vec<f64>,
    pub(crate) f: Vec<f64>,
    pub(crate) out_t: Vec<f64>,
    pub(crate) out_y: Vec<f64>,
    pub(crate) counters: Counters,
    pub(crate) status: Status,
}

impl RunState {
    /// The run over these buffers: checked against the state's length `dim` and whether the
    /// system is a rigid body (the methods it runs).
    pub(crate) fn run<'a>(
        &'a mut self,
        spec: &'a RunSpec,
        dim: usize,
        rigid_body: bool,
    ) -> PyResult<Run<'a>> {
        let spec = spec.core();
        spec.check_for(rigid_body).map_err(value_error)?;
        if self.z.len() != dim {
            return Err(value_error(format!(
                "the run's state holds {} numbers; this system's has {dim}",
                self.z.len()
            )));
        }
        if self.f.len() != dim {
            self.f = vec![0.0; dim];
        }
        Ok(Run {
            spec,
            clock: &mut self.clock,
            z: &mut self.z,
            f: &mut self.f,
            out: Output {
                t: &mut self.out_t,
                y: &mut self.out_y,
            },
            counters: &mut self.counters,
        })
    }
}

#[pymethods]
impl RunState {
    #[new]
    fn new(t0: f64, y0: Floats1<'_>, capacity: usize) -> PyResult<Self> {
        let z = y0.as_array().to_vec();
        if !t0.is_finite() {
            return Err(value_error(format!("`t0` must be finite, found {t0}")));
        }
        Ok(RunState {
            clock: Clock { t: t0, h: 0.0 },
            f: vec![0.0; z.len()],
            out_t: vec![0.0; capacity],
            out_y: vec![0.0; capacity * z.len()],
            z,
            counters: Counters::default(),
            status: Status::Running,
        })
    }

    /// The time reached.
    #[getter]
    fn t(&self) -> f64 {
        self.clock.t
    }

    /// The state reached (a copy).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.z)
    }

    /// The status of the last call (`poinsot._core.FINISHED`, ...).
    #[getter]
    fn status(&self) -> i64 {
        self.status as i64
    }

    #[getter]
    fn stats(&self) -> RunStats {
        RunStats {
            samples: self.counters.n_out,
            steps: self.counters.n_steps,
            evaluations: self.counters.n_fev,
            rejected: self.counters.n_rejected,
        }
    }

    /// Room for this many samples.
    #[getter]
    fn capacity(&self) -> usize {
        self.out_t.len()
    }

    /// Twice the room for samples (after `OUTPUT_FULL`).
    fn grow(&mut self) {
        let n = self.out_t.len().max(1);
        self.out_t.resize(2 * n, 0.0);
        self.out_y.resize(2 * n * self.z.len(), 0.0);
    }

    /// The samples written: times (k,) and states (k, n), copies.
    #[allow(clippy::type_complexity)]
    fn samples<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
        let (k, n) = (self.counters.n_out, self.z.len());
        let y = Array2::from_shape_vec((k, n), self.out_y[..k * n].to_vec())
            .map_err(|e| value_error(e.to_string()))?;
        Ok((
            Array1::from(self.out_t[..k].to_vec()).into_pyarray(py),
            y.into_pyarray(py),
        ))
    }
}

/// The registry's methods (`poinsot_core::spec::REGISTRY`), as `METHODS`: a tuple of dicts
/// `{name, kind, order, tableau, conserves, kicks, adaptive, summary}` in the order users see them.
fn methods<'py>(py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    use pyo3::types::{PyDict, PyTuple};
    let entries = spec::REGISTRY.iter().map(|e| {
        let d = PyDict::new(py);
        d.set_item("name", e.name)?;
        d.set_item("kind", e.kind)?;
        d.set_item("order", e.order)?;
        d.set_item("tableau", e.tableau)?;
        d.set_item("conserves", PyTuple::new(py, e.conserves)?)?;
        d.set_item("kicks", e.kicks)?;
        d.set_item("adaptive", Method::ADAPTIVE_KINDS.contains(&e.kind))?;
        d.set_item("summary", e.summary)?;
        Ok(d)
    });
    PyTuple::new(py, entries.collect::<PyResult<Vec<_>>>()?)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("METHODS", methods(m.py())?)?;
    m.add("METHOD_KINDS", Method::NAMES)?;
    m.add("FIELD_KINDS", Method::FIELD_KINDS)?;
    m.add_class::<RunSpec>()?;
    m.add_class::<RunState>()?;
    m.add_class::<RunStats>()?;
    Ok(())
}
