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

use crate::geometry::buffers::{Bvh2Node, InstanceRecord, LeafPrim};
use crate::geometry::features;
use crate::geometry::intersect::{SlabRay, slab_interval};
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::triangle::WatertightRay;
use crate::gpu::unchecked::{get, scratch, set};
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
    // One level: the instances are never read.
    let one = Level { nodes, leaves: leaf_prims };
    walk::<F, false, { 2 * STACK_DEPTH }>(o, d, from, &query, prims, &NoInstances, &one).0
}

/// The buffers a walk reads: the nodes of its trees (for an instanced
/// scene, the top level's from node 0, then every mesh's) and their leaf
/// primitives.
pub struct Level<'a, N: ?Sized, L: ?Sized> {
    pub nodes: &'a N,
    pub leaves: &'a L,
}

/// The instances of a walk without any ([`trace_bvh2`]).
pub struct NoInstances;

impl RecordLoad<InstanceRecord> for NoInstances {
    #[inline]
    fn load(&self, _: usize) -> InstanceRecord {
        InstanceRecord::default()
    }
}

/// A top-level child that is an instance carries this bit on its index
/// (and a count of 0: [`crate::layouts::bvh2::top_level_node_kernel`]), so
/// the walk goes to it as to an internal node and enters it when it gets
/// there; no node of a mesh's tree has an index this high.
pub use crate::geometry::buffers::ENTER;

/// The walk every traversal of this layout shares, nearer child first (see
/// the module doc), from `query.start()`. With `INSTANCED`, `trees` holds
/// an instanced scene's top level from node 0 (a tree over `instances`,
/// [`crate::trace::instances`]) and every mesh's tree after it: a top-level
/// child is an instance ([`ENTER`]), entered when the walk gets to it by
/// taking the ray into its mesh's space and going on in the mesh's tree
/// (at the instance's bases), on the same stack, until the stack is back
/// at its height on entering. One buffer for both levels, so every node is
/// read by the one load (two loads under a branch made the walk slower),
/// and one loop body for both (the top level has no leaves to test, so
/// nothing in the loop asks which level it is in).
/// Without, `trees` is the one tree and `instances` is never read: the
/// same code as a plain walk. `STACK`: words of the stack (two an entry;
/// [`STACK_DEPTH`] entries a level). Returns the hit and its instance
/// (`u32::MAX` without).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn walk<const F: u32, const INSTANCED: bool, const STACK: usize>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    query: &Query,
    prims: &Prims,
    instances: &(impl RecordLoad<InstanceRecord> + ?Sized),
    trees: &Level<impl RecordLoad<Bvh2Node> + ?Sized, impl RecordLoad<LeafPrim> + ?Sized>,
) -> (Hit, u32) {
    let mut hit = query.start();
    let mut found_in = u32::MAX;
    // The bases of the nodes and leaf primitives of the mesh the walk is
    // in (0 in the top level), and the ray in its space.
    let (mut node_base, mut leaf_base) = (0u32, 0u32);
    // A plain walk bounds the far bias of an axis the ray runs parallel to
    // by the root's box (`slab_ray`); the instanced walk does not yet (the
    // check cost its kernel 8 registers: docs/results/h200-axis-rays-2026-12-02).
    let slabs = if INSTANCED { SlabRay::new(o, d) } else { slab_ray(o, d, trees.nodes, 0) };
    let (mut slabs, mut ray, mut at_ray) = (slabs, WatertightRay::new(o, d), (o, d, from));
    // Entries: node index and the entry distance it was pushed with; below
    // `floor`, the top level's (`usize::MAX` while in the top level).
    // `STACK` words: two a level of depth, for both levels when
    // instanced, and then the world ray and the instance entered in the
    // last `WORLD` words: read only on entering and leaving a mesh, they
    // stay out of the registers the walk's loop keeps (held there, the
    // driver gave the engine's instanced kernel 80 registers against the
    // plain walk's 64, so three workgroups an SM instead of four; now 64
    // as well).
    let mut stack = scratch::<u32, STACK>();
    let entries = if INSTANCED { (STACK - WORLD) / 2 } else { STACK / 2 };
    if INSTANCED {
        let w = [o.x, o.y, o.z, d.x, d.y, d.z];
        let mut k = 0;
        while k < 6 {
            set(&mut stack, STACK - WORLD + k, w[k].to_bits());
            k += 1;
        }
    }
    let (mut top_len, mut floor) = (0usize, usize::MAX);
    let mut node = 0u32;
    loop {
        if INSTANCED && node & ENTER != 0 {
            let current = node & !ENTER;
            set(&mut stack, STACK - 1, current);
            let record = instances.load(current as usize);
            (node_base, leaf_base) = (record.node_base, record.leaf_base);
            let (wo, wd) = world_ray::<STACK>(&stack);
            let (o2, d2) = record.to_object(wo, wd);
            (slabs, ray, at_ray) = (SlabRay::new(o2, d2), WatertightRay::new(o2, d2), (o2, d2, Origin::NONE));
            floor = top_len;
            node = 0;
        }
        let n = trees.nodes.load((node_base + node) as usize);
        let reach = hit.reach();
        let (ln, lf) = slab_interval(n.left_min, n.left_max, &slabs, reach);
        let (rn, rf) = slab_interval(n.right_min, n.right_max, &slabs, reach);
        let (mut go_left, mut go_right) = (ln <= lf, rn <= rf);
        // Leaves are tested at once; only internal children are walked.
        let before = hit;
        let leaves = (leaf_base, query, &ray, prims, trees.leaves);
        if go_left && n.left_count > 0 {
            leaf::<F>(&mut hit, leaves.0 + n.left, n.left_count, at_ray, leaves.1, leaves.2, leaves.3, leaves.4);
            go_left = false;
        }
        if go_right && n.right_count > 0 {
            leaf::<F>(&mut hit, leaves.0 + n.right, n.right_count, at_ray, leaves.1, leaves.2, leaves.3, leaves.4);
            go_right = false;
        }
        if INSTANCED && (hit.t != before.t || hit.prim != before.prim) {
            found_in = get(&stack, STACK - 1);
        }
        if query.done(&hit) {
            return (hit, found_in);
        }
        let (left, right) = (n.left, n.right);
        if go_left && go_right {
            let (near, far, far_t) = if ln <= rn { (left, right, rn) } else { (right, left, ln) };
            if top_len < entries {
                set(&mut stack, 2 * top_len, far);
                set(&mut stack, 2 * top_len + 1, far_t.to_bits());
                top_len += 1;
            }
            node = near;
        } else if go_left {
            node = left;
        } else if go_right {
            node = right;
        } else {
            // Back to the nearest pushed child still worth entering; out of
            // the mesh when its entries are all taken.
            let mut next = u32::MAX;
            while next == u32::MAX {
                if INSTANCED && top_len == floor {
                    floor = usize::MAX;
                    node_base = 0;
                    let (wo, wd) = world_ray::<STACK>(&stack);
                    slabs = SlabRay::new(wo, wd);
                }
                if top_len == 0 {
                    break;
                }
                top_len -= 1;
                if f32::from_bits(get(&stack, 2 * top_len + 1)) <= hit.reach() {
                    next = get(&stack, 2 * top_len);
                }
            }
            if next == u32::MAX {
                return (hit, found_in);
            }
            node = next;
        }
    }
}

/// The slab ray of `(o, d)` for the tree whose root is node `root`:
/// [`SlabRay::within`] its box, which a ray parallel to an axis needs (one
/// more load of the root, for those rays only: loading it for every ray
/// cost short rays up to a fifth of their speed, and loading it once before
/// a loop that loads each next node at its end cost 5-20%, both measured).
/// Without it, a ray straight down a city of blocks entered 90 times the
/// nodes of one tilted by a thousandth (`tests/layouts.rs`).
#[inline]
fn slab_ray(o: Vec3, d: Vec3, nodes: &(impl RecordLoad<Bvh2Node> + ?Sized), root: u32) -> SlabRay {
    let slabs = SlabRay::new(o, d);
    if !slabs.is_parallel() {
        return slabs;
    }
    let r = nodes.load(root as usize);
    let (a, b) = (r.left_min, r.right_min);
    let lo = [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])];
    let (a, b) = (r.left_max, r.right_max);
    let hi = [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])];
    slabs.within(lo, hi)
}

/// Words at the end of an instanced walk's stack: the world ray (origin,
/// direction) and the instance the walk is in.
const WORLD: usize = 7;

/// The stack of an instanced walk: [`STACK_DEPTH`] entries of two words
/// for each level, and the world ray and instance (seven words, rounded up
/// to an entry) at its end.
pub const INSTANCED_STACK_WORDS: usize = 4 * STACK_DEPTH + WORLD + 1;

/// The world ray an instanced walk keeps at the end of its stack.
#[inline]
fn world_ray<const STACK: usize>(stack: &[u32; STACK]) -> (Vec3, Vec3) {
    let w = |k: usize| f32::from_bits(get(stack, STACK - WORLD + k));
    (Vec3::new(w(0), w(1), w(2)), Vec3::new(w(3), w(4), w(5)))
}

/// [`closest_hit_bvh2`] with every primitive kind compiled in.
#[inline]
pub fn closest_hit_bvh2_all(o: Vec3, d: Vec3, from: Origin, prims: &Prims, nodes: &[Bvh2Node], leaf_prims: &[LeafPrim]) -> Hit {
    closest_hit_bvh2::<{ features::ALL }>(o, d, from, prims, nodes, leaf_prims)
}
