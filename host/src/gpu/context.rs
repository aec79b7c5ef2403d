//! Adapter, device, and one compute pipeline per [`Kernel`], built once.
//!
//! Treelet's kernels are SPIR-V from rust-gpu, loaded through wgpu's
//! passthrough (naga cannot read the Vulkan memory model capability the
//! device-scope atomics need), so Treelet runs on Vulkan adapters only.
use std::collections::HashMap;
use std::sync::Arc;

use anyhow::{bail, Context as _, Result};

use crate::kernels::{Access, Kernel};

/// The SPIR-V module compiled from the `shader` crate by `build.rs`.
const SHADER_SPV: &[u8] = include_bytes!(env!("treelet_shader.spv"));

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
    pipelines: HashMap<Kernel, Pipeline>,
}

impl GpuContext {
    /// Opens the first Vulkan adapter (high performance preferred) and
    /// builds all pipelines. Fails with a clear message when there is none.
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
        let pipelines = build_pipelines(&device);
        Ok(Arc::new(Self { device, queue, info, limits, timestamps, pipelines }))
    }

    pub fn pipeline(&self, kernel: Kernel) -> &Pipeline {
        &self.pipelines[&kernel]
    }

    /// Largest buffer usable as one storage binding.
    pub fn max_binding_bytes(&self) -> u64 {
        self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size)
    }
}

fn build_pipelines(device: &wgpu::Device) -> HashMap<Kernel, Pipeline> {
    let words = wgpu::util::make_spirv_raw(SHADER_SPV);
    let entry_points: Vec<_> = Kernel::ALL
        .iter()
        .map(|k| wgpu::PassthroughShaderEntryPoint { name: k.entry_point().into(), workgroup_size: (256, 1, 1) })
        .collect();
    // SAFETY: the module is rust-gpu output validated by spirv-val at build time.
    let module = unsafe {
        device.create_shader_module_passthrough(wgpu::ShaderModuleDescriptorPassthrough {
            label: Some("treelet_shader"),
            entry_points: entry_points.into(),
            spirv: Some(words),
            ..Default::default()
        })
    };
    Kernel::ALL
        .iter()
        .map(|&kernel| {
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
                module: &module,
                entry_point: Some(kernel.entry_point()),
                compilation_options: Default::default(),
                cache: None,
            });
            (kernel, Pipeline { pipeline, layout })
        })
        .collect()
}
