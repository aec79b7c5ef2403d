//! Scenes whose meshes are placed by reference: each mesh stored once, in
//! its own space, and placed by any number of instances (a glTF file's
//! nodes, a scene file's `instances`), read by [`InstancedScene::load`].
//!
//! The engine API traces such a scene as it is
//! (`treelet::InstancedTracer::build_scene`: a tree per mesh, a top-level
//! tree over the instances). `render` keeps the copies of a mesh placed
//! more than once placed ([`InstancedScene::for_render`]); `build` and
//! `bench` take the scene flattened into one set of world-space triangles
//! ([`InstancedScene::flatten`]), and refuse, naming the counts, a
//! flattening past the primitive limit or the memory the machine has: a
//! thousand copies of a million-triangle mesh are 36 GB flattened.

use anyhow::{bail, Result};
use glam::Vec3;
use treelet_core::geometry::buffers::Material;
use treelet_core::geometry::triangle::Triangle;

use super::model::Scene;
use super::instances::SceneInstances;
pub use super::instances::{SceneInstance, SceneMesh};
use super::primitives::{Primitives, MAX_PRIMITIVES};
use crate::runtime::memory;

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
    /// What `build` and `bench` take.
    pub fn flatten(self) -> Result<Scene> {
        let InstancedScene { loose, meshes, instances } = self;
        flatten_into(loose, &meshes, &instances, "`build` and `bench` take instances flattened")
    }

    /// The scene as `render` traces it: where a mesh is placed more than
    /// once, the copies stay placed ([`Scene::instances`], traced through
    /// their meshes' own trees: `treelet_core::trace::with_instances`), but for
    /// copies that emit light, flattened among the scene's own triangles
    /// (the light table samples emitters one by one). Without a mesh
    /// placed twice, flattened as [`Self::flatten`] does.
    pub fn for_render(self) -> Result<Scene> {
        let InstancedScene { loose, meshes, instances } = self;
        let repeated = instances.len() > meshes.len();
        let (lit, kept): (Vec<_>, Vec<_>) = instances.into_iter().partition(|i| !repeated || SceneInstances::emits(&meshes, i));
        if kept.is_empty() {
            return flatten_into(loose, &meshes, &lit, "no mesh is instanced more than once");
        }
        let name = loose.name.clone();
        let own = flatten_into(loose, &meshes, &lit, "the lamps among them, flattened")?;
        let copies = SceneInstances { meshes, instances: kept };
        let placed = copies.triangles();
        let numbered = own.spheres.len() as u64 + own.triangles.len() as u64 + placed;
        if numbered >= u32::MAX as u64 {
            bail!(
                "{name}: {} instances place {placed} triangles beside the scene's own {}: the renderer numbers primitives in 32 bits (at most {})",
                copies.instances.len(),
                own.spheres.len() + own.triangles.len(),
                u32::MAX - 1
            );
        }
        eprintln!(
            "note: {name}: {} instances of {} ({placed} triangles, traced through each mesh's own tree{})",
            copies.instances.len(),
            plural(copies.meshes.len(), "mesh", "meshes"),
            if lit.is_empty() { String::new() } else { format!("; {} that emit light flattened", lit.len()) }
        );
        Ok(Scene { instances: Some(std::sync::Arc::new(copies)), ..own })
    }

    /// A scene of loose primitives alone (no meshes to place).
    pub fn from_loose(loose: Scene) -> InstancedScene {
        InstancedScene { loose, meshes: Vec::new(), instances: Vec::new() }
    }
}

/// `instances`' triangles placed in world space (in order, each mesh's
/// triangles in order), then `loose`'s own; refused by name past
/// [`MAX_PRIMITIVES`] or the memory available. A note says so where a mesh
/// is placed more than once (`why`: who takes them flattened).
fn flatten_into(mut loose: Scene, meshes: &[SceneMesh], instances: &[SceneInstance], why: &str) -> Result<Scene> {
    let name = loose.name.clone();
    let placed: u64 = instances.iter().map(|i| meshes[i.mesh as usize].triangles.len() as u64).sum();
    let flattened = placed + loose.triangles.len() as u64;
    let total = flattened + loose.spheres.len() as u64;
    let what = format!(
        "{name}: {} of {}, flattened into {flattened} triangles ({why})",
        plural(instances.len(), "instance", "instances"),
        plural(meshes.len(), "mesh", "meshes"),
    );
    if total > MAX_PRIMITIVES as u64 {
        bail!("{what}: at most {MAX_PRIMITIVES} primitives are supported");
    }
    let per = (std::mem::size_of::<Triangle>() + std::mem::size_of::<Material>()) as u64;
    memory::check_fits(&name, 2 * per * total, &what)?;
    if instances.len() > meshes.len() {
        eprintln!("note: {what}");
    }
    let mut triangles = Vec::with_capacity(total as usize);
    let mut materials = Vec::with_capacity(total as usize);
    materials.extend_from_slice(&loose.materials[..loose.spheres.len()]);
    for instance in instances {
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

/// `n` and the word for one or many.
fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
