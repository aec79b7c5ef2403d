//! A render's instances of meshes (`Scene::instances`): a tree per
//! mesh and the top level over the copies, built as the engine API builds
//! them ([`InstancedTracer`]), and what the render kernel reads beside
//! them (`render::render_instanced_cs`, `treelet_core::trace::with_instances`): each
//! copy's first primitive index and material, and the materials of every
//! mesh triangle.
use anyhow::{bail, Context, Result};
use treelet_core::geometry::buffers::{Material, InstanceInfo, RenderParams, NO_MATERIAL};

use crate::bvh::tree::Accel;
use crate::runtime::backend::Backend;
use crate::scene::instances::SceneInstances;
use crate::tracer::{Instance, InstancedTracer, Quality};

/// The builder of the copies' meshes: the one asked for (`--accel`), else
/// whichever gives the least build plus trace time for the render's
/// `paths` camera paths ([`Quality::ForRays`], per mesh).
pub fn mesh_quality(asked: Accel, paths: u64) -> Quality {
    match asked {
        Accel::Lbvh => Quality::Fast,
        Accel::Trbvh => Quality::High,
        Accel::Hploc => Quality::Balanced,
        Accel::Auto | Accel::None | Accel::Sweep | Accel::Reference => Quality::ForRays(paths),
    }
}

/// The copies on one device, ready to bind.
pub struct InstancesPart<B: Backend> {
    tracer: InstancedTracer<B>,
    info: B::Buffer,
    materials: B::Buffer,
    /// Device time of the meshes' trees and the top level, ms.
    pub build_ms: f64,
}

impl<B: Backend> InstancesPart<B> {
    /// Builds every mesh's tree with `quality`'s builder and the top level
    /// over the copies; `own` is how many primitives the scene has of its
    /// own (the copies' are numbered after them).
    pub fn build(b: &mut B, copies: &SceneInstances, own: u32, quality: Quality) -> Result<Self> {
        let meshes: Vec<&[treelet_core::Triangle]> = copies.meshes.iter().map(|m| m.triangles.as_slice()).collect();
        let instances: Vec<Instance> =
            copies.instances.iter().map(|i| Instance { mesh: i.mesh, transform: i.rows() }).collect();
        let tracer = InstancedTracer::build(b, &meshes, &instances, quality).context("the instances")?;
        let bound = tracer.instance_bindings();
        // Every mesh triangle's material where the mesh's triangles start,
        // then the copies' own materials.
        let mut materials = vec![Material::default(); bound.triangle_count as usize];
        for (mesh, &base) in copies.meshes.iter().zip(&bound.mesh_triangle_bases) {
            materials[base as usize..base as usize + mesh.materials.len()].copy_from_slice(&mesh.materials);
        }
        let mut info = Vec::with_capacity(copies.instances.len());
        let mut first = 0u64;
        for instance in &copies.instances {
            let material = match instance.material {
                Some(m) => {
                    materials.push(m);
                    materials.len() as u32 - 1
                }
                None => NO_MATERIAL,
            };
            info.push(InstanceInfo { first: first as u32, material, _pad: [0; 2] });
            first += copies.meshes[instance.mesh as usize].triangles.len() as u64;
        }
        if own as u64 + first >= u32::MAX as u64 {
            bail!("{first} instanced triangles beside the scene's own {own}: the renderer numbers primitives in 32 bits");
        }
        let info = b.upload("instance info", &info)?;
        let materials = b.upload("instance materials", &materials)?;
        let build_ms = tracer.last_update_ms();
        Ok(InstancesPart { tracer, info, materials, build_ms })
    }

    /// `params` with the copies' counts.
    pub fn params(&self, params: RenderParams) -> RenderParams {
        let bound = self.tracer.instance_bindings();
        RenderParams { instances: bound.instances, instance_triangles: bound.triangle_count, ..params }
    }

    /// The kernel's bindings after the scene's own (8 to 13): records,
    /// their infos, nodes, leaf primitives, triangles, materials.
    pub fn bindings(&self) -> [&B::Buffer; 6] {
        let bound = self.tracer.instance_bindings();
        [bound.records, &self.info, bound.nodes, bound.leaves, bound.triangles, &self.materials]
    }
}
