//! Which builder finishes the work at hand first. The treelet-optimized
//! tree (Karras & Aila 2013) costs about ten times the LBVH's build and
//! saves time on every ray, H-PLOC's (where measured: GPUs) about three
//! times and saves less; which of them gives the least build plus
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
    ///   left out). After the faster treelet kernels of 2026-11-27
    ///   (`docs/results/h100-treelet-2026-11-27/log_choice_builds.txt`):
    ///   0.114 / 0.147 / 0.230 / 0.415 ms against 1.314 / 1.992 / 3.352 /
    ///   8.460 ms, 1.3 ms plus 6.8 ns a primitive more (within 0.13 ms of
    ///   each).
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
    ///
    /// On GPUs the TRBVH now ends with two iterations of reinsertion
    /// (`crate::bvh::trbvh::GPU_TRBVH_REINSERT`); measured on the H200
    /// (`docs/results/h200-reinsertion-2026-11-29/`, TRBVH with against
    /// without, build and layout): 0.58 / 1.16 / 1.05 / 1.63 / 3.12 ms more
    /// at 104k / 263k / 300k / 1M (terrain) / 1M (city) triangles, about
    /// 0.4 ms plus 1.9 ns a primitive, added to the build cost below; on
    /// terrain:1000000, diffuse rays at 888 against 867 M/s, 0.03 ns a ray
    /// more saved, added below. Its saving per camera path was not
    /// measured and is left as it was (the estimate errs towards the
    /// cheaper build).
    ///
    /// Since 2026-12-01 the TRBVH and H-PLOC split large triangles first
    /// (`crate::bvh::tree::DEFAULT_SPLITS`, the LBVH does not); measured on
    /// the H200 (`docs/results/h200-splits-2026-12-01/`, budget 0.3 against
    /// none): the TRBVH's build 0.07-0.13 ms longer on scans and terrain,
    /// 0.26-0.82 ms on the real-scene suite (104k to 1M triangles), about
    /// 0.2 ms plus 0.8 ns a primitive, added below; rays on terrain within
    /// 1% (no saving added; inside interiors with large walls they gain up
    /// to 1.5x, which the estimate leaves out, erring towards the cheaper
    /// build).
    ///
    /// The GPU's savings were measured again beside H-PLOC's
    /// ([`TreeletTradeOff::hploc`]), in one call
    /// (`docs/results/h100-hploc/log_choice.txt`): render kernels for the
    /// 32 spp between 4 and 36, 6.83 ns a path with the LBVH, 5.32 with the
    /// treelet-optimized tree, 5.80 with H-PLOC; diffuse rays at 689, 758
    /// and 729 M/s (0.131 and 0.079 ns a ray saved).
    ///
    /// Refit on the real-scene suite (H200, 2026-12-02,
    /// `docs/results/h200-builder-choice-2026-12-02/`: `bench rays --suite`,
    /// six interiors and cities of 104k to 1M triangles with large and long
    /// triangles, outside and inside each, 1920x1080, `fit.py`): the
    /// TRBVH's build and `bvh2` layout 3.04 ms plus 9.11 ns a primitive more
    /// than the LBVH's (a least-squares line over the six scenes; with its
    /// split triangles and reinsertion, which the terms above added up to
    /// 1.9 ms plus 9.5 ns), and 0.297 ns saved a diffuse ray (the median of
    /// the twelve scene-views, 0.08 to 1.66 ns; the terrain's 0.16 had
    /// halved it: scans and height fields are what the LBVH builds well).
    /// These replace the engine's terms; a render's saving per camera path
    /// is the terrain's still (not measured on the suite).
    pub fn of(class: DeviceClass) -> Self {
        match class {
            DeviceClass::Gpu => TreeletTradeOff {
                extra_build_ms: 3.04,
                extra_build_ns_per_prim: 9.11,
                saved_ns_per_path: 1.51,
                saved_ns_per_ray: 0.297,
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

impl TreeletTradeOff {
    /// What H-PLOC's tree costs and saves against the LBVH, where measured:
    /// GPUs (H100, `docs/results/h100-hploc/log_choice.txt`: builds of
    /// random spheres without the leaf collapse, which both trees' layouts
    /// do, 0.17 / 0.23 / 0.42 / 1.24 / 4.55 ms more than the LBVH's at 4 096
    /// / 65 536 / 262 144 / 1M / 4M primitives, about 0.15 ms plus 1.1 ns a
    /// primitive; terrain:1M in the room as above; with its triangles split
    /// since 2026-12-01, 0.06-0.43 ms more on the H200, about 0.1 ms plus
    /// 0.6 ns a primitive, added). Refit on the real-scene suite as
    /// [`TreeletTradeOff::of`] (H200, 2026-12-02): 0.42 ms plus 1.19 ns a
    /// primitive more, 0.154 ns saved a diffuse ray (the median; it was
    /// 0.079 on terrain); the saving per path is the terrain's. Not on CPU
    /// devices, where it is unmeasured: there the choice stays between the
    /// other two.
    pub fn hploc(class: DeviceClass) -> Option<Self> {
        match class {
            DeviceClass::Gpu => Some(TreeletTradeOff {
                extra_build_ms: 0.42,
                extra_build_ns_per_prim: 1.19,
                saved_ns_per_path: 1.03,
                saved_ns_per_ray: 0.154,
            }),
            DeviceClass::CpuAdapter | DeviceClass::CpuRunner => None,
        }
    }

    /// Build time added and trace time saved (ms) for `prims` primitives
    /// and `work`.
    fn weigh(&self, prims: usize, work: Work) -> (f64, f64) {
        let extra = self.extra_build_ms + self.extra_build_ns_per_prim * prims as f64 * 1e-6;
        let saved = match work {
            Work::Paths(p) => self.saved_ns_per_path * p as f64 * 1e-6,
            Work::Rays(r) => self.saved_ns_per_ray * r as f64 * 1e-6,
        };
        (extra, saved)
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

/// The builder (LBVH, H-PLOC where measured, or treelet-optimized) with the
/// least build plus trace time for `work` over `prims` primitives on
/// `class`, and why, in words. Ties go to the shorter build (the shorter
/// wait before the first ray).
pub fn cheaper_builder(class: DeviceClass, prims: usize, work: Work) -> (Builder, String) {
    let what = match work {
        Work::Paths(p) => format!("{:.1}M camera paths", p as f64 * 1e-6),
        Work::Rays(r) => format!("{:.1}M rays per build", r as f64 * 1e-6),
    };
    let on = match class {
        DeviceClass::Gpu => "a GPU",
        DeviceClass::CpuAdapter => "a CPU Vulkan adapter",
        DeviceClass::CpuRunner => "the CPU runner",
    };
    // In order of build time: the first of equal net times wins.
    let mut options = vec![(Builder::Lbvh, "the LBVH", 0.0, 0.0)];
    if let Some(h) = TreeletTradeOff::hploc(class) {
        let (extra, saved) = h.weigh(prims, work);
        options.push((Builder::Hploc, "the H-PLOC tree", extra, saved));
    }
    let (extra, saved) = TreeletTradeOff::of(class).weigh(prims, work);
    options.push((Builder::Trbvh, "the treelet-optimized tree", extra, saved));
    let best = options.iter().fold(options[0], |best, &o| if o.2 - o.3 < best.2 - best.3 { o } else { best });
    let weighed: Vec<String> = options[1..]
        .iter()
        .map(|&(_, name, extra, saved)| format!("{name}: about {saved:.1} ms of rays saved, {extra:.1} ms more build"))
        .collect();
    let why = if best.0 == Builder::Lbvh {
        format!(
            "for {what} on {on} over {prims} primitives, no faster tree's rays pay for its longer build, as measured ({})",
            weighed.join("; ")
        )
    } else {
        format!(
            "for {what} on {on} over {prims} primitives, {} pays for its longer build with faster rays, the most of the trees, as measured ({})",
            best.1,
            weighed.join("; ")
        )
    };
    (best.0, why)
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
    fn the_choice_only_moves_to_longer_builds_as_work_grows() {
        let rank = |b: Builder| [Builder::Lbvh, Builder::Hploc, Builder::Trbvh].iter().position(|&x| x == b).unwrap();
        for class in [DeviceClass::Gpu, DeviceClass::CpuAdapter, DeviceClass::CpuRunner] {
            for work in [Work::Paths as fn(u64) -> Work, Work::Rays] {
                let mut last = Builder::Lbvh;
                for e in 0..40 {
                    let b = cheaper_builder(class, 100_000, work(1u64 << e)).0;
                    assert!(rank(b) >= rank(last), "{class:?}: {last:?} then {b:?} as the work doubled to 2^{e}");
                    last = b;
                }
            }
            // The extremes tests/tracer.rs relies on.
            assert_eq!(cheaper_builder(class, 100_000, Work::Rays(1)).0, Builder::Lbvh);
            assert_eq!(cheaper_builder(class, 100_000, Work::Rays(1 << 40)).0, Builder::Trbvh);
        }
    }

    #[test]
    fn hploc_wins_between_the_two_on_a_gpu_only() {
        // A million primitives of a real scene: the H-PLOC tree pays for
        // itself from about 10M rays, the treelets (with their reinsertion)
        // beat it from about 74M (both with their split triangles).
        let n = 1_000_000;
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Rays(40_000_000)).0, Builder::Hploc);
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Rays(5_000_000)).0, Builder::Lbvh);
        assert_eq!(cheaper_builder(DeviceClass::Gpu, n, Work::Rays(100_000_000)).0, Builder::Trbvh);
        for class in [DeviceClass::CpuAdapter, DeviceClass::CpuRunner] {
            for e in 0..40 {
                assert_ne!(cheaper_builder(class, n, Work::Rays(1 << e)).0, Builder::Hploc, "{class:?}");
            }
        }
    }

    #[test]
    fn the_reason_names_the_numbers_weighed() {
        let (_, why) = cheaper_builder(DeviceClass::Gpu, 940_544, Work::Paths(1024 * 768 * 16));
        assert!(why.contains("12.6M camera paths") && why.contains("940544 primitives"), "{why}");
    }
}
