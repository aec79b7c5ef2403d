//! Stable LSD radix sort of `(u64 key, u32 value)` pairs, 8 bits per pass.
//!
//! Each pass runs three stages over tiles of [`SORT_TILE`] keys:
//! 1. [`histogram`]: each workgroup counts the digits of its tile in
//!    workgroup memory and writes them *digit-major*:
//!    `block_hist[digit * blocks + tile]`;
//! 2. an exclusive prefix sum over that array ([`crate::scan`]), after which
//!    entry `(digit, tile)` is where the tile's first key of that digit goes;
//! 3. [`scatter`]: each workgroup walks its tile in rounds of
//!    `WORKGROUP_SIZE` consecutive keys; an invocation's rank among equal
//!    digits of its round is the number of lower local ids holding the same
//!    digit (a broadcast read of workgroup memory per id), so the scatter is
//!    stable and the result is identical on every device and on the CPU.
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
/// Marks an invocation without a key in the current round.
const NO_DIGIT: u32 = u32::MAX;

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

/// Phases of [`scatter_phase`]: load offsets, then three per round of
/// `WORKGROUP_SIZE` keys (read digits; rank and move; advance offsets).
pub const SCATTER_PHASES: u32 = 1 + 3 * SORT_ITEMS;

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
    round_count: &mut [u32; WG],
) {
    let l = lid as usize;
    if phase == 0 {
        if tile < params.blocks {
            running[l] = offsets[(lid * params.blocks + tile) as usize];
        }
        return;
    }
    let round = (phase - 1) / 3;
    let i = key_index(tile, round, lid);
    match (phase - 1) % 3 {
        0 => {
            digits[l] = if i < params.n { digit(keys_in[i as usize], params.shift) } else { NO_DIGIT };
        }
        1 => {
            let d = digits[l];
            // Nonzero only on the last invocation of each digit in this
            // round: how many keys of that digit the round held.
            round_count[l] = 0;
            if d != NO_DIGIT {
                let mut before = 0u32;
                let mut later = false;
                for j in 0..WORKGROUP_SIZE {
                    if digits[j as usize] == d {
                        if j < lid {
                            before += 1;
                        } else if j > lid {
                            later = true;
                        }
                    }
                }
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
