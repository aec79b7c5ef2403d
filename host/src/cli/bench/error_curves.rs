//! `treelet bench error`: how fast each integrator's error falls, as RMSE
//! against a reference that Treelet renders long (next-event estimation,
//! another seed), after each pass of one render, against the render's wall
//! time (`error`) and its kernel time (`error-kernel`). Mitsuba 3's images
//! of the same room (`peers/mitsuba/room_disk.py`, run on the same GPU) are
//! scored beside them with the same error code when `--mitsuba DIR` names
//! its output.
use std::path::Path;

use anyhow::{Context, Result};
use treelet::bvh::layout::Layout;
use treelet::render::variant::KernelChoice;
use treelet::bvh::tree::Accel;
use treelet::render::{render, Integrator, RenderSettings, Sampler};
use treelet::scene::Scene;

use super::figure::{bar, doc, Figure, FigureDoc, Point, Suite, ERROR_KERNEL};
use super::measure::median;
use treelet::runtime::device::Device;
use treelet::render::image_io::{self, HdrImage};
use anyhow::bail;
use treelet::render::{image_error, PassRow};

/// The scenes: smallpt's room with its big sphere light, and the room lit by
/// a small disk of triangles (as Mitsuba sees it).
const SCENES: [(&str, &str); 2] = [("cornell", "cornell"), ("room_disk", "room_disk")];

/// Both figures: against wall time, then against kernel time.
pub(crate) fn measure(s: &Suite, runner: &Device) -> Result<Vec<FigureDoc>> {
    let (w, h, spp, reference_spp) = if s.quick { (96, 72, 64, 1024) } else { (1024, 768, 1024, 4096) };
    let mut wall = doc(Figure::Error, &format!("RMSE against wall time, {w}x{h}"), "wall time (s)", "RMSE against the reference", (true, true));
    let mut kernel = doc(Figure::Error, &format!("RMSE against kernel time, {w}x{h}"), "kernel time (s)", "RMSE against the reference", (true, true));
    kernel.figure = ERROR_KERNEL.into();
    let parameters = serde_json::json!({ "scenes": SCENES.map(|s| s.1), "width": w, "height": h, "spp": spp, "reference_spp": reference_spp });
    wall.parameters = parameters.clone();
    kernel.parameters = parameters;
    let pb = bar(SCENES.len() * (1 + 4 * s.repeats), "renders");
    for (name, spec) in SCENES {
        let scene = Scene::from_spec(spec)?;
        let settings = |integrator, sampler, spp, seed, error_each_pass| RenderSettings {
            width: w,
            height: h,
            spp,
            seed,
            accel: Accel::Auto,
            layout: Layout::Auto,
            kernel: KernelChoice::Auto,
            integrator,
            sampler,
            error_each_pass,
            first_sample: 0,
        };
        treelet::with_backend!(runner, |b| {
            pb.set_message(format!("{name}: reference, {reference_spp} spp"));
            let reference = render(b, &scene, &settings(Integrator::Nee, Sampler::Sobol, reference_spp, 99, false), None, |_| {})?.image;
            let path = s.out.join(format!("error_reference_{name}.exr"));
            image_io::write(&path, &reference)?;
            pb.inc(1);
            // Every integrator with the default sampler, and next-event
            // estimation with independent numbers beside it.
            let runs_of = [
                (Integrator::Smallpt, Sampler::Sobol),
                (Integrator::Nee, Sampler::Sobol),
                (Integrator::Caustics, Sampler::Sobol),
                (Integrator::Nee, Sampler::Independent),
            ];
            for (integrator, sampler) in runs_of {
                pb.set_message(format!("{name}: {} ({})", integrator.name(), sampler.name()));
                // Warm-up: the first render compiles the kernel (Mitsuba's times also leave that out).
                render(b, &scene, &settings(integrator, sampler, 4, 1, false), None, |_| {})?;
                let mut runs = Vec::new();
                for _ in 0..s.repeats {
                    runs.push(render(b, &scene, &settings(integrator, sampler, spp, 1, true), Some(&reference), |_| {})?.rows);
                    pb.inc(1);
                }
                let series = match sampler {
                    Sampler::Sobol => format!("{name}: Treelet, {}", integrator.label()),
                    Sampler::Independent => format!("{name}: Treelet, {}, independent numbers", integrator.label()),
                };
                for (i, row) in runs[0].iter().enumerate() {
                    let rmse = row.rmse.context("a render against a reference has an RMSE")?;
                    let at = |time: fn(&PassRow) -> f64| median(runs.iter().map(|r| time(&r[i])).collect());
                    wall.points.push(Point { x: at(|r| r.wall_s), ..Point::once(&series, 0.0, rmse) });
                    kernel.points.push(Point { x: at(|r| r.kernel_s), ..Point::once(&series, 0.0, rmse) });
                }
                let spps: Vec<String> = runs[0].iter().map(|r| r.spp.to_string()).collect();
                wall.notes.push(format!("{series}: {} spp at its points", spps.join(", ")));
            }
        });
        if let (Some(dir), "room_disk") = (&s.mitsuba, name) {
            let reference = image_io::read_hdr(&s.out.join(format!("error_reference_{name}.exr")))?;
            for (label, time, rmse) in mitsuba_points(dir, &reference)? {
                let series = format!("{name}: Mitsuba 3, {label}");
                wall.points.push(Point::once(&series, time.0, rmse));
                kernel.points.push(Point::once(&series, time.1, rmse));
            }
        }
    }
    pb.finish_and_clear();
    for d in [&mut wall, &mut kernel] {
        d.notes.extend(equal_time_notes(d));
        d.notes.push(format!(
            "Treelet: one render per integrator and scene ({} repeats, median times), its error after each pass against \
             Treelet's reference (next-event estimation, {reference_spp} spp, seed 99); `--accel auto`; time from the start of \
             the render (BVH build included, kernel compilation left out by a warm-up render; wall time leaves out the \
             readbacks and scoring of earlier passes, which only this measurement needs)",
            s.repeats
        ));
    }
    if s.mitsuba.is_some() {
        wall.notes.push(
            "Mitsuba 3: `peers/mitsuba/room_disk.py` (a fresh render per sample count, its wall time from the render call to \
             its image in device memory, its kernel time from Dr.Jit's kernel history), scored by Treelet's error code \
             against its own largest sample count (its noise) and against Treelet's reference (which also shows where \
             the two renderers' rooms differ)"
                .into(),
        );
        wall.notes.push(
            "Pixel filters differ: Treelet (every integrator) counts each sample in its own pixel only, placed by smallpt's \
             tent jitter around the pixel's 2x2 subpixel centres; Mitsuba 3 uses the filter its series names (`rfilter`; \
             `room_disk.py` renders with a tent unless RFILTER=box), and a tent splats each sample into the pixels within \
             one pixel of it, which lowers per-pixel noise and blurs the image: only its box series is like for like"
                .into(),
        );
        wall.notes.push(
            "Samplers: Treelet's series draw Owen-scrambled Sobol points (`--sampler sobol`, its default) unless they say \
             independent numbers; Mitsuba 3's draw independent numbers (its default) unless they name its ldsampler \
             (`SAMPLER=ldsampler`: scrambled (0,2)-sequences)"
                .into(),
        );
    }
    Ok(vec![wall, kernel])
}

/// Mitsuba's images listed in `dir/mitsuba.jsonl` (one JSON object a line:
/// `spp`, `wall_s`, `kernel_ms`, `image`, and `rfilter`, its pixel filter,
/// `tent` where a line has none, and `sampler`, `independent` where a line
/// has none), each scored against the largest sample count of its filter
/// and sampler and against Treelet's `reference`: (series label, which
/// names the filter and any sampler but the independent one, (wall s,
/// kernel s), RMSE).
fn mitsuba_points(dir: &Path, reference: &HdrImage) -> Result<Vec<(String, (f64, f64), f64)>> {
    let list = dir.join("mitsuba.jsonl");
    let text = std::fs::read_to_string(&list).with_context(|| format!("reading {}", list.display()))?;
    let mut runs = Vec::new();
    for (i, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let where_ = || format!("{}:{}", list.display(), i + 1);
        let v: serde_json::Value = serde_json::from_str(line).with_context(where_)?;
        let field = |k: &str| v[k].as_f64().with_context(|| format!("{}: no number `{k}`", where_()));
        let image = v["image"].as_str().with_context(|| format!("{}: no string `image`", where_()))?;
        // The script wrote the path on the device; the image lies beside the list.
        let file = Path::new(image).file_name().with_context(|| format!("{}: `{image}` names no file", where_()))?;
        let hdr = image_io::read_hdr(&dir.join(file))?;
        if (hdr.width, hdr.height) != (reference.width, reference.height) {
            bail!(
                "{}: {} is {}x{}, the figure's images {}x{} (Mitsuba's script renders 1024x768: leave out --quick)",
                where_(),
                file.to_string_lossy(),
                hdr.width,
                hdr.height,
                reference.width,
                reference.height
            );
        }
        // Series by filter and, past Mitsuba's default, sampler.
        let filter = match (v["rfilter"].as_str().unwrap_or("tent"), v["sampler"].as_str().unwrap_or("independent")) {
            (filter, "independent") => format!("{filter} filter"),
            (filter, sampler) => format!("{filter} filter, {sampler} sampler"),
        };
        runs.push((filter, field("spp")?, (field("wall_s")?, field("kernel_ms")? / 1e3), hdr));
    }
    if runs.is_empty() {
        bail!("{}: no images listed", list.display());
    }
    let pixels = |img: &HdrImage| img.pixels.iter().map(|p| p.map(f64::from)).collect::<Vec<_>>().into_iter();
    let mut points = Vec::new();
    for (filter, spp, time, image) in &runs {
        let same = || runs.iter().filter(|r| r.0 == *filter);
        let top = same().map(|r| r.1).fold(0.0, f64::max);
        let own = &same().find(|r| r.1 == top).expect("the largest is in the list").3;
        if *spp < top {
            points.push((format!("{filter}, against its own {top} spp"), *time, image_error(pixels(image), own).0));
        }
        points.push((format!("{filter}, against Treelet's reference"), *time, image_error(pixels(image), reference).0));
    }
    points.sort_by(|a, b| a.0.cmp(&b.0).then(a.1 .0.total_cmp(&b.1 .0)));
    Ok(points)
}

/// For each scene: every series' RMSE at the time of next-event
/// estimation's last point, interpolated on the log-log curve (beyond a
/// series' ends, extended with slope -1/2, as Monte Carlo error falls).
fn equal_time_notes(d: &FigureDoc) -> Vec<String> {
    let mut notes = Vec::new();
    for (name, _) in SCENES {
        let nee = format!("{name}: Treelet, {}", Integrator::Nee.label());
        let Some(t) = d.points.iter().filter(|p| p.series == nee).map(|p| p.x).reduce(f64::max) else { continue };
        let mut names: Vec<&str> = Vec::new();
        for p in d.points.iter().filter(|p| p.series.starts_with(&format!("{name}: "))) {
            if !names.contains(&p.series.as_str()) {
                names.push(&p.series);
            }
        }
        let at = |series: &str| {
            let pts: Vec<(f64, f64)> = d.points.iter().filter(|p| p.series == series && p.x > 0.0 && p.median > 0.0).map(|p| (p.x, p.median)).collect();
            rmse_at(&pts, t)
        };
        let Some(base) = at(&nee) else { continue };
        let parts: Vec<String> = names
            .iter()
            .filter_map(|n| at(n).map(|e| format!("{} {:.4} ({:.2}x next-event estimation's)", n.trim_start_matches(&format!("{name}: ")), e, e / base)))
            .collect();
        notes.push(format!("{name} at {t:.3} s ({}): {}", d.x_label, parts.join("; ")));
    }
    notes
}

/// The error of a curve at time `t`: log-log interpolation between the
/// points around it, or slope -1/2 from the nearest end.
pub(crate) fn rmse_at(points: &[(f64, f64)], t: f64) -> Option<f64> {
    let mut pts = points.to_vec();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (first, last) = (*pts.first()?, *pts.last()?);
    if t <= first.0 {
        return Some(first.1 * (t / first.0).powf(-0.5));
    }
    if t >= last.0 {
        return Some(last.1 * (t / last.0).powf(-0.5));
    }
    let i = pts.iter().position(|p| p.0 >= t)?;
    let (a, b) = (pts[i - 1], pts[i]);
    let f = (t / a.0).ln() / (b.0 / a.0).ln();
    Some((a.1.ln() + f * (b.1 / a.1).ln()).exp())
}

#[cfg(test)]
mod tests {
    use super::{mitsuba_points, rmse_at};
    use treelet::render::image_io::{write, HdrImage};

    /// Mitsuba's list with a bad line or a missing image: an error that names
    /// the file and line; a good list: scores against both references.
    #[test]
    fn mitsuba_lists_are_read_with_clear_errors() {
        let dir = std::env::temp_dir().join(format!("treelet-mitsuba-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let image = |v: f32| HdrImage { width: 4, height: 2, pixels: vec![[v; 3]; 8] };
        write(&dir.join("a_16spp.pfm"), &image(1.5)).unwrap();
        write(&dir.join("a_64spp.pfm"), &image(1.25)).unwrap();
        let line = |spp: u32, file: &str| format!("{{\"spp\": {spp}, \"wall_s\": 0.5, \"kernel_ms\": 400, \"image\": \"/elsewhere/{file}\"}}\n");
        let list = dir.join("mitsuba.jsonl");
        std::fs::write(&list, line(16, "a_16spp.pfm") + &line(64, "a_64spp.pfm")).unwrap();
        let points = mitsuba_points(&dir, &image(1.0)).unwrap();
        assert_eq!(points.len(), 3);
        assert!(points.iter().any(|p| p.0 == "tent filter, against its own 64 spp" && (p.2 - 0.25).abs() < 1e-6));
        assert!(points.iter().any(|p| p.0 == "tent filter, against Treelet's reference" && (p.2 - 0.5).abs() < 1e-6));
        // Each filter is its own series, scored against its own largest count.
        let boxed = |spp: u32, file: &str| line(spp, file).replace("\"spp\"", "\"rfilter\": \"box\", \"spp\"");
        std::fs::write(&list, line(16, "a_16spp.pfm") + &line(64, "a_64spp.pfm") + &boxed(16, "a_64spp.pfm") + &boxed(32, "a_16spp.pfm")).unwrap();
        let points = mitsuba_points(&dir, &image(1.0)).unwrap();
        assert_eq!(points.len(), 6);
        assert!(points.iter().any(|p| p.0 == "box filter, against its own 32 spp" && (p.2 - 0.25).abs() < 1e-6), "{points:?}");
        // And each sampler.
        let ld = |spp: u32, file: &str| line(spp, file).replace("\"spp\"", "\"sampler\": \"ldsampler\", \"spp\"");
        std::fs::write(&list, line(16, "a_16spp.pfm") + &line(64, "a_64spp.pfm") + &ld(16, "a_64spp.pfm") + &ld(32, "a_16spp.pfm")).unwrap();
        let points = mitsuba_points(&dir, &image(1.0)).unwrap();
        assert_eq!(points.len(), 6);
        assert!(points.iter().any(|p| p.0 == "tent filter, ldsampler sampler, against its own 32 spp" && (p.2 - 0.25).abs() < 1e-6), "{points:?}");
        assert!(points.iter().any(|p| p.0 == "tent filter, against its own 64 spp" && (p.2 - 0.25).abs() < 1e-6), "{points:?}");
        std::fs::write(&list, line(16, "a_16spp.pfm") + "{\"spp\": 64}\n").unwrap();
        let e = format!("{:#}", mitsuba_points(&dir, &image(1.0)).unwrap_err());
        assert!(e.contains("mitsuba.jsonl:2") && e.contains("no string `image`"), "{e}");
        std::fs::write(&list, line(16, "missing.pfm")).unwrap();
        let e = format!("{:#}", mitsuba_points(&dir, &image(1.0)).unwrap_err());
        assert!(e.contains("missing.pfm"), "{e}");
        std::fs::write(&list, line(16, "a_16spp.pfm")).unwrap();
        let e = format!("{:#}", mitsuba_points(&dir, &HdrImage { width: 2, height: 2, pixels: vec![[1.0; 3]; 4] }).unwrap_err());
        assert!(e.contains("is 4x2, the figure's images 2x2"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn interpolates_on_the_log_log_curve_and_extends_with_slope_minus_half() {
        let pts = [(1.0, 1.0), (4.0, 0.5)];
        assert!((rmse_at(&pts, 2.0).unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((rmse_at(&pts, 16.0).unwrap() - 0.25).abs() < 1e-12);
        assert!((rmse_at(&pts, 0.25).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(rmse_at(&[], 1.0), None);
    }
}
