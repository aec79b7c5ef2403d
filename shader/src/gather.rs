use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::geometry::buffers::GatherParams;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::linear_id;

#[spirv(compute(threads(256)))]
pub fn gather_triangles_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &GatherParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] vertices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] out: &mut [Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] flags: &mut [u32],
) {
    treelet_core::geometry::gather::gather_triangles_kernel(linear_id(gid.x, gid.y, groups.x), params, vertices, indices, out, flags);
}
