//! The radix sort's pass ranked by subgroups: Onesweep's warp-level
//! multisplit (Adinets & Merrill 2022, section 4; CUB's
//! `BlockRadixRankMatch`), for devices whose subgroups have at least
//! [`MIN_SUBGROUP_SIZE`] lanes.
//!
//! [`super::onesweep_phase`] ranks a tile's keys in workgroup memory,
//! two barriers per round of 256 keys. Here each subgroup ranks a
//! contiguous run of the tile's keys, `ITEMS` per lane, without a
//! workgroup barrier:
//!
//! 1. for each of its keys in order, a lane finds the lanes of its subgroup
//!    holding the same digit ([`OP_MATCH_BYTE`]); the highest of them (the
//!    leader) adds the peers to the subgroup's count of that digit so far,
//!    in the subgroup's own row of counters, and hands the old count to its
//!    peers ([`OP_SHUFFLE`]); a key's rank within its subgroup's keys of its
//!    digit is that count plus its peers below it;
//! 2. after one workgroup barrier, the counters are scanned over the
//!    subgroups (so each subgroup's keys of a digit follow the earlier
//!    subgroups'), giving the tile's digit counts;
//! 3. from there as in Onesweep's pass: the tile's offsets by look-back
//!    ([`super::tile_offset`]), the digits' offsets within the tile,
//!    each key's place, the keys written out digit run by digit run
//!    ([`super::write_tile`]).
//!
//! Subgroup `s` of `S` lanes takes keys `s * S * ITEMS ..` of the tile, lane
//! `l` its keys `s * S * ITEMS + i * S + l` for `i` in `0..ITEMS`: so keys are
//! ranked in the order they came (the sort stays stable) and each load of
//! a subgroup is one contiguous stretch.
//!
//! **Workgroup memory is what bounds this pass on the H100.** A probe that
//! counted the workgroups resident at once (an atomic counter up at a
//! workgroup's start, down at its end) found 2 per SM for the workgroup-ranked
//! pass with 21.8 KB of workgroup memory and 3 for its small-tile form with
//! 15.7 KB, where 256 invocations of 24 registers would allow 8: NVIDIA's
//! Vulkan driver gives the SM's shared memory a carve-out of about 48 KB.
//! So the pass keeps each key's rank and place in its lane's registers
//! ([`MultisplitPassLane::ranks`]), counters are 16 bits, two to a word, a
//! row of [`ROW_WORDS`] per subgroup of at least [`MIN_SUBGROUP_SIZE`]
//! lanes, and the same words then hold the tile's order, 16 bits per key:
//! 7.2 KB in all (27.7 KB before), which took its 8 passes from 0.66 to
//! 0.35 ms at 1M keys and from 9.8 to 3.25 ms at 16M. Devices with smaller
//! subgroups (lavapipe: 8; some of Intel's: 16) keep
//! [`super::onesweep_phase`], which runs at any size. The result is
//! the same stable order on every device, at every subgroup size, and on
//! the CPU runner.
//!
//! With occupancy restored, the pass was bound by issuing the ranking's
//! subgroup operations (H100, 16M keys: 130 of a pass's 450 us ran them on
//! dummy data; `docs/results/h100-sort-subgroup-ops/`). So where the device
//! has NVIDIA's partition instruction the byte match is one instruction
//! ([`crate::gpu::subgroup::OP_MATCH_BYTE_PARTITIONED`], kernels
//! `sort_multisplit_partitioned_cs` and its small form: 8 passes of 1M
//! keys 0.337 -> 0.305 ms, 16M 3.00 -> 2.74 ms), elsewhere nine ballots
//! with 32-bit masks where the subgroup allows. Publishing the tile's
//! digit counts before ranking (Onesweep's early counts) was measured and
//! not kept (1-2% at 1M and 4M keys, 2% slower at 262 144).
//!
//! Written in the phases of [`crate::gpu::subgroup`], each ending in the
//! synchronisation code [`multisplit_pass_sync`] gives.
use crate::construct::sort::{digit, state, tile_offset, write_tile, RADIX, RADIX_BITS};
use crate::geometry::buffers::SortParams;
use crate::gpu::atomics;
use crate::gpu::subgroup::{
    highest_lane, lanes_below, popcount, Lane, OP_MATCH_BYTE, OP_MATCH_BYTE_PARTITIONED, OP_NONE, OP_SHUFFLE,
    THEN_SUBGROUP_BARRIER, THEN_WORKGROUP_BARRIER,
};
use crate::gpu::unchecked::{at, get, set};
use crate::gpu::workgroup::{small_scan_phase, SMALL_SCAN_PHASES, WG, WORKGROUP_SIZE};

/// Fewest lanes per subgroup this pass runs with (the counters' size).
/// 32, not less: the counters are most of the pass's workgroup memory, and
/// on the H100 workgroup memory is what bounds how many workgroups an SM
/// keeps in flight (see the module documentation).
pub const MIN_SUBGROUP_SIZE: u32 = 32;
/// Most subgroups in a workgroup.
pub const MAX_SUBGROUPS: u32 = WORKGROUP_SIZE / MIN_SUBGROUP_SIZE;
/// Digit counters packed two to a word (16 bits each: a subgroup's count
/// of a digit is at most `64 * ITEMS`, a tile's at most its size).
pub const ROW_WORDS: u32 = RADIX / 2;
/// Words of digit counters, a row of [`ROW_WORDS`] per subgroup; after
/// ranking they hold the tile's key order, 16 bits per key, so a tile has
/// at most twice this many keys.
pub const SUBGROUP_COUNTS: usize = (MAX_SUBGROUPS * ROW_WORDS) as usize;
/// Keys per lane (rounds of a workgroup) of a tile.
pub const MULTISPLIT_SORT_ITEMS: u32 = 8;
/// Keys per workgroup.
pub const MULTISPLIT_SORT_TILE: u32 = WORKGROUP_SIZE * MULTISPLIT_SORT_ITEMS;
/// Keys per lane of the small-tile form: twice the tiles, half the keys
/// each lane ranks one after another (faster for sorts that fill the GPU
/// less than twice over; the counters are sized for the larger tiles).
pub const SMALL_MULTISPLIT_SORT_ITEMS: u32 = 4;
/// Keys per workgroup of the small-tile form.
pub const SMALL_MULTISPLIT_SORT_TILE: u32 = WORKGROUP_SIZE * SMALL_MULTISPLIT_SORT_ITEMS;
/// Keys per lane of the medium-tile form: between the two (H100: 8 passes
/// of 1M keys 0.308 ms against 0.318 with 8 keys a lane and 0.334 with 4;
/// 2M 0.519 against 0.536; at 8M and 16M 8 keys a lane are faster,
/// `docs/results/h100-agglomerate-subgroup/log_sort_tiles.txt`).
pub const MEDIUM_MULTISPLIT_SORT_ITEMS: u32 = 6;
/// Keys per workgroup of the medium-tile form.
pub const MEDIUM_MULTISPLIT_SORT_TILE: u32 = WORKGROUP_SIZE * MEDIUM_MULTISPLIT_SORT_ITEMS;
const _: () = assert!(MULTISPLIT_SORT_TILE as usize <= 2 * SUBGROUP_COUNTS, "the counters hold the tile's order");
/// Most keys per lane: a lane keeps its digits in one 64-bit word.
pub const MAX_MULTISPLIT_ITEMS: u32 = 8;

/// What a lane keeps across the phases (registers on the GPU).
#[derive(Clone, Copy, Default)]
pub struct MultisplitPassLane {
    /// The digits of the lane's keys, a byte each, loaded at once so that
    /// the loads overlap.
    pub digits: u64,
    /// The digit of the key being ranked.
    pub digit: u32,
    /// Its peers: the lanes holding a key of the same digit.
    pub peers: u64,
    /// 16 bits per key: its rank among its subgroup's keys of its digit,
    /// then its place in the tile; keys 0..4, then 4..8. Kept here, not in
    /// workgroup memory, so that more workgroups fit an SM.
    pub ranks: [u64; 2],
}

impl MultisplitPassLane {
    /// The 16-bit rank (or place) of key `item`.
    #[inline]
    fn rank(&self, item: u32) -> u32 {
        let word = if item < 4 { self.ranks[0] } else { self.ranks[1] };
        (word >> (16 * (item % 4))) as u32 & 0xffff
    }

    /// Sets the 16-bit rank (or place) of key `item` (`value` < 65 536).
    #[inline]
    fn set_rank(&mut self, item: u32, value: u32) {
        let shift = 16 * (item % 4);
        let keep = !(0xffffu64 << shift);
        let v = (value as u64) << shift;
        if item < 4 {
            self.ranks[0] = self.ranks[0] & keep | v;
        } else {
            self.ranks[1] = self.ranks[1] & keep | v;
        }
    }
}

/// Phases with `items` keys per lane: clear; two per key (match, then
/// count and shuffle); the last key's rank; the scan over subgroups;
/// look-back with the first scan step; two more scan steps; places; clear;
/// order; write.
pub const fn multisplit_pass_phases(items: u32) -> u32 {
    2 * items + 7 + SMALL_SCAN_PHASES
}

/// The synchronisation code (see [`crate::gpu::subgroup`]) after phase
/// `phase` of a pass with `items` keys per lane; `partitioned`: the byte
/// match by NVIDIA's partition instruction ([`OP_MATCH_BYTE_PARTITIONED`],
/// the same result) instead of ballots.
pub const fn multisplit_pass_sync(phase: u32, items: u32, partitioned: bool) -> u32 {
    if phase == 0 || phase > 2 * items {
        OP_NONE | THEN_WORKGROUP_BARRIER
    } else if phase % 2 == 1 {
        if partitioned {
            OP_MATCH_BYTE_PARTITIONED
        } else {
            OP_MATCH_BYTE
        }
    } else {
        // The leader's count must be seen by the next key's leader.
        OP_SHUFFLE | THEN_SUBGROUP_BARRIER
    }
}

/// Index in the tile of key `item` of lane `lane` of subgroup `subgroup`.
#[inline]
fn key_index(subgroup: u32, lane: u32, size: u32, items: u32, item: u32) -> u32 {
    (subgroup * items + item) * size + lane
}

/// Kernel: one pass over one tile of `ITEMS` keys per invocation
/// (`ITEMS * WORKGROUP_SIZE` keys), with look-back (`sort_state` as laid out in
/// [`state`]). Invocation `lid` is lane `lane` of subgroup `subgroup`, whose
/// subgroups have `size` lanes (at least [`MIN_SUBGROUP_SIZE`]).
///
/// Workgroup memory: `ticket`, the tile this workgroup sorts; `counts`, a
/// row of digit counters per subgroup, then the tile's keys in order
/// (each key's rank, then its place, stays in its lane's `me`); `running`, the
/// tile's digit counts; `local_offsets` and `global_offsets`, where each
/// digit's keys start in the tile and in the output; `scan_sums`, scratch.
#[allow(clippy::too_many_arguments)]
pub fn multisplit_pass_phase<const ITEMS: u32>(
    phase: u32,
    lid: u32,
    subgroup: u32,
    lane: u32,
    size: u32,
    params: &SortParams,
    keys_in: &[u64],
    values_in: &[u32],
    keys_out: &mut [u64],
    values_out: &mut [u32],
    sort_state: &mut [u32],
    ticket: &mut [u32; 1],
    counts: &mut [u32; SUBGROUP_COUNTS],
    running: &mut [u32; WG],
    local_offsets: &mut [u32; WG],
    global_offsets: &mut [u32; WG],
    scan_sums: &mut [u32; 16],
    me: &mut MultisplitPassLane,
    io: &mut Lane,
) {
    let l = lid as usize;
    let shift = params.pass * RADIX_BITS;
    if phase == 0 {
        if lid == 0 {
            ticket[0] = atomics::add_device(&mut sort_state[(state::TICKETS + params.pass) as usize], 1);
        }
        for c in 0..SUBGROUP_COUNTS / WG {
            set(counts, c * WG + l, 0);
        }
        return;
    }
    let tile = ticket[0];
    if tile >= params.tiles {
        return; // A workgroup of the dispatch grid's padding.
    }
    let tile_keys = ITEMS * WORKGROUP_SIZE;
    let base = tile * tile_keys;
    // Keys of the tile: 0..valid (only the last tile is short).
    let valid = (params.n - base).min(tile_keys);
    let row = subgroup * ROW_WORDS;
    let ranked = 2 * ITEMS + 1; // The phase that ranks the last key.
    if phase <= ranked {
        let item = (phase - 1) / 2;
        if phase % 2 == 1 {
            // The rank of the previous key (its leader's count came by the
            // shuffle), then the digit of this one.
            if item > 0 {
                let k = key_index(subgroup, lane, size, ITEMS, item - 1);
                if k < valid {
                    let rank = io.output as u32 + popcount(me.peers & lanes_below(lane));
                    me.set_rank(item - 1, rank);
                }
            }
            if item == 0 {
                me.digits = 0;
                for i in 0..ITEMS {
                    let k = key_index(subgroup, lane, size, ITEMS, i);
                    if k < valid {
                        me.digits |= (digit(at(keys_in, (base + k) as usize), shift) as u64) << (8 * i);
                    }
                }
            }
            if item < ITEMS {
                let k = key_index(subgroup, lane, size, ITEMS, item);
                let has_key = k < valid;
                me.digit = (me.digits >> (8 * item)) as u32 & 0xff;
                io.input = me.digit;
                io.arg = has_key as u32;
            }
        } else {
            // The leader counts its peers in; every lane names the leader
            // to take the old count from.
            me.peers = io.output;
            let leader = if me.peers == 0 { lane } else { highest_lane(me.peers) };
            io.input = 0;
            if me.peers != 0 && leader == lane {
                // Atomic: the leader of the digit that shares the word may
                // be adding at the same time.
                let half = 16 * (me.digit % 2);
                let word = &mut counts[(row + me.digit / 2) as usize];
                io.input = (atomics::add_workgroup(word, popcount(me.peers) << half) >> half) & 0xffff;
            }
            io.arg = leader;
        }
        return;
    }
    let subgroups = WORKGROUP_SIZE / size;
    let look_back_phase = ranked + 2;
    if phase == ranked + 1 {
        // Digits `2 lid` and `2 lid + 1`: their counts over the subgroups,
        // scanned in place, both halves of a word at once (no half's sum
        // passes the tile's size, so none carries into the other).
        if lid < ROW_WORDS {
            let mut sum = 0;
            for s in 0..subgroups {
                let i = (s * ROW_WORDS + lid) as usize;
                let c = get(counts, i);
                set(counts, i, sum);
                sum += c;
            }
            running[2 * l] = sum & 0xffff;
            running[2 * l + 1] = sum >> 16;
        }
        return;
    }
    if phase == look_back_phase {
        global_offsets[l] = tile_offset::<true>(lid, tile, params, sort_state, running[l]);
    }
    let scan_step = phase - look_back_phase;
    if scan_step < SMALL_SCAN_PHASES {
        small_scan_phase(scan_step, lid, running, local_offsets, scan_sums);
    } else if scan_step == SMALL_SCAN_PHASES {
        // Each key's place in the tile.
        for item in 0..ITEMS {
            let k = key_index(subgroup, lane, size, ITEMS, item);
            if k < valid {
                let d = (me.digits >> (8 * item)) as u32 & 0xff;
                let below = (get(counts, (row + d / 2) as usize) >> (16 * (d % 2))) & 0xffff;
                me.set_rank(item, get(local_offsets, d as usize) + below + me.rank(item));
            }
        }
    } else if scan_step == SMALL_SCAN_PHASES + 1 {
        // The counters are all read: cleared for the tile's order.
        for c in 0..SUBGROUP_COUNTS / WG {
            set(counts, c * WG + l, 0);
        }
    } else if scan_step == SMALL_SCAN_PHASES + 2 {
        // The tile's order, two keys to a word.
        for item in 0..ITEMS {
            let k = key_index(subgroup, lane, size, ITEMS, item);
            if k < valid {
                let place = me.rank(item);
                atomics::or_workgroup(&mut counts[(place / 2) as usize], k << (16 * (place % 2)));
            }
        }
    } else {
        write_tile::<_, true>(
            lid,
            base,
            valid,
            ITEMS,
            shift,
            counts,
            local_offsets,
            global_offsets,
            keys_in,
            values_in,
            keys_out,
            values_out,
        );
    }
}
