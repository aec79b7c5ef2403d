//! The `treelet` Python module: Treelet's engine API ([`treelet::Tracer`])
//! for NumPy arrays. A `Tracer` builds a BVH over a triangle mesh on a
//! Vulkan GPU or on the CPU runner (the same kernels), and answers closest
//! hits and occlusion queries for arrays of rays. Wrong shapes and dtypes
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
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use treelet::error::{Error, ErrorKind};
use treelet::runtime::device::{Device, DeviceChoice};
use treelet::tracer::RayQueries;
use treelet::{CpuBackend, GpuBackend, Quality, Ray, RayHit, Triangle};

/// A library error as the Python exception of its kind.
fn py_err(e: Error) -> PyErr {
    let message = format!("{e:#}");
    match e.kind() {
        ErrorKind::Input => PyValueError::new_err(message),
        ErrorKind::TooLarge => PyMemoryError::new_err(message),
        _ => PyRuntimeError::new_err(message),
    }
}

/// The tree and the device it lives on.
enum Inner {
    Gpu(GpuBackend, treelet::Tracer<GpuBackend>, String),
    Cpu(CpuBackend, treelet::Tracer<CpuBackend>),
}

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
struct Tracer {
    inner: Inner,
    triangles: usize,
}

/// The closest hit of each ray: `t` (distance along the normalized
/// direction; inf for a miss), `primitive` (the triangle, -1 for a miss),
/// `instance` (0 for a hit, -1 for a miss), `barycentrics` (n, 2: of the
/// triangle's second and third vertex), `normal` (n, 3: unit, the
/// triangle's `(v1 - v0) x (v2 - v0)`), `hit` (a bool mask).
#[pyclass(module = "treelet", get_all)]
struct Hits {
    t: Py<PyArray1<f32>>,
    primitive: Py<PyArray1<i64>>,
    instance: Py<PyArray1<i64>>,
    barycentrics: Py<PyArray2<f32>>,
    normal: Py<PyArray2<f32>>,
    hit: Py<PyArray1<bool>>,
}

#[pymethods]
impl Hits {
    fn __len__(&self, py: Python<'_>) -> usize {
        self.t.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let hit = self.hit.bind(py).to_vec().unwrap_or_default();
        format!("Hits({} rays, {} hit)", hit.len(), hit.iter().filter(|&&h| h).count())
    }
}

/// An (n, 3) array as a C-ordered array of `dtype` (no copy where it is
/// one already), any memory order, its dtype's kind one of `kinds` (`what`
/// names the argument, `rows` its rows' letter in messages).
fn rows_of<'py, T: numpy::Element>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    what: &str,
    (kinds, expected, dtype, rows): (&[&str], &str, &str, &str),
) -> PyResult<PyReadonlyArray2<'py, T>> {
    let np = py.import("numpy")?;
    let a = np.call_method1("asarray", (array,)).map_err(|_| PyTypeError::new_err(format!("{what}: not an array")))?;
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    if !kinds.contains(&kind.as_str()) {
        return Err(PyTypeError::new_err(format!("{what}: {expected} expected, got an array of dtype {}", a.getattr("dtype")?)));
    }
    let a = np.call_method1("ascontiguousarray", (a, dtype))?;
    let a: PyReadonlyArray2<T> = a.extract().map_err(|_| {
        PyValueError::new_err(format!("{what}: expected a 2-dimensional ({rows}, 3) array, got shape {}", shape_of(array)))
    })?;
    if a.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!("{what}: expected shape ({rows}, 3), got {:?}", a.shape())));
    }
    Ok(a)
}

/// An (n, 3) array of numbers (floats, ints) as C-ordered f32.
fn f32_rows<'py>(py: Python<'py>, array: &Bound<'py, PyAny>, what: &str) -> PyResult<PyReadonlyArray2<'py, f32>> {
    rows_of(py, array, what, (&["f", "i", "u"], "numbers", "float32", "n"))
}

/// [`f32_rows`] as `[f32; 3]` rows.
fn rows3(py: Python<'_>, array: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f32; 3]>> {
    Ok(f32_rows(py, array, what)?.as_slice()?.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

fn shape_of(array: &Bound<'_, PyAny>) -> String {
    array.getattr("shape").map(|s| s.to_string()).unwrap_or_else(|_| "(none)".into())
}

/// `t_min` or `t_max`: one number for every ray, or an (n,) array.
enum PerRay<'py> {
    All(f32),
    Each(PyReadonlyArray1<'py, f32>),
}

fn per_ray<'py>(py: Python<'py>, value: &Bound<'py, PyAny>, n: usize, what: &str) -> PyResult<PerRay<'py>> {
    let np = py.import("numpy")?;
    // One number only where it is one (a size-1 array for many rays is an
    // error, not a value for all).
    let ndim: usize = np.call_method1("ndim", (value,))?.extract()?;
    if ndim == 0 {
        return value.extract::<f32>().map(PerRay::All).map_err(|_| PyTypeError::new_err(format!("{what}: a number expected")));
    }
    let kind: String = np.call_method1("asarray", (value,))?.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        return Err(PyTypeError::new_err(format!("{what}: numbers expected")));
    }
    let a = np.call_method1("ascontiguousarray", (value, "float32"))?;
    let a: PyReadonlyArray1<f32> =
        a.extract().map_err(|_| PyValueError::new_err(format!("{what}: a number, or an array of one number per ray")))?;
    if a.len() != n {
        return Err(PyValueError::new_err(format!("{what}: {} values for {n} rays", a.len())));
    }
    Ok(PerRay::Each(a))
}

/// The triangles of `vertices` ((v, 3) numbers) and `indices` ((m, 3)
/// integers, one triangle a row), each index checked against the vertices.
fn triangles_of(py: Python<'_>, vertices: &Bound<'_, PyAny>, indices: &Bound<'_, PyAny>) -> PyResult<Vec<Triangle>> {
    let positions = rows3(py, vertices, "vertices")?;
    let idx: PyReadonlyArray2<i64> = rows_of(py, indices, "indices", (&["i", "u"], "integers", "int64", "m"))?;
    let mut triangles = Vec::with_capacity(idx.shape()[0]);
    for (t, row) in idx.as_slice()?.chunks_exact(3).enumerate() {
        let vertex = |k: usize| -> PyResult<[f32; 3]> {
            usize::try_from(row[k]).ok().and_then(|i| positions.get(i).copied()).ok_or_else(|| {
                PyValueError::new_err(format!("indices[{t}]: vertex index {} is not one of the {} vertices", row[k], positions.len()))
            })
        };
        triangles.push(Triangle::new(vertex(0)?, vertex(1)?, vertex(2)?));
    }
    Ok(triangles)
}

/// The arrays of a batch of rays, held while the library reads them.
struct RayArrays<'py> {
    origins: PyReadonlyArray2<'py, f32>,
    directions: PyReadonlyArray2<'py, f32>,
    t_min: PerRay<'py>,
    t_max: PerRay<'py>,
}

/// One value for every ray, or one each.
#[derive(Clone, Copy)]
enum Column<'a> {
    All(f32),
    Each(&'a [f32]),
}

/// A batch's rays, read from the arrays in place: ray `k` is made when the
/// library asks for it, straight into the device's upload memory.
struct RayColumns<'a> {
    o: &'a [f32],
    d: &'a [f32],
    t_min: Column<'a>,
    t_max: Column<'a>,
}

impl<'py> RayArrays<'py> {
    /// The arrays as C-ordered f32 (no copy where they are), shapes checked.
    fn new(py: Python<'py>, origins: &Bound<'py, PyAny>, directions: &Bound<'py, PyAny>, t_min: Option<&Bound<'py, PyAny>>, t_max: Option<&Bound<'py, PyAny>>) -> PyResult<Self> {
        let (origins, directions) = (f32_rows(py, origins, "origins")?, f32_rows(py, directions, "directions")?);
        let (o, d) = (origins.shape()[0], directions.shape()[0]);
        if o != d {
            return Err(PyValueError::new_err(format!("{o} origins but {d} directions")));
        }
        let bound = |value: Option<&Bound<'py, PyAny>>, default: f32, what| match value {
            Some(v) => per_ray(py, v, o, what),
            None => Ok(PerRay::All(default)),
        };
        Ok(RayArrays { t_min: bound(t_min, 0.0, "t_min")?, t_max: bound(t_max, f32::INFINITY, "t_max")?, origins, directions })
    }

    /// The rays, every value checked: NaN and infinite coordinates are the
    /// caller's error here (the engine API traces them as misses); a
    /// direction of length 0 hits nothing.
    fn columns(&self) -> PyResult<RayColumns<'_>> {
        let (o, d) = (self.origins.as_slice()?, self.directions.as_slice()?);
        for (what, values) in [("origins", o), ("directions", d)] {
            // Chunks in parallel, each in one pass that vectorizes (no early
            // exit), the place only on failure: a million rays' 6M floats
            // took 5 ms by `position` alone on the H200's host.
            let bad = values.par_chunks(1 << 16).any(|c| c.iter().fold(false, |bad, v| bad | !v.is_finite()));
            if bad {
                let k = values.iter().position(|v| !v.is_finite()).expect("a value is not finite");
                return Err(PyValueError::new_err(format!("{what}[{}]: not finite ({})", k / 3, values[k])));
            }
        }
        Ok(RayColumns { o, d, t_min: column(&self.t_min, "t_min")?, t_max: column(&self.t_max, "t_max")? })
    }
}

/// `t_min` or `t_max` as a column, checked for NaN.
fn column<'a>(values: &'a PerRay<'_>, what: &str) -> PyResult<Column<'a>> {
    let column = match values {
        PerRay::All(x) => Column::All(*x),
        PerRay::Each(a) => Column::Each(a.as_slice()?),
    };
    let nan = match column {
        Column::All(x) => x.is_nan().then_some(0),
        Column::Each(a) => a.iter().position(|x| x.is_nan()),
    };
    match nan {
        Some(k) => Err(PyValueError::new_err(format!("{what}: NaN (at ray {k}); use inf for no limit"))),
        None => Ok(column),
    }
}

impl RayColumns<'_> {
    fn len(&self) -> usize {
        self.o.len() / 3
    }

    fn ray(&self, k: usize) -> Ray {
        let at = |c: Column<'_>| match c {
            Column::All(x) => x,
            Column::Each(a) => a[k],
        };
        Ray {
            origin: [self.o[3 * k], self.o[3 * k + 1], self.o[3 * k + 2]],
            dir: [self.d[3 * k], self.d[3 * k + 1], self.d[3 * k + 2]],
            t_min: at(self.t_min),
            t_max: at(self.t_max),
        }
    }
}

/// The arrays of [`Hits`], filled in one pass as the hits are read back
/// (each written in place: six `push`es a hit took twice as long).
struct HitColumns {
    t: Vec<f32>,
    primitive: Vec<i64>,
    instance: Vec<i64>,
    barycentrics: Vec<f32>,
    normal: Vec<f32>,
    hit: Vec<bool>,
}

impl HitColumns {
    /// Zeroed arrays for `n` hits (fresh zero pages: each is touched once,
    /// when its hit is written).
    fn zeroed(n: usize) -> Self {
        HitColumns { t: vec![0.0; n], primitive: vec![0; n], instance: vec![0; n], barycentrics: vec![0.0; 2 * n], normal: vec![0.0; 3 * n], hit: vec![false; n] }
    }

    fn set(&mut self, k: usize, h: RayHit) {
        let signed = |x: u32| if x == u32::MAX { -1 } else { i64::from(x) };
        self.t[k] = h.t;
        self.primitive[k] = signed(h.prim);
        self.instance[k] = signed(h.instance);
        self.hit[k] = h.is_hit();
        self.barycentrics[2 * k..2 * k + 2].copy_from_slice(&h.barycentrics);
        self.normal[3 * k..3 * k + 3].copy_from_slice(&h.normal);
    }

    /// The arrays handed to NumPy without a copy.
    fn into_hits(self, py: Python<'_>) -> Hits {
        let n = self.t.len();
        let barycentrics = Array2::from_shape_vec((n, 2), self.barycentrics).expect("n rows of 2");
        let normal = Array2::from_shape_vec((n, 3), self.normal).expect("n rows of 3");
        Hits {
            t: self.t.into_pyarray(py).unbind(),
            primitive: self.primitive.into_pyarray(py).unbind(),
            instance: self.instance.into_pyarray(py).unbind(),
            barycentrics: barycentrics.into_pyarray(py).unbind(),
            normal: normal.into_pyarray(py).unbind(),
            hit: self.hit.into_pyarray(py).unbind(),
        }
    }
}

/// Runs `$body` with the tree's backend `$b` and tracer `$t`, the GIL
/// released while a GPU works (the CPU runner's buffers stay on the thread
/// that holds the GIL: it works with the GIL held).
macro_rules! on_device {
    ($self:expr, $py:expr, |$b:ident, $t:ident| $body:expr) => {
        match &mut $self.inner {
            Inner::Gpu($b, $t, _) => $py.allow_threads(|| $body),
            Inner::Cpu($b, $t) => $body,
        }
    };
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
        let quality = match quality {
            "fast" => Quality::Fast,
            "balanced" => Quality::Balanced,
            "high" => Quality::High,
            other => return Err(PyValueError::new_err(format!("quality `{other}`: use fast, balanced or high"))),
        };
        let choice = match device {
            "auto" => DeviceChoice::Auto,
            "gpu" => DeviceChoice::Gpu,
            "cpu" => DeviceChoice::Cpu,
            other => return Err(PyValueError::new_err(format!("device `{other}`: use auto, gpu or cpu"))),
        };
        let (opened, _note) = choice.open_with_note().map_err(|e| PyRuntimeError::new_err(format!("{e:#}")))?;
        let inner = match opened {
            Device::Gpu(ctx) => {
                let name = ctx.info.name.clone();
                let mut b = GpuBackend::new(ctx);
                let tracer = treelet::Tracer::build(&mut b, &[], &triangles, quality).map_err(py_err)?;
                Inner::Gpu(b, tracer, name)
            }
            Device::Cpu => {
                let mut b = CpuBackend::new();
                let tracer = treelet::Tracer::build(&mut b, &[], &triangles, quality).map_err(py_err)?;
                Inner::Cpu(b, tracer)
            }
        };
        Ok(Tracer { inner, triangles: triangles.len() })
    }

    /// The device the tree is on: the adapter's name, or "cpu".
    #[getter]
    fn device(&self) -> String {
        match &self.inner {
            Inner::Gpu(_, _, name) => name.clone(),
            Inner::Cpu(..) => "cpu".into(),
        }
    }

    fn __len__(&self) -> usize {
        self.triangles
    }

    /// The closest hit of each ray `origins[k] + t directions[k]` (both
    /// (n, 3); directions of any length, one of length 0 hitting nothing),
    /// from `t_min` to `t_max`
    /// (numbers, or one per ray), `t` along the normalized direction.
    #[pyo3(signature = (origins, directions, t_min = None, t_max = None))]
    fn closest_hits(
        &mut self,
        py: Python<'_>,
        origins: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        t_min: Option<&Bound<'_, PyAny>>,
        t_max: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Hits> {
        let arrays = RayArrays::new(py, origins, directions, t_min, t_max)?;
        let rays = arrays.columns()?;
        let mut out = HitColumns::zeroed(rays.len());
        on_device!(self, py, |b, t| t.closest_hits_with(b, rays.len(), |k| rays.ray(k), |k, h| out.set(k, h))).map_err(py_err)?;
        Ok(out.into_hits(py))
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
        let arrays = RayArrays::new(py, origins, directions, t_min, t_max)?;
        let rays = arrays.columns()?;
        let mut hit = Vec::with_capacity(rays.len());
        on_device!(self, py, |b, t| t.occluded_with(b, rays.len(), |k| rays.ray(k), |_, o| hit.push(o))).map_err(py_err)?;
        Ok(hit.into_pyarray(py))
    }

    /// The benchmark's baseline (python/examples/bench_rays.py): the median
    /// wall milliseconds of the Rust API on these rays, taken `repeats`
    /// times, the rays already made (what an engine calling the Rust API
    /// pays, without this module's conversions): `closest_hits` into a new
    /// vector of hits, or with `kept`, `closest_hits_with` into one kept
    /// between calls (an engine's own buffer). Each result is dropped after
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
                on_device!(self, py, |b, t| t.closest_hits_with(b, rays.len(), |k| rays[k], |k, h| own[k] = h)).map_err(py_err)?;
                Vec::new()
            } else {
                on_device!(self, py, |b, t| t.closest_hits(b, &rays)).map_err(py_err)?
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
        match &mut self.inner {
            Inner::Gpu(b, t, _) => t.refit(b, &[], &triangles),
            Inner::Cpu(b, t) => t.refit(b, &[], &triangles),
        }
        .map_err(py_err)
    }
}

#[pymodule(name = "treelet")]
fn treelet_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Tracer>()?;
    m.add_class::<Hits>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
