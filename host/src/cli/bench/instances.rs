//! `bench instances`: what instancing costs an engine. The top-level tree's
//! rebuild for many instances (what a frame of moving instances pays), and
//! rays through a grid of copies of a mesh against rays through the mesh
//! alone, each framed the same way (`bench rays --mesh-only`'s eye: the
//! centre plus (0, 0.6, 0.8) times the extent, looking at the centre; the
//! grid also from nearly straight above), one camera ray a pixel and one
//! cosine bounce from each hit; and the mesh as one instance in place,
//! traced with the mesh alone's rays (the instanced walk's own cost).
use std::time::Instant;

use anyhow::{bail, Result};
use glam::{Mat3, Vec3};
use rand::{Rng, SeedableRng};
use treelet::runtime::backend::Backend;
use treelet::scene::Scene;
use treelet::{Instance, InstancedTracer, Quality, Ray, RayHit, Tracer, Triangle};

use super::measure::{cosine_bounces, median, traced_in_place_ms};

/// Medians (ms: device time, `last_update_ms` and the trace stage's
/// timestamps on a GPU; wall clock on the CPU runner).
#[derive(Debug, serde::Serialize)]
pub(crate) struct InstancesRow {
    pub(crate) triangles: usize,
    /// Top-level rebuilds: (instances, device ms, wall ms with the host's work and uploads).
    pub(crate) top_level: Vec<(usize, f64, f64)>,
    /// Stages of the largest top-level rebuild (device ms, medians).
    pub(crate) top_level_stages: Vec<(String, f64)>,
    /// The mesh as one instance in place, traced with the mesh alone's
    /// rays: what the instanced walk itself costs.
    pub(crate) in_place_primary_mrays: f64,
    pub(crate) in_place_diffuse_mrays: f64,
    /// Camera rays whose hit in place differs from the mesh alone's (0 expected).
    pub(crate) in_place_differ: usize,
    pub(crate) grid_instances: usize,
    pub(crate) single_primary_mrays: f64,
    pub(crate) single_diffuse_mrays: f64,
    pub(crate) instanced_primary_mrays: f64,
    pub(crate) instanced_diffuse_mrays: f64,
    /// The grid seen from nearly straight above.
    pub(crate) above_primary_mrays: f64,
    pub(crate) above_diffuse_mrays: f64,
    /// Rays cast in each measurement (primary; diffuse from their hits).
    pub(crate) single_rays: (usize, usize),
    pub(crate) instanced_rays: (usize, usize),
}

/// Copies of a mesh placed as `count` random rotations about the vertical
/// and translations within a cube, as a frame of moving instances.
fn scattered(count: usize, extent: f32, rng: &mut impl Rng) -> Vec<Instance> {
    let side = extent * (count as f32).cbrt() * 1.5;
    (0..count)
        .map(|_| {
            placed(
                rng.random_range(0.0..std::f32::consts::TAU),
                Vec3::new(rng.random_range(0.0..side), rng.random_range(0.0..side), rng.random_range(0.0..side)),
            )
        })
        .collect()
}

/// Mesh 0 turned by `angle` about the vertical, then moved by `at`.
fn placed(angle: f32, at: Vec3) -> Instance {
    let m = Mat3::from_rotation_y(angle);
    Instance { mesh: 0, transform: [0, 1, 2].map(|r| [m.col(0)[r], m.col(1)[r], m.col(2)[r], at[r]]) }
}

/// The box of `points`.
pub(crate) fn bounds(points: impl Iterator<Item = Vec3>) -> (Vec3, Vec3) {
    points.fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// The eye of `bench rays --mesh-only`: from the side and above.
pub(crate) const OBLIQUE: Vec3 = Vec3::new(0.0, 0.6, 0.8);
/// An eye nearly straight above (a grid of copies seen from above: about
/// one copy behind each pixel, as for the mesh alone).
const ABOVE: Vec3 = Vec3::new(0.0, 1.0, 0.2);

/// One camera ray a pixel, looking at the centre of `lo..hi` from the
/// centre plus `view` times its largest extent (smallpt's lens).
pub(crate) fn camera_rays((lo, hi): (Vec3, Vec3), view: Vec3, (w, h): (u32, u32)) -> Vec<Ray> {
    let centre = (lo + hi) * 0.5;
    let eye = centre + view * (hi - lo).max_element();
    let forward = (centre - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half = 0.5135 / 2.0;
    (0..w * h)
        .map(|k| {
            let (x, y) = ((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
            let dx = (2.0 * x / w as f32 - 1.0) * half * w as f32 / h as f32;
            let dy = (1.0 - 2.0 * y / h as f32) * half;
            Ray::new(eye.into(), (forward + right * dx + up * dy).normalize().into())
        })
        .collect()
}

/// A tracer as the benchmark drives it: closest hits from host rays (to
/// make the bounce rays), and in place on the device (what is timed).
pub(crate) struct Traced<'a, B: Backend> {
    pub(crate) closest: &'a dyn Fn(&mut B, &[Ray]) -> Result<Vec<RayHit>>,
    pub(crate) on_device: &'a dyn Fn(&mut B, &B::Buffer, usize) -> Result<()>,
}

/// Primary and diffuse M rays/s (medians of `repeats`) through `t`, and the
/// numbers of rays.
pub(crate) fn rays_per_second<B: Backend>(
    b: &mut B,
    (framing, view): ((Vec3, Vec3), Vec3),
    size: (u32, u32),
    extent: f32,
    repeats: usize,
    t: &Traced<B>,
) -> Result<(f64, f64, usize, usize)> {
    let primary = camera_rays(framing, view, size);
    let hits = (t.closest)(b, &primary)?;
    let diffuse = cosine_bounces(&primary, &hits, extent, &mut rand_pcg::Pcg64::seed_from_u64(7));
    let p = traced_in_place_ms(b, &primary, repeats, 0.5, t.on_device)?;
    let d = traced_in_place_ms(b, &diffuse, repeats, 0.5, t.on_device)?;
    let mrays = |n: usize, ms: f64| n as f64 / ms / 1e3;
    Ok((mrays(primary.len(), p), mrays(diffuse.len(), d), primary.len(), diffuse.len()))
}

/// `bench instances` on `b`: see the module doc.
pub(crate) fn bench_instances<B: Backend>(
    b: &mut B,
    scene: &Scene,
    grid: usize,
    top_sizes: &[usize],
    size: (u32, u32),
    repeats: usize,
) -> Result<InstancesRow> {
    let mesh: &[Triangle] = &scene.triangles;
    if mesh.is_empty() {
        bail!("bench instances places a mesh: scene `{}` has no triangles (give terrain:N, an .obj/.ply mesh or a .gltf/.glb scene)", scene.name);
    }
    if grid == 0 || repeats == 0 || size.0 == 0 || size.1 == 0 {
        bail!("bench instances needs a grid of at least one copy, one repeat and one ray");
    }
    let repeats = repeats.max(1);
    let (lo, hi) = bounds(mesh.iter().flat_map(|t| [t.v0, t.v1, t.v2]).map(Vec3::from));
    let extent = (hi - lo).max_element().max(1e-6);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);

    // The mesh alone.
    let single = Tracer::build(b, &[], mesh, Quality::High)?;
    let (sp, sd, sn, sdn) = rays_per_second(
        b,
        ((lo, hi), OBLIQUE),
        size,
        extent,
        repeats,
        &Traced {
            closest: &|b, r| Ok(single.closest_hits(b, r)?),
            on_device: &|b, r, n| Ok(single.closest_hits_on_device(b, r, n)?),
        },
    )?;
    let check_rays = camera_rays((lo, hi), OBLIQUE, size);
    let expected = single.closest_hits(b, &check_rays)?;
    drop(single);
    let one =
        InstancedTracer::build(b, &[mesh], &[Instance { mesh: 0, transform: Instance::IDENTITY }], Quality::High)?;
    let got = one.closest_hits(b, &check_rays)?;
    // The same walk through the same tree: every hit the same.
    let in_place_differ = expected.iter().zip(&got).filter(|(e, g)| (e.t, e.prim) != (g.t, g.prim)).count();
    let (op, od, _, _) = rays_per_second(
        b,
        ((lo, hi), OBLIQUE),
        size,
        extent,
        repeats,
        &Traced { closest: &|b, r| Ok(one.closest_hits(b, r)?), on_device: &|b, r, n| Ok(one.closest_hits_on_device(b, r, n)?) },
    )?;
    drop(one);

    // A grid of copies, each turned about the vertical.
    let step = 1.25 * extent;
    let copies: Vec<Instance> = (0..grid * grid)
        .map(|k| {
            placed(
                rng.random_range(0.0..std::f32::consts::TAU),
                Vec3::new((k % grid) as f32 * step, 0.0, (k / grid) as f32 * step),
            )
        })
        .collect();
    let mut scene_tracer = InstancedTracer::build(b, &[mesh], &copies, Quality::High)?;
    let centre = (lo + hi) * 0.5;
    let framing = bounds(copies.iter().flat_map(|i| {
        let at = Vec3::new(i.transform[0][3], i.transform[1][3], i.transform[2][3]);
        [at + centre - Vec3::splat(extent * 0.5), at + centre + Vec3::splat(extent * 0.5)]
    }));
    let (ip, id, ins, idn) = rays_per_second(
        b,
        (framing, OBLIQUE),
        size,
        extent,
        repeats,
        &Traced {
            closest: &|b, r| Ok(scene_tracer.closest_hits(b, r)?),
            on_device: &|b, r, n| Ok(scene_tracer.closest_hits_on_device(b, r, n)?),
        },
    )?;
    let (ap, ad, _, _) = rays_per_second(
        b,
        (framing, ABOVE),
        size,
        extent,
        repeats,
        &Traced {
            closest: &|b, r| Ok(scene_tracer.closest_hits(b, r)?),
            on_device: &|b, r, n| Ok(scene_tracer.closest_hits_on_device(b, r, n)?),
        },
    )?;

    // Top-level rebuilds of scattered copies (one warm-up each).
    let mut top_level = Vec::new();
    let mut top_level_stages = Vec::new();
    for &count in top_sizes {
        let (mut device, mut wall) = (Vec::new(), Vec::new());
        let mut stages: Vec<(String, Vec<f64>)> = Vec::new();
        // Made ahead: the GPU's clock falls while the host works between
        // dispatches (see `traced_in_place_ms`).
        let frames: Vec<Vec<Instance>> = (0..=repeats).map(|_| scattered(count, extent, &mut rng)).collect();
        for (k, frame) in frames.iter().enumerate() {
            b.take_times()?;
            let start = Instant::now();
            scene_tracer.set_instances(b, frame)?;
            b.take_times()?;
            if k > 0 {
                device.push(scene_tracer.last_update_ms());
                wall.push(start.elapsed().as_secs_f64() * 1e3);
                let times = scene_tracer.top_level_stages();
                for s in &times.order {
                    match stages.iter_mut().find(|(n, _)| n == s) {
                        Some((_, v)) => v.push(times.get(s)),
                        None => stages.push((s.to_string(), vec![times.get(s)])),
                    }
                }
            }
        }
        top_level.push((count, median(device), median(wall)));
        top_level_stages = stages.into_iter().map(|(n, v)| (n, median(v))).collect();
    }
    Ok(InstancesRow {
        triangles: mesh.len(),
        top_level,
        top_level_stages,
        in_place_primary_mrays: op,
        in_place_diffuse_mrays: od,
        in_place_differ,
        grid_instances: copies.len(),
        single_primary_mrays: sp,
        single_diffuse_mrays: sd,
        instanced_primary_mrays: ip,
        instanced_diffuse_mrays: id,
        above_primary_mrays: ap,
        above_diffuse_mrays: ad,
        single_rays: (sn, sdn),
        instanced_rays: (ins, idn),
    })
}
