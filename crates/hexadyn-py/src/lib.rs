//! Thin PyO3 bindings of the hexadyn engine: numpy arrays in and out.

use pyo3::prelude::*;

mod mbs;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<mbs::PyMultibody>()?;
    Ok(())
}
