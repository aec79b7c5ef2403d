//! The path tracer: GPU against the CPU run of the same kernel, BVH against
//! linear scan, and the picture's sanity (no NaN, no black speckles).
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::layout::Layout;
use treelet::bvh::tree::Accel;
use treelet::render::{render, Integrator, RenderSettings, Sampler};
use treelet::render::variant::KernelChoice;
use treelet::scene::{cornell, mesh_scene, random_scene, Scene};
use treelet_core::geometry::triangle::Triangle;
use treelet_tests::gpu;

/// A small closed mesh (an octahedron with each face split into four),
/// standing in smallpt's room.
fn mesh() -> Scene {
    let v = [[1.0f32, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let faces = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    let mid = |a: [f32; 3], b: [f32; 3]| [0, 1, 2].map(|k| (a[k] + b[k]) * 0.5);
    let mut tris = Vec::new();
    for f in faces {
        let (a, b, c) = (v[f[0]], v[f[1]], v[f[2]]);
        let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
        for t in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
            tris.push(Triangle::new(t[0], t[1], t[2]));
        }
    }
    mesh_scene("octahedron", &tris)
}

/// `scene` with 24 disks and parallelograms of random places, sizes and
/// orientations (every fourth a lamp) added to its flat primitives.
fn with_flat_shapes(mut scene: Scene, seed: u64) -> Scene {
    let mut state = seed | 1;
    let mut r = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for i in 0..24 {
        let center = [10.0 + 80.0 * r(), 5.0 + 70.0 * r(), 20.0 + 120.0 * r()];
        let normal = [r() - 0.5, r() - 0.5, r() - 0.5];
        let edge = [r() - 0.5, r() - 0.5, r() - 0.5].map(|x| 12.0 * x);
        scene.triangles.push(if i % 2 == 0 { Triangle::disk(center, normal, 2.0 + 6.0 * r()) } else { Triangle::parallelogram(center, normal.map(|x| 10.0 * x), edge) });
        let color = [r(), r(), r()].map(|c| 0.2 + 0.7 * c);
        let emission = if i % 4 == 0 { [8.0; 3] } else { [0.0; 3] };
        scene.materials.push(Material { emission, ..diffuse(color) });
    }
    scene.name = format!("{} with disks and parallelograms", scene.name);
    scene
}

fn settings(width: u32, height: u32, spp: u32, seed: u32, accel: Accel) -> RenderSettings {
    RenderSettings {
        width,
        height,
        spp,
        seed,
        accel,
        layout: Layout::Auto,
        kernel: KernelChoice::Auto,
        integrator: Integrator::Smallpt,
        sampler: Sampler::Sobol,
        error_each_pass: true,
        first_sample: 0,
    }
}

fn pixels<B: Backend>(b: &mut B, scene: &Scene, s: &RenderSettings) -> Vec<[f32; 3]> {
    render(b, scene, s, None, |_| {}).unwrap().image.pixels
}

/// Mean absolute difference of two images, over pixels and channels.
fn mean_abs(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (0..3).map(|k| (x[k] - y[k]).abs() as f64).sum::<f64>()).sum::<f64>()
        / (3 * a.len()) as f64
}

/// Fraction of pixels whose channels differ by more than `tol` (relative to 1 + value).
fn mismatch_fraction(a: &[[f32; 3]], b: &[[f32; 3]], tol: f32) -> f64 {
    let bad = a.iter().zip(b).filter(|(x, y)| (0..3).any(|k| (x[k] - y[k]).abs() > tol * (1.0 + y[k].abs()))).count();
    bad as f64 / a.len() as f64
}

#[test]
fn gpu_render_matches_cpu() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed() as u32;
    for (scene, accel, sampler) in [
        (cornell(), Accel::None, Sampler::Independent),
        (cornell(), Accel::None, Sampler::Sobol),
        (random_scene("random:300", 300, seed as u64), Accel::Lbvh, Sampler::Sobol),
        (mesh(), Accel::Trbvh, Sampler::Sobol),
        (with_flat_shapes(mesh(), seed as u64), Accel::Hploc, Sampler::Sobol),
    ] {
        let s = RenderSettings { sampler, ..settings(48, 36, 16, seed, accel) };
        let g = pixels(&mut GpuBackend::new(ctx.clone()), &scene, &s);
        let c = pixels(&mut CpuBackend::new(), &scene, &s);
        // The noise of the estimate itself: the CPU with another seed.
        let other = pixels(&mut CpuBackend::new(), &scene, &RenderSettings { seed: seed.wrapping_add(1), ..s });
        // Same random numbers, same code: most paths agree to the last bits.
        // A few diverge where the GPU rounds differently (fused multiply-adds,
        // its square root) and a path then takes another branch.
        let same = 1.0 - mismatch_fraction(&g, &c, 1e-4);
        let (gpu_cpu, noise) = (mean_abs(&g, &c), mean_abs(&c, &other));
        eprintln!(
            "{} {accel:?} {sampler:?}: {:.1}% of pixels agree within 1e-4; mean |gpu - cpu| {gpu_cpu:.2e}, noise {noise:.2e}",
            scene.name,
            100.0 * same
        );
        // Scenes full of glass diverge more (every refraction is a branch).
        assert!(same > 0.5, "{}: only {:.1}% of pixels agree", scene.name, 100.0 * same);
        assert!(gpu_cpu < 0.25 * noise, "{}: GPU and CPU differ by {gpu_cpu}, noise is {noise}", scene.name);
    }
}

#[test]
fn every_tree_and_layout_renders_what_the_scan_renders() {
    let seed = treelet_tests::fresh_seed();
    // Spheres alone, then triangles and spheres in one tree, then disks and
    // parallelograms too.
    for scene in [random_scene("random:400", 400, seed), mesh(), with_flat_shapes(mesh(), seed)] {
        let s = |accel| settings(40, 30, 8, seed as u32, accel);
        let none = pixels(&mut CpuBackend::new(), &scene, &s(Accel::None));
        assert!(none.iter().flatten().all(|v| v.is_finite() && *v >= 0.0), "{}: NaN or negative pixels", scene.name);
        for accel in [Accel::Lbvh, Accel::Trbvh, Accel::Hploc, Accel::Sweep] {
            for layout in Layout::ALL {
                let tree = pixels(&mut CpuBackend::new(), &scene, &RenderSettings { layout, ..s(accel) });
                assert_eq!(
                    mismatch_fraction(&none, &tree, 1e-6),
                    0.0,
                    "{}: {accel:?} traversal in the {} layout missed or invented hits",
                    scene.name,
                    layout.name()
                );
            }
        }
    }
}

#[test]
fn cornell_has_no_nan_and_no_black_speckles() {
    // smallpt's box is closed and lit: after 256 samples a pixel can only be
    // black if it sees the black front wall through the mirror or the glass.
    // A black pixel on a diffuse surface means acne (rays hitting their own
    // surface) or a leak.
    let (w, h) = (32, 24);
    let scene = cornell();
    let s = settings(w, h, 256, 5, Accel::None);
    let p = match gpu() {
        Some(ctx) => pixels(&mut GpuBackend::new(ctx), &scene, &s),
        None => pixels(&mut CpuBackend::new(), &scene, &s),
    };
    assert!(p.iter().flatten().all(|v| v.is_finite() && *v >= 0.0), "NaN, infinite or negative pixels");
    let camera = scene.camera.camera(w, h);
    let v = |a: [f32; 3]| glam::Vec3::from_array(a);
    for (i, c) in p.iter().enumerate() {
        if c.iter().any(|&x| x > 0.0) {
            continue;
        }
        let (x, y) = ((i as u32 % w) as f32, (h - 1 - i as u32 / w) as f32);
        let d =
            v(camera.cx) * ((x + 0.5) / w as f32 - 0.5) + v(camera.cy) * ((y + 0.5) / h as f32 - 0.5) + v(camera.dir);
        let o = v(camera.origin) + d * camera.near;
        let hit = treelet_core::trace::classic::closest_hit_linear(
            o,
            d.normalize(),
            treelet_core::geometry::prims::Origin::NONE,
            &treelet_core::geometry::prims::Prims::spheres(&scene.spheres),
        );
        let kind = scene.materials[hit.prim as usize].kind;
        assert_ne!(kind, treelet_core::geometry::buffers::DIFFUSE, "black pixel {i} on diffuse sphere {}", hit.prim);
    }
    let mean = p.iter().flatten().sum::<f32>() / (3 * p.len()) as f32;
    assert!((0.3..1.2).contains(&mean), "mean {mean}");
}

#[test]
fn render_rejects_bad_settings() {
    let scene = cornell();
    let mut b = CpuBackend::new();
    for (w, h, spp) in [(0, 10, 4), (10, 0, 4), (10, 10, 0)] {
        let e = render(&mut b, &scene, &settings(w, h, spp, 0, Accel::None), None, |_| {}).err().unwrap();
        assert!(e.to_string().contains("must be positive"), "{e}");
    }
    let reference = treelet::render::image_io::HdrImage { width: 3, height: 3, pixels: vec![[0.0; 3]; 9] };
    let e = render(&mut b, &scene, &settings(4, 4, 4, 0, Accel::None), Some(&reference), |_| {}).err().unwrap();
    assert!(e.to_string().contains("reference image is 3x3"), "{e}");
}

/// A render past the GPU's own memory (Vulkan's largest device-local heap)
/// is refused before anything is allocated on it, with the estimate, the
/// adapter and its memory.
#[test]
fn render_past_device_memory_is_refused() {
    let Some(ctx) = gpu() else { return };
    let heap = ctx.device_memory.expect("Vulkan reports the adapter's memory heaps");
    let refused = |b: &mut GpuBackend, limit: u64| {
        // 16 bytes of sums a pixel: one pixel more than `limit` holds.
        let pixels = limit / 16 + 1;
        let width = 65536u32;
        let height = pixels.div_ceil(width as u64) as u32;
        let e = treelet::render::Prepared::new(b, &cornell(), &settings(width, height, 1, 0, Accel::None), None).err().unwrap();
        let e = format!("{e:#}");
        assert!(e.contains("device memory") && e.contains(&ctx.info.name) && e.contains(&format!("{width}x{height}")), "{e}");
    };
    // The adapter's own heap, where an image can pass it (not an H200's
    // 141 GB: 16 bytes a pixel of at most 2^31 pixels).
    if heap <= 16 << 30 {
        refused(&mut GpuBackend::new(ctx.clone()), heap);
    } else {
        eprintln!("{} has {heap} bytes of device memory: more than an image can fill; checked under a cap", ctx.info.name);
    }
    // Under a cap, as an engine sharing the GPU sets it.
    let cap = heap.min(16 << 30) / 2;
    refused(&mut GpuBackend::new(ctx.clone()).with_device_memory_cap(cap), cap);
}

/// The ray-casting benchmark's kernels: primary and diffuse rays through the
/// TRBVH of a mesh scene in each layout (and cwbvh with its stack's top in
/// workgroup memory), GPU against the CPU run of the same kernel.
#[test]
fn cast_kernels_match_cpu() {
    use treelet::runtime::kernels::Kernel;
    use treelet::scene::primitives::Primitives;
    use treelet_core::render::rays::{CAST_BOUNCE, CAST_DIFFUSE, CAST_PRIMARY};
    fn cast<B: Backend>(b: &mut B, scene: &Scene, layout: Layout, kernel: Kernel, (w, h): (u32, u32)) -> Vec<[f32; 4]> {
        let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
        let (tree, prims, _) = treelet::bvh::tree::traced_tree(b, all, Accel::Trbvh, layout).unwrap();
        let materials = b.upload("materials", &scene.materials).unwrap();
        let rays = b.zeroed("rays", (w * h) as u64 * 32).unwrap();
        let base = treelet_core::RenderParams {
            width: w,
            height: h,
            samples: 1,
            seed: 3,
            prims: scene.spheres.len() as u32,
            triangles: scene.triangles.len() as u32,
            camera: scene.camera.camera(w, h),
            ..Default::default()
        };
        for mode in [CAST_PRIMARY, CAST_BOUNCE, CAST_DIFFUSE] {
            let p = b.upload("cast params", &[treelet_core::RenderParams { cast_mode: mode, ..base }]).unwrap();
            let bindings = [&p, &prims.spheres, &materials, &tree.nodes, &tree.prims, &rays, &prims.triangles];
            b.dispatch(kernel, &bindings, treelet_core::render::integrator::tiled_invocations(w, h).div_ceil(kernel.workgroup_size()));
        }
        b.read(&rays, (2 * w * h) as usize).unwrap()
    }
    use treelet::runtime::kernels::Method;
    let room = mesh();
    // A height field alone: its bounce rays meet its own hills.
    let alone = Scene::from_spec("terrain:3000").unwrap().mesh_only().unwrap();
    let kernels = [
        (&room, Layout::Classic, Kernel::Cast(Method::Classic, false)),
        (&room, Layout::Bvh2, Kernel::Cast(Method::Bvh2, false)),
        (&room, Layout::Bvh4, Kernel::Cast(Method::Bvh4, false)),
        (&room, Layout::Cwbvh, Kernel::Cast(Method::Cwbvh, false)),
        (&room, Layout::Cwbvh, Kernel::CastWideWorkgroupStack),
        // The kernels compiled for triangles alone, on the mesh alone.
        (&alone, Layout::Classic, Kernel::Cast(Method::Classic, false)),
        (&alone, Layout::Classic, Kernel::Cast(Method::Classic, true)),
        (&alone, Layout::Bvh2, Kernel::Cast(Method::Bvh2, true)),
        (&alone, Layout::Bvh4, Kernel::Cast(Method::Bvh4, true)),
        (&alone, Layout::Cwbvh, Kernel::Cast(Method::Cwbvh, true)),
    ];
    let reference = |scene: &Scene| cast(&mut CpuBackend::new(), scene, Layout::Classic, kernels[0].2, (64, 48));
    let (room_reference, alone_reference) = (reference(&room), reference(&alone));
    for r in [&room_reference, &alone_reference] {
        let cast = r.iter().step_by(2).filter(|r| r[3] != 0.0).count();
        let hits = r.iter().step_by(2).filter(|r| r[3] > 0.0).count();
        assert!(cast > 64 * 48 / 4 && hits > 64 * 48 / 50, "{cast} camera rays hit and {hits} diffuse rays: a weak test");
    }
    let ctx = gpu();
    for (scene, layout, kernel) in kernels {
        // Every layout finds the same hits on the CPU runner, bit for bit.
        let c = cast(&mut CpuBackend::new(), scene, layout, kernel, (64, 48));
        let reference = if std::ptr::eq(scene, &room) { &room_reference } else { &alone_reference };
        assert!(c == *reference, "{kernel:?}: the CPU runner's casts differ from the classic layout's");
        let Some(ctx) = &ctx else { continue };
        let g = cast(&mut GpuBackend::new(ctx.clone()), scene, layout, kernel, (64, 48));
        // Lavapipe does not fuse its `Fma` (the wall intersection's error terms
        // vanish), so hits on smallpt's 1e5-radius walls land up to ~0.02 units
        // apart: positions and distances are compared with that allowance.
        let near = |a: f32, b: f32, abs: f32, rel: f32| (a - b).abs() <= abs + rel * b.abs();
        let same = |i: usize| {
            let (go, co, gd, cd) = (g[i], c[i], g[i + 1], c[i + 1]);
            (0..3).all(|k| near(go[k], co[k], 0.05, 1e-4) && near(gd[k], cd[k], 1e-3, 0.0))
                && (go[3] > 0.0) == (co[3] > 0.0)
                && near(go[3], co[3], 0.1, 1e-3)
        };
        let agree = (0..g.len()).step_by(2).filter(|&i| same(i)).count();
        eprintln!("{kernel:?}: {agree} of {} pixels cast the same diffuse ray to the same hit", 64 * 48);
        assert!(agree as f64 >= 0.95 * (64 * 48) as f64, "{kernel:?}: GPU and CPU casts differ: {agree} agree");
    }
}

// --- Next-event estimation (`--integrator nee`) ---

use treelet::scene::{cornell_room, diffuse, CameraSpec};
use treelet_core::geometry::buffers::{GLASS, Material, Sphere};

/// smallpt's room without its light, plus `extra` spheres and `triangles`.
fn room_with(name: &str, extra: Vec<(Sphere, Material)>, triangles: Vec<(Triangle, Material)>) -> Scene {
    let mut room = cornell_room();
    room.pop(); // The light.
    let (spheres, mut materials): (Vec<_>, Vec<_>) = room.into_iter().chain(extra).unzip();
    let (triangles, tri_materials): (Vec<_>, Vec<_>) = triangles.into_iter().unzip();
    materials.extend(tri_materials);
    Scene { name: name.into(), spheres, materials, room: 0, camera: CameraSpec::SMALLPT, environment: [0.0; 3], triangles, instances: None }
}

fn emitter(e: f32) -> Material {
    Material { emission: [e; 3], ..diffuse([0.0; 3]) }
}

fn balls() -> Vec<(Sphere, Material)> {
    vec![
        (Sphere::new([27.0, 16.5, 47.0], 16.5), diffuse([0.7, 0.7, 0.3])),
        (Sphere::new([73.0, 16.5, 78.0], 16.5), diffuse([0.3, 0.7, 0.7])),
    ]
}

/// The scenes the light sampler must get right: smallpt's cornell (a sphere
/// light mostly hidden by the ceiling), a small square light of two
/// triangles under the ceiling, a tilted disk light and a rectangle light
/// (one primitive each, sampled by area), a light inside a glass ball (shadow rays
/// cannot reach it: only paths through the glass may), a mesh that is the
/// only light, the disk-lit room of `scenes/room_disk.json` (mirror and
/// glass balls, rectangle walls, a disk lamp), and a room with no light at
/// all.
fn light_scenes() -> Vec<Scene> {
    let square = |y: f32| {
        let (a, b, c, d) = ([40.0, y, 70.0], [60.0, y, 70.0], [60.0, y, 90.0], [40.0, y, 90.0]);
        vec![(Triangle::new(a, b, c), emitter(40.0)), (Triangle::new(a, c, d), emitter(40.0))]
    };
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/room_disk.json");
    let mut glass_lamp = balls();
    glass_lamp.push((Sphere::new([50.0, 60.0, 80.0], 10.0), Material { color: [0.999; 3], kind: GLASS, ior: 1.5, ..Default::default() }));
    glass_lamp.push((Sphere::new([50.0, 60.0, 80.0], 3.0), emitter(60.0)));
    let lamp_mesh = mesh();
    let mut lit_mesh = room_with("octahedron as the light", balls(), Vec::new());
    let first = lit_mesh.materials.len();
    lit_mesh.triangles = lamp_mesh.triangles.iter().map(|t| {
        // Small, near the ceiling.
        let place = |v: [f32; 3]| [50.0 + 6.0 * (v[0] - 50.0) / 30.0, 70.0 + 6.0 * v[1] / 60.0, 80.0 + 6.0 * (v[2] - 80.0) / 30.0];
        Triangle::new(place(t.v0), place(t.v1), place(t.v2))
    }).collect();
    lit_mesh.materials.extend(std::iter::repeat_n(emitter(25.0), lit_mesh.triangles.len()));
    assert_eq!(lit_mesh.materials.len(), first + lit_mesh.triangles.len());
    vec![
        cornell(),
        room_with("square light", balls(), square(81.0)),
        room_with(
            "disk and rectangle lights",
            balls(),
            vec![
                (Triangle::disk([50.0, 78.0, 80.0], [0.3, -1.0, 0.2], 12.0), emitter(30.0)),
                (Triangle::parallelogram([5.0, 40.0, 60.0], [0.0, 0.0, 30.0], [2.0, 20.0, 0.0]), emitter(10.0)),
            ],
        ),
        room_with("light in glass", glass_lamp, square(81.0)),
        lit_mesh,
        Scene::from_spec(room).expect(room),
        room_with("no light", balls(), Vec::new()),
    ]
}

fn with_integrator(s: RenderSettings, integrator: Integrator) -> RenderSettings {
    RenderSettings { integrator, ..s }
}

/// Mean of each 4x4-pixel block's luminance.
fn block_means(p: &[[f32; 3]], w: usize, h: usize) -> Vec<f64> {
    let lum = |c: &[f32; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
    let (bw, bh) = (4, 4);
    let mut out = Vec::new();
    for by in 0..h / bh {
        for bx in 0..w / bw {
            let mut s = 0.0;
            for y in by * bh..(by + 1) * bh {
                for x in bx * bw..(bx + 1) * bw {
                    s += lum(&p[y * w + x]);
                }
            }
            out.push(s / (bw * bh) as f64);
        }
    }
    out
}

/// Several seeds' block means: their mean per block, and that mean's
/// variance per block (the block's sample variance over the seeds, over
/// the number of seeds).
fn mean_and_variance(images: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let k = images.len() as f64;
    let n = images[0].len();
    let mean: Vec<f64> = (0..n).map(|i| images.iter().map(|b| b[i]).sum::<f64>() / k).collect();
    let var = (0..n).map(|i| images.iter().map(|b| (b[i] - mean[i]).powi(2)).sum::<f64>() / (k - 1.0) / k).collect();
    (mean, var)
}

/// Next-event estimation, alone and with light paths for caustics, is
/// unbiased: on every light scene its image matches smallpt's estimator's
/// with independent numbers (whole-image mean within 3%, 4x4-pixel blocks
/// within the noise of the two) and has no NaN, infinite or negative
/// pixel, with the Sobol sampler (the default) and with independent numbers.
/// A lost MIS weight (light counted twice), a wrong density (a factor of π
/// or 2), a light behind glass left dark, or sample points that are not
/// uniform all fail this.
///
/// Each side is 16 seeds of 256 samples a pixel, so that each block has its
/// own noise, measured with 15 degrees of freedom a side: each block's
/// difference over that noise is a z-score, and their root mean square must
/// stay under 2 (about 1 when unbiased). Earlier forms pooled one noise
/// over all blocks from four seeds of 1 024 samples, and failed by chance
/// in CI (seed 4573351399162283677: the small octahedron lamp with
/// independent numbers, 2.29x): a few blocks around a small light carry
/// most of the variance, so the pooled figure had few degrees of freedom.
/// On that lamp with independent numbers, eleven seeds' renders measured
/// both ways gave a pooled ratio of 0.80-1.46 (four seeds of 1 024) and
/// 0.77-1.80 (sixteen of 256), and this form 0.95-1.35. Power, one seed:
/// one side scaled by 1.03 reaches 2 on cornell, the room and the disk
/// lights, by 1.05 on every lit scene but the lamp (1.39-1.59); the
/// whole-image means fail anything past 3% everywhere. Highest over five
/// seeds of the whole test: cornell with light paths, 1.16-1.69, its mean
/// 0.2-1.2% under smallpt's in four of them (every other pair 0.74-1.36),
/// but 0.9% over next-event estimation's alone in a sixth run: the light
/// paths' caustics are heavy-tailed there, no bias was found.
#[test]
fn nee_converges_to_the_smallpt_estimate() {
    let seed = treelet_tests::fresh_seed() as u32;
    let (w, h, spp) = (32usize, 24usize, 256);
    let seeds: Vec<u32> = (0..16u32).map(|k| k.wrapping_mul(0x9e37_79b9)).collect();
    let blocks_of = |scene: &Scene, integrator, sampler, salt: u32, name: &str| -> Vec<Vec<f64>> {
        seeds
            .iter()
            .map(|&k| {
                let s = RenderSettings { sampler, ..with_integrator(settings(w as u32, h as u32, spp, seed ^ salt ^ k, Accel::None), integrator) };
                let image = pixels(&mut CpuBackend::new(), scene, &s);
                assert!(image.iter().flatten().all(|v| v.is_finite() && *v >= 0.0), "{} {name}: NaN, infinite or negative pixels", scene.name);
                block_means(&image, w, h)
            })
            .collect()
    };
    let mut failures = Vec::new();
    for scene in light_scenes() {
        let (bp, var_p) = mean_and_variance(&blocks_of(&scene, Integrator::Smallpt, Sampler::Independent, 0x1111_0000, "smallpt"));
        let mp = bp.iter().sum::<f64>() / bp.len() as f64;
        for (k, (integrator, sampler)) in [(Integrator::Nee, Sampler::Sobol), (Integrator::Nee, Sampler::Independent), (Integrator::Caustics, Sampler::Sobol)].into_iter().enumerate() {
            let name = format!("{} ({})", integrator.name(), sampler.name());
            let (bn, var_n) = mean_and_variance(&blocks_of(&scene, integrator, sampler, 0x2222_0000 + k as u32, &name));
            let mn = bn.iter().sum::<f64>() / bn.len() as f64;
            // A block both sides see without noise (a light filling it)
            // still gets a floor of a thousandth of the mean.
            let z2 = (0..bp.len()).map(|i| (bp[i] - bn[i]).powi(2) / (var_p[i] + var_n[i] + (1e-3 * mp).powi(2)).max(1e-30));
            let z = (z2.sum::<f64>() / bp.len() as f64).sqrt();
            eprintln!("{}: mean luminance {name} {mn:.4}, smallpt {mp:.4}; blocks differ by {z:.2} standard deviations (rms)", scene.name);
            if scene.name == "no light" {
                if !(mn == 0.0 && mp == 0.0) {
                    failures.push(format!("no light: the image must be black ({name} {mn}, smallpt {mp})"));
                }
                continue;
            }
            if (mn / mp - 1.0).abs() >= 0.03 {
                failures.push(format!("{} {name}: mean luminance {mn}, smallpt {mp}", scene.name));
            }
            if z >= 2.0 {
                failures.push(format!("{} {name}: blocks differ by {z:.2} standard deviations (rms)", scene.name));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The Sobol sampler's images have less error than independent numbers'
/// at equal samples: the mean squared difference between two seeds' images
/// (twice the variance of one) on cornell and the disk-lit room, CPU
/// runner (48x36, 256 spp). A scramble
/// that lost the points' strata (or correlated two pairs) fails this.
/// The mean leaves out the 0.3% of pixels that differ most (5 of 1 728): a
/// few fireflies (light through cornell's glass ball, found by chance)
/// otherwise decide it (one seed's Sobol pair came out 0.64x with them;
/// without them six seeds gave cornell 1.9-2.2x, the room 1.4-1.8x).
#[test]
fn sobol_points_lower_the_error_at_equal_samples() {
    let seed = treelet_tests::fresh_seed() as u32;
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/room_disk.json");
    for scene in [cornell(), Scene::from_spec(room).expect(room)] {
        let variance = |sampler| {
            let s = RenderSettings { sampler, ..with_integrator(settings(48, 36, 256, seed, Accel::None), Integrator::Nee) };
            let a = pixels(&mut CpuBackend::new(), &scene, &s);
            let b = pixels(&mut CpuBackend::new(), &scene, &RenderSettings { seed: seed ^ 0x9e37, ..s });
            let mut d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| (0..3).map(|k| ((x[k] - y[k]) as f64).powi(2)).sum::<f64>() / 3.0).collect();
            d.sort_by(f64::total_cmp);
            let kept = &d[..d.len() - d.len() / 300];
            kept.iter().sum::<f64>() / kept.len() as f64
        };
        let (sobol, plain) = (variance(Sampler::Sobol), variance(Sampler::Independent));
        eprintln!("{}: mean squared difference of two seeds, sobol {sobol:.3e}, independent {plain:.3e} ({:.2}x)", scene.name, plain / sobol);
        assert!(sobol < 0.85 * plain, "{}: sobol {sobol:.3e}, independent {plain:.3e}", scene.name);
    }
}

/// Next-event estimation, alone and with light paths, on the GPU equals the
/// CPU runner's within noise (light paths land through atomics, in any order).
#[test]
fn nee_gpu_matches_cpu() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed() as u32;
    for (scene, integrator) in light_scenes().into_iter().take(4).flat_map(|s| [(s.clone(), Integrator::Nee), (s, Integrator::Caustics)]) {
        let s = with_integrator(settings(48, 36, 16, seed, Accel::None), integrator);
        let g = pixels(&mut GpuBackend::new(ctx.clone()), &scene, &s);
        let c = pixels(&mut CpuBackend::new(), &scene, &s);
        let other = pixels(&mut CpuBackend::new(), &scene, &RenderSettings { seed: seed.wrapping_add(1), ..s });
        let (gpu_cpu, noise) = (mean_abs(&g, &c), mean_abs(&c, &other));
        let same = 1.0 - mismatch_fraction(&g, &c, 1e-4);
        let name = integrator.name();
        eprintln!("{} {name}: {:.1}% of pixels agree within 1e-4; mean |gpu - cpu| {gpu_cpu:.2e}, noise {noise:.2e}", scene.name, 100.0 * same);
        if integrator == Integrator::Caustics {
            // Light paths land through atomics in any order (the float sums
            // differ in their last bits wherever they land), and one that
            // rounds onto another way through glass carries a lamp's whole
            // weight into one pixel (cornell's: 0.2x the noise in one run).
            // So: all but the 1% most different pixels far below the noise,
            // and all of them below it.
            let mut d: Vec<f64> = g.iter().zip(&c).map(|(x, y)| (0..3).map(|k| (x[k] - y[k]).abs() as f64).sum::<f64>() / 3.0).collect();
            d.sort_by(f64::total_cmp);
            let kept = &d[..d.len() * 99 / 100];
            let trimmed = kept.iter().sum::<f64>() / kept.len() as f64;
            eprintln!("{} {name}: mean |gpu - cpu| of the 99% closest pixels {trimmed:.2e}", scene.name);
            assert!(trimmed < 0.05 * noise, "{} {name}: GPU and CPU differ by {trimmed} (99% of pixels), noise is {noise}", scene.name);
            assert!(gpu_cpu < 0.5 * noise, "{} {name}: GPU and CPU differ by {gpu_cpu}, noise is {noise}", scene.name);
        } else {
            assert!(same > 0.5, "{} {name}: only {:.1}% of pixels agree", scene.name, 100.0 * same);
            assert!(gpu_cpu < 0.25 * noise, "{} {name}: GPU and CPU differ by {gpu_cpu}, noise is {noise}", scene.name);
        }
    }
}

/// A small image with many samples per pixel, so that each dispatch takes
/// many samples of a pixel and later dispatches add to earlier ones: the
/// GPU's image must be the CPU runner's, for both integrators. lavapipe got
/// this wrong twice (far too dark at 512 samples per dispatch with
/// smallpt's estimator, lost light from the second dispatch on at 32 with
/// next-event estimation in the disk-lit room): see `max_samples_per_dispatch`.
#[test]
fn many_samples_per_pixel_on_a_small_image() {
    let Some(ctx) = gpu() else { return };
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/room_disk.json");
    let mut scenes = vec![cornell(), Scene::from_spec(room).expect(room)];
    scenes.extend(light_scenes().into_iter().take(2));
    for scene in &scenes {
        for integrator in [Integrator::Smallpt, Integrator::Nee] {
            let s = with_integrator(settings(16, 12, 256, 3, Accel::None), integrator);
            let g = pixels(&mut GpuBackend::new(ctx.clone()), scene, &s);
            let c = pixels(&mut CpuBackend::new(), scene, &s);
            let other = pixels(&mut CpuBackend::new(), scene, &RenderSettings { seed: 4, ..s });
            let (gpu_cpu, noise) = (mean_abs(&g, &c), mean_abs(&c, &other));
            let same = 1.0 - mismatch_fraction(&g, &c, 1e-3);
            eprintln!("{} {integrator:?}: {:.1}% of pixels agree within 1e-3; mean |gpu - cpu| {gpu_cpu:.2e}, noise {noise:.2e}", scene.name, 100.0 * same);
            assert!(same > 0.25, "{} {integrator:?}: only {:.1}% of pixels agree", scene.name, 100.0 * same);
            assert!(gpu_cpu < 0.25 * noise, "{} {integrator:?}: GPU and CPU differ by {gpu_cpu}, noise is {noise}", scene.name);
        }
    }
}

/// On a GPU a render's dispatches grow from their first size to the
/// device's measured rate (`treelet::render::dispatch_size`): here to
/// hundreds of samples of a pixel in one invocation's loop. CPU adapters
/// keep their 16 (lavapipe gets longer loops wrong). Either way the image
/// is the CPU runner's within noise.
#[test]
fn dispatches_grow_to_the_gpu_rate_and_keep_the_image() {
    use treelet::runtime::backend::DeviceClass;
    let Some(ctx) = gpu() else { return };
    let class = GpuBackend::new(ctx.clone()).class();
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/room_disk.json");
    for scene in [cornell(), Scene::from_spec(room).expect(room)] {
        let s = RenderSettings { error_each_pass: false, ..with_integrator(settings(24, 16, 1024, 5, Accel::None), Integrator::Nee) };
        let r = render(&mut GpuBackend::new(ctx.clone()), &scene, &s, None, |_| {}).unwrap();
        let largest = r.shares[0].dispatch_samples;
        eprintln!("{} on {class:?}: dispatches of up to {largest} spp", scene.name);
        match class {
            DeviceClass::Gpu => assert!(largest >= 256, "{}: dispatches of at most {largest} spp on a GPU", scene.name),
            _ => assert!((1..=16).contains(&largest), "{}: dispatches of {largest} spp on {class:?}", scene.name),
        }
        let g = r.image.pixels;
        let c = pixels(&mut CpuBackend::new(), &scene, &s);
        let other = pixels(&mut CpuBackend::new(), &scene, &RenderSettings { seed: 6, ..s });
        let (gpu_cpu, noise) = (mean_abs(&g, &c), mean_abs(&c, &other));
        let same = 1.0 - mismatch_fraction(&g, &c, 1e-3);
        eprintln!("{}: {:.1}% of pixels agree within 1e-3; mean |gpu - cpu| {gpu_cpu:.2e}, noise {noise:.2e}", scene.name, 100.0 * same);
        assert!(same > 0.25, "{}: only {:.1}% of pixels agree", scene.name, 100.0 * same);
        assert!(gpu_cpu < 0.25 * noise, "{}: GPU and CPU differ by {gpu_cpu}, noise is {noise}", scene.name);
    }
}

/// With `--layout auto`, a render on a Vulkan device (here: the GPU, or
/// lavapipe) of at least `PILOT_MIN_SPP` samples
/// through a tree first times one sample of every pixel through each
/// layout and renders through the faster: the plan names it and the times,
/// and the image is, bit for bit, the same render with that layout asked
/// for (the pilot's samples are not in it). A shorter render runs no pilot.
#[test]
fn layout_pilot_keeps_the_faster_layout_and_leaves_no_trace() {
    let Some(ctx) = gpu() else { return };
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/room_disk.json");
    let scene = Scene::from_spec(room).expect(room);
    let s = RenderSettings {
        integrator: Integrator::Nee,
        error_each_pass: false,
        ..settings(24, 16, treelet::render::variant::PILOT_MIN_SPP, 3, Accel::Lbvh)
    };
    let auto = render(&mut GpuBackend::new(ctx.clone()), &scene, &s, None, |_| {}).unwrap();
    let reason = &auto.plan.layout_reason;
    assert!(reason.contains("the faster of") && reason.contains("bvh2 ") && reason.contains("cwbvh "), "no pilot: {reason}");
    assert!(matches!(auto.plan.layout, Layout::Bvh2 | Layout::Cwbvh), "{:?}", auto.plan.layout);
    let asked = render(&mut GpuBackend::new(ctx.clone()), &scene, &RenderSettings { layout: auto.plan.layout, ..s }, None, |_| {}).unwrap();
    assert_eq!(auto.image.pixels, asked.image.pixels, "the pilot changed the image ({reason})");
    assert!(auto.image.pixels.iter().flatten().any(|&v| v > 0.0), "the room rendered black");
    let short = RenderSettings { spp: treelet::render::variant::PILOT_MIN_SPP - 1, ..s };
    let plain = render(&mut GpuBackend::new(ctx), &scene, &short, None, |_| {}).unwrap();
    assert!(!plain.plan.layout_reason.contains("the faster of"), "a pilot below the threshold: {}", plain.plan.layout_reason);
}

/// A render scored against a reference measures its error at every pass
/// end (4, 8, 16, ... samples), on the GPU and on the CPU runner, however
/// large the chunks its device would take: `bench error` draws its curves
/// from these rows.
#[test]
fn a_scored_render_has_a_row_at_every_pass() {
    let Some(ctx) = gpu() else { return };
    let scene = cornell();
    let s = RenderSettings { error_each_pass: true, ..settings(32, 24, 256, 5, Accel::None) };
    let reference = render(&mut CpuBackend::new(), &scene, &RenderSettings { seed: 6, ..s }, None, |_| {}).unwrap().image;
    let cpu = render(&mut CpuBackend::new(), &scene, &s, Some(&reference), |_| {}).unwrap();
    let gpu = render(&mut GpuBackend::new(ctx), &scene, &s, Some(&reference), |_| {}).unwrap();
    for (name, r) in [("cpu", &cpu), ("gpu", &gpu)] {
        let spp: Vec<u32> = r.rows.iter().map(|row| row.spp).collect();
        assert_eq!(spp, vec![4, 8, 16, 32, 64, 128, 256], "{name}");
        let rmse: Vec<f64> = r.rows.iter().map(|row| row.rmse.unwrap()).collect();
        // Error falls with samples (by about sqrt 2 a pass, so 4 to 256 at least halves it).
        assert!(rmse[6] < 0.5 * rmse[0], "{name}: {rmse:?}");
    }
}
