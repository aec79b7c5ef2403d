//! A tree and the device it lives on (a GPU's backend, or the CPU
//! runner's), and the queries both kinds of tracer answer through
//! [`RayQueries`].
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use treelet::runtime::device::{Device, DeviceChoice};
use treelet::tracer::RayQueries;
use treelet::{CpuBackend, GpuBackend, Quality};

use crate::arrays::RayArrays;
use crate::hits::{FreshHits, HitArrays, Hits};
use rayon::prelude::*;
use treelet::internals::input::zeroed_vec;
use crate::py_err;

/// A tracer `G` on a GPU (with its adapter's name), or `C` on the CPU runner.
pub(crate) enum OnDevice<G, C> {
    Gpu(GpuBackend, G, String),
    Cpu(CpuBackend, C),
}

/// Runs `$body` with the backend `$b` and tracer `$t` of an [`OnDevice`],
/// the GIL released while a GPU works (the CPU runner's buffers stay on the
/// thread that holds the GIL: it works with the GIL held).
macro_rules! on_device {
    ($inner:expr, $py:expr, |$b:ident, $t:ident| $body:expr) => {
        match $inner {
            $crate::device::OnDevice::Gpu($b, $t, _) => $py.allow_threads(|| $body),
            $crate::device::OnDevice::Cpu($b, $t) => $body,
        }
    };
}
pub(crate) use on_device;

/// `quality` as the library takes it.
pub(crate) fn quality(quality: &str) -> PyResult<Quality> {
    match quality {
        "fast" => Ok(Quality::Fast),
        "balanced" => Ok(Quality::Balanced),
        "high" => Ok(Quality::High),
        other => Err(PyValueError::new_err(format!("quality `{other}`: use fast, balanced or high"))),
    }
}

/// A backend of `device`: "auto" (the first GPU, else the CPU runner),
/// "gpu" (a Vulkan adapter, or an error) or "cpu" (the CPU runner).
pub(crate) fn open(device: &str) -> PyResult<OnDevice<(), ()>> {
    let choice = match device {
        "auto" => DeviceChoice::Auto,
        "gpu" => DeviceChoice::Gpu,
        "cpu" => DeviceChoice::Cpu,
        other => return Err(PyValueError::new_err(format!("device `{other}`: use auto, gpu or cpu"))),
    };
    let (opened, _note) = choice.open_with_note().map_err(|e| PyRuntimeError::new_err(format!("{e:#}")))?;
    Ok(match opened {
        Device::Gpu(ctx) => {
            let name = ctx.info.name.clone();
            OnDevice::Gpu(GpuBackend::new(ctx), (), name)
        }
        Device::Cpu => OnDevice::Cpu(CpuBackend::new(), ()),
    })
}

/// Opens `device` (as [`open`]) and builds on it, by `gpu` or `cpu`.
pub(crate) fn build<G, C>(
    device: &str,
    gpu: impl FnOnce(&mut GpuBackend) -> treelet::error::Result<G>,
    cpu: impl FnOnce(&mut CpuBackend) -> treelet::error::Result<C>,
) -> PyResult<OnDevice<G, C>> {
    Ok(match open(device)? {
        OnDevice::Gpu(mut b, (), name) => {
            let tracer = gpu(&mut b).map_err(py_err)?;
            OnDevice::Gpu(b, tracer, name)
        }
        OnDevice::Cpu(mut b, ()) => {
            let tracer = cpu(&mut b).map_err(py_err)?;
            OnDevice::Cpu(b, tracer)
        }
    })
}

impl<G, C> OnDevice<G, C>
where
    G: RayQueries<GpuBackend> + Sync,
    C: RayQueries<CpuBackend>,
{
    /// The device's name: the adapter's, or "cpu".
    pub(crate) fn name(&self) -> String {
        match self {
            OnDevice::Gpu(_, _, name) => name.clone(),
            OnDevice::Cpu(..) => "cpu".into(),
        }
    }

    /// The closest hits of the rays in the arrays: new arrays, or those of
    /// `out` (a [`Hits`] of as many rays, from an earlier call) written in
    /// place and handed back.
    pub(crate) fn closest_hits(&mut self, py: Python<'_>, arrays: &RayArrays<'_>, out: Option<&Bound<'_, Hits>>) -> PyResult<Py<Hits>> {
        let rays = arrays.columns()?;
        let Some(out) = out else {
            let mut fresh = FreshHits::new(rays.len())?;
            let into = fresh.slices();
            let filled = on_device!(self, py, |b, t| t.closest_hits_batch(b, rays.len(), |k| rays.ray(k), |hits| into.fill(hits))).map_err(py_err)?;
            return Py::new(py, fresh.into_hits(py, filled));
        };
        let mut held = HitArrays::borrow(py, out, rays.len())?;
        let into = held.slices()?;
        on_device!(self, py, |b, t| t.closest_hits_batch(b, rays.len(), |k| rays.ray(k), |hits| into.fill(hits))).map_err(py_err)?;
        drop(held);
        Ok(out.clone().unbind())
    }

    /// Whether each ray of the arrays is occluded.
    pub(crate) fn occluded<'py>(&mut self, py: Python<'py>, arrays: &RayArrays<'_>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let rays = arrays.columns()?;
        let mut hit = zeroed_vec::<bool>(rays.len(), "occluded").map_err(|e| pyo3::exceptions::PyMemoryError::new_err(format!("{e:#}")))?;
        on_device!(self, py, |b, t| t.occluded_batch(b, rays.len(), |k| rays.ray(k), |answers| {
            hit.par_iter_mut().enumerate().for_each(|(k, h)| *h = answers.get(k))
        }))
        .map_err(py_err)?;
        Ok(hit.into_pyarray(py))
    }
}
