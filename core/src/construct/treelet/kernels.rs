//! The device schedule of treelet restructuring ([`crate::construct::treelet`]).
//!
//! Before the first round, [`treelet_init_kernel`] climbs from the leaves
//! and writes every node's primitive count, SAH cost and height;
//! restructuring keeps them current, so later rounds need no new climb. A
//! round: the roots of its treelets (subtrees of at least `gamma`
//! primitives) are counted and listed by height
//! ([`treelet_histogram_phase`], [`treelet_scatter_phase`]); then one
//! dispatch per height, bottom up, restructures them
//! ([`treelet_restructure_phase`]). Nodes of one height never contain each
//! other, so one dispatch works on disjoint subtrees, and each sees the
//! subtrees below it finished.
//!
//! Restructuring is a team of 32 lanes per treelet (a slice of a workgroup,
//! so no subgroup size is assumed), as in the paper's warp-wide scheme, the
//! treelet and its DP tables in workgroup memory throughout: nothing of it
//! lives in per-invocation arrays, which GPUs keep in slow local memory
//! when indexed at run time. The result does not depend on which lane
//! solves which subset: every subset's cost is the same minimum over the
//! same partitions in the same order (for the whole treelet, whose
//! partitions the lanes share, the first of equal costs across lanes).
//!
//! What one treelet's latency is made of (H100, one treelet per dispatch,
//! `TREELET_PROFILE_LEVELS`): the launch 7 µs, forming 5 µs, the subset
//! sizes 2 to 6 about 2 µs each, the whole treelet and its plan 6 µs, the
//! rewiring 2 µs. Global reads are unchecked (`crate::gpu::unchecked`): a bounds
//! check's branch kept the GPU from issuing the next load before the last
//! one returned, which made forming 12 µs.
use crate::construct::climb::Climb;
use crate::construct::climb_queue;
use crate::construct::treelet::{PACKED_WORDS, SUBSETS, TreeletSolution, TREELET_LEAVES, TREELET_WORDS, T_CHANGED, T_COSTS, T_COUNT, T_CURRENT, T_HEIGHT, T_INTERNALS, T_REWIRE, best_whole_partition, first_cheapest, form_treelet, improves, node_cost, optimize, optimize_sized, packed_bits, plan_rewire, rewire_internal, solve_subset, subset_box, subset_count, whole_partition};
use crate::geometry::buffers::{Node, TreeletParams};
use crate::geometry::records::RecordLoad;
use crate::geometry::split::SplitMut;
use crate::gpu::atomics;
use crate::gpu::unchecked::{at, get, set};
use crate::gpu::workgroup::{WG, WORKGROUP_SIZE};

/// Levels [`treelet_init_kernel`] climbs before it queues the climbs that go
/// on for [`treelet_init_climb_kernel`] (about one leaf in eight). H100,
/// the `bvh2` layout's collapse stage of a 1M-triangle LBVH: 0.379 ms with
/// 3 levels, 0.407 to 0.420 with 1, 0.407 in one kernel; at 4M 1.23 ms
/// either way (1.26 in one kernel).
pub const INIT_FIRST_LEVELS: u32 = 3;

/// Kernel (one invocation per leaf, climbing with [`Climb`] as
/// [`crate::construct::fit`] does), the first of two: writes
/// every node's primitive count, subtree SAH cost and height (leaves 0), and
/// its number of leaves after the final collapse (1 where it collapses), an
/// internal node once both children are done. `flags` are zeroed counters.
/// Climbs at most [`INIT_FIRST_LEVELS`] levels, then queues the last node it
/// finished in `queue` (counts in the zeroed `queued`, see
/// [`crate::construct::climb_queue`]) for [`treelet_init_climb_kernel`],
/// whose subgroups are then full of long climbs (H100, 1M leaves: 0.093 +
/// 0.119 ms, one kernel 0.235; `docs/results/h100-agglomerate-subgroup/`).
/// A small gain next to the hierarchy's (`crate::construct::agglomerate_subgroup`):
/// without merging within subgroups, the first kernel's subgroups still
/// wait for their slowest lane over three levels.
#[allow(clippy::too_many_arguments)]
pub fn treelet_init_kernel<const ORDERED: bool, N: RecordLoad<Node> + ?Sized>(
    i: u32,
    params: &TreeletParams,
    nodes: &N,
    parents: &[u32],
    flags: &mut [u32],
    summaries: (&mut [u32], &mut [f32], &mut [u32], &mut [u32]),
    queue: &mut [u32],
    queued: &mut [u32],
) {
    let n = params.n;
    if i >= n {
        return;
    }
    let (counts, node_costs, heights, tree_leaves) = summaries;
    let costs = params.costs();
    // Leaves are found through the tree, not by index: restructuring moves
    // internal nodes but never leaves, and leaf `i` stays at `n - 1 + i`.
    let leaf = n - 1 + i;
    let node = nodes.load(leaf as usize);
    atomics::store_u32(&mut counts[leaf as usize], node.prim_count());
    atomics::store_f32(&mut node_costs[leaf as usize], node_cost(&node, node.prim_count(), (0.0, 0.0), &costs));
    atomics::store_u32(&mut heights[leaf as usize], 0);
    atomics::store_u32(&mut tree_leaves[leaf as usize], 1);
    let mut climb = Climb::<ORDERED>::new(leaf);
    let mut levels = 0;
    while let Some(parent) = climb.next(parents, flags) {
        summarize(parent, params, nodes, (&mut *counts, &mut *node_costs, &mut *heights, &mut *tree_leaves));
        levels += 1;
        if levels == INIT_FIRST_LEVELS && parent != 0 {
            let k = climb_queue::reserve(i, n, queued, 1);
            queue[climb_queue::place(i, n, k) as usize] = parent;
            return;
        }
    }
}

/// Kernel, the second of two: the climb from the node at place `id` of
/// the queues [`treelet_init_kernel`] filled, as that kernel climbs.
#[allow(clippy::too_many_arguments)]
pub fn treelet_init_climb_kernel<const ORDERED: bool, N: RecordLoad<Node> + ?Sized>(
    id: u32,
    params: &TreeletParams,
    nodes: &N,
    parents: &[u32],
    flags: &mut [u32],
    summaries: (&mut [u32], &mut [f32], &mut [u32], &mut [u32]),
    queue: &[u32],
    queued: &[u32],
) {
    let Some(place) = climb_queue::entry(id, params.n, queued) else {
        return;
    };
    let (counts, node_costs, heights, tree_leaves) = summaries;
    let mut climb = Climb::<ORDERED>::new(queue[place as usize]);
    while let Some(parent) = climb.next(parents, flags) {
        summarize(parent, params, nodes, (&mut *counts, &mut *node_costs, &mut *heights, &mut *tree_leaves));
    }
}

/// Writes internal node `parent`'s count, cost, height and collapsed leaf
/// count from its children's.
#[inline]
fn summarize<N: RecordLoad<Node> + ?Sized>(
    parent: u32,
    params: &TreeletParams,
    nodes: &N,
    summaries: (&mut [u32], &mut [f32], &mut [u32], &mut [u32]),
) {
    let (counts, node_costs, heights, tree_leaves) = summaries;
    let costs = params.costs();
    let p = nodes.load(parent as usize);
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
}

/// Heights the level lists hold; the last slot counts deeper nodes (an
/// error for the host: traversal refuses such trees anyway). One per lane
/// of a workgroup, so that a workgroup's local histogram has a lane per bin.
pub const MAX_LEVELS: usize = WG;

/// Whether internal node `i` roots a treelet this round, and at which height.
#[inline]
fn treelet_root(i: u32, params: &TreeletParams, counts: &[u32], heights: &[u32]) -> Option<usize> {
    if params.n < 2 || i >= params.n - 1 || counts[i as usize] < params.gamma {
        return None;
    }
    Some((heights[i as usize] as usize).min(MAX_LEVELS - 1))
}

/// Phases of [`treelet_histogram_phase`].
pub const HISTOGRAM_PHASES: u32 = 3;

/// Kernel (one invocation per internal node, phase by phase): counts the
/// treelet roots of each height into `level_counts` (zeroed, [`MAX_LEVELS`]
/// entries), first within the workgroup, so that the device-wide counters
/// take one atomic per workgroup and height rather than one per root.
pub fn treelet_histogram_phase(
    phase: u32,
    lid: u32,
    group: u32,
    params: &TreeletParams,
    counts: &[u32],
    heights: &[u32],
    level_counts: &mut [u32],
    local: &mut [u32; WG],
) {
    let i = group * WORKGROUP_SIZE + lid;
    match phase {
        0 => local[lid as usize] = 0,
        1 => {
            if let Some(h) = treelet_root(i, params, counts, heights) {
                atomics::add_workgroup(&mut local[h], 1);
            }
        }
        _ => {
            let c = local[lid as usize];
            if c > 0 {
                atomics::add_device(&mut level_counts[lid as usize], c);
            }
        }
    }
}

/// Phases of [`treelet_scatter_phase`].
pub const SCATTER_PHASES: u32 = 4;

/// Kernel (one invocation per internal node, phase by phase): appends each
/// treelet root to its height's list; `cursors` start at each list's
/// offset. A workgroup reserves one range per height and fills it. Order
/// within a list does not matter: the treelets of one height are disjoint.
#[allow(clippy::too_many_arguments)]
pub fn treelet_scatter_phase(
    phase: u32,
    lid: u32,
    group: u32,
    params: &TreeletParams,
    counts: &[u32],
    heights: &[u32],
    cursors: &mut [u32],
    roots: &mut [u32],
    local: &mut [u32; WG],
    ranks: &mut [u32; WG],
) {
    let i = group * WORKGROUP_SIZE + lid;
    let l = lid as usize;
    match phase {
        0 => local[l] = 0,
        1 => {
            if let Some(h) = treelet_root(i, params, counts, heights) {
                ranks[l] = atomics::add_workgroup(&mut local[h], 1);
            }
        }
        2 => {
            let c = local[l];
            if c > 0 {
                local[l] = atomics::add_device(&mut cursors[l], c);
            }
        }
        _ => {
            if let Some(h) = treelet_root(i, params, counts, heights) {
                roots[(local[h] + ranks[l]) as usize] = i;
            }
        }
    }
}

/// Binomial coefficient C(n, k) for n, k <= 7, from Pascal's triangle
/// packed six bits per entry, rows picked by selects (no division, no
/// branch: GPUs do both slowly).
#[inline]
pub fn binomial(n: u32, k: u32) -> u32 {
    let pick = |row: u64, i: u32, r: u64| if n == i { r } else { row };
    let mut row = 1u64;
    row = pick(row, 1, 1 | 1 << 6);
    row = pick(row, 2, 1 | 2 << 6 | 1 << 12);
    row = pick(row, 3, 1 | 3 << 6 | 3 << 12 | 1 << 18);
    row = pick(row, 4, 1 | 4 << 6 | 6 << 12 | 4 << 18 | 1 << 24);
    row = pick(row, 5, 1 | 5 << 6 | 10 << 12 | 10 << 18 | 5 << 24 | 1 << 30);
    row = pick(row, 6, 1 | 6 << 6 | 15 << 12 | 20 << 18 | 15 << 24 | 6 << 30 | 1 << 36);
    row = pick(row, 7, 1 | 7 << 6 | 21 << 12 | 35 << 18 | 35 << 24 | 21 << 30 | 7 << 36 | 1 << 42);
    if n > 7 {
        return 0;
    }
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

/// Lanes per treelet (the paper's warp). On the H100, teams of 16 or 8
/// lanes (more treelets per workgroup) were slower: the latency of one
/// treelet, not idle lanes, bounds this kernel.
pub const TEAM: u32 = 32;
/// Treelets per workgroup.
pub const TEAMS: u32 = RESTRUCTURE_THREADS / TEAM;
/// Invocations per workgroup of the team kernel (at least [`SUBSETS`]: its
/// first phase copies the subset order, an entry per invocation). Its 56
/// registers an invocation (H100) allow 36 warps an SM: 4 workgroups of 256
/// held 32 of them, 9 of 128 hold all 36 (TRBVH 1M 8.87 -> 8.60 ms, 4M 30.04
/// -> 29.25; `docs/results/h100-treelet-2026-11-27`).
pub const RESTRUCTURE_THREADS: u32 = 128;
const _: () = assert!(RESTRUCTURE_THREADS as usize >= SUBSETS);
/// Workgroup memory: the staged treelets (see [`crate::construct::treelet`]'s `T_*`
/// words), their DP costs and their packed partitions, one row per team
/// (odd strides, so that the teams' rows start on different banks).
pub const TEAM_STAGE: usize = TEAMS as usize * TREELET_WORDS;
pub const COST_ROW: usize = SUBSETS + 1;
pub const TEAM_COSTS: usize = TEAMS as usize * COST_ROW;
pub const PARTS_ROW: usize = PACKED_WORDS + 1;
pub const TEAM_PARTS: usize = TEAMS as usize * PARTS_ROW;
/// Every subset of seven leaves, by size, and within a size in colex
/// order: the subsets of `size` leaves among the first `n` are the first
/// `binomial(n, size)` of their size (colex order lists the subsets of a
/// set before any subset with a larger element). The kernel reads a
/// subset per lane from this table rather than unranking it.
pub fn subset_order() -> [u32; SUBSETS] {
    let mut out = [0u32; SUBSETS];
    let mut i = 0;
    let mut size = 0;
    while size <= TREELET_LEAVES as u32 {
        let mut rank = 0;
        while rank < binomial(TREELET_LEAVES as u32, size) {
            out[i] = subset_of_rank(rank, TREELET_LEAVES as u32, size);
            i += 1;
            rank += 1;
        }
        size += 1;
    }
    out
}

/// Where the subsets of `size` leaves start in [`subset_order`].
#[inline]
pub fn subset_order_start(size: u32) -> usize {
    // Partial sums of the binomials C(7, k), a byte each.
    const STARTS: u64 = 1 << 8 | 8 << 16 | 29 << 24 | 64 << 32 | 99 << 40 | 120 << 48 | 127 << 56;
    ((STARTS >> (8 * size)) & 0xff) as usize
}

/// A node's mark: the round in which its subtree last changed (shifted
/// left by one; 0 before the first), and in bit 0 whether the treelet
/// rooted at it was solved and kept since (nothing cheaper): such a treelet
/// is skipped while no subtree under it changes.
#[inline]
fn mark(changed_round: u32, kept: bool) -> u32 {
    (changed_round << 1) | kept as u32
}

/// Whether treelet `root` is solved this round (`params.round`): `None`
/// where it was kept in an earlier round and nothing under it changed
/// since (with `params.skip_kept`), else the round its subtree last
/// changed in: this one if anything under it did.
#[inline]
fn changed_round<NS: RecordLoad<Node> + ?Sized>(root: u32, params: &TreeletParams, nodes: &NS, marks: &[u32]) -> Option<u32> {
    let round = params.round;
    let r = nodes.load(root as usize);
    let below = at(marks, r.left as usize) >> 1 == round || at(marks, r.right as usize) >> 1 == round;
    let old = at(marks, root as usize);
    if params.skip_kept == 1 && old & 1 == 1 && !below {
        return None;
    }
    Some(if below { round } else { old >> 1 })
}

/// Keeps treelet `root` as it is: its current cost and height, marked kept.
#[inline]
fn keep(
    root: u32,
    cost: f32,
    height: u32,
    changed: u32,
    node_costs: &mut [f32],
    heights: &mut [u32],
    marks: &mut [u32],
) {
    node_costs[root as usize] = cost;
    heights[root as usize] = height;
    marks[root as usize] = mark(changed, true);
}

// Phases of [`treelet_restructure_phase`]: form; one per subset size 2..=7
// (the whole treelet's partitions dealt to all lanes); choose the whole
// treelet's best partition and plan the rewiring; rewire.
const P_CHOOSE: u32 = 7;
const P_REWIRE: u32 = 8;
pub const RESTRUCTURE_PHASES: u32 = P_REWIRE + 1;
/// Lanes that share the whole treelet's partitions (up to 63), each
/// keeping its cheapest for one lane to compare: few, so that comparing is
/// short, yet enough that each share is. On the H100 (1M random spheres,
/// gamma 3) comparing all 32 lanes' shares took 0.36 to 0.71 of the first
/// round's 3.83 ms above height 2; with 8 voters TRBVH 1M 9.22 -> 8.88 ms,
/// 4M 31.35 -> 29.95 (`docs/results/h100-treelet-2026-11-27`).
pub const VOTERS: u32 = 8;
/// Workgroup memory for each lane's best partition of the whole treelet
/// (cost bits, then partition number), per team.
pub const TEAM_VOTES: usize = TEAMS as usize * 2 * VOTERS as usize;

/// Kernel ([`TEAMS`] teams of [`TEAM`] lanes per workgroup, phase by
/// phase): restructures the treelets of `roots[level_offset..][..level_count]`,
/// one per team. One lane forms the treelet into workgroup memory; the team
/// solves the subsets of one size per phase, dealt round-robin to its lanes
/// (`subsets` is [`subset_order`], copied to `order`), and the whole
/// treelet's partitions dealt to [`VOTERS`] lanes (their best in `votes`); one lane
/// picks the best of those and, if that lowers the treelet's cost, plans the
/// new topology, which a lane per internal node rewires, or else it stores
/// the root's current cost and height. `marks` (see
/// `mark`; zeroed before the first round) let later rounds skip treelets
/// that were kept and under which nothing changed: every node whose
/// subtree changes this round is a treelet root or inside a rewired
/// treelet (changes only come from treelets, whose roots have at least
/// `gamma` primitives, as have all their ancestors), so a change reaches
/// the marks of the children of every root above it before that root is
/// processed.
#[allow(clippy::too_many_arguments)]
pub fn treelet_restructure_phase(
    phase: u32,
    lid: u32,
    group: u32,
    params: &TreeletParams,
    roots: &[u32],
    subsets: &[u32],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &mut [u32],
    marks: &mut [u32],
    stage: &mut [u32; TEAM_STAGE],
    cost: &mut [f32; TEAM_COSTS],
    parts: &mut [u32; TEAM_PARTS],
    order: &mut [u32; SUBSETS],
    votes: &mut [u32; TEAM_VOTES],
) {
    let round = params.round;
    let team = lid / TEAM;
    let lane = lid % TEAM;
    let index = group * TEAMS + team;
    let (b, cb, pb) = (team as usize * TREELET_WORDS, team as usize * COST_ROW, team as usize * PARTS_ROW);
    let costs = params.costs();
    if phase == 0 {
        // The subset order, into workgroup memory once for all phases.
        if (lid as usize) < SUBSETS {
            order[lid as usize] = at(subsets, lid as usize);
        }
        let mut w = lane as usize;
        while w < PACKED_WORDS {
            parts[pb + w] = 0;
            w += TEAM as usize;
        }
        if lane != 0 {
            return;
        }
        stage[b + T_COUNT] = 0;
        if index >= params.level_count {
            return;
        }
        let root = at(roots, (params.level_offset + index) as usize);
        let Some(changed) = changed_round(root, params, nodes, marks) else {
            return; // kept, and nothing under it changed: it would be kept again
        };
        stage[b + T_CHANGED] = changed;
        let f = form_treelet(root, nodes, counts, node_costs, heights, &costs, stage, b);
        if f.leaf_count < 3 {
            // Two leaves: only one tree, nothing for the team to solve.
            keep(root, f.current, f.height, changed, node_costs, heights, marks);
            stage[b + T_COUNT] = 0;
            return;
        }
        let mut k = 0;
        while k < f.leaf_count as usize {
            cost[cb + (1 << k)] = f32::from_bits(stage[b + T_COSTS + k]);
            k += 1;
        }
        return;
    }
    let n = stage[b + T_COUNT];
    if n == 0 {
        return;
    }
    let vb = team as usize * 2 * VOTERS as usize;
    if phase < P_CHOOSE {
        let size = phase + 1;
        if size > n {
            return;
        }
        if size == n {
            // The whole treelet, after every smaller subset: its many
            // partitions dealt to the first VOTERS lanes, the best of each
            // kept (the first of equal costs) for the next phase to
            // choose from.
            if lane < VOTERS {
                let (best, m) = best_whole_partition(n, lane, VOTERS, cost, cb);
                votes[vb + lane as usize] = best.to_bits();
                votes[vb + (VOTERS + lane) as usize] = m;
            }
            return;
        }
        // Subsets of one size, dealt round-robin to the lanes.
        let (start, total) = (subset_order_start(size), binomial(n, size));
        let mut rank = lane;
        while rank < total {
            let s = get(order, start + rank as usize);
            let area = costs.area(&subset_box(s, n, stage, b));
            let p = solve_subset(s, cb, area, subset_count(s, n, stage, b), cost, &costs);
            atomics::or_workgroup(&mut parts[pb + (s / 4) as usize], packed_bits(s, p));
            rank += TEAM;
        }
        return;
    }
    if phase == P_CHOOSE {
        if lane == 0 {
            // The voters' best partitions: the cheapest, the first of equal
            // costs, as one lane enumerating them all would find.
            let mut vote = (f32::MAX, u32::MAX);
            let mut l = 0;
            while l < VOTERS as usize {
                let lane_vote = (f32::from_bits(get(votes, vb + l)), get(votes, vb + VOTERS as usize + l));
                vote = first_cheapest(vote, lane_vote);
                l += 1;
            }
            let (best, best_m) = vote;
            let full = (1u32 << n) - 1;
            let p = if best_m == u32::MAX { 0 } else { whole_partition(best_m) };
            let area = costs.area(&subset_box(full, n, stage, b));
            set(cost, cb + full as usize, costs.subtree(area, subset_count(full, n, stage, b), best));
            atomics::or_workgroup(&mut parts[pb + (full / 4) as usize], packed_bits(full, p));
            // Rewire the treelet if that lowers its cost.
            let current = f32::from_bits(stage[b + T_CURRENT]);
            let rewire = improves(cost[cb + full as usize], current);
            if rewire {
                plan_rewire(stage, b, parts, pb);
            } else {
                let root = stage[b + T_INTERNALS];
                keep(root, current, stage[b + T_HEIGHT], stage[b + T_CHANGED], node_costs, heights, marks);
            }
            stage[b + T_REWIRE] = rewire as u32;
        }
        return;
    }
    if lane < n - 1 && stage[b + T_REWIRE] == 1 {
        rewire_internal(lane as usize, stage, b, cost, cb, nodes, parents, counts, node_costs, heights);
        // A new subtree, not solved as a treelet root yet.
        marks[stage[b + T_INTERNALS + lane as usize] as usize] = mark(round, false);
    }
}

/// Kernel: restructures treelet `id` of `roots[level_offset..][..level_count]`
/// in one invocation, with the same decisions as
/// [`treelet_restructure_phase`] (the same marks, and the same DP:
/// [`crate::construct::treelet::optimize`], which the team's phases split
/// over lanes; `tests/treelet.rs` checks that they agree node for node).
///
/// For heights of many small treelets (near the leaves a treelet has few
/// leaves, and there are hundreds of thousands of them): a team of
/// [`TEAM`] lanes through [`RESTRUCTURE_PHASES`] barriers is latency per
/// treelet, where one invocation per treelet keeps the GPU full. Its DP
/// tables live in the invocation's private memory.
#[allow(clippy::too_many_arguments)]
pub fn treelet_restructure_single(
    id: u32,
    params: &TreeletParams,
    roots: &[u32],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &mut [u32],
    marks: &mut [u32],
) {
    if id >= params.level_count {
        return;
    }
    let root = at(roots, (params.level_offset + id) as usize);
    let Some(changed) = changed_round(root, params, nodes, marks) else {
        return; // kept, and nothing under it changed: it would be kept again
    };
    let costs = params.costs();
    let mut stage = [0u32; TREELET_WORDS];
    let f = form_treelet(root, nodes, counts, node_costs, heights, &costs, &mut stage, 0);
    // Tables as large as the treelet needs: at height 2 (the default
    // schedule's only one here) a treelet has at most four leaves, whose
    // tables are an eighth of seven leaves' in private memory (H100, the
    // 225 526 treelets of height 2 of 1M spheres: 0.450 -> 0.305 ms).
    let rewired = if f.leaf_count < 3 {
        false
    } else if f.leaf_count <= SMALL_LEAVES {
        let sol = optimize_sized::<_, SMALL_SUBSETS, SMALL_PACKED_WORDS>(&stage, 0, &costs);
        rewire_if_cheaper(&sol, f.leaf_count, f.current, params.round, &mut stage, nodes, parents, counts, node_costs, heights, marks)
    } else {
        let sol = optimize(&stage, 0, &costs);
        rewire_if_cheaper(&sol, f.leaf_count, f.current, params.round, &mut stage, nodes, parents, counts, node_costs, heights, marks)
    };
    if !rewired {
        // Two leaves (only one tree), or nothing cheaper.
        keep(root, f.current, f.height, changed, node_costs, heights, marks);
    }
}

/// Leaves, subsets and packed partition words of the small tables of
/// [`treelet_restructure_single`].
const SMALL_LEAVES: u32 = 4;
const SMALL_SUBSETS: usize = 1 << SMALL_LEAVES;
const SMALL_PACKED_WORDS: usize = SMALL_SUBSETS / 4;

/// Rewires the treelet staged at 0 into the tree `sol` describes if that
/// costs less than `current`; whether it did.
#[allow(clippy::too_many_arguments)]
#[inline]
fn rewire_if_cheaper<const C: usize, const P: usize>(
    sol: &TreeletSolution<C, P>,
    leaf_count: u32,
    current: f32,
    round: u32,
    stage: &mut [u32; TREELET_WORDS],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    counts: &mut [u32],
    node_costs: &mut [f32],
    heights: &mut [u32],
    marks: &mut [u32],
) -> bool {
    if !improves(get(&sol.cost, (1usize << leaf_count) - 1), current) {
        return false;
    }
    plan_rewire(stage, 0, &sol.parts, 0);
    let mut k = 0;
    while k + 1 < leaf_count as usize {
        rewire_internal(k, stage, 0, &sol.cost, 0, nodes, parents, counts, node_costs, heights);
        // A new subtree, not solved as a treelet root yet.
        marks[stage[T_INTERNALS + k] as usize] = mark(round, false);
        k += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

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
    fn subset_order_lists_each_size_from_its_start() {
        let order = subset_order();
        for n in 1..=TREELET_LEAVES as u32 {
            for size in 1..=n {
                let start = subset_order_start(size);
                let mut got: Vec<u32> = order[start..start + binomial(n, size) as usize].to_vec();
                assert!(got.iter().all(|s| s.count_ones() == size && *s < (1 << n)), "n {n} size {size}");
                got.sort();
                got.dedup();
                assert_eq!(got.len() as u32, binomial(n, size), "n {n} size {size}");
            }
        }
        assert_eq!(subset_order_start(TREELET_LEAVES as u32), SUBSETS - 1);
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

}
