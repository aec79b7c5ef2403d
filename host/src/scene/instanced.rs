//! Scenes whose meshes are placed by reference: each mesh stored once, in
//! its own space, and placed by any number of instances (a glTF file's
//! nodes, a scene file's `instances`), read by [`InstancedScene::load`].
//!
//! The engine API traces such a scene as it is
//! (`treelet::InstancedTracer::build_scene`: a tree per mesh, a top-level
//! tree over the instances). `render`, `build` and `bench` take it
//! flattened into one set of world-space triangles ([`InstancedScene::flatten`]:
//! the renderer does not trace instances yet), and refuse, naming the
//! counts, a flattening past the primitive limit or the memory the machine
//! has: a thousand copies of a million-triangle mesh are 36 GB flattened.
use anyhow::{bail, Result};
use glam::{Affine3A, Vec3};
use treelet_core::geometry::buffers::Material;
use treelet_core::geometry::triangle::Triangle;

use super::model::Scene;
use super::primitives::{Primitives, MAX_PRIMITIVES};
use crate::runtime::memory;

/// One mesh, in its own space: triangles and a material each.
#[derive(Clone, Debug)]
pub struct SceneMesh {
    /// Where it came from (the glTF mesh's name or index, the file's path).
    pub name: String,
    pub triangles: Vec<Triangle>,
    pub materials: Vec<Material>,
}

/// A placed copy of a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneInstance {
    /// Index into [`InstancedScene::meshes`].
    pub mesh: u32,
    /// Mesh space to world space (affine).
    pub transform: Affine3A,
    /// Every triangle of this copy in this material instead of the mesh's.
    pub material: Option<Material>,
}

impl SceneInstance {
    /// The transform as three rows of `[x, y, z, translation]` (what
    /// `treelet::Instance` takes).
    pub fn rows(&self) -> [[f32; 4]; 3] {
        let m = &self.transform.matrix3;
        let t = self.transform.translation;
        [0, 1, 2].map(|r| [m.x_axis[r], m.y_axis[r], m.z_axis[r], t[r]])
    }
}

/// A scene with its meshes placed by reference. `loose` holds everything
/// not instanced (spheres, disks and parallelograms of a scene file, in
/// world space), the camera and the name; its triangles come after the
/// instances' when flattened, as the primitives of a scene file always
/// have (meshes, then disks, then parallelograms).
#[derive(Clone, Debug)]
pub struct InstancedScene {
    pub loose: Scene,
    pub meshes: Vec<SceneMesh>,
    pub instances: Vec<SceneInstance>,
}

impl InstancedScene {
    /// Triangles once flattened: the instances' and the loose ones.
    pub fn flattened_triangles(&self) -> u64 {
        let placed: u64 = self.instances.iter().map(|i| self.meshes[i.mesh as usize].triangles.len() as u64).sum();
        placed + self.loose.triangles.len() as u64
    }

    /// Every instance's triangles placed in world space (the instances in
    /// order, each mesh's triangles in order), then the loose triangles;
    /// refused by name past [`MAX_PRIMITIVES`] or the memory available.
    pub fn flatten(self) -> Result<Scene> {
        let name = self.loose.name.clone();
        let total = self.flattened_triangles() + self.loose.spheres.len() as u64;
        let plural = |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        let what = format!(
            "{name}: {} of {}, flattened into {} triangles (the renderer and the builders take instances flattened)",
            plural(self.instances.len(), "instance", "instances"),
            plural(self.meshes.len(), "mesh", "meshes"),
            self.flattened_triangles()
        );
        if total > MAX_PRIMITIVES as u64 {
            bail!("{what}: at most {MAX_PRIMITIVES} primitives are supported");
        }
        let per = (std::mem::size_of::<Triangle>() + std::mem::size_of::<Material>()) as u64;
        memory::check_fits(&name, 2 * per * total, &what)?;
        if self.instances.len() > self.meshes.len() {
            eprintln!("note: {what}");
        }
        let InstancedScene { mut loose, meshes, instances } = self;
        let mut triangles = Vec::with_capacity(total as usize);
        let mut materials = Vec::with_capacity(total as usize);
        materials.extend_from_slice(&loose.materials[..loose.spheres.len()]);
        for instance in &instances {
            let mesh = &meshes[instance.mesh as usize];
            let place = |v: [f32; 3]| instance.transform.transform_point3(Vec3::from(v)).to_array();
            triangles.extend(mesh.triangles.iter().map(|t| Triangle::new(place(t.v0), place(t.v1), place(t.v2))));
            match instance.material {
                Some(m) => materials.extend(std::iter::repeat_n(m, mesh.triangles.len())),
                None => materials.extend_from_slice(&mesh.materials),
            }
        }
        Primitives::triangles(&triangles)
            .check()
            .map_err(|e| anyhow::anyhow!("{name}: after the mesh transforms: {e:#}"))?;
        materials.extend_from_slice(&loose.materials[loose.spheres.len()..]);
        triangles.append(&mut loose.triangles);
        loose.triangles = triangles;
        loose.materials = materials;
        Ok(loose)
    }

    /// A scene of loose primitives alone (no meshes to place).
    pub fn from_loose(loose: Scene) -> InstancedScene {
        InstancedScene { loose, meshes: Vec::new(), instances: Vec::new() }
    }
}
