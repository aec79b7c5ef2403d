use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::Node;
use treelet_core::geometry::split::SplitMut;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::gpu::workgroup::linear_id;

#[spirv(compute(threads(256)))]
pub fn radix_tree_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes_hi: &mut [Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::construct::radix_tree::radix_tree_kernel(id, params.n, keys, &mut SplitMut::new(nodes, nodes_hi), parents);
}
