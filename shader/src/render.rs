use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::features::VARIANTS;
use treelet_core::layout::{Material, Node, RenderParams, Sphere};
use treelet_core::render::{accumulate, render_pixel, SceneRefs, ACCEL_BVH, ACCEL_NONE};
use treelet_core::triangle::Triangle;
use treelet_core::workgroup::linear_id;

/// One path-tracing entry point: `render_pixel` for one closest-hit method
/// and one feature set (see `treelet_core::features::VARIANTS`, whose names
/// these must match: the feature sets come from it by index).
macro_rules! render_kernel {
    ($name:ident, $accel:expr, $features:expr) => {
        #[spirv(compute(threads(256)))]
        pub fn $name(
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
                accumulate(&mut accum[id as usize], render_pixel::<{ $accel }, { $features }>(id, params, &scene));
            }
        }
    };
}

const _: () = assert!(VARIANTS.len() == 6, "one pair of lines per variant");

render_kernel!(render_linear_spheres_diffuse_cs, ACCEL_NONE, VARIANTS[0].0);
render_kernel!(render_bvh_spheres_diffuse_cs, ACCEL_BVH, VARIANTS[0].0);
render_kernel!(render_linear_spheres_mirror_cs, ACCEL_NONE, VARIANTS[1].0);
render_kernel!(render_bvh_spheres_mirror_cs, ACCEL_BVH, VARIANTS[1].0);
render_kernel!(render_linear_spheres_cs, ACCEL_NONE, VARIANTS[2].0);
render_kernel!(render_bvh_spheres_cs, ACCEL_BVH, VARIANTS[2].0);
render_kernel!(render_linear_triangles_diffuse_cs, ACCEL_NONE, VARIANTS[3].0);
render_kernel!(render_bvh_triangles_diffuse_cs, ACCEL_BVH, VARIANTS[3].0);
render_kernel!(render_linear_mixed_diffuse_cs, ACCEL_NONE, VARIANTS[4].0);
render_kernel!(render_bvh_mixed_diffuse_cs, ACCEL_BVH, VARIANTS[4].0);
render_kernel!(render_linear_full_cs, ACCEL_NONE, VARIANTS[5].0);
render_kernel!(render_bvh_full_cs, ACCEL_BVH, VARIANTS[5].0);

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
