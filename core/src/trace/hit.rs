//! What every traversal looks for ([`Query`]) and returns ([`Hit`]), and the
//! trait every layout implements ([`ClosestHit`]), so renderers and ray
//! casts are generic over it.
use glam::Vec3;

use crate::geometry::buffers::Material;
use crate::geometry::intersect::MISS;
use crate::geometry::prims::{Origin, Prims};

/// A way to find closest hits: the scan, or a tree in one of the traversal
/// layouts (the seed's 32-byte nodes here; [`crate::trace::bvh2`],
/// [`crate::trace::cwbvh`]). The renderer and the ray-casting kernels are generic
/// over it, so each layout gets kernels of its own.
pub trait ClosestHit {
    /// Whether an occlusion query pays here: a walk that stops at its first
    /// hit saves the rest of the walk. The scan tests every primitive in any
    /// case, so the renderer's shadow ray through it is a closest hit,
    /// checked against the light (no test of the light's distance first).
    const OCCLUSION_STOPS_EARLY: bool = true;

    /// What `query` asks of the ray `o + t d` (`d` of unit length) among the
    /// primitives: the closest hit up to `query.t_max`, ties to the lower
    /// index, or any hit up to it; `F` (see [`crate::geometry::features`])
    /// may leave out the test of a kind the scene lacks. `stack` is
    /// workgroup memory a traversal may keep the top of its stack in, at
    /// `lane + WG * k` (see [`crate::trace::cwbvh::closest_hit_cwbvh_with`]); a
    /// one-word array means none.
    #[allow(clippy::too_many_arguments)]
    fn trace<const F: u32, const S: usize>(
        &self,
        o: Vec3,
        d: Vec3,
        from: Origin,
        query: Query,
        prims: &Prims,
        stack: &mut [u32; S],
        lane: u32,
    ) -> Hit;

    /// The material and outward normal (unit length) of the `k`-th
    /// primitive past the scene's own, hit along `d`: a placed copy's
    /// triangle ([`crate::trace::with_instances`]). Only a tree over copies finds
    /// such primitives; the others never are asked.
    #[inline]
    fn instance_surface(&self, _k: u32, d: Vec3) -> (Material, Vec3) {
        (Material::default(), -d)
    }
}

/// What a traversal looks for: the closest hit up to `t_max`, or, for an
/// occlusion query (`any`), the first hit it finds up to `t_max` (whether
/// there is one: what shadow and ambient-occlusion rays need, and cheaper:
/// the walk stops there). `skip` is a primitive never hit (a shadow ray's
/// own light, so that it is never its own occluder), `u32::MAX` for none.
#[derive(Clone, Copy)]
pub struct Query {
    pub t_max: f32,
    pub skip: u32,
    pub any: bool,
}

impl Query {
    /// The closest hit at any distance.
    pub const CLOSEST: Query = Query { t_max: MISS, skip: u32::MAX, any: false };

    /// The closest hit up to `t_max` (inclusive).
    #[inline]
    pub fn closest_within(t_max: f32) -> Query {
        Query { t_max, ..Query::CLOSEST }
    }

    /// Any hit up to `t_max` (inclusive) other than primitive `skip`.
    #[inline]
    pub fn occlusion(t_max: f32, skip: u32) -> Query {
        Query { t_max, skip, any: true }
    }

    /// The hit a traversal starts from: none nearer than `t_max` yet (a
    /// NaN or larger `t_max` is no bound).
    #[inline]
    pub fn start(&self) -> Hit {
        Hit { t: if self.t_max < MISS { self.t_max } else { MISS }, prim: u32::MAX }
    }

    /// Whether a traversal that found `hit` is done: an occlusion query's first hit.
    #[inline]
    pub fn done(&self, hit: &Hit) -> bool {
        self.any && hit.is_hit()
    }
}

/// Depth of the traversal stack. A tree deeper than this (possible for a
/// radix tree over pathological keys) would skip subtrees, so the host
/// refuses to trace such trees.
pub const STACK_DEPTH: usize = 64;
const _: () = assert!(crate::layouts::depth::DEPTH_LIMIT as usize == STACK_DEPTH + 1, "the depth check finds trees too deep for the stack");

/// The closest hit: distance and sphere index (`MISS`, `u32::MAX` if none).
#[derive(Clone, Copy)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
}

impl Hit {
    pub const NONE: Hit = Hit { t: MISS, prim: u32::MAX };
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }

    /// Whether a hit at `t` on `prim` beats this one. Equal distances go to
    /// the lower index, so every traversal order finds the same hit (a ray
    /// through the rim of smallpt's light, which dips into the ceiling,
    /// meets both at one distance).
    #[inline]
    pub fn is_beaten_by(&self, t: f32, prim: u32) -> bool {
        t < self.t || (t == self.t && t != MISS && prim < self.prim)
    }

    /// How far a traversal still enters boxes: this hit's distance widened
    /// by [`TIE_WIDENING`](crate::geometry::intersect::TIE_WIDENING) (for
    /// ties between primitives that share an edge or vertex), for the tests
    /// that compare a box's entry with the hit (a child pushed, a cwbvh
    /// node's children); infinite for no hit.
    #[inline]
    pub fn reach(&self) -> f32 {
        self.t * crate::geometry::intersect::TIE_WIDENING
    }
}
