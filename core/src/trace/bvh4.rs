//! The walk of the 4-wide layout ([`crate::layouts::bvh4`]): each step loads
//! one [`Bvh4Node`] and tests its four boxes (the slab test of
//! [`crate::trace::bvh2`], so the same boxes pass); leaves among the hit
//! children are tested at once, and the internal ones, sorted by entry
//! distance, are walked nearest first, the others pushed with their
//! distance (skipped on the way back if a hit came nearer). The leaf
//! primitives are the `bvh2` layout's.
use glam::Vec3;

use crate::geometry::buffers::{Bvh4Node, LeafPrim};
use crate::geometry::features;
use crate::geometry::intersect::{SlabRay, slab_interval};
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::records::RecordLoad;
use crate::geometry::triangle::WatertightRay;
use crate::gpu::unchecked::{get, scratch, set};
use crate::trace::bvh2::leaf;
use crate::trace::hit::{ClosestHit, Hit, Query, STACK_DEPTH};

/// Stack entries of the walk: a step pushes at most three, and goes down
/// at least one binary level (a node's children are its descendants), so a
/// tree the depth check admits (internal nodes at most `STACK_DEPTH - 1`
/// levels deep) needs at most `3 STACK_DEPTH`.
pub const BVH4_STACK_ENTRIES: usize = 3 * STACK_DEPTH;

/// A tree in this layout: its nodes and the `bvh2` layout's leaf
/// primitives, as records or as the 16-byte vectors of their bytes (see
/// [`crate::trace::bvh2::Bvh2Tree`]).
pub struct Bvh4Tree<N, P> {
    pub nodes: N,
    pub leaf_prims: P,
}

impl<N: RecordLoad<Bvh4Node>, P: RecordLoad<LeafPrim>> Bvh4Tree<N, P> {
    #[inline]
    pub fn new(nodes: N, leaf_prims: P) -> Self {
        Bvh4Tree { nodes, leaf_prims }
    }
}

impl<N: RecordLoad<Bvh4Node>, P: RecordLoad<LeafPrim>> ClosestHit for Bvh4Tree<N, P> {
    #[inline]
    fn trace<const F: u32, const S: usize>(&self, o: Vec3, d: Vec3, from: Origin, query: Query, prims: &Prims, _: &mut [u32; S], _: u32) -> Hit {
        trace_bvh4::<F>(o, d, from, query, prims, &self.nodes, &self.leaf_prims)
    }
}

/// The closest hit through a [`Bvh4Node`] tree (root 0); `F` as for
/// [`crate::trace::classic::closest_hit_linear_for`].
#[inline]
pub fn closest_hit_bvh4<const F: u32>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    prims: &Prims,
    nodes: &[Bvh4Node],
    leaf_prims: &[LeafPrim],
) -> Hit {
    trace_bvh4::<F>(o, d, from, Query::CLOSEST, prims, nodes, leaf_prims)
}

/// [`closest_hit_bvh4`] with every primitive kind compiled in.
#[inline]
pub fn closest_hit_bvh4_all(o: Vec3, d: Vec3, from: Origin, prims: &Prims, nodes: &[Bvh4Node], leaf_prims: &[LeafPrim]) -> Hit {
    closest_hit_bvh4::<{ features::ALL }>(o, d, from, prims, nodes, leaf_prims)
}

/// A child to walk: its node and entry distance (+inf: none).
#[derive(Clone, Copy)]
struct Candidate {
    node: u32,
    t: f32,
}

/// Child `node` if the ray meets its box (`near <= far`), it is internal
/// (`count == 0`) and it starts no farther than the hit so far.
#[inline]
fn candidate(node: u32, count: u32, (near, far): (f32, f32), t_hit: f32) -> Candidate {
    let walk = near <= far && count == 0 && near <= t_hit;
    Candidate { node, t: if walk { near } else { f32::INFINITY } }
}

/// Puts the nearer of `a` and `b` first.
#[inline]
fn order(a: &mut Candidate, b: &mut Candidate) {
    if b.t < a.t {
        let x = *a;
        *a = *b;
        *b = x;
    }
}

/// [`closest_hit_bvh4`] for any [`Query`].
#[inline]
pub fn trace_bvh4<const F: u32>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    query: Query,
    prims: &Prims,
    nodes: &(impl RecordLoad<Bvh4Node> + ?Sized),
    leaf_prims: &(impl RecordLoad<LeafPrim> + ?Sized),
) -> Hit {
    let mut hit = query.start();
    if prims.count() == 0 {
        return hit;
    }
    let mut slabs = SlabRay::new(o, d);
    if slabs.is_parallel() {
        // See `SlabRay::within`: the root's box, the union of its slots'.
        let r = nodes.load(0);
        let (mut lo, mut hi) = r.slot_box(0);
        let mut k = 1;
        while k < 4 {
            let (l, h) = r.slot_box(k);
            lo = [lo[0].min(l[0]), lo[1].min(l[1]), lo[2].min(l[2])];
            hi = [hi[0].max(h[0]), hi[1].max(h[1]), hi[2].max(h[2])];
            k += 1;
        }
        slabs = slabs.within(lo, hi);
    }
    let (ray, at_ray) = (WatertightRay::new(o, d), (o, d, from));
    // Entries: node index and the entry distance it was pushed with.
    let mut stack = scratch::<u32, { 2 * BVH4_STACK_ENTRIES }>();
    let mut top = 0usize;
    let mut node = 0u32;
    loop {
        let n = nodes.load(node as usize);
        let reach = hit.reach();
        let s0 = slab_interval(n.slot_box(0).0, n.slot_box(0).1, &slabs, reach);
        let s1 = slab_interval(n.slot_box(1).0, n.slot_box(1).1, &slabs, reach);
        let s2 = slab_interval(n.slot_box(2).0, n.slot_box(2).1, &slabs, reach);
        let s3 = slab_interval(n.slot_box(3).0, n.slot_box(3).1, &slabs, reach);
        // Leaves are tested at once, in slot order; only internal children
        // are walked.
        if s0.0 <= s0.1 && n.count[0] > 0 {
            leaf::<F>(&mut hit, n.child[0], n.count[0], at_ray, &query, &ray, prims, leaf_prims);
        }
        if s1.0 <= s1.1 && n.count[1] > 0 {
            leaf::<F>(&mut hit, n.child[1], n.count[1], at_ray, &query, &ray, prims, leaf_prims);
        }
        if s2.0 <= s2.1 && n.count[2] > 0 {
            leaf::<F>(&mut hit, n.child[2], n.count[2], at_ray, &query, &ray, prims, leaf_prims);
        }
        if s3.0 <= s3.1 && n.count[3] > 0 {
            leaf::<F>(&mut hit, n.child[3], n.count[3], at_ray, &query, &ray, prims, leaf_prims);
        }
        if query.done(&hit) {
            return hit;
        }
        let reach = hit.reach();
        let mut c0 = candidate(n.child[0], n.count[0], s0, reach);
        let mut c1 = candidate(n.child[1], n.count[1], s1, reach);
        let mut c2 = candidate(n.child[2], n.count[2], s2, reach);
        let mut c3 = candidate(n.child[3], n.count[3], s3, reach);
        // Five exchanges sort four.
        order(&mut c0, &mut c1);
        order(&mut c2, &mut c3);
        order(&mut c0, &mut c2);
        order(&mut c1, &mut c3);
        order(&mut c1, &mut c2);
        if c0.t != f32::INFINITY {
            // The farthest first, so that the nearer come off the stack first.
            push(&mut stack, &mut top, c3);
            push(&mut stack, &mut top, c2);
            push(&mut stack, &mut top, c1);
            node = c0.node;
        } else {
            // Back to the nearest pushed child still worth entering.
            let mut next = u32::MAX;
            while next == u32::MAX && top > 0 {
                top -= 1;
                if f32::from_bits(get(&stack, 2 * top + 1)) <= hit.reach() {
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

/// Pushes `c` if it is a child to walk (the stack holds every entry a tree
/// the depth check admits can need: [`BVH4_STACK_ENTRIES`]).
#[inline]
fn push<const S: usize>(stack: &mut [u32; S], top: &mut usize, c: Candidate) {
    if c.t != f32::INFINITY && *top < S / 2 {
        set(stack, 2 * *top, c.node);
        set(stack, 2 * *top + 1, c.t.to_bits());
        *top += 1;
    }
}
