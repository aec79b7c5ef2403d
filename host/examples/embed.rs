//! Embedding Treelet in another engine, on the CPU: build a tree over your
//! own spheres with the same kernels the GPU runs, lay it out for
//! traversal, then find the closest hits of a few rays with
//! `treelet-core`'s traversal of that layout (one function per layout).
//!
//!     cargo run --release -p treelet --example embed
use glam::Vec3;
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::bvh::layout::{wide_nodes, Layout};
use treelet::scene::primitives::Primitives;
use treelet::bvh::tree::{traced_tree, Accel};
use treelet_core::geometry::buffers::{Bvh2Node, LeafPrim};
use treelet_core::geometry::features::ALL;
use treelet_core::geometry::prims::{Origin, Prims};
use treelet_core::trace::bvh2::closest_hit_bvh2;
use treelet_core::trace::classic::{closest_hit_bvh, closest_hit_linear};
use treelet_core::trace::cwbvh::closest_hit_cwbvh;
use treelet_core::{Node, Sphere};

fn main() -> anyhow::Result<()> {
    // The engine's own geometry: a 20 x 20 x 20 grid of small spheres.
    let mut spheres = Vec::new();
    for i in 0..8000 {
        let (x, y, z) = ((i % 20) as f32, ((i / 20) % 20) as f32, (i / 400) as f32);
        spheres.push(Sphere::new([x * 3.0, y * 3.0, z * 3.0], 1.0));
    }
    let prims = Primitives::spheres(&spheres);
    prims.check()?;
    let (sp, scene) = (&spheres, Prims::spheres(&spheres));
    let rays: Vec<(Vec3, Vec3)> = (0..5)
        .map(|k| (Vec3::new(-10.0, 28.5, 28.5), Vec3::new(1.0, 0.05 * k as f32 - 0.1, 0.03 * k as f32).normalize()))
        .collect();

    // Build on the CPU: the very kernels of the GPU build, run invocation by
    // invocation (a `GpuBackend` builds the same tree on the GPU). The
    // treelet-optimized tree, laid out three ways.
    let b = &mut CpuBackend::new();
    for layout in Layout::ALL {
        let (tree, _, build_ms) = traced_tree(b, prims, Accel::Trbvh, layout)?;
        println!("{}: built and laid out over {} spheres in {build_ms:.2} ms", layout.name(), spheres.len());
        // Read the layout back and trace with its traversal function.
        let trace: Box<dyn Fn(Vec3, Vec3) -> treelet_core::trace::hit::Hit> = match layout {
            Layout::Classic => {
                let nodes: Vec<Node> = b.read(&tree.nodes, tree.node_count as usize)?;
                let indices: Vec<u32> = b.read(&tree.prims, spheres.len())?;
                Box::new(move |o, d| closest_hit_bvh(o, d, Origin::NONE, &Prims::spheres(sp), &nodes, &indices))
            }
            Layout::Bvh2 => {
                let nodes: Vec<Bvh2Node> = b.read(&tree.nodes, tree.node_count as usize)?;
                let leaf: Vec<LeafPrim> = b.read(&tree.prims, spheres.len())?;
                Box::new(move |o, d| closest_hit_bvh2::<ALL>(o, d, Origin::NONE, &Prims::spheres(sp), &nodes, &leaf))
            }
            _ => {
                let nodes = wide_nodes(b, &tree)?;
                let leaf: Vec<LeafPrim> = b.read(&tree.prims, spheres.len())?;
                Box::new(move |o, d| closest_hit_cwbvh::<ALL>(o, d, Origin::NONE, &Prims::spheres(sp), &nodes, &leaf))
            }
        };
        // Closest hits through the tree, checked against a scan of every sphere.
        for (k, &(o, d)) in rays.iter().enumerate() {
            let (hit, check) = (trace(o, d), closest_hit_linear(o, d, Origin::NONE, &scene));
            assert_eq!((hit.prim, hit.t), (check.prim, check.t));
            if hit.is_hit() {
                println!("  ray {k}: sphere {} at distance {:.4}", hit.prim, hit.t);
            } else {
                println!("  ray {k}: no hit");
            }
        }
    }
    Ok(())
}
