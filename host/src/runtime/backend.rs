//! What a build needs from a device: buffers, dispatches, readback and
//! per-stage times. The GPU ([`crate::runtime::gpu::GpuBackend`]) and the CPU
//! ([`crate::runtime::cpu_runner::CpuBackend`]) implement it, so the order of stages
//! of a build is written once ([`crate::bvh::lbvh`]).
use std::collections::BTreeMap;

use anyhow::Result;
use bytemuck::Pod;

use treelet_core::geometry::buffers::{CopyParams, FillParams};
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};

use crate::runtime::kernels::{bind, Bindings, Kernel};

/// The kernels a backend dispatches of its own, for [`Backend::zeroed`],
/// [`Backend::zero_words`] and [`Backend::copy_words`]: built ahead with
/// every list ([`Backend::prepare_kernels`]). A kernel set as
/// `crate::runtime::kernel_set` makes them, written out here, as that
/// module builds on this one.
#[derive(Clone, Copy, Debug)]
pub struct BackendKernels {
    pub fill: Kernel,
    pub copy: Kernel,
}

impl BackendKernels {
    /// The set as `_b` runs it.
    pub fn of<B: Backend + ?Sized>(_b: &B) -> Self {
        BackendKernels { fill: Kernel::Fill, copy: Kernel::CopyWords }
    }
    /// Both kernels, for building their pipelines ahead.
    pub fn all(&self) -> Vec<Kernel> {
        vec![self.fill, self.copy]
    }
}

/// Milliseconds per named stage, in the order the stages first ran.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct StageTimes {
    pub order: Vec<&'static str>,
    pub ms: BTreeMap<&'static str, f64>,
    /// How the times were taken: "gpu-timestamps", "wall-clock".
    pub source: &'static str,
}

impl StageTimes {
    pub fn add(&mut self, stage: &'static str, ms: f64) {
        if !self.ms.contains_key(stage) {
            self.order.push(stage);
        }
        *self.ms.entry(stage).or_insert(0.0) += ms;
    }
    pub fn total(&self) -> f64 {
        self.ms.values().sum()
    }
    pub fn get(&self, stage: &str) -> f64 {
        self.ms.get(stage).copied().unwrap_or(0.0)
    }
}

/// What kind of device runs the kernels: what is fastest differs (the
/// crossover of the scan, the traversal layout).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum DeviceClass {
    /// A GPU.
    Gpu,
    /// A Vulkan adapter that runs on CPU cores (lavapipe).
    CpuAdapter,
    /// The CPU runner.
    CpuRunner,
}

pub trait Backend: Send {
    /// A device buffer; cloning clones the handle, not the data.
    type Buffer: Clone;

    /// Adapter name ("cpu" for the CPU runner).
    fn adapter(&self) -> String;
    /// "gpu" or "cpu".
    fn device_kind(&self) -> &'static str;
    /// Whether the kernels run on CPU cores (the CPU runner, or a CPU
    /// Vulkan adapter such as lavapipe): what is fastest differs there.
    fn runs_on_cpu(&self) -> bool;
    /// What kind of device this is.
    fn class(&self) -> DeviceClass {
        match (self.device_kind(), self.runs_on_cpu()) {
            ("cpu", _) => DeviceClass::CpuRunner,
            (_, true) => DeviceClass::CpuAdapter,
            _ => DeviceClass::Gpu,
        }
    }
    /// False on devices that mis-execute ordered atomics in divergent control
    /// flow (lavapipe): they get the relaxed variants of such kernels.
    fn ordered_atomics_in_divergent_flow(&self) -> bool {
        true
    }
    /// `kernel` as this device runs it: its relaxed twin
    /// ([`Kernel::relaxed`]) where ordered atomics in divergent flow are
    /// not to be trusted, else itself.
    fn atomics_for(&self, kernel: Kernel) -> Kernel {
        if self.ordered_atomics_in_divergent_flow() { kernel } else { kernel.relaxed() }
    }
    /// False where the radix sort's decoupled look-back was seen to give
    /// wrong offsets (lavapipe: see `treelet_core::construct::sort`); the sort runs
    /// without it there.
    fn look_back_works(&self) -> bool {
        true
    }
    /// Fewest lanes a subgroup of this device may have: kernels written for
    /// larger subgroups keep another path below their minimum.
    fn min_subgroup_size(&self) -> u32 {
        1
    }
    /// Whether kernels may use NVIDIA's subgroup partition instruction
    /// (`VK_NV_shader_subgroup_partitioned`, enabled when the device was
    /// opened): the sort's digit match in one instruction instead of nine
    /// ballots. The CPU runner computes both forms alike.
    fn subgroup_partitioned(&self) -> bool {
        false
    }
    /// Largest buffer this device accepts, in bytes (on a GPU, two
    /// bindings' worth: kernels bind large buffers in two parts, see
    /// `treelet_core::geometry::split`).
    fn max_buffer_bytes(&self) -> u64;
    /// Largest buffer one storage binding holds, in bytes.
    fn max_binding_bytes(&self) -> u64 {
        self.max_buffer_bytes()
    }
    /// The device's own memory, in bytes, where it has one apart from the
    /// host's and says how large (Vulkan's largest device-local heap).
    fn device_memory_bytes(&self) -> Option<u64> {
        None
    }
    /// The size of `buffer` in bytes (an engine's buffer, to check what it
    /// says it holds against).
    fn buffer_bytes(&self, buffer: &Self::Buffer) -> u64;
    /// Whether `a` and `b` are the same buffer (kernels bind a buffer once:
    /// the CPU runner borrows each binding mutably).
    fn same_buffer(&self, a: &Self::Buffer, b: &Self::Buffer) -> bool;
    /// A buffer holding `data`.
    fn upload<T: Pod>(&mut self, label: &'static str, data: &[T]) -> Result<Self::Buffer>;
    /// A buffer of `len` elements, element `k` being `item(k)`: on a GPU
    /// made in parallel and written straight into upload memory kept between
    /// calls, so that a large batch (an engine's rays) costs no vector of its
    /// own first. Where some items are errors, the first of them is returned
    /// and nothing is uploaded.
    fn upload_indexed<T: Pod + Send>(&mut self, label: &'static str, len: usize, item: impl Fn(usize) -> Result<T> + Sync) -> Result<Self::Buffer> {
        let mut data: Vec<T> = crate::internals::input::room_for(len, label)?;
        for k in 0..len {
            data.push(item(k)?);
        }
        self.upload(label, &data)
    }
    /// A buffer of at least `bytes` bytes whose contents are undefined
    /// (kernels overwrite it). May be a buffer of an earlier build.
    fn scratch(&mut self, label: &'static str, bytes: u64) -> Result<Self::Buffer>;
    /// A buffer of at least `bytes` bytes (a multiple of 4), zeroed by a
    /// fill dispatch in the current stage, so the cost shows in its time;
    /// up to [`SMALL_ZEROED_BYTES`] (counters and flags) written from the
    /// host instead, as parameters are, where a fill's cost would be its
    /// launch and not its writes.
    fn zeroed(&mut self, label: &'static str, bytes: u64) -> Result<Self::Buffer> {
        if bytes <= SMALL_ZEROED_BYTES {
            return self.upload(label, &vec![0u32; bytes.div_ceil(4).max(1) as usize]);
        }
        let buffer = self.scratch(label, bytes)?;
        let len = u32::try_from(bytes / 4).map_err(|_| anyhow::anyhow!("buffer `{label}` too large to fill"))?;
        self.zero_words(&buffer, len)?;
        Ok(buffer)
    }
    /// Zeroes the first `len` u32 words of `buffer` by a fill dispatch in the
    /// current stage.
    fn zero_words(&mut self, buffer: &Self::Buffer, len: u32) -> Result<()> {
        let params = self.upload("fill params", &[FillParams { len, value: 0, _pad0: [0; 2] }])?;
        self.dispatch_with(BackendKernels::of(self).fill, bind::Fill { params: &params, data: buffer }, groups_for(len, WORKGROUP_SIZE));
        Ok(())
    }
    /// Starts a new build: buffers handed out for the previous one may be
    /// handed out again (their results must have been read back), except
    /// those given to [`Backend::keep`].
    fn begin_build(&mut self) {}
    /// The caller keeps `buffers` (an engine's tracer its tree and
    /// primitives): the backend never hands them out again, and forgets
    /// them, so they are freed when the caller drops them.
    fn keep(&mut self, _buffers: &[&Self::Buffer]) {}

    /// Copies `len` u32 words of `src`, from word `src_offset`, into `dst`
    /// at word `dst_offset`, by a dispatch in the current stage.
    fn copy_words(&mut self, (src, src_offset): (&Self::Buffer, u32), (dst, dst_offset): (&Self::Buffer, u32), len: u32) -> Result<()> {
        let params = self.upload("copy params", &[CopyParams { len, src_offset, dst_offset, _pad0: 0 }])?;
        self.dispatch_with(BackendKernels::of(self).copy, bind::CopyWords { params: &params, src, dst }, groups_for(len, WORKGROUP_SIZE));
        Ok(())
    }

    /// Hands `buffers` (taken since the last build, and no longer needed by
    /// any dispatch not yet waited for) back to the pool now, rather than at
    /// the next build: what a caller that traces batch after batch without
    /// building does with each batch's buffers, so that memory does not
    /// grow with every batch.
    fn release(&mut self, _buffers: &[&Self::Buffer]) {}
    /// Builds the pipelines of `kernels` ahead of the work that uses them,
    /// with the backend's own ([`BackendKernels`]), several at once where
    /// the device compiles them (a GPU's driver); returns the wall seconds
    /// it took. Kernels left out are built when first used, as always.
    fn prepare_kernels(&mut self, _kernels: &[Kernel]) -> f64 {
        0.0
    }
    /// Dispatches that follow belong to `stage` (for timing).
    fn stage(&mut self, stage: &'static str);
    /// Runs `kernel` over `groups` workgroups with these bindings (params
    /// first): what each backend implements, called through
    /// [`Backend::dispatch`] or [`Backend::dispatch_with`].
    fn dispatch_listed(&mut self, kernel: Kernel, bindings: &[&Self::Buffer], groups: u32);
    /// Runs a kernel written out in the shader crate (not in the registry)
    /// over `groups` workgroups with these bindings (params first). A
    /// registered kernel is refused: it takes its bindings by name
    /// ([`Backend::dispatch_with`]).
    fn dispatch(&mut self, kernel: Kernel, bindings: &[&Self::Buffer], groups: u32) {
        assert!(kernel.registration().is_none(), "{kernel:?} is registered: dispatch it with its bindings by name (dispatch_with)");
        self.dispatch_listed(kernel, bindings, groups);
    }
    /// Runs a registered kernel with its bindings named
    /// (`crate::runtime::kernels::bind`), in the order its declaration
    /// gives: `kernel` is theirs, or its relaxed twin (as a kernel set
    /// picks it).
    fn dispatch_with<'a, K: Bindings<'a, Self::Buffer>>(&mut self, kernel: Kernel, bindings: K, groups: u32)
    where
        Self::Buffer: 'a,
    {
        assert!(kernel == K::KERNEL || kernel == K::KERNEL.relaxed(), "{kernel:?} dispatched with the bindings of {:?}", K::KERNEL);
        self.dispatch_listed(kernel, &bindings.list(), groups);
    }
    /// Waits for all work so far and returns the first `count` elements.
    fn read<T: Pod>(&mut self, buffer: &Self::Buffer, count: usize) -> Result<Vec<T>>;
    /// Waits for all work so far and lends the first `count` elements to
    /// `take` where they lie: on a GPU, read-back memory kept between calls,
    /// so that a large result (an engine's hits) is read once, into the
    /// caller's own form.
    fn read_with<T: Pod, R>(&mut self, buffer: &Self::Buffer, count: usize, take: impl FnOnce(&[T]) -> R) -> Result<R> {
        Ok(take(&self.read(buffer, count)?))
    }
    /// Waits for all work so far and returns the stage times since the last call.
    fn take_times(&mut self) -> Result<StageTimes>;
}

/// Largest buffer [`Backend::zeroed`] writes from the host rather than by a
/// fill dispatch (flags and single counters): a dispatch costs about 3 µs on
/// the H100 before its first write (a quarter of the depth check of a `bvh2`
/// layout, whose one word it zeroed: 0.013 -> 0.010 ms). Not larger: with
/// 4 KiB, the TRBVH's per-round level counts (1 KiB) were written so, and
/// its collapse stage ran 24 µs slower on the H100, for a reason not found
/// (`docs/results/h100-lbvh-dispatches-2026-11-27/log_small_zeroed.txt`).
pub const SMALL_ZEROED_BYTES: u64 = 64;

/// Checks that a buffer of `bytes` fits the device; names the buffer if not.
pub fn check_fits<B: Backend>(backend: &B, label: &str, bytes: u64) -> Result<()> {
    let max = backend.max_buffer_bytes();
    if bytes > max {
        return Err(crate::error::too_large(format!("scene too large for this device: buffer `{label}` needs {bytes} bytes, \
             the adapter `{}` allows {max} bytes per buffer",
            backend.adapter())));
    }
    Ok(())
}
