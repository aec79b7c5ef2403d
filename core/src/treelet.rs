//! Treelet restructuring: T. Karras and T. Aila, "Fast Parallel Construction
//! of High-Quality Bounding Volume Hierarchies", HPG 2013, section 4 and
//! algorithms 2 and 3.
//!
//! A *treelet* is the root node plus up to six of its descendants, formed by
//! repeatedly expanding the treelet leaf with the largest surface area;
//! its (up to seven) leaves are subtrees that stay intact. A dynamic program
//! over all 127 non-empty subsets of the leaves finds the binary tree over
//! them with the lowest SAH cost, and the treelet's internal nodes are
//! rewired into it:
//!
//! ```text
//!          R                 R             subsets of {a,b,c,d}, bitmask:
//!         / \               / \            area[s]  = area of the union of s
//!        x   d     =>      x'  y'          cost[s]  = C_i area[s]
//!       / \               / \  / \                    + min over partitions
//!      y   c             a  c b   d                     (p, s^p) of cost[p] + cost[s^p]
//!     / \                                  cost[{leaf}] = the leaf subtree's SAH cost
//!    a   b
//! ```
//!
//! Costs here are unnormalized SAH (`C_i·A` per internal node, `C_t·A·N` per
//! leaf); areas are half surface areas of boxes scaled by the caller's
//! `inv_extent`, so scenes near the f32 range do not overflow. As in the
//! paper, a subtree of at most `max_leaf` primitives costs the cheaper of its
//! tree and one leaf holding all its primitives (`C_t·A·N`): the DP and the
//! rounds optimize for the tree that [`crate::collapse`] finally produces.
//! Treelet departs from the paper in one way so far: the DP here runs in one
//! invocation per treelet (the paper's warp-wide version is the speed target).
use crate::aabb::Aabb;
use crate::atomics;
use crate::fit::second_arrival;
use crate::layout::{Node, TreeletParams};

/// Leaves of a treelet (the paper's 7).
pub const TREELET_LEAVES: usize = 7;
/// Internal nodes of a full treelet, its root included.
pub const TREELET_INTERNALS: usize = TREELET_LEAVES - 1;
/// Subsets of the leaves, the empty set included.
pub const SUBSETS: usize = 1 << TREELET_LEAVES;

/// SAH constants and the area scale.
#[derive(Clone, Copy, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct TreeletCosts {
    /// Cost of an internal node per unit area (`C_i`, 1.2 in the paper).
    pub node: f32,
    /// Cost of a primitive per unit area (`C_t`, 1.0 in the paper).
    pub prim: f32,
    /// Boxes are scaled by this before taking areas (1 / the scene's extent).
    pub inv_extent: f32,
    /// Largest leaf a subtree may collapse into (1: never collapse).
    pub max_leaf: u32,
}

impl TreeletParams {
    /// The cost constants of these parameters.
    #[inline]
    pub fn costs(&self) -> TreeletCosts {
        TreeletCosts {
            node: self.node_cost,
            prim: self.prim_cost,
            inv_extent: self.inv_extent,
            max_leaf: self.max_leaf,
        }
    }
}

impl TreeletCosts {
    /// Half surface area of `b` after scaling by `inv_extent`.
    #[inline]
    pub fn area(&self, b: &Aabb) -> f32 {
        if b.is_empty() {
            return 0.0;
        }
        let e = b.extent() * self.inv_extent;
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// SAH cost of a subtree of `count` primitives whose root has area
    /// `area` and whose children cost `children` together: the cheaper of
    /// an internal node and, when `count <= max_leaf`, one leaf.
    #[inline]
    pub fn subtree(&self, area: f32, count: u32, children: f32) -> f32 {
        let internal = self.node * area + children;
        if count <= self.max_leaf {
            let leaf = self.prim * area * count as f32;
            if leaf <= internal {
                return leaf;
            }
        }
        internal
    }

    /// Whether a subtree collapses into one leaf (the choice of [`Self::subtree`]).
    #[inline]
    pub fn collapses(&self, area: f32, count: u32, children: f32) -> bool {
        count <= self.max_leaf && self.prim * area * count as f32 <= self.node * area + children
    }
}

/// A treelet: its root, its leaves and its internal nodes (root first).
#[derive(Clone, Copy)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Treelet {
    pub leaves: [u32; TREELET_LEAVES],
    pub leaf_count: u32,
    pub internals: [u32; TREELET_INTERNALS],
}

/// Forms the treelet under internal node `root` (algorithm 2's first loop):
/// expand, among the current leaves that are internal BVH nodes, the one of
/// largest area, until seven leaves or no expandable leaf remain.
#[inline]
pub fn form_treelet(root: u32, nodes: &[Node], costs: &TreeletCosts) -> Treelet {
    let r = nodes[root as usize];
    let mut t = Treelet { leaves: [0; TREELET_LEAVES], leaf_count: 2, internals: [0; TREELET_INTERNALS] };
    t.internals[0] = root;
    t.leaves[0] = r.left;
    t.leaves[1] = r.right;
    let mut internal_count = 1usize;
    while (t.leaf_count as usize) < TREELET_LEAVES {
        let mut best = usize::MAX;
        let mut best_area = -1.0f32;
        let mut i = 0;
        while i < t.leaf_count as usize {
            let n = nodes[t.leaves[i] as usize];
            if !n.is_leaf() {
                let a = costs.area(&n.aabb());
                if a > best_area {
                    best_area = a;
                    best = i;
                }
            }
            i += 1;
        }
        if best == usize::MAX {
            break;
        }
        let expanded = t.leaves[best];
        let n = nodes[expanded as usize];
        t.internals[internal_count] = expanded;
        internal_count += 1;
        t.leaves[best] = n.left;
        t.leaves[t.leaf_count as usize] = n.right;
        t.leaf_count += 1;
    }
    t
}

/// The optimal tree over a treelet's leaves: `partition[s]` is the subset of
/// `s` that forms one child of the node covering `s` (the other is `s ^ p`).
pub struct TreeletSolution {
    pub partition: [u32; SUBSETS],
    pub area: [f32; SUBSETS],
    pub cost: [f32; SUBSETS],
}

/// Algorithm 2's dynamic program over the subsets of `n` leaves with boxes
/// `boxes`, subtree costs `leaf_costs` and primitive counts `leaf_counts`.
#[inline]
pub fn optimize(
    n: u32,
    boxes: &[Aabb; TREELET_LEAVES],
    leaf_costs: &[f32; TREELET_LEAVES],
    leaf_counts: &[u32; TREELET_LEAVES],
    costs: &TreeletCosts,
) -> TreeletSolution {
    let mut sol = TreeletSolution { partition: [0u32; SUBSETS], area: [0.0; SUBSETS], cost: [0.0; SUBSETS] };
    let full = (1u32 << n) - 1;
    // Areas of every subset's union.
    let mut s = 1u32;
    while s <= full {
        let mut b = Aabb::EMPTY;
        let mut i = 0;
        while i < n {
            if s & (1 << i) != 0 {
                b = b.union(&boxes[i as usize]);
            }
            i += 1;
        }
        sol.area[s as usize] = costs.area(&b);
        s += 1;
    }
    // Primitive counts of every subset, built from the subset minus its lowest leaf.
    let mut count = [0u32; SUBSETS];
    let mut s = 1u32;
    while s <= full {
        let low = s.trailing_zeros();
        count[s as usize] = count[(s & (s - 1)) as usize] + leaf_counts[low as usize];
        s += 1;
    }
    // Leaves: their subtrees' costs.
    let mut i = 0;
    while i < n {
        sol.cost[1 << i] = leaf_costs[i as usize];
        i += 1;
    }
    // Subsets by increasing size, so that every part is solved before.
    let mut size = 2;
    while size <= n {
        let mut s = 1u32;
        while s <= full {
            if s.count_ones() == size {
                // Algorithm 3: partitions (p, s^p) with p inside s minus its
                // lowest bit, each unordered pair once.
                let delta = (s - 1) & s;
                let mut p = delta.wrapping_neg() & s;
                let mut best = f32::MAX;
                let mut best_p = 0u32;
                loop {
                    let c = sol.cost[p as usize] + sol.cost[(s ^ p) as usize];
                    if c < best {
                        best = c;
                        best_p = p;
                    }
                    p = p.wrapping_sub(delta) & s;
                    if p == 0 {
                        break;
                    }
                }
                sol.cost[s as usize] = costs.subtree(sol.area[s as usize], count[s as usize], best);
                sol.partition[s as usize] = best_p;
            }
            s += 1;
        }
        size += 1;
    }
    sol
}

/// Rewires the treelet's internal nodes into the optimal tree (children and
/// parent links only; boxes and costs are the caller's to refit). The root
/// keeps its index; the other internal nodes are reused in order.
#[inline]
pub fn apply(t: &Treelet, sol: &TreeletSolution, nodes: &mut [Node], parents: &mut [u32]) {
    let n = t.leaf_count;
    let full = (1u32 << n) - 1;
    // Stack of (subset, node index), depth at most the number of internals.
    let mut stack_s = [0u32; TREELET_INTERNALS];
    let mut stack_n = [0u32; TREELET_INTERNALS];
    let mut top = 1usize;
    stack_s[0] = full;
    stack_n[0] = t.internals[0];
    let mut next_internal = 1usize;
    while top > 0 {
        top -= 1;
        let s = stack_s[top];
        let node = stack_n[top];
        let p = sol.partition[s as usize];
        let mut side = 0;
        while side < 2 {
            let part = if side == 0 { p } else { s ^ p };
            let child = if part.count_ones() == 1 {
                t.leaves[part.trailing_zeros() as usize]
            } else {
                let c = t.internals[next_internal];
                next_internal += 1;
                stack_s[top] = part;
                stack_n[top] = c;
                top += 1;
                c
            };
            if side == 0 {
                nodes[node as usize].left = child;
            } else {
                nodes[node as usize].right = child;
            }
            parents[child as usize] = node;
            side += 1;
        }
    }
}

/// SAH cost of the subtree under `node` with `count` primitives, given its
/// children's costs (for a leaf: its primitives'), collapse included.
#[inline]
pub fn node_cost(node: &Node, count: u32, child_costs: (f32, f32), costs: &TreeletCosts) -> f32 {
    let area = costs.area(&node.aabb());
    if node.is_leaf() {
        costs.prim * area * node.prim_count() as f32
    } else {
        costs.subtree(area, count, child_costs.0 + child_costs.1)
    }
}

/// Restructures the treelet rooted at internal node `root` in place:
/// forms it, solves the DP, rewires it if that lowers its cost, and refits
/// the boxes and costs of its internal nodes. `node_costs` holds every
/// node's subtree cost (as [`node_cost`] defines it) and `counts` its
/// primitive count. Returns whether the treelet changed.
#[inline]
pub fn restructure(
    root: u32,
    nodes: &mut [Node],
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    costs: &TreeletCosts,
) -> bool {
    let t = form_treelet(root, nodes, costs);
    if t.leaf_count < 3 {
        return false; // two leaves: only one tree
    }
    let mut boxes = [Aabb::EMPTY; TREELET_LEAVES];
    let mut leaf_costs = [0.0f32; TREELET_LEAVES];
    let mut leaf_counts = [0u32; TREELET_LEAVES];
    let mut i = 0;
    while i < t.leaf_count as usize {
        boxes[i] = nodes[t.leaves[i] as usize].aabb();
        leaf_costs[i] = node_costs[t.leaves[i] as usize];
        leaf_counts[i] = counts[t.leaves[i] as usize];
        i += 1;
    }
    let sol = optimize(t.leaf_count, &boxes, &leaf_costs, &leaf_counts, costs);
    let full = (1usize << t.leaf_count) - 1;
    // The current topology is one of the candidates: keep it unless the
    // optimum is strictly cheaper (avoids churn on ties and rounding).
    if sol.cost[full] >= node_costs[root as usize] * (1.0 - 1e-6) {
        return false;
    }
    apply(&t, &sol, nodes, parents);
    // Children are assigned after their parents, so refit in reverse.
    let internal_count = t.leaf_count as usize - 1;
    let mut k = internal_count;
    while k > 0 {
        k -= 1;
        let id = t.internals[k] as usize;
        let (l, r) = (nodes[id].left as usize, nodes[id].right as usize);
        let b = nodes[l].aabb().union(&nodes[r].aabb());
        nodes[id].set_aabb(b);
        counts[id] = counts[l] + counts[r];
        node_costs[id] = node_cost(&nodes[id], counts[id], (node_costs[l], node_costs[r]), costs);
    }
    true
}

/// Kernel (one invocation per leaf, climbing like [`crate::fit`]): writes
/// every node's primitive count, subtree SAH cost and height (leaves 0), and
/// its number of leaves after the final collapse (1 where it collapses), an
/// internal node once both children are done. `flags` are zeroed counters.
#[allow(clippy::too_many_arguments)]
pub fn treelet_init_kernel<const ORDERED: bool>(
    i: u32,
    params: &TreeletParams,
    nodes: &[Node],
    parents: &[u32],
    flags: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &mut [u32],
    tree_leaves: &mut [u32],
) {
    let n = params.n;
    if i >= n {
        return;
    }
    let costs = params.costs();
    // Leaves are found through the tree, not by index: restructuring moves
    // internal nodes but never leaves, and leaf `i` stays at `n - 1 + i`.
    let leaf = n - 1 + i;
    let node = nodes[leaf as usize];
    atomics::store_u32(&mut counts[leaf as usize], node.prim_count());
    atomics::store_f32(&mut node_costs[leaf as usize], node_cost(&node, node.prim_count(), (0.0, 0.0), &costs));
    atomics::store_u32(&mut heights[leaf as usize], 0);
    atomics::store_u32(&mut tree_leaves[leaf as usize], 1);
    let mut current = leaf;
    while current != 0 {
        let parent = parents[current as usize];
        if !second_arrival::<ORDERED>(&mut flags[parent as usize]) {
            return;
        }
        let p = nodes[parent as usize];
        let (l, r) = (p.left as usize, p.right as usize);
        let count = atomics::load_u32(&counts[l]) + atomics::load_u32(&counts[r]);
        let children = atomics::load_f32(&node_costs[l]) + atomics::load_f32(&node_costs[r]);
        let area = costs.area(&p.aabb());
        let height = 1 + atomics::load_u32(&heights[l]).max(atomics::load_u32(&heights[r]));
        let leaves = if costs.collapses(area, count, children) {
            1
        } else {
            atomics::load_u32(&tree_leaves[l]) + atomics::load_u32(&tree_leaves[r])
        };
        atomics::store_u32(&mut counts[parent as usize], count);
        atomics::store_f32(&mut node_costs[parent as usize], costs.subtree(area, count, children));
        atomics::store_u32(&mut heights[parent as usize], height);
        atomics::store_u32(&mut tree_leaves[parent as usize], leaves);
        current = parent;
    }
}

/// Kernel (one invocation per internal node): restructures the treelet of
/// node `i` when `i` has height `params.level` and at least `params.gamma`
/// primitives. Nodes of one height never contain each other, so their
/// treelets are disjoint; levels run as separate dispatches, bottom up.
pub fn treelet_level_kernel(
    i: u32,
    params: &TreeletParams,
    nodes: &mut [Node],
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &[u32],
) {
    if params.n < 2 || i >= params.n - 1 {
        return;
    }
    if heights[i as usize] == params.level && counts[i as usize] >= params.gamma {
        restructure(i, nodes, parents, counts, node_costs, &params.costs());
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use glam::Vec3;
    use std::vec::Vec;

    const COSTS: TreeletCosts = TreeletCosts { node: 1.2, prim: 1.0, inv_extent: 0.01, max_leaf: 1 };

    /// A treelet's leaves for the brute force: boxes, subtree costs, counts.
    struct Leaves {
        boxes: [Aabb; TREELET_LEAVES],
        costs: [f32; TREELET_LEAVES],
        counts: [u32; TREELET_LEAVES],
    }

    /// The best cost over every binary tree on the leaves in `set`, each
    /// subtree of at most `max_leaf` primitives also tried as one leaf; by
    /// brute force over all ordered splits, with areas from the boxes.
    fn brute_force(set: u32, leaves: &Leaves, costs: &TreeletCosts) -> f32 {
        if set.count_ones() == 1 {
            return leaves.costs[set.trailing_zeros() as usize];
        }
        let members = || (0..TREELET_LEAVES).filter(|&i| set & (1 << i) != 0);
        let area = costs.area(&members().fold(Aabb::EMPTY, |b, i| b.union(&leaves.boxes[i])));
        let count: u32 = members().map(|i| leaves.counts[i]).sum();
        let mut best = f32::MAX;
        let mut p = (set - 1) & set;
        while p != 0 {
            best = best.min(brute_force(p, leaves, costs) + brute_force(set ^ p, leaves, costs));
            p = (p - 1) & set;
        }
        let tree = costs.node * area + best;
        if count <= costs.max_leaf {
            tree.min(costs.prim * area * count as f32)
        } else {
            tree
        }
    }

    fn random_leaves(seed: u32, n: u32) -> Leaves {
        let mut l = Leaves { boxes: [Aabb::EMPTY; TREELET_LEAVES], costs: [0.0; TREELET_LEAVES], counts: [0; 7] };
        for i in 0..n as usize {
            let r = crate::rng::BounceRng::new(seed, i as u32, 0, 0);
            let lo = Vec3::new(r.uniform(0), r.uniform(1), r.uniform(2)) * 100.0;
            let size = Vec3::new(r.uniform(3), r.uniform(4), r.uniform(5)) * 30.0;
            l.boxes[i] = Aabb::new(lo, lo + size);
            l.counts[i] = 1 + (r.uniform(7) * 3.0) as u32;
            l.costs[i] = COSTS.area(&l.boxes[i]) * (1.0 + 3.0 * r.uniform(6));
        }
        l
    }

    #[test]
    fn dp_equals_brute_force() {
        for max_leaf in [1, 4, 8, 64] {
            let costs = TreeletCosts { max_leaf, ..COSTS };
            for n in 2..=TREELET_LEAVES as u32 {
                for seed in 0..20 {
                    let l = random_leaves(seed * 31 + n, n);
                    let sol = optimize(n, &l.boxes, &l.costs, &l.counts, &costs);
                    let full = (1u32 << n) - 1;
                    let expected = brute_force(full, &l, &costs);
                    let got = sol.cost[full as usize];
                    assert!(
                        (got - expected).abs() <= 1e-5 * expected,
                        "max_leaf {max_leaf} n {n} seed {seed}: dp {got} brute {expected}"
                    );
                }
            }
        }
    }

    #[test]
    fn partitions_are_enumerated_once_each() {
        for s in 3u32..128 {
            if s.count_ones() < 2 {
                continue;
            }
            let delta = (s - 1) & s;
            let mut p = delta.wrapping_neg() & s;
            let mut seen = Vec::new();
            loop {
                assert!(p != 0 && p != s && p & s == p, "s {s:#b} p {p:#b}");
                seen.push(p.min(s ^ p));
                p = p.wrapping_sub(delta) & s;
                if p == 0 {
                    break;
                }
            }
            let mut unique = seen.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), seen.len(), "a partition of {s:#b} came twice");
            assert_eq!(seen.len(), (1usize << (s.count_ones() - 1)) - 1, "s {s:#b}");
        }
    }
}
