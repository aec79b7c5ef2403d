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
//! rounds optimize for the tree that [`crate::construct::collapse`] finally produces.
//! [`restructure`] is the steps in one invocation (the reference the tests
//! use); [`crate::construct::treelet::kernels`] runs them on the device, the DP of each
//! treelet spread over a team of lanes.
pub mod kernels;

use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{Node, TreeletParams};
use crate::geometry::records::{RecordLoad, RecordStore};
use crate::gpu::unchecked::{at, get, put, scratch, set};

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

// A treelet is staged in an array of words (floats as bits) from some base:
// in a private array for the one-invocation reference, in workgroup memory
// in the kernel, where a team of lanes reads it. Words, from the base:
/// Leaf node ids (7).
pub const T_LEAVES: usize = 0;
/// Leaf count (2 to 7).
pub const T_COUNT: usize = 7;
/// Internal node ids, root first (up to 6).
pub const T_INTERNALS: usize = 8;
/// The root's current cost (bits) and height, for the kernel.
pub const T_CURRENT: usize = 14;
pub const T_HEIGHT: usize = 15;
/// Leaf primitive counts, subtree heights and subtree costs (bits), 7 each.
pub const T_PRIMS: usize = 16;
pub const T_HEIGHTS: usize = 23;
pub const T_COSTS: usize = 30;
/// Leaf boxes, 6 floats each (min xyz, max xyz).
pub const T_BOXES: usize = 37;
/// Scratch of [`form_treelet`] (areas, left and right children per slot)
/// and of [`plan_rewire`] (subsets, children, heights per internal node, a stack).
const T_SCRATCH: usize = T_BOXES + 6 * TREELET_LEAVES;
const F_AREAS: usize = T_SCRATCH;
const F_LEFTS: usize = T_SCRATCH + TREELET_LEAVES;
const F_RIGHTS: usize = T_SCRATCH + 2 * TREELET_LEAVES;
const A_SETS: usize = T_SCRATCH;
const A_KIDS: usize = A_SETS + TREELET_INTERNALS;
const A_HEIGHTS: usize = A_KIDS + 2 * TREELET_INTERNALS;
const A_STACK: usize = A_HEIGHTS + TREELET_INTERNALS;
/// Whether the kernel rewires the treelet (1) or keeps it (0).
pub const T_REWIRE: usize = A_STACK + TREELET_INTERNALS;
/// The round in which the root's subtree last changed, for the kernel's marks.
pub const T_CHANGED: usize = T_REWIRE + 1;
/// Words of one staged treelet, rounded up to odd so that treelets staged
/// side by side in workgroup memory start on different banks.
pub const TREELET_WORDS: usize = (T_CHANGED + 1) | 1;
const _: () = assert!(TREELET_WORDS % 2 == 1);

/// The box of leaf `k` of the treelet staged at `b`.
#[inline]
pub fn staged_box<const N: usize>(stage: &[u32; N], b: usize, k: usize) -> Aabb {
    let f = b + T_BOXES + 6 * k;
    let w = |j: usize| f32::from_bits(get(stage, f + j));
    Aabb::from_arrays([w(0), w(1), w(2)], [w(3), w(4), w(5)])
}

/// Stages box `x` as the box of leaf `k`.
#[inline]
pub fn stage_box<const N: usize>(stage: &mut [u32; N], b: usize, k: usize, x: &Aabb) {
    let f = b + T_BOXES + 6 * k;
    let (lo, hi) = (x.min, x.max);
    set(stage, f, lo[0].to_bits());
    set(stage, f + 1, lo[1].to_bits());
    set(stage, f + 2, lo[2].to_bits());
    set(stage, f + 3, hi[0].to_bits());
    set(stage, f + 4, hi[1].to_bits());
    set(stage, f + 5, hi[2].to_bits());
}

/// Stages node `id` (with its primitive count, cost and height) as leaf
/// `slot` of the treelet being formed, with what expanding it needs.
#[allow(clippy::too_many_arguments)]
#[inline]
fn stage_leaf<const N: usize>(
    stage: &mut [u32; N],
    b: usize,
    slot: usize,
    id: u32,
    node: &Node,
    count: u32,
    cost: f32,
    height: u32,
    costs: &TreeletCosts,
) {
    let x = node.aabb();
    set(stage, b + T_LEAVES + slot, id);
    stage_box(stage, b, slot, &x);
    set(stage, b + F_LEFTS + slot, node.left);
    set(stage, b + F_RIGHTS + slot, node.right);
    let area = if node.is_leaf() { -1.0 } else { costs.area(&x) };
    set(stage, b + F_AREAS + slot, area.to_bits());
    set(stage, b + T_PRIMS + slot, count);
    set(stage, b + T_COSTS + slot, cost.to_bits());
    set(stage, b + T_HEIGHTS + slot, height);
}

/// What [`form_treelet`] finds besides the staged treelet.
#[derive(Clone, Copy)]
pub struct Formed {
    /// Leaves of the treelet (2 to 7).
    pub leaf_count: u32,
    /// The root's subtree cost and height from its children's, which must
    /// be current. A root keeps its treelet when nothing cheaper exists, yet
    /// the subtrees under it may have changed: storing these lets the
    /// changes reach the nodes above, and later rounds, without a new climb.
    pub current: f32,
    pub height: u32,
}

/// Forms the treelet under internal node `root` (algorithm 2's first loop)
/// into `stage` at `b`: expand, among the current leaves that are internal
/// BVH nodes, the one of largest area (the first on ties), until seven
/// leaves or no expandable leaf remain. Each node is read once, and with it
/// its primitive count, cost and height, whether it stays a leaf or not:
/// the chain of dependent loads is one per expansion and no longer.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn form_treelet<const N: usize, NS: RecordLoad<Node> + ?Sized>(
    root: u32,
    nodes: &NS,
    counts: &[u32],
    node_costs: &[f32],
    heights: &[u32],
    costs: &TreeletCosts,
    stage: &mut [u32; N],
    b: usize,
) -> Formed {
    stage[b + T_INTERNALS] = root;
    let r = nodes.load(root as usize);
    let root_count = at(counts, root as usize);
    let mut internal_count = 1usize;
    let mut leaf_count = 2usize;
    // Slot `best` takes the left child, a new slot the right one.
    let mut best = 0usize;
    let (mut left, mut right) = (r.left, r.right);
    loop {
        // Both new leaves' data first, then the stage writes: the loads
        // wait on no one, one round trip to memory per expansion.
        let (ln, rn) = (nodes.load(left as usize), nodes.load(right as usize));
        let (lc, rc) = (at(counts, left as usize), at(counts, right as usize));
        let (lk, rk) = (at(node_costs, left as usize), at(node_costs, right as usize));
        let (lh, rh) = (at(heights, left as usize), at(heights, right as usize));
        stage_leaf(stage, b, best, left, &ln, lc, lk, lh, costs);
        stage_leaf(stage, b, leaf_count - 1, right, &rn, rc, rk, rh, costs);
        if leaf_count == 2 {
            // The root's children, before either is expanded.
            let (c0, c1) = (f32::from_bits(stage[b + T_COSTS]), f32::from_bits(stage[b + T_COSTS + 1]));
            stage[b + T_CURRENT] = costs.subtree(costs.area(&r.aabb()), root_count, c0 + c1).to_bits();
            stage[b + T_HEIGHT] = 1 + stage[b + T_HEIGHTS].max(stage[b + T_HEIGHTS + 1]);
        }
        if leaf_count == TREELET_LEAVES {
            break;
        }
        best = usize::MAX;
        let mut best_area = -1.0f32;
        let mut i = 0;
        while i < leaf_count {
            let a = f32::from_bits(get(stage, b + F_AREAS + i));
            if a > best_area {
                best_area = a;
                best = i;
            }
            i += 1;
        }
        if best == usize::MAX {
            break;
        }
        set(stage, b + T_INTERNALS + internal_count, get(stage, b + T_LEAVES + best));
        internal_count += 1;
        left = get(stage, b + F_LEFTS + best);
        right = get(stage, b + F_RIGHTS + best);
        leaf_count += 1;
    }
    stage[b + T_COUNT] = leaf_count as u32;
    Formed {
        leaf_count: leaf_count as u32,
        current: f32::from_bits(stage[b + T_CURRENT]),
        height: stage[b + T_HEIGHT],
    }
}

/// Words of a packed partition table: the partition of subset `s` is byte
/// `s % 4` of word `s / 4` (a subset of seven leaves fits in a byte).
pub const PACKED_WORDS: usize = SUBSETS / 4;

/// The partition of subset `s` in a packed table whose words start at `base`.
#[inline]
pub fn packed_partition<const M: usize>(parts: &[u32; M], base: usize, s: u32) -> u32 {
    (parts[base + (s / 4) as usize] >> (8 * (s % 4))) & 0xff
}

/// `p` placed where [`packed_partition`] finds the partition of subset `s`
/// (to be or-ed into word `s / 4`).
#[inline]
pub fn packed_bits(s: u32, p: u32) -> u32 {
    p << (8 * (s % 4))
}

/// Union of the boxes of the leaves in subset `s` of the treelet staged at `b`.
#[inline]
pub fn subset_box<const N: usize>(s: u32, n: u32, stage: &[u32; N], b: usize) -> Aabb {
    // Set bits only, lowest first: no branch per leaf (lanes of a team
    // hold different subsets and would take both sides of it).
    let mut x = Aabb::EMPTY;
    let mut rest = s & ((1u32 << n) - 1);
    while rest != 0 {
        x = x.union(&staged_box(stage, b, rest.trailing_zeros() as usize));
        rest &= rest - 1;
    }
    x
}

/// Primitives under the leaves in subset `s` of the treelet staged at `b`.
#[inline]
pub fn subset_count<const N: usize>(s: u32, n: u32, stage: &[u32; N], b: usize) -> u32 {
    let mut c = 0;
    let mut rest = s & ((1u32 << n) - 1);
    while rest != 0 {
        c += get(stage, b + T_PRIMS + rest.trailing_zeros() as usize);
        rest &= rest - 1;
    }
    c
}

/// One step of the DP: the best partition of subset `s` (of at least two
/// leaves) from the solved costs of its parts. Writes the cost of `s` (at
/// `base + s`, several treelets share one table in the kernel) and returns
/// the partition.
///
/// Algorithm 3: partitions `(p, s ^ p)` with `p` inside `s` minus its lowest
/// bit, each unordered pair once, the first of equal costs kept: whoever
/// solves `s`, the result is the same.
#[inline]
pub fn solve_subset<const N: usize>(
    s: u32,
    base: usize,
    area: f32,
    count: u32,
    cost: &mut [f32; N],
    costs: &TreeletCosts,
) -> u32 {
    let delta = (s - 1) & s;
    let mut p = delta.wrapping_neg() & s;
    let mut best = f32::MAX;
    let mut best_p = 0u32;
    loop {
        let c = get(cost, base + p as usize) + get(cost, base + (s ^ p) as usize);
        if c < best {
            best = c;
            best_p = p;
        }
        p = p.wrapping_sub(delta) & s;
        if p == 0 {
            break;
        }
    }
    set(cost, base + s as usize, costs.subtree(area, count, best));
    best_p
}

/// Partition number `m` (1 to `2^(n-1) - 1`) of a whole treelet of `n`
/// leaves: the `m`-th that [`solve_subset`] enumerates for it (the
/// sub-masks of all leaves but the first, increasing).
#[inline]
pub fn whole_partition(m: u32) -> u32 {
    m << 1
}

/// One lane's share of [`solve_subset`] over a whole treelet of `n` leaves:
/// partitions `m = lane + 1, lane + 1 + lanes, ...`; returns the cheapest
/// sum of part costs and its `m` (the first of equal costs; `u32::MAX` if
/// none is below `f32::MAX`). The smallest `m` among the lanes' cheapest is
/// the partition [`solve_subset`] would pick.
#[inline]
pub fn best_whole_partition<const N: usize>(n: u32, lane: u32, lanes: u32, cost: &[f32; N], base: usize) -> (f32, u32) {
    let full = (1u32 << n) - 1;
    let count = (1u32 << (n - 1)) - 1;
    let (mut best, mut best_m) = (f32::MAX, u32::MAX);
    let mut m = lane + 1;
    while m <= count {
        let p = whole_partition(m);
        let c = get(cost, base + p as usize) + get(cost, base + (full ^ p) as usize);
        if c < best {
            best = c;
            best_m = m;
        }
        m += lanes;
    }
    (best, best_m)
}

/// Of two lanes' results of [`best_whole_partition`], the one
/// [`solve_subset`] would keep: the cheaper, the lower number on equal costs.
#[inline]
pub fn first_cheapest(a: (f32, u32), b: (f32, u32)) -> (f32, u32) {
    if b.0 < a.0 || (b.0 == a.0 && b.1 < a.1) {
        b
    } else {
        a
    }
}

/// The optimal tree over a treelet's leaves: `cost[s]` is the cost of the
/// best subtree over subset `s`; its root splits `s` into `p` and `s ^ p`,
/// `p` = [`packed_partition`]`(&parts, 0, s)`. Tables for up to seven leaves
/// by default; `C` costs and `P` packed words hold `log2(C)` leaves.
pub struct TreeletSolution<const C: usize = SUBSETS, const P: usize = PACKED_WORDS> {
    pub cost: [f32; C],
    pub parts: [u32; P],
}

/// Algorithm 2's dynamic program over the subsets of the leaves of the
/// treelet staged at `b`, in one invocation (the kernel deals the same
/// steps to a team of lanes). Subsets go in increasing order: every proper
/// subset of `s` is smaller than `s`, so its parts are solved before it.
#[inline]
pub fn optimize<const N: usize>(stage: &[u32; N], b: usize, costs: &TreeletCosts) -> TreeletSolution {
    optimize_sized(stage, b, costs)
}

/// [`optimize`] into tables of `C` costs and `P` packed words, which must
/// hold the staged treelet's subsets (`2^n <= C`): smaller tables for
/// small treelets take less private memory.
#[inline]
pub fn optimize_sized<const N: usize, const C: usize, const P: usize>(
    stage: &[u32; N],
    b: usize,
    costs: &TreeletCosts,
) -> TreeletSolution<C, P> {
    // Every subset's cost is written before it is read (see above); the
    // packed words are or-ed into.
    let mut sol = TreeletSolution { cost: scratch::<f32, C>(), parts: [0u32; P] };
    let n = stage[b + T_COUNT];
    let mut i = 0;
    while i < n as usize {
        set(&mut sol.cost, 1 << i, f32::from_bits(stage[b + T_COSTS + i]));
        i += 1;
    }
    let full = (1u32 << n) - 1;
    let mut s = 3u32;
    while s <= full {
        if s & (s - 1) != 0 {
            let area = costs.area(&subset_box(s, n, stage, b));
            let p = solve_subset(s, 0, area, subset_count(s, n, stage, b), &mut sol.cost, costs);
            let w = (s / 4) as usize;
            let word = get(&sol.parts, w) | packed_bits(s, p);
            set(&mut sol.parts, w, word);
        }
        s += 1;
    }
    sol
}

/// First step of rewiring the treelet staged at `b` into the tree that the
/// packed partitions `parts` (from `base`) describe: which subset each of
/// its `leaf_count - 1` internal nodes covers (the root keeps its index and
/// covers all; the others are reused in order), their children and their
/// heights, into the stage's scratch for [`rewire_internal`].
#[inline]
pub fn plan_rewire<const N: usize, const M: usize>(stage: &mut [u32; N], b: usize, parts: &[u32; M], base: usize) {
    let n = get(stage, b + T_COUNT);
    // Children: a leaf index below 8, or 8 + the child's internal slot. A
    // stack of internal slots still to split, at most as deep as there
    // are internal nodes.
    set(stage, b + A_SETS, (1u32 << n) - 1);
    set(stage, b + A_STACK, 0);
    let mut top = 1usize;
    let mut next_internal = 1usize;
    while top > 0 {
        top -= 1;
        let k = get(stage, b + A_STACK + top) as usize;
        let s = get(stage, b + A_SETS + k);
        let p = packed_partition(parts, base, s);
        let mut side = 0;
        while side < 2 {
            let part = if side == 0 { p } else { s ^ p };
            if part.count_ones() == 1 {
                set(stage, b + A_KIDS + 2 * k + side, part.trailing_zeros());
            } else {
                set(stage, b + A_KIDS + 2 * k + side, 8 + next_internal as u32);
                set(stage, b + A_SETS + next_internal, part);
                set(stage, b + A_STACK + top, next_internal as u32);
                top += 1;
                next_internal += 1;
            }
            side += 1;
        }
    }
    // Children come after their parents: heights in reverse.
    let mut k = next_internal;
    while k > 0 {
        k -= 1;
        let mut height = 0u32;
        let mut side = 0;
        while side < 2 {
            let kid = get(stage, b + A_KIDS + 2 * k + side) as usize;
            let h = if kid < 8 { get(stage, b + T_HEIGHTS + kid) } else { get(stage, b + A_HEIGHTS + kid - 8) };
            height = height.max(h + 1);
            side += 1;
        }
        set(stage, b + A_HEIGHTS + k, height);
    }
}

/// Second step of rewiring (after [`plan_rewire`]), for internal node `k`
/// of the treelet staged at `b`: its children, their parent links, and its
/// box, primitive count, cost and height from its subset (the union of its
/// leaves' boxes; the cost the DP found for the subset, in `cost` from
/// `cb`). Internal nodes are independent here: lanes may take one each.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn rewire_internal<const N: usize, const C: usize, NS: RecordStore<Node> + ?Sized>(
    k: usize,
    stage: &[u32; N],
    b: usize,
    cost: &[f32; C],
    cb: usize,
    nodes: &mut NS,
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &mut [u32],
) {
    let n = get(stage, b + T_COUNT);
    let s = get(stage, b + A_SETS + k);
    let node = get(stage, b + T_INTERNALS + k) as usize;
    let child = |side: usize| {
        let kid = get(stage, b + A_KIDS + 2 * k + side) as usize;
        if kid < 8 {
            get(stage, b + T_LEAVES + kid)
        } else {
            get(stage, b + T_INTERNALS + kid - 8)
        }
    };
    let (left, right) = (child(0), child(1));
    // The whole node in one store: it is not read here, only written.
    let x = subset_box(s, n, stage, b);
    nodes.store(node, &Node { min: x.min, left, max: x.max, right });
    put(parents, left as usize, node as u32);
    put(parents, right as usize, node as u32);
    put(counts, node, subset_count(s, n, stage, b));
    put(node_costs, node, get(cost, cb + s as usize));
    put(heights, node, get(stage, b + A_HEIGHTS + k));
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
/// it), `counts` its primitive count and `heights` its height (leaves 0),
/// current below `root`; they are current at `root` afterwards.
/// Returns whether the treelet changed.
#[inline]
pub fn restructure(
    root: u32,
    nodes: &mut [Node],
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &mut [u32],
    costs: &TreeletCosts,
) -> bool {
    let mut stage = [0u32; TREELET_WORDS];
    let f = form_treelet(root, nodes, counts, node_costs, heights, costs, &mut stage, 0);
    let sol = if f.leaf_count >= 3 { Some(optimize(&stage, 0, costs)) } else { None };
    match sol {
        Some(sol) if improves(sol.cost[(1usize << f.leaf_count) - 1], f.current) => {
            plan_rewire(&mut stage, 0, &sol.parts, 0);
            for k in 0..f.leaf_count as usize - 1 {
                rewire_internal(k, &stage, 0, &sol.cost, 0, nodes, parents, counts, node_costs, heights);
            }
            true
        }
        // Two leaves (only one tree), or nothing cheaper.
        _ => {
            node_costs[root as usize] = f.current;
            heights[root as usize] = f.height;
            false
        }
    }
}

/// Whether an optimum of cost `best` replaces a subtree of cost `current`:
/// the current topology is one of the candidates, so only a strictly lower
/// cost counts (avoids churn on ties and rounding).
#[inline]
pub fn improves(best: f32, current: f32) -> bool {
    best < current * (1.0 - 1e-6)
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
            let r = crate::gpu::rng::BounceRng::new(seed, i as u32, 0, 0);
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
                    let mut stage = [0u32; TREELET_WORDS];
                    stage[T_COUNT] = n;
                    for k in 0..n as usize {
                        stage_box(&mut stage, 0, k, &l.boxes[k]);
                        stage[T_PRIMS + k] = l.counts[k];
                        stage[T_COSTS + k] = l.costs[k].to_bits();
                    }
                    let sol = optimize(&stage, 0, &costs);
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
    fn lanes_sharing_the_whole_treelet_pick_the_partition_of_one_lane() {
        // Costs with many ties (few distinct values), so that the first of
        // equal costs matters.
        let mut state = 0x9e37_79b9u32;
        for n in 3..=TREELET_LEAVES as u32 {
            for trial in 0..200 {
                let mut cost = [0f32; SUBSETS];
                for c in cost.iter_mut() {
                    state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    *c = if trial % 2 == 0 { (state >> 29) as f32 } else { (state >> 8) as f32 };
                }
                let full = (1u32 << n) - 1;
                let mut one = cost;
                let expected = solve_subset(full, 0, 1.0, 1, &mut one, &TreeletCosts { node: 1.2, prim: 1.0, inv_extent: 1.0, max_leaf: 1 });
                for lanes in [1u32, 5, 32] {
                    let mut vote = (f32::MAX, u32::MAX);
                    for lane in 0..lanes {
                        vote = first_cheapest(vote, best_whole_partition(n, lane, lanes, &cost, 0));
                    }
                    let best_m = vote.1;
                    assert_eq!(whole_partition(best_m), expected, "n {n} trial {trial} lanes {lanes}");
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
