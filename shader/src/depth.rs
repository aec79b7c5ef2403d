use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::geometry::buffers::{LayoutParams, Node};
use treelet_core::geometry::split::Split;
use treelet_core::gpu::workgroup::linear_id;

/// One node of a tree: a leaf raises the tree's depth to its own.
#[spirv(compute(threads(256)))]
pub fn tree_depth_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] deepest: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes_hi: &[Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let nodes = Split::new(nodes, nodes_hi);
    treelet_core::layouts::depth::leaf_depth_kernel(id, params.nodes, &nodes, parents, deepest);
}
