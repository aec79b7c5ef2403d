//! Stable LSD radix sort of `(u64 key, u32 value)` pairs, 8 bits per pass,
//! one sweep over the keys per pass: Adinets & Merrill, "Onesweep: A Faster
//! Least Significant Digit Radix Sort for GPUs", 2022.
//!
//! 1. [`histogram_phase`]: one read of the keys counts the digits of *every*
//!    pass at once (workgroup counters, then device atomics);
//! 2. [`offsets_phase`]: one workgroup per pass scans its 256 counts, so that
//!    each digit knows where its keys start;
//! 3. one [`onesweep_phase`] dispatch per pass: a workgroup takes the next
//!    tile of [`SORT_TILE`] keys, ranks them stably within the tile,
//!    publishes its digit counts, finds how many keys of each digit all
//!    earlier tiles hold by *decoupled look-back* (Merrill & Garland, "Single-
//!    pass Parallel Prefix Scan with Decoupled Look-back", 2016), and writes
//!    its keys in digit order, so that each digit's run leaves as one
//!    contiguous stretch of memory.
//!
//! So a sort of `p` passes is `p + 3` dispatches (with the fill of its state)
//! where a reduce-then-scan sort needs five per pass.
//!
//! **Forward progress.** The look-back waits on earlier tiles, and Vulkan
//! promises nothing about the order in which workgroups start or whether a
//! waiting one lets another run. So tiles are not workgroup ids: each
//! workgroup takes a ticket from a device counter when it starts, and the
//! tile it sorts is its ticket. A workgroup only ever waits on tickets taken
//! before its own, by workgroups that were therefore already running (or
//! done); a running workgroup is never waiting on one that has not started.
//! On lavapipe, which runs each workgroup to its end on one of a few
//! threads, an earlier ticket's workgroup is done or running on another
//! thread; on the CPU runner, which runs workgroups one after another, it is
//! done, and the look-back never waits. No spin depends on scheduling order.
//!
//! **Memory model.** A tile's status is one 32-bit word per digit holding
//! both its flag and its count, written and read with device-scope atomics:
//! a reader sees a count together with the flag that says what it is, and
//! needs no ordering against any other memory: relaxed atomics suffice.
//!
//! **lavapipe.** On Mesa 22.3's lavapipe the look-back gave some tiles wrong
//! offsets now and then: about one sort in a hundred of 70 000 keys and three
//! or more passes, and only with the CPU busy (the test threads beside it).
//! Neither reading the status by an atomic add of zero (which no compiler
//! may hoist; on the H100 such adds made the sort 3% slower than loads) nor
//! a fresh status region per pass nor a loop without `continue` cured it,
//! and the cause was not found. There (the host asks
//! `Backend::look_back_works`) each pass runs without look-back instead:
//! [`tile_counts_phase`] counts each tile's digits, a prefix sum over them
//! (digit-major) gives every tile its offsets, and the same
//! [`onesweep_phase`] ranks and writes the keys: three dispatches more per
//! pass, and no workgroup ever waits on another.
//!
//! Ranks are counted as in Satish, Harris & Garland (2009) without warp
//! ballots (so the same code runs at any subgroup size): per round of 256 keys,
//! per-chunk digit counts scanned over the round's chunks, plus a count
//! within the chunk four packed digits at a time ([`count_before`]). The
//! result is identical on every device and on the CPU. A round takes two
//! phases (barriers), its ranking sharing a phase with the next round's
//! counting in a second set of counters. On the H100 this pass is bound by
//! its 21.8 KB of workgroup memory, which lets an SM hold only two of its
//! workgroups (see [`multisplit`], which measured it). [`multisplit`] is the same pass
//! ranked by subgroup ballots instead (Onesweep's own ranking), for devices
//! with subgroups of 32 lanes or more; it shares [`tile_offset`] and
//! [`write_tile`] with this one.
//!
//! Kernels are phase functions: see [`crate::gpu::workgroup`]. Hot reads and
//! writes skip bounds checks on the GPU ([`crate::gpu::unchecked`]; the CPU runner
//! keeps them), as in the treelet kernel.
pub mod multisplit;
pub mod multisplit_rank;
pub mod passes;
pub mod scan;
pub mod ties;

use crate::geometry::buffers::SortParams;
use crate::gpu::atomics;
use crate::gpu::unchecked::{at, get, put, set};
use crate::gpu::workgroup::{SMALL_SCAN_PHASES, WG, WORKGROUP_SIZE, small_scan_phase};

/// Bits of the key sorted per pass.
pub const RADIX_BITS: u32 = 8;
/// Number of distinct digits; equal to the workgroup size, one counter each.
pub const RADIX: u32 = 1 << RADIX_BITS;
const _: () = assert!(RADIX == WORKGROUP_SIZE);
/// Most passes a sort makes (64-bit keys).
pub const MAX_PASSES: u32 = 64 / RADIX_BITS;
/// Rounds of `WORKGROUP_SIZE` keys per tile.
pub const SORT_ITEMS: u32 = 8;
/// Keys per workgroup of [`onesweep_phase`] and [`tile_counts_phase`].
pub const SORT_TILE: u32 = WORKGROUP_SIZE * SORT_ITEMS;
/// Rounds per tile of the small-tile pass kernel: four times the tiles and
/// under half the phases, for sorts too small to fill the GPU with large
/// tiles.
pub const SMALL_SORT_ITEMS: u32 = 2;
/// Keys per workgroup of the small-tile pass kernel.
pub const SMALL_SORT_TILE: u32 = WORKGROUP_SIZE * SMALL_SORT_ITEMS;

/// Rounds of keys [`histogram_phase`] loads before counting them.
pub const HISTOGRAM_BATCH: u32 = 8;
/// Keys per workgroup of [`histogram_phase`]: large, so that few workgroups
/// add their counts to the same device counters.
pub const HISTOGRAM_TILE: u32 = WORKGROUP_SIZE * 32;
/// Keys per workgroup of [`histogram_phase`] for sorts of at most
/// [`SMALL_HISTOGRAM_UP_TO`] keys: enough workgroups to spread the counting.
pub const SMALL_HISTOGRAM_TILE: u32 = WORKGROUP_SIZE * 8;
/// See [`SMALL_HISTOGRAM_TILE`].
pub const SMALL_HISTOGRAM_UP_TO: u32 = 1 << 18;

/// Keys per workgroup of [`histogram_phase`] for a sort of `n` keys.
#[inline]
pub fn histogram_tile(n: u32) -> u32 {
    if n <= SMALL_HISTOGRAM_UP_TO {
        SMALL_HISTOGRAM_TILE
    } else {
        HISTOGRAM_TILE
    }
}
/// Most keys a sort takes: a status word keeps 30 bits for a count.
pub const MAX_KEYS: u32 = COUNT_MASK;

/// Passes needed to sort keys of `key_bits` significant bits.
#[inline]
pub const fn passes_for(key_bits: u32) -> u32 {
    key_bits.div_ceil(RADIX_BITS)
}

#[inline]
pub fn digit(key: u64, shift: u32) -> u32 {
    ((key >> shift) & (RADIX as u64 - 1)) as u32
}

/// The sort's state buffer, zeroed before the first kernel: the digit
/// counts of every pass (then their offsets), a ticket counter per pass, and
/// two regions of tile status words used by alternate passes (each pass
/// zeroes the other region for the next one).
pub mod state {
    use super::{MAX_PASSES, RADIX};
    /// `counts[pass * RADIX + digit]`, scanned in place into offsets.
    pub const COUNTS: u32 = 0;
    /// Ticket counter of each pass.
    pub const TICKETS: u32 = MAX_PASSES * RADIX;
    /// Set to 1 by `construct::sort::ties` where a run of ties is too long to
    /// settle: a spare word of the tickets' region, so that the flag is
    /// zeroed with the state rather than by a fill dispatch of its own.
    pub const TIE_OVERFLOW: u32 = TICKETS + MAX_PASSES;
    /// First status region.
    pub const STATUS: u32 = TICKETS + RADIX;
    const _: () = assert!(TIE_OVERFLOW < STATUS);
    /// Words of the state of a sort of `tiles` tiles.
    #[inline]
    pub const fn words(tiles: u32) -> u32 {
        STATUS + 2 * tiles * RADIX
    }
    /// Words that must be zero before the first kernel (pass 0 clears the
    /// second region).
    #[inline]
    pub const fn zeroed_words(tiles: u32) -> u32 {
        STATUS + tiles * RADIX
    }
    /// Status word of `digit` in `tile` for pass `pass`.
    #[inline]
    pub fn status(tiles: u32, pass: u32, tile: u32, digit: u32) -> usize {
        (STATUS + ((pass % 2) * tiles + tile) * RADIX + digit) as usize
    }
}

/// Flag bits of a status word: nothing published yet, this tile's own
/// count, or the count of this tile and every tile before it (plus the
/// digit's global offset).
const FLAG_SHIFT: u32 = 30;
const COUNT_MASK: u32 = (1 << FLAG_SHIFT) - 1;
const AGGREGATE: u32 = 1 << FLAG_SHIFT;
const INCLUSIVE: u32 = 2 << FLAG_SHIFT;

/// Phases of [`histogram_phase`]: clear, count, add.
pub const HISTOGRAM_PHASES: u32 = 3;

/// Kernel: digit counts of every pass from `params.pass` on (0 for a sort of
/// every digit; see [`ties`] for one of the high digits) over one
/// tile of [`histogram_tile`] keys, added to the state's counts.
pub fn histogram_phase(
    phase: u32,
    lid: u32,
    tile: u32,
    params: &SortParams,
    keys: &[u64],
    sort_state: &mut [u32],
    counts: &mut [u32; (MAX_PASSES * RADIX) as usize],
) {
    let l = lid as usize;
    match phase {
        0 => {
            for p in 0..MAX_PASSES as usize {
                counts[p * WG + l] = 0;
            }
        }
        1 => {
            // Eight rounds' keys loaded at once, then counted: one load's
            // latency per eight keys instead of one per key (H100, 1M keys:
            // see `HISTOGRAM_BATCH`).
            let keys_per_tile = histogram_tile(params.n);
            let mut round = 0;
            while round < keys_per_tile / WORKGROUP_SIZE {
                let first = tile * keys_per_tile + round * WORKGROUP_SIZE + lid;
                let mut batch = [0u64; HISTOGRAM_BATCH as usize];
                unrolled_8!(b, {
                    let i = first + b as u32 * WORKGROUP_SIZE;
                    if i < params.n {
                        batch[b] = at(keys, i as usize);
                    }
                });
                unrolled_8!(b, {
                    if first + (b as u32) * WORKGROUP_SIZE < params.n {
                        for p in params.pass..params.passes {
                            let d = digit(batch[b], p * RADIX_BITS);
                            atomics::add_workgroup(&mut counts[(p * RADIX + d) as usize], 1);
                        }
                    }
                });
                round += HISTOGRAM_BATCH;
            }
        }
        _ => {
            for p in params.pass..params.passes {
                let c = counts[(p * RADIX) as usize + l];
                if c != 0 {
                    atomics::add_device(&mut sort_state[(state::COUNTS + p * RADIX + lid) as usize], c);
                }
            }
        }
    }
}

/// Phases of [`tile_counts_phase`]: clear, count, write.
pub const TILE_COUNTS_PHASES: u32 = 3;

/// Kernel of the sort without look-back (see [`onesweep_phase`]): this
/// pass's digit counts of one tile, written digit-major,
/// `tile_counts[digit * tiles + tile]`, so that their exclusive prefix sum
/// is where each tile's keys of each digit go.
pub fn tile_counts_phase(
    phase: u32,
    lid: u32,
    tile: u32,
    params: &SortParams,
    keys: &[u64],
    tile_counts: &mut [u32],
    counts: &mut [u32; WG],
) {
    if phase == 0 {
        counts[lid as usize] = 0;
    } else if phase == 1 {
        for round in 0..SORT_ITEMS {
            let i = tile * SORT_TILE + round * WORKGROUP_SIZE + lid;
            if i < params.n {
                let d = digit(keys[i as usize], params.pass * RADIX_BITS);
                atomics::add_workgroup(&mut counts[d as usize], 1);
            }
        }
    } else if tile < params.tiles {
        tile_counts[(lid * params.tiles + tile) as usize] = counts[lid as usize];
    }
}

/// Phases of [`offsets_phase`]: load, scan, store.
pub const OFFSETS_PHASES: u32 = 1 + SMALL_SCAN_PHASES + 1;

/// Kernel: workgroup `pass` turns that pass's digit counts into the offsets
/// where each digit's keys start.
pub fn offsets_phase(
    phase: u32,
    lid: u32,
    pass: u32,
    params: &SortParams,
    sort_state: &mut [u32],
    values: &mut [u32; WG],
    out: &mut [u32; WG],
    sums: &mut [u32; 16],
) {
    let slot = (state::COUNTS + pass * RADIX + lid) as usize;
    if pass >= params.passes {
        return;
    }
    if phase == 0 {
        values[lid as usize] = sort_state[slot];
    } else if phase <= SMALL_SCAN_PHASES {
        small_scan_phase(phase - 1, lid, values, out, sums);
    } else {
        sort_state[slot] = out[lid as usize];
    }
}

/// Digits packed four to a word, one byte each.
pub const PACKED_DIGITS: usize = WG / 4;
/// Keys per chunk of a round: ranks are counted within a chunk, and chunk
/// counts per digit are scanned, so no key compares against the whole round.
pub const CHUNK: u32 = 64;
/// Chunks per round.
pub const CHUNKS: usize = (WORKGROUP_SIZE / CHUNK) as usize;
/// Per-chunk digit counters of one round, `chunk * RADIX + digit`.
pub const ROUND_COUNTS: usize = CHUNKS * RADIX as usize;
/// Two rounds' counters (one round is ranked while the next is counted);
/// after ranking, the same array holds the tile's key order (see
/// [`onesweep_phase`]). (Tiles of 4096 keys, which would need more, made a
/// pass slower at every size on the H100: 0.88 ms against 0.58 for 1M keys.)
pub const CHUNK_COUNTS: usize = 2 * ROUND_COUNTS;
const _: () = assert!(CHUNK_COUNTS >= SORT_TILE as usize, "the counters are reused as the tile's order");

/// Bit 7 of each byte of the result is set where that byte of `x` is zero
/// (exact, no carries between bytes).
#[inline]
fn zero_bytes(x: u32) -> u32 {
    let t = (x & 0x7f7f_7f7f) + 0x7f7f_7f7f;
    !(t | x | 0x7f7f_7f7f)
}

/// How many of the digits at local ids `from..lid` equal `d`, counting four
/// packed digits per step (`from` is a multiple of 4).
#[inline]
pub fn count_before(packed: &[u32; PACKED_DIGITS], from: u32, lid: u32, d: u32) -> u32 {
    let pattern = d * 0x0101_0101;
    let mut count = 0;
    let mut w = from / 4;
    while w < lid / 4 {
        count += zero_bytes(get(packed, w as usize) ^ pattern).count_ones();
        w += 1;
    }
    let partial = zero_bytes(get(packed, (lid / 4) as usize) ^ pattern) & ((1u32 << (8 * (lid % 4))) - 1);
    count + partial.count_ones()
}

/// Round `round`'s digit of invocation `lid`'s key in the tile at `base`,
/// kept in `digits` and counted in its chunk's counters of that round
/// (buffer `round % 2`).
#[allow(clippy::too_many_arguments)]
#[inline]
fn count_digit(
    round: u32,
    lid: u32,
    base: u32,
    valid: u32,
    shift: u32,
    keys_in: &[u64],
    digits: &mut [u32; WG],
    counts: &mut [u32; CHUNK_COUNTS],
) {
    let k = round * WORKGROUP_SIZE + lid;
    let d = if k < valid { digit(at(keys_in, (base + k) as usize), shift) } else { 0 };
    digits[lid as usize] = d;
    if k < valid {
        let counter = (round % 2) as usize * ROUND_COUNTS + ((lid / CHUNK) * RADIX + d) as usize;
        atomics::add_workgroup(&mut counts[counter], 1);
    }
}

/// Phases of [`onesweep_phase`] with `items` rounds: ticket; the first
/// round's digits; two per round of ranking; the last round's counts; look-back
/// (with the first step of the local scan); two more scan steps; order;
/// write.
pub const fn onesweep_phases(items: u32) -> u32 {
    3 + 2 * items + SMALL_SCAN_PHASES + 2
}

/// Kernel: one pass over one tile of `ITEMS` rounds, `TILE` =
/// `ITEMS * WORKGROUP_SIZE` keys ([`SORT_ITEMS`] or [`SMALL_SORT_ITEMS`]).
/// See the module documentation.
///
/// `LOOK_BACK`: find the tile's offsets by decoupled look-back, with
/// `sort_state` as laid out in [`state`]. Without it (on lavapipe, see
/// `treelet::backend::Backend::look_back_works`), the tile is the workgroup
/// `group` and `sort_state` holds the scanned [`tile_counts_phase`] counts.
///
/// Workgroup memory (passed one array at a time: rust-gpu cannot hold
/// references in a struct): `ticket`, the tile this workgroup sorts;
/// `running`, keys of each digit ranked so far, at the end the tile's digit
/// counts; `digits` and `packed`, this round's digits by local id, plain and
/// four to a word; `counts`, chunk counters while ranking, then the tile's
/// keys in sorted order; `totals`, this round's count of each digit;
/// `ranks`, each key's rank among the tile's keys of its digit, and the
/// digit (`rank | digit << 16`); `local_offsets` and `global_offsets`, where
/// each digit's keys start within the tile and in the output; `scan_sums`,
/// scratch of the local scan.
#[allow(clippy::too_many_arguments)]
pub fn onesweep_phase<const LOOK_BACK: bool, const ITEMS: u32, const TILE: usize>(
    phase: u32,
    lid: u32,
    group: u32,
    params: &SortParams,
    keys_in: &[u64],
    values_in: &[u32],
    keys_out: &mut [u64],
    values_out: &mut [u32],
    sort_state: &mut [u32],
    ticket: &mut [u32; 1],
    running: &mut [u32; WG],
    digits: &mut [u32; WG],
    packed: &mut [u32; PACKED_DIGITS],
    counts: &mut [u32; CHUNK_COUNTS],
    totals: &mut [u32; WG],
    ranks: &mut [u32; TILE],
    local_offsets: &mut [u32; WG],
    global_offsets: &mut [u32; WG],
    scan_sums: &mut [u32; 16],
) {
    let l = lid as usize;
    let shift = params.pass * RADIX_BITS;
    let tile_keys = ITEMS * WORKGROUP_SIZE;
    let look_back_phase = 3 + 2 * ITEMS;
    if phase == 0 {
        if lid == 0 {
            ticket[0] = if LOOK_BACK {
                atomics::add_device(&mut sort_state[(state::TICKETS + params.pass) as usize], 1)
            } else {
                group
            };
        }
        running[l] = 0;
        totals[l] = 0;
        for c in 0..CHUNK_COUNTS / WG {
            counts[c * WG + l] = 0;
        }
        return;
    }
    let tile = ticket[0];
    if tile >= params.tiles {
        return; // A workgroup of the dispatch grid's padding.
    }
    let base = tile * tile_keys;
    // Keys of the tile: 0..valid (only the last tile is short).
    let valid = (params.n - base).min(tile_keys);
    let chunk = lid / CHUNK;
    if phase < look_back_phase {
        // Phase 1 counts round 0; then each round takes two phases, one
        // round's ranking overlapping the next round's counting.
        if phase == 1 {
            count_digit(0, lid, base, valid, shift, keys_in, digits, counts);
        } else if phase == look_back_phase - 1 {
            running[l] += totals[l]; // The tile's digit counts.
        } else if phase % 2 == 0 {
            // Scan of round `round`: pack its digits, scan digit `lid`'s
            // chunk counters; take the last round's totals into `running`;
            // clear the other buffer for the next round.
            let round = (phase - 2) / 2;
            if l < PACKED_DIGITS {
                let b = 4 * l;
                packed[l] = digits[b] | (digits[b + 1] << 8) | (digits[b + 2] << 16) | (digits[b + 3] << 24);
            }
            let (this, other) = ((round % 2) as usize * ROUND_COUNTS, ((round + 1) % 2) as usize * ROUND_COUNTS);
            let mut sum = 0;
            for c in 0..CHUNKS {
                let i = this + c * WG + l;
                let v = get(counts, i);
                set(counts, i, sum);
                sum += v;
                set(counts, other + c * WG + l, 0);
            }
            running[l] += totals[l];
            totals[l] = sum;
        } else {
            // Ranks of round `round`, then the next round's digit.
            let round = (phase - 3) / 2;
            let k = round * WORKGROUP_SIZE + lid;
            if k < valid {
                let d = digits[l];
                let counter = (round % 2) as usize * ROUND_COUNTS + (chunk * RADIX + d) as usize;
                let before = get(counts, counter) + count_before(packed, chunk * CHUNK, lid, d);
                set(ranks, k as usize, (get(running, d as usize) + before) | (d << 16));
            }
            if round + 1 < ITEMS {
                count_digit(round + 1, lid, base, valid, shift, keys_in, digits, counts);
            }
        }
        return;
    }
    if phase == look_back_phase {
        global_offsets[l] = tile_offset::<LOOK_BACK>(lid, tile, params, sort_state, running[l]);
    }
    let scan_step = phase - look_back_phase;
    if scan_step < SMALL_SCAN_PHASES {
        small_scan_phase(scan_step, lid, running, local_offsets, scan_sums);
    } else if scan_step == SMALL_SCAN_PHASES {
        // The tile's order: `counts[position] = key`.
        for round in 0..ITEMS {
            let k = round * WORKGROUP_SIZE + lid;
            if k < valid {
                let r = get(ranks, k as usize);
                let position = get(local_offsets, (r >> 16) as usize) + (r & 0xffff);
                set(counts, position as usize, k);
            }
        }
    } else {
        write_tile::<_, false>(lid, base, valid, ITEMS, shift, counts, local_offsets, global_offsets, keys_in, values_in, keys_out, values_out);
    }
}

/// Where the tile's keys of digit `lid` start in the output (one phase,
/// invocation `lid` for digit `lid`; `count`: the tile's keys of that
/// digit). With `LOOK_BACK`, by decoupled look-back over the earlier tiles'
/// status words in `sort_state` (see [`state`]), publishing this tile's;
/// without, read from the scanned [`tile_counts_phase`] counts that
/// `sort_state` holds then.
#[inline]
pub fn tile_offset<const LOOK_BACK: bool>(
    lid: u32,
    tile: u32,
    params: &SortParams,
    sort_state: &mut [u32],
    count: u32,
) -> u32 {
    if !LOOK_BACK {
        return sort_state[(lid * params.tiles + tile) as usize];
    }
    let own = state::status(params.tiles, params.pass, tile, lid);
    let mut prefix = 0;
    if tile == 0 {
        prefix = sort_state[(state::COUNTS + params.pass * RADIX + lid) as usize];
    } else {
        atomics::store_u32(&mut sort_state[own], AGGREGATE | count);
        let mut earlier = tile - 1;
        // Until a tile's inclusive count, add up aggregates; a tile that
        // has published nothing yet is read again (its workgroup is
        // running: see the module doc).
        loop {
            let s = atomics::load_u32(&sort_state[state::status(params.tiles, params.pass, earlier, lid)]);
            if s & !COUNT_MASK != 0 {
                prefix += s & COUNT_MASK;
                if s & INCLUSIVE != 0 {
                    break;
                }
                earlier -= 1;
            }
        }
    }
    atomics::store_u32(&mut sort_state[own], INCLUSIVE | (prefix + count));
    // The next pass uses the other region: clear this tile's row of it.
    atomics::store_u32(&mut sort_state[state::status(params.tiles, params.pass + 1, tile, lid)], 0);
    prefix
}

/// The tile's keys and values to the output, in the tile's order
/// (`order[position]` = the key's index in the tile; with `PACKED`, 16 bits
/// each, two to a word): consecutive invocations write consecutive places
/// of a digit's run.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn write_tile<const N: usize, const PACKED: bool>(
    lid: u32,
    base: u32,
    valid: u32,
    items: u32,
    shift: u32,
    order: &[u32; N],
    local_offsets: &[u32; WG],
    global_offsets: &[u32; WG],
    keys_in: &[u64],
    values_in: &[u32],
    keys_out: &mut [u64],
    values_out: &mut [u32],
) {
    for round in 0..items {
        let position = round * WORKGROUP_SIZE + lid;
        if position < valid {
            let k = if PACKED {
                (get(order, (position / 2) as usize) >> (16 * (position % 2))) & 0xffff
            } else {
                get(order, position as usize)
            };
            let key = at(keys_in, (base + k) as usize);
            let d = digit(key, shift) as usize;
            let dest = (get(global_offsets, d) + position - get(local_offsets, d)) as usize;
            put(keys_out, dest, key);
            put(values_out, dest, at(values_in, (base + k) as usize));
        }
    }
}


#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_bytes_is_exact() {
        for x in [0u32, 0x0100_0000, 0x0001_0001, 0x8000_0080, 0xffff_ff00, 0x00ff_00ff, 0x0101_0101] {
            let expected = (0..4).filter(|b| (x >> (8 * b)) & 0xff == 0).fold(0, |m, b| m | 0x80 << (8 * b));
            assert_eq!(zero_bytes(x), expected, "{x:#x}");
        }
    }

    #[test]
    fn count_before_matches_a_direct_count() {
        let mut digits = [0u32; WG];
        for (i, d) in digits.iter_mut().enumerate() {
            *d = ((i * 7919) % 13) as u32 * 17 % 256;
        }
        let mut packed = [0u32; PACKED_DIGITS];
        for w in 0..PACKED_DIGITS {
            packed[w] = (0..4).fold(0, |acc, b| acc | digits[4 * w + b] << (8 * b));
        }
        for lid in 0..WORKGROUP_SIZE {
            let from = lid / CHUNK * CHUNK;
            let d = digits[lid as usize];
            let expected = (from..lid).filter(|&j| digits[j as usize] == d).count() as u32;
            assert_eq!(count_before(&packed, from, lid, d), expected, "lid {lid}");
        }
    }
}
