//! Adapter, device, and one compute pipeline per [`Kernel`], built on first
//! use (a run needs a few of the render variants, and compiling a path
//! tracer takes seconds on lavapipe).
//!
//! Treelet's kernels are SPIR-V from rust-gpu, loaded through wgpu's
//! passthrough (naga cannot read the Vulkan memory model capability the
//! device-scope atomics need), so Treelet runs on Vulkan adapters only.
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use anyhow::{Context as _, Result};

use crate::runtime::kernels::{Access, Kernel};
use crate::tuning::PipelineCache;

use super::shaders::{self, SHADERS};

pub struct Pipeline {
    pub pipeline: wgpu::ComputePipeline,
    pub layout: wgpu::BindGroupLayout,
}

/// A device ready to run every kernel. Cheap to share (`Arc`).
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Whether compute passes can be timed with timestamp queries.
    pub timestamps: bool,
    /// The adapter's largest device-local memory heap, in bytes (for lavapipe,
    /// the host's memory), if Vulkan says.
    pub device_memory: Option<u64>,
    /// Whether `VK_NV_shader_subgroup_partitioned` was enabled (the device
    /// has it and runs partition operations in compute shaders).
    pub subgroup_partitioned: bool,
    pipelines: Mutex<HashMap<Kernel, Arc<Pipeline>>>,
    /// The driver's compiled pipelines, kept on disk between runs.
    cache: Option<DiskCache>,
    /// Where the start-up time went.
    pub startup: Startup,
    /// Pipelines built so far, their seconds (summed), each one's seconds,
    /// and the wall seconds of [`GpuContext::prepare`] (the cache is saved on
    /// drop only when some were built).
    built: Mutex<(u32, f64, Vec<(Kernel, f64)>, f64)>,
}

/// Seconds spent opening the device and building pipelines.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Startup {
    /// Vulkan instance, adapter and device.
    pub device_s: f64,
    /// Reading the SPIR-V modules (one per entry point, passed through to
    /// the driver as each pipeline is built).
    pub module_s: f64,
    /// Whether a pipeline cache from an earlier run was found.
    pub cache_loaded: bool,
}

/// A pipeline cache and the file it is loaded from and saved to.
struct DiskCache {
    cache: wgpu::PipelineCache,
    path: PathBuf,
}

/// The folder of the pipeline cache: `TREELET_PIPELINE_CACHE` (a folder, or
/// `off`), else `$XDG_CACHE_HOME/treelet`, else `$HOME/.cache/treelet`.
fn cache_dir() -> Option<PathBuf> {
    match &crate::tuning::Tuning::current().pipeline_cache {
        PipelineCache::Off => None,
        PipelineCache::At(dir) => Some(dir.clone()),
        PipelineCache::Default => std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
            .map(|d| d.join("treelet")),
    }
}

/// The file of this adapter's and this shader's cache (a shader of another
/// build gets its own file, so that caches do not grow without end).
fn cache_file(info: &wgpu::AdapterInfo) -> Option<PathBuf> {
    let key = wgpu::util::pipeline_cache_key(info)?;
    let hash = SHADERS.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
    Some(cache_dir()?.join(format!("{key}_{hash:016x}.bin")))
}

impl Drop for GpuContext {
    /// Saves the pipeline cache when this run built pipelines. A cache that
    /// cannot be written only costs the next run its compile time: ignored.
    fn drop(&mut self) {
        let Some(c) = &self.cache else { return };
        if self.pipelines_built().0 == 0 {
            return;
        }
        if let (Some(data), Some(dir)) = (c.cache.get_data(), c.path.parent()) {
            // A temporary name of this process and context alone, renamed into place
            // whole: runs that save at once never leave a mixed file.
            let temp = c.path.with_extension(format!("{}-{:p}.tmp", std::process::id(), self));
            let _ = std::fs::create_dir_all(dir)
                .and_then(|()| std::fs::write(&temp, &data))
                .and_then(|()| std::fs::rename(&temp, &c.path));
        }
    }
}

/// The largest device-local memory heap of `adapter` (Vulkan's memory
/// properties), in bytes; `None` off Vulkan.
fn device_local_bytes(adapter: &wgpu::Adapter) -> Option<u64> {
    // SAFETY: reads the physical device's memory properties only; the
    // adapter, and with it the instance, outlives the call.
    let hal = unsafe { adapter.as_hal::<wgpu::hal::api::Vulkan>() }?;
    let instance = hal.shared_instance().raw_instance();
    let props = unsafe { instance.get_physical_device_memory_properties(hal.raw_physical_device()) };
    props.memory_heaps[..props.memory_heap_count as usize]
        .iter()
        .filter(|h| h.flags.contains(ash::vk::MemoryHeapFlags::DEVICE_LOCAL))
        .map(|h| h.size)
        .max()
}

/// A device just opened, and what was found of its adapter.
struct Opened {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    timestamps: bool,
    device_memory: Option<u64>,
    partitioned: bool,
    cache_path: Option<PathBuf>,
}

/// The most storage buffers any kernel binds, and the most workgroup
/// memory any module declares (bytes).
fn kernel_needs() -> (u32, u32) {
    static NEEDS: std::sync::OnceLock<(u32, u32)> = std::sync::OnceLock::new();
    *NEEDS.get_or_init(|| {
        let buffers = Kernel::all().iter().map(|k| k.bindings().len() + k.split_bindings().len()).max().unwrap_or(0);
        let modules = shaders::unpack(SHADERS).unwrap_or_default();
        let workgroup = modules.iter().map(|m| m.workgroup_bytes()).max().unwrap_or(0);
        (buffers as u32, workgroup as u32)
    })
}

/// The device extension of NVIDIA's subgroup partition instruction.
const PARTITIONED: &std::ffi::CStr = c"VK_NV_shader_subgroup_partitioned";

/// Whether `adapter` has [`PARTITIONED`] and runs partition operations in
/// compute shaders (`TREELET_SUBGROUP_PARTITIONED=0` says no, to measure).
fn subgroup_partitioned_supported(adapter: &wgpu::Adapter) -> bool {
    if !crate::tuning::Tuning::current().subgroup_partitioned {
        return false;
    }
    // SAFETY: queries of the physical device only; the adapter, and with it
    // the instance, outlives the calls.
    let Some(hal) = (unsafe { adapter.as_hal::<wgpu::hal::api::Vulkan>() }) else {
        return false;
    };
    let instance = hal.shared_instance().raw_instance();
    let device = hal.raw_physical_device();
    let has_extension = unsafe { instance.enumerate_device_extension_properties(device) }
        .is_ok_and(|e| e.iter().any(|p| p.extension_name_as_c_str() == Ok(PARTITIONED)));
    if !has_extension {
        return false;
    }
    let mut subgroup = ash::vk::PhysicalDeviceSubgroupProperties::default();
    let mut props = ash::vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
    unsafe { instance.get_physical_device_properties2(device, &mut props) };
    subgroup.supported_operations.contains(ash::vk::SubgroupFeatureFlags::PARTITIONED_NV)
        && subgroup.supported_stages.contains(ash::vk::ShaderStageFlags::COMPUTE)
}

/// Opens `adapter` as `request_device` does, with [`PARTITIONED`] enabled
/// as well (wgpu knows no such feature, so through wgpu-hal); whether it
/// was (if not, with a note, the device as `request_device` opens it).
fn open_with_partitioned(
    adapter: &wgpu::Adapter,
    descriptor: &wgpu::DeviceDescriptor,
) -> std::result::Result<((wgpu::Device, wgpu::Queue), bool), wgpu::RequestDeviceError> {
    // SAFETY: the device is opened from this adapter with exactly the
    // features and limits of `descriptor` (plus one extension wgpu does not
    // see), then handed to wgpu, which owns it from there.
    unsafe {
        let hal = adapter.as_hal::<wgpu::hal::api::Vulkan>().expect("a Vulkan adapter");
        let callback = |args: wgpu::hal::vulkan::CreateDeviceCallbackArgs| {
            if !args.extensions.contains(&PARTITIONED) {
                args.extensions.push(PARTITIONED);
            }
        };
        let open = hal
            .open_with_callback(
                descriptor.required_features,
                &descriptor.required_limits,
                &descriptor.memory_hints,
                Some(Box::new(callback)),
            )
            .map_err(|e| {
                eprintln!("note: opening the device with {PARTITIONED:?} failed ({e}); without it");
                e
            });
        drop(hal);
        match open {
            Ok(open) => adapter.create_device_from_hal(open, descriptor).map(|d| (d, true)),
            Err(_) => pollster::block_on(adapter.request_device(descriptor)).map(|d| (d, false)),
        }
    }
}

impl GpuContext {
    /// Opens the first Vulkan adapter (high performance preferred) and
    /// loads the shader module. Fails with a clear message when there is none.
    pub fn new() -> crate::error::Result<Arc<Self>> {
        crate::error::typed(|| pollster::block_on(Self::new_async(None)))
    }

    /// Opens the Vulkan adapter of index `index` in [`GpuContext::adapters`].
    pub fn with_adapter(index: usize) -> crate::error::Result<Arc<Self>> {
        crate::error::typed(|| pollster::block_on(Self::new_async(Some(index))))
    }

    /// The names of the machine's Vulkan adapters, in index order.
    pub fn adapters() -> Vec<String> {
        vulkan().1.iter().map(|a| a.get_info().name).collect()
    }

    /// The indices (as [`GpuContext::with_adapter`] takes them) of the
    /// Vulkan adapters that are GPUs, not CPU implementations such as lavapipe.
    pub fn gpu_adapters() -> Vec<usize> {
        let adapters = &vulkan().1;
        (0..adapters.len()).filter(|&i| adapters[i].get_info().device_type != wgpu::DeviceType::Cpu).collect()
    }

    async fn new_async(index: Option<usize>) -> Result<Arc<Self>> {
        let start = Instant::now();
        let adapter = match index {
            Some(i) => vulkan().1.get(i).cloned(),
            // High performance first, from the adapters the process listed
            // already (`request_adapter` would list them again).
            None => vulkan()
                .1
                .iter()
                .min_by_key(|a| match a.get_info().device_type {
                    wgpu::DeviceType::DiscreteGpu => 0,
                    wgpu::DeviceType::IntegratedGpu => 1,
                    wgpu::DeviceType::VirtualGpu => 2,
                    wgpu::DeviceType::Other => 3,
                    wgpu::DeviceType::Cpu => 4,
                })
                .cloned(),
        };
        let adapter = adapter.ok_or_else(|| {
            crate::error::device(
                "no Vulkan adapter found (install a Vulkan driver; without a GPU, \
                 `apt-get install mesa-vulkan-drivers` gives lavapipe)",
            )
        })?;
        let info = adapter.get_info();
        let needed = Self::required_features();
        let missing = needed - adapter.features();
        if !missing.is_empty() {
            return Err(crate::error::device(format!("adapter `{}` lacks features Treelet needs: {missing:?}", info.name)));
        }
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let device_memory = device_local_bytes(&adapter);
        let cache_path = cache_file(&info).filter(|_| adapter.features().contains(wgpu::Features::PIPELINE_CACHE));
        let optional = [(timestamps, wgpu::Features::TIMESTAMP_QUERY), (cache_path.is_some(), wgpu::Features::PIPELINE_CACHE)];
        let features = optional.iter().filter(|o| o.0).fold(needed, |f, o| f | o.1);
        // Ask for everything the adapter offers: large scenes need large buffers.
        let limits = adapter.limits();
        let descriptor = wgpu::DeviceDescriptor {
            label: Some("treelet"),
            required_features: features,
            required_limits: limits.clone(),
            experimental_features: unsafe { wgpu::ExperimentalFeatures::enabled() },
            // Memory blocks from 8 MiB (host-visible ones from 4), growing to
            // 256 MiB: the first read-back's block was 64 MiB of pinned host
            // memory with `Performance`, 13-17 ms before a render's first
            // dispatch (1.2 ms with small blocks; large buffers get blocks of
            // their own either way).
            memory_hints: wgpu::MemoryHints::Manual { suballocated_device_memory_block_size: (8 << 20)..(256 << 20) },
            trace: wgpu::Trace::Off,
        };
        let ((device, queue), partitioned) = if subgroup_partitioned_supported(&adapter) {
            open_with_partitioned(&adapter, &descriptor)
        } else {
            adapter.request_device(&descriptor).await.map(|d| (d, false))
        }
        .with_context(|| format!("could not open adapter `{}`", info.name))?;
        let opened = Opened { device, queue, info, limits, timestamps, device_memory, partitioned, cache_path };
        Ok(Self::assemble(opened, start))
    }

    /// The features a device must have for Treelet's kernels (SPIR-V
    /// passthrough needs wgpu's experimental features enabled, and Vulkan).
    pub fn required_features() -> wgpu::Features {
        wgpu::Features::PASSTHROUGH_SHADERS | wgpu::Features::SHADER_INT64
    }

    /// `base` with the limits Treelet's kernels need raised to them: storage
    /// buffers per stage (the most any kernel binds, second parts of split
    /// buffers included), workgroup memory (the most any module declares)
    /// and 256 invocations a workgroup. An engine opens its device with
    /// these (and [`GpuContext::required_features`]) to share it.
    pub fn required_limits(base: wgpu::Limits) -> wgpu::Limits {
        let (buffers, workgroup_bytes) = kernel_needs();
        wgpu::Limits {
            max_storage_buffers_per_shader_stage: base.max_storage_buffers_per_shader_stage.max(buffers),
            max_compute_workgroup_storage_size: base.max_compute_workgroup_storage_size.max(workgroup_bytes),
            max_compute_invocations_per_workgroup: base.max_compute_invocations_per_workgroup.max(256),
            max_compute_workgroup_size_x: base.max_compute_workgroup_size_x.max(256),
            ..base
        }
    }

    /// Treelet on an engine's own device: `device` and `queue` opened from
    /// `adapter` (Vulkan) with [`GpuContext::required_features`] and
    /// [`GpuContext::required_limits`]; an error names each missing feature
    /// and each limit below what the kernels need. Treelet records its
    /// dispatches on encoders of its own and submits them to `queue`
    /// itself; buffers it makes live on `device`, so the engine can bind
    /// them (and Treelet the engine's: see `Tracer`). Optional features the
    /// device has are used (timestamps, a pipeline cache); NVIDIA's
    /// partition instruction is not (wgpu cannot enable its extension on a
    /// device opened elsewhere), so the sort ranks digits with ballots.
    pub fn from_wgpu(adapter: &wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> crate::error::Result<Arc<Self>> {
        crate::error::typed(|| {
            let start = Instant::now();
            let info = adapter.get_info();
            if info.backend != wgpu::Backend::Vulkan {
                return Err(crate::error::device(format!("device of adapter `{}` runs on {:?}: Treelet's kernels are SPIR-V and need a Vulkan device", info.name, info.backend)));
            }
            let features = device.features();
            let missing = Self::required_features() - features;
            let limits = device.limits();
            let needed = Self::required_limits(wgpu::Limits::downlevel_defaults());
            let mut short = Vec::new();
            let mut check = |name: &str, has: u32, needs: u32| {
                if has < needs {
                    short.push(format!("{name} is {has}, the kernels need {needs}"));
                }
            };
            check("max_storage_buffers_per_shader_stage", limits.max_storage_buffers_per_shader_stage, needed.max_storage_buffers_per_shader_stage);
            check("max_compute_workgroup_storage_size", limits.max_compute_workgroup_storage_size, needed.max_compute_workgroup_storage_size);
            check("max_compute_invocations_per_workgroup", limits.max_compute_invocations_per_workgroup, needed.max_compute_invocations_per_workgroup);
            check("max_compute_workgroup_size_x", limits.max_compute_workgroup_size_x, needed.max_compute_workgroup_size_x);
            if !missing.is_empty() || !short.is_empty() {
                let mut why = Vec::new();
                if !missing.is_empty() {
                    why.push(format!("it lacks features {missing:?} (open it with GpuContext::required_features(), wgpu's experimental features enabled)"));
                }
                if !short.is_empty() {
                    why.push(format!("{} (open it with GpuContext::required_limits(..))", short.join("; ")));
                }
                return Err(crate::error::device(format!("the device of adapter `{}` cannot run Treelet: {}", info.name, why.join("; "))));
            }
            let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
            let cache_path = cache_file(&info).filter(|_| features.contains(wgpu::Features::PIPELINE_CACHE));
            let device_memory = device_local_bytes(adapter);
            let opened = Opened { device, queue, info, limits, timestamps, device_memory, partitioned: false, cache_path };
            Ok(Self::assemble(opened, start))
        })
    }

    /// The context of a device just opened; `start`: when opening began.
    fn assemble(opened: Opened, start: Instant) -> Arc<Self> {
        let Opened { device, queue, info, limits, timestamps, device_memory, partitioned, cache_path } = opened;
        let device_s = start.elapsed().as_secs_f64();
        crate::runtime::timeline::mark("device");
        // Unpacks the modules now, so that a damaged file fails here.
        let _ = shaders::module("");
        let module_s = start.elapsed().as_secs_f64() - device_s;
        let mut startup = Startup { device_s, module_s, cache_loaded: false };
        let cache = cache_path.map(|path| {
            let data = std::fs::read(&path).ok();
            startup.cache_loaded = data.is_some();
            // SAFETY: the data is what `get_data` saved for an adapter of the same
            // pipeline_cache_key (the file name); the driver checks it and, with
            // `fallback`, starts an empty cache when it does not match.
            let cache = unsafe {
                device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor { label: Some("treelet"), data: data.as_deref(), fallback: true })
            };
            DiskCache { cache, path }
        });
        Arc::new(Self {
            device,
            queue,
            info,
            limits,
            timestamps,
            device_memory,
            subgroup_partitioned: partitioned,
            pipelines: Mutex::default(), cache, startup, built: Mutex::default() })
    }

    /// The pipeline of `kernel`, built the first time it is asked for (the
    /// driver compiles it then: on a fresh machine, seconds for the largest
    /// kernels; see [`GpuContext::prepare`]).
    pub fn pipeline(&self, kernel: Kernel) -> Arc<Pipeline> {
        if let Some(p) = self.pipelines.lock().unwrap_or_else(|e| e.into_inner()).get(&kernel) {
            return p.clone();
        }
        // Built without holding the map, so that several build at once.
        let start = Instant::now();
        let p = Arc::new(build_pipeline(&self.device, kernel, self.cache.as_ref().map(|c| &c.cache)));
        let seconds = start.elapsed().as_secs_f64();
        let mut pipelines = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(first) = pipelines.get(&kernel) {
            return first.clone(); // Another thread built it meanwhile.
        }
        pipelines.insert(kernel, p.clone());
        let mut built = self.built.lock().unwrap_or_else(|e| e.into_inner());
        built.0 += 1;
        built.1 += seconds;
        built.2.push((kernel, seconds));
        p
    }

    /// Builds the pipelines of `kernels` that are not built yet, several at
    /// once (the driver's compiles run in parallel on the host's cores), so
    /// that work timed afterwards does not wait for a compile. Returns the
    /// wall seconds it took.
    pub fn prepare(&self, kernels: &[Kernel]) -> f64 {
        let start = Instant::now();
        let missing: Vec<Kernel> = {
            let pipelines = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
            let mut m: Vec<Kernel> = kernels.iter().copied().filter(|k| !pipelines.contains_key(k)).collect();
            m.sort();
            m.dedup();
            m
        };
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(missing.len());
        let next = std::sync::atomic::AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(|| {
                    while let Some(&k) = missing.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed)) {
                        self.pipeline(k);
                    }
                });
            }
        });
        let seconds = start.elapsed().as_secs_f64();
        self.built.lock().unwrap_or_else(|e| e.into_inner()).3 += seconds;
        seconds
    }

    /// Pipelines built so far and the seconds their builds took (summed
    /// over threads).
    pub fn pipelines_built(&self) -> (u32, f64) {
        let built = self.built.lock().unwrap_or_else(|e| e.into_inner());
        (built.0, built.1)
    }

    /// The wall seconds spent in [`GpuContext::prepare`], and the slowest
    /// pipeline builds so far, slowest first.
    pub fn pipeline_report(&self, slowest: usize) -> (f64, Vec<(Kernel, f64)>) {
        let built = self.built.lock().unwrap_or_else(|e| e.into_inner());
        let mut each = built.2.clone();
        each.sort_by(|a, b| b.1.total_cmp(&a.1));
        each.truncate(slowest);
        (built.3, each)
    }

    /// Whether compiled pipelines are kept on disk between runs.
    pub fn has_pipeline_cache(&self) -> bool {
        self.cache.is_some()
    }

    /// Largest buffer usable as one storage binding.
    pub fn max_binding_bytes(&self) -> u64 {
        self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size)
    }

    /// Where a buffer bound in two parts is split, in bytes: the most one
    /// binding holds, on a boundary of every record kept in such buffers
    /// (16-byte vectors, 32-byte nodes, 48-byte triangles and leaf
    /// primitives, 64-byte `bvh2` nodes) and of the offset alignment.
    pub fn split_bytes(&self) -> u64 {
        let unit = SPLIT_UNIT.max(self.limits.min_storage_buffer_offset_alignment as u64);
        (self.max_binding_bytes() / unit * unit).max(unit)
    }

    /// Largest buffer: two bindings' worth where kernels bind it in two
    /// parts (`Kernel::split_bindings`).
    pub fn max_buffer_bytes(&self) -> u64 {
        (2 * self.split_bytes()).min(self.limits.max_buffer_size)
    }
}

/// Split points are multiples of this (the least common multiple of the
/// record sizes in split buffers, 16, 32, 48 and 64 bytes, and of 256, the
/// largest offset alignment Vulkan allows).
pub const SPLIT_UNIT: u64 = 768;

/// The process's one Vulkan instance (the backend Treelet's SPIR-V
/// passthrough needs) and its adapters, made on first use: a default render
/// asked for them three times (are there GPUs, which, open it), and each new
/// instance loads and queries the drivers again.
fn vulkan() -> &'static (wgpu::Instance, Vec<wgpu::Adapter>) {
    static VULKAN: std::sync::OnceLock<(wgpu::Instance, Vec<wgpu::Adapter>)> = std::sync::OnceLock::new();
    VULKAN.get_or_init(|| {
        quiet_mesa_runtime_dir();
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
        crate::runtime::timeline::mark("Vulkan instance");
        (instance, adapters)
    })
}

/// Mesa's Vulkan drivers print `error: XDG_RUNTIME_DIR is invalid or not
/// set` when the variable is missing (containers, ssh without a session),
/// which reads as Treelet failing. Give them a private runtime directory,
/// as a login session would. The `treelet` command calls it first thing;
/// every Vulkan instance is made after it, so library users and tests get
/// it too.
pub fn quiet_mesa_runtime_dir() {
    use std::os::unix::fs::PermissionsExt;
    let usable = |d: &std::ffi::OsStr| std::path::Path::new(d).is_dir();
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| usable(&d)) {
        return;
    }
    let user = std::env::var("USER").unwrap_or_default();
    let dir = std::env::temp_dir().join(format!("treelet-runtime-{user}"));
    let made = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)));
    if made.is_ok() {
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
    }
}

/// The module of `kernel`'s entry point alone (see [`shaders`]).
fn shader_module(device: &wgpu::Device, kernel: Kernel) -> wgpu::ShaderModule {
    let entry_point = kernel.entry_point();
    let module = shaders::module(entry_point)
        .unwrap_or_else(|| panic!("the SPIR-V built into treelet has no entry point `{entry_point}`"));
    // SAFETY: the module is rust-gpu output validated by spirv-val at build time.
    unsafe {
        device.create_shader_module_passthrough(wgpu::ShaderModuleDescriptorPassthrough {
            label: Some(entry_point),
            entry_points: vec![wgpu::PassthroughShaderEntryPoint { name: entry_point.into(), workgroup_size: (256, 1, 1) }]
                .into(),
            spirv: Some(wgpu::util::make_spirv_raw(module.spirv)),
            ..Default::default()
        })
    }
}

fn build_pipeline(device: &wgpu::Device, kernel: Kernel, cache: Option<&wgpu::PipelineCache>) -> Pipeline {
            let module = &shader_module(device, kernel);
            let accesses = kernel.bindings();
            let entries: Vec<_> = accesses
                .iter()
                .chain(kernel.split_bindings().iter().map(|&i| &accesses[i]))
                .enumerate()
                .map(|(i, access)| wgpu::BindGroupLayoutEntry {
                    binding: i as u32,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: *access == Access::Read },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect();
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(kernel.entry_point()),
                entries: &entries,
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(kernel.entry_point()),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(kernel.entry_point()),
                layout: Some(&pipeline_layout),
                module,
                entry_point: Some(kernel.entry_point()),
                compilation_options: Default::default(),
                cache,
            });
            Pipeline { pipeline, layout }
}

/// Size in 32-bit words of an entry point's module, or None if there is no
/// such entry point: the code size of one kernel variant (rust-gpu inlines
/// everything a kernel calls into it).
pub fn entry_point_words(name: &str) -> Option<usize> {
    shaders::module(name).map(|m| m.words())
}
