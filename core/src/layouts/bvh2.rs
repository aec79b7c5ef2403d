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
//! in leaf order) by two kernels without atomics: [`bvh2_node_kernel`]
//! (internal node `i` of the input becomes node `f(i)` of the output, the
//! number of internal nodes before it in depth-first order, found by
//! climbing) and [`leaf_prims_kernel`] (the primitives in leaf order).
use crate::construct::climb::second_arrival;
use crate::construct::primitive_boxes::primitive_box;
use crate::geometry::aabb::Aabb;
use crate::geometry::records::{RecordLoad, RecordStore};
use crate::geometry::buffers::{Bvh2Node, LeafPrim, Node, Sphere};
use crate::geometry::prims::Prims;
use crate::geometry::split::{Split, SplitMut};
use crate::geometry::triangle::Triangle;
use crate::gpu::atomics;
use crate::gpu::unchecked::at;
use crate::geometry::buffers::ENTER;

/// Kernel, one invocation per node `i` of a collapsed tree (`node_count`
/// nodes, root 0, depth-first order: a left child follows its parent, a
/// right child `right = i + 2 L` where `L` is its left sibling's leaf
/// count): each internal node writes its [`Bvh2Node`]. A tree of one leaf
/// gets a root whose second child is an empty box.
pub fn bvh2_node_kernel<N: RecordLoad<Node> + ?Sized, O: RecordStore<Bvh2Node> + ?Sized>(
    i: u32,
    node_count: u32,
    nodes: &N,
    parents: &[u32],
    out: &mut O,
) {
    if i >= node_count {
        return;
    }
    let node = nodes.load(i as usize);
    if node.is_leaf() {
        if node_count == 1 {
            out.store(0, &single_leaf_root(&node, node.left, node.prim_count()));
        }
        return;
    }
    let index = output_index(i, parents);
    let (l, r) = (nodes.load(node.left as usize), nodes.load(node.right as usize));
    let record = two_boxes(&l, &r, child_ref(&l, index + 1), child_ref(&r, index + (node.right - i) / 2));
    out.store(index as usize, &record);
}

/// Internal node `i` of a collapsed tree (depth-first order, as
/// [`bvh2_node_kernel`] takes it) is node `f(i)` of the layout: the number
/// of internal nodes before it in depth-first order. A left child is its
/// parent's next; a right child comes after its left sibling's `L - 1`
/// internal nodes (`right = parent + 2 L`).
#[inline]
fn output_index(i: u32, parents: &[u32]) -> u32 {
    let mut index = 0u32;
    let mut x = i;
    while x != 0 {
        let p = parents[x as usize];
        index += if x == p + 1 { 1 } else { (x - p) / 2 };
        x = p;
    }
    index
}

/// Kernel, one invocation per node `i` of the collapsed tree a layout was
/// made from: the state [`refit_kernel`] climbs on, made once per tree and
/// kept from one refit to the next. Two words per node: `state[2 i]` is
/// node `i`'s arrival counter (zeroed; a climb leaves it even, as it found
/// it: [`crate::construct::climb::second_arrival`]), `state[2 i + 1]` the
/// index of its [`Bvh2Node`] in the layout (internal nodes; `u32::MAX` for
/// a leaf), side by side so that the climber that counts at a node reads
/// where to write from the same cache line. Then a word per primitive slot
/// (`state[2 node_count + j]`): the leaf whose first slot `j` is, else
/// `u32::MAX`.
pub fn refit_state_kernel<N: RecordLoad<Node> + ?Sized>(i: u32, node_count: u32, nodes: &N, parents: &[u32], state: &mut [u32]) {
    if i >= node_count {
        return;
    }
    let node = nodes.load(i as usize);
    let slot = if node.is_leaf() { u32::MAX } else { output_index(i, parents) };
    state[2 * i as usize] = 0;
    state[2 * i as usize + 1] = slot;
    if node.is_leaf() {
        let slots = 2 * node_count as usize + node.left as usize;
        state[slots] = i;
        let mut k = 1;
        while k < node.prim_count() as usize {
            state[slots + k] = u32::MAX;
            k += 1;
        }
    }
}

/// Kernel: the refit of a `bvh2` layout in place, over the collapsed tree it
/// was made from (its shape kept; `prims` moved), one invocation per
/// primitive slot `j` of `n`. Each writes its slot's [`LeafPrim`] again
/// (slots side by side in neighbouring invocations); the first slot of a
/// leaf then makes the leaf's box, the union of its primitives' (read again,
/// from the cache its neighbours just filled), writes it into its parent's
/// [`Bvh2Node`] (`out_nodes`, as 16 words a node), and climbs as the
/// build's fit does ([`crate::construct::fit`]): the second child to arrive
/// at a node reads its sibling's box from the same node and writes the
/// union into the node above. So the layout's boxes are written where the
/// climb makes them: no pass over the nodes after it, and the collapsed tree
/// is only read (its boxes stay those of the build; its shape and parent
/// links are what the refit uses). `state` is [`refit_state_kernel`]'s.
#[allow(clippy::too_many_arguments)]
pub fn refit_kernel<const ORDERED: bool, N: RecordLoad<Node> + ?Sized, O: RecordStore<LeafPrim> + ?Sized>(
    j: u32,
    n: u32,
    node_count: u32,
    prims: &Prims,
    prim_indices: &[u32],
    nodes: &N,
    parents: &[u32],
    state: &mut [u32],
    out_prims: &mut O,
    out_nodes: &mut SplitMut<f32>,
) {
    if j >= n {
        return;
    }
    out_prims.store(j as usize, &prims.leaf_prim(prim_indices[j as usize]));
    let i = state[2 * node_count as usize + j as usize];
    if i == u32::MAX {
        return;
    }
    let node = nodes.load(i as usize);
    let mut own = Aabb::EMPTY;
    for slot in node.left..node.left + node.prim_count() {
        let prim = prim_indices[slot as usize];
        own = own.union(&primitive_box(prim, prims.sphere_count, prims.spheres, &prims.triangles));
    }
    if node_count == 1 {
        // A tree of one leaf: the root's first child.
        store_child_box(out_nodes, 0, true, &own);
        return;
    }
    // The climber keeps its subtree's box and reads only the sibling's.
    let mut child = i;
    loop {
        let parent = parents[child as usize];
        let slot = state[2 * parent as usize + 1];
        let left = child == parent + 1;
        store_child_box(out_nodes, slot, left, &own);
        if !second_arrival::<ORDERED>(&mut state[2 * parent as usize]) {
            return;
        }
        let sibling = load_child_box(out_nodes, slot, !left);
        own = if left { own.union(&sibling) } else { sibling.union(&own) };
        if parent == 0 {
            return;
        }
        child = parent;
    }
}

/// The first word of a child's box in node `slot` of a layout read as
/// words: [`Bvh2Node`] holds `left_min, left, left_max, right, right_min,
/// left_count, right_max, right_count`, a box's minimum three words and its
/// maximum four further on.
#[inline]
fn child_box_word(slot: u32, left: bool) -> usize {
    16 * slot as usize + if left { 0 } else { 8 }
}

/// Writes a child's box into its parent's node, with device-scope stores:
/// the sibling's climber reads it after the arrival that orders them (see
/// [`crate::construct::climb`]).
#[inline]
fn store_child_box(out_nodes: &mut SplitMut<f32>, slot: u32, left: bool, b: &Aabb) {
    let w = child_box_word(slot, left);
    for k in 0..3 {
        out_nodes.with_mut(w + k, |x| atomics::store_f32(x, b.min[k]));
        out_nodes.with_mut(w + 4 + k, |x| atomics::store_f32(x, b.max[k]));
    }
}

/// Reads a child's box from its parent's node, written by
/// [`store_child_box`] in another invocation.
#[inline]
fn load_child_box(out_nodes: &SplitMut<f32>, slot: u32, left: bool) -> Aabb {
    let w = child_box_word(slot, left);
    let mut b = Aabb::EMPTY;
    for k in 0..3 {
        b.min[k] = out_nodes.with(w + k, atomics::load_f32);
        b.max[k] = out_nodes.with(w + 4 + k, atomics::load_f32);
    }
    b
}

/// The node of children `l` and `r`, referred to as given (a leaf by its
/// first primitive and count, an internal node by its index and 0).
#[inline]
fn two_boxes(l: &Node, r: &Node, (left, left_count): (u32, u32), (right, right_count): (u32, u32)) -> Bvh2Node {
    Bvh2Node { left_min: l.min, left, left_max: l.max, right, right_min: r.min, left_count, right_max: r.max, right_count }
}

/// The root of a tree of one leaf: that leaf (as `left`, `count`), and a
/// second child with an empty box, a leaf that no ray reaches.
#[inline]
fn single_leaf_root(leaf: &Node, left: u32, count: u32) -> Bvh2Node {
    let mut root = Bvh2Node { left, left_count: count, ..Default::default() };
    (root.left_min, root.left_max) = (leaf.min, leaf.max);
    (root.right_min, root.right_max) = ([f32::MAX; 3], [-f32::MAX; 3]);
    root.right_count = 1;
    root
}

/// A child as its parent refers to it: a leaf by its first primitive and
/// count, an internal node by its index in the output.
#[inline]
fn child_ref(c: &Node, internal_index: u32) -> (u32, u32) {
    if c.is_leaf() {
        (c.left, c.prim_count())
    } else {
        (internal_index, 0)
    }
}

/// Kernel, one invocation per internal node `i < n - 1` of a tree over
/// `n` instances in the LBVH layout (as built: root 0, leaf of slot `j` at
/// `n - 1 + j`): the top level of an instanced scene
/// ([`crate::trace::instances`]) in the [`Bvh2Node`] layout, node `i` at
/// `i`, without the collapse's depth-first compaction or leaf primitives:
/// a leaf child refers to its instance directly (`prim_indices[j]` with
/// [`ENTER`], count 0: walked to as a node, and entered). One tree of one
/// leaf gets a root whose second child is an empty box.
pub fn top_level_node_kernel<N: RecordLoad<Node> + ?Sized, O: RecordStore<Bvh2Node> + ?Sized>(
    i: u32,
    n: u32,
    nodes: &N,
    prim_indices: &[u32],
    out: &mut O,
) {
    if n == 1 {
        if i == 0 {
            out.store(0, &single_leaf_root(&nodes.load(0), ENTER | at(prim_indices, 0), 0));
        }
        return;
    }
    if i + 1 >= n {
        return;
    }
    let node = nodes.load(i as usize);
    let (l, r) = (nodes.load(node.left as usize), nodes.load(node.right as usize));
    let child = |index: u32, c: &Node| if c.is_leaf() { (ENTER | at(prim_indices, c.left as usize), 0) } else { (index, 0) };
    out.store(i as usize, &two_boxes(&l, &r, child(node.left, &l), child(node.right, &r)));
}

/// Kernel, one invocation per node `i` of an instanced scene's top level
/// (`2n - 1` of them, as built): [`top_level_node_kernel`], and each leaf's
/// depth raised into `deepest[0]` (zeroed) by
/// [`crate::layouts::depth::leaf_depth_kernel`]. One dispatch for both: the
/// top level is rebuilt every frame, and a dispatch of its own cost the
/// depth check about 3 µs on the H100.
#[allow(clippy::too_many_arguments)]
pub fn top_level_kernel<N: RecordLoad<Node> + ?Sized, O: RecordStore<Bvh2Node> + ?Sized>(
    i: u32,
    n: u32,
    nodes: &N,
    parents: &[u32],
    prim_indices: &[u32],
    out: &mut O,
    deepest: &mut [u32],
) {
    top_level_node_kernel(i, n, nodes, prim_indices, out);
    crate::layouts::depth::leaf_depth_kernel(i, 2 * n - 1, nodes, parents, deepest);
}

/// Kernel, one invocation per primitive slot `j < n`: the primitive of
/// slot `j` (`prim_indices[j]`, in leaf order) as its leaf stores it.
pub fn leaf_prims_kernel<O: RecordStore<LeafPrim> + ?Sized>(
    j: u32,
    n: u32,
    sphere_count: u32,
    prim_indices: &[u32],
    spheres: &[Sphere],
    triangles: Split<'_, Triangle>,
    out: &mut O,
) {
    if j >= n {
        return;
    }
    let prims = Prims { spheres, sphere_count, triangles, triangle_count: n - sphere_count };
    out.store(j as usize, &prims.leaf_prim(prim_indices[j as usize]));
}

