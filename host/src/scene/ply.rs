//! Writing a scene's triangles as a binary little-endian PLY (`treelet
//! export`), or as an OBJ where the path ends in `.obj` (to time the OBJ
//! reader: `treelet bench load`): three vertices per triangle, unshared, and faces of a `uchar`
//! count and `int` indices, the form [`super::mesh`] reads back and the
//! peers (`peers/mitsuba/rays.py`, OptiX through Mitsuba 3) take, so that a
//! generated scene (`city:N`) or a glTF file can be timed by other tracers.
//! Parallelograms become two triangles; spheres and disks have no
//! triangles and are left out (the summary says how many).
use std::io::Write as _;
use std::path::Path;

use anyhow::{bail, Context as _, Result};
use treelet_core::geometry::triangle::{SHAPE_DISK, SHAPE_PARALLELOGRAM, SHAPE_TRIANGLE};

use super::model::Scene;

/// What [`write()`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    pub triangles: usize,
    /// Smallest and largest triangle area (f64 from the f32 corners).
    pub min_area: f64,
    pub max_area: f64,
    /// What the file leaves out, as "N spheres" and the like.
    pub left_out: Vec<String>,
}

/// Writes `scene`'s triangles to `path` (whole or not at all: a temporary
/// file beside it, renamed over it).
pub fn write(scene: &Scene, path: &Path) -> Result<Written> {
    let mut triangles: Vec<[[f32; 3]; 3]> = Vec::with_capacity(scene.triangles.len());
    let mut disks = 0;
    for t in &scene.triangles {
        match t.shape {
            SHAPE_TRIANGLE => triangles.push([t.v0, t.v1, t.v2]),
            // Corner v0, edges v1 - v0 and v2 - v0.
            SHAPE_PARALLELOGRAM => {
                let far = [0, 1, 2].map(|k| t.v1[k] + t.v2[k] - t.v0[k]);
                triangles.extend([[t.v0, t.v1, far], [t.v0, far, t.v2]]);
            }
            SHAPE_DISK => disks += 1,
            other => bail!("scene {}: unknown shape tag {other:#x}", scene.name),
        }
    }
    let objects = scene.spheres.len() - scene.room;
    let left_out: Vec<String> = [(objects, "spheres"), (scene.room, "spheres of the room"), (disks, "disks")]
        .iter()
        .filter(|(count, _)| *count > 0)
        .map(|(count, what)| format!("{count} {what}"))
        .collect();
    if triangles.is_empty() {
        bail!("scene {}: no triangles to write", scene.name);
    }
    // Indices are PLY `int`s.
    if triangles.len() > i32::MAX as usize / 3 {
        bail!("scene {}: {} triangles, at most {} fit int vertex indices", scene.name, triangles.len(), i32::MAX / 3);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = tempfile::NamedTempFile::new_in(dir).with_context(|| format!("cannot write in {}", dir.display()))?;
    let obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let body = if obj { write_obj_body(tmp.as_file(), &scene.name, &triangles) } else { write_body(tmp.as_file(), &scene.name, &triangles) };
    body.with_context(|| format!("cannot write {}", path.display()))?;
    tmp.persist(path).with_context(|| format!("cannot write {}", path.display()))?;
    let (min_area, max_area) = triangles.iter().map(area).fold((f64::MAX, 0.0f64), |(lo, hi), a| (lo.min(a), hi.max(a)));
    Ok(Written { triangles: triangles.len(), min_area, max_area, left_out })
}

/// A triangle's area, in f64 from its f32 corners.
fn area([a, b, c]: &[[f32; 3]; 3]) -> f64 {
    let edge = |p: &[f32; 3], q: &[f32; 3]| [0, 1, 2].map(|k| f64::from(q[k]) - f64::from(p[k]));
    let (u, v) = (edge(a, b), edge(a, c));
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0
}

fn write_body(file: &std::fs::File, name: &str, triangles: &[[[f32; 3]; 3]]) -> Result<()> {
    let mut w = std::io::BufWriter::new(file);
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment {}\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        // One header line: no control characters from the name.
        name.replace(char::is_control, " "),
        3 * triangles.len(),
        triangles.len()
    )?;
    for x in triangles.iter().flatten().flatten() {
        w.write_all(&x.to_le_bytes())?;
    }
    for i in 0..triangles.len() as i32 {
        w.write_all(&[3])?;
        for k in 0..3 {
            w.write_all(&(3 * i + k).to_le_bytes())?;
        }
    }
    w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
    Ok(())
}

/// The same as OBJ text: `v` lines in f32's shortest exact form (they
/// read back bit for bit), then `f` lines.
fn write_obj_body(file: &std::fs::File, name: &str, triangles: &[[[f32; 3]; 3]]) -> Result<()> {
    let mut w = std::io::BufWriter::new(file);
    writeln!(w, "# {}", name.replace(char::is_control, " "))?;
    for [x, y, z] in triangles.iter().flatten() {
        writeln!(w, "v {x} {y} {z}")?;
    }
    for i in 0..triangles.len() {
        writeln!(w, "f {} {} {}", 3 * i + 1, 3 * i + 2, 3 * i + 3)?;
    }
    w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_scene_reads_back_as_the_same_triangles() {
        let scene = Scene::from_spec("city:2000:3").unwrap();
        let dir = tempfile::tempdir().unwrap();
        for name in ["city.ply", "city.obj"] {
            let path = dir.path().join(name);
            let w = write(&scene, &path).unwrap();
            assert_eq!(w.triangles, scene.triangles.len());
            let back = super::super::mesh::load(&path).unwrap();
            assert_eq!(back.len(), scene.triangles.len());
            for (a, b) in back.iter().zip(&scene.triangles) {
                assert_eq!((a.v0, a.v1, a.v2), (b.v0, b.v1, b.v2), "{name}");
            }
        }
        assert!(write(&Scene::from_spec("random:10").unwrap(), &dir.path().join("none.ply")).is_err());
    }
}
