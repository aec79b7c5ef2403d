use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::Aabb;
use treelet_core::construct::bounds;
use treelet_core::construct::instances::InstanceBoxes;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::geometry::split::Split;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::Sphere;
use treelet_core::gpu::workgroup::{WG, linear_group};

/// The primitive boxes, and their centroid bounds.
#[spirv(compute(threads(256)))]
#[allow(clippy::too_many_arguments)]
pub fn primitive_bounds_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] triangles: &[Triangle],
    // Two 16-byte vectors per box (see `treelet_core::geometry::records`).
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] boxes: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] bounds: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles_hi: &[Triangle],
    #[spirv(workgroup)] shared: &mut [Aabb; WG],
) {
    let group = linear_group(group.x, group.y, groups.x);
    let triangles = Split::new(triangles, triangles_hi);
    unrolled_phases!(bounds::REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9], |phase| {
        let mut source = bounds::PrimitiveBoxes { spheres: params.spheres, sphere_data: spheres, triangles };
        bounds::primitive_bounds_phase(phase, lid, group, params.n, &mut source, boxes, bounds, shared)
    });
}

/// An instanced scene's top level: each instance's record and world box
/// (`treelet_core::construct::instances`), and their centroid bounds.
#[spirv(compute(threads(256)))]
#[allow(clippy::too_many_arguments)]
pub fn instance_bounds_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] placed: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] meshes: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] records: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] boxes: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] bounds: &mut [u32],
    #[spirv(workgroup)] shared: &mut [Aabb; WG],
) {
    let group = linear_group(group.x, group.y, groups.x);
    unrolled_phases!(bounds::REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9], |phase| {
        let mut source = InstanceBoxes { placed, meshes, records: &mut *records };
        bounds::primitive_bounds_phase(phase, lid, group, params.n, &mut source, boxes, bounds, shared)
    });
}
