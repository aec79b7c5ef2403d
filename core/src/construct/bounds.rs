//! Scene bounds by parallel reduction: each workgroup reduces a tile of
//! [`REDUCE_TILE`] boxes to one; the host runs the kernel again on the
//! partial results until one box remains. The first pass reduces the
//! *centroids* of the primitive boxes (the Morton frame), later ones boxes.
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::BuildParams;
use crate::gpu::workgroup::{WG, WG_LOG2, WORKGROUP_SIZE, reduction_stride};

/// Boxes each invocation reads.
pub const REDUCE_ITEMS: u32 = 8;
/// Boxes per workgroup.
pub const REDUCE_TILE: u32 = WORKGROUP_SIZE * REDUCE_ITEMS;

/// Phases of [`reduce_bounds_phase`]: load, tree reduction, write.
pub const REDUCE_PHASES: u32 = 2 + WG_LOG2;

/// Kernel: `output[group] = union of input[group's tile]` (of centroids
/// when `params.reduce_centroids != 0`).
pub fn reduce_bounds_phase(
    phase: u32,
    lid: u32,
    group: u32,
    params: &BuildParams,
    input: &[Aabb],
    output: &mut [Aabb],
    shared: &mut [Aabb; WG],
) {
    if phase == 0 {
        let mut acc = Aabb::EMPTY;
        for k in 0..REDUCE_ITEMS {
            let i = group * REDUCE_TILE + k * WORKGROUP_SIZE + lid;
            if i < params.reduce_len {
                let b = input[i as usize];
                let b = if params.reduce_centroids != 0 { Aabb::point(b.centroid()) } else { b };
                acc = acc.union(&b);
            }
        }
        shared[lid as usize] = acc;
    } else if phase <= WG_LOG2 {
        let stride = reduction_stride(phase - 1);
        if lid < stride {
            shared[lid as usize] = shared[lid as usize].union(&shared[(lid + stride) as usize]);
        }
    } else if lid == 0 && group * REDUCE_TILE < params.reduce_len {
        output[group as usize] = shared[0];
    }
}
