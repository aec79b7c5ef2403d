//! Bottom-up bounds (Karras 2012, section 4): one invocation per leaf writes
//! its leaf, then climbs towards the root ([`crate::construct::climb`]): at
//! each internal node the second of its children's invocations to arrive,
//! which knows both children are done, writes the union of their boxes and
//! goes on. Every internal node is thus written exactly once.
//!
//! On the GPU the boxes cross invocations, so they are written and read with
//! device-scope atomics (under the Vulkan memory model plain accesses would
//! not be made visible), ordered by the counter's acquire-release semantics.
use crate::construct::climb::Climb;
use crate::construct::radix_tree::leaf_node;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{INVALID, LEAF_BIT, Node};
use crate::geometry::split::SplitMut;
use crate::gpu::atomics;

#[inline]
pub(crate) fn store_box(node: &mut Node, b: &Aabb) {
    for k in 0..3 {
        atomics::store_f32(&mut node.min[k], b.min[k]);
        atomics::store_f32(&mut node.max[k], b.max[k]);
    }
}

#[inline]
pub(crate) fn load_box(node: &Node) -> Aabb {
    let mut b = Aabb::EMPTY;
    for k in 0..3 {
        b.min[k] = atomics::load_f32(&node.min[k]);
        b.max[k] = atomics::load_f32(&node.max[k]);
    }
    b
}

/// Leaf `i` (sorted position): its node, and its box.
#[inline]
pub(crate) fn leaf_record(i: u32, sorted_prims: &[u32], prim_boxes: &[Aabb]) -> (Node, Aabb) {
    let b = prim_boxes[sorted_prims[i as usize] as usize];
    (Node { min: b.min, left: i, max: b.max, right: LEAF_BIT | 1 }, b)
}

/// Writes leaf `i` (sorted position) of `n` and its box, which it returns;
/// for a one-leaf tree, also its parent link (none). The start of every
/// bottom-up climb ([`fit_kernel`], [`crate::construct::agglomerate`]).
#[inline]
pub(crate) fn write_leaf(
    i: u32,
    n: u32,
    sorted_prims: &[u32],
    prim_boxes: &[Aabb],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
) -> Aabb {
    let leaf = leaf_node(n, i);
    let (record, b) = leaf_record(i, sorted_prims, prim_boxes);
    nodes.with_mut(leaf as usize, |node| {
        node.left = record.left;
        node.right = record.right;
        store_box(node, &b);
    });
    if n == 1 {
        parents[0] = INVALID;
    }
    b
}

/// Kernel: leaf `i` (sorted position) of `n`. `flags` holds one zeroed counter
/// per internal node; `sorted_prims[i]` is the primitive of leaf `i`.
/// `ORDERED` gives the counter acquire-release semantics (see
/// [`atomics::add_device_acq_rel`] for the one device that needs it relaxed).
pub fn fit_kernel<const ORDERED: bool>(
    i: u32,
    n: u32,
    sorted_prims: &[u32],
    prim_boxes: &[Aabb],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    flags: &mut [u32],
) {
    if i >= n {
        return;
    }
    let b = write_leaf(i, n, sorted_prims, prim_boxes, nodes, parents);
    if n == 1 {
        return;
    }
    climb_boxes::<ORDERED>(leaf_node(n, i), b, nodes, parents, flags);
}

/// Kernel: leaf `i` of a tree of `n` leaves in the LBVH layout whose
/// shape changed ([`crate::construct::reinsert`]): climbs as [`fit_kernel`]
/// does, from the box the leaf holds, so every internal node gets the
/// union of its children's boxes again. `flags` are zeroed counters.
pub fn refit_nodes_kernel<const ORDERED: bool>(i: u32, n: u32, nodes: &mut SplitMut<Node>, parents: &[u32], flags: &mut [u32]) {
    if i >= n || n == 1 {
        return;
    }
    let leaf = leaf_node(n, i);
    let own = nodes.with(leaf as usize, load_box);
    climb_boxes::<ORDERED>(leaf, own, nodes, parents, flags);
}

/// The climb of [`fit_kernel`] from node `start`, whose box `own` is
/// written: each internal node it arrives at second gets the union of its
/// children's boxes. (The `bvh2` layout's refit climbs the same way but
/// keeps its boxes in the layout's nodes: `crate::layouts::bvh2::refit_kernel`.)
#[inline]
fn climb_boxes<const ORDERED: bool>(start: u32, own: Aabb, nodes: &mut SplitMut<Node>, parents: &[u32], flags: &mut [u32]) {
    // The climber keeps its subtree's box and reads only the sibling's.
    let mut own = own;
    let mut climb = Climb::<ORDERED>::new(start);
    while let Some(parent) = climb.next(parents, flags) {
        let (left, right) = nodes.with(parent as usize, |node| (node.left, node.right));
        own = if left == climb.child() {
            own.union(&nodes.with(right as usize, load_box))
        } else {
            nodes.with(left as usize, load_box).union(&own)
        };
        nodes.with_mut(parent as usize, |node| store_box(node, &own));
    }
}
