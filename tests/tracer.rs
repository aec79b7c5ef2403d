//! The engine API (`treelet::tracer`): closest hits of random rays through
//! trees over random spheres, triangles, disks and parallelograms, on the GPU and the CPU runner,
//! each against the scan of every primitive (`treelet_core`, no tree), before
//! and after a refit; and its errors.
use glam::Vec3;
use rand::{Rng, SeedableRng};
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::tracer::{Quality, Ray, RayHit, Tracer};
use treelet_core::geometry::buffers::Sphere;
use treelet_core::geometry::prims::{Origin, Prims};
use treelet_core::geometry::triangle::{Triangle, SHAPE_DISK, SHAPE_PARALLELOGRAM};
use treelet_core::trace::classic::closest_hit_linear;
use treelet_tests::{fresh_seed, gpu};

type Geometry = (Vec<Sphere>, Vec<Triangle>);

fn geometry(rng: &mut impl Rng, spheres: usize, triangles: usize) -> Geometry {
    let mut p = || [rng.random_range(0.0..100.0f32), rng.random_range(0.0..100.0f32), rng.random_range(0.0..100.0f32)];
    let s = (0..spheres).map(|_| Sphere::new(p(), 1.5)).collect();
    // Every fifth a disk, every seventh a parallelogram (the flat shapes
    // an engine may pass beside its triangles), on the same three points.
    let t = (0..triangles)
        .map(|k| {
            let a = p();
            let (e1, e2) = ([4.0, 1.0, 0.0], [0.0, 3.0, 4.0]);
            let t = Triangle::new(a, [a[0] + e1[0], a[1] + e1[1], a[2]], [a[0], a[1] + e2[1], a[2] + e2[2]]);
            match k {
                k if k % 5 == 0 => Triangle { shape: SHAPE_DISK, ..t },
                k if k % 7 == 0 => Triangle::parallelogram(a, e1, e2),
                _ => t,
            }
        })
        .collect();
    (s, t)
}

/// Every primitive moved by its own random offset.
fn moved(g: &Geometry, rng: &mut impl Rng) -> Geometry {
    let mut off = || Vec3::new(rng.random_range(-20.0..20.0), rng.random_range(-20.0..20.0), rng.random_range(-20.0..20.0));
    let s = g.0.iter().map(|s| Sphere::new((Vec3::from(s.center) + off()).into(), s.radius)).collect();
    let t = g.1.iter().map(|t| {
        let o = off();
        let placed = Triangle::new((Vec3::from(t.v0) + o).into(), (Vec3::from(t.v1) + o).into(), (Vec3::from(t.v2) + o).into());
        Triangle { shape: t.shape, ..placed }
    });
    (s, t.collect())
}

fn rays(rng: &mut impl Rng, n: usize) -> Vec<Ray> {
    (0..n)
        .map(|k| {
            let o = [rng.random_range(-10.0..110.0), rng.random_range(-10.0..110.0), rng.random_range(-10.0..110.0)];
            let d = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
            // Every fourth ray stops at 30 units; every third starts at 10.
            let t_min = if k % 3 == 0 { 10.0 } else { 0.0 };
            Ray { origin: o, dir: d, t_min, t_max: if k % 4 == 0 { 30.0 } else { f32::INFINITY } }
        })
        .collect()
}

/// The closest hit from `t_min` on (the scan from the point at `t_min`),
/// up to `t_max`: distance and primitive (the record is checked apart).
fn scan(g: &Geometry, r: &Ray) -> RayHit {
    let prims = Prims::new(&g.0, &g.1);
    let d = Vec3::from(r.dir);
    if d.length() == 0.0 {
        return RayHit::MISS;
    }
    let h = closest_hit_linear(Vec3::from(r.origin) + d.normalize() * r.t_min, d.normalize(), Origin::NONE, &prims);
    if h.is_hit() && h.t + r.t_min <= r.t_max {
        RayHit { t: h.t + r.t_min, prim: h.prim, ..RayHit::MISS }
    } else {
        RayHit::MISS
    }
}

/// A hit's record against the primitive itself: the point its barycentrics
/// give (a triangle's) or its normal gives (a sphere's) is the point at
/// distance `t` along the ray, within the intersection tests' error, and
/// the normal is the primitive's, of unit length.
fn check_record(what: &str, g: &Geometry, r: &Ray, h: &RayHit) {
    let x = Vec3::from(r.origin) + Vec3::from(r.dir).normalize() * h.t;
    let n = Vec3::from(h.normal);
    let tol = 1e-3 * (1.0 + x.length());
    assert!((n.length() - 1.0).abs() < 1e-4, "{what}: ray {r:?}: normal {n} of {h:?}");
    match g.0.get(h.prim as usize) {
        Some(s) => {
            let on = Vec3::from(s.center) + n * s.radius;
            assert!((on - x).length() < tol, "{what}: ray {r:?}: sphere hit {h:?} at {x}, normal gives {on}");
            assert_eq!(h.barycentrics, [0.0; 2], "{what}: a sphere has no barycentrics");
        }
        None => {
            let t = &g.1[h.prim as usize - g.0.len()];
            let (a, b, c) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
            let [b1, b2] = h.barycentrics;
            let inside = match t.shape {
                SHAPE_DISK => b1 * b1 + b2 * b2 <= 1.0 + 1e-5,
                SHAPE_PARALLELOGRAM => (-1e-6..=1.0 + 1e-6).contains(&b1) && (-1e-6..=1.0 + 1e-6).contains(&b2),
                _ => b1 >= -1e-6 && b2 >= -1e-6 && b1 + b2 <= 1.0 + 1e-5,
            };
            assert!(inside, "{what}: ray {r:?}: barycentrics of {h:?}, shape {}", t.shape);
            // v0 + b1 (v1 - v0) + b2 (v2 - v0), for every flat shape.
            let p = a * (1.0 - b1 - b2) + b * b1 + c * b2;
            assert!((p - x).length() < tol, "{what}: ray {r:?}: flat hit {h:?} at {x}, barycentrics give {p}");
            assert!((n - (b - a).cross(c - a).normalize()).length() < 1e-4, "{what}: ray {r:?}: normal of {h:?}");
        }
    }
}

/// The tracer's hits equal the scan's: same primitive, same distance within
/// rounding (a ray grazing two primitives at one distance may name either).
fn check(what: &str, hits: &[RayHit], g: &Geometry, rays: &[Ray]) {
    assert_eq!(hits.len(), rays.len());
    let mut hit = 0;
    for (r, h) in rays.iter().zip(hits) {
        let s = scan(g, r);
        assert_eq!(h.is_hit(), s.is_hit(), "{what}: ray {r:?}: tracer {h:?}, scan {s:?}");
        if s.is_hit() {
            hit += 1;
            check_record(what, g, r, h);
            assert!((h.t - s.t).abs() <= 1e-4 * s.t.max(1.0), "{what}: ray {r:?}: tracer {h:?}, scan {s:?}");
            assert!(h.prim == s.prim || (h.t - s.t).abs() <= 1e-5 * s.t.max(1.0), "{what}: ray {r:?}: tracer {h:?}, scan {s:?}");
        }
    }
    assert!(hit > rays.len() / 20, "{what}: only {hit} of {} rays hit: the test would prove little", rays.len());
}

fn round_trip<B: Backend>(b: &mut B, seed: u64, quality: Quality) -> (Vec<RayHit>, Vec<RayHit>) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let g = geometry(&mut rng, 300, 1700);
    let rays = rays(&mut rng, 3000);
    let what = format!("{} {quality:?} seed {seed}", b.adapter());
    let mut t = Tracer::build(b, &g.0, &g.1, quality).unwrap();
    let first = t.closest_hits(b, &rays).unwrap();
    check(&what, &first, &g, &rays);
    let m = moved(&g, &mut rng);
    t.refit(b, &m.0, &m.1).unwrap();
    let second = t.closest_hits(b, &rays).unwrap();
    check(&format!("{what}, refit"), &second, &m, &rays);
    (first, second)
}

#[test]
fn tracer_finds_the_scans_hits_before_and_after_a_refit() {
    let seed = fresh_seed();
    // ForRays: every device class picks the LBVH for one ray and the treelets for 2^40.
    for quality in [Quality::Fast, Quality::High, Quality::Balanced, Quality::ForRays(1), Quality::ForRays(1 << 40)] {
        let mut b = CpuBackend::new();
        let cpu = round_trip(&mut b, seed, quality);
        // The build prepared every pipeline the tracer then used (on a GPU:
        // none compiled in the middle of a frame).
        assert!(b.kernels_not_prepared().is_empty(), "{quality:?}: not built ahead: {:?}", b.kernels_not_prepared());
        if let Some(ctx) = gpu() {
            let gpu = round_trip(&mut GpuBackend::new(ctx), seed, quality);
            // Same kernels, same tree: the same primitives, distances within rounding.
            let same = cpu.0.iter().chain(&cpu.1).zip(gpu.0.iter().chain(&gpu.1)).filter(|(c, g)| c.prim == g.prim).count();
            assert!(same as f64 >= 0.999 * 2.0 * cpu.0.len() as f64, "{quality:?}: GPU and CPU agree on {same} hits of {}", 2 * cpu.0.len());
        }
    }
}

/// A tree of one leaf refits too (the climb has no parent to go to; the
/// refit writes the root's one child box): a triangle moved three times is
/// hit where it went and missed where it was, on the CPU runner and the GPU.
#[test]
fn a_tree_of_one_leaf_refits() {
    fn moves<B: Backend>(b: &mut B, what: &str) {
        let at = |z: f32, x: f32| [Triangle::new([x, 0.0, z], [x + 1.0, 0.0, z], [x, 1.0, z])];
        let probe = |x: f32| Ray::new([x + 0.2, 0.2, 0.0], [0.0, 0.0, 1.0]);
        let mut t = Tracer::build(b, &[], &at(5.0, 0.0), Quality::High).unwrap();
        let mut was = 0.0;
        for (z, x) in [(7.0, 10.0), (3.0, -4.0), (6.0, 0.0)] {
            t.refit(b, &[], &at(z, x)).unwrap();
            let hits = t.closest_hits(b, &[probe(x), probe(was)]).unwrap();
            // Within rounding: the GPU fuses the watertight test's products.
            assert!(hits[0].prim == 0 && (hits[0].t - z).abs() <= 1e-6 * z, "{what}: the triangle moved to x {x}, z {z}: {:?}", hits[0]);
            assert!(!hits[1].is_hit(), "{what}: a hit where the triangle was: {:?}", hits[1]);
            was = x;
        }
    }
    moves(&mut CpuBackend::new(), "CPU runner");
    if let Some(ctx) = gpu() {
        moves(&mut GpuBackend::new(ctx), "GPU");
    }
}

#[test]
fn tracer_small_and_empty_scenes() {
    let b = &mut CpuBackend::new();
    let one = [Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])];
    let t = Tracer::build(b, &[], &one, Quality::Fast).unwrap();
    let hits = t.closest_hits(b, &[Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 2.0]), Ray::new([3.0, 3.0, 0.0], [0.0, 0.0, 1.0])]).unwrap();
    assert_eq!((hits[0].prim, hits[0].t), (0, 5.0));
    assert!(!hits[1].is_hit());
    let empty = Tracer::build(b, &[], &[], Quality::High).unwrap();
    assert!(!empty.closest_hits(b, &[Ray::new([0.0; 3], [1.0, 0.0, 0.0])]).unwrap()[0].is_hit());
    // A zero direction hits nothing.
    assert!(!t.closest_hits(b, &[Ray::new([0.2, 0.2, 0.0], [0.0; 3])]).unwrap()[0].is_hit());
    // t_min: past a sphere's near side, its far side; past the triangle, nothing.
    let ball = [treelet::Sphere::new([0.0, 0.0, 10.0], 2.0)];
    let s = Tracer::build(b, &ball, &[], Quality::Fast).unwrap();
    let from = |t_min| Ray { t_min, ..Ray::new([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]) };
    let hits = s.closest_hits(b, &[from(0.0), from(8.5), from(12.5)]).unwrap();
    assert_eq!((hits[0].prim, hits[0].t, hits[0].normal), (0, 8.0, [0.0, 0.0, -1.0]), "{hits:?}");
    assert_eq!((hits[1].prim, hits[1].t, hits[1].normal), (0, 12.0, [0.0, 0.0, 1.0]), "{hits:?}");
    assert!(!hits[2].is_hit(), "{hits:?}");
    let tri = t.closest_hits(b, &[from(0.0), from(5.5)]).unwrap();
    assert_eq!((tri[0].prim, tri[0].t), (0, 5.0));
    assert!(!tri[1].is_hit());
    assert_eq!(t.occluded(b, &[from(0.0), from(5.5)]).unwrap(), vec![true, false]);
    for bad in [-1.0, f32::NAN, f32::INFINITY] {
        let e = format!("{:#}", t.closest_hits(b, &[Ray::new([0.0; 3], [1.0, 0.0, 0.0]), from(bad)]).unwrap_err());
        assert!(e.contains("ray 1") && e.contains("t_min"), "{e}");
    }
}

#[test]
fn tracer_rejects_bad_input_by_name() {
    let b = &mut CpuBackend::new();
    let bad = [Triangle::new([0.0, f32::NAN, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])];
    let e = Tracer::build(b, &[], &bad, Quality::Fast).err().expect("NaN accepted");
    assert_eq!(e.kind(), treelet::error::ErrorKind::Input, "{e}");
    let e = e.to_string();
    assert!(e.contains("triangle 0") || e.contains("NaN"), "{e}");
    let good = [Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])];
    let mut t = Tracer::build(b, &[], &good, Quality::Fast).unwrap();
    let e = t.refit(b, &[], &[good[0], good[0]]).unwrap_err();
    assert_eq!(e.kind(), treelet::error::ErrorKind::Input, "{e}");
    let e = e.to_string();
    assert!(e.contains("2 triangles") && e.contains("built over"), "{e}");
}

/// Occlusion queries agree with closest hits: a ray is occluded exactly when
/// the scan's closest hit (no tree, no bound) lies within its `t_max`. Rays
/// are bounded just past their closest hit, just short of it, at random,
/// not at all, at zero and at NaN; on the CPU runner and the GPU, both
/// qualities, before and after a refit.
#[test]
fn occlusion_agrees_with_closest_hit() {
    let seed = fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let g = geometry(&mut rng, 200, 1300);
    let m = moved(&g, &mut rng);
    let unbounded = rays(&mut rng, 2000).into_iter().map(|r| Ray { t_max: f32::INFINITY, ..r }).collect::<Vec<_>>();
    let bounded = |g: &Geometry, rng: &mut rand_pcg::Pcg64| -> Vec<Ray> {
        unbounded
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let t = scan(g, r).t;
                let t_max = match k % 6 {
                    0 if t.is_finite() => t * 1.001,
                    1 if t.is_finite() => t * 0.999,
                    2 => rng.random_range(0.0..150.0),
                    3 => f32::INFINITY,
                    4 => 0.0,
                    5 if k % 12 == 5 => f32::NAN,
                    _ => rng.random_range(0.0..60.0),
                };
                Ray { t_max, ..*r }
            })
            .collect()
    };
    let expected = |g: &Geometry, rays: &[Ray]| -> Vec<bool> { rays.iter().map(|r| scan(g, r).is_hit()).collect() };
    let (rays_g, rays_m) = (bounded(&g, &mut rng), bounded(&m, &mut rng));
    let (want_g, want_m) = (expected(&g, &rays_g), expected(&m, &rays_m));
    let occluded = want_g.iter().filter(|&&o| o).count();
    assert!(occluded > 100 && occluded < 1900, "{occluded} of 2000 occluded: the test would prove little");
    fn run<B: Backend>(b: &mut B, g: &Geometry, m: &Geometry, rays: (&[Ray], &[Ray]), quality: Quality) -> (Vec<bool>, Vec<bool>) {
        let mut t = Tracer::build(b, &g.0, &g.1, quality).unwrap();
        let first = t.occluded(b, rays.0).unwrap();
        t.refit(b, &m.0, &m.1).unwrap();
        (first, t.occluded(b, rays.1).unwrap())
    }
    let ctx = gpu();
    for quality in [Quality::Fast, Quality::High] {
        let mut results = vec![("cpu", run(&mut CpuBackend::new(), &g, &m, (&rays_g, &rays_m), quality))];
        if let Some(ctx) = &ctx {
            results.push(("gpu", run(&mut GpuBackend::new(ctx.clone()), &g, &m, (&rays_g, &rays_m), quality)));
        }
        for (device, (first, second)) in results {
            let wrong: Vec<usize> = (0..first.len()).filter(|&k| first[k] != want_g[k]).collect();
            eprintln!("{device} {quality:?}: {} wrong of {} ({} occluded); wrong by k % 6: {:?}", wrong.len(), first.len(), occluded, (0..6).map(|c| wrong.iter().filter(|&&k| k % 6 == c).count()).collect::<Vec<_>>());
            for (k, (got, want)) in first.iter().zip(&want_g).enumerate() {
                assert_eq!(got, want, "{device} {quality:?} seed {seed}: ray {k} {:?}, closest hit {:?}", rays_g[k], scan(&g, &unbounded[k]));
            }
            for (k, (got, want)) in second.iter().zip(&want_m).enumerate() {
                assert_eq!(got, want, "{device} {quality:?} seed {seed}, refit: ray {k} {:?}, closest hit {:?}", rays_m[k], scan(&m, &unbounded[k]));
            }
        }
    }
}

/// An engine may hold several tracers on one device: building or refitting
/// one must not hand out another's buffers (the backend pools buffers
/// between builds), and a tracer refit frame after frame must not make the
/// pool grow.
#[test]
fn tracers_on_one_device_keep_their_own_trees() {
    let Some(ctx) = gpu() else { return };
    let b = &mut GpuBackend::new(ctx);
    let grid = |z: f32| -> Vec<Triangle> {
        (0..400).map(|k| {
            let (x, y) = ((k % 20) as f32, (k / 20) as f32);
            Triangle::new([x, y, z], [x + 1.0, y, z], [x, y + 1.0, z])
        }).collect()
    };
    let ray = [Ray::new([0.25, 0.25, 0.0], [0.0, 0.0, 1.0])];
    for quality in [Quality::Fast, Quality::High] {
        let mut a = Tracer::build(b, &[], &grid(5.0), quality).unwrap();
        let bt = Tracer::build(b, &[], &grid(9.0), quality).unwrap();
        assert_eq!(a.closest_hits(b, &ray).unwrap()[0].t, 5.0, "{quality:?}: the first tracer after building a second");
        assert_eq!(bt.closest_hits(b, &ray).unwrap()[0].t, 9.0, "{quality:?}: the second tracer");
        let first = b.pooled_bytes();
        for frame in 0..20 {
            a.refit(b, &[], &grid(5.0 + frame as f32 * 0.125)).unwrap();
        }
        assert_eq!(a.closest_hits(b, &ray).unwrap()[0].t, 5.0 + 19.0 * 0.125, "{quality:?}: the first tracer after refits");
        assert_eq!(bt.closest_hits(b, &ray).unwrap()[0].t, 9.0, "{quality:?}: the second tracer after the first's refits");
        assert!(b.pooled_bytes() <= 2 * first.max(1 << 20), "{quality:?}: the pool grew from {first} to {} bytes over 20 refits", b.pooled_bytes());
    }
}

/// An engine's own device: opened by the engine (a wgpu instance of its
/// own, Treelet's required features and limits), handed to
/// `GpuContext::from_wgpu`; the tracer on it finds the scan's hits, and
/// writes them into a buffer the engine made on its device (rays written
/// there by the engine's queue). A device opened with wgpu's defaults is
/// refused, the missing feature and the short limit named.
#[test]
fn tracer_on_an_engines_own_device() {
    use treelet::runtime::gpu::GpuContext;
    use treelet::wgpu;
    let Some(ours) = gpu() else { return };
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    let adapter = adapters.into_iter().find(|a| a.get_info().name == ours.info.name).expect("the tests' adapter, listed again");

    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default())).unwrap();
    let e = format!("{:#}", GpuContext::from_wgpu(&adapter, device, queue).err().expect("a device without Treelet's features"));
    assert!(e.contains("PASSTHROUGH_SHADERS") && e.contains("max_storage_buffers_per_shader_stage is 8"), "{e}");

    let descriptor = wgpu::DeviceDescriptor {
        label: Some("an engine's device"),
        required_features: GpuContext::required_features(),
        required_limits: GpuContext::required_limits(wgpu::Limits::default()),
        // SAFETY: SPIR-V passthrough is an experimental wgpu feature; the
        // modules are rust-gpu's, validated by the driver.
        experimental_features: unsafe { wgpu::ExperimentalFeatures::enabled() },
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).unwrap();
    // The engine keeps its handles (wgpu's are shared references).
    let ctx = GpuContext::from_wgpu(&adapter, device.clone(), queue.clone()).unwrap();
    assert_eq!(ctx.info.name, ours.info.name);
    let b = &mut GpuBackend::new(ctx);
    let seed = fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let g = geometry(&mut rng, 300, 700);
    let rs = rays(&mut rng, 2000);
    let mut tracer = Tracer::build(b, &g.0, &g.1, Quality::High).unwrap();
    check("the engine's device", &tracer.closest_hits(b, &rs).unwrap(), &g, &rs);
    let m = moved(&g, &mut rng);
    tracer.refit(b, &m.0, &m.1).unwrap();
    let hits = tracer.closest_hits(b, &rs).unwrap();
    check("the engine's device, refit", &hits, &m, &rs);

    // The engine's own buffer: rays in, hits out, in place.
    let data = treelet::tracer::device_rays(&rs).unwrap();
    let engine_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("the engine's rays"),
        size: (data.len() * 16) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    queue.write_buffer(&engine_buffer, 0, bytemuck::cast_slice(&data));
    tracer.closest_hits_on_device(b, &engine_buffer, rs.len()).unwrap();
    let out = b.read::<[f32; 4]>(&engine_buffer, 2 * rs.len()).unwrap();
    for (k, h) in hits.iter().enumerate() {
        let (t, prim) = (out[2 * k][0], out[2 * k][1].to_bits());
        assert_eq!(prim, h.prim, "ray {k}: in the engine's buffer {prim}, from closest_hits {}", h.prim);
        // Distances from the point at t_min on, as `device_rays` moves the origin there.
        if h.is_hit() {
            assert!((t + rs[k].t_min - h.t).abs() <= 1e-3 * h.t.max(1.0), "ray {k}: {t} + {} against {}", rs[k].t_min, h.t);
        }
    }
}

/// A random indexed mesh as an engine keeps it: `v` vertices of 7 words
/// (a position, then four words of the engine's own, which must not be
/// read as coordinates) after 4 words, and `n` triangles of random indices
/// (some repeat a vertex: degenerate triangles, which nothing hits);
/// returns the vertex words, the indices, and the triangles they make.
fn engine_mesh(rng: &mut impl Rng, v: usize, n: usize) -> (Vec<u32>, Vec<u32>, Vec<Triangle>) {
    let points: Vec<[f32; 3]> = (0..v).map(|_| [rng.random_range(0.0..100.0f32), rng.random_range(0.0..100.0f32), rng.random_range(0.0..100.0f32)]).collect();
    let mut words = vec![0x7FC0_0000u32; 4]; // NaN before the first vertex
    for p in &points {
        words.extend(p.map(f32::to_bits));
        words.extend([0x7F80_0000, 0xFFFF_FFFF, 0x7FC0_0000, 1]); // inf, NaN, NaN, 1e-45
    }
    // Indices near each other, so triangles are small, as a mesh's are.
    let indices: Vec<u32> = (0..n)
        .flat_map(|_| {
            let a = rng.random_range(0..v as u32);
            let mut near = || (a + rng.random_range(0..8)).min(v as u32 - 1);
            [a, near(), near()]
        })
        .collect();
    let tris = indices.chunks(3).map(|t| Triangle::new(points[t[0] as usize], points[t[1] as usize], points[t[2] as usize])).collect();
    (words, indices, tris)
}

/// u16 indices packed two a word, after `pad` halves.
fn halves(indices: &[u32], pad: usize) -> Vec<u32> {
    let mut h: Vec<u32> = vec![0xABCD; pad];
    h.extend(indices);
    h.resize(h.len().div_ceil(2) * 2, 0);
    h.chunks(2).map(|p| p[0] | p[1] << 16).collect()
}

/// An engine's mesh in its own buffers (`Tracer::build_from_buffers`):
/// strided vertices with words of the engine's own between them; `u32`
/// indices, `u16` indices at an odd half, no index buffer, and indices in
/// the vertex buffer itself; on the CPU runner and the GPU, with random
/// rays, each against the scan of the triangles the host assembles from
/// the same words; then moved and refit from the buffers; an instanced
/// scene of such meshes against the same scene built from the host's
/// triangles, before and after a mesh's refit. Bad buffers are refused by
/// name.
#[test]
fn tracer_from_an_engines_buffers() {
    use treelet::tracer::{IndexBuffer, IndexFormat, Instance, InstancedTracer, MeshBuffers};
    let seed = fresh_seed();
    let mut backends: Vec<Box<dyn FnMut(u64)>> = vec![Box::new(|seed| engine_buffers(&mut CpuBackend::new(), seed))];
    if let Some(ctx) = gpu() {
        backends.push(Box::new(move |seed| engine_buffers(&mut GpuBackend::new(ctx.clone()), seed)));
    }
    for run in &mut backends {
        run(seed);
    }

    fn engine_buffers<B: Backend>(b: &mut B, seed: u64) {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let (v, n) = (3000, 2000);
        let (words, indices, tris) = engine_mesh(&mut rng, v, n);
        let rs = rays(&mut rng, 2000);
        let adapter = b.adapter();
        let what = |case: &str| format!("{adapter} seed {seed}: {case}");
        let vertices = b.upload("engine vertices", &words).unwrap();
        let u32s = b.upload("engine u32 indices", &indices).unwrap();
        let u16s = b.upload("engine u16 indices", &halves(&indices, 3)).unwrap();
        // An engine's buffers stay its own: out of the backend's pool.
        b.keep(&[&vertices, &u32s, &u16s]);
        let mesh = |indices, vertices, vertex_count| engine_buffers_of::<B>(indices, vertices, vertex_count, n);
        let g: Geometry = (vec![], tris.clone());
        for (case, index) in [
            ("u32 indices", Some(IndexBuffer { buffer: &u32s, offset: 0, format: IndexFormat::U32 })),
            ("u16 indices", Some(IndexBuffer { buffer: &u16s, offset: 6, format: IndexFormat::U16 })),
        ] {
            let tracer = Tracer::build_from_buffers(b, &mesh(index, &vertices, v), Quality::High).unwrap();
            check(&what(case), &tracer.closest_hits(b, &rs).unwrap(), &g, &rs);
        }
        // Indices after the vertices, in the vertex buffer itself.
        let mut both = words.clone();
        let index_offset = both.len() as u64 * 4;
        both.extend(&indices);
        let both = b.upload("engine vertices and indices", &both).unwrap();
        b.keep(&[&both]);
        let one = mesh(Some(IndexBuffer { buffer: &both, offset: index_offset, format: IndexFormat::U32 }), &both, v);
        let tracer = Tracer::build_from_buffers(b, &one, Quality::Fast).unwrap();
        check(&what("indices in the vertex buffer"), &tracer.closest_hits(b, &rs).unwrap(), &g, &rs);

        // No index buffer: three vertices a triangle; then moved, refit from the buffer.
        let mut unindexed = words[..4].to_vec();
        for k in &indices {
            unindexed.extend_from_slice(&words[4 + 7 * *k as usize..11 + 7 * *k as usize]);
        }
        let buffer = b.upload("engine triangle soup", &unindexed).unwrap();
        b.keep(&[&buffer]);
        let mut tracer = Tracer::build_from_buffers(b, &mesh(None, &buffer, 3 * n), Quality::Balanced).unwrap();
        check(&what("no index buffer"), &tracer.closest_hits(b, &rs).unwrap(), &g, &rs);
        let shift = [rng.random_range(-5.0..5.0f32), rng.random_range(-5.0..5.0f32), rng.random_range(-5.0..5.0f32)];
        let mut moved_words = unindexed.clone();
        for k in 0..3 * n {
            for c in 0..3 {
                let w = &mut moved_words[4 + 7 * k + c];
                *w = (f32::from_bits(*w) + shift[c]).to_bits();
            }
        }
        let moved_tris: Vec<Triangle> = moved_words[4..]
            .chunks(21)
            .map(|t| {
                let p = |k: usize| [f32::from_bits(t[7 * k]), f32::from_bits(t[7 * k + 1]), f32::from_bits(t[7 * k + 2])];
                Triangle::new(p(0), p(1), p(2))
            })
            .collect();
        let moved_buffer = b.upload("engine triangle soup, moved", &moved_words).unwrap();
        b.keep(&[&moved_buffer]);
        tracer.refit_from_buffers(b, &mesh(None, &moved_buffer, 3 * n)).unwrap();
        let moved: Geometry = (vec![], moved_tris.clone());
        check(&what("no index buffer, refit"), &tracer.closest_hits(b, &rs).unwrap(), &moved, &rs);
        // Back and forth: from the second refit on, each gathers into the
        // primitives of the update before the last.
        for (case, (source, geometry)) in [(&buffer, &g), (&moved_buffer, &moved), (&buffer, &g)].into_iter().enumerate() {
            tracer.refit_from_buffers(b, &mesh(None, source, 3 * n)).unwrap();
            check(&what(&format!("no index buffer, refit {}", case + 2)), &tracer.closest_hits(b, &rs).unwrap(), geometry, &rs);
        }

        // Instanced: the indexed mesh and the moved soup, placed five times,
        // from the buffers against the same scene built from host triangles
        // (which tests/instances.rs checks against the flattened scan).
        let placed: Vec<Instance> = (0..5u32)
            .map(|k| {
                let (s, c) = (k as f32 * 0.7).sin_cos();
                Instance { mesh: k % 2, transform: [[c, 0.0, s, 30.0 * k as f32 - 60.0], [0.0, 1.0, 0.0, 5.0 * k as f32], [-s, 0.0, c, 10.0]] }
            })
            .collect();
        let meshes = [mesh(Some(IndexBuffer { buffer: &u16s, offset: 6, format: IndexFormat::U16 }), &vertices, v), mesh(None, &buffer, 3 * n)];
        let mut from_buffers = InstancedTracer::build_from_buffers(b, &meshes, &placed, Quality::High).unwrap();
        let mut from_host = InstancedTracer::build(b, &[&tris, &tris], &placed, Quality::High).unwrap();
        let same = |case: &str, a: &[RayHit], h: &[RayHit]| {
            let hits = a.iter().filter(|x| x.is_hit()).count();
            assert!(hits > a.len() / 20, "{}: only {hits} hits", what(case));
            for (k, (x, y)) in a.iter().zip(h).enumerate() {
                assert_eq!((x.prim, x.instance), (y.prim, y.instance), "{}: ray {k}: from buffers {x:?}, from the host {y:?}", what(case));
                assert!(x.t == y.t || (x.t - y.t).abs() <= 1e-5 * y.t.max(1.0), "{}: ray {k}: {x:?} against {y:?}", what(case));
            }
        };
        same("instanced", &from_buffers.closest_hits(b, &rs).unwrap(), &from_host.closest_hits(b, &rs).unwrap());
        from_buffers.refit_mesh_from_buffers(b, 1, &mesh(None, &moved_buffer, 3 * n)).unwrap();
        from_host.refit_mesh(b, 1, &moved_tris).unwrap();
        same("instanced, mesh 1 refit", &from_buffers.closest_hits(b, &rs).unwrap(), &from_host.closest_hits(b, &rs).unwrap());

        // Refused, by name.
        let mut bad_index = indices.clone();
        bad_index[3 * 17 + 1] = v as u32 + 5;
        let bad_index = b.upload("bad indices", &bad_index).unwrap();
        let mut nan = words.clone();
        nan[4 + 7 * indices[3 * 29 + 2] as usize + 1] = f32::NAN.to_bits();
        let nan = b.upload("NaN vertex", &nan).unwrap();
        let short = b.upload("short index buffer", &indices[..3 * n - 2]).unwrap();
        b.keep(&[&bad_index, &nan, &short]);
        let u32_index = |buffer| Some(IndexBuffer { buffer, offset: 0, format: IndexFormat::U32 });
        let cases = [
            (mesh(u32_index(&bad_index), &vertices, v), "triangle 17 names a vertex past the 3000 vertices".to_string()),
            (mesh(u32_index(&u32s), &nan, v), format!("triangle {} has a coordinate that is not finite", first_user(&indices, indices[3 * 29 + 2]))),
            (MeshBuffers { vertex_stride: 10, ..mesh(u32_index(&u32s), &vertices, v) }, "vertex stride 10".to_string()),
            (mesh(u32_index(&u32s), &vertices, v + 10), "past the vertex buffer's".to_string()),
            (mesh(u32_index(&short), &vertices, v), "past the index buffer's".to_string()),
            (mesh(None, &vertices, v), "need 6000 vertices, not 3000".to_string()),
        ];
        for (m, expected) in cases {
            let e = format!("{:#}", Tracer::build_from_buffers(b, &m, Quality::Fast).err().expect(&expected));
            assert!(e.contains(&expected), "{}: expected {expected:?}, got {e}", b.adapter());
        }
    }

    /// The mesh of `n` triangles with the test's vertex layout (7 words a
    /// vertex after 4).
    fn engine_buffers_of<'a, B: Backend>(indices: Option<IndexBuffer<'a, B>>, vertices: &'a B::Buffer, vertex_count: usize, n: usize) -> MeshBuffers<'a, B> {
        MeshBuffers { vertices, vertex_offset: 16, vertex_stride: 28, vertex_count: vertex_count as u32, indices, triangle_count: n as u32 }
    }

    /// The first triangle that uses vertex `k`.
    fn first_user(indices: &[u32], k: u32) -> usize {
        indices.iter().position(|&i| i == k).unwrap() / 3
    }
}

/// Rays given as columns through `closest_hits_with` and `occluded_with`
/// (what the Python package does: written straight into the device's upload
/// memory, hits read where they land) give exactly the slice API's answers,
/// each ray's once and in order, on batches of several sizes through the
/// same kept staging memory; a bad ray in the middle is an error naming it,
/// and the next batch is unharmed.
#[test]
fn rays_as_columns_give_the_slice_apis_answers() {
    use treelet::tracer::RayQueries;
    let seed = fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let g = geometry(&mut rng, 100, 900);
    let all = rays(&mut rng, 5000);
    fn run<B: Backend>(b: &mut B, g: &Geometry, all: &[Ray], seed: u64) {
        let t = Tracer::build(b, &g.0, &g.1, Quality::Fast).unwrap();
        let what = format!("{} seed {seed}", b.adapter());
        // Larger, smaller, then larger again than the kept staging.
        for n in [3000, 17, 1, 0, 5000, 1025] {
            let rays = &all[..n];
            let columns: [Vec<f32>; 4] = [
                rays.iter().flat_map(|r| r.origin).collect(),
                rays.iter().flat_map(|r| r.dir).collect(),
                rays.iter().map(|r| r.t_min).collect(),
                rays.iter().map(|r| r.t_max).collect(),
            ];
            let ray = |k: usize| Ray {
                origin: columns[0][3 * k..3 * k + 3].try_into().unwrap(),
                dir: columns[1][3 * k..3 * k + 3].try_into().unwrap(),
                t_min: columns[2][k],
                t_max: columns[3][k],
            };
            let mut hits = Vec::new();
            t.closest_hits_with(b, n, ray, |k, h| {
                assert_eq!(k, hits.len(), "{what}: hit {k} out of order");
                hits.push(h)
            })
            .unwrap();
            assert_eq!(hits, t.closest_hits(b, rays).unwrap(), "{what}: {n} rays");
            if n > 100 {
                check(&format!("{what}, {n} rays as columns"), &hits, g, rays);
            }
            let mut occluded = vec![None; n];
            t.occluded_with(b, n, ray, |k, o| occluded[k] = Some(o)).unwrap();
            let occluded: Vec<bool> = occluded.into_iter().map(|o| o.expect("every ray answered")).collect();
            assert_eq!(occluded, t.occluded(b, rays).unwrap(), "{what}: {n} rays");
            // Closest hits stop at t_max too: occluded exactly where one was found.
            assert_eq!(occluded, hits.iter().map(RayHit::is_hit).collect::<Vec<_>>(), "{what}: {n} rays");
        }
        let bad = |k: usize| Ray { t_min: if k == 1500 { -1.0 } else { 0.0 }, ..all[k] };
        let err = t.closest_hits_with(b, 3000, bad, |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("ray 1500") && err.contains("t_min"), "{what}: {err}");
        let mut hits = Vec::new();
        t.closest_hits_with(b, 3000, |k| all[k], |_, h| hits.push(h)).unwrap();
        assert_eq!(hits, t.closest_hits(b, &all[..3000]).unwrap(), "{what}: after an error");
    }
    run(&mut CpuBackend::new(), &g, &all, seed);
    if let Some(ctx) = gpu() {
        run(&mut GpuBackend::new(ctx), &g, &all, seed);
    }
}
