//! Instances of meshes, as scenes hold them: each mesh once, in its own
//! space ([`SceneMesh`]), and its instances (a transform each,
//! [`SceneInstance`]). [`crate::scene::instanced::InstancedScene`] holds them
//! as a glTF file or a scene file gives them; a [`Scene`](super::Scene)
//! that `render` traces may keep them ([`SceneInstances`] in
//! [`Scene::instances`](super::Scene::instances):
//! `treelet_core::trace::with_instances`) instead of flattened.
use glam::Affine3A;
use treelet_core::geometry::buffers::Material;
use treelet_core::geometry::triangle::Triangle;

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
    /// Index into the meshes it places ([`SceneInstances::meshes`],
    /// [`crate::scene::instanced::InstancedScene::meshes`]).
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

/// Copies of meshes a render traces through their meshes' own trees, beside
/// a scene's own primitives (see `treelet::render::prepared`): `instances`
/// place `meshes`. None of them emits light (lamps stay among the scene's
/// own primitives, where the light table samples them).
#[derive(Clone, Debug, Default)]
pub struct SceneInstances {
    pub meshes: Vec<SceneMesh>,
    pub instances: Vec<SceneInstance>,
}

impl SceneInstances {
    /// Triangles of every copy, as many as the scene has flattened.
    pub fn triangles(&self) -> u64 {
        self.instances.iter().map(|i| self.meshes[i.mesh as usize].triangles.len() as u64).sum()
    }

    /// Whether any triangle of `instance` emits light.
    pub fn emits(meshes: &[SceneMesh], instance: &SceneInstance) -> bool {
        let lit = |m: &Material| m.emission.iter().any(|&e| e > 0.0);
        match &instance.material {
            Some(m) => lit(m),
            None => meshes[instance.mesh as usize].materials.iter().any(lit),
        }
    }
}
