//! Bindings of the gyrostat, `poinsot_core::gyrostat`: its right-hand side, its regressor and
//! its motion integrated onto sample times, for many parameter sets at once (the members of a
//! finite-difference Jacobian run on rayon's threads). Shapes and orderings are checked here
//! with the argument's name in the error; the GIL is released around every computation.

use crate::arrays::{Floats1, Floats2, Floats3};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use poinsot_core::drivers::Status;
use poinsot_core::gyrostat::{
    gyrostat_omega_dot as omega_dot, gyrostat_omegas as omegas, gyrostat_regressor as regressor,
    gyrostat_sensitivities as sensitivities, point_acceleration_matrix, GyroDual, SampledRotor,
    GYRO_DIRECTIONS,
};
use poinsot_core::real::Real;
use poinsot_core::so3::{Mat3, Vec3};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use rayon::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::args::{mat3_from, rows, v3, value_error};
use crate::spec::RunSpec;
use poinsot_core::spec::RunSpec as CoreSpec;

/// Run `f` without the GIL; a panic becomes `RuntimeError`.
fn detached<T: Send, F: FnOnce() -> T + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|_| PyRuntimeError::new_err("internal error in poinsot._core (gyrostat)"))
}

fn vec3_from(a: &Floats1<'_>, name: &str) -> PyResult<Vec3> {
    let v = a.as_slice()?;
    if v.len() != 3 {
        return Err(value_error(format!(
            "`{name}` must have shape (3,), found ({},)",
            v.len()
        )));
    }
    Ok([v[0], v[1], v[2]])
}

fn increasing(t: &[f64], name: &str) -> PyResult<()> {
    if let Some(k) = t.iter().position(|x| !x.is_finite()) {
        return Err(value_error(format!("`{name}[{k}]` is not finite")));
    }
    if let Some(k) = t.windows(2).position(|p| p[1] <= p[0]) {
        return Err(value_error(format!(
            "`{name}` must increase strictly, found {name}[{}] = {} after {}",
            k + 1,
            t[k + 1],
            t[k]
        )));
    }
    Ok(())
}

/// `ω̇` (n, 3) of the gyrostat `I ω̇ + ω × (Iω + h) + ḣ = 0` with `I = E diag(moments) Eᵀ`
/// (`axes` = E), at body-frame `omega`, `h`, `h_dot` (n, 3).
#[pyfunction]
fn gyrostat_omega_dot<'py>(
    py: Python<'py>,
    moments: Floats1<'py>,
    axes: Floats2<'py>,
    omega: Floats2<'py>,
    h: Floats2<'py>,
    h_dot: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = vec3_from(&moments, "moments")?;
    let e = mat3_from(&axes, "axes")?;
    let (w, hh, hd) = (
        rows(&omega, 3, "omega")?,
        rows(&h, 3, "h")?,
        rows(&h_dot, 3, "h_dot")?,
    );
    let n = w.nrows();
    if hh.nrows() != n || hd.nrows() != n {
        return Err(value_error(format!(
            "`h` and `h_dot` must have the rows of `omega` ({n}), found {} and {}",
            hh.nrows(),
            hd.nrows()
        )));
    }
    let (w, hh, hd): (Vec<Vec3>, Vec<Vec3>, Vec<Vec3>) = (
        (0..n).map(|i| v3(&w, i)).collect(),
        (0..n).map(|i| v3(&hh, i)).collect(),
        (0..n).map(|i| v3(&hd, i)).collect(),
    );
    let flat = detached(py, || {
        (0..n)
            .flat_map(|i| omega_dot(m, &e, w[i], hh[i], hd[i]))
            .collect::<Vec<f64>>()
    })?;
    let a = Array2::from_shape_vec((n, 3), flat).map_err(|e| value_error(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// The regressor `Φ` (n, 3, 7) of the gyrostat equation at each sample:
/// `Φ θ = I ω̇ + ω × (Iω + J ω_R a) + J ω̇_R a`, `θ = (I11, I22, I33, I12, I13, I23, J)`.
#[pyfunction]
fn gyrostat_regressor<'py>(
    py: Python<'py>,
    omega: Floats2<'py>,
    omega_dot: Floats2<'py>,
    rotor_speed: Floats1<'py>,
    rotor_accel: Floats1<'py>,
    rotor_axis: Floats1<'py>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (w, wd) = (rows(&omega, 3, "omega")?, rows(&omega_dot, 3, "omega_dot")?);
    let (s, sd) = (rotor_speed.as_slice()?, rotor_accel.as_slice()?);
    let a = vec3_from(&rotor_axis, "rotor_axis")?;
    let n = w.nrows();
    if wd.nrows() != n || s.len() != n || sd.len() != n {
        return Err(value_error(format!(
            "`omega_dot`, `rotor_speed` and `rotor_accel` must have the {n} rows of `omega`"
        )));
    }
    let (w, wd): (Vec<Vec3>, Vec<Vec3>) = (
        (0..n).map(|i| v3(&w, i)).collect(),
        (0..n).map(|i| v3(&wd, i)).collect(),
    );
    let (s, sd) = (s.to_vec(), sd.to_vec());
    let flat = detached(py, || {
        (0..n)
            .flat_map(|i| regressor(w[i], wd[i], s[i], sd[i], a))
            .flatten()
            .collect::<Vec<f64>>()
    })?;
    let arr = Array3::from_shape_vec((n, 3, 7), flat).map_err(|e| value_error(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

/// Body-frame ω (m, n, 3) at the sample times `spec.t_eval` (n,) of m gyrostats: member i
/// has the inertia `E_i diag(moments_i) E_iᵀ` (`moments` (m, 3), `axes` (m, 3, 3)), the rotor
/// inertia `rotor_inertia[i]` and starts from `omega0[i]` at `t_eval[0]`; all share the rotor
/// speed `rotor_speed` (k,) sampled at `rotor_t` (k,) (linear between samples) about
/// `rotor_axis`. The momentum form is run by `spec` (a `RunSpec` of a method for any vector
/// field, with its step, sample times and budget), built once and shared by every member and
/// every call of a fit. A member whose motion stops being finite reads NaN from there on.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (moments, axes, rotor_inertia, omega0, spec, rotor_t, rotor_speed, rotor_axis))]
fn gyrostat_omegas<'py>(
    py: Python<'py>,
    moments: Floats2<'py>,
    axes: Floats3<'py>,
    rotor_inertia: Floats1<'py>,
    omega0: Floats2<'py>,
    spec: PyRef<'py, RunSpec>,
    rotor_t: Floats1<'py>,
    rotor_speed: Floats1<'py>,
    rotor_axis: Floats1<'py>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let members = gyrostats(&moments, &axes, &rotor_inertia, &omega0)?;
    let run = onto_samples(&spec)?;
    let ts = run.sampling.t_eval;
    let rotor = Rotor::new(&rotor_t, &rotor_speed, &rotor_axis)?;
    let (m, n) = (members.len(), ts.len());
    let out = detached(py, || rotor.omegas(&members, &run))?;
    let flat: Vec<f64> = out.into_iter().flatten().collect();
    let arr = Array3::from_shape_vec((m, n, 3), flat).map_err(|e| value_error(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

/// One parameter of `gyrostat_sensitivities` as dual numbers: the values `value` (k,) with the
/// seeds `seeds` (p, k) of the `p` directions.
fn seeded<const K: usize>(
    value: &[f64],
    seeds: &Floats2<'_>,
    p: usize,
    name: &str,
) -> PyResult<[GyroDual; K]> {
    let s = seeds.as_array();
    if value.len() != K || s.shape() != [p, K] {
        return Err(value_error(format!(
            "`{name}` must have shape ({K},) and its seeds ({p}, {K}), found ({},) and {:?}",
            value.len(),
            s.shape()
        )));
    }
    Ok(std::array::from_fn(|k| {
        let mut x = GyroDual::splat(value[k]);
        for j in 0..p {
            x.d[j] = s[[j, k]];
        }
        x
    }))
}

/// The segments of a log as one ensemble: for each segment `k`, ω (n_k, 3) and its
/// derivatives (n_k, 3, p) at the sample times of `specs[k]` of one gyrostat with moments
/// `moments`, principal axes `E0 exp(δ̂)` (`axes0`, `delta`), rotor inertia `rotor_inertia`
/// and `ω(t0) = omega0[k]` (K, 3), each given with the seeds (p, ·) of the `p` directions (at
/// most 16; the same for every segment): the variational equations integrated with the
/// motion (`poinsot_core::gyrostat::gyrostat_sensitivities`), the segments on rayon's threads.
#[pyfunction]
#[pyo3(signature = (moments, moment_seeds, axes0, delta, delta_seeds, rotor_inertia, inertia_seeds, omega0, omega_seeds, specs, rotor_t, rotor_speed, rotor_axis))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn gyrostat_sensitivities<'py>(
    py: Python<'py>,
    moments: Floats1<'py>,
    moment_seeds: Floats2<'py>,
    axes0: Floats2<'py>,
    delta: Floats1<'py>,
    delta_seeds: Floats2<'py>,
    rotor_inertia: f64,
    inertia_seeds: Floats1<'py>,
    omega0: Floats2<'py>,
    omega_seeds: Floats2<'py>,
    specs: Vec<PyRef<'py, RunSpec>>,
    rotor_t: Floats1<'py>,
    rotor_speed: Floats1<'py>,
    rotor_axis: Floats1<'py>,
) -> PyResult<Vec<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray3<f64>>)>> {
    let p = moment_seeds.as_array().nrows();
    if p == 0 || p > GYRO_DIRECTIONS {
        return Err(value_error(format!(
            "the seeds must have 1 to {GYRO_DIRECTIONS} rows (directions), found {p}"
        )));
    }
    let m = seeded::<3>(moments.as_slice()?, &moment_seeds, p, "moments")?;
    let d = seeded::<3>(delta.as_slice()?, &delta_seeds, p, "delta")?;
    let w0 = rows(&omega0, 3, "omega0")?;
    if w0.nrows() != specs.len() {
        return Err(value_error(format!(
            "`omega0` must have one row per segment ({}), found {}",
            specs.len(),
            w0.nrows()
        )));
    }
    let ws = (0..w0.nrows())
        .map(|k| seeded::<3>(&v3(&w0, k), &omega_seeds, p, "omega0"))
        .collect::<PyResult<Vec<_>>>()?;
    let js = inertia_seeds.as_slice()?;
    if js.len() != p {
        return Err(value_error(format!(
            "`inertia_seeds` must have shape ({p},), found ({},)",
            js.len()
        )));
    }
    let mut j = GyroDual::splat(rotor_inertia);
    j.d[..p].copy_from_slice(js);
    let e0 = mat3_from(&axes0, "axes0")?;
    let runs = specs
        .iter()
        .map(|s| onto_samples(s))
        .collect::<PyResult<Vec<_>>>()?;
    let rotor = Rotor::new(&rotor_t, &rotor_speed, &rotor_axis)?;
    let outs = detached(py, || {
        let sampled = SampledRotor {
            t: &rotor.t,
            speed: &rotor.speed,
            axis: rotor.axis,
            inertia: rotor_inertia,
        };
        runs.par_iter()
            .zip(&ws)
            .map(|(run, &w)| {
                let n = run.sampling.t_eval.len();
                let mut out = vec![[GyroDual::splat(0.0); 3]; n];
                sensitivities(m, &e0, d, j, sampled, w, p, run, &mut out);
                out
            })
            .collect::<Vec<_>>()
    })?;
    Ok(outs
        .into_iter()
        .map(|out| {
            let n = out.len();
            let omega = Array2::from_shape_fn((n, 3), |(k, i)| out[k][i].v);
            let deriv = Array3::from_shape_fn((n, 3, p), |(k, i, j)| out[k][i].d[j]);
            (omega.into_pyarray(py), deriv.into_pyarray(py))
        })
        .collect())
}

/// A member of `gyrostat_omegas`: its principal moments and axes, its rotor's inertia, its ω
/// at the first time.
type Gyrostat = (Vec3, Mat3, f64, Vec3);

/// The members of `gyrostat_omegas`, their shapes checked against the m rows of `moments`,
/// in the order of the arguments.
fn gyrostats(
    moments: &Floats2<'_>,
    axes: &Floats3<'_>,
    rotor_inertia: &Floats1<'_>,
    omega0: &Floats2<'_>,
) -> PyResult<Vec<Gyrostat>> {
    let mo = rows(moments, 3, "moments")?;
    let m = mo.nrows();
    let ax = axes.as_array();
    if ax.shape() != [m, 3, 3] {
        return Err(value_error(format!(
            "`axes` must have shape ({m}, 3, 3), found {:?}",
            ax.shape()
        )));
    }
    let j = rotor_inertia.as_slice()?;
    if j.len() != m {
        return Err(value_error(format!(
            "`rotor_inertia` must have shape ({m},), found ({},)",
            j.len()
        )));
    }
    let w0 = rows(omega0, 3, "omega0")?;
    if w0.nrows() != m {
        return Err(value_error(format!(
            "`omega0` must have shape ({m}, 3), found {:?}",
            w0.shape()
        )));
    }
    Ok((0..m)
        .map(|i| {
            let e: Mat3 = std::array::from_fn(|r| std::array::from_fn(|c| ax[[i, r, c]]));
            (v3(&mo, i), e, j[i], v3(&w0, i))
        })
        .collect())
}

/// The core's run of `spec`, checked for a vector field and for its sample times (some,
/// increasing, finite).
fn onto_samples<'a>(spec: &'a RunSpec) -> PyResult<CoreSpec<'a>> {
    let run = spec.core();
    run.check_for(false).map_err(value_error)?;
    let ts = run.sampling.t_eval;
    if ts.is_empty() {
        return Err(value_error("`spec` must have sample times `t_eval`"));
    }
    increasing(ts, "t_eval")?;
    Ok(run)
}

/// The rotor every member of `gyrostat_omegas` shares: its speed `speed` sampled at the
/// times `t` (increasing, finite) about `axis`.
struct Rotor {
    t: Vec<f64>,
    speed: Vec<f64>,
    axis: Vec3,
}

impl Rotor {
    /// The rotor's arguments, checked in their order.
    fn new(
        rotor_t: &Floats1<'_>,
        rotor_speed: &Floats1<'_>,
        rotor_axis: &Floats1<'_>,
    ) -> PyResult<Self> {
        let (rt, rs) = (
            rotor_t.as_slice()?.to_vec(),
            rotor_speed.as_slice()?.to_vec(),
        );
        if rt.len() != rs.len() {
            return Err(value_error(format!(
                "`rotor_speed` must have the length of `rotor_t` ({}), found {}",
                rt.len(),
                rs.len()
            )));
        }
        increasing(&rt, "rotor_t")?;
        if let Some(k) = rs.iter().position(|x| !x.is_finite()) {
            return Err(value_error(format!("`rotor_speed[{k}]` is not finite")));
        }
        let axis = vec3_from(rotor_axis, "rotor_axis")?;
        Ok(Rotor {
            t: rt,
            speed: rs,
            axis,
        })
    }

    /// Each member's ω at the sample times of `run` (m · n rows, in parallel when there are
    /// several); NaN from where a member's motion stops being finite.
    fn omegas(&self, members: &[Gyrostat], run: &CoreSpec<'_>) -> Vec<Vec3> {
        let n = run.sampling.t_eval.len();
        let mut out = vec![[0.0; 3]; members.len() * n];
        let run = |(member, block): (&Gyrostat, &mut [Vec3])| {
            let (mom, e, ji, w) = member;
            let rotor = SampledRotor {
                t: &self.t,
                speed: &self.speed,
                axis: self.axis,
                inertia: *ji,
            };
            let status = omegas(*mom, e, rotor, *w, run, block);
            if status != Status::Finished {
                for o in block
                    .iter_mut()
                    .filter(|o| o.iter().any(|x| !x.is_finite()))
                {
                    *o = [f64::NAN; 3];
                }
            }
        };
        if n > 0 {
            if members.len() > 1 {
                members.par_iter().zip(out.par_chunks_mut(n)).for_each(run);
            } else {
                members.iter().zip(out.chunks_mut(n)).for_each(run);
            }
        }
        out
    }
}

/// `hat(ω̇) + hat(ω)²` (n, 3, 3) at body-frame `omega`, `omega_dot` (n, 3): the matrices with
/// `A p = ω̇ × p + ω × (ω × p)`, the acceleration of the body point `p` relative to the centre
/// of mass.
#[pyfunction]
fn point_acceleration_matrices<'py>(
    py: Python<'py>,
    omega: Floats2<'py>,
    omega_dot: Floats2<'py>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (w, wd) = (rows(&omega, 3, "omega")?, rows(&omega_dot, 3, "omega_dot")?);
    let n = w.nrows();
    if wd.nrows() != n {
        return Err(value_error(format!(
            "`omega_dot` must have the {n} rows of `omega`, found {}",
            wd.nrows()
        )));
    }
    let (w, wd): (Vec<Vec3>, Vec<Vec3>) = (
        (0..n).map(|i| v3(&w, i)).collect(),
        (0..n).map(|i| v3(&wd, i)).collect(),
    );
    let flat = detached(py, || {
        (0..n)
            .flat_map(|i| point_acceleration_matrix(w[i], wd[i]))
            .flatten()
            .collect::<Vec<f64>>()
    })?;
    let arr = Array3::from_shape_vec((n, 3, 3), flat).map_err(|e| value_error(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(point_acceleration_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(gyrostat_omega_dot, m)?)?;
    m.add_function(wrap_pyfunction!(gyrostat_regressor, m)?)?;
    m.add_function(wrap_pyfunction!(gyrostat_omegas, m)?)?;
    m.add_function(wrap_pyfunction!(gyrostat_sensitivities, m)?)?;
    Ok(())
}
