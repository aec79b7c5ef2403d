//! The final SAH leaf collapse (Karras & Aila 2013, section 4.4) and
//! compaction: the tree is rewritten in depth-first order into fresh arrays,
//! each subtree that is cheaper as one leaf becoming a leaf of several
//! primitives.
//!
//! Inputs are a tree in the LBVH layout (leaf of primitive slot `j` at node
//! `n - 1 + j`, one primitive each) and, per node, its primitive count and
//! its leaf count in the output (`tree_leaves`: 1 where the subtree
//! collapses), as [`crate::construct::treelet::kernels::treelet_init_kernel`] writes them.
//! In depth-first (pre-)order every node's position follows from counts
//! along its path to the root alone:
//!
//! ```text
//!   node index:  root 0; left child = parent + 1;
//!                right child = parent + 1 + (2 * tree_leaves[left] - 1)
//!   primitives:  a subtree's primitives are contiguous; right child's start
//!                = parent's start + counts[left]
//! ```
//!
//! So one invocation per primitive climbs to the root twice: once to sum its
//! offsets, once to write every output node whose leftmost primitive it is.
//! No atomics and no ordering between invocations are needed.
use crate::geometry::records::{RecordLoad, RecordStore};
use crate::geometry::buffers::{INVALID, LEAF_BIT, Node};

/// Kernel, one invocation per primitive slot `i < n`: writes its primitive
/// index into `out_prims`, and the output nodes (and parent links) of which
/// it is the leftmost primitive. The output has `2 * tree_leaves[0] - 1` nodes.
#[allow(clippy::too_many_arguments)]
pub fn collapse_kernel<N: RecordLoad<Node> + ?Sized, O: RecordStore<Node> + ?Sized>(
    i: u32,
    n: u32,
    nodes: &N,
    parents: &[u32],
    counts: &[u32],
    tree_leaves: &[u32],
    prims: &[u32],
    out_nodes: &mut O,
    out_parents: &mut [u32],
    out_prims: &mut [u32],
) {
    if i >= n {
        return;
    }
    let leaf = n - 1 + i;
    // First climb: the primitive's output position, the node offset of the
    // whole path, and how far up the topmost collapsing ancestor is.
    let (mut prim_pos, mut node_pos) = (0u32, 0u32);
    let (mut depth, mut top_depth) = (0u32, 0u32);
    let mut current = leaf;
    while current != 0 {
        let parent = parents[current as usize];
        let (prim_step, node_step) = step(&nodes.load(parent as usize), current, counts, tree_leaves);
        prim_pos += prim_step;
        node_pos += node_step;
        depth += 1;
        if tree_leaves[parent as usize] == 1 {
            top_depth = depth;
        }
        current = parent;
    }
    out_prims[prim_pos as usize] = prims[i as usize];
    // Second climb: below the output leaf nothing is written; from it up,
    // write each node while this primitive is its leftmost one.
    let (mut prim_below, mut node_below) = (0u32, 0u32);
    let mut d = 0u32;
    let mut current = leaf;
    loop {
        if prim_below != 0 && d >= top_depth {
            return; // not the leftmost primitive of anything higher
        }
        let (parent, prim_step, node_step) = if current == 0 {
            (INVALID, 0, 0)
        } else {
            let parent = parents[current as usize];
            let (p, s) = step(&nodes.load(parent as usize), current, counts, tree_leaves);
            (parent, p, s)
        };
        if d >= top_depth {
            let index = node_pos - node_below;
            let src = nodes.load(current as usize);
            let mut out = src;
            if d == top_depth {
                out.left = prim_pos - prim_below;
                out.right = LEAF_BIT | counts[current as usize];
            } else {
                out.left = index + 1;
                out.right = index + 2 * tree_leaves[src.left as usize];
            }
            out_nodes.store(index as usize, &out);
            out_parents[index as usize] = if current == 0 { INVALID } else { node_pos - node_below - node_step };
        }
        if current == 0 {
            return;
        }
        prim_below += prim_step;
        node_below += node_step;
        d += 1;
        current = parent;
    }
}

/// Offsets gained going from `child` up to `parent`: primitives and nodes
/// that come before `child`'s subtree within `parent`'s, in depth-first order.
#[inline]
fn step(parent: &Node, child: u32, counts: &[u32], tree_leaves: &[u32]) -> (u32, u32) {
    if parent.right == child {
        let left = parent.left as usize;
        (counts[left], 2 * tree_leaves[left])
    } else {
        (0, 1)
    }
}
