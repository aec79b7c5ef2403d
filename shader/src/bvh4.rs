use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::geometry::buffers::LayoutParams;
use treelet_core::gpu::workgroup::linear_id;

/// One node of the two-box layout into the 4-wide one
/// (`treelet_core::layouts::bvh4`).
#[spirv(compute(threads(256)))]
pub fn bvh4_nodes_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::layouts::bvh4::bvh4_node_kernel(id, params.nodes, nodes, out);
}
