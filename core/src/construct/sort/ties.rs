//! Sorting by the high digits first, then settling ties: the same order as a
//! sort of every digit, in about half the passes where keys seldom agree in
//! their high digits.
//!
//! An LSD radix sort of the build's 63-bit Morton keys takes eight passes.
//! But a stable sort by the top half of the bits alone already puts every
//! key in its place except among keys equal in that half, which it leaves in
//! input order: runs of ties. Ordering each run by its keys' low bits,
//! stably, gives exactly the order of the full sort (a stable sort has one
//! result), so the trees built from it are the same bit for bit. With
//! eight bits more than `log2(n)` in the high digits, ties are rare and short on the
//! meshes and point sets measured (runs of two or three keys); so the host
//! sorts the high passes (`pass..passes` of [`SortParams`]; how many:
//! [`first_high_digit`]), then
//! [`settle_ties_kernel`] orders each run in place, one invocation per run.
//!
//! A run longer than [`MAX_TIE_RUN`] is not settled: the kernel raises a
//! flag, and the host sorts every digit instead (a small detailed mesh
//! inside a huge room falls into a handful of top-half cells: see
//! `treelet_core::construct::morton::SORTED_KEY_BITS`). That costs the high
//! passes once more than a plain sort; the flag is one word read back.
//!
//! The idea is an MSD-first split of an LSD sort; Onesweep (Adinets &
//! Merrill 2022) sorts every digit, as CUB does unless asked for fewer bits.
use crate::construct::sort::{RADIX_BITS, state};
use crate::geometry::buffers::SortParams;
use crate::gpu::atomics;

/// Longest run of ties one invocation settles (insertion sort in place).
pub const MAX_TIE_RUN: u32 = 32;

/// Bits the high digits keep beyond `log2(n)`: `n` keys spread evenly over
/// `2^(log2 n + 8)` cells share one with a chance of 1 in 256, and keys
/// crowded onto a mesh's surface still seldom fill 32 of one.
pub const TIE_MARGIN_BITS: u32 = 8;

/// The first of the high digits a sort of `n` keys over `passes` digits
/// takes first: enough of them for `log2(n) + TIE_MARGIN_BITS` bits (three
/// of eight digits up to 65 536 keys, four up to 2^24, five beyond).
#[inline]
pub const fn first_high_digit(n: u32, passes: u32) -> u32 {
    let log2 = 32 - n.saturating_sub(1).leading_zeros();
    let high = (log2 + TIE_MARGIN_BITS).div_ceil(RADIX_BITS);
    if high >= passes {
        0
    } else {
        passes - high
    }
}

/// The bits of `key` the sort orders by (the low `passes` digits), moved to
/// the top of the word: comparing them compares what the sort compares.
#[inline]
fn sorted_bits(key: u64, params: &SortParams) -> u64 {
    key << (64 - params.passes * RADIX_BITS)
}

/// The high digits (`params.pass..params.passes`) of a key's sorted bits.
#[inline]
fn high(key: u64, params: &SortParams) -> u64 {
    sorted_bits(key, params) >> (64 - (params.passes - params.pass) * RADIX_BITS)
}

/// Kernel, one invocation per key `i` of `params.n`, after a stable sort by
/// the high digits: the first key of a run of keys with equal high digits
/// orders the run by the low digits (insertion sort, stable), in place; a
/// run longer than [`MAX_TIE_RUN`] sets `sort_state[state::TIE_OVERFLOW]`
/// to 1 and stays as it is (`sort_state`: the sort's state, or zeroed words).
/// `params.pass` is the first high digit, `params.passes` all of them.
pub fn settle_ties_kernel(i: u32, params: &SortParams, keys: &mut [u64], values: &mut [u32], sort_state: &mut [u32]) {
    let n = params.n;
    if i >= n {
        return;
    }
    let first = i as usize;
    let h = high(keys[first], params);
    if i > 0 && high(keys[first - 1], params) == h {
        return; // inside a run: its first key settles it
    }
    let mut end = first + 1;
    while end < n as usize && end - first <= MAX_TIE_RUN as usize && high(keys[end], params) == h {
        end += 1;
    }
    if end - first > MAX_TIE_RUN as usize {
        atomics::store_u32(&mut sort_state[state::TIE_OVERFLOW as usize], 1);
        return;
    }
    let mut j = first + 1;
    while j < end {
        let (key, value) = (keys[j], values[j]);
        let bits = sorted_bits(key, params);
        let mut m = j;
        while m > first && sorted_bits(keys[m - 1], params) > bits {
            keys[m] = keys[m - 1];
            values[m] = values[m - 1];
            m -= 1;
        }
        keys[m] = key;
        values[m] = value;
        j += 1;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec;
    use std::vec::Vec;

    fn settle(keys: &mut [u64], values: &mut [u32], pass: u32, passes: u32) -> bool {
        let params = SortParams { n: keys.len() as u32, tiles: 0, pass, passes };
        let mut sort_state = vec![0u32; state::TIE_OVERFLOW as usize + 1];
        for i in 0..params.n {
            settle_ties_kernel(i, &params, keys, values, &mut sort_state);
        }
        sort_state[state::TIE_OVERFLOW as usize] == 1
    }

    #[test]
    fn high_digits_cover_log2_n_and_the_margin() {
        assert_eq!(first_high_digit(65_536, 8), 5); // 24 bits
        assert_eq!(first_high_digit(65_537, 8), 4);
        assert_eq!(first_high_digit(1_000_000, 8), 4); // 32 bits
        assert_eq!(first_high_digit(1 << 24, 8), 4);
        assert_eq!(first_high_digit((1 << 24) + 1, 8), 3);
        assert_eq!(first_high_digit(1000, 2), 0); // every digit
        assert_eq!(first_high_digit(2, 8), 6);
    }

    #[test]
    fn runs_of_ties_end_in_full_order_and_stay_stable() {
        // Sorted by the high 32 bits (stable), ties in input order.
        let input: Vec<u64> =
            vec![5 << 32 | 9, 5 << 32 | 3, 5 << 32 | 9, 5 << 32 | 1, 6 << 32 | 7, 7 << 32 | 2, 7 << 32 | 1];
        let mut keys = input.clone();
        let mut values: Vec<u32> = (0..keys.len() as u32).collect();
        assert!(!settle(&mut keys, &mut values, 4, 8));
        let mut expected: Vec<(u64, u32)> = input.into_iter().zip(0..).collect();
        expected.sort_by_key(|&(k, _)| k);
        assert_eq!(keys, expected.iter().map(|e| e.0).collect::<Vec<_>>());
        assert_eq!(values, expected.iter().map(|e| e.1).collect::<Vec<_>>(), "equal keys keep input order");
    }

    #[test]
    fn bits_above_the_sorted_digits_are_ignored() {
        // Sorting 4 digits (32 bits): bit 40 is not part of the key.
        let mut keys = vec![1u64 << 40 | 0x0001_0002, 0x0001_0001];
        let mut values = vec![0, 1];
        assert!(!settle(&mut keys, &mut values, 2, 4));
        assert_eq!(values, [1, 0]);
    }

    #[test]
    fn a_run_too_long_raises_the_flag_and_is_left_alone() {
        let n = MAX_TIE_RUN as u64 + 1;
        let mut keys: Vec<u64> = (0..n).rev().collect();
        let before = keys.clone();
        let mut values: Vec<u32> = (0..n as u32).collect();
        assert!(settle(&mut keys, &mut values, 4, 8));
        assert_eq!(keys, before);
        // One shorter settles.
        let mut keys: Vec<u64> = (0..n - 1).rev().collect();
        let mut values: Vec<u32> = (0..n as u32 - 1).collect();
        assert!(!settle(&mut keys, &mut values, 4, 8));
        assert!(keys.windows(2).all(|w| w[0] <= w[1]));
    }
}
