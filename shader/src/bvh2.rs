use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::geometry::buffers::{LayoutParams, Node, Sphere};
use treelet_core::geometry::split::{Split, SplitMut};
use treelet_core::geometry::prims::Prims;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::linear_id;

/// One node of a collapsed tree into the two-box layout.
#[spirv(compute(threads(256)))]
pub fn bvh2_nodes_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] out: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes_hi: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] out_hi: &mut [Vec4],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let nodes = Split::new(nodes, nodes_hi);
    let out = &mut SplitMut::new(out, out_hi);
    treelet_core::layouts::bvh2::bvh2_node_kernel(id, params.nodes, &nodes, parents, out);
}

/// One node of an instanced scene's top level (its LBVH as built): an
/// internal one into the two-box layout, a leaf's depth checked.
#[spirv(compute(threads(256)))]
pub fn top_level_nodes_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] prim_indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] out: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] deepest: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::layouts::bvh2::top_level_kernel(id, params.n, nodes, parents, prim_indices, out, deepest);
}

/// One primitive, in leaf order, as its leaf stores it.
#[spirv(compute(threads(256)))]
pub fn leaf_prims_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] prim_indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] out: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles_hi: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] out_hi: &mut [Vec4],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let triangles = Split::new(triangles, triangles_hi);
    let out = &mut SplitMut::new(out, out_hi);
    treelet_core::layouts::bvh2::leaf_prims_kernel(id, params.n, params.spheres, prim_indices, spheres, triangles, out);
}

/// The state a layout's refit climbs on, one collapsed node each: its
/// counter zeroed, its index in the layout, and for a leaf, which primitive
/// slot starts it (`treelet_core::layouts::bvh2::refit_state_kernel`).
#[spirv(compute(threads(256)))]
pub fn refit_state_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] state: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes_hi: &[Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let nodes = Split::new(nodes, nodes_hi);
    treelet_core::layouts::bvh2::refit_state_kernel(id, params.nodes, &nodes, parents, state);
}

/// A layout's refit in place: each primitive slot writes its leaf primitive,
/// each leaf's first then climbs, writing each box into the layout's node above
/// it (`treelet_core::layouts::bvh2::refit_kernel`); `$ordered` as for the
/// build's fit kernels.
macro_rules! refit_kernel {
    ($name:ident, $ordered:literal) => {
        #[spirv(compute(threads(256)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] prim_indices: &[u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] spheres: &[Sphere],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes: &[Node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] parents: &[u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] state: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] out_prims: &mut [Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] out_nodes: &mut [f32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] triangles_hi: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] nodes_hi: &[Node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 11)] out_prims_hi: &mut [Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 12)] out_nodes_hi: &mut [f32],
        ) {
            let id = linear_id(gid.x, gid.y, groups.x);
            let prims = Prims {
                spheres,
                sphere_count: params.spheres,
                triangles: Split::new(triangles, triangles_hi),
                triangle_count: params.n - params.spheres,
            };
            treelet_core::layouts::bvh2::refit_kernel::<$ordered, _, _>(
                id,
                params.n,
                params.nodes,
                &prims,
                prim_indices,
                &Split::new(nodes, nodes_hi),
                parents,
                state,
                &mut SplitMut::new(out_prims, out_prims_hi),
                &mut SplitMut::new(out_nodes, out_nodes_hi),
            );
        }
    };
}
refit_kernel!(refit_cs, true);
refit_kernel!(refit_relaxed_cs, false);
