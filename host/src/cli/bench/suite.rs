//! `treelet bench <figure>|all --out DIR`: the seed report's figures and a
//! few more, each measured on this machine and written as `DIR/<figure>.json`
//! (every measurement: series, x, median, min, max, repeats), `DIR/<figure>.png`
//! and a printed table; `all` also writes `DIR/RESULTS.md` (see `docs/RESULTS.md`).
use anyhow::{Context, Result};
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::layout::Layout;
use treelet::bvh::tree::{Accel, Builder};
use treelet::scene::{random_spheres, Scene};
use treelet::bvh::trbvh::TreeletConfig;
use treelet::render::variant::KernelChoice;

use super::error_curves;
use super::figure::{bar, doc, print_table, write_figure, Figure, FigureDoc, Point, Suite};
use super::measure::{bench_rays, bench_render_kernel, bench_sizes, median, RaysPlan};
use treelet::runtime::device::Device;

/// CUB's sort times on the H100 (`peers/cub`), a reference series of
/// graph 2.5 and 3.5.
const CUB_SORT_H100: &str = include_str!("../../../data/cub_sort_h100.jsonl");


pub fn run(figure: Figure, suite: &Suite) -> Result<()> {
    // Inputs first: a run of minutes must not fail at its last figure.
    // (Its scenes are built in: `treelet::scene::builtin`.)
    if let Some(dir) = suite.mitsuba.as_ref().filter(|_| matches!(figure, Figure::Error | Figure::All)) {
        let list = dir.join("mitsuba.jsonl");
        if !list.is_file() {
            anyhow::bail!("--mitsuba {}: no mitsuba.jsonl there (peers/mitsuba/room_disk.py writes it)", dir.display());
        }
    }
    std::fs::create_dir_all(&suite.out).with_context(|| format!("creating {}", suite.out.display()))?;
    let runner = suite.device.open()?;
    let adapter = runner.name();
    let figures: Vec<Figure> = if figure == Figure::All { Figure::EACH.to_vec() } else { vec![figure] };
    let mut docs = Vec::new();
    for f in figures {
        eprintln!("== {} ({adapter})", f.name());
        let start = std::time::Instant::now();
        let measured = match f {
            Figure::Error => error_curves::measure(suite, &runner)?,
            _ => vec![measure(f, suite, &runner)?],
        };
        for mut doc in measured {
            doc.adapter = adapter.clone();
            doc.device = format!("{:?}", suite.device).to_lowercase();
            doc.date = chrono::Utc::now().format("%Y-%m-%d").to_string();
            doc.quick = suite.quick;
            doc.command = format!(
                "treelet bench {}{} --device {}{} --out DIR",
                if f == Figure::Rays { "rays-figure" } else { f.name() },
                if suite.quick { " --quick" } else { "" },
                doc.device,
                if f == Figure::Error && suite.mitsuba.is_some() { " --mitsuba MITSUBA_DIR" } else { "" }
            );
            write_figure(&suite.out, &doc)?;
            print_table(&doc);
            docs.push(doc);
        }
        eprintln!("   {:.1} s", start.elapsed().as_secs_f64());
    }
    if figure == Figure::All {
        let md = super::results::markdown(&docs, "");
        let path = suite.out.join("RESULTS.md");
        std::fs::write(&path, md).with_context(|| format!("writing {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Render-kernel seconds of `repeats` renders (after one warm-up).
fn render_times<B: Backend>(
    b: &mut B,
    scene: &Scene,
    (w, h, spp): (u32, u32, u32),
    (accel, layout): (Accel, Layout),
    repeats: usize,
) -> Result<Vec<f64>> {
    bench_render_kernel(b, scene, (w, h, spp.min(4)), accel, layout, KernelChoice::Auto)?;
    let mut v = Vec::new();
    for _ in 0..repeats {
        v.push(bench_render_kernel(b, scene, (w, h, spp), accel, layout, KernelChoice::Auto)?.kernel_s);
        // One run of several seconds is enough: its noise is small.
        if v[0] > 5.0 {
            break;
        }
    }
    Ok(v)
}

/// A tree and its layout, as the figures name them ("TRBVH, cwbvh").
pub(crate) fn tree_name(a: Accel, layout: Layout) -> String {
    match layout {
        Layout::Auto => accel_name(a).to_string(),
        _ => format!("{}, {}", accel_name(a), layout.name()),
    }
}

fn accel_name(a: Accel) -> &'static str {
    match a {
        Accel::Auto => "auto",
        Accel::None => "linear scan",
        Accel::Lbvh => "LBVH",
        Accel::Trbvh => "TRBVH",
        Accel::Hploc => "H-PLOC",
        Accel::Sweep => "full-sweep SAH",
        Accel::Reference => "reference (obvhs PLOC + reinsertion)",
    }
}

fn measure(figure: Figure, s: &Suite, runner: &Device) -> Result<FigureDoc> {
    let q = s.quick;
    let r = s.repeats;
    match figure {
        Figure::Graph1 => {
            let size = if q { (128, 96) } else { (1024, 768) };
            let gpu_spp: Vec<u32> = if q { vec![4, 16, 64] } else { vec![4, 16, 64, 256, 1024] };
            let cpu_spp: Vec<u32> = if q { vec![4, 16] } else { vec![4, 16, 64] };
            let mut d = doc(figure, "cornell: render time against samples per pixel", "samples per pixel", "render-kernel time (s)", (true, true));
            d.parameters = serde_json::json!({ "scene": "cornell", "width": size.0, "height": size.1, "gpu_spp": gpu_spp, "cpu_spp": cpu_spp });
            let cornell = Scene::from_spec("cornell")?;
            let pb = bar(gpu_spp.len() + cpu_spp.len(), "renders");
            if let Device::Gpu(ctx) = runner {
                let b = &mut GpuBackend::new(ctx.clone());
                for &spp in &gpu_spp {
                    d.points.push(Point::of(format!("GPU ({})", ctx.info.name), spp as f64, &render_times(b, &cornell, (size.0, size.1, spp), (Accel::Auto, Layout::Auto), r)?));
                    pb.inc(1);
                }
            }
            let b = &mut CpuBackend::new();
            for &spp in &cpu_spp {
                d.points.push(Point::of("CPU runner (rayon)", spp as f64, &render_times(b, &cornell, (size.0, size.1, spp), (Accel::Auto, Layout::Auto), r.min(2))?));
                pb.inc(1);
            }
            pb.finish_and_clear();
            d.notes.push(format!("{}x{}; GPU time from timestamp queries, CPU runner by wall clock of its kernels", size.0, size.1));
            Ok(d)
        }
        Figure::Graph2 | Figure::Graph3 => {
            let (size, sizes, accels, title) = if figure == Figure::Graph2 {
                let sizes: Vec<usize> = if q { vec![10, 100, 1000] } else { vec![100, 1000, 4000, 16000, 65536] };
                let accels = [Accel::None, Accel::Lbvh, Accel::Trbvh].map(|a| (a, Layout::Auto));
                ((128, 96, 4), sizes, accels.to_vec(), "random:N at 4 spp: linear scan against BVHs")
            } else {
                let sizes: Vec<usize> = if q { vec![1000, 10000] } else { vec![1000, 10000, 100000, 1000000] };
                let trees = vec![
                    (Accel::Lbvh, Layout::Cwbvh),
                    (Accel::Trbvh, Layout::Cwbvh),
                    (Accel::Sweep, Layout::Cwbvh),
                    (Accel::Lbvh, Layout::Classic),
                    (Accel::Trbvh, Layout::Classic),
                    (Accel::Trbvh, Layout::Bvh2),
                ];
                ((128, 96, 4), sizes, trees, "random:N at 4 spp: LBVH against optimized BVHs, in each layout")
            };
            let size = if q { size } else { (1024, 768, 4) };
            let mut d = doc(figure, title, "spheres (N, plus the 9 of the room)", "render-kernel time (s)", (true, true));
            d.parameters = serde_json::json!({ "width": size.0, "height": size.1, "spp": size.2, "sizes": sizes });
            let pb = bar(sizes.len() * accels.len(), "renders");
            treelet::with_backend!(runner, |b| {
                for &n in &sizes {
                    let scene = Scene::from_spec(&format!("random:{n}"))?;
                    for &(a, layout) in &accels {
                        let name = if a == Accel::None { accel_name(a).to_string() } else { tree_name(a, layout) };
                        pb.set_message(format!("random:{n} {name}"));
                        d.points.push(Point::of(name, n as f64, &render_times(b, &scene, size, (a, layout), r)?));
                        pb.inc(1);
                    }
                }
            });
            pb.finish_and_clear();
            if figure == Figure::Graph3 {
                d.notes.push(
                    "the full-sweep tree is built on the CPU before each of its renders (not counted here); at 1M that \
                     takes seconds, the GPU idles meanwhile and its clocks drop, which slows the render that follows: \
                     `treelet bench rays`, which warms up first, compares the trees' traversal fairly"
                        .into(),
                );
            }
            Ok(d)
        }
        Figure::Graph25 | Figure::Graph35 => {
            let device_sizes: Vec<usize> =
                if q { vec![1000, 10000, 65000] } else { vec![1000, 10000, 65000, 1_000_000, 4_000_000, 16_000_000] };
            let mut d = if figure == Figure::Graph25 {
                doc(figure, "BVH build time against size (random:N spheres)", "primitives", "build time (ms)", (true, true))
            } else {
                doc(figure, "treelet optimization time against size (random:N spheres)", "primitives", "optimization time (ms)", (true, true))
            };
            d.parameters = serde_json::json!({ "sizes": device_sizes, "treelets": TreeletConfig::default() });
            let device = if matches!(runner, Device::Gpu(_)) { "device" } else { "CPU runner" };
            treelet::with_backend!(runner, |b| {
                let configs: Vec<(String, Option<TreeletConfig>)> = if figure == Figure::Graph25 {
                    vec![(format!("LBVH ({device})"), None)]
                } else {
                    vec![
                        (format!("TRBVH, gamma 3 ({device})"), Some(TreeletConfig::default())),
                        (format!("TRBVH, gamma 7 ({device})"), Some(TreeletConfig { gamma: 7, ..Default::default() })),
                    ]
                };
                for (name, config) in configs {
                    let builder = match &config {
                        Some(c) => (Builder::Trbvh, c),
                        None => (Builder::Lbvh, &TreeletConfig::default()),
                    };
                    for row in bench_sizes(b, &device_sizes, r.max(3), builder)? {
                        let total = if figure == Figure::Graph25 {
                            [row.total_min_ms, row.total_median_ms, row.total_max_ms]
                        } else {
                            // The optimization alone: rounds and collapse.
                            let opt: f64 = row.median_ms.iter().filter(|(s, _)| s.starts_with("round") || *s == "collapse").map(|(_, v)| v).sum();
                            [opt, opt, opt]
                        };
                        d.points.push(Point { series: name.clone(), x: row.primitives as f64, median: total[1], min: total[0], max: total[2], repeats: r.max(3) });
                    }
                }
            });
            // What a CUDA user's sort alone costs on the H100 (CUB, measured
            // by peers/cub in the same lease as Treelet's H100 build figures):
            // a reference series from the file, not measured by this run.
            for line in CUB_SORT_H100.lines().filter(|l| !l.trim().is_empty()) {
                let row: serde_json::Value = serde_json::from_str(line).context("docs/results/h100-sort/cub_sort.jsonl")?;
                if let (Some(n), Some(ms)) = (row["n"].as_f64(), row["cub_sort_ms_64bit"].as_f64()) {
                    d.points.push(Point::once("CUB sort alone, 64-bit keys (H100, measured file)", n, ms));
                }
            }
            d.notes.push(
                "CUB sort (H100): cub::DeviceRadixSort::SortPairs of random 64-bit keys and 32-bit values, median of 21, \
                 from docs/results/h100-sort/cub_sort.jsonl (peers/cub), not measured by this run; a sort alone, \
                 the floor under an LBVH build that sorts its keys with it"
                    .into(),
            );
            if figure == Figure::Graph25 {
                // CPU builders over the same boxes, wall clock.
                let cpu_sizes: Vec<usize> = device_sizes.iter().copied().filter(|&n| n <= if q { 65000 } else { 1_000_000 }).collect();
                for &n in &cpu_sizes {
                    for (name, ms) in cpu_builds(&random_boxes(n))? {
                        d.points.push(Point::once(name, n as f64, ms));
                    }
                }
                // The seed's published endpoints (GRID K520; intermediate values not known here).
                d.points.push(Point::once("seed report (GRID K520)", 1000.0, 1.2));
                d.points.push(Point::once("seed report (GRID K520)", 65000.0, 4.0));
                d.notes.push("seed report row: its table's endpoints, 1.2 ms at 1 000 and 4.0 ms at 65 000 primitives, on a GRID K520".into());
                d.notes.push("CPU builders: one thread, wall clock, one run each".into());
            } else {
                d.notes.push("rounds + SAH leaf collapse, without the LBVH build".into());
            }
            Ok(d)
        }
        Figure::Pareto => {
            let specs: Vec<&str> = if q { vec!["random:10000", "terrain:10000"] } else { vec!["random:1000000", "terrain:1002528"] };
            let mut d = doc(
                figure,
                &format!("SAH cost against build time ({})", specs.join(", ")),
                "build time (ms)",
                "SAH cost / full-sweep SAH cost of the same scene",
                (true, false),
            );
            d.scatter = true;
            d.parameters = serde_json::json!({ "scenes": specs });
            for spec in &specs {
                let scene = Scene::from_spec(spec)?;
                let tag = spec.split(':').next().unwrap_or(spec);
                let mut found: Vec<(String, f64, f64)> = Vec::new();
                treelet::with_backend!(runner, |b| {
                    for (name, builder, config) in [
                        ("LBVH", Builder::Lbvh, None),
                        ("TRBVH g1", Builder::Trbvh, Some(TreeletConfig { gamma: 1, ..Default::default() })),
                        ("TRBVH g3", Builder::Trbvh, Some(TreeletConfig::default())),
                        ("TRBVH g7", Builder::Trbvh, Some(TreeletConfig { gamma: 7, ..Default::default() })),
                        // H-PLOC with its leaves collapsed, as traced; then with three treelet rounds.
                        ("H-PLOC", Builder::Hploc, None),
                        ("H-PLOC + 3 rounds", Builder::Hploc, Some(TreeletConfig::default())),
                    ] {
                        if builder == Builder::Hploc && b.min_subgroup_size() < treelet_core::construct::hploc::MIN_SUBGROUP_SIZE {
                            continue;
                        }
                        let (sah, ms) = device_build(b, &scene, builder, config.as_ref())?;
                        found.push((name.to_string(), ms, sah));
                        if name == "LBVH" || name == "TRBVH g3" {
                            // The same tree laid out as a compressed wide BVH:
                            // its build time with the layout (its binary SAH).
                            let wide_ms = device_build_wide(b, &scene, config.as_ref())?;
                            found.push((format!("{name} + cwbvh layout"), wide_ms, sah));
                        }
                    }
                });
                found.extend(cpu_builds_scored(&scene.primitives().boxes())?);
                // Relative to the full-sweep tree, so that scenes share an axis.
                let sweep = found.iter().find(|f| f.0.starts_with("full-sweep")).map(|f| f.2).unwrap_or(1.0);
                let mut absolute = Vec::new();
                for (name, ms, sah) in found {
                    d.points.push(Point::once(format!("{name} {tag}"), ms, sah / sweep));
                    absolute.push(format!("{name} {sah:.2}"));
                }
                d.notes.push(format!("{spec}, absolute SAH: {}", absolute.join(", ")));
            }
            d.notes.push("device builds: GPU timestamps (median of 3 after 0.5 s of warm-up); CPU builders: one thread, wall clock".into());
            Ok(d)
        }
        Figure::Rays => {
            let (w, h) = if q { (256, 192) } else { (1920, 1080) };
            let sizes: Vec<usize> = if q { vec![1000, 10000] } else { vec![10000, 100000, 1000000] };
            let mut d = doc(figure, "rays per second through each tree (terrain:N, mesh alone)", "triangles", "M rays/s", (true, false));
            d.parameters = serde_json::json!({ "width": w, "height": h, "sizes": sizes });
            let pb = bar(sizes.len() * 4, "trees");
            treelet::with_backend!(runner, |b| {
                for &n in &sizes {
                    let scene = Scene::from_spec(&format!("terrain:{n}"))?.mesh_only()?;
                    for a in [Accel::Lbvh, Accel::Trbvh, Accel::Hploc, Accel::Sweep] {
                        // The seed's layout and the compressed wide one for every
                        // tree; the two-box binary layout for the TRBVH and H-PLOC.
                        let layouts = match a {
                            Accel::Trbvh => Layout::ALL.to_vec(),
                            Accel::Hploc => vec![Layout::Bvh2, Layout::Cwbvh],
                            _ => vec![Layout::Classic, Layout::Cwbvh],
                        };
                        let plan = RaysPlan { layouts, workgroup_stack: false };
                        for row in bench_rays(b, &scene, a, &plan, (w, h), r.max(3))? {
                            let (x, name) = (row.primitives as f64, tree_name(a, row.layout));
                            d.points.push(Point::once(format!("{name} primary"), x, row.primary_mrays_per_s));
                            d.points.push(Point::once(format!("{name} diffuse"), x, row.diffuse_mrays_per_s));
                        }
                        pb.inc(1);
                    }
                }
            });
            pb.finish_and_clear();
            d.notes.push(format!("{w}x{h}, one camera ray and one cosine bounce per pixel, no shading; medians of {} passes", r.max(3)));
            Ok(d)
        }
        Figure::All => unreachable!("all is expanded by run"),
        Figure::Error => unreachable!("error makes two figures: error_curves::measure"),
    }
}

fn random_boxes(n: usize) -> Vec<treelet_core::Aabb> {
    random_spheres(n, 1).iter().map(|s| s.aabb()).collect()
}

/// SAH and build time (ms, GPU timestamps: median of 3 after half a second
/// of warm-up builds, as `bench build`) of a device build.
fn device_build<B: Backend>(b: &mut B, scene: &Scene, builder: Builder, config: Option<&TreeletConfig>) -> Result<(f64, f64)> {
    use treelet::bvh::lbvh;
    use treelet_core::construct::sah::{SahCosts, sah_cost};
    let all = scene.primitives();
    // No config: no treelet rounds (H-PLOC's leaves still collapsed, as traced).
    let config = config.copied().unwrap_or(TreeletConfig { rounds: 0, ..Default::default() });
    let once = |b: &mut B| -> Result<(lbvh::DeviceBvh<B>, f64)> {
        b.begin_build();
        let (bvh, t) = treelet::bvh::tree::collapsed_tree(b, all, builder, &config)?;
        Ok((bvh, t.total()))
    };
    let warm = std::time::Instant::now();
    while warm.elapsed().as_secs_f64() < 0.5 {
        once(b)?;
    }
    let mut times = Vec::new();
    let mut sah = 0.0;
    for i in 0..3 {
        let (bvh, ms) = once(b)?;
        times.push(ms);
        if i == 2 {
            let nodes = b.read::<treelet_core::Node>(&bvh.nodes, bvh.node_count as usize)?;
            sah = sah_cost(&nodes, SahCosts::KARRAS_AILA);
        }
    }
    Ok((sah, median(times)))
}

/// Build time (ms, as [`device_build`]) of the tree laid out as a
/// compressed wide BVH: the LBVH, the treelet rounds if `config`, the wide
/// layout (which does its own leaf collapse).
fn device_build_wide<B: Backend>(b: &mut B, scene: &Scene, config: Option<&TreeletConfig>) -> Result<f64> {
    use treelet::bvh::layout::{lay_out, PrimBuffers};
    use treelet::bvh::{lbvh, trbvh};
    let all = scene.primitives();
    let once = |b: &mut B| -> Result<f64> {
        b.begin_build();
        let (mut bvh, t) = lbvh::build_primitives_on_device(b, all)?;
        let mut ms = t.total();
        if let Some(c) = config {
            let root = trbvh::root_box(b, &bvh)?;
            let (o, t) = trbvh::restructure(b, bvh, &root, c)?;
            (bvh, ms) = (o, ms + t.total());
        }
        let prims = PrimBuffers::upload(b, all)?;
        b.take_times()?;
        lay_out(b, bvh, Layout::Cwbvh, 1, &prims)?;
        Ok(ms + b.take_times()?.total())
    };
    let warm = std::time::Instant::now();
    while warm.elapsed().as_secs_f64() < 0.5 {
        once(b)?;
    }
    let times = (0..3).map(|_| once(b)).collect::<Result<Vec<_>>>()?;
    Ok(median(times))
}

/// The CPU builders over `boxes`: (name, build ms).
fn cpu_builds(boxes: &[treelet_core::Aabb]) -> Result<Vec<(String, f64)>> {
    Ok(cpu_builds_scored(boxes)?.into_iter().map(|(n, ms, _)| (n, ms)).collect())
}

/// The CPU builders over `boxes`: (name, build ms, SAH with Treelet's function).
fn cpu_builds_scored(boxes: &[treelet_core::Aabb]) -> Result<Vec<(String, f64, f64)>> {
    use treelet_core::construct::sah::{SahCosts, sah_cost};
    let mut out = Vec::new();
    let start = std::time::Instant::now();
    let sweep = treelet::bvh::sweep::build_collapsed_boxes(boxes, TreeletConfig::default().max_leaf)?;
    out.push(("full-sweep SAH (Treelet, CPU)".to_string(), start.elapsed().as_secs_f64() * 1e3, sah_cost(&sweep.nodes, SahCosts::KARRAS_AILA)));
    #[cfg(feature = "peers")]
    for t in [treelet_peers::bvh_crate(boxes), treelet_peers::obvhs_ploc(boxes)] {
        out.push((format!("peer: {} (CPU)", t.name), t.build_ms, sah_cost(&t.nodes, SahCosts::KARRAS_AILA)));
    }
    Ok(out)
}
