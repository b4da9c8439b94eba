//! Bindings of the constrained-system engine (`poinsot_core::lagrange`): a model's compiled
//! expressions (`LagrangianModel`), the samples' post-processing and parameter ensembles on a
//! rayon pool; one run's call is `lagrange_run.rs` (`integrate_lagrange`). Arguments are checked here, named; the GIL is released unless
//! an input is a Python callable (the slow path); Ctrl-C is honoured between chunks.

use std::sync::Arc;

use crate::arrays::{Bools1, Floats1, Floats2, Ints1};
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use poinsot_core::expressions::Program;
use poinsot_core::lagrange::{
    run_members_with, samples as core_samples, Constant, Lagrangian, MemberRun, Model, OneSided,
    SampleOut, Shape, Stabilization,
};
use poinsot_core::system::VectorField;
use poinsot_jit::Jit;
use pyo3::prelude::*;

use crate::args::{rows, value_error};
use crate::engine::RunSpec;
use crate::ensemble::{interruptible, pool};

/// A model's expressions compiled once: `LagrangianModel(codes, values, n, m, nh, np, nu)`,
/// the postfix program of `[M, f, G, b, γ, g, h]` in `[q, q̇, t, p, u]`
/// (`poinsot_core::lagrange::Shape`).
#[pyclass(frozen, module = "poinsot._core")]
pub(crate) struct LagrangianModel {
    pub(crate) model: Arc<Model>,
}

pub(crate) fn slice_len(x: &[f64], k: usize, name: &str) -> PyResult<()> {
    if x.len() != k {
        return Err(value_error(format!(
            "`{name}` must hold {k} numbers, found {}",
            x.len()
        )));
    }
    Ok(())
}

/// A model's sizes and its program (`codes`, `values`) with `outputs` outputs of
/// `[q, q̇, t, p, u]`, checked (`what`: the model or its tangent, for the message).
pub(crate) fn checked_program(
    shape: Shape,
    codes: &Ints1<'_>,
    values: &Floats1<'_>,
    outputs: usize,
    what: &str,
) -> PyResult<Program> {
    let Shape { n, m, nh, .. } = shape;
    if nh > m || n == 0 {
        return Err(value_error(format!(
            "a model needs n ≥ 1 coordinates and nh ≤ m holonomic constraints among its \
             constraints; found n = {n}, m = {m}, nh = {nh}"
        )));
    }
    Program::new(
        codes.as_slice()?,
        values.as_slice()?,
        shape.n_inputs(),
        outputs,
    )
    .map_err(|e| value_error(format!("the {what}'s program is malformed: {e}")))
}

/// `q`, `q̇` (or the state `y`, `2n`, as `q` with `qd` empty), `p` and `u` checked against a
/// model's sizes, each named.
pub(crate) fn check_point(
    shape: Shape,
    q: &[f64],
    v: Option<&[f64]>,
    p: &[f64],
    u: &[f64],
) -> PyResult<()> {
    match v {
        Some(v) => {
            slice_len(q, shape.n, "q")?;
            slice_len(v, shape.n, "qd")?;
        }
        None => slice_len(q, 2 * shape.n, "y")?,
    }
    slice_len(p, shape.np, "p")?;
    slice_len(u, shape.nu, "u")
}

pub(crate) fn mask(active: Option<Bools1<'_>>, m: usize) -> PyResult<Option<Vec<bool>>> {
    active
        .map(|a| {
            let v = a.as_slice()?.to_vec();
            if v.len() != m {
                return Err(value_error(format!(
                    "`active` must hold {m} flags (one per constraint), found {}",
                    v.len()
                )));
            }
            Ok(v)
        })
        .transpose()
}

impl LagrangianModel {
    fn shape(&self) -> Shape {
        self.model.shape
    }

    fn check_point(&self, q: &[f64], v: &[f64], p: &[f64], u: &[f64]) -> PyResult<()> {
        check_point(self.shape(), q, Some(v), p, u)
    }
}

#[pymethods]
impl LagrangianModel {
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
        let program = checked_program(shape, &codes, &values, shape.n_outputs(), "model")?;
        let model = py
            .detach(|| Model::new(shape, program, &Jit))
            .map_err(|e| value_error(format!("the model is malformed: {e}")))?;
        Ok(LagrangianModel {
            model: Arc::new(model),
        })
    }

    /// True when the model's expressions run as machine code (else they are interpreted).
    #[getter]
    fn machine_code(&self) -> bool {
        self.model.is_machine_code()
    }

    /// `(n, m, nh, np, nu)`.
    #[getter]
    fn sizes(&self) -> (usize, usize, usize, usize, usize) {
        let s = self.shape();
        (s.n, s.m, s.nh, s.np, s.nu)
    }

    /// `(M (n, n), f (n,), G (m, n), b (m,), γ (m,), g (nh,), h)` at `(t, q, q̇)` with
    /// parameters `p` and inputs `u`.
    #[allow(clippy::type_complexity)]
    fn parts<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q: Floats1<'py>,
        qd: Floats1<'py>,
        p: Floats1<'py>,
        u: Floats1<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        f64,
    )> {
        let (q, v, p, u) = (q.as_slice()?, qd.as_slice()?, p.as_slice()?, u.as_slice()?);
        self.check_point(q, v, p, u)?;
        let s = self.shape();
        let mut ev = self.model.evaluator();
        ev.evaluate(t, q, v, p, u);
        let x = &ev.parts;
        let (n, m, nh) = (s.n, s.m, s.nh);
        let mut at = 0;
        let mut take = |k: usize| {
            let v = x[at..at + k].to_vec();
            at += k;
            v
        };
        let mm = Array2::from_shape_vec((n, n), take(n * n)).expect("n·n");
        let f = Array1::from(take(n));
        let g_jac = Array2::from_shape_vec((m, n), take(m * n)).expect("m·n");
        let b = Array1::from(take(m));
        let gamma = Array1::from(take(m));
        let g = Array1::from(take(nh));
        let h = take(1)[0];
        Ok((
            mm.into_pyarray(py),
            f.into_pyarray(py),
            g_jac.into_pyarray(py),
            b.into_pyarray(py),
            gamma.into_pyarray(py),
            g.into_pyarray(py),
            h,
        ))
    }

    /// `ẏ = [q̇, q̈]` (2n,) at `(t, y)` as the integrators see it: Baumgarte's gains `(α, β)`
    /// in the KKT system, the constraints in `active` (all when absent); NaN where the
    /// system is singular.
    #[pyo3(signature = (t, y, p, u, alpha=0.0, beta=0.0, active=None))]
    #[allow(clippy::too_many_arguments)]
    fn rhs<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        y: Floats1<'py>,
        p: Floats1<'py>,
        u: Floats1<'py>,
        alpha: f64,
        beta: f64,
        active: Option<Bools1<'py>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s = self.shape();
        let (y, p, u) = (y.as_slice()?, p.as_slice()?, u.as_slice()?);
        slice_len(y, 2 * s.n, "y")?;
        slice_len(p, s.np, "p")?;
        slice_len(u, s.nu, "u")?;
        let active = mask(active, s.m)?;
        let st = Stabilization {
            alpha,
            beta,
            projection: false,
        };
        let sys = Lagrangian::new(&self.model, p, Constant(u), st, active).map_err(value_error)?;
        let mut out = vec![0.0; 2 * s.n];
        sys.rhs(t, y, &mut out);
        Ok(Array1::from(out).into_pyarray(py))
    }

    /// `(q̈ (n,), λ (m,))` at `(t, q, q̇)`: the physical multipliers (no stabilisation), NaN
    /// for a constraint not in `active`, and everything NaN where the system is singular.
    #[pyo3(signature = (t, q, qd, p, u, active=None))]
    #[allow(clippy::too_many_arguments)]
    fn accelerations<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q: Floats1<'py>,
        qd: Floats1<'py>,
        p: Floats1<'py>,
        u: Floats1<'py>,
        active: Option<Bools1<'py>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
        let (q, v, p, u) = (q.as_slice()?, qd.as_slice()?, p.as_slice()?, u.as_slice()?);
        self.check_point(q, v, p, u)?;
        let s = self.shape();
        let active = mask(active, s.m)?;
        let mut ev = self.model.evaluator();
        ev.evaluate(t, q, v, p, u);
        let mut qdd = vec![f64::NAN; s.n];
        let mut lam = vec![f64::NAN; s.m];
        if ev.solve(v, active.as_deref(), 0.0, 0.0) {
            let (a, l) = ev.solution();
            qdd = a;
            for (r, &c) in ev.rows().iter().enumerate() {
                lam[c] = l[r];
            }
        }
        Ok((
            Array1::from(qdd).into_pyarray(py),
            Array1::from(lam).into_pyarray(py),
        ))
    }

    /// Per sample: `(q̈ (S, n), λ (S, m), Gᵀλ (S, n), g (S, nh), G q̇ + b (S, m), h (S,))` at
    /// times `t` (S,), states `y` (S, 2n), inputs `u` (S, nu).
    #[pyo3(signature = (t, y, p, u, active=None))]
    #[allow(clippy::type_complexity)]
    fn samples<'py>(
        &self,
        py: Python<'py>,
        t: Floats1<'py>,
        y: Floats2<'py>,
        p: Floats1<'py>,
        u: Floats2<'py>,
        active: Option<Bools1<'py>>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let s = self.shape();
        let t = t.as_slice()?;
        let ns = t.len();
        let y = rows(&y, 2 * s.n, "y")?;
        let u = rows(&u, s.nu, "u")?;
        if y.nrows() != ns || u.nrows() != ns {
            return Err(value_error(format!(
                "`y` and `u` must have one row per time ({ns}), found {} and {}",
                y.nrows(),
                u.nrows()
            )));
        }
        let p = p.as_slice()?;
        slice_len(p, s.np, "p")?;
        let active = mask(active, s.m)?;
        let y: Vec<f64> = y.iter().copied().collect();
        let u: Vec<f64> = u.iter().copied().collect();
        let (mut qdd, mut lam, mut forces) = (
            vec![0.0; ns * s.n],
            vec![0.0; ns * s.m],
            vec![0.0; ns * s.n],
        );
        let (mut g, mut vel, mut energy) =
            (vec![0.0; ns * s.nh], vec![0.0; ns * s.m], vec![0.0; ns]);
        let model = &self.model;
        py.detach(|| {
            core_samples(
                model,
                t,
                &y,
                p,
                &u,
                active.as_deref(),
                SampleOut {
                    qdd: &mut qdd,
                    lam: &mut lam,
                    forces: &mut forces,
                    g: &mut g,
                    velocity: &mut vel,
                    energy: &mut energy,
                },
            )
        });
        let a2 = |v: Vec<f64>, k: usize| {
            Array2::from_shape_vec((ns, k), v)
                .expect("rows")
                .into_pyarray(py)
        };
        Ok((
            a2(qdd, s.n),
            a2(lam, s.m),
            a2(forces, s.n),
            a2(g, s.nh),
            a2(vel, s.m),
            Array1::from(energy).into_pyarray(py),
        ))
    }

    /// The nearest consistent state `(q, q̇)`: Gauss–Newton with minimum-norm corrections on
    /// the holonomic residuals, then the velocities onto `G q̇ + b = 0`; the third value is
    /// false when a correction cannot be computed.
    #[pyo3(signature = (t, q, qd, p, u, active=None, tol=1e-13, max_iter=20))]
    #[allow(clippy::too_many_arguments)]
    fn project<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q: Floats1<'py>,
        qd: Floats1<'py>,
        p: Floats1<'py>,
        u: Floats1<'py>,
        active: Option<Bools1<'py>>,
        tol: f64,
        max_iter: usize,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, bool)> {
        let (q, v, p, u) = (q.as_slice()?, qd.as_slice()?, p.as_slice()?, u.as_slice()?);
        self.check_point(q, v, p, u)?;
        let active = mask(active, self.shape().m)?;
        let (mut q, mut v) = (q.to_vec(), v.to_vec());
        let mut ev = self.model.evaluator();
        let ok = ev.project(t, &mut q, &mut v, p, u, active.as_deref(), tol, max_iter);
        Ok((
            Array1::from(q).into_pyarray(py),
            Array1::from(v).into_pyarray(py),
            ok,
        ))
    }

    /// For every member's initial state `Z` (k, 2n) with parameters `P` (k, np) and inputs `U`
    /// (k, nu) at `t`: `(max |g|, max |G q̇ + b|, solvable)`, each (k,).
    #[allow(clippy::type_complexity)]
    fn starts<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        z: Floats2<'py>,
        params: Floats2<'py>,
        inputs: Floats2<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
    )> {
        let s = self.shape();
        let z = rows(&z, 2 * s.n, "Z")?;
        let pp = rows(&params, s.np, "P")?;
        let uu = rows(&inputs, s.nu, "U")?;
        let k = z.nrows();
        if pp.nrows() != k || uu.nrows() != k {
            return Err(value_error("`Z`, `P` and `U` must have one row per member"));
        }
        let mut ev = self.model.evaluator();
        let (mut pos, mut vel, mut ok) = (vec![0.0; k], vec![0.0; k], vec![false; k]);
        for i in 0..k {
            let row: Vec<f64> = z.row(i).iter().copied().collect();
            let p: Vec<f64> = pp.row(i).iter().copied().collect();
            let u: Vec<f64> = uu.row(i).iter().copied().collect();
            let (q, v) = row.split_at(s.n);
            ev.evaluate(t, q, v, &p, &u);
            pos[i] = (0..s.nh).fold(0.0f64, |a, c| a.max(ev.residual(c).abs()));
            vel[i] = (0..s.m).fold(0.0f64, |a, c| a.max(ev.velocity_residual(c, v).abs()));
            ok[i] = ev.solve(v, None, 0.0, 0.0) && ev.solution().0.iter().all(|x| x.is_finite());
        }
        Ok((
            Array1::from(pos).into_pyarray(py),
            Array1::from(vel).into_pyarray(py),
            Array1::from(ok).into_pyarray(py),
        ))
    }

    /// Integrate members with parameters `P` (k, np), constant inputs `U` (k, nu) and initial
    /// states `Y0` (k, 2n) from `t0` on a pool of `threads`, each the run `spec` (DOP853 or an
    /// explicit tableau; its sample times `t_eval`, at least one, and its end; at most its
    /// `max_steps` steps: a member stopped there has the status `RUNNING` and NaN samples):
    /// `(samples (k, len(t_eval), 2n), status, steps, evaluations, releases)` per member.
    /// `unilateral`: the one-sided constraints (indices among the model's), each released
    /// where its multiplier falls through zero, located inside the time loop with detection
    /// points no further apart than a grid of `resolution` points
    /// (`poinsot_core::lagrange::run_member_with`); `releases` (k, len(unilateral)): the
    /// release times, NaN where a constraint held.
    #[pyo3(signature = (
        params, inputs, y0, alpha, beta, projection, spec, t0, threads, unilateral=Vec::new(),
        resolution=2001
    ))]
    #[allow(clippy::too_many_arguments)]
    fn run_ensemble<'py>(
        &self,
        py: Python<'py>,
        params: Floats2<'py>,
        inputs: Floats2<'py>,
        y0: Floats2<'py>,
        alpha: f64,
        beta: f64,
        projection: bool,
        spec: PyRef<'py, RunSpec>,
        t0: f64,
        threads: usize,
        unilateral: Vec<usize>,
        resolution: usize,
    ) -> PyResult<EnsembleOutputs<'py>> {
        let s = self.shape();
        let rows = self.member_rows(&params, &inputs, &y0)?;
        let run = spec.core();
        run.check_for(false).map_err(value_error)?;
        let (method, dt, max_steps) = (run.method, run.dt, run.max_steps);
        let (t1, t_eval) = (run.sampling.t_end, run.sampling.t_eval);
        if t_eval.is_empty() {
            return Err(value_error("`t_eval` must hold at least one time"));
        }
        let st = Stabilization {
            alpha,
            beta,
            projection,
        };
        let one_sided = one_sided(&unilateral, s.m, resolution)?;
        let k = rows.k;
        let mut samples = vec![0.0; k * t_eval.len() * 2 * s.n];
        let mut releases = vec![f64::NAN; k * unilateral.len()];
        let pool = pool(threads.max(1))?;
        let model = &*self.model;
        let runs = {
            let (samples, releases, rows) = (&mut samples, &mut releases, &rows);
            interruptible(py, &pool, move |stop| {
                run_members_with(
                    model,
                    (&rows.params, &rows.inputs, &rows.y0),
                    st,
                    method,
                    (t0, t1, dt),
                    t_eval,
                    samples,
                    max_steps,
                    stop,
                    one_sided,
                    releases,
                )
            })?
        };
        let releases = Array2::from_shape_vec((k, unilateral.len()), releases)
            .expect("members · one-sided constraints");
        let samples = Array3::from_shape_vec((k, t_eval.len(), 2 * s.n), samples)
            .expect("members · samples · 2n");
        Ok(ensemble_outputs(py, samples, &runs, releases))
    }
}

/// What `LagrangianModel.run_ensemble` returns: the samples (k, len(t_eval), 2n), the status,
/// steps and evaluations per member, and the release times (k, len(unilateral)).
type EnsembleOutputs<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
);

/// The members of a parameter ensemble, checked: `k` rows of parameters `P` (k, np), constant
/// inputs `U` (k, nu) and initial states `Y0` (k, 2n), each flattened in C order.
struct MemberRows {
    k: usize,
    params: Vec<f64>,
    inputs: Vec<f64>,
    y0: Vec<f64>,
}

impl LagrangianModel {
    /// The members' rows `P`, `U` and `Y0` ([`MemberRows`]), their widths and counts checked.
    fn member_rows(
        &self,
        params: &Floats2<'_>,
        inputs: &Floats2<'_>,
        y0: &Floats2<'_>,
    ) -> PyResult<MemberRows> {
        let s = self.shape();
        let pp = rows(params, s.np, "P")?;
        let uu = rows(inputs, s.nu, "U")?;
        let zz = rows(y0, 2 * s.n, "Y0")?;
        let k = zz.nrows();
        if pp.nrows() != k || uu.nrows() != k {
            return Err(value_error(
                "`P`, `U` and `Y0` must have one row per member",
            ));
        }
        Ok(MemberRows {
            k,
            params: pp.iter().copied().collect(),
            inputs: uu.iter().copied().collect(),
            y0: zz.iter().copied().collect(),
        })
    }
}

/// The one-sided constraints `unilateral` of a model with `m` constraints, checked in range,
/// with the detection grid's `resolution` (at least 2 points).
fn one_sided(unilateral: &[usize], m: usize, resolution: usize) -> PyResult<OneSided<'_>> {
    if let Some(&c) = unilateral.iter().find(|&&c| c >= m) {
        return Err(value_error(format!(
            "`unilateral` names constraint {c}; the model has {m}"
        )));
    }
    if resolution < 2 {
        return Err(value_error(format!(
            "`resolution` must be at least 2, found {resolution}"
        )));
    }
    Ok(OneSided {
        constraints: unilateral,
        resolution,
    })
}

/// The ensemble's result ([`EnsembleOutputs`]): the samples, the members' runs column by
/// column, the release times.
fn ensemble_outputs<'py>(
    py: Python<'py>,
    samples: Array3<f64>,
    runs: &[MemberRun],
    releases: Array2<f64>,
) -> EnsembleOutputs<'py> {
    let col = |f: fn(&MemberRun) -> i64| Array1::from_iter(runs.iter().map(f)).into_pyarray(py);
    (
        samples.into_pyarray(py),
        col(|r| r.status as i64),
        col(|r| r.n_steps as i64),
        col(|r| r.n_fev as i64),
        releases.into_pyarray(py),
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<LagrangianModel>()?;
    m.add_function(wrap_pyfunction!(
        crate::lagrange_run::integrate_lagrange,
        m
    )?)?;
    Ok(())
}
