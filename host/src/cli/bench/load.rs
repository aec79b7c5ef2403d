//! `treelet bench load`: how fast meshes load, beside how fast their bytes
//! are read (the `cat FILE >/dev/null` of issue 66's benchmark). The files
//! are given, or made once from `terrain:N` as a binary PLY and an OBJ.
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context as _, Result};
use treelet::scene::Scene;

/// One file's row.
#[derive(serde::Serialize)]
pub struct LoadRow {
    pub file: String,
    pub bytes: u64,
    pub triangles: usize,
    /// Streaming the file's bytes through a 1 MiB buffer, as `cat FILE
    /// >/dev/null` does (from the page cache after a first read), median.
    pub cat_s: f64,
    /// Reading them into memory (`std::fs::read`: the pages of a new
    /// buffer as well), median.
    pub read_s: f64,
    /// `treelet::scene::mesh::load` (read, parse, checks), median.
    pub load_s: f64,
}

impl LoadRow {
    pub fn cat_mb_s(&self) -> f64 {
        self.bytes as f64 / 1e6 / self.cat_s
    }
    pub fn read_mb_s(&self) -> f64 {
        self.bytes as f64 / 1e6 / self.read_s
    }
    pub fn load_mb_s(&self) -> f64 {
        self.bytes as f64 / 1e6 / self.load_s
    }
}

/// `files`, then a PLY and an OBJ of `terrain:N` in `dir` for each of `sizes`
/// (written where missing); each timed `repeats` times.
pub fn bench_load(files: &[PathBuf], sizes: &[usize], dir: &Path, repeats: usize) -> Result<Vec<LoadRow>> {
    let mut all = files.to_vec();
    for &n in sizes {
        let mut scene = None;
        for ext in ["ply", "obj"] {
            let path = dir.join(format!("terrain_{n}.{ext}"));
            if !path.exists() {
                std::fs::create_dir_all(dir).with_context(|| format!("cannot make {}", dir.display()))?;
                let scene = match &mut scene {
                    Some(s) => s,
                    None => scene.insert(Scene::from_spec(&format!("terrain:{n}"))?),
                };
                eprintln!("writing {}", path.display());
                treelet::scene::ply::write(scene, &path)?;
            }
            all.push(path);
        }
    }
    let mut rows = Vec::new();
    for path in &all {
        let bytes = std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?.len();
        std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?; // into the page cache
        let cat_s = median(repeats, || {
            let mut file = std::fs::File::open(path)?;
            let mut buffer = vec![0u8; 1 << 20];
            while std::io::Read::read(&mut file, &mut buffer)? > 0 {}
            Ok(())
        })?;
        let read_s = median(repeats, || {
            std::fs::read(path)?;
            Ok(())
        })?;
        let mut triangles = 0;
        let load_s = median(repeats, || {
            triangles = treelet::scene::mesh::load(path)?.len();
            Ok(())
        })?;
        let row = LoadRow { file: path.display().to_string(), bytes, triangles, cat_s, read_s, load_s };
        println!(
            "{:<40} {:>7.1} MB {:>10} triangles  cat {:>6.0} MB/s  read {:>6.0} MB/s  load {:>6.0} MB/s ({:>3.0}% of cat, {:>3.0}% of read)  {:>6.3} s",
            row.file,
            bytes as f64 / 1e6,
            triangles,
            row.cat_mb_s(),
            row.read_mb_s(),
            row.load_mb_s(),
            100.0 * row.load_mb_s() / row.cat_mb_s(),
            100.0 * row.load_mb_s() / row.read_mb_s(),
            load_s
        );
        rows.push(row);
    }
    Ok(rows)
}

/// Median seconds of `repeats` runs of `f` (the median of `measure`).
fn median(repeats: usize, mut f: impl FnMut() -> Result<()>) -> Result<f64> {
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        f()?;
        times.push(start.elapsed().as_secs_f64());
    }
    Ok(super::measure::median(times))
}
