//! Embedding Treelet in another engine, on the CPU: build a BVH over your own
//! spheres with the same kernels the GPU runs, then find the closest hit of a
//! few rays with `treelet-core`'s traversal.
//!
//!     cargo run --release -p treelet --example embed
use glam::Vec3;
use treelet::cpu_runner::CpuBackend;
use treelet::lbvh;
use treelet_core::traverse::{closest_hit_bvh, closest_hit_linear, Origin, Prims};
use treelet_core::Sphere;

fn main() -> anyhow::Result<()> {
    // The engine's own geometry: a 20 x 20 x 20 grid of small spheres.
    let mut spheres = Vec::new();
    for i in 0..8000 {
        let (x, y, z) = ((i % 20) as f32, ((i / 20) % 20) as f32, (i / 400) as f32);
        spheres.push(Sphere::new([x * 3.0, y * 3.0, z * 3.0], 1.0));
    }
    treelet::scene::validate_spheres(&spheres)?;

    // Build on the CPU: the very kernels of the GPU build, run invocation by invocation.
    let (bvh, times) = lbvh::build(&mut CpuBackend::new(), &spheres)?;
    println!("built {} nodes over {} spheres in {:.2} ms", bvh.nodes.len(), spheres.len(), times.total());

    // Closest hits through the tree, checked against a scan of every sphere.
    let origin = Vec3::new(-10.0, 28.5, 28.5);
    for k in 0..5 {
        let dir = Vec3::new(1.0, 0.05 * k as f32 - 0.1, 0.03 * k as f32).normalize();
        let prims = Prims::spheres(&spheres);
        let hit = closest_hit_bvh(origin, dir, Origin::NONE, &prims, &bvh.nodes, &bvh.prim_indices);
        let check = closest_hit_linear(origin, dir, Origin::NONE, &prims);
        assert_eq!(hit.prim, check.prim);
        if hit.is_hit() {
            println!("ray {k}: sphere {} at distance {:.4}", hit.prim, hit.t);
        } else {
            println!("ray {k}: no hit");
        }
    }
    Ok(())
}
