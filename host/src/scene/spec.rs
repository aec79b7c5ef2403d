//! Scene names as the command line takes them: `cornell`, `random:N[:SEED]`,
//! `terrain:N`, `city:N[:SEED]`, a JSON scene file, a glTF 2.0 scene, or an
//! `.obj` / `.ply` mesh.
use anyhow::{bail, Context as _, Result};

use super::city::city;
use super::instanced::InstancedScene;
use super::model::{cornell, mesh_alone, mesh_scene, random_scene, terrain, Scene};
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
            // In its own coordinates, under a sky: nothing is scaled.
            return mesh_alone(spec, super::mesh::load(std::path::Path::new(spec))?);
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
    use crate::scene::model::CameraSpec;

    /// A mesh file keeps its coordinates: a camera given in them looks at
    /// what it aimed at (its centre ray hits the triangle it was aimed at,
    /// for each of a row of small triangles far from the origin), and the
    /// mesh alone is seen from above under the default sky.
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
            let camera = CameraSpec::looking_at(eye.to_array(), aim.to_array()).unwrap();
            let (o, d) = (Vec3::from_array(camera.origin), Vec3::from_array(camera.direction).normalize());
            let hit = closest_hit_linear(o, d, Origin::NONE, &prims);
            assert!(hit.is_hit() && hit.prim == k as u32, "aimed at triangle {k}, hit {} at {}", hit.prim, hit.t);
        }
        // Refused: a camera that looks nowhere.
        assert!(CameraSpec::looking_at([1.0; 3], [1.0; 3]).is_err());
        assert_eq!((scene.room, scene.spheres.len(), scene.environment), (0, 0, crate::scene::model::DEFAULT_SKY));
        assert_eq!(scene.triangles[3].v0, corner(3).to_array(), "the file's coordinates");
        // The framing sees the mesh: the centre ray meets the row's box.
        let (o, d) = (Vec3::from_array(scene.camera.origin), Vec3::from_array(scene.camera.direction));
        let (lo, hi) = (corner(0), corner(9) + Vec3::new(10.0, 10.0, 0.0));
        let at = o + d * ((lo.z - o.z) / d.z);
        assert!(at.x >= lo.x && at.x <= hi.x && at.y >= lo.y - 1.0 && at.y <= hi.y + 1.0, "the centre ray meets the mesh's plane at {at}");
    }
}
