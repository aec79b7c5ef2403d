//! `treelet.Tracer`: a BVH over one triangle mesh.
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use treelet::tracer::RayQueries;
use treelet::{CpuBackend, GpuBackend, Ray, RayHit};

use crate::arrays::{triangles_of, RayArrays};
use crate::device::{self, on_device, OnDevice};
use crate::hits::Hits;
use crate::py_err;

/// A BVH over a triangle mesh, on a GPU (Vulkan) or the CPU runner, and
/// the ray queries it answers.
///
/// >>> import numpy as np, treelet
/// >>> v = np.array([[0, 0, 5], [1, 0, 5], [0, 1, 5]], dtype=np.float32)
/// >>> t = treelet.Tracer(v, np.array([[0, 1, 2]]), device="cpu")
/// >>> hits = t.closest_hits(np.array([[0.2, 0.2, 0.0]]), np.array([[0.0, 0.0, 1.0]]))
/// >>> float(hits.t[0]), int(hits.primitive[0])
/// (5.0, 0)
#[pyclass(unsendable, module = "treelet")]
pub(crate) struct Tracer {
    inner: OnDevice<treelet::Tracer<GpuBackend>, treelet::Tracer<CpuBackend>>,
    triangles: usize,
}

#[pymethods]
impl Tracer {
    /// Builds the tree over `vertices` ((v, 3) numbers) and `indices`
    /// ((m, 3) integers: one triangle a row) on `device`: "auto" (the first
    /// GPU, else the CPU runner), "gpu" (a Vulkan adapter, or an error) or
    /// "cpu" (the CPU runner). `quality`: "fast" (the LBVH), "balanced"
    /// (H-PLOC) or "high" (the TRBVH: the slowest build, the fastest rays).
    #[new]
    #[pyo3(signature = (vertices, indices, device = "auto", quality = "fast"))]
    fn new(py: Python<'_>, vertices: &Bound<'_, PyAny>, indices: &Bound<'_, PyAny>, device: &str, quality: &str) -> PyResult<Self> {
        let triangles = triangles_of(py, vertices, indices)?;
        let quality = device::quality(quality)?;
        let inner = device::build(device, |b| treelet::Tracer::build(b, &[], &triangles, quality), |b| treelet::Tracer::build(b, &[], &triangles, quality))?;
        Ok(Tracer { inner, triangles: triangles.len() })
    }

    /// The device the tree is on: the adapter's name, or "cpu".
    #[getter]
    fn device(&self) -> String {
        self.inner.name()
    }

    fn __len__(&self) -> usize {
        self.triangles
    }

    /// The closest hit of each ray `origins[k] + t directions[k]` (both
    /// (n, 3); directions of any length, one of length 0 hitting nothing),
    /// from `t_min` to `t_max`
    /// (numbers, or one per ray), `t` along the normalized direction.
    /// `out`, the `Hits` of an earlier batch of as many rays, is filled in
    /// place and returned (no new arrays: for batch after batch).
    #[pyo3(signature = (origins, directions, t_min = None, t_max = None, out = None))]
    fn closest_hits(
        &mut self,
        py: Python<'_>,
        origins: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        t_min: Option<&Bound<'_, PyAny>>,
        t_max: Option<&Bound<'_, PyAny>>,
        out: Option<&Bound<'_, Hits>>,
    ) -> PyResult<Py<Hits>> {
        self.inner.closest_hits(py, &RayArrays::new(py, origins, directions, t_min, t_max)?, out)
    }

    /// Whether each ray hits anything from `t_min` up to `t_max`
    /// (inclusive): a bool array, as `closest_hits(...).t <= t_max`.
    #[pyo3(signature = (origins, directions, t_min = None, t_max = None))]
    fn occluded<'py>(
        &mut self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        t_min: Option<&Bound<'py, PyAny>>,
        t_max: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        self.inner.occluded(py, &RayArrays::new(py, origins, directions, t_min, t_max)?)
    }

    /// The benchmark's baseline (python/examples/bench_rays.py): the median
    /// wall milliseconds of the Rust API on these rays, taken `repeats`
    /// times, the rays already made (what an engine calling the Rust API
    /// pays, without this module's conversions): `closest_hits` into a new
    /// vector of hits, or with `kept`, `closest_hits_batch` into one kept
    /// between calls (an engine's own buffer, written on every core). Each result is dropped after
    /// its time is taken, as `bench_rays.py` drops the module's.
    #[pyo3(signature = (origins, directions, repeats = 7, kept = false))]
    fn _rust_api_ms(&mut self, py: Python<'_>, origins: &Bound<'_, PyAny>, directions: &Bound<'_, PyAny>, repeats: usize, kept: bool) -> PyResult<f64> {
        let arrays = RayArrays::new(py, origins, directions, None, None)?;
        let columns = arrays.columns()?;
        let rays: Vec<Ray> = (0..columns.len()).map(|k| columns.ray(k)).collect();
        let mut own = vec![RayHit::MISS; rays.len()];
        let mut ms = Vec::with_capacity(repeats);
        for _ in 0..repeats.max(1) {
            let start = std::time::Instant::now();
            let hits = if kept {
                on_device!(&mut self.inner, py, |b, t| t.closest_hits_batch(b, rays.len(), |k| rays[k], |hits| {
                    own.par_iter_mut().enumerate().for_each(|(k, h)| *h = hits.get(k))
                }))
                .map_err(py_err)?;
                Vec::new()
            } else {
                on_device!(&mut self.inner, py, |b, t| t.closest_hits(b, &rays)).map_err(py_err)?
            };
            ms.push(start.elapsed().as_secs_f64() * 1e3);
            std::hint::black_box((hits, &own));
        }
        ms.sort_by(f64::total_cmp);
        Ok(ms[ms.len() / 2])
    }

    /// Moves the mesh's vertices (the same count; the indices stay) and
    /// refits the tree's boxes: the tree keeps its shape, so rays slow
    /// down as the mesh moves far from where it was built.
    fn refit(&mut self, py: Python<'_>, vertices: &Bound<'_, PyAny>, indices: &Bound<'_, PyAny>) -> PyResult<()> {
        let triangles = triangles_of(py, vertices, indices)?;
        if triangles.len() != self.triangles {
            return Err(PyValueError::new_err(format!("refit: {} triangles where the tree has {}", triangles.len(), self.triangles)));
        }
        on_device!(&mut self.inner, py, |b, t| t.refit(b, &[], &triangles)).map_err(py_err)
    }
}

