//! The GPU [`Backend`]: dispatches are recorded per stage and submitted when
//! a result is read. Each stage becomes one compute pass, timed with
//! timestamp queries where the adapter has them (otherwise each stage is
//! submitted alone and timed by the wall clock around its completion).
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};
use bytemuck::Pod;
use treelet_core::gpu::workgroup::dispatch_grid;

use super::context::GpuContext;
use crate::runtime::backend::{Backend, StageTimes};
use crate::runtime::kernels::Kernel;

/// Readbacks are copied in pieces no larger than this.
const READBACK_CHUNK: u64 = 64 << 20;
/// Every buffer has at least this many bytes (wgpu rejects empty bindings).
const MIN_BUFFER: u64 = 16;
/// Largest upload or read-back staging buffer kept for the next call
/// (`upload_with`, `read_with`): an engine's batches of a million rays are
/// 32 MB each way, and fresh host memory for each cost more than the copies
/// (first touches of new pages: 45-70 ms a million rays on the H200's host,
/// against about 1 ms of tracing). Larger ones are made for the call alone.
const STAGING_KEEP: u64 = 256 << 20;

struct Dispatch {
    kernel: Kernel,
    bind_group: wgpu::BindGroup,
    grid: [u32; 2],
}

struct Segment {
    stage: &'static str,
    dispatches: Vec<Dispatch>,
}

/// Buffers are pooled by label and size, so repeated builds of one scene
/// size allocate nothing after the first.
type PoolKey = (&'static str, u64);

pub struct GpuBackend {
    ctx: Arc<GpuContext>,
    /// Buffers of the previous build, free to hand out again.
    free: std::collections::HashMap<PoolKey, Vec<wgpu::Buffer>>,
    /// Buffers handed out since the last `begin_build`.
    used: Vec<(PoolKey, wgpu::Buffer)>,
    /// Time each dispatch alone, under its kernel's name (profiling).
    per_kernel: bool,
    /// Device memory this backend may use, below what the adapter reports.
    memory_cap: Option<u64>,
    stage: &'static str,
    pending: Vec<Segment>,
    times: StageTimes,
    /// Where buffers bound in two parts are split (bytes; tests set it
    /// small, see [`GpuBackend::with_split_bytes`]).
    split_bytes: u64,
    /// The second part of a binding whose buffer fits the first (never
    /// read): one for read-only bindings, one for writable ones (wgpu
    /// forbids one buffer in both uses within a dispatch).
    unused_parts: [wgpu::Buffer; 2],
    /// A dispatch that could not be bound, reported by the next wait.
    error: Option<anyhow::Error>,
    /// Staging kept between `upload_with` calls (MAP_WRITE) and between
    /// `read_with` calls (MAP_READ), up to [`STAGING_KEEP`] bytes each.
    staging: [Option<wgpu::Buffer>; 2],
}

impl GpuBackend {
    pub fn new(ctx: Arc<GpuContext>) -> Self {
        let unused_part = |label| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: crate::runtime::gpu::context::SPLIT_UNIT,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        Self {
            split_bytes: ctx.split_bytes(),
            unused_parts: [unused_part("unused second part (read)"), unused_part("unused second part (write)")],
            error: None,
            staging: [None, None],
            ctx,
            free: Default::default(),
            used: Vec::new(),
            per_kernel: false,
            memory_cap: None,
            stage: "unnamed",
            pending: Vec::new(),
            times: StageTimes::default(),
        }
    }

    /// Times every dispatch in its own pass, named by its entry point,
    /// instead of one pass per stage. Adds a little overhead per dispatch.
    pub fn with_per_kernel_times(mut self, on: bool) -> Self {
        self.per_kernel = on;
        self
    }

    /// Uses at most `bytes` of device memory (a GPU shared with an engine's
    /// own work): renders that need more are refused as if the adapter had
    /// no more.
    pub fn with_device_memory_cap(mut self, bytes: u64) -> Self {
        self.memory_cap = Some(bytes);
        self
    }

    /// Splits buffers bound in two parts after `bytes` (a multiple of
    /// [`crate::runtime::gpu::context::SPLIT_UNIT`], at most the device's
    /// own split) instead of only those past one binding's limit: how the
    /// tests run both parts of every split kernel on small scenes.
    pub fn with_split_bytes(mut self, bytes: u64) -> Self {
        let unit = crate::runtime::gpu::context::SPLIT_UNIT;
        self.split_bytes = (bytes / unit * unit).clamp(unit, self.ctx.split_bytes());
        self
    }

    /// Bytes of the buffers the pool holds (handed out since the last
    /// build, and free to hand out again).
    pub fn pooled_bytes(&self) -> u64 {
        self.used.iter().map(|(k, _)| k.1).sum::<u64>() + self.free.iter().map(|(k, v)| k.1 * v.len() as u64).sum::<u64>()
    }

    /// Submits the kernels recorded so far to the device's queue and waits
    /// for them (their stage times are kept for the next `take_times`). An
    /// engine sharing the device calls it before submitting work of its own
    /// that reads what they wrote: dispatches such as
    /// `Tracer::closest_hits_on_device` are recorded, and submitted only at
    /// such a flush (this, a read, `take_times`).
    pub fn submit(&mut self) -> Result<()> {
        self.flush()
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.ctx
    }

    fn encode_segment(&self, encoder: &mut wgpu::CommandEncoder, seg: &Segment, ts: Option<(&wgpu::QuerySet, u32)>) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(seg.stage),
            timestamp_writes: ts.map(|(query_set, i)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(2 * i),
                end_of_pass_write_index: Some(2 * i + 1),
            }),
        });
        for d in &seg.dispatches {
            pass.set_pipeline(&self.ctx.pipeline(d.kernel).pipeline);
            pass.set_bind_group(0, &d.bind_group, &[]);
            pass.dispatch_workgroups(d.grid[0], d.grid[1], 1);
        }
    }

    /// A storage buffer of exactly `size` bytes, from the pool if one is free.
    fn take_buffer(&mut self, label: &'static str, size: u64) -> wgpu::Buffer {
        let key = (label, size);
        let buffer = self.free.get_mut(&key).and_then(Vec::pop).unwrap_or_else(|| {
            self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        self.used.push((key, buffer.clone()));
        buffer
    }

    /// A staging buffer of at least `size` bytes for writing (`write`) or
    /// reading, the kept one where it is large enough.
    fn staging(&mut self, write: bool, size: u64) -> wgpu::Buffer {
        let slot = &mut self.staging[write as usize];
        if let Some(b) = slot.as_ref().filter(|b| b.size() >= size) {
            return b.clone();
        }
        let usage = if write {
            wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC
        } else {
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST
        };
        let label = if write { "upload staging" } else { "read-back staging" };
        let buffer = self.ctx.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false });
        if size <= STAGING_KEEP {
            *slot = Some(buffer.clone());
        }
        buffer
    }

    /// Maps `0..bytes` of a staging buffer once the work before it is done.
    fn map(&self, staging: &wgpu::Buffer, mode: wgpu::MapMode, bytes: u64) -> Result<()> {
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(mode, 0..bytes, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv().context("map callback lost")?.context("could not map a staging buffer")?;
        Ok(())
    }

    fn wait(&self) -> Result<()> {
        self.ctx.device.poll(wgpu::PollType::wait_indefinitely()).context("GPU did not finish its work")?;
        Ok(())
    }

    /// Submits every recorded dispatch and waits; adds their stage times.
    fn flush(&mut self) -> Result<()> {
        if let Some(e) = self.error.take() {
            self.pending.clear();
            return Err(e);
        }
        let segments = std::mem::take(&mut self.pending);
        if segments.is_empty() {
            return Ok(());
        }
        let device = &self.ctx.device;
        if !self.ctx.timestamps {
            for seg in &segments {
                let start = Instant::now();
                let mut encoder = device.create_command_encoder(&Default::default());
                self.encode_segment(&mut encoder, seg, None);
                self.ctx.queue.submit([encoder.finish()]);
                self.wait()?;
                self.times.add(seg.stage, start.elapsed().as_secs_f64() * 1e3);
            }
            self.times.source = "wall-clock";
            return Ok(());
        }
        let count = 2 * segments.len() as u32;
        let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("stage timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let bytes = count as u64 * 8;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        for (i, seg) in segments.iter().enumerate() {
            self.encode_segment(&mut encoder, seg, Some((&query_set, i as u32)));
        }
        encoder.resolve_query_set(&query_set, 0..count, &resolve, 0);
        encoder.copy_buffer_to_buffer(&resolve, 0, &staging, 0, bytes);
        self.ctx.queue.submit([encoder.finish()]);
        let ticks: Vec<u64> = self.map_read(&staging, bytes)?;
        let period_ns = self.ctx.queue.get_timestamp_period() as f64;
        for (i, seg) in segments.iter().enumerate() {
            let ticks = ticks[2 * i + 1].saturating_sub(ticks[2 * i]);
            self.times.add(seg.stage, ticks as f64 * period_ns / 1e6);
        }
        self.times.source = "gpu-timestamps";
        Ok(())
    }

    /// Maps a MAP_READ buffer (after its copy was submitted) and returns its contents.
    fn map_read<T: Pod>(&self, staging: &wgpu::Buffer, bytes: u64) -> Result<Vec<T>> {
        let mut out: Vec<T> = bytemuck::zeroed_vec(bytes as usize / std::mem::size_of::<T>());
        self.map_into(staging, bytes, bytemuck::cast_slice_mut(&mut out))?;
        Ok(out)
    }

    /// Maps a MAP_READ buffer of `bytes` (after its copy was submitted) and
    /// copies its first `into.len()` bytes into `into`.
    fn map_into(&self, staging: &wgpu::Buffer, bytes: u64, into: &mut [u8]) -> Result<()> {
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, 0..bytes, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv().context("readback callback lost")?.context("could not map a readback buffer")?;
        into.copy_from_slice(&staging.get_mapped_range(0..bytes)?[..into.len()]);
        staging.unmap();
        Ok(())
    }
}

/// Bytes made in cached memory before each copy into mapped memory.
const MAPPED_CHUNK: usize = 64 << 10;

/// Writes `item(k)`, `k < len`, into mapped memory of `len` elements'
/// bytes. Made a chunk at a time in cached memory and copied whole, chunks
/// in parallel: mapped upload memory is write-combined or the device's own,
/// over the bus, and element-by-element writes into it from one thread ran
/// at 1.5 GB/s on the H200's host (a million rays' 32 MB in 21 ms).
fn write_items<T: Pod + Send>(data: wgpu::WriteOnly<'_, [u8]>, len: usize, item: impl Fn(usize) -> Result<T> + Sync) -> Result<()> {
    use rayon::prelude::*;
    let size = std::mem::size_of::<T>();
    if size == 0 {
        return Ok(());
    }
    // The bytes from `start` on, from the items that span them.
    let fill = |start: usize, mut out: wgpu::WriteOnly<'_, [u8]>| -> Result<()> {
        let end = start + out.len();
        let (first, last) = (start / size, end.div_ceil(size).min(len));
        let items = (first..last).map(&item).collect::<Result<Vec<T>>>()?;
        let bytes: &[u8] = bytemuck::cast_slice(&items);
        out.copy_from_slice(&bytes[start - first * size..end - first * size]);
        Ok(())
    };
    let (chunks, tail) = data.into_chunks::<MAPPED_CHUNK>();
    let chunks: Vec<wgpu::WriteOnly<'_, [u8; MAPPED_CHUNK]>> = chunks.into_iter().collect();
    let whole = chunks.len() * MAPPED_CHUNK;
    let written = chunks
        .into_par_iter()
        .enumerate()
        .try_for_each(|(c, chunk)| fill(c * MAPPED_CHUNK, chunk.into()))
        .and_then(|()| fill(whole, tail));
    // Which failing chunk reports first varies: the first failing item, as
    // a sequential upload would have found it.
    written.map_err(|e| (0..len).find_map(|k| item(k).err()).unwrap_or(e))
}

impl Backend for GpuBackend {
    type Buffer = wgpu::Buffer;

    fn adapter(&self) -> String {
        self.ctx.info.name.clone()
    }
    fn buffer_bytes(&self, buffer: &wgpu::Buffer) -> u64 {
        buffer.size()
    }
    fn same_buffer(&self, a: &wgpu::Buffer, b: &wgpu::Buffer) -> bool {
        a == b
    }
    fn device_kind(&self) -> &'static str {
        "gpu"
    }
    fn runs_on_cpu(&self) -> bool {
        self.ctx.info.device_type == wgpu::DeviceType::Cpu
    }
    fn ordered_atomics_in_divergent_flow(&self) -> bool {
        self.ctx.info.device_type != wgpu::DeviceType::Cpu
    }
    fn look_back_works(&self) -> bool {
        // TREELET_SORT_LOOK_BACK=0 forces the sort without look-back (to measure it).
        self.ctx.info.device_type != wgpu::DeviceType::Cpu
            && crate::tuning::Tuning::current().sort_look_back
    }
    fn min_subgroup_size(&self) -> u32 {
        // Vulkan's minSubgroupSize (subgroup size control, core in 1.3);
        // wgpu reports 4 where the device does not say.
        self.ctx.info.subgroup_min_size
    }
    fn subgroup_partitioned(&self) -> bool {
        // TREELET_SORT_MATCH=ballots keeps the ballots (to measure).
        self.ctx.subgroup_partitioned && !crate::tuning::Tuning::current().sort_match_ballots
    }
    fn max_buffer_bytes(&self) -> u64 {
        self.ctx.max_buffer_bytes()
    }
    fn max_binding_bytes(&self) -> u64 {
        self.ctx.max_binding_bytes()
    }
    fn device_memory_bytes(&self) -> Option<u64> {
        match (self.ctx.device_memory, self.memory_cap) {
            (Some(heap), Some(cap)) => Some(heap.min(cap)),
            (heap, cap) => heap.or(cap),
        }
    }
    fn prepare_kernels(&mut self, kernels: &[Kernel]) -> f64 {
        let own = crate::runtime::backend::BackendKernels::of(self).all();
        self.ctx.prepare(&[kernels, &own].concat())
    }

    fn upload<T: Pod>(&mut self, label: &'static str, data: &[T]) -> Result<wgpu::Buffer> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        crate::runtime::backend::check_fits(self, label, bytes.len() as u64)?;
        let size = (bytes.len() as u64).max(MIN_BUFFER).next_multiple_of(4);
        let buffer = self.take_buffer(label, size);
        // Staged by the queue and copied before the next submission, which
        // holds every dispatch recorded so far.
        if bytes.len().is_multiple_of(4) {
            self.ctx.queue.write_buffer(&buffer, 0, bytes);
        } else {
            let mut padded = bytes.to_vec();
            padded.resize(bytes.len().next_multiple_of(4), 0);
            self.ctx.queue.write_buffer(&buffer, 0, &padded);
        }
        Ok(buffer)
    }

    fn upload_indexed<T: Pod + Send>(&mut self, label: &'static str, len: usize, item: impl Fn(usize) -> Result<T> + Sync) -> Result<wgpu::Buffer> {
        let bytes = (len as u64).checked_mul(std::mem::size_of::<T>() as u64).unwrap_or(u64::MAX);
        crate::runtime::backend::check_fits(self, label, bytes)?;
        let size = bytes.max(MIN_BUFFER).next_multiple_of(8);
        let staging = self.staging(true, size);
        self.map(&staging, wgpu::MapMode::Write, size)?;
        let written = {
            let mut view = staging.get_mapped_range_mut(0..size)?;
            let (data, mut padding) = view.slice(..).split_at(bytes as usize);
            padding.fill(0);
            write_items(data, len, item)
        };
        staging.unmap();
        written?;
        let buffer = self.take_buffer(label, size);
        // Submitted now, so before every dispatch recorded so far, as the
        // queue's own writes are (the buffer is new to them).
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&staging, 0, &buffer, 0, size);
        self.ctx.queue.submit([encoder.finish()]);
        Ok(buffer)
    }

    fn read_with<T: Pod, R>(&mut self, buffer: &wgpu::Buffer, count: usize, take: impl FnOnce(&[T]) -> R) -> Result<R> {
        let total = (count as u64).checked_mul(std::mem::size_of::<T>() as u64).unwrap_or(u64::MAX);
        if total > STAGING_KEEP.min(buffer.size()) || total == 0 {
            return Ok(take(&self.read(buffer, count)?));
        }
        self.flush()?;
        let padded = total.next_multiple_of(4);
        let staging = self.staging(false, padded);
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, padded);
        self.ctx.queue.submit([encoder.finish()]);
        self.map(&staging, wgpu::MapMode::Read, padded)?;
        let out = {
            let view = staging.get_mapped_range(0..padded)?;
            match bytemuck::try_cast_slice::<u8, T>(&view[..total as usize]) {
                Ok(data) => take(data),
                Err(_) => take(&bytemuck::pod_collect_to_vec::<u8, T>(&view[..total as usize])),
            }
        };
        staging.unmap();
        Ok(out)
    }

    fn scratch(&mut self, label: &'static str, bytes: u64) -> Result<wgpu::Buffer> {
        crate::runtime::backend::check_fits(self, label, bytes)?;
        Ok(self.take_buffer(label, bytes.max(MIN_BUFFER).next_multiple_of(4)))
    }

    fn keep(&mut self, buffers: &[&wgpu::Buffer]) {
        self.used.retain(|(_, b)| !buffers.contains(&b));
        for list in self.free.values_mut() {
            list.retain(|b| !buffers.contains(&b));
        }
    }

    fn release(&mut self, buffers: &[&wgpu::Buffer]) {
        for b in buffers {
            if let Some(i) = self.used.iter().position(|(_, u)| u == *b) {
                let (key, buffer) = self.used.swap_remove(i);
                self.free.entry(key).or_default().push(buffer);
            }
        }
    }

    fn begin_build(&mut self) {
        self.free.clear();
        for (key, buffer) in self.used.drain(..) {
            self.free.entry(key).or_default().push(buffer);
        }
    }

    fn stage(&mut self, stage: &'static str) {
        self.stage = stage;
    }

    fn dispatch_listed(&mut self, kernel: Kernel, bindings: &[&wgpu::Buffer], groups: u32) {
        assert_eq!(bindings.len(), kernel.bindings().len(), "{kernel:?}: wrong number of bindings");
        if groups == 0 {
            return;
        }
        // Buffers past `split_bytes` are bound in two parts where the kernel
        // reads them so (`Kernel::split_bindings`), else whole.
        let split = kernel.split_bindings();
        let mut entries: Vec<_> = Vec::with_capacity(bindings.len() + split.len());
        for (i, b) in bindings.iter().enumerate() {
            let resource = if split.contains(&i) && b.size() > self.split_bytes {
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: b,
                    offset: 0,
                    size: std::num::NonZeroU64::new(self.split_bytes),
                })
            } else if b.size() > self.ctx.max_binding_bytes() {
                self.error.get_or_insert_with(|| {
                    crate::error::too_large(format!(
                        "scene too large for this device: `{}` binds a buffer of {} bytes whole, the adapter `{}` \
                         allows {} bytes per binding (the builds, the bvh2 layout and its traversal split large buffers; cwbvh does not yet)",
                        kernel.entry_point(),
                        b.size(),
                        self.ctx.info.name,
                        self.ctx.max_binding_bytes()
                    ))
                });
                return;
            } else {
                b.as_entire_binding()
            };
            entries.push(wgpu::BindGroupEntry { binding: i as u32, resource });
        }
        for (k, &i) in split.iter().enumerate() {
            let b = bindings[i];
            let resource = if b.size() > self.split_bytes {
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: b,
                    offset: self.split_bytes,
                    size: std::num::NonZeroU64::new(b.size() - self.split_bytes),
                })
            } else {
                let writes = kernel.bindings()[i] == crate::runtime::kernels::Access::ReadWrite;
                self.unused_parts[writes as usize].as_entire_binding()
            };
            entries.push(wgpu::BindGroupEntry { binding: (bindings.len() + k) as u32, resource });
        }
        let bind_group = self.ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(kernel.entry_point()),
            layout: &self.ctx.pipeline(kernel).layout,
            entries: &entries,
        });
        let dispatch = Dispatch { kernel, bind_group, grid: dispatch_grid(groups) };
        if self.per_kernel {
            self.pending.push(Segment { stage: kernel.entry_point(), dispatches: vec![dispatch] });
            return;
        }
        match self.pending.last_mut() {
            Some(seg) if seg.stage == self.stage => seg.dispatches.push(dispatch),
            _ => self.pending.push(Segment { stage: self.stage, dispatches: vec![dispatch] }),
        }
    }

    fn read<T: Pod>(&mut self, buffer: &wgpu::Buffer, count: usize) -> Result<Vec<T>> {
        self.flush()?;
        let total = (count * std::mem::size_of::<T>()) as u64;
        // Mapped bytes are copied once, straight into the result (a render's
        // sums are tens of MB, and every copy is on the way to the image).
        let mut out: Vec<T> = crate::internals::input::zeroed_vec(count, "a buffer read back from the device")?;
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut out);
        let mut offset = 0;
        while offset < total {
            let len = (total - offset).min(READBACK_CHUNK);
            let padded = len.next_multiple_of(4);
            let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("readback"),
                size: padded,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, padded);
            self.ctx.queue.submit([encoder.finish()]);
            self.map_into(&staging, padded, &mut bytes[offset as usize..(offset + len) as usize])?;
            offset += len;
        }
        Ok(out)
    }

    fn take_times(&mut self) -> Result<StageTimes> {
        self.flush()?;
        Ok(std::mem::take(&mut self.times))
    }
}
