//! `treelet bench rays --suite`: rays per second on the real-scene suite,
//! from outside (the mesh-only framing) and inside (each scene's camera),
//! in one table, with OptiX's column beside when asked (`--with-optix`:
//! `peers/mitsuba/rays.py`, OptiX through Mitsuba 3, given the same mesh
//! and camera).
//!
//! The suite: the interiors of `scenes/real/` (compressed PLY, cameras in
//! `cameras.json`, in each file's coordinates) and the generated city
//! (`treelet::scene::city`) at 300k and 1M triangles, seen from above and
//! from a street.
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context as _, Result};
use serde::Serialize;
use treelet_core::geometry::triangle::Triangle;

use super::measure::{bench_rays, RaysPlan, RaysRow};
use treelet::bvh::tree::Accel;
use treelet::runtime::backend::Backend;
use treelet::scene::model::{mesh_placement, mesh_scene, CameraSpec, Scene};

/// The city's street camera: at eye height in the middle of the street
/// along x = 0, looking down it (`treelet::scene::city`'s streets run between
/// its 50-unit blocks).
const CITY_STREET: ([f32; 3], [f32; 3]) = ([0.0, 1.7, -85.0], [0.0, 1.7, 85.0]);
/// The generated scenes of the suite (triangles).
const CITY_SIZES: [usize; 2] = [300_000, 1_000_000];

/// One scene of the suite: its triangles in their file's coordinates, the
/// inside camera there, and the mesh OptiX's peer reads.
struct Entry {
    name: String,
    triangles: Vec<Triangle>,
    inside: Option<([f32; 3], [f32; 3])>,
    /// The file, or `None` for a generated scene (written to a temporary
    /// PLY for the peer).
    file: Option<PathBuf>,
}

/// The folder of the real scenes: `dir`, or `scenes/real` of this
/// repository (where the program was built from), or of the working folder.
fn real_scenes_dir(dir: Option<&Path>) -> Result<PathBuf> {
    if let Some(d) = dir {
        return Ok(d.to_path_buf());
    }
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/real");
    let candidates = [built, PathBuf::from("scenes/real")];
    candidates.iter().find(|d| d.join("cameras.json").is_file()).cloned().with_context(|| {
        format!("the real-scene suite: no cameras.json in {} (pass --suite-dir)", candidates.map(|d| d.display().to_string()).join(" or "))
    })
}

/// The scenes of `dir` (`NAME.ply.xz`, sorted) and their inside cameras
/// (`cameras.json`: `NAME: {eye, look_at}` in the file's coordinates).
fn listing(dir: &Path) -> Result<(Vec<String>, std::collections::HashMap<String, ([f32; 3], [f32; 3])>)> {
    let cameras_path = dir.join("cameras.json");
    let cameras: serde_json::Value = serde_json::from_str(&treelet::internals::input::read_text(&cameras_path, "camera list")?)
        .with_context(|| format!("{}: not valid JSON", cameras_path.display()))?;
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot list it", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().to_string()))
        .filter_map(|f| f.strip_suffix(".ply.xz").map(str::to_string))
        .collect();
    names.sort();
    if names.is_empty() {
        bail!("{}: no .ply.xz scenes", dir.display());
    }
    let mut out = std::collections::HashMap::new();
    for name in &names {
        let point = |key: &str| -> Option<[f32; 3]> {
            let v = cameras.get(name)?.get(key)?.as_array()?;
            let p: Vec<f32> = v.iter().filter_map(|x| x.as_f64().map(|x| x as f32)).collect();
            (p.len() == 3).then(|| [p[0], p[1], p[2]])
        };
        match (point("eye"), point("look_at")) {
            (Some(e), Some(t)) => out.insert(name.clone(), (e, t)),
            _ => bail!("{}: no camera (eye, look_at: three numbers each) for {name}", cameras_path.display()),
        };
    }
    Ok((names, out))
}

fn entries(dir: Option<&Path>) -> Result<Vec<Entry>> {
    let dir = real_scenes_dir(dir)?;
    let (names, cameras) = listing(&dir)?;
    let mut out = Vec::new();
    for name in names {
        let file = dir.join(format!("{name}.ply.xz"));
        eprintln!("loading {}", file.display());
        let triangles = treelet::scene::mesh::load(&file)?;
        out.push(Entry { inside: Some(cameras[&name]), name, triangles, file: Some(file) });
    }
    for n in CITY_SIZES {
        out.push(Entry { name: format!("city:{n}"), triangles: treelet::scene::city::city(n, 1), inside: Some(CITY_STREET), file: None });
    }
    Ok(out)
}

/// OptiX's figures for one scene and view (`peers/mitsuba/rays.py`'s line).
#[derive(Clone, Debug, Serialize)]
pub(crate) struct PeerRow {
    pub(crate) build_ms: f64,
    pub(crate) primary_mrays_per_s: f64,
    pub(crate) diffuse_mrays_per_s: f64,
}

/// Runs the peer on `mesh` (from `camera`, in the mesh's coordinates, or
/// the mesh-only framing).
fn optix(script: &Path, mesh: &Path, size: (u32, u32), repeats: usize, camera: Option<([f32; 3], [f32; 3])>) -> Result<PeerRow> {
    let python = std::env::var("TREELET_PYTHON").unwrap_or_else(|_| "python3".into());
    let mut cmd = Command::new(&python);
    cmd.arg(script).arg(mesh).arg(size.0.to_string()).arg(size.1.to_string()).arg(repeats.to_string());
    if let Some((e, t)) = camera {
        cmd.arg(e.iter().chain(&t).map(|x| x.to_string()).collect::<Vec<_>>().join(","));
    }
    let out = cmd.output().with_context(|| format!("cannot run {python} {}", script.display()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().rev().find(|l| l.trim_start().starts_with('{'));
    let Some(line) = line.filter(|_| out.status.success()) else {
        let err = String::from_utf8_lossy(&out.stderr);
        bail!("the OptiX peer on {} failed ({}): {}", mesh.display(), out.status, err.lines().rev().take(3).collect::<Vec<_>>().join(" | "));
    };
    let v: serde_json::Value = serde_json::from_str(line).with_context(|| format!("the OptiX peer's line `{line}`"))?;
    let num = |k: &str| v.get(k).and_then(|x| x.as_f64()).with_context(|| format!("the OptiX peer's line has no `{k}`"));
    Ok(PeerRow { build_ms: num("build_wall_ms_median")?, primary_mrays_per_s: num("primary_mrays_s")?, diffuse_mrays_per_s: num("diffuse_mrays_s")? })
}

/// The peer script: `peers/mitsuba/rays.py` of this repository or of the
/// working folder.
fn peer_script() -> Result<PathBuf> {
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join("../peers/mitsuba/rays.py");
    [built, PathBuf::from("peers/mitsuba/rays.py")].into_iter().find(|p| p.is_file()).context("--with-optix: peers/mitsuba/rays.py not found")
}

/// One row of the suite's table: a tree and layout on one scene and view.
#[derive(Serialize)]
pub(crate) struct SuiteRow {
    pub(crate) scene: String,
    pub(crate) view: &'static str,
    pub(crate) triangles: usize,
    pub(crate) treelet: RaysRow,
    pub(crate) optix: Option<PeerRow>,
}

/// Runs the suite: every scene, outside and inside, each accel of
/// `accels` in each layout of `plan`; OptiX beside when `with_optix`.
pub(crate) fn run<B: Backend>(
    b: &mut B,
    dir: Option<&Path>,
    accels: &[Accel],
    plan: &RaysPlan,
    size: (u32, u32),
    repeats: usize,
    with_optix: bool,
) -> Result<Vec<SuiteRow>> {
    let script = with_optix.then(peer_script).transpose()?;
    let scratch = tempfile::tempdir().context("a temporary folder for the peer's meshes")?;
    let mut rows = Vec::new();
    for e in entries(dir)? {
        let place = mesh_placement(&e.triangles);
        let base = mesh_scene(&e.name, &e.triangles).mesh_only()?;
        // The peer reads the file, or the generated mesh as placed (what
        // `treelet export` writes), with the camera placed the same way.
        let (peer_mesh, placed) = match &e.file {
            Some(f) => (f.clone(), false),
            None => {
                let p = scratch.path().join(format!("{}.ply", e.name.replace(':', "_")));
                treelet::scene::ply::write(&base, &p)?;
                (p, true)
            }
        };
        for view in ["outside", "inside"] {
            let camera = match view {
                "inside" => match e.inside {
                    Some(c) => Some(c),
                    None => continue,
                },
                _ => None,
            };
            let mut scene: Scene = base.clone();
            if let Some((eye, target)) = camera {
                scene.camera = CameraSpec::looking_at(place(eye), place(target))?;
            }
            eprintln!("{} {view}: {} triangles", e.name, e.triangles.len());
            let peer = match &script {
                Some(s) => {
                    let cam = camera.map(|(eye, t)| if placed { (place(eye), place(t)) } else { (eye, t) });
                    Some(optix(s, &peer_mesh, size, repeats, cam)?)
                }
                None => None,
            };
            for &a in accels {
                for r in bench_rays(b, &scene, a, plan, size, repeats)? {
                    rows.push(SuiteRow { scene: e.name.clone(), view, triangles: e.triangles.len(), treelet: r, optix: peer.clone() });
                }
            }
        }
    }
    Ok(rows)
}

/// Prints the suite's table: Treelet's rates and, with the peer, OptiX's
/// and the ratios.
pub(crate) fn print(rows: &[SuiteRow]) {
    println!(
        "{:>16}{:>8}{:>9}{:>7}{:>7}{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}{:>8}{:>8}",
        "scene", "view", "tris", "accel", "layout", "build ms", "primary", "diffuse", "OptiX ms", "OptiX pri", "OptiX dif", "x pri", "x dif"
    );
    for r in rows {
        let t = &r.treelet;
        let (om, op, od, xp, xd) = match &r.optix {
            Some(o) => (
                format!("{:.2}", o.build_ms),
                format!("{:.0}", o.primary_mrays_per_s),
                format!("{:.0}", o.diffuse_mrays_per_s),
                format!("{:.2}", t.primary_mrays_per_s / o.primary_mrays_per_s),
                format!("{:.2}", t.diffuse_mrays_per_s / o.diffuse_mrays_per_s),
            ),
            None => ("-".into(), "-".into(), "-".into(), "-".into(), "-".into()),
        };
        println!(
            "{:>16}{:>8}{:>9}{:>7}{:>7}{:>10.2}{:>10.0}{:>10.0}{:>10}{:>10}{:>10}{:>8}{:>8}",
            r.scene,
            r.view,
            r.triangles,
            format!("{:?}", t.accel).to_lowercase(),
            if t.stack == "private" { t.layout.name().to_string() } else { format!("{}/wg", t.layout.name()) },
            t.build_ms + t.layout_ms,
            t.primary_mrays_per_s,
            t.diffuse_mrays_per_s,
            om,
            op,
            od,
            xp,
            xd
        );
    }
    println!("rates in M rays/s; build ms: the tree and its layout (GPU timestamps); OptiX's build is the wall time of making its scene");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every scene of scenes/real has its inside camera, with the eye inside
    /// the scene's bounds (a camera outside would time the outside view
    /// twice).
    #[test]
    fn every_real_scene_has_a_camera_inside_it() {
        let dir = real_scenes_dir(None).unwrap();
        let (names, cameras) = listing(&dir).unwrap();
        assert!(names.len() >= 4, "{names:?}");
        for name in &names {
            let (eye, _) = cameras[name];
            let tris = treelet::scene::mesh::load(&dir.join(format!("{name}.ply.xz"))).unwrap();
            let b = tris.iter().fold(treelet_core::Aabb::EMPTY, |b, t| b.union(&t.aabb()));
            let e = glam::Vec3::from_array(eye);
            assert!(e.cmpge(b.lo()).all() && e.cmple(b.hi()).all(), "{name}: eye {eye:?} outside {b:?}");
        }
    }

    /// The city's street camera stands in the open and looks down the
    /// street: no triangle's box comes within a metre of the eye, and the
    /// ray through the middle of the picture runs at least 50 metres before
    /// it meets anything (the scan, not a tree).
    #[test]
    fn the_city_street_camera_stands_in_the_street() {
        use treelet_core::geometry::triangle::{ray_triangle, WatertightRay};
        let (eye, target) = (glam::Vec3::from_array(CITY_STREET.0), glam::Vec3::from_array(CITY_STREET.1));
        let tris = treelet::scene::city::city(300_000, 1);
        for t in &tris {
            let b = t.aabb();
            let near = b.lo() - glam::Vec3::ONE;
            let far = b.hi() + glam::Vec3::ONE;
            assert!(!(eye.cmpge(near).all() && eye.cmple(far).all()), "a triangle within a metre of the eye: {t:?}");
        }
        let d = (target - eye).normalize();
        let ray = WatertightRay::new(eye, d);
        let nearest = tris.iter().map(|t| ray_triangle(&ray, t, f32::MAX)).fold(f32::MAX, f32::min);
        assert!(nearest >= 50.0, "the view down the street is blocked {nearest} m ahead");
    }
}
