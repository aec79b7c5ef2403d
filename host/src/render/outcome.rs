//! What a render gives back: the image and its per-pixel sums, the error
//! after each pass, each device's share, and whether it stopped early.
use std::ops::Range;

use serde::Serialize;

use super::image_io::HdrImage;
use super::variant::Plan;

/// The error of the image after one pass.
#[derive(Clone, Debug, Serialize)]
pub struct PassRow {
    pub pass: u32,
    /// Samples per pixel so far.
    pub spp: u32,
    /// Seconds since the render started (BVH build included).
    pub elapsed_s: f64,
    /// The wall time a render that stopped after this pass would have taken:
    /// `elapsed_s` less the readbacks and scoring of earlier passes, which
    /// only the error measurement needs.
    pub wall_s: f64,
    /// Kernel time so far (BVH build and render kernels; GPU timestamps
    /// where available).
    pub kernel_s: f64,
    /// Root mean square error against the reference (per channel).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rmse: Option<f64>,
    /// Mean of `(x - ref)² / (ref² + 0.01)` against the reference.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rel_mse: Option<f64>,
    /// Without a reference: mean over pixels of the standard error of the
    /// pixel's mean luminance, from its sample variance. That treats the
    /// samples as independent: with `--sampler sobol`, whose points are
    /// not, the true error is smaller (an upper estimate).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_std_error: Option<f64>,
}

/// A finished (or stopped) render.
pub struct RenderResult {
    pub image: HdrImage,
    /// Per pixel, the sums of radiance (r, g, b) and of squared luminance
    /// over the samples rendered: what parts of a render add up.
    pub sums: Vec<[f32; 4]>,
    pub rows: Vec<PassRow>,
    /// BVH build time on the device (ms; 0 without a BVH).
    pub build_ms: f64,
    /// Render-kernel time, summed (ms; GPU timestamps where available).
    pub render_ms: f64,
    pub total_s: f64,
    /// What ran (acceleration structure, kernel variant) and why (on the
    /// first device that prepared the render).
    pub plan: Plan,
    /// The samples in `sums`: `first..last`. Short of what was asked when
    /// the render stopped early.
    pub samples: Range<u32>,
    /// Why the render stopped before its last sample, if it did.
    pub stopped: Option<Stopped>,
    /// What each device did.
    pub shares: Vec<Share>,
}

/// Why a render stopped before its last sample.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Stopped {
    /// Asked to stop (Ctrl-C): the chunks under way were finished and kept.
    Interrupted,
    /// Every device failed; the samples read back before are kept.
    Failed(String),
}

/// What one device did.
#[derive(Clone, Debug, Serialize)]
pub struct Share {
    pub device: String,
    /// Samples per pixel it rendered (and that were read back).
    pub samples: u32,
    pub chunks: u32,
    /// Samples per pixel in its largest dispatch (see
    /// [`super::dispatch_size`]).
    pub dispatch_samples: u32,
    /// Wall seconds from its start to its last chunk.
    pub seconds: f64,
    /// Its rate: camera paths per second.
    pub paths_per_s: f64,
    /// Why it stopped early, if it did (its unfinished chunks went to the others).
    pub failed: Option<String>,
    /// Where its time went: preparing (tree build, uploads; wall), render
    /// kernels (GPU timestamps where available), reading its sums back.
    pub prepare_s: f64,
    /// Of `prepare_s`, the tree's build and layout on the device (device time).
    pub build_s: f64,
    pub kernel_s: f64,
    pub read_s: f64,
}
