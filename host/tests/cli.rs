//! The `treelet` command as a user runs it: exit codes and messages.
use std::process::Command;

fn treelet(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_treelet")).args(args).output().expect("run treelet")
}

#[test]
fn cli_exits_nonzero_with_message() {
    let out = treelet(&["build", "--scene", "random:nope", "--device", "cpu"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("error:") && stderr.contains("random:nope"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn cpu_build_prints_valid_json() {
    let out = treelet(&["build", "--scene", "random:5000:3", "--device", "cpu", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
    assert_eq!(v["valid"], true);
    assert_eq!(v["primitives"], 5000);
    assert_eq!(v["nodes"], 9999);
    assert_eq!(v["device"], "cpu");
    assert_eq!(v["adapter"], "cpu");
    assert!(v["sah_cost"].as_f64().unwrap() > 0.0);
    for stage in ["bounds", "morton", "sort", "tree", "fit"] {
        assert!(v["ms"][stage].as_f64().is_some(), "stage {stage} missing");
    }
}

#[test]
fn empty_scene_builds_an_empty_tree() {
    let out = treelet(&["build", "--scene", "random:0", "--device", "cpu", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["nodes"], 0);
    assert_eq!(v["valid"], true);
}

fn stderr_of(args: &[&str]) -> String {
    let out = treelet(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn render_bad_input_names_the_problem() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let broken = dir.join("broken.json");
    std::fs::write(&broken, "{\n  \"camera\": { \"origin\": [0, 0, 0],\n  \"direction\": [0, 0, -1] \n").unwrap();
    let e = stderr_of(&["render", "--device", "cpu", "--scene", broken.to_str().unwrap()]);
    assert!(e.contains("broken.json") && e.contains("line 4"), "{e}");
    // A negative or zero size is named as such, not as an unknown argument.
    let e = stderr_of(&["render", "--width", "-1"]);
    assert!(e.contains("--width") && e.contains("-1 is not a positive whole number"), "{e}");
    let e = stderr_of(&["render", "--spp", "0"]);
    assert!(e.contains("--spp") && e.contains("0 is not a positive"), "{e}");

    let unknown = dir.join("unknown.json");
    std::fs::write(
        &unknown,
        r#"{"camera": {"origin": [0,0,0], "direction": [0,0,-1]}, "materials": {},
            "spheres": [{"center": [0,0,-5], "radius": 1, "material": "gold"}]}"#,
    )
    .unwrap();
    let e = stderr_of(&["render", "--device", "cpu", "--scene", unknown.to_str().unwrap()]);
    assert!(e.contains("spheres[0]") && e.contains("unknown material `gold`"), "{e}");

    let nan = dir.join("nan.json");
    std::fs::write(
        &nan,
        r#"{"camera": {"origin": [0,0,0], "direction": [0,0,-1]}, "materials": {"w": {"type": "diffuse", "color": [1,1,1]}},
            "spheres": [{"center": [0,0,-5], "radius": 1, "material": "w"}, {"center": [0,1e39,-5], "radius": 1, "material": "w"}]}"#,
    )
    .unwrap();
    let e = stderr_of(&["render", "--device", "cpu", "--scene", nan.to_str().unwrap()]);
    assert!(e.contains("sphere 1"), "{e}");

    let e = stderr_of(&["render", "--device", "cpu", "--scene", "nowhere.json"]);
    assert!(e.contains("nowhere.json"), "{e}");
    let e = stderr_of(&["render", "--device", "cpu", "--width", "0"]);
    assert!(e.contains("--width") && e.contains("0 is not a positive"), "{e}");
    let e = stderr_of(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "4", "--out", "x.bmp"]);
    assert!(e.contains("unknown image format"), "{e}");
    let e = stderr_of(&["render", "--device", "cpu", "--scene", "teapot"]);
    assert!(e.contains("unknown scene `teapot`"), "{e}");
}

#[test]
fn render_adds_a_sky_and_a_lens_to_any_scene() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-sky-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // One white ball under a sky of 0.5 and nothing else: the background
    // is the sky, the ball 0.75 of it.
    let ball = dir.join("ball.json");
    std::fs::write(
        &ball,
        r#"{"camera": {"origin": [0,0,0], "direction": [0,0,-1], "fov": 0.6}, "materials": {"w": {"type": "diffuse", "color": [0.75, 0.75, 0.75]}},
            "spheres": [{"center": [0,0,-5], "radius": 1, "material": "w"}]}"#,
    )
    .unwrap();
    let out_path = dir.join("ball.exr");
    let args = ["render", "--device", "cpu", "--scene", ball.to_str().unwrap(), "--width", "32", "--height", "24", "--spp", "16"];
    let out = treelet(&[&args[..], &["--environment", "0.5,0.5,0.5", "--lens", "0.2,5", "--explain", "--out", out_path.to_str().unwrap()]].concat());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let all = String::from_utf8_lossy(&out.stdout).to_string() + &stderr;
    assert!(all.contains("environment") && all.contains("thin lens"), "the kernel should have both: {all}");
    assert!(!stderr.contains("nothing in the scene emits light"), "{stderr}");
    let image = image::open(&out_path).unwrap().into_rgb32f();
    let corner = image.get_pixel(0, 0).0;
    assert!(corner.iter().all(|&c| (c - 0.5).abs() < 1e-5), "the corner sees the sky: {corner:?}");
    // A convex ball's every bounce leaves for the sky: 0.75 of it, exactly.
    let centre = image.get_pixel(16, 12).0;
    assert!(centre.iter().all(|&c| (c - 0.375).abs() < 1e-4), "the ball: {centre:?}");
    // Bad values are named.
    let e = stderr_of(&[&args[..], &["--environment", "1,-1,0"]].concat());
    assert!(e.contains("--environment") && e.contains("negative"), "{e}");
    let e = stderr_of(&[&args[..], &["--lens", "0.5"]].concat());
    assert!(e.contains("--lens") && e.contains("RADIUS,FOCUS"), "{e}");
    let e = stderr_of(&[&args[..], &["--lens", "0.5,0"]].concat());
    assert!(e.contains("--lens") && e.contains("focus_distance 0"), "{e}");
    let e = stderr_of(&[&args[..], &["--environment", "1e30,0,0"]].concat());
    assert!(e.contains("--environment") && e.contains("at most"), "{e}");
}

#[test]
fn render_writes_image_report_and_plot() {
    let dir = std::env::temp_dir().join(format!("treelet-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (img, report) = (dir.join("c.pfm"), dir.join("c.json"));
    let out = treelet(&[
        "render",
        "--device",
        "cpu",
        "--width",
        "24",
        "--height",
        "18",
        "--spp",
        "16",
        "--out",
        img.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let image = treelet::render::image_io::read_hdr(&img).unwrap();
    assert_eq!((image.width, image.height), (24, 18));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(v["spp"], 16);
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3); // 4, 8, 16 spp
    assert!(dir.join("c.png").exists(), "the error plot beside the report");
    // Against a reference: the error is measured and falls.
    let out = treelet(&[
        "render",
        "--device",
        "cpu",
        "--width",
        "24",
        "--height",
        "18",
        "--spp",
        "64",
        "--seed",
        "9",
        "--out",
        dir.join("d.exr").to_str().unwrap(),
        "--reference",
        img.to_str().unwrap(),
        "--report",
        dir.join("d.json").to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("d.json")).unwrap()).unwrap();
    let rmse: Vec<f64> = v["rows"].as_array().unwrap().iter().map(|r| r["rmse"].as_f64().unwrap()).collect();
    assert!(rmse.first() > rmse.last(), "{rmse:?}");
}

/// `--out x.png --report x.json`: the plot must not overwrite the image.
#[test]
fn report_plot_never_overwrites_the_image() {
    let dir = std::env::temp_dir().join(format!("treelet-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (img, report) = (dir.join("same.png"), dir.join("same.json"));
    let args = ["render", "--device", "cpu", "--width", "20", "--height", "16", "--spp", "16", "--out"];
    let out = treelet(&[&args[..], &[img.to_str().unwrap(), "--report", report.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let image = image::image_dimensions(&img).unwrap();
    assert_eq!(image, (20, 16), "the render was overwritten");
    assert!(dir.join("same.error.png").exists(), "the plot goes to same.error.png");
}

/// `terrain:N` builds and renders as a mesh scene; bad counts are clear errors.
#[test]
fn terrain_scenes() {
    let out = treelet(&["build", "--device", "cpu", "--builder", "trbvh", "--scene", "terrain:2000", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((v["triangles"].as_u64(), v["spheres"].as_u64()), (Some(2048), Some(0)));
    assert_eq!(v["valid"], true);
    for (spec, needle) in [("terrain:0", "N > 0"), ("terrain:lots", "not a triangle count")] {
        let e = stderr_of(&["build", "--device", "cpu", "--scene", spec]);
        assert!(e.contains(needle), "{spec}: {e}");
    }
}

/// `bench rays` casts at a mesh alone with `--mesh-only`, and refuses scenes without triangles.
#[test]
fn bench_rays_mesh_only() {
    let args = ["bench", "rays", "--device", "cpu", "--width", "32", "--height", "24", "--repeats", "1", "--mesh-only"];
    let out = treelet(&[&args[..], &["--scene", "terrain:500"]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("primary Mray/s"));
    let e = stderr_of(&[&args[..], &["--scene", "random:10"]].concat());
    assert!(e.contains("has no triangles"), "{e}");
}

/// `bench rays --figure` draws build time against rays/s for each tree,
/// with OptiX's point from peer.py's output; a peer file for another mesh
/// or size, or without a mesh line, is refused by name.
#[test]
fn bench_rays_tradeoff_figure_with_the_peer_point() {
    let dir = std::env::temp_dir().join(format!("treelet-tradeoff-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let peer = dir.join("peer.jsonl");
    let line = |tris: u32, w: u32| {
        format!(
            "{{\"peer\": \"OptiX via Mitsuba 3.9.1 cuda_ad_rgb\", \"triangles\": {tris}, \"build_wall_ms_median\": 1.5, \"width\": {w}, \"height\": 24, \"primary_mrays_s\": 40.0, \"diffuse_mrays_s\": 20.0}}\n{{\"peer\": \"Mitsuba path\", \"scene\": \"smallpt cornell\"}}\n"
        )
    };
    std::fs::write(&peer, line(512, 32)).unwrap();
    let args = ["bench", "rays", "--device", "cpu", "--width", "32", "--height", "24", "--repeats", "1", "--mesh-only", "--scene", "terrain:500"]; // 512 triangles
    let extra = ["--accels", "lbvh,hploc", "--layouts", "bvh2,cwbvh", "--figure", dir.to_str().unwrap(), "--optix", peer.to_str().unwrap()];
    let out = treelet(&[&args[..], &extra[..]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for kind in ["primary", "diffuse"] {
        assert!(dir.join(format!("tradeoff-{kind}.png")).is_file(), "{kind}");
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join(format!("tradeoff-{kind}.json"))).unwrap()).unwrap();
        let points = doc["points"].as_array().unwrap();
        let names: Vec<&str> = points.iter().map(|p| p["series"].as_str().unwrap()).collect();
        // Two trees in two layouts (H-PLOC where the CPU runner's subgroups allow), and the peer.
        assert!(names.contains(&"LBVH, bvh2") && names.contains(&"LBVH, cwbvh"), "{names:?}");
        let optix = points.iter().find(|p| p["series"] == "OptiX via Mitsuba 3.9.1").expect("the peer's point");
        assert_eq!((optix["x"].as_f64(), optix["median"].as_f64()), (Some(1.5), Some(if kind == "primary" { 40.0 } else { 20.0 })));
        for p in points {
            assert!(p["x"].as_f64().unwrap() > 0.0 && p["median"].as_f64().unwrap() > 0.0, "{p}");
        }
    }
    for (text, needle) in [
        (line(500, 32), "for 500 triangles, this mesh has 512"),
        (line(512, 64), "for 64x24, these rays for 32x24"),
        ("{\"peer\": \"Mitsuba path\"}\n".to_string(), "no mesh measurement"),
        ("not json\n".to_string(), "line 1: not a JSON line"),
    ] {
        std::fs::write(&peer, text).unwrap();
        let e = stderr_of(&[&args[..], &extra[..]].concat());
        assert!(e.contains(needle), "{needle}: {e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `bench instances` times top-level rebuilds and rays through a grid of
/// copies against the mesh alone, and writes them; a scene without
/// triangles is refused.
#[test]
fn bench_instances_times_top_levels_and_rays() {
    let json = std::env::temp_dir().join(format!("treelet-instances-{}.json", std::process::id()));
    let args = ["bench", "instances", "--device", "cpu", "--repeats", "1", "--width", "24", "--height", "16", "--grid", "3"];
    let out = treelet(&[&args[..], &["--scene", "terrain:300", "--top-sizes", "5,40", "--json", json.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let row = &doc["row"];
    assert_eq!((row["grid_instances"].as_u64(), row["top_level"][1][0].as_u64()), (Some(9), Some(40)), "{doc}");
    assert_eq!(row["in_place_differ"].as_u64(), Some(0), "one copy in place hits as the mesh alone: {doc}");
    for key in ["single_primary_mrays", "single_diffuse_mrays", "instanced_primary_mrays", "instanced_diffuse_mrays"] {
        assert!(row[key].as_f64().is_some_and(|v| v > 0.0 && v.is_finite()), "{key}: {doc}");
    }
    std::fs::remove_file(&json).ok();
    let e = stderr_of(&[&args[..], &["--scene", "random:10"]].concat());
    assert!(e.contains("has no triangles"), "{e}");
}

/// `bench dynamic` animates a mesh frame by frame (refit, rebuilds, rays)
/// and writes what it measured; a scene without triangles is refused.
#[test]
fn bench_dynamic_times_refit_rebuild_and_rays() {
    let json = std::env::temp_dir().join(format!("treelet-dynamic-{}.json", std::process::id()));
    let args = ["bench", "dynamic", "--device", "cpu", "--frames", "2", "--width", "16", "--height", "12"];
    let out = treelet(&[&args[..], &["--scene", "terrain:800", "--json", json.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let row = &doc["row"];
    assert_eq!((row["triangles"].as_u64(), row["rays"].as_u64(), row["frames"].as_u64()), (Some(800), Some(192), Some(2)), "{doc}");
    for key in ["refit_ms", "rebuild_lbvh_ms", "rebuild_trbvh_ms", "closest_refit_mrays", "occluded_rebuilt_mrays", "closest_diffuse_mrays", "occluded_diffuse_mrays", "closest_ao_mrays", "occluded_ao_mrays"] {
        assert!(row[key].as_f64().is_some_and(|v| v > 0.0 && v.is_finite()), "{key}: {doc}");
    }
    std::fs::remove_file(&json).ok();
    let e = stderr_of(&[&args[..], &["--scene", "random:10"]].concat());
    assert!(e.contains("has no triangles"), "{e}");
}

#[test]
fn figure_writes_json_png_and_results() {
    let dir = std::env::temp_dir().join(format!("treelet-figure-{}", std::process::id()));
    let out = treelet(&["bench", "graph2.5", "--quick", "--device", "cpu", "--repeats", "1", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("graph2.5.json")).unwrap()).unwrap();
    assert_eq!(doc["figure"], "graph2.5");
    assert_eq!(doc["adapter"], "cpu");
    let points = doc["points"].as_array().unwrap();
    // The device LBVH and the CPU sweep at each quick size, and the seed's two points.
    for series in ["LBVH (CPU runner)", "full-sweep SAH (Treelet, CPU)", "seed report (GRID K520)"] {
        let mine: Vec<_> = points.iter().filter(|p| p["series"] == series).collect();
        assert!(mine.len() >= 2, "{series}: {} points", mine.len());
        for p in mine {
            let (lo, med, hi) = (p["min"].as_f64().unwrap(), p["median"].as_f64().unwrap(), p["max"].as_f64().unwrap());
            assert!(lo > 0.0 && lo <= med && med <= hi, "{series}: {lo} {med} {hi}");
        }
    }
    assert!(std::fs::metadata(dir.join("graph2.5.png")).unwrap().len() > 10_000, "the plot is missing or empty");
    let md = dir.join("R.md");
    let out = treelet(&["bench", "results", "--runs", dir.to_str().unwrap(), "--out", md.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&md).unwrap();
    assert!(text.contains("### graph2.5") && text.contains("graph2.5.png") && text.contains("| primitives |"), "{text}");
    // A run directory without figures is an error that names it.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = treelet(&["bench", "results", "--runs", empty.to_str().unwrap(), "--out", md.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no figure files"));
}

/// `compare` scores an image against a reference: 0 against itself, more
/// against a noisier render of the same scene, and a clear error for images
/// of different sizes or a missing file.
#[test]
fn compare_scores_images_and_names_bad_input() {
    let dir = std::env::temp_dir().join(format!("treelet-compare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let render = |name: &str, w: &str, spp: &str| {
        let path = dir.join(name);
        let args = ["render", "--device", "cpu", "--width", w, "--height", "12", "--spp", spp, "--out"];
        let out = treelet(&[&args[..], &[path.to_str().unwrap()]].concat());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        path.to_str().unwrap().to_string()
    };
    let (fine, coarse, wide) = (render("fine.pfm", "16", "64"), render("coarse.pfm", "16", "4"), render("wide.pfm", "20", "4"));
    let score = |image: &str| {
        let out = treelet(&["compare", image, "--reference", &fine]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
        v["rmse"].as_f64().unwrap()
    };
    assert_eq!(score(&fine), 0.0);
    assert!(score(&coarse) > 0.0);
    let e = stderr_of(&["compare", &wide, "--reference", &fine]);
    assert!(e.contains("20x12") && e.contains("16x12"), "{e}");
    let e = stderr_of(&["compare", "nowhere.exr", "--reference", &fine]);
    assert!(e.contains("nowhere.exr"), "{e}");
}

/// A first run on a machine without a Vulkan driver renders on the CPU
/// runner with one note; `--device gpu` there is an error that says what to
/// install; and no run prints Mesa's XDG_RUNTIME_DIR complaint.
#[test]
fn first_run_without_vulkan_renders_on_the_cpu_runner() {
    let dir = std::env::temp_dir().join(format!("treelet-novulkan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let image = dir.join("a.png");
    let run = |device: &str| {
        Command::new(env!("CARGO_BIN_EXE_treelet"))
            .args(["render", "--width", "16", "--height", "12", "--spp", "4", "--device", device, "--out"])
            .arg(&image)
            .env("VK_DRIVER_FILES", "/nonexistent")
            .env("VK_ICD_FILENAMES", "/nonexistent")
            .env_remove("XDG_RUNTIME_DIR")
            .output()
            .expect("run treelet")
    };
    let out = run("auto");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(image.exists(), "no image written: {err}");
    assert_eq!(err.matches("note:").count(), 1, "{err}");
    assert!(err.contains("no Vulkan adapter") && err.contains("CPU runner") && err.contains("on cpu"), "{err}");
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    let out = run("gpu");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("mesa-vulkan-drivers") && !err.contains("panicked"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// With Vulkan present (lavapipe in CI) and no runtime directory set, Mesa
/// stays quiet, on the adapter and when `auto` looks at it; and `auto`
/// renders on the CPU runner where the only adapters run on CPU cores,
/// saying so.
#[test]
fn no_xdg_runtime_dir_message() {
    let image = std::env::temp_dir().join(format!("treelet-xdg-{}.png", std::process::id()));
    let gpus = treelet::runtime::gpu::GpuContext::gpu_adapters();
    for device in ["gpu", "auto"] {
        let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
            .args(["render", "--width", "16", "--height", "12", "--spp", "4", "--device", device, "--out"])
            .arg(&image)
            .env_remove("XDG_RUNTIME_DIR")
            .output()
            .expect("run treelet");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
        if device == "auto" && gpus.is_empty() {
            assert!(err.contains("runs on CPU cores") && err.contains(" on cpu "), "{err}");
        }
    }
    std::fs::remove_file(&image).ok();
}

/// A render split into sample ranges in separate processes, then merged,
/// is the render made in one go (up to float rounding of the sums); merge
/// names the file of every mismatch, gap and overlap.
#[test]
fn parts_rendered_apart_merge_into_the_whole() {
    let dir = std::env::temp_dir().join(format!("treelet-parts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_string_lossy().to_string();
    let render = |extra: &[&str], out: &str| {
        let mut args = vec!["render", "--device", "cpu", "--scene", "cornell", "--width", "32", "--height", "24"];
        if !extra.contains(&"--seed") {
            args.extend_from_slice(&["--seed", "5"]);
        }
        args.extend_from_slice(extra);
        let o = path(out);
        args.extend_from_slice(&["--out", &o]);
        let out = treelet(&args);
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    for (range, file) in [("0..10", "a.exr"), ("10..33", "b.exr"), ("33..48", "c.exr")] {
        render(&["--samples", range], file);
    }
    render(&["--spp", "48"], "whole.pfm");
    let out = treelet(&["merge", &path("c.exr"), &path("a.exr"), &path("b.exr"), "--out", &path("merged.pfm")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = treelet(&["compare", &path("merged.pfm"), "--reference", &path("whole.pfm")]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("compare prints JSON");
    assert!(v["rmse"].as_f64().unwrap() < 1e-5, "merged against whole: {v}");

    let merge_error = |files: &[&str]| {
        let mut args = vec!["merge".to_string()];
        args.extend(files.iter().map(|f| path(f)));
        args.extend(["--out".to_string(), path("x.png")]);
        stderr_of(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let e = merge_error(&["a.exr", "c.exr"]);
    assert!(e.contains("samples 10..33 are missing") && e.contains("a.exr") && e.contains("c.exr"), "{e}");
    let e = merge_error(&["a.exr", "b.exr", "a.exr"]);
    assert!(e.contains("overlap") && e.contains("a.exr"), "{e}");
    render(&["--samples", "10..33", "--seed", "6"], "other_seed.exr");
    let e = merge_error(&["a.exr", "other_seed.exr"]);
    assert!(e.contains("other_seed.exr") && e.contains("seed 6"), "{e}");
    let e = merge_error(&["a.exr", "whole.pfm"]);
    assert!(e.contains("whole.pfm"), "{e}");
    let e = stderr_of(&["render", "--samples", "0..4", "--out", &path("part.png")]);
    assert!(e.contains(".exr"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `deploy/slurm-array.sh` as a job array would run it: every task's range,
/// then the merge, equal to one render of all the samples.
#[test]
fn slurm_array_script_splits_and_merges() {
    let dir = std::env::temp_dir().join(format!("treelet-slurm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../deploy/slurm-array.sh");
    let run = |step: &str, task: Option<u32>| {
        let mut c = Command::new("bash");
        c.arg(script).arg(step).current_dir(&dir);
        c.env("TREELET", env!("CARGO_BIN_EXE_treelet")).env("DEVICE", "cpu").env("WIDTH", "24").env("HEIGHT", "16");
        c.env("SPP", "30").env("TASKS", "4").env("SEED", "2").env("OUT", dir.join("merged.pfm"));
        if let Some(t) = task {
            c.env("SLURM_ARRAY_TASK_ID", t.to_string());
        }
        let out = c.output().expect("run bash");
        assert!(out.status.success(), "{step} {task:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    for task in 0..4 {
        run("render", Some(task));
    }
    run("merge", None);
    let whole = dir.join("whole.pfm").to_string_lossy().to_string();
    let args = ["render", "--device", "cpu", "--width", "24", "--height", "16", "--spp", "30", "--seed", "2", "--out", &whole];
    assert!(treelet(&args).status.success());
    let merged = dir.join("merged.pfm").to_string_lossy().to_string();
    let out = treelet(&["compare", &merged, "--reference", &whole]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("compare prints JSON");
    assert!(v["rmse"].as_f64().unwrap() < 1e-5, "{v}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `render --devices`: a list of devices renders the image that one device
/// renders; a name that matches no adapter is an error that lists them.
#[test]
fn render_on_a_list_of_devices() {
    let dir = std::env::temp_dir().join(format!("treelet-devices-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |n: &str| dir.join(n).to_string_lossy().to_string();
    let base = ["render", "--width", "24", "--height", "16", "--spp", "12", "--seed", "9"];
    let (two, one) = (path("two.pfm"), path("one.pfm"));
    let out = treelet(&[&base[..], &["--devices", "cpu,cpu", "--out", &two]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("on 2 devices"), "{err}");
    assert!(treelet(&[&base[..], &["--device", "cpu", "--out", &one]].concat()).status.success());
    let out = treelet(&["compare", &two, "--reference", &one]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("compare prints JSON");
    assert!(v["rmse"].as_f64().unwrap() < 1e-5, "{v}");
    let e = stderr_of(&[&base[..], &["--devices", "no-such-gpu", "--out", &one]].concat());
    assert!(e.contains("no-such-gpu") && e.contains("names no adapter"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Every output is checked before any work: a scene that does not exist
/// would be the first error otherwise, so each of these names the output.
#[test]
fn outputs_are_checked_before_the_render() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-outputs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing_dir = dir.join("no_such_folder");
    let scene = dir.join("no_such_scene.json");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--device", "cpu", "--scene", scene.to_str().unwrap()];
        args.extend_from_slice(extra);
        stderr_of(&args)
    };
    let p = |p: std::path::PathBuf| p.to_str().unwrap().to_string();
    let e = render(&["--out", &p(missing_dir.join("a.png"))]);
    assert!(e.contains("no_such_folder") && e.contains("does not exist") && !e.contains("no_such_scene"), "{e}");
    let e = render(&["--out", &p(dir.join("a.jpg"))]);
    assert!(e.contains("unknown image format `.jpg`") && !e.contains("no_such_scene"), "{e}");
    let e = render(&["--out", &p(dir.join("a"))]);
    assert!(e.contains("no file extension") && !e.contains("no_such_scene"), "{e}");
    let e = render(&["--out", &p(dir.clone())]);
    assert!(e.contains("--out") && !e.contains("no_such_scene"), "{e}");
    let e = render(&["--out", &p(dir.join("a.png")), "--report", &p(missing_dir.join("r.json"))]);
    assert!(e.contains("--report") && e.contains("does not exist") && !e.contains("no_such_scene"), "{e}");
    let e = render(&["--samples", "0..4", "--out", &p(missing_dir.join("part.exr"))]);
    assert!(e.contains("does not exist") && !e.contains("no_such_scene"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `merge --out` naming one of its parts is refused, and the part is kept.
#[test]
fn merge_never_overwrites_a_part() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-merge-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let part = dir.join("a.exr");
    let part_s = part.to_str().unwrap();
    let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--samples", "0..2", "--out", part_s]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let before = std::fs::read(&part).unwrap();
    let e = stderr_of(&["merge", part_s, "--out", part_s]);
    assert!(e.contains("names the part") && e.contains("a.exr"), "{e}");
    // The same file through another path is the same part.
    let other = dir.join(".").join("a.exr");
    let e = stderr_of(&["merge", part_s, "--out", other.to_str().unwrap()]);
    assert!(e.contains("names the part"), "{e}");
    assert_eq!(std::fs::read(&part).unwrap(), before, "the part was changed");
    let e = stderr_of(&["merge", part_s, "--out", dir.join("merged.jpg").to_str().unwrap()]);
    assert!(e.contains("unknown image format `.jpg`"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `compare` (and `--reference`) score images of means: a part (per-pixel
/// sums) and an image with a non-finite pixel are refused, naming why.
#[test]
fn compare_refuses_parts_and_non_finite_images() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-compare-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let (part, image) = (dir.join("part.exr"), dir.join("image.pfm"));
    let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--samples", "0..2", "--out", &s(&part)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "2", "--out", &s(&image)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let e = stderr_of(&["compare", &s(&part), "--reference", &s(&image)]);
    assert!(e.contains("part.exr") && e.contains("render part"), "{e}");
    let e = stderr_of(&["compare", &s(&image), "--reference", &s(&part)]);
    assert!(e.contains("--reference") && e.contains("render part"), "{e}");
    // A 2x1 PFM (little-endian) with a NaN in its second pixel.
    let nan = dir.join("nan.pfm");
    let mut bytes = b"PF\n2 1\n-1.0\n".to_vec();
    for v in [0.5f32, 0.5, 0.5, f32::NAN, 0.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(&nan, bytes).unwrap();
    let e = stderr_of(&["compare", &s(&nan), "--reference", &s(&nan)]);
    assert!(e.contains("nan.pfm") && e.contains("pixel (1, 0)") && e.contains("not finite"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Parts carry a hash of the scene's contents: one file named by two paths
/// merges, a file edited between two parts does not; a merged range that
/// does not start at sample 0 is named.
#[test]
fn merge_compares_scene_contents_and_names_a_missing_start() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-merge-hash-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.json");
    let original = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_diffuse.json")).unwrap();
    std::fs::write(&scene, &original).unwrap();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let part = |scene: &std::path::Path, range: &str, name: &str| {
        let out = dir.join(name);
        let args = ["render", "--device", "cpu", "--width", "8", "--height", "6", "--scene", &s(scene), "--samples", range, "--out", &s(&out)];
        let o = treelet(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        s(&out)
    };
    let a = part(&scene, "0..2", "a.exr");
    let b = part(&dir.join(".").join("scene.json"), "2..4", "b.exr");
    let o = treelet(&["merge", &a, &b, "--out", &s(&dir.join("ab.pfm"))]);
    assert!(o.status.success(), "one file by two paths: {}", String::from_utf8_lossy(&o.stderr));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("note:"), "{}", String::from_utf8_lossy(&o.stderr));

    std::fs::write(&scene, original.replace("[0.75, 0.25, 0.25]", "[0.7, 0.25, 0.25]")).unwrap();
    let c = part(&scene, "4..6", "c.exr");
    let e = stderr_of(&["merge", &a, &b, &c, "--out", &s(&dir.join("abc.pfm"))]);
    assert!(e.contains("c.exr") && e.contains("edited"), "{e}");

    let o = treelet(&["merge", &b, "--out", &s(&dir.join("b.pfm"))]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && err.contains("samples 0..2 are in no part"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene whose lights are all black renders, with a warning that says so.
#[test]
fn a_scene_without_light_gets_a_warning() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-dark-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("dark.json");
    let original = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_diffuse.json")).unwrap();
    std::fs::write(&scene, original.replace("\"emission\": [12, 12, 12]", "\"emission\": [0, 0, 0]")).unwrap();
    let out = dir.join("dark.png");
    let o = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--spp", "1", "--scene", scene.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && err.contains("warning") && err.contains("emits light"), "{err}");
    let o = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--spp", "1", "--out", out.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("emits light"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `samples A..B` that a stopped render's summary names.
fn samples_done(stderr: &str) -> std::ops::Range<u32> {
    let at = stderr.find("interrupted: samples ").unwrap_or_else(|| panic!("no `interrupted:` line in: {stderr}"));
    let range = stderr[at + "interrupted: samples ".len()..].split_whitespace().next().unwrap();
    let (a, b) = range.split_once("..").unwrap();
    a.parse().unwrap()..b.parse().unwrap()
}

/// Ctrl-C (SIGINT) stops a long render without losing it: it exits 130
/// and writes the image of the samples done and a part of them; `merge`
/// turns the part into that same image, and `--resume` continues it to the
/// image that an uninterrupted render makes, bit for bit on the CPU runner.
#[test]
fn an_interrupted_render_keeps_its_samples_and_resumes_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-interrupt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let base = ["render", "--device", "cpu", "--width", "8", "--height", "8", "--seed", "3"];
    let child = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(base)
        .args(["--spp", "100000000", "--out", &p("img.exr")])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(2500));
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(130), "{err}");
    let done = samples_done(&err);
    assert!(done.start == 0 && done.end > 0 && done.end < 100000000, "{done:?}");
    assert!(err.contains("--resume"), "{err}");

    // The part merges into the image written at the stop, with a note of
    // the samples that the stop left out.
    let o = treelet(&["merge", &p("img.part.exr"), "--out", &p("merged.exr")]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && e.contains(&format!("samples {}..100000000 are in no part", done.end)), "{e}");
    let o = treelet(&["compare", &p("merged.exr"), "--reference", &p("img.exr")]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("compare prints JSON");
    assert_eq!(v["rmse"].as_f64(), Some(0.0), "{v}");

    // Resumed to N samples, it is the render of N samples. N is chosen so
    // that the passes up to the stop are those of the first render's
    // schedule (4, 8, 16, ...: whole powers of two below N/2).
    let n = 2 * (done.end + 1).next_power_of_two();
    let o = treelet(&[&base[..], &["--spp", &n.to_string(), "--resume", &p("img.part.exr"), "--out", &p("resumed.exr")]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = treelet(&[&base[..], &["--spp", &n.to_string(), "--out", &p("whole.exr")]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = treelet(&["compare", &p("resumed.exr"), "--reference", &p("whole.exr")]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("compare prints JSON");
    assert_eq!(v["rmse"].as_f64(), Some(0.0), "resumed at {} of {n}: {v}", done.end);
    assert_eq!(std::fs::read(p("resumed.exr")).unwrap(), std::fs::read(p("whole.exr")).unwrap());

    // A part of another render is refused, naming the difference.
    let e = stderr_of(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--seed", "4", "--spp", &n.to_string(), "--resume", &p("img.part.exr"), "--out", &p("x.exr")]);
    assert!(e.contains("--resume") && e.contains("seed"), "{e}");
    let e = stderr_of(&[&base[..], &["--spp", "2", "--resume", &p("img.part.exr"), "--out", &p("x.exr")]].concat());
    assert!(e.contains("--resume") && e.contains("end no earlier"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--checkpoint` writes the samples done as it goes: a render killed
/// outright (SIGKILL: no chance to write anything) leaves its last
/// checkpoint, which merges into an image; a render that completes removes
/// its checkpoint, and no temporary file is left behind. While a render
/// runs, another of the same `--out` is refused; the killed one's lock is
/// taken over.
#[test]
fn checkpoints_survive_a_kill_and_go_when_the_render_completes() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-checkpoint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let mut child = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "100000000", "--checkpoint", "0.2"])
        .args(["--out", &p("img.png")])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(2500));
    // A second render of the same --out while the first runs: refused,
    // naming the first (the two wrote over each other's checkpoint).
    let e = stderr_of(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "16", "--out", &p("img.png")]);
    assert!(e.contains("being rendered by another treelet") && e.contains(&format!("pid {}", child.id())), "{e}");
    child.kill().unwrap();
    child.wait().unwrap();
    let o = treelet(&["merge", &p("img.part.exr"), "--out", &p("merged.png")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && err.contains("samples 0.."), "{err}");
    assert!(!std::path::Path::new(&p("img.png")).exists(), "a killed render wrote no image");
    // Running the command again without --resume would write over the
    // checkpoint: refused, saying how to continue.
    let before = std::fs::read(p("img.part.exr")).unwrap();
    let e = stderr_of(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "16", "--checkpoint", "0.2", "--out", &p("img.png")]);
    assert!(e.contains("did not finish") && e.contains("--resume"), "{e}");
    assert_eq!(std::fs::read(p("img.part.exr")).unwrap(), before, "the checkpoint was touched");

    let o = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "256", "--checkpoint", "0.01", "--out", &p("done.png")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::path::Path::new(&p("done.png")).exists());
    assert!(!std::path::Path::new(&p("done.part.exr")).exists(), "the checkpoint of a completed render is removed");
    // The completed render's temporary files are all gone (the killed one
    // may have died in the middle of writing a checkpoint: a SIGKILL leaves
    // its temporary file, which nothing can remove).
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().to_string()).filter(|n| n.starts_with(".done")).collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
    let e = stderr_of(&["render", "--device", "cpu", "--checkpoint", "0", "--out", &p("x.png")]);
    assert!(e.contains("--checkpoint"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Under an address-space limit (`ulimit -v`, as batch systems set), a
/// render whose memory estimate is past the room left is refused before it
/// starts, naming the estimate (the limit was not counted: such a render
/// ran, then aborted when an allocation failed).
#[test]
fn an_address_space_limit_is_counted() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-ulimit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("big.png");
    let command = format!(
        "ulimit -v 3000000 && exec '{}' render --device cpu --width 7000 --height 7000 --spp 1 --out '{}'",
        env!("CARGO_BIN_EXE_treelet"),
        out.display()
    );
    let o = Command::new("bash").args(["-c", &command]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("this render needs about") && err.contains("available") && !err.contains("panicked"), "{err}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Past a file-size limit (`ulimit -f`) a render's write fails with an
/// error naming the file, and leaves no temporary file (SIGXFSZ killed it,
/// exit 153, its temporary file left behind).
#[test]
fn a_file_size_limit_is_a_write_error() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-fsize-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("x.exr");
    let command = format!(
        "ulimit -f 20 && exec '{}' render --device cpu --width 256 --height 256 --spp 1 --out '{}'",
        env!("CARGO_BIN_EXE_treelet"),
        out.display()
    );
    let o = Command::new("bash").args(["-c", &command]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("x.exr") && err.contains("File too large"), "{err}");
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `treelet args` with `env`, killed after `seconds`: a hang fails the
/// test instead of blocking it.
fn treelet_within(seconds: u64, env: &[(&str, &str)], args: &[&str]) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(args)
        .envs(env.iter().copied())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() >= seconds {
            child.kill().unwrap();
            panic!("treelet {args:?} still ran after {seconds} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Only regular files are read, within a size cap a flag raises: a FIFO
/// would block, a link to /dev/zero read forever; a folder named like a
/// mesh is named as a folder.
#[test]
fn inputs_are_regular_files_within_a_cap() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-inputs-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    assert!(Command::new("mkfifo").arg(p("fifo.obj")).status().unwrap().success());
    assert!(Command::new("mkfifo").arg(p("fifo.json")).status().unwrap().success());
    std::os::unix::fs::symlink("/dev/zero", p("zero.ply")).unwrap();
    for (scene, says) in [("fifo.obj", "not a regular file"), ("fifo.json", "not a regular file"), ("zero.ply", "not a regular file"), ("folder.obj", "is a folder")] {
        let o = treelet_within(60, &[], &["build", "--device", "cpu", "--scene", &p(scene)]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && e.contains(scene) && e.contains(says), "{scene}: {e}");
    }
    let o = treelet_within(60, &[], &["compare", &p("fifo.obj"), "--reference", &p("zero.ply")]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("not a regular file"));
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_diffuse.json");
    let e = stderr_of(&["render", "--device", "cpu", "--scene", scene, "--max-input-bytes", "100", "--out", &p("x.png")]);
    assert!(e.contains("cornell_diffuse.json") && e.contains("--max-input-bytes"), "{e}");
    let o = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "1", "--scene", scene, "--max-input-bytes", "100000", "--out", &p("x.png")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Loader errors name the line (OBJ, as tobj does not) or the element
/// (PLY), and the reason, on one line.
#[test]
fn loader_errors_name_the_line_or_element() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-loaders-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &[u8], &[&str]); 6] = [
        ("pos.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n", &["line 3", "position", "v 0 1 x"]),
        ("bounds.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n", &["line 5", "out of bounds", "f 1 2 9"]),
        ("back.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 -3\nv 0 1 0\n", &["line 3", "out of bounds"]),
        ("face.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n", &["line 4", "face parse error"]),
        ("binary.obj", b"v 0 0 0\n\x00\xff\xfe\x00\n", &["line 2", "not UTF-8"]),
        (
            "vertex.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 zz\n0 1 0\n3 0 1 2\n",
            &["vertex 1", "Line 11", "`1 0 zz`"],
        ),
    ];
    for (name, bytes, says) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = stderr_of(&["build", "--device", "cpu", "--scene", path.to_str().unwrap()]);
        assert!(e.contains(name) && says.iter().all(|s| e.contains(s)), "{name}: {e}");
        assert_eq!(e.trim().lines().count(), 1, "{name}: one line: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A thread count far past the cores is cut (with a warning), so a tiny
/// render does not stall starting a million threads.
#[test]
fn huge_thread_counts_are_bounded() {
    let out = std::env::temp_dir().join(format!("treelet-cli-threads-{}.png", std::process::id()));
    let o = treelet_within(120, &[("RAYON_NUM_THREADS", "1000000")], &["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "2", "--out", out.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && e.contains("RAYON_NUM_THREADS") && e.contains("warning"), "{e}");
    let _ = std::fs::remove_file(&out);
}

/// `--integrator auto`: NEE without a pilot where light paths have nothing
/// to find or the pilot would cost too much; a pilot on cornell (whose lamp
/// sits inside the ceiling, so light paths are noisy: 2 to 4x NEE's error
/// measured) keeps NEE and says what it measured; refused for parts.
#[test]
fn integrator_auto_pilots_and_says_why() {
    let out = std::env::temp_dir().join(format!("treelet-cli-auto-{}.png", std::process::id()));
    let out = out.to_str().unwrap();
    let render = |scene: &str, size: [&str; 2], spp: &str| {
        let o = treelet(&["render", "--device", "cpu", "--scene", scene, "--width", size[0], "--height", size[1], "--spp", spp, "--integrator", "auto", "--explain", "--out", out]);
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(o.status.success(), "{e}");
        let line = e.lines().find(|l| l.starts_with("integrator ")).unwrap_or_else(|| panic!("no integrator line: {e}")).to_string();
        let summary = e.lines().find(|l| l.contains("M camera paths/s")).unwrap_or_else(|| panic!("no summary: {e}")).to_string();
        (line, summary)
    };
    let (line, summary) = render(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_diffuse.json"), ["16", "12"], "8");
    assert!(line.starts_with("integrator nee (auto: the scene has no mirrors or glass"), "{line}");
    assert!(summary.contains("integrator nee"), "{summary}");
    let (line, _) = render("cornell", ["16", "12"], "64");
    assert!(line.starts_with("integrator nee (auto: a pilot of both") && line.contains("over 1/8"), "{line}");
    let (line, summary) = render("cornell", ["128", "96"], "352");
    assert!(line.starts_with("integrator nee (auto: a pilot of 11 spp, twice each: light paths would give"), "{line}");
    let ratio: f64 = line.split("would give ").nth(1).and_then(|r| r.split('x').next()).and_then(|r| r.parse().ok()).unwrap_or_else(|| panic!("{line}"));
    assert!(ratio > 1.2, "cornell's light paths measured at {ratio}x NEE's error: {line}");
    assert!(summary.contains("integrator nee"), "{summary}");
    let o = treelet(&["render", "--device", "cpu", "--samples", "0..4", "--integrator", "auto", "--out", "part.exr"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && e.contains("--integrator auto with --samples"), "{e}");
    let _ = std::fs::remove_file(out);
}

/// Sizes past the memory are refused before anything is allocated, with
/// the estimate and the limit (no abort from a failed allocation):
/// against the machine's memory, and against TREELET_MAX_MEMORY.
#[test]
fn renders_past_the_memory_are_refused_with_the_estimate() {
    let out = std::env::temp_dir().join(format!("treelet-cli-memory-{}.png", std::process::id()));
    let out = out.to_str().unwrap();
    // About 190 GiB of image sums: no test machine has that much free.
    let o = treelet_within(60, &[], &["render", "--device", "cpu", "--width", "46000", "--height", "46000", "--out", out]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("46000x46000") && e.contains("GiB") && e.contains("available"), "{e}");
    let small = [("TREELET_MAX_MEMORY", "1000000")];
    let o = treelet_within(60, &small, &["render", "--device", "cpu", "--width", "512", "--height", "384", "--out", out]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && e.contains("512x384") && e.contains("976.6 KiB available"), "{e}");
    let o = treelet_within(60, &small, &["render", "--device", "cpu", "--scene", "random:100000", "--width", "8", "--height", "8", "--out", out]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && e.contains("random:100000") && e.contains("100000 spheres"), "{e}");
    let o = treelet_within(60, &[("TREELET_MAX_MEMORY", "30000000")], &["build", "--device", "cpu", "--scene", "random:100000"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && e.contains("tree over 100000 primitives"), "{e}");
    let o = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "1", "--explain", "--out", out]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && e.contains("of host memory") && e.contains("available"), "{e}");
    // Cornell has glass and a lamp: the explanation names the light paths,
    // and asking for them picks the variant that traces them.
    assert!(e.contains("`--integrator caustics` adds light paths"), "{e}");
    // The timeline names every stage of the process once, in order.
    let timeline = e.lines().find(|l| l.starts_with("timeline")).unwrap_or_else(|| panic!("no timeline: {e}"));
    let at = |what: &str| timeline.find(what).unwrap_or_else(|| panic!("no `{what}` in {timeline}"));
    assert!(at("arguments") < at("scene on the device") && at("scene on the device") < at("render (kernels") && at("render (kernels") < at("image made") && at("image made") < at("image written"), "{timeline}");
    let o = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "8", "--spp", "4", "--integrator", "caustics", "--explain", "--out", out]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && e.contains("spheres_caustics") && e.contains("light paths for caustics"), "{e}");
    let _ = std::fs::remove_file(out);
}

/// `deploy/slurm-array.sh submit` on a real one-node Slurm cluster
/// (`deploy/slurm-local.sh`, started by the test; needs root and the
/// slurm-wlm and munge packages, which CI installs): the job array renders
/// the parts, the dependent job merges them, and the image is the single
/// render's. Ignored by a plain `cargo test`, which lists it as such;
/// `.ci/run` installs Slurm and runs it (`-- --ignored`), and run without
/// Slurm it fails and says why.
#[test]
#[ignore = "needs slurmd, munged and root (.ci/run installs them and runs it with --ignored)"]
fn slurm_array_script_on_a_real_cluster() {
    let have = Command::new("sh").args(["-c", "command -v slurmd && command -v munged && [ $(id -u) = 0 ]"]).output().unwrap();
    assert!(have.status.success(), "this test needs slurm-wlm, munge and root (.ci/run installs them)");
    let dir = std::env::temp_dir().join(format!("treelet-slurm-real-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let deploy = concat!(env!("CARGO_MANIFEST_DIR"), "/../deploy");
    let cluster = dir.join("cluster");
    /// Stops the cluster however the test ends.
    struct Stop(std::path::PathBuf, &'static str);
    impl Drop for Stop {
        fn drop(&mut self) {
            let _ = Command::new("bash").arg(format!("{}/slurm-local.sh", self.1)).arg("stop").arg(&self.0).status();
        }
    }
    let start = Command::new("bash").arg(format!("{deploy}/slurm-local.sh")).arg("start").arg(&cluster).output().unwrap();
    let _stop = Stop(cluster.clone(), deploy);
    assert!(start.status.success(), "the cluster did not start: {}", String::from_utf8_lossy(&start.stderr));
    let conf = cluster.join("slurm.conf");
    let submit = Command::new("bash")
        .arg(format!("{deploy}/slurm-array.sh"))
        .arg("submit")
        .current_dir(&dir)
        .env("SLURM_CONF", &conf)
        .env("TREELET", env!("CARGO_BIN_EXE_treelet"))
        .envs([("DEVICE", "cpu"), ("WIDTH", "24"), ("HEIGHT", "16"), ("SPP", "30"), ("TASKS", "4"), ("SEED", "2"), ("OUT", "merged.pfm")])
        .output()
        .unwrap();
    assert!(submit.status.success(), "submit: {}", String::from_utf8_lossy(&submit.stderr));
    let waited = std::time::Instant::now();
    loop {
        let q = Command::new("squeue").arg("-h").env("SLURM_CONF", &conf).output().unwrap();
        if q.status.success() && q.stdout.is_empty() {
            break;
        }
        assert!(waited.elapsed().as_secs() < 300, "jobs still queued: {}", String::from_utf8_lossy(&q.stdout));
        std::thread::sleep(std::time::Duration::from_millis(250));
    }
    let logs: Vec<String> = std::fs::read_dir(dir.join("parts")).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(logs.iter().filter(|n| n.ends_with(".log")).count() == 5, "four task logs and the merge's: {logs:?}");
    let merged = dir.join("merged.pfm");
    assert!(merged.exists(), "no merged image; logs: {logs:?}");
    let whole = dir.join("whole.pfm").to_string_lossy().to_string();
    let args = ["render", "--device", "cpu", "--width", "24", "--height", "16", "--spp", "30", "--seed", "2", "--out", &whole];
    assert!(treelet(&args).status.success());
    let out = treelet(&["compare", merged.to_str().unwrap(), "--reference", &whole]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("compare prints JSON");
    assert!(v["rmse"].as_f64().unwrap() < 1e-5, "{v}");
    drop(_stop);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene file `name` in a fresh temporary folder (`tag` names it) beside
/// a copy of `scenes/pyramid.obj`, named `p` once and placed again by
/// `copies` (scene-file instance entries); the folder and the file.
fn pyramid_copies(tag: &str, name: &str, copies: &[String]) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("treelet-cli-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/pyramid.obj"), dir.join("pyramid.obj")).unwrap();
    let text = format!(
        r#"{{"camera": {{"origin": [8, 20, 40], "direction": [0, -0.3, -1]}}, "materials": {{"w": {{"type": "diffuse", "color": [1, 1, 1]}}}},
  "meshes": [{{"path": "pyramid.obj", "material": "w", "name": "p"}}], "instances": [{}]}}"#,
        copies.join(", ")
    );
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    (dir, file)
}

/// A scene file placing a mesh by reference: built flattened, with a note
/// that says so; a flattening past the memory available is refused by name
/// before anything is allocated.
#[test]
fn scene_file_instances_are_flattened_with_a_note() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/pyramids.json");
    let out = treelet(&["build", "--scene", scene, "--device", "cpu", "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("5 instances of 1 mesh, flattened into 37 triangles"), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["triangles"], 37, "five pyramids of six triangles, a disk and six walls");
    assert_eq!(v["valid"], true);

    let copies: Vec<String> = (0..2000).map(|k| format!(r#"{{"mesh": "p", "translate": [{k}, 0, 0]}}"#)).collect();
    let (dir, file) = pyramid_copies("instances", "many.json", &copies);
    let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(["build", "--device", "cpu", "--scene", file.to_str().unwrap()])
        .env("TREELET_MAX_MEMORY", "100000")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && !err.contains("panicked"), "{err}");
    assert!(err.contains("many.json") && err.contains("2001 instances of 1 mesh, flattened into 12006 triangles") && err.contains("memory"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `render` keeps a file's copies as instances (`--explain` says so, with the
/// counts), so that copies whose flattening `build` refuses for memory
/// render; `--integrator caustics` traces its light paths through them.
#[test]
fn render_keeps_copies_as_instances() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-render-placed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("pyramids.png");
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/pyramids.json");
    let o = treelet(&["render", "--device", "cpu", "--scene", scene, "--width", "16", "--height", "12", "--spp", "2", "--explain", "--out", out.to_str().unwrap()]);
    let (stdout, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "{err}");
    assert!(err.contains("5 instances of 1 mesh (30 triangles"), "{err}");
    let text = format!("{stdout}{err}");
    assert!(text.contains("kernel     instanced") && text.contains("5 instances of meshes (30 triangles)"), "{text}");
    assert!(out.exists());
    let o = treelet(&["render", "--device", "cpu", "--scene", scene, "--width", "8", "--height", "8", "--spp", "1", "--integrator", "caustics", "--explain", "--out", out.to_str().unwrap()]);
    let (stdout, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "{err}");
    let text = format!("{stdout}{err}");
    assert!(text.contains("kernel     instanced") && text.contains("light paths for caustics, instances of meshes"), "{text}");
    std::fs::remove_dir_all(&dir).ok();

    let copies: Vec<String> = (0..2000).map(|k| format!(r#"{{"mesh": "p", "translate": [{}, 0, {}]}}"#, (k % 50) * 2, (k / 50) * 2)).collect();
    let (dir, file) = pyramid_copies("render-many", "many.json", &copies);
    let out = dir.join("many.png");
    // 1 MB: the copies flattened need about 1.9 MB, placed about 0.8 MB.
    let with_cap = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_treelet")).args(args).env("TREELET_MAX_MEMORY", "1000000").output().unwrap();
    let scene = file.to_str().unwrap();
    let o = with_cap(&["build", "--device", "cpu", "--scene", scene]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("flattened into 12006 triangles") && err.contains("memory"), "{err}");
    let o = with_cap(&["render", "--device", "cpu", "--scene", scene, "--width", "16", "--height", "12", "--spp", "1", "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("2001 instances of 1 mesh (12006 triangles"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `bench file-instances` traces a file's own instances against the same scene
/// flattened, with the same hits; a file whose own shapes are not
/// triangles is refused by name.
#[test]
fn bench_file_instances_traces_a_files_instances() {
    let copies: Vec<String> =
        (0..24).map(|k| format!(r#"{{"mesh": "p", "translate": [{}, 0, {}], "rotate": [0, {}, 0]}}"#, (k % 6) * 3, (k / 6) * 3, k * 7)).collect();
    let (dir, file) = pyramid_copies("placed", "grid.json", &copies);
    let json = dir.join("out.json");
    let args = ["bench", "file-instances", "--device", "cpu", "--repeats", "1", "--width", "32", "--height", "24"];
    let out = treelet(&[&args[..], &["--scene", file.to_str().unwrap(), "--json", json.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let row = &doc["row"];
    assert_eq!((row["meshes"].as_u64(), row["instances"].as_u64()), (Some(1), Some(25)), "{doc}");
    assert_eq!((row["triangles_kept"].as_u64(), row["triangles_flattened"].as_u64()), (Some(6), Some(150)), "{doc}");
    assert!(row["hits_differ"].as_u64().is_some_and(|d| d * 100 <= row["camera_rays"].as_u64().unwrap()), "{doc}");
    for key in ["build_instanced_ms", "top_level_ms", "instanced_primary_mrays", "flattened_diffuse_mrays"] {
        assert!(row[key].as_f64().is_some_and(|v| v > 0.0 && v.is_finite()), "{key}: {doc}");
    }
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/pyramids.json");
    let e = stderr_of(&[&args[..], &["--scene", room]].concat());
    assert!(e.contains("pyramids.json") && e.contains("triangles only"), "{e}");
    let e = stderr_of(&[&args[..], &["--scene", "cornell"]].concat());
    assert!(e.contains("expected a .gltf/.glb or a .json scene file"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Untrusted input and hostile outputs (issue 66): no panic, no replaced
/// device or part, and a clear message.
#[test]
fn hostile_arguments_and_outputs_get_clear_errors() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    // Checkpoints past what a clock holds.
    for every in ["1e19", "1e30", "inf", "nan"] {
        let e = stderr_of(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--spp", "1", "--checkpoint", every, "--out", &path("c.png")]);
        assert!(e.contains("--checkpoint") && e.contains("at most"), "{every}: {e}");
    }
    // A full standard output: exit 1 and a note, not a panic.
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(["build", "--scene", "random:100", "--device", "cpu", "--json"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code() == Some(1) && err.contains("standard output") && !err.contains("panicked"), "{:?} {err}", out.status);
    // A full standard error loses the notes only.
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(["build", "--scene", "random:100", "--device", "cpu", "--json"])
        .stderr(full)
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", out.status);
    // --resume naming --out would replace the part with the image.
    std::fs::write(dir.join("p.exr"), b"not read").unwrap();
    let e = stderr_of(&["render", "--device", "cpu", "--resume", &path("p.exr"), "--out", &path("p.exr")]);
    assert!(e.contains("--resume") && e.contains("same file"), "{e}");
    // A memory cap, or any other TREELET_* knob, that cannot be read is an
    // error that names it, not a knob ignored.
    for (name, value) in [("TREELET_MAX_MEMORY", "lots"), ("TREELET_SPLITS", "-1"), ("TREELET_SORT_TILES", "huge"), ("TREELET_TREELETS", "3,3")] {
        let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
            .args(["build", "--scene", "random:100", "--device", "cpu"])
            .env(name, value)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.code() == Some(1) && err.contains(&format!("{name}={value}: ")), "{err}");
    }
    // A folder that is a file is called a file.
    std::fs::write(dir.join("afile"), b"x").unwrap();
    let e = stderr_of(&["render", "--device", "cpu", "--out", &path("afile/out.png")]);
    assert!(e.contains("is a file, not a folder"), "{e}");
    // A report written through a link to a regular file keeps the link.
    std::fs::write(dir.join("target.json"), b"{}").unwrap();
    let link = dir.join("report.json");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(dir.join("target.json"), &link).unwrap();
    let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--spp", "1", "--out", &path("r.png"), "--report", &path("report.json")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link was replaced by a file");
    assert!(std::fs::read_to_string(dir.join("target.json")).unwrap().len() > 2, "the report went elsewhere");
    // A scene file that starts with a byte-order mark reads as without.
    let scene = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell.json")).unwrap();
    std::fs::write(dir.join("bom.json"), format!("\u{feff}{scene}")).unwrap();
    let out = treelet(&["render", "--device", "cpu", "--scene", &path("bom.json"), "--width", "8", "--height", "6", "--spp", "1", "--out", &path("bom.png")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

/// Cases a probe of 428 hostile inputs found (2026-12-02), each of which
/// replaced an input, hung or said the wrong thing: no output over a file
/// the command read, bounded knobs, empty device names, unknown export
/// formats, a memory cap named as such.
#[test]
fn outputs_never_replace_inputs_and_probe_findings_stay_fixed() {
    let dir = std::env::temp_dir().join(format!("treelet-cli-probe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let scene = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell.json")).unwrap();
    std::fs::write(dir.join("in.json"), &scene).unwrap();
    let small = ["--device", "cpu", "--width", "8", "--height", "6", "--spp", "1"];
    let render = |extra: &[&str]| {
        let mut args = vec!["render"];
        args.extend_from_slice(&small);
        args.extend_from_slice(extra);
        stderr_of(&args)
    };
    // --report over the scene file it renders: refused, the scene kept.
    let e = render(&["--scene", &path("in.json"), "--out", &path("o.png"), "--report", &path("in.json")]);
    assert!(e.contains("--report") && e.contains("read that file as an input"), "{e}");
    assert_eq!(std::fs::read_to_string(dir.join("in.json")).unwrap(), scene);
    // --report naming --out by another path (`sub/../o.png`), before either exists.
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let e = render(&["--out", &path("o2.pfm"), "--report", &path("sub/../o2.pfm")]);
    assert!(e.contains("--report") && e.contains("same file as --out"), "{e}");
    // A part rendered again over its own finished part (a requeued Slurm or
    // Kubernetes task): read only to judge it, not an input, so not refused.
    for _ in 0..2 {
        let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--samples", "0..2", "--out", &path("again.exr")]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    // --out over the reference image it is scored against.
    let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--spp", "1", "--out", &path("ref.pfm")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference = std::fs::read(dir.join("ref.pfm")).unwrap();
    let e = render(&["--reference", &path("ref.pfm"), "--out", &path("ref.pfm")]);
    assert!(e.contains("--out") && e.contains("read that file as an input"), "{e}");
    assert_eq!(std::fs::read(dir.join("ref.pfm")).unwrap(), reference);
    // export over the mesh it exports, or over the mesh a scene file names.
    let mesh = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(dir.join("q.obj"), mesh).unwrap();
    let e = stderr_of(&["export", "--scene", &path("q.obj"), "--out", &path("q.obj")]);
    assert!(e.contains("read that file as an input"), "{e}");
    assert_eq!(std::fs::read_to_string(dir.join("q.obj")).unwrap(), mesh);
    let e = stderr_of(&["export", "--scene", &path("q.obj"), "--out", &path("q.stl")]);
    assert!(e.contains("export writes .ply or .obj"), "{e}");
    // Knobs bounded as their options are: 2^32 - 1 reinsertion iterations ran for ever.
    let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(["build", "--scene", "terrain:300", "--builder", "trbvh", "--device", "cpu"])
        .env("TREELET_REINSERT", "4294967295")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code() == Some(1) && err.contains("TREELET_REINSERT=4294967295"), "{err}");
    // An empty device name matched every adapter.
    let e = stderr_of(&["render", "--devices", ",,", "--width", "8", "--height", "6", "--spp", "1", "--out", &path("d.png")]);
    assert!(e.contains("an empty name in the list"), "{e}");
    // A memory cap that refuses a render is named as the cause.
    let out = Command::new(env!("CARGO_BIN_EXE_treelet"))
        .args(["render", "--device", "cpu", "--width", "64", "--height", "64", "--spp", "1", "--out", &path("m.png")])
        .env("TREELET_MAX_MEMORY", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("TREELET_MAX_MEMORY"), "{err}");
    // A --max-input-bytes of 2^64 - 1 read every input as empty (it wrapped).
    let out = treelet(&["render", "--device", "cpu", "--width", "8", "--height", "6", "--spp", "1", "--scene", &path("in.json"), "--max-input-bytes", "18446744073709551615", "--out", &path("x.png")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

/// A glTF file's cameras and extensions as `render` takes them: `--camera
/// N` picks camera N (a camera that does not exist, or a scene without
/// cameras, is an error naming it); each extension Treelet does not read
/// gets one note, the ones it reads none.
#[test]
fn gltf_cameras_are_chosen_and_unread_extensions_named() {
    use base64::Engine as _;
    let dir = std::env::temp_dir().join(format!("treelet-cli-cameras-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let positions: Vec<u8> = [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|x| x.to_le_bytes()).collect();
    let uri = format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&positions));
    let gltf = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_ior", "KHR_texture_transform", "KHR_lights_punctual"],
  "scene": 0, "scenes": [{{"nodes": [0, 1, 2]}}],
  "nodes": [{{"mesh": 0}}, {{"translation": [0.3, 0.3, 4], "camera": 0}}, {{"translation": [0.3, 0.3, 2], "camera": 1}}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1}}}}, {{"type": "perspective", "perspective": {{"yfov": 1.2, "znear": 0.1}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": 36}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}}]}}"#
    );
    let path = dir.join("two_cameras.gltf");
    std::fs::write(&path, gltf).unwrap();
    let scene = path.to_str().unwrap();
    let out_png = dir.join("c1.png");
    let o = treelet(&["render", "--device", "cpu", "--scene", scene, "--camera", "1", "--width", "16", "--height", "12", "--spp", "1", "--out", out_png.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("extension KHR_texture_transform is not supported"), "{err}");
    assert!(err.contains("punctual lights (KHR_lights_punctual) are not supported"), "{err}");
    assert!(!err.contains("KHR_materials_ior"), "a read extension got a note: {err}");
    assert!(!err.contains("perspective cameras; the first placed is used"), "--camera was given: {err}");
    let e = stderr_of(&["render", "--device", "cpu", "--scene", scene, "--camera", "7", "--spp", "1"]);
    assert!(e.contains("no camera 7: the file has 2"), "{e}");
    let e = stderr_of(&["render", "--device", "cpu", "--scene", "cornell", "--camera", "0", "--spp", "1"]);
    assert!(e.contains("only glTF scenes"), "{e}");
    // Without --camera, a note says which of the two is used.
    let o = treelet(&["render", "--device", "cpu", "--scene", scene, "--width", "16", "--height", "12", "--spp", "1", "--out", dir.join("c0.png").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && err.contains("2 perspective cameras; the first placed is used"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
