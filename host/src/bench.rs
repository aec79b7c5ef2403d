//! `treelet bench ...`: sweeps of build sizes, reporting per-stage medians.
use anyhow::Result;
use clap::Subcommand;
use indicatif::{ProgressBar, ProgressStyle};
use treelet::backend::{Backend, StageTimes};
use treelet::cpu_runner::CpuBackend;
use treelet::gpu::{GpuBackend, GpuContext};
use treelet::layout::Layout;
use treelet::lbvh;
use treelet::render::{render, Accel, Integrator, RenderSettings};
use treelet::scene::{random_spheres, Scene};
use treelet::trbvh::{self, TreeletConfig};
use treelet::variant::KernelChoice;
use treelet_core::Sphere;

use crate::suite::{Figure, Suite};
use crate::Device;

/// Options of every figure command.
#[derive(clap::Args, Clone)]
pub struct FigureArgs {
    #[arg(long, value_enum, default_value = "gpu")]
    device: Device,
    /// Small sizes: minutes on lavapipe or a CPU (default: the seed's sizes and beyond).
    #[arg(long)]
    quick: bool,
    /// Where the JSON and PNG of each figure (and RESULTS.md for `all`) go.
    #[arg(long)]
    out: std::path::PathBuf,
    /// Timed repeats per measurement (median, min and max are recorded).
    #[arg(long, default_value_t = 3)]
    repeats: usize,
}

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Figure: cornell render time against samples per pixel, GPU and CPU runner (the seed's Graph 1).
    #[command(name = "graph1")]
    Graph1(FigureArgs),
    /// Figure: render time against scene size, linear scan against BVHs (Graph 2).
    #[command(name = "graph2")]
    Graph2(FigureArgs),
    /// Figure: BVH build time against size, with CPU builders and peers (Graph 2.5).
    #[command(name = "graph2.5")]
    Graph25(FigureArgs),
    /// Figure: render time against size, LBVH against optimized BVHs (Graph 3).
    #[command(name = "graph3")]
    Graph3(FigureArgs),
    /// Figure: treelet-optimization time against size (Graph 3.5).
    #[command(name = "graph3.5")]
    Graph35(FigureArgs),
    /// Figures: RMSE against wall and kernel time for each integrator on
    /// cornell and the disk-lit room, Mitsuba 3 beside (`--mitsuba`).
    Error {
        #[command(flatten)]
        figure: FigureArgs,
        /// Folder of `peers/mitsuba/room_disk.py`'s output (`mitsuba.jsonl` and
        /// its images): Mitsuba 3's renders of the room, scored beside Treelet's.
        #[arg(long)]
        mitsuba: Option<std::path::PathBuf>,
    },
    /// Figure: SAH cost against build time for every builder and peer.
    Pareto(FigureArgs),
    /// Figure: primary and diffuse rays per second through each tree.
    #[command(name = "rays-figure")]
    RaysFigure(FigureArgs),
    /// Every figure, then RESULTS.md in --out.
    All(FigureArgs),
    /// One RESULTS.md from the figure files of several `bench all` runs (how docs/RESULTS.md is made).
    Results {
        /// Run directories, each written by `treelet bench all --out DIR`.
        #[arg(long, value_delimiter = ',', required = true)]
        runs: Vec<std::path::PathBuf>,
        #[arg(long, default_value = "docs/RESULTS.md")]
        out: std::path::PathBuf,
    },
    /// LBVH (and treelet-optimization) build times over random:N scenes.
    Build {
        /// lbvh: the Karras 2012 build; trbvh: the build plus treelet restructuring (stage times of both).
        #[arg(long, value_enum, default_value = "lbvh")]
        builder: TreeBuilder,
        /// Treelet rounds, first gamma and largest collapsed leaf (trbvh).
        #[arg(long, default_value_t = TreeletConfig::default().rounds)]
        rounds: u32,
        #[arg(long, default_value_t = TreeletConfig::default().gamma)]
        gamma: u32,
        #[arg(long, default_value_t = TreeletConfig::default().max_leaf)]
        max_leaf: u32,
        /// Primitive counts (the seed's table, then millions).
        #[arg(long, value_delimiter = ',', default_values_t = vec![1000, 10000, 20000, 35000, 50000, 65000, 1_000_000, 4_000_000, 16_000_000])]
        sizes: Vec<usize>,
        #[arg(long, value_enum, default_value = "gpu")]
        device: Device,
        /// Timed repeats per size (after half a second of warm-up builds).
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Also write the rows as JSON to this file.
        #[arg(long)]
        json: Option<std::path::PathBuf>,
        /// Time each kernel alone (GPU only) instead of each stage.
        #[arg(long)]
        per_kernel: bool,
    },
    /// Rays per second: one primary and one diffuse ray per pixel, cast alone
    /// (no shading), through the chosen tree.
    Rays {
        /// Scene: cornell, random:N[:SEED], terrain:N, a .json scene, or an .obj/.ply mesh.
        #[arg(long, default_value = "random:65536")]
        scene: String,
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = vec![Accel::Lbvh, Accel::Trbvh])]
        accels: Vec<Accel>,
        /// Traversal layouts of each tree.
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = Layout::ALL.to_vec())]
        layouts: Vec<Layout>,
        /// Also time cwbvh with the top of each ray's stack in workgroup memory.
        #[arg(long)]
        workgroup_stack: bool,
        #[arg(long, default_value_t = 1024)]
        width: u32,
        #[arg(long, default_value_t = 768)]
        height: u32,
        #[arg(long, value_enum, default_value = "gpu")]
        device: Device,
        /// Timed repeats (median reported), after one warm-up pass.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Cast at the scene's triangles alone, framed by the camera (no room).
        #[arg(long)]
        mesh_only: bool,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// Specialized render kernels against the general one (--kernel full):
    /// render-kernel time per scene, and each kernel's SPIR-V size.
    Variants {
        #[arg(long, value_enum, default_value = "gpu")]
        device: Device,
        /// 256x192 at 16 spp instead of 1024x768 at 64 (for a CPU or lavapipe).
        #[arg(long)]
        quick: bool,
        #[arg(long, value_delimiter = ',', default_values_t = VARIANT_SCENES.map(String::from).to_vec())]
        scenes: Vec<String>,
        /// Timed renders per kernel (median reported), after one warm-up each.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// Render times at 1024x768 (--quick: 256x192): cornell against spp, and
    /// random:N at 4 spp with each closest-hit method.
    Render {
        #[arg(long, value_enum, default_value = "gpu")]
        device: Device,
        /// Small sizes, for a CPU or lavapipe.
        #[arg(long)]
        quick: bool,
        /// Samples per pixel of the cornell renders (default 4..1024, --quick 4,16,64).
        #[arg(long, value_delimiter = ',')]
        spp: Option<Vec<u32>>,
        /// Sphere counts of the random:N renders (default 1000..65000, --quick 100,1000,4000).
        #[arg(long, value_delimiter = ',')]
        sizes: Option<Vec<usize>>,
        /// Closest-hit methods compared on the random:N scenes.
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = vec![Accel::None, Accel::Lbvh, Accel::Trbvh])]
        accels: Vec<Accel>,
        /// Also write the rows as JSON to this file.
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
}

fn figure(f: Figure, a: FigureArgs) -> Result<()> {
    figure_with(f, a, None)
}

fn figure_with(f: Figure, a: FigureArgs, mitsuba: Option<std::path::PathBuf>) -> Result<()> {
    let suite = Suite { device: a.device, quick: a.quick, out: a.out, repeats: a.repeats.max(1), mitsuba };
    crate::suite::run(f, &suite)
}

/// Scenes `bench variants` compares by default: each exercises a different
/// specialized kernel (cornell: no triangles; diffuse and mirror-only
/// variants; many spheres through a BVH; a mesh in smallpt's room).
const VARIANT_SCENES: [&str; 5] =
    ["cornell", "scenes/cornell_diffuse.json", "scenes/cornell_mirrors.json", "random:1000", "terrain:100000"];

/// The device builders `bench build` times.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TreeBuilder {
    Lbvh,
    Trbvh,
}

/// One build on the device, the tree left there (as in a renderer).
fn build_once<B: Backend>(b: &mut B, spheres: &[Sphere], builder: Option<&TreeletConfig>) -> Result<StageTimes> {
    let (bvh, mut times) = lbvh::build_on_device(b, spheres)?;
    if let Some(config) = builder {
        let root = trbvh::root_box(b, &bvh)?;
        let (_, rounds) = trbvh::optimize(b, bvh, &root, config)?;
        for s in &rounds.order {
            times.add(s, rounds.get(s));
        }
    }
    Ok(times)
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
    let settings = RenderSettings { width, height, spp, seed: 1, accel, layout, kernel, integrator: Integrator::Smallpt, error_each_pass: true };
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
struct VariantRow {
    scene: String,
    accel: Accel,
    kernel: &'static str,
    /// SPIR-V words of the entry points that ran (None on the CPU runner).
    kernel_words: Option<usize>,
    full_words: Option<usize>,
    /// Median render-kernel seconds.
    kernel_s: f64,
    full_s: f64,
    speedup: f64,
}

fn bench_variants<B: Backend>(
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
            let method = if accel == Accel::None { "linear" } else { Layout::Auto.resolve(b.class()).method().name() };
            (b.device_kind() == "gpu")
                .then(|| treelet::gpu::context::entry_point_words(&format!("render::render_{method}_{name}_cs")))
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

fn print_render_rows(title: &str, rows: &[RenderRow]) {
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
struct RenderSweep {
    quick: bool,
    spps: Vec<u32>,
    sizes: Vec<usize>,
    accels: Vec<Accel>,
}

fn render_sweeps<B: Backend>(b: &mut B, sweep: &RenderSweep) -> Result<(Vec<RenderRow>, Vec<RenderRow>)> {
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
    builder: Option<&TreeletConfig>,
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
        // Warm up (pipelines, buffer pool, GPU clocks) for at least half a second.
        let warm = std::time::Instant::now();
        while warm.elapsed().as_secs_f64() < 0.5 {
            build_once(b, &spheres, builder)?;
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
    use treelet::kernels::Kernel;
    use treelet::layout::PrimBuffers;
    use treelet::primitives::Primitives;
    anyhow::ensure!(
        !matches!(accel, Accel::None | Accel::Auto),
        "bench rays traces trees: pick lbvh, trbvh or sweep (not {accel:?})"
    );
    let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
    all.check()?;
    let pixels = width as u64 * height as u64;
    anyhow::ensure!(pixels > 0 && pixels <= u32::MAX as u64 / 4, "image size {width}x{height} out of range");
    let Some(built) = treelet::render::binary_tree(b, all, accel)? else { unreachable!("a tree was asked for") };
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
            let (primary_ms, diffuse_ms, diffuse_rays) = time_casts(b, scene, kernel, &bindings, (width, height), repeats)?;
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
            });
        }
    }
    Ok(rows)
}

/// Median kernel times (ms) of the primary and the diffuse pass of `kernel`
/// (bindings 1.. as the cast kernels take them), and the number of diffuse
/// rays (pixels whose camera ray hit).
fn time_casts<B: Backend>(
    b: &mut B,
    scene: &Scene,
    kernel: treelet::kernels::Kernel,
    bindings: &[&B::Buffer; 6],
    (width, height): (u32, u32),
    repeats: usize,
) -> Result<(f64, f64, u64)> {
    use treelet_core::rays::{CAST_BOUNCE, CAST_DIFFUSE, CAST_PRIMARY};
    use treelet_core::workgroup::{groups_for, WORKGROUP_SIZE};
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
    let groups = groups_for(treelet_core::render::tiled_invocations(width, height), WORKGROUP_SIZE);
    let (mut primary, mut diffuse) = (Vec::new(), Vec::new());
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
        // The bounce rays are made between the two timed passes.
        for (stage, mode) in [("primary", CAST_PRIMARY), ("bounce", CAST_BOUNCE), ("diffuse", CAST_DIFFUSE)] {
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
    }
    Ok((median(primary), median(diffuse), diffuse_rays))
}

pub fn run(cmd: BenchCommand) -> Result<()> {
    match cmd {
        BenchCommand::Rays { scene, accels, layouts, workgroup_stack, width, height, device, repeats, mesh_only, json } => {
            let scene = Scene::from_spec(&scene)?;
            let scene = if mesh_only { scene.mesh_only()? } else { scene };
            let plan = RaysPlan { layouts, workgroup_stack };
            let mut rows = Vec::new();
            let adapter = match device {
                Device::Gpu => {
                    let mut b = GpuBackend::new(GpuContext::new()?);
                    for &a in &accels {
                        rows.extend(bench_rays(&mut b, &scene, a, &plan, (width, height), repeats)?);
                    }
                    b.adapter()
                }
                Device::Cpu => {
                    let mut b = CpuBackend::new();
                    for &a in &accels {
                        rows.extend(bench_rays(&mut b, &scene, a, &plan, (width, height), repeats)?);
                    }
                    b.adapter()
                }
            };
            println!("rays per second, {} ({} primitives), {width}x{height}, {adapter}, median of {repeats}", scene.name, rows.first().map_or(0, |r| r.primitives));
            println!(
                "{:>6}{:>8}{:>10}{:>11}{:>11}{:>12}{:>12}{:>16}{:>16}",
                "accel", "layout", "stack", "build ms", "layout ms", "primary ms", "diffuse ms", "primary Mray/s", "diffuse Mray/s"
            );
            for r in rows.iter().filter(|r| r.layout_stages.len() > 1) {
                let stages: Vec<String> = r.layout_stages.iter().map(|(s, ms)| format!("{s} {ms:.3}")).collect();
                eprintln!("{} layout of the {:?} tree, ms: {}", r.layout.name(), r.accel, stages.join(", "));
            }
            for r in &rows {
                println!(
                    "{:>6}{:>8}{:>10}{:>11.3}{:>11.3}{:>12.3}{:>12.3}{:>16.1}{:>16.1}",
                    format!("{:?}", r.accel).to_lowercase(),
                    r.layout.name(),
                    r.stack,
                    r.build_ms,
                    r.layout_ms,
                    r.primary_median_ms,
                    r.diffuse_median_ms,
                    r.primary_mrays_per_s,
                    r.diffuse_mrays_per_s
                );
            }
            if let Some(path) = json {
                let doc = serde_json::json!({ "adapter": adapter, "width": width, "height": height, "repeats": repeats, "rows": rows });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::Graph1(a) => figure(Figure::Graph1, a),
        BenchCommand::Graph2(a) => figure(Figure::Graph2, a),
        BenchCommand::Graph25(a) => figure(Figure::Graph25, a),
        BenchCommand::Graph3(a) => figure(Figure::Graph3, a),
        BenchCommand::Graph35(a) => figure(Figure::Graph35, a),
        BenchCommand::Error { figure: a, mitsuba } => figure_with(Figure::Error, a, mitsuba),
        BenchCommand::Pareto(a) => figure(Figure::Pareto, a),
        BenchCommand::RaysFigure(a) => figure(Figure::Rays, a),
        BenchCommand::All(a) => figure(Figure::All, a),
        BenchCommand::Results { runs, out } => {
            crate::results::collect(&runs, &out)?;
            eprintln!("wrote {}", out.display());
            Ok(())
        }
        BenchCommand::Variants { device, quick, scenes, repeats, json } => {
            let size = if quick { (256, 192, 16) } else { (1024, 768, 64) };
            let (adapter, rows) = match device {
                Device::Gpu => {
                    let mut b = GpuBackend::new(GpuContext::new()?);
                    (b.adapter(), bench_variants(&mut b, &scenes, size, repeats)?)
                }
                Device::Cpu => ("cpu".to_string(), bench_variants(&mut CpuBackend::new(), &scenes, size, repeats)?),
            };
            println!("Specialized kernel against the general one, {}x{} at {} spp, {adapter}, median of {repeats}", size.0, size.1, size.2);
            println!(
                "{:>30}{:>7}{:>18}{:>13}{:>12}{:>11}{:>11}{:>9}",
                "scene", "accel", "kernel", "SPIR-V words", "full words", "kernel s", "full s", "speedup"
            );
            let words = |w: Option<usize>| w.map(|w| w.to_string()).unwrap_or_else(|| "-".into());
            for r in &rows {
                println!(
                    "{:>30}{:>7}{:>18}{:>13}{:>12}{:>11.4}{:>11.4}{:>9.3}",
                    r.scene,
                    format!("{:?}", r.accel).to_lowercase(),
                    r.kernel,
                    words(r.kernel_words),
                    words(r.full_words),
                    r.kernel_s,
                    r.full_s,
                    r.speedup
                );
            }
            if let Some(path) = json {
                let doc = serde_json::json!({ "adapter": adapter, "width": size.0, "height": size.1, "spp": size.2, "repeats": repeats, "rows": rows });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::Render { device, quick, spp, sizes, accels, json } => {
            let sweep = RenderSweep {
                quick,
                spps: spp.unwrap_or_else(|| if quick { vec![4, 16, 64] } else { vec![4, 16, 64, 256, 1024] }),
                sizes: sizes.unwrap_or_else(|| {
                    if quick {
                        vec![100, 1000, 4000]
                    } else {
                        vec![1000, 4000, 16000, 35000, 65536]
                    }
                }),
                accels,
            };
            let (adapter, (graph1, graph2)) = match device {
                Device::Gpu => {
                    let mut b = GpuBackend::new(GpuContext::new()?);
                    (b.adapter(), render_sweeps(&mut b, &sweep)?)
                }
                Device::Cpu => (CpuBackend::new().adapter(), render_sweeps(&mut CpuBackend::new(), &sweep)?),
            };
            print_render_rows(&format!("cornell against samples per pixel, {adapter}"), &graph1);
            print_render_rows(&format!("random:N at 4 spp, each closest-hit method, {adapter}"), &graph2);
            if let Some(path) = json {
                let doc = serde_json::json!({ "adapter": adapter, "cornell": graph1, "random": graph2 });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::Build { builder, rounds, gamma, max_leaf, sizes, device, repeats, json, per_kernel } => {
            let config = TreeletConfig { rounds, gamma, max_leaf, ..Default::default() };
            let treelets = (builder == TreeBuilder::Trbvh).then_some(&config);
            let (adapter, timing, rows) = match device {
                Device::Gpu => {
                    let mut b = GpuBackend::new(GpuContext::new()?).with_per_kernel_times(per_kernel);
                    let ts = if b.context().timestamps { "gpu-timestamps" } else { "wall-clock" };
                    (b.adapter(), ts, bench_sizes(&mut b, &sizes, repeats, treelets)?)
                }
                Device::Cpu => {
                    let mut b = CpuBackend::new();
                    (b.adapter(), "wall-clock", bench_sizes(&mut b, &sizes, repeats, treelets)?)
                }
            };
            println!("{builder:?} build, {adapter} ({timing}), median of {repeats} (ms)");
            let names: Vec<&str> =
                rows.first().map(|r| r.median_ms.iter().map(|(s, _)| *s).collect()).unwrap_or_default();
            let short = |s: &str| s.rsplit("::").next().unwrap_or(s).trim_end_matches("_cs").to_string();
            let width = names.iter().map(|s| short(s).len() + 2).max().unwrap_or(9).max(9);
            print!("{:>10}", "N");
            for s in &names {
                print!("{:>width$}", short(s));
            }
            println!("{:>10}{:>10}", "total", "Mprims/s");
            for r in &rows {
                print!("{:>10}", r.primitives);
                for (_, v) in &r.median_ms {
                    print!("{v:>width$.3}");
                }
                println!("{:>10.3}{:>10.1}", r.total_median_ms, r.mprims_per_s);
            }
            if let Some(path) = json {
                let builder = format!("{builder:?}").to_lowercase();
                let doc = serde_json::json!({
                    "adapter": adapter, "builder": builder, "treelets": treelets,
                    "timing": timing, "repeats": repeats, "rows": rows
                });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
    }
}
