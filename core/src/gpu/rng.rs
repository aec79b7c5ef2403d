//! Counter-based random numbers: every draw is a hash of (seed, pixel,
//! sample, bounce, dimension), so a GPU and a CPU render of one seed draw the
//! same numbers for the same path, in any order of execution.
//!
//! The mixer is Chris Wellons' `lowbias32` (a 32-bit integer hash with low
//! bias, found by his hash-prospector).

/// `lowbias32`: a bijective 32-bit mixer.
#[inline]
pub fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The random stream of one bounce of one path.
///
/// ```
/// use treelet_core::gpu::rng::BounceRng;
/// let rng = BounceRng::new(7, 1234, 0, 2); // seed, pixel, sample, bounce
/// let u = rng.uniform(0);
/// assert!((0.0..1.0).contains(&u));
/// assert_eq!(u, BounceRng::new(7, 1234, 0, 2).uniform(0)); // counter-based: repeatable
/// ```
#[derive(Clone, Copy)]
pub struct BounceRng {
    key: u32,
}

impl BounceRng {
    #[inline]
    pub fn new(seed: u32, pixel: u32, sample: u32, bounce: u32) -> Self {
        let key = hash(hash(hash(seed ^ 0x9e37_79b9) ^ pixel) ^ sample.wrapping_mul(0x85eb_ca6b));
        Self { key: hash(key ^ bounce.wrapping_mul(0xc2b2_ae35)) }
    }

    /// The word the stream is keyed by (to keep a stream in one word).
    #[inline]
    pub fn key(&self) -> u32 {
        self.key
    }

    /// The stream [`Self::key`] gave.
    #[inline]
    pub fn from_key(key: u32) -> Self {
        Self { key }
    }

    /// Uniform in `[0, 1)`, 24 bits, for dimension `dim` of this bounce.
    #[inline]
    pub fn uniform(&self, dim: u32) -> f32 {
        let bits = hash(self.key ^ dim.wrapping_mul(0x2545_f491).wrapping_add(0x68e3_1da4));
        (bits >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_is_in_range_and_roughly_flat() {
        let mut bins = [0u32; 16];
        for sample in 0..20_000 {
            let u = BounceRng::new(7, 123, sample, 0).uniform(0);
            assert!((0.0..1.0).contains(&u));
            bins[(u * 16.0) as usize] += 1;
        }
        // 1250 expected per bin; 5 sigma is about 175.
        assert!(bins.iter().all(|&b| (1075..1425).contains(&b)), "{bins:?}");
    }

    #[test]
    fn streams_differ_by_every_key() {
        let base = BounceRng::new(1, 2, 3, 4).uniform(0);
        assert_ne!(base, BounceRng::new(9, 2, 3, 4).uniform(0));
        assert_ne!(base, BounceRng::new(1, 9, 3, 4).uniform(0));
        assert_ne!(base, BounceRng::new(1, 2, 9, 4).uniform(0));
        assert_ne!(base, BounceRng::new(1, 2, 3, 9).uniform(0));
        assert_ne!(base, BounceRng::new(1, 2, 3, 4).uniform(1));
    }
}
