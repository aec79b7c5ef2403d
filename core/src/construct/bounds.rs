//! Scene bounds by parallel reduction: each workgroup reduces a tile of
//! [`REDUCE_TILE`] boxes to one; the host runs the kernel again on the
//! partial results until one box remains. The first pass
//! ([`primitive_bounds_phase`]) makes the primitive boxes and reduces their
//! *centroids* (the Morton frame), later ones ([`reduce_bounds_phase`])
//! reduce boxes.
use crate::construct::primitive_boxes::primitive_box;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{BuildParams, Sphere};
use crate::geometry::records::RecordStore;
use crate::geometry::split::Split;
use crate::geometry::triangle::Triangle;
use crate::gpu::workgroup::{WG, WG_LOG2, WORKGROUP_SIZE, reduction_stride};

/// Boxes each invocation reads.
pub const REDUCE_ITEMS: u32 = 8;
/// Boxes per workgroup.
pub const REDUCE_TILE: u32 = WORKGROUP_SIZE * REDUCE_ITEMS;

/// Phases of [`reduce_bounds_phase`]: load, tree reduction, write.
pub const REDUCE_PHASES: u32 = 2 + WG_LOG2;

/// Kernel: `output[group] = union of input[group's tile]`.
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
                acc = acc.union(&input[i as usize]);
            }
        }
        shared[lid as usize] = acc;
    } else {
        reduce_and_write(phase, lid, group, params.reduce_len, output, shared);
    }
}

/// Kernel: the first pass of the bounds fused with the primitive boxes:
/// each invocation computes and stores the boxes of its `REDUCE_ITEMS`
/// primitives (as [`crate::construct::primitive_boxes::primitive_boxes_kernel`]
/// does) and reduces their centroids, so the boxes are not read again;
/// `output[group]` = the centroid bounds of the group's tile of the `n`
/// primitives. H100, the bounds stage (boxes and every pass) as two
/// kernels, then fused: 1M primitives 0.047 -> 0.030 ms, 4M 0.170 ->
/// 0.088, 16M 0.590 -> 0.294 (`docs/results/h100-agglomerate-subgroup/log_fused_bounds.txt`).
#[allow(clippy::too_many_arguments)]
pub fn primitive_bounds_phase<B: RecordStore<Aabb> + ?Sized>(
    phase: u32,
    lid: u32,
    group: u32,
    params: &BuildParams,
    spheres: &[Sphere],
    triangles: &Split<Triangle>,
    boxes: &mut B,
    output: &mut [Aabb],
    shared: &mut [Aabb; WG],
) {
    if phase == 0 {
        let mut acc = Aabb::EMPTY;
        for k in 0..REDUCE_ITEMS {
            let i = group * REDUCE_TILE + k * WORKGROUP_SIZE + lid;
            if i < params.n {
                let b = primitive_box(i, params.spheres, spheres, triangles);
                boxes.store(i as usize, &b);
                acc = acc.union(&Aabb::point(b.centroid()));
            }
        }
        shared[lid as usize] = acc;
    } else {
        reduce_and_write(phase, lid, group, params.n, output, shared);
    }
}

/// The phases after the load: the tree reduction of `shared`, then the
/// group's box written (for a group that read any of the `len` boxes).
#[inline]
fn reduce_and_write(phase: u32, lid: u32, group: u32, len: u32, output: &mut [Aabb], shared: &mut [Aabb; WG]) {
    if phase <= WG_LOG2 {
        let stride = reduction_stride(phase - 1);
        if lid < stride {
            shared[lid as usize] = shared[lid as usize].union(&shared[(lid + stride) as usize]);
        }
    } else if lid == 0 && group * REDUCE_TILE < len {
        output[group as usize] = shared[0];
    }
}
