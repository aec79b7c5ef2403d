//! Apetrei's agglomerative build ([`super::agglomerate`]) in two kernels:
//! its lowest levels merged inside each subgroup, without atomics, then the
//! climbs of what is left, packed.
//!
//! Why. In [`super::agglomerate`] each invocation climbs from its leaf, one
//! device-scope exchange and a read of the sibling's box per level, and a
//! subgroup stays resident until its slowest lane has reached its last
//! level: most lanes stop at the first level, one or two climb thirty. On
//! the H100 the whole build of 65 536 leaves, one wave, took 70 us, about
//! the time of one climb from a leaf to the root; 1M leaves, four waves of
//! subgroups held by their longest climbs, 0.33 ms.
//!
//! 1. **Merging within the subgroup** ([`agglomerate_subgroup_phase`]).
//!    The lanes of a subgroup hold consecutive leaves (lane `k` leaf
//!    `base + k`). In [`SUBGROUP_ROUNDS`] rounds, each lane holding a
//!    cluster (a finished node over `[l, r]`, kept at the lane of its first
//!    leaf) says by ballot which side its parent lies on (Apetrei's rule,
//!    [`super::agglomerate::parent_side`], from the prefix lengths at its
//!    borders, kept in registers); a cluster that wants its right
//!    neighbour, whose neighbour within the subgroup wants it back, merges
//!    with it: the two are siblings (each is a child of the one node whose
//!    split is `r`), so their parent is a node of the tree. The left one's
//!    lane takes the right one's box and outer prefix length by shuffles and
//!    writes the parent; the right one's lane lets go. No invocation reads
//!    these nodes during the dispatch, so they are written as whole 32-byte
//!    records ([`RecordStore`]; field by field, as the climb must write, they
//!    took 1.7 of this kernel's 3 ms at 16M leaves). Then the clusters still
//!    held are queued ([`crate::construct::climb_queue`]).
//! 2. **The climbs** ([`climb_queued_kernel`]): one invocation per queued
//!    cluster goes on with [`super::agglomerate::climb_from`], which is
//!    correct from any finished node: a split whose two children were both
//!    finished in one subgroup was merged there and its exchange slot is
//!    never touched, and at every other split the two climbs meet as
//!    before. Packed, their subgroups are few and full.
//!
//! The nodes are the radix tree's, bit for bit, whatever the subgroup size
//! (1 to 64; at 1 nothing merges) and the number of rounds (tests below, and
//! the GPU = CPU tests). H100, 6 rounds: the hierarchy of 1M leaves 0.33 ->
//! 0.21 ms, 4M 1.12 -> 0.61 ms; at 65 536 the second dispatch costs more
//! than the merging saves, so the host keeps [`super::agglomerate`] there
//! (`docs/results/h100-agglomerate-subgroup/`). Written in the phases of
//! [`crate::gpu::subgroup`].
use crate::construct::agglomerate::{climb_from, node_index};
use crate::construct::climb_queue;
use crate::construct::fit::{leaf_record, load_box};
use crate::construct::radix_tree::{delta, leaf_node};
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{Node, INVALID};
use crate::geometry::records::RecordStore;
use crate::geometry::split::SplitMut;
use crate::gpu::subgroup::{highest_lane, lanes_below, lowest_lane, popcount, Lane, OP_BALLOT, OP_NONE, OP_SHUFFLE};

/// Rounds of merging within the subgroup before the climb (H100, 1M and 16M
/// leaves: 4, 6, 8 and 12 rounds within 5% of each other, 6 the fastest).
pub const SUBGROUP_ROUNDS: u32 = 6;
/// Step that writes the leaf and states the first round's side.
pub const STEP_START: u32 = 0;
/// Last step of a round: the merge (steps `1..=STEP_MERGE` make a round).
pub const STEP_MERGE: u32 = 9;
/// Steps after the rounds: a ballot of the lanes still holding clusters,
/// their places in the queue reserved, the clusters queued.
pub const STEP_HOLDERS: u32 = 10;
pub const STEP_RESERVE: u32 = 11;
pub const STEP_QUEUE: u32 = 12;
/// Phases of the kernel: the start, the rounds, the queueing.
pub const AGGLOMERATE_SUBGROUP_PHASES: u32 = 4 + STEP_MERGE * SUBGROUP_ROUNDS;

/// The step that phase `phase` runs.
#[inline]
pub const fn agglomerate_subgroup_step(phase: u32) -> u32 {
    if phase == 0 {
        STEP_START
    } else if phase > STEP_MERGE * SUBGROUP_ROUNDS {
        phase - STEP_MERGE * SUBGROUP_ROUNDS - 1 + STEP_HOLDERS
    } else {
        (phase - 1) % STEP_MERGE + 1
    }
}

/// The subgroup operation after step `step`: ballots of who wants which
/// side, then shuffles of the partner's box (six words) and prefix length.
#[inline]
pub const fn agglomerate_subgroup_op(step: u32) -> u32 {
    match step {
        STEP_START | 1 | STEP_MERGE | STEP_HOLDERS => OP_BALLOT,
        2..=8 | STEP_RESERVE => OP_SHUFFLE,
        _ => OP_NONE,
    }
}

/// No partner lane.
const NONE: u32 = u32::MAX;

/// What a lane keeps across the phases (registers on the GPU).
#[derive(Clone, Copy, Default)]
pub struct AgglomerateLane {
    /// The lane holds a cluster (it is the cluster's first leaf) that is not
    /// the root.
    pub holds: bool,
    /// The cluster's range of leaves and its node.
    pub l: u32,
    pub r: u32,
    pub node: u32,
    /// Prefix lengths at its borders: `δ(l - 1, l)` (for `l > 0`) and
    /// `δ(r, r + 1)` (for `r < n - 1`).
    pub dl: i32,
    pub dr: i32,
    /// Its box.
    pub own: Aabb,
    /// Its parent lies to the right (it is a left child).
    pub wants_right: bool,
    /// Lanes whose clusters want the right side, and lanes holding clusters.
    pub right_mask: u64,
    pub held_mask: u64,
    /// The lane of the cluster this one merges with this round, or none.
    pub partner: u32,
    /// The partner's box, as shuffled.
    pub other: Aabb,
}

/// Apetrei's side of the node over `[l, r]` from its border prefix lengths
/// ([`super::agglomerate::parent_side`] without reading the keys again).
#[inline]
fn wants_right(n: u32, l: u32, r: u32, dl: i32, dr: i32) -> bool {
    l == 0 || (r != n - 1 && dr > dl)
}

/// Word `k` of a box (min x, y, z, then max x, y, z) as bits.
#[inline]
fn box_word(b: &Aabb, k: u32) -> u32 {
    if k < 3 { b.min[k as usize] } else { b.max[k as usize - 3] }.to_bits()
}

#[inline]
fn set_box_word(b: &mut Aabb, k: u32, bits: u32) {
    if k < 3 {
        b.min[k as usize] = f32::from_bits(bits);
    } else {
        b.max[k as usize - 3] = f32::from_bits(bits);
    }
}

/// Step `step` ([`agglomerate_subgroup_step`]) of invocation `id`, lane
/// `lane` of a subgroup of `size` lanes holding leaves `id - lane ..`;
/// buffers as [`super::agglomerate::agglomerate_kernel`]'s.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn agglomerate_subgroup_phase<Nodes: RecordStore<Node> + ?Sized>(
    step: u32,
    id: u32,
    lane: u32,
    size: u32,
    n: u32,
    keys: &[u64],
    sorted_prims: &[u32],
    prim_boxes: &[Aabb],
    nodes: &mut Nodes,
    parents: &mut [u32],
    ends: &mut [u32],
    queue: &mut [u32],
    queued: &mut [u32],
    me: &mut AgglomerateLane,
    io: &mut Lane,
) {
    if step == STEP_START {
        me.holds = false;
        // The climbs' exchange slots, zeroed here rather than by a fill
        // before: only the second kernel uses them.
        if id + 1 < n {
            ends[id as usize] = 0;
        }
        if id < n {
            let (leaf, b) = leaf_record(id, sorted_prims, prim_boxes);
            nodes.store(leaf_node(n, id) as usize, &leaf);
            if n == 1 {
                parents[0] = INVALID;
            }
            me.own = b;
            if n > 1 {
                me.holds = true;
                (me.l, me.r, me.node) = (id, id, leaf_node(n, id));
                me.dl = if id > 0 { delta(keys, n, id as i32 - 1, id as i32) } else { -1 };
                me.dr = delta(keys, n, id as i32, id as i32 + 1);
                me.wants_right = wants_right(n, me.l, me.r, me.dl, me.dr);
            }
        }
        io.input = (me.holds && me.wants_right) as u32;
    } else if step == 1 {
        me.right_mask = io.output;
        io.input = (me.holds && !me.wants_right) as u32;
    } else if step == 2 {
        let left_mask = io.output;
        me.held_mask = me.right_mask | left_mask;
        // The right neighbour starts where this cluster ends.
        let neighbour = lane + (me.r - me.l + 1);
        let mutual = me.holds && me.wants_right && neighbour < size && (left_mask >> neighbour) & 1 != 0;
        me.partner = if mutual { neighbour } else { NONE };
        io.arg = if mutual { neighbour } else { lane };
        io.input = box_word(&me.own, 0);
    } else if step < STEP_MERGE - 1 {
        set_box_word(&mut me.other, step - 3, io.output as u32);
        io.input = box_word(&me.own, step - 2);
    } else if step == STEP_MERGE - 1 {
        set_box_word(&mut me.other, 5, io.output as u32);
        io.input = me.dr as u32;
    } else if step == STEP_MERGE {
        let other_dr = io.output as u32 as i32;
        if me.partner != NONE {
            let b = me.partner;
            // The partner's cluster ends where the next one starts, or at
            // the end of the subgroup's leaves.
            let above = me.held_mask & !lanes_below(b) & !(1u64 << b);
            let base = id - lane;
            let other_r = if above != 0 { base + lowest_lane(above) - 1 } else { (base + size).min(n) - 1 };
            let sibling = node_index(n, base + b, other_r, false);
            let left = me.node;
            me.own = me.own.union(&me.other);
            (me.r, me.dr) = (other_r, other_dr);
            let root = me.l == 0 && me.r == n - 1;
            me.wants_right = !root && wants_right(n, me.l, me.r, me.dl, me.dr);
            me.node = node_index(n, me.l, me.r, me.wants_right);
            // Whole 32-byte records: no invocation reads them during this
            // dispatch (see the module documentation).
            let record = Node { min: me.own.min, left, max: me.own.max, right: sibling };
            nodes.store(me.node as usize, &record);
            (parents[left as usize], parents[sibling as usize]) = (me.node, me.node);
            if root {
                parents[0] = INVALID;
            }
            if root {
                me.holds = false;
            }
        } else if me.holds && !me.wants_right {
            // Merged into the cluster on the left if that one wants this side.
            let below = me.held_mask & lanes_below(lane);
            if below != 0 && (me.right_mask >> highest_lane(below)) & 1 != 0 {
                me.holds = false;
            }
        }
        io.input = (me.holds && me.wants_right) as u32;
    } else if step == STEP_HOLDERS {
        io.input = me.holds as u32;
    } else if step == STEP_RESERVE {
        // The lowest holder reserves places for the subgroup's clusters.
        let holders = io.output;
        me.held_mask = holders;
        let leader = if holders != 0 { lowest_lane(holders) } else { lane };
        if lane == leader && holders != 0 {
            io.input = climb_queue::reserve(id, n, queued, popcount(holders));
        }
        io.arg = leader;
    } else if step == STEP_QUEUE && me.holds {
        let place = climb_queue::place(id, n, io.output as u32 + popcount(me.held_mask & lanes_below(lane)));
        queue[2 * place as usize] = me.l | (me.wants_right as u32) << 31;
        queue[2 * place as usize + 1] = me.r;
    }
}

/// Kernel: the climb of the cluster at place `id` of the queues (see
/// [`climb_queue`]; places past a queue's count hold none), as
/// [`agglomerate_subgroup_phase`] left it in `queue`; `ends` zeroed before.
#[allow(clippy::too_many_arguments)]
pub fn climb_queued_kernel<const ORDERED: bool>(
    id: u32,
    n: u32,
    keys: &[u64],
    nodes: &mut SplitMut<Node>,
    parents: &mut [u32],
    ends: &mut [u32],
    queue: &[u32],
    queued: &[u32],
) {
    let Some(id) = climb_queue::entry(id, n, queued) else {
        return;
    };
    let (first, r) = (queue[2 * id as usize], queue[2 * id as usize + 1]);
    let (l, wants_right) = (first & !(1 << 31), first >> 31 != 0);
    let node = node_index(n, l, r, wants_right);
    let own = nodes.with(node as usize, load_box);
    climb_from::<ORDERED>(n, keys, nodes, parents, ends, l, r, node, own, wants_right);
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::construct::agglomerate::agglomerate_kernel;
    use crate::construct::agglomerate::tests::{leaves, random_keys};
    use crate::gpu::subgroup::emulate;
    use std::vec;
    use std::vec::Vec;

    /// The kernel over `n` leaves run as the CPU runner runs it, subgroups
    /// of `size` lanes in workgroups of `group` invocations, workgroups
    /// in `order`.
    fn run(keys: &[u64], size: u32, group: u32, order: &[u32], boxes: &[Aabb], prims: &[u32]) -> (Vec<Node>, Vec<u32>) {
        let n = keys.len() as u32;
        let count = 2 * keys.len() - 1;
        // Exchange slots not zeroed: the first kernel zeroes them.
        let (mut nodes, mut parents, mut ends) =
            (vec![Node::default(); count], vec![0u32; count], vec![u32::MAX; count]);
        let (queues, capacity) = climb_queue::queue_shape(n);
        let places = queues * capacity;
        let (mut queue, mut queued) =
            (vec![0u32; 2 * places as usize], vec![0u32; (queues * climb_queue::QUEUE_COUNTER_STRIDE) as usize]);
        let mut lanes = vec![Lane::default(); group as usize];
        let mut states = vec![AgglomerateLane::default(); group as usize];
        for &g in order {
            for phase in 0..AGGLOMERATE_SUBGROUP_PHASES {
                let step = agglomerate_subgroup_step(phase);
                for lid in 0..group {
                    let id = g * group + lid;
                    let (me, io) = (&mut states[lid as usize], &mut lanes[lid as usize]);
                    let (q, c) = (&mut queue[..], &mut queued[..]);
                    agglomerate_subgroup_phase(
                        step,
                        id,
                        lid % size,
                        size,
                        n,
                        keys,
                        prims,
                        boxes,
                        &mut nodes[..],
                        &mut parents,
                        &mut ends,
                        q,
                        c,
                        me,
                        io,
                    );
                }
                for chunk in lanes.chunks_mut(size as usize) {
                    emulate(agglomerate_subgroup_op(step), chunk);
                }
            }
        }
        // The queue's climbs last to first: they meet the other way round.
        for id in (0..places).rev() {
            climb_queued_kernel::<true>(id, n, keys, &mut crate::geometry::split::thirds(&mut nodes), &mut parents, &mut ends, &queue, &queued);
        }
        (nodes, parents)
    }

    fn check(keys: &[u64]) {
        let n = keys.len() as u32;
        let count = 2 * keys.len() - 1;
        let (boxes, prims) = leaves(n);
        let (mut nodes, mut parents, mut ends) = (vec![Node::default(); count], vec![0u32; count], vec![0u32; count]);
        for i in 0..n {
            agglomerate_kernel::<true>(i, n, keys, &prims, &boxes, &mut crate::geometry::split::thirds(&mut nodes), &mut parents, &mut ends);
        }
        for size in [1u32, 4, 8, 32, 64] {
            let group = crate::gpu::workgroup::WORKGROUP_SIZE;
            let groups = n.div_ceil(group);
            // Workgroups last to first: climbs meet the other way round.
            let order: Vec<u32> = (0..groups).rev().collect();
            let (nb, pb) = run(keys, size, group, &order, &boxes, &prims);
            for k in 0..count {
                assert_eq!(bytemuck::bytes_of(&nodes[k]), bytemuck::bytes_of(&nb[k]), "size {size}, n {n}: node {k}");
            }
            assert_eq!(parents, pb, "size {size}, n {n}: parents");
        }
    }

    #[test]
    fn same_tree_as_the_plain_agglomerative_build() {
        for n in 1..80u64 {
            check(&vec![7u64; n as usize]);
            check(&(0..n).map(|k| k / 3).collect::<Vec<_>>());
            check(&(0..n).map(|k| k * k).collect::<Vec<_>>());
        }
        let mut x = 0x9abc_def0_1234_5678u64;
        for n in [100usize, 1000, 5000, 70_000] {
            check(&random_keys(n, &mut x));
        }
    }
}
