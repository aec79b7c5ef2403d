//! The closest hits of a batch, as NumPy arrays.
use std::mem::MaybeUninit;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use treelet::internals::input::room_to_fill;
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

/// New arrays for a batch's hits: their room mapped in on every core
/// (`room_to_fill`: on the H200's virtual machine, fresh memory taken a
/// page fault at a time cost more than tracing the rays) and written once,
/// by [`HitSlices::fill`], then handed to NumPy without a copy. Not zeroed
/// first: that pass over a million hits' 41 MB made fresh arrays cost
/// 1.3x the Rust API's time on the H200, against 1.1x for `out=` ones.
pub(crate) struct FreshHits {
    n: usize,
    t: Vec<f32>,
    primitive: Vec<i64>,
    instance: Vec<i64>,
    barycentrics: Vec<f32>,
    normal: Vec<f32>,
    hit: Vec<bool>,
}

/// Made only by [`HitSlices::fill`] once every hit of its arrays is written:
/// what [`FreshHits::into_hits`] needs to hand them over.
pub(crate) struct Filled(());

impl FreshHits {
    /// Room for `n` hits; a `MemoryError` where the memory cannot hold it.
    pub(crate) fn new(n: usize) -> PyResult<Self> {
        fn room<T>(n: usize, what: &str) -> PyResult<Vec<T>> {
            room_to_fill(n, what).map_err(|e| pyo3::exceptions::PyMemoryError::new_err(format!("{e:#}")))
        }
        Ok(FreshHits {
            n,
            t: room(n, "t")?,
            primitive: room(n, "primitive")?,
            instance: room(n, "instance")?,
            barycentrics: room(2 * n, "barycentrics")?,
            normal: room(3 * n, "normal")?,
            hit: room(n, "hit")?,
        })
    }

    /// The room, to be filled.
    pub(crate) fn slices(&mut self) -> HitSlices<'_> {
        let n = self.n;
        HitSlices {
            t: &mut self.t.spare_capacity_mut()[..n],
            primitive: &mut self.primitive.spare_capacity_mut()[..n],
            instance: &mut self.instance.spare_capacity_mut()[..n],
            barycentrics: &mut self.barycentrics.spare_capacity_mut()[..2 * n],
            normal: &mut self.normal.spare_capacity_mut()[..3 * n],
            hit: &mut self.hit.spare_capacity_mut()[..n],
        }
    }

    /// The filled arrays as NumPy's.
    pub(crate) fn into_hits(mut self, py: Python<'_>, _: Filled) -> Hits {
        let n = self.n;
        // SAFETY: `Filled` is made only by a fill of `slices()`, which
        // writes every element of the first `n` (`2n`, `3n`) of each.
        unsafe {
            self.t.set_len(n);
            self.primitive.set_len(n);
            self.instance.set_len(n);
            self.barycentrics.set_len(2 * n);
            self.normal.set_len(3 * n);
            self.hit.set_len(n);
        }
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
            t: written(self.t.as_slice_mut().map_err(|_| whole("t"))?),
            primitive: written(self.primitive.as_slice_mut().map_err(|_| whole("primitive"))?),
            instance: written(self.instance.as_slice_mut().map_err(|_| whole("instance"))?),
            barycentrics: written(self.barycentrics.as_slice_mut().map_err(|_| whole("barycentrics"))?),
            normal: written(self.normal.as_slice_mut().map_err(|_| whole("normal"))?),
            hit: written(self.hit.as_slice_mut().map_err(|_| whole("hit"))?),
        })
    }
}

/// Initialized elements seen as room that [`HitSlices`] writes: it only
/// ever writes whole values into it, so they stay initialized.
fn written<T>(s: &mut [T]) -> &mut [MaybeUninit<T>] {
    // SAFETY: same layout; every write through the result is a whole `T`
    // (`HitSlices::write`), never an uninitialized value.
    unsafe { &mut *(s as *mut [T] as *mut [MaybeUninit<T>]) }
}

/// The arrays of a batch's hits, [`HitArrays`] or [`FreshHits`], as room
/// to write every hit into.
pub(crate) struct HitSlices<'a> {
    t: &'a mut [MaybeUninit<f32>],
    primitive: &'a mut [MaybeUninit<i64>],
    instance: &'a mut [MaybeUninit<i64>],
    barycentrics: &'a mut [MaybeUninit<f32>],
    normal: &'a mut [MaybeUninit<f32>],
    hit: &'a mut [MaybeUninit<bool>],
}

impl HitSlices<'_> {
    /// Fills the arrays with the batch's hits on every core (in parts of
    /// [`PART`] rays: a million hits are 41 MB of arrays, which one core
    /// writes slower than the GPU traces them).
    pub(crate) fn fill<R: Fn(usize) -> Ray + Sync>(self, hits: &BatchHits<'_, R>) -> Filled {
        self.fill_from(hits, 0);
        Filled(())
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
        self.t[k].write(h.t);
        self.primitive[k].write(signed(h.prim));
        self.instance[k].write(signed(h.instance));
        self.hit[k].write(h.is_hit());
        for (j, &b) in h.barycentrics.iter().enumerate() {
            self.barycentrics[2 * k + j].write(b);
        }
        for (j, &x) in h.normal.iter().enumerate() {
            self.normal[3 * k + j].write(x);
        }
    }
}

/// Hits a core writes at a time ([`HitSlices::fill`]).
const PART: usize = 1 << 14;
