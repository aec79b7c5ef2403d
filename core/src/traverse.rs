//! Closest hit: by scanning every sphere, or through a BVH with a stack.
use glam::Vec3;

use crate::intersect::{ray_box, ray_sphere_mode, safe_inverse, MISS};
use crate::layout::{Node, Sphere};

/// Depth of the traversal stack. A tree deeper than this (possible for a
/// radix tree over pathological keys) would skip subtrees, so the host
/// refuses to trace such trees.
pub const STACK_DEPTH: usize = 64;

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
}

/// The surface a ray starts on, if any: a ray leaving sphere `prim` cannot
/// hit it again (`into == false`), or hits only its far side (`into`).
#[derive(Clone, Copy)]
pub struct Origin {
    pub prim: u32,
    pub into: bool,
}

impl Origin {
    /// A ray from no surface (a camera ray).
    pub const NONE: Origin = Origin { prim: u32::MAX, into: false };

    /// Distance to sphere `prim` along the ray, honouring the start surface.
    #[inline]
    fn distance(&self, o: Vec3, d: Vec3, s: &Sphere, prim: u32) -> f32 {
        if prim == self.prim {
            if !self.into {
                return MISS;
            }
            return ray_sphere_mode(o, d, Vec3::from_array(s.center), s.radius, 0.0, true);
        }
        ray_sphere_mode(o, d, Vec3::from_array(s.center), s.radius, 0.0, false)
    }
}

/// Tests every sphere.
///
/// ```
/// use glam::Vec3;
/// use treelet_core::traverse::{closest_hit_linear, Origin};
/// use treelet_core::Sphere;
/// let spheres = [Sphere::new([5.0, 0.0, 0.0], 1.0), Sphere::new([3.0, 0.0, 0.0], 1.0)];
/// let hit = closest_hit_linear(Vec3::ZERO, Vec3::X, Origin::NONE, &spheres, 2);
/// assert_eq!((hit.prim, hit.t), (1, 2.0));
/// ```
#[inline]
pub fn closest_hit_linear(o: Vec3, d: Vec3, from: Origin, spheres: &[Sphere], count: u32) -> Hit {
    let mut hit = Hit::NONE;
    let mut i = 0;
    while i < count {
        let s = spheres[i as usize];
        let t = from.distance(o, d, &s, i);
        if t < hit.t {
            hit = Hit { t, prim: i };
        }
        i += 1;
    }
    hit
}

/// Walks the BVH rooted at node 0 (`2 * count - 1` nodes), nearest child
/// first, pruning boxes beyond the closest hit so far.
#[inline]
pub fn closest_hit_bvh(
    o: Vec3,
    d: Vec3,
    from: Origin,
    spheres: &[Sphere],
    count: u32,
    nodes: &[Node],
    prim_indices: &[u32],
) -> Hit {
    let mut hit = Hit::NONE;
    if count == 0 {
        return hit;
    }
    let inv_d = safe_inverse(d);
    let mut stack = [0u32; STACK_DEPTH];
    let mut top = 1usize; // stack[0] = root
    while top > 0 {
        top -= 1;
        let node = nodes[stack[top] as usize];
        if !ray_box(&node, o, inv_d, hit.t) {
            continue;
        }
        if node.is_leaf() {
            let mut k = 0;
            while k < node.prim_count() {
                let prim = prim_indices[(node.left + k) as usize];
                let s = spheres[prim as usize];
                let t = from.distance(o, d, &s, prim);
                if t < hit.t {
                    hit = Hit { t, prim };
                }
                k += 1;
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
