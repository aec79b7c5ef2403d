//! Making the compressed wide BVH ([`crate::trace::cwbvh`]) from a binary tree
//! of one primitive per leaf (the LBVH layout: what the treelet rounds
//! leave, before their leaf collapse), after Ylitie, Karras & Laine 2017,
//! section 4.
//!
//! 1. [`wide_dp_kernel`], bottom up (climbing with [`Climb`]): for
//!    every binary node `n` and `i = 1..=8`, the SAH cost `C(n, i)` of
//!    representing `n`'s subtree by at most `i` children of a wide node:
//!    * `C(n, 1)`: `n` as one leaf child (at most 3 primitives, cost
//!      `A(n) c_prim P(n)`) or as a wide node (`A(n) c_node + D(n, 8)`);
//!    * `C(n, i)`, `i >= 2`: the cheaper of `C(n, i - 1)` and
//!      `D(n, i) = min_k C(left, k) + C(right, i - k)`.
//!
//!    Each choice is kept as a byte (`decisions`): the split `k`, or
//!    "as with one fewer", or, for `i = 1`, leaf or wide node.
//! 2. [`wide_count_kernel`], per binary node: whether it is a wide node
//!    (walking the decisions down from the root along its path), and then
//!    its children (following its decisions down again, at most 8): how many
//!    are wide nodes and how many primitives its leaf children hold.
//! 3. Two exclusive prefix sums of those counts, in binary-node order: each
//!    wide node's children get the contiguous block of node indices, and
//!    its leaf primitives the contiguous run of [`LeafPrim`]s, that the
//!    layout needs. (The order of blocks is the binary nodes' order; only
//!    siblings need be contiguous.)
//! 4. [`wide_place_kernel`], per wide node: its children to slots by octant
//!    (the paper's ordering, greedily, as the authors' code does), kept for
//!    the next step, and each internal child's index from the block and its
//!    slot order.
//! 5. [`wide_emit_kernel`], per wide node: its [`WideNode`] at its index,
//!    child boxes quantized outwards ([`crate::layouts::cwbvh::quantize_lo`]), and
//!    its leaf primitives.
//!
//! No step depends on the order invocations run in, so the CPU runner
//! builds the same tree (up to the rounding of the DP's sums, fused or not).
use crate::geometry::records::RecordStore;
use crate::construct::climb::Climb;
use crate::construct::treelet::TreeletCosts;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{LayoutParams, LeafPrim, Node, Sphere, WideNode};
use crate::geometry::prims::Prims;
use crate::geometry::split::Split;
use crate::geometry::triangle::Triangle;
use crate::gpu::atomics;
use crate::gpu::unchecked::{get, set};
use crate::layouts::cwbvh::{MAX_LEAF_PRIMS, META_INTERNAL, WIDTH, grid_exponent, grid_step, quantize_hi, quantize_lo};

// Loops over slots are unrolled (`unrolled_8!`): their arrays stay in
// registers.
const _: () = assert!(WIDTH == 8, "`unrolled_8!` lists the slots");

/// Decision byte: `C(n, i)` is `C(n, i - 1)`.
const FEWER: u32 = 0;
/// Decision byte of `i = 1`: the subtree is one leaf child (else its low
/// bits are the split `k` of `D(n, 8)`).
const LEAF: u32 = 0x80;

/// The cost model of the DP: per wide node visited and per primitive tested,
/// per unit of (scaled) area. The paper's ratio (`c_prim = 0.3`) made 0.6 on
/// the H200: 2-6% more diffuse rays inside real scenes, primary ones 0-3% fewer
/// (`docs/results/h200-cwbvh-unroll-2026-12-02/README.md`, "knobs").
pub const WIDE_NODE_COST: f32 = 1.0;
pub const WIDE_PRIM_COST: f32 = 0.6;

impl LayoutParams {
    #[inline]
    fn costs(&self) -> TreeletCosts {
        TreeletCosts { node: self.node_cost, prim: self.prim_cost, inv_extent: self.inv_extent, max_leaf: MAX_LEAF_PRIMS }
    }
}

/// Byte `i - 1` (`i` in 1..=8) of a node's decisions.
#[inline]
fn decision(decisions: &[u32], node: u32, i: u32) -> u32 {
    (decisions[(2 * node + (i - 1) / 4) as usize] >> (8 * ((i - 1) % 4))) & 0xFF
}

/// Kernel, one invocation per primitive slot `j < n` (climbing from leaf
/// `n - 1 + j`; node 0 when `n == 1`): every node's primitive count, costs
/// `C(n, 1..=8)` and decision bytes, written once both children are done.
/// `flags` are zeroed counters, one per internal node.
#[allow(clippy::too_many_arguments)]
pub fn wide_dp_kernel<const ORDERED: bool>(
    j: u32,
    params: &LayoutParams,
    nodes: &[Node],
    parents: &[u32],
    flags: &mut [u32],
    counts: &mut [u32],
    costs: &mut [f32],
    decisions: &mut [u32],
) {
    let n = params.n;
    if j >= n {
        return;
    }
    let model = params.costs();
    let leaf = if n == 1 { 0 } else { n - 1 + j };
    let node = nodes[leaf as usize];
    let count = node.prim_count();
    let cost = model.prim * model.area(&node.aabb()) * count as f32;
    atomics::store_u32(&mut counts[leaf as usize], count);
    for i in 0..WIDTH {
        atomics::store_f32(&mut costs[leaf as usize * WIDTH + i], cost);
    }
    atomics::store_u32(&mut decisions[2 * leaf as usize], LEAF);
    atomics::store_u32(&mut decisions[2 * leaf as usize + 1], 0);
    let mut climb = Climb::<ORDERED>::new(leaf);
    while let Some(parent) = climb.next(parents, flags) {
        let p = nodes[parent as usize];
        let (l, r) = (p.left as usize, p.right as usize);
        let mut left = [0f32; WIDTH];
        let mut right = [0f32; WIDTH];
        unrolled_8!(i, {
            left[i] = atomics::load_f32(&costs[l * WIDTH + i]);
            right[i] = atomics::load_f32(&costs[r * WIDTH + i]);
        });
        let count = atomics::load_u32(&counts[l]) + atomics::load_u32(&counts[r]);
        let area = model.area(&p.aabb());
        // D(parent, i) for i = 2..=8 and its first cheapest split (slot
        // `i - 1` of each array; every loop unrolled, every index constant).
        let mut distribute = [0f32; WIDTH];
        let mut split = [0u32; WIDTH];
        unrolled_8!(j, {
            let i = j + 1;
            if i >= 2 {
                let (mut best, mut best_k) = (f32::MAX, 1u32);
                unrolled_8!(m, {
                    let k = m + 1;
                    if k < i {
                        let c = left[k - 1] + right[i - k - 1];
                        if c < best {
                            (best, best_k) = (c, k as u32);
                        }
                    }
                });
                distribute[j] = best;
                split[j] = best_k;
            }
        });
        let internal = libm::fmaf(model.node, area, distribute[WIDTH - 1]);
        let as_leaf = if count <= MAX_LEAF_PRIMS { model.prim * area * count as f32 } else { f32::MAX };
        let mut c = [0f32; WIDTH];
        let mut bytes = [0u32; WIDTH];
        if as_leaf <= internal {
            (c[0], bytes[0]) = (as_leaf, LEAF);
        } else {
            (c[0], bytes[0]) = (internal, split[WIDTH - 1]);
        }
        unrolled_8!(j, {
            // Slot `j` of `c` and `bytes` is the choice for `i = j + 1`.
            if j >= 1 {
                if distribute[j] < c[j - 1] {
                    c[j] = distribute[j];
                    bytes[j] = split[j];
                } else {
                    c[j] = c[j - 1];
                    bytes[j] = FEWER;
                }
            }
        });
        let parent_index = parent as usize;
        atomics::store_u32(&mut counts[parent_index], count);
        for i in 0..WIDTH {
            atomics::store_f32(&mut costs[parent_index * WIDTH + i], c[i]);
        }
        let low = bytes[0] | bytes[1] << 8 | bytes[2] << 16 | bytes[3] << 24;
        let high = bytes[4] | bytes[5] << 8 | bytes[6] << 16 | bytes[7] << 24;
        atomics::store_u32(&mut decisions[2 * parent_index], low);
        atomics::store_u32(&mut decisions[2 * parent_index + 1], high);
    }
}

/// What a binary node is, reached with `budget` children to fill:
/// [`WIDE`] (a wide node), [`LEAF_CHILD`], or `i >= 2`: its subtree split
/// among up to `i` children by its decision for `i`.
pub const WIDE: u32 = 0;
pub const LEAF_CHILD: u32 = 1;

#[inline]
fn resolve(decisions: &[u32], node: u32, budget: u32) -> u32 {
    let mut i = budget;
    while i >= 2 && decision(decisions, node, i) == FEWER {
        i -= 1;
    }
    if i >= 2 {
        i
    } else if decision(decisions, node, 1) & LEAF != 0 {
        LEAF_CHILD
    } else {
        WIDE
    }
}

/// Budgets of the two children of `node` in state `state` ([`WIDE`]: they
/// share 8; `i >= 2`: they share `i`).
#[inline]
fn child_budgets(decisions: &[u32], node: u32, state: u32) -> (u32, u32) {
    if state == WIDE {
        let k = decision(decisions, node, 1) & !LEAF;
        (k, WIDTH as u32 - k)
    } else {
        let k = decision(decisions, node, state);
        (k, state - k)
    }
}

/// Whether binary node `m` becomes a wide node: the root does; others if
/// the decisions, followed down from the root along `m`'s path, reach it
/// with a budget it fills alone and as a node. The path is read by
/// climbing (at most 64 levels: bits of a u64).
#[inline]
pub fn is_wide_node(m: u32, nodes: &[Node], parents: &[u32], decisions: &[u32]) -> bool {
    // Only a node whose own one-child choice is a wide node can be one:
    // most nodes (those near the leaves) need no walk.
    if m != 0 && decision(decisions, m, 1) & LEAF != 0 {
        return false;
    }
    let mut path = 0u64;
    let mut depth = 0u32;
    let mut x = m;
    while x != 0 && depth < 64 {
        let p = parents[x as usize];
        path |= ((nodes[p as usize].right == x) as u64) << depth;
        depth += 1;
        x = p;
    }
    let mut state = WIDE;
    let mut current = 0u32;
    while depth > 0 {
        if state == LEAF_CHILD {
            return false;
        }
        depth -= 1;
        let (left_budget, right_budget) = child_budgets(decisions, current, state);
        let node = nodes[current as usize];
        let (child, budget) =
            if (path >> depth) & 1 == 1 { (node.right, right_budget) } else { (node.left, left_budget) };
        state = resolve(decisions, child, budget);
        current = child;
    }
    state == WIDE
}

/// Bit of a gathered child: it is a leaf child (else a wide node).
pub const CHILD_LEAF: u32 = 1 << 31;

/// The children of wide node `w`, left to right: binary node indices, with
/// [`CHILD_LEAF`] on leaf children. Returns how many (1..=8).
#[inline]
pub fn wide_children(w: u32, nodes: &[Node], decisions: &[u32], out: &mut [u32; WIDTH]) -> usize {
    let node = nodes[w as usize];
    if node.is_leaf() {
        // A tree of one primitive: the root holds it as a leaf child.
        out[0] = w | CHILD_LEAF;
        return 1;
    }
    // Pending (node, budget) pairs, the left one on top.
    let mut stack = [0u32; 2 * WIDTH];
    let (left_budget, right_budget) = child_budgets(decisions, w, WIDE);
    (stack[0], stack[1], stack[2], stack[3]) = (node.right, right_budget, node.left, left_budget);
    let mut top = 2usize;
    let mut count = 0usize;
    while top > 0 {
        top -= 1;
        let (c, budget) = (get(&stack, 2 * top), get(&stack, 2 * top + 1));
        let state = resolve(decisions, c, budget);
        if state == WIDE || state == LEAF_CHILD {
            if count < WIDTH {
                set(out, count, if state == LEAF_CHILD { c | CHILD_LEAF } else { c });
                count += 1;
            }
        } else if top + 2 <= WIDTH {
            let (lb, rb) = child_budgets(decisions, c, state);
            let n = nodes[c as usize];
            set(&mut stack, 2 * top, n.right);
            set(&mut stack, 2 * top + 1, rb);
            set(&mut stack, 2 * top + 2, n.left);
            set(&mut stack, 2 * top + 3, lb);
            top += 2;
        }
    }
    count
}

/// Kernel, one invocation per binary internal node `m` (node 0 when `n ==
/// 1`): for a wide node, its number of wide children and of primitives in
/// its leaf children, and 1 in `is_wide`; zeros for every other node.
#[allow(clippy::too_many_arguments)]
pub fn wide_count_kernel(
    m: u32,
    params: &LayoutParams,
    nodes: &[Node],
    parents: &[u32],
    counts: &[u32],
    decisions: &[u32],
    is_wide: &mut [u32],
    child_counts: &mut [u32],
    prim_counts: &mut [u32],
) {
    if m >= params.n.max(2) - 1 {
        return;
    }
    let (mut wide, mut children_wide, mut prims) = (0u32, 0u32, 0u32);
    if is_wide_node(m, nodes, parents, decisions) {
        let mut children = [0u32; WIDTH];
        let count = wide_children(m, nodes, decisions, &mut children);
        wide = 1;
        for k in 0..count {
            let c = children[k];
            if c & CHILD_LEAF != 0 {
                prims += counts[(c & !CHILD_LEAF) as usize];
            } else {
                children_wide += 1;
            }
        }
    }
    is_wide[m as usize] = wide;
    child_counts[m as usize] = children_wide;
    prim_counts[m as usize] = prims;
}

/// A wide node's children in their slots: `slots[s]` is the binary node
/// (with [`CHILD_LEAF`]) in slot `s`, or `u32::MAX` for an empty slot.
/// Slot `s` is the octant whose rays should meet its child first (the
/// children nearest the corner a ray of octant `s` comes from), assigned
/// greedily by the cost `(child centre - node centre) · ds`, cheapest
/// pair first (ties to the lower slot, then child).
///
/// Written so that no array is indexed by a value known only at run time
/// (every loop over slots and children is unrolled, free slots and
/// children are bit masks, costs are recomputed from the offsets): such
/// arrays live in local memory on the H100, which made this the layout's
/// slowest step.
#[inline]
#[allow(unused_assignments)] // the last unrolled copy's choice is read by none
pub fn assign_slots(w_box: &Aabb, children: &[u32; WIDTH], count: usize, nodes: &[Node], slots: &mut [u32; WIDTH]) {
    let centre = w_box.centroid();
    let mut offsets = [glam::Vec3::ZERO; WIDTH];
    unrolled_8!(c, {
        if c < count {
            offsets[c] = nodes[(children[c] & !CHILD_LEAF) as usize].aabb().centroid() - centre;
        }
    });
    // The cost of child offset `o` in slot `s`: ds = (±1, ±1, ±1), minus
    // where slot bit 2, 1, 0 is set.
    let cost = |s: usize, o: glam::Vec3| {
        let x = if s & 4 != 0 { -o.x } else { o.x };
        let y = if s & 2 != 0 { -o.y } else { o.y };
        let z = if s & 1 != 0 { -o.z } else { o.z };
        x + y + z
    };
    let (mut free_slots, mut free_children) = (0xffu32, (1u32 << count) - 1);
    let mut child_in = [u32::MAX; WIDTH];
    let mut round = 0;
    while round < count {
        // The cheapest free pair, the first in (slot, child) order on ties.
        let (mut best, mut best_s, mut best_c) = (f32::MAX, 0u32, 0u32);
        let mut found = false;
        unrolled_8!(s, {
            unrolled_8!(c, {
                if free_slots & (1 << s) != 0 && free_children & (1 << c) != 0 {
                    let v = cost(s, offsets[c]);
                    if !found || v < best {
                        (best, best_s, best_c, found) = (v, s as u32, c as u32, true);
                    }
                }
            });
        });
        free_slots &= !(1 << best_s);
        free_children &= !(1 << best_c);
        unrolled_8!(s, {
            if s as u32 == best_s {
                child_in[s] = best_c;
            }
        });
        round += 1;
    }
    unrolled_8!(s, {
        let mut slot = u32::MAX;
        unrolled_8!(c, {
            if child_in[s] == c as u32 {
                slot = children[c];
            }
        });
        slots[s] = slot;
    });
}

/// Kernel, one invocation per binary internal node `m`: a wide node writes
/// its children by slot (`slots[8 m + s]`, see [`assign_slots`]) and the
/// index of each wide child (`positions[child]`): its block's start
/// (`1 + child_offsets[m]`) plus the child's rank in slot order. The root
/// writes its own (0).
#[allow(clippy::too_many_arguments)]
pub fn wide_place_kernel(
    m: u32,
    params: &LayoutParams,
    nodes: &[Node],
    decisions: &[u32],
    is_wide: &[u32],
    child_offsets: &[u32],
    positions: &mut [u32],
    slots_out: &mut [u32],
) {
    if m >= params.n.max(2) - 1 || is_wide[m as usize] == 0 {
        return;
    }
    if m == 0 {
        positions[0] = 0;
    }
    let mut children = [0u32; WIDTH];
    let count = wide_children(m, nodes, decisions, &mut children);
    let mut slots = [0u32; WIDTH];
    assign_slots(&nodes[m as usize].aabb(), &children, count, nodes, &mut slots);
    let mut next = 1 + child_offsets[m as usize];
    for s in 0..WIDTH {
        let c = slots[s];
        slots_out[m as usize * WIDTH + s] = c;
        if c != u32::MAX && c & CHILD_LEAF == 0 {
            positions[c as usize] = next;
            next += 1;
        }
    }
}

/// Kernel, one invocation per binary internal node `m`: a wide node writes
/// its [`WideNode`] at `positions[m]` and its leaf children's primitives
/// from `prim_offsets[m]` on, in slot order (`slots`, as
/// [`wide_place_kernel`] left them).
#[allow(clippy::too_many_arguments)]
pub fn wide_emit_kernel<W: RecordStore<WideNode> + ?Sized, L: RecordStore<LeafPrim> + ?Sized>(
    m: u32,
    params: &LayoutParams,
    nodes: &[Node],
    slots: &[u32],
    is_wide: &[u32],
    child_offsets: &[u32],
    prim_offsets: &[u32],
    positions: &[u32],
    prim_indices: &[u32],
    spheres: &[Sphere],
    triangles: Split<'_, Triangle>,
    out_nodes: &mut W,
    out_prims: &mut L,
) {
    if m >= params.n.max(2) - 1 || is_wide[m as usize] == 0 {
        return;
    }
    let prims = Prims { spheres, sphere_count: params.spheres, triangles, triangle_count: params.n - params.spheres };
    let w_box = nodes[m as usize].aabb();
    let origin = w_box.min;
    let e = [
        grid_exponent(w_box.min[0], w_box.max[0]),
        grid_exponent(w_box.min[1], w_box.max[1]),
        grid_exponent(w_box.min[2], w_box.max[2]),
    ];
    let step = [grid_step(e[0]), grid_step(e[1]), grid_step(e[2])];
    let mut out = WideNode {
        origin,
        child_base: 1 + child_offsets[m as usize],
        prim_base: prim_offsets[m as usize],
        ..Default::default()
    };
    let mut imask = 0u32;
    let mut prim_offset = 0u32;
    for s in 0..WIDTH {
        let c = slots[m as usize * WIDTH + s];
        if c == u32::MAX {
            continue;
        }
        let node = c & !CHILD_LEAF;
        let b = nodes[node as usize].aabb();
        let (word, shift) = (s / 4, 8 * (s % 4) as u32);
        let (lx, hx) = (quantize_lo(b.min[0], origin[0], step[0]), quantize_hi(b.max[0], origin[0], step[0]));
        let (ly, hy) = (quantize_lo(b.min[1], origin[1], step[1]), quantize_hi(b.max[1], origin[1], step[1]));
        let (lz, hz) = (quantize_lo(b.min[2], origin[2], step[2]), quantize_hi(b.max[2], origin[2], step[2]));
        out.lo_x[word] |= lx << shift;
        out.hi_x[word] |= hx << shift;
        out.lo_y[word] |= ly << shift;
        out.hi_y[word] |= hy << shift;
        out.lo_z[word] |= lz << shift;
        out.hi_z[word] |= hz << shift;
        let meta = if c & CHILD_LEAF == 0 {
            imask |= 1 << s;
            META_INTERNAL | (24 + s as u32)
        } else {
            // The leaf's primitives, left to right, from its first slot on.
            let first = prim_offset;
            let mut stack = [0u32; 4];
            stack[0] = node;
            let mut top = 1usize;
            while top > 0 {
                top -= 1;
                let x = nodes[get(&stack, top) as usize];
                if x.is_leaf() {
                    let slot = out.prim_base + prim_offset;
                    out_prims.store(slot as usize, &prims.leaf_prim(prim_indices[x.left as usize]));
                    prim_offset += 1;
                } else if top + 2 <= 4 {
                    set(&mut stack, top, x.right);
                    set(&mut stack, top + 1, x.left);
                    top += 2;
                }
            }
            let unary = (1u32 << (prim_offset - first)) - 1;
            unary << 5 | first
        };
        out.meta[word] |= meta << shift;
    }
    out.exp_imask = e[0] | e[1] << 8 | e[2] << 16 | imask << 24;
    out_nodes.store(positions[m as usize] as usize, &out);
}
