//! `treelet bench ...`: the benchmark commands. [`measure`] times builds,
//! renders and ray casts; [`suite`] turns them into figures ([`figure`]:
//! JSON, table, plot), [`error_curves`] makes `bench error`, and [`results`]
//! gathers figure files into `RESULTS.md`.
use anyhow::Result;
use clap::Subcommand;
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::layout::Layout;
use treelet::bvh::tree::{Accel, Builder};
use treelet::scene::{CameraSpec, Scene};
use treelet::bvh::trbvh::TreeletConfig;

use figure::{Figure, Suite};
use treelet::runtime::device::{Device, DeviceChoice};
use measure::*;

mod clocks;
mod dynamic;
mod error_curves;
mod figure;
mod instances;
mod load;
mod measure;
mod file_instances;
mod rays_suite;
pub mod results;
mod suite;
mod tradeoff;

/// Options of every figure command.
#[derive(clap::Args, Clone)]
pub struct FigureArgs {
    #[arg(long, value_enum, default_value = "gpu")]
    device: DeviceChoice,
    /// Small sizes: minutes on lavapipe or a CPU (default: the seed's sizes and beyond).
    #[arg(long)]
    quick: bool,
    /// Where the JSON and PNG of each figure (and RESULTS.md for all) go.
    #[arg(long)]
    out: std::path::PathBuf,
    /// Timed repeats per measurement (median, min and max are recorded);
    /// default 3, with --quick 2.
    #[arg(long)]
    repeats: Option<usize>,
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
    /// cornell and the disk-lit room, Mitsuba 3 beside (--mitsuba).
    Error {
        #[command(flatten)]
        figure: FigureArgs,
        /// Folder of peers/mitsuba/room_disk.py's output (mitsuba.jsonl and
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
    /// One RESULTS.md from the figure files of several bench all runs (how docs/RESULTS.md is made).
    Results {
        /// Run directories, each written by treelet bench all --out DIR.
        #[arg(long, value_delimiter = ',', required = true)]
        runs: Vec<std::path::PathBuf>,
        #[arg(long, default_value = "docs/RESULTS.md")]
        out: std::path::PathBuf,
    },
    /// LBVH (and treelet-optimization) build times over random:N scenes.
    Build {
        /// lbvh: the Karras 2012 build; trbvh: the build plus treelet
        /// restructuring (stage times of both); hploc: H-PLOC plus the SAH
        /// leaf collapse (and treelet rounds with --rounds).
        #[arg(long, value_enum, default_value = "lbvh")]
        builder: Builder,
        /// Treelet rounds (trbvh: default 3; hploc: default 0), first gamma
        /// and largest collapsed leaf (trbvh, hploc).
        #[arg(long)]
        rounds: Option<u32>,
        #[arg(long, default_value_t = TreeletConfig::default().gamma)]
        gamma: u32,
        #[arg(long, default_value_t = TreeletConfig::default().max_leaf)]
        max_leaf: u32,
        /// Iterations of parallel reinsertion after the rounds (trbvh, hploc); default: 2 for trbvh on GPUs, else 0.
        #[arg(long)]
        reinsert: Option<u32>,
        /// Primitive counts (the seed's table, then millions).
        #[arg(long, value_delimiter = ',', default_values_t = vec![1000, 10000, 20000, 35000, 50000, 65000, 1_000_000, 4_000_000, 16_000_000])]
        sizes: Vec<usize>,
        #[arg(long, value_enum, default_value = "gpu")]
        device: DeviceChoice,
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
        /// Scene: cornell, random:N[:SEED], terrain:N, a .json scene, a .gltf/.glb scene, or an .obj/.ply mesh.
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
        device: DeviceChoice,
        /// Timed repeats (median reported), after one warm-up pass.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Cast at the scene's triangles alone, framed by the camera (no room).
        #[arg(long)]
        mesh_only: bool,
        /// The camera instead of the scene's (or the mesh-only framing): its
        /// eye and the point it looks at, EX,EY,EZ,TX,TY,TZ (a camera
        /// inside a building, say), in the coordinates of the scene's file;
        /// peers/mitsuba/rays.py takes the same.
        #[arg(long, allow_hyphen_values = true)]
        camera: Option<String>,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
        /// Also draw build time against rays per second (tradeoff-primary
        /// and tradeoff-diffuse, JSON and PNG) into this folder.
        #[arg(long)]
        figure: Option<std::path::PathBuf>,
        /// OptiX's point for that figure: the output of
        /// ../shared/tools/optix-peer/peer.py for the same mesh and size.
        #[arg(long, requires = "figure")]
        optix: Option<std::path::PathBuf>,
        /// The real-scene suite instead of --scene: the interiors of
        /// scenes/real (outside and from each one's camera) and the
        /// generated city (300k and 1M triangles, from above and from a
        /// street), in one table.
        #[arg(long, conflicts_with_all = ["camera", "figure"])]
        suite: bool,
        /// The suite's folder of .ply.xz scenes and cameras.json (default:
        /// scenes/real of this repository).
        #[arg(long, requires = "suite")]
        suite_dir: Option<std::path::PathBuf>,
        /// Time OptiX on each of the suite's scenes and views too
        /// (peers/mitsuba/rays.py through python3, or $TREELET_PYTHON;
        /// needs Mitsuba 3 and an NVIDIA GPU), with the ratios.
        #[arg(long, requires = "suite")]
        with_optix: bool,
    },
    /// Mesh loading speed against reading the file's bytes: the files
    /// given, and a binary PLY and an OBJ of terrain:N for each size (made
    /// in --dir where missing). On the host's cores; no device.
    Load {
        /// Mesh files (.obj, .ply, either as .xz).
        files: Vec<std::path::PathBuf>,
        /// Triangle counts of the terrains to make and time (default, when no
        /// file is given: 1000000,10000000).
        #[arg(long, value_delimiter = ',')]
        sizes: Vec<usize>,
        /// Where the terrains' files are made (and kept for later runs).
        #[arg(long, default_value = "target/bench-load")]
        dir: std::path::PathBuf,
        /// Timed loads per file (median).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// An animated mesh through the engine API: per frame, refit against
    /// rebuild (LBVH, TRBVH), and one frame's rays (closest hits and
    /// occlusion queries) through the refit and the rebuilt tree.
    Dynamic {
        /// The mesh: terrain:N, an .obj/.ply mesh or a .gltf/.glb scene (its triangles).
        #[arg(long, default_value = "terrain:1000000")]
        scene: String,
        /// Timed frames (after one warm-up frame).
        #[arg(long, default_value_t = 11)]
        frames: usize,
        /// The frame's rays: a grid of this many looking down onto the mesh.
        #[arg(long, default_value_t = 1920)]
        width: u32,
        #[arg(long, default_value_t = 1080)]
        height: u32,
        #[arg(long, value_enum, default_value = "gpu")]
        device: DeviceChoice,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// Instancing through the engine API: top-level rebuilds of many
    /// instances, and rays through a grid of copies of a mesh against rays
    /// through the mesh alone.
    Instances {
        /// The mesh: terrain:N, an .obj/.ply mesh or a .gltf/.glb scene (its triangles).
        #[arg(long, default_value = "terrain:100000")]
        scene: String,
        /// Copies on a side of the square grid traced (grid x grid instances).
        #[arg(long, default_value_t = 32)]
        grid: usize,
        /// Instance counts of the timed top-level rebuilds.
        #[arg(long, value_delimiter = ',', default_values_t = vec![1000, 10000, 100000])]
        top_sizes: Vec<usize>,
        #[arg(long, default_value_t = 1920)]
        width: u32,
        #[arg(long, default_value_t = 1080)]
        height: u32,
        #[arg(long, value_enum, default_value = "gpu")]
        device: DeviceChoice,
        /// Timed repeats (median reported), after one warm-up.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// A scene file's or glTF file's own instances (meshes placed by
    /// reference) through the engine API, against the same scene
    /// flattened: memory, build time, rays per second, top-level rebuild
    /// (also named placed, its name before).
    #[command(alias = "placed")]
    FileInstances {
        /// A .gltf/.glb or .json scene that places meshes.
        #[arg(long)]
        scene: std::path::PathBuf,
        #[arg(long, default_value_t = 1920)]
        width: u32,
        #[arg(long, default_value_t = 1080)]
        height: u32,
        #[arg(long, value_enum, default_value = "gpu")]
        device: DeviceChoice,
        /// Timed repeats (median reported), after one warm-up.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// Specialized render kernels against the general one (--kernel full):
    /// render-kernel time per scene, and each kernel's SPIR-V size.
    Variants {
        #[arg(long, value_enum, default_value = "gpu")]
        device: DeviceChoice,
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
        device: DeviceChoice,
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
    let repeats = a.repeats.unwrap_or(if a.quick { 2 } else { 3 }).max(1);
    let suite = Suite { device: a.device, quick: a.quick, out: a.out, repeats, mitsuba };
    suite::run(f, &suite)
}

/// Scenes `bench variants` compares by default: each exercises a different
/// specialized kernel (cornell: no triangles; diffuse and mirror-only
/// variants; spheres and flat shapes, no triangles; many spheres through a
/// BVH; a mesh in smallpt's room).
const VARIANT_SCENES: [&str; 6] = [
    "cornell",
    "cornell_diffuse",
    "cornell_mirrors",
    "room_disk",
    "random:1000",
    "terrain:100000",
];


pub fn run(cmd: BenchCommand) -> Result<()> {
    match cmd {
        BenchCommand::Instances { scene, grid, top_sizes, width, height, device, repeats, json } => {
            let scene = Scene::from_spec(&scene)?;
            let device = device.open()?;
            let before = clocks::read();
            let (adapter, row) = treelet::with_backend!(&device, |b| (
                b.adapter(),
                instances::bench_instances(b, &scene, grid, &top_sizes, (width, height), repeats)?
            ));
            let clocks = matches!(device, Device::Gpu(_)).then(|| (before, clocks::read()));
            println!("instances of {} ({} triangles), {width}x{height}, {adapter}, median of {repeats}", scene.name, row.triangles);
            if let Some((before, after)) = clocks {
                println!("{}", clocks::describe(before, after));
            }
            for (count, device_ms, wall_ms) in &row.top_level {
                println!("  top level, {count:>8} instances {device_ms:>9.3} ms  (wall {wall_ms:.3})");
            }
            let stages: Vec<String> = row.top_level_stages.iter().map(|(s, ms)| format!("{s} {ms:.3}")).collect();
            println!("  largest top level, ms: {}", stages.join(", "));
            let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
            println!("  mesh alone         {:>9.1} M primary rays/s, {:.1} M diffuse", row.single_primary_mrays, row.single_diffuse_mrays);
            println!(
                "  one copy in place  {:>9.1} M primary rays/s, {:.1} M diffuse ({:.2}x, {:.2}x the mesh alone's: the instanced walk's own cost; {} hits differ)",
                row.in_place_primary_mrays,
                row.in_place_diffuse_mrays,
                ratio(row.in_place_primary_mrays, row.single_primary_mrays),
                ratio(row.in_place_diffuse_mrays, row.single_diffuse_mrays),
                row.in_place_differ
            );
            println!(
                "  {} copies       {:>9.1} M primary rays/s, {:.1} M diffuse ({:.2}x, {:.2}x the mesh alone's)",
                row.grid_instances,
                row.instanced_primary_mrays,
                row.instanced_diffuse_mrays,
                ratio(row.instanced_primary_mrays, row.single_primary_mrays),
                ratio(row.instanced_diffuse_mrays, row.single_diffuse_mrays)
            );
            println!(
                "  the same, above    {:>9.1} M primary rays/s, {:.1} M diffuse ({:.2}x, {:.2}x)",
                row.above_primary_mrays,
                row.above_diffuse_mrays,
                ratio(row.above_primary_mrays, row.single_primary_mrays),
                ratio(row.above_diffuse_mrays, row.single_diffuse_mrays)
            );
            if let Some(path) = json {
                let clocks = clocks.map(|(before, after)| serde_json::json!({ "before": before, "after": after }));
                let doc = serde_json::json!({ "adapter": adapter, "width": width, "height": height, "repeats": repeats, "row": row, "clocks": clocks });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::FileInstances { scene, width, height, device, repeats, json } => {
            let scene = treelet::scene::instanced::InstancedScene::load(&scene)?;
            let device = device.open()?;
            let before = clocks::read();
            let (adapter, row) = treelet::with_backend!(&device, |b| (b.adapter(), file_instances::bench_file_instances(b, &scene, (width, height), repeats)?));
            let clocks = matches!(device, Device::Gpu(_)).then(|| (before, clocks::read()));
            println!(
                "{}: {} mesh(es), {} instances ({} triangles kept, {} flattened), {width}x{height}, {adapter}, median of {repeats}",
                scene.loose.name, row.meshes, row.instances, row.triangles_kept, row.triangles_flattened
            );
            if let Some((before, after)) = clocks {
                println!("{}", clocks::describe(before, after));
            }
            println!("  build            {:>9.3} ms instanced (every mesh and the top level), {:.3} flattened", row.build_instanced_ms, row.build_flattened_ms);
            println!("  top level again  {:>9.3} ms  (wall {:.3})", row.top_level_ms, row.top_level_wall_ms);
            let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
            println!(
                "  instances        {:>9.1} M primary rays/s, {:.1} M diffuse ({:.2}x, {:.2}x the flattened scene's)",
                row.instanced_primary_mrays,
                row.instanced_diffuse_mrays,
                ratio(row.instanced_primary_mrays, row.flattened_primary_mrays),
                ratio(row.instanced_diffuse_mrays, row.flattened_diffuse_mrays)
            );
            println!("  flattened        {:>9.1} M primary rays/s, {:.1} M diffuse", row.flattened_primary_mrays, row.flattened_diffuse_mrays);
            println!("  camera rays whose hit differs from the flattened scene's: {} of {}", row.hits_differ, row.camera_rays);
            if let Some(path) = json {
                let clocks = clocks.map(|(before, after)| serde_json::json!({ "before": before, "after": after }));
                let doc = serde_json::json!({ "adapter": adapter, "scene": scene.loose.name, "width": width, "height": height, "repeats": repeats, "row": row, "clocks": clocks });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::Load { files, sizes, dir, repeats, json } => {
            println!("mesh loads on {} threads, median of {repeats}", rayon::current_num_threads());
            let sizes = if sizes.is_empty() && files.is_empty() { vec![1_000_000, 10_000_000] } else { sizes };
            let rows = load::bench_load(&files, &sizes, &dir, repeats)?;
            if let Some(path) = json {
                std::fs::write(&path, serde_json::to_string_pretty(&serde_json::json!({ "threads": rayon::current_num_threads(), "rows": rows }))?)?;
            }
            Ok(())
        }
        BenchCommand::Dynamic { scene, frames, width, height, device, json } => {
            let scene = Scene::from_spec(&scene)?;
            let device = device.open()?;
            let before = clocks::read();
            let (adapter, row) = treelet::with_backend!(&device, |b| (b.adapter(), dynamic::bench_dynamic(b, &scene, frames, (width, height))?));
            let clocks = matches!(device, Device::Gpu(_)).then(|| (before, clocks::read()));
            println!("dynamic mesh {} ({} triangles), {} rays a frame, {adapter}, median of {frames} frames", scene.name, row.triangles, row.rays);
            if let Some((before, after)) = clocks {
                println!("{}", clocks::describe(before, after));
            }
            println!("  refit            {:>9.3} ms  (wall {:.3})", row.refit_ms, row.wall_refit_ms);
            println!("  rebuild, LBVH    {:>9.3} ms  (wall {:.3})", row.rebuild_lbvh_ms, row.wall_rebuild_lbvh_ms);
            println!("  rebuild, TRBVH   {:>9.3} ms  (wall {:.3})", row.rebuild_trbvh_ms, row.wall_rebuild_trbvh_ms);
            println!("  closest hits     {:>9.1} Mray/s refit, {:.1} rebuilt (TRBVH)", row.closest_refit_mrays, row.closest_rebuilt_mrays);
            println!("  occlusion        {:>9.1} Mray/s refit, {:.1} rebuilt (TRBVH)", row.occluded_refit_mrays, row.occluded_rebuilt_mrays);
            println!(
                "  bounce rays ({} a frame, rebuilt TRBVH): diffuse {:.1} Mray/s closest, {:.1} occlusion ({:.2}x); ambient occlusion (reach {}% of the extent) {:.1} closest, {:.1} occlusion ({:.2}x)",
                row.bounce_rays,
                row.closest_diffuse_mrays,
                row.occluded_diffuse_mrays,
                row.occluded_diffuse_mrays / row.closest_diffuse_mrays,
                dynamic::AO_REACH * 100.0,
                row.closest_ao_mrays,
                row.occluded_ao_mrays,
                row.occluded_ao_mrays / row.closest_ao_mrays
            );
            if let Some(path) = json {
                let clocks = clocks.map(|(before, after)| serde_json::json!({ "before": before, "after": after }));
                let doc = serde_json::json!({ "adapter": adapter, "scene": scene.name, "clocks": clocks, "row": row });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::Rays { suite: true, suite_dir, with_optix, accels, layouts, workgroup_stack, width, height, device, repeats, json, .. } => {
            let plan = RaysPlan { layouts, workgroup_stack };
            let dir = suite_dir.as_deref();
            let (adapter, rows, clocks) = match device.open()? {
                Device::Gpu(ctx) => {
                    let mut b = GpuBackend::new(ctx);
                    let before = clocks::read();
                    let rows = rays_suite::run(&mut b, dir, &accels, &plan, (width, height), repeats, with_optix)?;
                    (b.adapter(), rows, Some((before, clocks::read())))
                }
                Device::Cpu => {
                    let mut b = CpuBackend::new();
                    let rows = rays_suite::run(&mut b, dir, &accels, &plan, (width, height), repeats, with_optix)?;
                    (b.adapter(), rows, None)
                }
            };
            println!("rays per second, the real-scene suite, {width}x{height}, {adapter}, median of {repeats}");
            if let Some((before, after)) = clocks {
                println!("{}", clocks::describe(before, after));
            }
            rays_suite::print(&rows);
            if let Some(path) = json {
                let clocks = clocks.map(|(before, after)| serde_json::json!({ "before": before, "after": after }));
                let doc = serde_json::json!({ "adapter": adapter, "width": width, "height": height, "repeats": repeats, "rows": rows, "clocks": clocks });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
        BenchCommand::Rays { scene, accels, layouts, workgroup_stack, width, height, device, repeats, mesh_only, camera, json, figure, optix, .. } => {
            // The peer's file first: a bad one fails before minutes of timing.
            let peer = optix.as_deref().map(tradeoff::read_peer).transpose()?;
            let spec = scene;
            let scene = Scene::from_spec(&spec)?;
            let mut scene = if mesh_only { scene.mesh_only()? } else { scene };
            if let Some(text) = camera {
                let c: Vec<f32> = text.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().ok().filter(|c: &Vec<f32>| c.len() == 6).ok_or_else(|| {
                    anyhow::anyhow!("--camera {text}: expected six numbers EX,EY,EZ,TX,TY,TZ (eye, then the point looked at)")
                })?;
                scene.camera = CameraSpec::looking_at([c[0], c[1], c[2]], [c[3], c[4], c[5]])?;
            }
            if let Some(p) = &peer {
                tradeoff::check_peer(p, scene.triangles.len(), (width, height))?;
            }
            let plan = RaysPlan { layouts, workgroup_stack };
            let mut rows = Vec::new();
            let mut clocks = None;
            let opened = device.open()?;
            let kind = if matches!(opened, Device::Gpu(_)) { "gpu" } else { "cpu" };
            let adapter = match opened {
                Device::Gpu(ctx) => {
                    let mut b = GpuBackend::new(ctx);
                    let before = clocks::read();
                    for &a in &accels {
                        rows.extend(bench_rays(&mut b, &scene, a, &plan, (width, height), repeats)?);
                    }
                    clocks = Some((before, clocks::read()));
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
            if let Some((before, after)) = clocks {
                println!("{}", clocks::describe(before, after));
            }
            println!(
                "{:>6}{:>8}{:>10}{:>11}{:>11}{:>12}{:>12}{:>16}{:>16}{:>16}",
                "accel", "layout", "stack", "build ms", "layout ms", "primary ms", "diffuse ms", "primary Mray/s", "diffuse Mray/s", "occluded Mray/s"
            );
            for r in rows.iter().filter(|r| r.layout_stages.len() > 1) {
                let stages: Vec<String> = r.layout_stages.iter().map(|(s, ms)| format!("{s} {ms:.3}")).collect();
                eprintln!("{} layout of the {:?} tree, ms: {}", r.layout.name(), r.accel, stages.join(", "));
            }
            for r in &rows {
                println!(
                    "{:>6}{:>8}{:>10}{:>11.3}{:>11.3}{:>12.3}{:>12.3}{:>16.1}{:>16.1}{:>16.1}",
                    format!("{:?}", r.accel).to_lowercase(),
                    r.layout.name(),
                    r.stack,
                    r.build_ms,
                    r.layout_ms,
                    r.primary_median_ms,
                    r.diffuse_median_ms,
                    r.primary_mrays_per_s,
                    r.diffuse_mrays_per_s,
                    r.occlusion_mrays_per_s
                );
            }
            if let Some(path) = json {
                let clocks = clocks.map(|(before, after)| serde_json::json!({ "before": before, "after": after }));
                let doc = serde_json::json!({ "adapter": adapter, "width": width, "height": height, "repeats": repeats, "rows": rows, "clocks": clocks });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            if let Some(dir) = figure {
                tradeoff::write(&dir, &rows, (width, height), (kind, &adapter), peer.as_ref())?;
                eprintln!("wrote {}/tradeoff-primary.png and tradeoff-diffuse.png", dir.display());
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
            results::collect(&runs, &out)?;
            eprintln!("wrote {}", out.display());
            Ok(())
        }
        BenchCommand::Variants { device, quick, scenes, repeats, json } => {
            let size = if quick { (256, 192, 16) } else { (1024, 768, 64) };
            let (adapter, rows) = match device.open()? {
                Device::Gpu(ctx) => {
                    let mut b = GpuBackend::new(ctx);
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
            let (adapter, (graph1, graph2)) = match device.open()? {
                Device::Gpu(ctx) => {
                    let mut b = GpuBackend::new(ctx);
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
        BenchCommand::Build { builder, rounds, gamma, max_leaf, reinsert, sizes, device, repeats, json, per_kernel } => {
            let rounds = rounds.unwrap_or(if builder == Builder::Trbvh { TreeletConfig::default().rounds } else { 0 });
            let defaults = TreeletConfig::default();
            let config = TreeletConfig { rounds, gamma, max_leaf, reinsert: reinsert.or(defaults.reinsert), ..defaults };
            if matches!(builder, Builder::Sweep | Builder::Reference) {
                anyhow::bail!("bench build times the device builders (lbvh, trbvh, hploc); time the CPU builders with `treelet build --builder {} --device cpu`", builder.name());
            }
            let treelets = (builder, &config);
            let (adapter, timing, rows, clocks) = match device.open()? {
                Device::Gpu(ctx) => {
                    let mut b = GpuBackend::new(ctx).with_per_kernel_times(per_kernel);
                    let ts = if b.context().timestamps { "gpu-timestamps" } else { "wall-clock" };
                    let before = clocks::read();
                    let rows = bench_sizes(&mut b, &sizes, repeats, treelets)?;
                    (b.adapter(), ts, rows, Some((before, clocks::read())))
                }
                Device::Cpu => {
                    let mut b = CpuBackend::new();
                    (b.adapter(), "wall-clock", bench_sizes(&mut b, &sizes, repeats, treelets)?, None)
                }
            };
            println!("{builder:?} build, {adapter} ({timing}), median of {repeats} (ms)");
            if let Some((before, after)) = clocks {
                println!("{}", clocks::describe(before, after));
            }
            // Every stage (or kernel) any size ran, in the order first run:
            // the kernels differ by size (the sort's tiles, the hierarchy).
            let mut names: Vec<&str> = Vec::new();
            for (s, _) in rows.iter().flat_map(|r| &r.median_ms) {
                if !names.contains(s) {
                    names.push(s);
                }
            }
            let short = |s: &str| s.rsplit("::").next().unwrap_or(s).trim_end_matches("_cs").to_string();
            let width = names.iter().map(|s| short(s).len() + 2).max().unwrap_or(9).max(9);
            print!("{:>10}", "N");
            for s in &names {
                print!("{:>width$}", short(s));
            }
            println!("{:>10}{:>10}", "total", "Mprims/s");
            for r in &rows {
                print!("{:>10}", r.primitives);
                for name in &names {
                    match r.median_ms.iter().find(|(s, _)| s == name) {
                        Some((_, v)) => print!("{v:>width$.3}"),
                        None => print!("{:>width$}", "-"),
                    }
                }
                println!("{:>10.3}{:>10.1}", r.total_median_ms, r.mprims_per_s);
            }
            if let Some(path) = json {
                let builder = format!("{builder:?}").to_lowercase();
                let doc = serde_json::json!({
                    "adapter": adapter, "builder": builder, "treelets": treelets,
                    "timing": timing, "repeats": repeats, "rows": rows,
                    "clocks": clocks.map(|(before, after)| serde_json::json!({ "before": before, "after": after }))
                });
                std::fs::write(&path, serde_json::to_string_pretty(&doc)?)?;
            }
            Ok(())
        }
    }
}
