//! Triangle splitting before a build (`treelet_core::construct::presplit`).
use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::Aabb;
use treelet_core::construct::{bounds, presplit};
use treelet_core::geometry::buffers::{BuildParams, SplitParams};
use treelet_core::geometry::split::Split;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::{WG, linear_group};

/// Each primitive's priority, and their sum per workgroup.
#[spirv(compute(threads(256)))]
#[allow(clippy::too_many_arguments)]
pub fn split_priority_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &SplitParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] priorities: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] partials: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] triangles_hi: &[Triangle],
    #[spirv(workgroup)] shared: &mut [f32; WG],
) {
    let group = linear_group(group.x, group.y, groups.x);
    let triangles = Split::new(triangles, triangles_hi);
    unrolled_phases!(presplit::PRIORITY_PHASES, [0 1 2 3 4 5 6 7 8 9], |phase| {
        presplit::priority_phase(phase, lid, group, params, triangles, priorities, partials, shared)
    });
}

/// The pieces' boxes as the build's, and their centroid bounds.
#[spirv(compute(threads(256)))]
pub fn split_bounds_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] ref_boxes: &[Aabb],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] boxes: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] bounds: &mut [u32],
    #[spirv(workgroup)] shared: &mut [Aabb; WG],
) {
    let group = linear_group(group.x, group.y, groups.x);
    unrolled_phases!(bounds::REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9], |phase| {
        let mut source = presplit::StoredBoxes { boxes: ref_boxes };
        bounds::primitive_bounds_phase(phase, lid, group, params.n, &mut source, boxes, bounds, shared)
    });
}

