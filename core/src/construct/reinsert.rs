//! Parallel reinsertion (Meister & Bittner 2018, "Parallel Reinsertion for
//! Bounding Volume Hierarchy Optimization"): every node looks, all at once,
//! for the place in the tree where moving it lowers the tree's summed
//! surface area the most; the moves that no better move shares a node with
//! are made together; the boxes are refit ([`crate::construct::fit::refit_nodes_kernel`]);
//! and again. Moves reach anywhere in the tree, where treelet
//! restructuring only reshapes seven-leaf neighbourhoods: a large node
//! that the Morton order put in the wrong corner is moved out of it.
//!
//! The search is theirs (as madmann91/bvh and obvhs write it): from the
//! node's parent up to the root, and at each ancestor down into its other
//! child's subtree, pruned once no place below can beat the best gain.
//! The gain of moving `N` (parent `P`, sibling `S`) to become the sibling
//! of `X` is exact for the sum of areas:
//!
//! ```text
//!   area(P)                                  P is removed
//! + sum over P's ancestors A below the      A loses N: its box shrinks
//!   lowest common ancestor of N and X:
//!   area(A) - area(A without N)
//! - area(N ∪ X)                              the new parent of N and X
//! - sum over X's ancestors B below it:       B gains N
//!   area(B ∪ N) - area(B)
//! ```
//!
//! Conflicts: a move rewrites links of six nodes (`N`, `P`, `S`, `P`'s
//! parent, `X`, `X`'s parent). Each move bids its gain on its six nodes
//! (atomic max), then those that won all six claim them by index (atomic
//! min, for ties), and the moves that hold all six are made: no two made
//! moves share a node, so each reads and writes only its own.
//!
//! The tree keeps the LBVH layout (root 0, leaf `j` at `n - 1 + j`): only
//! internal nodes change place, and a move that would move the root (`P`
//! the root) is not made.
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{INVALID, Node, Reinsertion, ReinsertParams};
use crate::geometry::records::RecordLoad;
use crate::geometry::split::SplitMut;
use crate::gpu::atomics;
use crate::gpu::unchecked::scratch;

/// Entries of a search's private stack: a subtree is searched to this
/// depth below the path (deeper places are not looked at; the move found
/// is still exact, only perhaps not the best).
pub const SEARCH_STACK: usize = 48;

/// Half the surface area of `b` scaled by `s` (which keeps f32 areas of
/// huge scenes finite), with explicit fused multiply-adds so that the GPU
/// and the CPU compute the same gains (see [`Aabb::surface_area`]).
#[inline]
fn area(b: &Aabb, s: f32) -> f32 {
    let d = b.extent() * s;
    libm::fmaf(d.x, d.y, libm::fmaf(d.y, d.z, d.z * d.x))
}

/// The child of `node` that is not `child`.
#[inline]
fn other_child(node: &Node, child: u32) -> u32 {
    if node.left == child { node.right } else { node.left }
}

/// Kernel, one invocation per node but the root (`2n - 2`): node `i + 1`'s
/// best move, into `moves[i]`.
pub fn search_kernel<N: RecordLoad<Node> + ?Sized>(
    i: u32,
    params: &ReinsertParams,
    nodes: &N,
    parents: &[u32],
    moves: &mut [Reinsertion],
) {
    let n = params.n;
    if n < 3 || i >= 2 * n - 2 {
        return;
    }
    moves[i as usize] = best_move(i + 1, params.inv_extent, params.max_climb, nodes, parents);
}

/// The move of node `from` that lowers the summed area most, if any,
/// searching below at most `max_climb` of its ancestors, its parent first
/// (0: all of them).
pub fn best_move<N: RecordLoad<Node> + ?Sized>(from: u32, s: f32, max_climb: u32, nodes: &N, parents: &[u32]) -> Reinsertion {
    let none = Reinsertion { from, to: INVALID, gain: 0.0, _pad: 0 };
    let parent = parents[from as usize];
    if parent == 0 || parent == INVALID {
        return none;
    }
    let own = nodes.load(from as usize).aabb();
    let own_area = area(&own, s);
    let parent_node = nodes.load(parent as usize);
    let first_sibling = other_child(&parent_node, from);
    let (mut best, mut best_to) = (0.0f32, INVALID);
    // Gain so far from the removal: P's area, then each ancestor's shrink.
    let mut removal = area(&parent_node.aabb(), s);
    // The box of the pivot's subtree without `from`.
    let mut without = nodes.load(first_sibling as usize).aabb();
    let (mut pivot, mut sibling) = (parent, first_sibling);
    let mut gains: [f32; SEARCH_STACK] = scratch();
    let mut places: [u32; SEARCH_STACK] = scratch();
    let mut climbed = 0u32;
    loop {
        // Down the pivot's other subtree: each entry is the gain left once
        // the boxes above it have grown to hold `from`.
        gains[0] = removal;
        places[0] = sibling;
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let (left_over, x) = (gains[top], places[top]);
            // No place below can cost less than `from`'s own area.
            if left_over - own_area <= best {
                continue;
            }
            let node = nodes.load(x as usize);
            let node_box = node.aabb();
            let node_area = area(&node_box, s);
            let gain = left_over - area(&node_box.union(&own), s);
            if gain > best {
                best = gain;
                best_to = x;
            }
            if !node.is_leaf() && top + 2 <= SEARCH_STACK {
                // Below `x`, `x` itself grows to hold `from`.
                let below = gain + node_area;
                gains[top] = below;
                places[top] = node.left;
                gains[top + 1] = below;
                places[top + 1] = node.right;
                top += 2;
            }
        }
        if pivot != parent {
            // Above the subtree just searched, the pivot loses `from`.
            without = without.union(&nodes.load(sibling as usize).aabb());
            removal += area(&nodes.load(pivot as usize).aabb(), s) - area(&without, s);
        }
        if pivot == 0 || climbed == max_climb.wrapping_sub(1) {
            break;
        }
        climbed += 1;
        let up = parents[pivot as usize];
        sibling = other_child(&nodes.load(up as usize), pivot);
        pivot = up;
    }
    if best_to == INVALID || best_to == first_sibling {
        return none;
    }
    Reinsertion { from, to: best_to, gain: best, _pad: 0 }
}

/// The six nodes a move rewrites links of: `from`, its parent, sibling and
/// grandparent, `to` and its parent.
#[inline]
fn touched<N: RecordLoad<Node> + ?Sized>(m: &Reinsertion, nodes: &N, parents: &[u32]) -> [u32; 6] {
    let parent = parents[m.from as usize];
    let sibling = other_child(&nodes.load(parent as usize), m.from);
    [m.from, parent, sibling, parents[parent as usize], m.to, parents[m.to as usize]]
}

/// Move `i`, unless `i` is past the moves or its node found none.
#[inline]
fn proposed(i: u32, params: &ReinsertParams, moves: &[Reinsertion]) -> Option<Reinsertion> {
    if params.n < 3 || i >= 2 * params.n - 2 {
        return None;
    }
    let m = moves[i as usize];
    (m.to != INVALID).then_some(m)
}

/// Whether the bid on each node of `set` is `bits` (the move's own).
/// Index loops: rust-gpu compiles no array iterators.
#[inline]
fn won_bids(set: &[u32; 6], bids: &[u32], bits: u32) -> bool {
    let mut k = 0;
    while k < 6 {
        if bids[set[k] as usize] != bits {
            return false;
        }
        k += 1;
    }
    true
}

/// Kernel, one invocation per move: bids the move's gain on its nodes
/// (`bids` zeroed; a positive f32's bits order as the float).
pub fn bid_kernel<N: RecordLoad<Node> + ?Sized>(
    i: u32,
    params: &ReinsertParams,
    nodes: &N,
    parents: &[u32],
    moves: &[Reinsertion],
    bids: &mut [u32],
) {
    let Some(m) = proposed(i, params, moves) else { return };
    let set = touched(&m, nodes, parents);
    for k in 0..6 {
        atomics::max_device(&mut bids[set[k] as usize], m.gain.to_bits());
    }
}

/// Kernel, one invocation per move: a move that won the bid on each of its
/// nodes claims them with its index (`owners` filled with `u32::MAX`), so
/// that of equal bids one wins.
pub fn claim_kernel<N: RecordLoad<Node> + ?Sized>(
    i: u32,
    params: &ReinsertParams,
    nodes: &N,
    parents: &[u32],
    moves: &[Reinsertion],
    bids: &[u32],
    owners: &mut [u32],
) {
    let Some(m) = proposed(i, params, moves) else { return };
    let set = touched(&m, nodes, parents);
    if !won_bids(&set, bids, m.gain.to_bits()) {
        return;
    }
    for k in 0..6 {
        atomics::min_device(&mut owners[set[k] as usize], i);
    }
}

/// Kernel, one invocation per move: makes the moves that won their nodes'
/// bids and claims, and counts them in `made[params.iteration]`. `from`'s
/// parent `P` is reused as the new parent of `from` and `to`; `from`'s
/// sibling takes `P`'s place. Boxes above are stale until the refit.
#[allow(clippy::too_many_arguments)]
pub fn apply_kernel(
    i: u32,
    params: &ReinsertParams,
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    moves: &[Reinsertion],
    bids: &[u32],
    owners: &[u32],
    made: &mut [u32],
) {
    let Some(m) = proposed(i, params, moves) else { return };
    let set = touched(&m, &*nodes, &*parents);
    if !won_bids(&set, bids, m.gain.to_bits()) {
        return;
    }
    for k in 0..6 {
        if owners[set[k] as usize] != i {
            return;
        }
    }
    let [from, parent, sibling, grandparent, to, to_parent] = set;
    // The sibling takes the parent's place.
    nodes.with_mut(grandparent as usize, |g| {
        if g.left == parent { g.left = sibling } else { g.right = sibling }
    });
    parents[sibling as usize] = grandparent;
    // The parent goes between `to` and its parent (which may now be the
    // grandparent, or the sibling).
    nodes.with_mut(to_parent as usize, |t| {
        if t.left == to { t.left = parent } else { t.right = parent }
    });
    parents[parent as usize] = to_parent;
    nodes.with_mut(parent as usize, |p| {
        p.left = from;
        p.right = to;
    });
    parents[to as usize] = parent;
    atomics::add_device(&mut made[params.iteration as usize], 1);
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::construct::sah::{SahCosts, sah_cost};
    use std::vec::Vec;

    /// One iteration on the CPU, as the host schedules it: search, bid,
    /// claim, apply, then boxes refit from the leaves (recursively here).
    fn iterate(nodes: &mut Vec<Node>, parents: &mut Vec<u32>, n: u32, max_climb: u32) -> u32 {
        let p = ReinsertParams { n, iteration: 0, inv_extent: 1.0, max_climb };
        let count = 2 * n - 2;
        let mut moves = std::vec![Reinsertion::default(); count as usize];
        for i in 0..count {
            search_kernel(i, &p, nodes.as_slice(), parents, &mut moves);
        }
        let mut bids = std::vec![0u32; nodes.len()];
        for i in 0..count {
            bid_kernel(i, &p, nodes.as_slice(), parents, &moves, &mut bids);
        }
        let mut owners = std::vec![u32::MAX; nodes.len()];
        for i in 0..count {
            claim_kernel(i, &p, nodes.as_slice(), parents, &moves, &bids, &mut owners);
        }
        let mut made = [0u32; 1];
        for i in 0..count {
            apply_kernel(i, &p, &mut SplitMut::whole(nodes.as_mut_slice()), parents, &moves, &bids, &owners, &mut made);
        }
        refit(nodes, 0);
        made[0]
    }

    fn refit(nodes: &mut Vec<Node>, v: u32) -> Aabb {
        let node = nodes[v as usize];
        if node.is_leaf() {
            return node.aabb();
        }
        let b = refit(nodes, node.left).union(&refit(nodes, node.right));
        nodes[v as usize].set_aabb(b);
        b
    }

    /// A tree in the LBVH layout over `boxes` that pairs them badly: leaves
    /// in a shuffled order, merged as a balanced tree.
    fn bad_tree(boxes: &[Aabb]) -> (Vec<Node>, Vec<u32>) {
        let n = boxes.len() as u32;
        let mut nodes = std::vec![Node::default(); 2 * n as usize - 1];
        let mut parents = std::vec![INVALID; 2 * n as usize - 1];
        for (j, b) in boxes.iter().enumerate() {
            let leaf = &mut nodes[n as usize - 1 + j];
            leaf.set_aabb(*b);
            leaf.left = j as u32;
            leaf.right = crate::geometry::buffers::LEAF_BIT | 1;
        }
        // Leaves visited in a scrambled order, merged pairwise level by level.
        let mut level: Vec<u32> = (0..n).map(|j| n - 1 + (j * 7919 % n)).collect();
        let mut next_internal = n - 2;
        while level.len() > 1 {
            let mut up = Vec::new();
            for pair in level.chunks(2) {
                if pair.len() == 1 {
                    up.push(pair[0]);
                    continue;
                }
                let v = if level.len() == 2 { 0 } else { let v = next_internal; next_internal -= 1; v };
                nodes[v as usize].left = pair[0];
                nodes[v as usize].right = pair[1];
                parents[pair[0] as usize] = v;
                parents[pair[1] as usize] = v;
                up.push(v);
            }
            level = up;
        }
        refit(&mut nodes, 0);
        (nodes, parents)
    }

    fn check_tree(nodes: &[Node], parents: &[u32], n: u32) {
        let mut seen = std::vec![false; nodes.len()];
        let mut stack = std::vec![0u32];
        let mut leaves = 0;
        assert_eq!(parents[0], INVALID);
        while let Some(v) = stack.pop() {
            assert!(!seen[v as usize], "node {v} reached twice");
            seen[v as usize] = true;
            let node = nodes[v as usize];
            if node.is_leaf() {
                assert!(v >= n - 1, "leaf at {v}");
                leaves += 1;
                continue;
            }
            for c in [node.left, node.right] {
                assert_eq!(parents[c as usize], v, "parent of {c}");
                let b = nodes[c as usize].aabb();
                assert!(node.aabb().contains(&b), "box of {v} does not hold {c}");
                stack.push(c);
            }
        }
        assert_eq!(leaves, n);
        assert!(seen.iter().all(|&s| s), "a node fell out of the tree");
    }

    #[test]
    fn reinsertion_keeps_a_valid_tree_and_lowers_its_area() {
        for (n, max_climb) in [(3u32, 0), (4, 0), (5, 0), (17, 0), (100, 0), (1000, 0), (17, 1), (1000, 1), (1000, 4)] {
            let boxes: Vec<Aabb> = (0..n)
                .map(|j| {
                    let x = (j * 37 % 101) as f32;
                    let y = (j * 11 % 13) as f32;
                    let size = 1.0 + (j % 5) as f32 * 3.0;
                    Aabb::new(glam::Vec3::new(x, y, 0.0), glam::Vec3::new(x + size, y + 1.0, 1.0))
                })
                .collect();
            let (mut nodes, mut parents) = bad_tree(&boxes);
            let area_sum = |nodes: &[Node]| -> f64 {
                let mut sum = 0.0;
                let mut stack = std::vec![0u32];
                while let Some(v) = stack.pop() {
                    let node = nodes[v as usize];
                    sum += node.aabb().half_area_f64();
                    if !node.is_leaf() {
                        stack.push(node.left);
                        stack.push(node.right);
                    }
                }
                sum
            };
            let (before, sah_before) = (area_sum(&nodes), sah_cost(&nodes, SahCosts::KARRAS_AILA));
            let mut total = 0;
            for _ in 0..8 {
                let made = iterate(&mut nodes, &mut parents, n, max_climb);
                check_tree(&nodes, &parents, n);
                total += made;
            }
            let (after, sah_after) = (area_sum(&nodes), sah_cost(&nodes, SahCosts::KARRAS_AILA));
            assert!(after <= before * (1.0 + 1e-6), "n {n}, climb {max_climb}: area {before} -> {after}");
            if n >= 17 {
                assert!(total > 0 && after < before * 0.95, "n {n}: {total} moves, area {before} -> {after}");
                assert!(sah_after < sah_before, "n {n}: SAH {sah_before} -> {sah_after}");
            }
        }
    }

    /// The gain a search reports is the drop in the summed area the move
    /// makes, once made alone and refit.
    #[test]
    fn a_moves_gain_is_its_drop_in_area() {
        let n = 64u32;
        let boxes: Vec<Aabb> = (0..n)
            .map(|j| {
                let x = (j * 29 % 64) as f32 * 2.0;
                Aabb::new(glam::Vec3::new(x, 0.0, 0.0), glam::Vec3::new(x + 1.0 + (j % 3) as f32, 1.0, 1.0))
            })
            .collect();
        let (nodes, parents) = bad_tree(&boxes);
        let sum = |nodes: &[Node]| -> f64 {
            let mut s = 0.0;
            let mut stack = std::vec![0u32];
            while let Some(v) = stack.pop() {
                let node = nodes[v as usize];
                s += area(&node.aabb(), 1.0) as f64;
                if !node.is_leaf() {
                    stack.push(node.left);
                    stack.push(node.right);
                }
            }
            s
        };
        let mut checked = 0;
        for from in 1..2 * n - 1 {
            let m = best_move(from, 1.0, 0, nodes.as_slice(), &parents);
            if m.to == INVALID {
                continue;
            }
            let (mut moved, mut moved_parents) = (nodes.clone(), parents.clone());
            let p = ReinsertParams { n, iteration: 0, inv_extent: 1.0, max_climb: 0 };
            let mut moves = std::vec![Reinsertion::default(); (2 * n - 2) as usize];
            moves[(from - 1) as usize] = m;
            let mut bids = std::vec![0u32; nodes.len()];
            let mut owners = std::vec![u32::MAX; nodes.len()];
            let i = from - 1;
            bid_kernel(i, &p, moved.as_slice(), &moved_parents, &moves, &mut bids);
            claim_kernel(i, &p, moved.as_slice(), &moved_parents, &moves, &bids, &mut owners);
            let mut made = [0u32; 1];
            apply_kernel(i, &p, &mut SplitMut::whole(moved.as_mut_slice()), &mut moved_parents, &moves, &bids, &owners, &mut made);
            assert_eq!(made[0], 1);
            refit(&mut moved, 0);
            check_tree(&moved, &moved_parents, n);
            let drop = sum(&nodes) - sum(&moved);
            assert!((drop - m.gain as f64).abs() <= 1e-3 * sum(&nodes), "node {from} to {}: gain {} drop {drop}", m.to, m.gain);
            checked += 1;
        }
        assert!(checked > 10, "{checked} moves");
    }
}
