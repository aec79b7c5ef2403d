use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::layout::{Material, Node, RenderParams, Sphere};
use treelet_core::render::{accumulate, render_pixel, SceneRefs, ACCEL_BVH, ACCEL_NONE};
use treelet_core::triangle::Triangle;
use treelet_core::workgroup::linear_id;

/// Path tracing with a linear scan over all primitives.
#[spirv(compute(threads(256)))]
pub fn render_linear_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prim_indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] accum: &mut [[f32; 4]],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    if id < params.width * params.height {
        let scene = SceneRefs::new(params, spheres, triangles, materials, nodes, prim_indices);
        accumulate(&mut accum[id as usize], render_pixel::<ACCEL_NONE>(id, params, &scene));
    }
}

/// Path tracing through a BVH.
#[spirv(compute(threads(256)))]
pub fn render_bvh_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prim_indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] accum: &mut [[f32; 4]],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    if id < params.width * params.height {
        let scene = SceneRefs::new(params, spheres, triangles, materials, nodes, prim_indices);
        accumulate(&mut accum[id as usize], render_pixel::<ACCEL_BVH>(id, params, &scene));
    }
}

/// Ray-casting throughput: one primary or one diffuse ray per pixel, through a BVH.
#[spirv(compute(threads(256)))]
pub fn cast_bvh_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prim_indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] rays: &mut [[f32; 4]],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let scene = SceneRefs::new(params, spheres, triangles, materials, nodes, prim_indices);
    treelet_core::rays::cast_kernel::<ACCEL_BVH>(id, params, &scene, rays);
}
