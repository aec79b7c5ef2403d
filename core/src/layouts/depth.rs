//! The depth of a tree, on the device: what the traversal stack must hold
//! ([`crate::trace::hit::STACK_DEPTH`]). The host refuses deeper trees;
//! reading the whole tree back to walk it cost an engine's refit of 1M
//! triangles about 40 ms of wall time on the H100, where this kernel
//! returns one word.
use crate::geometry::buffers::Node;
use crate::geometry::records::RecordLoad;
use crate::gpu::atomics;

/// Longest climb [`leaf_depth_kernel`] makes: one more level than the
/// traversal stack holds (`crate::trace::hit::STACK_DEPTH`, which asserts
/// it), so that a tree too deep for it is found, and any
/// deeper leaf counts as this deep. It bounds the kernel's work by the leaf
/// count times this (a chain of a million nodes would otherwise climb a
/// million steps from each leaf), and a damaged parent chain cannot loop.
pub const DEPTH_LIMIT: u32 = 65;

/// Kernel, one invocation per node `i` of a tree of `node_count` nodes
/// (root 0, `parents` its parent links): a leaf climbs to the root and
/// raises `deepest[0]` (zeroed) to its depth (the root's is 0), or to
/// [`DEPTH_LIMIT`] if it is deeper.
pub fn leaf_depth_kernel<N: RecordLoad<Node> + ?Sized>(
    i: u32,
    node_count: u32,
    nodes: &N,
    parents: &[u32],
    deepest: &mut [u32],
) {
    if i >= node_count || !nodes.load(i as usize).is_leaf() {
        return;
    }
    let (mut x, mut depth) = (i, 0u32);
    while x != 0 && depth < DEPTH_LIMIT {
        x = parents[x as usize];
        depth += 1;
    }
    atomics::max_device(&mut deepest[0], depth);
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::geometry::buffers::LEAF_BIT;
    use std::vec;
    use std::vec::Vec;

    /// A tree from its internal nodes' children; parents derived.
    fn tree(children: &[(u32, u32)], count: usize) -> (Vec<Node>, Vec<u32>) {
        let mut nodes = vec![Node::default(); count];
        let mut parents = vec![u32::MAX; count];
        for (i, &(l, r)) in children.iter().enumerate() {
            nodes[i].left = l;
            nodes[i].right = r;
            parents[l as usize] = i as u32;
            parents[r as usize] = i as u32;
        }
        for n in nodes.iter_mut().skip(children.len()) {
            n.right = LEAF_BIT | 1;
        }
        (nodes, parents)
    }

    fn depth(nodes: &[Node], parents: &[u32]) -> u32 {
        let mut deepest = [0u32];
        for i in 0..nodes.len() as u32 {
            leaf_depth_kernel(i, nodes.len() as u32, nodes, parents, &mut deepest);
        }
        deepest[0]
    }

    #[test]
    fn chains_and_balanced_trees() {
        // A chain: internal node k has children k + 1 and a leaf; 70 deep,
        // counted as the limit; 40 deep, counted.
        for k in [70u32, 40] {
            let count = 2 * k as usize + 1;
            let children: Vec<(u32, u32)> = (0..k).map(|i| (if i + 1 < k { i + 1 } else { k }, k + 1 + i)).collect();
            let (nodes, parents) = tree(&children, count);
            assert_eq!(depth(&nodes, &parents), k.min(DEPTH_LIMIT));
        }
        // Balanced over 8 leaves: 3 deep.
        let children = [(1, 2), (3, 4), (5, 6), (7, 8), (9, 10), (11, 12), (13, 14)];
        let (nodes, parents) = tree(&children, 15);
        assert_eq!(depth(&nodes, &parents), 3);
        // One leaf: 0 deep.
        let (nodes, parents) = tree(&[], 1);
        assert_eq!(depth(&nodes, &parents), 0);
    }

    #[test]
    fn a_looping_parent_chain_stops_at_the_limit() {
        let (mut nodes, mut parents) = tree(&[(1, 2)], 3);
        parents[1] = 1;
        nodes[0].left = 1;
        assert_eq!(depth(&nodes, &parents), DEPTH_LIMIT);
    }
}
