//! What the Vulkan driver made of Treelet's kernels: registers, local and
//! workgroup memory per entry point, from its pipeline statistics
//! (`VK_KHR_pipeline_executable_properties`; NVIDIA reports them, lavapipe
//! does not). A developer's tool for tuning kernels: registers bound how
//! many invocations a GPU keeps in flight.
//!
//!     cargo run --release -p treelet --example pipeline_stats [ENTRY_POINT ...]
//!
//! Entry points are named as in the shader crate (`render::cast_cwbvh_cs`);
//! without names, every kernel of `treelet::runtime::kernels::Kernel::all()`.
//! A name ending in `.spv` is a SPIR-V file of one entry point instead (a
//! module cut down by `spirv-reduce`, say, to report a driver's bug).
use std::ffi::CString;

use anyhow::{bail, Context, Result};
use ash::vk;

fn main() -> Result<()> {
    let mut names: Vec<String> = std::env::args().skip(1).collect();
    if names.is_empty() {
        names = treelet::runtime::kernels::Kernel::all().iter().map(|k| k.entry_point().to_string()).collect();
    }
    // SAFETY: plain Vulkan calls on objects created here, destroyed at exit.
    unsafe {
        let entry = ash::Entry::load().context("no Vulkan loader")?;
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_2);
        let instance = entry.create_instance(&vk::InstanceCreateInfo::default().application_info(&app), None)?;
        let devices = instance.enumerate_physical_devices()?;
        let pdev = *devices
            .iter()
            .find(|&&d| instance.get_physical_device_properties(d).device_type == vk::PhysicalDeviceType::DISCRETE_GPU)
            .or(devices.first())
            .context("no Vulkan device")?;
        let props = instance.get_physical_device_properties(pdev);
        println!("{}", props.device_name_as_c_str()?.to_string_lossy());
        let family = instance
            .get_physical_device_queue_family_properties(pdev)
            .iter()
            .position(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE))
            .context("no compute queue")? as u32;
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        let extensions = [ash::khr::pipeline_executable_properties::NAME.as_ptr()];
        let mut exec = vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default().pipeline_executable_info(true);
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default()
            .vulkan_memory_model(true)
            .vulkan_memory_model_device_scope(true);
        let features = vk::PhysicalDeviceFeatures::default().shader_int64(true);
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_extension_names(&extensions)
            .enabled_features(&features)
            .push_next(&mut exec)
            .push_next(&mut v12);
        let device = instance.create_device(pdev, &info, None).context("device without pipeline statistics")?;
        let stats = ash::khr::pipeline_executable_properties::Device::new(&instance, &device);
        // One layout that covers every kernel's bindings: storage buffers 0..16.
        let bindings: Vec<_> = (0..16)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let set = device.create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None)?;
        let sets = [set];
        let layout = device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&sets), None)?;
        for name in &names {
            let (words, cname) = if name.ends_with(".spv") {
                let bytes = std::fs::read(name).with_context(|| format!("reading {name}"))?;
                let words = ash::util::read_spv(&mut std::io::Cursor::new(bytes))?;
                let entry = first_entry_point(&words).with_context(|| format!("{name}: no OpEntryPoint"))?;
                (words, CString::new(entry)?)
            } else {
                let Some(m) = treelet::runtime::gpu::shaders::module(name) else { bail!("no entry point `{name}`") };
                (ash::util::read_spv(&mut std::io::Cursor::new(m.spirv))?, CString::new(name.as_str())?)
            };
            let module = device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None)?;
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(&cname);
            let create = [vk::ComputePipelineCreateInfo::default()
                .stage(stage)
                .layout(layout)
                .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR)];
            let pipeline = match device.create_compute_pipelines(vk::PipelineCache::null(), &create, None) {
                Ok(p) => p[0],
                Err((_, e)) => bail!("{name}: {e:?}"),
            };
            let pinfo = vk::PipelineInfoKHR::default().pipeline(pipeline);
            let executables = stats.get_pipeline_executable_properties(&pinfo)?;
            let mut line = format!("{name:44}");
            for i in 0..executables.len() as u32 {
                let einfo = vk::PipelineExecutableInfoKHR::default().pipeline(pipeline).executable_index(i);
                for s in stats.get_pipeline_executable_statistics(&einfo)? {
                    let value = match s.format {
                        vk::PipelineExecutableStatisticFormatKHR::UINT64 => s.value.u64.to_string(),
                        vk::PipelineExecutableStatisticFormatKHR::INT64 => s.value.i64.to_string(),
                        vk::PipelineExecutableStatisticFormatKHR::FLOAT64 => format!("{:.1}", s.value.f64),
                        _ => "?".into(),
                    };
                    line += &format!("  {}={value}", s.name_as_c_str()?.to_string_lossy().replace(' ', "_"));
                }
            }
            println!("{line}");
            device.destroy_pipeline(pipeline, None);
            device.destroy_shader_module(module, None);
        }
        device.destroy_pipeline_layout(layout, None);
        device.destroy_descriptor_set_layout(set, None);
        device.destroy_device(None);
        instance.destroy_instance(None);
    }
    Ok(())
}

/// The name of a SPIR-V module's first entry point: `OpEntryPoint` (opcode
/// 15) holds the execution model, the function, then the name as a
/// nul-terminated string packed into words.
fn first_entry_point(words: &[u32]) -> Option<String> {
    let mut at = 5; // past the header
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        if count == 0 {
            return None;
        }
        if opcode == 15 {
            let bytes: Vec<u8> = words.get(at + 3..at + count)?.iter().flat_map(|w| w.to_le_bytes()).collect();
            let end = bytes.iter().position(|&b| b == 0)?;
            return String::from_utf8(bytes[..end].to_vec()).ok();
        }
        at += count;
    }
    None
}
