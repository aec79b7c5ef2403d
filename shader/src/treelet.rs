use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::layout::{Node, TreeletParams};
use treelet_core::collapse::collapse_kernel;
use treelet_core::treelet::{
    treelet_commit_kernel, treelet_form_kernel, treelet_histogram_kernel, treelet_init_kernel, treelet_scatter_kernel,
    treelet_solve_phase, SOLVE_PHASES, TEAM_LEAVES, TEAM_TABLE,
};
use treelet_core::workgroup::{barrier, linear_group, linear_id};

/// Per-node counts, costs and heights, bottom up; acquire-release counters (GPUs).
#[spirv(compute(threads(256)))]
pub fn treelet_init_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] flags: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] costs: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] heights: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] tree_leaves: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_init_kernel::<true>(id, params, nodes, parents, flags, counts, costs, heights, tree_leaves);
}

/// As `treelet_init_cs` with relaxed counters, for CPU adapters (lavapipe).
#[spirv(compute(threads(256)))]
pub fn treelet_init_relaxed_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] flags: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] costs: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] heights: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] tree_leaves: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_init_kernel::<false>(id, params, nodes, parents, flags, counts, costs, heights, tree_leaves);
}

/// Counts treelet roots per height.
#[spirv(compute(threads(256)))]
pub fn treelet_histogram_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] counts: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] heights: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] level_counts: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_histogram_kernel(id, params, counts, heights, level_counts);
}

/// Lists treelet roots by height.
#[spirv(compute(threads(256)))]
pub fn treelet_scatter_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] counts: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] heights: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] cursors: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] roots: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_scatter_kernel(id, params, counts, heights, cursors, roots);
}

/// Forms the treelets of one height, one invocation each.
#[spirv(compute(threads(256)))]
pub fn treelet_form_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] roots: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] counts: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] costs: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] records: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_form_kernel(id, params, roots, nodes, counts, costs, records);
}

/// The DP of the treelets of one height, 32 lanes per treelet.
#[spirv(compute(threads(256)))]
pub fn treelet_solve_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] records: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] solutions: &mut [u32],
    #[spirv(workgroup)] leaves: &mut [f32; TEAM_LEAVES],
    #[spirv(workgroup)] cost: &mut [f32; TEAM_TABLE],
    #[spirv(workgroup)] partition: &mut [u32; TEAM_TABLE],
) {
    let group = linear_group(group.x, group.y, groups.x);
    for phase in 0..SOLVE_PHASES {
        treelet_solve_phase(phase, lid, group, params, records, solutions, leaves, cost, partition);
        barrier();
    }
}

/// Rewires the treelets of one height into their solved trees, one invocation each.
#[spirv(compute(threads(256)))]
pub fn treelet_commit_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] records: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] solutions: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] costs: &mut [f32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_commit_kernel(id, params, records, solutions, nodes, parents, counts, costs);
}

/// The final SAH leaf collapse and depth-first compaction, one invocation per primitive.
#[spirv(compute(threads(256)))]
pub fn collapse_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] counts: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] tree_leaves: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] prims: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] out_nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] out_parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] out_prims: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    collapse_kernel(id, params.n, nodes, parents, counts, tree_leaves, prims, out_nodes, out_parents, out_prims);
}
