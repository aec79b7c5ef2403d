//! Instanced scenes: a top-level tree over instances of meshes
//! ([`InstanceRecord`]), each copy entered with the ray taken into its
//! mesh's space, where the mesh's own (bottom-level) tree is walked. Both
//! levels are trees in the [`crate::trace::bvh2`] layout and share its walk
//! ([`walk`]); the top level's leaves are the instances' world boxes, and
//! refer to the instances directly
//! ([`crate::layouts::bvh2::top_level_node_kernel`]). The top level lies
//! at the start of one node buffer, the bottom-level trees of every mesh
//! one after another behind it (and their leaf primitives in one leaf
//! buffer); an instance says where its mesh's start.
//!
//! Hits are the closest over all instances; at equal distances the lower
//! primitive index wins, then the instance the walk met first (the same
//! on every device: they run the same walk).
use glam::Vec3;

use crate::geometry::buffers::{Bvh2Node, InstanceRecord, LeafPrim};
use crate::geometry::features;
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::records::RecordLoad;
use crate::trace::bvh2::{walk, Level, INSTANCED_STACK_WORDS};
use crate::trace::hit::Query;

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
/// the top-level tree over `instances` (`nodes` from 0), and into the
/// bottom-level trees of their meshes (further on in `nodes`; `leaves`,
/// triangles only: `prims` holds no spheres), in one walk on one stack
/// ([`walk`]; a nested walk, the plain walk run per instance reached, is
/// faster on one instance but slower on many overlapping ones, whose
/// lanes then wait for each other: `docs/design.md`).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn trace_instances(
    o: Vec3,
    d: Vec3,
    query: Query,
    instances: &(impl RecordLoad<InstanceRecord> + ?Sized),
    nodes: &(impl RecordLoad<Bvh2Node> + ?Sized),
    leaves: &(impl RecordLoad<LeafPrim> + ?Sized),
    prims: &Prims,
) -> InstanceHit {
    let trees = Level { nodes, leaves };
    let (hit, instance) =
        walk::<{ features::TRIANGLES }, true, INSTANCED_STACK_WORDS>(o, d, Origin::NONE, &query, prims, instances, &trees);
    if hit.is_hit() {
        InstanceHit { t: hit.t, prim: hit.prim, instance }
    } else {
        InstanceHit { t: hit.t, prim: u32::MAX, instance: u32::MAX }
    }
}
