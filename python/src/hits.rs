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
        let signed = |x: u32| if x == u32::MAX { -1 } else { i64::from(x) };
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

