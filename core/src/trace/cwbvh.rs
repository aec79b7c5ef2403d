//! The compressed 8-wide BVH (Ylitie, Karras & Laine 2017, "Efficient
//! Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs"): its
//! node ([`WideNode`], 80 bytes) quantizes the eight child boxes to bytes
//! on a grid of the node's own, so a ray tests eight boxes with one
//! 80-byte load. How the tree is made: [`crate::layouts::cwbvh::build`].
//!
//! ## Traversal
//! As in the paper: the ray carries a *node group* (the base index of a
//! node's internal children and a mask of those it hit, in visiting order)
//! and a *primitive group* (a node's first leaf primitive and a mask of the
//! leaf primitives it hit). Children sit in the slots of their octant (see
//! `assign_slots` in the builder), so for a ray of octant `o` visiting
//! slots by `slot ^ (7 - o)` descending goes roughly front to back; the
//! stack holds groups, not nodes.
//!
//! ## Never missing a hit
//! Every layout must find exactly the scan's closest hit, so the box test
//! must never cull a box the ray touches, whatever the rounding:
//! * the builder rounds each child's box outwards to the grid, each plane
//!   strictly beyond the box as f32 computes it, hence in real numbers too
//!   ([`quantize_lo`](crate::layouts::cwbvh::quantize_lo), [`quantize_hi`](crate::layouts::cwbvh::quantize_hi)): the dequantized box `origin + q 2^e`
//!   contains the exact one;
//! * the traversal computes a plane as `((origin - o) ± slack) + q 2^e`,
//!   then `(…) * inv`: the rounding of `origin - o` is an error relative
//!   to the ray's distance from the node's corner, not from the plane;
//!   each plane is pushed out by [`SLACK`] grid cells, eight times the
//!   worst such error (`2 ε (|plane - o| + 255 · 2^e)`), and the far
//!   distance is widened by [`WIDE_FAR_WIDENING`] for the rest, all of it
//!   relative to the distance (Ize 2013's argument with five roundings);
//! * directions parallel to an axis get `±f32::MAX` for an inverse
//!   ([`crate::geometry::intersect::SlabRay`]): no NaN, and exact signs; a ray lying
//!   in a child's face is inside the slab, as the slack puts the face
//!   strictly beyond it.
//!
//! The stack is a private array: see [`STACK_KINDS`] for the measured
//! alternatives.
use crate::geometry::records::RecordLoad;
use glam::Vec3;

use crate::geometry::buffers::{LeafPrim, WideNode};
use crate::geometry::intersect::SlabRay;
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::triangle::WatertightRay;
use crate::gpu::unchecked::{get, scratch, set};
use crate::layouts::cwbvh::grid_step;
use crate::trace::hit::{ClosestHit, Hit, Query, STACK_DEPTH};


/// Grid cells each plane is pushed out by in the traversal (see the module
/// doc): 2^-12, against a worst rounding error of 2 ε · 255 ≈ 2^-15 cells.
pub const SLACK: f32 = 1.0 / 4096.0;
/// The far distance's widening: `1 + 2^-19`, more than `1 + 2γ(6)` (five
/// roundings of the distance and one of the widened inverse).
pub const WIDE_FAR_WIDENING: f32 = 1.0 + 1.0 / 524_288.0;

/// Byte `shift / 8` of `word` as an f32, by the exponent trick
/// (`2^23 + b` has `b` in its low mantissa bits): integer operations and
/// one subtraction instead of a conversion, which GPUs run at a quarter
/// of the rate.
#[inline]
fn byte_f32(word: u32, shift: u32) -> f32 {
    f32::from_bits(0x4B00_0000 | ((word >> shift) & 0xFF)) - 8_388_608.0
}

/// Per axis of one node, what its eight child tests share: the byte words
/// of the planes the ray meets first and last (by its direction's sign),
/// the grid step, those planes' offsets from the ray origin (slack
/// included) and the inverse direction.
#[derive(Clone, Copy)]
struct Axis {
    near: [u32; 2],
    far: [u32; 2],
    step: f32,
    near_offset: f32,
    far_offset: f32,
    inv: f32,
    /// `inv` times [`WIDE_FAR_WIDENING`] (kept finite): far distances come
    /// out widened without a multiply per child.
    inv_far: f32,
}

impl Axis {
    /// (The widened inverse is made here, per node, rather than kept per
    /// ray: three multiplies a node against three registers all along.)
    #[inline]
    fn new(lo: [u32; 2], hi: [u32; 2], biased: u32, origin: f32, o: f32, inv: f32) -> Axis {
        let inv_far = (inv * WIDE_FAR_WIDENING).clamp(-f32::MAX, f32::MAX);
        let step = grid_step(biased);
        let from_ray = origin - o;
        let (lo_offset, hi_offset) = (from_ray - SLACK * step, from_ray + SLACK * step);
        if inv >= 0.0 {
            Axis { near: lo, far: hi, step, near_offset: lo_offset, far_offset: hi_offset, inv, inv_far }
        } else {
            Axis { near: hi, far: lo, step, near_offset: hi_offset, far_offset: lo_offset, inv, inv_far }
        }
    }

    /// Distances to child `(word, shift)`'s near and (widened) far planes on this axis.
    #[inline]
    fn planes(&self, word: usize, shift: u32) -> (f32, f32) {
        let near = (byte_f32(get(&self.near, word), shift) * self.step + self.near_offset) * self.inv;
        let far = (byte_f32(get(&self.far, word), shift) * self.step + self.far_offset) * self.inv_far;
        (near, far)
    }
}

/// Whether the ray meets child `(word, shift)`'s box before `t_max`.
#[inline]
fn child_hit(x: &Axis, y: &Axis, z: &Axis, word: usize, shift: u32, t_max: f32) -> bool {
    let ((nx, fx), (ny, fy), (nz, fz)) = (x.planes(word, shift), y.planes(word, shift), z.planes(word, shift));
    let near = nx.max(ny).max(nz.max(0.0));
    let far = fx.min(fy).min(fz.min(t_max));
    near <= far
}

/// Spreads bit 7 of each byte over the byte.
#[inline]
fn byte_masks(x: u32) -> u32 {
    ((x >> 7) & 0x0101_0101) * 0xFF
}

/// The hit bits of the four children in `word` (0: slots 0..4, 1: 4..8):
/// an internal child sets bit `24 + (slot ^ oct_inv)`, a leaf child one
/// bit per primitive at its offset.
#[inline]
fn hit_bits(x: &Axis, y: &Axis, z: &Axis, meta: u32, word: usize, oct_inv4: u32, t_max: f32) -> u32 {
    let is_internal = (meta & (meta << 1)) & 0x1010_1010;
    let bit_index = (meta ^ (oct_inv4 & byte_masks(is_internal << 3))) & 0x1F1F_1F1F;
    let child_bits = (meta >> 5) & 0x0707_0707;
    // Written out rather than looped: each byte's shift is then a
    // constant, whatever the driver makes of a loop.
    child_mask(x, y, z, word, 0, child_bits, bit_index, t_max)
        | child_mask(x, y, z, word, 8, child_bits, bit_index, t_max)
        | child_mask(x, y, z, word, 16, child_bits, bit_index, t_max)
        | child_mask(x, y, z, word, 24, child_bits, bit_index, t_max)
}

/// Child `(word, shift)`'s hit bits if the ray meets its box, else 0.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn child_mask(x: &Axis, y: &Axis, z: &Axis, word: usize, shift: u32, child_bits: u32, bit_index: u32, t_max: f32) -> u32 {
    let bits = ((child_bits >> shift) & 0xFF) << ((bit_index >> shift) & 0x1F);
    if child_hit(x, y, z, word, shift, t_max) {
        bits
    } else {
        0
    }
}

/// A tree in this layout: nodes (root 0) and leaf primitives.
/// Its nodes and leaf primitives as records or as the 16-byte vectors of
/// their bytes (how the GPU kernels bind them: see
/// [`crate::geometry::records`]).
/// Held by value, as [`crate::trace::bvh2::Bvh2Tree`].
pub struct WideTree<N, P> {
    pub nodes: N,
    pub leaf_prims: P,
}

impl<N: RecordLoad<WideNode>, P: RecordLoad<LeafPrim>> WideTree<N, P> {
    #[inline]
    pub fn new(nodes: N, leaf_prims: P) -> Self {
        WideTree { nodes, leaf_prims }
    }
}

impl<N: RecordLoad<WideNode>, P: RecordLoad<LeafPrim>> ClosestHit for WideTree<N, P> {
    #[inline]
    fn trace<const F: u32, const S: usize>(
        &self,
        o: Vec3,
        d: Vec3,
        from: Origin,
        query: Query,
        prims: &Prims,
        stack: &mut [u32; S],
        lane: u32,
    ) -> Hit {
        let mut private = scratch::<u32, { 2 * WIDE_STACK }>();
        trace_cwbvh_with::<F, S>(o, d, from, query, prims, &self.nodes, &self.leaf_prims, &mut private, stack, lane as usize)
    }
}

/// Stack layouts measured for this traversal on the H100 (`treelet bench
/// rays --stacks`): the private array kept here, and workgroup memory for
/// the top entries with the private array below them (the paper's choice).
pub const STACK_KINDS: [&str; 2] = ["private", "workgroup"];

/// Stack entries per ray kept in workgroup memory by the kernels that
/// try it (the paper kept 12, the authors' code 8).
pub const WORKGROUP_STACK_ENTRIES: usize = 8;
/// Words of workgroup memory those kernels declare: two per entry and lane.
pub const WORKGROUP_STACK_WORDS: usize = 2 * WORKGROUP_STACK_ENTRIES * crate::gpu::workgroup::WG;

/// Most groups a ray's stack holds: a node pushes at most one group, and
/// the tree is no deeper than the binary tree it was made from, which the
/// host keeps below [`STACK_DEPTH`].
pub const WIDE_STACK: usize = STACK_DEPTH;

/// The closest hit through a compressed wide BVH (root 0); see the
/// module doc. `F` as for [`crate::trace::classic::closest_hit_linear_for`].
#[inline]
pub fn closest_hit_cwbvh<const F: u32>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    prims: &Prims,
    nodes: &[WideNode],
    leaf_prims: &[LeafPrim],
) -> Hit {
    let mut stack = scratch::<u32, { 2 * WIDE_STACK }>();
    trace_cwbvh_with::<F, 1>(o, d, from, Query::CLOSEST, prims, nodes, leaf_prims, &mut stack, &mut [0u32; 1], 0)
}

/// [`closest_hit_cwbvh`] with its stack in `private` and, for its top
/// `SHARED / WG` entries, in `shared` at `lane + WG * entry` (workgroup
/// memory, interleaved across lanes); `SHARED = 1` keeps it all private.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn closest_hit_cwbvh_with<const F: u32, const SHARED: usize>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    prims: &Prims,
    nodes: &[WideNode],
    leaf_prims: &[LeafPrim],
    private: &mut [u32; 2 * WIDE_STACK],
    shared: &mut [u32; SHARED],
    lane: usize,
) -> Hit {
    trace_cwbvh_with::<F, SHARED>(o, d, from, Query::CLOSEST, prims, nodes, leaf_prims, private, shared, lane)
}

/// [`closest_hit_cwbvh_with`] for any [`Query`].
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn trace_cwbvh_with<const F: u32, const SHARED: usize>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    query: Query,
    prims: &Prims,
    nodes: &(impl RecordLoad<WideNode> + ?Sized),
    leaf_prims: &(impl RecordLoad<LeafPrim> + ?Sized),
    private: &mut [u32; 2 * WIDE_STACK],
    shared: &mut [u32; SHARED],
    lane: usize,
) -> Hit {
    let mut hit = query.start();
    if prims.count() == 0 {
        return hit;
    }
    // Parallel axes need no far bias here: the planes' slack keeps a ray
    // lying in a face inside the slab (see the module doc).
    let inv = SlabRay::new(Vec3::ZERO, d).inv;
    let ray = WatertightRay::new(o, d);
    let octant = ((inv[0] < 0.0) as u32) << 2 | ((inv[1] < 0.0) as u32) << 1 | (inv[2] < 0.0) as u32;
    let oct_inv = 7 - octant;
    let oct_inv4 = oct_inv * 0x0101_0101;
    // Shared entries per lane (0 when the stack is all private).
    let shared_entries = if SHARED > 1 { SHARED / crate::gpu::workgroup::WG / 2 } else { 0 };
    // The root's group: one hit internal child at base 0.
    let (mut node_base, mut node_hits) = (0u32, 0x8000_0000u32);
    let mut top = 0usize;
    loop {
        let mut prim_base = 0u32;
        let mut prim_hits = 0u32;
        if node_hits > 0x00FF_FFFF {
            // The next child of the group, in visiting order.
            let bit = 31 - node_hits.leading_zeros();
            node_hits &= !(1u32 << bit);
            let slot = (bit - 24) ^ oct_inv;
            let index = node_base + (node_hits & !(0xFFFF_FFFFu32 << slot)).count_ones();
            if node_hits > 0x00FF_FFFF {
                push(private, shared, lane, shared_entries, &mut top, node_base, node_hits);
            }
            let n = nodes.load(index as usize);
            let x = Axis::new(n.lo_x, n.hi_x, n.exp_imask & 0xFF, n.origin[0], o.x, inv[0]);
            let y = Axis::new(n.lo_y, n.hi_y, (n.exp_imask >> 8) & 0xFF, n.origin[1], o.y, inv[1]);
            let z = Axis::new(n.lo_z, n.hi_z, (n.exp_imask >> 16) & 0xFF, n.origin[2], o.z, inv[2]);
            let reach = hit.reach();
            let mask = hit_bits(&x, &y, &z, n.meta[0], 0, oct_inv4, reach) | hit_bits(&x, &y, &z, n.meta[1], 1, oct_inv4, reach);
            node_base = n.child_base;
            node_hits = (mask & 0xFF00_0000) | (n.exp_imask >> 24);
            prim_base = n.prim_base;
            prim_hits = mask & 0x00FF_FFFF;
        }
        // An occlusion query stops at its first hit (by the conditions, not
        // a `return` from inside the loop: see `trace::bvh2`).
        while prim_hits != 0 && !query.done(&hit) {
            let bit = 31 - prim_hits.leading_zeros();
            prim_hits &= !(1u32 << bit);
            let p = leaf_prims.load((prim_base + bit) as usize);
            let t = prims.leaf_distance::<F>(o, d, &ray, from, &p, hit.t);
            if p.prim != query.skip && hit.is_beaten_by(t, p.prim) {
                hit = Hit { t, prim: p.prim };
            }
        }
        if query.done(&hit) {
            return hit;
        }
        if node_hits <= 0x00FF_FFFF {
            if top == 0 {
                return hit;
            }
            (node_base, node_hits) = pop(private, shared, lane, shared_entries, &mut top);
        }
    }
}

#[inline]
fn push<const SHARED: usize>(
    private: &mut [u32; 2 * WIDE_STACK],
    shared: &mut [u32; SHARED],
    lane: usize,
    shared_entries: usize,
    top: &mut usize,
    base: u32,
    hits: u32,
) {
    let t = *top;
    if t < shared_entries {
        let slot = lane + 2 * t * crate::gpu::workgroup::WG;
        set(shared, slot, base);
        set(shared, slot + crate::gpu::workgroup::WG, hits);
    } else if t - shared_entries < WIDE_STACK {
        set(private, 2 * (t - shared_entries), base);
        set(private, 2 * (t - shared_entries) + 1, hits);
    }
    *top = t + 1;
}

#[inline]
fn pop<const SHARED: usize>(
    private: &mut [u32; 2 * WIDE_STACK],
    shared: &mut [u32; SHARED],
    lane: usize,
    shared_entries: usize,
    top: &mut usize,
) -> (u32, u32) {
    let t = *top - 1;
    *top = t;
    if t < shared_entries {
        let slot = lane + 2 * t * crate::gpu::workgroup::WG;
        (get(shared, slot), get(shared, slot + crate::gpu::workgroup::WG))
    } else if t - shared_entries < WIDE_STACK {
        (get(private, 2 * (t - shared_entries)), get(private, 2 * (t - shared_entries) + 1))
    } else {
        (0, 0) // never pushed: the host keeps trees shallower than the stack
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_convert_exactly() {
        for b in 0..256u32 {
            let word = b << 16 | 0xAB;
            assert_eq!(byte_f32(word, 16), b as f32);
        }
    }
}
