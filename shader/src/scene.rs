use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::geometry::split::Split;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::linear_id;
use treelet_core::Sphere;

#[spirv(compute(threads(256)))]
pub fn primitive_boxes_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] boxes: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] triangles_hi: &[Triangle],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let triangles = Split::new(triangles, triangles_hi);
    treelet_core::construct::primitive_boxes::primitive_boxes_kernel(id, params.n, params.spheres, spheres, &triangles, boxes);
}
