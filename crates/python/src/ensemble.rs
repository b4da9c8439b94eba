//! Bindings of the ensembles (`poinsot_core::ensemble`): one call runs a chunk of members on a
//! rayon pool of the caller's size (`poinsot.ensemble.tasks.run_chunk`). Arguments are checked
//! here, with their names; the GIL is released for the run; an interrupt (Ctrl-C) is looked
//! for every few milliseconds and raises the stop flag every worker polls, so the call returns
//! promptly with the `KeyboardInterrupt`; a panic in the core becomes a `RuntimeError`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::arrays::{Floats2, Floats3, Ints1};
use numpy::ndarray::{Array1, Array2, Array3, ArrayView3};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadwriteArray2, PyReadwriteArray3,
    PyUntypedArrayMethods,
};
use poinsot_core::ensemble::{member_body, run_members, Member, MemberSummary, Schedule};
use poinsot_core::forces::{Force, ForceKind};
use poinsot_core::layout::{load, Body, BODY_SIZE, FORCE_PARAMS, STATE_SIZE};
use poinsot_core::so3::Mat3;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use rayon::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};

use crate::engine::{body_from, value_error, RunSpec};

/// How often the calling thread looks for an interrupt while the workers run.
const POLL: Duration = Duration::from_millis(5);

/// The rows of a per-member argument: 1 (shared) or `m` (one per member).
fn shared_or_per_member(rows: usize, m: usize, name: &str, shape: &str) -> PyResult<()> {
    if rows != 1 && rows != m {
        return Err(value_error(format!(
            "`{name}` must have shape (1, {shape}) or ({m}, {shape}) (shared or one per member), \
             found {rows} rows"
        )));
    }
    Ok(())
}

/// An array's memory as a slice in C order (rust-numpy also gives a slice for Fortran order,
/// whose elements would be read in the wrong order).
pub(crate) fn c_order<S, E>(c_contiguous: bool, slice: Result<S, E>, name: &str) -> PyResult<S> {
    match slice {
        Ok(s) if c_contiguous => Ok(s),
        _ => Err(value_error(format!("`{name}` must be C-contiguous"))),
    }
}

fn mats<'a>(a: &'a Floats3<'_>, m: usize, name: &str) -> PyResult<ArrayView3<'a, f64>> {
    let v = a.as_array();
    if v.shape()[1..] != [3, 3] {
        return Err(value_error(format!(
            "`{name}` must have shape (n, 3, 3), found {:?}",
            v.shape()
        )));
    }
    shared_or_per_member(v.shape()[0], m, name, "3, 3")?;
    Ok(v)
}

fn mat(a: &ArrayView3<f64>, i: usize) -> Mat3 {
    let i = if a.shape()[0] > 1 { i } else { 0 };
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| a[[i, r, c]]))
}

/// Each member's (or the shared) lowered forces: kinds (k,), parameters (1 | m, k,
/// FORCE_PARAMS).
fn member_forces(kind: &[i64], params: &Floats3<'_>, m: usize) -> PyResult<Vec<Vec<Force>>> {
    let p = params.as_array();
    let k = kind.len();
    if p.shape()[1] != k || (p.shape()[2] != FORCE_PARAMS && k > 0) {
        return Err(value_error(format!(
            "`force_params` must have shape (n, {k}, {FORCE_PARAMS}), found {:?}",
            p.shape()
        )));
    }
    shared_or_per_member(
        p.shape()[0],
        m,
        "force_params",
        &format!("{k}, {FORCE_PARAMS}"),
    )?;
    let kinds = kind
        .iter()
        .enumerate()
        .map(|(j, &code)| {
            ForceKind::from_code(code)
                .ok_or_else(|| value_error(format!("`force_kind[{j}]` = {code} is no force kind")))
        })
        .collect::<PyResult<Vec<_>>>()?;
    Ok((0..p.shape()[0])
        .map(|i| {
            kinds
                .iter()
                .enumerate()
                .map(|(j, &kind)| Force {
                    kind,
                    p: std::array::from_fn(|c| p[[i, j, c]]),
                })
                .collect()
        })
        .collect())
}

/// The parameters and principal axes of members with their own inertia about the centre of
/// mass (`inertia` (m, 3, 3), body frame), sharing the body's `mass` and its centre of mass
/// `c` seen from the reference point: `(bodies (m, BODY_SIZE), axes (m, 3, 3), degenerate
/// (m,))` (`poinsot_core::ensemble::member_body`; the pivot is placed by `run_ensemble`).
#[pyfunction]
fn member_bodies<'py>(
    py: Python<'py>,
    mass: f64,
    inertia: Floats3<'py>,
    c: [f64; 3],
    has_pivot: bool,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray1<bool>>,
)> {
    let a = inertia.as_array();
    if a.shape()[1..] != [3, 3] {
        return Err(value_error(format!(
            "`inertia` must have shape (m, 3, 3), found {:?}",
            a.shape()
        )));
    }
    let m = a.shape()[0];
    let mut bodies = Array2::<f64>::zeros((m, BODY_SIZE));
    let mut axes = Array3::<f64>::zeros((m, 3, 3));
    let mut degenerate = Array1::from_elem(m, false);
    for i in 0..m {
        let (p, e, d) = member_body(mass, &mat(&a, i), c, has_pivot);
        for k in 0..BODY_SIZE {
            bodies[[i, k]] = p[k];
        }
        for r in 0..3 {
            for s in 0..3 {
                axes[[i, r, s]] = e[r][s];
            }
        }
        degenerate[i] = d;
    }
    Ok((
        bodies.into_pyarray(py),
        axes.into_pyarray(py),
        degenerate.into_pyarray(py),
    ))
}

/// The rayon pool of `threads` workers, built once per process and size.
pub(crate) fn pool(threads: usize) -> PyResult<Arc<ThreadPool>> {
    static POOLS: Mutex<Vec<(u32, usize, Arc<ThreadPool>)>> = Mutex::new(Vec::new());
    let pid = std::process::id(); // a forked child builds its own
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    pools.retain(|(p, _, _)| *p == pid);
    if let Some((_, _, p)) = pools.iter().find(|(_, n, _)| *n == threads) {
        return Ok(p.clone());
    }
    let p = Arc::new(
        ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("poinsot-ensemble-{i}"))
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("no thread pool of {threads}: {e}")))?,
    );
    pools.push((pid, threads, p.clone()));
    Ok(p)
}

/// Run `work` on `pool` with the GIL released while this thread looks for an interrupt every
/// [`POLL`]: an interrupt raises the stop flag `work` polls, and is returned once the workers
/// have stopped; a panic in the core becomes a `RuntimeError`.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    pool: &ThreadPool,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let stop = AtomicBool::new(false);
    let mut interrupt: Option<PyErr> = None;
    let outcome = py.detach(|| {
        std::thread::scope(|scope| {
            let caller = std::thread::current();
            let stop = &stop;
            let worker = scope.spawn(move || {
                let done = catch_unwind(AssertUnwindSafe(|| pool.install(|| work(stop))));
                caller.unpark();
                done
            });
            while !worker.is_finished() {
                std::thread::park_timeout(POLL);
                if interrupt.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        interrupt = Some(e);
                        stop.store(true, Ordering::Relaxed);
                    }
                }
            }
            worker.join()
        })
    });
    if let Some(e) = interrupt {
        return Err(e);
    }
    match outcome {
        Ok(Ok(t)) => Ok(t),
        Ok(Err(p)) | Err(p) => Err(PyRuntimeError::new_err(format!(
            "the engine failed (a bug in poinsot, please report it): {}",
            panic_message(p)
        ))),
    }
}

fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// What `run_ensemble` returns: samples (m, n, 18) or None (not kept, or written to
/// `samples_out`), final states (m, 18) or None (written to `finals_out`), the drifts
/// (energy, momentum, orthogonality), the flips (first, last, count), and status, steps and
/// evaluations per member.
type Outputs<'py> = (
    Option<Bound<'py, PyArray3<f64>>>,
    Option<Bound<'py, PyArray2<f64>>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// Integrate a chunk of members (`poinsot.ensemble.tasks.run_chunk`).
///
/// `spec` the run every member takes (its method, step, sample times `t_eval` (n,), at
/// least one, and its end), from `t0`. Per member (one row shared by all, or one row each):
/// `inertia` (about the centre of mass, body frame), `bodies` (parameter vectors, principal
/// frame, pivot not placed), `axes` (principal axes, columns), `force_params` (k forces of
/// kinds `force_kind`, lowered in the member's principal frame); `y0` (m, 18) the body-frame
/// initial states. `keep_samples`: return the samples (else only the final states);
/// `threads`: the pool's size. `samples_out` (m, n, 18) and `finals_out` (m, 18),
/// C-contiguous, receive the samples and final states in place (MuJoCo's `rollout` style:
/// the caller's result arrays, no copy), and None is returned for them.
#[pyfunction]
#[pyo3(signature = (
    spec, t0, inertia, bodies, axes, force_kind, force_params, y0, flips=true,
    keep_samples=true, threads=1, samples_out=None, finals_out=None
))]
#[allow(clippy::too_many_arguments)]
fn run_ensemble<'py>(
    py: Python<'py>,
    spec: PyRef<'py, RunSpec>,
    t0: f64,
    inertia: Floats3<'py>,
    bodies: Floats2<'py>,
    axes: Floats3<'py>,
    force_kind: Ints1<'py>,
    force_params: Floats3<'py>,
    y0: Floats2<'py>,
    flips: bool,
    keep_samples: bool,
    threads: i64,
    samples_out: Option<PyReadwriteArray3<'py, f64>>,
    finals_out: Option<PyReadwriteArray2<'py, f64>>,
) -> PyResult<Outputs<'py>> {
    let run = spec.core();
    let schedule = schedule_from(&run, t0, flips, threads)?;
    let args = MemberArgs {
        inertia: &inertia,
        bodies: &bodies,
        axes: &axes,
        force_kind: &force_kind,
        force_params: &force_params,
        y0: &y0,
    };
    let members = Members::new(args)?;
    let (m, n) = (members.m, schedule.t_eval.len());
    let mut buffers = Buffers::new(samples_out, finals_out, keep_samples, (m, n))?;
    let (samples, finals) = buffers.slices()?;
    // the run: workers on the pool, this thread looking for an interrupt
    let mut summaries = vec![MemberSummary::default(); m];
    let pool = pool(threads as usize)?;
    {
        let (summaries, schedule, members) = (&mut summaries, &schedule, &members);
        interruptible(py, &pool, move |stop| {
            // each member's body, axes, inertia, forces and initial state, made on the pool's
            // threads with the run (the GIL released)
            let members: Vec<Member> = (0..m).into_par_iter().map(|i| members.member(i)).collect();
            run_members(schedule, &members, samples, finals, summaries, stop)
        })?;
    }
    let (samples, finals) = buffers.returned(py, (m, n))?;
    Ok(outputs(py, samples, finals, &summaries))
}

/// The schedule of a chunk: the run `spec`'s own (checked when it was built; a method a rigid
/// body runs) from `t0`, its end at or after `t0` and at least one sample time, all within
/// `[t0, t_end]`, the flips recorded or not; and the pool's size `threads`, positive. Checked
/// in this order, each error naming its argument.
fn schedule_from<'s>(
    run: &poinsot_core::spec::RunSpec<'s>,
    t0: f64,
    flips: bool,
    threads: i64,
) -> PyResult<Schedule<'s>> {
    run.check_for(true).map_err(value_error)?;
    let (t1, times) = (run.sampling.t_end, run.sampling.t_eval);
    if !(t0.is_finite() && t1 >= t0) {
        return Err(value_error(format!(
            "`t0` must be finite and at most the run's end {t1}, found {t0}"
        )));
    }
    if times.is_empty() {
        return Err(value_error("`t_eval` must hold at least one time"));
    }
    if !(times[0] >= t0 && times[times.len() - 1] <= t1) {
        return Err(value_error(format!(
            "`t_eval` must lie within [{t0}, {t1}], found [{}, {}]",
            times[0],
            times[times.len() - 1]
        )));
    }
    if threads < 1 {
        return Err(value_error(format!(
            "`threads` must be a positive integer, found {threads}"
        )));
    }
    Ok(Schedule {
        method: run.method,
        t0,
        t1,
        dt: run.dt,
        t_eval: times,
        flips,
        max_steps: run.max_steps,
    })
}

/// The member arguments of `run_ensemble`, as received.
struct MemberArgs<'a, 'py> {
    inertia: &'a Floats3<'py>,
    bodies: &'a Floats2<'py>,
    axes: &'a Floats3<'py>,
    force_kind: &'a Ints1<'py>,
    force_params: &'a Floats3<'py>,
    y0: &'a Floats2<'py>,
}

/// A chunk's `m` members, checked: per member (one row shared by all, or one row each) the
/// inertia, the principal axes, the body and the lowered forces; each member's initial
/// state (`y0`, m · 18, C order).
struct Members<'a> {
    m: usize,
    inertia: ArrayView3<'a, f64>,
    axes: ArrayView3<'a, f64>,
    bodies: Vec<Body>,
    forces: Vec<Vec<Force>>,
    y0: &'a [f64],
}

impl<'a> Members<'a> {
    /// The members of `args`, checked in the order of the arguments' names in the errors:
    /// `y0`, `inertia`, `axes`, `bodies`, the forces.
    fn new(args: MemberArgs<'a, '_>) -> PyResult<Self> {
        let y0 = args.y0;
        if y0.shape()[1] != STATE_SIZE {
            return Err(value_error(format!(
                "`y0` must have shape (m, {STATE_SIZE}), found {:?}",
                y0.shape()
            )));
        }
        let m = y0.shape()[0];
        let inertia = mats(args.inertia, m, "inertia")?;
        let axes = mats(args.axes, m, "axes")?;
        let bodies = args.bodies.as_array();
        if bodies.ncols() != BODY_SIZE {
            return Err(value_error(format!(
                "`bodies` must have shape (n, {BODY_SIZE}), found {:?}",
                bodies.shape()
            )));
        }
        shared_or_per_member(bodies.nrows(), m, "bodies", &BODY_SIZE.to_string())?;
        let bodies = (0..bodies.nrows())
            .map(|i| body_from(&bodies.row(i).to_vec()))
            .collect::<PyResult<Vec<Body>>>()?;
        let forces = member_forces(args.force_kind.as_slice()?, args.force_params, m)?;
        Ok(Members {
            m,
            inertia,
            axes,
            bodies,
            forces,
            // C order: the argument is converted when it is not
            y0: y0.as_slice()?,
        })
    }

    /// Member `i`: its body, axes, inertia, forces and initial state.
    fn member(&self, i: usize) -> Member<'_> {
        let pick = |len: usize| if len > 1 { i } else { 0 };
        Member::new(
            self.bodies[pick(self.bodies.len())],
            mat(&self.axes, i),
            mat(&self.inertia, i),
            &self.forces[pick(self.forces.len())],
            load(&self.y0[i * STATE_SIZE..(i + 1) * STATE_SIZE]),
        )
    }
}

/// Where a chunk's samples and final states go: the caller's arrays (`samples_out`,
/// `finals_out`) or buffers of our own; samples only when kept (`keep`).
struct Buffers<'py> {
    samples_out: Option<PyReadwriteArray3<'py, f64>>,
    finals_out: Option<PyReadwriteArray2<'py, f64>>,
    own_samples: Vec<f64>,
    own_finals: Vec<f64>,
    keep: bool,
}

impl<'py> Buffers<'py> {
    /// The buffers of `m` members with `n` samples each: the caller's arrays' shapes checked
    /// (`samples_out` only with `keep`), our own made where they are not given.
    fn new(
        samples_out: Option<PyReadwriteArray3<'py, f64>>,
        finals_out: Option<PyReadwriteArray2<'py, f64>>,
        keep: bool,
        (m, n): (usize, usize),
    ) -> PyResult<Self> {
        if let Some(a) = &samples_out {
            if !keep || a.shape() != [m, n, STATE_SIZE] {
                return Err(value_error(format!(
                    "`samples_out` must have shape ({m}, {n}, {STATE_SIZE}) with `keep_samples`, \
                     found {:?}",
                    a.shape()
                )));
            }
        }
        if let Some(a) = &finals_out {
            if a.shape() != [m, STATE_SIZE] {
                return Err(value_error(format!(
                    "`finals_out` must have shape ({m}, {STATE_SIZE}), found {:?}",
                    a.shape()
                )));
            }
        }
        let own_samples = vec![
            0.0;
            if keep && samples_out.is_none() {
                m * n * STATE_SIZE
            } else {
                0
            }
        ];
        let own_finals = vec![
            0.0;
            if finals_out.is_none() {
                m * STATE_SIZE
            } else {
                0
            }
        ];
        Ok(Buffers {
            samples_out,
            finals_out,
            own_samples,
            own_finals,
            keep,
        })
    }

    /// The memory the run writes: the samples (None when not kept) and the final states, the
    /// caller's arrays checked C-contiguous.
    fn slices(&mut self) -> PyResult<(Option<&mut [f64]>, &mut [f64])> {
        let samples = match &mut self.samples_out {
            Some(a) => Some(c_order(
                a.is_c_contiguous(),
                a.as_slice_mut(),
                "samples_out",
            )?),
            None if self.keep => Some(&mut self.own_samples[..]),
            None => None,
        };
        let finals = match &mut self.finals_out {
            Some(a) => c_order(a.is_c_contiguous(), a.as_slice_mut(), "finals_out")?,
            None => &mut self.own_finals[..],
        };
        Ok((samples, finals))
    }

    /// The arrays returned: our own samples (m, n, 18) and final states (m, 18), None for
    /// what went to the caller's arrays or was not kept.
    #[allow(clippy::type_complexity)]
    fn returned(
        self,
        py: Python<'py>,
        (m, n): (usize, usize),
    ) -> PyResult<(
        Option<Bound<'py, PyArray3<f64>>>,
        Option<Bound<'py, PyArray2<f64>>>,
    )> {
        let returned = self.keep && self.samples_out.is_none();
        let own_samples = self.own_samples;
        let samples = returned
            .then(|| {
                Array3::from_shape_vec((m, n, STATE_SIZE), own_samples).map(|a| a.into_pyarray(py))
            })
            .transpose()
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        let own_finals = self.own_finals;
        let finals = self
            .finals_out
            .is_none()
            .then(|| {
                Array2::from_shape_vec((m, STATE_SIZE), own_finals).map(|a| a.into_pyarray(py))
            })
            .transpose()
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok((samples, finals))
    }
}

/// `run_ensemble`'s result ([`Outputs`]): the samples and final states returned, and the
/// members' summaries column by column.
fn outputs<'py>(
    py: Python<'py>,
    samples: Option<Bound<'py, PyArray3<f64>>>,
    finals: Option<Bound<'py, PyArray2<f64>>>,
    summaries: &[MemberSummary],
) -> Outputs<'py> {
    let column =
        |f: fn(&MemberSummary) -> f64| Array1::from_iter(summaries.iter().map(f)).into_pyarray(py);
    let counts =
        |f: fn(&MemberSummary) -> i64| Array1::from_iter(summaries.iter().map(f)).into_pyarray(py);
    (
        samples,
        finals,
        column(|s| s.energy),
        column(|s| s.momentum),
        column(|s| s.orthogonality),
        column(|s| s.first_flip),
        column(|s| s.last_flip),
        counts(|s| s.flip_count),
        counts(|s| s.status as i64),
        counts(|s| s.n_steps as i64),
        counts(|s| s.n_fev as i64),
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(member_bodies, m)?)?;
    m.add_function(wrap_pyfunction!(run_ensemble, m)?)?;
    Ok(())
}
