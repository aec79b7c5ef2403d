//! The `treelet` Python module: Treelet's engine API ([`treelet::Tracer`])
//! for NumPy arrays. A `Tracer` builds a BVH over a triangle mesh on a
//! Vulkan GPU or on the CPU runner (the same kernels), and answers closest
//! hits and occlusion queries for arrays of rays; an `InstancedTracer` the
//! same for meshes placed many times by transforms. Files: `tracer.rs`,
//! `instanced.rs` (the two classes), `render.rs` (`treelet.render`: an
//! HDR image of a scene), `device.rs` (a tree on its device, the
//! queries both answer), `arrays.rs` (arrays in), `hits.rs` (hits out). Wrong shapes and dtypes
//! are `TypeError`s or `ValueError`s that name the argument; what the
//! library refuses (NaN coordinates, an index past the vertices) is a
//! `ValueError` with its message. A direction of length 0 hits nothing.
//!
//! What is copied: vertices and indices once into the triangles the build
//! takes (any layout, C order or not, is read through NumPy's view);
//! rays are read from the arrays in place (C-ordered float32 already, else
//! after one conversion) straight into the device's upload memory, and
//! hits from its read-back memory straight into the returned arrays. The
//! GIL is released while a GPU traces: the arrays must not change meanwhile.
mod arrays;
mod device;
mod hits;
mod instanced;
mod render;
mod tracer;

use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use treelet::error::{Error, ErrorKind};

/// A library error as the Python exception of its kind.
fn py_err(e: Error) -> PyErr {
    let message = format!("{e:#}");
    match e.kind() {
        ErrorKind::Input => PyValueError::new_err(message),
        ErrorKind::TooLarge => PyMemoryError::new_err(message),
        _ => PyRuntimeError::new_err(message),
    }
}

#[pymodule(name = "treelet")]
fn treelet_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<tracer::Tracer>()?;
    m.add_class::<instanced::InstancedTracer>()?;
    m.add_class::<hits::Hits>()?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
