//! A render, pass by pass, over any [`Backend`]: the BVH (if any) is built
//! on the device, then each pass adds samples to every pixel and the error
//! is measured, against a reference image or from the per-pixel variance.
pub mod devices;
pub mod image_io;
pub mod parts;
pub mod variant;

use std::time::Instant;

use anyhow::{bail, Result};
use serde::Serialize;
use treelet_core::geometry::buffers::RenderParams;
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};
use treelet_core::render::integrator::tiled_invocations;
use treelet_core::render::lights::{Light, light_power};
use treelet_core::render::sampling::luminance;

use crate::bvh::layout::{Layout, PrimBuffers, TracedTree};
use crate::bvh::tree::{traced_tree, Accel};
use crate::bvh::lbvh;
use crate::runtime::backend::{Backend, DeviceClass};
use crate::runtime::kernels::Kernel;
use crate::scene::Scene;
use crate::scene::primitives::Primitives;
use image_io::HdrImage;
use variant::{KernelChoice, Plan};

/// How radiance is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// smallpt's: emitters count only where a path hits them.
    Smallpt,
    /// Next-event estimation: a light sampled at every diffuse bounce, with
    /// multiple importance sampling (`treelet_core::render::lights`).
    Nee,
}

impl Integrator {
    fn code(self) -> u32 {
        match self {
            Integrator::Smallpt => treelet_core::geometry::buffers::SMALLPT,
            Integrator::Nee => treelet_core::geometry::buffers::NEE,
        }
    }

    /// The word the command line takes (`--integrator`).
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Smallpt => "smallpt",
            Integrator::Nee => "nee",
        }
    }

    /// What it is, for figures.
    pub fn label(self) -> &'static str {
        match self {
            Integrator::Smallpt => "smallpt's estimator",
            Integrator::Nee => "next-event estimation",
        }
    }
}

/// The light table of `prims` (spheres then triangles, one material each):
/// every emitter, chosen in proportion to its power
/// (`treelet_core::render::lights::light_power`), in primitive order. Empty
/// without emitters.
pub fn light_table(prims: Primitives, materials: &[treelet_core::geometry::buffers::Material]) -> Vec<Light> {
    let p = prims.as_core();
    let powers: Vec<(u32, f64)> = (0..p.count())
        .map(|i| (i, light_power(&p, materials, i) as f64))
        .filter(|&(_, w)| w > 0.0 && w.is_finite())
        .collect();
    let total: f64 = powers.iter().map(|&(_, w)| w).sum();
    let mut cumulative = 0.0;
    let mut table: Vec<Light> = powers
        .iter()
        .map(|&(prim, w)| {
            cumulative += w;
            Light { prim, pmf: (w / total) as f32, cdf: (cumulative / total) as f32, _pad: 0 }
        })
        .collect();
    if let Some(last) = table.last_mut() {
        last.cdf = 1.0; // Whatever rounding did, the last light takes the rest.
    }
    table
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

/// Camera paths per dispatch at most, so that no dispatch runs long enough
/// for a driver to time it out, whatever the sample count.
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
    /// pixel's mean luminance, from its sample variance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_std_error: Option<f64>,
}

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
    /// What ran (acceleration structure, kernel variant) and why.
    pub plan: Plan,
}

/// Adds per-pixel sums (radiance r, g, b and squared luminance) of one
/// part of a render into `total`, in f64 so that many parts add without
/// loss (devices, `treelet merge`).
pub fn add_sums<T: Copy + Into<f64>>(total: &mut [[f64; 4]], part: &[[T; 4]]) {
    for (t, p) in total.iter_mut().zip(part) {
        for k in 0..4 {
            t[k] += p[k].into();
        }
    }
}

/// The image of mean radiance from per-pixel sums over `samples` samples.
pub fn mean_image<T: Copy + Into<f64>>(width: u32, height: u32, sums: &[[T; 4]], samples: u32) -> HdrImage {
    let n = samples as f64;
    HdrImage { width, height, pixels: sums.iter().map(|s| [s[0], s[1], s[2]].map(|v| (v.into() / n) as f32)).collect() }
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

/// Everything a render needs on one device before its first sample: the
/// tree and buffers, the kernel, and an accumulation buffer of per-pixel
/// sums. A render is samples dispatched into it, in any ranges, on any
/// number of devices ([`render`], [`devices`]).
pub struct Prepared<B: Backend> {
    tree: TracedTree<B>,
    buffers: PrimBuffers<B>,
    materials: B::Buffer,
    lights: B::Buffer,
    accum: B::Buffer,
    kernel: Kernel,
    /// Render parameters but for the samples of a dispatch.
    params: RenderParams,
    per_dispatch: u32,
    pixels: u64,
    pub build_ms: f64,
    pub plan: Plan,
}

impl<B: Backend> Prepared<B> {
    /// Checks the settings and the scene, builds the tree on `b` and uploads
    /// the scene.
    pub fn new(b: &mut B, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        let RenderSettings { width, height, spp, seed, accel, layout, kernel, integrator, first_sample, .. } = *settings;
        if width == 0 || height == 0 || spp == 0 {
            bail!("image size {width}x{height} at {spp} samples per pixel: all three must be positive");
        }
        let pixels = width as u64 * height as u64;
        if pixels > u32::MAX as u64 / 2 {
            bail!("image size {width}x{height} is too large ({pixels} pixels)");
        }
        if first_sample.checked_add(spp).is_none() {
            bail!("samples {first_sample}.. plus {spp}: the sample index must stay below 2^32");
        }
        // Everything the render traces: spheres (the room included), then triangles.
        let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
        all.check()?;
        if scene.materials.len() != all.len() {
            bail!("{}: {} materials for {} primitives", scene.name, scene.materials.len(), all.len());
        }
        let plan = variant::plan(scene, accel, layout, kernel, b.class());
        let (tree, buffers, build_ms) = traced_tree(b, all, plan.accel, plan.layout)?;
        let materials = b.upload("materials", &scene.materials)?;
        let table = light_table(all, &scene.materials);
        let lights = lbvh::upload_or_placeholder(b, "lights", &table)?;
        let accum = b.zeroed("accumulation", pixels * 16)?;
        let params = RenderParams {
            width,
            height,
            seed,
            prims: scene.spheres.len() as u32,
            triangles: scene.triangles.len() as u32,
            camera: scene.camera.camera(width, height),
            integrator: integrator.code(),
            light_count: table.len() as u32,
            ..Default::default()
        };
        Ok(Prepared {
            tree,
            buffers,
            materials,
            lights,
            accum,
            kernel: Kernel::Render(plan.method(), plan.variant as u8),
            params,
            per_dispatch: (MAX_PATHS_PER_DISPATCH / pixels).clamp(1, max_samples_per_dispatch(b.class()) as u64) as u32,
            pixels,
            build_ms,
            plan,
        })
    }

    /// Dispatches samples `first .. first + count` of every pixel, adding
    /// to the accumulation (recorded, not waited for).
    pub fn dispatch_samples(&self, b: &mut B, first: u32, count: u32) -> Result<()> {
        b.stage("render");
        let mut done = 0;
        while done < count {
            let samples = (count - done).min(self.per_dispatch);
            let p = b.upload("render params", &[RenderParams { samples, first_sample: first + done, ..self.params }])?;
            let t = &self.tree;
            b.dispatch(
                self.kernel,
                &[&p, &self.buffers.spheres, &self.materials, &t.nodes, &t.prims, &self.accum, &self.buffers.triangles, &self.lights],
                groups_for(tiled_invocations(self.params.width, self.params.height), WORKGROUP_SIZE),
            );
            done += samples;
        }
        Ok(())
    }

    /// The per-pixel sums so far (waits for the dispatches).
    pub fn read_sums(&self, b: &mut B) -> Result<Vec<[f32; 4]>> {
        b.read(&self.accum, self.pixels as usize)
    }

    /// Empties the accumulation.
    pub fn clear(&self, b: &mut B) -> Result<()> {
        b.zero_words(&self.accum, (self.pixels * 4) as u32)
    }
}

/// Renders `scene`; `on_pass` sees each pass's row as it completes.
pub fn render<B: Backend>(
    b: &mut B,
    scene: &Scene,
    settings: &RenderSettings,
    reference: Option<&HdrImage>,
    mut on_pass: impl FnMut(&PassRow),
) -> Result<RenderResult> {
    let RenderSettings { width, height, spp, error_each_pass, first_sample, .. } = *settings;
    if let Some(r) = reference {
        if (r.width, r.height) != (width, height) {
            bail!("reference image is {}x{}, the render {width}x{height}", r.width, r.height);
        }
    }
    let start = Instant::now();
    let prepared = Prepared::new(b, scene, settings)?;
    let build_ms = prepared.build_ms;

    let mut rows = Vec::new();
    let mut render_ms = 0.0;
    let mut done = 0u32;
    let mut sums: Vec<[f32; 4]> = Vec::new();
    // Seconds spent reading back and scoring images that only the error rows need.
    let mut measuring_s = 0.0;
    let schedule = pass_schedule(spp);
    for (pass, target) in schedule.iter().copied().enumerate() {
        prepared.dispatch_samples(b, first_sample + done, target - done)?;
        done = target;
        let last = pass + 1 == schedule.len();
        if error_each_pass || last {
            // Waits for the pass (its timestamps) first, so that the readback is timed alone.
            render_ms += b.take_times()?.get("render");
            let read_start = start.elapsed().as_secs_f64();
            sums = prepared.read_sums(b)?;
            let elapsed_s = start.elapsed().as_secs_f64();
            let times = (elapsed_s, elapsed_s - measuring_s, (build_ms + render_ms) / 1e3);
            let row = error_row(pass as u32, done, times, &sums, reference);
            if !last {
                measuring_s += start.elapsed().as_secs_f64() - read_start;
            }
            on_pass(&row);
            rows.push(row);
        } else {
            // Waits for the pass (its timestamps), without reading the image.
            render_ms += b.take_times()?.get("render");
            let elapsed_s = start.elapsed().as_secs_f64();
            let kernel_s = (build_ms + render_ms) / 1e3;
            let wall_s = elapsed_s - measuring_s;
            on_pass(&PassRow { pass: pass as u32, spp: done, elapsed_s, wall_s, kernel_s, rmse: None, rel_mse: None, mean_std_error: None });
        }
    }
    let image = mean_image(width, height, &sums, spp);
    let plan = prepared.plan;
    Ok(RenderResult { image, sums, rows, build_ms, render_ms, total_s: start.elapsed().as_secs_f64(), plan })
}

/// Root mean square error (per channel) of `image` against `reference`,
/// and the mean of `(x - ref)² / (ref² + 0.01)`: how every render and
/// `treelet compare` score an image. Images must have the same size.
pub fn image_error(image: impl Iterator<Item = [f64; 3]>, reference: &HdrImage) -> (f64, f64) {
    let (mut se, mut rel, mut count) = (0.0f64, 0.0f64, 0usize);
    for (x, rp) in image.zip(&reference.pixels) {
        for k in 0..3 {
            let y = rp[k] as f64;
            se += (x[k] - y) * (x[k] - y);
            rel += (x[k] - y) * (x[k] - y) / (y * y + 0.01);
        }
        count += 3;
    }
    ((se / count.max(1) as f64).sqrt(), rel / count.max(1) as f64)
}

/// `times`: elapsed, wall and kernel seconds (see [`PassRow`]).
fn error_row(pass: u32, spp: u32, times: (f64, f64, f64), sums: &[[f32; 4]], reference: Option<&HdrImage>) -> PassRow {
    let n = spp as f64;
    let (elapsed_s, wall_s, kernel_s) = times;
    let mut row = PassRow { pass, spp, elapsed_s, wall_s, kernel_s, rmse: None, rel_mse: None, mean_std_error: None };
    match reference {
        Some(r) => {
            let (rmse, rel) = image_error(sums.iter().map(|s| [0, 1, 2].map(|k| s[k] as f64 / n)), r);
            row.rmse = Some(rmse);
            row.rel_mse = Some(rel);
        }
        None if spp >= 2 => {
            let mut total = 0.0f64;
            for s in sums {
                let mean = luminance(glam::Vec3::new(s[0], s[1], s[2])) as f64 / n;
                let var = ((s[3] as f64 - n * mean * mean) / (n - 1.0)).max(0.0);
                total += (var / n).sqrt();
            }
            row.mean_std_error = Some(total / sums.len() as f64);
        }
        None => {}
    }
    row
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
