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
//!    digit, counted four at a time over digits packed into bytes
//!    ([`rank_in_round`]), so the scatter is stable and the result is
//!    identical on every device and on the CPU.
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
/// `WORKGROUP_SIZE` keys (read digits; pack them; rank and move; advance).
pub const SCATTER_PHASES: u32 = 1 + 4 * SORT_ITEMS;
/// Digits packed four to a word, one byte each.
pub const PACKED_DIGITS: usize = WG / 4;

/// Bit 7 of each byte of the result is set where that byte of `x` is zero
/// (exact, no carries between bytes).
#[inline]
fn zero_bytes(x: u32) -> u32 {
    let t = (x & 0x7f7f_7f7f) + 0x7f7f_7f7f;
    !(t | x | 0x7f7f_7f7f)
}

/// Rank of invocation `lid`'s digit `d` among the first `valid` digits of the
/// round, and whether a later invocation holds the same digit. Compares four
/// packed digits per step, so a rank costs `WORKGROUP_SIZE / 4` steps.
#[inline]
pub fn rank_in_round(packed: &[u32; PACKED_DIGITS], valid: u32, lid: u32, d: u32) -> (u32, bool) {
    let pattern = d * 0x0101_0101;
    let words = valid.div_ceil(4);
    let (my_word, my_byte) = (lid / 4, lid % 4);
    let mut before = 0;
    let mut total = 0;
    for w in 0..words {
        let mut hits = zero_bytes(packed[w as usize] ^ pattern);
        if w == words - 1 && valid % 4 != 0 {
            hits &= (1u32 << (8 * (valid % 4))) - 1; // bytes past `valid` hold no key
        }
        let count = hits.count_ones();
        total += count;
        if w < my_word {
            before += count;
        } else if w == my_word {
            before += (hits & ((1u32 << (8 * my_byte)) - 1)).count_ones();
        }
    }
    (before, total > before + 1)
}

/// Kernel: moves the tile's pairs to their sorted places. `offsets` is the
/// scanned `block_hist`.
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
    round_count: &mut [u32; WG],
) {
    let l = lid as usize;
    if phase == 0 {
        if tile < params.blocks {
            running[l] = offsets[(lid * params.blocks + tile) as usize];
        }
        return;
    }
    let round = (phase - 1) / 4;
    let first = key_index(tile, round, 0);
    // Keys of the round sit at local ids 0..valid (only the last tile is short).
    let valid = if first < params.n { (params.n - first).min(WORKGROUP_SIZE) } else { 0 };
    let i = first + lid;
    match (phase - 1) % 4 {
        0 => {
            digits[l] = if lid < valid { digit(keys_in[i as usize], params.shift) } else { 0 };
        }
        1 => {
            if l < PACKED_DIGITS {
                let b = 4 * l;
                packed[l] = digits[b] | (digits[b + 1] << 8) | (digits[b + 2] << 16) | (digits[b + 3] << 24);
            }
        }
        2 => {
            // Nonzero only on the last invocation of each digit in this
            // round: how many keys of that digit the round held.
            round_count[l] = 0;
            if lid < valid {
                let d = digits[l];
                let (before, later) = rank_in_round(packed, valid, lid, d);
                let dest = (running[d as usize] + before) as usize;
                keys_out[dest] = keys_in[i as usize];
                values_out[dest] = values_in[i as usize];
                if !later {
                    round_count[l] = before + 1;
                }
            }
        }
        _ => {
            let c = round_count[l];
            if c != 0 {
                running[digits[l] as usize] += c;
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
    fn rank_matches_a_direct_count() {
        let mut digits = [0u32; WG];
        for (i, d) in digits.iter_mut().enumerate() {
            *d = ((i * 7919) % 13) as u32 * 17 % 256;
        }
        let mut packed = [0u32; PACKED_DIGITS];
        for w in 0..PACKED_DIGITS {
            packed[w] = (0..4).fold(0, |acc, b| acc | digits[4 * w + b] << (8 * b));
        }
        for valid in [0u32, 1, 5, 128, 255, 256] {
            for lid in 0..valid {
                let d = digits[lid as usize];
                let before = (0..lid).filter(|&j| digits[j as usize] == d).count() as u32;
                let later = (lid + 1..valid).any(|j| digits[j as usize] == d);
                assert_eq!(rank_in_round(&packed, valid, lid, d), (before, later), "valid {valid} lid {lid}");
            }
        }
    }
}
