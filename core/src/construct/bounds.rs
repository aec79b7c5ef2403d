//! Scene bounds in one dispatch ([`primitive_bounds_phase`]): each
//! workgroup makes the boxes of a tile of [`REDUCE_TILE`] items, reduces
//! their *centroids* (the Morton frame) to one box, and merges that box
//! into the scene's by device atomics: min and max of each coordinate as an
//! order-preserving `u32` ([`ordered_bits`]), in six words that start as
//! [`BOUNDS_START`]. Min and max are exact in any order, so the bounds are
//! those of a reduction pass by pass, without the passes (H100, 65 536
//! primitives: the second pass alone was 5 µs, a thirtieth of the build).
use crate::construct::primitive_boxes::primitive_box;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::Sphere;
use crate::geometry::records::RecordStore;
use crate::geometry::split::Split;
use crate::geometry::triangle::Triangle;
use crate::gpu::atomics;
use crate::gpu::workgroup::{WG, WG_LOG2, WORKGROUP_SIZE, reduction_stride};

/// Boxes each invocation reads.
pub const REDUCE_ITEMS: u32 = 8;
/// Boxes per workgroup.
pub const REDUCE_TILE: u32 = WORKGROUP_SIZE * REDUCE_ITEMS;

/// Phases of [`primitive_bounds_phase`]: load, tree reduction, merge.
pub const REDUCE_PHASES: u32 = 2 + WG_LOG2;

/// Words of the scene's bounds: min x, y, z, then max x, y, z, each as
/// [`ordered_bits`].
pub const BOUNDS_WORDS: usize = 6;
/// The bounds' words before any merge: min +infinity, max -infinity
/// ([`ordered_bits`] of each).
pub const BOUNDS_START: [u32; BOUNDS_WORDS] = [0xff80_0000, 0xff80_0000, 0xff80_0000, 0x007f_ffff, 0x007f_ffff, 0x007f_ffff];

/// `f` as a `u32` that orders as `f` does (for every `f` but NaN): the sign
/// bit flipped for positive numbers, every bit for negative ones.
#[inline]
pub fn ordered_bits(f: f32) -> u32 {
    let bits = f.to_bits();
    if bits & 0x8000_0000 != 0 { !bits } else { bits | 0x8000_0000 }
}

/// The `f32` whose [`ordered_bits`] are `u`.
#[inline]
pub fn from_ordered_bits(u: u32) -> f32 {
    f32::from_bits(if u & 0x8000_0000 != 0 { u & 0x7fff_ffff } else { !u })
}

/// The box the bounds' words hold (min +infinity and max -infinity where
/// nothing was merged).
pub fn bounds_from_words(w: &[u32; BOUNDS_WORDS]) -> Aabb {
    let min = [from_ordered_bits(w[0]), from_ordered_bits(w[1]), from_ordered_bits(w[2])];
    let max = [from_ordered_bits(w[3]), from_ordered_bits(w[4]), from_ordered_bits(w[5])];
    Aabb::from_arrays(min, max)
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
/// does) and reduces their centroids, so the boxes are not read again,
/// and merges the centroid bounds of the group's tile of the `n` items
/// into `bounds` (see the module doc). H100, the bounds stage (boxes and every pass) as two
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
    bounds: &mut [u32],
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
    } else if phase <= WG_LOG2 {
        let stride = reduction_stride(phase - 1);
        if lid < stride {
            shared[lid as usize] = shared[lid as usize].union(&shared[(lid + stride) as usize]);
        }
    } else if group * REDUCE_TILE < n && (lid as usize) < BOUNDS_WORDS {
        // Six invocations, one word each.
        let b = shared[0];
        let axis = (lid % 3) as usize;
        if lid < 3 {
            atomics::min_device(&mut bounds[lid as usize], ordered_bits(b.min[axis]));
        } else {
            atomics::max_device(&mut bounds[lid as usize], ordered_bits(b.max[axis]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordered_bits_order_as_the_floats_do_and_round_trip() {
        let values = [
            f32::NEG_INFINITY, -f32::MAX, -1e30, -2.5, -1.0, -f32::MIN_POSITIVE, -1e-45, -0.0,
            0.0, 1e-45, f32::MIN_POSITIVE, 1.0, 2.5, 1e30, f32::MAX, f32::INFINITY,
        ];
        for w in values.windows(2) {
            assert!(ordered_bits(w[0]) <= ordered_bits(w[1]), "{} {}", w[0], w[1]);
            if w[0] < w[1] {
                assert!(ordered_bits(w[0]) < ordered_bits(w[1]), "{} {}", w[0], w[1]);
            }
        }
        for v in values {
            assert_eq!(from_ordered_bits(ordered_bits(v)).to_bits(), v.to_bits());
        }
    }

    #[test]
    fn start_words_are_the_empty_box_and_merging_gives_the_union() {
        let mut words = BOUNDS_START;
        let boxes = [Aabb::from_arrays([1.0, -2.0, 3.0], [4.0, 5.0, 6.0]), Aabb::from_arrays([-7.0, 0.5, 3.5], [-1.0, 9.0, 3.5])];
        let mut expected = Aabb::EMPTY;
        for b in boxes {
            for k in 0..3 {
                words[k] = words[k].min(ordered_bits(b.min[k]));
                words[3 + k] = words[3 + k].max(ordered_bits(b.max[k]));
            }
            expected = expected.union(&b);
        }
        assert_eq!(bounds_from_words(&words), expected);
        assert_eq!(BOUNDS_START[0], ordered_bits(f32::INFINITY));
        assert_eq!(BOUNDS_START[3], ordered_bits(f32::NEG_INFINITY));
        let empty = bounds_from_words(&BOUNDS_START);
        assert_eq!((empty.min, empty.max), ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]));
    }
}
