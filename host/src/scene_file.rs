//! JSON scene files: spheres, named materials and a camera.
//!
//! ```json
//! {
//!   "camera": { "origin": [50, 52, 295.6], "direction": [0, -0.042612, -1], "near": 140, "fov": 0.5135 },
//!   "materials": {
//!     "white": { "type": "diffuse", "color": [0.75, 0.75, 0.75] },
//!     "lamp":  { "type": "diffuse", "color": [0, 0, 0], "emission": [12, 12, 12] },
//!     "glass": { "type": "glass", "color": [0.999, 0.999, 0.999], "ior": 1.5 }
//!   },
//!   "spheres": [
//!     { "center": [50, 1e5, 81.6], "radius": 1e5, "material": "white" }
//!   ]
//! }
//! ```
//! `scenes/cornell.json` in the repository is smallpt's scene in this form.
use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context as _, Result};
use serde::Deserialize;
use treelet_core::layout::{Material, Sphere, DIFFUSE, GLASS, MIRROR};

use crate::scene::{CameraSpec, Scene};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: CameraSpec,
    materials: BTreeMap<String, MaterialSpec>,
    spheres: Vec<SphereSpec>,
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

/// Reads a scene file; errors name the file and the line and column, or the
/// sphere or material at fault.
pub fn load(path: &Path) -> Result<Scene> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read scene file {}", path.display()))?;
    parse(&text, &path.display().to_string())
}

/// Parses scene-file text; `name` labels errors and the scene.
pub fn parse(text: &str, name: &str) -> Result<Scene> {
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
        if kind == GLASS && m.ior <= 0.0 {
            bail!("scene file {name}: material `{key}` has index of refraction {} (must be positive)", m.ior);
        }
        let ior = if kind == GLASS { m.ior } else { 0.0 }; // meaningful for glass alone
        materials.insert(key.clone(), Material { emission: m.emission, kind, color: m.color, ior });
    }
    if file.spheres.is_empty() {
        bail!("scene file {name}: no spheres");
    }
    let mut spheres = Vec::with_capacity(file.spheres.len());
    let mut sphere_materials = Vec::with_capacity(file.spheres.len());
    for (i, s) in file.spheres.iter().enumerate() {
        let m = materials
            .get(&s.material)
            .with_context(|| format!("scene file {name}: sphere {i} uses unknown material `{}`", s.material))?;
        spheres.push(Sphere::new(s.center, s.radius));
        sphere_materials.push(*m);
    }
    crate::scene::validate_spheres(&spheres).with_context(|| format!("scene file {name}"))?;
    let c = &file.camera;
    if c.origin.iter().chain(&c.direction).chain([&c.near, &c.fov]).any(|v| !v.is_finite())
        || c.direction.iter().all(|&v| v == 0.0)
        || c.fov <= 0.0
    {
        bail!("scene file {name}: the camera needs a finite origin, a non-zero direction and a positive fov");
    }
    Ok(Scene {
        name: name.into(),
        spheres,
        materials: sphere_materials,
        room: 0,
        camera: file.camera,
        triangles: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_cornell_file_is_smallpts_scene() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell.json");
        let file = load(Path::new(path)).unwrap();
        let builtin = crate::scene::cornell();
        assert_eq!(file.spheres, builtin.spheres);
        assert_eq!(file.materials, builtin.materials);
        assert_eq!(file.camera, builtin.camera);
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
        assert!(e.contains("no spheres"), "{e}");
    }
}
