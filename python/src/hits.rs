//! The closest hits of a batch, as NumPy arrays.
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use treelet::internals::input::zeroed_vec;
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

/// The arrays of [`Hits`], filled in one pass as the hits are read back
/// (each written in place: six `push`es a hit took twice as long).
pub(crate) struct HitColumns {
    t: Vec<f32>,
    primitive: Vec<i64>,
    instance: Vec<i64>,
    barycentrics: Vec<f32>,
    normal: Vec<f32>,
    hit: Vec<bool>,
}

impl HitColumns {
    /// Zeroed arrays for `n` hits, their pages mapped in at once
    /// (`zeroed_vec`: a page fault at a time, a million hits' 41 MB cost
    /// more than the hits' copy on the H200's virtual machine). A `MemoryError`
    /// where the memory cannot hold them.
    pub(crate) fn zeroed(n: usize) -> PyResult<Self> {
        let room = |what: &str| PyErr::new::<pyo3::exceptions::PyMemoryError, _>(format!("{what} of {n} hits"));
        let (z32, z64) = (|k: usize, w: &str| zeroed_vec::<f32>(k, w), |k: usize, w: &str| zeroed_vec::<i64>(k, w));
        Ok(HitColumns {
            t: z32(n, "t").map_err(|_| room("t"))?,
            primitive: z64(n, "primitive").map_err(|_| room("primitive"))?,
            instance: z64(n, "instance").map_err(|_| room("instance"))?,
            barycentrics: z32(2 * n, "barycentrics").map_err(|_| room("barycentrics"))?,
            normal: z32(3 * n, "normal").map_err(|_| room("normal"))?,
            // (bool is no `Pod`; an eighth of the bytes of `t`.)
            hit: vec![false; n],
        })
    }

    pub(crate) fn set(&mut self, k: usize, h: RayHit) {
        let signed = |x: u32| if x == u32::MAX { -1 } else { i64::from(x) };
        self.t[k] = h.t;
        self.primitive[k] = signed(h.prim);
        self.instance[k] = signed(h.instance);
        self.hit[k] = h.is_hit();
        self.barycentrics[2 * k..2 * k + 2].copy_from_slice(&h.barycentrics);
        self.normal[3 * k..3 * k + 3].copy_from_slice(&h.normal);
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

