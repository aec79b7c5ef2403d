//! NumPy arrays in, as the library takes them: (n, 3) rows of vertices,
//! indices and rays, read in place where their layout allows, each checked
//! with an error that names the argument and the row.
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use treelet::{Ray, Triangle};

/// `array` as a NumPy array: an object that exports DLPack (a PyTorch, JAX
/// or CuPy array) through `numpy.from_dlpack`, which shares its memory
/// where it is on the CPU; anything else through `numpy.asarray` (NumPy
/// arrays as they are, nested lists, objects with `__array__`). A tensor on
/// a GPU is refused by name: its memory is not the host's.
pub(crate) fn as_numpy<'py>(np: &Bound<'py, PyModule>, array: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyAny>> {
    if !array.is_instance_of::<numpy::PyUntypedArray>() && array.hasattr("__dlpack__")? {
        // DLPack's device types: 1 the CPU, 3 CUDA's pinned host memory.
        if let Ok((device, _)) = array.call_method0("__dlpack_device__").and_then(|d| d.extract::<(i64, i64)>()) {
            if device != 1 && device != 3 {
                return Err(PyTypeError::new_err(format!(
                    "{what}: not readable on the CPU through DLPack (its memory is on a device of DLPack type {device}, not the host's): move it to the CPU first (a tensor's .cpu())"
                )));
            }
        }
        return np.call_method1("from_dlpack", (array,)).map_err(|e| {
            PyTypeError::new_err(format!("{what}: not readable on the CPU through DLPack ({}): move it to the CPU first (a tensor's .cpu())", e.value(np.py())))
        });
    }
    np.call_method1("asarray", (array,)).map_err(|_| PyTypeError::new_err(format!("{what}: not an array")))
}

/// An (n, 3) array as a C-ordered array of `dtype` (no copy where it is
/// one already), any memory order, its dtype's kind one of `kinds` (`what`
/// names the argument, `rows` its rows' letter in messages).
pub(crate) fn rows_of<'py, T: numpy::Element>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    what: &str,
    (kinds, expected, dtype, rows): (&[&str], &str, &str, &str),
) -> PyResult<PyReadonlyArray2<'py, T>> {
    let np = py.import("numpy")?;
    let a = as_numpy(&np, array, what)?;
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
pub(crate) fn f32_rows<'py>(py: Python<'py>, array: &Bound<'py, PyAny>, what: &str) -> PyResult<PyReadonlyArray2<'py, f32>> {
    rows_of(py, array, what, (&["f", "i", "u"], "numbers", "float32", "n"))
}

/// [`f32_rows`] as `[f32; 3]` rows.
pub(crate) fn rows3(py: Python<'_>, array: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f32; 3]>> {
    Ok(f32_rows(py, array, what)?.as_slice()?.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

pub(crate) fn shape_of(array: &Bound<'_, PyAny>) -> String {
    array.getattr("shape").map(|s| s.to_string()).unwrap_or_else(|_| "(none)".into())
}

/// `t_min` or `t_max`: one number for every ray, or an (n,) array.
pub(crate) enum PerRay<'py> {
    All(f32),
    Each(PyReadonlyArray1<'py, f32>),
}

pub(crate) fn per_ray<'py>(py: Python<'py>, value: &Bound<'py, PyAny>, n: usize, what: &str) -> PyResult<PerRay<'py>> {
    let np = py.import("numpy")?;
    // One number only where it is one (a size-1 array for many rays is an
    // error, not a value for all).
    let array = as_numpy(&np, value, what)?;
    let ndim: usize = array.getattr("ndim")?.extract()?;
    if ndim == 0 {
        return value.extract::<f32>().map(PerRay::All).map_err(|_| PyTypeError::new_err(format!("{what}: a number expected")));
    }
    let value = array;
    let kind: String = value.getattr("dtype")?.getattr("kind")?.extract()?;
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
pub(crate) fn triangles_of(py: Python<'_>, vertices: &Bound<'_, PyAny>, indices: &Bound<'_, PyAny>) -> PyResult<Vec<Triangle>> {
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
pub(crate) struct RayArrays<'py> {
    origins: PyReadonlyArray2<'py, f32>,
    directions: PyReadonlyArray2<'py, f32>,
    t_min: PerRay<'py>,
    t_max: PerRay<'py>,
}

/// One value for every ray, or one each.
#[derive(Clone, Copy)]
pub(crate) enum Column<'a> {
    All(f32),
    Each(&'a [f32]),
}

/// A batch's rays, read from the arrays in place: ray `k` is made when the
/// library asks for it, straight into the device's upload memory.
pub(crate) struct RayColumns<'a> {
    o: &'a [f32],
    d: &'a [f32],
    t_min: Column<'a>,
    t_max: Column<'a>,
}

impl<'py> RayArrays<'py> {
    /// The arrays as C-ordered f32 (no copy where they are), shapes checked.
    pub(crate) fn new(py: Python<'py>, origins: &Bound<'py, PyAny>, directions: &Bound<'py, PyAny>, t_min: Option<&Bound<'py, PyAny>>, t_max: Option<&Bound<'py, PyAny>>) -> PyResult<Self> {
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
    pub(crate) fn columns(&self) -> PyResult<RayColumns<'_>> {
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
pub(crate) fn column<'a>(values: &'a PerRay<'_>, what: &str) -> PyResult<Column<'a>> {
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
    pub(crate) fn len(&self) -> usize {
        self.o.len() / 3
    }

    pub(crate) fn ray(&self, k: usize) -> Ray {
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

