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

    /// No module merges pointers at a phi (`OpPhi` of a pointer, or of a
    /// struct holding one): NVIDIA's SPIR-V compiler (driver 580.159.04)
    /// segfaulted creating every pipeline that did. rust-gpu makes one of a
    /// value that holds a buffer's reference and changes in a loop: keep
    /// what a loop carries plain values, buffers beside it
    /// (`docs/results/h200-cast-crash-2026-12-03/`).
    #[test]
    fn no_module_merges_pointers_at_a_phi() {
        for m in unpack(SHADERS).unwrap() {
            let words: Vec<u32> = m.spirv.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
            // Pointer types, and structs with such a member (at any depth:
            // SPIR-V declares a type before its use).
            let mut holds_pointer = std::collections::HashSet::new();
            let mut at = 5;
            while at < words.len() {
                let (count, op) = ((words[at] >> 16) as usize, words[at] & 0xFFFF);
                assert!(count > 0 && at + count <= words.len(), "{}: malformed at word {at}", m.entry_point);
                let ins = &words[at..at + count];
                match op {
                    32 => {
                        holds_pointer.insert(ins[1]); // OpTypePointer
                    }
                    30 if ins[2..].iter().any(|t| holds_pointer.contains(t)) => {
                        holds_pointer.insert(ins[1]); // OpTypeStruct
                    }
                    245 => assert!(!holds_pointer.contains(&ins[1]), "{}: a phi of pointers (%{})", m.entry_point, ins[2]), // OpPhi
                    _ => {}
                }
                at += count;
            }
        }
    }
}

impl Module {
    /// Bytes of workgroup memory the module declares (its `Workgroup`
    /// variables, sizes summed without padding): what a device's
    /// `max_compute_workgroup_storage_size` must hold for its pipeline.
    pub fn workgroup_bytes(&self) -> u64 {
        const OP_TYPE_INT: u32 = 21;
        const OP_TYPE_FLOAT: u32 = 22;
        const OP_TYPE_VECTOR: u32 = 23;
        const OP_TYPE_ARRAY: u32 = 28;
        const OP_TYPE_STRUCT: u32 = 30;
        const OP_TYPE_POINTER: u32 = 32;
        const OP_CONSTANT: u32 = 43;
        const OP_VARIABLE: u32 = 59;
        const WORKGROUP: u32 = 4;
        let words: Vec<u32> = self.spirv.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let mut sizes: HashMap<u32, u64> = HashMap::new();
        let mut constants: HashMap<u32, u64> = HashMap::new();
        let mut pointees: HashMap<u32, u32> = HashMap::new();
        let mut total = 0;
        let mut at = 5;
        while at < words.len() {
            let (count, op) = ((words[at] >> 16) as usize, words[at] & 0xffff);
            if count == 0 || at + count > words.len() {
                break;
            }
            let i = &words[at..at + count];
            let size = |id: u32| sizes.get(&id).copied().unwrap_or(0);
            match op {
                OP_TYPE_INT | OP_TYPE_FLOAT => {
                    sizes.insert(i[1], i[2] as u64 / 8);
                }
                OP_TYPE_VECTOR => {
                    sizes.insert(i[1], size(i[2]) * i[3] as u64);
                }
                OP_TYPE_ARRAY => {
                    sizes.insert(i[1], size(i[2]) * constants.get(&i[3]).copied().unwrap_or(0));
                }
                OP_TYPE_STRUCT => {
                    sizes.insert(i[1], i[2..].iter().map(|&m| size(m)).sum());
                }
                OP_TYPE_POINTER if i[2] == WORKGROUP => {
                    pointees.insert(i[1], i[3]);
                }
                OP_CONSTANT if count >= 4 => {
                    constants.insert(i[2], i[3] as u64);
                }
                OP_VARIABLE if i[3] == WORKGROUP => {
                    total += pointees.get(&i[1]).map_or(0, |&t| size(t));
                }
                _ => {}
            }
            at += count;
        }
        total
    }
}

use std::collections::HashMap;

#[cfg(test)]
mod workgroup_tests {
    use super::*;

    /// The reader finds the workgroup arrays the shader declares: the sort's
    /// tiles, the treelet teams' rows; none in a fill.
    #[test]
    fn workgroup_bytes_of_known_kernels() {
        let fill = module("per_invocation::fill_cs").unwrap();
        assert_eq!(fill.workgroup_bytes(), 0);
        let every = unpack(SHADERS).unwrap();
        let largest = every.iter().map(|m| (m.workgroup_bytes(), m.entry_point)).max().unwrap();
        assert!(largest.0 >= 4096 && largest.0 <= 65536, "{largest:?}");
        // Two arrays of 256 words at least (the scan's `a` and `b`).
        let scan = every.iter().find(|m| m.entry_point == "per_workgroup::scan_spine_cs").unwrap();
        assert!(scan.workgroup_bytes() >= 2048, "{}: {}", scan.entry_point, scan.workgroup_bytes());
    }
}
