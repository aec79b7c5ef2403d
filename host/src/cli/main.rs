//! `treelet`: build BVHs, trace and render them, on the GPU or the CPU.
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};

use treelet::runtime::device::{Device, DeviceChoice};
use treelet::runtime::gpu::GpuContext;
use treelet::render::image_io;
use treelet::bvh::layout::Layout;
use treelet::internals::plot::Series;
use treelet::bvh::tree::{Accel, Builder};
use treelet::render::parts::{self, PartInfo};
use treelet::render::settings::MemoryEstimate;
use treelet::render::{Control, Integrator, PassRow, RenderSettings, Sampler, Stopped};
use treelet::runtime::memory::{available_bytes, human};
use treelet::bvh::report::{run_build_with, run_build_cpu, BuildReport};
use treelet::scene::Scene;
use treelet::bvh::trbvh::TreeletConfig;
use treelet::render::variant::{self, KernelChoice};

// Output that never panics on a full or closed stream (`treelet::internals::console`);
// defined before the modules, so that theirs are these.
macro_rules! println {
    () => { treelet::internals::console::out(format_args!(""), true) };
    ($($t:tt)*) => { treelet::internals::console::out(format_args!($($t)*), true) };
}
macro_rules! print {
    ($($t:tt)*) => { treelet::internals::console::out(format_args!($($t)*), false) };
}
macro_rules! eprintln {
    () => { treelet::internals::console::err(format_args!("")) };
    ($($t:tt)*) => { treelet::internals::console::err(format_args!($($t)*)) };
}

mod bench;
#[cfg(test)]
mod cli_help;

#[derive(Parser)]
#[command(name = "treelet", version, about = "GPU BVH construction (Karras 2012) and a smallpt path tracer, in Rust")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The largest file (scene, mesh, image, part) read, in bytes.
    #[arg(long, global = true, value_name = "BYTES", default_value_t = treelet::internals::input::DEFAULT_MAX_INPUT_BYTES)]
    max_input_bytes: u64,
}


#[derive(Subcommand)]
enum Command {
    /// Build a BVH over a scene, check it, and report its cost and stage times.
    Build {
        /// Scene: random:N[:SEED] (N spheres), terrain:N (N triangles), city:N[:SEED] (N triangles of a city), cornell, room_disk, a .json scene file, a .gltf/.glb scene, or an .obj/.ply mesh.
        #[arg(long, default_value = "random:100000")]
        scene: String,
        #[arg(long, value_enum, default_value = "lbvh")]
        builder: Builder,
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
        /// Treelet optimization rounds after the build: trbvh (default 3),
        /// hploc (default 0: the tree as H-PLOC merged it).
        #[arg(long)]
        rounds: Option<u32>,
        /// Smallest subtree restructured in the first round, doubled each round (trbvh).
        #[arg(long, default_value_t = TreeletConfig::default().gamma)]
        gamma: u32,
        /// Largest leaf the final SAH collapse makes; 1 keeps one primitive per leaf (trbvh, sweep).
        #[arg(long, default_value_t = TreeletConfig::default().max_leaf, value_parser = clap::value_parser!(u32).range(1..=1024))]
        max_leaf: u32,
        /// Iterations of parallel reinsertion after the rounds (Meister and Bittner 2018: nodes moved where they lower the SAH most; trbvh, hploc). Default: 2 for trbvh on GPUs, else 0.
        #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
        reinsert: Option<u32>,
        /// Print one JSON object instead of a summary.
        #[arg(long)]
        json: bool,
    },
    /// Path-trace a scene (smallpt) and write the image, with an error report.
    Render(RenderArgs),
    /// Add the parts of a render (render --samples A..B --out part.exr,
    /// from other processes or machines) into one image; checks that they
    /// share scene, size, seed and integrator, and that their sample ranges
    /// neither overlap nor leave gaps.
    Merge {
        #[arg(required = true)]
        parts: Vec<std::path::PathBuf>,
        /// The image: .png (gamma 2.2), .exr or .pfm (linear means).
        #[arg(long, default_value = "treelet.png")]
        out: std::path::PathBuf,
    },
    /// Score an image (.exr or .pfm, linear) against a reference with the
    /// render's own error measure; prints one JSON object (rmse, rel_mse).
    Compare {
        image: std::path::PathBuf,
        #[arg(long)]
        reference: std::path::PathBuf,
    },
    /// Write a scene's triangles as a binary PLY mesh, for other tracers
    /// (peers/mitsuba/rays.py times OptiX on it), or as OBJ text where
    /// --out ends in .obj: a generated scene, a glTF or scene file
    /// flattened, or a mesh.
    Export {
        /// Scene: terrain:N, city:N[:SEED], a .json scene file, a .gltf/.glb scene, or an .obj/.ply mesh.
        #[arg(long)]
        scene: String,
        #[arg(long)]
        out: std::path::PathBuf,
    },
    /// Benchmarks (medians over repeats; GPU stage times from timestamp queries).
    Bench {
        #[command(subcommand)]
        what: bench::BenchCommand,
    },
}

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
struct RenderArgs {
    /// Scene: cornell, room_disk, cornell_diffuse or cornell_mirrors (built in), random:N[:SEED] (N spheres in the Cornell box), terrain:N (N triangles), city:N[:SEED] (N triangles of a city), a .json scene file, a .gltf/.glb scene, or an .obj/.ply mesh (alone under a white sky, seen from above).
    #[arg(long, default_value = "cornell")]
    scene: String,
    /// Trace a scene file's or glTF file's copies of meshes flattened into
    /// the scene's own triangles, as build does (by default a mesh placed
    /// more than once is traced as instances: one tree per mesh).
    #[arg(long)]
    flatten: bool,
    /// A glTF scene's camera N (its index in the file's cameras list),
    /// placed by the first node that names it; by default the first
    /// perspective camera the scene places, else one framing the scene.
    #[arg(long, value_name = "N")]
    camera: Option<usize>,
    /// A uniform sky of radiance R,G,B around the scene (over a scene
    /// file's environment): what rays that leave the scene see.
    #[arg(long, value_name = "R,G,B", value_parser = parse_sky)]
    environment: Option<[f32; 3]>,
    /// A thin lens on the scene's camera (over a scene file's): its radius,
    /// and the distance along the view of the plane kept sharp.
    #[arg(long, value_name = "RADIUS,FOCUS", value_parser = parse_lens)]
    lens: Option<(f32, f32)>,
    #[arg(long, default_value_t = 512, value_parser = positive)]
    width: u32,
    #[arg(long, default_value_t = 384, value_parser = positive)]
    height: u32,
    /// Samples per pixel (taken in turn by the 2x2 subpixels).
    #[arg(long, default_value_t = 64, conflicts_with = "samples", value_parser = positive)]
    spp: u32,
    /// Render only samples FIRST..LAST (LAST excluded) and write them to
    /// --out (.exr) as a part: per-pixel sums and the range in its header,
    /// for treelet merge to add to the other parts.
    #[arg(long, value_name = "FIRST..LAST", value_parser = parse_range)]
    samples: Option<std::ops::Range<u32>>,
    /// How closest hits are found: through which tree, or a linear scan.
    #[arg(long, value_enum, default_value = "auto")]
    accel: Accel,
    /// How the tree is laid out for traversal.
    #[arg(long, value_enum, default_value = "auto")]
    layout: Layout,
    /// Render kernel: auto, the variant compiled for the scene's features
    /// only; full, the general one (for comparison).
    #[arg(long, value_enum, default_value = "auto")]
    kernel: KernelChoice,
    /// Print the scene's features and the accel and kernel chosen, and why.
    #[arg(long)]
    explain: bool,
    #[arg(long, value_enum, default_value = "nee")]
    integrator: IntegratorArg,
    /// Where paths draw their sample points (independent numbers run the
    /// general kernel: the smaller variants draw Sobol points only).
    #[arg(long, value_enum, default_value = "sobol")]
    sampler: Sampler,
    #[arg(long, value_enum, default_value = "auto")]
    device: DeviceChoice,
    /// Render on several devices at once, each taking chunks of samples as
    /// it finishes the last (without it, a machine with several GPUs renders
    /// on all its GPUs; --devices 0 takes one): all (every Vulkan adapter; the CPU runner where
    /// there is none: beside a GPU or lavapipe it slowed renders, measured),
    /// gpu (every adapter), or a list of adapter indices or names and cpu
    /// (--devices list prints the adapters).
    #[arg(long, value_name = "all|gpu|LIST", conflicts_with = "device")]
    devices: Option<String>,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Output image: .png (gamma 2.2, clamped), .exr or .pfm (linear).
    #[arg(long, default_value = "treelet.png")]
    out: std::path::PathBuf,
    /// Linear reference image (.exr or .pfm) to measure the error against.
    #[arg(long)]
    reference: Option<std::path::PathBuf>,
    /// Write the error-against-time rows and run facts as JSON here.
    #[arg(long)]
    report: Option<std::path::PathBuf>,
    /// Every SECONDS, write the samples done so far as a part (beside
    /// --out as NAME.part.exr, or --out itself with --samples), so that a
    /// crash loses at most that much; removed when the render completes.
    /// Ctrl-C writes it (and the image of the samples done) in any case.
    #[arg(long, value_name = "SECONDS")]
    checkpoint: Option<f64>,
    /// Continue the render that PART.exr (a checkpoint, or a render stopped
    /// with Ctrl-C) holds the start of: same scene, size, seed,
    /// integrator and sampler; --spp (or --samples) names where it ends. On the CPU
    /// runner the image is the uninterrupted render's, bit for bit.
    #[arg(long, value_name = "PART.exr")]
    resume: Option<std::path::PathBuf>,
}

/// How radiance is estimated (--integrator): one by name, or auto.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum IntegratorArg {
    /// smallpt's: emitters count only where paths hit them.
    Smallpt,
    /// A light sampled at every diffuse bounce, with multiple importance
    /// sampling (on the H100, about as little error as smallpt's estimator
    /// at equal time on cornell, half of it on scenes/room_disk.json).
    Nee,
    /// nee, and one light path per camera path through mirrors and glass
    /// to what the camera sees: the caustics nee cannot find (the disk-lit
    /// room: 0.89x nee's error at equal time; cornell: 4x).
    Caustics,
    /// nee or caustics, whichever a pilot (four short images, thrown away)
    /// measures to give less error in equal time; nee without mirrors or
    /// glass lit by a lamp, or where the pilot would take over an eighth of
    /// the render's samples. --explain gives the measurements.
    Auto,
}

impl IntegratorArg {
    /// The integrator named; `None` for `auto`.
    fn fixed(self) -> Option<Integrator> {
        match self {
            IntegratorArg::Smallpt => Some(Integrator::Smallpt),
            IntegratorArg::Nee => Some(Integrator::Nee),
            IntegratorArg::Caustics => Some(Integrator::Caustics),
            IntegratorArg::Auto => None,
        }
    }
}

/// A whole number from 1 to 2^32 - 1 (sizes, sample counts).
fn positive(s: &str) -> std::result::Result<u32, String> {
    match s.trim().parse::<i64>() {
        Ok(v) if v >= 1 && v <= u32::MAX as i64 => Ok(v as u32),
        Ok(v) => Err(format!("{v} is not a positive whole number below 2^32")),
        Err(_) => Err(format!("`{s}` is not a whole number")),
    }
}

/// Comma-separated finite numbers, `n` of them.
fn numbers(s: &str, n: usize, what: &str) -> std::result::Result<Vec<f32>, String> {
    let v: Vec<f32> = s.split(',').map(|x| x.trim().parse::<f32>()).collect::<std::result::Result<_, _>>().map_err(|_| format!("`{s}`: expected {what}"))?;
    if v.len() != n || !v.iter().all(|x| x.is_finite()) {
        return Err(format!("`{s}`: expected {what}, {n} finite numbers"));
    }
    Ok(v)
}

/// `R,G,B`, as scene files' `environment` is checked.
fn parse_sky(s: &str) -> std::result::Result<[f32; 3], String> {
    let v = numbers(s, 3, "R,G,B")?;
    let sky = [v[0], v[1], v[2]];
    treelet::scene::file::check_sky(sky).map_err(|e| format!("`{s}`: {e}"))?;
    Ok(sky)
}

/// `RADIUS,FOCUS`, as scene files' lenses are checked.
fn parse_lens(s: &str) -> std::result::Result<(f32, f32), String> {
    let v = numbers(s, 2, "RADIUS,FOCUS")?;
    treelet::scene::file::check_lens(v[0], v[1]).map_err(|e| format!("`{s}`: {e}"))?;
    Ok((v[0], v[1]))
}

/// `A..B` (B excluded) with A < B.
fn parse_range(s: &str) -> std::result::Result<std::ops::Range<u32>, String> {
    let (a, b) = s.split_once("..").ok_or_else(|| format!("`{s}`: expected FIRST..LAST, e.g. 0..256"))?;
    let (a, b): (u32, u32) = (a.parse().map_err(|_| format!("`{a}` is not a sample index"))?, b.parse().map_err(|_| format!("`{b}` is not a sample index"))?);
    if a >= b {
        return Err(format!("`{s}`: the range is empty (FIRST must be below LAST)"));
    }
    Ok(a..b)
}

/// Set by Ctrl-C (SIGINT), SIGTERM or SIGHUP: a render stops handing out
/// samples, finishes the chunks under way and writes what it has.
static STOP: AtomicBool = AtomicBool::new(false);

/// The first signal stops the render gently; a second quits at once.
fn catch_stop_signals() {
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            eprintln!("\nstopped at once: nothing more is written");
            std::process::exit(130);
        }
        eprintln!("\nstopping: the chunks under way finish, then the samples done are written (again to quit at once)");
    });
}

/// Where `path` leads, for comparing outputs that do not exist yet: the
/// file itself where it exists, else its folder resolved and its name (so
/// `./o.pfm`, `sub/../o.pfm` and `/abs/o.pfm` are one file), and a link
/// that points nowhere yet by where it points.
fn resolved(path: &std::path::Path) -> std::path::PathBuf {
    if let Ok(full) = path.canonicalize() {
        return full;
    }
    let in_folder = |p: &std::path::Path| match (p.parent(), p.file_name()) {
        (Some(dir), Some(name)) => {
            let dir = if dir.as_os_str().is_empty() { std::path::Path::new(".") } else { dir };
            dir.canonicalize().map_or_else(|_| p.to_path_buf(), |d| d.join(name))
        }
        _ => p.to_path_buf(),
    };
    match std::fs::read_link(path) {
        Ok(target) if target.is_absolute() => in_folder(&target),
        Ok(target) => in_folder(&path.parent().unwrap_or(std::path::Path::new(".")).join(target)),
        Err(_) => in_folder(path),
    }
}

fn run_render(mut args: RenderArgs) -> Result<()> {
    let part = args.samples.clone();
    // Every output is checked before any work, so a typo never costs a render.
    if let Some(range) = &part {
        if image_io::extension(&args.out) != "exr" {
            anyhow::bail!("--samples writes a part of a render: --out must name an .exr file (not {})", args.out.display());
        }
        image_io::check_output(&args.out, "--out", &["exr"])?;
        args.spp = range.end - range.start;
    } else {
        image_io::check_output(&args.out, "--out", &image_io::IMAGE_FORMATS)?;
    }
    // Where the samples done go when the render stops early, and its
    // checkpoints: the part itself with --samples, else beside the image.
    let part_path = if part.is_some() { args.out.clone() } else { args.out.with_extension("part.exr") };
    if part.is_none() {
        image_io::check_output(&part_path, "the part beside --out", &["exr"])?;
    }
    if let Some(report) = &args.report {
        image_io::check_output(report, "--report", &[])?;
    }
    // Files one render would write over another it reads or writes.
    let same = |a: &std::path::Path, b: &std::path::Path| a == b || resolved(a) == resolved(b);
    if let (Some(resume), None) = (&args.resume, &part) {
        if same(resume, &args.out) {
            anyhow::bail!("--resume {} and --out name the same file: the image would replace the part it continues", resume.display());
        }
    }
    // One render at a time writes --out and the part beside it.
    let _lock = treelet::render::lock::OutputLock::take(&args.out)?;
    // Samples a stopped render left where this one would write its own (a
    // checkpoint beside --out, or an unfinished part at --out): written over
    // without resuming them, they would be lost.
    if part_path.exists() && !args.resume.as_ref().is_some_and(|r| same(r, &part_path)) {
        let unfinished = match parts::read_part(&part_path) {
            // Beside --out, a part is always one a render did not finish (a
            // finished render removes it); at --out, one short of its plan.
            Ok((info, _)) => part.is_none() || info.samples.end < info.planned_end,
            Err(_) => false,
        };
        // Read to be judged, not as an input: a finished part this render
        // will write over again (a requeued Slurm or Kubernetes task) is
        // not one of the inputs no output may replace.
        treelet::internals::input::forget_read(&part_path);
        if unfinished {
            anyhow::bail!(
                "{} holds the samples of a render that did not finish: continue it with `--resume {}` and the same options, or delete it to start again",
                part_path.display(),
                part_path.display()
            );
        }
    }
    if let Some(report) = &args.report {
        for (other, what) in [(Some(&args.out), "--out"), (args.resume.as_ref(), "--resume"), (Some(&part_path), "the part beside --out")] {
            if other.is_some_and(|o| same(report, o)) {
                anyhow::bail!("--report {} names the same file as {what}: one would replace the other", report.display());
            }
        }
    }
    if args.integrator == IntegratorArg::Auto && part.is_some() {
        anyhow::bail!(
            "--integrator auto with --samples: parts rendered apart must share one integrator, and a pilot on each machine may choose another; name one (nee or caustics)"
        );
    }
    // A bound, so that the time of the next checkpoint is one a clock holds
    // (1e19 s overflowed the program's clock, 1e30 its durations).
    const MAX_CHECKPOINT_S: f64 = 1e9;
    if args.checkpoint.is_some_and(|s| !(s > 0.0 && s <= MAX_CHECKPOINT_S)) {
        anyhow::bail!(
            "--checkpoint {}: seconds between checkpoints must be a positive number, at most {MAX_CHECKPOINT_S:e} (about 31 years)",
            args.checkpoint.unwrap_or(0.0)
        );
    }
    if args.devices.as_deref() == Some("list") {
        for (i, name) in GpuContext::adapters().iter().enumerate() {
            println!("{i}: {name}");
        }
        println!("cpu: the CPU runner");
        return Ok(());
    }
    // The devices open (Vulkan's instance and device: a tenth of a second
    // each on an H100) while the scene and any parts load.
    let opening = OpenDevices::start(args.devices.clone(), args.device);
    let mut scene = match args.camera {
        Some(camera) => Scene::with_gltf_camera(&args.scene, camera, args.flatten)?,
        None if args.flatten => Scene::from_spec(&args.scene)?,
        None => Scene::for_render(&args.scene)?,
    };
    if let Some(sky) = args.environment {
        scene.environment = sky;
    }
    if let Some((radius, focus)) = args.lens {
        (scene.camera.lens_radius, scene.camera.focus_distance) = (radius, focus);
    }
    treelet::runtime::timeline::mark("scene");
    if scene.materials.iter().all(|m| m.emission.iter().all(|&e| e == 0.0)) && scene.environment == [0.0; 3] {
        eprintln!("warning: {}: nothing in the scene emits light, so the image will be black", scene.name);
    }
    let first_sample = part.as_ref().map_or(0, |r| r.start);
    let resumed = args.resume.as_deref().map(|path| parts::read_part(path).map(|r| (path, r))).transpose()?;
    let reference = args.reference.as_deref().map(|r| parts::read_scored_image(r, "--reference")).transpose()?;
    // No output over a file this render read: its scene, the meshes and
    // buffers that names, the reference. (The part it continues is written
    // over by its checkpoints: that is what continuing it means.)
    for (output, what) in [(Some(&args.out), "--out"), (args.report.as_ref(), "--report"), (Some(&part_path), "the part beside --out")] {
        if let Some(output) = output.filter(|o| !args.resume.as_ref().is_some_and(|r| same(r, o))) {
            treelet::internals::input::refuse_if_read(output, what)?;
        }
    }
    let mut settings = RenderSettings {
        width: args.width,
        height: args.height,
        spp: args.spp,
        seed: args.seed,
        accel: args.accel,
        layout: args.layout,
        kernel: args.kernel,
        integrator: Integrator::Nee,
        sampler: args.sampler,
        error_each_pass: args.report.is_some() || args.reference.is_some(),
        first_sample,
    };
    let list = opening.finish()?;
    // The integrator: the one named; for `auto`, the one a resumed part was
    // made with, else the pilot's choice.
    let (integrator, choice) = match (args.integrator.fixed(), &resumed) {
        (Some(i), _) => (i, None),
        (None, Some((path, (info, _)))) => {
            let i = Integrator::from_name(&info.integrator).with_context(|| {
                format!("--resume {}: the part's integrator `{}` is not one this build knows", path.display(), info.integrator)
            })?;
            (i, Some(format!("the part resumed was rendered with {}", i.name())))
        }
        (None, None) => {
            let c = treelet::render::integrator_choice::choose(&list, &scene, &settings)?;
            (c.integrator, Some(c.reason))
        }
    };
    settings.integrator = integrator;
    let part_info = |samples: std::ops::Range<u32>| PartInfo {
        scene: scene.name.clone(),
        scene_hash: format!("{:016x}", scene.content_hash()),
        width: args.width,
        height: args.height,
        seed: args.seed,
        integrator: integrator.name().into(),
        sampler: args.sampler.name().into(),
        samples,
        planned_end: first_sample.saturating_add(args.spp),
    };
    let resume = match resumed {
        Some((path, (info, sums))) => {
            let asked = part_info(first_sample..first_sample.saturating_add(args.spp));
            if let Some(why) = info.differs_from(&asked) {
                anyhow::bail!("--resume {}: the part is of another render than this one: {why}", path.display());
            }
            if info.samples.start != asked.samples.start || info.samples.end > asked.samples.end {
                anyhow::bail!(
                    "--resume {}: the part holds samples {}..{}, and this render is of {}..{}: it must start where the part starts and end no earlier",
                    path.display(),
                    info.samples.start,
                    info.samples.end,
                    asked.samples.start,
                    asked.samples.end
                );
            }
            Some((info.samples, sums))
        }
        None => None,
    };
    let bar = ProgressBar::new(args.spp as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} spp  {elapsed_precise}  {msg}").unwrap());
    let on_pass = |row: &PassRow| {
        bar.set_position(row.spp as u64);
        let err = match (row.rmse, row.mean_std_error) {
            (Some(e), _) => format!("rmse {e:.4}"),
            (_, Some(e)) => format!("std error {e:.4}"),
            _ => String::new(),
        };
        bar.set_message(err);
    };
    let classes: Vec<_> = list.iter().map(Device::class).collect();
    let memory = MemoryEstimate::of(&settings, scene.traced_primitives(), &classes);
    if args.explain {
        bar.suspend(|| {
            eprintln!("{}", variant::plan(&scene, settings.paths(), args.accel, args.layout, args.kernel, list[0].class(), integrator == Integrator::Caustics, args.sampler == Sampler::Independent).explain());
            eprintln!(
                "memory     about {} of host memory (image {}, scene and trees {}); {} available (TREELET_MAX_MEMORY caps it)",
                human(memory.total_bytes),
                human(memory.image_bytes),
                human(memory.scene_bytes),
                available_bytes().map_or("unknown".into(), human)
            );
            for d in &list {
                if let Device::Gpu(ctx) = d {
                    let needed = MemoryEstimate::device_bytes(&settings, scene.traced_primitives());
                    let has = ctx.device_memory.map_or("an unknown amount".into(), human);
                    eprintln!("           about {} of device memory on {}, which has {has}", human(needed), ctx.info.name);
                }
            }
            let features = variant::SceneFeatures::of(&scene);
            let has_caustics = features.mirror + features.glass > 0 && features.emissive > 0;
            if let Some(why) = &choice {
                eprintln!("integrator {} (auto: {why})", integrator.name());
            } else { eprintln!("integrator {}", match (integrator, has_caustics) {
                (Integrator::Smallpt, _) => "smallpt (emitters count where paths hit them; --integrator)",
                (Integrator::Nee, false) => "nee (a light sampled at every diffuse bounce, weighted by multiple importance sampling; --integrator)",
                (Integrator::Nee, true) => "nee (a light sampled at every diffuse bounce, weighted by multiple importance sampling; --integrator).\n           The scene has mirrors or glass, so caustics: `--integrator caustics` adds light paths for them\n           (the disk-lit room: 0.89x nee's error at equal time on an H100; not the default, as a lamp mostly hidden, as cornell's, makes them noisy;\n           `--integrator auto` measures both first)",
                (Integrator::Caustics, true) => "caustics (nee, and one light path per camera path, traced through mirrors and glass to the diffuse points the camera sees: the caustics nee cannot find; --integrator)",
                (Integrator::Caustics, false) => "caustics: without mirrors or glass, or without lights, the scene has none, so this is nee (--integrator)",
            }); }
        });
    }
    catch_stop_signals();
    let mut checkpoints = 0u32;
    let mut write_checkpoint = |samples: std::ops::Range<u32>, sums: &[[f32; 4]]| -> Result<()> {
        parts::write_part(&part_path, &part_info(samples.clone()), sums)?;
        checkpoints += 1;
        bar.println(format!("checkpoint: samples {}..{} in {}", samples.start, samples.end, part_path.display()));
        Ok(())
    };
    let control = Control {
        stop: Some(&STOP),
        checkpoint: args.checkpoint.map(|s| (std::time::Duration::from_secs_f64(s), &mut write_checkpoint as &mut dyn FnMut(_, &_) -> _)),
        resume: resume.as_ref().map(|(r, sums)| (r.clone(), sums.as_slice())),
        inject: None,
    };
    let result = treelet::render::devices::render_on_devices(&list, &scene, &settings, reference.as_ref(), control, on_pass)?;
    bar.finish_and_clear();
    // A NaN or infinite pixel is a wrong image, whatever made it: said, not
    // left for the user to find.
    let bad = result.image.pixels.iter().filter(|p| !p.iter().all(|v| v.is_finite())).count();
    if bad > 0 {
        eprintln!("warning: {bad} of {} pixels are NaN or infinite (a material or light out of range?)", result.image.pixels.len());
    }
    // So is an image of nothing at all from a scene that emits light (the
    // note before the render covers one that does not): the camera sees
    // nothing lit, or nothing at all.
    let emits = scene.materials.iter().any(|m| m.emission.iter().any(|&e| e > 0.0));
    if emits && result.samples.end > result.samples.start && result.image.pixels.iter().all(|p| p.iter().all(|&v| v == 0.0)) {
        eprintln!(
            "warning: every pixel of the image is black: the camera sees nothing lit (is its near plane past the scene, or the scene flattened by a transform?)"
        );
    }
    let done = result.samples.clone();
    let write_start = std::time::Instant::now();
    match (&result.stopped, &part) {
        (None, Some(_)) => parts::write_part(&args.out, &part_info(done.clone()), &result.sums)?,
        (None, None) => {
            image_io::write(&args.out, &result.image)?;
            // The image holds every sample now: the checkpoint is spent.
            if checkpoints > 0 {
                let _ = std::fs::remove_file(&part_path);
            }
        }
        (Some(_), _) => {
            // The samples done, as a part that `merge` and `--resume` take and,
            // without --samples, as the image of them.
            parts::write_part(&part_path, &part_info(done.clone()), &result.sums)?;
            if part.is_none() {
                image_io::write(&args.out, &result.image)?;
            }
        }
    }
    let write_s = write_start.elapsed().as_secs_f64();
    treelet::runtime::timeline::mark("image written");
    let startup = match &list[..] {
        [Device::Gpu(ctx)] => {
            let (pipelines, pipelines_s) = ctx.pipelines_built();
            let (prepare_s, slowest) = ctx.pipeline_report(3);
            serde_json::json!({
                "device_s": ctx.startup.device_s,
                "module_s": ctx.startup.module_s,
                "pipelines": pipelines,
                "pipelines_s": pipelines_s,
                "pipelines_ahead_wall_s": prepare_s,
                "slowest_pipelines": slowest.iter().map(|(k, s)| serde_json::json!({"kernel": k.entry_point(), "s": s})).collect::<Vec<_>>(),
                "pipeline_cache": if !ctx.has_pipeline_cache() { "none" } else if ctx.startup.cache_loaded { "loaded" } else { "new" },
            })
        }
        _ => serde_json::Value::Null,
    };
    if args.explain && !startup.is_null() {
        eprintln!(
            "start-up   device {:.3} s, shader module {:.3} s, {} pipelines {:.3} s, built ahead in {:.3} s of wall (pipeline cache: {}); image written in {write_s:.3} s",
            startup["device_s"].as_f64().unwrap_or(0.0),
            startup["module_s"].as_f64().unwrap_or(0.0),
            startup["pipelines"],
            startup["pipelines_s"].as_f64().unwrap_or(0.0),
            startup["pipelines_ahead_wall_s"].as_f64().unwrap_or(0.0),
            startup["pipeline_cache"].as_str().unwrap_or("none"),
        );
        let slowest: Vec<String> = startup["slowest_pipelines"]
            .as_array()
            .map(|a| a.iter().map(|p| format!("{} {:.3} s", p["kernel"].as_str().unwrap_or("?"), p["s"].as_f64().unwrap_or(0.0))).collect())
            .unwrap_or_default();
        if !slowest.is_empty() {
            eprintln!("           slowest pipelines: {}", slowest.join(", "));
        }
    }
    if args.explain {
        eprintln!("timeline   {} s (the stages of this process so far, each ending where named)", treelet::runtime::timeline::summary());
        let sizes: Vec<String> = result.shares.iter().map(|s| format!("{}: up to {} spp each", s.device, s.dispatch_samples)).collect();
        eprintln!(
            "dispatches {} (a GPU's are sized to its rate, about {} s each)",
            sizes.join(", "),
            treelet::render::dispatch_size::DISPATCH_S
        );
    }
    if args.explain && args.layout == Layout::Auto && result.plan.accel != Accel::None {
        eprintln!("layout     {} (as rendered): {}", result.plan.layout.name(), result.plan.layout_reason);
    }
    // Wall time of the whole run so far: start-up, device, pipelines, render, image.
    let process_s = treelet::runtime::timeline::now_s();
    let spp = done.end - done.start;
    // Only the samples this run rendered count toward its rate.
    let resumed = resume.as_ref().map_or(0, |(r, _)| r.end - r.start);
    let paths = args.width as f64 * args.height as f64 * (spp - resumed.min(spp)) as f64;
    let (device, adapter) = match &list[..] {
        [Device::Gpu(ctx)] => ("gpu", ctx.info.name.clone()),
        [Device::Cpu] => ("cpu", "cpu".to_string()),
        _ => ("devices", format!("{} devices", list.len())),
    };
    eprintln!(
        "{}: {}x{} at {spp} spp{} on {adapter} (accel {}, layout {}, kernel {}, integrator {}), {:.3} s ({:.1} M camera paths/s; kernels {:.3} s, process {:.3} s), wrote {}",
        scene.name,
        args.width,
        args.height,
        if resumed > 0 { format!(" ({resumed} of them resumed)") } else { String::new() },
        result.plan.accel.name(),
        if result.plan.accel == Accel::None { "-" } else { result.plan.layout.name() },
        result.plan.kernel,
        integrator.name(),
        result.total_s,
        paths / result.total_s / 1e6,
        (result.build_ms + result.render_ms) / 1e3,
        process_s,
        if result.stopped.is_some() && part.is_none() { format!("{} and {}", args.out.display(), part_path.display()) } else { args.out.display().to_string() }
    );
    if list.len() > 1 {
        for s in &result.shares {
            eprintln!(
                "  {}: {} spp ({:.1}%) in {} chunks (dispatches of up to {} spp), {:.1} M paths/s{}",
                s.device,
                s.samples,
                100.0 * s.samples as f64 / spp.max(1) as f64,
                s.chunks,
                s.dispatch_samples,
                s.paths_per_s / 1e6,
                s.failed.as_ref().map(|f| format!(", stopped: {f}")).unwrap_or_default()
            );
            if args.explain {
                let other = s.seconds - s.prepare_s - s.kernel_s - s.read_s;
                eprintln!(
                    "    time: prepare {:.3} s (tree build and layout on the device {:.3} s), render kernels {:.3} s, read-backs {:.3} s, the rest (waits, submissions) {:.3} s of {:.3} s",
                    s.prepare_s, s.build_s, s.kernel_s, s.read_s, other, s.seconds
                );
            }
            if s.failed.is_some() && result.stopped.is_none() {
                eprintln!("warning: {} failed; the other devices rendered its unfinished samples", s.device);
            }
        }
    }
    if let Some(path) = &args.report {
        let doc = serde_json::json!({
            "scene": scene.name,
            "width": args.width,
            "height": args.height,
            "spp": spp,
            "samples": [done.start, done.end],
            "stopped": result.stopped.as_ref().map(|s| format!("{s:?}")),
            "seed": args.seed,
            "accel": result.plan.accel,
            "integrator": integrator,
            "plan": result.plan,
            "device": device,
            "adapter": adapter,
            "devices": result.shares,
            "build_ms": result.build_ms,
            "render_ms": result.render_ms,
            "total_s": result.total_s,
            "kernel_s": (result.build_ms + result.render_ms) / 1e3,
            "process_s": process_s,
            "startup": startup,
            "write_s": write_s,
            "samples_per_s": paths / result.total_s,
            "memory_estimate": memory,
            "rows": result.rows,
        });
        let text = serde_json::to_string_pretty(&doc)?;
        image_io::write_atomically(path, |tmp| Ok(std::fs::write(tmp, &text)?)).with_context(|| format!("cannot write {}", path.display()))?;
        // The log-log plot of error against time, beside the report.
        let (label, points): (&str, Vec<(f64, f64)>) = if reference.is_some() {
            ("RMSE against the reference", result.rows.iter().filter_map(|r| Some((r.elapsed_s, r.rmse?))).collect())
        } else {
            (
                "mean standard error (from sample variance)",
                result.rows.iter().filter_map(|r| Some((r.elapsed_s, r.mean_std_error?))).collect(),
            )
        };
        // Never over the rendered image: `--out a.png --report a.json` puts the plot in `a.error.png`.
        let mut plot_path = path.with_extension("png");
        if plot_path == args.out {
            plot_path = path.with_extension("error.png");
        }
        let title = format!("{}: {}x{}, {spp} spp, accel {}, {adapter}", scene.name, args.width, args.height, result.plan.accel.name());
        let series = [Series { label: format!("{device} ({adapter})"), points }];
        match treelet::internals::plot::error_vs_time(&plot_path, &title, label, &series) {
            Ok(()) => eprintln!("wrote {} and {}", path.display(), plot_path.display()),
            Err(e) => eprintln!("wrote {}; no plot: {e:#}", path.display()),
        }
    }
    match &result.stopped {
        None => Ok(()),
        Some(Stopped::Interrupted) => {
            eprintln!(
                "interrupted: samples {}..{} of {}..{} are done; `--resume {}` with the same options continues the render",
                done.start,
                done.end,
                first_sample,
                first_sample + args.spp,
                part_path.display()
            );
            Ok(())
        }
        Some(Stopped::Failed(why)) => anyhow::bail!(
            "every device failed ({why}); samples {}..{} are done and written to {} (`--resume` it)",
            done.start,
            done.end,
            part_path.display()
        ),
    }
}

fn print_summary(r: &BuildReport) {
    println!("scene      {} ({} primitives)", r.scene, r.primitives);
    println!("device     {} ({})", r.device, r.adapter);
    let epo = r.epo.map_or("not counted (the triangles overlap too many boxes)".to_string(), |e| format!("{e:.3}"));
    println!("builder    {}: {} nodes, {} leaves, {} references, SAH {:.3}, EPO {epo}", r.builder, r.nodes, r.leaves, r.references, r.sah_cost);
    if let (Some(before), Some(after)) = (r.sah_before, r.sah_after) {
        println!("treelets   SAH {before:.3} -> {after:.3} ({:.1}% lower)", 100.0 * (1.0 - after / before));
    }
    println!("valid      {}", r.valid);
    for e in &r.errors {
        println!("  error: {e}");
    }
    let stages: Vec<String> = r.ms.iter().map(|(k, v)| format!("{k} {:.3}", v.as_f64().unwrap_or(0.0))).collect();
    println!("time       {:.3} ms ({}; {})", r.total_ms, r.timing, stages.join(", "));
}

/// Caps the CPU runner's threads: `RAYON_NUM_THREADS` far above the cores
/// only costs (a million threads would take the machine's memory), so more
/// than 4 per core are cut to that, with a warning.
fn bound_threads() {
    let Some(asked) = std::env::var("RAYON_NUM_THREADS").ok().and_then(|v| v.trim().parse::<usize>().ok()) else { return };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let max = 4 * cores;
    if asked > max {
        eprintln!("warning: RAYON_NUM_THREADS={asked} is more than 4 threads per core ({cores} cores here): using {max}");
        let _ = rayon::ThreadPoolBuilder::new().num_threads(max).build_global();
    }
}

/// A bar for each load that takes more than a second (the library counts
/// its bytes: `treelet::internals::progress`), drawn on stderr where it is
/// a terminal, by a thread that looks ten times a second.
fn show_long_loads() {
    use std::sync::Arc;
    use treelet::internals::progress::{current, Work};
    std::thread::spawn(|| {
        let mut shown: Option<(Arc<Work>, ProgressBar)> = None;
        loop {
            std::thread::sleep(std::time::Duration::from_millis(100));
            let work = current();
            if let Some((w, bar)) = &shown {
                if work.as_ref().is_some_and(|now| Arc::ptr_eq(now, w)) {
                    bar.set_position(w.done().min(w.total));
                    continue;
                }
                bar.finish_and_clear();
                shown = None;
            }
            if let Some(w) = work.filter(|w| w.started.elapsed().as_secs_f64() > 1.0) {
                let bar = ProgressBar::new(w.total);
                bar.set_style(ProgressStyle::with_template("{bar:40} {bytes}/{total_bytes}  {msg}").unwrap());
                bar.set_message(w.what.clone());
                bar.set_position(w.done().min(w.total));
                shown = Some((w, bar));
            }
        }
    });
}

fn run(cli: Cli) -> Result<bool> {
    treelet::internals::input::set_max_input_bytes(cli.max_input_bytes);
    // Every TREELET_* knob, read and checked once, before any work: a value
    // that does not parse is an error, not a knob ignored.
    let _ = treelet::tuning::Tuning::from_env()?.install();
    show_long_loads();
    match cli.command {
        Command::Build { scene, builder, device, rounds, gamma, max_leaf, reinsert, json } => {
            let rounds = rounds.unwrap_or(if builder == Builder::Trbvh { TreeletConfig::default().rounds } else { 0 });
            let defaults = TreeletConfig::default();
            let config = TreeletConfig { rounds, gamma, max_leaf, reinsert: reinsert.or(defaults.reinsert), ..defaults };
            let on_cpu = matches!(builder, Builder::Sweep | Builder::Reference);
            if on_cpu && device == DeviceChoice::Gpu {
                anyhow::bail!("the {} builder runs on the CPU only: add --device cpu", builder.name());
            }
            // The device opens while the scene loads.
            let opening = (!on_cpu).then(|| OpenDevices::one(device));
            let scene = Scene::from_spec(&scene)?;
            let (_, report) = match opening {
                None => run_build_cpu(&scene, builder, max_leaf)?,
                Some(opening) => {
                    let device = opening.finish()?.pop().expect("one device opened");
                    treelet::with_backend!(device, |b| run_build_with(b, &scene, builder, config)?)
                }
            };
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print_summary(&report);
            }
            Ok(report.valid)
        }
        Command::Render(args) => run_render(args).map(|_| true),
        Command::Merge { parts, out } => {
            image_io::check_output(&out, "--out", &image_io::IMAGE_FORMATS)?;
            // A merged image over one of its parts would lose that part's sums.
            if let Ok(target) = out.canonicalize() {
                if let Some(p) = parts.iter().find(|p| p.canonicalize().is_ok_and(|p| p == target)) {
                    anyhow::bail!("--out {} names the part {}: merging would overwrite it; write elsewhere", out.display(), p.display());
                }
            }
            let (info, image) = treelet::render::parts::merge(&parts)?;
            if info.samples.start > 0 {
                eprintln!(
                    "note: samples 0..{} are in no part: the image is of samples {}..{} only",
                    info.samples.start, info.samples.start, info.samples.end
                );
            }
            if info.planned_end > info.samples.end {
                eprintln!(
                    "note: samples {}..{} are in no part: a part was of a render planned up to sample {} (stopped early, or a checkpoint)",
                    info.samples.end, info.planned_end, info.planned_end
                );
            }
            image_io::write(&out, &image)?;
            eprintln!(
                "{}: {}x{}, samples {}..{} from {} parts, wrote {}",
                info.scene,
                info.width,
                info.height,
                info.samples.start,
                info.samples.end,
                parts.len(),
                out.display()
            );
            Ok(true)
        }
        Command::Export { scene, out } => {
            let ext = image_io::extension(&out);
            if ext != "ply" && ext != "obj" {
                anyhow::bail!("--out {}: export writes .ply or .obj meshes", out.display());
            }
            let scene = Scene::from_spec(&scene)?;
            treelet::internals::input::refuse_if_read(&out, "--out")?;
            let w = treelet::scene::ply::write(&scene, &out)?;
            if !w.left_out.is_empty() {
                eprintln!("note: left out {} (a mesh file holds triangles)", w.left_out.join(", "));
            }
            println!(
                "{}: {} triangles, areas {:.3e} to {:.3e} ({:.1e} apart)",
                out.display(),
                w.triangles,
                w.min_area,
                w.max_area,
                w.max_area / w.min_area.max(f64::MIN_POSITIVE)
            );
            Ok(true)
        }
        Command::Compare { image, reference } => {
            use treelet::render::parts::read_scored_image;
            let (img, r) = (read_scored_image(&image, "image")?, read_scored_image(&reference, "--reference")?);
            if (img.width, img.height) != (r.width, r.height) {
                anyhow::bail!(
                    "{} is {}x{}, the reference {} is {}x{}",
                    image.display(),
                    img.width,
                    img.height,
                    reference.display(),
                    r.width,
                    r.height
                );
            }
            let (rmse, rel_mse) = treelet::render::image_error(img.pixels.iter().map(|p| p.map(f64::from)), &r);
            println!("{}", serde_json::json!({ "image": image, "reference": reference, "rmse": rmse, "rel_mse": rel_mse }));
            Ok(true)
        }
        Command::Bench { what } => bench::run(what).map(|_| true),
    }
}

/// The render's devices, opened on a thread of their own; joined when
/// taken or dropped, so that no thread is inside a driver when the
/// process ends.
struct OpenDevices(Option<std::thread::JoinHandle<Result<(Vec<Device>, Option<String>)>>>);

impl OpenDevices {
    /// The devices a render asked for (`--devices`, else `--device`).
    fn start(devices: Option<String>, device: DeviceChoice) -> Self {
        OpenDevices(Some(std::thread::spawn(move || {
            // A single device is a list of one; by default a machine with several
            // GPUs renders on all of them.
            let gpus = if devices.is_none() && device == DeviceChoice::Auto { GpuContext::gpu_adapters() } else { Vec::new() };
            match &devices {
                Some(spec) => Ok((treelet::render::devices::open(spec)?, None)),
                None if gpus.len() > 1 => {
                    Ok((gpus.into_iter().map(|i| Ok(Device::Gpu(GpuContext::with_adapter(i)?))).collect::<Result<_>>()?, None))
                }
                None => device.open_with_note().map(|(d, note)| (vec![d], note)),
            }
        })))
    }

    /// One device, as `device` says.
    fn one(device: DeviceChoice) -> Self {
        OpenDevices(Some(std::thread::spawn(move || device.open_with_note().map(|(d, note)| (vec![d], note)))))
    }

    /// The devices, once open; prints the note of a fallback to the CPU runner.
    fn finish(mut self) -> Result<Vec<Device>> {
        let handle = self.0.take().expect("joined once");
        let (list, note) = handle.join().map_err(|_| anyhow::anyhow!("opening the devices panicked"))??;
        if let Some(note) = note {
            eprintln!("{note}");
        }
        Ok(list)
    }
}

impl Drop for OpenDevices {
    fn drop(&mut self) {
        if let Some(handle) = self.0.take() {
            let _ = handle.join();
        }
    }
}

/// Past a file-size limit (`ulimit -f`, as batch systems set) the kernel
/// kills a writer with SIGXFSZ, leaving its temporary file and no word of
/// why; ignored, the write fails with EFBIG instead, which the writers
/// report (naming the file) after removing their temporary file.
fn ignore_file_size_signal() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to SIG_IGN, before any thread
    // starts; no handler runs.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

fn main() -> ExitCode {
    // The process's clock (as near as `main` knows), for wall times.
    treelet::runtime::timeline::start();
    // Before any thread starts (the library also does it when it opens Vulkan).
    treelet::runtime::gpu::quiet_mesa_runtime_dir();
    ignore_file_size_signal();
    bound_threads();
    let cli = Cli::parse();
    treelet::runtime::timeline::mark("arguments");
    let mut outcome = run(cli);
    if let Err(e) = treelet::internals::console::finish() {
        outcome = outcome.and_then(|_| Err(anyhow::anyhow!("cannot write to standard output: {e}")));
    }
    // A render stopped by a signal exits as the shell expects of one (128 + SIGINT).
    if STOP.load(Ordering::SeqCst) {
        if let Err(e) = &outcome {
            eprintln!("error: {e:#}");
        }
        return ExitCode::from(130);
    }
    match outcome {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => {
            eprintln!("error: the built tree failed validation");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
