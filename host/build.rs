//! Compiles the `shader` crate to one SPIR-V module with rust-gpu and exposes
//! its path to the host as `env!("treelet_shader.spv")`.
use spirv_builder::{Capability, SpirvBuilder};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let shader = concat!(env!("CARGO_MANIFEST_DIR"), "/../shader");
    let mut builder = SpirvBuilder::new(shader, "spirv-unknown-vulkan1.2")
        // u64 Morton codes and radix-sort keys.
        .capability(Capability::Int64)
        // Device-scope atomics (bottom-up fit): needs SPIR-V passthrough in wgpu.
        .capability(Capability::VulkanMemoryModelDeviceScope)
        // Subgroup operations (Vulkan 1.1 core): ids, ballots, shuffles, sums.
        .capability(Capability::GroupNonUniform)
        .capability(Capability::GroupNonUniformBallot)
        .capability(Capability::GroupNonUniformShuffle)
        .capability(Capability::GroupNonUniformArithmetic);
    builder.release = true;
    builder.build_script.defaults = true;
    builder.build_script.env_shader_spv_path = Some(true);
    builder.build()?;
    Ok(())
}
