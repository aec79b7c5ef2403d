//! Ranking keys by digit within a subgroup: Onesweep's warp-level multisplit
//! (Adinets & Merrill 2022, "Onesweep: A Faster Least Significant Digit
//! Radix Sort for GPUs", after Ashkiani et al. 2016, "GPU Multisplit").
//! Each lane finds the lanes of its subgroup whose keys have its digit with
//! one ballot per bit of the digit (the peers: for each bit, the lanes that
//! voted as it did), and its rank is the number of peers below it. No
//! workgroup memory and no barrier: eight ballots, where ranking in
//! workgroup memory takes phases separated by barriers.
//!
//! This kernel ranks one key per invocation; the radix sort's pass is to rank
//! its tiles with it (issue 30). Written in the phases of
//! [`crate::gpu::subgroup`]; correct at every subgroup size from 1 to 64.
use crate::geometry::buffers::SortParams;
use crate::gpu::subgroup::{lanes_below, popcount, Lane, OP_BALLOT, OP_NONE};
use crate::gpu::unchecked::{at, put};

/// Bits of a digit (a radix sort pass's).
pub const MULTISPLIT_BITS: u32 = 8;
/// Phases: a ballot of which lanes hold a key, one per bit, then the ranks.
pub const MULTISPLIT_PHASES: u32 = MULTISPLIT_BITS + 2;

/// The subgroup operation after phase `phase`.
#[inline]
pub const fn multisplit_op(phase: u32) -> u32 {
    if phase <= MULTISPLIT_BITS {
        OP_BALLOT
    } else {
        OP_NONE
    }
}

/// What a lane keeps across the phases (registers on the GPU).
#[derive(Clone, Copy, Default)]
pub struct MultisplitLane {
    pub digit: u32,
    /// The lanes that hold a key with the same bits of the digit so far.
    pub peers: u64,
}

/// Phase `phase` of invocation `id` of workgroup `group`, lane `lane` of a
/// subgroup of `size` lanes. The digit is bits `8 * params.pass ..` of
/// `keys[id]` (for `id < params.n`); the last phase writes `ranks[id]` (the
/// number of lanes below this one in its subgroup with the same digit) and
/// `counts[id]` (the lanes of its subgroup with that digit), and lane 0 of
/// each workgroup writes the subgroup size it ran with to `sizes[group]`.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn multisplit_phase(
    phase: u32,
    id: u32,
    group: u32,
    lane: u32,
    size: u32,
    params: &SortParams,
    keys: &[u64],
    ranks: &mut [u32],
    counts: &mut [u32],
    sizes: &mut [u32],
    state: &mut MultisplitLane,
    io: &mut Lane,
) {
    let valid = id < params.n;
    if phase == 0 {
        if valid {
            state.digit =
                ((at(keys, id as usize) >> (MULTISPLIT_BITS * params.pass)) & ((1 << MULTISPLIT_BITS) - 1)) as u32;
        }
        // Ballot: which lanes hold a key (past the end, none does).
        io.input = valid as u32;
        return;
    }
    // The ballot that ended the last phase narrows the peers.
    if phase == 1 {
        state.peers = io.output;
    } else {
        let voted = (state.digit >> (phase - 2)) & 1;
        state.peers &= if voted == 1 { io.output } else { !io.output };
    }
    if phase <= MULTISPLIT_BITS {
        // Ballot: which lanes have bit `phase - 1` of the digit set.
        io.input = (state.digit >> (phase - 1)) & 1;
        return;
    }
    if valid {
        put(ranks, id as usize, popcount(state.peers & lanes_below(lane)));
        put(counts, id as usize, popcount(state.peers));
    }
    if id % crate::gpu::workgroup::WORKGROUP_SIZE == 0 {
        put(sizes, group as usize, size);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::subgroup::emulate;
    use crate::gpu::workgroup::WG;
    extern crate std;

    /// The phases over one workgroup of keys, emulated at `size` lanes a
    /// subgroup, against counting by hand.
    #[test]
    fn ranks_count_the_same_digits_below() {
        for size in [1u32, 4, 8, 16, 32, 64] {
            let keys: std::vec::Vec<u64> = (0..WG as u64).map(|i| (i * 2654435761) % 7 | (i % 3) << 8).collect();
            for (pass, n) in [(0u32, WG as u32), (1, WG as u32), (0, 200)] {
                let params = SortParams { n, tiles: 1, pass, passes: 2 };
                let (mut ranks, mut counts, mut sizes) = ([u32::MAX; WG], [u32::MAX; WG], [0u32; 1]);
                let mut states = [MultisplitLane::default(); WG];
                let mut lanes = [Lane::default(); WG];
                for phase in 0..MULTISPLIT_PHASES {
                    for id in 0..WG as u32 {
                        let l = id as usize;
                        multisplit_phase(
                            phase,
                            id,
                            0,
                            id % size,
                            size,
                            &params,
                            &keys,
                            &mut ranks,
                            &mut counts,
                            &mut sizes,
                            &mut states[l],
                            &mut lanes[l],
                        );
                    }
                    for chunk in lanes.chunks_mut(size as usize) {
                        emulate(multisplit_op(phase), chunk);
                    }
                }
                let digit = |i: usize| (keys[i] >> (8 * pass)) & 0xff;
                for i in 0..n as usize {
                    let first = i / size as usize * size as usize;
                    let same = |k: &usize| *k < n as usize && digit(*k) == digit(i);
                    let below = (first..i).filter(same).count() as u32;
                    let all = (first..first + size as usize).filter(same).count() as u32;
                    assert_eq!((ranks[i], counts[i]), (below, all), "size {size}, pass {pass}, n {n}, key {i}");
                }
                assert!(ranks[n as usize..].iter().all(|&r| r == u32::MAX), "nothing written past n");
                assert_eq!(sizes[0], size);
            }
        }
    }
}
