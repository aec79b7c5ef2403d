//! JSON scene files: spheres, triangle meshes, named materials and a camera.
//!
//! ```json
//! {
//!   "camera": { "origin": [50, 52, 295.6], "direction": [0, -0.042612, -1], "near": 140, "fov": 0.5135,
//!               "lens_radius": 0, "focus_distance": 150 },
//!   "environment": [0, 0, 0],
//!   "materials": {
//!     "white": { "type": "diffuse", "color": [0.75, 0.75, 0.75] },
//!     "lamp":  { "type": "diffuse", "color": [0, 0, 0], "emission": [12, 12, 12] },
//!     "glass": { "type": "glass", "color": [0.999, 0.999, 0.999], "ior": 1.5 }
//!   },
//!   "spheres": [
//!     { "center": [50, 1e5, 81.6], "radius": 1e5, "material": "white" }
//!   ],
//!   "meshes": [
//!     { "path": "pyramid.obj", "material": "glass", "name": "pyramid",
//!       "scale": [20, 20, 20], "rotate": [0, 30, 0], "translate": [60, 0, 90] }
//!   ],
//!   "instances": [
//!     { "mesh": "pyramid", "material": "white", "scale": [10, 10, 10], "translate": [20, 0, 60] }
//!   ],
//!   "disks": [
//!     { "center": [50, 81.5, 81.6], "normal": [0, -1, 0], "radius": 18, "material": "lamp" }
//!   ],
//!   "parallelograms": [
//!     { "corner": [0, 0, 0], "edges": [[100, 0, 0], [0, 0, 170]], "material": "white" }
//!   ]
//! }
//! ```
//! A camera with a `lens_radius` above 0 is a thin lens: points
//! `focus_distance` away along its direction are sharp, others blur (depth
//! of field). `environment` (optional, black by default) is the radiance
//! that rays leaving the scene see from every direction: a uniform sky.
//! A disk or a parallelogram (a rectangle when its edges are square) is one
//! primitive (intersected, bounded and, as a lamp, sampled as one shape:
//! `treelet_core::geometry::flat`), not a fan or a pair of triangles; both
//! faces are surfaces, the normal (a parallelogram's `edges[0] × edges[1]`)
//! only orients it. Unlike a mesh's triangles, such shapes share no edges:
//! let walls overlap at their corners so that no ray slips between them.
//! A mesh (`.obj` or `.ply`, its path relative to the scene file) is scaled,
//! then rotated about x, y and z (degrees, in that order), then translated;
//! all three are optional. An instance places another copy of a named mesh
//! by its own transform (from the mesh file's space, not from the first
//! copy's), in the mesh's material unless it names one; a file read by
//! several meshes is read once. `render`, `build` and `bench` flatten the
//! copies into one set of triangles; [`load_instanced`] keeps them (see
//! [`super::instanced`]). `scenes/cornell.json` in the repository is
//! smallpt's scene in this form, `scenes/cornell_mesh.json` adds a mesh.
use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context as _, Result};
use serde::Deserialize;
use treelet_core::geometry::buffers::{DIFFUSE, GLASS, MIRROR, Material, Sphere};

use super::instanced::{InstancedScene, SceneInstance, SceneMesh};
use super::model::{CameraSpec, Scene};
use super::primitives::validate_spheres;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: CameraSpec,
    #[serde(default)]
    environment: [f32; 3],
    materials: BTreeMap<String, MaterialSpec>,
    #[serde(default)]
    spheres: Vec<SphereSpec>,
    #[serde(default)]
    meshes: Vec<MeshSpec>,
    #[serde(default)]
    instances: Vec<InstanceSpec>,
    #[serde(default)]
    disks: Vec<DiskSpec>,
    #[serde(default)]
    parallelograms: Vec<ParallelogramSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParallelogramSpec {
    corner: [f32; 3],
    edges: [[f32; 3]; 2],
    material: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DiskSpec {
    center: [f32; 3],
    normal: [f32; 3],
    radius: f32,
    material: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshSpec {
    path: String,
    material: String,
    /// What instances call it.
    #[serde(default)]
    name: Option<String>,
    #[serde(flatten)]
    placement: Placement,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InstanceSpec {
    mesh: String,
    #[serde(default)]
    material: Option<String>,
    #[serde(flatten)]
    placement: Placement,
}

/// Where a copy of a mesh goes: scaled, rotated, translated.
#[derive(Deserialize)]
struct Placement {
    #[serde(default = "unit_scale")]
    scale: [f32; 3],
    #[serde(default)]
    rotate: [f32; 3],
    #[serde(default)]
    translate: [f32; 3],
}

fn unit_scale() -> [f32; 3] {
    [1.0; 3]
}

impl Placement {
    /// Scale, rotate (x, then y, then z; degrees), translate.
    fn transform(&self) -> glam::Affine3A {
        let r = self.rotate.map(f32::to_radians);
        let rotation = glam::Quat::from_euler(glam::EulerRot::ZYX, r[2], r[1], r[0]);
        glam::Affine3A::from_scale_rotation_translation(self.scale.into(), rotation, self.translate.into())
    }

    fn is_finite(&self) -> bool {
        self.scale.iter().chain(&self.rotate).chain(&self.translate).all(|v| v.is_finite())
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
enum Kind {
    Diffuse,
    Mirror,
    Glass,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialSpec {
    #[serde(rename = "type")]
    kind: Kind,
    color: [f32; 3],
    #[serde(default)]
    emission: [f32; 3],
    #[serde(default = "default_ior")]
    ior: f32,
}

/// Indices of refraction a glass may have (relative ones below 1 included:
/// a bubble of air in water is 0.75).
pub(crate) const MIN_IOR: f32 = 0.01;
pub(crate) const MAX_IOR: f32 = 100.0;
/// The widest camera: an image plane `2 tan(89.9 degrees)` high at unit
/// distance (`fov` is the full height: see `Camera::look`).
pub(crate) const MAX_FOV: f32 = 1146.0;
/// The narrowest camera a scene file may have (see where it is checked).
const MIN_FOV: f32 = 1e-6;

fn default_ior() -> f32 {
    1.5
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereSpec {
    center: [f32; 3],
    radius: f32,
    material: String,
}

/// The largest emission a material may have: a pixel's sum of squared
/// luminance over 2^16 samples of it stays far below `f32::MAX`.
pub const MAX_EMISSION: f32 = 1e6;

/// A thin lens's radius (0: a pinhole) and, with a lens, the distance of
/// the plane in focus: what scene files and `render --lens` accept.
pub fn check_lens(radius: f32, focus_distance: f32) -> std::result::Result<(), String> {
    if !(radius >= 0.0 && radius.is_finite()) {
        return Err(format!("lens_radius {radius}: use 0 (a pinhole) or a finite positive radius"));
    }
    if radius > 0.0 && !(focus_distance > 0.0 && focus_distance.is_finite()) {
        return Err(format!(
            "focus_distance {focus_distance}: a camera with a lens (lens_radius {radius}) needs the distance of the plane in focus, finite and positive"
        ));
    }
    Ok(())
}

/// A sky's radiance: finite, not negative, and no more than a lamp's
/// [`MAX_EMISSION`] (what scene files and `render --environment` accept).
pub fn check_sky(environment: [f32; 3]) -> std::result::Result<(), String> {
    if !environment.iter().all(|v| v.is_finite() && (0.0..=MAX_EMISSION).contains(v)) {
        return Err(format!(
            "environment {environment:?}: radiance must be finite, not negative and at most {MAX_EMISSION:e} (a pixel's sums of squares would overflow f32)"
        ));
    }
    Ok(())
}

/// Reads a scene file, its instances flattened; errors name the file and
/// the line and column, or the sphere or material at fault.
pub fn load(path: &Path) -> Result<Scene> {
    load_instanced(path)?.flatten()
}

/// Reads a scene file with its meshes once each and their copies as
/// instances (see [`super::instanced`]).
pub fn load_instanced(path: &Path) -> Result<InstancedScene> {
    let text = crate::internals::input::read_text(path, "scene file")?;
    parse_instanced_in(&text, &path.display().to_string(), path.parent().unwrap_or(Path::new(".")))
}

/// Parses scene-file text; `name` labels errors and the scene; mesh paths
/// are relative to the current directory.
pub fn parse(text: &str, name: &str) -> Result<Scene> {
    parse_in(text, name, Path::new("."))
}

/// Parses scene-file text whose mesh paths are relative to `dir`.
pub fn parse_in(text: &str, name: &str, dir: &Path) -> Result<Scene> {
    parse_instanced_in(text, name, dir)?.flatten()
}

/// [`parse_in`] with the instances kept.
pub fn parse_instanced_in(text: &str, name: &str, dir: &Path) -> Result<InstancedScene> {
    super::json_keys::check(text.as_bytes()).map_err(|e| anyhow::anyhow!("scene file {name}: {e}"))?;
    let file: SceneFile = serde_json::from_str(text)
        .map_err(|e| anyhow::anyhow!("scene file {name}: line {}, column {}: {e}", e.line(), e.column()))?;
    let mut materials = BTreeMap::new();
    for (key, m) in &file.materials {
        let kind = match m.kind {
            Kind::Diffuse => DIFFUSE,
            Kind::Mirror => MIRROR,
            Kind::Glass => GLASS,
        };
        let values = m.color.iter().chain(&m.emission).chain([&m.ior]);
        if values.clone().any(|v| !v.is_finite()) {
            bail!("scene file {name}: material `{key}` has a non-finite value");
        }
        if m.color.iter().chain(&m.emission).any(|&v| v < 0.0) {
            bail!("scene file {name}: material `{key}` has a negative colour or emission");
        }
        if m.color.iter().any(|&v| v > 1.0) {
            bail!(
                "scene file {name}: material `{key}` has colour {:?}: a surface reflects at most the light it receives (each component in [0, 1])",
                m.color
            );
        }
        if m.emission.iter().any(|&v| v > MAX_EMISSION) {
            bail!(
                "scene file {name}: material `{key}` has emission {:?}, above {MAX_EMISSION:e} (a pixel's sums of squares would overflow f32)",
                m.emission
            );
        }
        if kind == GLASS && !(m.ior >= MIN_IOR && m.ior <= MAX_IOR) {
            bail!(
                "scene file {name}: material `{key}` has index of refraction {} (it must lie between {MIN_IOR} and {MAX_IOR}; past that, refraction's arithmetic overflows into NaN pixels)",
                m.ior
            );
        }
        let ior = if kind == GLASS { m.ior } else { 0.0 }; // meaningful for glass alone
        materials.insert(key.clone(), Material { emission: m.emission, kind, color: m.color, ior });
    }
    if file.spheres.is_empty() && file.meshes.is_empty() && file.disks.is_empty() && file.parallelograms.is_empty() {
        bail!("scene file {name}: no spheres, meshes, disks or parallelograms");
    }
    let mut spheres = Vec::with_capacity(file.spheres.len());
    let mut sphere_materials = Vec::with_capacity(file.spheres.len());
    for (i, s) in file.spheres.iter().enumerate() {
        let m = materials
            .get(&s.material)
            .with_context(|| format!("scene file {name}: spheres[{i}] uses unknown material `{}`", s.material))?;
        spheres.push(Sphere::new(s.center, s.radius));
        sphere_materials.push(*m);
    }
    validate_spheres(&spheres).with_context(|| format!("scene file {name}"))?;
    let mut meshes: Vec<SceneMesh> = Vec::new();
    let mut instances = Vec::new();
    let mut names: BTreeMap<&str, (u32, Material)> = BTreeMap::new();
    for (i, mesh) in file.meshes.iter().enumerate() {
        let m = materials
            .get(&mesh.material)
            .with_context(|| format!("scene file {name}: meshes[{i}] uses unknown material `{}`", mesh.material))?;
        if !mesh.placement.is_finite() {
            bail!("scene file {name}: meshes[{i}] has a non-finite transform");
        }
        let path = dir.join(&mesh.path);
        let label = path.display().to_string();
        let slot = match meshes.iter().position(|s| s.name == label) {
            Some(slot) => slot as u32,
            None => {
                let loaded = super::mesh::load(&path).with_context(|| format!("scene file {name}: meshes[{i}]"))?;
                let materials = vec![*m; loaded.len()];
                meshes.push(SceneMesh { name: label, triangles: loaded, materials });
                meshes.len() as u32 - 1
            }
        };
        if let Some(key) = &mesh.name {
            if names.insert(key, (slot, *m)).is_some() {
                bail!("scene file {name}: meshes[{i}]: a mesh is already named `{key}`");
            }
        }
        instances.push(SceneInstance { mesh: slot, transform: mesh.placement.transform(), material: Some(*m) });
    }
    for (i, instance) in file.instances.iter().enumerate() {
        let &(slot, named) = names.get(instance.mesh.as_str()).with_context(|| {
            format!("scene file {name}: instances[{i}] places `{}`, which no mesh is named", instance.mesh)
        })?;
        if !instance.placement.is_finite() {
            bail!("scene file {name}: instances[{i}] has a non-finite transform");
        }
        let material = match &instance.material {
            Some(key) => *materials
                .get(key)
                .with_context(|| format!("scene file {name}: instances[{i}] uses unknown material `{key}`"))?,
            None => named, // the material of the mesh entry that named it

        };
        instances.push(SceneInstance { mesh: slot, transform: instance.placement.transform(), material: Some(material) });
    }
    let mut triangles = Vec::new();
    let mut triangle_materials = Vec::new();
    for (i, d) in file.disks.iter().enumerate() {
        let m = materials
            .get(&d.material)
            .with_context(|| format!("scene file {name}: disks[{i}] uses unknown material `{}`", d.material))?;
        if d.center.iter().chain(&d.normal).any(|v| !v.is_finite()) {
            bail!("scene file {name}: disks[{i}] has a non-finite centre or normal");
        }
        let n = glam::Vec3::from_array(d.normal);
        if !(n.length() > 0.0) || !n.normalize().is_finite() {
            bail!("scene file {name}: disks[{i}] has normal {:?}, which gives no direction", d.normal);
        }
        if !(d.radius > 0.0 && d.radius.is_finite()) {
            bail!("scene file {name}: disks[{i}] has radius {} (must be positive and finite)", d.radius);
        }
        let disk = treelet_core::geometry::triangle::Triangle::disk(d.center, d.normal, d.radius);
        if !disk.aabb().extent().is_finite() {
            bail!("scene file {name}: disks[{i}]: its bounding box overflows f32 (centre {:?}, radius {})", d.center, d.radius);
        }
        triangles.push(disk);
        triangle_materials.push(*m);
    }
    for (i, p) in file.parallelograms.iter().enumerate() {
        let m = materials
            .get(&p.material)
            .with_context(|| format!("scene file {name}: parallelograms[{i}] uses unknown material `{}`", p.material))?;
        if p.corner.iter().chain(p.edges.iter().flatten()).any(|v| !v.is_finite()) {
            bail!("scene file {name}: parallelograms[{i}] has a non-finite corner or edge");
        }
        let [e1, e2] = p.edges.map(glam::Vec3::from_array);
        if !(e1.cross(e2).length() > 0.0) {
            bail!("scene file {name}: parallelograms[{i}] has edges {:?} and {:?}, which span no area", p.edges[0], p.edges[1]);
        }
        let shape = treelet_core::geometry::triangle::Triangle::parallelogram(p.corner, p.edges[0], p.edges[1]);
        if !shape.aabb().extent().is_finite() || !shape.area().is_finite() {
            bail!("scene file {name}: parallelograms[{i}]: its size overflows f32 (corner {:?}, edges {:?})", p.corner, p.edges);
        }
        triangles.push(shape);
        triangle_materials.push(*m);
    }
    let c = &file.camera;
    if c.origin.iter().chain(&c.direction).chain([&c.near, &c.fov]).any(|v| !v.is_finite())
        || glam::Vec3::from_array(c.direction).normalize_or_zero() == glam::Vec3::ZERO
        || c.fov <= 0.0
    {
        bail!("scene file {name}: the camera needs a finite origin, a non-zero direction and a positive fov");
    }
    // Cameras that would render black, or from behind their origin.
    // Below this, the camera's basis underflows to NaN (fov 1e-23 and less
    // rendered black, the probe of 2026-12-02): a view of 6e-5 degrees.
    if c.fov < MIN_FOV {
        bail!("scene file {name}: camera fov {} (the height of the image plane at unit distance) is below {MIN_FOV:e}, a view of 6e-5 degrees", c.fov);
    }
    if c.fov > MAX_FOV {
        bail!("scene file {name}: camera fov {} (the height of the image plane at unit distance) is past {MAX_FOV}, a view of 179.8 degrees", c.fov);
    }
    if c.near < 0.0 {
        bail!("scene file {name}: camera near {}: rays would start behind the camera (use 0 or more)", c.near);
    }
    if let Err(e) = check_lens(c.lens_radius, c.focus_distance) {
        bail!("scene file {name}: camera {e}");
    }
    if let Err(e) = check_sky(file.environment) {
        bail!("scene file {name}: {e}");
    }
    let mut materials = sphere_materials;
    materials.extend(triangle_materials);
    let loose =
        Scene { name: name.into(), spheres, materials, room: 0, camera: file.camera, environment: file.environment, triangles, instances: None };
    Ok(InstancedScene { loose, meshes, instances })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_cornell_file_is_smallpts_scene() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell.json");
        let file = load(Path::new(path)).unwrap();
        let builtin = super::super::model::cornell();
        assert_eq!(file.spheres, builtin.spheres);
        assert_eq!(file.materials, builtin.materials);
        assert_eq!(file.camera, builtin.camera);
    }

    #[test]
    fn lenses_and_environments_are_read_and_bad_ones_are_errors() {
        let scene = |camera_extra: &str, top_extra: &str| {
            format!(r#"{{"camera": {{"origin": [0,0,0], "direction": [0,0,1]{camera_extra}}}{top_extra}, "materials": {{"m": {{"type": "diffuse", "color": [1, 1, 1]}}}}, "spheres": [{{"center": [0,0,5], "radius": 1, "material": "m"}}]}}"#)
        };
        let ok = parse(&scene(r#", "lens_radius": 0.25, "focus_distance": 5"#, r#", "environment": [0.5, 0.6, 0.7]"#), "ok.json").unwrap();
        assert_eq!((ok.camera.lens_radius, ok.camera.focus_distance), (0.25, 5.0));
        assert_eq!(ok.environment, [0.5, 0.6, 0.7]);
        let plain = parse(&scene("", ""), "plain.json").unwrap();
        assert_eq!((plain.camera.lens_radius, plain.environment), (0.0, [0.0; 3]));
        // Parts of renders merge by the scene's hash: a lens or a sky makes
        // another scene, and a pinhole without a sky hashes as before both.
        let lens_only = parse(&scene(r#", "lens_radius": 0.25, "focus_distance": 5"#, ""), "l.json").unwrap();
        let sky_only = parse(&scene("", r#", "environment": [0.5, 0.6, 0.7]"#), "s.json").unwrap();
        let hashes = [&ok, &plain, &lens_only, &sky_only].map(|s| s.content_hash());
        assert!((0..4).all(|i| (0..i).all(|j| hashes[i] != hashes[j])), "{hashes:x?}");
        assert_eq!(serde_json::to_string(&plain.camera).unwrap(), r#"{"origin":[0.0,0.0,0.0],"direction":[0.0,0.0,1.0],"near":0.0,"fov":0.5135}"#);
        for (camera, top, expected) in [
            (r#", "lens_radius": 1"#, "", "focus_distance 0"),
            (r#", "lens_radius": 1, "focus_distance": -2"#, "", "focus_distance -2"),
            (r#", "lens_radius": -1, "focus_distance": 2"#, "", "lens_radius -1"),
            ("", r#", "environment": [1, -1, 0]"#, "environment"),
            ("", r#", "environment": [1, 2]"#, "expected an array of length 3"),
            ("", r#", "environment": [1, 1e30, 0]"#, "at most"),
        ] {
            let e = format!("{:#}", parse(&scene(camera, top), "bad.json").unwrap_err());
            assert!(e.contains("bad.json") && e.contains(expected), "{camera} {top}: {e}");
        }
    }

    #[test]
    fn albedo_above_one_and_huge_emission_are_errors() {
        let scene = |material: &str| {
            format!(r#"{{"camera": {{"origin": [0,0,0], "direction": [0,0,1]}}, "materials": {{"m": {material}}}, "spheres": [{{"center": [0,0,5], "radius": 1, "material": "m"}}]}}"#)
        };
        let e = parse(&scene(r#"{"type": "diffuse", "color": [1.5, 0.5, 0.5]}"#), "a.json").unwrap_err().to_string();
        assert!(e.contains("a.json") && e.contains("`m`") && e.contains("[0, 1]"), "{e}");
        let e = parse(&scene(r#"{"type": "diffuse", "color": [0, 0, 0], "emission": [1e30, 0, 0]}"#), "b.json").unwrap_err().to_string();
        assert!(e.contains("b.json") && e.contains("emission"), "{e}");
        assert!(parse(&scene(r#"{"type": "diffuse", "color": [1, 1, 1], "emission": [1e6, 0, 0]}"#), "c.json").is_ok());
        // Glass whose index overflows refraction's arithmetic (NaN pixels).
        let e = parse(&scene(r#"{"type": "glass", "color": [1, 1, 1], "ior": 1e30}"#), "d.json").unwrap_err().to_string();
        assert!(e.contains("d.json") && e.contains("index of refraction"), "{e}");
        assert!(parse(&scene(r#"{"type": "glass", "color": [1, 1, 1], "ior": 0.75}"#), "e.json").is_ok());
    }

    #[test]
    fn cameras_that_would_render_black_or_backwards_are_errors() {
        let scene = |camera: &str| {
            format!(r#"{{"camera": {camera}, "materials": {{"m": {{"type": "diffuse", "color": [1, 1, 1]}}}}, "spheres": [{{"center": [0,0,5], "radius": 1, "material": "m"}}]}}"#)
        };
        for (camera, expected) in [
            (r#"{"origin": [0,0,0], "direction": [0,0,1], "fov": 1e38}"#, "fov"),
            (r#"{"origin": [0,0,0], "direction": [0,0,1], "fov": 1e-30}"#, "below 1e-6"),
            (r#"{"origin": [0,0,0], "direction": [0,0,1], "near": -1}"#, "behind the camera"),
            (r#"{"origin": [0,0,0], "direction": [0,0,1e-30]}"#, "non-zero direction"),
        ] {
            let e = parse(&scene(camera), "cam.json").unwrap_err().to_string();
            assert!(e.contains("cam.json") && e.contains(expected), "{camera}: {e}");
        }
        assert!(parse(&scene(r#"{"origin": [0,0,0], "direction": [0,0,1e-3], "fov": 2}"#), "ok.json").is_ok());
    }

    /// A material named twice rendered with the second silently.
    #[test]
    fn a_key_named_twice_is_an_error() {
        let text = "{\"camera\": {\"origin\": [0,0,0], \"direction\": [0,0,1]}, \"materials\": {\"m\": {\"type\": \"diffuse\", \"color\": [1, 1, 1]},\n \"m\": {\"type\": \"mirror\", \"color\": [1, 1, 1]}},\n \"spheres\": [{\"center\": [0,0,5], \"radius\": 1, \"material\": \"m\"}]}";
        let e = parse(text, "twice.json").unwrap_err().to_string();
        assert!(e.contains("twice.json") && e.contains("\"m\" appears twice") && e.contains("line 2"), "{e}");
        let once = text.replace("\n \"m\": {\"type\": \"mirror\"", "\n \"n\": {\"type\": \"mirror\"");
        parse(&once, "once.json").unwrap();
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse("{\n \"camera\": 3\n}", "x.json").unwrap_err().to_string();
        assert!(e.contains("x.json: line 2"), "{e}");
        let e = parse(r#"{"camera": {"origin": [0,0,0], "direction": [0,0,0]}, "materials": {"w": {"type": "diffuse", "color": [1,1,1]}}, "spheres": [{"center": [0,0,0], "radius": 1, "material": "w"}]}"#, "y.json").unwrap_err().to_string();
        assert!(e.contains("non-zero direction"), "{e}");
        let e =
            parse(r#"{"camera": {"origin": [0,0,0], "direction": [0,0,1]}, "materials": {}, "spheres": []}"#, "z.json")
                .unwrap_err()
                .to_string();
        assert!(e.contains("no spheres, meshes, disks or parallelograms"), "{e}");
    }

    #[test]
    fn meshes_are_loaded_relative_to_the_file_and_transformed() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_mesh.json");
        let scene = load(Path::new(path)).unwrap();
        assert_eq!((scene.spheres.len(), scene.triangles.len()), (8, 6));
        assert_eq!(scene.materials.len(), 14);
        assert!(scene.materials[8..].iter().all(|m| m.kind == GLASS));
        // The unit pyramid scaled by 30 and stood at (68, 0, 80): apex at y = 30.
        let top = scene.triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).fold(f32::MIN, |a, v| a.max(v[1]));
        assert!((top - 30.0).abs() < 1e-4, "apex at {top}");
        let bottom = scene.triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).fold(f32::MAX, |a, v| a.min(v[1]));
        assert!(bottom.abs() < 1e-4, "base at {bottom}");
    }

    #[test]
    fn disks_are_one_primitive_each_and_bad_ones_are_named() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/room_disk.json");
        let scene = load(Path::new(path)).unwrap();
        let disks: Vec<_> = scene.triangles.iter().filter(|t| t.shape == treelet_core::geometry::triangle::SHAPE_DISK).collect();
        assert_eq!(disks.len(), 1);
        let d = disks[0];
        assert_eq!(d.v0, [50.0, 81.5, 81.6]);
        assert!((d.area() - std::f32::consts::PI * 18.0 * 18.0).abs() < 0.05, "{}", d.area());
        let (lo, hi) = (d.aabb().lo(), d.aabb().hi());
        assert!((lo.y - 81.5).abs() < 1e-4 && (hi.y - 81.5).abs() < 1e-4 && (hi.x - 68.0).abs() < 1e-3, "{lo} {hi}");
        // Its material is the lamp's, and the walls are six rectangles.
        let at = scene.triangles.iter().position(|t| t.shape == treelet_core::geometry::triangle::SHAPE_DISK).unwrap();
        assert!(scene.materials[scene.spheres.len() + at].emission[0] > 0.0);
        let walls = scene.triangles.iter().filter(|t| t.shape == treelet_core::geometry::triangle::SHAPE_PARALLELOGRAM);
        assert_eq!(walls.count(), 6);

        let base = r#"{"camera": {"origin": [0,0,0], "direction": [0,0,1]}, "materials": {"w": {"type": "diffuse", "color": [1,1,1]}}, "disks": ["#;
        let case = |disk: &str| format!("{:#}", parse(&format!("{base}{disk}]}}"), "d.json").unwrap_err());
        let e = case(r#"{"center": [0,0,5], "normal": [0,0,0], "radius": 1, "material": "w"}"#);
        assert!(e.contains("d.json") && e.contains("disks[0]") && e.contains("normal"), "{e}");
        let e = case(r#"{"center": [0,0,5], "normal": [0,0,1], "radius": -1, "material": "w"}"#);
        assert!(e.contains("disks[0]") && e.contains("radius -1"), "{e}");
        let e = case(r#"{"center": [0,0,5], "normal": [0,0,1], "radius": 1, "material": "w"}, {"center": [0,0,5], "normal": [0,0,1], "radius": 1, "material": "x"}"#);
        assert!(e.contains("disks[1] uses unknown material `x`"), "{e}");
        let e = case(r#"{"center": [3e38,0,5], "normal": [1,1,0], "radius": 3e38, "material": "w"}"#);
        assert!(e.contains("disks[0]") && e.contains("overflows"), "{e}");
        assert!(parse(&format!("{base}{}]}}", r#"{"center": [0,0,5], "normal": [0,0,1], "radius": 1, "material": "w"}"#), "ok.json").is_ok());

        let base = base.replace("\"disks\"", "\"parallelograms\"");
        let case = |p: &str| format!("{:#}", parse(&format!("{base}{p}]}}"), "p.json").unwrap_err());
        let e = case(r#"{"corner": [0,0,5], "edges": [[1,0,0], [2,0,0]], "material": "w"}"#);
        assert!(e.contains("p.json") && e.contains("parallelograms[0]") && e.contains("span no area"), "{e}");
        let e = case(r#"{"corner": [0,0,5], "edges": [[1,0,0], [0,1,0]], "material": "w"}, {"corner": [0,0,5], "edges": [[1,0,0], [0,"x",0]], "material": "w"}"#);
        assert!(e.contains("p.json: line 1"), "{e}");
        let e = case(r#"{"corner": [0,0,5], "edges": [[3e38,0,0], [0,3e38,0]], "material": "w"}"#);
        assert!(e.contains("parallelograms[0]") && e.contains("overflows"), "{e}");
        let scene = parse(&format!("{base}{}]}}", r#"{"corner": [0,0,5], "edges": [[2,0,0], [0,3,0]], "material": "w"}"#), "ok.json").unwrap();
        assert_eq!((scene.triangles.len(), scene.triangles[0].area()), (1, 6.0));
    }

    #[test]
    fn mesh_errors_name_the_mesh() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes"));
        let base = r#"{"camera": {"origin": [0,0,0], "direction": [0,0,1]}, "materials": {"w": {"type": "diffuse", "color": [1,1,1]}}, "meshes": ["#;
        let case = |mesh: &str| parse_in(&format!("{base}{mesh}]}}"), "m.json", dir).unwrap_err();
        let e = format!("{:#}", case(r#"{"path": "pyramid.obj", "material": "gold"}"#));
        assert!(e.contains("meshes[0] uses unknown material `gold`"), "{e}");
        let e = format!("{:#}", case(r#"{"path": "missing.obj", "material": "w"}"#));
        assert!(e.contains("meshes[0]") && e.contains("missing.obj"), "{e}");
        let e = format!("{:#}", case(r#"{"path": "pyramid.obj", "material": "w", "scale": [3e38, 3e38, 3e38], "translate": [3e38, 0, 0]}"#));
        assert!(e.contains("after the mesh transforms"), "{e}");
        let e = format!("{:#}", case(r#"{"path": "pyramid.obj", "material": "w", "spin": 3}"#));
        assert!(e.contains("line 1") && e.contains("spin"), "{e}");
    }

    #[test]
    fn instances_place_named_meshes_and_bad_ones_are_named() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes"));
        let file = |meshes: &str, instances: &str| {
            format!(
                r#"{{"camera": {{"origin": [0,0,0], "direction": [0,0,1]}}, "materials": {{"w": {{"type": "diffuse", "color": [1,1,1]}}, "m": {{"type": "mirror", "color": [1,1,1]}}}}, "meshes": [{meshes}], "instances": [{instances}]}}"#
            )
        };
        let named = r#"{"path": "pyramid.obj", "material": "w", "name": "p"}"#;
        let err = |text: String| format!("{:#}", parse_instanced_in(&text, "i.json", dir).unwrap_err());
        let e = err(file(named, r#"{"mesh": "q"}"#));
        assert!(e.contains("i.json") && e.contains("instances[0] places `q`, which no mesh is named"), "{e}");
        let e = err(file(named, r#"{"mesh": "p"}, {"mesh": "p", "material": "gold"}"#));
        assert!(e.contains("instances[1] uses unknown material `gold`"), "{e}");
        let e = err(file(&format!("{named}, {named}"), ""));
        assert!(e.contains("meshes[1]: a mesh is already named `p`"), "{e}");
        let e = err(file(named, r#"{"mesh": "p", "turn": 3}"#));
        assert!(e.contains("line 1") && e.contains("turn"), "{e}");
        // The same file under two mesh entries is read once; copies keep
        // their entry's material unless they name one.
        let other = r#"{"path": "pyramid.obj", "material": "m", "translate": [5, 0, 0]}"#;
        let scene = parse_instanced_in(&file(&format!("{named}, {other}"), r#"{"mesh": "p", "translate": [0, 9, 0]}"#), "ok.json", dir).unwrap();
        assert_eq!((scene.meshes.len(), scene.instances.len()), (1, 3));
        let flat = scene.flatten().unwrap();
        let n = flat.triangles.len() / 3;
        let kinds: Vec<u32> = [0, n, 2 * n].iter().map(|&k| flat.materials[k].kind).collect();
        assert_eq!(kinds, [DIFFUSE, MIRROR, DIFFUSE]);
        assert_eq!(flat.triangles[2 * n].v0[1], flat.triangles[0].v0[1] + 9.0);
    }
}
