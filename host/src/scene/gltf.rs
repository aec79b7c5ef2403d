//! glTF 2.0 scenes (`.gltf` with its buffers, or `.glb`), through the `gltf`
//! crate: the triangle meshes of the default scene, each read once and
//! placed by every node that names it (an instance: [`load_instanced`];
//! [`load`] flattens them into one set of triangles), their materials
//! mapped to the path tracer's, and the first perspective camera placed
//! (or camera N of the file's list: `render --camera N`; else one framing
//! the placed meshes' boxes). Extensions beyond the materials' are named
//! in a note each ([`SUPPORTED_EXTENSIONS`]).
//!
//! Materials (metallic-roughness, with the transmission, IOR and emissive
//! strength extensions): transmission above one half is glass (colour: the
//! base colour, index: `KHR_materials_ior`, 1.5 without it); metallic at
//! least one half with roughness below 0.2 is a mirror; anything else is
//! diffuse in its base colour. Emission is the emissive factor times its
//! strength. Textures are not read: a material with one renders in its
//! factor alone, and a note says so. Punctual lights
//! (`KHR_lights_punctual`) are not supported either (emissive surfaces
//! light the scene): a note says so. Buffers are embedded (`.glb`, base64
//! data URIs) or files beside the scene, read within the input limits.
use std::path::Path;

use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Affine3A, Mat4, Vec3};
use treelet_core::geometry::buffers::{Material, DIFFUSE, GLASS, MIRROR};
use treelet_core::geometry::triangle::Triangle;

use super::file::MAX_EMISSION;
use super::instanced::{InstancedScene, SceneInstance, SceneMesh};
use super::model::{CameraSpec, Scene};

/// The extensions read (the materials'); a note names each other one a
/// file uses.
pub const SUPPORTED_EXTENSIONS: [&str; 3] = ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"];

/// Loads a glTF 2.0 file as a scene, its instances flattened; errors name
/// the file and the mesh, primitive or material at fault.
pub fn load(path: &Path) -> Result<Scene> {
    load_instanced(path)?.flatten()
}

/// [`load`] seen from the file's camera `camera` (its index in the file's
/// `cameras` list), or from the first perspective camera a node places.
pub fn load_with_camera(path: &Path, camera: Option<usize>) -> Result<Scene> {
    load_instanced_with_camera(path, camera)?.flatten()
}

/// Loads a glTF 2.0 file with each mesh once, in its own space, and an
/// instance for every node that places it (see
/// [`super::instanced`]); errors name the file and the mesh, primitive or
/// material at fault.
pub fn load_instanced(path: &Path) -> Result<InstancedScene> {
    load_instanced_with_camera(path, None)
}

/// [`load_instanced`] from the file's camera `camera`, as [`load_with_camera`].
pub fn load_instanced_with_camera(path: &Path, camera: Option<usize>) -> Result<InstancedScene> {
    let name = path.display().to_string();
    let bytes = crate::internals::input::read(path, "glTF file")?;
    // glTF readers may ignore a byte-order mark before the JSON.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    precheck(bytes, &name)?;
    let mut gltf = gltf::Gltf::from_slice(bytes).map_err(|e| anyhow!("{name}: not a valid glTF 2.0 file: {e}"))?;
    let buffers = buffers(&mut gltf, path.parent().unwrap_or(Path::new(".")), &name)?;
    check_ranges(&gltf.document, &name)?;
    check_node_transforms(&gltf.document, &name)?;
    let document = &gltf.document;
    let scene =
        document.default_scene().or_else(|| document.scenes().next()).with_context(|| format!("{name}: no scene"))?;
    let mut out = Loaded {
        mesh_slots: vec![None; document.meshes().len()],
        cameras: vec![None; document.cameras().len()],
        ..Default::default()
    };
    walk(document, &scene, &buffers, &name, &mut out)?;
    let placed = out.instances.iter().map(|i| out.meshes[i.mesh as usize].triangles.len() as u64).sum::<u64>();
    if placed == 0 {
        bail!("{name}: the scene has no triangles");
    }
    if out.textured {
        eprintln!("note: {name}: textures are not read; textured materials render in their colour factors alone");
    }
    for extension in document.extensions_used() {
        match extension {
            e if SUPPORTED_EXTENSIONS.contains(&e) => {}
            "KHR_lights_punctual" => eprintln!(
                "note: {name}: punctual lights (KHR_lights_punctual) are not supported; only emissive materials give light"
            ),
            other => eprintln!("note: {name}: extension {other} is not supported; what it adds is ignored"),
        }
    }
    let placed_cameras = out.cameras.iter().filter(|c| c.is_some_and(|c| c.yfov.is_some())).count();
    if camera.is_none() && placed_cameras > 1 {
        eprintln!("note: {name}: {placed_cameras} perspective cameras; the first placed is used (--camera N picks camera N of the file's list)");
    }
    let camera = match (camera, out.camera, out.orthographic) {
        (Some(index), _, _) => chosen_camera(&name, &out.cameras, index)?,
        (None, Some(c), _) => c,
        (None, None, Some(node)) => bail!(
            "{name}: node {node}: orthographic cameras are not supported (perspective only); remove it to get a camera that frames the scene"
        ),
        (None, None, None) => framing(instances_bounds(&out.meshes, &out.instances)),
    };
    // A file without lights would render black: a uniform sky lights it,
    // as glTF viewers light such files by a default environment.
    let emits = |m: &Material| m.emission.iter().any(|&e| e > 0.0);
    let lit = out.instances.iter().any(|i| match &i.material {
        Some(m) => emits(m),
        None => out.meshes[i.mesh as usize].materials.iter().any(emits),
    });
    let environment = if lit {
        [0.0; 3]
    } else {
        eprintln!("note: {name}: nothing in it emits light; a uniform white sky lights it (render --environment R,G,B sets another)");
        DEFAULT_SKY
    };
    let loose = Scene { name, spheres: Vec::new(), materials: Vec::new(), room: 0, camera, environment, triangles: Vec::new(), instances: None };
    Ok(InstancedScene { loose, meshes: out.meshes, instances: out.instances })
}

/// The sky of a glTF scene in which nothing emits light.
pub use super::model::DEFAULT_SKY;

/// The box of every instance's mesh box, placed (each placed box's eight
/// corners; the triangles' own box where the transforms keep axes).
fn instances_bounds(meshes: &[SceneMesh], instances: &[SceneInstance]) -> (Vec3, Vec3) {
    let boxes: Vec<(Vec3, Vec3)> = meshes
        .iter()
        .map(|m| {
            m.triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), v| (lo.min(v.into()), hi.max(v.into())),
            )
        })
        .collect();
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for i in instances {
        let (a, b) = boxes[i.mesh as usize];
        if a.x > b.x {
            continue; // no triangles
        }
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { a.x } else { b.x },
                if k & 2 == 0 { a.y } else { b.y },
                if k & 4 == 0 { a.z } else { b.z },
            );
            let p = i.transform.transform_point3(corner);
            (lo, hi) = (lo.min(p), hi.max(p));
        }
    }
    (lo, hi)
}

/// What the `gltf` crate indexes without checking (found by fuzzing: its
/// validation indexes a primitive's POSITION accessor before checking that
/// it exists): every attribute's accessor exists.
fn precheck(bytes: &[u8], name: &str) -> Result<()> {
    let json = if bytes.starts_with(b"glTF") {
        check_glb(bytes, name)?;
        gltf::Glb::from_slice(bytes).map_err(|e| anyhow!("{name}: not a valid GLB file: {e}"))?.json.into_owned()
    } else {
        bytes.to_vec()
    };
    super::json_keys::check(&json).map_err(|e| anyhow!("{name}: {e}"))?;
    let root: gltf::json::Root =
        gltf::json::deserialize::from_slice(&json).map_err(|e| anyhow!("{name}: not a valid glTF 2.0 file: {e}"))?;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(a) = primitive.attributes.values().find(|a| a.value() >= root.accessors.len()) {
                bail!("{name}: mesh {m} primitive {p}: accessor {} does not exist", a.value());
            }
        }
    }
    Ok(())
}

/// A GLB file's header and chunk lengths against its size, so that a cut
/// or lying file is called what it is (the `gltf` crate reports "failed to
/// fill whole buffer", or subtracts past zero on a header length under 12).
fn check_glb(bytes: &[u8], name: &str) -> Result<()> {
    let word = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        bail!("{name}: truncated: {} bytes, where a GLB header takes 12", bytes.len());
    };
    if version != 2 {
        bail!("{name}: GLB version {version}; only version 2 is read");
    }
    if length < 20 {
        bail!("{name}: its GLB header gives a length of {length} bytes, less than a header and one chunk");
    }
    if length > bytes.len() {
        bail!("{name}: truncated: the GLB header says {length} bytes, the file has {}", bytes.len());
    }
    let (mut at, mut k, mut binary) = (12usize, 0, false);
    while at < length {
        let (Some(chunk), Some(kind)) = (word(at), bytes.get(at + 4..at + 8).filter(|_| at + 8 <= length)) else {
            bail!("{name}: truncated: the header of chunk {k} at byte {at} is cut off");
        };
        if k == 0 && kind != b"JSON" {
            bail!("{name}: the first GLB chunk is not JSON");
        }
        // One BIN chunk at most (glTF 2.0, 4.4.3); the crate read the first
        // of two and left the other, silently.
        if kind == b"BIN\0" {
            if binary {
                bail!("{name}: chunk {k} at byte {at} is a second BIN chunk; a GLB file holds one");
            }
            binary = true;
        }
        if chunk > length - at - 8 {
            bail!("{name}: truncated or corrupt: chunk {k} says {chunk} bytes, {} remain", length - at - 8);
        }
        at += 8 + chunk;
        k += 1;
    }
    Ok(())
}

/// A node gives its transform once: as a matrix, or as translation,
/// rotation and scale (glTF 2.0, 5.25). With both, the `gltf` crate takes
/// the matrix and drops the rest without a word.
fn check_node_transforms(document: &gltf::Document, name: &str) -> Result<()> {
    for (i, node) in document.as_json().nodes.iter().enumerate() {
        if node.matrix.is_some() && (node.translation.is_some() || node.rotation.is_some() || node.scale.is_some()) {
            bail!("{name}: node {i} has both a matrix and translation, rotation or scale; glTF allows one or the other");
        }
    }
    Ok(())
}

/// Every buffer view within its buffer and every accessor within its view,
/// so that reading them cannot go out of bounds.
fn check_ranges(document: &gltf::Document, name: &str) -> Result<()> {
    for view in document.views() {
        let end = view.offset().checked_add(view.length());
        if end.is_none_or(|end| end > view.buffer().length()) {
            bail!("{name}: buffer view {} reaches past its buffer", view.index());
        }
    }
    for accessor in document.accessors() {
        // The crate's iterators count from `count - 1`.
        if accessor.count() == 0 {
            bail!("{name}: accessor {}: a count of 0 (glTF asks for at least 1)", accessor.index());
        }
        let Some(view) = accessor.view() else { continue };
        let element = accessor.size();
        let stride = view.stride().unwrap_or(element);
        let last = accessor.count().checked_sub(1).map(|k| k.checked_mul(stride).and_then(|x| x.checked_add(element)));
        let end = match last {
            None => Some(accessor.offset()),
            Some(l) => l.and_then(|l| l.checked_add(accessor.offset())),
        };
        if end.is_none_or(|end| end > view.length()) || stride < element {
            bail!("{name}: accessor {} reaches past its buffer view", accessor.index());
        }
        if accessor.sparse().is_some() {
            bail!("{name}: accessor {}: sparse accessors are not supported", accessor.index());
        }
    }
    Ok(())
}

#[derive(Default)]
struct Loaded {
    meshes: Vec<SceneMesh>,
    /// Per glTF mesh: its index in `meshes`, once a node has placed it.
    mesh_slots: Vec<Option<u32>>,
    /// Per entry of `meshes`: its vertices' box, to check each placement.
    mesh_bounds: Vec<(Vec3, Vec3)>,
    instances: Vec<SceneInstance>,
    camera: Option<CameraSpec>,
    /// Per camera of the file, the first node that places it.
    cameras: Vec<Option<CameraNode>>,
    /// The first node with an orthographic camera, if any.
    orthographic: Option<usize>,
    textured: bool,
}

/// Deepest node hierarchy read: real scenes nest a few tens of levels; a
/// chain of a hundred thousand nodes is an attack on the reader.
const MAX_NODE_DEPTH: usize = 1000;

/// Each buffer's bytes: the `.glb` binary chunk (moved, not copied: glTF
/// gives it to the first buffer alone), a base64 data URI, or a
/// file beside the scene.
fn buffers(gltf: &mut gltf::Gltf, dir: &Path, name: &str) -> Result<Vec<Vec<u8>>> {
    use base64::Engine as _;
    let mut out = Vec::new();
    let mut blob = gltf.blob.take();
    let had_blob = blob.is_some();
    for buffer in gltf.document.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => match blob.take() {
                Some(bytes) => bytes,
                None if had_blob => bail!("{name}: buffer {i}: the binary chunk is an earlier buffer's (glTF gives it to the first alone)"),
                None => bail!("{name}: buffer {i}: no binary chunk"),
            },
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let (_, encoded) = uri
                    .split_once(";base64,")
                    .with_context(|| format!("{name}: buffer {i}: a data URI that is not base64"))?;
                base64::engine::general_purpose::STANDARD
                    .decode(encoded)
                    .map_err(|e| anyhow!("{name}: buffer {i}: bad base64: {e}"))?
            }
            gltf::buffer::Source::Uri(uri) => {
                if uri.contains("://") {
                    bail!("{name}: buffer {i}: `{uri}` is not a local file");
                }
                let file = percent_decoded(uri).with_context(|| format!("{name}: buffer {i}: `{uri}`"))?;
                // A URI reference relative to the file (glTF 2.0, 2.8), so
                // not an absolute path (escaped as `%2F` too). `..` is legal
                // glTF: a file may still name its parent folders' files.
                let drive = file.as_bytes().get(..3).is_some_and(|d| d[0].is_ascii_alphabetic() && d[1] == b':' && matches!(d[2], b'/' | b'\\'));
                if file.starts_with('/') || file.starts_with('\\') || drive {
                    bail!("{name}: buffer {i}: `{uri}` is an absolute path; glTF buffers are named relative to the file");
                }
                crate::internals::input::read(&dir.join(file), "glTF buffer").with_context(|| format!("{name}: buffer {i}"))?
            }
        };
        if data.len() < buffer.length() {
            bail!("{name}: buffer {i} holds {} bytes, the file says {}", data.len(), buffer.length());
        }
        out.push(data);
    }
    Ok(out)
}

/// Adds the nodes of `scene` and their children, each placed by its
/// parent's transform times its own ([`visit`]), depth first in the file's
/// order, with an explicit stack (a chain of nodes as deep as the file
/// likes cannot overflow the program's). A node met twice is refused: the
/// glTF nodes form disjoint trees, and a cycle would never end.
fn walk(document: &gltf::Document, scene: &gltf::Scene, buffers: &[Vec<u8>], name: &str, out: &mut Loaded) -> Result<()> {
    enum Step<'a> {
        Enter(gltf::Node<'a>, Mat4, usize),
        Leave(usize),
    }
    // 0: not met yet, 1: an ancestor of the node being read, 2: read.
    let mut state = vec![0u8; document.nodes().len()];
    let roots: Vec<gltf::Node> = scene.nodes().collect();
    let mut stack: Vec<Step> = roots.into_iter().rev().map(|n| Step::Enter(n, Mat4::IDENTITY, 1)).collect();
    while let Some(step) = stack.pop() {
        let (node, parent, depth) = match step {
            Step::Leave(i) => {
                state[i] = 2;
                continue;
            }
            Step::Enter(node, parent, depth) => (node, parent, depth),
        };
        let i = node.index();
        match state[i] {
            1 => bail!("{name}: node {i} is its own ancestor (the node hierarchy has a cycle)"),
            2 => bail!("{name}: node {i} is reached twice (it has two parents, or a scene lists it twice); glTF nodes form disjoint trees"),
            _ => {}
        }
        if depth > MAX_NODE_DEPTH {
            bail!("{name}: node {i} is {depth} levels deep; at most {MAX_NODE_DEPTH} are read");
        }
        state[i] = 1;
        let world = visit(&node, parent, buffers, name, out)?;
        stack.push(Step::Leave(i));
        let children: Vec<gltf::Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| Step::Enter(c, world, depth + 1)));
    }
    Ok(())
}

/// `node`'s own transform: its matrix, or its translation, rotation and
/// scale, the rotation a unit quaternion (rounding within 1% is
/// normalised; anything else is refused, since the `gltf` crate would
/// make its matrix as it is and scale the mesh by the length squared).
fn local_transform(node: &gltf::Node, name: &str) -> Result<Mat4> {
    Ok(match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Mat4::from_cols_array_2d(&matrix),
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let q = glam::Quat::from_array(rotation);
            let length = q.length();
            if !(length.is_finite() && (length - 1.0).abs() <= 1e-2) {
                bail!("{name}: node {}: rotation {rotation:?} is not a unit quaternion (length {length})", node.index());
            }
            Mat4::from_scale_rotation_translation(Vec3::from_array(scale), q / length, Vec3::from_array(translation))
        }
    })
}

/// Adds `node`, placed by `parent` times its transform: an instance of its
/// mesh (read the first time a node places it), and the first perspective
/// camera. Returns its world transform, its children's parent.
fn visit(node: &gltf::Node, parent: Mat4, buffers: &[Vec<u8>], name: &str, out: &mut Loaded) -> Result<Mat4> {
    let world = parent * local_transform(node, name)?;
    if !world.is_finite() {
        bail!("{name}: node {} has a non-finite transform", node.index());
    }
    if world.row(3) != glam::Vec4::W {
        bail!("{name}: node {} has a projective transform (its matrix's last row is not 0, 0, 0, 1)", node.index());
    }
    if let Some(mesh) = node.mesh() {
        let slot = match out.mesh_slots[mesh.index()] {
            Some(slot) => slot,
            None => {
                let loaded = read_mesh(&mesh, buffers, name, out)?;
                let corners = loaded.triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).map(Vec3::from);
                out.mesh_bounds.push(corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p))));
                out.meshes.push(loaded);
                let slot = out.meshes.len() as u32 - 1;
                out.mesh_slots[mesh.index()] = Some(slot);
                slot
            }
        };
        // A transform finite in itself may still take the mesh's vertices past
        // f32's range (a scale of 1e30 on coordinates of 1e10): named here, by
        // node, not later by a triangle of the flattened scene.
        let (lo, hi) = out.mesh_bounds[slot as usize];
        let corner = |k: u32| Vec3::new([lo.x, hi.x][k as usize & 1], [lo.y, hi.y][(k as usize >> 1) & 1], [lo.z, hi.z][(k as usize >> 2) & 1]);
        if lo.cmple(hi).all() && (0..8).any(|k| !world.transform_point3(corner(k)).is_finite()) {
            bail!(
                "{name}: node {} places mesh {} past the range of 32-bit floats (its vertices span {lo} to {hi}; the node's transform, with its parents', scales them by up to {:e})",
                node.index(),
                mesh.index(),
                world.x_axis.truncate().length().max(world.y_axis.truncate().length()).max(world.z_axis.truncate().length())
            );
        }
        out.instances.push(SceneInstance { mesh: slot, transform: Affine3A::from_mat4(world), material: None });
    }
    if let Some(camera) = node.camera() {
        let yfov = match camera.projection() {
            gltf::camera::Projection::Perspective(p) => Some(p.yfov()),
            gltf::camera::Projection::Orthographic(_) => None,
        };
        let slot = &mut out.cameras[camera.index()];
        if slot.is_none() {
            *slot = Some(CameraNode { node: node.index(), world, yfov });
        }
        match yfov {
            Some(yfov) if out.camera.is_none() => out.camera = Some(camera_spec(name, node.index(), world, yfov)?),
            None => {
                out.orthographic.get_or_insert(node.index());
            }
            _ => {}
        }
    }
    Ok(world)
}

/// The first node that places one of the file's cameras: where, and its
/// vertical field of view (`None`: orthographic).
#[derive(Clone, Copy)]
struct CameraNode {
    node: usize,
    world: Mat4,
    yfov: Option<f32>,
}

/// A perspective camera placed by `world`, checked.
fn camera_spec(name: &str, node: usize, world: Mat4, yfov: f32) -> Result<CameraSpec> {
    let origin = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(-Vec3::Z);
    // Narrower than 1e-6 radians, the camera's basis underflows (1e-40
    // rendered black); wider, as scene files' widest (179.8 degrees).
    let widest = 2.0 * (super::file::MAX_FOV / 2.0).atan();
    if !(yfov >= 1e-6 && yfov <= widest) {
        bail!("{name}: node {node}: camera field of view {yfov} radians (it must lie between 1e-6 and {widest}, 179.8 degrees)");
    }
    if !(direction.length_squared() > 0.0 && direction.is_finite()) {
        bail!("{name}: node {node}: the camera's transform gives it no direction to look in");
    }
    // `fov` is the image plane's full height at unit distance
    // (`Camera::look`); glTF's `yfov` the whole vertical angle.
    Ok(CameraSpec::pinhole(origin.into(), direction.into(), 0.0, 2.0 * (yfov / 2.0).tan()))
}

/// Camera `index` of the file (its `cameras` array), where the first node
/// that names it places it; an error says why it cannot be used.
fn chosen_camera(name: &str, cameras: &[Option<CameraNode>], index: usize) -> Result<CameraSpec> {
    let Some(slot) = cameras.get(index) else {
        bail!("{name}: no camera {index}: the file has {} (numbered from 0 in its `cameras` list)", cameras.len());
    };
    let Some(c) = slot else {
        bail!("{name}: camera {index} is placed by no node of the scene");
    };
    match c.yfov {
        Some(yfov) => camera_spec(name, c.node, c.world, yfov),
        None => bail!("{name}: camera {index} (node {}) is orthographic; only perspective cameras are supported", c.node),
    }
}

/// A glTF mesh's triangles in its own space, every primitive's in order,
/// with their materials.
fn read_mesh(mesh: &gltf::Mesh, buffers: &[Vec<u8>], name: &str, out: &mut Loaded) -> Result<SceneMesh> {
    let mut triangles = Vec::new();
    let mut materials = Vec::new();
    for primitive in mesh.primitives() {
        let at = format!("{name}: mesh {} primitive {}", mesh.index(), primitive.index());
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            bail!("{at}: {:?} primitives are not supported (triangles only)", primitive.mode());
        }
        // The crate reads positions as three f32 and indices as unsigned
        // integers whatever the accessors say (and panics on other index
        // types): what it reads must be what they hold.
        use gltf::accessor::{DataType, Dimensions};
        let positions = primitive.get(&gltf::Semantic::Positions).with_context(|| format!("{at}: no positions"))?;
        check_accessor(&positions, &at, "POSITION", &[DataType::F32], Dimensions::Vec3)?;
        if let Some(indices) = primitive.indices() {
            check_accessor(&indices, &at, "indices", &[DataType::U8, DataType::U16, DataType::U32], Dimensions::Scalar)?;
        }
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<[f32; 3]> = reader.read_positions().with_context(|| format!("{at}: no positions"))?.collect();
        if let Some(p) = positions.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            bail!("{at}: position {p} is not finite: {:?}", positions[p]);
        }
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if indices.len() % 3 != 0 {
            bail!("{at}: {} indices, not a multiple of three", indices.len());
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            bail!("{at}: index {bad} past its {} vertices", positions.len());
        }
        let material = material(&primitive.material(), &at, out)?;
        for t in indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
            triangles.push(Triangle::new(a, b, c));
            materials.push(material);
        }
    }
    let label = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), |n| format!("mesh {} `{n}`", mesh.index()));
    Ok(SceneMesh { name: format!("{name}: {label}"), triangles, materials })
}

/// That accessor `a` (a primitive's `role`) holds `dims` of one of `types`
/// in a buffer view (quantized or sparse data, or none, is not read).
fn check_accessor(a: &gltf::Accessor, at: &str, role: &str, types: &[gltf::accessor::DataType], dims: gltf::accessor::Dimensions) -> Result<()> {
    if !types.contains(&a.data_type()) || a.dimensions() != dims || a.normalized() {
        bail!(
            "{at}: the {role} accessor {} holds {:?} of {:?}{}; Treelet reads {dims:?} of {}",
            a.index(),
            a.dimensions(),
            a.data_type(),
            if a.normalized() { ", normalized" } else { "" },
            types.iter().map(|t| format!("{t:?}")).collect::<Vec<_>>().join(" or ")
        );
    }
    if a.view().is_none() {
        bail!("{at}: the {role} accessor {} has no buffer view", a.index());
    }
    Ok(())
}

/// The path tracer's material for a glTF material (see the module doc).
fn material(m: &gltf::Material, at: &str, out: &mut Loaded) -> Result<Material> {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let color = [r, g, b];
    out.textured |= pbr.base_color_texture().is_some() || m.emissive_texture().is_some();
    let strength = m.emissive_strength().unwrap_or(1.0);
    let emission = m.emissive_factor().map(|e| e * strength);
    let what = format!("{at}: material `{}`", m.name().unwrap_or("(default)"));
    if color.iter().chain(&emission).any(|v| !v.is_finite() || *v < 0.0) || color.iter().any(|&v| v > 1.0) {
        bail!(
            "{what}: colour {color:?} and emission {emission:?} must be finite, colour in [0, 1], emission at least 0"
        );
    }
    if emission.iter().any(|&v| v > MAX_EMISSION) {
        bail!("{what}: emission {emission:?} above {MAX_EMISSION:e}");
    }
    let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
    let (kind, ior) = if transmission > 0.5 {
        let ior = m.ior().unwrap_or(1.5);
        // As scene files: past these, refraction's arithmetic gives NaN pixels.
        let (min, max) = (super::file::MIN_IOR, super::file::MAX_IOR);
        if !(ior >= min && ior <= max) {
            bail!("{what}: index of refraction {ior} (it must lie between {min} and {max})");
        }
        (GLASS, ior)
    } else if pbr.metallic_factor() >= 0.5 && pbr.roughness_factor() < 0.2 {
        (MIRROR, 0.0)
    } else {
        (DIFFUSE, 0.0)
    };
    Ok(Material { emission, kind, color, ior })
}

/// A camera for a file without one: on the +z side of the box `lo..hi`,
/// looking down -z at its centre, the box filling about the image.
fn framing((lo, hi): (Vec3, Vec3)) -> CameraSpec {
    let (center, half) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
    // An image plane 0.5 high at unit distance: the box's front face, at
    // 4.4 times its half-size, fills it with a margin of a tenth.
    let fov = 0.5;
    let distance = 1.1 * half.x.max(half.y) / (fov / 2.0) + half.z;
    CameraSpec::pinhole((center + Vec3::Z * distance.max(1e-3)).into(), [0.0, 0.0, -1.0], 0.0, fov)
}

/// A URI's path with its `%XX` escapes decoded (`my%20data.bin` names
/// `my data.bin`); a bad escape or bytes that are not UTF-8 are an error.
fn percent_decoded(uri: &str) -> Result<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        if bytes[k] == b'%' {
            let hex = uri.get(k + 1..k + 3).and_then(|h| u8::from_str_radix(h, 16).ok());
            out.push(hex.with_context(|| format!("a `%` at byte {k} not followed by two hex digits"))?);
            k += 3;
        } else {
            out.push(bytes[k]);
            k += 1;
        }
    }
    String::from_utf8(out).map_err(|_| anyhow!("its escapes decode to bytes that are not UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine as _;

    /// Two triangles (a unit square in z = 0, indexed) as a buffer: four
    /// positions, then six u16 indices.
    fn square_buffer() -> Vec<u8> {
        let mut bytes = Vec::new();
        for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
            for v in p {
                bytes.extend(v.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            bytes.extend(i.to_le_bytes());
        }
        bytes
    }

    /// A glTF document over `uri` (the buffer's), with the square placed by
    /// two nodes (a parent translation, a child scale), a camera node, and
    /// three primitives of three materials; `mode` and `index_count` let
    /// tests break it.
    fn document(uri: &str, mode: u32, index_count: u32) -> String {
        format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"],
  "scene": 0,
  "scenes": [{{"nodes": [0, 2]}}],
  "nodes": [
    {{"translation": [10, 0, 0], "children": [1]}},
    {{"scale": [2, 2, 2], "mesh": 0}},
    {{"translation": [0, 0, 9], "camera": 0}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 1.0, "znear": 0.1}}}}],
  "meshes": [{{"primitives": [
    {{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0, "mode": {mode}}},
    {{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 1}},
    {{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 2}}
  ]}}],
  "materials": [
    {{"pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.25, 1, 1], "metallicFactor": 0}}, "emissiveFactor": [1, 1, 0.5],
      "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 4}}}}}},
    {{"pbrMetallicRoughness": {{"metallicFactor": 0}}, "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1}}, "KHR_materials_ior": {{"ior": 1.33}}}}}},
    {{"pbrMetallicRoughness": {{"metallicFactor": 1, "roughnessFactor": 0}}}}
  ],
  "buffers": [{{"uri": "{uri}", "byteLength": 60}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5123, "count": {index_count}, "type": "SCALAR"}}
  ]
}}"#
        )
    }

    /// The square as a GLB file: a header, the JSON chunk (padded with
    /// spaces), the BIN chunk; and the JSON chunk's length.
    fn square_glb() -> (Vec<u8>, usize) {
        let json = document("", 4, 6).replace(r#""uri": "", "#, "");
        let mut json = json.into_bytes();
        json.resize(json.len().div_ceil(4) * 4, b' ');
        let bin = square_buffer(); // 60 bytes, a multiple of 4
        let mut chunk = (bin.len() as u32).to_le_bytes().to_vec();
        chunk.extend(b"BIN\0");
        chunk.extend(&bin);
        (glb(&json, &chunk), json.len())
    }

    /// A GLB file of a JSON chunk (padded with spaces) and `rest`, the
    /// chunks after it, as they are.
    fn glb(json: &[u8], rest: &[u8]) -> Vec<u8> {
        let mut json = json.to_vec();
        json.resize(json.len().div_ceil(4) * 4, b' ');
        let mut glb = Vec::new();
        glb.extend(b"glTF");
        glb.extend(2u32.to_le_bytes());
        glb.extend(((12 + 8 + json.len() + rest.len()) as u32).to_le_bytes());
        glb.extend((json.len() as u32).to_le_bytes());
        glb.extend(b"JSON");
        glb.extend(&json);
        glb.extend(rest);
        glb
    }

    /// Only the first buffer may be a GLB's binary chunk (it is moved into
    /// that buffer, not copied): a second that names none is refused by name.
    #[test]
    fn a_second_buffer_without_a_uri_is_refused() {
        let (square, json_len) = square_glb();
        let json = std::str::from_utf8(&square[20..20 + json_len]).unwrap();
        let two = json.replace(r#""buffers": [{"byteLength": 60}]"#, r#""buffers": [{"byteLength": 60}, {"byteLength": 60}]"#);
        let two = two.replace(r#"{"buffer": 0, "byteOffset": 48"#, r#"{"buffer": 1, "byteOffset": 48"#);
        assert_ne!(two, json, "the document changed");
        let d = dir();
        let path = d.join("twobuffers.glb");
        std::fs::write(&path, glb(two.as_bytes(), &square[20 + json_len..])).unwrap();
        let e = format!("{:#}", load(&path).unwrap_err());
        assert!(e.contains("buffer 1: the binary chunk is an earlier buffer's"), "{e}");
        std::fs::remove_dir_all(&d).ok();
    }

    fn data_uri() -> String {
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(square_buffer())
        )
    }

    fn dir() -> std::path::PathBuf {
        let d =
            std::env::temp_dir().join(format!("treelet-gltf-{}-{:?}", std::process::id(), std::thread::current().id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn check_scene(s: &Scene) {
        assert_eq!(s.triangles.len(), 6, "three primitives of two triangles");
        // The child's scale, then the parent's translation.
        assert_eq!(s.triangles[0], Triangle::new([10.0, 0.0, 0.0], [12.0, 0.0, 0.0], [12.0, 2.0, 0.0]));
        assert_eq!(s.materials.len(), 6);
        assert_eq!(
            s.materials[0],
            Material { emission: [4.0, 4.0, 2.0], kind: DIFFUSE, color: [0.5, 0.25, 1.0], ior: 0.0 }
        );
        assert_eq!((s.materials[2].kind, s.materials[2].ior), (GLASS, 1.33));
        assert_eq!(s.materials[4].kind, MIRROR);
        assert_eq!(s.camera.origin, [0.0, 0.0, 9.0]);
        assert_eq!(s.camera.direction, [0.0, 0.0, -1.0]);
        assert!((s.camera.fov - 2.0 * 0.5f32.tan()).abs() < 1e-6);
    }

    /// `--camera N` picks the file's camera N where the first node that
    /// names it places it: the square's document with four cameras (0 at
    /// the node of the default, 1 orthographic, 2 placed by two nodes, 3
    /// by none); the refusals name the camera and why.
    #[test]
    fn a_camera_is_chosen_by_its_index_in_the_file() {
        let d = dir();
        let path = d.join("cameras.gltf");
        let text = document(&data_uri(), 4, 6)
            .replace(
                r#"{"translation": [0, 0, 9], "camera": 0}"#,
                r#"{"translation": [0, 0, 9], "camera": 0}, {"translation": [0, 5, 0], "camera": 1}, {"translation": [3, 0, 7], "rotation": [0, 0.38268343, 0, 0.9238795], "camera": 2}, {"translation": [-3, 0, 7], "camera": 2}"#,
            )
            .replace(r#""nodes": [0, 2]"#, r#""nodes": [0, 2, 3, 4, 5]"#)
            .replace(
                r#""cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}]"#,
                r#""cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}, {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}, {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}, {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]"#,
            );
        assert!(text.contains(r#""camera": 2}, {"translation": [-3"#), "the document changed: {text}");
        std::fs::write(&path, &text).unwrap();
        // The default: the first perspective camera placed.
        assert_eq!(load(&path).unwrap().camera.origin, [0.0, 0.0, 9.0]);
        assert_eq!(load_with_camera(&path, Some(0)).unwrap().camera, load(&path).unwrap().camera);
        let c = load_with_camera(&path, Some(2)).unwrap().camera;
        assert_eq!(c.origin, [3.0, 0.0, 7.0], "the first node that names camera 2");
        // Turned 45 degrees about y: -z goes to (-sin 45, 0, -cos 45).
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!((c.direction[0] + h).abs() < 1e-6 && c.direction[1].abs() < 1e-6 && (c.direction[2] + h).abs() < 1e-6, "{:?}", c.direction);
        assert!((c.fov - 2.0 * 0.25f32.tan()).abs() < 1e-6);
        // In the picture: the middle pixel's ray leaves the node's place
        // along its turned axis; the top and bottom rows' (rows count up)
        // run half of yfov (0.25 radian) above and below it.
        let (w, rows) = (101, 1000);
        let camera = c.camera(w, rows);
        let (o, mid) = camera.primary_ray(w / 2, rows / 2, 0, w, rows, (0.5, 0.0));
        assert!((o - Vec3::new(3.0, 0.0, 7.0)).length() < 1e-4, "{o:?}");
        assert!((mid.normalize() - Vec3::new(-h, 0.0, -h)).length() < 1e-3, "{mid:?}");
        let elevation = |y: u32| {
            let (_, d) = camera.primary_ray(w / 2, y, 0, w, rows, (0.5, 0.5));
            d.y.atan2((d.x * d.x + d.z * d.z).sqrt())
        };
        let pixel = 1.0 / rows as f32;
        assert!((elevation(rows - 1) - 0.25).abs() < pixel, "top row at {} radians", elevation(rows - 1));
        assert!((elevation(0) + 0.25).abs() < pixel, "bottom row at {} radians", elevation(0));
        for (camera, needle) in [(1, "camera 1 (node 3) is orthographic"), (3, "camera 3 is placed by no node"), (4, "no camera 4: the file has 4")] {
            let e = load_with_camera(&path, Some(camera)).unwrap_err().to_string();
            assert!(e.contains(needle), "camera {camera}: {e}");
        }
        let e = Scene::with_gltf_camera("scenes/cornell.json", 0, true).unwrap_err().to_string();
        assert!(e.contains("only glTF scenes"), "{e}");
    }

    /// Where a glTF camera puts things in the picture: the camera at
    /// (0, 0, 9) looking down -z with `yfov` 1 radian sees the point half a
    /// radian above its axis on the image's top edge (it saw it a quarter
    /// of the way down when the loader passed the plane's half-height).
    #[test]
    fn a_gltf_camera_sees_its_whole_vertical_field_of_view() {
        let d = dir();
        let path = d.join("camera.gltf");
        std::fs::write(&path, document(&data_uri(), 4, 6)).unwrap();
        let s = load(&path).unwrap();
        let (w, h) = (64, 100);
        let camera = s.camera.camera(w, h);
        let up_angle = |y: u32| {
            let (_, dir) = camera.primary_ray(w / 2, y, 0, w, h, (0.5, 0.5));
            dir.y.atan2(-dir.z)
        };
        // Pixel centres: the top row's half a pixel below the edge.
        let pixel = 1.0 / h as f32;
        assert!((up_angle(h - 1) - 0.5).abs() < pixel, "top row at {} radians", up_angle(h - 1));
        assert!((up_angle(0) + 0.5).abs() < pixel, "bottom row at {} radians", up_angle(0));
        assert!(up_angle(h / 2).abs() < pixel);
        std::fs::remove_dir_all(&d).ok();
    }

    /// A file without a camera is framed whole: the rays of the image's
    /// edges pass outside the box's front face, those near its centre
    /// inside.
    #[test]
    fn the_default_framing_shows_the_whole_box() {
        let (lo, hi) = (Vec3::new(-1.0, -2.0, -0.5), Vec3::new(3.0, 2.0, 0.5));
        let camera = framing((lo, hi)).camera(100, 100);
        let front_at = |x: u32, y: u32| {
            let (o, dir) = camera.primary_ray(x, y, 0, 100, 100, (0.5, 0.5));
            o + dir * ((hi.z - o[2]) / dir.z)
        };
        for (x, y) in [(0, 50), (99, 50), (50, 0), (50, 99)] {
            let p = front_at(x, y);
            assert!(p.x <= lo.x || p.x >= hi.x || p.y <= lo.y || p.y >= hi.y, "pixel ({x}, {y}) lands inside the box at {p}");
        }
        let p = front_at(50, 50);
        assert!(p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y);
    }

    #[test]
    fn embedded_external_and_binary_files_load_the_same_scene() {
        let d = dir();
        let embedded = d.join("square.gltf");
        std::fs::write(&embedded, document(&data_uri(), 4, 6)).unwrap();
        check_scene(&load(&embedded).unwrap());
        std::fs::write(d.join("square.bin"), square_buffer()).unwrap();
        let external = d.join("external.gltf");
        std::fs::write(&external, document("square.bin", 4, 6)).unwrap();
        check_scene(&load(&external).unwrap());
        // A name with a space, escaped in the URI as glTF asks (`my%20data.bin`).
        std::fs::write(d.join("my data.bin"), square_buffer()).unwrap();
        let escaped = d.join("escaped.gltf");
        std::fs::write(&escaped, document("my%20data.bin", 4, 6)).unwrap();
        check_scene(&load(&escaped).unwrap());
        // GLB: a header, the JSON chunk (padded with spaces), the BIN chunk.
        let (glb, _) = square_glb();
        let binary = d.join("square.glb");
        std::fs::write(&binary, glb).unwrap();
        check_scene(&Scene::from_spec(binary.to_str().unwrap()).unwrap());
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn bad_files_fail_naming_the_problem() {
        let d = dir();
        let cases = [
            ("broken.gltf", "{ not json".to_string(), "not a valid glTF"),
            ("points.gltf", document(&data_uri(), 0, 6), "primitive 0: Points primitives are not supported"),
            ("short.gltf", document(&data_uri(), 4, 5), "not a multiple of three"),
            ("missing.gltf", document("nowhere.bin", 4, 6), "buffer 0"),
            ("remote.gltf", document("https://example.com/a.bin", 4, 6), "not a local file"),
            // Any file of the machine read as a buffer (the probe of 2026-12-02 read /etc/passwd).
            ("absolute.gltf", document("/etc/passwd", 4, 6), "`/etc/passwd` is an absolute path"),
            ("escapedabsolute.gltf", document("%2Fetc%2Fpasswd", 4, 6), "is an absolute path"),
            ("wide.gltf", document(&data_uri(), 4, 6).replace(r#""yfov": 1.0"#, r#""yfov": 3.14002"#), "179.8 degrees"),
            ("badescape.gltf", document("a%zz.bin", 4, 6), "not followed by two hex digits"),
            (
                "noaccessor.gltf",
                document(&data_uri(), 4, 6).replacen(r#""POSITION": 0"#, r#""POSITION": 7"#, 1),
                "accessor 7 does not exist",
            ),
            (
                "longview.gltf",
                document(&data_uri(), 4, 6)
                    .replace(r#""byteOffset": 48, "byteLength": 12"#, r#""byteOffset": 48, "byteLength": 40"#),
                "buffer view 1 reaches past",
            ),
            (
                "longaccessor.gltf",
                document(&data_uri(), 4, 6).replace(r#""count": 4, "type": "VEC3""#, r#""count": 5, "type": "VEC3""#),
                "accessor 0 reaches past",
            ),
            // Index and position accessors of types the crate does not read
            // as they are (float indices made it panic).
            ("floatindices.gltf", document(&data_uri(), 4, 3).replace("5123", "5126"), "indices accessor 1 holds Scalar of F32"),
            ("signedindices.gltf", document(&data_uri(), 4, 6).replace("5123", "5122"), "indices accessor 1 holds Scalar of I16"),
            ("bytepositions.gltf", document(&data_uri(), 4, 6).replace("5126", "5121"), "POSITION accessor 0 holds Vec3 of U8"),
            ("emptyaccessor.gltf", document(&data_uri(), 4, 0), "accessor 1: a count of 0"),
            // Node hierarchies that are not trees, or too deep to walk.
            ("selfchild.gltf", document(&data_uri(), 4, 6).replace(r#""children": [1]"#, r#""children": [0]"#), "node 0 is its own ancestor"),
            (
                "cycle.gltf",
                document(&data_uri(), 4, 6).replace(r#""scale": [2, 2, 2], "mesh": 0"#, r#""scale": [2, 2, 2], "mesh": 0, "children": [0]"#),
                "node 0 is its own ancestor",
            ),
            ("twoparents.gltf", document(&data_uri(), 4, 6).replace(r#""nodes": [0, 2]"#, r#""nodes": [0, 2, 1]"#), "node 1 is reached twice"),
            ("deep.gltf", deep_chain(100_000), "levels deep"),
            // The last of two keys would win silently.
            (
                "twokeys.gltf",
                document(&data_uri(), 4, 6).replace(r#""scenes": [{"nodes": [0, 2]}]"#, r#""scenes": [{"nodes": [0, 2], "nodes": [0]}]"#),
                "the key \"nodes\" appears twice",
            ),
            // Found by a probe (2026-12-02), each rendered a wrong image with exit 0:
            // a transform given twice (the crate took the matrix alone), a camera
            // too narrow for its basis, glass past the range of its arithmetic.
            (
                "matrixandscale.gltf",
                document(&data_uri(), 4, 6).replace(r#""scale": [2, 2, 2]"#, r#""scale": [2, 2, 2], "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]"#),
                "node 1 has both a matrix and translation",
            ),
            ("narrow.gltf", document(&data_uri(), 4, 6).replace(r#""yfov": 1.0"#, r#""yfov": 1e-40"#), "between 1e-6 and"),
            ("ior.gltf", document(&data_uri(), 4, 6).replace(r#""ior": 1.33"#, r#""ior": 1e30"#), "(it must lie between 0.01 and 100)"),
            // A transform finite in itself that takes the mesh past f32's range
            // (the diagonal of the square, turned 45 degrees, reaches 4.2e38):
            // named by node (it was named by a triangle of the flattened scene).
            (
                "overflow.gltf",
                document(&data_uri(), 4, 6).replace(r#""scale": [2, 2, 2]"#, r#""rotation": [0, 0, 0.38268343, 0.92387953], "scale": [3e38, 3e38, 3e38]"#),
                "node 1 places mesh 0 past the range of 32-bit floats",
            ),
            // A rotation that is no rotation; a camera Treelet cannot make.
            ("quaternion.gltf", document(&data_uri(), 4, 6).replace(r#""scale": [2, 2, 2]"#, r#""rotation": [10, 0, 0, 0]"#), "not a unit quaternion"),
            (
                "orthographic.gltf",
                document(&data_uri(), 4, 6).replace(
                    r#"{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}"#,
                    r#"{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}"#,
                ),
                "node 2: orthographic cameras are not supported",
            ),
        ];
        for (file, text, expected) in cases {
            let path = d.join(file);
            std::fs::write(&path, text).unwrap();
            let e = format!("{:#}", load(&path).unwrap_err());
            assert!(e.contains(expected) && e.contains(file), "{file}: {e}");
        }
        std::fs::remove_dir_all(&d).ok();
    }

    /// The square under a chain of `depth` nodes.
    fn deep_chain(depth: usize) -> String {
        let nodes: Vec<String> = (0..depth)
            .map(|k| if k + 1 < depth { format!(r#"{{"children": [{}]}}"#, k + 1) } else { r#"{"mesh": 0}"#.to_string() })
            .collect();
        let text = document(&data_uri(), 4, 6);
        let start = text.find("\"nodes\": [\n").unwrap();
        let end = start + text[start..].find("],\n  \"cameras\"").unwrap() + 1;
        let text = format!("{}\"nodes\": [{}]{}", &text[..start], nodes.join(","), &text[end..]);
        text.replace(r#""scenes": [{"nodes": [0, 2]}]"#, r#""scenes": [{"nodes": [0]}]"#)
    }

    #[test]
    fn extras_of_any_json_type_are_read_past() {
        // glTF allows any value in `extras`; the crate without its `extras`
        // feature refused all but objects ("expected unit").
        let d = dir();
        let path = d.join("extras.gltf");
        let text = document(&data_uri(), 4, 6).replace(r#""scale": [2, 2, 2]"#, r#""scale": [2, 2, 2], "extras": [1, "two", null]"#);
        std::fs::write(&path, text).unwrap();
        check_scene(&load(&path).unwrap());
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_slightly_unnormalised_rotation_is_normalised() {
        let d = dir();
        let path = d.join("rounded.gltf");
        let text = document(&data_uri(), 4, 6).replace(r#""scale": [2, 2, 2]"#, r#""rotation": [0, 0, 0, 1.001]"#);
        std::fs::write(&path, text).unwrap();
        let s = load(&path).unwrap();
        assert_eq!(s.triangles[0], Triangle::new([10.0, 0.0, 0.0], [11.0, 0.0, 0.0], [11.0, 1.0, 0.0]));
        std::fs::remove_dir_all(&d).ok();
    }

    /// A GLB cut anywhere, or whose lengths lie, is called truncated or
    /// corrupt, never read past its end.
    #[test]
    fn cut_glb_files_are_called_truncated() {
        let d = dir();
        let (glb, json_len) = square_glb();
        let path = d.join("cut.glb");
        for cut in [10, 16, 12 + 8 + json_len / 2, 12 + 8 + json_len + 4, glb.len() - 7] {
            std::fs::write(&path, &glb[..cut]).unwrap();
            let e = format!("{:#}", load(&path).unwrap_err());
            assert!(e.contains("truncated") && e.contains("cut.glb"), "cut at {cut}: {e}");
        }
        // A second BIN chunk (the crate read the first, silently).
        let mut two = glb.clone();
        two.extend(8u32.to_le_bytes());
        two.extend(b"BIN\0");
        two.extend([0u8; 8]);
        let total = two.len() as u32;
        two[8..12].copy_from_slice(&total.to_le_bytes());
        std::fs::write(&path, &two).unwrap();
        let e = format!("{:#}", load(&path).unwrap_err());
        assert!(e.contains("a second BIN chunk"), "{e}");
        for (length, expected) in [(8u32, "less than a header"), (u32::MAX, "truncated")] {
            let mut lying = glb.clone();
            lying[8..12].copy_from_slice(&length.to_le_bytes());
            std::fs::write(&path, &lying).unwrap();
            let e = format!("{:#}", load(&path).unwrap_err());
            assert!(e.contains(expected), "length {length}: {e}");
        }
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_mesh_placed_by_two_nodes_is_one_mesh_and_two_instances() {
        let d = dir();
        // Node 2 (the camera's) also places mesh 0.
        let text = document(&data_uri(), 4, 6).replace(r#""camera": 0}"#, r#""camera": 0, "mesh": 0}"#);
        let path = d.join("twice.gltf");
        std::fs::write(&path, &text).unwrap();
        let scene = load_instanced(&path).unwrap();
        assert_eq!((scene.meshes.len(), scene.instances.len()), (1, 2));
        assert_eq!(scene.meshes[0].triangles.len(), 6);
        assert_eq!(scene.instances[1].rows()[2][3], 9.0);
        let flat = load(&path).unwrap();
        assert_eq!(flat.triangles.len(), 12);
        // Its first material emits: no sky. Without it, the default one.
        assert_eq!(flat.environment, [0.0; 3]);
        let dark = text.replace(r#""emissiveFactor": [1, 1, 0.5],"#, "");
        let path_dark = d.join("dark.gltf");
        std::fs::write(&path_dark, dark).unwrap();
        assert_eq!(load(&path_dark).unwrap().environment, DEFAULT_SKY);
        assert_eq!(flat.triangles[6], Triangle::new([0.0, 0.0, 9.0], [1.0, 0.0, 9.0], [1.0, 1.0, 9.0]));
        // A matrix whose last row is not (0, 0, 0, 1) places nothing affinely.
        let projective = text.replace(r#""translation": [0, 0, 9], "camera": 0, "mesh": 0"#, r#""matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0.5, 0,0,0,1], "camera": 0, "mesh": 0"#);
        let path = d.join("projective.gltf");
        std::fs::write(&path, projective).unwrap();
        let e = format!("{:#}", load(&path).unwrap_err());
        assert!(e.contains("projective.gltf") && e.contains("node 2") && e.contains("projective"), "{e}");
        std::fs::remove_dir_all(&d).ok();
    }
}
