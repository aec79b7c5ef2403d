//! `bench file-instances`: a scene file's or glTF file's own instances (meshes
//! placed by reference, `treelet::scene::instanced`) through the engine
//! API, against the same scene flattened into one mesh: what the instances
//! save in memory and build time, what they cost in rays per second, and
//! the top level rebuilt over the file's placements (a frame that moves
//! them). Rays as `bench instances` casts them: one camera ray a pixel from
//! the side and above the placed meshes' box, and a cosine bounce from
//! each hit.
use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use treelet::runtime::backend::Backend;
use treelet::scene::instanced::InstancedScene;
use treelet::{Instance, InstancedTracer, Quality, Tracer, Triangle};

use super::instances::{bounds, camera_rays, rays_per_second, Traced, OBLIQUE};
use super::measure::median;

/// Medians (ms: device time on a GPU, wall clock on the CPU runner).
#[derive(Debug, serde::Serialize)]
pub(crate) struct FileInstancesRow {
    pub(crate) meshes: usize,
    pub(crate) instances: usize,
    /// Triangles kept (each mesh once) and once flattened.
    pub(crate) triangles_kept: usize,
    pub(crate) triangles_flattened: usize,
    /// Every mesh's tree and the top level; the flattened scene's tree.
    pub(crate) build_instanced_ms: f64,
    pub(crate) build_flattened_ms: f64,
    /// The top level rebuilt over the file's placements: device, and wall
    /// with the host's checks and the upload.
    pub(crate) top_level_ms: f64,
    pub(crate) top_level_wall_ms: f64,
    pub(crate) instanced_primary_mrays: f64,
    pub(crate) instanced_diffuse_mrays: f64,
    pub(crate) flattened_primary_mrays: f64,
    pub(crate) flattened_diffuse_mrays: f64,
    /// Camera rays whose hit (instance and triangle) differs from the
    /// flattened scene's (rounding at edges only: a few in ten thousand).
    pub(crate) camera_rays: usize,
    pub(crate) hits_differ: usize,
}

/// `bench file-instances` on `b`: see the module doc.
pub(crate) fn bench_file_instances<B: Backend>(
    b: &mut B,
    scene: &InstancedScene,
    size: (u32, u32),
    repeats: usize,
) -> Result<FileInstancesRow> {
    if scene.instances.is_empty() {
        bail!("bench file-instances traces a file's instances: `{}` places no mesh (give a .gltf/.glb or .json scene with meshes)", scene.loose.name);
    }
    if repeats == 0 || size.0 == 0 || size.1 == 0 {
        bail!("bench file-instances needs one repeat and one ray");
    }
    let flat = scene.clone().flatten()?;
    let kept = scene.meshes.iter().map(|m| m.triangles.len()).sum::<usize>() + scene.loose.triangles.len();
    let instanced = InstancedTracer::build_scene(b, scene, Quality::High)?;
    let build_instanced_ms = instanced.last_update_ms();
    let whole = Tracer::build(b, &flat.spheres, &flat.triangles, Quality::High)?;
    let build_flattened_ms = whole.last_update_ms();

    // The rays, framed on the flattened scene's triangles.
    let framing = bounds(flat.triangles.iter().flat_map(|t: &Triangle| [t.v0, t.v1, t.v2]).map(Vec3::from));
    let extent = (framing.1 - framing.0).max_element().max(1e-6);
    let (ip, id, primary, _) = rays_per_second(
        b,
        (framing, OBLIQUE),
        size,
        extent,
        repeats,
        &Traced {
            closest: &|b, r| Ok(instanced.closest_hits(b, r)?),
            on_device: &|b, r, n| Ok(instanced.closest_hits_on_device(b, r, n)?),
        },
    )?;
    let (fp, fd, _, _) = rays_per_second(
        b,
        (framing, OBLIQUE),
        size,
        extent,
        repeats,
        &Traced {
            closest: &|b, r| Ok(whole.closest_hits(b, r)?),
            on_device: &|b, r, n| Ok(whole.closest_hits_on_device(b, r, n)?),
        },
    )?;

    // The same hits: flattened triangle k is instance i's triangle p.
    let owner: Vec<(u32, u32)> = instanced
        .instances()
        .iter()
        .enumerate()
        .flat_map(|(i, inst)| {
            let n = if (inst.mesh as usize) < scene.meshes.len() {
                scene.meshes[inst.mesh as usize].triangles.len()
            } else {
                scene.loose.triangles.len() // the loose triangles' own mesh, placed last
            };
            (0..n as u32).map(move |p| (i as u32, p))
        })
        .collect();
    let rays = camera_rays(framing, OBLIQUE, size);
    let a = instanced.closest_hits(b, &rays)?;
    let f = whole.closest_hits(b, &rays)?;
    let hits_differ = a
        .iter()
        .zip(&f)
        .filter(|(a, f)| {
            (a.is_hit(), a.is_hit().then(|| (a.instance, a.prim)))
                != (f.is_hit(), f.is_hit().then(|| owner[f.prim as usize]))
        })
        .count();
    drop(whole);

    // The top level again over the same placements (one warm-up).
    let mut instanced = instanced;
    let instances: Vec<Instance> = instanced.instances().to_vec();
    let (mut device, mut wall) = (Vec::new(), Vec::new());
    for k in 0..=repeats {
        b.take_times()?;
        let start = Instant::now();
        instanced.set_instances(b, &instances)?;
        b.take_times()?;
        if k > 0 {
            device.push(instanced.last_update_ms());
            wall.push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    Ok(FileInstancesRow {
        meshes: scene.meshes.len(),
        instances: scene.instances.len(),
        triangles_kept: kept,
        triangles_flattened: flat.triangles.len(),
        build_instanced_ms,
        build_flattened_ms,
        top_level_ms: median(device),
        top_level_wall_ms: median(wall),
        instanced_primary_mrays: ip,
        instanced_diffuse_mrays: id,
        flattened_primary_mrays: fp,
        flattened_diffuse_mrays: fd,
        camera_rays: primary,
        hits_differ,
    })
}
