//! Array arguments in every layout, for every binding: the one place where user input
//! becomes the contiguous memory the core reads.
//!
//! A parameter typed [`Floats1`] (or [`Floats2`], [`Floats3`], [`FloatsDyn`]; [`Ints1`],
//! [`Ints2`], [`IntsDyn`] for int64; [`Bools1`] for bool) takes what
//! `numpy.asarray(x, dtype=float64)` (int64, bool) takes: an array of any real dtype (float32,
//! int, bool, big-endian `'>f8'`) in any layout (slices with steps, negative strides,
//! transposes, Fortran order, misaligned buffers), a NumPy scalar, or a (nested) list of
//! numbers. It derefs to a [`PyReadonlyArray`] that is C-contiguous and aligned, so
//! `.as_slice()` always succeeds and holds the elements in C (row-major) order, and
//! `.as_array()` is a plain view.
//!
//! An array that is already C-contiguous, aligned and of the native dtype is borrowed as it
//! is (no copy); anything else is converted in one copy, by `PyArray_FromAny` with
//! `NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED | NPY_ARRAY_FORCECAST`: NumPy's own
//! `ascontiguousarray(x, dtype=...)`, with `asarray`'s casting.
//!
//! Refused, with a `TypeError` that says what was expected and what was found (pyo3 adds the
//! note `while processing '<argument>'`, naming the argument): text (NumPy would read `"1"`
//! as 1.0), complex numbers (NumPy would drop the imaginary part with only a warning),
//! `None`, a wrong number of dimensions, and whatever NumPy cannot convert (a ragged list, a
//! dict), NumPy's own message then following.
//!
//! Buffers the core writes into (`PyReadwriteArray`, `out=`) are not taken through this:
//! they are the project's own arrays, whose layout the bindings check.

use std::ops::Deref;

use numpy::ndarray::{Dimension, Ix1, Ix2, Ix3, IxDyn};
use numpy::npyffi::{
    _PyArray_GET_ITEM_DATA, NPY_ARRAY_ALIGNED, NPY_ARRAY_C_CONTIGUOUS, NPY_ARRAY_FORCECAST,
};
use numpy::{
    Element, PyArray, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray, PyUntypedArray,
    PyUntypedArrayMethods, PY_ARRAY_API,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyString};
use pyo3::Borrowed;

/// A read-only array argument of element `T` and dimension `D`, C-contiguous and aligned
/// (see the module's documentation).
#[derive(Debug)]
#[repr(transparent)]
pub(crate) struct Arr<'py, T: Element, D: Dimension>(PyReadonlyArray<'py, T, D>);

/// float64, one dimension.
pub(crate) type Floats1<'py> = Arr<'py, f64, Ix1>;
/// float64, two dimensions.
pub(crate) type Floats2<'py> = Arr<'py, f64, Ix2>;
/// float64, three dimensions.
pub(crate) type Floats3<'py> = Arr<'py, f64, Ix3>;
/// float64, any number of dimensions (0-d included).
pub(crate) type FloatsDyn<'py> = Arr<'py, f64, IxDyn>;
/// int64, one dimension.
pub(crate) type Ints1<'py> = Arr<'py, i64, Ix1>;
/// int64, two dimensions.
pub(crate) type Ints2<'py> = Arr<'py, i64, Ix2>;
/// int64, any number of dimensions.
pub(crate) type IntsDyn<'py> = Arr<'py, i64, IxDyn>;
/// bool, one dimension.
pub(crate) type Bools1<'py> = Arr<'py, bool, Ix1>;

impl<'py, T: Element, D: Dimension> Deref for Arr<'py, T, D> {
    type Target = PyReadonlyArray<'py, T, D>;

    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl<'a, 'py, T: Element + 'py, D: Dimension + 'py> FromPyObject<'a, 'py> for Arr<'py, T, D> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        // the common case: already what the core reads, borrowed as it is
        if let Ok(a) = ob.cast::<PyArray<T, D>>() {
            if a.is_c_contiguous() && aligned(a.as_untyped()) {
                return Ok(Self(a.try_readonly()?));
            }
        }
        convert(ob)
    }
}

/// Whether NumPy flags the array's data as aligned for its dtype.
fn aligned(a: &Bound<'_, PyUntypedArray>) -> bool {
    // SAFETY: `as_array_ptr` points to the live array object `a` holds a reference to, and
    // the GIL is held.
    unsafe { (*_PyArray_GET_ITEM_DATA(a.as_array_ptr())).flags & NPY_ARRAY_ALIGNED != 0 }
}

/// What the argument should have been, for the errors.
fn expected<T: Element, D: Dimension>(py: Python<'_>) -> String {
    let dtype = numpy::dtype::<T>(py);
    match D::NDIM {
        Some(n) => format!("a {n}-dimensional array of {dtype} (or numbers NumPy converts)"),
        None => format!("an array of {dtype} (or numbers NumPy converts)"),
    }
}

fn refused<T: Element, D: Dimension>(py: Python<'_>, found: impl std::fmt::Display) -> PyErr {
    PyTypeError::new_err(format!("expected {}, found {found}", expected::<T, D>(py)))
}

/// `PyArray_FromAny(ob, dtype, 0, 0, flags)`: NumPy's conversion of anything to an array
/// (`dtype` None: the dtype NumPy finds).
fn from_any<'py>(
    ob: &Bound<'py, PyAny>,
    dtype: Option<Bound<'py, numpy::PyArrayDescr>>,
    flags: i32,
) -> PyResult<Bound<'py, PyAny>> {
    let py = ob.py();
    let descr = dtype.map_or(std::ptr::null_mut(), |d| d.into_ptr().cast());
    // SAFETY: `ob` is a live object; `PyArray_FromAny` steals the reference to `descr`
    // (null: none) and returns a new reference or null with an exception set.
    unsafe {
        let ptr =
            PY_ARRAY_API.PyArray_FromAny(py, ob.as_ptr(), descr, 0, 0, flags, std::ptr::null_mut());
        Bound::from_owned_ptr_or_err(py, ptr)
    }
}

/// Anything else than a C-contiguous, aligned array of `T`: checked, then converted in one
/// copy.
fn convert<'py, T: Element + 'py, D: Dimension + 'py>(
    ob: Borrowed<'_, 'py, PyAny>,
) -> PyResult<Arr<'py, T, D>> {
    let py = ob.py();
    let ob = ob.to_owned();
    if ob.is_none() || ob.is_instance_of::<PyString>() || ob.is_instance_of::<PyBytes>() {
        return Err(refused::<T, D>(py, type_name(&ob)));
    }
    // the values as NumPy reads them, in their own dtype (an array is taken as it is)
    let (raw, is_array) = match ob.cast::<PyUntypedArray>() {
        Ok(a) => (a.clone(), true),
        Err(_) => {
            let a = from_any(&ob, None, 0).map_err(|e| {
                let err = refused::<T, D>(py, format!("{} ({e})", type_name(&ob)));
                err.set_cause(py, Some(e));
                err
            })?;
            (a.cast_into::<PyUntypedArray>()?, false)
        }
    };
    let dtype = raw.dtype();
    match dtype.kind() {
        b'U' | b'S' => return Err(refused::<T, D>(py, format!("text (dtype {dtype})"))),
        b'c' => {
            let found = format!("complex numbers (dtype {dtype}; pass the real part)");
            return Err(refused::<T, D>(py, found));
        }
        _ => {}
    }
    if D::NDIM.is_some_and(|n| n != raw.ndim()) {
        let found = if is_array {
            format!("an array of shape {}", py_shape(raw.shape()))
        } else if raw.ndim() == 0 {
            type_name(&ob) // a number, a dict, an object
        } else {
            format!("{} of shape {}", type_name(&ob), py_shape(raw.shape()))
        };
        return Err(refused::<T, D>(py, found));
    }
    let flags = NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED | NPY_ARRAY_FORCECAST;
    let array = from_any(raw.as_any(), Some(numpy::dtype::<T>(py)), flags).map_err(|e| {
        let err = refused::<T, D>(py, format!("dtype {dtype} ({e})"));
        err.set_cause(py, Some(e));
        err
    })?;
    let array = array.cast_into::<PyArray<T, D>>()?;
    Ok(Arr(array.try_readonly()?))
}

/// A shape as Python prints it: `()`, `(4,)`, `(2, 3)`.
fn py_shape(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

fn type_name(ob: &Bound<'_, PyAny>) -> String {
    ob.get_type()
        .name()
        .map_or_else(|_| "an object".to_string(), |n| n.to_string())
}
