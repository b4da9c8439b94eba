//! Arguments checked at the boundary, once for every binding: the error names the argument
//! and the rule broken.

use crate::arrays::Floats2;
use numpy::ndarray::ArrayView2;
use poinsot_core::forces::{Force, ForceKind};
use poinsot_core::layout::{Body, FORCE_PARAMS};
use poinsot_core::so3::{Mat3, Vec3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

pub(crate) fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// The body parameter vector, checked.
pub(crate) fn body_from(body: &[f64]) -> PyResult<Body> {
    Body::from_slice(body).ok_or_else(|| {
        value_error(format!(
            "`body` must hold {} parameters, found {}",
            poinsot_core::layout::BODY_SIZE,
            body.len()
        ))
    })
}

/// The lowered forces, checked: kinds (k,) and parameters (k, FORCE_PARAMS).
pub(crate) fn forces_from(kind: &[i64], params: &Floats2<'_>) -> PyResult<Vec<Force>> {
    let p = params.as_array();
    if p.nrows() != kind.len() || (p.ncols() != FORCE_PARAMS && !kind.is_empty()) {
        return Err(value_error(format!(
            "`force_params` must have shape ({}, {FORCE_PARAMS}), found {:?}",
            kind.len(),
            p.shape()
        )));
    }
    kind.iter()
        .enumerate()
        .map(|(i, &code)| {
            let kind = ForceKind::from_code(code).ok_or_else(|| {
                value_error(format!("`force_kind[{i}]` = {code} is no force kind"))
            })?;
            let mut row = [0.0; FORCE_PARAMS];
            for (j, r) in row.iter_mut().enumerate() {
                *r = p[[i, j]];
            }
            Ok(Force { kind, p: row })
        })
        .collect()
}

pub(crate) fn mat3_from(a: &Floats2<'_>, name: &str) -> PyResult<Mat3> {
    let v = a.as_array();
    if v.shape() != [3, 3] {
        return Err(value_error(format!(
            "`{name}` must have shape (3, 3), found {:?}",
            v.shape()
        )));
    }
    Ok([0, 1, 2].map(|i| [0, 1, 2].map(|j| v[[i, j]])))
}

/// The rows of an (n, k) array, checked.
pub(crate) fn rows<'a>(a: &'a Floats2<'_>, k: usize, name: &str) -> PyResult<ArrayView2<'a, f64>> {
    let v = a.as_array();
    if v.ncols() != k {
        return Err(value_error(format!(
            "`{name}` must have {k} columns, found shape {:?}",
            v.shape()
        )));
    }
    Ok(v)
}

/// Row `i` of an (n, 3) array.
#[inline]
pub(crate) fn v3(a: &ArrayView2<f64>, i: usize) -> Vec3 {
    [a[[i, 0]], a[[i, 1]], a[[i, 2]]]
}
