//! The SPIR-V of the `shader` crate, one module per entry point, packed into
//! one file and exposed to the host as `env!("treelet_shaders.bin")`: with
//! feature `rebuild-shaders`, compiled here by rust-gpu (the pinned
//! nightly); without it, the file committed in `shaders/treelet_shaders.bin`,
//! so that crates depending on `treelet` build on any toolchain.
//! `env!("treelet_shaders_committed.bin")` is the committed file's path
//! either way (a test compares the two).
//!
//! One module per entry point, because a Vulkan driver reads the whole
//! module for every pipeline it compiles: with all kernels in one 2.2 MB
//! module, NVIDIA's took 0.4 s even for the one-line fill kernel, on every
//! run whose pipeline cache was cold.
//!
//! The packed format (little-endian u32s), read by
//! `treelet::runtime::gpu::shaders`: the magic `TRLTSPV1` (two words), the
//! module count, then per module its name's length in bytes, the name
//! padded with zeros to whole words, its length in words, its words.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The manifest's folder as cargo gives it to this run, not as it was
    // when this script was compiled: two checkouts sharing one target
    // folder share the compiled script, and one read the other's shaders.
    let manifest = std::env::var("CARGO_MANIFEST_DIR")?;
    let committed = format!("{manifest}/shaders/treelet_shaders.bin");
    println!("cargo:rustc-env=treelet_shaders_committed.bin={committed}");
    println!("cargo:rerun-if-changed={committed}");
    #[cfg(feature = "rebuild-shaders")]
    rebuild()?;
    #[cfg(not(feature = "rebuild-shaders"))]
    println!("cargo:rustc-env=treelet_shaders.bin={committed}");
    Ok(())
}

/// The shader crate's groups of entry points (its features), built one per
/// rust-gpu run: the linker holds all of a run's kernels at once, and one
/// run of every kernel peaked at 22 GB of memory (issue 69). The split
/// follows the SPIR-V's size: about 1.1 to 2.6 MB of modules per group.
#[cfg(feature = "rebuild-shaders")]
const GROUPS: [&str; 6] = ["kernels", "render-linear", "render-bvh2", "render-bvh2-light", "render-bvh4", "render-cwbvh"];

#[cfg(feature = "rebuild-shaders")]
fn rebuild() -> Result<(), Box<dyn std::error::Error>> {
    use spirv_builder::{Capability, ModuleResult, SpirvBuilder};
    let shader = format!("{}/../shader", std::env::var("CARGO_MANIFEST_DIR")?);
    // Sorted by entry point, so the same sources pack the same bytes.
    let mut modules: std::collections::BTreeMap<String, Vec<u32>> = Default::default();
    for group in GROUPS {
        let mut builder = SpirvBuilder::new(&shader, "spirv-unknown-vulkan1.2")
            // u64 Morton codes and radix-sort keys.
            .capability(Capability::Int64)
            // Device-scope atomics (bottom-up fit): needs SPIR-V passthrough in wgpu.
            .capability(Capability::VulkanMemoryModelDeviceScope)
            // Subgroup operations (Vulkan 1.1 core): ids, ballots, shuffles, sums.
            .capability(Capability::GroupNonUniform)
            .capability(Capability::GroupNonUniformBallot)
            .capability(Capability::GroupNonUniformShuffle)
            .capability(Capability::GroupNonUniformArithmetic)
            // NVIDIA's partition instruction (the sort's digit match), kept only
            // in the modules that use it (see `strip_unused_partitioned`).
            .capability(Capability::GroupNonUniformPartitionedNV)
            .extension("SPV_NV_shader_subgroup_partitioned")
            .shader_crate_default_features(false)
            .shader_crate_features([group.to_string()])
            .multimodule(true);
        builder.release = true;
        builder.build_script.defaults = true;
        let result = builder.build()?;
        let ModuleResult::MultiModule(built) = result.module else {
            return Err("spirv-builder gave one module where one per entry point was asked for".into());
        };
        // Read now: the next group's run may write where this one did.
        for (name, path) in built {
            let bytes = std::fs::read(&path)?;
            if bytes.len() % 4 != 0 {
                return Err(format!("{}: not whole SPIR-V words", path.display()).into());
            }
            let module: Vec<u32> = bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
            let module = strip_unused_partitioned(&module).map_err(|e| format!("{}: {e}", path.display()))?;
            if modules.insert(name.clone(), module).is_some() {
                return Err(format!("entry point {name} is in two groups of the shader crate").into());
            }
        }
    }
    let mut words: Vec<u32> = vec![u32::from_le_bytes(*b"TRLT"), u32::from_le_bytes(*b"SPV1"), modules.len() as u32];
    for (name, module) in &modules {
        let mut padded = name.as_bytes().to_vec();
        padded.resize(name.len().div_ceil(4) * 4, 0);
        words.push(name.len() as u32);
        words.extend(padded.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
        words.push(module.len() as u32);
        words.extend_from_slice(module);
    }
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR")?).join("treelet_shaders.bin");
    std::fs::write(&out, words.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>())?;
    println!("cargo:rustc-env=treelet_shaders.bin={}", out.display());
    // The largest resident size of any process these runs started (rustc
    // with the SPIR-V backend): CI holds it under 8 GB (tests/layering.rs).
    println!("cargo:rustc-env=treelet_shader_build_peak_rss_kb={}", children_peak_rss_kb());
    Ok(())
}

/// The peak resident set size, in KiB, of the largest child process this
/// build script has waited for (`getrusage(RUSAGE_CHILDREN)`; on Linux a
/// child's figure includes its own children's).
#[cfg(feature = "rebuild-shaders")]
fn children_peak_rss_kb() -> i64 {
    // SAFETY: getrusage writes the struct it is given, nothing else.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) } != 0 {
        return -1;
    }
    // KiB on Linux (bytes on macOS, where the shaders are not built in CI).
    usage.ru_maxrss
}

/// `module` without the partitioned capability and extension where it has
/// no partition instruction: every module declares what the builder was
/// given, and a device without the extension (lavapipe) must still load
/// the modules that do not need it.
#[cfg(feature = "rebuild-shaders")]
fn strip_unused_partitioned(module: &[u32]) -> Result<Vec<u32>, String> {
    const OP_EXTENSION: u32 = 10;
    const OP_CAPABILITY: u32 = 17;
    const OP_PARTITION: u32 = 5296;
    const CAPABILITY_PARTITIONED: u32 = 5297;
    const EXTENSION: &[u8] = b"SPV_NV_shader_subgroup_partitioned";
    if module.len() < 5 || module[0] != 0x0723_0203 {
        return Err("not a SPIR-V module".into());
    }
    let mut instructions = Vec::new();
    let mut at = 5;
    while at < module.len() {
        let count = (module[at] >> 16) as usize;
        if count == 0 || at + count > module.len() {
            return Err(format!("malformed instruction at word {at}"));
        }
        instructions.push(&module[at..at + count]);
        at += count;
    }
    if instructions.iter().any(|i| i[0] & 0xffff == OP_PARTITION) {
        return Ok(module.to_vec());
    }
    let is_extension = |i: &[u32]| {
        let bytes: Vec<u8> = i[1..].iter().flat_map(|w| w.to_le_bytes()).collect();
        bytes.split(|&b| b == 0).next() == Some(EXTENSION)
    };
    let mut out = module[..5].to_vec();
    for i in instructions {
        let op = i[0] & 0xffff;
        let drop = (op == OP_CAPABILITY && i[1] == CAPABILITY_PARTITIONED) || (op == OP_EXTENSION && is_extension(i));
        if !drop {
            out.extend_from_slice(i);
        }
    }
    Ok(out)
}
