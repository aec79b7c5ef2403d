//! Parallel reinsertion (`treelet_core::construct::reinsert`): search, bid,
//! claim and apply, then the boxes refit from the leaves.
use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::construct::fit::refit_nodes_kernel;
use treelet_core::construct::reinsert::{apply_kernel, bid_kernel, claim_kernel, search_kernel};
use treelet_core::geometry::buffers::{Node, ReinsertParams, Reinsertion};
use treelet_core::geometry::split::{Split, SplitMut};
use treelet_core::gpu::workgroup::linear_id;

/// Each node's best move.
#[spirv(compute(threads(256)))]
pub fn reinsert_search_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ReinsertParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] moves: &mut [Reinsertion],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes_hi: &[Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    search_kernel(id, params, &Split::new(nodes, nodes_hi), parents, moves);
}

/// Each move bids its gain on its nodes.
#[spirv(compute(threads(256)))]
pub fn reinsert_bid_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ReinsertParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] moves: &[Reinsertion],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] bids: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] nodes_hi: &[Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    bid_kernel(id, params, &Split::new(nodes, nodes_hi), parents, moves, bids);
}

/// The moves that won every bid claim their nodes.
#[spirv(compute(threads(256)))]
pub fn reinsert_claim_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ReinsertParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &[Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] moves: &[Reinsertion],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] bids: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] owners: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] nodes_hi: &[Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    claim_kernel(id, params, &Split::new(nodes, nodes_hi), parents, moves, bids, owners);
}

/// The moves that hold all their nodes are made.
#[spirv(compute(threads(256)))]
#[allow(clippy::too_many_arguments)]
pub fn reinsert_apply_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ReinsertParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &mut [Node],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] moves: &[Reinsertion],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] bids: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] owners: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] made: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] nodes_hi: &mut [Node],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    apply_kernel(id, params, &mut SplitMut::new(nodes, nodes_hi), parents, moves, bids, owners, made);
}

/// New boxes after the moves, one invocation per leaf climbing; `$ordered`
/// as for the fit (acquire-release counters on GPUs, relaxed on CPU
/// adapters: see `treelet_core::gpu::atomics::add_device_acq_rel`).
macro_rules! refit_kernel {
    ($name:ident, $ordered:literal) => {
        #[spirv(compute(threads(256)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ReinsertParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] nodes: &mut [Node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] parents: &[u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] flags: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes_hi: &mut [Node],
        ) {
            let id = linear_id(gid.x, gid.y, groups.x);
            refit_nodes_kernel::<$ordered>(id, params.n, &mut SplitMut::new(nodes, nodes_hi), parents, flags);
        }
    };
}
refit_kernel!(reinsert_refit_cs, true);
refit_kernel!(reinsert_refit_relaxed_cs, false);
