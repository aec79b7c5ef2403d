use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::construct::treelet::SUBSETS;
use treelet_core::construct::treelet::kernels::{RESTRUCTURE_PHASES, TEAM, TEAM_COSTS, TEAM_PARTS, TEAM_STAGE, TEAM_VOTES, treelet_restructure_phase};
use treelet_core::geometry::buffers::{Node, TreeletParams};
use treelet_core::geometry::split::SplitMut;
use treelet_core::gpu::subgroup::subgroup_barrier;
use treelet_core::gpu::workgroup::{barrier, linear_group};

/// Restructures the treelets of one height, a team of 32 lanes each.
#[spirv(compute(threads(128)))]
pub fn treelet_restructure_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(subgroup_size)] subgroup_size: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] roots: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] subsets: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] costs: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] heights: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] marks: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] nodes_hi: &mut [Node],
    #[spirv(workgroup)] stage: &mut [u32; TEAM_STAGE],
    #[spirv(workgroup)] cost: &mut [f32; TEAM_COSTS],
    #[spirv(workgroup)] parts: &mut [u32; TEAM_PARTS],
    #[spirv(workgroup)] order: &mut [u32; SUBSETS],
    #[spirv(workgroup)] votes: &mut [u32; TEAM_VOTES],
) {
    let group = linear_group(group.x, group.y, groups.x);
    let nodes = &mut SplitMut::new(nodes, nodes_hi);
    // Read once: each phase would load it again after its barrier.
    let params = *params;
    // After the first phase (which fills the shared subset order), a team
    // shares workgroup memory only within itself: where a team lies within
    // one subgroup, a subgroup barrier suffices, and a team goes on without
    // waiting for the workgroup's slowest.
    let team_in_subgroup = subgroup_size >= TEAM;
    // The phases unrolled, each with its number a constant, so that the
    // driver's compiler keeps only that phase's branch (as the sort pass
    // does: see `sort::sort_multisplit_cs`).
    macro_rules! phases {
        ($($phase:literal)*) => {
            const _: () = assert!([$($phase),*].len() as u32 == RESTRUCTURE_PHASES);
            $(
                treelet_restructure_phase(
                    $phase, lid, group, &params, roots, subsets, nodes, parents, counts, costs, heights, marks, stage,
                    cost, parts, order, votes,
                );
                if $phase == 0 || !team_in_subgroup {
                    barrier();
                } else {
                    subgroup_barrier();
                }
            )*
        };
    }
    phases!(0 1 2 3 4 5 6 7 8);
}
