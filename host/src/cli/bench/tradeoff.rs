//! `bench rays --figure DIR`: build time against rays per second, one
//! point per tree and layout, and OptiX's point beside them from
//! `../shared/tools/optix-peer/peer.py`'s output (`--optix FILE`) for the
//! same mesh and image size. Two figures, `tradeoff-primary` and
//! `tradeoff-diffuse`: a user picks the tree that sits highest for the
//! build time they can afford.
use std::path::Path;

use anyhow::{bail, Context, Result};

use super::figure::{write_figure, FigureDoc, Point};
use super::measure::RaysRow;
use super::suite::tree_name;

/// What peer.py measured: its build and its rays through the same framing.
#[derive(Debug, PartialEq)]
pub(crate) struct PeerPoint {
    pub(crate) name: String,
    pub(crate) triangles: u64,
    pub(crate) size: (u32, u32),
    pub(crate) build_ms: f64,
    pub(crate) primary_mrays: f64,
    pub(crate) diffuse_mrays: f64,
}

/// Reads the mesh line of peer.py's JSON lines (the one with a build time);
/// other lines (its smallpt render) are skipped. A file without one, or
/// with a field missing, is an error naming the file and line.
pub(crate) fn read_peer(path: &Path) -> Result<PeerPoint> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading OptiX results {}", path.display()))?;
    for (i, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let v: serde_json::Value = serde_json::from_str(line)
            .with_context(|| format!("{} line {}: not a JSON line of peer.py", path.display(), i + 1))?;
        if v.get("build_wall_ms_median").is_none() {
            continue;
        }
        let num = |k: &str| {
            v[k].as_f64()
                .filter(|x| x.is_finite() && *x >= 0.0)
                .with_context(|| format!("{} line {}: `{k}` missing or not a number", path.display(), i + 1))
        };
        return Ok(PeerPoint {
            name: v["peer"].as_str().unwrap_or("OptiX").split(" cuda_ad").next().unwrap_or("OptiX").to_string(),
            triangles: num("triangles")? as u64,
            size: (num("width")? as u32, num("height")? as u32),
            build_ms: num("build_wall_ms_median")?,
            primary_mrays: num("primary_mrays_s")?,
            diffuse_mrays: num("diffuse_mrays_s")?,
        });
    }
    bail!("{}: no mesh measurement (a line with `build_wall_ms_median`) from peer.py", path.display())
}

/// The peer must have measured the same mesh (triangle count) at the same
/// image size, or the points would not compare: an error says which.
pub(crate) fn check_peer(p: &PeerPoint, triangles: usize, size: (u32, u32)) -> Result<()> {
    if p.triangles != triangles as u64 {
        bail!(
            "the OptiX results are for {} triangles, this mesh has {triangles}: run peer.py on the same mesh",
            p.triangles
        );
    }
    if p.size != size {
        bail!(
            "the OptiX results are for {}x{}, these rays for {}x{}: give both the same size",
            p.size.0,
            p.size.1,
            size.0,
            size.1
        );
    }
    Ok(())
}

/// Writes `tradeoff-primary` and `tradeoff-diffuse` (JSON and PNG) into
/// `dir`, the peer's point (checked by [`check_peer`]) beside Treelet's.
pub(crate) fn write(
    dir: &Path,
    rows: &[RaysRow],
    size: (u32, u32),
    (device, adapter): (&str, &str),
    peer: Option<&PeerPoint>,
) -> Result<()> {
    let Some(first) = rows.first() else {
        bail!("no trees were timed: nothing to draw");
    };
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for (kind, pick) in [("primary", 0), ("diffuse", 1)] {
        let mut doc = FigureDoc {
            figure: format!("tradeoff-{kind}"),
            title: format!(
                "{kind} rays per second against build time ({}, {} triangles)",
                first.scene, first.primitives
            ),
            x_label: "build + layout time (ms)".into(),
            y_label: format!("M {kind} rays/s"),
            log_x: true,
            log_y: false,
            scatter: true,
            device: device.into(),
            adapter: adapter.into(),
            date: chrono::Utc::now().format("%Y-%m-%d").to_string(),
            command: std::env::args().collect::<Vec<_>>().join(" "),
            quick: false,
            parameters: serde_json::json!({ "width": size.0, "height": size.1, "scene": first.scene }),
            notes: vec![format!(
                "{}x{}, one camera ray and one cosine bounce per pixel, no shading; Treelet: GPU timestamps, medians",
                size.0, size.1
            )],
            points: Vec::new(),
        };
        for r in rows {
            let y = if pick == 0 { r.primary_mrays_per_s } else { r.diffuse_mrays_per_s };
            doc.points.push(Point::once(tree_name(r.accel, r.layout), r.build_ms + r.layout_ms, y));
        }
        if let Some(p) = peer {
            let y = if pick == 0 { p.primary_mrays } else { p.diffuse_mrays };
            doc.points.push(Point::once(p.name.clone(), p.build_ms, y));
            doc.notes.push(format!(
                "{}: build is the wall time of creating the scene (median), rays Dr.Jit's kernel times, from peer.py in the same call",
                p.name
            ));
        }
        write_figure(dir, &doc)?;
    }
    Ok(())
}
