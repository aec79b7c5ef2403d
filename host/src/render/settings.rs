//! What a render is asked for: image size, samples, seed, tree, kernel and
//! estimator ([`RenderSettings`]), and how its samples are cut into
//! dispatches and passes.
use serde::Serialize;

use super::variant::KernelChoice;
use crate::bvh::layout::Layout;
use crate::bvh::tree::{tree_host_bytes, Accel};
use crate::runtime::backend::DeviceClass;

/// How radiance is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// smallpt's: emitters count only where a path hits them.
    Smallpt,
    /// Next-event estimation: a light sampled at every diffuse bounce, with
    /// multiple importance sampling.
    Nee,
    /// Next-event estimation, and light paths for the caustics it cannot
    /// find: light through mirrors and glass onto what the camera sees.
    Caustics,
}

impl Integrator {
    pub(super) fn code(self) -> u32 {
        match self {
            Integrator::Smallpt => treelet_core::geometry::buffers::SMALLPT,
            Integrator::Nee => treelet_core::geometry::buffers::NEE,
            Integrator::Caustics => treelet_core::geometry::buffers::CAUSTICS,
        }
    }

    /// The word the command line takes (`--integrator`).
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Smallpt => "smallpt",
            Integrator::Nee => "nee",
            Integrator::Caustics => "caustics",
        }
    }

    /// The integrator of a name [`Integrator::name`] gives.
    pub fn from_name(name: &str) -> Option<Integrator> {
        [Integrator::Smallpt, Integrator::Nee, Integrator::Caustics].into_iter().find(|i| i.name() == name)
    }

    /// What it is, for figures.
    pub fn label(self) -> &'static str {
        match self {
            Integrator::Smallpt => "smallpt's estimator",
            Integrator::Nee => "next-event estimation",
            Integrator::Caustics => "next-event estimation and light paths",
        }
    }
}

/// Where camera paths draw their sample points (`--sampler`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Sampler {
    /// Every number an independent hash of (seed, pixel, sample, bounce,
    /// dimension); sample s of a pixel in subpixel s mod 4 (smallpt's).
    Independent,
    /// The pixel position, the diffuse direction and the point on a light
    /// from Owen-scrambled Sobol pairs: less error at equal samples, as
    /// unbiased.
    Sobol,
}

impl Sampler {
    pub(super) fn code(self) -> u32 {
        match self {
            Sampler::Independent => treelet_core::geometry::buffers::INDEPENDENT,
            Sampler::Sobol => treelet_core::geometry::buffers::SOBOL,
        }
    }

    /// The word the command line takes (`--sampler`).
    pub fn name(self) -> &'static str {
        match self {
            Sampler::Independent => "independent",
            Sampler::Sobol => "sobol",
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel in all (smallpt's 2x2 subpixels take them in turn).
    pub spp: u32,
    pub seed: u32,
    pub accel: Accel,
    /// How the tree is laid out for traversal.
    pub layout: Layout,
    /// The render kernel: the smallest variant for the scene, or the general one.
    pub kernel: KernelChoice,
    pub integrator: Integrator,
    pub sampler: Sampler,
    /// Read the image back and measure its error after every pass (for a
    /// report or a reference); else only after the last, which saves a
    /// readback of the whole image per pass.
    pub error_each_pass: bool,
    /// The index of the first sample: a render of samples `first_sample ..
    /// first_sample + spp` is that part of a longer render (the random
    /// numbers are counted from (seed, pixel, sample)), so parts rendered
    /// apart add up to it (`treelet render --samples`, `treelet merge`).
    pub first_sample: u32,
}

impl RenderSettings {
    /// Camera paths the render traces: pixels times samples.
    pub fn paths(&self) -> u64 {
        self.width as u64 * self.height as u64 * self.spp as u64
    }
}

/// Camera paths per dispatch at most until a GPU's rate is known (and
/// always on CPU devices), so that no dispatch runs long enough for a
/// driver to time it out, whatever the sample count; a GPU's later
/// dispatches are sized to its rate ([`super::dispatch_size`]).
pub const MAX_PATHS_PER_DISPATCH: u64 = 1 << 22;

/// Samples per pixel per dispatch at most: each invocation loops over
/// that many camera paths of its pixel.
///
/// lavapipe (Mesa 22.3, LLVM 15) gets the image wrong when that loop is
/// long, and the CPU runner, which runs the same code, never does; the
/// cause is not known. Seen twice: far too dark at 512 samples a dispatch
/// with smallpt's estimator (cornell at 64x48 and 32x24; 256 were right),
/// and, with next-event estimation in the disk-lit room, most of the light
/// lost from the second dispatch on at 32 and 64 samples a dispatch (16x12
/// to 128x96; 24 and fewer were right at every size tried). CPU adapters
/// therefore take 16; more dispatches cost them little.
pub fn max_samples_per_dispatch(class: DeviceClass) -> u32 {
    match class {
        DeviceClass::CpuAdapter => 16,
        DeviceClass::Gpu | DeviceClass::CpuRunner => 64,
    }
}

/// Samples per pixel in one dispatch for an image of `pixels` on a device
/// of `class` (a GPU's first dispatches): as many as
/// [`MAX_PATHS_PER_DISPATCH`] and [`max_samples_per_dispatch`] allow, at
/// least one.
pub fn samples_per_dispatch(pixels: u64, class: DeviceClass) -> u32 {
    (MAX_PATHS_PER_DISPATCH / pixels.max(1)).clamp(1, max_samples_per_dispatch(class) as u64) as u32
}

/// Host bytes a render takes per pixel, whatever its devices: the f64
/// total, the f32 sums, the image and its encoding, and the CPU runner's
/// accumulation (measured: 74 bytes a pixel on the CPU runner between
/// 1000x1000 and 2000x1000); each device adds [`BYTES_PER_PIXEL_PER_DEVICE`].
pub const HOST_BYTES_PER_PIXEL: u64 = 80;
/// Each device's read-back sums, per pixel.
pub const BYTES_PER_PIXEL_PER_DEVICE: u64 = 16;
/// A render's host memory, estimated before anything is allocated.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MemoryEstimate {
    /// For the image: sums, read-backs, the image itself.
    pub image_bytes: u64,
    /// For the scene and the trees of the devices whose memory is the host's.
    pub scene_bytes: u64,
    pub total_bytes: u64,
}

impl MemoryEstimate {
    /// The estimate for `settings` over `prims` primitives on devices of `classes`.
    pub fn of(settings: &RenderSettings, prims: u64, classes: &[DeviceClass]) -> Self {
        let pixels = settings.width as u64 * settings.height as u64;
        let image_bytes =
            pixels.saturating_mul(HOST_BYTES_PER_PIXEL + BYTES_PER_PIXEL_PER_DEVICE * classes.len() as u64);
        let scene_bytes = classes.iter().map(|&c| tree_host_bytes(prims, c)).fold(0u64, u64::saturating_add);
        MemoryEstimate { image_bytes, scene_bytes, total_bytes: image_bytes.saturating_add(scene_bytes) }
    }

    /// The device memory a render takes on one device: its accumulation and
    /// the tree's buffers (the CPU runner's measured per-primitive bytes:
    /// the same buffers).
    pub fn device_bytes(settings: &RenderSettings, prims: u64) -> u64 {
        let pixels = settings.width as u64 * settings.height as u64;
        pixels.saturating_mul(BYTES_PER_PIXEL_PER_DEVICE).saturating_add(tree_host_bytes(prims, DeviceClass::CpuRunner))
    }

    /// Refuses the render if the machine has less memory available.
    pub fn check(&self, settings: &RenderSettings, prims: u64) -> anyhow::Result<()> {
        use crate::runtime::memory::{check_fits, human};
        let detail = format!(
            "{}x{} image: {}; scene and trees of {prims} primitives: {}",
            settings.width,
            settings.height,
            human(self.image_bytes),
            human(self.scene_bytes)
        );
        check_fits("this render", self.total_bytes, &detail)
    }
}

/// Cumulative sample counts after each pass: 4, 8, 16, ... then `spp`.
pub fn pass_schedule(spp: u32) -> Vec<u32> {
    let mut out = Vec::new();
    let mut s = 4u32.min(spp);
    while s < spp {
        out.push(s);
        s = s.saturating_mul(2);
    }
    out.push(spp);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_doubles_and_ends_at_spp() {
        assert_eq!(pass_schedule(1), vec![1]);
        assert_eq!(pass_schedule(4), vec![4]);
        assert_eq!(pass_schedule(64), vec![4, 8, 16, 32, 64]);
        assert_eq!(pass_schedule(100), vec![4, 8, 16, 32, 64, 100]);
    }
}
