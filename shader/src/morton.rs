use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::Aabb;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::gpu::workgroup::linear_id;

#[spirv(compute(threads(256)))]
pub fn morton_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] boxes: &[Aabb],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] keys: &mut [u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] values: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] slots: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] zeroed: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::construct::morton::morton_kernel(id, params, boxes, keys, values, slots, zeroed);
}
