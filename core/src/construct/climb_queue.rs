//! Queues that hand climbs from one kernel to the next
//! ([`crate::construct::climb`]).
//!
//! A bottom-up climb is bound by its longest climbs: a subgroup stays
//! resident until its last lane has reached its last level, and most lanes
//! stop at the first levels. So kernels climb the lowest levels (or merge
//! them within subgroups), queue the nodes whose climbs go on, and a second
//! kernel, one invocation per queued node, climbs on from there: its
//! subgroups are few and full. The arrival counters (or exchange slots)
//! stay in memory between the two dispatches, so the climbs meet as in one
//! (H100: the LBVH's hierarchy of 1M leaves 0.33 -> 0.21 ms,
//! `crate::construct::agglomerate_subgroup`).
//!
//! The places: workgroup `g` (of [`WORKGROUP_SIZE`] invocations of the
//! first kernel, one per leaf) queues into queue `g % queues`, which has
//! room for all its workgroups' leaves; its counter is word
//! `QUEUE_COUNTER_STRIDE * (g % queues)` of the zeroed counters. One counter
//! for all took queueing 16M leaves from tenths of a millisecond to 3 ms on
//! the H100: one atomic at a time on one word.
use crate::gpu::atomics;
use crate::gpu::workgroup::WORKGROUP_SIZE;

/// Most queues.
pub const MAX_QUEUES: u32 = 256;
/// Words from one queue's counter to the next: each on its own 128-byte
/// line, so that the queues' atomics do not meet in one place.
pub const QUEUE_COUNTER_STRIDE: u32 = 32;

/// The queues for `n` leaves: how many, and the places in each. The second
/// kernel is dispatched over `queues * capacity` invocations, words of
/// counters are `queues * QUEUE_COUNTER_STRIDE`.
#[inline]
pub const fn queue_shape(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(WORKGROUP_SIZE);
    let queues = if groups < MAX_QUEUES {
        if groups == 0 {
            1
        } else {
            groups
        }
    } else {
        MAX_QUEUES
    };
    (queues, groups.div_ceil(queues) * WORKGROUP_SIZE)
}

/// The queue of invocation `id` of the first kernel, for `n` leaves.
#[inline]
fn queue_of(id: u32, n: u32) -> u32 {
    (id / WORKGROUP_SIZE) % queue_shape(n).0
}

/// Reserves `count` places in the queue of invocation `id` (of the first
/// kernel); returns the first one's index within that queue.
#[inline]
pub fn reserve(id: u32, n: u32, queued: &mut [u32], count: u32) -> u32 {
    atomics::add_device(&mut queued[(queue_of(id, n) * QUEUE_COUNTER_STRIDE) as usize], count)
}

/// The place (an index into the queue buffer, in entries) of the `k`-th
/// entry of invocation `id`'s queue.
#[inline]
pub fn place(id: u32, n: u32, k: u32) -> u32 {
    queue_of(id, n) * queue_shape(n).1 + k
}

/// For invocation `id` of the second kernel: `Some(id)` if place `id` holds
/// an entry (places past a queue's count hold none).
#[inline]
pub fn entry(id: u32, n: u32, queued: &[u32]) -> Option<u32> {
    let (queues, capacity) = queue_shape(n);
    let (which, k) = (id / capacity, id % capacity);
    if which < queues && k < queued[(which * QUEUE_COUNTER_STRIDE) as usize] {
        Some(id)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn every_leaf_has_room_and_places_do_not_overlap() {
        for n in [1u32, 255, 256, 257, 65_536, 65_537, 1_000_000, 16_000_000] {
            let (queues, capacity) = queue_shape(n);
            assert!(queues >= 1 && queues <= MAX_QUEUES);
            // The workgroups of one queue, all their leaves queued.
            let groups = n.div_ceil(WORKGROUP_SIZE);
            let most = groups.div_ceil(queues) * WORKGROUP_SIZE;
            assert!(most <= capacity, "n {n}");
            // Places of different queues never meet.
            let last_group = groups - 1;
            let id = last_group * WORKGROUP_SIZE;
            assert!(place(id, n, capacity - 1) < queues * capacity);
            assert_eq!(place(id, n, 0) % capacity, 0);
        }
    }

    #[test]
    fn entries_are_the_reserved_places() {
        let n = 70_000;
        let (queues, capacity) = queue_shape(n);
        let mut queued = std::vec![0u32; (queues * QUEUE_COUNTER_STRIDE) as usize];
        // Two reservations by invocation 300 (workgroup 1), one by 0.
        let a = reserve(300, n, &mut queued, 3);
        let b = reserve(300, n, &mut queued, 2);
        let c = reserve(0, n, &mut queued, 1);
        assert_eq!((a, b, c), (0, 3, 0));
        let filled: std::vec::Vec<u32> = (0..queues * capacity).filter(|&id| entry(id, n, &queued).is_some()).collect();
        let mut expected = std::vec![place(0, n, 0)];
        expected.extend((0..5).map(|k| place(300, n, k)));
        expected.sort();
        assert_eq!(filled, expected);
    }
}
