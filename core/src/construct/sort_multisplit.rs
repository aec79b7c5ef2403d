//! The radix sort's pass ranked by subgroups: Onesweep's warp-level
//! multisplit (Adinets & Merrill 2022, section 4; CUB's
//! `BlockRadixRankMatch`), for devices whose subgroups have at least
//! [`MIN_SUBGROUP_SIZE`] lanes.
//!
//! [`super::sort::onesweep_phase`] ranks a tile's keys in workgroup memory,
//! two barriers per round of 256 keys; on the H100 those barriers, not the
//! memory traffic, bound a pass. Here each subgroup ranks a contiguous run
//! of the tile's keys, `ITEMS` per lane, without a workgroup barrier:
//!
//! 1. for each of its keys in order, a lane finds the lanes of its subgroup
//!    holding the same digit ([`OP_MATCH_BYTE`]); the highest of them (the
//!    leader) reads the subgroup's count of that digit so far from the
//!    subgroup's own row of counters and adds the peers to it, and hands the
//!    old count to its peers ([`OP_SHUFFLE`]); a key's rank within its
//!    subgroup's keys of its digit is that count plus its peers below it;
//! 2. after one workgroup barrier, invocation `d` scans digit `d`'s counts
//!    over the subgroups (so each subgroup's keys of a digit follow the
//!    earlier subgroups'), giving the tile's digit counts;
//! 3. from there as in Onesweep's pass: the tile's offsets by look-back
//!    ([`super::sort::tile_offset`]), the digits' offsets within the tile,
//!    each key's place, the keys written out digit run by digit run
//!    ([`super::sort::write_tile`]).
//!
//! Subgroup `s` of `S` lanes takes keys `s * S * ITEMS ..` of the tile, lane
//! `l` its keys `s * S * ITEMS + i * S + l` for `i` in `0..ITEMS`: so keys are
//! ranked in the order they came (the sort stays stable) and each load of
//! a subgroup is one contiguous stretch. The counters are one row of
//! [`RADIX`] per subgroup: [`SUBGROUP_COUNTS`] words hold a workgroup of
//! subgroups of [`MIN_SUBGROUP_SIZE`] or more lanes; devices with smaller
//! ones (lavapipe: 8) keep [`super::sort::onesweep_phase`], which runs at any
//! size. The result is the same stable order on every device, at every
//! subgroup size, and on the CPU runner.
//!
//! Written in the phases of [`crate::gpu::subgroup`], each ending in the
//! synchronisation code [`multisplit_pass_sync`] gives.
use crate::construct::sort::{digit, state, tile_offset, write_tile, RADIX, RADIX_BITS};
use crate::geometry::buffers::SortParams;
use crate::gpu::atomics;
use crate::gpu::subgroup::{
    highest_lane, lanes_below, popcount, Lane, OP_MATCH_BYTE, OP_NONE, OP_SHUFFLE, THEN_SUBGROUP_BARRIER,
    THEN_WORKGROUP_BARRIER,
};
use crate::gpu::unchecked::{at, get, set};
use crate::gpu::workgroup::{small_scan_phase, SMALL_SCAN_PHASES, WG, WORKGROUP_SIZE};

/// Fewest lanes per subgroup this pass runs with (the counters' size).
pub const MIN_SUBGROUP_SIZE: u32 = 16;
/// Most subgroups in a workgroup.
pub const MAX_SUBGROUPS: u32 = WORKGROUP_SIZE / MIN_SUBGROUP_SIZE;
/// Words of digit counters, a row of [`RADIX`] per subgroup; after ranking
/// they hold the tile's key order, so a tile has at most this many keys.
pub const SUBGROUP_COUNTS: usize = (MAX_SUBGROUPS * RADIX) as usize;
/// Keys per lane (rounds of a workgroup) of a tile.
pub const MULTISPLIT_SORT_ITEMS: u32 = 8;
/// Keys per workgroup.
pub const MULTISPLIT_SORT_TILE: u32 = WORKGROUP_SIZE * MULTISPLIT_SORT_ITEMS;
const _: () = assert!(MULTISPLIT_SORT_TILE as usize <= SUBGROUP_COUNTS, "the counters hold the tile's order");
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
}

/// Phases with `items` keys per lane: clear; two per key (match, then
/// count and shuffle); the last key's rank; the scan over subgroups;
/// look-back with the first scan step; two more scan steps; places; order;
/// write.
pub const fn multisplit_pass_phases(items: u32) -> u32 {
    2 * items + 6 + SMALL_SCAN_PHASES
}

/// The synchronisation code (see [`crate::gpu::subgroup`]) after phase
/// `phase` of a pass with `items` keys per lane.
pub const fn multisplit_pass_sync(phase: u32, items: u32) -> u32 {
    if phase == 0 || phase > 2 * items {
        OP_NONE | THEN_WORKGROUP_BARRIER
    } else if phase % 2 == 1 {
        OP_MATCH_BYTE
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

/// Kernel: one pass over one tile of `ITEMS` keys per invocation, `TILE` =
/// `ITEMS * WORKGROUP_SIZE`, with look-back (`sort_state` as laid out in
/// [`state`]). Invocation `lid` is lane `lane` of subgroup `subgroup`, whose
/// subgroups have `size` lanes (at least [`MIN_SUBGROUP_SIZE`]).
///
/// Workgroup memory: `ticket`, the tile this workgroup sorts; `counts`, a
/// row of digit counters per subgroup, then the tile's keys in order;
/// `ranks`, each key's rank among its subgroup's keys of its digit and the
/// digit (`rank | digit << 16`), then its place in the tile; `running`, the
/// tile's digit counts; `local_offsets` and `global_offsets`, where each
/// digit's keys start in the tile and in the output; `scan_sums`, scratch.
#[allow(clippy::too_many_arguments)]
pub fn multisplit_pass_phase<const ITEMS: u32, const TILE: usize>(
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
    ranks: &mut [u32; TILE],
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
    let base = tile * TILE as u32;
    // Keys of the tile: 0..valid (only the last tile is short).
    let valid = (params.n - base).min(TILE as u32);
    let row = subgroup * RADIX;
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
                    set(ranks, k as usize, rank | me.digit << 16);
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
                let counter = (row + me.digit) as usize;
                let before = get(counts, counter);
                set(counts, counter, before + popcount(me.peers));
                io.input = before;
            }
            io.arg = leader;
        }
        return;
    }
    let subgroups = WORKGROUP_SIZE / size;
    let look_back_phase = ranked + 2;
    if phase == ranked + 1 {
        // Digit `lid`'s counts over the subgroups, scanned in place.
        let mut sum = 0;
        for s in 0..subgroups {
            let i = (s * RADIX + lid) as usize;
            let c = get(counts, i);
            set(counts, i, sum);
            sum += c;
        }
        running[l] = sum;
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
                let r = get(ranks, k as usize);
                let d = r >> 16;
                let place = get(local_offsets, d as usize) + get(counts, (row + d) as usize) + (r & 0xffff);
                set(ranks, k as usize, place);
            }
        }
    } else if scan_step == SMALL_SCAN_PHASES + 1 {
        // The tile's order, in the counters (all read by now).
        for item in 0..ITEMS {
            let k = key_index(subgroup, lane, size, ITEMS, item);
            if k < valid {
                set(counts, get(ranks, k as usize) as usize, k);
            }
        }
    } else {
        write_tile(
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
