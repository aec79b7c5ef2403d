//! Work per ray of each traversal layout: node records and leaf primitives
//! loaded for a scene's camera rays and their diffuse bounces, counted on
//! the CPU by wrapping the loads the traversals make through
//! `RecordLoad` (the same traversal code the kernels run, untouched). A
//! developer's tool: whether one layout is slower because it does more
//! work or because each step costs more on the GPU.
//!
//!     cargo run --release -p treelet --example trace_counts -- SCENE [WIDTH HEIGHT] [EX,EY,EZ,TX,TY,TZ]
//!
//! Trees: TRBVH, split as by default or as `TREELET_SPLITS` says, built by
//! the CPU runner, or on the GPU with `TREELET_COUNTS_DEVICE=gpu` (the
//! counts are still made on the CPU, over the GPU's tree).
use std::cell::Cell;

use anyhow::{Context, Result};
use treelet::bvh::layout::{wide_nodes, Layout};
use treelet::bvh::tree::split_budget;
use treelet::bvh::tree::{binary_tree_split, Accel};
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::{GpuBackend, GpuContext};
use treelet::scene::{CameraSpec, Scene};
use treelet_core::geometry::buffers::{Bvh2Node, LeafPrim, WideNode};
use treelet_core::geometry::features::ALL;
use treelet_core::geometry::intersect::surface_offset;
use treelet_core::geometry::prims::{Origin, Prims};
use treelet_core::geometry::records::RecordLoad;
use treelet_core::render::integrator::hit_normal_for;
use treelet_core::render::sampling::cosine_direction;
use treelet_core::trace::bvh2::trace_bvh2;
use treelet_core::trace::cwbvh::{trace_cwbvh_with, WIDE_STACK};
use treelet_core::trace::hit::Query;

/// A slice whose loads are counted.
struct Counted<'a, T> {
    records: &'a [T],
    loads: &'a Cell<u64>,
}

impl<T: Copy> RecordLoad<T> for Counted<'_, T> {
    fn load(&self, i: usize) -> T {
        self.loads.set(self.loads.get() + 1);
        self.records[i]
    }
}

fn main() -> Result<()> {
    // The TREELET_* knobs (TREELET_SPLITS among them), as the command takes them.
    let _ = treelet::tuning::Tuning::from_env()?.install();
    if std::env::var("TREELET_COUNTS_DEVICE").is_ok_and(|d| d == "gpu") {
        let ctx = GpuContext::new()?;
        println!("trees built on {}", ctx.info.name);
        count(&mut GpuBackend::new(ctx))
    } else {
        count(&mut CpuBackend::new())
    }
}

fn count<B: Backend>(b: &mut B) -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let spec = args.first().context("usage: trace_counts SCENE [WIDTH HEIGHT] [EX,EY,EZ,TX,TY,TZ]")?;
    let (w, h) = match (args.get(1), args.get(2)) {
        (Some(a), Some(b)) => (a.parse()?, b.parse()?),
        _ => (320u32, 180u32),
    };
    let mut scene = Scene::from_spec(spec)?.mesh_only()?;
    if let Some(c) = args.get(3) {
        let c: Vec<f32> = c.split(',').map(|x| x.parse()).collect::<Result<_, _>>()?;
        scene.camera = CameraSpec::looking_at([c[0], c[1], c[2]], [c[3], c[4], c[5]])?;
    }
    let prims_host = scene.primitives();
    let prims = Prims::new(&scene.spheres, &scene.triangles);
    let camera = scene.camera.camera(w, h);
    let builder = Accel::Trbvh.builder()?.context("trbvh")?;
    let built = binary_tree_split(b, prims_host, builder, split_budget(builder))?;
    let slots = built.bvh.n as usize;
    let buffers = built.prim_buffers(b, prims_host)?;
    let (bt, _) = built.lay_out(b, Layout::Bvh2, &buffers)?;
    let bvh2_nodes: Vec<Bvh2Node> = b.read(&bt.nodes, bt.node_count as usize)?;
    let bvh2_leaf: Vec<LeafPrim> = b.read(&bt.prims, slots)?;
    let (wt, _) = built.lay_out(b, Layout::Cwbvh, &buffers)?;
    let wide: Vec<WideNode> = wide_nodes(b, &wt)?;
    let wide_leaf: Vec<LeafPrim> = b.read(&wt.prims, slots)?;
    println!("{spec}: {} triangles, {w}x{h}; bvh2 {} nodes, cwbvh {} nodes", scene.triangles.len(), bvh2_nodes.len(), wide.len());
    let counts = [(); 4].map(|_| Cell::new(0u64)); // bvh2 nodes, leaves; cwbvh nodes, leaves
    let mut rays = [0u64; 2];
    let mut disagreements = 0;
    for pass in 0..2 {
        let before: Vec<u64> = counts.iter().map(Cell::get).collect();
        // bvh2 steps (nodes + leaf primitives) of each ray, by pixel, for
        // the spread: a warp runs as long as its longest ray.
        let mut steps = vec![0u64; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let at = counts[0].get() + counts[1].get();
                let (o, d) = camera.primary_ray(x, h - 1 - y, 0, w, h, (0.5, 0.5));
                let (o, d, from) = if pass == 0 {
                    (o, d, Origin::NONE)
                } else {
                    let hit = trace_bvh2::<ALL>(o, d, Origin::NONE, Query::CLOSEST, &prims, &bvh2_nodes[..], &bvh2_leaf[..]);
                    if !hit.is_hit() {
                        continue;
                    }
                    let p = o + d * hit.t;
                    let n = hit_normal_for::<ALL>(&prims, hit.prim, p, d);
                    let nl = if n.dot(d) < 0.0 { n } else { -n };
                    let u = ((x * 7919 + y * 104729) % 1000) as f32 / 1000.0;
                    let v = ((x * 104729 + y * 7919) % 997) as f32 / 997.0;
                    (p + nl * surface_offset(p), cosine_direction(nl, u, v), Origin { prim: hit.prim, into: false })
                };
                rays[pass] += 1;
                let a = trace_bvh2::<ALL>(
                    o,
                    d,
                    from,
                    Query::CLOSEST,
                    &prims,
                    &Counted { records: &bvh2_nodes, loads: &counts[0] },
                    &Counted { records: &bvh2_leaf, loads: &counts[1] },
                );
                let mut private = [0u32; 2 * WIDE_STACK];
                let c = trace_cwbvh_with::<ALL, 1>(
                    o,
                    d,
                    from,
                    Query::CLOSEST,
                    &prims,
                    &Counted { records: &wide, loads: &counts[2] },
                    &Counted { records: &wide_leaf, loads: &counts[3] },
                    &mut private,
                    &mut [0u32; 1],
                    0,
                );
                steps[(y * w + x) as usize] = counts[0].get() + counts[1].get() - at;
                disagreements += (a.t != c.t || a.prim != c.prim) as u32;
            }
        }
        print_spread(&steps, w, h);
        let per = |k: usize| (counts[k].get() - before[k]) as f64 / rays[pass].max(1) as f64;
        let name = if pass == 0 { "primary" } else { "diffuse" };
        println!(
            "{name:>8}: {} rays; per ray: bvh2 {:.1} nodes ({:.0} B), {:.1} leaf prims; cwbvh {:.1} nodes ({:.0} B), {:.1} leaf prims",
            rays[pass],
            per(0),
            per(0) * 64.0,
            per(1),
            per(2),
            per(2) * 80.0,
            per(3)
        );
    }
    println!("hits that differ between the layouts: {disagreements} (must be 0)");
    Ok(())
}

/// Percentiles of the bvh2 steps a ray, and how busy a warp's lanes are
/// in tiles of 8x4 pixels (the mean over the tile's rays against its
/// longest: the share of lane-steps doing work if a warp were one tile).
fn print_spread(steps: &[u64], w: u32, h: u32) {
    let mut sorted: Vec<u64> = steps.iter().copied().filter(|&s| s > 0).collect();
    sorted.sort_unstable();
    if sorted.is_empty() {
        return;
    }
    let q = |f: f64| sorted[((sorted.len() - 1) as f64 * f) as usize];
    let (mut sum, mut max_sum) = (0u64, 0u64);
    for ty in 0..h / 4 {
        for tx in 0..w / 8 {
            let tile = (0..32).map(|k| steps[((ty * 4 + k / 8) * w + tx * 8 + k % 8) as usize]);
            sum += tile.clone().sum::<u64>();
            max_sum += 32 * tile.max().unwrap_or(0);
        }
    }
    println!(
        "          bvh2 steps a ray: median {}, 90% {}, 99% {}, 99.9% {}, max {}; lanes busy in 8x4 tiles {:.0}%",
        q(0.5),
        q(0.9),
        q(0.99),
        q(0.999),
        sorted[sorted.len() - 1],
        100.0 * sum as f64 / max_sum.max(1) as f64
    );
}
