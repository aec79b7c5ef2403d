//! Treelet inside an engine: a tree over the engine's own triangles and
//! spheres on a device, closest hits for a batch of rays, then the geometry
//! moves, the tree is refit and the rays traced again. Every hit is checked
//! against a scan of every primitive (`treelet_core`'s reference). Then a
//! frame loop: refit or rebuild, camera rays, shadow rays as occlusion
//! queries, and the device time of each (the moving balls part of the one
//! tree). Last, the same frame loop with instances: the waves one mesh,
//! refit every frame, and a rock mesh placed 48 times, the copies moving
//! every frame (the top level rebuilt over them); hits are checked against
//! a scan of the scene flattened into world triangles.
//!
//!     cargo run --release -p treelet --example tracer            # the first Vulkan adapter
//!     cargo run --release -p treelet --example tracer -- cpu     # the CPU runner
//!
//! `cargo test` runs it on both (it is also the example's test).
use anyhow::{ensure, Result};
use glam::Vec3;
use treelet::{
    Backend, CpuBackend, GpuBackend, GpuContext, Instance, InstancedTracer, Quality, Ray, RayHit, Sphere, Tracer,
    Triangle,
};
// The reference every hit is checked against: treelet-core's scan.
use treelet_core::geometry::prims::{Origin, Prims};
use treelet_core::trace::classic::closest_hit_linear;

/// The engine's geometry: a wavy 64 x 64 grid of quads (8 192 triangles)
/// and a row of balls above it; `phase` moves the waves.
fn geometry(phase: f32) -> (Vec<Sphere>, Vec<Triangle>) {
    let height = |x: f32, z: f32| 2.0 * ((x * 0.15 + phase).sin() + (z * 0.11 - phase).cos());
    let mut triangles = Vec::new();
    for i in 0..64 {
        for j in 0..64 {
            let p = |di: i32, dj: i32| {
                let (x, z) = ((i + di) as f32, (j + dj) as f32);
                [x, height(x, z), z]
            };
            triangles.push(Triangle::new(p(0, 0), p(1, 0), p(1, 1)));
            triangles.push(Triangle::new(p(0, 0), p(1, 1), p(0, 1)));
        }
    }
    let spheres = (0..8).map(|k| Sphere::new([8.0 * k as f32 + 4.0, 8.0 + phase, 32.0], 3.0)).collect();
    (spheres, triangles)
}

/// A batch of rays from above, looking down and a little sideways.
fn rays() -> Vec<Ray> {
    (0..4096)
        .map(|k| {
            let (x, z) = ((k % 64) as f32 + 0.37, (k / 64) as f32 + 0.61);
            Ray::new([x, 20.0, z], [0.1, -1.0, 0.05])
        })
        .collect()
}

/// Traces `rays` through `tracer` and checks every hit against the scan.
fn trace_and_check<B: Backend>(
    b: &mut B,
    tracer: &Tracer<B>,
    scene: &(Vec<Sphere>, Vec<Triangle>),
    rays: &[Ray],
) -> Result<Vec<RayHit>> {
    let hits = tracer.closest_hits(b, rays)?;
    let (spheres, triangles) = scene;
    let prims = Prims::new(spheres, triangles);
    for (r, h) in rays.iter().zip(&hits) {
        let d = Vec3::from(r.dir).normalize();
        let scan = closest_hit_linear(Vec3::from(r.origin), d, Origin::NONE, &prims);
        ensure!(h.prim == scan.prim, "ray {r:?}: the tree hit {h:?}, the scan {} at {}", scan.prim, scan.t);
        ensure!(!h.is_hit() || (h.t - scan.t).abs() <= 1e-4 * scan.t.max(1.0), "ray {r:?}: {} against {}", h.t, scan.t);
    }
    Ok(hits)
}

/// The whole job on one device.
fn run<B: Backend>(b: &mut B) -> Result<()> {
    let rays = rays();
    let scene = geometry(0.0);
    let tracer = &mut Tracer::build(b, &scene.0, &scene.1, Quality::High)?;
    let hits = trace_and_check(b, tracer, &scene, &rays)?;
    let on_balls = hits.iter().filter(|h| h.is_hit() && h.prim < 8).count();
    println!(
        "{}: {} of {} rays hit ({on_balls} a ball), all equal to the scan",
        b.adapter(),
        hits.iter().filter(|h| h.is_hit()).count(),
        rays.len()
    );
    // The waves move and the balls rise: refit, trace again.
    let moved = geometry(1.3);
    tracer.refit(b, &moved.0, &moved.1)?;
    let moved_hits = trace_and_check(b, tracer, &moved, &rays)?;
    let changed = hits.iter().zip(&moved_hits).filter(|(a, b)| a != b).count();
    println!("after the refit: {changed} rays hit something else or elsewhere, all equal to the scan");
    ensure!(changed > rays.len() / 2, "moving the geometry should move most hits");
    Ok(())
}

/// Shadow rays: from each hit, a little off the surface on the side the
/// camera ray came from (the geometric normal's side depends on the
/// triangle's winding), towards the sun.
fn shadow_rays(rays: &[Ray], hits: &[RayHit], sun: Vec3) -> Vec<Ray> {
    rays.iter()
        .zip(hits)
        .filter(|(_, h)| h.is_hit())
        .map(|(r, h)| {
            let d = Vec3::from(r.dir).normalize();
            let n = Vec3::from(h.normal);
            let facing = if n.dot(d) < 0.0 { n } else { -n };
            Ray::new((Vec3::from(r.origin) + d * h.t + facing * 1e-3).into(), sun.into())
        })
        .collect()
}

/// An engine's frame loop: the waves and balls move every frame; the tree
/// is refit each frame and rebuilt every fourth (a refit tree slows down as
/// the geometry drifts from what it was built for); each frame traces its
/// camera rays, then shadow rays from their hits towards a sun as occlusion
/// queries, and prints what each step cost on the device.
fn frame_loop<B: Backend>(b: &mut B, frames: usize) -> Result<()> {
    let rays = rays();
    let sun = Vec3::new(0.3, 1.0, 0.2).normalize();
    let first = geometry(0.0);
    let mut tracer = Tracer::build(b, &first.0, &first.1, Quality::Fast)?;
    for frame in 1..=frames {
        let scene = geometry(frame as f32 * 0.2);
        let update = if frame % 4 == 0 {
            tracer = Tracer::build(b, &scene.0, &scene.1, Quality::Fast)?;
            "rebuild"
        } else {
            tracer.refit(b, &scene.0, &scene.1)?;
            "refit"
        };
        let update_ms = tracer.last_update_ms();
        b.take_times()?;
        let hits = tracer.closest_hits(b, &rays)?;
        let shadow = shadow_rays(&rays, &hits, sun);
        let shadowed = tracer.occluded(b, &shadow)?;
        let trace_ms = b.take_times()?.get("trace");
        println!(
            "frame {frame}: {update} {update_ms:.3} ms, {} rays and {} shadow rays traced in {trace_ms:.3} ms, {} in shadow",
            rays.len(),
            shadow.len(),
            shadowed.iter().filter(|&&s| s).count()
        );
        ensure!(shadow.len() > rays.len() / 2, "most rays should hit the waves");
        let in_shadow = shadowed.iter().filter(|&&s| s).count();
        ensure!(
            in_shadow > 0 && in_shadow < shadow.len() / 2,
            "{in_shadow} of {} points in shadow: the balls shade a part of the waves",
            shadow.len()
        );
    }
    Ok(())
}

/// A rock: an octahedron of radius 1 about the origin, 8 triangles.
fn rock() -> Vec<Triangle> {
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let neg = |v: [f32; 3]| v.map(|c| -c);
    let mut t = Vec::new();
    for (a, b) in [(x, z), (z, neg(x)), (neg(x), neg(z)), (neg(z), x)] {
        t.push(Triangle::new(a, b, y));
        t.push(Triangle::new(b, a, neg(y)));
    }
    t
}

/// Copy `k` of the rock at frame time `time`: in a ring above the waves,
/// turning about y, squashed, swinging round and bobbing.
fn rock_copy(k: usize, time: f32) -> Instance {
    let angle = k as f32 / 48.0 * std::f32::consts::TAU + 0.3 * time;
    let centre = Vec3::new(32.0 + 20.0 * angle.cos(), 6.0 + (2.0 * time + k as f32).sin(), 32.0 + 20.0 * angle.sin());
    let m = glam::Affine3A::from_scale_rotation_translation(
        Vec3::new(1.5, 0.8, 1.2),
        glam::Quat::from_rotation_y(angle * 3.0),
        centre,
    );
    let c = m.matrix3;
    let t = m.translation;
    Instance {
        mesh: 1,
        transform: [
            [c.x_axis.x, c.y_axis.x, c.z_axis.x, t.x],
            [c.x_axis.y, c.y_axis.y, c.z_axis.y, t.y],
            [c.x_axis.z, c.y_axis.z, c.z_axis.z, t.z],
        ],
    }
}

/// Instances in an engine's frame loop: mesh 0 (the waves) deforms and is
/// refit every frame, mesh 1 (a rock) is placed 48 times and the copies
/// move every frame (the top level is rebuilt over them, the rock's own
/// tree never). Each frame traces camera rays and shadow rays towards a sun
/// as occlusion queries, prints the device time of each step, and checks
/// the hits against a scan of the scene flattened into world triangles.
fn instanced_frame_loop<B: Backend>(b: &mut B, frames: usize) -> Result<()> {
    let rays = rays();
    let sun = Vec3::new(0.3, 1.0, 0.2).normalize();
    let rock = rock();
    let place = |time: f32| -> Vec<Instance> {
        let mut instances = vec![Instance { mesh: 0, transform: Instance::IDENTITY }];
        instances.extend((0..48).map(|k| rock_copy(k, time)));
        instances
    };
    let waves = geometry(0.0).1;
    let mut scene = InstancedTracer::build(b, &[&waves, &rock], &place(0.0), Quality::Fast)?;
    for frame in 1..=frames {
        let time = frame as f32 * 0.2;
        let waves = geometry(time).1;
        scene.refit_mesh(b, 0, &waves)?;
        let refit_ms = scene.last_update_ms();
        let instances = place(time);
        scene.set_instances(b, &instances)?;
        let top_ms = scene.last_update_ms();
        b.take_times()?;
        let hits = scene.closest_hits(b, &rays)?;
        let shadow = shadow_rays(&rays, &hits, sun);
        let shadowed = scene.occluded(b, &shadow)?;
        let trace_ms = b.take_times()?.get("trace");
        // The scene flattened: every instance's triangles in the world.
        let world: Vec<Triangle> = instances
            .iter()
            .flat_map(|i| {
                let mesh = if i.mesh == 0 { &waves } else { &rock };
                let m = i.transform;
                let apply = move |p: [f32; 3]| -> [f32; 3] {
                    std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
                };
                mesh.iter().map(move |t| Triangle::new(apply(t.v0), apply(t.v1), apply(t.v2)))
            })
            .collect();
        let prims = Prims::new(&[], &world);
        let mut differ = 0;
        for (r, h) in rays.iter().zip(&hits) {
            let d = Vec3::from(r.dir).normalize();
            let scan = closest_hit_linear(Vec3::from(r.origin), d, Origin::NONE, &prims);
            let same = h.is_hit() == scan.is_hit() && (!h.is_hit() || (h.t - scan.t).abs() <= 1e-3 * scan.t.max(1.0));
            differ += usize::from(!same);
        }
        // Rays through a shared edge may land on either triangle, and the
        // placed mesh is intersected in its own space: a few may differ.
        ensure!(
            differ * 200 <= rays.len(),
            "frame {frame}: {differ} of {} hits differ from the flattened scene's",
            rays.len()
        );
        let on_rocks = hits.iter().filter(|h| h.is_hit() && h.instance > 0).count();
        println!(
            "instanced frame {frame}: refit of the waves + top level {refit_ms:.3} ms, top level of {} instances {top_ms:.3} ms, {} rays ({on_rocks} on rocks) and {} shadow rays in {trace_ms:.3} ms, {} in shadow",
            instances.len(),
            rays.len(),
            shadow.len(),
            shadowed.iter().filter(|&&s| s).count()
        );
        ensure!(on_rocks > 0, "frame {frame}: the rocks should stand in some rays' way");
    }
    Ok(())
}

/// Rays that live on the GPU already (an engine's own `wgpu::Buffer`):
/// traced in place, without a round trip through host memory.
fn on_device(ctx: std::sync::Arc<GpuContext>) -> Result<()> {
    let b = &mut GpuBackend::new(ctx.clone());
    let scene = geometry(0.0);
    let tracer = Tracer::build(b, &scene.0, &scene.1, Quality::Fast)?;
    let rays = rays();
    // The engine's buffer: ray k is (origin, t_max), (direction, 1), padded
    // with zeros (an engine would write these from its own shaders).
    let data = treelet::tracer::device_rays(&rays)?;
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("engine rays"),
        size: (data.len() * 16) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    ctx.queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&data));
    tracer.closest_hits_on_device(b, &buffer, rays.len())?;
    // Here an engine would bind `buffer` to its next pass; the example reads it back to check.
    let out: Vec<[f32; 4]> = b.read(&buffer, 2 * rays.len())?;
    let from_host = tracer.closest_hits(b, &rays)?;
    for (k, h) in from_host.iter().enumerate() {
        ensure!(
            out[2 * k][1].to_bits() == h.prim && (out[2 * k][0] == h.t),
            "ray {k}: on the device {:?}, from the host {h:?}",
            out[2 * k]
        );
    }
    println!("{} rays traced in a wgpu buffer: the same hits as from host slices", rays.len());
    Ok(())
}

fn main() -> Result<()> {
    if std::env::args().nth(1).as_deref() == Some("cpu") {
        let b = &mut CpuBackend::new();
        run(b)?;
        frame_loop(b, 8)?;
        return instanced_frame_loop(b, 8);
    }
    match GpuContext::new() {
        Ok(ctx) => {
            let b = &mut GpuBackend::new(ctx.clone());
            run(b)?;
            frame_loop(b, 8)?;
            instanced_frame_loop(b, 8)?;
            on_device(ctx)
        }
        Err(e) => {
            eprintln!("note: {e}: running on the CPU runner instead");
            let b = &mut CpuBackend::new();
            run(b)?;
            frame_loop(b, 8)?;
            instanced_frame_loop(b, 8)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_on_the_cpu_runner() {
        run(&mut CpuBackend::new()).unwrap();
        frame_loop(&mut CpuBackend::new(), 4).unwrap();
        instanced_frame_loop(&mut CpuBackend::new(), 3).unwrap();
    }

    /// A machine without a usable adapter fails this test, unless
    /// `TREELET_TESTS_WITHOUT_GPU=1` (never under `CI`) asks to skip it.
    #[test]
    fn runs_on_the_gpu() {
        match GpuContext::new() {
            Ok(ctx) => {
                run(&mut GpuBackend::new(ctx.clone())).unwrap();
                instanced_frame_loop(&mut GpuBackend::new(ctx.clone()), 3).unwrap();
                on_device(ctx).unwrap();
            }
            Err(e) if std::env::var_os("CI").is_some() => panic!("CI is set and no GPU adapter is usable: {e:#}"),
            Err(e) if std::env::var("TREELET_TESTS_WITHOUT_GPU").is_ok_and(|v| v == "1") => {
                eprintln!("SKIPPED (no GPU adapter, TREELET_TESTS_WITHOUT_GPU=1): {e:#}")
            }
            Err(e) => panic!("no GPU adapter is usable ({e:#}): install lavapipe (sh scripts/setup), or set TREELET_TESTS_WITHOUT_GPU=1"),
        }
    }
}
