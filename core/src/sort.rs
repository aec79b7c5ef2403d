//! Stable LSD radix sort of `(u64 key, u32 value)` pairs, 8 bits per pass.
//!
//! Each pass runs three stages over tiles of [`SORT_TILE`] keys:
//! 1. [`histogram_phase`]: each workgroup counts the digits of its tile in
//!    workgroup memory and writes them *digit-major*:
//!    `block_hist[digit * blocks + tile]`;
//! 2. an exclusive prefix sum over that array ([`crate::scan`]), after which
//!    entry `(digit, tile)` is where the tile's first key of that digit goes;
//! 3. [`scatter_phase`]: each workgroup walks its tile in rounds of
//!    `WORKGROUP_SIZE` consecutive keys; an invocation's rank among equal
//!    digits of its round is the number of lower local ids holding the same
//!    digit: per-chunk digit counts scanned over the round's chunks, plus a
//!    count within its own chunk four digits at a time ([`count_before`]).
//!    So the scatter is stable and the result is identical on every device
//!    and on the CPU.
//!
//! Kernels are phase functions: see [`crate::workgroup`].
//!
//! (Satish, Harris & Garland, "Designing Efficient Sorting Algorithms for
//! Manycore GPUs", 2009, without their in-tile local sort.)
use crate::atomics;
use crate::layout::SortParams;
use crate::workgroup::{WG, WORKGROUP_SIZE};

/// Bits of the key sorted per pass.
pub const RADIX_BITS: u32 = 8;
/// Number of distinct digits; equal to the workgroup size, one counter each.
pub const RADIX: u32 = 1 << RADIX_BITS;
const _: () = assert!(RADIX == WORKGROUP_SIZE);
/// Rounds of `WORKGROUP_SIZE` keys per tile.
pub const SORT_ITEMS: u32 = 8;
/// Keys per workgroup of [`histogram`] and [`scatter`].
pub const SORT_TILE: u32 = WORKGROUP_SIZE * SORT_ITEMS;

/// Passes needed to sort keys of `key_bits` significant bits.
#[inline]
pub const fn passes_for(key_bits: u32) -> u32 {
    key_bits.div_ceil(RADIX_BITS)
}

#[inline]
pub fn digit(key: u64, shift: u32) -> u32 {
    ((key >> shift) & (RADIX as u64 - 1)) as u32
}

#[inline]
fn key_index(tile: u32, round: u32, lid: u32) -> u32 {
    tile * SORT_TILE + round * WORKGROUP_SIZE + lid
}

/// Phases of [`histogram_phase`]: clear, count, write.
pub const HISTOGRAM_PHASES: u32 = 3;

/// Kernel: digit counts of one tile, written digit-major into `block_hist`.
pub fn histogram_phase(
    phase: u32,
    lid: u32,
    tile: u32,
    params: &SortParams,
    keys: &[u64],
    block_hist: &mut [u32],
    counts: &mut [u32; WG],
) {
    if phase == 0 {
        counts[lid as usize] = 0;
    } else if phase == 1 {
        for round in 0..SORT_ITEMS {
            let i = key_index(tile, round, lid);
            if i < params.n {
                let d = digit(keys[i as usize], params.shift);
                atomics::add_workgroup(&mut counts[d as usize], 1);
            }
        }
    } else if tile < params.blocks {
        block_hist[(lid * params.blocks + tile) as usize] = counts[lid as usize];
    }
}

/// Phases of [`scatter_phase`]: load offsets, then four per round of
/// `WORKGROUP_SIZE` keys (read and count digits; pack them and scan counts;
/// rank and move; advance offsets).
pub const SCATTER_PHASES: u32 = 1 + 4 * SORT_ITEMS;
/// Digits packed four to a word, one byte each.
pub const PACKED_DIGITS: usize = WG / 4;
/// Keys per chunk of a round: ranks are counted within a chunk, and chunk
/// counts per digit are scanned, so no key compares against the whole round.
pub const CHUNK: u32 = 32;
/// Chunks per round.
pub const CHUNKS: usize = (WORKGROUP_SIZE / CHUNK) as usize;
/// Per-chunk digit counters: `chunk * RADIX + digit`.
pub const CHUNK_COUNTS: usize = CHUNKS * RADIX as usize;

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
        count += zero_bytes(packed[w as usize] ^ pattern).count_ones();
        w += 1;
    }
    let partial = zero_bytes(packed[(lid / 4) as usize] ^ pattern) & ((1u32 << (8 * (lid % 4))) - 1);
    count + partial.count_ones()
}

/// Kernel: moves the tile's pairs to their sorted places. `offsets` is the
/// scanned `block_hist`.
///
/// In each round, invocation `lid` holds one key of digit `d`; its place is
/// `running[d]` (keys of digit `d` placed by earlier rounds and tiles) plus
/// the keys of digit `d` in earlier chunks of the round (`counts`, scanned
/// over chunks by one invocation per digit) plus those before it in its own
/// chunk (`count_before`).
#[allow(clippy::too_many_arguments)]
pub fn scatter_phase(
    phase: u32,
    lid: u32,
    tile: u32,
    params: &SortParams,
    keys_in: &[u64],
    values_in: &[u32],
    offsets: &[u32],
    keys_out: &mut [u64],
    values_out: &mut [u32],
    running: &mut [u32; WG],
    digits: &mut [u32; WG],
    packed: &mut [u32; PACKED_DIGITS],
    counts: &mut [u32; CHUNK_COUNTS],
    totals: &mut [u32; WG],
) {
    let l = lid as usize;
    if phase == 0 {
        if tile < params.blocks {
            running[l] = offsets[(lid * params.blocks + tile) as usize];
        }
        for c in 0..CHUNKS {
            counts[c * WG + l] = 0;
        }
        return;
    }
    let round = (phase - 1) / 4;
    let first = key_index(tile, round, 0);
    // Keys of the round sit at local ids 0..valid (only the last tile is short).
    let valid = if first < params.n { (params.n - first).min(WORKGROUP_SIZE) } else { 0 };
    let i = first + lid;
    let chunk = lid / CHUNK;
    match (phase - 1) % 4 {
        0 => {
            let d = if lid < valid { digit(keys_in[i as usize], params.shift) } else { 0 };
            digits[l] = d;
            if lid < valid {
                atomics::add_workgroup(&mut counts[(chunk * RADIX + d) as usize], 1);
            }
        }
        1 => {
            if l < PACKED_DIGITS {
                let b = 4 * l;
                packed[l] = digits[b] | (digits[b + 1] << 8) | (digits[b + 2] << 16) | (digits[b + 3] << 24);
            }
            // Invocation `lid` scans digit `lid`'s counts over the chunks.
            let mut sum = 0;
            for c in 0..CHUNKS {
                let k = c * WG + l;
                let v = counts[k];
                counts[k] = sum;
                sum += v;
            }
            totals[l] = sum;
        }
        2 => {
            if lid < valid {
                let d = digits[l];
                let before = counts[(chunk * RADIX + d) as usize] + count_before(packed, chunk * CHUNK, lid, d);
                let dest = (running[d as usize] + before) as usize;
                keys_out[dest] = keys_in[i as usize];
                values_out[dest] = values_in[i as usize];
            }
        }
        _ => {
            running[l] += totals[l];
            for c in 0..CHUNKS {
                counts[c * WG + l] = 0;
            }
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
