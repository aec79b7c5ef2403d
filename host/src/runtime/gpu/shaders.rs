//! The kernels' SPIR-V: one module per entry point, packed into one file by
//! `host/build.rs` (which documents the format). A pipeline is compiled
//! from its own entry point's module only: a driver reads the whole module
//! it is given for every pipeline, and with every kernel in one module a
//! cold compile of even the smallest kernel took 0.4 s on the H200.

/// The packed modules: compiled by `build.rs` with feature
/// `rebuild-shaders`, else the committed `host/shaders/treelet_shaders.bin`.
pub const SHADERS: &[u8] = include_bytes!(env!("treelet_shaders.bin"));
/// Where the committed packed modules live (`host/shaders/`): what builds
/// without feature `rebuild-shaders` use as [`SHADERS`].
pub const COMMITTED_SHADERS_PATH: &str = env!("treelet_shaders_committed.bin");
/// Whether [`SHADERS`] was compiled by this build (feature `rebuild-shaders`).
pub const SHADERS_REBUILT: bool = cfg!(feature = "rebuild-shaders");
/// With feature `rebuild-shaders`, the shader build's peak memory in KiB:
/// the largest resident size of any process it ran (rust-gpu's rustc).
pub const SHADER_BUILD_PEAK_RSS_KB: Option<&str> = option_env!("treelet_shader_build_peak_rss_kb");

/// One entry point's module.
#[derive(Clone, Copy, Debug)]
pub struct Module {
    /// The entry point, as named in the shader crate (`sort::sort_onesweep_cs`).
    pub entry_point: &'static str,
    /// Its SPIR-V, little-endian words.
    pub spirv: &'static [u8],
}

impl Module {
    /// Length in 32-bit words: the code size of one kernel (rust-gpu
    /// inlines everything a kernel calls into it).
    pub fn words(&self) -> usize {
        self.spirv.len() / 4
    }
}

/// Every module of `packed`, in the order packed (sorted by entry point),
/// or why the bytes are not a packed set of modules.
pub fn unpack(packed: &'static [u8]) -> Result<Vec<Module>, String> {
    let word = |i: usize| -> Result<u32, String> {
        packed
            .get(4 * i..4 * i + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("packed SPIR-V ends at byte {} inside word {i}", packed.len()))
    };
    if packed.get(..8) != Some(b"TRLTSPV1".as_slice()) {
        return Err("packed SPIR-V does not start with TRLTSPV1".into());
    }
    let count = word(2)? as usize;
    let mut at = 3;
    let mut modules = Vec::with_capacity(count);
    for _ in 0..count {
        let name_len = word(at)? as usize;
        let name_bytes = packed
            .get(4 * (at + 1)..4 * (at + 1) + name_len)
            .ok_or_else(|| format!("packed SPIR-V: module {} has its name cut off", modules.len()))?;
        let entry_point =
            std::str::from_utf8(name_bytes).map_err(|e| format!("packed SPIR-V: a module's name: {e}"))?;
        at += 1 + name_len.div_ceil(4);
        let len = word(at)? as usize;
        let spirv = packed
            .get(4 * (at + 1)..4 * (at + 1 + len))
            .ok_or_else(|| format!("packed SPIR-V: module `{entry_point}` is cut off"))?;
        at += 1 + len;
        modules.push(Module { entry_point, spirv });
    }
    if 4 * at != packed.len() {
        return Err(format!("packed SPIR-V: {} bytes after the last module", packed.len() - 4 * at));
    }
    Ok(modules)
}

/// The module of `entry_point` in [`SHADERS`].
pub fn module(entry_point: &str) -> Option<Module> {
    static MODULES: std::sync::OnceLock<Vec<Module>> = std::sync::OnceLock::new();
    MODULES
        .get_or_init(|| unpack(SHADERS).unwrap_or_else(|e| panic!("the SPIR-V built into treelet: {e}")))
        .iter()
        .find(|m| m.entry_point == entry_point)
        .copied()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::kernels::Kernel;

    #[test]
    fn every_kernel_has_its_own_module() {
        for k in Kernel::all() {
            let m = module(k.entry_point()).unwrap_or_else(|| panic!("no module for {}", k.entry_point()));
            assert_eq!(&m.spirv[..4], &0x0723_0203u32.to_le_bytes(), "{}: not SPIR-V", k.entry_point());
        }
    }

    #[test]
    fn damaged_files_are_refused() {
        assert!(unpack(b"").is_err());
        assert!(unpack(b"TRLTSPV2\0\0\0\0").is_err());
        let whole = SHADERS;
        assert!(unpack(&whole[..whole.len() - 4]).is_err(), "a module cut short");
        assert_eq!(unpack(whole).map(|m| m.len()).unwrap_or(0), Kernel::all().len(), "one module per kernel");
    }
}
