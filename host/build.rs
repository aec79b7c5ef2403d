//! The SPIR-V module of the `shader` crate, exposed to the host as
//! `env!("treelet_shader.spv")`: with feature `rebuild-shaders`, compiled
//! here by rust-gpu (the pinned nightly); without it, the module committed
//! in `shaders/treelet_shader.spv`, so that crates depending on `treelet`
//! build on any toolchain. `env!("treelet_shader_committed.spv")` is the
//! committed module's path either way (a test compares the two).
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let committed = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders/treelet_shader.spv");
    println!("cargo:rustc-env=treelet_shader_committed.spv={committed}");
    println!("cargo:rerun-if-changed={committed}");
    #[cfg(feature = "rebuild-shaders")]
    rebuild()?;
    #[cfg(not(feature = "rebuild-shaders"))]
    println!("cargo:rustc-env=treelet_shader.spv={committed}");
    Ok(())
}

#[cfg(feature = "rebuild-shaders")]
fn rebuild() -> Result<(), Box<dyn std::error::Error>> {
    use spirv_builder::{Capability, SpirvBuilder};
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
