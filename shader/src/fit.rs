use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::layout::BuildParams;
use treelet_core::workgroup::linear_id;
use treelet_core::{Aabb, Node};

/// The bottom-up fit with an acquire-release counter: for GPUs.
#[spirv(compute(threads(256)))]
pub fn fit_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] sorted_prims: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] prim_boxes: &[Aabb],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] flags: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::fit::fit_kernel::<true>(id, params.n, sorted_prims, prim_boxes, nodes, parents, flags);
}

/// The bottom-up fit with a relaxed counter: for CPU adapters (lavapipe), see
/// `treelet_core::atomics::add_device_acq_rel`.
#[spirv(compute(threads(256)))]
pub fn fit_relaxed_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] sorted_prims: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] prim_boxes: &[Aabb],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] flags: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::fit::fit_kernel::<false>(id, params.n, sorted_prims, prim_boxes, nodes, parents, flags);
}

/// Hierarchy and bounds in one bottom-up pass (Apetrei 2014), with
/// acquire-release exchanges: for GPUs.
#[spirv(compute(threads(256)))]
pub fn agglomerate_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] sorted_prims: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] prim_boxes: &[Aabb],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] ends: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::agglomerate::agglomerate_kernel::<true>(
        id,
        params.n,
        keys,
        sorted_prims,
        prim_boxes,
        nodes,
        parents,
        ends,
    );
}

/// [`agglomerate_cs`] with relaxed exchanges: for CPU adapters (lavapipe).
#[spirv(compute(threads(256)))]
pub fn agglomerate_relaxed_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] sorted_prims: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] prim_boxes: &[Aabb],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] ends: &mut [u32],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    treelet_core::agglomerate::agglomerate_kernel::<false>(
        id,
        params.n,
        keys,
        sorted_prims,
        prim_boxes,
        nodes,
        parents,
        ends,
    );
}
