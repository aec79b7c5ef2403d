//! H-PLOC (`treelet_core::construct::hploc`).
use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::geometry::buffers::BuildParams;
use treelet_core::gpu::workgroup::{linear_id, WG};
use treelet_core::geometry::split::SplitMut;
use treelet_core::{Aabb, Node};

/// H-PLOC (`treelet_core::construct::hploc`) over the sorted keys: the
/// steps in the order `hploc_schedule!` gives, each followed by its
/// subgroup operation; `ORDERED` as for the fit (`treelet_core::construct::fit::fit_kernel`:
/// acquire-release counters on GPUs, relaxed on CPU adapters).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn hploc<const ORDERED: bool>(
    gid: UVec3,
    groups: UVec3,
    lane: u32,
    size: u32,
    settings: (u32, u32, u32),
    inputs: (&[u64], &[u32], &[Aabb]),
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    ends: &mut [u32],
    lists: &mut [u32],
    shared: (&mut treelet_core::construct::hploc::SharedBoxes, &mut [u32; WG], &mut [u32; WG]),
) {
    use treelet_core::construct::hploc::{hploc_op, hploc_step, HplocLane};
    use treelet_core::gpu::subgroup::{apply, Lane};
    let id = linear_id(gid.x, gid.y, groups.x);
    let base = gid.x % treelet_core::gpu::workgroup::WORKGROUP_SIZE - lane;
    let (boxes, clusters, nearest) = shared;
    let mut me = HplocLane::default();
    let mut io = Lane::default();
    macro_rules! step {
        ($step:expr, $arg:expr) => {
            hploc_step::<ORDERED>(
                $step,
                $arg,
                id,
                lane,
                size,
                base,
                settings,
                inputs,
                nodes,
                parents,
                ends,
                lists,
                (&mut *boxes, &mut *clusters, &mut *nearest),
                &mut me,
                &mut io,
            );
            // The relaxed variant is for CPU adapters, whose subgroups run
            // in lockstep (see `treelet_core::gpu::subgroup::lockstep`).
            let sync = hploc_op($step);
            apply(if ORDERED { sync } else { treelet_core::gpu::subgroup::lockstep(sync) }, &mut io);
        };
    }
    treelet_core::hploc_schedule!(step, io.output, me.more());
}

/// The H-PLOC entry points; `$ordered` as for `hploc`.
macro_rules! hploc_kernel {
    ($name:ident, $ordered:literal) => {
        #[spirv(compute(threads(256)))]
        #[allow(clippy::too_many_arguments)]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(subgroup_local_invocation_id)] lane: u32,
            #[spirv(subgroup_size)] size: u32,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &BuildParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] sorted_prims: &[u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] prim_boxes: &[Aabb],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] nodes: &mut [Node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] parents: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] ends: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] lists: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] nodes_hi: &mut [Node],
            #[spirv(workgroup)] boxes: &mut treelet_core::construct::hploc::SharedBoxes,
            #[spirv(workgroup)] clusters: &mut [u32; WG],
            #[spirv(workgroup)] nearest: &mut [u32; WG],
        ) {
            let inputs = (keys, sorted_prims, prim_boxes);
            let shared = (boxes, clusters, nearest);
            let settings = (params.n, params.cluster_keep, params.cluster_radius);
            let nodes = &mut SplitMut::new(nodes, nodes_hi);
            hploc::<$ordered>(gid, groups, lane, size, settings, inputs, nodes, parents, ends, lists, shared);
        }
    };
}

hploc_kernel!(hploc_cs, true);
hploc_kernel!(hploc_relaxed_cs, false);
