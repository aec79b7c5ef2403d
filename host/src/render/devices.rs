//! A render on opened devices (`--device`, or several at once with
//! `--devices`: every Vulkan adapter of the machine and the CPU runner),
//! through the one render loop ([`super::run`]).
use anyhow::{bail, Context, Result};

use super::image_io::HdrImage;
use super::outcome::{PassRow, RenderResult};
use super::run::{device_loop, run, Control, Worker};
use super::settings::{samples_per_dispatch, MemoryEstimate, RenderSettings};
use crate::runtime::cpu_runner::CpuBackend;
pub use crate::runtime::device::Device;
use crate::runtime::gpu::{GpuBackend, GpuContext};
use crate::scene::Scene;

/// The devices `spec` names: `all` (every Vulkan adapter; the CPU runner
/// where there is none), `gpu` (every Vulkan adapter), or a comma list of adapter
/// indices (as `treelet render --devices list` prints them), adapter names
/// (or a part of one) and `cpu`.
pub fn open(spec: &str) -> Result<Vec<Device>> {
    let adapters = GpuContext::adapters();
    let gpu = |i: usize| -> Result<Device> { Ok(Device::Gpu(GpuContext::with_adapter(i)?)) };
    let mut out = Vec::new();
    for item in spec.split(',').map(str::trim) {
        match item {
            "all" | "gpu" => {
                for i in 0..adapters.len() {
                    out.push(gpu(i)?);
                }
                // The CPU runner only where there is no adapter. Measured: beside
                // lavapipe (the same cores) it made a 2-core machine's render 1.3x
                // slower than the CPU runner alone; beside the H100 it rendered 1%
                // of the samples and slowed the GPU's thread by 6 to 13%. `cpu` in a
                // list still adds it.
                if item == "all" && adapters.is_empty() {
                    out.push(Device::Cpu);
                }
            }
            "cpu" => out.push(Device::Cpu),
            // An empty name is part of every adapter's name: `--devices ,,`
            // opened adapter 0 three times.
            "" => bail!("--devices `{spec}`: an empty name in the list (name adapters by index or name, or use cpu, gpu, all)"),
            _ => {
                let index = match item.parse::<usize>() {
                    Ok(i) if i < adapters.len() => i,
                    Ok(i) => bail!("--devices: no adapter {i}; this machine has {}: {}", adapters.len(), adapters.join(", ")),
                    Err(_) => adapters.iter().position(|a| a.to_lowercase().contains(&item.to_lowercase())).with_context(|| {
                        format!("--devices: `{item}` names no adapter (this machine has: {}; or use cpu, gpu, all)", adapters.join(", "))
                    })?,
                };
                out.push(gpu(index)?);
            }
        }
    }
    if out.is_empty() {
        bail!("--devices `{spec}`: no device (no Vulkan adapter found; `cpu` is the CPU runner)");
    }
    Ok(out)
}

/// Renders `scene` on `devices` (one or several), steered by `control`;
/// `on_pass` sees each pass's row as it completes. The result may stop
/// short (see [`RenderResult::stopped`]).
pub fn render_on_devices(
    devices: &[Device],
    scene: &Scene,
    settings: &RenderSettings,
    reference: Option<&HdrImage>,
    control: Control<'_>,
    on_pass: impl FnMut(&PassRow),
) -> Result<RenderResult> {
    let classes: Vec<_> = devices.iter().map(Device::class).collect();
    let prims = scene.traced_primitives();
    MemoryEstimate::of(settings, prims, &classes).check(settings, prims)?;
    // Before the clock starts (see `prepare_pipelines`).
    for d in devices {
        if let Device::Gpu(ctx) = d {
            super::prepared::prepare_pipelines(&mut GpuBackend::new(ctx.clone()), scene, settings);
        }
    }
    let gpus = devices.iter().filter(|d| matches!(d, Device::Gpu(_))).count();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu_threads = cores.saturating_sub(gpus).max(1);
    let workers: Vec<(String, Worker<'_>)> = devices
        .iter()
        .map(|d| {
            let worker: Worker<'_> = match d {
                Device::Gpu(ctx) => Box::new(move |job| device_loop(&mut GpuBackend::new(ctx.clone()), job)),
                // Alone, the CPU runner takes every core. Beside GPUs, a core is left to
                // each GPU's thread: measured on the H100 host, a CPU runner on all 16
                // cores slowed the GPU's submissions more than it helped.
                Device::Cpu if devices.len() == 1 => Box::new(|job| device_loop(&mut CpuBackend::new(), job)),
                Device::Cpu => Box::new(move |job| match rayon::ThreadPoolBuilder::new().num_threads(cpu_threads).build() {
                    Ok(pool) => pool.install(|| device_loop(&mut CpuBackend::new(), job)),
                    Err(_) => device_loop(&mut CpuBackend::new(), job),
                }),
            };
            (d.name(), worker)
        })
        .collect();
    // One device cuts its chunks where its own dispatches end, so that a
    // resumed render repeats the dispatches of an uninterrupted one.
    let step = match devices {
        [d] => samples_per_dispatch(settings.width as u64 * settings.height as u64, d.class()),
        _ => 1,
    };
    run(workers, step, scene, settings, reference, control, on_pass)
}
