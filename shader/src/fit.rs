use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::gpu::workgroup::linear_id;
use treelet_core::{Aabb, Node};

/// A bottom-up fit entry point; `$ordered` as in
/// `treelet_core::construct::fit::fit_kernel` (acquire-release counters for GPUs,
/// relaxed for CPU adapters: see `treelet_core::gpu::atomics::add_device_acq_rel`).
macro_rules! fit_kernel {
    ($name:ident, $ordered:literal) => {
        #[spirv(compute(threads(256)))]
        pub fn $name(
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
            treelet_core::construct::fit::fit_kernel::<$ordered>(id, params.n, sorted_prims, prim_boxes, nodes, parents, flags);
        }
    };
}

/// Hierarchy and bounds in one bottom-up pass (Apetrei 2014); `$ordered` as
/// for `fit_kernel!`.
macro_rules! agglomerate_kernel {
    ($name:ident, $ordered:literal) => {
        #[spirv(compute(threads(256)))]
        pub fn $name(
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
            let n = params.n;
            treelet_core::construct::agglomerate::agglomerate_kernel::<$ordered>(
                id,
                n,
                keys,
                sorted_prims,
                prim_boxes,
                nodes,
                parents,
                ends,
            );
        }
    };
}

fit_kernel!(fit_cs, true);
fit_kernel!(fit_relaxed_cs, false);
agglomerate_kernel!(agglomerate_cs, true);
agglomerate_kernel!(agglomerate_relaxed_cs, false);
