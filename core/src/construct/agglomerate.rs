//! Hierarchy and bounds in one bottom-up pass: C. Apetrei, "Fast and Simple
//! Agglomerative LBVH Construction", CGVC 2014.
//!
//! One invocation per leaf climbs as in [`crate::construct::fit`], but no radix tree is
//! built first, so there are no parent links to climb along (as
//! [`crate::construct::climb::Climb`] does): a node covering the sorted keys
//! `[l, r]` finds its parent by comparing the prefixes it shares with its
//! two neighbours. It merges with
//! the side whose neighbour shares the longer prefix: with the keys right of
//! `r` when `δ(r, r+1) > δ(l-1, l)` (it is then a left child, and the parent's
//! split is `r`), else with the keys left of `l` (a right child, split
//! `l - 1`). The two are never equal (see [`parent_side`]).
//!
//! At the split's slot the first child to arrive leaves the far end of its
//! range and stops; the second swaps in its own, so learns the sibling's
//! range, and so the parent's
//! ([`crate::construct::climb::second_arrival_exchange`]). This yields the binary radix tree of
//! Karras 2012 (`crate::construct::radix_tree`) *with its node numbering*: a left child
//! covering `[l, γ]` is node `γ`, a right child covering `[γ+1, r]` is node
//! `γ+1`, the root is node 0 and a one-key range is a leaf. So everything
//! after the build sees the same nodes, bit for bit, as after radix tree plus
//! fit, from one dispatch instead of two and with half the box reads of the
//! fit (the sibling's box only; the climber keeps its own).
use crate::construct::climb::second_arrival_exchange;
use crate::construct::fit::{load_box, store_box, write_leaf};
use crate::construct::radix_tree::{delta, leaf_node};
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{INVALID, Node};
use crate::geometry::split::SplitMut;

/// Whether the node covering `[l, r]` of `n` sorted keys is its parent's
/// left child (the parent's split is then `r`; else `l - 1`).
///
/// Why the two prefixes never tie: if `δ(l-1, l) = δ(r, r+1) = p`, keys
/// `l-1..=r+1` share `p` bits and differ in bit `p` across both borders, so
/// key `l` has a 1 there and key `r` a 0; but the node's keys share more
/// than `p` bits. (With the index tie-break the same holds for the
/// concatenation of key and index.)
#[inline]
pub fn parent_side(keys: &[u64], n: u32, l: u32, r: u32) -> bool {
    l == 0 || (r != n - 1 && delta(keys, n, r as i32, r as i32 + 1) > delta(keys, n, l as i32 - 1, l as i32))
}

/// Node index of the node covering `[l, r]`, given which child it is.
#[inline]
pub(crate) fn node_index(n: u32, l: u32, r: u32, left_child: bool) -> u32 {
    if l == r {
        leaf_node(n, l)
    } else if l == 0 && r == n - 1 {
        0
    } else if left_child {
        r
    } else {
        l
    }
}

/// Kernel: leaf `i` (sorted position) of `n`. `keys` are the sorted keys,
/// `sorted_prims[i]` the primitive of leaf `i`; `ends` holds one zeroed word
/// per split where the first child to arrive leaves its far end plus one.
/// `ORDERED`: the exchange releases this subtree's writes and acquires the
/// sibling's (relaxed for the one device that needs it, see
/// [`crate::gpu::atomics::add_device_acq_rel`]).
#[allow(clippy::too_many_arguments)]
pub fn agglomerate_kernel<const ORDERED: bool>(
    i: u32,
    n: u32,
    keys: &[u64],
    sorted_prims: &[u32],
    prim_boxes: &[Aabb],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    ends: &mut [u32],
) {
    if i >= n {
        return;
    }
    let own = write_leaf(i, n, sorted_prims, prim_boxes, nodes, parents);
    if n == 1 {
        return;
    }
    let left_child = parent_side(keys, n, i, i);
    climb_from::<ORDERED>(n, keys, nodes, parents, ends, i, i, leaf_node(n, i), own, left_child);
}

/// The climb of the invocation that holds the finished node `current`
/// covering `[l, r]` (not the root) with box `own`; `left_child` is
/// [`parent_side`] of it. Goes on while it arrives second at its parent's
/// split. The leaf's climb in [`agglomerate_kernel`], and the climb of the
/// nodes that `crate::construct::agglomerate_subgroup` could not finish
/// within their subgroup.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn climb_from<const ORDERED: bool>(
    n: u32,
    keys: &[u64],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    ends: &mut [u32],
    mut l: u32,
    mut r: u32,
    mut current: u32,
    mut own: Aabb,
    mut left_child: bool,
) {
    loop {
        let split = if left_child { r } else { l - 1 };
        let far = if left_child { l } else { r };
        // The arrival is the climb's (first stops, second goes on), but
        // at the split, whose node is not known yet, and it hands over the
        // first child's far end.
        let Some(other) = second_arrival_exchange::<ORDERED>(&mut ends[split as usize], far) else {
            return; // The sibling's invocation will finish the parent.
        };
        // The sibling covers the rest of the parent's range.
        let (lo, hi, sibling) = if left_child {
            (l, other, node_index(n, split + 1, other, false))
        } else {
            (other, r, node_index(n, other, split, true))
        };
        let sibling_box = nodes.with(sibling as usize, load_box);
        let (left, right) = if left_child { (current, sibling) } else { (sibling, current) };
        own = if left_child { own.union(&sibling_box) } else { sibling_box.union(&own) };
        let root = lo == 0 && hi == n - 1;
        left_child = !root && parent_side(keys, n, lo, hi);
        let parent = node_index(n, lo, hi, left_child);
        write_parent(nodes, parents, parent, left, right, &own, root);
        if root {
            return;
        }
        (l, r, current) = (lo, hi, parent);
    }
}

/// Writes internal node `parent` over children `left` and `right` with box
/// `b`, and the children's parent links (and the root's: none).
#[inline]
pub(crate) fn write_parent(
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    parent: u32,
    left: u32,
    right: u32,
    b: &Aabb,
    root: bool,
) {
    nodes.with_mut(parent as usize, |node| {
        node.left = left;
        node.right = right;
        store_box(node, b);
    });
    parents[left as usize] = parent;
    parents[right as usize] = parent;
    if root {
        parents[0] = INVALID;
    }
}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use super::*;
    use crate::construct::fit::fit_kernel;
    use crate::construct::radix_tree::radix_tree_kernel;
    use std::vec;
    use std::vec::Vec;

    /// Radix tree plus fit, and the agglomerative build, on the same keys.
    fn both(keys: &[u64]) -> [(Vec<Node>, Vec<u32>); 2] {
        let n = keys.len() as u32;
        let count = 2 * keys.len() - 1;
        let (boxes, prims) = leaves(n);
        let (mut nodes_a, mut parents_a) = (vec![Node::default(); count], vec![0u32; count]);
        let mut flags = vec![0u32; count];
        for i in 0..n {
            radix_tree_kernel(i, n, keys, &mut crate::geometry::split::thirds(&mut nodes_a), &mut parents_a);
        }
        for i in 0..n {
            fit_kernel::<true>(i, n, &prims, &boxes, &mut crate::geometry::split::thirds(&mut nodes_a), &mut parents_a, &mut flags);
        }
        let (mut nodes_b, mut parents_b) = (vec![Node::default(); count], vec![0u32; count]);
        let mut ends = vec![0u32; count];
        // Leaves in a scrambled order: the result must not depend on it.
        let order: Vec<u32> = {
            let mut o: Vec<u32> = (0..n).collect();
            o.sort_by_key(|&k| (k.wrapping_mul(2_654_435_761)) ^ 0x5bd1_e995);
            o
        };
        for &i in &order {
            agglomerate_kernel::<true>(i, n, keys, &prims, &boxes, &mut crate::geometry::split::thirds(&mut nodes_b), &mut parents_b, &mut ends);
        }
        [(nodes_a, parents_a), (nodes_b, parents_b)]
    }

    /// Boxes for `n` leaves in an order unrelated to the keys, some sharing
    /// faces, and the leaves' primitives (reversed).
    pub(crate) fn leaves(n: u32) -> (Vec<Aabb>, Vec<u32>) {
        let boxes = (0..n)
            .map(|k| {
                let x = ((k * 7919) % 97) as f32 * 0.5;
                Aabb::new(glam::Vec3::new(x, -x, (k % 5) as f32), glam::Vec3::new(x + 1.0, 3.0, (k % 5) as f32 + 2.0))
            })
            .collect();
        (boxes, (0..n).rev().collect())
    }

    /// Sorted random keys with many lengths of common prefix and some
    /// duplicates.
    pub(crate) fn random_keys(n: usize, x: &mut u64) -> Vec<u64> {
        let mut keys: Vec<u64> = (0..n)
            .map(|_| {
                *x ^= *x << 13;
                *x ^= *x >> 7;
                *x ^= *x << 17;
                *x >> (*x % 50)
            })
            .collect();
        keys.sort_unstable();
        keys
    }

    fn check(keys: &[u64]) {
        let [(na, pa), (nb, pb)] = both(keys);
        for k in 0..na.len() {
            assert_eq!(bytemuck::bytes_of(&na[k]), bytemuck::bytes_of(&nb[k]), "keys {keys:?}: node {k}");
        }
        assert_eq!(pa, pb, "keys {keys:?}: parents");
    }

    #[test]
    fn same_tree_as_radix_tree_and_fit() {
        for n in 1..70u64 {
            check(&vec![7u64; n as usize]);
            check(&(0..n).map(|k| k / 3).collect::<Vec<_>>());
            check(&(0..n).map(|k| k * k).collect::<Vec<_>>());
            check(&(0..n).map(|k| k.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 1).collect::<Vec<_>>().tap_sort());
        }
        let mut x = 0x1234_5678_9abc_def0u64;
        for n in [200usize, 1000, 4097] {
            check(&random_keys(n, &mut x));
        }
    }

    trait TapSort {
        fn tap_sort(self) -> Self;
    }
    impl TapSort for Vec<u64> {
        fn tap_sort(mut self) -> Self {
            self.sort_unstable();
            self
        }
    }
}
