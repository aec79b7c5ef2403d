//! Triangle meshes through the builders: GPU against the CPU run of the same
//! kernels, the independent validator, and the SAH ordering of the builders.
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::lbvh::{build_primitives_on_device, Bvh};
use treelet::scene::primitives::Primitives;
use treelet::bvh::trbvh::{optimize, root_box, TreeletConfig};
use treelet::bvh::validate::validate_primitives;
use treelet_core::construct::sah::{SahCosts, sah_cost};
use treelet_core::geometry::triangle::Triangle;

/// A height field over an n x n grid, two triangles per cell, with a
/// seed-dependent phase: a terrain-like mesh.
fn terrain(n: usize, seed: u64) -> Vec<Triangle> {
    let phase = (seed % 1000) as f32 * 0.01;
    let p = |i: usize, j: usize| {
        let (x, z) = (i as f32 / n as f32 * 10.0, j as f32 / n as f32 * 10.0);
        [x, (x * 1.3 + phase).sin() * (z * 0.7).cos(), z]
    };
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push(Triangle::new(p(i, j), p(i + 1, j), p(i + 1, j + 1)));
            t.push(Triangle::new(p(i, j), p(i + 1, j + 1), p(i, j + 1)));
        }
    }
    t
}

fn build<B: Backend>(b: &mut B, tris: &[Triangle], treelets: Option<&TreeletConfig>) -> Bvh {
    let (bvh, _) = build_primitives_on_device(b, Primitives::triangles(tris)).unwrap();
    match treelets {
        None => bvh.read(b).unwrap(),
        Some(config) => {
            let root = root_box(b, &bvh).unwrap();
            optimize(b, bvh, &root, config).unwrap().0.read(b).unwrap()
        }
    }
}

#[test]
fn mesh_lbvh_matches_cpu_and_is_valid() {
    let seed = treelet_tests::fresh_seed();
    for n in [1usize, 5, 60, 150] {
        let tris = terrain(n, seed);
        let c = build(&mut CpuBackend::new(), &tris, None);
        let v = validate_primitives(Primitives::triangles(&tris), &c.nodes, &c.parents, &c.prim_indices);
        assert!(v.is_valid(), "n = {n}: {:?}", v.errors);
        let Some(ctx) = treelet_tests::gpu() else { continue };
        let g = build(&mut GpuBackend::new(ctx), &tris, None);
        assert_eq!(g.prim_indices, c.prim_indices, "n = {n}");
        assert!(g.nodes == c.nodes && g.parents == c.parents, "n = {n}: GPU and CPU LBVHs differ");
    }
}

/// The TRBVH of a mesh: valid on both devices, its SAH closing at least
/// three quarters of the gap from the LBVH's to the sweep's (a ratio that
/// does not depend on how good the LBVH already is) and not below the
/// sweep's. Its decisions compare float costs, and a GPU
/// compiler may fuse a multiply and an add that the CPU rounds twice, so on
/// near ties the two devices may pick different (equally good) trees: the
/// test requires their SAH to agree within 1e-4 and reports how many nodes
/// differ.
#[test]
fn mesh_trbvh_lowers_sah_on_both_devices() {
    let seed = treelet_tests::fresh_seed();
    let tris = terrain(120, seed);
    let prims = Primitives::triangles(&tris);
    let config = TreeletConfig::default();
    let lbvh = sah_cost(&build(&mut CpuBackend::new(), &tris, None).nodes, SahCosts::KARRAS_AILA);
    let c = build(&mut CpuBackend::new(), &tris, Some(&config));
    let v = validate_primitives(prims, &c.nodes, &c.parents, &c.prim_indices);
    assert!(v.is_valid(), "{:?}", v.errors);
    let trbvh = sah_cost(&c.nodes, SahCosts::KARRAS_AILA);
    let sweep = treelet::bvh::sweep::build_collapsed_boxes(&prims.boxes(), config.max_leaf).unwrap();
    let sweep = sah_cost(&sweep.nodes, SahCosts::KARRAS_AILA);
    eprintln!("terrain of {} triangles: SAH lbvh {lbvh:.3}, trbvh {trbvh:.3}, sweep {sweep:.3}", tris.len());
    assert!(
        trbvh - sweep < 0.25 * (lbvh - sweep),
        "TRBVH {trbvh} closes too little of the gap from the LBVH's {lbvh} to the sweep's {sweep}"
    );
    assert!(sweep <= trbvh * 1.001, "the sweep reference {sweep} is worse than the TRBVH {trbvh}");
    let Some(ctx) = treelet_tests::gpu() else { return };
    let g = build(&mut GpuBackend::new(ctx), &tris, Some(&config));
    let v = validate_primitives(prims, &g.nodes, &g.parents, &g.prim_indices);
    assert!(v.is_valid(), "GPU: {:?}", v.errors);
    let gpu = sah_cost(&g.nodes, SahCosts::KARRAS_AILA);
    let differing = g.nodes.iter().zip(&c.nodes).filter(|(a, b)| a != b).count();
    eprintln!("GPU SAH {gpu:.6} vs CPU {trbvh:.6}; {differing} of {} nodes differ", c.nodes.len());
    assert!((gpu - trbvh).abs() <= 1e-4 * trbvh, "GPU SAH {gpu} vs CPU {trbvh}");
}

/// Stiff meshes through the whole pipeline: a million triangles with one
/// box (every Morton key equal), duplicated triangles, and a mesh 1e6 from
/// the origin traced through its trees, each hit compared with a scan.
mod stiff {
    use super::*;
    use glam::Vec3;
    use treelet_core::geometry::prims::{Origin, Prims};
    use treelet_core::trace::classic::{closest_hit_bvh, closest_hit_linear};

    /// Triangles spanning the same unit cube at `c` (three corners each, in
    /// varying order): identical boxes and centroids.
    fn same_box(n: usize, c: Vec3) -> Vec<Triangle> {
        let corner = |i: usize| (c + Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32)).to_array();
        let spanning = [[0, 6, 3], [1, 7, 2], [4, 2, 7], [5, 3, 6]]; // each spans x, y and z
        (0..n)
            .map(|i| {
                let t = spanning[i % 4];
                let r = i / 4 % 3;
                Triangle::new(corner(t[r]), corner(t[(r + 1) % 3]), corner(t[(r + 2) % 3]))
            })
            .collect()
    }

    #[test]
    fn a_million_triangles_with_one_box() {
        let tris = same_box(1_000_000, Vec3::new(3.0, -2.0, 7.0));
        let prims = Primitives::triangles(&tris);
        let (bvh, _) = match treelet_tests::gpu() {
            Some(ctx) => {
                let b = &mut GpuBackend::new(ctx);
                let (d, t) = build_primitives_on_device(b, prims).unwrap();
                (d.read(b).unwrap(), t)
            }
            None => {
                let b = &mut CpuBackend::new();
                let (d, t) = build_primitives_on_device(b, prims).unwrap();
                (d.read(b).unwrap(), t)
            }
        };
        let v = validate_primitives(prims, &bvh.nodes, &bvh.parents, &bvh.prim_indices);
        assert!(v.is_valid(), "{:?}", v.errors);
        // Equal keys split by index: a balanced tree, depth about log2(n).
        let mut depth = vec![0u32; bvh.nodes.len()];
        let mut max_depth = 0;
        for i in 0..bvh.nodes.len() {
            let n = bvh.nodes[i];
            if !n.is_leaf() {
                for c in [n.left as usize, n.right as usize] {
                    depth[c] = depth[i] + 1;
                    max_depth = max_depth.max(depth[c]);
                }
            }
        }
        assert!(max_depth <= 24, "depth {max_depth} for a million equal keys");
    }

    /// Closest hits of many rays through the LBVH, the TRBVH and the sweep
    /// tree of `tris`, each against the scan of every triangle.
    fn trees_find_the_scans_hits(tris: &[Triangle], what: &str) {
        let prims = Primitives::triangles(tris);
        let b = &mut CpuBackend::new();
        let lbvh = build(b, tris, None);
        let trbvh = build(b, tris, Some(&TreeletConfig::default()));
        let sweep = treelet::bvh::sweep::build_collapsed_boxes(&prims.boxes(), 8).unwrap();
        let scene = Prims::new(&[], tris);
        let bounds = prims.boxes().iter().fold(treelet_core::Aabb::EMPTY, |a, b| a.union(b));
        let (center, size) = (bounds.centroid(), bounds.extent().max_element());
        let mut hits = 0;
        for i in 0..2000u32 {
            let r = treelet_core::gpu::rng::BounceRng::new(17, i, 0, 0);
            let dir = Vec3::new(r.uniform(0) - 0.5, r.uniform(1) - 0.5, r.uniform(2) - 0.5).normalize_or(Vec3::X);
            let target = center + Vec3::new(r.uniform(3) - 0.5, r.uniform(4) - 0.5, r.uniform(5) - 0.5) * size;
            let o = target - dir * (2.0 * size);
            let scan = closest_hit_linear(o, dir, Origin::NONE, &scene);
            for (name, t) in [("lbvh", &lbvh), ("trbvh", &trbvh), ("sweep", &sweep)] {
                let hit = closest_hit_bvh(o, dir, Origin::NONE, &scene, &t.nodes, &t.prim_indices);
                assert!(
                    hit.t == scan.t,
                    "{what}, {name}, ray {i}: tree hit at {} (triangle {}), scan at {} (triangle {})",
                    hit.t,
                    hit.prim,
                    scan.t,
                    scan.prim
                );
            }
            hits += scan.is_hit() as u32;
        }
        assert!(hits > 200, "{what}: only {hits} rays hit");
    }

    #[test]
    fn far_duplicated_and_tiny_meshes_trace_like_the_scan() {
        let seed = treelet_tests::fresh_seed();
        let terrain = terrain(40, seed);
        let shift = |t: &Triangle, by: f32, scale: f32| {
            let f = |v: [f32; 3]| v.map(|x| x * scale + by);
            Triangle::new(f(t.v0), f(t.v1), f(t.v2))
        };
        trees_find_the_scans_hits(&terrain, "terrain");
        let far: Vec<Triangle> = terrain.iter().map(|t| shift(t, 1e6, 1.0)).collect();
        trees_find_the_scans_hits(&far, "terrain at 1e6");
        let tiny: Vec<Triangle> = terrain.iter().map(|t| shift(t, 0.0, 1e-4)).collect();
        trees_find_the_scans_hits(&tiny, "terrain scaled 1e-4");
        let doubled: Vec<Triangle> = terrain.iter().flat_map(|t| [*t, *t]).collect();
        trees_find_the_scans_hits(&doubled, "every triangle twice");
        let degenerate: Vec<Triangle> =
            terrain.iter().enumerate().map(|(i, t)| if i % 7 == 0 { Triangle::new(t.v0, t.v0, t.v1) } else { *t }).collect();
        trees_find_the_scans_hits(&degenerate, "with zero-area triangles");
        trees_find_the_scans_hits(&same_box(5000, Vec3::new(-4.0, 1.0, 9.0)), "5000 triangles with one box");
    }
}
