//! Bindings of the geometry of `poinsot-core`: SO(3) and quaternions (`so3`), mass properties
//! (`inertia`) and uniform solids (`shapes`).
//!
//! Batched functions take `(..., 3)`, `(..., 4)` or `(..., 3, 3)` array-likes (any real dtype,
//! any layout; read as C-ordered float64 by `crate::arrays`) and loop over the items in Rust,
//! with the GIL released. A wrong trailing shape is a `ValueError` naming the argument. The
//! core never panics on checked input; should it, the panic is caught here and raised as
//! `RuntimeError`, never as pyo3's `PanicException`.

use std::borrow::Cow;
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::arrays::{FloatsDyn, IntsDyn};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use poinsot_core::so3::{Mat3, Quat, Vec3};
use poinsot_core::{inertia, shapes, so3};

type ArrayLike<'py> = FloatsDyn<'py>;
type Out<'py> = Bound<'py, PyArrayDyn<f64>>;

/// Run `f` without the GIL; a panic becomes a `RuntimeError`.
fn guarded<T: Send, F: FnOnce() -> T + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|e| {
            let what = e
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            PyRuntimeError::new_err(format!("internal error in poinsot._core: {what}"))
        })
}

/// A batch of items: the leading shape and the contiguous data (borrowed when possible).
struct Items<'a> {
    lead: Vec<usize>,
    data: Cow<'a, [f64]>,
    width: usize,
}

impl Items<'_> {
    fn len(&self) -> usize {
        self.data.len().checked_div(self.width).unwrap_or(0)
    }
    fn item(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }
}

/// A shape as Python prints it: `(4,)`, `(2, 3)`.
fn py_shape(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

fn shape_text(tail: &[usize]) -> String {
    let parts: Vec<String> = tail.iter().map(|n| n.to_string()).collect();
    format!("(..., {})", parts.join(", "))
}

/// The items of `a` whose trailing axes are `tail`.
fn items<'a>(a: &'a ArrayLike<'_>, name: &str, tail: &[usize]) -> PyResult<Items<'a>> {
    let shape = a.shape();
    if shape.len() < tail.len() || &shape[shape.len() - tail.len()..] != tail {
        return Err(PyValueError::new_err(format!(
            "`{name}` must have shape {}, found {}",
            shape_text(tail),
            py_shape(shape)
        )));
    }
    let data = Cow::Borrowed(a.as_slice()?); // C order: converted on extraction
    Ok(Items {
        lead: shape[..shape.len() - tail.len()].to_vec(),
        data,
        width: tail.iter().product(),
    })
}

/// One item of exactly `shape`.
fn single<'a>(a: &'a ArrayLike<'_>, name: &str, shape: &[usize]) -> PyResult<Cow<'a, [f64]>> {
    if a.shape() != shape {
        return Err(PyValueError::new_err(format!(
            "`{name}` must have shape {}, found {}",
            py_shape(shape),
            py_shape(a.shape())
        )));
    }
    Ok(Cow::Borrowed(a.as_slice()?)) // C order: converted on extraction
}

fn array<'py>(py: Python<'py>, shape: Vec<usize>, data: Vec<f64>) -> PyResult<Out<'py>> {
    ArrayD::from_shape_vec(IxDyn(&shape), data)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| PyRuntimeError::new_err(format!("internal error in poinsot._core: {e}")))
}

fn with_tail(lead: &[usize], tail: &[usize]) -> Vec<usize> {
    lead.iter().chain(tail).copied().collect()
}

fn v3(s: &[f64]) -> Vec3 {
    [s[0], s[1], s[2]]
}

fn q4(s: &[f64]) -> Quat {
    [s[0], s[1], s[2], s[3]]
}

fn m3(s: &[f64]) -> Mat3 {
    [[s[0], s[1], s[2]], [s[3], s[4], s[5]], [s[6], s[7], s[8]]]
}

fn flat(m: &Mat3) -> [f64; 9] {
    [
        m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2],
    ]
}

/// Apply `f` to every item (trailing shape `tin`), giving items of trailing shape `tout`.
fn map<'py, const N: usize>(
    py: Python<'py>,
    a: &ArrayLike<'py>,
    name: &str,
    tin: &[usize],
    tout: &[usize],
    f: impl Fn(&[f64]) -> [f64; N] + Send + Sync,
) -> PyResult<Out<'py>> {
    let it = items(a, name, tin)?;
    let data = guarded(py, || {
        let mut out = Vec::with_capacity(it.len() * N);
        for i in 0..it.len() {
            out.extend_from_slice(&f(it.item(i)));
        }
        out
    })?;
    array(py, with_tail(&it.lead, tout), data)
}

/// Apply `f` to pairs of items: equal numbers of items, or one of them a single item (as NumPy
/// broadcasts one). The result has the leading shape of the argument with all the items: the
/// first when both have (the second with `prefer_second`).
#[allow(clippy::too_many_arguments)]
fn map2<'py, const N: usize>(
    py: Python<'py>,
    a: &ArrayLike<'py>,
    b: &ArrayLike<'py>,
    names: (&str, &str),
    tails: (&[usize], &[usize]),
    tout: &[usize],
    prefer_second: bool,
    f: impl Fn(&[f64], &[f64]) -> [f64; N] + Send + Sync,
) -> PyResult<Out<'py>> {
    let x = items(a, names.0, tails.0)?;
    let y = items(b, names.1, tails.1)?;
    let (na, nb) = (x.len(), y.len());
    let n = na.max(nb);
    if !((na == n || na == 1) && (nb == n || nb == 1)) {
        return Err(PyValueError::new_err(format!(
            "`{}` and `{}` must have the same number of items, or one of them a single item; \
             found leading shapes {} and {}",
            names.0,
            names.1,
            py_shape(&x.lead),
            py_shape(&y.lead)
        )));
    }
    let data = guarded(py, || {
        let mut out = Vec::with_capacity(n * N);
        for i in 0..n {
            let p = x.item(if na == 1 { 0 } else { i });
            let q = y.item(if nb == 1 { 0 } else { i });
            out.extend_from_slice(&f(p, q));
        }
        out
    })?;
    let second = if prefer_second { nb == n } else { na != n };
    let lead = if second { &y.lead } else { &x.lead };
    array(py, with_tail(lead, tout), data)
}

// ------------------------------------------------------------------------------------ SO(3)

/// Skew matrices `hat(w)` (`hat(w) v = w × v`): (..., 3) → (..., 3, 3).
#[pyfunction]
fn hat<'py>(py: Python<'py>, w: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &w, "w", &[3], &[3, 3], |s| flat(&so3::hat(v3(s))))
}

/// `vee(B)`, the vector of the skew part of `B`: (..., 3, 3) → (..., 3).
#[pyfunction]
fn vee<'py>(py: Python<'py>, b: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &b, "B", &[3, 3], &[3], |s| so3::vee(&m3(s)))
}

/// Rotation matrices `exp(hat(w))` (Rodrigues): (..., 3) → (..., 3, 3).
#[pyfunction]
fn exp_so3<'py>(py: Python<'py>, w: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &w, "w", &[3], &[3, 3], |s| flat(&so3::exp_so3(v3(s))))
}

/// Rotation vectors (angle in [0, π]) of rotation matrices: (..., 3, 3) → (..., 3).
#[pyfunction]
fn log_so3<'py>(py: Python<'py>, r: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &r, "R", &[3, 3], &[3], |s| so3::log_so3(&m3(s)))
}

/// `dexp⁻¹_u(v)`: `u`, `v` (..., 3), equal shapes or one of them a single (3,).
#[pyfunction]
fn dexpinv<'py>(py: Python<'py>, u: ArrayLike<'py>, v: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map2(py, &u, &v, ("u", "v"), (&[3], &[3]), &[3], false, |a, b| {
        so3::dexpinv3(v3(a), v3(b))
    })
}

/// The rotation matrix (3, 3) by `angle` about the coordinate axis `axis` ∈ {0, 1, 2}.
#[pyfunction]
fn axis_rotation<'py>(py: Python<'py>, axis: i64, angle: f64) -> PyResult<Out<'py>> {
    if !(0..3).contains(&axis) {
        return Err(PyValueError::new_err(format!(
            "`axis` must be 0, 1 or 2, found {axis}"
        )));
    }
    let r = so3::axis_rotation(axis as usize, angle);
    array(py, vec![3, 3], flat(&r).to_vec())
}

/// Hamilton products `p ⊗ q` (..., 4): equal shapes, or one of them a single (4,).
#[pyfunction]
fn quat_multiply<'py>(py: Python<'py>, p: ArrayLike<'py>, q: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map2(py, &p, &q, ("p", "q"), (&[4], &[4]), &[4], false, |a, b| {
        so3::quat_multiply(q4(a), q4(b))
    })
}

/// Conjugates `(w, −x, −y, −z)` (..., 4).
#[pyfunction]
fn quat_conjugate<'py>(py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &q, "q", &[4], &[4], |s| so3::quat_conjugate(q4(s)))
}

/// Unit quaternions `q/|q|` (..., 4); `ValueError` on a zero quaternion.
#[pyfunction]
fn quat_normalize<'py>(py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Out<'py>> {
    let it = items(&q, "q", &[4])?;
    let data = guarded(py, || {
        let mut out = Vec::with_capacity(it.len() * 4);
        for i in 0..it.len() {
            out.extend_from_slice(&so3::quat_normalize(q4(it.item(i))).ok_or(i)?);
        }
        Ok::<_, usize>(out)
    })?
    .map_err(|i| {
        PyValueError::new_err(format!("`q` must be non-zero to be normalised (item {i})"))
    })?;
    array(py, with_tail(&it.lead, &[4]), data)
}

/// Rotation matrices of unit quaternions (w, x, y, z): (..., 4) → (..., 3, 3).
#[pyfunction]
fn quat_to_matrix<'py>(py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &q, "q", &[4], &[3, 3], |s| {
        flat(&so3::quat_to_matrix(q4(s)))
    })
}

/// Rotate vectors `v` (..., 3) by unit quaternions `q` (..., 4): `q v q*`.
#[pyfunction]
fn quat_rotate<'py>(py: Python<'py>, q: ArrayLike<'py>, v: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map2(py, &q, &v, ("q", "v"), (&[4], &[3]), &[3], true, |a, b| {
        so3::quat_rotate(q4(a), v3(b))
    })
}

/// Unit quaternions (w ≥ 0) of rotation matrices (Shepperd): (..., 3, 3) → (..., 4).
#[pyfunction]
fn matrix_to_quat<'py>(py: Python<'py>, r: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &r, "R", &[3, 3], &[4], |s| so3::matrix_to_quat(&m3(s)))
}

/// Unit quaternions of rotation vectors: (..., 3) → (..., 4).
#[pyfunction]
fn rotvec_to_quat<'py>(py: Python<'py>, w: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &w, "w", &[3], &[4], |s| so3::rotvec_to_quat(v3(s)))
}

/// Rotation vectors (angle in [0, π]) of unit quaternions: (..., 4) → (..., 3).
#[pyfunction]
fn quat_to_rotvec<'py>(py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &q, "q", &[4], &[3], |s| so3::quat_to_rotvec(q4(s)))
}

/// `Rz(ψ) Rx(θ) Rz(φ)` of z-x-z Euler angles `(ψ, θ, φ)`: (..., 3) → (..., 3, 3).
#[pyfunction]
fn zxz_matrix<'py>(py: Python<'py>, angles: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &angles, "angles", &[3], &[3, 3], |s| {
        flat(&so3::zxz_matrix(s[0], s[1], s[2]))
    })
}

fn same_items(a: &ArrayLike<'_>, b: &ArrayLike<'_>, names: (&str, &str)) -> PyResult<()> {
    if a.shape() != b.shape() {
        return Err(PyValueError::new_err(format!(
            "`{}` and `{}` must have the same shape, found {}, {}",
            names.0,
            names.1,
            py_shape(a.shape()),
            py_shape(b.shape())
        )));
    }
    Ok(())
}

/// Body rates `(p, q, r)` from z-x-z angles and their rates (paper eq. (13)); (..., 3) each.
#[pyfunction]
fn zxz_body_rates<'py>(
    py: Python<'py>,
    angles: ArrayLike<'py>,
    rates: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    same_items(&angles, &rates, ("angles", "rates"))?;
    map2(
        py,
        &angles,
        &rates,
        ("angles", "rates"),
        (&[3], &[3]),
        &[3],
        false,
        |a, d| so3::zxz_body_rates(v3(a), v3(d)),
    )
}

/// z-x-z angle rates from body rates (the inverse of `zxz_body_rates`); (..., 3) each.
#[pyfunction]
fn zxz_angle_rates<'py>(
    py: Python<'py>,
    angles: ArrayLike<'py>,
    omega: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    same_items(&angles, &omega, ("angles", "omega"))?;
    map2(
        py,
        &angles,
        &omega,
        ("angles", "omega"),
        (&[3], &[3]),
        &[3],
        false,
        |a, w| so3::zxz_angle_rates(v3(a), v3(w)),
    )
}

// ---------------------------------------------------------------------------------- inertia

/// The masses (N,) and their 3-vectors (N, 3), of equal length.
fn particles<'a>(
    masses: &'a ArrayLike<'_>,
    vectors: &'a ArrayLike<'_>,
    names: (&str, &str),
) -> PyResult<(Cow<'a, [f64]>, Vec<Vec3>)> {
    let m = items(masses, names.0, &[])?;
    if m.lead.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "`{}` must have shape (N,), found {}",
            names.0,
            py_shape(masses.shape())
        )));
    }
    let r = items(vectors, names.1, &[3])?;
    if r.lead.len() != 1 || r.len() != m.data.len() {
        return Err(PyValueError::new_err(format!(
            "`{}` must have shape (N, 3) with N = {} (the length of `{}`), found {}",
            names.1,
            m.data.len(),
            names.0,
            py_shape(vectors.shape())
        )));
    }
    let vs = (0..r.len()).map(|i| v3(r.item(i))).collect();
    Ok((m.data, vs))
}

/// `Σ m_i r_i / Σ m_i`: masses (N,), positions (N, 3) → (3,).
#[pyfunction]
fn center_of_mass<'py>(
    py: Python<'py>,
    masses: ArrayLike<'py>,
    positions: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    let (m, r) = particles(&masses, &positions, ("masses", "positions"))?;
    let c = guarded(py, || inertia::center_of_mass(&m, &r))?;
    array(py, vec![3], c.to_vec())
}

/// `A_jk = Σ m_i (|u_i|² δ_jk − u_ij u_ik)` (eqs (04), (13)–(15)): masses (N,), offsets (N, 3)
/// → (3, 3).
#[pyfunction]
fn particle_inertia<'py>(
    py: Python<'py>,
    masses: ArrayLike<'py>,
    offsets: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    let (m, u) = particles(&masses, &offsets, ("masses", "offsets"))?;
    let a = guarded(py, || inertia::particle_inertia(&m, &u))?;
    array(py, vec![3, 3], flat(&a).to_vec())
}

/// `A_P = A_G + M (|d|² 𝟙 − d dᵀ)` (Huygens–Steiner): (3, 3), float, (3,) → (3, 3).
#[pyfunction]
fn parallel_axis<'py>(
    py: Python<'py>,
    inertia_com: ArrayLike<'py>,
    mass: f64,
    d: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    let j = m3(&single(&inertia_com, "inertia_com", &[3, 3])?);
    let d = v3(&single(&d, "d", &[3])?);
    array(
        py,
        vec![3, 3],
        flat(&inertia::parallel_axis(&j, mass, d)).to_vec(),
    )
}

/// The planar inertia `J' = ½ tr(J) 𝟙 − J` (paper eqs (3)–(4)): (..., 3, 3) → (..., 3, 3).
#[pyfunction]
fn planar_inertia<'py>(py: Python<'py>, inertia: ArrayLike<'py>) -> PyResult<Out<'py>> {
    map(py, &inertia, "inertia", &[3, 3], &[3, 3], |s| {
        flat(&inertia::planar_inertia(&m3(s)))
    })
}

/// `R J Rᵀ`: inertia (3, 3), rotations `R` (..., 3, 3) → (..., 3, 3).
#[pyfunction]
fn rotate_inertia<'py>(
    py: Python<'py>,
    inertia: ArrayLike<'py>,
    r: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    let j = m3(&single(&inertia, "inertia", &[3, 3])?);
    map(py, &r, "R", &[3, 3], &[3, 3], move |s| {
        flat(&inertia::rotate_inertia(&j, &m3(s)))
    })
}

/// Principal moments (ascending) and right-handed axes (columns) of symmetric inertia
/// matrices: (..., 3, 3) → ((..., 3), (..., 3, 3)).
#[pyfunction]
fn principal_decomposition<'py>(
    py: Python<'py>,
    inertia: ArrayLike<'py>,
) -> PyResult<Bound<'py, PyTuple>> {
    let it = items(&inertia, "inertia", &[3, 3])?;
    let (moments, axes) = guarded(py, || {
        let mut moments = Vec::with_capacity(it.len() * 3);
        let mut axes = Vec::with_capacity(it.len() * 9);
        for i in 0..it.len() {
            let (m, e) = inertia::principal_decomposition(&m3(it.item(i)));
            moments.extend_from_slice(&m);
            axes.extend_from_slice(&flat(&e));
        }
        (moments, axes)
    })?;
    let moments = array(py, with_tail(&it.lead, &[3]), moments)?;
    let axes = array(py, with_tail(&it.lead, &[3, 3]), axes)?;
    PyTuple::new(py, [moments, axes])
}

/// The one check of inertia tensors (..., 3, 3) (`poinsot_core::inertia::check_inertia`,
/// relative tolerance `rtol`): `(codes (...), moments (..., 3), asymmetry (...), degenerate
/// (...))`, the code 0 for a rigid body's inertia, 1 not finite, 2 not symmetric (by the
/// asymmetry), 3 not positive semi-definite, 4 the triangle inequality broken (by the
/// moments, ascending); `degenerate` 1 where the moments are those of mass on a line
/// (`is_degenerate`).
#[pyfunction]
fn check_inertia<'py>(
    py: Python<'py>,
    inertia: ArrayLike<'py>,
    rtol: f64,
) -> PyResult<(Out<'py>, Out<'py>, Out<'py>, Out<'py>)> {
    use poinsot_core::inertia::InertiaCheck;
    let it = items(&inertia, "inertia", &[3, 3])?;
    let (codes, moments, asym, degenerate) = guarded(py, || {
        let n = it.len();
        let mut codes = vec![0.0; n];
        let mut moments = vec![f64::NAN; 3 * n];
        let mut asym = vec![0.0; n];
        let mut degenerate = vec![0.0; n];
        for i in 0..n {
            let check = inertia::check_inertia(&m3(it.item(i)), rtol);
            codes[i] = check.code() as f64;
            match check {
                InertiaCheck::Valid(m)
                | InertiaCheck::NotPositive(m)
                | InertiaCheck::Triangle(m) => {
                    moments[3 * i..3 * i + 3].copy_from_slice(&m);
                    degenerate[i] = f64::from(u8::from(inertia::is_degenerate(m, rtol)));
                }
                InertiaCheck::NotSymmetric(a) => asym[i] = a,
                InertiaCheck::NotFinite => {}
            }
        }
        (codes, moments, asym, degenerate)
    })?;
    Ok((
        array(py, it.lead.clone(), codes)?,
        array(py, with_tail(&it.lead, &[3]), moments)?,
        array(py, it.lead.clone(), asym)?,
        array(py, it.lead.clone(), degenerate)?,
    ))
}

/// Symmetry class code of ascending moments (3,): 0 asymmetric, 1 prolate, 2 oblate,
/// 3 spherical (an index into `SYMMETRY_CLASSES`).
#[pyfunction]
fn symmetry_code(moments: ArrayLike<'_>, rtol: f64) -> PyResult<u8> {
    let m = v3(&single(&moments, "moments", &[3])?);
    Ok(inertia::symmetry_code(m, rtol))
}

/// True when the smallest of the ascending moments (3,) vanishes (relative `rtol`).
#[pyfunction]
fn is_degenerate(moments: ArrayLike<'_>, rtol: f64) -> PyResult<bool> {
    let m = v3(&single(&moments, "moments", &[3])?);
    Ok(inertia::is_degenerate(m, rtol))
}

/// Volume, centroid (3,) and unit-density inertia (3, 3) about the centroid of a closed
/// triangulated polyhedron: vertices (V, 3), faces (F, 3) integer indices.
#[pyfunction]
fn polyhedron_mass_properties<'py>(
    py: Python<'py>,
    vertices: ArrayLike<'py>,
    faces: IntsDyn<'py>,
) -> PyResult<(f64, Out<'py>, Out<'py>)> {
    let v = items(&vertices, "vertices", &[3])?;
    if v.lead.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "`vertices` must have shape (V, 3), found {}",
            py_shape(vertices.shape())
        )));
    }
    let fshape = faces.shape();
    if fshape.len() != 2 || fshape[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "`faces` must have shape (F, 3), found {}",
            py_shape(fshape)
        )));
    }
    let nv = v.len();
    let mut tris = Vec::with_capacity(fshape[0]);
    for (i, row) in faces.as_array().rows().into_iter().enumerate() {
        let mut t = [0usize; 3];
        for (k, &x) in row.iter().enumerate() {
            if x < 0 || x as u64 >= nv as u64 {
                return Err(PyValueError::new_err(format!(
                    "`faces[{i}, {k}]` = {x} indexes no vertex (0..{nv})"
                )));
            }
            t[k] = x as usize;
        }
        tris.push(t);
    }
    let verts: Vec<Vec3> = (0..nv).map(|i| v3(v.item(i))).collect();
    let (volume, centroid, j) = guarded(py, || inertia::polyhedron_mass_properties(&verts, &tris))?
        .ok_or_else(|| PyRuntimeError::new_err("internal error in poinsot._core: face index"))?;
    Ok((
        volume,
        array(py, vec![3], centroid.to_vec())?,
        array(py, vec![3, 3], flat(&j).to_vec())?,
    ))
}

// ----------------------------------------------------------------------------------- shapes

fn mat<'py>(py: Python<'py>, m: Mat3) -> PyResult<Out<'py>> {
    array(py, vec![3, 3], flat(&m).to_vec())
}

/// Box with edges `size = (a, b, c)`: `m/12 · diag(b²+c², a²+c², a²+b²)`.
#[pyfunction]
fn box_inertia<'py>(py: Python<'py>, m: f64, size: ArrayLike<'py>) -> PyResult<Out<'py>> {
    let s = v3(&single(&size, "size", &[3])?);
    mat(py, shapes::box_inertia(m, s))
}

/// Solid sphere: `2/5 m r² 𝟙`.
#[pyfunction]
fn sphere_inertia(py: Python<'_>, m: f64, r: f64) -> PyResult<Out<'_>> {
    mat(py, shapes::sphere_inertia(m, r))
}

/// Thin spherical shell: `2/3 m r² 𝟙`.
#[pyfunction]
fn spherical_shell_inertia(py: Python<'_>, m: f64, r: f64) -> PyResult<Out<'_>> {
    mat(py, shapes::spherical_shell_inertia(m, r))
}

/// Solid cylinder, axis z: `Ixx = Iyy = m(3r² + h²)/12`, `Izz = m r²/2`.
#[pyfunction]
fn cylinder_inertia(py: Python<'_>, m: f64, r: f64, h: f64) -> PyResult<Out<'_>> {
    mat(py, shapes::cylinder_inertia(m, r, h))
}

/// Solid ellipsoid of semi-axes `(a, b, c)`: `m/5 · diag(b²+c², a²+c², a²+b²)`.
#[pyfunction]
fn ellipsoid_inertia<'py>(
    py: Python<'py>,
    m: f64,
    semi_axes: ArrayLike<'py>,
) -> PyResult<Out<'py>> {
    let s = v3(&single(&semi_axes, "semi_axes", &[3])?);
    mat(py, shapes::ellipsoid_inertia(m, s))
}

/// Thin rod along z: `Ixx = Iyy = m l²/12`, `Izz = 0`.
#[pyfunction]
fn rod_inertia(py: Python<'_>, m: f64, length: f64) -> PyResult<Out<'_>> {
    mat(py, shapes::rod_inertia(m, length))
}

/// Solid cone, axis z, about its centre of mass: `Izz = 3/10 m r²`,
/// `Ixx = Iyy = 3/20 m r² + 3/80 m h²`.
#[pyfunction]
fn cone_inertia(py: Python<'_>, m: f64, r: f64, h: f64) -> PyResult<Out<'_>> {
    mat(py, shapes::cone_inertia(m, r, h))
}

/// Half extents of the uniform box with principal moments `moments` (3,) and mass `mass`.
#[pyfunction]
fn equivalent_box_half_extents<'py>(
    py: Python<'py>,
    moments: ArrayLike<'py>,
    mass: f64,
) -> PyResult<Out<'py>> {
    let m = v3(&single(&moments, "moments", &[3])?);
    array(
        py,
        vec![3],
        shapes::equivalent_box_half_extents(m, mass).to_vec(),
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(hat, m)?)?;
    m.add_function(wrap_pyfunction!(vee, m)?)?;
    m.add_function(wrap_pyfunction!(exp_so3, m)?)?;
    m.add_function(wrap_pyfunction!(log_so3, m)?)?;
    m.add_function(wrap_pyfunction!(dexpinv, m)?)?;
    m.add_function(wrap_pyfunction!(axis_rotation, m)?)?;
    m.add_function(wrap_pyfunction!(quat_multiply, m)?)?;
    m.add_function(wrap_pyfunction!(quat_conjugate, m)?)?;
    m.add_function(wrap_pyfunction!(quat_normalize, m)?)?;
    m.add_function(wrap_pyfunction!(quat_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(quat_rotate, m)?)?;
    m.add_function(wrap_pyfunction!(matrix_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(rotvec_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(quat_to_rotvec, m)?)?;
    m.add_function(wrap_pyfunction!(zxz_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(zxz_body_rates, m)?)?;
    m.add_function(wrap_pyfunction!(zxz_angle_rates, m)?)?;
    m.add_function(wrap_pyfunction!(center_of_mass, m)?)?;
    m.add_function(wrap_pyfunction!(particle_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(parallel_axis, m)?)?;
    m.add_function(wrap_pyfunction!(planar_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(rotate_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(principal_decomposition, m)?)?;
    m.add_function(wrap_pyfunction!(symmetry_code, m)?)?;
    m.add_function(wrap_pyfunction!(check_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(is_degenerate, m)?)?;
    m.add_function(wrap_pyfunction!(polyhedron_mass_properties, m)?)?;
    m.add_function(wrap_pyfunction!(box_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(sphere_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(spherical_shell_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(cylinder_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(ellipsoid_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(rod_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(cone_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(equivalent_box_half_extents, m)?)?;
    m.add("SYMMETRY_RTOL", inertia::SYMMETRY_RTOL)?;
    m.add("DEGENERATE_RTOL", inertia::DEGENERATE_RTOL)?;
    m.add(
        "SYMMETRY_CLASSES",
        PyTuple::new(m.py(), inertia::SYMMETRY_CLASSES)?,
    )?;
    Ok(())
}
