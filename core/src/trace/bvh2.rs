//! The binary layout made for GPUs (Aila & Laine 2009, "Understanding the
//! Efficiency of Ray Traversal on GPUs"): each node holds both children's
//! boxes ([`Bvh2Node`], 64 bytes), so one load tests both children; the
//! ray goes on into the nearer child it hits, by the slab test's entry
//! distance, and pushes the other (with that distance, to skip it on the
//! way back if a hit came nearer). Leaves read their primitives in leaf
//! order ([`LeafPrim`]): no index indirection.
//!
//! It is made from a collapsed tree in depth-first order (what
//! [`crate::construct::collapse`] writes: leaves of several primitives, `out_prims`
//! in leaf order) by two kernels without atomics: [`bvh2_node_kernel`](crate::layouts::bvh2::bvh2_node_kernel)
//! (internal node `i` of the input becomes node `f(i)` of the output, the
//! number of internal nodes before it in depth-first order, found by
//! climbing) and [`leaf_prims_kernel`](crate::layouts::bvh2::leaf_prims_kernel) (the primitives in leaf order).
use glam::Vec3;

use crate::geometry::buffers::{Bvh2Node, LeafPrim};
use crate::geometry::features;
use crate::geometry::intersect::{SlabRay, slab_interval};
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::triangle::WatertightRay;
use crate::gpu::unchecked::{get, set};
use crate::geometry::records::RecordLoad;
use crate::trace::hit::{ClosestHit, Hit, Query, STACK_DEPTH};

/// A tree in the layout of this module: its nodes and leaf primitives as
/// records (`[Bvh2Node]`, `[LeafPrim]`) or as the 16-byte vectors of their
/// bytes (`[Vec4]`, how the GPU kernels bind them: see
/// [`crate::geometry::records`]), held by value: slices, or views of
/// buffers bound in two parts ([`crate::geometry::split::Split`]; a
/// reference to such a view made in the shader lost its contents).
pub struct Bvh2Tree<N, P> {
    pub nodes: N,
    pub leaf_prims: P,
}

impl<N: RecordLoad<Bvh2Node>, P: RecordLoad<LeafPrim>> Bvh2Tree<N, P> {
    #[inline]
    pub fn new(nodes: N, leaf_prims: P) -> Self {
        Bvh2Tree { nodes, leaf_prims }
    }
}

impl<N: RecordLoad<Bvh2Node>, P: RecordLoad<LeafPrim>> ClosestHit for Bvh2Tree<N, P> {
    #[inline]
    fn trace<const F: u32, const S: usize>(&self, o: Vec3, d: Vec3, from: Origin, query: Query, prims: &Prims, _: &mut [u32; S], _: u32) -> Hit {
        trace_bvh2::<F>(o, d, from, query, prims, &self.nodes, &self.leaf_prims)
    }
}

/// Tests the `count` primitives of a leaf from `first` on (up to the first
/// hit for an occlusion query: by the loop's condition, as a `return` from
/// inside this loop lost hits on lavapipe, about one occluded ray in twenty).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn leaf<const F: u32>(
    hit: &mut Hit,
    first: u32,
    count: u32,
    (o, d, from): (Vec3, Vec3, Origin),
    query: &Query,
    ray: &WatertightRay,
    prims: &Prims,
    leaf_prims: &(impl RecordLoad<LeafPrim> + ?Sized),
) {
    let mut k = 0;
    while k < count && !query.done(hit) {
        let p = leaf_prims.load((first + k) as usize);
        let t = prims.leaf_distance::<F>(o, d, ray, from, &p, hit.t);
        if p.prim != query.skip && hit.is_beaten_by(t, p.prim) {
            *hit = Hit { t, prim: p.prim };
        }
        k += 1;
    }
}

/// The closest hit through a [`Bvh2Node`] tree (root 0), nearer child
/// first; see the module doc. `F` as for
/// [`crate::trace::classic::closest_hit_linear_for`].
#[inline]
pub fn closest_hit_bvh2<const F: u32>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    prims: &Prims,
    nodes: &[Bvh2Node],
    leaf_prims: &[LeafPrim],
) -> Hit {
    trace_bvh2::<F>(o, d, from, Query::CLOSEST, prims, nodes, leaf_prims)
}

/// [`closest_hit_bvh2`] for any [`Query`].
#[inline]
pub fn trace_bvh2<const F: u32>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    query: Query,
    prims: &Prims,
    nodes: &(impl RecordLoad<Bvh2Node> + ?Sized),
    leaf_prims: &(impl RecordLoad<LeafPrim> + ?Sized),
) -> Hit {
    if prims.count() == 0 {
        return query.start();
    }
    let ray = WatertightRay::new(o, d);
    walk_bvh2(&SlabRay::new(o, d), &query, nodes, |hit, first, count| {
        leaf::<F>(hit, first, count, (o, d, from), &query, &ray, prims, leaf_prims)
    })
}

/// The walk through a [`Bvh2Node`] tree (root 0) that every traversal of
/// this layout shares, from `query.start()`: nearer child first; a leaf's
/// `count` items from `first` on go to `leaf(hit, first, count)`, which
/// narrows `hit` (primitives, or an instanced scene's instances:
/// [`crate::trace::instances`]). Returns when `query` is done or no node
/// nearer than the hit is left.
#[inline]
pub fn walk_bvh2(
    slabs: &SlabRay,
    query: &Query,
    nodes: &(impl RecordLoad<Bvh2Node> + ?Sized),
    mut leaf: impl FnMut(&mut Hit, u32, u32),
) -> Hit {
    let mut hit = query.start();
    // Entries: node index and the entry distance it was pushed with.
    let mut stack = [0u32; 2 * STACK_DEPTH];
    let mut top = 0usize;
    let mut node = 0u32;
    loop {
        let n = nodes.load(node as usize);
        let (ln, lf) = slab_interval(n.left_min, n.left_max, slabs, hit.t);
        let (rn, rf) = slab_interval(n.right_min, n.right_max, slabs, hit.t);
        let (mut go_left, mut go_right) = (ln <= lf, rn <= rf);
        // Leaves are tested at once; only internal children are walked.
        if go_left && n.left_count > 0 {
            leaf(&mut hit, n.left, n.left_count);
            go_left = false;
        }
        if go_right && n.right_count > 0 {
            leaf(&mut hit, n.right, n.right_count);
            go_right = false;
        }
        if query.done(&hit) {
            return hit;
        }
        if go_left && go_right {
            let (near, far, far_t) = if ln <= rn { (n.left, n.right, rn) } else { (n.right, n.left, ln) };
            if top < STACK_DEPTH {
                set(&mut stack, 2 * top, far);
                set(&mut stack, 2 * top + 1, far_t.to_bits());
                top += 1;
            }
            node = near;
        } else if go_left {
            node = n.left;
        } else if go_right {
            node = n.right;
        } else {
            // Back to the nearest pushed child still worth entering.
            let mut next = u32::MAX;
            while top > 0 && next == u32::MAX {
                top -= 1;
                if f32::from_bits(get(&stack, 2 * top + 1)) <= hit.t {
                    next = get(&stack, 2 * top);
                }
            }
            if next == u32::MAX {
                return hit;
            }
            node = next;
        }
    }
}

/// [`closest_hit_bvh2`] with every primitive kind compiled in.
#[inline]
pub fn closest_hit_bvh2_all(o: Vec3, d: Vec3, from: Origin, prims: &Prims, nodes: &[Bvh2Node], leaf_prims: &[LeafPrim]) -> Hit {
    closest_hit_bvh2::<{ features::ALL }>(o, d, from, prims, nodes, leaf_prims)
}
