//! Closest hit: by scanning every primitive, or through a BVH with a stack.
//! Primitives are spheres then triangles: index `i < sphere_count` is
//! sphere `i`, a larger one triangle `i - sphere_count`.
use glam::Vec3;

use crate::geometry::buffers::Node;
use crate::geometry::features::{self};
use crate::geometry::intersect::{MISS, ray_box, safe_inverse};
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::triangle::WatertightRay;
use crate::gpu::unchecked::scratch;
use crate::trace::hit::{ClosestHit, Hit, Query, STACK_DEPTH};

/// Every primitive tested: no tree. (Not zero-sized: rust-gpu cannot take
/// the address of a zero-sized field.)
pub struct Scan {
    _unused: u32,
}

impl Scan {
    /// The scan, from the bindings a tree would have (which it ignores).
    #[inline]
    pub fn new(_nodes: &[Node], _prim_indices: &[u32]) -> Self {
        Scan { _unused: 0 }
    }
}

impl ClosestHit for Scan {
    /// On the H100 (smallpt's room, 1024x768 at 1024 spp, kernel time) the
    /// shadow ray as an occlusion query up to the light's distance took
    /// 0.802 s, as a closest hit 0.756 s (before occlusion queries: 0.748).
    const OCCLUSION_STOPS_EARLY: bool = false;

    #[inline]
    fn trace<const F: u32, const S: usize>(&self, o: Vec3, d: Vec3, from: Origin, query: Query, prims: &Prims, _: &mut [u32; S], _: u32) -> Hit {
        trace_linear::<F>(o, d, from, query, prims)
    }
}

/// The seed's layout: 32-byte nodes that hold their own box, leaves that
/// name their primitives through `prim_indices`.
pub struct ClassicTree<'a> {
    pub nodes: &'a [Node],
    pub prim_indices: &'a [u32],
}

impl<'a> ClassicTree<'a> {
    #[inline]
    pub fn new(nodes: &'a [Node], prim_indices: &'a [u32]) -> Self {
        ClassicTree { nodes, prim_indices }
    }
}

impl ClosestHit for ClassicTree<'_> {
    #[inline]
    fn trace<const F: u32, const S: usize>(&self, o: Vec3, d: Vec3, from: Origin, query: Query, prims: &Prims, _: &mut [u32; S], _: u32) -> Hit {
        trace_bvh::<F>(o, d, from, query, prims, self.nodes, self.prim_indices)
    }
}

/// Tests every primitive; `F` (see [`crate::geometry::features`]) may leave out the
/// test of a primitive kind the scene lacks.
///
/// ```
/// use glam::Vec3;
/// use treelet_core::geometry::prims::{Origin, Prims};
/// use treelet_core::trace::classic::closest_hit_linear;
/// use treelet_core::Sphere;
/// let spheres = [Sphere::new([5.0, 0.0, 0.0], 1.0), Sphere::new([3.0, 0.0, 0.0], 1.0)];
/// let hit = closest_hit_linear(Vec3::ZERO, Vec3::X, Origin::NONE, &Prims::spheres(&spheres));
/// assert_eq!((hit.prim, hit.t), (1, 2.0));
/// ```
#[inline]
pub fn closest_hit_linear_for<const F: u32>(o: Vec3, d: Vec3, from: Origin, prims: &Prims) -> Hit {
    trace_linear::<F>(o, d, from, Query::CLOSEST, prims)
}

/// [`closest_hit_linear_for`] for any [`Query`].
///
/// One loop, and no early stop for an occlusion query: the closest hit up
/// to `t_max` other than `skip` answers it too, and a scan of the few
/// primitives it is chosen for gains less by stopping than its loop loses
/// by asking. On the H100 (smallpt's room, 1024x768 at 1024 spp, kernel
/// time) a loop that stopped at an occlusion query's first hit took 0.882 s
/// against 0.748 s before occlusion queries, and two loops (one per kind of
/// query) 1.019 s.
#[inline]
pub fn trace_linear<const F: u32>(o: Vec3, d: Vec3, from: Origin, query: Query, prims: &Prims) -> Hit {
    let ray = WatertightRay::new(o, d);
    let count = prims.count();
    // In index order the first of equal distances stays (the lower index,
    // as [`Hit::is_beaten_by`] picks) with a plain `<`; starting just past
    // `t_max` keeps a hit at exactly `t_max` (the bound is inclusive).
    let start = query.start();
    let mut hit = Hit { t: if start.t < MISS { start.t.next_up() } else { start.t }, prim: u32::MAX };
    let mut i = 0;
    while i < count {
        let t = prims.distance::<F>(o, d, &ray, from, i, hit.t);
        if t < hit.t && i != query.skip {
            hit = Hit { t, prim: i };
        }
        i += 1;
    }
    if hit.is_hit() { hit } else { start }
}

/// Walks the BVH rooted at node 0 (`2 * count - 1` nodes), nearest child
/// first, pruning boxes beyond the closest hit so far; `F` as for
/// [`closest_hit_linear_for`].
#[inline]
pub fn closest_hit_bvh_for<const F: u32>(o: Vec3, d: Vec3, from: Origin, prims: &Prims, nodes: &[Node], prim_indices: &[u32]) -> Hit {
    trace_bvh::<F>(o, d, from, Query::CLOSEST, prims, nodes, prim_indices)
}

/// [`closest_hit_bvh_for`] for any [`Query`].
#[inline]
pub fn trace_bvh<const F: u32>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    query: Query,
    prims: &Prims,
    nodes: &[Node],
    prim_indices: &[u32],
) -> Hit {
    let mut hit = query.start();
    if prims.count() == 0 {
        return hit;
    }
    let inv_d = safe_inverse(d);
    let ray = WatertightRay::new(o, d);
    let mut stack = scratch::<u32, STACK_DEPTH>();
    stack[0] = 0; // the root
    let mut top = 1usize;
    while top > 0 {
        top -= 1;
        let node = nodes[stack[top] as usize];
        if !ray_box(&node, o, inv_d, hit.t) {
            continue;
        }
        if node.is_leaf() {
            let mut k = 0;
            while k < node.prim_count() && !query.done(&hit) {
                let prim = prim_indices[(node.left + k) as usize];
                let t = prims.distance::<F>(o, d, &ray, from, prim, hit.t);
                if prim != query.skip && hit.is_beaten_by(t, prim) {
                    hit = Hit { t, prim };
                }
                k += 1;
            }
            if query.done(&hit) {
                return hit;
            }
        } else if top + 2 <= STACK_DEPTH {
            // Visit the child whose box centre is nearer along the ray first.
            let (l, r) = (nodes[node.left as usize], nodes[node.right as usize]);
            let dl = (l.aabb().centroid() - o).dot(d);
            let dr = (r.aabb().centroid() - o).dot(d);
            let (first, second) = if dl <= dr { (node.left, node.right) } else { (node.right, node.left) };
            stack[top] = second;
            stack[top + 1] = first;
            top += 2;
        }
    }
    hit
}

/// [`closest_hit_linear_for`] with every primitive kind compiled in.
#[inline]
pub fn closest_hit_linear(o: Vec3, d: Vec3, from: Origin, prims: &Prims) -> Hit {
    closest_hit_linear_for::<{ features::ALL }>(o, d, from, prims)
}

/// [`closest_hit_bvh_for`] with every primitive kind compiled in.
#[inline]
pub fn closest_hit_bvh(o: Vec3, d: Vec3, from: Origin, prims: &Prims, nodes: &[Node], prim_indices: &[u32]) -> Hit {
    closest_hit_bvh_for::<{ features::ALL }>(o, d, from, prims, nodes, prim_indices)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::buffers::{Sphere, LEAF_BIT};
    use crate::geometry::triangle::Triangle;

    /// Two leaves under one root; the tree visits the primitive of
    /// `prim_indices[0]` first when both boxes are equally near.
    fn two_leaf_tree(a: crate::geometry::aabb::Aabb, b: crate::geometry::aabb::Aabb) -> [Node; 3] {
        let mut nodes = [Node::default(); 3];
        nodes[0].set_aabb(a.union(&b));
        (nodes[0].left, nodes[0].right) = (1, 2);
        for (k, bx) in [(1, a), (2, b)] {
            nodes[k].set_aabb(bx);
            (nodes[k].left, nodes[k].right) = (k as u32 - 1, LEAF_BIT | 1);
        }
        nodes
    }

    #[test]
    fn ties_go_to_the_lower_index_in_any_traversal_order() {
        let (o, d) = (Vec3::ZERO, Vec3::X);
        // Two spheres the ray meets at one distance; the tree visits index 1 first.
        let spheres = [Sphere::new([5.0, 0.0, 0.0], 1.0), Sphere::new([5.0, 0.0, 0.0], 1.0)];
        let prims = Prims::spheres(&spheres);
        let nodes = two_leaf_tree(spheres[1].aabb(), spheres[0].aabb());
        for hit in [closest_hit_linear(o, d, Origin::NONE, &prims), closest_hit_bvh(o, d, Origin::NONE, &prims, &nodes, &[1, 0])] {
            assert_eq!((hit.prim, hit.t), (0, 4.0));
        }
        // Two triangles sharing the edge the ray crosses.
        let tris = [
            Triangle::new([3.0, -1.0, 0.0], [3.0, 1.0, 0.0], [3.0, 0.0, 1.0]),
            Triangle::new([3.0, 1.0, 0.0], [3.0, -1.0, 0.0], [3.0, 0.0, -1.0]),
        ];
        let d = Vec3::new(1.0, 0.1, 0.0).normalize(); // crosses the shared edge (z = 0)
        let prims = Prims { spheres: &[], sphere_count: 0, triangles: crate::geometry::split::Split::whole(&tris), triangle_count: 2 };
        let nodes = two_leaf_tree(tris[1].aabb(), tris[0].aabb());
        let linear = closest_hit_linear(o, d, Origin::NONE, &prims);
        let bvh = closest_hit_bvh(o, d, Origin::NONE, &prims, &nodes, &[1, 0]);
        assert!(linear.is_hit());
        assert_eq!((bvh.prim, bvh.t), (linear.prim, linear.t));
    }
}
