//! `bench dynamic`: an animated mesh through the engine API, frame by frame:
//! refit the tree against rebuilding it with each builder, and one frame's
//! rays (closest hits and occlusion queries) through the refit tree and the
//! rebuilt one, whose difference is what refitting costs in ray speed; and
//! through the rebuilt tree, a cosine bounce from each hit (an engine's
//! diffuse rays, unbounded, and its ambient-occlusion rays, reaching 5% of
//! the mesh's extent) as closest hits and as occlusion queries.
use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use treelet::runtime::backend::Backend;
use treelet::scene::Scene;
use treelet::{Quality, Ray, Tracer, Triangle};

use rand::SeedableRng;

use super::measure::{cosine_bounces, median, traced_in_place_ms};

/// Medians over the frames, in ms (device time: `Tracer::last_update_ms` and
/// the trace stage's timestamps on a GPU, wall clock on the CPU runner;
/// `wall_*`: the call on the host, with uploads and read-backs).
#[derive(Debug, serde::Serialize)]
pub(crate) struct DynamicRow {
    pub(crate) triangles: usize,
    pub(crate) rays: usize,
    pub(crate) frames: usize,
    pub(crate) refit_ms: f64,
    pub(crate) rebuild_lbvh_ms: f64,
    pub(crate) rebuild_trbvh_ms: f64,
    pub(crate) wall_refit_ms: f64,
    pub(crate) wall_rebuild_lbvh_ms: f64,
    pub(crate) wall_rebuild_trbvh_ms: f64,
    /// Rays per second (millions) through the refit tree and a fresh TRBVH.
    pub(crate) closest_refit_mrays: f64,
    pub(crate) closest_rebuilt_mrays: f64,
    pub(crate) occluded_refit_mrays: f64,
    pub(crate) occluded_rebuilt_mrays: f64,
    /// Bounce rays a frame (the hits' cosine bounces), and their rays per
    /// second (millions) through the rebuilt tree: unbounded, and reaching
    /// [`AO_REACH`] of the mesh's extent.
    pub(crate) bounce_rays: usize,
    pub(crate) closest_diffuse_mrays: f64,
    pub(crate) occluded_diffuse_mrays: f64,
    pub(crate) closest_ao_mrays: f64,
    pub(crate) occluded_ao_mrays: f64,
}

/// How far ambient-occlusion rays reach, in the mesh's largest extent.
pub(crate) const AO_REACH: f32 = 0.05;

/// The mesh at `frame`: every vertex lifted by a travelling wave of 2% of
/// the mesh's extent (the same vertex always moves the same way, so shared
/// vertices stay shared).
fn deform(triangles: &[Triangle], frame: usize, lo: Vec3, extent: f32) -> Vec<Triangle> {
    let phase = frame as f32 * 0.4;
    let lift = |v: [f32; 3]| {
        let p = Vec3::from(v);
        let k = 6.0 / extent;
        [p.x, p.y + 0.02 * extent * ((p.x - lo.x) * k + phase).sin() * ((p.z - lo.z) * k - phase).cos(), p.z]
    };
    triangles.iter().map(|t| Triangle::new(lift(t.v0), lift(t.v1), lift(t.v2))).collect()
}

/// A `width` x `height` grid of rays looking down onto the mesh's box, a
/// little tilted; their `t_max` ends just below the box (occlusion rays).
fn rays(lo: Vec3, hi: Vec3, (width, height): (u32, u32)) -> Vec<Ray> {
    let top = hi.y + 0.1 * (hi - lo).length();
    (0..width * height)
        .map(|k| {
            let (u, v) = (((k % width) as f32 + 0.5) / width as f32, ((k / width) as f32 + 0.5) / height as f32);
            let origin = [lo.x + u * (hi.x - lo.x), top, lo.z + v * (hi.z - lo.z)];
            Ray { t_max: top - lo.y + 1.0, ..Ray::new(origin, [0.1, -1.0, 0.07]) }
        })
        .collect()
}

/// The device time of `tracer`'s last build or refit and the wall time
/// since `start` (all work waited for).
fn update_times<B: Backend>(b: &mut B, tracer: &Tracer<B>, start: Instant) -> Result<(f64, f64)> {
    b.take_times()?;
    Ok((tracer.last_update_ms(), start.elapsed().as_secs_f64() * 1e3))
}

/// Runs `frames` frames of the animated `scene` on `b` (after one warm-up frame).
pub(crate) fn bench_dynamic<B: Backend>(
    b: &mut B,
    scene: &Scene,
    frames: usize,
    size: (u32, u32),
) -> Result<DynamicRow> {
    if scene.triangles.is_empty() {
        bail!("bench dynamic animates a mesh: scene `{}` has no triangles (give terrain:N, an .obj/.ply mesh or a .gltf/.glb scene)", scene.name);
    }
    if frames == 0 || size.0 == 0 || size.1 == 0 {
        bail!("bench dynamic needs at least one frame and one ray");
    }
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in &scene.triangles {
        for v in [t.v0, t.v1, t.v2] {
            (lo, hi) = (lo.min(v.into()), hi.max(v.into()));
        }
    }
    let extent = (hi - lo).max_element().max(1e-6);
    let rays = rays(lo, hi, size);
    let mut tracer = Tracer::build(b, &[], &scene.triangles, Quality::High)?;
    let mut m: [Vec<f64>; 10] = Default::default();
    // Bounce rays: Mray/s each frame (their count changes with the mesh).
    let mut bounce: [Vec<f64>; 4] = Default::default();
    let mut bounce_rays = 0;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    b.take_times()?;
    for frame in 0..=frames {
        let mesh = deform(&scene.triangles, frame, lo, extent);
        // Each update timed with the GPU's clock up, as in an engine's busy frame.
        warm_up(b, &tracer, &rays)?;
        let start = Instant::now();
        tracer.refit(b, &[], &mesh)?;
        let refit = update_times(b, &tracer, start)?;
        let (closest_refit, occluded_refit) = trace(b, &tracer, &rays)?;
        let start = Instant::now();
        let fast = Tracer::build(b, &[], &mesh, Quality::Fast)?;
        let lbvh = update_times(b, &fast, start)?;
        drop(fast);
        warm_up(b, &tracer, &rays)?;
        let start = Instant::now();
        let rebuilt = Tracer::build(b, &[], &mesh, Quality::High)?;
        let trbvh = update_times(b, &rebuilt, start)?;
        let (closest_rebuilt, occluded_rebuilt) = trace(b, &rebuilt, &rays)?;
        let hits = rebuilt.closest_hits(b, &rays)?;
        let diffuse = cosine_bounces(&rays, &hits, extent, &mut rng);
        let ao: Vec<Ray> = diffuse.iter().map(|r| Ray { t_max: AO_REACH * extent, ..*r }).collect();
        let mut per_s = Vec::new();
        for set in [&diffuse, &ao] {
            warm_up(b, &rebuilt, set)?;
            let (closest, occluded) = trace(b, &rebuilt, set)?;
            per_s.extend([set.len() as f64 / closest / 1e3, set.len() as f64 / occluded / 1e3]);
        }
        if frame == 0 {
            continue; // warm-up
        }
        bounce_rays = diffuse.len();
        for (list, v) in bounce.iter_mut().zip(per_s) {
            list.push(v);
        }
        let values = [
            refit.0,
            lbvh.0,
            trbvh.0,
            refit.1,
            lbvh.1,
            trbvh.1,
            closest_refit,
            closest_rebuilt,
            occluded_refit,
            occluded_rebuilt,
        ];
        for (list, v) in m.iter_mut().zip(values) {
            list.push(v);
        }
    }
    let [refit_ms, rebuild_lbvh_ms, rebuild_trbvh_ms, wall_refit_ms, wall_rebuild_lbvh_ms, wall_rebuild_trbvh_ms, c_refit, c_rebuilt, o_refit, o_rebuilt] =
        m.map(median);
    let mrays = |ms: f64| rays.len() as f64 / ms / 1e3;
    let [closest_diffuse_mrays, occluded_diffuse_mrays, closest_ao_mrays, occluded_ao_mrays] = bounce.map(median);
    Ok(DynamicRow {
        triangles: scene.triangles.len(),
        rays: rays.len(),
        frames,
        refit_ms,
        rebuild_lbvh_ms,
        rebuild_trbvh_ms,
        wall_refit_ms,
        wall_rebuild_lbvh_ms,
        wall_rebuild_trbvh_ms,
        closest_refit_mrays: mrays(c_refit),
        closest_rebuilt_mrays: mrays(c_rebuilt),
        occluded_refit_mrays: mrays(o_refit),
        occluded_rebuilt_mrays: mrays(o_rebuilt),
        bounce_rays,
        closest_diffuse_mrays,
        occluded_diffuse_mrays,
        closest_ao_mrays,
        occluded_ao_mrays,
    })
}

/// Keeps the GPU busy for a twentieth of a second (tracing `rays`), so that
/// the update timed next runs at full clock rather than the idle clock the
/// host's work on the frame lets the GPU fall to.
fn warm_up<B: Backend>(b: &mut B, tracer: &Tracer<B>, rays: &[Ray]) -> Result<()> {
    traced_in_place_ms(b, rays, 1, 0.05, &|b, r, n| Ok(tracer.closest_hits_on_device(b, r, n)?)).map(drop)
}

/// Device ms of the closest hits and of the occlusion queries of `rays`
/// (the trace stage's timestamps; wall clock on the CPU runner), traced in
/// place on the device after a warm-up: timed right after the host's work
/// on the frame, the H100 traced at its idle clock (345 MHz) and this
/// benchmark reported a quarter of the rays/s `bench rays` measures.
fn trace<B: Backend>(b: &mut B, tracer: &Tracer<B>, rays: &[Ray]) -> Result<(f64, f64)> {
    let closest = traced_in_place_ms(b, rays, 3, 0.1, &|b, r, n| Ok(tracer.closest_hits_on_device(b, r, n)?))?;
    let occluded = traced_in_place_ms(b, rays, 3, 0.1, &|b, r, n| Ok(tracer.occluded_on_device(b, r, n)?))?;
    Ok((closest, occluded))
}
