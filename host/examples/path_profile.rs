//! Where a render's rays go, on the CPU: the render kernel's own path loop
//! (`treelet_core::render::integrator::Path`) run sample by sample over a
//! scene, with a traversal that counts what it is asked (the linear scan:
//! the same hits as any tree, so the same paths), to tell per camera path
//! how many rays a render casts, how many are shadow rays, and how long its
//! paths are. A developer's tool for reading a render's cost: divide a GPU's
//! camera paths per second by the rays here to get its rays per second.
//!
//!     cargo run --release -p treelet --example path_profile [SCENE] [WIDTH HEIGHT SPP] [smallpt|nee]
//!
//! SCENE as `treelet render --scene` takes it (default `cornell`); 128x96 at 16 spp.
use std::cell::Cell;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use treelet::render::prepared::light_table;
use treelet::scene::{Primitives, Scene};
use treelet_core::geometry::buffers::{RenderParams, NEE, SMALLPT};
use treelet_core::geometry::features::ALL;
use treelet_core::geometry::prims::{Origin, Prims};
use treelet_core::geometry::split::Split;
use treelet_core::render::integrator::{Path, SceneRefs};
use treelet_core::trace::classic::Scan;
use treelet_core::trace::hit::{ClosestHit, Hit, Query};

/// The scan, counting the queries it answers: closest hits (the paths'
/// rays) and occlusion queries (shadow rays; asked as such because this
/// says they stop early, which the scan answers exactly all the same).
struct Counting {
    scan: Scan,
    closest: Cell<u64>,
    occlusion: Cell<u64>,
}

impl ClosestHit for Counting {
    fn trace<const F: u32, const S: usize>(
        &self,
        o: Vec3,
        d: Vec3,
        from: Origin,
        query: Query,
        prims: &Prims,
        stack: &mut [u32; S],
        lane: u32,
    ) -> Hit {
        let counter = if query.any { &self.occlusion } else { &self.closest };
        counter.set(counter.get() + 1);
        self.scan.trace::<F, S>(o, d, from, query, prims, stack, lane)
    }
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let spec = args.first().map_or("cornell", String::as_str);
    let number = |i: usize, default: u32| -> Result<u32> {
        args.get(i)
            .map_or(Ok(default), |s| s.parse().with_context(|| format!("argument {}: `{s}` is not a number", i + 1)))
    };
    let (width, height, spp) = (number(1, 128)?, number(2, 96)?, number(3, 16)?);
    let integrator = match args.get(4).map(String::as_str) {
        None | Some("nee") => NEE,
        Some("smallpt") => SMALLPT,
        Some(other) => bail!("integrator `{other}`: smallpt or nee"),
    };
    if width == 0 || height == 0 || spp == 0 {
        bail!("image size {width}x{height} at {spp} spp: all three must be positive");
    }
    let scene = Scene::from_spec(spec)?;
    let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
    all.check()?;
    let lights = light_table(all, &scene.materials);
    let params = RenderParams {
        width,
        height,
        samples: spp,
        seed: 1,
        prims: scene.spheres.len() as u32,
        triangles: scene.triangles.len() as u32,
        camera: scene.camera.camera(width, height),
        integrator,
        light_count: lights.len() as u32,
        ..Default::default()
    };
    let counting = Counting { scan: Scan::new(&[], &[]), closest: Cell::new(0), occlusion: Cell::new(0) };
    let refs = SceneRefs::new(&params, &scene.spheres, Split::whole(&scene.triangles), &scene.materials, counting);
    // Paths by their number of closest-hit rays (the camera ray and each
    // bounce's), the last bin counting longer ones.
    let mut lengths = [0u64; 17];
    let (mut paths, mut lit) = (0u64, 0u64);
    for pixel in 0..width * height {
        for sample in 0..spp {
            let before = refs.tree.closest.get();
            let mut path = Path::camera::<ALL>(&params, pixel, sample);
            while path.step::<_, ALL, 1>(&params, pixel, &refs, &lights, &mut [0; 1], 0) {}
            let length = (refs.tree.closest.get() - before) as usize;
            lengths[length.min(lengths.len() - 1)] += 1;
            paths += 1;
            lit += (path.result != Vec3::ZERO) as u64;
        }
    }
    let (closest, occlusion) = (refs.tree.closest.get(), refs.tree.occlusion.get());
    let per = |n: u64| n as f64 / paths as f64;
    println!(
        "{spec}: {width}x{height} at {spp} spp, {} ({} spheres, {} triangles, {} lights)",
        if integrator == NEE { "nee" } else { "smallpt" },
        scene.spheres.len(),
        scene.triangles.len(),
        lights.len()
    );
    println!(
        "rays per camera path: {:.3} ({:.3} closest hits, {:.3} shadow rays); {:.1}% of paths bring light",
        per(closest + occlusion),
        per(closest),
        per(occlusion),
        100.0 * per(lit)
    );
    println!("paths by closest-hit rays (the last bin: that many or more):");
    for (length, &count) in lengths.iter().enumerate().filter(|(_, &c)| c > 0) {
        println!("  {length:>2}: {:>6.2}%", 100.0 * per(count));
    }
    Ok(())
}
