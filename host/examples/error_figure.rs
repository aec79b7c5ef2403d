//! The error-against-time figure of `docs/results/h100-nee/`: RMSE against
//! wall time on the disk-lit room for Treelet's two integrators (from their
//! `render --report` files) and Mitsuba 3 (from `peers/mitsuba/room_disk.py`'s
//! timings and `treelet compare`'s scores against Mitsuba's own 4096-spp image).
//!
//!     cargo run --release -p treelet --example error_figure -- docs/results/h100-nee
use std::path::Path;

use anyhow::{Context, Result};
use treelet::internals::plot::{error_vs_time, Series};

fn main() -> Result<()> {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "docs/results/h100-nee".into());
    let dir = Path::new(&dir);
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).with_context(|| format!("{}/{name}", dir.display()));
    let mut series = Vec::new();
    for (file, label) in [("room_disk_nee.json", "Treelet, next-event estimation"), ("room_disk_smallpt.json", "Treelet, smallpt's estimator")] {
        let report: serde_json::Value = serde_json::from_str(&read(file)?)?;
        let points = report["rows"]
            .as_array()
            .context("rows")?
            .iter()
            .filter_map(|r| Some((r["elapsed_s"].as_f64()?, r["rmse"].as_f64()?)))
            .collect();
        series.push(Series { label: format!("{label} (against Treelet's 8192 spp)"), points });
    }
    // Mitsuba: wall time per sample count, RMSE against its own 4096-spp image.
    let times: Vec<(u64, f64)> = read("mitsuba.jsonl")?
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter_map(|v| Some((v["spp"].as_u64()?, v["wall_s"].as_f64()?)))
        .collect();
    let mut points = Vec::new();
    for l in read("mitsuba_scores.jsonl")?.lines() {
        let v: serde_json::Value = serde_json::from_str(l)?;
        let (image, reference) = (v["image"].as_str().unwrap_or(""), v["reference"].as_str().unwrap_or(""));
        if !reference.contains("mitsuba_room_disk_4096spp") {
            continue;
        }
        let spp: u64 = image.rsplit('_').next().and_then(|s| s.strip_suffix("spp.exr")).and_then(|s| s.parse().ok()).context(image.to_string())?;
        if let Some(&(_, t)) = times.iter().find(|&&(s, _)| s == spp) {
            points.push((t, v["rmse"].as_f64().context("rmse")?));
        }
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    series.push(Series { label: "Mitsuba 3 (OptiX), path tracer with MIS (against its own 4096 spp)".into(), points });
    let out = dir.join("room_disk_error.png");
    error_vs_time(&out, "scenes/room_disk.json, 1024x768, NVIDIA H100: RMSE against wall time", "RMSE", &series)?;
    println!("wrote {}", out.display());
    Ok(())
}
