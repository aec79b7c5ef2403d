//! Instanced scenes: a top-level tree over placed copies of meshes
//! ([`InstanceRecord`]), each copy entered with the ray taken into its
//! mesh's space, where the mesh's own (bottom-level) tree is walked. Both
//! levels are trees in the [`crate::trace::bvh2`] layout and share its walk
//! ([`walk_bvh2`]); the top level's leaf primitives are the instances'
//! world boxes, their `prim` the instance's index. The bottom-level trees
//! of every mesh lie one after another in one node buffer and one leaf
//! buffer; an instance says where its mesh's start ([`Based`]).
//!
//! Hits are the closest over all instances, ties to the lower instance and
//! then to the lower primitive, so every order of the walk finds the same.
use glam::Vec3;

use crate::geometry::buffers::{Bvh2Node, InstanceRecord, LeafPrim};
use crate::geometry::features;
use crate::geometry::intersect::SlabRay;
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::records::{Based, RecordLoad};
use crate::geometry::triangle::WatertightRay;
use crate::trace::bvh2::{leaf, walk_bvh2};
use crate::trace::hit::{Hit, Query};

/// The closest (or, for an occlusion query, the first found) hit in an
/// instanced scene: distance, the primitive within its mesh and the
/// instance (both `u32::MAX` for none).
#[derive(Clone, Copy)]
pub struct InstanceHit {
    pub t: f32,
    pub prim: u32,
    pub instance: u32,
}

impl InstanceHit {
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.instance != u32::MAX
    }
}

/// Traces `o + t d` (`d` of unit length, so that `t` is a distance) through
/// the top-level tree `top_nodes`/`top_leaves` over `instances`, and into
/// the bottom-level trees of their meshes (`nodes`, `leaves`, triangles
/// only: `prims` holds no spheres). `query` as for any traversal.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn trace_instances(
    o: Vec3,
    d: Vec3,
    query: Query,
    top_nodes: &(impl RecordLoad<Bvh2Node> + ?Sized),
    top_leaves: &(impl RecordLoad<LeafPrim> + ?Sized),
    instances: &(impl RecordLoad<InstanceRecord> + ?Sized),
    nodes: &(impl RecordLoad<Bvh2Node> + ?Sized),
    leaves: &(impl RecordLoad<LeafPrim> + ?Sized),
    prims: &Prims,
) -> InstanceHit {
    // The top level's hit holds the instance as its primitive, so that
    // equal distances go to the lower instance; the primitive within it
    // is kept beside.
    let mut prim = u32::MAX;
    let top = walk_bvh2(&SlabRay::new(o, d), &query, top_nodes, |hit, first, count| {
        let mut k = 0;
        while k < count && !query.done(hit) {
            let instance = top_leaves.load((first + k) as usize).prim;
            let record = instances.load(instance as usize);
            let (o2, d2) = record.to_object(o, d);
            // Only hits nearer than the best so far (or as near, for the tie-break).
            let inner = Query { t_max: hit.t, skip: u32::MAX, any: query.any };
            let ray = WatertightRay::new(o2, d2);
            let mesh_leaves = Based { records: leaves, base: record.leaf_base };
            let found = walk_bvh2(&SlabRay::new(o2, d2), &inner, &Based { records: nodes, base: record.node_base }, |h, f, c| {
                leaf::<{ features::TRIANGLES }>(h, f, c, (o2, d2, Origin::NONE), &inner, &ray, prims, &mesh_leaves)
            });
            if found.is_hit() && hit.is_beaten_by(found.t, instance) {
                *hit = Hit { t: found.t, prim: instance };
                prim = found.prim;
            }
            k += 1;
        }
    });
    if top.is_hit() {
        InstanceHit { t: top.t, prim, instance: top.prim }
    } else {
        InstanceHit { t: top.t, prim: u32::MAX, instance: u32::MAX }
    }
}
