//! Bindings of the exact torque-free solution: `poinsot_core::{elliptic, torque_free,
//! freebody}`. Array arguments take any layout and real dtype, read as C-ordered float64
//! (`crate::arrays`; the Python layer validates the values, and the shapes are checked again
//! here, with the argument's name in the error). Inputs are copied out (the rows of an (N, 3)
//! array of ω are read in place), the GIL is released around the computation, and a panic in
//! the core comes back as `RuntimeError`, never as a crash or a `PanicException`.

use std::borrow::Cow;

use crate::arrays::FloatsDyn;
use numpy::ndarray::{Array1, Array2, Array3, Array4, ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArray4, PyArrayDyn};
use poinsot_core::so3::{Mat3, Vec3};
use poinsot_core::{elliptic, freebody, torque_free};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{catch_unwind, AssertUnwindSafe};

type Arr<'py> = FloatsDyn<'py>;
type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

// --------------------------------------------------------------------------- helpers

/// Run `f` without the GIL; a panic becomes `RuntimeError`.
fn detached<T: Send, F: FnOnce() -> T + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|e| {
            let msg = e
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            PyRuntimeError::new_err(format!("internal error in poinsot._core: {msg}"))
        })
}

/// A flat buffer of doubles seen as arrays of `N` (its length a multiple of `N`): the core
/// writes vectors and matrices straight into the array NumPy will own.
fn as_arrays<const N: usize>(flat: &mut [f64]) -> &mut [[f64; N]] {
    assert_eq!(flat.len() % N, 0, "a whole number of arrays");
    // SAFETY: [f64; N] has the alignment of f64 and the size of N of them; the length is a
    // multiple of N, and the borrow is unique.
    unsafe { std::slice::from_raw_parts_mut(flat.as_mut_ptr().cast(), flat.len() / N) }
}

fn shape_error(name: &str, want: &str, got: &[usize]) -> PyErr {
    PyValueError::new_err(format!("`{name}` must have shape {want}, found {got:?}"))
}

fn vec3(a: &Arr<'_>, name: &str) -> PyResult<Vec3> {
    let v = a.as_array();
    if v.shape() != [3] {
        return Err(shape_error(name, "(3,)", v.shape()));
    }
    Ok([v[[0]], v[[1]], v[[2]]])
}

fn mat3(a: &Arr<'_>, name: &str) -> PyResult<Mat3> {
    let v = a.as_array();
    if v.shape() != [3, 3] {
        return Err(shape_error(name, "(3, 3)", v.shape()));
    }
    Ok(std::array::from_fn(|r| std::array::from_fn(|c| v[[r, c]])))
}

/// The rows of an (N, 3) array as 3-vectors: borrowed, not copied, from a C-ordered array
/// (10⁶ rows were 24 MB copied per call).
fn vecs3<'a>(a: &'a Arr<'_>, name: &str) -> PyResult<Cow<'a, [Vec3]>> {
    let v = a.as_array();
    if v.ndim() != 2 || v.shape()[1] != 3 {
        return Err(shape_error(name, "(N, 3)", v.shape()));
    }
    // C order (converted on extraction): the rows one after another
    let flat = a.as_slice()?;
    // SAFETY: [f64; 3] has the alignment of f64 and the size of three; the length is 3N.
    let rows = unsafe { std::slice::from_raw_parts(flat.as_ptr().cast(), flat.len() / 3) };
    Ok(Cow::Borrowed(rows))
}

fn mats3(a: &Arr<'_>, name: &str) -> PyResult<Vec<Mat3>> {
    let v = a.as_array();
    if v.ndim() != 3 || v.shape()[1..] != [3, 3] {
        return Err(shape_error(name, "(N, 3, 3)", v.shape()));
    }
    Ok((0..v.shape()[0])
        .map(|i| std::array::from_fn(|r| std::array::from_fn(|c| v[[i, r, c]])))
        .collect())
}

fn times(a: &Arr<'_>, name: &str) -> PyResult<Vec<f64>> {
    let v = a.as_array();
    if v.ndim() != 1 {
        return Err(shape_error(name, "(n,)", v.shape()));
    }
    Ok(v.iter().copied().collect())
}

fn symmetry(code: i64) -> PyResult<u8> {
    match code {
        0..=3 => Ok(code as u8),
        _ => Err(PyValueError::new_err(format!(
            "`symmetry` must be a code 0…3 (asymmetric, prolate, oblate, spherical), found {code}"
        ))),
    }
}

/// `f` applied to every element of `u`: `K` arrays of `u`'s shape.
fn map_elements<'py, const K: usize, F>(
    py: Python<'py>,
    u: &Arr<'py>,
    f: F,
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; K]>
where
    F: Fn(f64) -> [f64; K] + Send + Sync,
{
    let view = u.as_array();
    let shape = view.shape().to_vec();
    let flat: Vec<f64> = view.iter().copied().collect();
    let out = detached(py, || {
        let mut out: [Vec<f64>; K] = std::array::from_fn(|_| Vec::with_capacity(flat.len()));
        for &x in &flat {
            for (o, y) in out.iter_mut().zip(f(x)) {
                o.push(y);
            }
        }
        out
    })?;
    let mut arrays = Vec::with_capacity(K);
    for o in out {
        let a = ArrayD::from_shape_vec(IxDyn(&shape), o)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        arrays.push(a.into_pyarray(py));
    }
    arrays
        .try_into()
        .map_err(|_| PyRuntimeError::new_err("internal error in poinsot._core: array count"))
}

// --------------------------------------------------------------------------- elliptic

/// `(sn, cn, dn, p, v)` of `u` (any shape) with `k = K(m)`:
/// `poinsot_core::elliptic::jacobi_reduced`.
#[pyfunction]
fn jacobi_reduced<'py>(
    py: Python<'py>,
    u: Arr<'py>,
    m: f64,
    m1: f64,
    k: f64,
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; 5]> {
    map_elements(py, &u, |x| {
        let (a, b, c, p, v) = elliptic::jacobi_reduced(x, m, m1, k);
        [a, b, c, p, v]
    })
}

/// `(sn, cn, dn, am)` of `u` (any shape) by the plain AGM: `elliptic::jacobi_agm`.
#[pyfunction]
fn jacobi_sn_cn_dn_am<'py>(
    py: Python<'py>,
    u: Arr<'py>,
    m: f64,
    m1: f64,
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; 4]> {
    map_elements(py, &u, |x| {
        let (a, b, c, d) = elliptic::jacobi_agm(x, m, m1);
        [a, b, c, d]
    })
}

/// `K(m)` from `m1 = 1 − m`; `inf` at `m1 = 0`.
#[pyfunction]
fn ellipk_m1(m1: f64) -> f64 {
    elliptic::ellipk_m1(m1)
}

/// `F(φ | m)` of every element of `phi`.
#[pyfunction]
fn ellipf<'py>(
    py: Python<'py>,
    phi: Arr<'py>,
    m: f64,
    m1: f64,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let [a] = map_elements(py, &phi, |x| [elliptic::ellipf(x, m, m1)])?;
    Ok(a)
}

/// `Π(n | m)`, `n < 1`.
#[pyfunction]
fn ellippi_complete(n: f64, m: f64, m1: f64) -> f64 {
    elliptic::ellippi_complete(n, m, m1)
}

/// `Π(n; φ | m)` of every element of `phi`, `n < 1`.
#[pyfunction]
fn ellippi<'py>(
    py: Python<'py>,
    n: f64,
    phi: Arr<'py>,
    m: f64,
    m1: f64,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let [a] = map_elements(py, &phi, |x| [elliptic::ellippi(n, x, m, m1)])?;
    Ok(a)
}

/// The argument `u` in (−2K, 2K] with `sn u = s`, `cn u = c`.
#[pyfunction]
fn first_kind_from_sn_cn(s: f64, c: f64, m: f64, m1: f64) -> f64 {
    elliptic::first_kind_from_sn_cn(s, c, m, m1)
}

/// `∫₀^u du'/(1 − n sn²u')` of every element of `u`, `n < 1`.
#[pyfunction]
fn third_kind_u<'py>(
    py: Python<'py>,
    n: f64,
    u: Arr<'py>,
    m: f64,
    m1: f64,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let k = elliptic::ellipk_m1(m1);
    let [a] = map_elements(py, &u, |x| [elliptic::third_kind_u(n, x, m, m1, k)])?;
    Ok(a)
}

/// Carlson's `R_F(x, y, z)`.
#[pyfunction]
fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    elliptic::carlson_rf(x, y, z)
}

/// Carlson's `R_J(x, y, z, p)`.
#[pyfunction]
fn carlson_rj(x: f64, y: f64, z: f64, p: f64) -> f64 {
    elliptic::carlson_rj(x, y, z, p)
}

// --------------------------------------------------------------------------- torque-free

/// The regime rows (N, `REGIME_OFFSETS["size"]`) of the motions from body-frame ω `w` (N, 3),
/// for sorted moments `moments` (3,), sorted axes `axes` (3, 3) and symmetry code `symmetry`.
#[pyfunction]
fn torque_free_regimes<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    axes: Arr<'py>,
    symmetry: i64,
    w: Arr<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (i, s, code, ws) = (
        vec3(&moments, "moments")?,
        mat3(&axes, "axes")?,
        self::symmetry(symmetry)?,
        vecs3(&w, "w")?,
    );
    let rows = detached(py, || {
        ws.iter()
            .flat_map(|&w| torque_free::regime_of(i, &s, code, w).to_row())
            .collect::<Vec<f64>>()
    })?;
    let a = Array2::from_shape_vec((ws.len(), torque_free::row::SIZE), rows)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// The family code, period of ω(t) and flip interval (N, 3) of the motions from body-frame ω
/// `w` (N, 3): `torque_free::families` (`Regime::case`, `Regime::period`,
/// `Regime::flip_interval`, in SIMD lanes and on rayon's threads).
#[pyfunction]
fn torque_free_families<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    axes: Arr<'py>,
    symmetry: i64,
    w: Arr<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (i, s, code, ws) = (
        vec3(&moments, "moments")?,
        mat3(&axes, "axes")?,
        self::symmetry(symmetry)?,
        vecs3(&w, "w")?,
    );
    let rows = detached(py, || {
        let mut out = vec![torque_free::Family::default(); ws.len()];
        torque_free::families(i, &s, code, &ws, &mut out);
        out.iter()
            .flat_map(|f| [f.case as f64, f.period, f.flip_interval])
            .collect::<Vec<f64>>()
    })?;
    let a = Array2::from_shape_vec((ws.len(), 3), rows)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// ω(t) (N, n, 3), body frame, of the motions from body-frame ω `w` (N, 3) at the times `t`
/// (n,): `torque_free::exact_omegas` (members on rayon's threads when many).
#[pyfunction]
fn torque_free_omegas<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    axes: Arr<'py>,
    symmetry: i64,
    w: Arr<'py>,
    t: Arr<'py>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (i, s, code, ws, ts) = (
        vec3(&moments, "moments")?,
        mat3(&axes, "axes")?,
        self::symmetry(symmetry)?,
        vecs3(&w, "w")?,
        times(&t, "t")?,
    );
    let (nw, nt) = (ws.len(), ts.len());
    let flat = detached(py, || {
        let mut flat = vec![0.0; nw * nt * 3];
        torque_free::exact_omegas(i, &s, code, &ws, &ts, as_arrays::<3>(&mut flat));
        flat
    })?;
    let a = Array3::from_shape_vec((nw, nt, 3), flat)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// The exact derivatives of one torque-free motion (`torque_free::ExactTangent`): from ω0
/// `w` (3,) in the sorted principal frame of the sorted `moments` (three distinct) and `Q(0) =
/// q0` (3, 3) (sorted frame → space), ω(t) (n, 3) and `∂ω(t)/∂p` (n, 3, 6) for the directions
/// `p = (I1, I2, I3, ω0_1, ω0_2, ω0_3)`, Q(t) (n, 3, 3) and `∂Q(t)/∂p` (n, 3, 3, 6), and the
/// period and the flip interval with their derivatives (7,: the value, then the six).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn torque_free_derivatives<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    w: Arr<'py>,
    q0: Arr<'py>,
    t: Arr<'py>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray4<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let (i, w, q0, ts) = (
        vec3(&moments, "moments")?,
        vec3(&w, "w")?,
        mat3(&q0, "q0")?,
        times(&t, "t")?,
    );
    let tangent =
        torque_free::ExactTangent::new(i, w).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let n = ts.len();
    let mut omega = Vec::with_capacity(3 * n);
    let mut d = Vec::with_capacity(18 * n);
    let mut q = Vec::with_capacity(9 * n);
    let mut dq = Vec::with_capacity(54 * n);
    for &t in ts.iter() {
        let (value, rows) = tangent.omega_at(t);
        omega.extend_from_slice(&value);
        for row in rows {
            d.extend_from_slice(&row);
        }
        let (value, parts) = tangent.attitude_at(&q0, t);
        for (row, part) in value.iter().zip(&parts) {
            q.extend_from_slice(row);
            for entry in part {
                dq.extend_from_slice(entry);
            }
        }
    }
    let with = |x: poinsot_core::dual::Dual<6>| {
        let mut v = vec![x.v];
        v.extend_from_slice(&x.d);
        Array1::from(v).into_pyarray(py)
    };
    let shaped = |e: numpy::ndarray::ShapeError| PyRuntimeError::new_err(e.to_string());
    let omega = Array2::from_shape_vec((n, 3), omega).map_err(shaped)?;
    let d = Array3::from_shape_vec((n, 3, 6), d).map_err(shaped)?;
    let q = Array3::from_shape_vec((n, 3, 3), q).map_err(shaped)?;
    let dq = Array4::from_shape_vec((n, 3, 3, 6), dq).map_err(shaped)?;
    Ok((
        omega.into_pyarray(py),
        d.into_pyarray(py),
        q.into_pyarray(py),
        dq.into_pyarray(py),
        with(tangent.period()),
        with(tangent.flip_interval()),
    ))
}

/// Q(t) (N, n, 3, 3) (body → space) of the motions from `w` (N, 3) and attitudes `q0`
/// (N, 3, 3) or one shared (1, 3, 3), at the times `t` (n,): `torque_free::exact_attitudes`.
#[pyfunction]
fn torque_free_attitudes<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    axes: Arr<'py>,
    symmetry: i64,
    w: Arr<'py>,
    q0: Arr<'py>,
    t: Arr<'py>,
) -> PyResult<Bound<'py, PyArray4<f64>>> {
    let (i, s, code, ws, qs, ts) = (
        vec3(&moments, "moments")?,
        mat3(&axes, "axes")?,
        self::symmetry(symmetry)?,
        vecs3(&w, "w")?,
        mats3(&q0, "q0")?,
        times(&t, "t")?,
    );
    if !(qs.len() == 1 || qs.len() == ws.len()) {
        return Err(PyValueError::new_err(format!(
            "`q0` must hold one rotation or one per member ({}), found {}",
            ws.len(),
            qs.len()
        )));
    }
    let (nw, nt) = (ws.len(), ts.len());
    let flat = detached(py, || {
        let mut flat = vec![0.0; nw * nt * 9];
        let out = as_arrays::<9>(&mut flat);
        // SAFETY: [[f64; 3]; 3] and [f64; 9] have the same size and alignment
        let out: &mut [[[f64; 3]; 3]] =
            unsafe { std::slice::from_raw_parts_mut(out.as_mut_ptr().cast(), out.len()) };
        torque_free::exact_attitudes(i, &s, code, &ws, &qs, &ts, out);
        flat
    })?;
    let a = Array4::from_shape_vec((nw, nt, 3, 3), flat)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// `Q0 exp(Ω t)` (n, 3, 3) at a fixed point ω `w` (3,) from `q0` (3, 3), at the times `t` (n,):
/// `torque_free::fixed_point_attitude`.
#[pyfunction]
fn fixed_point_attitudes<'py>(
    py: Python<'py>,
    w: Arr<'py>,
    q0: Arr<'py>,
    t: Arr<'py>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (w, q, ts) = (vec3(&w, "w")?, mat3(&q0, "q0")?, times(&t, "t")?);
    let out = detached(py, || {
        ts.iter()
            .flat_map(|&t| torque_free::fixed_point_attitude(&q, w, t))
            .flatten()
            .collect::<Vec<f64>>()
    })?;
    let a = Array3::from_shape_vec((ts.len(), 3, 3), out)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

// --------------------------------------------------------------------------- the free body

/// `(k, a)` (N,), (N,) of principal `moments` (3,) and ω (N, 3) in principal axes, eqs (30)–(31).
#[pyfunction]
fn principal_invariants<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    w: Arr<'py>,
) -> PyResult<Pair<'py>> {
    let (i, ws) = (vec3(&moments, "moments")?, vecs3(&w, "w")?);
    let (k, a): (Vec<f64>, Vec<f64>) = detached(py, || {
        ws.iter().map(|&w| freebody::invariants(i, w)).unzip()
    })?;
    Ok((
        Array1::from(k).into_pyarray(py),
        Array1::from(a).into_pyarray(py),
    ))
}

/// `(k, |L|)` (N,), (N,) for a full inertia (3, 3) and body-frame ω (N, 3): eq. (12)'s
/// rotational energy and the norm of eq. (03)'s `A ω`.
#[pyfunction]
fn rotational_energies_and_momenta<'py>(
    py: Python<'py>,
    inertia: Arr<'py>,
    w: Arr<'py>,
) -> PyResult<Pair<'py>> {
    use poinsot_core::invariants::{angular_momentum_body, rotational_energy};
    let (a, ws) = (mat3(&inertia, "inertia")?, vecs3(&w, "w")?);
    let (k, l): (Vec<f64>, Vec<f64>) = detached(py, || {
        ws.iter()
            .map(|&w| {
                let l = angular_momentum_body(&a, w);
                (
                    rotational_energy(&a, w),
                    (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt(),
                )
            })
            .unzip()
    })?;
    Ok((
        Array1::from(k).into_pyarray(py),
        Array1::from(l).into_pyarray(py),
    ))
}

/// Semi-axes `√(2k/I_i)` of the energy ellipsoid (30).
#[pyfunction]
fn energy_ellipsoid_semi_axes<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    energy: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let i = vec3(&moments, "moments")?;
    Ok(PyArray1::from_slice(
        py,
        &freebody::energy_ellipsoid_semi_axes(i, energy),
    ))
}

/// Semi-axes `a/I_i` of the momentum ellipsoid (31).
#[pyfunction]
fn momentum_ellipsoid_semi_axes<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    momentum: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let i = vec3(&moments, "moments")?;
    Ok(PyArray1::from_slice(
        py,
        &freebody::momentum_ellipsoid_semi_axes(i, momentum),
    ))
}

/// `b_i = I_i (a²/(2k) − I_i)` of the cone (32).
#[pyfunction]
fn cone_coefficients<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    energy: f64,
    momentum: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let i = vec3(&moments, "moments")?;
    Ok(PyArray1::from_slice(
        py,
        &freebody::cone_coefficients(i, energy, momentum),
    ))
}

/// `∂ω̇/∂ω = A⁻¹(hat(Aω) − hat(ω) A)` (3, 3) of Euler's equation (20).
#[pyfunction]
fn euler_jacobian<'py>(
    py: Python<'py>,
    inertia: Arr<'py>,
    w: Arr<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, w) = (mat3(&inertia, "inertia")?, vec3(&w, "w")?);
    let j = freebody::euler_jacobian(&a, w)
        .ok_or_else(|| PyValueError::new_err("`inertia` is singular"))?;
    let flat: Vec<f64> = j.into_iter().flatten().collect();
    let arr =
        Array2::from_shape_vec((3, 3), flat).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

/// `ω̇` (N, 3) of the torque-free Euler equation, eqs (27)–(29), principal components.
#[pyfunction]
fn euler_omega_dot_free<'py>(
    py: Python<'py>,
    moments: Arr<'py>,
    w: Arr<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (i, ws) = (vec3(&moments, "moments")?, vecs3(&w, "w")?);
    let flat: Vec<f64> = ws
        .iter()
        .flat_map(|&w| freebody::euler_omega_dot(i, w))
        .collect();
    let arr = Array2::from_shape_vec((ws.len(), 3), flat)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

/// Add the exact torque-free solution to the module `m`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(jacobi_reduced, m)?)?;
    m.add_function(wrap_pyfunction!(jacobi_sn_cn_dn_am, m)?)?;
    m.add_function(wrap_pyfunction!(ellipk_m1, m)?)?;
    m.add_function(wrap_pyfunction!(ellipf, m)?)?;
    m.add_function(wrap_pyfunction!(ellippi_complete, m)?)?;
    m.add_function(wrap_pyfunction!(ellippi, m)?)?;
    m.add_function(wrap_pyfunction!(first_kind_from_sn_cn, m)?)?;
    m.add_function(wrap_pyfunction!(third_kind_u, m)?)?;
    m.add_function(wrap_pyfunction!(carlson_rf, m)?)?;
    m.add_function(wrap_pyfunction!(carlson_rj, m)?)?;
    m.add_function(wrap_pyfunction!(torque_free_regimes, m)?)?;
    m.add_function(wrap_pyfunction!(torque_free_families, m)?)?;
    m.add_function(wrap_pyfunction!(torque_free_omegas, m)?)?;
    m.add_function(wrap_pyfunction!(torque_free_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(torque_free_attitudes, m)?)?;
    m.add_function(wrap_pyfunction!(fixed_point_attitudes, m)?)?;
    m.add_function(wrap_pyfunction!(principal_invariants, m)?)?;
    m.add_function(wrap_pyfunction!(rotational_energies_and_momenta, m)?)?;
    m.add_function(wrap_pyfunction!(energy_ellipsoid_semi_axes, m)?)?;
    m.add_function(wrap_pyfunction!(momentum_ellipsoid_semi_axes, m)?)?;
    m.add_function(wrap_pyfunction!(cone_coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(euler_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(euler_omega_dot_free, m)?)?;
    let py = m.py();
    let offsets = PyDict::new(py);
    {
        use torque_free::row::*;
        for (name, value) in [
            ("case", CASE),
            ("energy", ENERGY),
            ("momentum", MOMENTUM),
            ("alpha", ALPHA),
            ("lam", LAM),
            ("m", M),
            ("m1", M1),
            ("signs", SIGNS),
            ("u0", U0),
            ("pole", POLE),
            ("quarter", QUARTER),
            ("nu", NU),
            ("axis", AXIS),
            ("i_perp", I_PERP),
            ("size", SIZE),
        ] {
            offsets.set_item(name, value)?;
        }
    }
    m.add("REGIME_OFFSETS", offsets)?;
    m.add("TORQUE_FREE_CASE_NAMES", torque_free::CASE_NAMES.to_vec())?;
    m.add("NEAR_UNSTABLE_AXIS", torque_free::NEAR_UNSTABLE_AXIS)?;
    m.add("ELLIPTIC_NEAR_ONE", elliptic::NEAR_ONE)?;
    m.add("ELLIPTIC_TINY_M1", elliptic::TINY_M1)?;
    Ok(())
}
