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
//! On the device, [`treelet_solve_phase`] spreads the DP of each treelet over
//! 32 lanes as the paper does, between [`treelet_form_kernel`] and
//! [`treelet_commit_kernel`]; [`restructure`] is the same steps in one
//! invocation (the CPU reference and tests).
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
        // Explicit fused multiply-adds: a GPU compiler may fuse `a * b + c`
        // on its own, the CPU does not, and the tree must not depend on it.
        libm::fmaf(e.x, e.y, libm::fmaf(e.y, e.z, e.z * e.x))
    }

    /// SAH cost of a subtree of `count` primitives whose root has area
    /// `area` and whose children cost `children` together: the cheaper of
    /// an internal node and, when `count <= max_leaf`, one leaf.
    #[inline]
    pub fn subtree(&self, area: f32, count: u32, children: f32) -> f32 {
        let internal = libm::fmaf(self.node, area, children);
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
        count <= self.max_leaf && self.prim * area * count as f32 <= libm::fmaf(self.node, area, children)
    }
}

/// A treelet: its leaves (with their boxes, primitive counts and subtree
/// costs, read once while forming it) and its internal nodes (root first).
#[derive(Clone, Copy)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Treelet {
    pub leaves: [u32; TREELET_LEAVES],
    pub leaf_count: u32,
    pub internals: [u32; TREELET_INTERNALS],
    pub boxes: [Aabb; TREELET_LEAVES],
    pub counts: [u32; TREELET_LEAVES],
    pub costs: [f32; TREELET_LEAVES],
}

/// Forms the treelet under internal node `root` (algorithm 2's first loop):
/// expand, among the current leaves that are internal BVH nodes, the one of
/// largest area (the first on ties), until seven leaves or no expandable
/// leaf remain. Each node is read once: an expansion loads only the two new
/// children, so the chain of dependent loads is one per expansion.
#[inline]
pub fn form_treelet(
    root: u32,
    nodes: &[Node],
    counts: &[u32],
    node_costs: &[f32],
    costs: &TreeletCosts,
) -> Treelet {
    let mut t = Treelet {
        leaves: [0; TREELET_LEAVES],
        leaf_count: 2,
        internals: [0; TREELET_INTERNALS],
        boxes: [Aabb::EMPTY; TREELET_LEAVES],
        counts: [0; TREELET_LEAVES],
        costs: [0.0; TREELET_LEAVES],
    };
    // Per treelet leaf: its children (if internal) and area (-1 if a BVH leaf).
    let mut lefts = [0u32; TREELET_LEAVES];
    let mut rights = [0u32; TREELET_LEAVES];
    let mut areas = [0.0f32; TREELET_LEAVES];
    t.internals[0] = root;
    let r = nodes[root as usize];
    let (first, second) = (r.left, r.right);
    let mut internal_count = 1usize;
    // Slot `best` takes the left child, a new slot the right one.
    let mut best = 0usize;
    let mut children = [first, second];
    loop {
        let mut side = 0;
        while side < 2 {
            let slot = if side == 0 { best } else { t.leaf_count as usize - 1 };
            let id = children[side];
            let node = nodes[id as usize];
            t.leaves[slot] = id;
            t.boxes[slot] = node.aabb();
            lefts[slot] = node.left;
            rights[slot] = node.right;
            areas[slot] = if node.is_leaf() { -1.0 } else { costs.area(&t.boxes[slot]) };
            side += 1;
        }
        if t.leaf_count as usize == TREELET_LEAVES {
            break;
        }
        best = usize::MAX;
        let mut best_area = -1.0f32;
        let mut i = 0;
        while i < t.leaf_count as usize {
            if areas[i] > best_area {
                best_area = areas[i];
                best = i;
            }
            i += 1;
        }
        if best == usize::MAX {
            break;
        }
        t.internals[internal_count] = t.leaves[best];
        internal_count += 1;
        children = [lefts[best], rights[best]];
        t.leaf_count += 1;
    }
    let mut i = 0;
    while i < t.leaf_count as usize {
        t.counts[i] = counts[t.leaves[i] as usize];
        t.costs[i] = node_costs[t.leaves[i] as usize];
        i += 1;
    }
    t
}

/// The optimal tree over a treelet's leaves: `partition[s]` is the subset of
/// `s` that forms one child of the node covering `s` (the other is `s ^ p`),
/// `cost[s]` the cost of that best subtree.
pub struct TreeletSolution {
    pub partition: [u32; SUBSETS],
    pub cost: [f32; SUBSETS],
}

/// Union of the boxes of the leaves in subset `s` (exact: min and max).
#[inline]
pub fn subset_box(s: u32, n: u32, boxes: &[Aabb; TREELET_LEAVES]) -> Aabb {
    let mut b = Aabb::EMPTY;
    let mut i = 0;
    while i < n {
        if s & (1 << i) != 0 {
            b = b.union(&boxes[i as usize]);
        }
        i += 1;
    }
    b
}

/// Scaled area of the union of the leaves in subset `s`.
#[inline]
pub fn subset_area(s: u32, n: u32, boxes: &[Aabb; TREELET_LEAVES], costs: &TreeletCosts) -> f32 {
    costs.area(&subset_box(s, n, boxes))
}

/// Primitives under the leaves in subset `s`.
#[inline]
pub fn subset_count(s: u32, n: u32, leaf_counts: &[u32; TREELET_LEAVES]) -> u32 {
    let mut c = 0;
    let mut i = 0;
    while i < n {
        if s & (1 << i) != 0 {
            c += leaf_counts[i as usize];
        }
        i += 1;
    }
    c
}

/// One step of the DP: the best partition of subset `s` (of at least two
/// leaves) from the solved costs of its parts. Tables are rows of
/// [`SUBSETS`] entries starting at `base` (several treelets share one table
/// in the wide kernel).
///
/// Algorithm 3: partitions `(p, s ^ p)` with `p` inside `s` minus its lowest
/// bit, each unordered pair once.
#[inline]
pub fn solve_subset<const N: usize>(
    s: u32,
    base: usize,
    area: f32,
    count: u32,
    cost: &mut [f32; N],
    partition: &mut [u32; N],
    costs: &TreeletCosts,
) {
    let delta = (s - 1) & s;
    let mut p = delta.wrapping_neg() & s;
    let mut best = f32::MAX;
    let mut best_p = 0u32;
    loop {
        let c = cost[base + p as usize] + cost[base + (s ^ p) as usize];
        if c < best {
            best = c;
            best_p = p;
        }
        p = p.wrapping_sub(delta) & s;
        if p == 0 {
            break;
        }
    }
    cost[base + s as usize] = costs.subtree(area, count, best);
    partition[base + s as usize] = best_p;
}

/// Algorithm 2's dynamic program over the subsets of the leaves of `t`, in
/// one invocation (the wide kernel spreads the same steps over a team).
#[inline]
pub fn optimize(t: &Treelet, costs: &TreeletCosts) -> TreeletSolution {
    let n = t.leaf_count;
    let mut sol = TreeletSolution { partition: [0u32; SUBSETS], cost: [0.0; SUBSETS] };
    let full = (1u32 << n) - 1;
    let mut i = 0;
    while i < n {
        sol.cost[1 << i] = t.costs[i as usize];
        i += 1;
    }
    // Subsets by increasing size, so that every part is solved before.
    let mut size = 2;
    while size <= n {
        let mut s = 1u32;
        while s <= full {
            if s.count_ones() == size {
                let area = subset_area(s, n, &t.boxes, costs);
                let count = subset_count(s, n, &t.counts);
                solve_subset(s, 0, area, count, &mut sol.cost, &mut sol.partition, costs);
            }
            s += 1;
        }
        size += 1;
    }
    sol
}

/// Rewires the treelet's internal nodes into the tree that `partition`
/// (indexed by subset, from `base`) describes, and sets each one's box,
/// primitive count and cost from its subset: the union of its leaves' boxes,
/// and the cost the DP gave that subset, recomputed bottom-up with the DP's
/// own operations (so it is the same number, and a refit from memory is not
/// needed). The root keeps its index; the other internal nodes are reused in
/// order.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn apply(
    t: &Treelet,
    partition: &[u32],
    base: usize,
    nodes: &mut [Node],
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    costs: &TreeletCosts,
) {
    let n = t.leaf_count;
    let full = (1u32 << n) - 1;
    // Per internal slot: its subset and its children (a leaf index below
    // 8, or 8 + the child's internal slot).
    let mut sets = [0u32; TREELET_INTERNALS];
    let mut kids = [0u32; 2 * TREELET_INTERNALS];
    // Stack of internal slots still to split, depth at most the number of internals.
    let mut stack = [0u32; TREELET_INTERNALS];
    let mut top = 1usize;
    sets[0] = full;
    let mut next_internal = 1usize;
    while top > 0 {
        top -= 1;
        let k = stack[top] as usize;
        let s = sets[k];
        let node = t.internals[k];
        let p = partition[base + s as usize];
        let mut side = 0;
        while side < 2 {
            let part = if side == 0 { p } else { s ^ p };
            let child = if part.count_ones() == 1 {
                kids[2 * k + side] = part.trailing_zeros();
                t.leaves[part.trailing_zeros() as usize]
            } else {
                kids[2 * k + side] = 8 + next_internal as u32;
                sets[next_internal] = part;
                stack[top] = next_internal as u32;
                top += 1;
                next_internal += 1;
                t.internals[next_internal - 1]
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
    // Children come after their parents: fill boxes and costs in reverse.
    let mut internal_costs = [0.0f32; TREELET_INTERNALS];
    let mut k = next_internal;
    while k > 0 {
        k -= 1;
        let s = sets[k];
        let mut children = 0.0f32;
        let mut side = 0;
        while side < 2 {
            let kid = kids[2 * k + side];
            let c = if kid < 8 { t.costs[kid as usize] } else { internal_costs[(kid - 8) as usize] };
            children = if side == 0 { c } else { children + c };
            side += 1;
        }
        let count = subset_count(s, n, &t.counts);
        let b = subset_box(s, n, &t.boxes);
        let cost = costs.subtree(costs.area(&b), count, children);
        internal_costs[k] = cost;
        let node = t.internals[k] as usize;
        nodes[node].set_aabb(b);
        counts[node] = count;
        node_costs[node] = cost;
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

/// Restructures the treelet rooted at internal node `root` in place, in one
/// invocation: forms it, solves the DP, and commits the result if cheaper.
/// `node_costs` holds every node's subtree cost (as [`node_cost`] defines
/// it) and `counts` its primitive count. Returns whether the treelet changed.
#[inline]
pub fn restructure(
    root: u32,
    nodes: &mut [Node],
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    costs: &TreeletCosts,
) -> bool {
    let t = form_treelet(root, nodes, counts, node_costs, costs);
    if t.leaf_count < 3 {
        return false; // two leaves: only one tree
    }
    let sol = optimize(&t, costs);
    let full = (1usize << t.leaf_count) - 1;
    if !improves(sol.cost[full], node_costs[root as usize]) {
        return false;
    }
    apply(&t, &sol.partition, 0, nodes, parents, counts, node_costs, costs);
    true
}

/// Whether an optimum of cost `best` replaces a subtree of cost `current`:
/// the current topology is one of the candidates, so only a strictly lower
/// cost counts (avoids churn on ties and rounding).
#[inline]
pub fn improves(best: f32, current: f32) -> bool {
    best < current * (1.0 - 1e-6)
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

/// Heights the level lists hold; the last slot counts deeper nodes (an
/// error for the host: traversal refuses such trees anyway).
pub const MAX_LEVELS: usize = 256;

/// Whether internal node `i` roots a treelet this round, and at which height.
#[inline]
fn treelet_root(i: u32, params: &TreeletParams, counts: &[u32], heights: &[u32]) -> Option<usize> {
    if params.n < 2 || i >= params.n - 1 || counts[i as usize] < params.gamma {
        return None;
    }
    Some((heights[i as usize] as usize).min(MAX_LEVELS - 1))
}

/// Kernel (one invocation per internal node): counts the treelet roots of
/// each height into `level_counts` (zeroed, [`MAX_LEVELS`] entries).
pub fn treelet_histogram_kernel(
    i: u32,
    params: &TreeletParams,
    counts: &[u32],
    heights: &[u32],
    level_counts: &mut [u32],
) {
    if let Some(h) = treelet_root(i, params, counts, heights) {
        atomics::add_device(&mut level_counts[h], 1);
    }
}

/// Kernel (one invocation per internal node): appends each treelet root to
/// its height's list; `cursors` start at each list's offset. Order within a
/// list does not matter: the treelets of one height are disjoint.
pub fn treelet_scatter_kernel(
    i: u32,
    params: &TreeletParams,
    counts: &[u32],
    heights: &[u32],
    cursors: &mut [u32],
    roots: &mut [u32],
) {
    if let Some(h) = treelet_root(i, params, counts, heights) {
        let slot = atomics::add_device(&mut cursors[h], 1);
        roots[slot as usize] = i;
    }
}

// The device restructures the treelets of one height in three dispatches:
// form (one invocation per treelet, writing a record), solve (a team of 32
// lanes per treelet, the DP as in the paper's warp-wide scheme, writing the
// partitions), commit (one invocation per treelet). Splitting keeps the
// one-lane steps from holding the registers of the wide one.

/// Words of one treelet record: leaves (7) and leaf count, internal nodes
/// (6), the root's current cost, leaf boxes (7 x 6), leaf primitive counts
/// (7), leaf subtree costs (7). Floats are stored as bits.
pub const RECORD_WORDS: usize = 72;
const R_COUNT: usize = 7;
const R_INTERNALS: usize = 8;
const R_CURRENT: usize = 14;
const R_BOXES: usize = 16;
const R_COUNTS: usize = 58;
const R_COSTS: usize = 65;
/// Words of one solution row: `partition[s]` at `s`, and at 0 the optimum's cost bits.
pub const SOLUTION_WORDS: usize = SUBSETS;

/// Kernel (one invocation per treelet of this height): forms the treelet of
/// `roots[level_offset + i]` and writes its record (leaf count 0 when it
/// has fewer than three leaves: nothing to choose).
#[allow(clippy::too_many_arguments)]
pub fn treelet_form_kernel(
    i: u32,
    params: &TreeletParams,
    roots: &[u32],
    nodes: &[Node],
    counts: &[u32],
    node_costs: &[f32],
    records: &mut [u32],
) {
    if i >= params.level_count {
        return;
    }
    let root = roots[(params.level_offset + i) as usize];
    let t = form_treelet(root, nodes, counts, node_costs, &params.costs());
    let r = i as usize * RECORD_WORDS;
    records[r + R_COUNT] = if t.leaf_count >= 3 { t.leaf_count } else { 0 };
    let mut k = 0;
    while k < TREELET_LEAVES {
        records[r + k] = t.leaves[k];
        if k < TREELET_INTERNALS {
            records[r + R_INTERNALS + k] = t.internals[k];
        }
        let (lo, hi) = (t.boxes[k].min, t.boxes[k].max);
        let f = r + R_BOXES + 6 * k;
        records[f] = lo[0].to_bits();
        records[f + 1] = lo[1].to_bits();
        records[f + 2] = lo[2].to_bits();
        records[f + 3] = hi[0].to_bits();
        records[f + 4] = hi[1].to_bits();
        records[f + 5] = hi[2].to_bits();
        records[r + R_COUNTS + k] = t.counts[k];
        records[r + R_COSTS + k] = t.costs[k].to_bits();
        k += 1;
    }
    records[r + R_CURRENT] = node_costs[root as usize].to_bits();
}

/// The treelet of a record.
#[inline]
fn read_record(records: &[u32], r: usize) -> Treelet {
    let mut t = Treelet {
        leaves: [0; TREELET_LEAVES],
        leaf_count: records[r + R_COUNT],
        internals: [0; TREELET_INTERNALS],
        boxes: [Aabb::EMPTY; TREELET_LEAVES],
        counts: [0; TREELET_LEAVES],
        costs: [0.0; TREELET_LEAVES],
    };
    let mut k = 0;
    while k < TREELET_LEAVES {
        t.leaves[k] = records[r + k];
        if k < TREELET_INTERNALS {
            t.internals[k] = records[r + R_INTERNALS + k];
        }
        let f = r + R_BOXES + 6 * k;
        let lo = [f32::from_bits(records[f]), f32::from_bits(records[f + 1]), f32::from_bits(records[f + 2])];
        let hi = [f32::from_bits(records[f + 3]), f32::from_bits(records[f + 4]), f32::from_bits(records[f + 5])];
        t.boxes[k] = Aabb::from_arrays(lo, hi);
        t.counts[k] = records[r + R_COUNTS + k];
        t.costs[k] = f32::from_bits(records[r + R_COSTS + k]);
        k += 1;
    }
    t
}

/// Lanes that solve one treelet together (the paper's warp; a slice of a
/// workgroup here, so no subgroup size is assumed).
pub const TEAM: u32 = 32;
/// Treelets per workgroup of the solve kernel.
pub const TEAMS: usize = crate::workgroup::WG / TEAM as usize;
/// Shared DP tables: one row of [`SUBSETS`] per team.
pub const TEAM_TABLE: usize = TEAMS * SUBSETS;
/// Shared leaf data: per team, the leaf count, 7 boxes of 6 floats, 7 primitive counts.
pub const TEAM_LEAVES: usize = TEAMS * 64;
/// Phases of [`treelet_solve_phase`]: load, one per subset size 2..=7, store.
pub const SOLVE_PHASES: u32 = 2 + TREELET_LEAVES as u32 - 1;

/// Binomial coefficient C(n, k) for n, k <= 7, from Pascal's triangle
/// packed six bits per entry (no division: GPUs do it slowly).
#[inline]
pub fn binomial(n: u32, k: u32) -> u32 {
    let row: u64 = match n {
        0 => 1,
        1 => 1 | 1 << 6,
        2 => 1 | 2 << 6 | 1 << 12,
        3 => 1 | 3 << 6 | 3 << 12 | 1 << 18,
        4 => 1 | 4 << 6 | 6 << 12 | 4 << 18 | 1 << 24,
        5 => 1 | 5 << 6 | 10 << 12 | 10 << 18 | 5 << 24 | 1 << 30,
        6 => 1 | 6 << 6 | 15 << 12 | 20 << 18 | 15 << 24 | 6 << 30 | 1 << 36,
        7 => 1 | 7 << 6 | 21 << 12 | 35 << 18 | 35 << 24 | 21 << 30 | 7 << 36 | 1 << 42,
        _ => 0,
    };
    if k > 7 {
        return 0;
    }
    ((row >> (6 * k)) & 63) as u32
}

/// The `rank`-th subset (in colex order) of `size` leaves among `n`: how a
/// lane finds its subsets of one size without scanning all of them.
#[inline]
pub fn subset_of_rank(mut rank: u32, n: u32, size: u32) -> u32 {
    let mut s = 0u32;
    let mut k = size;
    let mut pos = n;
    while k > 0 && pos > 0 {
        pos -= 1;
        let below = binomial(pos, k);
        if rank >= below {
            s |= 1 << pos;
            rank -= below;
            k -= 1;
        }
    }
    s
}

/// Kernel (workgroups of [`TEAMS`] teams of [`TEAM`] lanes; phase by phase):
/// the DP of [`optimize`] for the treelets of `records`, one per team: each
/// lane takes every 32nd subset of each size, sizes in increasing order with
/// a barrier between them. Writes each treelet's partitions to `solutions`.
#[allow(clippy::too_many_arguments)]
pub fn treelet_solve_phase(
    phase: u32,
    lid: u32,
    group: u32,
    params: &TreeletParams,
    records: &[u32],
    solutions: &mut [u32],
    leaves: &mut [f32; TEAM_LEAVES],
    cost: &mut [f32; TEAM_TABLE],
    partition: &mut [u32; TEAM_TABLE],
) {
    let team = (lid / TEAM) as usize;
    let lane = lid % TEAM;
    let index = group * TEAMS as u32 + team as u32;
    let (lb, tb) = (team * 64, team * SUBSETS);
    let r = index as usize * RECORD_WORDS;
    if phase == 0 {
        // The record into workgroup memory, the team's lanes side by side:
        // leaf count at 0, boxes from 1, primitive counts from 43 (as f32,
        // exact below 2^24), the leaves' costs into the DP's singleton entries.
        if index >= params.level_count {
            if lane == 0 {
                leaves[lb] = 0.0;
            }
            return;
        }
        let mut w = lane as usize;
        while w < R_COSTS + TREELET_LEAVES {
            let word = records[r + w];
            if w == R_COUNT {
                leaves[lb] = word as f32;
            } else if (R_BOXES..R_COUNTS).contains(&w) {
                leaves[lb + 1 + w - R_BOXES] = f32::from_bits(word);
            } else if (R_COUNTS..R_COSTS).contains(&w) {
                leaves[lb + 43 + w - R_COUNTS] = word as f32;
            } else if w >= R_COSTS {
                cost[tb + (1 << (w - R_COSTS))] = f32::from_bits(word);
            }
            w += TEAM as usize;
        }
        return;
    }
    let n = leaves[lb] as u32;
    if n == 0 {
        return;
    }
    let full = (1u32 << n) - 1;
    if phase < SOLVE_PHASES - 1 {
        // Subsets of one size, dealt round-robin to the lanes.
        let size = phase + 1;
        if size > n {
            return;
        }
        let costs = params.costs();
        let total = binomial(n, size);
        let mut rank = lane;
        while rank < total {
            let s = subset_of_rank(rank, n, size);
            // The subset's box and count straight from workgroup memory (a
            // union is exact in any order, so this equals `subset_area`).
            let (mut lo, mut hi) = ([f32::MAX; 3], [-f32::MAX; 3]);
            let mut count = 0u32;
            let mut k = 0;
            while k < n as usize {
                if s & (1 << k) != 0 {
                    let f = lb + 1 + 6 * k;
                    lo = [lo[0].min(leaves[f]), lo[1].min(leaves[f + 1]), lo[2].min(leaves[f + 2])];
                    hi = [hi[0].max(leaves[f + 3]), hi[1].max(leaves[f + 4]), hi[2].max(leaves[f + 5])];
                    count += leaves[lb + 43 + k] as u32;
                }
                k += 1;
            }
            let a = costs.area(&Aabb::from_arrays(lo, hi));
            solve_subset(s, tb, a, count, cost, partition, &costs);
            rank += TEAM;
        }
    } else {
        let row = index as usize * SOLUTION_WORDS;
        let mut s = lane as usize;
        while s <= full as usize {
            solutions[row + s] = if s == 0 { cost[tb + full as usize].to_bits() } else { partition[tb + s] };
            s += TEAM as usize;
        }
    }
}

/// Kernel (one invocation per treelet of this height): rewires the treelet
/// into its solved tree when that lowers its cost.
#[allow(clippy::too_many_arguments)]
pub fn treelet_commit_kernel(
    i: u32,
    params: &TreeletParams,
    records: &[u32],
    solutions: &[u32],
    nodes: &mut [Node],
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
) {
    if i >= params.level_count {
        return;
    }
    let r = i as usize * RECORD_WORDS;
    if records[r + R_COUNT] == 0 {
        return;
    }
    let row = i as usize * SOLUTION_WORDS;
    let (best, current) = (f32::from_bits(solutions[row]), f32::from_bits(records[r + R_CURRENT]));
    if !improves(best, current) {
        return;
    }
    let t = read_record(records, r);
    apply(&t, solutions, row, nodes, parents, counts, node_costs, &params.costs());
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
                    let t = Treelet {
                        leaves: [0; TREELET_LEAVES],
                        leaf_count: n,
                        internals: [0; TREELET_INTERNALS],
                        boxes: l.boxes,
                        counts: l.counts,
                        costs: l.costs,
                    };
                    let sol = optimize(&t, &costs);
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
    fn binomials_match_pascal() {
        for n in 0..=7u32 {
            for k in 0..=8u32 {
                let expected = if k > n { 0 } else { (0..k).fold(1u32, |c, i| c * (n - i) / (i + 1)) };
                assert_eq!(binomial(n, k), expected, "C({n}, {k})");
            }
        }
    }

    #[test]
    fn subsets_of_rank_cover_each_size_once() {
        for n in 1..=TREELET_LEAVES as u32 {
            for size in 1..=n {
                let mut seen: Vec<u32> = (0..binomial(n, size)).map(|r| subset_of_rank(r, n, size)).collect();
                assert!(seen.iter().all(|s| s.count_ones() == size && *s < (1 << n)), "n {n} size {size}");
                seen.sort();
                seen.dedup();
                let expected = (1u32..1 << n).filter(|s| s.count_ones() == size).count();
                assert_eq!(seen.len(), expected, "n {n} size {size}");
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
