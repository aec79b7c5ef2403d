//! The closest hits of a batch, as NumPy arrays.
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use treelet::internals::input::room_to_fill;
use treelet::RayHit;

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

/// The arrays of [`Hits`], filled in one pass as the hits are read back.
pub(crate) struct HitColumns {
    t: Vec<f32>,
    primitive: Vec<i64>,
    instance: Vec<i64>,
    barycentrics: Vec<f32>,
    normal: Vec<f32>,
    hit: Vec<bool>,
}

impl HitColumns {
    /// Room for `n` hits in each array, its pages mapped in at once
    /// (`room_to_fill`), filled by [`HitColumns::push`]. On the H200, a
    /// million hits took 18 ms so against 21 ms written in place into zeroed
    /// arrays (their pages faulted in one at a time) and 9 ms with no
    /// arrays at all. A `MemoryError` where the memory cannot hold them.
    pub(crate) fn with_room(n: usize) -> PyResult<Self> {
        fn room<T>(n: usize, what: &str) -> PyResult<Vec<T>> {
            room_to_fill(n, what).map_err(|e| pyo3::exceptions::PyMemoryError::new_err(format!("{e:#}")))
        }
        Ok(HitColumns {
            t: room(n, "t")?,
            primitive: room(n, "primitive")?,
            instance: room(n, "instance")?,
            barycentrics: room(2 * n, "barycentrics")?,
            normal: room(3 * n, "normal")?,
            hit: room(n, "hit")?,
        })
    }

    /// The next hit (hits arrive in order).
    pub(crate) fn push(&mut self, h: RayHit) {
        self.t.push(h.t);
        self.primitive.push(signed(h.prim));
        self.instance.push(signed(h.instance));
        self.hit.push(h.is_hit());
        self.barycentrics.extend_from_slice(&h.barycentrics);
        self.normal.extend_from_slice(&h.normal);
    }

    /// The arrays handed to NumPy without a copy.
    pub(crate) fn into_hits(self, py: Python<'_>) -> Hits {
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
    /// Hit `k` of the batch.
    pub(crate) fn write(&mut self, k: usize, h: RayHit) {
        self.t[k] = h.t;
        self.primitive[k] = signed(h.prim);
        self.instance[k] = signed(h.instance);
        self.hit[k] = h.is_hit();
        self.barycentrics[2 * k..2 * k + 2].copy_from_slice(&h.barycentrics);
        self.normal[3 * k..3 * k + 3].copy_from_slice(&h.normal);
    }
}
