//! The compressed 8-wide node format (Ylitie, Karras & Laine 2017): children
//! per node, leaf sizes, and the quantization of child boxes to a node's
//! own grid, rounded outwards so the dequantized box always contains the
//! exact one. The builder is [`crate::layouts::cwbvh::build`], the traversal
//! [`crate::trace::cwbvh`].

pub mod build;

/// Children per node.
pub const WIDTH: usize = 8;
/// Most primitives in one leaf child (three bits of unary count in `meta`).
pub const MAX_LEAF_PRIMS: u32 = 3;
/// Flag of an internal child's `meta` byte: `0b001` over `24 + slot`.
pub const META_INTERNAL: u32 = 0b001_00000;

/// The grid step `2^(e - 127)` of a biased exponent byte `e` (1..=254).
#[inline]
pub fn grid_step(biased: u32) -> f32 {
    f32::from_bits(biased << 23)
}

/// The biased exponent (`e + 127`, at most 254) of a grid step `s = 2^e`
/// with `lo + 254 s > hi` as f32 arithmetic computes it: the node `lo..hi`
/// fits 254 steps with room to spare, so every child's upper plane can be
/// rounded strictly above its box (see [`quantize_hi`]). The smallest such
/// step from a guess, in a few doublings.
///
/// Quantization relies only on single, correctly rounded operations and
/// comparisons, never on error-free transformations (two-sums): Mesa's
/// shader compilers may rewrite `a - (a - b)` into `b` unless an operation
/// is marked exact, which rust-gpu does not do (seen on lavapipe).
#[inline]
pub fn grid_exponent(lo: f32, hi: f32) -> u32 {
    // Never below an ulp of the coordinates: a thinner node needs no finer grid.
    let magnitude = lo.abs().max(hi.abs());
    let ulp = f32::from_bits(magnitude.to_bits() & 0x7F80_0000) * (1.0 / 8_388_608.0);
    let span = (hi - lo).max(ulp);
    let guess = ((span * (1.0 / 254.0)).to_bits() >> 23) & 0xFF; // floor(log2) + 127, or 0
    let mut biased = if guess > 2 { guess - 1 } else { 1 };
    let mut k = 0;
    while k < 8 && biased < 254 && lo + 254.0 * grid_step(biased) <= hi {
        biased += 1;
        k += 1;
    }
    biased
}

/// The largest `q` in `0..=254` with `origin + q s < lo` as f32 arithmetic
/// computes it, or 0 (`origin` itself, the node's lower corner, is `<= lo`).
/// A float sum strictly below `lo` is below it in real numbers too, so the
/// plane contains `lo` exactly. The guess from a division is mended both
/// ways, so the answer is the same whatever the division's rounding (GPUs
/// may divide within a few ulps).
#[inline]
pub fn quantize_lo(lo: f32, origin: f32, s: f32) -> u32 {
    let below = move |q: f32| q == 0.0 || origin + q * s < lo;
    let mut q = libm::floorf((lo - origin) / s).clamp(0.0, 254.0);
    let mut k = 0;
    while k < 4 && q < 254.0 && below(q + 1.0) {
        q += 1.0;
        k += 1;
    }
    while k < 8 && !below(q) {
        q -= 1.0;
        k += 1;
    }
    if !below(q) {
        q = 0.0; // a guess off by more than the loops mend: the corner is safe
    }
    q as u32
}

/// The smallest `q` in `0..=254` with `origin + q s > hi` as f32 arithmetic
/// computes it (254 always is, by [`grid_exponent`]): a float sum strictly
/// above `hi` is above it in real numbers too. Mended both ways, as
/// [`quantize_lo`].
#[inline]
pub fn quantize_hi(hi: f32, origin: f32, s: f32) -> u32 {
    let above = move |q: f32| q >= 254.0 || origin + q * s > hi;
    let mut q = libm::ceilf((hi - origin) / s).clamp(0.0, 254.0);
    let mut k = 0;
    while k < 4 && q > 0.0 && above(q - 1.0) {
        q -= 1.0;
        k += 1;
    }
    while k < 8 && !above(q) {
        q += 1.0;
        k += 1;
    }
    if !above(q) {
        q = 254.0;
    }
    q as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_fits_the_extent_with_room() {
        for (lo, hi) in [(0.0f32, 1.0f32), (-3.0, 7.5), (1e30, 1.0000001e30), (-1e-30, 1e-30), (5.0, 5.0), (0.1, 0.3), (1e6, 1e6)] {
            let e = grid_exponent(lo, hi);
            let s = grid_step(e) as f64;
            assert!(lo as f64 + 254.0 * s > hi as f64, "{lo}..{hi}: step {s} too small");
            assert!(e < 254);
        }
    }

    #[test]
    fn quantized_planes_contain_the_exact_box() {
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        for _ in 0..20_000 {
            let scale = [1e-20f32, 1e-3, 1.0, 1e4, 1e20][(next() * 5.0) as usize % 5];
            let offset = [0.0f32, 1.0, -1e6, 3e8][(next() * 4.0) as usize % 4];
            let (a, b) = (offset + next() * scale, offset + next() * scale);
            let (lo, hi) = (a.min(b), a.max(b));
            let (c0, c1) = (lo + (hi - lo) * next(), lo + (hi - lo) * next());
            let (clo, chi) = (c0.min(c1).max(lo), c0.max(c1).min(hi));
            let e = grid_exponent(lo, hi);
            let s = grid_step(e);
            let (ql, qh) = (quantize_lo(clo, lo, s), quantize_hi(chi, lo, s));
            assert!(ql <= qh && qh <= 254, "{lo}..{hi} child {clo}..{chi}: {ql} {qh}");
            // In exact arithmetic: f64 holds these sums exactly where the
            // step is not far below the coordinates' ulp, and rounds them
            // towards the f32 values otherwise (a weaker check there).
            let (pl, ph) = (lo as f64 + ql as f64 * s as f64, lo as f64 + qh as f64 * s as f64);
            assert!(pl <= clo as f64 && ph >= chi as f64, "{lo}..{hi} child {clo}..{chi}: {pl} {ph}");
        }
    }
}
