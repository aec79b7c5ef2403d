//! Device choice, in one place: what the command line, the benchmarks and a
//! render over several devices ask for ([`DeviceChoice`]), and what opening
//! it gives ([`Device`]): a Vulkan adapter's context or the CPU runner.
//! [`with_backend!`](crate::with_backend) runs one piece of code on either.
use std::sync::Arc;

use anyhow::{Context, Result};

use crate::runtime::gpu::GpuContext;

/// Where work runs (`--device`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum DeviceChoice {
    /// The first GPU; the CPU runner when there is none (a Vulkan adapter
    /// on CPU cores, such as lavapipe, is slower than the CPU runner there).
    Auto,
    /// A Vulkan adapter (a GPU, or lavapipe on CPU cores); an error when there is none.
    Gpu,
    /// The CPU runner: the same kernels over every invocation id, with rayon.
    Cpu,
}

impl DeviceChoice {
    /// Opens the device: `auto` falls back to the CPU runner with a note
    /// (printed) that says why (no adapter, or only adapters on CPU cores).
    pub fn open(self) -> Result<Device> {
        let (device, note) = self.open_with_note()?;
        if let Some(note) = note {
            eprintln!("{note}");
        }
        Ok(device)
    }

    /// [`DeviceChoice::open`], with the note returned instead of printed
    /// (for a caller that opens devices on another thread and prints once
    /// it knows the run goes on).
    pub fn open_with_note(self) -> Result<(Device, Option<String>)> {
        match self {
            DeviceChoice::Gpu => Ok((
                Device::Gpu(GpuContext::new().context("--device gpu (--device auto or cpu run on the CPU runner)")?),
                None,
            )),
            DeviceChoice::Cpu => Ok((Device::Cpu, None)),
            DeviceChoice::Auto => {
                if let Some(&gpu) = GpuContext::gpu_adapters().first() {
                    return Ok(match GpuContext::with_adapter(gpu) {
                        Ok(ctx) => (Device::Gpu(ctx), None),
                        Err(e) => (
                            Device::Cpu,
                            Some(format!("note: {e:#}: running on the CPU runner instead (--device cpu skips this note)")),
                        ),
                    });
                }
                let adapters = GpuContext::adapters();
                let note = if adapters.is_empty() {
                    // GpuContext's own message: it says what is missing and how to get it.
                    let e = GpuContext::new().err().map_or_else(|| "no Vulkan adapter found".to_string(), |e| e.to_string());
                    format!("note: {e}: running on the CPU runner instead (--device cpu skips this note)")
                } else {
                    // On two cores the CPU runner rendered cornell 512x384 at
                    // 64 spp in 10.8 s where lavapipe took 14.9 to 17.1 s, the
                    // disk-lit room (256x192, 16 spp) in 1.0 s against 4.9 s,
                    // and built a 200 000-sphere TRBVH in 1.4 s against 16.7 s.
                    format!(
                        "note: the only Vulkan adapter ({}) runs on CPU cores, where the CPU runner is faster: running on the CPU runner (--device gpu uses the adapter, --device cpu skips this note)",
                        adapters.join(", ")
                    )
                };
                Ok((Device::Cpu, Some(note)))
            }
        }
    }
}

/// An opened device: a Vulkan adapter (its context is made once and shared
/// by every backend made on it) or the CPU runner.
#[derive(Clone)]
pub enum Device {
    Gpu(Arc<GpuContext>),
    Cpu,
}

impl Device {
    /// The adapter's name, or `cpu`.
    pub fn name(&self) -> String {
        match self {
            Device::Gpu(ctx) => ctx.info.name.clone(),
            Device::Cpu => "cpu".into(),
        }
    }

    /// What kind of device it is (as its backend's `class()` says).
    pub fn class(&self) -> crate::runtime::backend::DeviceClass {
        use crate::runtime::backend::DeviceClass;
        match self {
            Device::Gpu(ctx) if ctx.info.device_type == wgpu::DeviceType::Cpu => DeviceClass::CpuAdapter,
            Device::Gpu(_) => DeviceClass::Gpu,
            Device::Cpu => DeviceClass::CpuRunner,
        }
    }
}

/// Runs `$body` with `$b` bound to a fresh backend on `$device` (a
/// [`Device`](crate::runtime::device::Device)): a `GpuBackend` on its
/// context, or a `CpuBackend`. The body is compiled once per backend.
#[macro_export]
macro_rules! with_backend {
    ($device:expr, |$b:ident| $body:expr) => {
        match $device {
            $crate::runtime::device::Device::Gpu(ctx) => {
                let $b = &mut $crate::runtime::gpu::GpuBackend::new(ctx.clone());
                $body
            }
            $crate::runtime::device::Device::Cpu => {
                let $b = &mut $crate::runtime::cpu_runner::CpuBackend::new();
                $body
            }
        }
    };
}
