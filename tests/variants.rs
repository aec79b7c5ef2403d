//! Per-scene kernel variants: each specialized kernel renders the same image
//! as the general one (same seed) on a scene that selects it, on the CPU
//! runner and on the GPU; the choice never drops a feature the scene has.
use std::collections::BTreeSet;

use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::layout::Layout;
use treelet::bvh::choice::{cheaper_builder, Work};
use treelet::bvh::tree::{Accel, Builder};
use treelet::render::{render, RenderResult, RenderSettings};
use treelet::scene::{cornell, mesh_scene, random_scene, Scene};
use treelet::render::variant::{plan, KernelChoice, SceneFeatures, LINEAR_MAX_CPU, TRIANGLE_SCAN_WEIGHT};
use treelet_core::geometry::features;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::render::variants::VARIANTS;
use treelet_tests::gpu;

/// A tetrahedron-studded patch of triangles.
fn triangles(n: usize, seed: u64) -> Vec<Triangle> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let c = [rng.random_range(-1.0..1.0f32), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
            let v = |rng: &mut rand_pcg::Pcg64| c.map(|x| x + rng.random_range(-0.3..0.3f32));
            Triangle::new(v(&mut rng), v(&mut rng), v(&mut rng))
        })
        .collect()
}

/// `random:60` with a glass sphere and a mirror whatever the seed: each
/// sphere is glass or a mirror with 15% odds, so one seed in about 17 000
/// draws no glass and picks the mirrors' variant (seed 5767741004366092768).
fn mixed_spheres(seed: u64) -> Scene {
    use treelet_core::geometry::buffers::{GLASS, MIRROR, Material};
    let mut scene = random_scene("random:60", 60, seed);
    scene.materials[0] = Material { color: [0.9; 3], kind: GLASS, ior: 1.5, ..Default::default() };
    scene.materials[1] = Material { color: [0.9; 3], kind: MIRROR, ..Default::default() };
    scene
}

/// Scenes that select each specialized variant: (scene, variant name).
fn scenes(seed: u64) -> Vec<(Scene, &'static str)> {
    let mut diffuse = Scene::from_spec("scenes/cornell_diffuse.json")
        .or_else(|_| Scene::from_spec("../scenes/cornell_diffuse.json"))
        .unwrap();
    diffuse.name = "cornell diffuse".into();
    let mirrors = Scene::from_spec("scenes/cornell_mirrors.json")
        .or_else(|_| Scene::from_spec("../scenes/cornell_mirrors.json"))
        .unwrap();
    // Spheres, a disk lamp and parallelogram walls: flat shapes, no triangles.
    let shapes = Scene::from_spec("scenes/room_disk.json").or_else(|_| Scene::from_spec("../scenes/room_disk.json")).unwrap();
    let mixed = mesh_scene("triangles in the room", &triangles(150, seed));
    // Triangles alone, half of them lights.
    let mut only = mixed.mesh_only().unwrap();
    for (i, m) in only.materials.iter_mut().enumerate() {
        if i % 2 == 0 {
            m.emission = [2.0, 2.0, 2.0];
        }
    }
    vec![
        (cornell(), "spheres"),
        (diffuse, "spheres_diffuse"),
        (mirrors, "spheres_mirror"),
        (mixed_spheres(seed), "spheres"),
        (shapes, "spheres_shapes"),
        (mixed, "mixed_diffuse"),
        (only, "triangles_diffuse"),
    ]
}

fn run<B: Backend>(b: &mut B, scene: &Scene, kernel: KernelChoice, accel: Accel, seed: u32) -> RenderResult {
    let s = RenderSettings {
        width: 40,
        height: 30,
        spp: 8,
        seed,
        accel,
        layout: Layout::Auto,
        kernel,
        integrator: treelet::render::Integrator::Smallpt,
        sampler: treelet::render::Sampler::Sobol,
        error_each_pass: true,
        first_sample: 0,
    };
    render(b, scene, &s, None, |_| {}).unwrap()
}

/// Fraction of pixels whose channels differ by more than `tol` (relative to 1 + value).
fn mismatch_fraction(a: &[[f32; 3]], b: &[[f32; 3]], tol: f32) -> f64 {
    let bad = a.iter().zip(b).filter(|(x, y)| (0..3).any(|k| (x[k] - y[k]).abs() > tol * (1.0 + y[k].abs()))).count();
    bad as f64 / a.len() as f64
}

#[test]
fn every_variant_renders_what_the_full_kernel_renders() {
    let seed = treelet_tests::fresh_seed();
    let ctx = gpu();
    let mut exercised = BTreeSet::new();
    for (scene, expected) in scenes(seed) {
        for accel in [Accel::None, Accel::Lbvh] {
            let auto = run(&mut CpuBackend::new(), &scene, KernelChoice::Auto, accel, seed as u32);
            assert_eq!(auto.plan.kernel, expected, "{}: chose {}", scene.name, auto.plan.kernel);
            exercised.insert(auto.plan.kernel);
            let full = run(&mut CpuBackend::new(), &scene, KernelChoice::Full, accel, seed as u32);
            assert_eq!(full.plan.kernel, "full");
            // The same operations in the same order: the same image, bit for bit.
            assert!(auto.image.pixels == full.image.pixels, "{} ({accel:?}): CPU variant differs from full", scene.name);
            let lit = auto.image.pixels.iter().filter(|p| p.iter().any(|&c| c > 0.0)).count();
            assert!(lit > auto.image.pixels.len() / 4, "{}: only {lit} lit pixels, a weak test", scene.name);
            let Some(ctx) = &ctx else { continue };
            let g = run(&mut GpuBackend::new(ctx.clone()), &scene, KernelChoice::Auto, accel, seed as u32);
            let gf = run(&mut GpuBackend::new(ctx.clone()), &scene, KernelChoice::Full, accel, seed as u32);
            // Separately compiled code may round a few paths differently (see
            // tests/render.rs); nearly all pixels agree to 1e-4.
            let off = mismatch_fraction(&g.image.pixels, &gf.image.pixels, 1e-4);
            assert!(off < 0.02, "{} ({accel:?}): {:.1}% of GPU pixels differ from the full kernel", scene.name, off * 100.0);
            eprintln!("{} ({accel:?}, {}): {:.2}% of GPU pixels differ from the full kernel", scene.name, g.plan.kernel, off * 100.0);
        }
    }
    // (The caustics variants are the light paths' tests': tests/render.rs;
    // the general kernels with independent numbers, the samplers' there.)
    let specialized: BTreeSet<&str> = VARIANTS
        .iter()
        .filter(|v| v.0 & (features::CAUSTICS | features::INDEPENDENT_NUMBERS) == 0)
        .map(|v| v.1)
        .filter(|&n| n != "full")
        .collect();
    assert_eq!(exercised, specialized, "every specialized variant is exercised");
}

#[test]
fn choices_keep_every_feature_and_follow_the_crossover() {
    let seed = treelet_tests::fresh_seed();
    for (scene, _) in scenes(seed) {
        let bits = SceneFeatures::of(&scene).bits();
        for kernel in [KernelChoice::Auto, KernelChoice::Full] {
            let p = plan(&scene, 1 << 20, Accel::Auto, Layout::Auto, kernel, treelet::runtime::backend::DeviceClass::CpuRunner, false, false);
            let compiled = VARIANTS[p.variant].0;
            assert_eq!(compiled & bits, bits, "{}: {} lacks a feature", scene.name, p.kernel);
            assert_eq!(compiled & features::CAUSTICS, 0, "{}: {} has light paths unasked", scene.name, p.kernel);
            // Light paths asked for: where there are mirrors or glass, and lights.
            let c = plan(&scene, 1 << 20, Accel::Auto, Layout::Auto, kernel, treelet::runtime::backend::DeviceClass::CpuRunner, true, false);
            let f = SceneFeatures::of(&scene);
            let wants = f.mirror + f.glass > 0 && f.emissive > 0;
            assert_eq!(VARIANTS[c.variant].0 & features::CAUSTICS != 0, wants, "{}: {} with --integrator caustics", scene.name, c.kernel);
            assert_eq!(VARIANTS[c.variant].0 & bits, bits, "{}: {} lacks a feature", scene.name, c.kernel);
            // Independent numbers: only a kernel that has them, and none
            // that has them unasked.
            assert_eq!(compiled & features::INDEPENDENT_NUMBERS, 0, "{}: {} carries independent numbers unasked", scene.name, p.kernel);
            for light_paths in [false, true] {
                let i = plan(&scene, 1 << 20, Accel::Auto, Layout::Auto, kernel, treelet::runtime::backend::DeviceClass::CpuRunner, light_paths, true);
                let v = VARIANTS[i.variant].0;
                assert!(v & features::INDEPENDENT_NUMBERS != 0 && v & bits == bits, "{}: {} for --sampler independent", scene.name, i.kernel);
                assert_eq!(v & features::CAUSTICS != 0, light_paths && wants, "{}: {} for --sampler independent", scene.name, i.kernel);
            }
            if scene.materials.iter().any(|m| m.kind == treelet_core::geometry::buffers::GLASS) {
                assert!(compiled & features::GLASS != 0, "{}: glass without refraction", scene.name);
            }
            let cost = scene.spheres.len() + TRIANGLE_SCAN_WEIGHT * scene.triangles.len();
            assert_eq!(p.accel == Accel::None, cost <= LINEAR_MAX_CPU, "{}: scan cost {cost}, {:?}", scene.name, p.accel);
            // Above it, the builder that finishes first by the measured trade-off.
            if cost > LINEAR_MAX_CPU {
                let n = scene.spheres.len() + scene.triangles.len();
                let cpu = treelet::runtime::backend::DeviceClass::CpuRunner;
                let expected = match cheaper_builder(cpu, n, Work::Paths(1 << 20)).0 {
                    Builder::Trbvh => Accel::Trbvh,
                    Builder::Hploc => Accel::Hploc,
                    _ => Accel::Lbvh,
                };
                assert_eq!(p.accel, expected, "{}: {}", scene.name, p.accel_reason);
            }
        }
        // On a GPU, a render long enough pays for the treelets, a short one does not.
        if scene.spheres.len() + TRIANGLE_SCAN_WEIGHT * scene.triangles.len() > LINEAR_MAX_CPU {
            let gpu = treelet::runtime::backend::DeviceClass::Gpu;
            assert_eq!(plan(&scene, 1, Accel::Auto, Layout::Auto, KernelChoice::Auto, gpu, false, false).accel, Accel::Lbvh);
            let long = plan(&scene, 1 << 40, Accel::Auto, Layout::Auto, KernelChoice::Auto, gpu, false, false);
            assert_eq!(long.accel, Accel::Trbvh, "{}", scene.name);
            assert!(long.accel_reason.contains("pays for"), "{}", long.accel_reason);
        }
        // Forced choices stay as asked.
        use treelet::runtime::backend::DeviceClass::Gpu;
        assert_eq!(plan(&scene, 1 << 40, Accel::Sweep, Layout::Auto, KernelChoice::Auto, Gpu, false, false).accel, Accel::Sweep);
        assert_eq!(plan(&scene, 1, Accel::Sweep, Layout::Cwbvh, KernelChoice::Auto, Gpu, false, false).layout, Layout::Cwbvh);
    }
}
