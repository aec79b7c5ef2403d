//! Scene names as the command line takes them: `cornell`, `random:N[:SEED]`,
//! `terrain:N`, `city:N[:SEED]`, a JSON scene file, a glTF 2.0 scene, or an
//! `.obj` / `.ply` mesh.
use anyhow::{bail, Context as _, Result};

use super::city::city;
use super::instanced::InstancedScene;
use super::model::{cornell, mesh_scene, random_scene, terrain, CameraSpec, Scene};
use super::primitives::MAX_PRIMITIVES;
use crate::runtime::memory;
use treelet_core::geometry::buffers::{Material, Sphere};
use treelet_core::geometry::triangle::Triangle;

impl Scene {
    /// Parses a scene: `cornell`, a built-in scene file by name
    /// ([`super::builtin::BUILT_IN`]: `room_disk`, ...), `random:N[:SEED]`, `terrain:N`,
    /// `city:N[:SEED]`, or a path to a JSON scene file, a glTF scene or an
    /// `.obj` / `.ply` mesh (either also as `.xz`).
    pub fn from_spec(spec: &str) -> Result<Scene> {
        if spec == "cornell" {
            return Ok(cornell());
        }
        if let Some(scene) = super::builtin::scene(spec) {
            return scene;
        }
        if spec.ends_with(".json") {
            return super::file::load(std::path::Path::new(spec));
        }
        let lower = spec.to_ascii_lowercase();
        if lower.ends_with(".gltf") || lower.ends_with(".glb") {
            return super::gltf::load(std::path::Path::new(spec));
        }
        if super::mesh::mesh_kind(std::path::Path::new(spec)).is_some() {
            let triangles = super::mesh::load(std::path::Path::new(spec))?;
            // A mesh alone is scaled to fit the room: one too small for that
            // scale in f32 became NaN coordinates, blamed on the file's triangle 0.
            let size = triangles.iter().fold(treelet_core::Aabb::EMPTY, |b, t| b.union(&t.aabb())).extent().max_element();
            if size > 0.0 && !(60.0 / size).is_finite() {
                bail!("{spec}: the mesh spans {size:e} units, too small to scale into the room (scale it up in the file, or place it with a scene file)");
            }
            return Ok(mesh_scene(spec, &triangles));
        }
        let mut parts = spec.split(':');
        match parts.next() {
            Some("random") => {
                let (n, seed) = count_and_seed(spec, &mut parts, "random:N[:SEED]", "primitive")?;
                if parts.next().is_some() {
                    bail!("scene `{spec}`: expected random:N[:SEED]");
                }
                if n > MAX_PRIMITIVES as usize {
                    bail!("scene `{spec}`: {n} primitives, at most {} are supported", MAX_PRIMITIVES);
                }
                let bytes = n as u64 * (std::mem::size_of::<Sphere>() + std::mem::size_of::<Material>()) as u64;
                memory::check_fits(&format!("scene `{spec}`"), 2 * bytes, &format!("{n} spheres and their materials"))?;
                Ok(random_scene(spec, n, seed))
            }
            Some("terrain") => {
                let n = parts.next().with_context(|| format!("scene `{spec}`: expected terrain:N"))?;
                let n: usize = n.parse().with_context(|| format!("scene `{spec}`: `{n}` is not a triangle count"))?;
                if parts.next().is_some() || n == 0 {
                    bail!("scene `{spec}`: expected terrain:N with N > 0 triangles");
                }
                check_generated_mesh(spec, n)?;
                Ok(mesh_scene(spec, &terrain(n)))
            }
            Some("city") => {
                let (n, seed) = count_and_seed(spec, &mut parts, "city:N[:SEED]", "triangle")?;
                if parts.next().is_some() || n == 0 {
                    bail!("scene `{spec}`: expected city:N[:SEED] with N > 0 triangles");
                }
                check_generated_mesh(spec, n)?;
                Ok(mesh_scene(spec, &city(n, seed)))
            }
            _ => bail!(
                "unknown scene `{spec}`: expected cornell, random:N[:SEED], terrain:N, city:N[:SEED], a .json scene file, a .gltf/.glb scene or an .obj/.ply mesh (or .obj.xz/.ply.xz)"
            ),
        }
    }
}

/// The count and optional seed (1 if none) of a generated scene `form`
/// (`random:N[:SEED]`, `city:N[:SEED]`), from the parts after its name;
/// `unit` names what is counted.
fn count_and_seed<'a>(spec: &str, parts: &mut impl Iterator<Item = &'a str>, form: &str, unit: &str) -> Result<(usize, u64)> {
    let n = parts.next().with_context(|| format!("scene `{spec}`: expected {form}"))?;
    let n: usize = n.parse().with_context(|| format!("scene `{spec}`: `{n}` is not a {unit} count"))?;
    let seed = match parts.next() {
        Some(s) => s.parse().with_context(|| format!("scene `{spec}`: `{s}` is not a seed"))?,
        None => 1,
    };
    Ok((n, seed))
}

/// Refuses a generated mesh (`terrain:N`, `city:N`) of more triangles than
/// a build supports, or than the machine's memory holds.
fn check_generated_mesh(spec: &str, n: usize) -> Result<()> {
    if n > MAX_PRIMITIVES as usize {
        bail!("scene `{spec}`: {n} triangles, at most {} are supported", MAX_PRIMITIVES);
    }
    let bytes = n as u64 * (2 * std::mem::size_of::<Triangle>() + std::mem::size_of::<Material>()) as u64;
    memory::check_fits(&format!("scene `{spec}`"), 2 * bytes, &format!("{n} triangles and their materials"))
}

impl Scene {
    /// smallpt's lens at `eye`, looking at `target`, both in the coordinates
    /// of the scene `spec` names: an `.obj` or `.ply` mesh is moved into
    /// smallpt's room when loaded ([`super::model::mesh_placement`]), and the
    /// camera with it (the mesh is read again for its bounds: a command's
    /// set-up, not a hot path); other scenes keep their coordinates.
    pub fn camera_in_file(spec: &str, eye: [f32; 3], target: [f32; 3]) -> Result<CameraSpec> {
        if super::mesh::mesh_kind(std::path::Path::new(spec)).is_some() {
            let place = super::model::mesh_placement(&super::mesh::load(std::path::Path::new(spec))?);
            return CameraSpec::looking_at(place(eye), place(target));
        }
        CameraSpec::looking_at(eye, target)
    }

    /// [`Scene::from_spec`] for `render`: a glTF or scene file keeps the
    /// copies of meshes it places more than once placed
    /// ([`InstancedScene::for_render`]); every other scene as `from_spec`
    /// gives it.
    pub fn for_render(spec: &str) -> Result<Scene> {
        let lower = spec.to_ascii_lowercase();
        if [".json", ".gltf", ".glb"].iter().any(|e| lower.ends_with(e)) {
            InstancedScene::load(std::path::Path::new(spec))?.for_render()
        } else {
            Scene::from_spec(spec)
        }
    }
}

impl Scene {
    /// A glTF scene seen from the file's camera `camera` (its index in the
    /// file's `cameras` list: `render --camera N`), flattened or as
    /// `render` traces it ([`Scene::for_render`]); other scenes have no
    /// cameras to choose from, and are refused.
    pub fn with_gltf_camera(spec: &str, camera: usize, flatten: bool) -> Result<Scene> {
        let lower = spec.to_ascii_lowercase();
        if !(lower.ends_with(".gltf") || lower.ends_with(".glb")) {
            bail!("--camera {camera}: only glTF scenes (.gltf, .glb) have cameras to choose from; `{spec}` is not one");
        }
        let scene = super::gltf::load_instanced_with_camera(std::path::Path::new(spec), Some(camera))?;
        if flatten { scene.flatten() } else { scene.for_render() }
    }
}

impl InstancedScene {
    /// Loads a glTF 2.0 file or a JSON scene file with its instances kept
    /// (see [`super::instanced`]).
    pub fn load(path: &std::path::Path) -> Result<InstancedScene> {
        let lower = path.to_string_lossy().to_ascii_lowercase();
        if lower.ends_with(".gltf") || lower.ends_with(".glb") {
            super::gltf::load_instanced(path)
        } else if lower.ends_with(".json") {
            super::file::load_instanced(path)
        } else {
            bail!("{}: expected a .gltf/.glb or a .json scene file", path.display())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use treelet_core::geometry::prims::{Origin, Prims};
    use treelet_core::trace::classic::closest_hit_linear;

    /// A camera given in a mesh file's coordinates looks at what it looked at
    /// there once the loader has moved the mesh: its centre ray hits the
    /// triangle it was aimed at, for each of a row of small triangles far
    /// from the room.
    #[test]
    fn a_camera_in_file_coordinates_hits_what_it_aimed_at() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("row.obj");
        let mut obj = String::new();
        let corner = |k: usize| Vec3::new(1000.0 + 40.0 * k as f32, -300.0 + 7.0 * k as f32, 500.0);
        for k in 0..10 {
            let c = corner(k);
            for v in [c, c + Vec3::new(10.0, 0.0, 0.0), c + Vec3::new(0.0, 10.0, 0.0)] {
                obj += &format!("v {} {} {}\n", v.x, v.y, v.z);
            }
            obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
        }
        std::fs::write(&path, obj).unwrap();
        let spec = path.to_str().unwrap();
        let scene = Scene::from_spec(spec).unwrap();
        let prims = Prims::new(&[], &scene.triangles);
        for k in 0..10 {
            let aim = corner(k) + Vec3::new(3.0, 3.0, 0.0);
            let eye = aim - Vec3::new(5.0, -2.0, 400.0);
            let camera = Scene::camera_in_file(spec, eye.to_array(), aim.to_array()).unwrap();
            let (o, d) = (Vec3::from_array(camera.origin), Vec3::from_array(camera.direction).normalize());
            let hit = closest_hit_linear(o, d, Origin::NONE, &prims);
            assert!(hit.is_hit() && hit.prim == k as u32, "aimed at triangle {k}, hit {} at {}", hit.prim, hit.t);
        }
        // Refused: a camera that looks nowhere.
        assert!(Scene::camera_in_file(spec, [1.0; 3], [1.0; 3]).is_err());
    }
}
