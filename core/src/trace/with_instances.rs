//! Scenes with instances of meshes, as the renderer traces them: the
//! scene's own primitives through their tree (any [`ClosestHit`]), then the
//! copies through the instanced walk ([`crate::trace::instances`]) up to
//! the hit found, so that a copy is never flattened into the scene's
//! arrays (a thousand copies of a million triangles stay one million).
//!
//! Primitives keep one index space, so that the path tracer shades, skips
//! and samples by index as it does without copies: the scene's own first
//! (`0..prims.count()`), then each copy's triangles in turn, from its
//! [`InstanceInfo::first`] on. Lamps are never placed: the host keeps the
//! copies of an emitting mesh among the scene's own triangles, where the
//! light table samples them one by one.
use glam::Vec3;

use crate::geometry::buffers::{Bvh2Node, InstanceRecord, LeafPrim, Material, InstanceInfo, NO_MATERIAL};
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::records::RecordLoad;
use crate::trace::bvh2::Level;
use crate::trace::hit::{ClosestHit, Hit, Query};
use crate::trace::instances::trace_instances;

/// A scene's own tree (`own`) and the instances beside it: `count`
/// instances (records and [`InstanceInfo`]s, in the same order, `first`
/// rising), the top level and every mesh's tree in `trees` (as
/// [`trace_instances`] walks them), every mesh's triangles in `meshes`
/// (no spheres), and `materials`: one per mesh triangle (at the mesh's
/// `triangle_base`), then the copies' own.
pub struct SceneWithInstances<'a, T, I: ?Sized, N: ?Sized, L: ?Sized> {
    pub own: T,
    pub instances: &'a I,
    pub info: &'a [InstanceInfo],
    pub count: u32,
    pub trees: Level<'a, N, L>,
    pub meshes: Prims<'a>,
    pub materials: &'a [Material],
}

impl<T, I, N, L> ClosestHit for SceneWithInstances<'_, T, I, N, L>
where
    T: ClosestHit,
    I: RecordLoad<InstanceRecord> + ?Sized,
    N: RecordLoad<Bvh2Node> + ?Sized,
    L: RecordLoad<LeafPrim> + ?Sized,
{
    const OCCLUSION_STOPS_EARLY: bool = T::OCCLUSION_STOPS_EARLY;

    /// The scene's own hit, then the copies' nearer one if any. At equal
    /// distances a copy's triangle beats the scene's own triangles but not
    /// its spheres, as in the scene flattened (spheres, then the copies'
    /// triangles, then the scene's own: a pyramid standing on the floor
    /// has its base in the floor's plane, and glass then tells the two
    /// apart). Rays
    /// leaving a copy's triangle start off its surface by the renderer's
    /// offset (the walk into copies skips no primitive by index: `from`
    /// and `query.skip` name the scene's own).
    #[inline]
    fn trace<const F: u32, const S: usize>(
        &self,
        o: Vec3,
        d: Vec3,
        from: Origin,
        query: Query,
        prims: &Prims,
        stack: &mut [u32; S],
        lane: u32,
    ) -> Hit {
        let own = self.own.trace::<F, S>(o, d, from, query, prims, stack, lane);
        if self.count == 0 || query.done(&own) {
            return own;
        }
        let copies = Query { t_max: own.t, skip: u32::MAX, any: query.any };
        let inst = trace_instances(o, d, copies, self.instances, self.trees.nodes, self.trees.leaves, &self.meshes);
        let beats = inst.t < own.t || (inst.t == own.t && !prims.is_sphere::<F>(own.prim));
        if inst.is_hit() && beats {
            let first = self.info[inst.instance as usize].first;
            Hit { t: inst.t, prim: prims.count() + first + inst.prim }
        } else {
            own
        }
    }

    #[inline]
    fn instance_surface(&self, k: u32, d: Vec3) -> (Material, Vec3) {
        // The copy holding triangle k: the last whose first is k or less.
        let (mut lo, mut hi) = (0u32, self.count);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.info[mid as usize].first <= k {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let info = self.info[lo as usize];
        let record = self.instances.load(lo as usize);
        let triangle = record.triangle_base + (k - info.first);
        let t = self.meshes.triangle(triangle);
        let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
        let n = record.normal_to_world((b - a).cross(c - a)).normalize_or(-d);
        let material = if info.material == NO_MATERIAL { triangle } else { info.material };
        (self.materials[material as usize], n)
    }
}
