//! The binary radix tree over sorted Morton keys, one internal node per
//! invocation: T. Karras, "Maximizing Parallelism in the Construction of
//! BVHs, Octrees, and k-d Trees", HPG 2012, section 3 and figure 4.
//!
//! Internal node `i` covers a range of sorted keys with one end at `i`:
//!
//! ```text
//!   keys:  0   1   2   3   4   5   6   7        node 3, d = -1:
//!                      [-----------]            range [0,3] or [3,7]?
//!          δ(3,2) < δ(3,4)  =>  d = +1, range grows right from 3
//!          j = far end (exponential then binary search on δ > δmin)
//!          γ = split: last index sharing more than δ(i,j) prefix bits
//!          left child covers [min(i,j), γ], right child [γ+1, max(i,j)];
//!          a one-key range is a leaf.
//! ```
//!
//! `δ(i, j)` is the length of the common prefix of keys `i` and `j`, and -1
//! outside `0..n`. Duplicate keys (as the paper says) compare their indices
//! instead: `δ = 64 + clz(i ^ j)`, so identical keys still give a valid tree.
use crate::geometry::buffers::{INVALID, Node};
use crate::geometry::split::SplitMut;

/// Leading zeros of a u64 from two 32-bit counts: rust-gpu's 64-bit
/// `leading_zeros` gave wrong results on lavapipe when the high word is set.
#[inline]
pub fn clz64(x: u64) -> u32 {
    let hi = (x >> 32) as u32;
    if hi != 0 {
        hi.leading_zeros()
    } else {
        32 + (x as u32).leading_zeros()
    }
}

/// δ(i, j): common prefix length of sorted keys i and j, with the key index
/// as tie-break; -1 when j is out of range.
#[inline]
pub fn delta(keys: &[u64], n: u32, i: i32, j: i32) -> i32 {
    if j < 0 || j >= n as i32 {
        return -1;
    }
    let a = keys[i as usize];
    let b = keys[j as usize];
    if a != b {
        clz64(a ^ b) as i32
    } else {
        64 + (i as u32 ^ j as u32).leading_zeros() as i32
    }
}

/// Node index of leaf `j`.
#[inline]
pub fn leaf_node(n: u32, j: u32) -> u32 {
    n - 1 + j
}

/// The children `(left, right)` of internal node `i` (node indices).
pub fn children(keys: &[u64], n: u32, i: u32) -> (u32, u32) {
    let i = i as i32;
    // Direction of the range.
    let d: i32 = if delta(keys, n, i, i + 1) > delta(keys, n, i, i - 1) { 1 } else { -1 };
    // Upper bound of the range length, then the exact far end by binary search.
    let delta_min = delta(keys, n, i, i - d);
    let mut l_max: i32 = 2;
    while delta(keys, n, i, i + l_max * d) > delta_min {
        l_max *= 2;
    }
    let mut l: i32 = 0;
    let mut t = l_max / 2;
    while t >= 1 {
        if delta(keys, n, i, i + (l + t) * d) > delta_min {
            l += t;
        }
        t /= 2;
    }
    let j = i + l * d;
    // Split position: binary search on the node's own prefix length.
    let delta_node = delta(keys, n, i, j);
    let mut s: i32 = 0;
    let mut div: i32 = 2;
    loop {
        let t = (l + div - 1) / div;
        if delta(keys, n, i, i + (s + t) * d) > delta_node {
            s += t;
        }
        if t <= 1 {
            break;
        }
        div *= 2;
    }
    let gamma = i + s * d + if d < 0 { -1 } else { 0 };
    let (lo, hi) = if i < j { (i, j) } else { (j, i) };
    let left = if lo == gamma { leaf_node(n, gamma as u32) } else { gamma as u32 };
    let right = if hi == gamma + 1 { leaf_node(n, gamma as u32 + 1) } else { gamma as u32 + 1 };
    (left, right)
}

/// Kernel: writes internal node `i`'s children and their parent links.
/// Boxes are left for [`crate::construct::fit`].
pub fn radix_tree_kernel(i: u32, n: u32, keys: &[u64], nodes: &mut SplitMut<Node>, parents: &mut [u32]) {
    if n < 2 || i >= n - 1 {
        return;
    }
    let (left, right) = children(keys, n, i);
    nodes.with_mut(i as usize, |node| {
        node.left = left;
        node.right = right;
    });
    parents[left as usize] = i;
    parents[right as usize] = i;
    if i == 0 {
        parents[0] = INVALID;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec;
    use std::vec::Vec;

    /// Checks that the children of all internal nodes form one binary tree
    /// over all leaves (each node reached once from the root).
    fn check_tree(keys: &[u64]) {
        let n = keys.len() as u32;
        let mut seen = vec![0u32; 2 * n as usize - 1];
        let mut stack = vec![0u32];
        while let Some(node) = stack.pop() {
            seen[node as usize] += 1;
            if node < n - 1 {
                let (l, r) = children(keys, n, node);
                stack.push(l);
                stack.push(r);
            }
        }
        assert!(seen.iter().all(|&c| c == 1), "keys {keys:?}: visits {seen:?}");
    }

    #[test]
    fn clz64_matches_leading_zeros() {
        for x in [0u64, 1, 0xffff_ffff, 1 << 32, 0x7fff_ffff_ffff_ffff, u64::MAX, 0x36db_6db6_db6d_b6db] {
            assert_eq!(clz64(x), x.leading_zeros(), "{x:#x}");
        }
    }

    #[test]
    fn paper_figure_example() {
        // The eight 5-bit keys of Karras 2012, figure 3.
        let keys: Vec<u64> =
            [0b00001, 0b00010, 0b00100, 0b00101, 0b10011, 0b11000, 0b11001, 0b11110].iter().map(|&k| k << 59).collect();
        let n = 8;
        assert_eq!(children(&keys, n, 0), (3, 4));
        assert_eq!(children(&keys, n, 1), (leaf_node(n, 0), leaf_node(n, 1)));
        assert_eq!(children(&keys, n, 3), (1, 2));
        assert_eq!(children(&keys, n, 4), (leaf_node(n, 4), 5));
        check_tree(&keys);
    }

    #[test]
    fn duplicates_and_small_sizes_give_trees() {
        for n in 2..40u64 {
            check_tree(&vec![7u64; n as usize]);
            check_tree(&(0..n).map(|k| k / 3).collect::<Vec<_>>());
            check_tree(&(0..n).map(|k| k * k).collect::<Vec<_>>());
        }
    }
}
