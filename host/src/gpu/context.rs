//! Adapter, device, and one compute pipeline per [`Kernel`], built on first
//! use (a run needs a few of the render variants, and compiling a path
//! tracer takes seconds on lavapipe).
//!
//! Treelet's kernels are SPIR-V from rust-gpu, loaded through wgpu's
//! passthrough (naga cannot read the Vulkan memory model capability the
//! device-scope atomics need), so Treelet runs on Vulkan adapters only.
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use anyhow::{bail, Context as _, Result};

use crate::kernels::{Access, Kernel};

/// The SPIR-V module compiled from the `shader` crate by `build.rs`.
pub const SHADER_SPV: &[u8] = include_bytes!(env!("treelet_shader.spv"));

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
    module: wgpu::ShaderModule,
    pipelines: Mutex<HashMap<Kernel, Arc<Pipeline>>>,
}

impl GpuContext {
    /// Opens the first Vulkan adapter (high performance preferred) and
    /// loads the shader module. Fails with a clear message when there is none.
    pub fn new() -> Result<Arc<Self>> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Arc<Self>> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            })
            .await
            .context(
                "no Vulkan adapter found: install a Vulkan driver \
                 (on a machine without a GPU: `apt-get install mesa-vulkan-drivers` for lavapipe), \
                 or use --device cpu",
            )?;
        let info = adapter.get_info();
        let needed = wgpu::Features::PASSTHROUGH_SHADERS | wgpu::Features::SHADER_INT64;
        let missing = needed - adapter.features();
        if !missing.is_empty() {
            bail!("adapter `{}` lacks features Treelet needs: {missing:?}", info.name);
        }
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let features = needed | if timestamps { wgpu::Features::TIMESTAMP_QUERY } else { wgpu::Features::empty() };
        // Ask for everything the adapter offers: large scenes need large buffers.
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("treelet"),
                required_features: features,
                required_limits: limits.clone(),
                experimental_features: unsafe { wgpu::ExperimentalFeatures::enabled() },
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .with_context(|| format!("could not open adapter `{}`", info.name))?;
        let module = shader_module(&device);
        Ok(Arc::new(Self { device, queue, info, limits, timestamps, module, pipelines: Mutex::default() }))
    }

    /// The pipeline of `kernel`, built the first time it is asked for.
    pub fn pipeline(&self, kernel: Kernel) -> Arc<Pipeline> {
        let mut pipelines = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        pipelines.entry(kernel).or_insert_with(|| Arc::new(build_pipeline(&self.device, &self.module, kernel))).clone()
    }

    /// Largest buffer usable as one storage binding.
    pub fn max_binding_bytes(&self) -> u64 {
        self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size)
    }
}

fn shader_module(device: &wgpu::Device) -> wgpu::ShaderModule {
    let words = wgpu::util::make_spirv_raw(SHADER_SPV);
    let entry_points: Vec<_> = Kernel::all()
        .iter()
        .map(|k| wgpu::PassthroughShaderEntryPoint { name: k.entry_point().into(), workgroup_size: (256, 1, 1) })
        .collect();
    // SAFETY: the module is rust-gpu output validated by spirv-val at build time.
    unsafe {
        device.create_shader_module_passthrough(wgpu::ShaderModuleDescriptorPassthrough {
            label: Some("treelet_shader"),
            entry_points: entry_points.into(),
            spirv: Some(words),
            ..Default::default()
        })
    }
}

fn build_pipeline(device: &wgpu::Device, module: &wgpu::ShaderModule, kernel: Kernel) -> Pipeline {
            let entries: Vec<_> = kernel
                .bindings()
                .iter()
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
                cache: None,
            });
            Pipeline { pipeline, layout }
}

/// Size in 32-bit words of an entry point's function in the shader module
/// (rust-gpu inlines everything a kernel calls into it), or None if the
/// module has no such entry point: the code size of one kernel variant.
pub fn entry_point_words(name: &str) -> Option<usize> {
    const OP_ENTRY_POINT: u32 = 15;
    const OP_FUNCTION: u32 = 54;
    const OP_FUNCTION_END: u32 = 56;
    let words: Vec<u32> = SHADER_SPV.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    let mut target = None;
    let (mut i, mut start) = (5, None);
    while i < words.len() {
        let (count, op) = ((words[i] >> 16) as usize, words[i] & 0xffff);
        if count == 0 {
            return None;
        }
        let operands = &words[i + 1..(i + count).min(words.len())];
        match op {
            OP_ENTRY_POINT if operands.len() > 2 => {
                let bytes: Vec<u8> = operands[2..].iter().flat_map(|w| w.to_le_bytes()).collect();
                let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
                if &bytes[..end] == name.as_bytes() {
                    target = Some(operands[1]);
                }
            }
            OP_FUNCTION if operands.len() > 1 && Some(operands[1]) == target => start = Some(i),
            OP_FUNCTION_END if start.is_some() => return start.map(|s| i + count - s),
            _ => {}
        }
        i += count;
    }
    None
}
