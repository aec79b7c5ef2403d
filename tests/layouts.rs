//! The traversal layouts (`classic`, `bvh2`, `bvh4`, `cwbvh`): every layout of every
//! tree (LBVH, TRBVH, sweep) finds exactly the scan's closest hit, distance
//! and primitive, on random, mesh and stiff scenes, for rays from outside,
//! from inside, along the axes and leaving a surface; each layout passes
//! the independent validator (which checks, among the rest, that quantized
//! boxes contain their children's exact boxes); and the GPU builds the
//! layouts the CPU runner builds.
use glam::Vec3;
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::layout::{wide_nodes, Layout, TracedTree};
use treelet::scene::primitives::Primitives;
use treelet::bvh::tree::{binary_tree_split, binary_tree_with, split_budget, Accel};
use treelet::bvh::trbvh::{TreeletConfig, GPU_TRBVH_REINSERT};
use treelet::scene::{random_spheres, Scene};
use treelet::bvh::validate_layout::{validate_bvh2, validate_bvh2_split, validate_bvh4, validate_bvh4_split, validate_wide, validate_wide_split};
use treelet_core::geometry::buffers::{Bvh2Node, Bvh4Node, LeafPrim, Node, Sphere, WideNode};
use treelet_core::geometry::features::ALL;
use treelet_core::geometry::prims::{Origin, Prims};
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::rng::BounceRng;
use treelet_core::trace::bvh2::closest_hit_bvh2;
use treelet_core::trace::bvh4::closest_hit_bvh4;
use treelet_core::trace::classic::{closest_hit_bvh, closest_hit_linear};
use treelet_core::trace::cwbvh::closest_hit_cwbvh;
use treelet_core::trace::hit::{Hit, Query};

/// A laid-out tree, read back.
enum HostTree {
    Classic(Vec<Node>, Vec<u32>),
    Bvh2(Vec<Bvh2Node>, Vec<LeafPrim>),
    Bvh4(Vec<Bvh4Node>, Vec<LeafPrim>),
    Wide(Vec<WideNode>, Vec<LeafPrim>),
}

fn read<B: Backend>(b: &mut B, tree: &TracedTree<B>, n: usize) -> HostTree {
    match tree.layout {
        Layout::Classic => HostTree::Classic(b.read(&tree.nodes, tree.node_count as usize).unwrap(), b.read(&tree.prims, n).unwrap()),
        Layout::Bvh2 => HostTree::Bvh2(b.read(&tree.nodes, tree.node_count as usize).unwrap(), b.read(&tree.prims, n).unwrap()),
        Layout::Bvh4 => HostTree::Bvh4(b.read(&tree.nodes, tree.node_count as usize).unwrap(), b.read(&tree.prims, n).unwrap()),
        _ => HostTree::Wide(wide_nodes(b, tree).unwrap(), b.read(&tree.prims, n).unwrap()),
    }
}

/// The tree `accel` makes with the settings of a GPU's on any device: the
/// TRBVH reinserts on GPUs and not on the CPU runner by default, so trees
/// compared between the two are made alike.
/// Also the tree's leaf slots: more than the primitives where the builder
/// split large triangles (by default, within [`split_budget`]).
fn traced<B: Backend>(b: &mut B, prims: Primitives, accel: Accel, layout: Layout) -> (TracedTree<B>, usize) {
    let config = TreeletConfig { reinsert: Some(GPU_TRBVH_REINSERT), ..TreeletConfig::default() };
    let builder = accel.builder().unwrap().unwrap();
    let built = binary_tree_with(b, prims, builder, split_budget(builder), &config).unwrap();
    let buffers = built.prim_buffers(b, prims).unwrap();
    let (tree, _) = built.lay_out(b, layout, &buffers).unwrap();
    (tree, built.bvh.n as usize)
}

/// The tree [`traced`] makes, read back, and its leaf slots.
fn build_counted<B: Backend>(b: &mut B, prims: Primitives, accel: Accel, layout: Layout) -> (HostTree, usize) {
    let (tree, slots) = traced(b, prims, accel, layout);
    (read(b, &tree, slots), slots)
}

fn build<B: Backend>(b: &mut B, prims: Primitives, accel: Accel, layout: Layout) -> HostTree {
    build_counted(b, prims, accel, layout).0
}

impl HostTree {
    fn trace(&self, o: Vec3, d: Vec3, from: Origin, prims: &Prims) -> Hit {
        match self {
            HostTree::Classic(nodes, idx) => closest_hit_bvh(o, d, from, prims, nodes, idx),
            HostTree::Bvh2(nodes, leaf) => closest_hit_bvh2::<ALL>(o, d, from, prims, nodes, leaf),
            HostTree::Bvh4(nodes, leaf) => closest_hit_bvh4::<ALL>(o, d, from, prims, nodes, leaf),
            HostTree::Wide(nodes, leaf) => closest_hit_cwbvh::<ALL>(o, d, from, prims, nodes, leaf),
        }
    }

    fn validate(&self, prims: Primitives) {
        let v = match self {
            HostTree::Classic(..) => return, // the binary validator's business (tests/invariants.rs)
            HostTree::Bvh2(nodes, leaf) => validate_bvh2(prims, nodes, leaf),
            HostTree::Bvh4(nodes, leaf) => validate_bvh4(prims, nodes, leaf),
            HostTree::Wide(nodes, leaf) => validate_wide(prims, nodes, leaf),
        };
        assert!(v.is_valid(), "{:?}", v.errors);
    }
}

fn vec3(r: &BounceRng, k: u32) -> Vec3 {
    Vec3::new(r.uniform(k), r.uniform(k + 1), r.uniform(k + 2))
}

fn primitive_centre(prims: &Prims, p: u32) -> Vec3 {
    if p < prims.sphere_count {
        Vec3::from_array(prims.spheres[p as usize].center)
    } else {
        let t = prims.triangle(p - prims.sphere_count);
        (Vec3::from_array(t.v0) + Vec3::from_array(t.v1) + Vec3::from_array(t.v2)) / 3.0
    }
}

/// Primitive `p`'s box, as the builders bound it.
fn primitive_box(prims: &Prims, p: u32) -> (Vec3, Vec3) {
    let b = if p < prims.sphere_count { prims.spheres[p as usize].aabb() } else { prims.triangle(p - prims.sphere_count).aabb() };
    (b.lo(), b.hi())
}

/// Rays that probe a scene of bounds `lo..hi`: from outside through it,
/// from inside, exactly along an axis (from outside, and through a
/// primitive's corner, so lying in the faces of the boxes around it), and
/// leaving the surface a scan hit (`Origin` set, as the renderer's bounces
/// are). Each with the scan's hit.
fn rays(prims: &Prims, lo: Vec3, hi: Vec3, seed: u32, count: u32) -> Vec<(Vec3, Vec3, Origin, Hit)> {
    let (center, size) = ((lo + hi) * 0.5, (hi - lo).max_element().max(1e-30));
    let mut out = Vec::new();
    for i in 0..count {
        let r = BounceRng::new(seed, i, 0, 0);
        let target = lo + (hi - lo) * vec3(&r, 0);
        let (o, d) = match i % 5 {
            0 => {
                let d = (vec3(&r, 3) - 0.5).normalize_or(Vec3::X);
                (target - d * (2.0 * size), d)
            }
            1 => (lo + (hi - lo) * vec3(&r, 6), (vec3(&r, 3) - 0.5).normalize_or(Vec3::Y)),
            2 => {
                // Along one axis: two direction components exactly zero.
                let axis = (r.uniform(9) * 3.0) as usize % 3;
                let mut d = [0.0f32; 3];
                d[axis] = if r.uniform(10) < 0.5 { -1.0 } else { 1.0 };
                let d = Vec3::from_array(d);
                (target - d * (2.0 * size), d)
            }
            4 => {
                // Along an axis through a random primitive's box corner: the
                // ray lies in faces of the boxes that hold it (a far face
                // once made the slab test's distance 0 on that axis).
                let p = ((r.uniform(13) * prims.count() as f32) as u32).min(prims.count() - 1);
                let (plo, phi) = primitive_box(prims, p);
                let corner = Vec3::select(glam::BVec3::new(r.uniform(14) < 0.5, r.uniform(15) < 0.5, r.uniform(16) < 0.5), plo, phi);
                let axis = (r.uniform(9) * 3.0) as usize % 3;
                let mut d = [0.0f32; 3];
                d[axis] = if r.uniform(10) < 0.5 { -1.0 } else { 1.0 };
                let d = Vec3::from_array(d);
                // From outside the scene on that axis, keeping the corner's
                // other two coordinates exactly.
                let mut o = corner.to_array();
                o[axis] = if d[axis] > 0.0 { lo[axis] - size } else { hi[axis] + size };
                (Vec3::from_array(o), d)
            }
            _ => {
                // At a random primitive's centre, from outside the scene.
                let p = ((r.uniform(13) * prims.count() as f32) as u32).min(prims.count() - 1);
                let aim = primitive_centre(prims, p);
                let d = (aim - center + (vec3(&r, 3) - 0.5) * size * 1e-3).normalize_or(Vec3::Z);
                (aim - d * (2.0 * size), d)
            }
        };
        let hit = closest_hit_linear(o, d, Origin::NONE, prims);
        out.push((o, d, Origin::NONE, hit));
        if hit.is_hit() {
            // Leave the surface hit, outwards, as a bounce does.
            let x = o + d * hit.t;
            let n = treelet_core::render::integrator::hit_normal(prims, hit.prim, x, d);
            let nl = if n.dot(d) < 0.0 { n } else { -n };
            let d2 = treelet_core::render::sampling::cosine_direction(nl, r.uniform(11), r.uniform(12));
            let from = Origin { prim: hit.prim, into: d2.dot(n) < 0.0 };
            let o2 = x + nl * treelet_core::geometry::intersect::surface_offset(x);
            out.push((o2, d2, from, closest_hit_linear(o2, d2, from, prims)));
        }
    }
    out
}

/// Every tree in every layout, built by the CPU runner, finds exactly the
/// scan's hits in `spheres` and `triangles`, and passes the validator.
fn every_layout_traces_like_the_scan(what: &str, spheres: &[Sphere], triangles: &[Triangle], seed: u32) {
    let prims = Primitives { spheres, triangles };
    prims.check().unwrap();
    let scene = Prims::new(spheres, triangles);
    let bounds = prims.boxes().iter().fold(treelet_core::Aabb::EMPTY, |a, b| a.union(b));
    let probes = rays(&scene, bounds.lo(), bounds.hi(), seed, 600);
    let hits = probes.iter().filter(|p| p.3.is_hit()).count();
    assert!(hits * 8 > probes.len(), "{what}: only {hits} of {} rays hit: a weak test", probes.len());
    let b = &mut CpuBackend::new();
    for accel in [Accel::Lbvh, Accel::Trbvh, Accel::Hploc, Accel::Sweep] {
        for layout in Layout::ALL {
            // Split trees (large triangles in pieces) by their own validator.
            let (tree, slots) = build_counted(b, prims, accel, layout);
            if slots > prims.len() {
                tree.validate_split(prims, what);
            } else {
                tree.validate(prims);
            }
            for (k, &(o, d, from, scan)) in probes.iter().enumerate() {
                let hit = tree.trace(o, d, from, &scene);
                assert!(
                    hit.t.to_bits() == scan.t.to_bits() && hit.prim == scan.prim,
                    "{what}, {accel:?} in {}: ray {k} (o {o}, d {d}) hit {} at {}, the scan {} at {}",
                    layout.name(),
                    hit.prim,
                    hit.t,
                    scan.prim,
                    scan.t
                );
            }
        }
    }
}

/// A tree over pieces of the triangles (`budget` times the triangles more
/// at most), laid out, and its number of leaf slots.
fn build_split<B: Backend>(b: &mut B, prims: Primitives, accel: Accel, layout: Layout, budget: f32) -> (HostTree, usize) {
    let built = binary_tree_split(b, prims, accel.builder().unwrap().unwrap(), budget).unwrap();
    let buffers = built.prim_buffers(b, prims).unwrap();
    let (tree, _) = built.lay_out(b, layout, &buffers).unwrap();
    let slots = built.bvh.n as usize;
    (read(b, &tree, slots), slots)
}

impl HostTree {
    fn validate_split(&self, prims: Primitives, what: &str) {
        let v = match self {
            HostTree::Classic(..) => return,
            HostTree::Bvh2(nodes, leaf) => validate_bvh2_split(prims, nodes, leaf),
            HostTree::Bvh4(nodes, leaf) => validate_bvh4_split(prims, nodes, leaf),
            HostTree::Wide(nodes, leaf) => validate_wide_split(prims, nodes, leaf),
        };
        assert!(v.is_valid(), "{what}: {:?}", v.errors);
    }
}

/// Trees over pieces of triangles (`treelet_core::construct::presplit`),
/// built by the CPU runner and, where there is one, the GPU: valid (each
/// triangle covered by its pieces' leaves), with more leaf slots than
/// primitives where `splits` says the scene has triangles worth splitting,
/// and exactly the scan's hits in every layout. The GPU's reference count
/// is the CPU runner's to 1% or one (priorities are sums of products the GPU may
/// fuse, so a count at a rounding boundary may differ by one).
fn split_trees_trace_like_the_scan(what: &str, spheres: &[Sphere], triangles: &[Triangle], seed: u32, splits: bool) {
    let prims = Primitives { spheres, triangles };
    prims.check().unwrap();
    let scene = Prims::new(spheres, triangles);
    let bounds = prims.boxes().iter().fold(treelet_core::Aabb::EMPTY, |a, b| a.union(b));
    let probes = rays(&scene, bounds.lo(), bounds.hi(), seed, 600);
    let gpu = treelet_tests::gpu();
    for accel in [Accel::Lbvh, Accel::Trbvh, Accel::Hploc] {
        for layout in Layout::ALL {
            let cpu = build_split(&mut CpuBackend::new(), prims, accel, layout, 0.5);
            let mut trees = vec![("CPU runner", cpu.0)];
            assert!(!splits || cpu.1 > prims.len(), "{what}, {accel:?}: no triangle was split");
            assert!(cpu.1 <= prims.len() + triangles.len() / 2, "{what}, {accel:?}: {} slots past the budget", cpu.1);
            if let Some(ctx) = &gpu {
                let g = build_split(&mut GpuBackend::new(ctx.clone()), prims, accel, layout, 0.5);
                let diff = g.1.abs_diff(cpu.1);
                assert!(diff <= 1 || diff * 100 <= cpu.1, "{what}, {accel:?}: {} references on the GPU, {} on the CPU runner; {triangles:?}", g.1, cpu.1);
                trees.push(("GPU", g.0));
            }
            for (device, tree) in &trees {
                let what = format!("{what}, {accel:?} in {} over pieces, {device}, seed {seed}", layout.name());
                tree.validate_split(prims, &what);
                for (k, &(o, d, from, scan)) in probes.iter().enumerate() {
                    let hit = tree.trace(o, d, from, &scene);
                    assert!(
                        hit.t.to_bits() == scan.t.to_bits() && hit.prim == scan.prim,
                        "{what}: ray {k} (o {o}, d {d}) hit {} at {}, the scan {} at {}",
                        hit.prim,
                        hit.t,
                        scan.prim,
                        scan.t
                    );
                }
            }
        }
    }
}

/// Triangles of every size, as real scenes have: a ground of two huge
/// triangles, long slivers across it, walls, and small terrain detail.
fn irregular(seed: u32) -> Vec<Triangle> {
    let mut out = vec![
        Triangle::new([-500.0, 0.0, -500.0], [500.0, 0.0, -500.0], [500.0, 0.0, 500.0]),
        Triangle::new([-500.0, 0.0, -500.0], [500.0, 0.0, 500.0], [-500.0, 0.0, 500.0]),
    ];
    for i in 0..40 {
        let r = BounceRng::new(seed, i, 0, 0);
        let (a, b) = (vec3(&r, 0) * 800.0 - 400.0, vec3(&r, 3) * 800.0 - 400.0);
        // A cable: long, thin, diagonal.
        out.push(Triangle::new(a.to_array(), b.to_array(), (b + Vec3::splat(0.05)).to_array()));
        // A wall: a tall upright quad's half.
        out.push(Triangle::new([a.x, 0.0, a.z], [b.x, 0.0, b.z], [b.x, 30.0 + 100.0 * r.uniform(6), b.z]));
    }
    out.extend(terrain(2000).iter().map(|t| {
        let f = |v: [f32; 3]| [v[0] * 0.5 + 20.0, v[1] * 0.5 + 1.0, v[2] * 0.5 - 10.0];
        Triangle::new(f(t.v0), f(t.v1), f(t.v2))
    }));
    out
}

#[test]
fn split_trees_find_the_scans_hits() {
    let seed = treelet_tests::fresh_seed() as u32;
    let scene = irregular(seed);
    split_trees_trace_like_the_scan("irregular", &[], &scene, seed, true);
    let doubled: Vec<Triangle> = scene.iter().flat_map(|t| [*t, *t]).collect();
    split_trees_trace_like_the_scan("irregular, every triangle twice", &[], &doubled, seed, true);
    let far: Vec<Triangle> = scene.iter().map(|t| Triangle::new(t.v0.map(|x| x + 1e6), t.v1.map(|x| x + 1e6), t.v2.map(|x| x + 1e6))).collect();
    split_trees_trace_like_the_scan("irregular at 1e6", &[], &far, seed, true);
    let degenerate: Vec<Triangle> =
        scene.iter().enumerate().map(|(i, t)| if i % 5 == 0 { Triangle::new(t.v0, t.v0, t.v1) } else { *t }).collect();
    split_trees_trace_like_the_scan("irregular with zero-area triangles", &[], &degenerate, seed, true);
    // Spheres are never split; the room's walls (radius 1e5) beside triangles.
    let room = Scene::from_spec("terrain:1500").unwrap();
    split_trees_trace_like_the_scan("terrain in the room", &room.spheres, &room.triangles, seed, false);
    for n in [1usize, 2, 3, 5] {
        split_trees_trace_like_the_scan(&format!("{n} irregular triangles"), &[], &scene[..n], seed, false);
    }
}

/// The split validators must catch pieces that leave part of a triangle
/// uncovered, or the checks above prove nothing.
#[test]
fn split_validators_catch_uncovered_triangles() {
    let tris = irregular(7);
    let prims = Primitives::triangles(&tris);
    let b = &mut CpuBackend::new();
    let (HostTree::Bvh2(nodes, leaf), _) = build_split(b, prims, Accel::Trbvh, Layout::Bvh2, 0.5) else { unreachable!() };
    assert!(validate_bvh2_split(prims, &nodes, &leaf).is_valid());
    // The ground's first triangle: the boxes of every leaf holding it shrunk to a corner.
    let holds = |first: u32, count: u32| (first..first + count).any(|s| leaf[s as usize].prim == 0);
    let mut bad = nodes.clone();
    for n in bad.iter_mut() {
        if n.left_count > 0 && holds(n.left, n.left_count) {
            n.left_max = n.left_min;
        }
        if n.right_count > 0 && holds(n.right, n.right_count) {
            n.right_max = n.right_min;
        }
    }
    let v = validate_bvh2_split(prims, &bad, &leaf);
    assert!(v.errors.iter().any(|e| e.contains("in none of its")), "{:?}", v.errors);
    let (HostTree::Wide(nodes, leaf), _) = build_split(b, prims, Accel::Trbvh, Layout::Cwbvh, 0.5) else { unreachable!() };
    assert!(validate_wide_split(prims, &nodes, &leaf).is_valid());
    let mut bad = leaf.clone();
    let other = *leaf.iter().find(|p| p.prim != 1).unwrap();
    for p in bad.iter_mut().filter(|p| p.prim == 1) {
        *p = other;
    }
    let v = validate_wide_split(prims, &nodes, &bad);
    assert!(v.errors.iter().any(|e| e.contains("stored 0 times")), "{:?}", v.errors);
}

fn terrain(n: usize) -> Vec<Triangle> {
    Scene::from_spec(&format!("terrain:{n}")).unwrap().triangles
}

#[test]
fn random_spheres_and_meshes() {
    let seed = treelet_tests::fresh_seed() as u32;
    every_layout_traces_like_the_scan("random spheres", &random_spheres(3000, seed as u64), &[], seed);
    every_layout_traces_like_the_scan("terrain", &[], &terrain(3000), seed);
    // A mesh in smallpt's room: walls of radius 1e5 and triangles in one tree.
    let room = Scene::from_spec("terrain:2000").unwrap();
    every_layout_traces_like_the_scan("terrain in the room", &room.spheres, &room.triangles, seed);
}

#[test]
fn stiff_scenes() {
    let seed = treelet_tests::fresh_seed() as u32;
    let base = terrain(1500);
    let map = |f: &dyn Fn([f32; 3]) -> [f32; 3]| -> Vec<Triangle> {
        base.iter().map(|t| Triangle::new(f(t.v0), f(t.v1), f(t.v2))).collect()
    };
    every_layout_traces_like_the_scan("terrain at 1e6", &[], &map(&|v| v.map(|x| x + 1e6)), seed);
    every_layout_traces_like_the_scan("terrain scaled 1e-4", &[], &map(&|v| v.map(|x| x * 1e-4)), seed);
    let doubled: Vec<Triangle> = base.iter().flat_map(|t| [*t, *t]).collect();
    every_layout_traces_like_the_scan("every triangle twice", &[], &doubled, seed);
    let degenerate: Vec<Triangle> =
        base.iter().enumerate().map(|(i, t)| if i % 7 == 0 { Triangle::new(t.v0, t.v0, t.v1) } else { *t }).collect();
    every_layout_traces_like_the_scan("with zero-area triangles", &[], &degenerate, seed);
    // One box for all: triangles spanning the same unit cube.
    let corner = |i: usize| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32];
    let spanning: Vec<Triangle> = (0..2000)
        .map(|i| {
            let t = [[0, 6, 3], [1, 7, 2], [4, 2, 7], [5, 3, 6]][i % 4];
            Triangle::new(corner(t[0]), corner(t[1]), corner(t[2]))
        })
        .collect();
    every_layout_traces_like_the_scan("2000 triangles with one box", &[], &spanning, seed);
    let spheres = random_spheres(1500, seed as u64);
    // As far out and as small as f32 sphere tests themselves stay exact
    // (their squares must not overflow or underflow).
    for (scale, what) in [(1e16f32, "spheres near ±1e18"), (1e-17, "spheres near 1e-15")] {
        let s: Vec<Sphere> = spheres.iter().map(|s| Sphere::new(s.center.map(|x| (x - 50.0) * scale), s.radius * scale)).collect();
        every_layout_traces_like_the_scan(what, &s, &[], seed);
    }
    let same: Vec<Sphere> = (0..1000).map(|i| Sphere::new([5.0, -3.0, 2.0], 0.1 + i as f32 * 1e-3)).collect();
    every_layout_traces_like_the_scan("identical centres", &same, &[], seed);
}

/// `n` x `n` axis-aligned boxes on a grid of `step` (each `0.8 step` wide,
/// of heights from `step` to `3 step`), their five faces as triangles, on a
/// ground quad: walls and roofs in planes that many boxes share, as in
/// architectural scenes, which axis-parallel rays lie in.
fn blocks(n: usize, step: f32) -> Vec<Triangle> {
    let mut out = Vec::new();
    let mut quad = |a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3]| {
        out.push(Triangle::new(a, b, c));
        out.push(Triangle::new(a, c, d));
    };
    let size = n as f32 * step;
    quad([0.0, 0.0, 0.0], [size, 0.0, 0.0], [size, 0.0, size], [0.0, 0.0, size]);
    for i in 0..n {
        for j in 0..n {
            let (x0, z0) = (i as f32 * step, j as f32 * step);
            let (x1, z1) = (x0 + 0.75 * step, z0 + 0.75 * step);
            let y = step * (1 + (i * 7 + j * 3) % 3) as f32;
            quad([x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]);
            quad([x0, 0.0, z0], [x1, 0.0, z0], [x1, y, z0], [x0, y, z0]);
            quad([x0, 0.0, z1], [x1, 0.0, z1], [x1, y, z1], [x0, y, z1]);
            quad([x0, 0.0, z0], [x0, 0.0, z1], [x0, y, z1], [x0, y, z0]);
            quad([x1, 0.0, z0], [x1, 0.0, z1], [x1, y, z1], [x1, y, z0]);
        }
    }
    out
}

#[test]
fn axis_aligned_blocks() {
    let seed = treelet_tests::fresh_seed() as u32;
    // Steps of a power of two keep every plane exact at every scale.
    for (step, what) in [(0.25f32, "blocks"), (0.25 * 2f32.powi(32), "blocks near 1e10"), (0.25 * 2f32.powi(-32), "blocks near 1e-9")] {
        every_layout_traces_like_the_scan(what, &[], &blocks(12, step), seed);
    }
}

/// A node load counter over a slice (the traversals read through
/// `RecordLoad`).
struct Counted<'a, T> {
    records: &'a [T],
    loads: &'a std::cell::Cell<u64>,
}

impl<T: Copy> treelet_core::geometry::records::RecordLoad<T> for Counted<'_, T> {
    fn load(&self, i: usize) -> T {
        self.loads.set(self.loads.get() + 1);
        self.records[i]
    }
}

/// A ray straight down (two direction components exactly zero, as an
/// engine's ground query) does about the work of one tilted by a
/// thousandth, in the binary layouts: it once entered every box within a
/// unit of it beside, a few hundred of these blocks.
#[test]
fn axis_parallel_rays_do_no_more_work_than_tilted_ones() {
    let triangles = blocks(40, 0.05);
    let prims = Primitives { spheres: &[], triangles: &triangles };
    let scene = Prims::new(&[], &triangles);
    let b = &mut CpuBackend::new();
    let seed = treelet_tests::fresh_seed() as u32;
    for layout in [Layout::Bvh2, Layout::Bvh4] {
        let tree = build(b, prims, Accel::Trbvh, layout);
        let (straight, tilted) = (std::cell::Cell::new(0u64), std::cell::Cell::new(0u64));
        for i in 0..400 {
            let r = BounceRng::new(seed, i, 0, 0);
            let o = Vec3::new(0.1 + 1.8 * r.uniform(0), 0.5, 0.1 + 1.8 * r.uniform(1));
            for (d, loads) in [(Vec3::NEG_Y, &straight), (Vec3::new(1e-3, -1.0, 1e-3).normalize(), &tilted)] {
                let hit = match &tree {
                    HostTree::Bvh2(nodes, leaf) => treelet_core::trace::bvh2::trace_bvh2::<ALL>(
                        o,
                        d,
                        Origin::NONE,
                        Query::CLOSEST,
                        &scene,
                        &Counted { records: nodes, loads },
                        &leaf[..],
                    ),
                    HostTree::Bvh4(nodes, leaf) => treelet_core::trace::bvh4::trace_bvh4::<ALL>(
                        o,
                        d,
                        Origin::NONE,
                        Query::CLOSEST,
                        &scene,
                        &Counted { records: nodes, loads },
                        &leaf[..],
                    ),
                    _ => unreachable!(),
                };
                let scan = closest_hit_linear(o, d, Origin::NONE, &scene);
                assert!(hit.t == scan.t && hit.prim == scan.prim, "{}: ray {i} along {d}", layout.name());
            }
        }
        let (s, t) = (straight.get() as f64 / 400.0, tilted.get() as f64 / 400.0);
        assert!(s <= 1.5 * t + 4.0, "{}: {s:.1} nodes a ray straight down against {t:.1} tilted", layout.name());
    }
}

#[test]
fn tiny_scenes() {
    let seed = treelet_tests::fresh_seed() as u32;
    for n in [1usize, 2, 3, 4, 5, 9, 17] {
        every_layout_traces_like_the_scan(&format!("{n} spheres"), &random_spheres(n, seed as u64 + n as u64), &[], seed);
        every_layout_traces_like_the_scan(&format!("{n} triangles"), &[], &terrain(50)[..n], seed);
    }
}

/// The validators must catch broken layouts, or the checks above prove nothing.
#[test]
fn validators_catch_corruption() {
    let tris = terrain(500);
    let prims = Primitives::triangles(&tris);
    let b = &mut CpuBackend::new();
    let HostTree::Wide(nodes, leaf) = build(b, prims, Accel::Trbvh, Layout::Cwbvh) else { unreachable!() };
    assert!(validate_wide(prims, &nodes, &leaf).is_valid());
    let wide = |mutate: &dyn Fn(&mut Vec<WideNode>, &mut Vec<LeafPrim>), needle: &str| {
        let (mut n, mut l) = (nodes.clone(), leaf.clone());
        mutate(&mut n, &mut l);
        let v = validate_wide(prims, &n, &l);
        assert!(v.errors.iter().any(|e| e.contains(needle)), "expected `{needle}` in {:?}", v.errors);
    };
    // A quantized box collapsed onto its node's corner, or pushed to its
    // top, on some child (the first internal one).
    let slot = (0..8).find(|&s| nodes[0].exp_imask >> (24 + s) & 1 == 1).unwrap();
    let byte = 0xFFu32 << (8 * (slot % 4));
    wide(&|n, _| n[0].hi_x[slot / 4] &= !byte, "does not contain");
    wide(&|n, _| n[0].lo_y[slot / 4] |= byte & 0xFEFE_FEFE, "does not contain");
    wide(&|_, l| l[3].p1[1] += 1e-3, "as the scene has it");
    wide(&|_, l| l[5].prim = l[6].prim, "stored 2 times");
    wide(&|n, _| n[0].child_base += 1, "reached");
    wide(&|n, _| n[0].exp_imask ^= 1 << (24 + slot), "");
    let HostTree::Bvh2(nodes, leaf) = build(b, prims, Accel::Trbvh, Layout::Bvh2) else { unreachable!() };
    assert!(validate_bvh2(prims, &nodes, &leaf).is_valid());
    let mut bad = nodes.clone();
    bad[0].left_max[2] -= 1.0;
    assert!(validate_bvh2(prims, &bad, &leaf).errors.iter().any(|e| e.contains("does not contain")));
    let mut bad = leaf.clone();
    bad[1].prim = bad[0].prim;
    assert!(validate_bvh2(prims, &nodes, &bad).errors.iter().any(|e| e.contains("stored")));
    let HostTree::Bvh4(nodes, leaf) = build(b, prims, Accel::Trbvh, Layout::Bvh4) else { unreachable!() };
    assert!(validate_bvh4(prims, &nodes, &leaf).is_valid());
    let four = |mutate: &dyn Fn(&mut Vec<Bvh4Node>), needle: &str| {
        let mut n = nodes.clone();
        mutate(&mut n);
        let v = validate_bvh4(prims, &n, &leaf);
        assert!(v.errors.iter().any(|e| e.contains(needle)), "expected `{needle}` in {:?}", v.errors);
    };
    four(&|n| n[0].hi_z[0] -= 1.0, "does not contain");
    four(&|n| n[0].lo_x[1] = f32::INFINITY, "empty on some axes only");
    // A slot dropped: its primitives are then stored nowhere.
    four(&|n| (n[0].lo_x[0], n[0].lo_y[0], n[0].lo_z[0], n[0].hi_x[0], n[0].hi_y[0], n[0].hi_z[0], n[0].count[0]) = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1), "stored 0 times");
    // Two slots naming one internal node.
    four(&|n| (n[0].child[1], n[0].count[1]) = (n[0].child[0], n[0].count[0]), "reached twice");
}

/// The GPU lays out the trees the CPU runner does: the same buffers where
/// the GPU fuses multiply-adds as the CPU's `fmaf` (the DP's sums then
/// round alike), and on CPU adapters (lavapipe, which does not fuse) valid
/// layouts that find the scan's hits.
#[test]
fn gpu_layouts_equal_cpu() {
    let Some(ctx) = treelet_tests::gpu() else { return };
    let seed = treelet_tests::fresh_seed() as u32;
    let fused = !GpuBackend::new(ctx.clone()).runs_on_cpu();
    let spheres = random_spheres(20_000, seed as u64);
    let tris = terrain(20_000);
    for (what, prims) in [("random spheres", Primitives::spheres(&spheres)), ("terrain", Primitives::triangles(&tris))] {
        let scene = prims.as_core();
        let bounds = prims.boxes().iter().fold(treelet_core::Aabb::EMPTY, |a, b| a.union(b));
        let probes = rays(&scene, bounds.lo(), bounds.hi(), seed, 300);
        for layout in [Layout::Bvh2, Layout::Bvh4, Layout::Cwbvh] {
            let g = build(&mut GpuBackend::new(ctx.clone()), prims, Accel::Trbvh, layout);
            let c = build(&mut CpuBackend::new(), prims, Accel::Trbvh, layout);
            g.validate(prims);
            match (&g, &c) {
                (HostTree::Wide(gn, gl), HostTree::Wide(cn, cl)) if fused => {
                    assert!(gn == cn && gl == cl, "{what}: GPU and CPU wide trees differ");
                }
                (HostTree::Bvh2(gn, gl), HostTree::Bvh2(cn, cl)) if fused => {
                    assert!(gn == cn && gl == cl, "{what}: GPU and CPU two-box trees differ");
                }
                (HostTree::Bvh4(gn, gl), HostTree::Bvh4(cn, cl)) if fused => {
                    assert!(gn == cn && gl == cl, "{what}: GPU and CPU 4-wide trees differ");
                }
                _ => {}
            }
            for (k, &(o, d, from, scan)) in probes.iter().enumerate() {
                let hit = g.trace(o, d, from, &scene);
                assert!(hit.t == scan.t && hit.prim == scan.prim, "{what}, GPU-built {}: ray {k} differs", layout.name());
            }
        }
    }
}

/// A `bvh2` tree refit in place after its primitives moved
/// (`treelet::bvh::refit::refit_bvh2`: its leaf primitives written again
/// and its boxes bottom-up over the collapsed tree, no new collapse): valid
/// for the moved primitives, every child box exactly its subtree's, each
/// ray hitting what the scan of the moved primitives hits; the GPU writes
/// what the CPU runner writes.
#[test]
fn bvh2_refit_in_place_fits_the_moved_primitives() {
    let seed = treelet_tests::fresh_seed();
    let spheres = random_spheres(3000, seed);
    let tris = terrain(4000);
    // Every sphere moved and resized, every vertex lifted by a different wave.
    let moved_spheres: Vec<Sphere> = spheres
        .iter()
        .enumerate()
        .map(|(k, s)| Sphere { center: [s.center[0] + (k as f32 * 0.37).sin() * 30.0, s.center[1] - 12.0, s.center[2]], radius: s.radius * 1.5, ..*s })
        .collect();
    let lift = |v: [f32; 3]| [v[0], v[1] + 3.0 * (v[0] * 0.05).sin() * (v[2] * 0.07).cos() + 0.5, v[2]];
    let moved_tris: Vec<Triangle> = tris.iter().map(|t| Triangle::new(lift(t.v0), lift(t.v1), lift(t.v2))).collect();
    let cases = [
        ("spheres", Primitives::spheres(&spheres), Primitives::spheres(&moved_spheres)),
        ("terrain", Primitives::triangles(&tris), Primitives::triangles(&moved_tris)),
        ("both", Primitives { spheres: &spheres, triangles: &tris }, Primitives { spheres: &moved_spheres, triangles: &moved_tris }),
    ];
    let gpu = treelet_tests::gpu();
    for (what, prims, moved) in cases {
        let scene = moved.as_core();
        let boxes = moved.boxes();
        let bounds = boxes.iter().fold(treelet_core::Aabb::EMPTY, |a, b| a.union(b));
        let probes = rays(&scene, bounds.lo(), bounds.hi(), seed as u32, 300);
        for accel in [Accel::Lbvh, Accel::Trbvh] {
            let what = format!("{what}, {accel:?}, seed {seed}");
            let c = refit_in_place(&mut CpuBackend::new(), prims, moved, accel);
            c.validate(moved);
            let HostTree::Bvh2(nodes, leaf) = &c else { unreachable!() };
            tight_boxes(nodes, leaf, &boxes, 0, &what);
            for (k, &(o, d, from, scan)) in probes.iter().enumerate() {
                let hit = c.trace(o, d, from, &scene);
                assert!(hit.t == scan.t && hit.prim == scan.prim, "{what}: refit tree, ray {k}: {} at {}, the scan {} at {}", hit.prim, hit.t, scan.prim, scan.t);
            }
            if let Some(ctx) = &gpu {
                let mut b = GpuBackend::new(ctx.clone());
                let fused = !b.runs_on_cpu();
                let g = refit_in_place(&mut b, prims, moved, accel);
                g.validate(moved);
                if let (HostTree::Bvh2(gn, gl), true) = (&g, fused) {
                    assert!(gn == nodes && gl == leaf, "{what}: GPU and CPU refit trees differ");
                }
            }
        }
    }
}

/// Builds over `prims` in `bvh2`, then refits in place for `moved`, back
/// for `prims` and for `moved` again, the climb's state kept from one
/// refit to the next as an engine's tracer keeps it (a climb that left its
/// counters otherwise than it found them would misplace the last refit's
/// boxes).
fn refit_in_place<B: Backend>(b: &mut B, prims: Primitives, moved: Primitives, accel: Accel) -> HostTree {
    let (tree, _) = traced(b, prims, accel, Layout::Bvh2);
    assert!(tree.collapsed.is_some(), "a bvh2 layout keeps its collapsed tree");
    let mut counters = None;
    for frame in [moved, prims, moved] {
        let buffers = treelet::bvh::layout::PrimBuffers::upload(b, frame).unwrap();
        treelet::bvh::refit::refit_bvh2(b, &tree, &buffers, &mut counters).unwrap();
    }
    read(b, &tree, moved.len())
}

/// Every child box of node `i` equals the union of its primitives' boxes
/// (`boxes`, by primitive index), bit for bit; returns node `i`'s box.
fn tight_boxes(nodes: &[Bvh2Node], leaf: &[LeafPrim], boxes: &[treelet_core::Aabb], i: usize, what: &str) -> treelet_core::Aabb {
    let node = nodes[i];
    let mut all = treelet_core::Aabb::EMPTY;
    for (index, count, lo, hi) in [(node.left, node.left_count, node.left_min, node.left_max), (node.right, node.right_count, node.right_min, node.right_max)] {
        if lo[0] > hi[0] {
            continue; // the empty second child of a one-leaf root
        }
        let exact = if count > 0 {
            leaf[index as usize..(index + count) as usize].iter().fold(treelet_core::Aabb::EMPTY, |a, p| a.union(&boxes[p.prim as usize]))
        } else {
            tight_boxes(nodes, leaf, boxes, index as usize, what)
        };
        assert!(exact.min == lo && exact.max == hi, "{what}: node {i}: child box {lo:?}..{hi:?}, its primitives' {:?}..{:?}", exact.min, exact.max);
        all = all.union(&exact);
    }
    all
}

/// The kernels a render's pipelines are built ahead for
/// (`treelet::render::prepared::prepare_pipelines`) are every kernel the
/// render dispatches, for each tree and layout: on the CPU runner, which
/// asks the same questions of the device as a GPU (ordered atomics,
/// look-back) and records what it ran and what it was asked to prepare. A
/// kernel left out would be compiled in the middle of the timed render on
/// a fresh machine.
#[test]
fn pipelines_built_ahead_cover_what_a_render_dispatches() {
    use treelet::render::{render, Integrator, RenderSettings};
    use treelet::render::variant::KernelChoice;
    use treelet::runtime::cpu_runner::CpuBackend;
    use treelet::bvh::tree::Accel;
    use treelet::bvh::layout::Layout;
    for scene in [treelet::scene::cornell(), treelet::scene::random_scene("random:3000", 3000, 7), treelet::scene::mesh_scene("terrain", &treelet::scene::terrain(5000))] {
        for accel in [Accel::None, Accel::Lbvh, Accel::Trbvh, Accel::Hploc] {
            for layout in Layout::ALL {
                let settings = RenderSettings {
                    width: 16,
                    height: 12,
                    spp: 8,
                    seed: 1,
                    accel,
                    layout,
                    kernel: KernelChoice::Auto,
                    integrator: Integrator::Nee,
                    sampler: treelet::render::Sampler::Sobol,
                    error_each_pass: false,
                    first_sample: 0,
                };
                let mut b = CpuBackend::new();
                render(&mut b, &scene, &settings, None, |_| {}).unwrap();
                assert!(!b.kernels_dispatched().is_empty());
                let missing = b.kernels_not_prepared();
                assert!(missing.is_empty(), "{} with {accel:?} in {layout:?}: not built ahead: {missing:?}", scene.name);
            }
        }
    }
}

/// The same for `treelet build` (`treelet::bvh::report::run_build_with`):
/// each device builder, as configured by default and with reinsertion
/// (what GPUs run by default, the CPU runner only when asked), over
/// spheres and over triangles (which are split).
#[test]
fn pipelines_built_ahead_cover_what_a_build_dispatches() {
    use treelet::bvh::report::run_build_with;
    use treelet::bvh::trbvh::TreeletConfig;
    use treelet::bvh::tree::Builder;
    use treelet::runtime::cpu_runner::CpuBackend;
    for scene in [treelet::scene::random_scene("random:3000", 3000, 7), treelet::scene::mesh_scene("terrain", &treelet::scene::terrain(5000))] {
        for builder in [Builder::Lbvh, Builder::Trbvh, Builder::Hploc] {
            for reinsert in [None, Some(2)] {
                let config = TreeletConfig { reinsert, ..TreeletConfig::default() };
                let mut b = CpuBackend::new();
                run_build_with(&mut b, &scene, builder, config).unwrap();
                assert!(!b.kernels_dispatched().is_empty());
                let missing = b.kernels_not_prepared();
                assert!(missing.is_empty(), "{} by {builder:?}, reinsertion {reinsert:?}: not built ahead: {missing:?}", scene.name);
            }
        }
    }
}

/// The depth the device finds (`treelet::bvh::layout::tree_depth`, what the
/// layouts check against the traversal stack) is a walk's of the tree read
/// back: LBVH and TRBVH trees of random spheres and of spheres bunched
/// ever closer along a line (deep radix trees), CPU runner and GPU.
#[test]
fn tree_depth_on_the_device_is_the_trees_depth() {
    use treelet::bvh::layout::tree_depth;
    use treelet::bvh::tree::{binary_tree, Builder};
    let seed = treelet_tests::fresh_seed();
    let random = random_spheres(3000, seed);
    let bunched: Vec<Sphere> =
        (0..200).map(|k| Sphere::new([1.0 - 0.9f32.powi(k), (k % 3) as f32 * 1e-3, 0.0], 1e-4)).chain(random.iter().take(100).copied()).collect();
    fn walk(nodes: &[Node]) -> u32 {
        let (mut deepest, mut stack) = (0, vec![(0usize, 0u32)]);
        while let Some((i, d)) = stack.pop() {
            deepest = deepest.max(d);
            if !nodes[i].is_leaf() {
                stack.extend([(nodes[i].left as usize, d + 1), (nodes[i].right as usize, d + 1)]);
            }
        }
        deepest
    }
    fn check<B: Backend>(b: &mut B, spheres: &[Sphere], what: &str) {
        for builder in [Builder::Lbvh, Builder::Trbvh, Builder::Hploc] {
            let built = binary_tree(b, Primitives { spheres, triangles: &[] }, builder).unwrap();
            let nodes: Vec<Node> = b.read(&built.bvh.nodes, built.bvh.node_count as usize).unwrap();
            let expected = walk(&nodes).min(treelet_core::layouts::depth::DEPTH_LIMIT);
            assert_eq!(tree_depth(b, &built.bvh).unwrap(), expected, "{what}, {builder:?} on {}", b.adapter());
        }
    }
    for (spheres, what) in [(&random, format!("random, seed {seed}")), (&bunched, "bunched".to_string())] {
        check(&mut CpuBackend::new(), spheres, &what);
        if let Some(ctx) = treelet_tests::gpu() {
            check(&mut GpuBackend::new(ctx), spheres, &what);
        }
    }
}

/// Buffers bound in two parts (`treelet_core::geometry::split`: how scenes
/// past one binding's 2 GiB build and trace) give exactly the trees and
/// hits of the same buffers bound whole, on the same device: every buffer
/// the split kernels bind (triangles, nodes, through the treelet rounds
/// too, collapsed nodes, `bvh2` and leaf primitives, and the refit's writes
/// into them) is split after a few hundred records here, so each kernel
/// reads and writes both parts; the hits are also the scan's.
#[test]
fn gpu_buffers_in_two_parts_build_and_trace_as_whole() {
    use treelet::{Quality, Ray, Tracer};
    let Some(ctx) = treelet_tests::gpu() else { return };
    let seed = treelet_tests::fresh_seed() as u32;
    let spheres = random_spheres(700, seed as u64);
    let tris = terrain(5_000);
    let split = 768 * 13; // 208 triangles, 312 nodes, 156 bvh2 nodes
    for (what, prims) in [("terrain", Primitives::triangles(&tris)), ("spheres and terrain", Primitives { spheres: &spheres, triangles: &tris })] {
        for accel in [Accel::Lbvh, Accel::Hploc, Accel::Trbvh] {
            for layout in [Layout::Bvh2, Layout::Cwbvh] {
                let whole = build(&mut GpuBackend::new(ctx.clone()), prims, accel, layout);
                let parts = build(&mut GpuBackend::new(ctx.clone()).with_split_bytes(split), prims, accel, layout);
                parts.validate(prims);
                match (&whole, &parts) {
                    (HostTree::Bvh2(a, b), HostTree::Bvh2(c, d)) => assert!(a == c && b == d, "{what}, {accel:?}: bvh2 trees differ"),
                    (HostTree::Wide(a, b), HostTree::Wide(c, d)) => assert!(a == c && b == d, "{what}, {accel:?}: wide trees differ"),
                    _ => unreachable!(),
                }
            }
        }
        // Casts through split `bvh2` buffers (and triangles) on the device.
        let scene = prims.as_core();
        let bounds = prims.boxes().iter().fold(treelet_core::Aabb::EMPTY, |a, b| a.union(b));
        let probes = rays(&scene, bounds.lo(), bounds.hi(), seed, 400);
        let rays: Vec<Ray> = probes.iter().map(|(o, d, _, _)| Ray::new(o.to_array(), d.to_array())).collect();
        // And refit in place (boxes written into both parts of the nodes):
        // every primitive moved by a wave.
        let wave = |v: [f32; 3]| [v[0], v[1] + 2.0 * (v[0] * 0.05).sin() * (v[2] * 0.07).cos() + 0.5, v[2]];
        let moved_tris: Vec<Triangle> = prims.triangles.iter().map(|t| Triangle::new(wave(t.v0), wave(t.v1), wave(t.v2))).collect();
        let moved_spheres: Vec<Sphere> = prims.spheres.iter().map(|s| Sphere { center: wave(s.center), ..*s }).collect();
        let mut hits = Vec::new();
        let mut refit_hits = Vec::new();
        for mut b in [GpuBackend::new(ctx.clone()), GpuBackend::new(ctx.clone()).with_split_bytes(split)] {
            let mut t = Tracer::build(&mut b, prims.spheres, prims.triangles, Quality::Fast).unwrap();
            hits.push((t.closest_hits(&mut b, &rays).unwrap(), t.occluded(&mut b, &rays).unwrap()));
            t.refit(&mut b, &moved_spheres, &moved_tris).unwrap();
            refit_hits.push(t.closest_hits(&mut b, &rays).unwrap());
        }
        let found = refit_hits[1].iter().filter(|h| h.is_hit()).count();
        assert!(found > rays.len() / 4, "{what}: {found} of {} probes hit the moved primitives", rays.len());
        assert_eq!(refit_hits[0], refit_hits[1], "{what}: closest hits through split buffers differ after a refit");
        // The probes aim at primitives: most hit, and the scan agrees (to
        // rounding: the tracer takes unnormalized directions and `t_min`).
        let found = hits[1].0.iter().filter(|h| h.is_hit()).count();
        assert!(found > rays.len() / 2, "{what}: {found} of {} probes hit", rays.len());
        let agree = |h: &treelet::RayHit, scan: &treelet_core::trace::hit::Hit| {
            h.is_hit() == scan.is_hit() && (!h.is_hit() || (h.t - scan.t).abs() <= 1e-4 * scan.t.abs().max(1.0))
        };
        let disagree = hits[1].0.iter().zip(&probes).filter(|(h, p)| !agree(h, &p.3)).count();
        assert!(disagree * 100 <= rays.len(), "{what}: {disagree} of {} probes disagree with the scan", rays.len());
        assert_eq!(hits[0].0, hits[1].0, "{what}: closest hits through split buffers differ");
        assert_eq!(hits[0].1, hits[1].1, "{what}: occlusion through split buffers differs");
    }
}
