//! `poinsot._core`: thin bindings of `poinsot-core`. Arguments are checked here (names in the
//! errors), the GIL is released around every computation, and nothing here holds physics.

use pyo3::prelude::*;

mod exact;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", poinsot_core::version::VERSION)?;
    exact::register(m)?;
    Ok(())
}
