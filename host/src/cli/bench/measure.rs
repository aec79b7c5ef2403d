//! The measurements behind `treelet bench`: builds, renders and ray casts
//! timed on a device (GPU timestamps where there are any), medians over
//! repeats. The commands (`mod.rs`) and the figures (`suite.rs`) call these.
use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use treelet::runtime::backend::{Backend, StageTimes};
use treelet::bvh::layout::Layout;
use treelet::bvh::tree::{Accel, Builder};
use treelet::render::{render, Integrator, RenderSettings, Sampler};
use treelet::scene::{random_spheres, Scene};
use treelet::bvh::trbvh::TreeletConfig;
use treelet::render::variant::KernelChoice;
use treelet::runtime::kernels::{render_entry_point_name, Method};
use treelet_core::render::variants::VARIANTS;
use treelet_core::Sphere;
use std::time::Instant;
use treelet::runtime::backend::DeviceClass;
use treelet::tracer::{batch_slots, device_rays};
use treelet::Ray;

/// One device build of `builder` (`config`: the treelet rounds of trbvh,
/// and of hploc where it has any; the leaf collapse of both), the tree left
/// there (as in a renderer).
pub(crate) fn build_once<B: Backend>(b: &mut B, spheres: &[Sphere], (builder, config): (Builder, &TreeletConfig)) -> Result<StageTimes> {
    let prims = treelet::scene::primitives::Primitives::spheres(spheres);
    Ok(treelet::bvh::tree::collapsed_tree(b, prims, builder, config)?.1)
}

/// Paths per second of a render, by wall clock and by render-kernel time.
#[derive(serde::Serialize)]
pub(crate) struct RenderRow {
    pub(crate) scene: String,
    pub(crate) accel: Accel,
    pub(crate) layout: Layout,
    /// The render kernel variant that ran.
    pub(crate) kernel: &'static str,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) spp: u32,
    /// Whole render, BVH build and readbacks included (s).
    pub(crate) total_s: f64,
    /// Render kernels alone (GPU timestamps on a GPU) (s).
    pub(crate) kernel_s: f64,
    pub(crate) build_ms: f64,
    /// Camera paths per second of kernel time.
    pub(crate) paths_per_s: f64,
}

pub(crate) fn bench_render<B: Backend>(
    b: &mut B,
    scene: &Scene,
    width: u32,
    height: u32,
    spp: u32,
    accel: Accel,
) -> Result<RenderRow> {
    bench_render_kernel(b, scene, (width, height, spp), accel, Layout::Auto, KernelChoice::Auto)
}

pub(crate) fn bench_render_kernel<B: Backend>(
    b: &mut B,
    scene: &Scene,
    (width, height, spp): (u32, u32, u32),
    accel: Accel,
    layout: Layout,
    kernel: KernelChoice,
) -> Result<RenderRow> {
    let settings = RenderSettings { width, height, spp, seed: 1, accel, layout, kernel, integrator: Integrator::Smallpt, sampler: Sampler::Sobol, error_each_pass: true, first_sample: 0 };
    let r = render(b, scene, &settings, None, |_| {})?;
    let kernel_s = r.render_ms / 1e3;
    Ok(RenderRow {
        scene: scene.name.clone(),
        accel: r.plan.accel,
        layout: r.plan.layout,
        kernel: r.plan.kernel,
        width,
        height,
        spp,
        total_s: r.total_s,
        kernel_s,
        build_ms: r.build_ms,
        paths_per_s: width as f64 * height as f64 * spp as f64 / kernel_s,
    })
}

/// One scene of `bench variants`: the chosen variant against the general kernel.
#[derive(serde::Serialize)]
pub(crate) struct VariantRow {
    pub(crate) scene: String,
    pub(crate) accel: Accel,
    pub(crate) kernel: &'static str,
    /// SPIR-V words of the entry points that ran (None on the CPU runner).
    pub(crate) kernel_words: Option<usize>,
    pub(crate) full_words: Option<usize>,
    /// Median render-kernel seconds.
    pub(crate) kernel_s: f64,
    pub(crate) full_s: f64,
    pub(crate) speedup: f64,
}

pub(crate) fn bench_variants<B: Backend>(
    b: &mut B,
    scenes: &[String],
    (width, height, spp): (u32, u32, u32),
    repeats: usize,
) -> Result<Vec<VariantRow>> {
    let bar = ProgressBar::new((scenes.len() * 2 * (repeats + 1)) as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} renders {msg}").unwrap());
    let mut rows = Vec::new();
    for spec in scenes {
        bar.set_message(spec.clone());
        let scene = Scene::from_spec(spec)?;
        let (mut auto, mut full) = (Vec::new(), Vec::new());
        let (mut accel, mut kernel) = (Accel::Auto, "");
        // Alternate the two so that clock drift hits both alike; the first
        // of each warms pipelines and clocks.
        for r in 0..=repeats {
            for (choice, times) in [(KernelChoice::Auto, &mut auto), (KernelChoice::Full, &mut full)] {
                let row = bench_render_kernel(b, &scene, (width, height, spp), Accel::Auto, Layout::Auto, choice)?;
                if choice == KernelChoice::Auto {
                    (accel, kernel) = (row.accel, row.kernel);
                }
                if r > 0 {
                    times.push(row.kernel_s);
                }
                bar.inc(1);
            }
        }
        let entry = |name: &str| {
            let method = if accel == Accel::None { Method::Scan } else { Layout::Auto.resolve(b.class()).method() };
            let variant = VARIANTS.iter().position(|&(_, v)| v == name)?;
            (b.device_kind() == "gpu")
                .then(|| treelet::runtime::gpu::context::entry_point_words(&render_entry_point_name(method, variant)))
                .flatten()
        };
        let (kernel_s, full_s) = (median(auto), median(full));
        rows.push(VariantRow {
            scene: scene.name.clone(),
            accel,
            kernel,
            kernel_words: entry(kernel),
            full_words: entry("full"),
            kernel_s,
            full_s,
            speedup: full_s / kernel_s,
        });
    }
    bar.finish_and_clear();
    Ok(rows)
}

pub(crate) fn print_render_rows(title: &str, rows: &[RenderRow]) {
    println!("{title}");
    println!(
        "{:>14}{:>6}{:>11}{:>6}{:>10}{:>11}{:>10}{:>14}",
        "scene", "accel", "size", "spp", "total s", "kernel s", "build ms", "Mpaths/s"
    );
    for r in rows {
        println!(
            "{:>14}{:>6}{:>11}{:>6}{:>10.3}{:>11.4}{:>10.3}{:>14.3}",
            r.scene,
            format!("{:?}", r.accel).to_lowercase(),
            format!("{}x{}", r.width, r.height),
            r.spp,
            r.total_s,
            r.kernel_s,
            r.build_ms,
            r.paths_per_s / 1e6
        );
    }
}

/// What `bench render` sweeps.
pub(crate) struct RenderSweep {
    pub(crate) quick: bool,
    pub(crate) spps: Vec<u32>,
    pub(crate) sizes: Vec<usize>,
    pub(crate) accels: Vec<Accel>,
}

pub(crate) fn render_sweeps<B: Backend>(b: &mut B, sweep: &RenderSweep) -> Result<(Vec<RenderRow>, Vec<RenderRow>)> {
    // Graph 1 of the seed: cornell, time against samples per pixel.
    let (w, h) = if sweep.quick { (256, 192) } else { (1024, 768) };
    let (spps, sizes) = (&sweep.spps, &sweep.sizes);
    let bar = ProgressBar::new((spps.len() + sweep.accels.len() * sizes.len()) as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} renders {msg}").unwrap());
    let cornell = Scene::from_spec("cornell")?;
    // Warm up pipelines and clocks.
    bench_render(b, &cornell, 64, 48, 4, Accel::None)?;
    let mut graph1 = Vec::new();
    for &spp in spps.iter() {
        bar.set_message(format!("cornell {spp} spp"));
        graph1.push(bench_render(b, &cornell, w, h, spp, Accel::None)?);
        bar.inc(1);
    }
    // Graph 2: random:N at 4 spp, linear scan against the trees.
    let mut graph2 = Vec::new();
    for &n in sizes.iter() {
        let scene = Scene::from_spec(&format!("random:{n}"))?;
        for &accel in &sweep.accels {
            bar.set_message(format!("random:{n} {accel:?}"));
            graph2.push(bench_render(b, &scene, w, h, 4, accel)?);
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok((graph1, graph2))
}

#[derive(serde::Serialize)]
pub(crate) struct Row {
    pub(crate) primitives: usize,
    /// Median per stage (or per kernel, with --per-kernel), in the order run.
    pub(crate) median_ms: Vec<(&'static str, f64)>,
    pub(crate) total_median_ms: f64,
    pub(crate) total_min_ms: f64,
    pub(crate) total_max_ms: f64,
    pub(crate) mprims_per_s: f64,
}

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

pub(crate) fn bench_sizes<B: Backend>(
    b: &mut B,
    sizes: &[usize],
    repeats: usize,
    builder: (Builder, &TreeletConfig),
) -> Result<Vec<Row>> {
    let bar = ProgressBar::new((sizes.len() * (repeats + 1)) as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} builds {msg}").unwrap());
    let mut rows = Vec::new();
    for &n in sizes {
        bar.set_message(format!("N = {n}"));
        let spheres = random_spheres(n, 1);
        let mut names: Vec<&'static str> = Vec::new();
        let mut samples: std::collections::BTreeMap<&'static str, Vec<f64>> = Default::default();
        let mut totals = Vec::new();
        // Warm up (pipelines, buffer pool, GPU clocks) for at least half a
        // second and until the build time is stable: the last five within 3%
        // of each other (clocks still rising show as a falling time), or 5 s.
        let warm = std::time::Instant::now();
        let mut recent: std::collections::VecDeque<f64> = Default::default();
        loop {
            recent.push_back(build_once(b, &spheres, builder)?.total());
            if recent.len() > 5 {
                recent.pop_front();
            }
            let (lo, hi) = recent.iter().fold((f64::MAX, 0.0f64), |(lo, hi), &t| (lo.min(t), hi.max(t)));
            let stable = recent.len() == 5 && hi <= lo * 1.03;
            let elapsed = warm.elapsed().as_secs_f64();
            if (elapsed >= 0.5 && stable) || elapsed >= 5.0 {
                break;
            }
        }
        bar.inc(1);
        for _ in 0..repeats {
            // The tree stays on the device, as in a renderer: no readback.
            let times = build_once(b, &spheres, builder)?;
            bar.inc(1);
            for s in &times.order {
                if !names.contains(s) {
                    names.push(s);
                }
                samples.entry(s).or_default().push(times.get(s));
            }
            totals.push(times.total());
        }
        let total_median_ms = median(totals.clone());
        rows.push(Row {
            primitives: n,
            median_ms: names.iter().map(|s| (*s, median(samples[s].clone()))).collect(),
            total_median_ms,
            total_min_ms: totals.iter().copied().fold(f64::MAX, f64::min),
            total_max_ms: totals.iter().copied().fold(0.0, f64::max),
            mprims_per_s: n as f64 / total_median_ms / 1e3,
        });
    }
    bar.finish_and_clear();
    Ok(rows)
}

/// Primary and diffuse rays per second through one tree.
#[derive(serde::Serialize)]
pub(crate) struct RaysRow {
    pub(crate) scene: String,
    pub(crate) accel: Accel,
    pub(crate) layout: Layout,
    /// Where the traversal stack lives: "private" or "workgroup".
    pub(crate) stack: &'static str,
    pub(crate) primitives: usize,
    /// The binary tree's build (ms).
    pub(crate) build_ms: f64,
    /// Its layout for traversal (ms, collapse included).
    pub(crate) layout_ms: f64,
    /// The layout's stages (ms).
    pub(crate) layout_stages: Vec<(&'static str, f64)>,
    pub(crate) primary_rays: u64,
    pub(crate) diffuse_rays: u64,
    pub(crate) primary_median_ms: f64,
    pub(crate) diffuse_median_ms: f64,
    pub(crate) primary_mrays_per_s: f64,
    pub(crate) diffuse_mrays_per_s: f64,
    /// The same diffuse rays as occlusion queries (any hit, no bound).
    pub(crate) occlusion_median_ms: f64,
    pub(crate) occlusion_mrays_per_s: f64,
}

/// What `bench rays` times through one tree: its layouts, each with its
/// stacks (the workgroup-memory stack exists for cwbvh only).
pub(crate) struct RaysPlan {
    pub(crate) layouts: Vec<Layout>,
    pub(crate) workgroup_stack: bool,
}

/// Rays per second through the tree `accel` builds, in each layout of `plan`.
pub(crate) fn bench_rays<B: Backend>(
    b: &mut B,
    scene: &Scene,
    accel: Accel,
    plan: &RaysPlan,
    (width, height): (u32, u32),
    repeats: usize,
) -> Result<Vec<RaysRow>> {
    use treelet::runtime::kernels::Kernel;
    use treelet::bvh::layout::PrimBuffers;
    use treelet::scene::primitives::Primitives;
    anyhow::ensure!(
        !matches!(accel, Accel::None | Accel::Auto),
        "bench rays traces trees: pick lbvh, trbvh or sweep (not {accel:?})"
    );
    let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
    all.check()?;
    let pixels = width as u64 * height as u64;
    anyhow::ensure!(pixels > 0 && pixels <= u32::MAX as u64 / 4, "image size {width}x{height} out of range");
    let Some(builder) = accel.builder()? else { anyhow::bail!("bench rays needs a tree: --accels lbvh, trbvh or sweep") };
    let built = treelet::bvh::tree::binary_tree(b, all, builder)?;
    let buffers = PrimBuffers::upload(b, all)?;
    let materials = b.upload("materials", &scene.materials)?;
    let rays = b.zeroed("rays", pixels * 32)?;
    b.take_times()?;
    let mut rows = Vec::new();
    for &layout in &plan.layouts {
        let layout = layout.resolve(b.class());
        let (tree, stages) = built.lay_out_timed(b, layout, &buffers)?;
        let layout_ms = stages.total();
        let layout_stages: Vec<_> = stages.order.iter().map(|&s| (s, stages.get(s))).collect();
        // Meshes get the kernels compiled for triangles alone.
        let triangles_only = scene.spheres.is_empty();
        let mut kernels = vec![("private", Kernel::Cast(layout.method(), triangles_only))];
        if plan.workgroup_stack && layout == Layout::Cwbvh {
            kernels.push(("workgroup", Kernel::CastWideWorkgroupStack));
        }
        for (stack, kernel) in kernels {
            let bindings = [&buffers.spheres, &materials, &tree.nodes, &tree.prims, &rays, &buffers.triangles];
            let (primary_ms, diffuse_ms, occlusion_ms, diffuse_rays) = time_casts(b, scene, kernel, &bindings, (width, height), repeats)?;
            rows.push(RaysRow {
                scene: scene.name.clone(),
                accel,
                layout,
                stack,
                primitives: all.len(),
                build_ms: built.build_ms,
                layout_ms,
                layout_stages: layout_stages.clone(),
                primary_rays: pixels,
                diffuse_rays,
                primary_median_ms: primary_ms,
                diffuse_median_ms: diffuse_ms,
                primary_mrays_per_s: pixels as f64 / primary_ms / 1e3,
                diffuse_mrays_per_s: diffuse_rays as f64 / diffuse_ms / 1e3,
                occlusion_median_ms: occlusion_ms,
                occlusion_mrays_per_s: diffuse_rays as f64 / occlusion_ms / 1e3,
            });
        }
    }
    Ok(rows)
}

/// Median kernel times (ms) of the primary and the diffuse pass of `kernel`
/// (bindings 1.. as the cast kernels take them) and of the same diffuse rays
/// as occlusion queries, and the number of diffuse rays (pixels whose
/// camera ray hit).
pub(crate) fn time_casts<B: Backend>(
    b: &mut B,
    scene: &Scene,
    kernel: treelet::runtime::kernels::Kernel,
    bindings: &[&B::Buffer; 6],
    (width, height): (u32, u32),
    repeats: usize,
) -> Result<(f64, f64, f64, u64)> {
    use treelet_core::gpu::workgroup::groups_for;
    use treelet_core::render::rays::{CAST_BOUNCE, CAST_DIFFUSE, CAST_DIFFUSE_OCCLUDED, CAST_PRIMARY};
    let pixels = width * height;
    let base = treelet_core::RenderParams {
        width,
        height,
        samples: 1,
        prims: scene.spheres.len() as u32,
        triangles: scene.triangles.len() as u32,
        camera: scene.camera.camera(width, height),
        ..Default::default()
    };
    let groups = groups_for(treelet_core::render::integrator::tiled_invocations(width, height), kernel.workgroup_size());
    let (mut primary, mut diffuse, mut occlusion) = (Vec::new(), Vec::new(), Vec::new());
    let mut diffuse_rays = 0;
    // Warm-up passes for half a second first (pipelines, and GPU clocks,
    // which drop while a CPU-built tree is being made), then the timed ones.
    // The first casts of a process warm up for two seconds (GPUs were seen
    // to run their first seconds of work at a fraction of their speed),
    // later ones for half a second.
    static WARMED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    let warm_s = if WARMED.swap(true, std::sync::atomic::Ordering::Relaxed) { 0.5 } else { 2.0 };
    let warm = std::time::Instant::now();
    let mut warm_passes = 0;
    for r in 0.. {
        if r > warm_passes + repeats {
            break;
        }
        // The bounce rays are made between the two timed passes, then made
        // again (the same rays) for the occlusion queries.
        let passes = [
            ("primary", CAST_PRIMARY),
            ("bounce", CAST_BOUNCE),
            ("diffuse", CAST_DIFFUSE),
            ("remake", CAST_PRIMARY),
            ("remake", CAST_BOUNCE),
            ("occlusion", CAST_DIFFUSE_OCCLUDED),
        ];
        for (stage, mode) in passes {
            b.stage(stage);
            let p = b.upload("cast params", &[treelet_core::RenderParams { cast_mode: mode, first_sample: r as u32, ..base }])?;
            let [spheres, materials, nodes, prims, rays, triangles] = *bindings;
            b.dispatch(kernel, &[&p, spheres, materials, nodes, prims, rays, triangles], groups);
        }
        let t = b.take_times()?;
        if r == 0 {
            let rays: Vec<[f32; 4]> = b.read(bindings[4], 2 * pixels as usize)?;
            diffuse_rays = rays.iter().step_by(2).filter(|x| x[3] != 0.0).count() as u64;
        }
        if r == warm_passes {
            if warm.elapsed().as_secs_f64() < warm_s {
                warm_passes += 1;
            }
            continue;
        }
        primary.push(t.get("primary"));
        diffuse.push(t.get("diffuse"));
        occlusion.push(t.get("occlusion"));
    }
    Ok((median(primary), median(diffuse), median(occlusion), diffuse_rays))
}

/// Device ms of tracing `rays` (median of `repeats`), each repeat a fresh
/// copy of them made on the device right before, with no host work in
/// between: at 1080p an upload and read-back of the rays leaves the GPU
/// idle long enough for its clock to fall (H100: a traversal timed that
/// way ran 5.5x slower, 1980 against 345 MHz). `warm_s` seconds of untimed
/// repeats first bring the clock up (not on the CPU runner). `on_device`
/// traces the batch in place (`Tracer::closest_hits_on_device` and kin).
pub(crate) fn traced_in_place_ms<B: Backend>(
    b: &mut B,
    rays: &[Ray],
    repeats: usize,
    warm_s: f64,
    on_device: &dyn Fn(&mut B, &B::Buffer, usize) -> Result<()>,
) -> Result<f64> {
    let pristine = b.upload("bench rays", &device_rays(rays)?)?;
    let work = b.scratch("bench rays in place", 2 * batch_slots(rays.len())? as u64 * 16)?;
    let words = 2 * batch_slots(rays.len())? as u32 * 4;
    let cpu = b.class() == DeviceClass::CpuRunner;
    let once = |b: &mut B| -> Result<f64> {
        b.take_times()?;
        b.stage("copy");
        b.copy_words((&pristine, 0), (&work, 0), words)?;
        let start = Instant::now();
        on_device(b, &work, rays.len())?;
        let stages = b.take_times()?;
        Ok(if cpu { start.elapsed().as_secs_f64() * 1e3 } else { stages.get("trace") })
    };
    let warm = Instant::now();
    while !cpu && warm.elapsed().as_secs_f64() < warm_s {
        once(b)?;
    }
    let times = (0..repeats.max(1)).map(|_| once(b)).collect::<Result<Vec<f64>>>()?;
    Ok(median(times))
}

/// A cosine-distributed bounce from each hit, on the side the ray came from,
/// starting a little off the surface.
pub(crate) fn cosine_bounces(rays: &[Ray], hits: &[treelet::RayHit], extent: f32, rng: &mut impl rand::Rng) -> Vec<Ray> {
    rays.iter()
        .zip(hits)
        .filter(|(_, h)| h.is_hit())
        .map(|(r, h)| {
            use glam::Vec3;
            let d = Vec3::from(r.dir).normalize();
            let mut n = Vec3::from(h.normal);
            if n.dot(d) > 0.0 {
                n = -n;
            }
            let (u1, u2): (f32, f32) = (rng.random(), rng.random());
            let (a, b) = n.any_orthonormal_pair();
            let (s, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
            let dir = a * s * phi.cos() + b * s * phi.sin() + n * (1.0 - u1).sqrt();
            let x = Vec3::from(r.origin) + d * h.t;
            Ray { t_min: 1e-4 * extent, ..Ray::new(x.into(), dir.into()) }
        })
        .collect()
}
