//! Instanced scenes (`treelet::tracer::InstancedTracer`): random meshes
//! placed many times with random rotations, scales (mirrors too), shears
//! and translations, traced on the GPU and the CPU runner, against the same
//! scene flattened into one mesh (every copy's triangles transformed on the
//! host, in f64) and traced by a plain `Tracer`; occlusion against closest
//! hits; top-level rebuilds and mesh refits; errors by name.
use glam::{Mat3, Quat, Vec3};
use rand::{Rng, SeedableRng};
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::tracer::{Instance, InstancedTracer, Quality, Ray, RayHit, Tracer};
use treelet_core::geometry::triangle::Triangle;
use treelet_tests::{fresh_seed, gpu};

/// Meshes of random small triangles in the cube [-1, 1]^3.
fn meshes(rng: &mut impl Rng, sizes: &[usize]) -> Vec<Vec<Triangle>> {
    sizes
        .iter()
        .map(|&n| {
            (0..n)
                .map(|_| {
                    let mut p = || {
                        Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
                    };
                    let a = p();
                    let (b, c) = (a + p() * 0.3, a + p() * 0.3);
                    Triangle::new(a.into(), b.into(), c.into())
                })
                .collect()
        })
        .collect()
}

/// A random rotation, scale (unequal per axis, one in four mirrored), a
/// little shear, and a translation within [0, 40]^3.
fn transform(rng: &mut impl Rng) -> [[f32; 4]; 3] {
    let q = Quat::from_xyzw(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    )
    .normalize();
    let mut scale = Vec3::new(rng.random_range(0.5..3.0), rng.random_range(0.5..3.0), rng.random_range(0.5..3.0));
    if rng.random_range(0..4) == 0 {
        scale.x = -scale.x;
    }
    let shear = Mat3::from_cols(Vec3::X, Vec3::new(rng.random_range(-0.3..0.3), 1.0, 0.0), Vec3::Z);
    let m = Mat3::from_quat(q) * shear * Mat3::from_diagonal(scale);
    let t = Vec3::new(rng.random_range(0.0..40.0), rng.random_range(0.0..40.0), rng.random_range(0.0..40.0));
    [0, 1, 2].map(|r| [m.col(0)[r], m.col(1)[r], m.col(2)[r], t[r]])
}

fn instances(rng: &mut impl Rng, n: usize, meshes: usize) -> Vec<Instance> {
    (0..n).map(|_| Instance { mesh: rng.random_range(0..meshes as u32), transform: transform(rng) }).collect()
}

/// Point `v` of a mesh placed by `m`, in f64 then rounded.
fn place(m: &[[f32; 4]; 3], v: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|r| {
        (m[r][0] as f64 * v[0] as f64 + m[r][1] as f64 * v[1] as f64 + m[r][2] as f64 * v[2] as f64 + m[r][3] as f64)
            as f32
    })
}

/// The scene as one mesh, and for each of its triangles (instance, triangle in the mesh).
fn flatten(meshes: &[Vec<Triangle>], instances: &[Instance]) -> (Vec<Triangle>, Vec<(u32, u32)>) {
    let mut out = Vec::new();
    let mut from = Vec::new();
    for (k, i) in instances.iter().enumerate() {
        for (p, t) in meshes[i.mesh as usize].iter().enumerate() {
            out.push(Triangle::new(place(&i.transform, t.v0), place(&i.transform, t.v1), place(&i.transform, t.v2)));
            from.push((k as u32, p as u32));
        }
    }
    (out, from)
}

fn rays(rng: &mut impl Rng, n: usize) -> Vec<Ray> {
    (0..n)
        .map(|k| {
            let o = [rng.random_range(-5.0..45.0), rng.random_range(-5.0..45.0), rng.random_range(-5.0..45.0)];
            let d = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
            let t_min = if k % 3 == 0 { 2.0 } else { 0.0 };
            Ray { origin: o, dir: d, t_min, t_max: if k % 4 == 0 { 15.0 } else { f32::INFINITY } }
        })
        .collect()
}

/// The instanced hits against the flattened scene's: the same instance and
/// triangle (or another at the same distance, a tie, for at most 1%) and
/// the same distance within rounding, but for at most 0.3% of the rays (the flattened triangles are rounded after the transform, the
/// instanced ray before its mesh's test: a ray within rounding of an edge
/// may pass on either side). Each hit's barycentrics give its point on the
/// placed triangle, and its normal is the placed triangle's.
fn check(what: &str, hits: &[RayHit], flat: &[RayHit], scene: &(Vec<Triangle>, Vec<(u32, u32)>), rays: &[Ray], min_hits: usize) {
    assert_eq!(hits.len(), rays.len());
    let (mut differ, mut ties, mut hit) = (0, 0, 0);
    for ((r, h), f) in rays.iter().zip(hits).zip(flat) {
        let expected = f.is_hit().then(|| scene.1[f.prim as usize]);
        let got = h.is_hit().then_some((h.instance, h.prim));
        if got != expected {
            // Another triangle at the same distance: a squashed copy's
            // triangles lie within rounding of one plane, and which one a
            // ray meets first is the rounding's (seed 8323507393793727333:
            // 13 rays in 4 000, each within 3e-7 of the other's distance).
            if h.is_hit() && f.is_hit() && (h.t - f.t).abs() <= 1e-5 * f.t.max(1.0) {
                ties += 1;
            } else {
                differ += 1;
            }
            continue;
        }
        if !h.is_hit() {
            continue;
        }
        hit += 1;
        let t = &scene.0[f.prim as usize];
        let (a, b, c) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
        // A triangle's plane rounded by d moves a hit along the ray by
        // d / cos(angle to the normal): grazing hits get that much more room
        // (a seed failed here at 1e-4 flat, ray not kept; grazing rays are
        // where a flat room is too small).
        let cos = Vec3::from(r.dir).normalize().dot((b - a).cross(c - a).normalize()).abs().max(1e-3);
        let room = 1e-4 * f.t.max(1.0) / cos;
        assert!((h.t - f.t).abs() <= room, "{what}: ray {r:?}: instanced {h:?}, flattened {f:?}");
        let [b1, b2] = h.barycentrics;
        let p = a * (1.0 - b1 - b2) + b * b1 + c * b2;
        let x = Vec3::from(r.origin) + Vec3::from(r.dir).normalize() * h.t;
        assert!((p - x).length() < 1e-3 * (1.0 + x.length()), "{what}: ray {r:?}: {h:?} at {x}, barycentrics give {p}");
        let n = Vec3::from(h.normal);
        assert!((n - (b - a).cross(c - a).normalize()).length() < 1e-3, "{what}: ray {r:?}: normal of {h:?}");
    }
    assert!(differ * 1000 <= 3 * rays.len(), "{what}: {differ} of {} rays differ from the flattened scene", rays.len());
    assert!(ties * 100 <= rays.len(), "{what}: {ties} of {} rays hit another triangle at the same distance", rays.len());
    assert!(hit >= min_hits, "{what}: only {hit} of {} rays hit: the test would prove little", rays.len());
}

/// Builds, traces, moves the instances (top level only) and refits a mesh,
/// each checked against its flattened scene; returns every hit.
fn round_trip<B: Backend>(b: &mut B, seed: u64, quality: Quality) -> Vec<RayHit> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut m = meshes(&mut rng, &[400, 60, 1]);
    let placed = instances(&mut rng, 150, m.len());
    let rays = rays(&mut rng, 4000);
    let what = format!("{} {quality:?} seed {seed}", b.adapter());
    let refs: Vec<&[Triangle]> = m.iter().map(|m| m.as_slice()).collect();
    let mut scene = InstancedTracer::build(b, &refs, &placed, quality).unwrap();
    let mut all = Vec::new();
    let mut check_now =
        |b: &mut B, scene: &InstancedTracer<B>, m: &[Vec<Triangle>], placed: &[Instance], stage: &str| {
            let flat = flatten(m, placed);
            let flat_hits = Tracer::build(b, &[], &flat.0, Quality::Fast).unwrap().closest_hits(b, &rays).unwrap();
            let hits = scene.closest_hits(b, &rays).unwrap();
            // At least 2.5% of the rays hit (seed 16178518003258987997 drew 90
            // instances that 191 of 4000 met, under the 5% asked before).
            check(&format!("{what}, {stage}"), &hits, &flat_hits, &flat, &rays, rays.len() / 40);
            // Occlusion: exactly the rays whose closest hit is within t_max.
            let occluded = scene.occluded(b, &rays).unwrap();
            for ((r, h), o) in rays.iter().zip(&hits).zip(&occluded) {
                assert_eq!(*o, h.is_hit(), "{what}, {stage}: ray {r:?}: occluded {o}, closest hit {h:?}");
            }
            all.extend(hits);
        };
    check_now(b, &scene, &m, &placed, "built");
    // Next frame: other instances, fewer of them; the meshes' trees stay.
    let moved = instances(&mut rng, 90, m.len());
    scene.set_instances(b, &moved).unwrap();
    check_now(b, &scene, &m, &moved, "instances moved");
    // Mesh 0 deforms: its tree is refit, the top level rebuilt.
    for t in &mut m[0] {
        for v in [&mut t.v0, &mut t.v1, &mut t.v2] {
            v[1] += 0.5 * v[0].sin();
        }
    }
    scene.refit_mesh(b, 0, &m[0]).unwrap();
    check_now(b, &scene, &m, &moved, "mesh refit");
    // More instances than the top level had room for: the meshes are
    // gathered again behind a larger one.
    let more = instances(&mut rng, 700, m.len());
    scene.set_instances(b, &more).unwrap();
    check_now(b, &scene, &m, &more, "instances grew");
    all
}

#[test]
fn instanced_scenes_hit_what_the_flattened_scene_hits() {
    let seed = fresh_seed();
    for quality in [Quality::Fast, Quality::High] {
        let mut b = CpuBackend::new();
        let cpu = round_trip(&mut b, seed, quality);
        // Builds prepared every pipeline the scene then used.
        assert!(b.kernels_not_prepared().is_empty(), "{quality:?}: not built ahead: {:?}", b.kernels_not_prepared());
        if let Some(ctx) = gpu() {
            let gpu = round_trip(&mut GpuBackend::new(ctx), seed, quality);
            // Same kernels, same trees: the same hits but for rounding.
            let same = cpu.iter().zip(&gpu).filter(|(c, g)| (c.instance, c.prim) == (g.instance, g.prim)).count();
            assert!(
                same as f64 >= 0.999 * cpu.len() as f64,
                "{quality:?} seed {seed}: GPU and CPU agree on {same} hits of {}",
                cpu.len()
            );
        }
    }
}

/// Copies an engine places in the same place (here 40 of each of three
/// placements: more than a sort's tie run, more than a subgroup) hit what
/// one copy of each hits: the same triangle of the mesh at the same
/// distance (which of the coincident copies is reported is the walk's
/// tie-break), and every other ray misses.
fn coincident<B: Backend>(b: &mut B, seed: u64) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let m = meshes(&mut rng, &[300]);
    let once = instances(&mut rng, 3, 1);
    let repeated: Vec<Instance> = once.iter().flat_map(|i| std::iter::repeat_n(*i, 40)).collect();
    // Rays at the copies (random ones mostly miss three of them).
    let rays: Vec<Ray> = rays(&mut rng, 3000)
        .into_iter()
        .map(|r| {
            let at = once[rng.random_range(0..3)].transform.map(|row| row[3] + rng.random_range(-1.5..1.5));
            Ray { dir: [0, 1, 2].map(|k| at[k] - r.origin[k]), ..r }
        })
        .collect();
    let refs: Vec<&[Triangle]> = m.iter().map(|m| m.as_slice()).collect();
    let what = format!("{} seed {seed}", b.adapter());
    let single = InstancedTracer::build(b, &refs, &once, Quality::Fast).unwrap().closest_hits(b, &rays).unwrap();
    let scene = InstancedTracer::build(b, &refs, &repeated, Quality::Fast).unwrap();
    let hits = scene.closest_hits(b, &rays).unwrap();
    let occluded = scene.occluded(b, &rays).unwrap();
    let mut hit = 0;
    for (k, ((h, s), o)) in hits.iter().zip(&single).zip(&occluded).enumerate() {
        assert_eq!(h.is_hit(), s.is_hit(), "{what}: ray {k} {:?}: coincident copies {h:?}, one copy {s:?}", rays[k]);
        assert_eq!(*o, s.is_hit(), "{what}: ray {k}: occluded {o}, one copy {s:?}");
        if h.is_hit() {
            hit += 1;
            assert_eq!((h.prim, h.t, h.instance / 40), (s.prim, s.t, s.instance), "{what}: ray {k}: {h:?} against one copy's {s:?}");
        }
    }
    assert!(hit >= rays.len() / 20, "{what}: only {hit} rays hit");
}

#[test]
fn coincident_copies_hit_what_one_copy_hits() {
    let seed = fresh_seed();
    coincident(&mut CpuBackend::new(), seed);
    if let Some(ctx) = gpu() {
        coincident(&mut GpuBackend::new(ctx), seed);
    }
}

/// One copy in place (the identity) traces exactly as the mesh's own tracer:
/// the ray is taken into the mesh's space without rounding.
fn in_place<B: Backend>(b: &mut B, seed: u64) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let m = meshes(&mut rng, &[500]);
    let rays: Vec<Ray> =
        rays(&mut rng, 2000).into_iter().map(|r| Ray { origin: r.origin.map(|x| x / 20.0 - 1.0), ..r }).collect();
    let plain = Tracer::build(b, &[], &m[0], Quality::High).unwrap().closest_hits(b, &rays).unwrap();
    let placed =
        InstancedTracer::build(b, &[&m[0]], &[Instance { mesh: 0, transform: Instance::IDENTITY }], Quality::High)
            .unwrap();
    let hits = placed.closest_hits(b, &rays).unwrap();
    let mut n = 0;
    for ((r, p), h) in rays.iter().zip(&plain).zip(&hits) {
        assert_eq!(h, p, "{} seed {seed}: ray {r:?}", b.adapter());
        n += p.is_hit() as usize;
    }
    assert!(n > rays.len() / 10, "seed {seed}: only {n} hits");
}

#[test]
fn one_instance_in_place_is_the_mesh_itself() {
    let seed = fresh_seed();
    in_place(&mut CpuBackend::new(), seed);
    if let Some(ctx) = gpu() {
        in_place(&mut GpuBackend::new(ctx), seed);
    }
}

#[test]
fn instanced_tracer_rejects_bad_input_by_name() {
    let b = &mut CpuBackend::new();
    let tri = [Triangle::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])];
    // Each is the caller's input, and typed so.
    let err = |r: treelet::error::Result<InstancedTracer<CpuBackend>>| {
        let e = r.err().expect("an error");
        assert_eq!(e.kind(), treelet::error::ErrorKind::Input, "{e}");
        e.to_string()
    };
    let at = |k: u32| Instance::translated(k, [0.0, 0.0, 1.0]);
    let e = err(InstancedTracer::build(b, &[&tri], &[at(0), at(3)], Quality::Fast));
    assert!(e.contains("instances[1] places mesh 3, but there are 1 meshes"), "{e}");
    let flat = Instance { mesh: 0, transform: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]] };
    let e = err(InstancedTracer::build(b, &[&tri], &[at(0), flat], Quality::Fast));
    assert!(e.contains("instances[1]") && e.contains("singular"), "{e}");
    let nan = Instance { mesh: 0, transform: [[f32::NAN, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]] };
    let e = err(InstancedTracer::build(b, &[&tri], &[nan], Quality::Fast));
    assert!(e.contains("instances[0]") && e.contains("non-finite"), "{e}");
    let e = err(InstancedTracer::build(b, &[&tri, &[]], &[at(0)], Quality::Fast));
    assert!(e.contains("mesh 1 has no triangles"), "{e}");
    let bad = [Triangle::new([0.0, f32::INFINITY, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])];
    let e = err(InstancedTracer::build(b, &[&tri, &bad], &[at(0)], Quality::Fast));
    assert!(e.contains("mesh 1") && e.contains("triangle 0"), "{e}");
    let shapes = [tri[0], Triangle::disk([0.0; 3], [0.0, 0.0, 1.0], 1.0)];
    let e = err(InstancedTracer::build(b, &[&tri, &shapes], &[at(0)], Quality::Fast));
    assert!(e.contains("mesh 1") && e.contains("triangle 1") && e.contains("triangles only"), "{e}");
    // No instances: every ray misses, nothing is occluded.
    let mut scene = InstancedTracer::build(b, &[&tri], &[], Quality::Fast).unwrap();
    let ray = Ray::new([0.2, 0.2, -1.0], [0.0, 0.0, 1.0]);
    assert_eq!(scene.closest_hits(b, &[ray]).unwrap(), vec![RayHit::MISS]);
    assert_eq!(scene.occluded(b, &[ray]).unwrap(), vec![false]);
    scene.set_instances(b, &[at(0)]).unwrap();
    assert_eq!(scene.closest_hits(b, &[ray]).unwrap()[0].t, 2.0);
    let e = scene.refit_mesh(b, 2, &tri).unwrap_err();
    assert_eq!(e.kind(), treelet::error::ErrorKind::Input, "{e}");
    assert!(e.to_string().contains("refit of mesh 2: there are 1 meshes"), "{e}");
    let e = format!("{:#}", scene.refit_mesh(b, 0, &[tri[0], tri[0]]).unwrap_err());
    assert!(e.contains("mesh 0") && e.contains("refit with 0 spheres and 2 triangles"), "{e}");
    let e = format!("{:#}", scene.refit_mesh(b, 0, &[Triangle::parallelogram([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])]).unwrap_err());
    assert!(e.contains("mesh 0") && e.contains("triangles only"), "{e}");
}

/// Stiff transforms: copies squashed a hundred-thousandfold along one axis, then
/// sheared and turned (the inverse taken on the device in f32, the
/// flattened scene's points in f64).
fn stiff<B: Backend>(b: &mut B, seed: u64) -> Vec<RayHit> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let m = meshes(&mut rng, &[300]);
    let placed: Vec<Instance> = (0..80)
        .map(|k| {
            let mut transform = transform(&mut rng);
            for row in &mut transform {
                row[k % 3] *= 1e-5;
            }
            Instance { mesh: 0, transform }
        })
        .collect();
    let rays = rays(&mut rng, 4000);
    let scene = InstancedTracer::build(b, &[&m[0]], &placed, Quality::Fast).unwrap();
    let flat = flatten(&m, &placed);
    let flat_hits = Tracer::build(b, &[], &flat.0, Quality::Fast).unwrap().closest_hits(b, &rays).unwrap();
    let hits = scene.closest_hits(b, &rays).unwrap();
    // The squashed copies are thin: random rays hit them seldom (5% or a
    // little less, for some seeds: a 5% floor failed in CI).
    check(&format!("{} stiff, seed {seed}", b.adapter()), &hits, &flat_hits, &flat, &rays, rays.len() / 100);
    hits
}

#[test]
fn stiff_transforms_hit_what_the_flattened_scene_hits() {
    let seed = fresh_seed();
    let cpu = stiff(&mut CpuBackend::new(), seed);
    if let Some(ctx) = gpu() {
        let gpu = stiff(&mut GpuBackend::new(ctx), seed);
        // Squashed copies stack their triangles a hundred-thousandth apart:
        // where the device's fused multiply-adds round a ray's distances
        // differently, it may hit another triangle (or copy) at the same
        // distance (on the H100, 5 to 8 rays in 4 000 for some seeds). What
        // must agree is whether a ray hits and where.
        let same = cpu
            .iter()
            .zip(&gpu)
            .filter(|(c, g)| {
                (c.instance, c.prim) == (g.instance, g.prim) || (c.is_hit() && g.is_hit() && (c.t - g.t).abs() <= 1e-4 * c.t.max(1.0))
            })
            .count();
        assert!(
            same as f64 >= 0.999 * cpu.len() as f64,
            "seed {seed}: GPU and CPU agree on {same} hits of {}",
            cpu.len()
        );
        let exact = cpu.iter().zip(&gpu).filter(|(c, g)| (c.instance, c.prim) == (g.instance, g.prim)).count();
        assert!(exact as f64 >= 0.99 * cpu.len() as f64, "seed {seed}: GPU and CPU hit the same triangle for {exact} rays of {}", cpu.len());
    }
}

/// A glTF file placing `meshes` by `nodes` (each: a mesh, rotation
/// quaternion, scale, translation, and the index of a parent node or
/// none), the meshes' positions unindexed in one `.bin` beside it.
fn write_gltf(dir: &std::path::Path, meshes: &[Vec<Triangle>], nodes: &[(usize, Quat, Vec3, Vec3, Option<usize>)]) -> std::path::PathBuf {
    let mut bin = Vec::new();
    let (mut views, mut accessors, mut gltf_meshes) = (Vec::new(), Vec::new(), Vec::new());
    for (k, m) in meshes.iter().enumerate() {
        let offset = bin.len();
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for v in m.iter().flat_map(|t| [t.v0, t.v1, t.v2]) {
            for a in 0..3 {
                (lo[a], hi[a]) = (lo[a].min(v[a]), hi[a].max(v[a]));
                bin.extend(v[a].to_le_bytes());
            }
        }
        views.push(format!(r#"{{"buffer": 0, "byteOffset": {offset}, "byteLength": {}}}"#, bin.len() - offset));
        accessors.push(format!(
            r#"{{"bufferView": {k}, "componentType": 5126, "count": {}, "type": "VEC3", "min": {lo:?}, "max": {hi:?}}}"#,
            3 * m.len()
        ));
        gltf_meshes.push(format!(r#"{{"primitives": [{{"attributes": {{"POSITION": {k}}}}}]}}"#));
    }
    let node_json: Vec<String> = nodes
        .iter()
        .enumerate()
        .map(|(i, (mesh, q, s, t, _))| {
            let children: Vec<usize> = (0..nodes.len()).filter(|&c| nodes[c].4 == Some(i)).collect();
            format!(
                r#"{{"mesh": {mesh}, "rotation": {:?}, "scale": {:?}, "translation": {:?}, "children": {children:?}}}"#,
                q.to_array(),
                s.to_array(),
                t.to_array()
            )
        })
        .collect();
    let roots: Vec<usize> = (0..nodes.len()).filter(|&i| nodes[i].4.is_none()).collect();
    std::fs::write(dir.join("placed.bin"), &bin).unwrap();
    let text = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": {roots:?}}}], "nodes": [{}], "meshes": [{}],
  "buffers": [{{"uri": "placed.bin", "byteLength": {}}}], "bufferViews": [{}], "accessors": [{}]}}"#,
        node_json.join(", "),
        gltf_meshes.join(", "),
        bin.len(),
        views.join(", "),
        accessors.join(", ")
    );
    let path = dir.join("placed.gltf");
    std::fs::write(&path, text).unwrap();
    path
}

/// A glTF file with two meshes placed by 60 nodes (random rotations,
/// scales, translations; a third of them children of others), loaded with
/// its instances kept and traced through them, against the same file
/// loaded flattened (what `render` takes) and traced as one mesh; and a
/// JSON scene file placing a mesh file by reference.
fn scene_files<B: Backend>(b: &mut B, seed: u64) {
    use treelet::scene::instanced;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let m = meshes(&mut rng, &[300, 40]);
    let nodes: Vec<_> = (0..60)
        .map(|i| {
            let q = Quat::from_xyzw(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 1.0).normalize();
            let s = Vec3::new(rng.random_range(1.0..3.0), rng.random_range(1.0..3.0), rng.random_range(1.0..3.0));
            let t = Vec3::new(rng.random_range(0.0..30.0), rng.random_range(0.0..30.0), rng.random_range(0.0..30.0));
            let parent = (i % 3 == 2).then(|| rng.random_range(0..i));
            (rng.random_range(0..2usize), q, if parent.is_some() { s * 0.5 } else { s }, if parent.is_some() { t * 0.2 } else { t }, parent)
        })
        .collect();
    let dir = std::env::temp_dir().join(format!("treelet-placed-{}-{seed}-{}", std::process::id(), b.adapter().len()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = write_gltf(&dir, &m, &nodes);
    let what = format!("{} seed {seed}", b.adapter());
    let scene = instanced::InstancedScene::load(&path).unwrap();
    assert_eq!((scene.meshes.len(), scene.instances.len()), (2, 60), "{what}: each mesh once, a copy per node");
    let flat = treelet::scene::Scene::from_spec(path.to_str().unwrap()).unwrap();
    let from: Vec<(u32, u32)> = scene
        .instances
        .iter()
        .enumerate()
        .flat_map(|(k, i)| (0..scene.meshes[i.mesh as usize].triangles.len() as u32).map(move |p| (k as u32, p)))
        .collect();
    assert_eq!(flat.triangles.len(), from.len(), "{what}: the flattened file has every copy's triangles");
    let rays = rays(&mut rng, 4000);
    let placed = InstancedTracer::build_scene(b, &scene, Quality::High).unwrap();
    let hits = placed.closest_hits(b, &rays).unwrap();
    let flat_hits = Tracer::build(b, &[], &flat.triangles, Quality::Fast).unwrap().closest_hits(b, &rays).unwrap();
    // 60 copies of small meshes: a few percent of random rays hit.
    check(&format!("{what}, glTF"), &hits, &flat_hits, &(flat.triangles.clone(), from), &rays, rays.len() / 50);
    std::fs::remove_dir_all(&dir).ok();

    // A scene file: the repository's pyramid named once and placed twice
    // more, beside a parallelogram (not instanced: refused by the tracer,
    // by name).
    let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes");
    let text = r#"{"camera": {"origin": [0, 0, 60], "direction": [0, 0, -1]},
      "materials": {"w": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}, "g": {"type": "glass", "color": [1, 1, 1]}},
      "meshes": [{"path": "pyramid.obj", "material": "w", "name": "p", "scale": [10, 10, 10]}],
      "instances": [{"mesh": "p", "material": "g", "scale": [5, 5, 5], "rotate": [0, 45, 0], "translate": [20, 0, 0]},
                    {"mesh": "p", "scale": [8, -8, 8], "translate": [-20, 5, 0]}]}"#;
    let scene = treelet::scene::file::parse_instanced_in(text, "placed.json", std::path::Path::new(scenes)).unwrap();
    assert_eq!((scene.meshes.len(), scene.instances.len()), (1, 3), "{what}: the pyramid read once, placed three times");
    let flat = scene.clone().flatten().unwrap();
    let n = scene.meshes[0].triangles.len();
    assert_eq!(flat.triangles.len(), 3 * n);
    assert!(flat.materials[..n].iter().chain(&flat.materials[2 * n..]).all(|m| m.kind == treelet_core::geometry::buffers::DIFFUSE));
    assert!(flat.materials[n..2 * n].iter().all(|m| m.kind == treelet_core::geometry::buffers::GLASS), "{what}: the instance's own material");
    let from: Vec<(u32, u32)> = (0..3).flat_map(|k| (0..n as u32).map(move |p| (k, p))).collect();
    let rays: Vec<Ray> = (0..2000)
        .map(|_| {
            let o = [rng.random_range(-30.0..30.0), rng.random_range(-10.0..15.0), 40.0];
            Ray::new(o, [rng.random_range(-0.2..0.2), rng.random_range(-0.2..0.2), -1.0])
        })
        .collect();
    let placed = InstancedTracer::build_scene(b, &scene, Quality::Fast).unwrap();
    let hits = placed.closest_hits(b, &rays).unwrap();
    let flat_hits = Tracer::build(b, &[], &flat.triangles, Quality::Fast).unwrap().closest_hits(b, &rays).unwrap();
    check(&format!("{what}, scene file"), &hits, &flat_hits, &(flat.triangles.clone(), from), &rays, rays.len() / 20);
    let with_shape = text.replace(r#""instances""#, r#""parallelograms": [{"corner": [0, 0, -5], "edges": [[1, 0, 0], [0, 1, 0]], "material": "w"}], "instances""#);
    let scene = treelet::scene::file::parse_instanced_in(&with_shape, "shape.json", std::path::Path::new(scenes)).unwrap();
    let e = format!("{:#}", InstancedTracer::build_scene(b, &scene, Quality::Fast).err().expect("refused"));
    assert!(e.contains("shape.json") && e.contains("triangles only"), "{e}");
}

#[test]
fn scene_files_place_meshes_as_instances() {
    let seed = fresh_seed();
    scene_files(&mut CpuBackend::new(), seed);
    if let Some(ctx) = gpu() {
        scene_files(&mut GpuBackend::new(ctx), seed);
    }
}

/// Mean over pixels and channels of `|a - b|`, and the share of pixels
/// whose channels differ by more than `tol` (relative to 1 + value).
fn image_difference(a: &[[f32; 3]], b: &[[f32; 3]], tol: f32) -> (f64, f64) {
    let mean = a.iter().zip(b).map(|(x, y)| (0..3).map(|k| (x[k] - y[k]).abs() as f64).sum::<f64>()).sum::<f64>() / (3 * a.len()) as f64;
    let off = a.iter().zip(b).filter(|(x, y)| (0..3).any(|k| (x[k] - y[k]).abs() > tol * (1.0 + y[k].abs()))).count();
    (mean, off as f64 / a.len() as f64)
}

/// `render` keeps the copies of `scenes/pyramids.json` (one pyramid placed
/// five times, in glass, mirror and three diffuse materials, one upside
/// down under the ceiling) placed, and renders what the same file
/// flattened renders, on the CPU runner, with next-event estimation and
/// with light paths for caustics (traced from the lamp through the glass
/// and mirror copies: a copy whose light paths went missing would leave
/// its caustics out of the placed image only); the GPU renders it as the CPU
/// runner does, within the rounding that sends a few paths elsewhere. A
/// scene of copies alone (no primitives of its own) renders too.
#[test]
fn instances_render_what_the_flattened_scene_renders() {
    use treelet::render::{render, Integrator, RenderSettings};
    let seed = fresh_seed() as u32;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/pyramids.json");
    let placed = treelet::scene::Scene::for_render(path).unwrap();
    let flat = treelet::scene::Scene::from_spec(path).unwrap();
    let copies = placed.instances.as_ref().expect("the repeated pyramid is kept as instances");
    assert_eq!((copies.meshes.len(), copies.instances.len()), (1, 5));
    assert_eq!(placed.triangles.len() as u64 + copies.triangles(), flat.triangles.len() as u64, "the flattened file has every copy's triangles");
    let settings = RenderSettings {
        width: 64,
        height: 48,
        spp: 16,
        seed,
        accel: treelet::bvh::tree::Accel::Auto,
        layout: treelet::bvh::layout::Layout::Auto,
        kernel: treelet::render::variant::KernelChoice::Auto,
        integrator: Integrator::Nee,
        sampler: treelet::render::Sampler::Sobol,
        error_each_pass: false,
        first_sample: 0,
    };
    let mut cpu = CpuBackend::new();
    // Next-event estimation, and with light paths (the glass and mirror
    // copies' caustics, traced from the lamp through the copies).
    for integrator in [Integrator::Nee, Integrator::Caustics] {
        let settings = RenderSettings { integrator, ..settings };
        let placed_cpu = render(&mut cpu, &placed, &settings, None, |_| {}).unwrap();
        assert!(placed_cpu.plan.instanced && placed_cpu.plan.kernel == "instanced", "{:?}", placed_cpu.plan.kernel);
        let flat_cpu = render(&mut cpu, &flat, &settings, None, |_| {}).unwrap();
        let brightness = flat_cpu.image.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / (3 * flat_cpu.image.pixels.len()) as f64;
        assert!(brightness > 0.05, "the room is lit: mean {brightness}");
        // The same paths: a hit point rounds differently in a copy's own
        // space (no face of a copy lies in another's plane: coplanar faces
        // would tie by rounding).
        let (mean, off) = image_difference(&placed_cpu.image.pixels, &flat_cpu.image.pixels, 1e-2);
        let name = integrator.name();
        assert!(mean < 1e-3 * brightness && off < 0.01, "seed {seed}, {name}: placed against flattened on the CPU runner: mean difference {mean} (brightness {brightness}), {off} of pixels off");
        if let Some(ctx) = gpu() {
            let mut b = GpuBackend::new(ctx);
            let placed_gpu = render(&mut b, &placed, &settings, None, |_| {}).unwrap();
            let (mean, off) = image_difference(&placed_gpu.image.pixels, &placed_cpu.image.pixels, 1e-2);
            assert!(mean < 0.02 * brightness && off < 0.05, "seed {seed}, {name}: placed on {} against the CPU runner: mean difference {mean}, {off} of pixels off", b.adapter());
        }
    }
    // Copies alone: nothing of the scene's own, no light: black, and no
    // tree of its own built.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed as u64);
    let m = meshes(&mut rng, &[30]);
    let nodes = vec![(0usize, Quat::IDENTITY, Vec3::ONE, Vec3::ZERO, None), (0, Quat::IDENTITY, Vec3::ONE, Vec3::new(3.0, 0.0, 0.0), None)];
    let dir = std::env::temp_dir().join(format!("treelet-copies-alone-{}-{seed}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gltf = write_gltf(&dir, &m, &nodes);
    let mut alone = treelet::scene::Scene::for_render(gltf.to_str().unwrap()).unwrap();
    assert!(alone.instances.is_some() && alone.spheres.is_empty() && alone.triangles.is_empty());
    // Nothing in the file emits: it comes with the default sky, taken away here.
    assert_eq!(alone.environment, treelet::scene::gltf::DEFAULT_SKY);
    alone.environment = [0.0; 3];
    let black = render(&mut cpu, &alone, &RenderSettings { spp: 2, ..settings }, None, |_| {}).unwrap();
    assert!(black.image.pixels.iter().all(|p| p.iter().all(|&c| c == 0.0)));
    std::fs::remove_dir_all(&dir).ok();
}
