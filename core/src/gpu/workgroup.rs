//! Workgroups, on the GPU and on the CPU.
//!
//! Kernels that share workgroup memory are written as numbered *phases*
//! separated by barriers: `fn <kernel>_phase(phase, local_id, ...)` with a
//! constant `<KERNEL>_PHASES`. Every value that crosses a barrier lives in a
//! workgroup array, never in a local variable. On the GPU an entry point runs
//! the phases in order for its own invocation with a [`barrier`] after each;
//! the CPU runner runs each phase for local ids `0..WORKGROUP_SIZE` in turn,
//! which is one valid schedule of the same program. One source, two targets.
//!
//! (Phases are plain functions rather than closures because rust-gpu cannot
//! yet lower closures that capture references: they become structs of
//! pointers, which logical SPIR-V forbids.)

/// Invocations per workgroup, for every kernel of Treelet but the ray
/// kernels ([`RAY_WORKGROUP_SIZE`]).
pub const WORKGROUP_SIZE: u32 = 256;
/// Invocations per workgroup of the kernels that trace rays, one
/// invocation a pixel or ray (the render's camera and light paths, the
/// casts of `bench rays` and of the engine API; not the cast that keeps
/// its stack in workgroup memory). Their lanes end at different times (a
/// pixel's paths are as long as roulette makes them), and a workgroup's
/// registers come back only when its last lane is done: in workgroups of
/// two warps the SM starts new work sooner than in workgroups of eight. On
/// an H200, 1024x768 renders took 0.530 -> 0.521 s of kernels (cornell,
/// 1024 spp), 0.798 -> 0.758 s (`scenes/room_disk.json`), 0.574 -> 0.519 s
/// (the bunny through `bvh2`, 256 spp) against 256; 32 was no better
/// (`docs/results/h200-ray-workgroups-2026-11-28/`).
pub const RAY_WORKGROUP_SIZE: u32 = 64;
/// `WORKGROUP_SIZE` as a `usize`, for array lengths of workgroup memory.
pub const WG: usize = WORKGROUP_SIZE as usize;
/// log2(WORKGROUP_SIZE): steps of a tree reduction or a Hillis-Steele scan.
pub const WG_LOG2: u32 = WORKGROUP_SIZE.trailing_zeros();

/// Waits for every invocation of the workgroup and makes its workgroup-memory
/// writes visible (GPU only; the CPU schedule needs none).
#[inline]
pub fn barrier() {
    #[cfg(target_arch = "spirv")]
    spirv_std::arch::workgroup_memory_barrier_with_group_sync();
}

/// Phases of [`hillis_steele_step`] for a whole workgroup scan.
pub const SCAN_STEPS: u32 = 2 * WG_LOG2;

/// Step `step` (of [`SCAN_STEPS`]) of an inclusive Hillis-Steele scan of `a`
/// across the workgroup, with `b` as scratch: even steps add the value
/// `2^(step/2)` places to the left into `b`, odd steps copy `b` back.
#[inline]
pub fn hillis_steele_step(step: u32, lid: u32, a: &mut [u32; WG], b: &mut [u32; WG]) {
    let l = lid as usize;
    let offset = 1u32 << (step / 2);
    if step.is_multiple_of(2) {
        let prev = if lid >= offset { a[l - offset as usize] } else { 0 };
        b[l] = a[l] + prev;
    } else {
        a[l] = b[l];
    }
}

/// Phases of [`small_scan_phase`].
pub const SMALL_SCAN_PHASES: u32 = 3;
const _: () = assert!(WG == 16 * 16, "sixteen invocations of sixteen values");

/// Exclusive prefix sum of a workgroup's 256 values in three phases: sixteen invocations
/// each scan sixteen values, one scans their sums, all add. (Cheaper here
/// than a Hillis-Steele scan's sixteen phases: the values are few.)
#[inline]
pub fn small_scan_phase(phase: u32, lid: u32, values: &[u32; WG], out: &mut [u32; WG], sums: &mut [u32; 16]) {
    let l = lid as usize;
    match phase {
        0 => {
            if l < 16 {
                let mut sum = 0;
                for k in 16 * l..16 * l + 16 {
                    out[k] = sum;
                    sum += values[k];
                }
                sums[l] = sum;
            }
        }
        1 => {
            if l == 0 {
                let mut sum = 0;
                for k in 0..16 {
                    let v = sums[k];
                    sums[k] = sum;
                    sum += v;
                }
            }
        }
        _ => out[l] += sums[l / 16],
    }
}

/// Stride of step `step` (of [`WG_LOG2`]) of a tree reduction: 128, 64, .., 1.
#[inline]
pub fn reduction_stride(step: u32) -> u32 {
    (WORKGROUP_SIZE / 2) >> step
}

/// Linear invocation id of a 2D dispatch (x fastest), so that more than
/// 65535 workgroups of work can be dispatched: see [`dispatch_grid`].
#[inline]
pub fn linear_id(global_x: u32, global_y: u32, num_groups_x: u32) -> u32 {
    linear_id_in(global_x, global_y, num_groups_x, WORKGROUP_SIZE)
}

/// [`linear_id`] for workgroups of `size` invocations.
#[inline]
pub fn linear_id_in(global_x: u32, global_y: u32, num_groups_x: u32, size: u32) -> u32 {
    global_y * num_groups_x * size + global_x
}

/// Linear workgroup id of a 2D dispatch.
#[inline]
pub fn linear_group(group_x: u32, group_y: u32, num_groups_x: u32) -> u32 {
    group_y * num_groups_x + group_x
}

/// Largest workgroup count per dimension that every Vulkan device accepts.
pub const MAX_GROUPS_PER_DIM: u32 = 65535;

/// Splits `groups` workgroups into an (x, y) grid within the per-dimension
/// limit. Kernels see `linear_group(..) < groups` for the real ones and must
/// bounds-check the rest.
#[inline]
pub fn dispatch_grid(groups: u32) -> [u32; 2] {
    if groups <= MAX_GROUPS_PER_DIM {
        [groups, 1]
    } else {
        let y = groups.div_ceil(MAX_GROUPS_PER_DIM);
        [groups.div_ceil(y), y]
    }
}

/// Workgroups needed to cover `n` items, `per_group` at a time.
#[inline]
pub fn groups_for(n: u32, per_group: u32) -> u32 {
    n.div_ceil(per_group)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_scan_is_an_exclusive_prefix_sum() {
        let mut values = [0u32; WG];
        for (i, v) in values.iter_mut().enumerate() {
            *v = (i as u32).wrapping_mul(2654435761) % 97;
        }
        let (mut out, mut sums) = ([0u32; WG], [0u32; 16]);
        for phase in 0..SMALL_SCAN_PHASES {
            for lid in 0..WORKGROUP_SIZE {
                small_scan_phase(phase, lid, &values, &mut out, &mut sums);
            }
        }
        let mut sum = 0;
        for i in 0..WG {
            assert_eq!(out[i], sum, "at {i}");
            sum += values[i];
        }
    }

    #[test]
    fn grid_covers_every_group_once() {
        for groups in [0u32, 1, 65535, 65536, 200_000, 1 << 20] {
            let [x, y] = dispatch_grid(groups);
            assert!(x <= MAX_GROUPS_PER_DIM && y <= MAX_GROUPS_PER_DIM);
            assert!(x as u64 * y as u64 >= groups as u64);
            assert!((x as u64) * (y as u64 - 1) < groups.max(1) as u64);
        }
    }
}
