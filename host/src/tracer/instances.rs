//! Instanced scenes for engines: each mesh gets its own (bottom-level)
//! tree, built once and refit or rebuilt only when the mesh changes; the
//! scene places meshes many times with 3x4 transforms, and a top-level tree
//! over the instances, cheap to rebuild every frame, finds which copies
//! a ray meets. Both levels are traced in one kernel
//! (`treelet_core::trace::instances`), on the GPU or the CPU runner.
//!
//! ```
//! use treelet::{CpuBackend, Instance, InstancedTracer, Quality, Ray, Triangle};
//! let quad = [Triangle::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), Triangle::new([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0])];
//! let b = &mut CpuBackend::new();
//! // The quad twice: at z = 5, and at z = 9.
//! let placed = [Instance::translated(0, [0.0, 0.0, 5.0]), Instance::translated(0, [0.0, 0.0, 9.0])];
//! let mut scene = InstancedTracer::build(b, &[&quad], &placed, Quality::Fast)?;
//! let ray = Ray::new([0.7, 0.6, 0.0], [0.0, 0.0, 1.0]);
//! let hit = scene.closest_hits(b, &[ray])?[0];
//! assert_eq!((hit.t, hit.instance, hit.prim), (5.0, 0, 1));
//! // Next frame: the first copy moves away; only the top level is rebuilt.
//! scene.set_instances(b, &[Instance::translated(0, [4.0, 0.0, 5.0]), placed[1]])?;
//! assert_eq!(scene.closest_hits(b, &[ray])?[0].instance, 1);
//! # anyhow::Ok(())
//! ```
use anyhow::{Context, Result};
use treelet_core::geometry::buffers::{LayoutParams, MeshRecord, InstanceDesc, RenderParams};
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::{groups_for, WORKGROUP_SIZE};
use treelet_core::render::integrator::tiled_invocations;
use treelet_core::render::rays::{CAST_OCCLUDED, CAST_RAYS};
use treelet_core::trace::hit::STACK_DEPTH;

use super::engine_mesh::MeshBuffers;
use super::primitives::{Quality, Tracer};
use super::queries::{collect_hits, collect_occluded, ray_queries};
use super::rays::{batch_dims, Ray, RayHit};
use crate::bvh::lbvh;
use crate::runtime::backend::{Backend, StageTimes};
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};

kernel_set! {
    /// The kernels of an instanced world's top level and walk (the meshes'
    /// trees are built as any tree).
    pub struct InstanceKernels for b {
        /// The instances' records and world boxes: the top level's first pass.
        bounds: Kernel::InstanceBounds,
        /// The top level's nodes, with its depth.
        top_nodes: Kernel::TopLevelNodes,
        cast: Kernel::CastInstances,
    }
}

/// A placed copy of mesh `mesh` (its index in the list given to
/// [`InstancedTracer::build`]): `transform` takes the mesh's points into
/// the world, as the rows of a 3x4 matrix (`world = M · (x, y, z, 1)`). Any
/// invertible transform: rotations, scales (also negative or unequal),
/// shears, translations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub mesh: u32,
    pub transform: [[f32; 4]; 3],
}

impl Instance {
    /// The transform that leaves a mesh where it is.
    pub const IDENTITY: [[f32; 4]; 3] = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]];

    /// Mesh `mesh` moved by `offset`.
    pub fn translated(mesh: u32, offset: [f32; 3]) -> Instance {
        let mut transform = Self::IDENTITY;
        for (row, o) in transform.iter_mut().zip(offset) {
            row[3] = o;
        }
        Instance { mesh, transform }
    }
}

/// Every mesh's tree and triangles, one mesh after another in one buffer
/// each (what the instanced kernel binds), and where each mesh's start;
/// the node buffer holds the top level first (rebuilt in place).
struct Gathered<B: Backend> {
    nodes: B::Buffer,
    /// Nodes at the start of `nodes` for the top level.
    top_capacity: u32,
    leaves: B::Buffer,
    triangles: B::Buffer,
    /// Per mesh: its box and bases, as the top level's build reads them.
    meshes: B::Buffer,
    /// Per mesh: first node, first leaf primitive, first triangle.
    bases: Vec<[u32; 3]>,
    /// Per mesh: its layout's node count (a refit may change it: the SAH
    /// leaf collapse decides anew on the new boxes).
    node_counts: Vec<u32>,
    triangle_count: u32,
}

/// The instances as the kernel reads them; their top-level tree (`bvh2`
/// nodes whose leaves refer to instances) is at the start of the gathered
/// nodes.
struct TopLevel<B: Backend> {
    records: B::Buffer,
    count: u32,
}

/// The buffers a render binds for its instances
/// ([`InstancedTracer::instance_bindings`]): the instances' records (a
/// placeholder without any), every node (the top level, then each mesh's
/// tree), leaf primitive and triangle, and where each mesh's triangles
/// start.
pub(crate) struct InstanceBindings<'a, B: Backend> {
    pub records: &'a B::Buffer,
    pub nodes: &'a B::Buffer,
    pub leaves: &'a B::Buffer,
    pub triangles: &'a B::Buffer,
    pub triangle_count: u32,
    pub instances: u32,
    pub mesh_triangle_bases: Vec<u32>,
}

/// Meshes placed many times, on one device, for closest hits and occlusion
/// queries: see the module doc.
///
/// Speed, as measured (H100, `treelet bench instances`,
/// `docs/results/h100-instances-toplevel-2026-11-26/`): the mesh as one
/// instance in place traces at about two thirds of the rays/s of the mesh
/// alone in a [`Tracer`] (the walk's own cost); 1 024 overlapping copies of
/// the 940k-triangle bunny at 0.29-0.41x; the top level rebuilds in 0.17
/// ms of device time for 1 000 instances and 0.29 ms for 100 000 (5-10 ms
/// of wall time with the upload). Place meshes with this type where the
/// scene needs instances; a mesh alone traces faster with [`Tracer`].
pub struct InstancedTracer<B: Backend> {
    meshes: Vec<Tracer<B>>,
    /// Each mesh's box in its own space.
    bounds: Vec<[[f64; 3]; 2]>,
    gathered: Gathered<B>,
    top: Option<TopLevel<B>>,
    instances: Vec<Instance>,
    /// Placeholders: the kernel's sphere binding (instanced meshes are
    /// triangles), and its instances' while there are none.
    no_spheres: B::Buffer,
    no_instances: B::Buffer,
    update_ms: f64,
    top_stages: StageTimes,
}

impl<B: Backend> InstancedTracer<B> {
    /// Builds a tree per mesh (with `quality`'s builder) and the top-level
    /// tree over `instances`. Every mesh needs a triangle; bad input (a
    /// non-finite vertex, an instance of a mesh that is not there, a
    /// non-finite or singular transform) is refused by name.
    pub fn build(b: &mut B, meshes: &[&[Triangle]], instances: &[Instance], quality: Quality) -> crate::error::Result<Self> {
        crate::error::typed(|| {
            if meshes.len() > u32::MAX as usize {
                return Err(crate::error::too_large(format!("{} meshes: at most {} are supported", meshes.len(), u32::MAX)));
            }
            let mut trees = Vec::with_capacity(meshes.len());
            let mut bounds = Vec::with_capacity(meshes.len());
            let mut update_ms = 0.0;
            for (m, triangles) in meshes.iter().enumerate() {
                if triangles.is_empty() {
                    return Err(crate::error::input(format!("mesh {m} has no triangles: every instanced mesh needs one")));
                }
                only_triangles(triangles).with_context(|| format!("mesh {m}"))?;
                let tracer = Tracer::build(b, &[], triangles, quality).with_context(|| format!("mesh {m}"))?;
                update_ms += tracer.last_update_ms();
                trees.push(tracer);
                bounds.push(mesh_bounds(triangles));
            }
            Self::from_trees(b, trees, bounds, instances, update_ms)
        })
    }

    /// [`Self::build`] over meshes in an engine's own buffers (see
    /// [`Tracer::build_from_buffers`]): mesh `k` is `meshes[k]`, gathered
    /// and built on the device; each mesh's box is read from its tree's root
    /// (64 bytes a mesh).
    pub fn build_from_buffers(b: &mut B, meshes: &[MeshBuffers<B>], instances: &[Instance], quality: Quality) -> crate::error::Result<Self> {
        crate::error::typed(|| {
            if meshes.len() > u32::MAX as usize {
                return Err(crate::error::too_large(format!("{} meshes: at most {} are supported", meshes.len(), u32::MAX)));
            }
            let mut trees = Vec::with_capacity(meshes.len());
            let mut bounds = Vec::with_capacity(meshes.len());
            let mut update_ms = 0.0;
            for (m, mesh) in meshes.iter().enumerate() {
                if mesh.triangle_count == 0 {
                    return Err(crate::error::input(format!("mesh {m} has no triangles: every instanced mesh needs one")));
                }
                let tracer = Tracer::build_from_buffers(b, mesh, quality).with_context(|| format!("mesh {m}"))?;
                update_ms += tracer.last_update_ms();
                bounds.push(tracer.layout_bounds(b)?);
                trees.push(tracer);
            }
            Self::from_trees(b, trees, bounds, instances, update_ms)
        })
    }

    /// The scene over meshes whose trees are built: their layouts gathered,
    /// then the top level over `instances`.
    fn from_trees(b: &mut B, trees: Vec<Tracer<B>>, bounds: Vec<[[f64; 3]; 2]>, instances: &[Instance], update_ms: f64) -> Result<Self> {
        // The top level's kernels (the meshes' trees prepared theirs).
        b.prepare_kernels(&[lbvh::kernels(b), InstanceKernels::of(b).all()].concat());
        let gathered = gather(b, &trees, &bounds, top_nodes_for(instances.len()))?;
        let no_spheres = b.upload("no spheres", &[treelet_core::Sphere::default()])?;
        let no_instances = b.zeroed("no instances", 64)?;
        b.keep(&[&no_spheres, &no_instances]);
        let mut scene = InstancedTracer {
            meshes: trees,
            bounds,
            gathered,
            top: None,
            instances: Vec::new(),
            no_spheres,
            no_instances,
            update_ms: 0.0,
            top_stages: StageTimes::default(),
        };
        scene.set_instances(b, instances)?;
        scene.update_ms += update_ms;
        Ok(scene)
    }

    /// [`Self::build`] over a scene loaded with its instances kept
    /// ([`crate::scene::instanced::InstancedScene::load`]: glTF nodes, a scene file's
    /// copies): mesh `k` of the scene is mesh `k` here, and its instances
    /// keep their order. The scene's loose triangles (in world space) are
    /// one more mesh, placed once where it is, after the scene's; spheres,
    /// disks and parallelograms are refused by name (the instanced walk
    /// tests triangles only). Materials are the renderer's; hits carry
    /// mesh and primitive, by which an engine finds its own.
    pub fn build_scene(b: &mut B, scene: &crate::scene::instanced::InstancedScene, quality: Quality) -> crate::error::Result<Self> {
        crate::error::typed(|| {
            let name = &scene.loose.name;
            if !scene.loose.spheres.is_empty() {
                return Err(crate::error::input(format!("{name}: {} spheres: instanced scenes take triangles only", scene.loose.spheres.len())));
            }
            let mut meshes: Vec<&[Triangle]> = scene.meshes.iter().map(|m| m.triangles.as_slice()).collect();
            let mut instances: Vec<Instance> =
                scene.instances.iter().map(|i| Instance { mesh: i.mesh, transform: i.rows() }).collect();
            if !scene.loose.triangles.is_empty() {
                only_triangles(&scene.loose.triangles).with_context(|| format!("{name}: the scene's own (not instanced) primitives"))?;
                instances.push(Instance { mesh: meshes.len() as u32, transform: Instance::IDENTITY });
                meshes.push(&scene.loose.triangles);
            }
            Self::build(b, &meshes, &instances, quality).with_context(|| format!("{name}"))
        })
    }

    /// Places the meshes anew (any number of instances, any transforms):
    /// rebuilds the top-level tree only.
    pub fn set_instances(&mut self, b: &mut B, instances: &[Instance]) -> crate::error::Result<()> {
        crate::error::typed(|| {
            let descs = self.descs(instances)?;
            self.instances = instances.to_vec();
            self.top = None;
            self.update_ms = 0.0;
            if instances.is_empty() {
                return Ok(());
            }
            let needed = top_nodes_for(descs.len());
            if needed > self.gathered.top_capacity {
                // Room for twice as many, so that a growing scene gathers its
                // meshes again only now and then.
                self.gathered = gather(b, &self.meshes, &self.bounds, needed.saturating_mul(2))?;
            }
            let (top, stages) = build_top_level(b, &descs, &self.gathered)?;
            self.top = Some(top);
            self.update_ms = stages.total();
            self.top_stages = stages;
            Ok(())
        })
    }

    /// Moves the triangles of mesh `mesh` (the same count, in the same
    /// order): its tree is refit (see [`Tracer::refit`]), its part of the
    /// gathered buffers copied again, and the top level rebuilt over the
    /// instances' new boxes.
    pub fn refit_mesh(&mut self, b: &mut B, mesh: usize, triangles: &[Triangle]) -> crate::error::Result<()> {
        crate::error::typed(|| {
            let Some(tracer) = self.meshes.get_mut(mesh) else {
                return Err(crate::error::input(format!("refit of mesh {mesh}: there are {} meshes", self.meshes.len())));
            };
            only_triangles(triangles).with_context(|| format!("mesh {mesh}"))?;
            tracer.refit(b, &[], triangles).with_context(|| format!("mesh {mesh}"))?;
            self.after_mesh_refit(b, mesh, mesh_bounds(triangles))
        })
    }

    /// [`Self::refit_mesh`] from an engine's buffers (see
    /// [`Tracer::refit_from_buffers`]); the mesh's new box is read from its
    /// tree's root.
    pub fn refit_mesh_from_buffers(&mut self, b: &mut B, mesh: usize, buffers: &MeshBuffers<B>) -> crate::error::Result<()> {
        crate::error::typed(|| {
            let Some(tracer) = self.meshes.get_mut(mesh) else {
                return Err(crate::error::input(format!("refit of mesh {mesh}: there are {} meshes", self.meshes.len())));
            };
            tracer.refit_from_buffers(b, buffers).with_context(|| format!("mesh {mesh}"))?;
            let bounds = tracer.layout_bounds(b)?;
            self.after_mesh_refit(b, mesh, bounds)
        })
    }

    /// After mesh `mesh`'s tree was refit (its new box `bounds`): its part
    /// of the gathered buffers, and the top level.
    fn after_mesh_refit(&mut self, b: &mut B, mesh: usize, bounds: [[f64; 3]; 2]) -> Result<()> {
        let refit_ms = self.meshes[mesh].last_update_ms();
        self.bounds[mesh] = bounds;
        let nodes = self.meshes[mesh].tree.as_ref().map_or(0, |t| t.node_count);
        if nodes == self.gathered.node_counts[mesh] {
            copy_mesh(b, &self.meshes[mesh], &self.gathered, mesh)?;
            self.gathered.meshes = mesh_records(b, &self.gathered.bases, &self.bounds)?;
        } else {
            // The mesh's layout changed size: every mesh moves.
            self.gathered = gather(b, &self.meshes, &self.bounds, self.gathered.top_capacity)?;
        }
        let instances = std::mem::take(&mut self.instances);
        self.set_instances(b, &instances)?;
        self.update_ms += refit_ms;
        Ok(())
    }

    /// Device time of the last update ([`Self::build`], [`Self::set_instances`],
    /// [`Self::refit_mesh`]), in ms, as [`Tracer::last_update_ms`].
    pub fn last_update_ms(&self) -> f64 {
        self.update_ms
    }

    /// The stages of the last top-level build, device ms each (the LBVH's,
    /// whose `bounds` makes the instances' records and boxes; `layout`,
    /// with the depth check).
    pub fn top_level_stages(&self) -> &StageTimes {
        &self.top_stages
    }

    /// The instances as placed now.
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// The closest hit of each ray: as [`Tracer::closest_hits`], with the
    /// instance hit, the primitive within its mesh, and the geometric normal
    /// in world space. Rays in another form than a slice:
    /// [`RayQueries::closest_hits_with`](crate::tracer::RayQueries::closest_hits_with).
    pub fn closest_hits(&self, b: &mut B, rays: &[Ray]) -> crate::error::Result<Vec<RayHit>> {
        collect_hits(self, b, rays)
    }

    /// Whether each ray hits anything up to its `t_max`, as [`Tracer::occluded`].
    pub fn occluded(&self, b: &mut B, rays: &[Ray]) -> crate::error::Result<Vec<bool>> {
        collect_occluded(self, b, rays)
    }

    /// Whether no instance is placed (every ray misses).
    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// [`Tracer::closest_hits_on_device`] through the instances: the same
    /// layout, and the second vector of a hit holds the bits of the
    /// instance in its last word.
    pub fn closest_hits_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> crate::error::Result<()> {
        crate::error::typed(|| self.cast_on_device(b, rays, count, CAST_RAYS))
    }

    /// [`Tracer::occluded_on_device`] through the instances.
    pub fn occluded_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> crate::error::Result<()> {
        crate::error::typed(|| self.cast_on_device(b, rays, count, CAST_OCCLUDED))
    }

    fn cast_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize, cast_mode: u32) -> Result<()> {
        let (width, height) = batch_dims(count)?;
        let Some(top) = &self.top else {
            // No instances: every ray misses. The kernel still writes the misses.
            let p = RenderParams { width, height, cast_mode, instances: 0, ..Default::default() };
            return self.dispatch(b, &p, rays, None);
        };
        let p = RenderParams {
            width,
            height,
            triangles: self.gathered.triangle_count,
            cast_mode,
            instances: top.count,
            ..Default::default()
        };
        self.dispatch(b, &p, rays, Some(top))
    }

    fn dispatch(&self, b: &mut B, p: &RenderParams, rays: &B::Buffer, top: Option<&TopLevel<B>>) -> Result<()> {
        let params = b.upload("trace params", &[*p])?;
        let g = &self.gathered;
        // With no instances, the instances' binding is never read.
        let records = top.map_or(&self.no_instances, |t| &t.records);
        b.stage("trace");
        let cast = InstanceKernels::of(b).cast;
        b.dispatch(
            cast,
            &[&params, records, &g.nodes, &g.leaves, &self.no_spheres, &g.triangles, rays],
            groups_for(tiled_invocations(p.width, p.height), cast.workgroup_size()),
        );
        Ok(())
    }

    /// What a render kernel binds of these copies
    /// (`treelet_core::trace::with_instances`).
    pub(crate) fn instance_bindings(&self) -> InstanceBindings<'_, B> {
        let g = &self.gathered;
        InstanceBindings {
            records: self.top.as_ref().map_or(&self.no_instances, |t| &t.records),
            nodes: &g.nodes,
            leaves: &g.leaves,
            triangles: &g.triangles,
            triangle_count: g.triangle_count,
            instances: self.top.as_ref().map_or(0, |t| t.count),
            mesh_triangle_bases: g.bases.iter().map(|b| b[2]).collect(),
        }
    }

    /// `instances` as the top level's build reads them, after checking them.
    fn descs(&self, instances: &[Instance]) -> Result<Vec<InstanceDesc>> {
        if instances.len() > (u32::MAX / 2) as usize {
            return Err(crate::error::too_large(format!("{} instances: at most {} are supported", instances.len(), u32::MAX / 2)));
        }
        instances
            .iter()
            .enumerate()
            .map(|(k, i)| {
                if i.mesh as usize >= self.meshes.len() {
                    return Err(crate::error::input(format!("instances[{k}] places mesh {}, but there are {} meshes", i.mesh, self.meshes.len())));
                }
                check_transform(&i.transform).with_context(|| format!("instances[{k}]"))?;
                Ok(InstanceDesc { world_from_object: i.transform, mesh: i.mesh, _pad: [0; 3] })
            })
            .collect()
    }
}

/// The top level over `descs` (at least one), on the device: the
/// instances' records and world boxes (`treelet_core::construct::instances`)
/// as the LBVH's first pass, the LBVH (one instance a leaf), and its `bvh2`
/// nodes in the LBVH's order (no compaction: leaves refer to instances),
/// written at the start of the gathered nodes, its depth checked against
/// the walk's stack in the same dispatch.
fn build_top_level<B: Backend>(b: &mut B, descs: &[InstanceDesc], g: &Gathered<B>) -> Result<(TopLevel<B>, StageTimes)> {
    let n = descs.len() as u32;
    let mut records = None;
    let (bvh, mut stages) = lbvh::build_over_boxes(b, n, |b, p, boxes, bounds, groups| {
        let input = b.upload("instance descs", descs)?;
        let out = b.scratch("instance records", n as u64 * 64)?;
        let bounds = bind::InstanceBounds { params: p, descs: &input, meshes: &g.meshes, records: &out, boxes, bounds };
        b.dispatch_with(InstanceKernels::of(b).bounds, bounds, groups);
        records = Some(out);
        Ok(())
    })?;
    let records = records.context("internal: the top level's first pass did not run")?;
    // The nodes, and the depth checked in the same dispatch (the scene is
    // refused after, if too deep: nothing traces the nodes before).
    b.stage("layout");
    let internal = top_nodes_for(descs.len());
    anyhow::ensure!(internal <= g.top_capacity, "internal: no room for the top level");
    let p = b.upload("layout params", &[LayoutParams { n, nodes: bvh.node_count, ..Default::default() }])?;
    let deepest = b.zeroed("tree depth", 4)?;
    let bindings = bind::TopLevelNodes { params: &p, nodes: &bvh.nodes, prim_indices: &bvh.prim_indices, out: &g.nodes, parents: &bvh.parents, deepest: &deepest };
    b.dispatch_with(InstanceKernels::of(b).top_nodes, bindings, groups_for(bvh.node_count.max(internal), WORKGROUP_SIZE));
    let deepest = b.read::<u32>(&deepest, 1)?[0];
    if deepest as usize + 1 > STACK_DEPTH {
        return Err(crate::error::too_large(format!("the top level is {deepest} or more levels deep; traversal supports {}", STACK_DEPTH - 1)));
    }
    let rest = b.take_times()?;
    for stage in &rest.order {
        stages.add(stage, rest.get(stage));
    }
    b.keep(&[&records]);
    Ok((TopLevel { records, count: n }, stages))
}

/// `bvh2` nodes of the top level over `instances` (one for none or one).
fn top_nodes_for(instances: usize) -> u32 {
    instances.saturating_sub(1).clamp(1, u32::MAX as usize) as u32
}

/// Refuses a non-finite or singular transform (in f64, relative to the
/// matrix's own scale: a flattened copy has no inside, and its inverse no
/// meaning). The device inverts it.
fn check_transform(m: &[[f32; 4]; 3]) -> Result<()> {
    if m.iter().flatten().any(|x| !x.is_finite()) {
        return Err(crate::error::input(format!("the transform has a non-finite entry: {m:?}")));
    }
    let a = |r: usize, c: usize| m[r][c] as f64;
    let cof = |r: usize, c: usize| {
        let (r1, r2, c1, c2) = ((r + 1) % 3, (r + 2) % 3, (c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let det = a(0, 0) * cof(0, 0) + a(0, 1) * cof(0, 1) + a(0, 2) * cof(0, 2);
    let scale = (0..9).map(|k| a(k / 3, k % 3).abs()).fold(0.0f64, f64::max);
    if !(det.abs() > 1e-12 * scale * scale * scale) {
        return Err(crate::error::input(format!("the transform is singular (determinant {det:e}): it flattens the mesh")));
    }
    // The inverse's entries are cofactors over the determinant.
    let largest = (0..9).map(|k| cof(k / 3, k % 3).abs()).fold(0.0f64, f64::max) / det.abs();
    let shift = (0..3).map(|r| a(r, 3).abs()).fold(0.0f64, f64::max);
    if !(largest * (1.0 + shift) * 3.0 < f32::MAX as f64) {
        return Err(crate::error::input(format!("the transform's inverse overflows f32: {m:?}")));
    }
    Ok(())
}

/// Instanced meshes are walked by the triangle test alone (a kernel with
/// fewer registers): a disk or parallelogram among them is refused by name.
fn only_triangles(triangles: &[Triangle]) -> Result<()> {
    match triangles.iter().position(|t| !t.is_triangle()) {
        Some(i) => return Err(crate::error::input(format!("triangle {i} has shape {} (a disk or parallelogram): instanced meshes take triangles only", triangles[i].shape))),
        None => Ok(()),
    }
}

/// The box of a mesh's triangles, in f64.
fn mesh_bounds(triangles: &[Triangle]) -> [[f64; 3]; 2] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in triangles {
        for v in [t.v0, t.v1, t.v2] {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k] as f64);
                hi[k] = hi[k].max(v[k] as f64);
            }
        }
    }
    [lo, hi]
}

/// Gathers every mesh's layout and triangles into one buffer each.
fn gather<B: Backend>(b: &mut B, meshes: &[Tracer<B>], bounds: &[[[f64; 3]; 2]], top_capacity: u32) -> Result<Gathered<B>> {
    let mut bases = Vec::with_capacity(meshes.len());
    let mut node_counts = Vec::with_capacity(meshes.len());
    let (mut nodes, mut leaves, mut triangles) = (top_capacity as u64, 0u64, 0u64);
    for t in meshes {
        let tree = t.tree.as_ref().context("internal: an instanced mesh without a tree")?;
        bases.push([nodes, leaves, triangles].map(|x| x as u32));
        node_counts.push(tree.node_count);
        nodes += tree.node_count as u64;
        leaves += t.counts.1 as u64;
        triangles += t.counts.1 as u64;
        if nodes > u32::MAX as u64 / 16 || leaves > u32::MAX as u64 / 12 {
            return Err(crate::error::too_large(format!("the meshes hold {triangles} triangles together: too many for one instanced scene")));
        }
    }
    let gathered = Gathered {
        meshes: mesh_records(b, &bases, bounds)?,
        nodes: b.scratch("instanced nodes", nodes * 64)?,
        top_capacity,
        leaves: b.scratch("instanced leaf primitives", leaves * 48)?,
        triangles: b.scratch("instanced triangles", triangles * 48)?,
        bases,
        node_counts,
        triangle_count: triangles as u32,
    };
    b.keep(&[&gathered.nodes, &gathered.leaves, &gathered.triangles]);
    for (m, t) in meshes.iter().enumerate() {
        copy_mesh(b, t, &gathered, m)?;
    }
    Ok(gathered)
}

/// Copies mesh `m`'s layout and triangles into their places in `g`.
fn copy_mesh<B: Backend>(b: &mut B, t: &Tracer<B>, g: &Gathered<B>, m: usize) -> Result<()> {
    let tree = t.tree.as_ref().context("internal: an instanced mesh without a tree")?;
    let [node_base, leaf_base, triangle_base] = g.bases[m];
    let triangles = t.counts.1 as u32;
    b.stage("gather meshes");
    for (src, dst, base, words_each, count) in [
        (&tree.nodes, &g.nodes, node_base, 16, tree.node_count),
        (&tree.prims, &g.leaves, leaf_base, 12, triangles),
        (&t.prims.triangles, &g.triangles, triangle_base, 12, triangles),
    ] {
        b.copy_words((src, 0), (dst, base * words_each), count * words_each)?;
    }
    Ok(())
}

/// The meshes' boxes and bases, on the device (kept).
fn mesh_records<B: Backend>(b: &mut B, bases: &[[u32; 3]], bounds: &[[[f64; 3]; 2]]) -> Result<B::Buffer> {
    let records: Vec<MeshRecord> = bases
        .iter()
        .zip(bounds)
        .map(|(&[node_base, leaf_base, triangle_base], [lo, hi])| MeshRecord {
            // f32 vertices' extremes: exact in f32.
            min: lo.map(|x| x as f32),
            node_base,
            max: hi.map(|x| x as f32),
            leaf_base,
            triangle_base,
            _pad: [0; 3],
        })
        .collect();
    let buffer = b.upload("instanced meshes", &records)?;
    b.keep(&[&buffer]);
    Ok(buffer)
}

ray_queries!(InstancedTracer);
