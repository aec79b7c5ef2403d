use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::construct::sort::multisplit_rank::{multisplit_op, multisplit_phase, MultisplitLane, MULTISPLIT_PHASES};
use treelet_core::geometry::buffers::SortParams;
use treelet_core::gpu::subgroup::{apply, Lane};
use treelet_core::gpu::workgroup::{linear_group, linear_id};

/// Ranks each key among its subgroup's keys with the same digit: the lane's
/// state stays in registers, and the ballots between phases need no barrier.
#[spirv(compute(threads(256)))]
#[allow(clippy::too_many_arguments)]
pub fn multisplit_rank_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(subgroup_local_invocation_id)] lane: u32,
    #[spirv(subgroup_size)] size: u32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &SortParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] ranks: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] sizes: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let group = linear_group(group.x, group.y, groups.x);
    let mut state = MultisplitLane::default();
    let mut io = Lane::default();
    for phase in 0..MULTISPLIT_PHASES {
        multisplit_phase(phase, id, group, lane, size, params, keys, ranks, counts, sizes, &mut state, &mut io);
        apply(multisplit_op(phase), &mut io);
    }
}
