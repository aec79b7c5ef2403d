//! Which builder finishes the work at hand first. The treelet-optimized
//! tree (Karras & Aila 2013) costs about ten times the LBVH's build and
//! saves time on every ray; which of the two gives the least build plus
//! trace time depends on how much one build is used: the camera paths of a
//! render, or the rays an engine traces per build. `--accel auto` and the
//! engine API's [`crate::tracer::Quality::ForRays`] ask here.
//!
//! The trade-off is measured per device class ([`TreeletTradeOff::of`]);
//! it depends on the scene too, so the choice is an estimate, and
//! `--explain` says what it weighed.
use crate::bvh::tree::Builder;
use crate::runtime::backend::DeviceClass;

/// What the treelet-optimized tree costs and saves against the LBVH on one
/// class of device (both laid out as `bvh2`, or `cwbvh` on lavapipe).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeletTradeOff {
    /// Extra build time whatever the size (the treelet rounds' dispatches), ms.
    pub extra_build_ms: f64,
    /// Extra build and layout time per primitive, ns.
    pub extra_build_ns_per_prim: f64,
    /// Render time saved per camera path, ns (negative: its paths are slower).
    pub saved_ns_per_path: f64,
    /// Time saved per ray cast alone (the engine API's closest hits), ns.
    pub saved_ns_per_ray: f64,
}

impl TreeletTradeOff {
    /// The measured trade-off of `class`.
    ///
    /// - GPU (H100, 2026-11-26, `docs/results/h100-builder-choice/`):
    ///   `terrain:1000000` in smallpt's room, 1024x768 at 4 and 36 spp, twice
    ///   each: the render kernels' time for the 32 spp between is 7.16 ns a
    ///   path with the LBVH and 5.50 with the treelet-optimized tree;
    ///   `bench rays --mesh-only` at 1920x1080: diffuse rays at 602 against
    ///   679 M/s, 0.19 ns a ray saved (at 16 384 triangles 0.085 ns).
    ///   `bench build`, LBVH against treelet-optimized, measured again after
    ///   the faster sort and treelet kernels (`log_builds_after_sort.txt`):
    ///   0.18 / 0.23 / 0.40 / 0.81 ms against 1.43 / 2.20 / 3.81 / 9.81 ms at
    ///   4 096 / 65 536 / 262 144 / 1M primitives: 1.4 ms plus 7.6 ns a
    ///   primitive more, a least-squares line within 0.16 ms of each (it
    ///   was 1.5 ms plus 8.5 ns; the layouts: 0.72 against 0.56 ms at 1M,
    ///   left out).
    /// - CPU Vulkan adapter (lavapipe on two cores, `cwbvh`):
    ///   `terrain:50000` in the room, 128x96 at 4 and 20 spp: 5.04 against
    ///   4.88 µs a path; builds 47 ms against 2 567 ms; `bench rays` at
    ///   256x192: diffuse rays 65.1 against 55.3 ms, 0.20 µs a ray.
    /// - CPU runner (two cores, noisy): `terrain:200000` in the room, 128x96,
    ///   the samples between 16 and 80 spp and twice between 8 and 40: 1.45,
    ///   1.44 and 1.54 µs a path with the LBVH, 1.63, 1.22 and 1.11 with the
    ///   treelet-optimized tree (medians 1.45 and 1.22); builds 159 + 77 ms
    ///   against 1 088 + 54 ms for 200k triangles, 4.5 µs a primitive more;
    ///   `bench rays --mesh-only` at 512x384: diffuse rays 196.8 against
    ///   170.3 ms, 0.13 µs a ray saved.
    pub fn of(class: DeviceClass) -> Self {
        match class {
            DeviceClass::Gpu => TreeletTradeOff {
                extra_build_ms: 1.4,
                extra_build_ns_per_prim: 7.6,
                saved_ns_per_path: 1.66,
                saved_ns_per_ray: 0.19,
            },
            // On CPU cores the per-primitive cost dwarfs any fixed one.
            DeviceClass::CpuAdapter => TreeletTradeOff {
                extra_build_ms: 0.0,
                extra_build_ns_per_prim: 50_400.0,
                saved_ns_per_path: 160.0,
                saved_ns_per_ray: 200.0,
            },
            DeviceClass::CpuRunner => TreeletTradeOff {
                extra_build_ms: 0.0,
                extra_build_ns_per_prim: 4_500.0,
                saved_ns_per_path: 230.0,
                saved_ns_per_ray: 135.0,
            },
        }
    }
}

/// How much one build is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    /// Camera paths of a render (pixels times samples).
    Paths(u64),
    /// Rays an engine traces per build.
    Rays(u64),
}

/// The builder (LBVH or treelet-optimized) with the least build plus trace
/// time for `work` over `prims` primitives on `class`, and why, in words.
/// Ties go to the LBVH (the shorter wait before the first ray).
pub fn cheaper_builder(class: DeviceClass, prims: usize, work: Work) -> (Builder, String) {
    let t = TreeletTradeOff::of(class);
    let extra_ms = t.extra_build_ms + t.extra_build_ns_per_prim * prims as f64 * 1e-6;
    let (saved_ms, what) = match work {
        Work::Paths(p) => (t.saved_ns_per_path * p as f64 * 1e-6, format!("{:.1}M camera paths", p as f64 * 1e-6)),
        Work::Rays(r) => (t.saved_ns_per_ray * r as f64 * 1e-6, format!("{:.1}M rays per build", r as f64 * 1e-6)),
    };
    let on = match class {
        DeviceClass::Gpu => "a GPU",
        DeviceClass::CpuAdapter => "a CPU Vulkan adapter",
        DeviceClass::CpuRunner => "the CPU runner",
    };
    let builder = if saved_ms > extra_ms { Builder::Trbvh } else { Builder::Lbvh };
    let verdict = if builder == Builder::Trbvh { "pays for" } else { "does not pay for" };
    let why = format!(
        "for {what} on {on}, the treelet-optimized tree's faster rays (about {saved_ms:.1} ms saved, as measured) {verdict} its longer build (about {extra_ms:.1} ms more for {prims} primitives)"
    );
    (builder, why)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_work_pays_for_the_treelets_on_a_gpu_short_work_does_not() {
        let n = 1_000_000;
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Paths(1024 * 768)).0, Builder::Lbvh);
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Paths(1024 * 768 * 64)).0, Builder::Trbvh);
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Rays(2_000_000)).0, Builder::Lbvh);
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Rays(1_000_000_000)).0, Builder::Trbvh);
        // A small scene's treelets cost their dispatches: a frame's rays do
        // not pay for them, a hundred frames' do.
        assert_eq!(cheaper_builder(DeviceClass::Gpu, 10_000, Work::Rays(2_000_000)).0, Builder::Lbvh);
        assert_eq!(cheaper_builder(DeviceClass::Gpu, 10_000, Work::Rays(200_000_000)).0, Builder::Trbvh);
    }

    #[test]
    fn the_choice_flips_once_as_work_grows() {
        for class in [DeviceClass::Gpu, DeviceClass::CpuAdapter, DeviceClass::CpuRunner] {
            for work in [Work::Paths as fn(u64) -> Work, Work::Rays] {
                let mut flips = 0;
                let mut last = Builder::Lbvh;
                for e in 0..40 {
                    let b = cheaper_builder(class, 100_000, work(1u64 << e)).0;
                    flips += (b != last) as u32;
                    last = b;
                }
                assert!(flips <= 1, "{class:?}: the choice flips {flips} times");
            }
            // The extremes tests/tracer.rs relies on.
            assert_eq!(cheaper_builder(class, 100_000, Work::Rays(1)).0, Builder::Lbvh);
            assert_eq!(cheaper_builder(class, 100_000, Work::Rays(1 << 40)).0, Builder::Trbvh);
        }
    }

    #[test]
    fn the_reason_names_the_numbers_weighed() {
        let (_, why) = cheaper_builder(DeviceClass::Gpu, 940_544, Work::Paths(1024 * 768 * 16));
        assert!(why.contains("12.6M camera paths") && why.contains("940544 primitives"), "{why}");
    }
}
