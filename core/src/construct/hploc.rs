//! H-PLOC: hierarchical parallel locally-ordered clustering (Benthin,
//! Meister, Barczak, Mehalwal, Tsakok, Kensler, HPG 2024), over the sorted
//! Morton codes of the LBVH, in one dispatch.
//!
//! Each invocation climbs from its leaf as in Apetrei's agglomerative build
//! ([`super::agglomerate`]): at each split the first of the two children's
//! climbs stops and the second goes on with the parent's range of leaves.
//! Unlike there, a range is not one node: it holds up to `T` = half the
//! subgroup's size *clusters* (finished subtrees). When the range a lane
//! reaches holds more than `T` leaves, its subgroup merges the clusters of
//! the range's two halves (at most `2T`, one per lane) PLOC-fashion: each
//! cluster finds the cluster whose merged box has the smallest surface
//! area, and the pairs that find each other merge, until at most `T` are
//! left (one at the root). Merging nearest neighbours instead of following
//! the Morton order's splits is what makes the tree better than the LBVH's
//! (PLOC, Meister & Bittner 2018), and confining each merge to one
//! subgroup's registers and workgroup memory is what makes it fast.
//!
//! **Where clusters live between merges.** A finished range `[a, b]` keeps
//! its `c` clusters at `lists[a..a + c]`, and the count at `lists[2n + a]`.
//! A range of at most `T` leaves is never merged and stores nothing: its
//! clusters are its leaves.
//!
//! **Deterministic node numbering** (no allocation counter, so that the GPU
//! and the CPU runner build the same nodes, and the root is node 0 as
//! everything after the build expects). Each split `s` (between sorted keys
//! `s` and `s + 1`) is an internal node's slot, `n - 1` slots for `n - 1`
//! nodes. A range of `c` clusters owns `c - 1` free slots, kept sorted at
//! `lists[n + a..n + a + c - 1]`; a range never merged owns its splits
//! `a..b`. Merging two halves concatenates left's free slots, the split
//! between them, and right's: sorted again, as every slot of the left half
//! is below the split and every slot of the right above. Each merge takes
//! the highest free slots, so the lowest stays until the range holds one
//! cluster, and only the root's range gets there: a round at most halves
//! the clusters, so a range of more than `T` >= 2 stops at 2 or more. The
//! root's last merge takes slot 0. Hence subgroups of at least
//! [`MIN_SUBGROUP_SIZE`] lanes (every GPU's; the host checks).
//!
//! The kernel is written in steps ([`crate::gpu::subgroup`]); their order
//! depends on the data (how many lanes reach a range to merge, how many
//! rounds of merging a range takes), so it is given once, by the macro
//! [`hploc_schedule!`](crate::hploc_schedule), which the shader's entry point and the CPU runner
//! both expand, with the step and the subgroup-uniform values their own way.
//! The trees depend on the subgroup size (through `T`); the GPU and the CPU
//! runner at the same size build the same nodes, bit for bit.
use crate::construct::agglomerate::{parent_side, write_parent};
use crate::construct::climb::second_arrival_exchange;
use crate::construct::fit::{load_box, write_leaf};
use crate::construct::radix_tree::leaf_node;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::Node;
use crate::geometry::split::SplitMut;
use crate::gpu::atomics;
use crate::gpu::subgroup::{
    lanes_below, popcount, Lane, OP_BALLOT, OP_NONE, OP_SHUFFLE, THEN_STORAGE_BARRIER, THEN_SUBGROUP_BARRIER,
};
use crate::gpu::workgroup::WG;

/// Writes the leaf; the lane starts its climb.
pub const STEP_START: u32 = 0;
/// One level of every lane's climb, then a ballot of the lanes whose range
/// must be merged.
pub const STEP_CLIMB: u32 = 1;
/// The range to merge: its first leaf, last leaf and split, shuffled from
/// the lane that reached it.
pub const STEP_PICK_FIRST: u32 = 2;
pub const STEP_PICK_LAST: u32 = 3;
pub const STEP_PICK_SPLIT: u32 = 4;
/// The two halves' clusters and free slots loaded, a cluster a lane.
pub const STEP_LOAD: u32 = 5;
/// A round of merging: nearest neighbours, mutual pairs (ballot), their
/// slots (shuffle), the new nodes and who survives (ballot), compaction.
pub const STEP_NEAREST: u32 = 6;
pub const STEP_PAIRS: u32 = 7;
pub const STEP_SLOTS: u32 = 8;
pub const STEP_MERGE: u32 = 9;
pub const STEP_COMPACT: u32 = 10;
/// The range's clusters, free slots and count stored for its parent's merge.
pub const STEP_STORE: u32 = 11;
/// Ballot of the lanes still climbing.
pub const STEP_ACTIVE: u32 = 12;

/// The subgroup operation (and barrier) after each step.
#[inline]
pub const fn hploc_op(step: u32) -> u32 {
    match step {
        // What the climbing lane acquired, visible to the lanes that load it.
        STEP_CLIMB => OP_BALLOT | THEN_STORAGE_BARRIER,
        STEP_PICK_FIRST | STEP_PICK_LAST | STEP_PICK_SPLIT | STEP_SLOTS => OP_SHUFFLE,
        STEP_LOAD | STEP_NEAREST | STEP_COMPACT => OP_NONE | THEN_SUBGROUP_BARRIER,
        STEP_PAIRS | STEP_ACTIVE => OP_BALLOT,
        // Every read of the round's clusters done before compaction.
        STEP_MERGE => OP_BALLOT | THEN_SUBGROUP_BARRIER,
        // What the lanes stored, released by the climbing lane's next exchange.
        STEP_STORE => OP_NONE | THEN_STORAGE_BARRIER,
        _ => OP_NONE,
    }
}

/// Fewest lanes a subgroup needs (see the numbering above).
pub const MIN_SUBGROUP_SIZE: u32 = 4;

/// Most clusters a finished range keeps for a subgroup of `size` lanes:
/// the two halves of a range then fill the subgroup at most.
#[inline]
pub const fn cluster_limit(size: u32) -> u32 {
    size / 2
}

/// Words of the `lists` buffer for `n` primitives: clusters, free slots and
/// counts, `n` each.
pub const fn lists_words(n: u32) -> u32 {
    3 * n
}

/// The order of the steps, given once for the GPU and the CPU runner.
/// `$step!(step, arg)` runs a step on the subgroup's lanes and applies its
/// operation; `$output` is the subgroup's result of the last operation
/// (a ballot's mask), `$more` whether the range being merged holds more
/// clusters than it may keep (both the same in every lane).
#[macro_export]
macro_rules! hploc_schedule {
    ($step:ident, $output:expr, $more:expr) => {{
        $step!($crate::construct::hploc::STEP_START, 0);
        loop {
            $step!($crate::construct::hploc::STEP_CLIMB, 0);
            let mut pending: u64 = $output;
            while pending != 0 {
                let leader = $crate::gpu::subgroup::lowest_lane(pending);
                pending &= pending - 1;
                $step!($crate::construct::hploc::STEP_PICK_FIRST, leader);
                $step!($crate::construct::hploc::STEP_PICK_LAST, leader);
                $step!($crate::construct::hploc::STEP_PICK_SPLIT, leader);
                $step!($crate::construct::hploc::STEP_LOAD, leader);
                while $more {
                    $step!($crate::construct::hploc::STEP_NEAREST, 0);
                    $step!($crate::construct::hploc::STEP_PAIRS, 0);
                    $step!($crate::construct::hploc::STEP_SLOTS, 0);
                    $step!($crate::construct::hploc::STEP_MERGE, 0);
                    $step!($crate::construct::hploc::STEP_COMPACT, 0);
                }
                $step!($crate::construct::hploc::STEP_STORE, leader);
            }
            $step!($crate::construct::hploc::STEP_ACTIVE, 0);
            if $output == 0 {
                break;
            }
        }
    }};
}

/// What a lane keeps across the steps (registers on the GPU).
#[derive(Clone, Copy, Default)]
pub struct HplocLane {
    /// Still climbing: it has arrived second at every split so far.
    pub active: bool,
    /// Its range of leaves, and the split where it arrived last.
    pub l: u32,
    pub r: u32,
    pub split: u32,
    /// The range being merged (the same in every lane): first leaf, split,
    /// last leaf; its clusters now, and how many it may keep.
    pub first: u32,
    pub last: u32,
    pub mid: u32,
    pub count: u32,
    pub keep: u32,
    /// This lane's cluster of that range (lane `j` holds cluster `j`), its
    /// box, and free slot `j` of the range.
    pub cluster: u32,
    pub own: Aabb,
    pub free: u32,
    /// This round: the lane of its nearest neighbour; whether it writes the
    /// pair's node (the pair's lower lane) and whether its cluster remains.
    pub partner: u32,
    pub creates: bool,
    pub survives: bool,
}

impl HplocLane {
    /// Whether the range being merged holds more clusters than it may keep.
    #[inline]
    pub fn more(&self) -> bool {
        self.count > self.keep
    }
}

/// Words of workgroup memory for the boxes of a workgroup's lanes' clusters:
/// six floats a lane, no padding (8 KB of workgroup memory a workgroup in
/// all, not 10: one more workgroup fits an SM).
pub const SHARED_BOX_WORDS: usize = 6 * WG;
/// The workgroup's cluster boxes, six floats a lane.
pub type SharedBoxes = [f32; SHARED_BOX_WORDS];

#[inline]
fn load_shared(boxes: &SharedBoxes, i: usize) -> Aabb {
    let w = 6 * i;
    Aabb::from_arrays([boxes[w], boxes[w + 1], boxes[w + 2]], [boxes[w + 3], boxes[w + 4], boxes[w + 5]])
}

#[inline]
fn store_shared(boxes: &mut SharedBoxes, i: usize, b: &Aabb) {
    let w = 6 * i;
    for k in 0..3 {
        boxes[w + k] = b.min[k];
        boxes[w + 3 + k] = b.max[k];
    }
}

/// The surface area that orders merges; NaN (an infinite extent times a
/// zero one) as infinity, so that the order of pairs stays total and every
/// round merges at least its least pair.
#[inline]
fn merged_area(a: &Aabb, b: &Aabb) -> f32 {
    let area = a.union(b).surface_area();
    if area.is_nan() {
        f32::INFINITY
    } else {
        area
    }
}

/// Step `step` of lane `lane` (of `size`; `base` is the workgroup-local
/// index of the subgroup's lane 0) of invocation `id`, over `n` sorted
/// keys. `arg`: the lane whose range is being merged (pick and store
/// steps). `keep`: most clusters a finished range keeps (0: the most, half
/// the subgroup); `radius`: how far apart in cluster order two clusters may
/// merge (0: any). `lists`: [`lists_words`] words; `ends`: a zeroed word per split.
/// Workgroup memory (`boxes`, `clusters`, `nearest`): each subgroup uses its
/// own lanes' entries. `ORDERED` as for [`super::agglomerate::agglomerate_kernel`].
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn hploc_step<const ORDERED: bool>(
    step: u32,
    arg: u32,
    id: u32,
    lane: u32,
    size: u32,
    base: u32,
    (n, keep, radius): (u32, u32, u32),
    inputs: (&[u64], &[u32], &[Aabb]),
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    ends: &mut [u32],
    lists: &mut [u32],
    shared: (&mut SharedBoxes, &mut [u32; WG], &mut [u32; WG]),
    me: &mut HplocLane,
    io: &mut Lane,
) {
    let (keys, sorted_prims, prim_boxes) = inputs;
    let (boxes, clusters, nearest) = shared;
    let limit = cluster_limit(size);
    // At least 2 (see the numbering above), at most the limit.
    let keep = if keep == 0 { limit } else { keep.clamp(2, limit) };
    let at = (base + lane) as usize;
    if step == STEP_START {
        me.active = false;
        if id < n {
            write_leaf(id, n, sorted_prims, prim_boxes, nodes, parents);
            me.l = id;
            me.r = id;
            me.active = n > 1;
        }
    } else if step == STEP_CLIMB {
        let mut merge = false;
        if me.active {
            let left_child = parent_side(keys, n, me.l, me.r);
            let split = if left_child { me.r } else { me.l - 1 };
            let far = if left_child { me.l } else { me.r };
            match second_arrival_exchange::<ORDERED>(&mut ends[split as usize], far) {
                None => me.active = false,
                Some(other) => {
                    if left_child {
                        me.r = other;
                    } else {
                        me.l = other;
                    }
                    me.split = split;
                    let root = me.l == 0 && me.r == n - 1;
                    merge = me.r - me.l + 1 > limit || root;
                }
            }
        }
        io.input = merge as u32;
    } else if step == STEP_PICK_FIRST {
        io.input = me.l;
        io.arg = arg;
    } else if step == STEP_PICK_LAST {
        me.first = io.output as u32;
        io.input = me.r;
        io.arg = arg;
    } else if step == STEP_PICK_SPLIT {
        me.last = io.output as u32;
        io.input = me.split;
        io.arg = arg;
    } else if step == STEP_LOAD {
        me.mid = io.output as u32;
        let (first, mid, last) = (me.first, me.mid, me.last);
        // The halves: `[first, mid]` and `[mid + 1, last]`.
        let (left_leaves, right_leaves) = (mid - first + 1, last - mid);
        let left = if left_leaves <= limit { left_leaves } else { atomics::load_u32(&lists[(2 * n + first) as usize]) };
        let right =
            if right_leaves <= limit { right_leaves } else { atomics::load_u32(&lists[(2 * n + mid + 1) as usize]) };
        me.count = left + right;
        me.keep = if first == 0 && last == n - 1 { 1 } else { keep };
        let j = lane;
        if j < me.count {
            let (start, k, unmerged) =
                if j < left { (first, j, left_leaves <= limit) } else { (mid + 1, j - left, right_leaves <= limit) };
            let (cluster, b) = if unmerged {
                let i = start + k;
                (leaf_node(n, i), prim_boxes[sorted_prims[i as usize] as usize])
            } else {
                let c = atomics::load_u32(&lists[(start + k) as usize]);
                (c, nodes.with(c as usize, load_box))
            };
            clusters[at] = cluster;
            store_shared(boxes, at, &b);
        }
        if j + 1 < me.count {
            me.free = if j + 1 < left {
                if left_leaves <= limit {
                    first + j
                } else {
                    atomics::load_u32(&lists[(n + first + j) as usize])
                }
            } else if j + 1 == left {
                mid
            } else {
                let k = j - left;
                if right_leaves <= limit {
                    mid + 1 + k
                } else {
                    atomics::load_u32(&lists[(n + mid + 1 + k) as usize])
                }
            };
        }
    } else if step == STEP_NEAREST {
        // Every other cluster of the range is a candidate (at most one
        // subgroup's worth). Ties go to the pair of lower lanes, an order
        // both lanes of a pair agree on, so the least pair is always mutual.
        let j = lane;
        if j < me.count {
            let s = base as usize;
            me.own = load_shared(boxes, at);
            me.cluster = clusters[at];
            // Candidates `k` with |k - j| <= radius (0: all).
            let (low, high) = if radius == 0 {
                (0, me.count)
            } else {
                (if j > radius { j - radius } else { 0 }, (j + radius + 1).min(me.count))
            };
            let mut best = if j == low { low + 1 } else { low };
            let mut best_area = merged_area(&me.own, &load_shared(boxes, s + best as usize));
            let mut k = best + 1;
            while k < high {
                if k != j {
                    let area = merged_area(&me.own, &load_shared(boxes, s + k as usize));
                    if area < best_area {
                        best_area = area;
                        best = k;
                    }
                }
                k += 1;
            }
            nearest[at] = best;
        }
    } else if step == STEP_PAIRS {
        let j = lane;
        me.creates = false;
        me.survives = j < me.count;
        if j < me.count {
            let m = nearest[at];
            let mutual = nearest[(base + m) as usize] == j;
            me.partner = m;
            me.creates = mutual && j < m;
            me.survives = !(mutual && j > m);
        }
        io.input = me.creates as u32;
    } else if step == STEP_SLOTS {
        // The pairs take the highest free slots, the lowest pair the highest
        // (free slot `j` is held by lane `j`; there are `count - 1`).
        let rank = popcount(io.output & lanes_below(lane));
        io.input = me.free;
        io.arg = if me.creates { me.count - 2 - rank } else { 0 };
    } else if step == STEP_MERGE {
        if me.creates {
            let slot = io.output as u32;
            let other = (base + me.partner) as usize;
            let merged = me.own.union(&load_shared(boxes, other));
            // The root's last merge: two clusters left, one kept.
            let root = me.keep == 1 && me.count == 2;
            write_parent(nodes, parents, slot, me.cluster, clusters[other], &merged, root);
            me.cluster = slot;
            me.own = merged;
        }
        io.input = me.survives as u32;
    } else if step == STEP_COMPACT {
        let survivors = io.output;
        if me.survives {
            let to = (base + popcount(survivors & lanes_below(lane))) as usize;
            store_shared(boxes, to, &me.own);
            clusters[to] = me.cluster;
        }
        // The free slots left are the lowest: lanes keep theirs.
        me.count = popcount(survivors);
    } else if step == STEP_STORE {
        let (j, first) = (lane, me.first);
        if j < me.count {
            atomics::store_u32(&mut lists[(first + j) as usize], clusters[at]);
        }
        if j + 1 < me.count {
            atomics::store_u32(&mut lists[(n + first + j) as usize], me.free);
        }
        if j == 0 {
            atomics::store_u32(&mut lists[(2 * n + first) as usize], me.count);
        }
        if lane == arg && me.keep == 1 {
            me.active = false; // The root is built.
        }
    } else if step == STEP_ACTIVE {
        io.input = me.active as u32;
    }
}

/// The kernel on the CPU: the subgroup of `size` lanes whose lane 0 is
/// workgroup-local invocation `base` of workgroup `group`, run to its end
/// (no step waits on another subgroup, and the climbs meet in any order),
/// each step on every lane, then its operation emulated
/// ([`crate::gpu::subgroup::emulate`]). The CPU runner calls it for every
/// subgroup of a dispatch. Arguments as for [`hploc_step`].
#[cfg(not(target_arch = "spirv"))]
#[allow(clippy::too_many_arguments)]
pub fn hploc_subgroup_on_cpu(
    group: u32,
    base: u32,
    size: u32,
    settings: (u32, u32, u32),
    inputs: (&[u64], &[u32], &[Aabb]),
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    ends: &mut [u32],
    lists: &mut [u32],
    shared: (&mut SharedBoxes, &mut [u32; WG], &mut [u32; WG]),
) {
    use crate::gpu::subgroup::{emulate, MAX_SUBGROUP_SIZE};
    let (boxes, clusters, nearest) = shared;
    let mut lanes = [HplocLane::default(); MAX_SUBGROUP_SIZE as usize];
    let mut io = [Lane::default(); MAX_SUBGROUP_SIZE as usize];
    let (lanes, io) = (&mut lanes[..size as usize], &mut io[..size as usize]);
    macro_rules! step {
        ($step:expr, $arg:expr) => {
            for lane in 0..size {
                let id = group * crate::gpu::workgroup::WORKGROUP_SIZE + base + lane;
                let sh = (&mut *boxes, &mut *clusters, &mut *nearest);
                let (me, lane_io) = (&mut lanes[lane as usize], &mut io[lane as usize]);
                hploc_step::<true>(
                    $step, $arg, id, lane, size, base, settings, inputs, nodes, parents, ends, lists, sh, me, lane_io,
                );
            }
            emulate(hploc_op($step), io);
        };
    }
    hploc_schedule!(step, io[0].output, lanes[0].more());
}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use super::*;
    use crate::geometry::buffers::{INVALID, LEAF_BIT};
    use crate::gpu::rng::hash;
    use crate::gpu::workgroup::WORKGROUP_SIZE;
    use std::vec;
    use std::vec::Vec;

    /// Runs the kernel over `n` leaves, subgroup after subgroup, as the CPU
    /// runner does; returns nodes and parents.
    pub(crate) fn build(keys: &[u64], boxes: &[Aabb], size: u32) -> (Vec<Node>, Vec<u32>) {
        build_with(keys, boxes, size, 0, 0)
    }

    /// [`build`] with `keep` and `radius` as for [`hploc_step`].
    pub(crate) fn build_with(keys: &[u64], boxes: &[Aabb], size: u32, keep: u32, radius: u32) -> (Vec<Node>, Vec<u32>) {
        let n = keys.len() as u32;
        let prims: Vec<u32> = (0..n).collect();
        let count = (2 * n - 1) as usize;
        let (mut nodes, mut parents) = (vec![Node::default(); count], vec![0u32; count]);
        let mut ends = vec![0u32; n as usize];
        let mut lists = vec![0u32; lists_words(n) as usize];
        let mut shared = ([0f32; SHARED_BOX_WORDS], [0u32; WG], [0u32; WG]);
        let groups = n.div_ceil(WORKGROUP_SIZE);
        // Later workgroups first: the result must not depend on the order.
        for g in (0..groups).rev() {
            for base in (0..WORKGROUP_SIZE).step_by(size as usize) {
                let sh = (&mut shared.0, &mut shared.1, &mut shared.2);
                let inputs = (keys, &prims[..], boxes);
                hploc_subgroup_on_cpu(
                    g,
                    base,
                    size,
                    (n, keep, radius),
                    inputs,
                    &mut crate::geometry::split::thirds(&mut nodes),
                    &mut parents,
                    &mut ends,
                    &mut lists,
                    sh,
                );
            }
        }
        (nodes, parents)
    }

    fn random_scene(n: u32, seed: u32, duplicates: bool) -> (Vec<u64>, Vec<Aabb>) {
        let mut pts: Vec<(u64, Aabb)> = (0..n)
            .map(|i| {
                let k = if duplicates { i / 7 } else { i };
                let f = |s: u32| {
                    (hash(k.wrapping_mul(3).wrapping_add(s) ^ seed.wrapping_mul(0x9e37_79b9)) >> 8) as f32
                        / (1 << 24) as f32
                };
                let p = [f(0), f(1), f(2)];
                let r = 0.001 + 0.01 * f(7);
                let b = Aabb::from_arrays([p[0] - r, p[1] - r, p[2] - r], [p[0] + r, p[1] + r, p[2] + r]);
                let q = |x: f32| ((x * 1023.0) as u32).min(1023);
                let key = crate::construct::morton::interleave(q(p[0]), q(p[1]), q(p[2]));
                (key, b)
            })
            .collect();
        pts.sort_by_key(|p| p.0);
        (pts.iter().map(|p| p.0).collect(), pts.iter().map(|p| p.1).collect())
    }

    /// Invariants that do not depend on the builder: one root (node 0),
    /// parent links, every leaf reached once, boxes enclose their children.
    pub(crate) fn check_tree(nodes: &[Node], parents: &[u32], n: u32) {
        assert_eq!(parents[0], INVALID);
        let mut seen = vec![false; nodes.len()];
        let mut stack = vec![0u32];
        let mut leaves = 0;
        while let Some(i) = stack.pop() {
            assert!(!seen[i as usize], "node {i} reached twice");
            seen[i as usize] = true;
            let node = nodes[i as usize];
            if node.right & LEAF_BIT != 0 {
                assert_eq!(i, n - 1 + node.left, "leaf {i} holds sorted position {}", node.left);
                leaves += 1;
                continue;
            }
            for c in [node.left, node.right] {
                assert_eq!(parents[c as usize], i, "parent of {c}");
                assert!(node.aabb().contains(&nodes[c as usize].aabb()), "node {i} does not enclose {c}");
                stack.push(c);
            }
        }
        assert_eq!(leaves, n);
        assert!(seen.iter().all(|&s| s), "every node is in the tree");
    }

    #[test]
    fn trees_are_valid_at_every_subgroup_size() {
        for &size in &[4u32, 8, 16, 32, 64] {
            for &(n, dup) in
                &[(1u32, false), (2, false), (3, false), (17, false), (300, false), (1000, true), (5000, false)]
            {
                let (keys, boxes) = random_scene(n, n ^ size, dup);
                let (nodes, parents) = build(&keys, &boxes, size);
                if n == 1 {
                    assert_eq!(parents[0], INVALID);
                    continue;
                }
                check_tree(&nodes, &parents, n);
            }
        }
    }

    #[test]
    fn identical_boxes_still_merge() {
        let n = 700;
        let keys = vec![5u64; n];
        let boxes = vec![Aabb::from_arrays([0.0; 3], [1.0; 3]); n];
        let (nodes, parents) = build(&keys, &boxes, 32);
        check_tree(&nodes, &parents, n as u32);
    }

    #[test]
    fn extreme_boxes_still_merge() {
        // Extents whose areas overflow to infinity (or NaN).
        let n = 300u32;
        let (keys, _) = random_scene(n, 9, false);
        let boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let x = if i % 2 == 0 { 3e38 } else { -3e38 };
                Aabb::from_arrays([x, 0.0, 0.0], [x, 0.0, 0.0])
            })
            .collect();
        let (nodes, parents) = build(&keys, &boxes, 32);
        check_tree(&nodes, &parents, n);
    }

    /// An independent H-PLOC, recursive over Karras's radix tree of the
    /// same keys (the climbs meet at its nodes): returns the range's
    /// clusters' boxes and adds the areas of the nodes it makes to `areas`.
    fn reference(
        node: u32,
        keys: &[u64],
        boxes: &[Aabb],
        (limit, keep, radius): (u32, u32, u32),
        areas: &mut f64,
    ) -> (Vec<Aabb>, u32) {
        let n = keys.len() as u32;
        if node >= n - 1 {
            return (vec![boxes[(node - (n - 1)) as usize]], 1);
        }
        let (l, r) = crate::construct::radix_tree::children(keys, n, node);
        let (mut clusters, left_leaves) = reference(l, keys, boxes, (limit, keep, radius), areas);
        let (right, right_leaves) = reference(r, keys, boxes, (limit, keep, radius), areas);
        clusters.extend(right);
        let leaves = left_leaves + right_leaves;
        if leaves <= limit && node != 0 {
            return (clusters, leaves);
        }
        let keep = if node == 0 {
            1
        } else if keep == 0 {
            limit
        } else {
            keep.clamp(2, limit)
        } as usize;
        let radius = if radius == 0 { usize::MAX } else { radius as usize };
        while clusters.len() > keep {
            let c = clusters.len();
            let area = |a: &Aabb, b: &Aabb| {
                let x = a.union(b).surface_area();
                if x.is_nan() {
                    f32::INFINITY
                } else {
                    x
                }
            };
            // Least merged area; ties to the lower pair (lexicographically).
            let nearest: Vec<usize> = (0..c)
                .map(|j| {
                    let mut best = (f32::INFINITY, usize::MAX, usize::MAX, usize::MAX);
                    for k in (0..c).filter(|&k| k != j && k.abs_diff(j) <= radius) {
                        let cand = (area(&clusters[j], &clusters[k]), j.min(k), j.max(k), k);
                        if best.1 == usize::MAX
                            || cand.0 < best.0
                            || (cand.0 == best.0 && (cand.1, cand.2) < (best.1, best.2))
                        {
                            best = cand;
                        }
                    }
                    best.3
                })
                .collect();
            let mut next = Vec::new();
            for j in 0..c {
                let m = nearest[j];
                if nearest[m] == j && j < m {
                    let merged = clusters[j].union(&clusters[m]);
                    *areas += merged.surface_area() as f64;
                    next.push(merged);
                } else if !(nearest[m] == j && j > m) {
                    next.push(clusters[j]);
                }
            }
            clusters = next;
        }
        (clusters, leaves)
    }

    #[test]
    fn same_tree_as_an_independent_recursive_hploc() {
        let settings =
            [(4u32, 0u32, 0u32), (8, 0, 0), (32, 0, 0), (64, 0, 0), (32, 8, 0), (32, 2, 3), (64, 5, 1), (8, 3, 2)];
        for &(size, keep, radius) in &settings {
            for &(n, dup) in &[(2u32, false), (40, false), (3000, false), (2000, true)] {
                let (keys, boxes) = random_scene(n, 77 + n + size, dup);
                let (nodes, parents) = build_with(&keys, &boxes, size, keep, radius);
                check_tree(&nodes, &parents, n);
                let mut expected = 0.0;
                let (root, _) = reference(0, &keys, &boxes, (cluster_limit(size), keep, radius), &mut expected);
                assert_eq!(root.len(), 1);
                let got: f64 = nodes[..(n - 1) as usize].iter().map(|x| x.aabb().surface_area() as f64).sum();
                assert!(
                    (got - expected).abs() <= 1e-9 * expected.max(1.0),
                    "size {size}, n {n}: {got} against {expected}"
                );
                assert_eq!(nodes[0].aabb(), root[0]);
            }
        }
    }
}
