use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::geometry::buffers::{CopyParams, FillParams};
use treelet_core::gpu::workgroup::linear_id;

#[spirv(compute(threads(256)))]
pub fn fill_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &FillParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] data: &mut [u32],
) {
    treelet_core::construct::fill::fill_kernel(linear_id(gid.x, gid.y, groups.x), params, data);
}

#[spirv(compute(threads(256)))]
pub fn copy_words_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &CopyParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] dst: &mut [u32],
) {
    treelet_core::construct::fill::copy_words_kernel(linear_id(gid.x, gid.y, groups.x), params, src, dst);
}
