use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::layout::{Node, TreeletParams};
use treelet_core::collapse::collapse_kernel;
use treelet_core::treelet::{treelet_init_kernel, treelet_level_kernel};
use treelet_core::workgroup::linear_id;

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

/// Restructures the treelets of one height.
#[spirv(compute(threads(256)))]
pub fn treelet_level_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &TreeletParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] costs: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] heights: &[u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_level_kernel(id, params, nodes, parents, counts, costs, heights);
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
