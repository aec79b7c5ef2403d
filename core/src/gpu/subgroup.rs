//! Subgroup operations (ballot, shuffle, sums and prefix sums across the
//! lanes of a subgroup), on the GPU and on the CPU.
//!
//! This extends the phase model of [`super::workgroup`]. A kernel that uses
//! subgroup operations is written in numbered phases, and a phase may end in
//! one subgroup operation, which is a function of the phase number alone
//! (`const fn <kernel>_op(phase) -> u32`, one of the `OP_*` below, or
//! `<kernel>_sync` where it also carries a barrier: [`THEN_SUBGROUP_BARRIER`],
//! [`THEN_WORKGROUP_BARRIER`], for kernels that also share workgroup
//! memory, such as the sort pass of `construct::sort::multisplit`): the phase
//! writes the operation's input into its lane's [`Lane`], the entry point (or
//! the CPU runner) applies the operation, and the next phase reads the result
//! from the same [`Lane`]. A value that crosses a subgroup operation lives in
//! the lane's own state:
//!
//! - on the GPU, local variables of the invocation (registers: no workgroup
//!   memory, and no barrier, as subgroup operations synchronize their lanes
//!   themselves), with `apply` (GPU builds only) calling the SPIR-V instruction;
//! - on the CPU, one element per lane of arrays kept by the runner, which runs
//!   the phase for every lane, then [`emulate`]s the operation subgroup by
//!   subgroup.
//!
//! One source, and the CPU run is exact at any subgroup size, which the CPU
//! runner takes as a parameter so that it matches the GPU's (H100: 32;
//! lavapipe: 8). Every lane runs every phase, so every operation is reached
//! in uniform control flow, which SPIR-V's non-uniform operations need for a
//! result over the whole subgroup. Lanes are numbered as the GPU numbers
//! them in a one-dimensional workgroup: subgroup `lid / size`, lane
//! `lid % size` (what Vulkan implementations do with full subgroups; the GPU
//! = CPU tests check it on each device).
//!
//! Subgroup sizes from 1 to 64 are supported (ballots are 64-bit masks).
//!
//! Entry points unroll their phases (a macro with the phase numbers as
//! literals) rather than loop over them: on the H100 the sort pass ranked by
//! subgroups took 1.04 ms per 1M keys as a loop and 0.66 ms unrolled, as
//! the driver then keeps only each phase's own branch.

/// No subgroup operation after this phase.
pub const OP_NONE: u32 = 0;
/// `output` = the mask (bit `l` for lane `l`) of the lanes whose `input` is
/// not zero. Lanes past the subgroup's size are 0.
pub const OP_BALLOT: u32 = 1;
/// `output` = the `input` of lane `arg` (lane `arg` must exist).
pub const OP_SHUFFLE: u32 = 2;
/// `output` = the sum (wrapping) of the `input`s of the lanes below this one.
pub const OP_EXCLUSIVE_ADD: u32 = 3;
/// `output` = the sum (wrapping) of the `input`s of this lane and those below.
pub const OP_INCLUSIVE_ADD: u32 = 4;
/// `output` = the sum (wrapping) of every lane's `input`.
pub const OP_ADD: u32 = 5;

/// `output` = the mask of the lanes whose `arg` is not zero and whose
/// `input` has the same low 8 bits as this lane's (0 where this lane's `arg`
/// is zero): CUDA's `__match_any_sync` over a byte. Core Vulkan has no match
/// instruction (NVIDIA's partitioned extension is not core), so the GPU
/// builds it from nine ballots, as Onesweep's multisplit does.
pub const OP_MATCH_BYTE: u32 = 6;
/// [`OP_MATCH_BYTE`] by one instruction, `OpGroupNonUniformPartitionNV`
/// (`SPV_NV_shader_subgroup_partitioned`, NVIDIA's `MATCH.ANY`), for
/// kernels dispatched only on devices whose Vulkan driver has the
/// extension and on which the host enabled it. The same result as
/// [`OP_MATCH_BYTE`] (the CPU runner computes both alike): on the H100 the
/// nine ballots and their mask logic are what bound the sort's ranking.
pub const OP_MATCH_BYTE_PARTITIONED: u32 = 7;

/// The operation part of a phase's synchronisation code.
pub const OP_MASK: u32 = 0xff;
/// Flag of a synchronisation code: after the operation, a barrier across the
/// subgroup that makes the workgroup memory its lanes wrote visible to each
/// other (GLSL's `subgroupBarrier`). The CPU runner needs none: it runs a
/// phase for every lane of the workgroup before the next.
pub const THEN_SUBGROUP_BARRIER: u32 = 1 << 8;
/// Flag of a synchronisation code: after the operation, a workgroup barrier
/// ([`super::workgroup::barrier`]), for kernels that mix both kinds of phase.
pub const THEN_WORKGROUP_BARRIER: u32 = 1 << 9;

/// Flag of a synchronisation code: after the operation, a barrier across the
/// subgroup that also orders storage-buffer accesses at device scope, so
/// that what one lane acquired (or its lanes wrote) from other invocations
/// is visible to (or released by) the others: for kernels whose lanes take
/// turns at climbing and share the work at each level (`construct::hploc`).
pub const THEN_STORAGE_BARRIER: u32 = 1 << 10;

/// Synchronisation code `sync` for a device whose subgroups run their lanes
/// in lockstep, one vector instruction for all lanes in program order
/// (lavapipe: a subgroup is one SIMD vector of one CPU thread), where the
/// lanes see each other's accesses without a barrier: the subgroup barriers
/// are dropped. Needed there because lavapipe executes any barrier, even
/// an `OpMemoryBarrier`, as a workgroup barrier, so a kernel whose subgroups
/// loop a different number of times (`construct::hploc`) loses the
/// invocations that wait at one after the rest of the workgroup has
/// returned (seen: climbs stopped at their second level, merges after
/// loading their clusters).
#[inline]
pub const fn lockstep(sync: u32) -> u32 {
    sync & !(THEN_SUBGROUP_BARRIER | THEN_STORAGE_BARRIER)
}

/// Largest subgroup size supported (ballots are 64-bit).
pub const MAX_SUBGROUP_SIZE: u32 = 64;

/// One lane's side of a subgroup operation.
#[derive(Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Lane {
    pub input: u32,
    /// A second operand: the source lane of [`OP_SHUFFLE`].
    pub arg: u32,
    /// The result (a ballot's 64-bit mask).
    pub output: u64,
}

/// Applies synchronisation code `sync` (an `OP_*`, with `THEN_*` flags)
/// across the subgroup on the GPU: `lane` is this invocation's.
#[cfg(target_arch = "spirv")]
#[inline]
pub fn apply(sync: u32, lane: &mut Lane) {
    apply_with::<false>(sync, lane)
}

/// [`apply`], also for [`OP_MATCH_BYTE_PARTITIONED`] when `PARTITIONED`
/// (a kernel whose codes are not constants would otherwise carry the
/// partition instruction, and need its extension, for nothing).
#[cfg(target_arch = "spirv")]
#[inline]
pub fn apply_with<const PARTITIONED: bool>(sync: u32, lane: &mut Lane) {
    use spirv_std::arch::{
        subgroup_ballot, subgroup_exclusive_i_add, subgroup_i_add, subgroup_inclusive_i_add, subgroup_shuffle,
    };
    let op = sync & OP_MASK;
    if op == OP_MATCH_BYTE {
        let taking_part = subgroup_ballot(lane.arg != 0);
        if taking_part.y == 0 {
            // No lane above 31 takes part (always so in subgroups of 32
            // lanes, NVIDIA's): the masks in 32 bits. The ranking is bound
            // by issuing these instructions (H100: a pass that only ran its
            // subgroup operations took 130 of its 450 us at 16M keys), and
            // 64-bit masks take two of each logic operation.
            let mut peers = taking_part.x;
            let mut bit = 0;
            while bit < 8 {
                let set = (lane.input >> bit) & 1 != 0;
                let voted = subgroup_ballot(set).x;
                peers &= if set { voted } else { !voted };
                bit += 1;
            }
            lane.output = if lane.arg != 0 { peers as u64 } else { 0 };
        } else {
            let mut peers = ballot_mask(taking_part);
            let mut bit = 0;
            while bit < 8 {
                let set = (lane.input >> bit) & 1 != 0;
                let voted = ballot_mask(subgroup_ballot(set));
                peers &= if set { voted } else { !voted };
                bit += 1;
            }
            lane.output = if lane.arg != 0 { peers } else { 0 };
        }
    } else if PARTITIONED && op == OP_MATCH_BYTE_PARTITIONED {
        // Lanes not taking part share a value no byte has (and get 0).
        let value = if lane.arg != 0 { lane.input & 0xff } else { 0x100 };
        let peers = ballot_mask(partition(value));
        lane.output = if lane.arg != 0 { peers } else { 0 };
    } else if op == OP_BALLOT {
        lane.output = ballot_mask(subgroup_ballot(lane.input != 0));
    } else if op == OP_SHUFFLE {
        lane.output = subgroup_shuffle(lane.input, lane.arg) as u64;
    } else if op == OP_EXCLUSIVE_ADD {
        lane.output = subgroup_exclusive_i_add(lane.input) as u64;
    } else if op == OP_INCLUSIVE_ADD {
        lane.output = subgroup_inclusive_i_add(lane.input) as u64;
    } else if op == OP_ADD {
        lane.output = subgroup_i_add(lane.input) as u64;
    }
    if sync & THEN_SUBGROUP_BARRIER != 0 {
        subgroup_barrier();
    }
    if sync & THEN_WORKGROUP_BARRIER != 0 {
        super::workgroup::barrier();
    }
    if sync & THEN_STORAGE_BARRIER != 0 {
        subgroup_storage_barrier();
    }
}

/// A barrier across the subgroup that makes the workgroup memory its lanes
/// wrote visible to each other (GLSL's `subgroupBarrier`): for kernels whose
/// teams of lanes, each within one subgroup, share workgroup memory only
/// among themselves. Nothing to do on the CPU runner, which runs a phase
/// for every lane before the next.
#[inline]
pub fn subgroup_barrier() {
    #[cfg(target_arch = "spirv")]
    {
        use spirv_std::memory::{Scope, Semantics};
        spirv_std::arch::control_barrier::<
            { Scope::Subgroup as u32 },
            { Scope::Subgroup as u32 },
            { Semantics::WORKGROUP_MEMORY.bits() | Semantics::ACQUIRE_RELEASE.bits() },
        >();
    }
}

/// [`subgroup_barrier`] that also orders storage-buffer memory, at device
/// scope ([`THEN_STORAGE_BARRIER`]). Nothing to do on the CPU runner.
#[inline]
pub fn subgroup_storage_barrier() {
    #[cfg(target_arch = "spirv")]
    {
        use spirv_std::memory::{Scope, Semantics};
        spirv_std::arch::control_barrier::<
            { Scope::Subgroup as u32 },
            { Scope::Device as u32 },
            { Semantics::WORKGROUP_MEMORY.bits() | Semantics::UNIFORM_MEMORY.bits() | Semantics::ACQUIRE_RELEASE.bits() },
        >();
    }
}

/// The mask of the lanes whose `value` equals this lane's
/// (`OpGroupNonUniformPartitionNV`; rspirv spells the same opcode with EXT).
#[cfg(target_arch = "spirv")]
#[inline]
fn partition(value: u32) -> spirv_std::glam::UVec4 {
    let mut result = spirv_std::glam::UVec4::ZERO;
    // SAFETY: one subgroup instruction on a plain value; dispatched only
    // where the device has the extension (see `OP_MATCH_BYTE_PARTITIONED`).
    unsafe {
        core::arch::asm!(
            "%value = OpLoad _ {value}",
            "%result = OpGroupNonUniformPartitionEXT typeof*{result} %value",
            "OpStore {result} %result",
            value = in(reg) &value,
            result = in(reg) &mut result,
        );
    }
    result
}

/// A ballot's lanes as a 64-bit mask.
#[cfg(target_arch = "spirv")]
#[inline]
fn ballot_mask(ballot: spirv_std::glam::UVec4) -> u64 {
    ballot.x as u64 | (ballot.y as u64) << 32
}

/// Applies the operation of synchronisation code `sync` to one subgroup's
/// lanes on the CPU (`lanes.len()` is the subgroup's size, at most
/// [`MAX_SUBGROUP_SIZE`]), as the GPU's `apply` does in each of its
/// invocations. Barriers need nothing here (see [`THEN_SUBGROUP_BARRIER`]).
#[inline]
pub fn emulate(sync: u32, lanes: &mut [Lane]) {
    let n = lanes.len();
    let op = sync & OP_MASK;
    match op {
        OP_MATCH_BYTE | OP_MATCH_BYTE_PARTITIONED => {
            let mut bytes = [0u32; MAX_SUBGROUP_SIZE as usize];
            for l in 0..n {
                bytes[l] = if lanes[l].arg != 0 { lanes[l].input & 0xff } else { u32::MAX };
            }
            for l in 0..n {
                let mut peers = 0u64;
                if bytes[l] != u32::MAX {
                    for (k, &b) in bytes[..n].iter().enumerate() {
                        if b == bytes[l] {
                            peers |= 1 << k;
                        }
                    }
                }
                lanes[l].output = peers;
            }
        }
        OP_BALLOT => {
            let mut mask = 0u64;
            for (l, lane) in lanes.iter().enumerate() {
                if lane.input != 0 {
                    mask |= 1 << l;
                }
            }
            for lane in lanes.iter_mut() {
                lane.output = mask;
            }
        }
        OP_SHUFFLE => {
            let mut values = [0u32; MAX_SUBGROUP_SIZE as usize];
            for l in 0..n {
                values[l] = lanes[l].input;
            }
            for lane in lanes.iter_mut() {
                lane.output = values[lane.arg as usize] as u64;
            }
        }
        OP_EXCLUSIVE_ADD | OP_INCLUSIVE_ADD => {
            let mut sum = 0u32;
            for lane in lanes.iter_mut() {
                let before = sum;
                sum = sum.wrapping_add(lane.input);
                lane.output = if op == OP_EXCLUSIVE_ADD { before } else { sum } as u64;
            }
        }
        OP_ADD => {
            let sum = lanes.iter().fold(0u32, |s, l| s.wrapping_add(l.input));
            for lane in lanes.iter_mut() {
                lane.output = sum as u64;
            }
        }
        _ => {}
    }
}

/// The mask of the lanes below `lane` (`lane` < 64).
#[inline]
pub fn lanes_below(lane: u32) -> u64 {
    (1u64 << lane) - 1
}

/// The mask of every lane of a subgroup of `size` lanes.
#[inline]
pub fn all_lanes(size: u32) -> u64 {
    if size >= 64 {
        u64::MAX
    } else {
        (1u64 << size) - 1
    }
}

/// The highest lane of a non-empty mask (in 32-bit halves: the GPU's
/// find-most-significant-bit takes 32-bit operands).
#[inline]
pub fn highest_lane(mask: u64) -> u32 {
    let (low, high) = (mask as u32, (mask >> 32) as u32);
    if high != 0 {
        63 - high.leading_zeros()
    } else {
        31 - low.leading_zeros()
    }
}

/// The lowest lane of a non-empty mask (in 32-bit halves, as
/// [`highest_lane`]).
#[inline]
pub fn lowest_lane(mask: u64) -> u32 {
    let low = mask as u32;
    if low != 0 {
        low.trailing_zeros()
    } else {
        32 + ((mask >> 32) as u32).trailing_zeros()
    }
}

/// Bits set in a 64-bit mask (two 32-bit counts: 64-bit `OpBitCount` is
/// not required of Vulkan drivers).
#[inline]
pub fn popcount(mask: u64) -> u32 {
    (mask as u32).count_ones() + ((mask >> 32) as u32).count_ones()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::rng::hash;
    extern crate std;

    /// Plain references, one lane at a time.
    fn reference(op: u32, inputs: &[(u32, u32)], l: usize) -> u64 {
        let n = inputs.len();
        match op {
            OP_BALLOT => (0..n).filter(|&k| inputs[k].0 != 0).map(|k| 1u64 << k).sum(),
            OP_SHUFFLE => inputs[inputs[l].1 as usize].0 as u64,
            OP_EXCLUSIVE_ADD => inputs[..l].iter().map(|x| x.0 as u64).sum::<u64>() as u32 as u64,
            OP_INCLUSIVE_ADD => inputs[..=l].iter().map(|x| x.0 as u64).sum::<u64>() as u32 as u64,
            OP_ADD => inputs.iter().map(|x| x.0 as u64).sum::<u64>() as u32 as u64,
            OP_MATCH_BYTE if inputs[l].1 == 0 => 0,
            OP_MATCH_BYTE => (0..n)
                .filter(|&k| inputs[k].1 != 0 && inputs[k].0 % 256 == inputs[l].0 % 256)
                .map(|k| 1u64 << k)
                .sum(),
            _ => 0,
        }
    }

    #[test]
    fn each_operation_matches_a_plain_reference_at_every_size() {
        // A fresh seed each run (printed, to repeat a failure).
        let seed = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().subsec_nanos();
        std::eprintln!("seed {seed}");
        for size in [1u32, 4, 8, 16, 32, 64] {
            for trial in 0..50u32 {
                let draw = |k: u32| hash(seed ^ hash(trial ^ hash(size ^ hash(k))));
                let inputs: [(u32, u32); 64] = core::array::from_fn(|l| {
                    let v = draw(l as u32);
                    // Small values half the time (ballots of zero and non-zero), any the rest (wrapping sums).
                    // Few values, any values, or few low bytes under any high bits (matches).
                    let v = match trial % 3 {
                        0 => v % 3,
                        1 => v,
                        _ => v & !0xff | (v >> 24) % 4,
                    };
                    (v, draw(64 + l as u32) % size)
                });
                let inputs = &inputs[..size as usize];
                for op in [OP_BALLOT, OP_SHUFFLE, OP_EXCLUSIVE_ADD, OP_INCLUSIVE_ADD, OP_ADD, OP_MATCH_BYTE] {
                    let mut lanes = [Lane::default(); 64];
                    for (l, &(input, arg)) in inputs.iter().enumerate() {
                        lanes[l] = Lane { input, arg, output: 0 };
                    }
                    emulate(op, &mut lanes[..size as usize]);
                    for l in 0..size as usize {
                        assert_eq!(lanes[l].output, reference(op, inputs, l), "op {op}, size {size}, lane {l}");
                    }
                }
            }
        }
    }

    #[test]
    fn masks_and_counts() {
        assert_eq!(lanes_below(0), 0);
        assert_eq!(lanes_below(5), 0b11111);
        assert_eq!(lanes_below(63), u64::MAX >> 1);
        assert_eq!(all_lanes(8), 0xff);
        assert_eq!(all_lanes(64), u64::MAX);
        assert_eq!(popcount(u64::MAX), 64);
        assert_eq!(popcount(1 << 40 | 3), 3);
        assert_eq!(highest_lane(1), 0);
        assert_eq!(highest_lane(0b1011), 3);
        assert_eq!(highest_lane(1 << 40 | 3), 40);
        assert_eq!(highest_lane(u64::MAX), 63);
        assert_eq!(lowest_lane(1), 0);
        assert_eq!(lowest_lane(0b1010_0000), 5);
        assert_eq!(lowest_lane(1 << 40 | 1 << 63), 40);
        assert_eq!(lowest_lane(u64::MAX), 0);
    }
}
