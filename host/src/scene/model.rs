//! What a scene is (spheres and triangles, a material each, a camera) and
//! the built-in ones: smallpt's cornell, random spheres, terrains.
use anyhow::{bail, Result};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use treelet_core::geometry::buffers::{Camera, DIFFUSE, GLASS, MIRROR, Material, Sphere};
use treelet_core::geometry::triangle::Triangle;
use treelet_core::render::integrator::SMALLPT_FOV;

use crate::scene::instances::SceneInstances;
use crate::scene::primitives::Primitives;

/// Where random scenes place sphere centres: smallpt's room, short of the
/// plane (z about 155) where its camera rays start, so that no sphere
/// encloses a camera ray's origin.
pub const RANDOM_BOX_MIN: [f32; 3] = [1.0, 0.0, 0.0];
pub const RANDOM_BOX_MAX: [f32; 3] = [99.0, 81.6, 140.0];

/// A scene: spheres with one material each, and a camera.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    /// Every sphere a render traces. The last `room` of them are the room
    /// (walls and light) a `random:N` scene is rendered in; the others are
    /// the scene's objects, which `treelet build` builds over.
    pub spheres: Vec<Sphere>,
    /// One material per sphere.
    pub materials: Vec<Material>,
    pub room: usize,
    pub camera: CameraSpec,
    /// Radiance that rays leaving the scene see from every direction (a
    /// constant environment; black: none, as in smallpt's closed room).
    pub environment: [f32; 3],
    /// Triangles of a mesh scene (`treelet build` builds over them; they
    /// are not rendered yet).
    pub triangles: Vec<Triangle>,
    /// Instances of meshes beside the primitives above (each mesh stored
    /// once): only `render` takes a scene with them
    /// ([`crate::scene::instanced::InstancedScene::for_render`]); every
    /// other command loads scenes flattened ([`Scene::from_spec`]), with
    /// none.
    pub instances: Option<std::sync::Arc<SceneInstances>>,
}

/// Where the camera is; the image size comes from the render.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    pub origin: [f32; 3],
    pub direction: [f32; 3],
    /// Primary rays start this far along their direction.
    #[serde(default)]
    pub near: f32,
    /// Half-height of the image plane at unit distance.
    #[serde(default = "default_fov")]
    pub fov: f32,
    /// Radius of a thin lens (0: a pinhole): depth of field.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub lens_radius: f32,
    /// Distance along `direction` of the plane in focus (with a lens).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub focus_distance: f32,
}

impl CameraSpec {
    /// smallpt's lens at `eye`, looking at `target`: refused where either is
    /// not finite or they are the same point.
    pub fn looking_at(eye: [f32; 3], target: [f32; 3]) -> Result<CameraSpec> {
        let direction = Vec3::from_array(target) - Vec3::from_array(eye);
        if !eye.iter().chain(&target).all(|x| x.is_finite()) || direction.length_squared() == 0.0 || !direction.is_finite() {
            bail!("camera from {eye:?} to {target:?}: both points must be finite and apart");
        }
        Ok(CameraSpec::pinhole(eye, direction.to_array(), 0.0, SMALLPT_FOV))
    }
}

/// Left out of the camera's JSON (and so of [`Scene::content_hash`]) where
/// 0, so that a pinhole hashes as it did before lenses.
fn is_zero(x: &f32) -> bool {
    *x == 0.0
}

fn default_fov() -> f32 {
    SMALLPT_FOV
}

impl CameraSpec {
    /// smallpt's camera.
    pub const SMALLPT: CameraSpec = CameraSpec::pinhole([50.0, 52.0, 295.6], [0.0, -0.042612, -1.0], 140.0, SMALLPT_FOV);

    /// A camera without a lens.
    pub const fn pinhole(origin: [f32; 3], direction: [f32; 3], near: f32, fov: f32) -> CameraSpec {
        CameraSpec { origin, direction, near, fov, lens_radius: 0.0, focus_distance: 0.0 }
    }

    pub fn camera(&self, width: u32, height: u32) -> Camera {
        let camera = Camera::look(
            Vec3::from_array(self.origin),
            Vec3::from_array(self.direction),
            self.near,
            self.fov,
            width,
            height,
        );
        Camera { lens_radius: self.lens_radius, focus_distance: self.focus_distance, ..camera }
    }
}

pub fn diffuse(color: [f32; 3]) -> Material {
    Material { color, kind: DIFFUSE, ..Default::default() }
}

/// smallpt's scene, in smallpt's order: six walls of radius 1e5, the
/// mirror ball, the glass ball, the light.
pub fn cornell() -> Scene {
    let mut room = cornell_room();
    let light = room.pop().expect("the room ends with its light");
    let (spheres, materials): (Vec<_>, Vec<_>) = room
        .into_iter()
        .chain([
            (Sphere::new([27.0, 16.5, 47.0], 16.5), Material { color: [0.999; 3], kind: MIRROR, ..Default::default() }),
            (
                Sphere::new([73.0, 16.5, 78.0], 16.5),
                Material { color: [0.999; 3], kind: GLASS, ior: 1.5, ..Default::default() },
            ),
            light,
        ])
        .unzip();
    Scene { name: "cornell".into(), spheres, materials, room: 0, camera: CameraSpec::SMALLPT, environment: [0.0; 3], triangles: Vec::new(), instances: None }
}

/// `terrain:N`: a height field of about N triangles (a square grid, two per
/// cell) over 10 x 10 units, `y = sin 1.3x cos 0.7z + 0.2 sin(7.1x + 5.3z)`:
/// a mesh of any size for benchmarks.
pub fn terrain(n: usize) -> Vec<Triangle> {
    let cells = ((n as f64 / 2.0).sqrt().round() as usize).max(1);
    let p = |i: usize, j: usize| {
        let (x, z) = (i as f32 / cells as f32 * 10.0, j as f32 / cells as f32 * 10.0);
        [x, (x * 1.3).sin() * (z * 0.7).cos() + 0.2 * (x * 7.1 + z * 5.3).sin(), z]
    };
    let mut tris = Vec::with_capacity(2 * cells * cells);
    for j in 0..cells {
        for i in 0..cells {
            tris.push(Triangle::new(p(i, j), p(i + 1, j), p(i + 1, j + 1)));
            tris.push(Triangle::new(p(i, j), p(i + 1, j + 1), p(i, j + 1)));
        }
    }
    tris
}

/// Where [`mesh_scene`] puts a point of `mesh`: scaled so that the mesh
/// fits a 60-unit cube, centred in smallpt's room, standing on its floor.
pub fn mesh_placement(mesh: &[Triangle]) -> impl Fn([f32; 3]) -> [f32; 3] {
    let bounds = mesh.iter().fold(treelet_core::Aabb::EMPTY, |b, t| b.union(&t.aabb()));
    let size = bounds.extent().max_element();
    let scale = if size > 0.0 { 60.0 / size } else { 1.0 };
    let (lo, hi) = (bounds.lo(), bounds.hi());
    let shift = Vec3::new(50.0, 0.0, 80.0) - Vec3::new((lo.x + hi.x) * 0.5, lo.y, (lo.z + hi.z) * 0.5) * scale;
    move |v: [f32; 3]| (Vec3::from_array(v) * scale + shift).to_array()
}

/// How far a camera [`framed_from_above`] stands from its mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Framing {
    /// At the mesh's largest extent from its centre: the mesh fills most of
    /// the view, so most rays meet it (`bench rays --mesh-only`, and OptiX's
    /// peer, frame a mesh so).
    FillsTheView,
    /// Far enough that the mesh's bounding sphere fits the image's height,
    /// with a margin: the whole mesh in view, as a viewer shows it.
    WholeInView,
}

/// smallpt's lens above and in front of `mesh`, looking at the centre of its
/// box along -(0, 0.6, 0.8), at the distance `framing` says. Refused for a
/// mesh so small that the direction's squared length is no normal f32
/// (GPUs flush such numbers to zero, and the camera would look nowhere), or
/// so large that the camera's place is past f32.
pub fn framed_from_above(name: &str, mesh: &[Triangle], framing: Framing) -> Result<CameraSpec> {
    let bounds = mesh.iter().fold(treelet_core::Aabb::EMPTY, |b, t| b.union(&t.aabb()));
    let (center, size) = (bounds.centroid(), bounds.extent().max_element());
    if !(size * size >= f32::MIN_POSITIVE) {
        bail!("{name}: the mesh spans {size:e} units, too small to frame with a camera (scale it up in the file)");
    }
    let distance = match framing {
        Framing::FillsTheView => size,
        // The image is SMALLPT_FOV high at unit distance; a tenth of margin.
        Framing::WholeInView => 1.1 * (bounds.extent().length() / 2.0) / (SMALLPT_FOV / 2.0),
    };
    let origin = center + Vec3::new(0.0, 0.6, 0.8) * distance;
    if !origin.is_finite() || !(center - origin).is_finite() {
        bail!("{name}: the mesh spans {size:e} units, too large to frame with a camera in f32 (scale it down in the file)");
    }
    Ok(CameraSpec::pinhole(origin.to_array(), (center - origin).to_array(), 0.0, SMALLPT_FOV))
}

/// The sky of a scene in which nothing else gives light (a glTF file without
/// emitters, a mesh file alone): a white one of radiance 1, as mesh and
/// glTF viewers light such files by a default environment (a diffuse
/// surface open to it shows its colour).
pub const DEFAULT_SKY: [f32; 3] = [1.0; 3];

/// A mesh file alone, as a mesh viewer shows it: in its own coordinates,
/// seen whole from above ([`framed_from_above`]), mid-grey, under the white
/// [`DEFAULT_SKY`]; no room around it. (A scene file places a mesh in
/// smallpt's room, or anywhere, with lamps of its own.)
pub fn mesh_alone(name: &str, triangles: Vec<Triangle>) -> Result<Scene> {
    let camera = framed_from_above(name, &triangles, Framing::WholeInView)?;
    // Mid-grey: its shading stands out against the white sky behind it.
    let materials = vec![diffuse([0.5, 0.49, 0.46]); triangles.len()];
    Ok(Scene { name: name.into(), spheres: Vec::new(), materials, room: 0, camera, environment: DEFAULT_SKY, triangles, instances: None })
}

/// A mesh alone in smallpt's room, under its light and camera: scaled to fit
/// a 60-unit cube, centred in the room and standing on the floor, in a
/// light diffuse grey. (`treelet build` builds over the triangles alone.)
pub fn mesh_scene(name: &str, mesh: &[Triangle]) -> Scene {
    let place = mesh_placement(mesh);
    let triangles: Vec<Triangle> = mesh.iter().map(|t| Triangle::new(place(t.v0), place(t.v1), place(t.v2))).collect();
    let (spheres, mut materials): (Vec<_>, Vec<_>) = cornell_room().into_iter().unzip();
    let room = spheres.len();
    materials.extend(std::iter::repeat_n(diffuse([0.8, 0.78, 0.72]), triangles.len()));
    Scene { name: name.into(), spheres, materials, room, camera: CameraSpec::SMALLPT, environment: [0.0; 3], triangles, instances: None }
}

/// smallpt's walls and light (radius 600, poking 0.27 through the ceiling),
/// the light last.
pub fn cornell_room() -> Vec<(Sphere, Material)> {
    vec![
        (Sphere::new([1e5 + 1.0, 40.8, 81.6], 1e5), diffuse([0.75, 0.25, 0.25])),
        (Sphere::new([-1e5 + 99.0, 40.8, 81.6], 1e5), diffuse([0.25, 0.25, 0.75])),
        (Sphere::new([50.0, 40.8, 1e5], 1e5), diffuse([0.75; 3])),
        (Sphere::new([50.0, 40.8, -1e5 + 170.0], 1e5), diffuse([0.0; 3])),
        (Sphere::new([50.0, 1e5, 81.6], 1e5), diffuse([0.75; 3])),
        (Sphere::new([50.0, -1e5 + 81.6, 81.6], 1e5), diffuse([0.75; 3])),
        // 681.6 - 0.27, rounded once as smallpt's double is.
        (Sphere::new([50.0, 681.33, 81.6], 600.0), Material { emission: [12.0; 3], ..diffuse([0.0; 3]) }),
    ]
}

impl Scene {
    /// A hash of everything a render of the scene reads (spheres,
    /// materials, triangles, camera, sky), whatever its name or the path it was
    /// loaded from: parts of one render must agree on it. FNV-1a.
    pub fn content_hash(&self) -> u64 {
        use std::hash::Hasher;
        let mut h = fnv::FnvHasher::default();
        let mut field = |bytes: &[u8]| {
            h.write_usize(bytes.len());
            h.write(bytes);
        };
        field(bytemuck::cast_slice(&self.spheres));
        field(bytemuck::cast_slice(&self.materials));
        field(bytemuck::cast_slice(&self.triangles));
        field(serde_json::to_string(&self.camera).unwrap_or_default().as_bytes());
        // Only a sky that shines, so that scenes without one hash as before.
        if self.environment != [0.0; 3] {
            field(bytemuck::cast_slice(&self.environment));
        }
        // Instances: each mesh, then each copy's mesh, transform
        // and material.
        if let Some(copies) = &self.instances {
            for mesh in &copies.meshes {
                field(bytemuck::cast_slice(&mesh.triangles));
                field(bytemuck::cast_slice(&mesh.materials));
            }
            for instance in &copies.instances {
                field(&instance.mesh.to_le_bytes());
                field(bytemuck::cast_slice(&instance.rows()));
                field(instance.material.as_ref().map_or(&[][..], bytemuck::bytes_of));
            }
        }
        h.finish()
    }

    /// Primitives a render builds trees over: the scene's own, each instanced
    /// mesh's triangles once, and a top-level leaf per copy (what memory
    /// estimates count).
    pub fn traced_primitives(&self) -> u64 {
        let own = (self.spheres.len() + self.triangles.len()) as u64;
        let copied = self.instances.as_ref().map_or(0, |p| {
            p.meshes.iter().map(|m| m.triangles.len() as u64).sum::<u64>() + p.instances.len() as u64
        });
        own + copied
    }

    /// The spheres `treelet build` builds over: all but the room.
    pub fn objects(&self) -> &[Sphere] {
        &self.spheres[..self.spheres.len() - self.room]
    }

    /// The scene's triangles alone (no spheres, no room), seen from above and
    /// in front so that they fill most of the view: what `bench rays
    /// --mesh-only` casts at.
    pub fn mesh_only(&self) -> Result<Scene> {
        if self.triangles.is_empty() {
            bail!("scene `{}` has no triangles", self.name);
        }
        let camera = framed_from_above(&self.name, &self.triangles, Framing::FillsTheView)?;
        Ok(Scene {
            name: format!("{} (mesh only)", self.name),
            spheres: Vec::new(),
            materials: self.materials[self.spheres.len()..].to_vec(),
            room: 0,
            camera,
            environment: [0.0; 3],
            triangles: self.triangles.clone(),
            instances: None,
        })
    }

    /// What `treelet build` builds over: the objects (spheres but the room)
    /// and the triangles.
    pub fn primitives(&self) -> Primitives<'_> {
        Primitives { spheres: self.objects(), triangles: &self.triangles }
    }
}

/// `random:N`: N spheres of mixed materials inside smallpt's room: 70%
/// diffuse of random colours, 15% mirror, 15% glass. Specular spheres reflect
/// 90% (not smallpt's 99.9%): Russian roulette keeps paths between many
/// mirrors short only when reflectance is well below 1.
pub fn random_scene(name: &str, n: usize, seed: u64) -> Scene {
    let mut spheres = random_spheres(n, seed);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed ^ 0x5eed);
    let mut materials: Vec<Material> = (0..n)
        .map(|_| {
            let pick: f32 = rng.random();
            if pick < 0.7 {
                diffuse([0, 1, 2].map(|_| rng.random_range(0.2..0.9)))
            } else if pick < 0.85 {
                Material { color: [0.9; 3], kind: MIRROR, ..Default::default() }
            } else {
                Material { color: [0.9; 3], kind: GLASS, ior: 1.5, ..Default::default() }
            }
        })
        .collect();
    let room = cornell_room();
    let room_len = room.len();
    for (s, m) in room {
        spheres.push(s);
        materials.push(m);
    }
    Scene { name: name.into(), spheres, materials, room: room_len, camera: CameraSpec::SMALLPT, environment: [0.0; 3], triangles: Vec::new(), instances: None }
}

/// `n` spheres with uniform random centres inside the Cornell box and random
/// radii, sized so that the spheres fill a similar fraction of the box
/// whatever `n`. Deterministic for a given seed.
pub fn random_spheres(n: usize, seed: u64) -> Vec<Sphere> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let size: Vec<f32> = (0..3).map(|k| RANDOM_BOX_MAX[k] - RANDOM_BOX_MIN[k]).collect();
    let volume: f32 = size.iter().product();
    // Mean spacing between centres; radii up to a third of it.
    let spacing = (volume / n.max(1) as f32).cbrt();
    (0..n)
        .map(|_| {
            let c = [0, 1, 2].map(|k| RANDOM_BOX_MIN[k] + rng.random::<f32>() * size[k]);
            Sphere::new(c, spacing * rng.random_range(0.05..0.33))
        })
        .collect()
}

