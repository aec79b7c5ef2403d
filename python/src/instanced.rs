//! `treelet.InstancedTracer`: meshes placed many times by transforms (a
//! top-level tree over the instances, one tree per mesh), traced without
//! flattening them.
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use treelet::{CpuBackend, GpuBackend, Instance, Triangle};

use crate::arrays::{as_numpy, shape_of, triangles_of, RayArrays};
use crate::device::{self, on_device, OnDevice};
use crate::hits::Hits;
use crate::py_err;

/// Meshes placed by transforms (instancing), on a GPU (Vulkan) or the CPU
/// runner, and the ray queries they answer: a hit names its instance and
/// the triangle within that instance's mesh. On a GPU, queries release the
/// GIL while the device works.
///
/// >>> import numpy as np, treelet
/// >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
/// >>> moved = np.array([[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, z]] for z in (5, 9)], dtype=np.float32)
/// >>> s = treelet.InstancedTracer([(v, np.array([[0, 1, 2]]))], np.array([0, 0]), moved, device="cpu")
/// >>> hits = s.closest_hits(np.array([[0.2, 0.2, 0.0]]), np.array([[0.0, 0.0, 1.0]]))
/// >>> float(hits.t[0]), int(hits.instance[0]), int(hits.primitive[0])
/// (5.0, 0, 0)
#[pyclass(unsendable, module = "treelet")]
pub(crate) struct InstancedTracer {
    inner: OnDevice<treelet::InstancedTracer<GpuBackend>, treelet::InstancedTracer<CpuBackend>>,
    /// Each mesh's triangle count.
    meshes: Vec<usize>,
    instances: usize,
}

/// The instances: `mesh` ((k,) integers, each a mesh's index) placed by
/// `transforms` ((k, 3, 4) or (k, 4, 4) numbers, row-major: a point p goes
/// to `T @ [p, 1]`), checked against the `meshes` meshes.
fn instances_of(py: Python<'_>, mesh: &Bound<'_, PyAny>, transforms: &Bound<'_, PyAny>, meshes: usize) -> PyResult<Vec<Instance>> {
    let np = py.import("numpy")?;
    let (mesh, transforms) = (&as_numpy(&np, mesh, "mesh")?, &as_numpy(&np, transforms, "transforms")?);
    let kind = |a: &Bound<'_, PyAny>| -> PyResult<String> { a.getattr("dtype")?.getattr("kind")?.extract() };
    if !matches!(kind(mesh)?.as_str(), "i" | "u") {
        return Err(PyTypeError::new_err("mesh: integers expected (each instance's mesh)"));
    }
    if !matches!(kind(transforms)?.as_str(), "f" | "i" | "u") {
        return Err(PyTypeError::new_err("transforms: numbers expected"));
    }
    let mesh: PyReadonlyArray1<i64> = np
        .call_method1("ascontiguousarray", (mesh, "int64"))?
        .extract()
        .map_err(|_| PyValueError::new_err(format!("mesh: expected a 1-dimensional (k,) array, got shape {}", shape_of(mesh))))?;
    let t: PyReadonlyArray3<f32> = np.call_method1("ascontiguousarray", (transforms, "float32"))?.extract().map_err(|_| {
        PyValueError::new_err(format!("transforms: expected a (k, 3, 4) or (k, 4, 4) array, got shape {}", shape_of(transforms)))
    })?;
    let (k, rows) = (t.shape()[0], t.shape()[1]);
    if !matches!((rows, t.shape()[2]), (3, 4) | (4, 4)) {
        return Err(PyValueError::new_err(format!("transforms: expected shape (k, 3, 4) or (k, 4, 4), got {:?}", t.shape())));
    }
    if mesh.len() != k {
        return Err(PyValueError::new_err(format!("{} meshes for {k} transforms", mesh.len())));
    }
    let (mesh, t) = (mesh.as_slice()?, t.as_slice()?);
    (0..k)
        .map(|i| {
            let m = &t[i * rows * 4..(i + 1) * rows * 4];
            if let Some(v) = m.iter().find(|v| !v.is_finite()) {
                return Err(PyValueError::new_err(format!("transforms[{i}]: not finite ({v})")));
            }
            if rows == 4 && m[12..] != [0.0, 0.0, 0.0, 1.0] {
                return Err(PyValueError::new_err(format!("transforms[{i}]: its last row is {:?}, not [0, 0, 0, 1] (a projective transform)", &m[12..])));
            }
            let index = usize::try_from(mesh[i]).ok().filter(|&m| m < meshes).ok_or_else(|| {
                PyValueError::new_err(format!("mesh[{i}]: {} is not one of the {meshes} meshes", mesh[i]))
            })?;
            let row = |r: usize| [m[4 * r], m[4 * r + 1], m[4 * r + 2], m[4 * r + 3]];
            Ok(Instance { mesh: index as u32, transform: [row(0), row(1), row(2)] })
        })
        .collect()
}

#[pymethods]
impl InstancedTracer {
    /// Builds a tree for each of `meshes` (a sequence of `(vertices,
    /// indices)` pairs, as `Tracer` takes them) and the top-level tree over
    /// the instances: instance `i` is mesh `mesh[i]` placed by
    /// `transforms[i]` ((k, 3, 4) or (k, 4, 4), row-major). `device` and
    /// `quality` as for `Tracer`.
    #[new]
    #[pyo3(signature = (meshes, mesh, transforms, device = "auto", quality = "fast"))]
    fn new(py: Python<'_>, meshes: &Bound<'_, PyAny>, mesh: &Bound<'_, PyAny>, transforms: &Bound<'_, PyAny>, device: &str, quality: &str) -> PyResult<Self> {
        let mut triangles: Vec<Vec<Triangle>> = Vec::new();
        for (k, item) in meshes.try_iter().map_err(|_| PyTypeError::new_err("meshes: a sequence of (vertices, indices) pairs expected"))?.enumerate() {
            let (v, i): (Bound<'_, PyAny>, Bound<'_, PyAny>) =
                item?.extract().map_err(|_| PyTypeError::new_err(format!("meshes[{k}]: a (vertices, indices) pair expected")))?;
            triangles.push(triangles_of(py, &v, &i).map_err(|e| PyErr::from_type(e.get_type(py), format!("meshes[{k}]: {}", e.value(py))))?);
        }
        let instances = instances_of(py, mesh, transforms, triangles.len())?;
        let quality = device::quality(quality)?;
        let refs: Vec<&[Triangle]> = triangles.iter().map(Vec::as_slice).collect();
        let inner = device::build(
            device,
            |b| treelet::InstancedTracer::build(b, &refs, &instances, quality),
            |b| treelet::InstancedTracer::build(b, &refs, &instances, quality),
        )?;
        Ok(InstancedTracer { inner, meshes: triangles.iter().map(Vec::len).collect(), instances: instances.len() })
    }

    /// The device the trees are on: the adapter's name, or "cpu".
    #[getter]
    fn device(&self) -> String {
        self.inner.name()
    }

    /// The number of instances.
    fn __len__(&self) -> usize {
        self.instances
    }

    /// The closest hit of each ray, as `Tracer.closest_hits`: `instance` is
    /// the instance hit, `primitive` the triangle within its mesh (a row of
    /// that mesh's indices), `normal` in world space; `out` as there.
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

    /// Whether each ray hits anything from `t_min` up to `t_max`, as `Tracer.occluded`.
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

    /// Places the instances anew (any number, of the same meshes) and
    /// rebuilds the top-level tree only: the meshes' trees stay.
    fn set_instances(&mut self, py: Python<'_>, mesh: &Bound<'_, PyAny>, transforms: &Bound<'_, PyAny>) -> PyResult<()> {
        let instances = instances_of(py, mesh, transforms, self.meshes.len())?;
        on_device!(&mut self.inner, py, |b, t| t.set_instances(b, &instances)).map_err(py_err)?;
        self.instances = instances.len();
        Ok(())
    }

    /// Moves mesh `index`'s vertices (the same triangle count) and refits
    /// its tree; every instance of it moves with it.
    fn refit_mesh(&mut self, py: Python<'_>, index: usize, vertices: &Bound<'_, PyAny>, indices: &Bound<'_, PyAny>) -> PyResult<()> {
        let Some(&count) = self.meshes.get(index) else {
            return Err(PyValueError::new_err(format!("refit_mesh: mesh {index} is not one of the {} meshes", self.meshes.len())));
        };
        let triangles = triangles_of(py, vertices, indices)?;
        if triangles.len() != count {
            return Err(PyValueError::new_err(format!("refit_mesh: {} triangles where mesh {index} has {count}", triangles.len())));
        }
        on_device!(&mut self.inner, py, |b, t| t.refit_mesh(b, index, &triangles)).map_err(py_err)
    }
}
