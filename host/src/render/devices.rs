//! One render on several devices at once: every Vulkan adapter of the
//! machine and the CPU runner. Each device prepares its own copy of the
//! scene ([`Prepared`]), then takes chunks of samples from a shared queue
//! as it finishes the last, so a fast GPU takes most and a slow device still
//! helps. A device reads back its sums after each chunk; one that fails
//! loses only its unfinished chunk, which goes back to the queue for the
//! others. The host adds the devices' sums. Treelet's random numbers are
//! counted from (seed, pixel, sample), so the image is the one-device image
//! up to the devices' rounding.
use std::ops::Range;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde::Serialize;

use super::image_io::HdrImage;
use super::{add_sums, mean_image, Prepared, RenderSettings};
use crate::runtime::backend::Backend;
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

/// Sample ranges handed out to devices as they ask; ranges a failed
/// device gave back go out first. A device leaves only when no range is
/// left and none is being rendered (one may yet come back).
pub struct SampleQueue {
    /// Next sample, ranges given back, ranges out.
    state: Mutex<(u32, Vec<Range<u32>>, u32)>,
    end: u32,
    devices: u32,
}

/// What a device asking the queue gets.
pub enum Take {
    Range(Range<u32>),
    /// Nothing now, but a range out may come back: ask again.
    Wait,
    Done,
}

impl SampleQueue {
    /// The queue of `samples` for `devices` devices.
    pub fn new(samples: Range<u32>, devices: u32) -> Self {
        SampleQueue { state: Mutex::new((samples.start, Vec::new(), 0)), end: samples.end, devices: devices.max(1) }
    }

    /// Up to `want` samples (at least one; at most half of a fair share of
    /// what is left, so that the end is shared too), or a range given back
    /// whole.
    pub fn take(&self, want: u32) -> Take {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = s.1.pop() {
            s.2 += 1;
            return Take::Range(r);
        }
        let start = s.0;
        if start >= self.end {
            return if s.2 > 0 { Take::Wait } else { Take::Done };
        }
        let fair = ((self.end - start) / (2 * self.devices)).max(1);
        s.0 = start.saturating_add(want.clamp(1, fair)).min(self.end);
        s.2 += 1;
        Take::Range(start..s.0)
    }

    /// A range taken is rendered.
    pub fn finished(&self) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).2 -= 1;
    }

    /// A range taken is not rendered: another device takes it.
    pub fn give_back(&self, r: Range<u32>) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        s.1.push(r);
        s.2 -= 1;
    }
}

/// Seconds of work a device takes at a time.
const CHUNK_S: f64 = 0.25;

/// What one device did.
#[derive(Clone, Debug, Serialize)]
pub struct Share {
    pub device: String,
    /// Samples per pixel it rendered.
    pub samples: u32,
    pub chunks: u32,
    /// Wall seconds from its start to its last chunk.
    pub seconds: f64,
    /// Its rate: camera paths per second.
    pub paths_per_s: f64,
    /// Why it stopped early, if it did (its unfinished chunk went to the others).
    pub failed: Option<String>,
}

/// A failure injected for tests: device `device` fails when it takes its
/// chunk number `chunk` (from 0).
#[derive(Clone, Copy, Debug)]
pub struct InjectedFailure {
    pub device: usize,
    pub chunk: u32,
}

/// Renders `settings.first_sample ..+ settings.spp` of `scene` on `devices`;
/// returns the image, the sums and each device's share.
pub fn render_on_devices(
    devices: &[Device],
    scene: &Scene,
    settings: &RenderSettings,
    inject: Option<InjectedFailure>,
) -> Result<(HdrImage, Vec<[f32; 4]>, Vec<Share>)> {
    let first = settings.first_sample;
    let end = first.checked_add(settings.spp).context("the sample index must stay below 2^32")?;
    let queue = SampleQueue::new(first..end, devices.len() as u32);
    let pixels = (settings.width * settings.height) as usize;
    let gpus = devices.iter().filter(|d| matches!(d, Device::Gpu(_))).count();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu_threads = cores.saturating_sub(gpus).max(1);
    let results: Vec<(Share, Vec<[f64; 4]>)> = std::thread::scope(|s| {
        let handles: Vec<_> = devices
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let (queue, inject) = (&queue, inject.filter(|f| f.device == i));
                s.spawn(move || match d {
                    Device::Gpu(ctx) => share(&mut GpuBackend::new(ctx.clone()), d.name(), scene, settings, queue, inject, pixels),
                    // A core left to each GPU's thread: measured on the H100 host, a CPU
                    // runner on all 16 cores slowed the GPU's submissions more than it helped.
                    Device::Cpu => match rayon::ThreadPoolBuilder::new().num_threads(cpu_threads).build() {
                        Ok(pool) => pool.install(|| share(&mut CpuBackend::new(), d.name(), scene, settings, queue, inject, pixels)),
                        Err(_) => share(&mut CpuBackend::new(), d.name(), scene, settings, queue, inject, pixels),
                    },
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("a device thread panicked")).collect()
    });
    let done: u32 = results.iter().map(|r| r.0.samples).sum();
    if done != settings.spp {
        let why: Vec<String> = results.iter().filter_map(|r| r.0.failed.as_ref().map(|f| format!("{}: {f}", r.0.device))).collect();
        bail!("{done} of {} samples rendered: every device failed ({})", settings.spp, why.join("; "));
    }
    let mut total = vec![[0f64; 4]; pixels];
    for (_, sums) in &results {
        add_sums(&mut total, sums);
    }
    let sums: Vec<[f32; 4]> = total.iter().map(|t| t.map(|v| v as f32)).collect();
    let image = mean_image(settings.width, settings.height, &total, settings.spp);
    Ok((image, sums, results.into_iter().map(|r| r.0).collect()))
}

/// One device's loop: prepare, then chunks until the queue is empty.
fn share<B: Backend>(
    b: &mut B,
    device: String,
    scene: &Scene,
    settings: &RenderSettings,
    queue: &SampleQueue,
    inject: Option<InjectedFailure>,
    pixels: usize,
) -> (Share, Vec<[f64; 4]>) {
    let start = Instant::now();
    let mut sums = vec![[0f64; 4]; pixels];
    let mut share = Share { device, samples: 0, chunks: 0, seconds: 0.0, paths_per_s: 0.0, failed: None };
    let prepared = match Prepared::new(b, scene, settings) {
        Ok(p) => p,
        Err(e) => {
            share.failed = Some(format!("{e:#}"));
            return (share, sums);
        }
    };
    // Chunks are sized by the device's own rate, to take about CHUNK_S
    // each: a slow device never holds a large chunk at the end, and a fast
    // one reads back seldom. The first chunk, one sample, measures the rate.
    let mut want = 1u32;
    loop {
        let range = match queue.take(want) {
            Take::Range(r) => r,
            Take::Wait => {
                std::thread::sleep(std::time::Duration::from_millis(2));
                continue;
            }
            Take::Done => break,
        };
        if inject.is_some_and(|f| f.chunk == share.chunks) {
            queue.give_back(range);
            share.failed = Some("injected failure".into());
            break;
        }
        let chunk_start = Instant::now();
        let chunk = (|| -> Result<Vec<[f32; 4]>> {
            prepared.clear(b)?;
            prepared.dispatch_samples(b, range.start, range.end - range.start)?;
            prepared.read_sums(b)
        })();
        match chunk {
            Ok(s) => {
                add_sums(&mut sums, &s);
                queue.finished();
                share.samples += range.end - range.start;
                share.chunks += 1;
                let rate = (range.end - range.start) as f64 / chunk_start.elapsed().as_secs_f64().max(1e-6);
                want = (rate * CHUNK_S).clamp(1.0, 4096.0) as u32;
            }
            Err(e) => {
                queue.give_back(range);
                share.failed = Some(format!("{e:#}"));
                break;
            }
        }
    }
    share.seconds = start.elapsed().as_secs_f64();
    share.paths_per_s = share.samples as f64 * pixels as f64 / share.seconds.max(1e-9);
    (share, sums)
}
