//! How many samples of every pixel one render dispatch traces.
//!
//! Each invocation loops over its pixel's samples of the dispatch, starting
//! the next path where the last ended, so a warp runs as long as its lane
//! with the longest paths in sum: the more samples a dispatch, the closer
//! that is to the mean. On an H200 (1024x768, 1024 spp, render kernels,
//! `docs/results/h200-dispatch-size-2026-11-28/`) cornell took 0.778 s at
//! 5 samples a dispatch (4M paths, the fixed size before), 0.672 at 10,
//! 0.550 at 64 and 0.527 at 256; `scenes/room_disk.json` 1.183, 0.888 and
//! 0.852 s.
//!
//! A long dispatch must not outlast a driver's watchdog (Windows resets a
//! GPU after 2 s, i915 preempts compute after 640 ms), so on a GPU the size
//! follows the device's measured rate: the first dispatches keep the old
//! size ([`samples_per_dispatch`]), later ones take about [`DISPATCH_S`] of
//! kernel time (at most 1.42 times that), a power of two of samples (so
//! the size, and with it the sums' rounding, seldom changes between runs). The CPU runner and CPU
//! adapters keep the fixed size: the runner's resumed renders repeat its
//! dispatches bit for bit, and lavapipe gets long loops wrong
//! (see [`max_samples_per_dispatch`](super::settings::max_samples_per_dispatch)).
//! A GPU's chunk is cut across the ends of passes unless each pass is
//! scored (`run::device_loop`): cornell 0.543 -> 0.530 s on the H200.
use super::settings::samples_per_dispatch;
use crate::runtime::backend::DeviceClass;

/// Kernel seconds a GPU's render dispatch aims at, once its rate is known.
pub const DISPATCH_S: f64 = 0.2;

/// Samples per pixel in one GPU dispatch at most (beyond 256 the H200
/// rendered cornell under 1% faster).
pub const MAX_GPU_SAMPLES_PER_DISPATCH: u32 = 1024;

/// The samples per pixel of a device's next dispatches.
#[derive(Clone, Debug)]
pub struct DispatchSize {
    class: DeviceClass,
    samples: u32,
}

impl DispatchSize {
    /// The size for an image of `pixels` on a device of `class` before any
    /// dispatch has been timed.
    pub fn new(pixels: u64, class: DeviceClass) -> Self {
        DispatchSize { class, samples: samples_per_dispatch(pixels, class) }
    }

    /// Samples per pixel in the next dispatch.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// After the device traced `samples` samples of every pixel in
    /// `kernel_s` seconds of kernels: on a GPU, the size that takes about
    /// [`DISPATCH_S`] at that rate. A short run's launch overhead makes
    /// its rate low, never high, so only runs too short to time at all
    /// (under 10 µs) are passed over.
    pub fn measured(&mut self, samples: u32, kernel_s: f64) {
        if self.class != DeviceClass::Gpu || samples == 0 || !(kernel_s >= 1e-5) || !kernel_s.is_finite() {
            return;
        }
        let fits = (samples as f64 / kernel_s * DISPATCH_S).clamp(1.0, MAX_GPU_SAMPLES_PER_DISPATCH as f64);
        // The nearest power of two (at most 1.42 DISPATCH_S).
        self.samples = 1 << (fits.log2().round() as u32);
    }

    /// `count` samples cut into dispatches of at most [`Self::samples`],
    /// as even as whole samples allow (a last short dispatch would run
    /// with less work per lane than the others).
    pub fn cuts(&self, count: u32) -> impl Iterator<Item = u32> {
        let n = count.div_ceil(self.samples.max(1)).max(1);
        let (base, extra) = (count / n, count % n);
        (0..n).map(move |i| base + u32::from(i < extra)).filter(|&s| s > 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PIXELS: u64 = 1024 * 768;

    #[test]
    fn a_gpu_grows_its_dispatches_to_the_time_aimed_at() {
        let mut d = DispatchSize::new(PIXELS, DeviceClass::Gpu);
        assert_eq!(d.samples(), 5); // 4M paths
        // 400 samples in 0.25 s: 320 fit in DISPATCH_S, so 256 (nearer
        // than 512 in ratio); 470: 376 fit, so 512.
        d.measured(400, 0.25);
        assert_eq!(d.samples(), 256);
        d.measured(470, 0.25);
        assert_eq!(d.samples(), 512);
        // A device 100 times slower: 4 samples (3.76).
        d.measured(470, 25.0);
        assert_eq!(d.samples(), 4);
        // Slower still: one sample a dispatch, never none.
        d.measured(1, 10.0);
        assert_eq!(d.samples(), 1);
        // Very fast: capped.
        d.measured(1000, 0.002);
        assert_eq!(d.samples(), MAX_GPU_SAMPLES_PER_DISPATCH);
        // Untimed or too short to time: kept.
        for s in [0.0, 1e-6, f64::NAN, f64::INFINITY] {
            d.measured(4, s);
            assert_eq!(d.samples(), MAX_GPU_SAMPLES_PER_DISPATCH);
        }
    }

    #[test]
    fn cpu_devices_keep_their_fixed_size() {
        for class in [DeviceClass::CpuRunner, DeviceClass::CpuAdapter] {
            let mut d = DispatchSize::new(128 * 96, class);
            let fixed = d.samples();
            d.measured(1000, 0.01);
            assert_eq!(d.samples(), fixed, "{class:?}");
        }
    }

    #[test]
    fn cuts_are_even_and_add_up() {
        let mut d = DispatchSize::new(PIXELS, DeviceClass::Gpu);
        d.measured(256, DISPATCH_S);
        assert_eq!(d.samples(), 256);
        assert!(DISPATCH_S * 1.42 < 0.64, "within i915's preemption timeout");
        for count in [0u32, 1, 255, 256, 257, 470, 1024, 1025] {
            let cuts: Vec<u32> = d.cuts(count).collect();
            assert_eq!(cuts.iter().sum::<u32>(), count, "{count}");
            assert!(cuts.iter().all(|&c| (1..=256).contains(&c)), "{count}: {cuts:?}");
            let (lo, hi) = (cuts.iter().min(), cuts.iter().max());
            assert!(hi.zip(lo).is_none_or(|(h, l)| h - l <= 1), "{count}: {cuts:?}");
            assert_eq!(cuts.len() as u32, count.div_ceil(256), "{count}");
        }
    }
}
