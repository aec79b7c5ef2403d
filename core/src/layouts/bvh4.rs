//! The 4-wide layout of full-precision boxes ([`Bvh4Node`]), made from the
//! `bvh2` layout ([`crate::layouts::bvh2`]): each two-box node's two
//! children, then twice the internal child of the largest surface area
//! replaced by its own two (the greedy collapse of wide BVH builders: the
//! children rays meet most are opened first). So a walk from the root
//! skips most levels of the binary tree: about half the steps, each
//! testing four boxes instead of two, with no decoding (the compressed
//! 8-wide layout spends about 40 instructions a child on its quantized
//! boxes, which made it slower than `bvh2` on the H200:
//! `docs/results/h200-real-scenes-2026-11-29b/`, section 4). Guthe 2014,
//! "Latency Considerations of Depth-first GPU Ray Tracing", found 4-wide
//! nodes the best trade of steps against work per step on GPUs.
//!
//! One kernel without atomics, [`bvh4_node_kernel`]: node `i` of the `bvh2`
//! layout becomes node `i` here, the internal nodes among its children
//! keeping their `bvh2` indices. A walk reaches only some of the nodes;
//! the others are written and never read (up to twice the nodes' memory,
//! none of it in the cache: each node is one 128-byte line). The leaf
//! primitives are the `bvh2` layout's, shared.
use crate::geometry::buffers::{Bvh2Node, Bvh4Node};
use crate::geometry::records::{RecordLoad, RecordStore};

/// A slot no ray reaches: an inverted infinite box (every slab test gives
/// an entry of +inf and an exit of -inf), a leaf of one primitive.
pub const EMPTY_SLOT: (f32, f32) = (f32::INFINITY, f32::NEG_INFINITY);

impl Bvh4Node {
    /// Every slot empty ([`EMPTY_SLOT`]).
    pub const EMPTY: Bvh4Node = Bvh4Node {
        lo_x: [EMPTY_SLOT.0; 4],
        hi_x: [EMPTY_SLOT.1; 4],
        lo_y: [EMPTY_SLOT.0; 4],
        hi_y: [EMPTY_SLOT.1; 4],
        lo_z: [EMPTY_SLOT.0; 4],
        hi_z: [EMPTY_SLOT.1; 4],
        child: [0; 4],
        count: [1; 4],
    };

    /// Slot `k`: the box `lo..hi`, and the child (`count` 0: an internal
    /// node; else a leaf of `count` primitives from `child` on).
    #[inline]
    fn set(&mut self, k: usize, lo: [f32; 3], hi: [f32; 3], child: u32, count: u32) {
        self.lo_x[k] = lo[0];
        self.lo_y[k] = lo[1];
        self.lo_z[k] = lo[2];
        self.hi_x[k] = hi[0];
        self.hi_y[k] = hi[1];
        self.hi_z[k] = hi[2];
        self.child[k] = child;
        self.count[k] = count;
    }

    /// Child `k`'s box.
    #[inline]
    pub fn slot_box(&self, k: usize) -> ([f32; 3], [f32; 3]) {
        ([self.lo_x[k], self.lo_y[k], self.lo_z[k]], [self.hi_x[k], self.hi_y[k], self.hi_z[k]])
    }
}

/// Kernel, one invocation per node `i` of a `bvh2` layout of `node_count`
/// nodes: its [`Bvh4Node`] at `i` (see the module doc): its two children in
/// slots 0 and 1, then, twice, the internal child of the largest half area
/// (the first such slot on ties) replaced by its left child, its right
/// child in the next free slot.
pub fn bvh4_node_kernel<N: RecordLoad<Bvh2Node> + ?Sized, O: RecordStore<Bvh4Node> + ?Sized>(
    i: u32,
    node_count: u32,
    nodes: &N,
    out: &mut O,
) {
    if i >= node_count {
        return;
    }
    let n = nodes.load(i as usize);
    let mut w = Bvh4Node::EMPTY;
    w.set(0, n.left_min, n.left_max, n.left, n.left_count);
    w.set(1, n.right_min, n.right_max, n.right, n.right_count);
    let mut used = 2usize;
    while used < 4 {
        let mut open = usize::MAX;
        let mut largest = -1.0f32;
        let mut k = 0;
        while k < used {
            if w.count[k] == 0 {
                let (lo, hi) = w.slot_box(k);
                let a = half_area(lo, hi);
                if a > largest {
                    (open, largest) = (k, a);
                }
            }
            k += 1;
        }
        if open == usize::MAX {
            break;
        }
        let c = nodes.load(w.child[open] as usize);
        w.set(open, c.left_min, c.left_max, c.left, c.left_count);
        w.set(used, c.right_min, c.right_max, c.right, c.right_count);
        used += 1;
    }
    out.store(i as usize, &w);
}

/// Half the surface area of the box `lo..hi` (0 for an empty or flat one).
#[inline]
fn half_area(lo: [f32; 3], hi: [f32; 3]) -> f32 {
    let (x, y, z) = ((hi[0] - lo[0]).max(0.0), (hi[1] - lo[1]).max(0.0), (hi[2] - lo[2]).max(0.0));
    x * y + y * z + z * x
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn two(lo: f32, left: (u32, u32), right: (u32, u32)) -> Bvh2Node {
        Bvh2Node {
            left_min: [lo; 3],
            left: left.0,
            left_max: [lo + 1.0; 3],
            right: right.0,
            right_min: [lo + 2.0; 3],
            left_count: left.1,
            right_max: [lo + 3.0; 3],
            right_count: right.1,
        }
    }

    #[test]
    fn the_largest_internal_children_are_opened_and_leaves_stay_one_slot() {
        // Root 0: left internal (node 1: two leaves), right a leaf of 3 at 7.
        let nodes: Vec<Bvh2Node> = std::vec![two(0.0, (1, 0), (7, 3)), two(10.0, (0, 2), (2, 5))];
        let mut out = std::vec![Bvh4Node::default(); 2];
        for i in 0..3 {
            bvh4_node_kernel(i, 2, &nodes[..], &mut out[..]);
        }
        let root = out[0];
        assert_eq!((root.child, root.count), ([0, 7, 2, 0], [2, 3, 5, 1]));
        assert_eq!(root.slot_box(0), ([10.0; 3], [11.0; 3]));
        assert_eq!(root.slot_box(1), ([2.0; 3], [3.0; 3]));
        assert_eq!(root.slot_box(2), ([12.0; 3], [13.0; 3]));
        assert_eq!(root.slot_box(3), ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]));
        // Node 1 (never walked from the root) is written all the same.
        assert_eq!((out[1].child, out[1].count), ([0, 2, 0, 0], [2, 5, 1, 1]));
        // Three internal levels: the larger of the two internal children is
        // opened first, then the largest of what is left.
        let deep: Vec<Bvh2Node> = std::vec![two(0.0, (1, 0), (2, 0)), two(0.0, (0, 1), (1, 1)), two(0.0, (2, 1), (3, 1))];
        let mut out = std::vec![Bvh4Node::default(); 3];
        for i in 0..3 {
            bvh4_node_kernel(i, 3, &deep[..], &mut out[..]);
        }
        // Node 0's right child (box 2..3, half area 3) is as large as its
        // left (0..1, half area 3): the first, node 1, opens, then node 2.
        assert_eq!((out[0].child, out[0].count), ([0, 2, 1, 3], [1, 1, 1, 1]));
    }
}
