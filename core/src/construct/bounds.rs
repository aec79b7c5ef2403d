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

/// What the first pass of the bounds reads: the box of each of its items.
/// Primitives ([`PrimitiveBoxes`]) or placed meshes
/// ([`crate::construct::instances::InstanceBoxes`], which also write each
/// instance's record on the way).
pub trait BoxSource {
    fn box_of(&mut self, i: u32) -> Aabb;
}

/// The boxes of a scene's primitives: sphere `i` below `spheres`, else
/// triangle `i - spheres`.
/// The split by value: a reference to a `Split` made in a shader loses
/// its contents under rust-gpu (see `crate::geometry::split`).
pub struct PrimitiveBoxes<'a> {
    pub spheres: u32,
    pub sphere_data: &'a [Sphere],
    pub triangles: Split<'a, Triangle>,
}

impl BoxSource for PrimitiveBoxes<'_> {
    #[inline]
    fn box_of(&mut self, i: u32) -> Aabb {
        primitive_box(i, self.spheres, self.sphere_data, &self.triangles)
    }
}

/// Kernel: the first pass of the bounds fused with the items' boxes: each
/// invocation computes and stores the boxes of its `REDUCE_ITEMS` items
/// (for primitives, as [`crate::construct::primitive_boxes::primitive_boxes_kernel`]
/// does) and reduces their centroids, so the boxes are not read again;
/// `output[group]` = the centroid bounds of the group's tile of the `n`
/// items. H100, the bounds stage (boxes and every pass) as two
/// kernels, then fused: 1M primitives 0.047 -> 0.030 ms, 4M 0.170 ->
/// 0.088, 16M 0.590 -> 0.294 (`docs/results/h100-agglomerate-subgroup/log_fused_bounds.txt`).
#[allow(clippy::too_many_arguments)]
pub fn primitive_bounds_phase<S: BoxSource, B: RecordStore<Aabb> + ?Sized>(
    phase: u32,
    lid: u32,
    group: u32,
    n: u32,
    source: &mut S,
    boxes: &mut B,
    output: &mut [Aabb],
    shared: &mut [Aabb; WG],
) {
    if phase == 0 {
        let mut acc = Aabb::EMPTY;
        for k in 0..REDUCE_ITEMS {
            let i = group * REDUCE_TILE + k * WORKGROUP_SIZE + lid;
            if i < n {
                let b = source.box_of(i);
                boxes.store(i as usize, &b);
                acc = acc.union(&Aabb::point(b.centroid()));
            }
        }
        shared[lid as usize] = acc;
    } else {
        reduce_and_write(phase, lid, group, n, output, shared);
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
