//! The agglomerative build's lowest levels merged within subgroups
//! (`treelet_core::construct::agglomerate_subgroup`).
use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::gpu::workgroup::linear_id;
use treelet_core::geometry::split::SplitMut;
use treelet_core::Aabb;

/// One step of `treelet_core::construct::agglomerate_subgroup`, its
/// number a constant (so the driver keeps only that step's branch), then
/// its subgroup operation.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn agglomerate_step<const STEP: u32>(
    id: u32,
    lane: u32,
    size: u32,
    n: u32,
    inputs: (&[u64], &[u32], &[Aabb]),
    nodes: &mut SplitMut<Vec4>,
    parents: &mut [u32],
    ends: &mut [u32],
    queue: &mut [u32],
    queued: &mut [u32],
    me: &mut treelet_core::construct::agglomerate_subgroup::AgglomerateLane,
    io: &mut treelet_core::gpu::subgroup::Lane,
) {
    use treelet_core::construct::agglomerate_subgroup::{agglomerate_subgroup_op, agglomerate_subgroup_phase};
    let (keys, sorted_prims, prim_boxes) = inputs;
    agglomerate_subgroup_phase(STEP, id, lane, size, n, keys, sorted_prims, prim_boxes, nodes, parents, ends, queue, queued, me, io);
    treelet_core::gpu::subgroup::apply(agglomerate_subgroup_op(STEP), io);
}

/// The agglomerative build's lowest levels, merged within each subgroup
/// (`treelet_core::construct::agglomerate_subgroup`): the start, the rounds
/// (each round's nine steps unrolled), then the clusters left queued for
/// `climb_queued_cs` (`per_invocation`).
#[spirv(compute(threads(256)))]
#[allow(clippy::too_many_arguments)]
pub fn agglomerate_subgroup_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(subgroup_local_invocation_id)] lane: u32,
    #[spirv(subgroup_size)] size: u32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] sorted_prims: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] prim_boxes: &[Aabb],
    // Two 16-byte vectors per node: whole records (see `treelet_core::geometry::records`).
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes: &mut [Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] parents: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] ends: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] queue: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] queued: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] nodes_hi: &mut [Vec4],
) {
    use treelet_core::construct::agglomerate_subgroup::{AgglomerateLane, SUBGROUP_ROUNDS};
    let id = linear_id(gid.x, gid.y, groups.x);
    let n = params.n;
    let mut me = AgglomerateLane::default();
    let mut io = treelet_core::gpu::subgroup::Lane::default();
    let nodes = &mut SplitMut::new(nodes, nodes_hi);
    let i = (keys, sorted_prims, prim_boxes);
    agglomerate_step::<0>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
    let mut round = 0;
    while round < SUBGROUP_ROUNDS {
        agglomerate_step::<1>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<2>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<3>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<4>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<5>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<6>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<7>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<8>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        agglomerate_step::<9>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
        round += 1;
    }
    agglomerate_step::<10>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
    agglomerate_step::<11>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
    agglomerate_step::<12>(id, lane, size, n, i, nodes, parents, ends, queue, queued, &mut me, &mut io);
}
