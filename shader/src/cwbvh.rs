use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::geometry::buffers::{LayoutParams, Node, Sphere};
use treelet_core::geometry::split::Split;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::linear_id;
use treelet_core::layouts::cwbvh_build::{wide_count_kernel, wide_dp_kernel, wide_emit_kernel, wide_place_kernel};

/// The wide DP, bottom up; acquire-release counters (GPUs).
#[spirv(compute(threads(256)))]
pub fn wide_dp_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] flags: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] costs: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] decisions: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    wide_dp_kernel::<true>(id, params, nodes, parents, flags, counts, costs, decisions);
}

/// As `wide_dp_cs` with relaxed counters, for CPU adapters (lavapipe).
#[spirv(compute(threads(256)))]
pub fn wide_dp_relaxed_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] flags: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] costs: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] decisions: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    wide_dp_kernel::<false>(id, params, nodes, parents, flags, counts, costs, decisions);
}

/// Which binary nodes are wide nodes, and their children's counts.
#[spirv(compute(threads(256)))]
pub fn wide_count_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] counts: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] decisions: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] is_wide: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] child_counts: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] prim_counts: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    wide_count_kernel(id, params, nodes, parents, counts, decisions, is_wide, child_counts, prim_counts);
}

/// Each wide node's wide children get their indices.
#[spirv(compute(threads(256)))]
pub fn wide_place_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] decisions: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] is_wide: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] child_offsets: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] positions: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] slots: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    wide_place_kernel(id, params, nodes, decisions, is_wide, child_offsets, positions, slots);
}

/// Each wide node writes its node and its leaf primitives.
#[spirv(compute(threads(256)))]
pub fn wide_emit_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &LayoutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] slots: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] is_wide: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] child_offsets: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] prim_offsets: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] positions: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] prim_indices: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] out_nodes: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 11)] out_prims: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 12)] triangles_hi: &[Triangle],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let triangles = Split::new(triangles, triangles_hi);
    wide_emit_kernel(
        id, params, nodes, slots, is_wide, child_offsets, prim_offsets, positions, prim_indices, spheres, triangles,
        out_nodes, out_prims,
    );
}
