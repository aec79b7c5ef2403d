//! The closest hits of a batch, as NumPy arrays.
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use treelet::internals::input::zeroed_vec;
use treelet::tracer::BatchHits;
use treelet::{Ray, RayHit};

/// The closest hit of each ray: `t` (distance along the normalized
/// direction; inf for a miss), `primitive` (the triangle, -1 for a miss),
/// `instance` (the instance hit: 0 for a `Tracer`'s; -1 for a miss), `barycentrics` (n, 2: of the
/// triangle's second and third vertex), `normal` (n, 3: unit, the
/// triangle's `(v1 - v0) x (v2 - v0)`), `hit` (a bool mask).
#[pyclass(module = "treelet", get_all)]
pub(crate) struct Hits {
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

impl Hits {
    /// New arrays for `n` hits, zeroed, their pages mapped in on every core
    /// (`zeroed_vec`: on the H200's virtual machine, fresh memory taken a
    /// page fault at a time cost more than tracing the rays), handed to
    /// NumPy without a copy; filled as `out=` arrays are. A `MemoryError`
    /// where the memory cannot hold them.
    pub(crate) fn zeroed(py: Python<'_>, n: usize) -> PyResult<Self> {
        fn zeroed<T: bytemuck::Zeroable>(n: usize, what: &str) -> PyResult<Vec<T>> {
            zeroed_vec(n, what).map_err(|e| pyo3::exceptions::PyMemoryError::new_err(format!("{e:#}")))
        }
        let barycentrics = Array2::from_shape_vec((n, 2), zeroed(2 * n, "barycentrics")?).expect("n rows of 2");
        let normal = Array2::from_shape_vec((n, 3), zeroed(3 * n, "normal")?).expect("n rows of 3");
        Ok(Hits {
            t: zeroed::<f32>(n, "t")?.into_pyarray(py).unbind(),
            primitive: zeroed::<i64>(n, "primitive")?.into_pyarray(py).unbind(),
            instance: zeroed::<i64>(n, "instance")?.into_pyarray(py).unbind(),
            barycentrics: barycentrics.into_pyarray(py).unbind(),
            normal: normal.into_pyarray(py).unbind(),
            hit: zeroed::<bool>(n, "hit")?.into_pyarray(py).unbind(),
        })
    }
}

/// A triangle or instance index as NumPy gets it: -1 for none.
fn signed(x: u32) -> i64 {
    if x == u32::MAX { -1 } else { i64::from(x) }
}

/// The arrays of a [`Hits`] given back as `out=`, borrowed writable for one
/// batch and written in place: no new memory (a million hits' six arrays
/// are 41 MB, and filling fresh ones took half of Python's time on the
/// H200).
pub(crate) struct HitArrays<'py> {
    t: numpy::PyReadwriteArray1<'py, f32>,
    primitive: numpy::PyReadwriteArray1<'py, i64>,
    instance: numpy::PyReadwriteArray1<'py, i64>,
    barycentrics: numpy::PyReadwriteArray2<'py, f32>,
    normal: numpy::PyReadwriteArray2<'py, f32>,
    hit: numpy::PyReadwriteArray1<'py, bool>,
}

impl<'py> HitArrays<'py> {
    /// `out`'s arrays for a batch of `n` rays: a `ValueError` where it holds
    /// another number of hits, or where one of its arrays is in use
    /// elsewhere in the call (given as the rays, say).
    pub(crate) fn borrow(py: Python<'py>, out: &Bound<'py, Hits>, n: usize) -> PyResult<Self> {
        let h = out.borrow();
        let held = h.t.bind(py).len();
        if held != n {
            return Err(pyo3::exceptions::PyValueError::new_err(format!("out: holds {held} hits, but {n} rays were given")));
        }
        let busy = |what: &str| pyo3::exceptions::PyValueError::new_err(format!("out.{what}: the array is in use elsewhere in this call (given as rays?)"));
        Ok(HitArrays {
            t: h.t.bind(py).try_readwrite().map_err(|_| busy("t"))?,
            primitive: h.primitive.bind(py).try_readwrite().map_err(|_| busy("primitive"))?,
            instance: h.instance.bind(py).try_readwrite().map_err(|_| busy("instance"))?,
            barycentrics: h.barycentrics.bind(py).try_readwrite().map_err(|_| busy("barycentrics"))?,
            normal: h.normal.bind(py).try_readwrite().map_err(|_| busy("normal"))?,
            hit: h.hit.bind(py).try_readwrite().map_err(|_| busy("hit"))?,
        })
    }

    /// The arrays as slices, to be written from any thread.
    pub(crate) fn slices(&mut self) -> PyResult<HitSlices<'_>> {
        let whole = |what: &str| pyo3::exceptions::PyValueError::new_err(format!("out.{what}: not contiguous"));
        Ok(HitSlices {
            t: self.t.as_slice_mut().map_err(|_| whole("t"))?,
            primitive: self.primitive.as_slice_mut().map_err(|_| whole("primitive"))?,
            instance: self.instance.as_slice_mut().map_err(|_| whole("instance"))?,
            barycentrics: self.barycentrics.as_slice_mut().map_err(|_| whole("barycentrics"))?,
            normal: self.normal.as_slice_mut().map_err(|_| whole("normal"))?,
            hit: self.hit.as_slice_mut().map_err(|_| whole("hit"))?,
        })
    }
}

/// [`HitArrays`] as slices.
pub(crate) struct HitSlices<'a> {
    t: &'a mut [f32],
    primitive: &'a mut [i64],
    instance: &'a mut [i64],
    barycentrics: &'a mut [f32],
    normal: &'a mut [f32],
    hit: &'a mut [bool],
}

impl HitSlices<'_> {
    /// Fills the arrays with the batch's hits on every core (in parts of
    /// [`PART`] rays: a million hits are 41 MB of arrays, which one core
    /// writes slower than the GPU traces them).
    pub(crate) fn fill<R: Fn(usize) -> Ray + Sync>(self, hits: &BatchHits<'_, R>) {
        self.fill_from(hits, 0);
    }

    /// [`HitSlices::fill`] of the arrays that hold hits `first..`.
    fn fill_from<R: Fn(usize) -> Ray + Sync>(mut self, hits: &BatchHits<'_, R>, first: usize) {
        let n = self.t.len();
        if n <= PART {
            (0..n).for_each(|k| self.write(k, hits.get(first + k)));
            return;
        }
        let (a, b) = self.split_at(n / 2);
        rayon::join(|| a.fill_from(hits, first), || b.fill_from(hits, first + n / 2));
    }

    /// The arrays of hits `..mid` and `mid..`.
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (t, t2) = self.t.split_at_mut(mid);
        let (primitive, primitive2) = self.primitive.split_at_mut(mid);
        let (instance, instance2) = self.instance.split_at_mut(mid);
        let (barycentrics, barycentrics2) = self.barycentrics.split_at_mut(2 * mid);
        let (normal, normal2) = self.normal.split_at_mut(3 * mid);
        let (hit, hit2) = self.hit.split_at_mut(mid);
        (
            HitSlices { t, primitive, instance, barycentrics, normal, hit },
            HitSlices { t: t2, primitive: primitive2, instance: instance2, barycentrics: barycentrics2, normal: normal2, hit: hit2 },
        )
    }

    /// Hit `k` of these arrays.
    fn write(&mut self, k: usize, h: RayHit) {
        self.t[k] = h.t;
        self.primitive[k] = signed(h.prim);
        self.instance[k] = signed(h.instance);
        self.hit[k] = h.is_hit();
        self.barycentrics[2 * k..2 * k + 2].copy_from_slice(&h.barycentrics);
        self.normal[3 * k..3 * k + 3].copy_from_slice(&h.normal);
    }
}

/// Hits a core writes at a time ([`HitSlices::fill`]).
const PART: usize = 1 << 14;
