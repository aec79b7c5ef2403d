//! End-point overlap (EPO; Aila, Karras & Laine 2013, "On Quality Metrics
//! of Bounding Volume Hierarchies"): the area of the geometry that lies
//! inside a node's box without being in the node's subtree, summed over the
//! nodes, weighted as the SAH weighs them (`C_i` an internal node, `C_t`
//! times its primitives a leaf), over the scene's total area. A ray that
//! ends on such geometry (a hit, or the start of the next bounce) still
//! has to enter the node: on scenes whose triangles span many sizes it
//! predicts trace speed better than the SAH, which sees no overlap at all.
//!
//! Where triangles are split into several leaves ([`super::tree::split_budget`]),
//! the part of a triangle in a node's subtree is the sum of its parts in
//! the boxes of the leaves under the node that hold it (the pieces' boxes
//! overlap by their padding alone). Triangles and parallelograms count;
//! spheres and disks are left out of the sums.
use rayon::prelude::*;
use treelet_core::construct::sah::SahCosts;
use treelet_core::geometry::buffers::Node;
use crate::bvh::clip::{triangle_area, triangle_area_in_box};
use treelet_core::geometry::triangle::{SHAPE_DISK, SHAPE_PARALLELOGRAM, Triangle};

use crate::scene::primitives::Primitives;

const NO_PARENT: u32 = u32::MAX;

/// Node boxes a triangle's walk may test, on average over the triangles
/// (plus [`EPO_BASE_VISITS`]): the metric's cost is the number of (triangle,
/// overlapping box) pairs, which a scene of triangles that all cross one
/// place makes quadratic (one OBJ polygon of 20 000 vertices, fanned, took
/// 77 s). Real scenes stay far below: 60-80 a triangle for the staircase,
/// the classroom and `city:300000` (TRBVH, splits 0.3).
pub const EPO_VISITS_PER_TRIANGLE: u64 = 256;
pub const EPO_BASE_VISITS: u64 = 1 << 20;

/// EPO of the tree `nodes` (root 0; a leaf's primitives are
/// `prim_indices[left..left + count]`, several slots for a split triangle)
/// over `prims`, normalized by the scene's area; 0 without triangles.
/// `None` where the triangles overlap more node boxes than the budget
/// ([`EPO_VISITS_PER_TRIANGLE`]) lets it count.
pub fn epo(prims: Primitives, nodes: &[Node], parents: &[u32], prim_indices: &[u32], costs: SahCosts) -> Option<f64> {
    if nodes.is_empty() {
        return Some(0.0);
    }
    let budget = EPO_BASE_VISITS + EPO_VISITS_PER_TRIANGLE * prims.triangles.len() as u64;
    let visits = std::sync::atomic::AtomicU64::new(0);
    // The leaves holding each primitive.
    let mut leaves_of: Vec<Vec<u32>> = vec![Vec::new(); prims.len()];
    for (i, n) in nodes.iter().enumerate() {
        if n.is_leaf() {
            for k in n.left..n.left + n.prim_count() {
                let leaves = &mut leaves_of[prim_indices[k as usize] as usize];
                if leaves.last() != Some(&(i as u32)) {
                    leaves.push(i as u32);
                }
            }
        }
    }
    let first_triangle = prims.spheres.len();
    // A thousand triangles spread over the list first, each walk cut off
    // at 16 times the budget's mean: where their mean is past the budget,
    // the whole count would be too (a polygon fanned around one point is
    // found in a few million visits instead of the full budget's).
    let step = (prims.triangles.len() / 1024).max(1);
    let sampled: Vec<u64> = (0..prims.triangles.len())
        .step_by(step)
        .collect::<Vec<_>>()
        .par_iter()
        .map(|&t| {
            let cut = 16 * EPO_VISITS_PER_TRIANGLE;
            let walked = std::sync::atomic::AtomicU64::new(0);
            for v in triangles_of(&prims.triangles[t]) {
                overlap_of(v, &leaves_of[first_triangle + t], nodes, parents, costs, (&walked, cut));
            }
            walked.load(std::sync::atomic::Ordering::Relaxed).min(cut)
        })
        .collect();
    if !sampled.is_empty() && sampled.iter().sum::<u64>() / sampled.len() as u64 > EPO_VISITS_PER_TRIANGLE {
        return None;
    }
    let (overlap, area) = prims
        .triangles
        .par_iter()
        .enumerate()
        .map(|(t, tri)| {
            let leaves = &leaves_of[first_triangle + t];
            let mut sums = (0.0, 0.0);
            for v in triangles_of(tri) {
                let s = overlap_of(v, leaves, nodes, parents, costs, (&visits, budget));
                sums = (sums.0 + s, sums.1 + triangle_area(v));
            }
            sums
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    if visits.load(std::sync::atomic::Ordering::Relaxed) > budget {
        return None;
    }
    Some(if area > 0.0 { overlap / area } else { 0.0 })
}

/// The flat triangles a primitive stored as a triangle covers.
fn triangles_of(t: &Triangle) -> Vec<[[f64; 3]; 3]> {
    let p = |v: [f32; 3]| v.map(f64::from);
    let (a, b, c) = (p(t.v0), p(t.v1), p(t.v2));
    match t.shape {
        0 => vec![[a, b, c]],
        SHAPE_PARALLELOGRAM => vec![[a, b, c], [b, [0, 1, 2].map(|k| b[k] + c[k] - a[k]), c]],
        SHAPE_DISK => Vec::new(),
        _ => Vec::new(),
    }
}

/// The weighted area of triangle `v` in the boxes of the nodes whose
/// subtrees do not hold it (or hold only part of it: `leaves` are those
/// that do).
fn overlap_of(v: [[f64; 3]; 3], leaves: &[u32], nodes: &[Node], parents: &[u32], costs: SahCosts, (visits, budget): (&std::sync::atomic::AtomicU64, u64)) -> f64 {
    let under = |leaf: u32, node: u32| {
        let mut at = leaf;
        while at != NO_PARENT {
            if at == node {
                return true;
            }
            at = parents[at as usize];
        }
        false
    };
    let part_in = |n: &Node| triangle_area_in_box(v, n.min.map(f64::from), n.max.map(f64::from));
    let mut sum = 0.0;
    let mut stack = vec![0u32];
    while let Some(i) = stack.pop() {
        // Past the budget every walk stops: the sum is then not reported.
        if visits.fetch_add(1, std::sync::atomic::Ordering::Relaxed) > budget {
            return sum;
        }
        let n = &nodes[i as usize];
        let inside = part_in(n);
        if inside <= 0.0 {
            continue; // the children's boxes are inside this one
        }
        let own: f64 = leaves.iter().filter(|&&l| under(l, i)).map(|&l| part_in(&nodes[l as usize])).sum();
        let weight = if n.is_leaf() { costs.prim * n.prim_count() as f64 } else { costs.node };
        sum += weight * (inside - own).max(0.0);
        if !n.is_leaf() {
            stack.extend([n.left, n.right]);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use treelet_core::Aabb;

    fn tri(v0: [f32; 3], v1: [f32; 3], v2: [f32; 3]) -> Triangle {
        Triangle { v0, v1, v2, ..Default::default() }
    }

    fn leaf(b: Aabb, first: u32, count: u32) -> Node {
        let mut n = Node { left: first, right: 0x8000_0000 | count, ..Default::default() };
        n.set_aabb(b);
        n
    }

    fn internal(b: Aabb, left: u32, right: u32) -> Node {
        let mut n = Node { left, right, ..Default::default() };
        n.set_aabb(b);
        n
    }

    /// A big ground triangle and a small one standing on it: the small one's
    /// leaf box cuts a piece out of the ground, which is overlap; two far
    /// apart triangles have none.
    #[test]
    fn overlap_is_the_area_of_others_in_a_box() {
        let ground = tri([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0]);
        let post = tri([1.0, 0.0, 1.0], [2.0, 0.0, 1.0], [1.0, 1.0, 1.0]);
        let tris = [ground, post];
        let b = |t: &Triangle| Aabb::from_arrays(t.v0, t.v0).grow(t.v1.into()).grow(t.v2.into());
        let root = b(&ground).union(&b(&post));
        let nodes = [internal(root, 1, 2), leaf(b(&ground), 0, 1), leaf(b(&post), 1, 1)];
        let parents = [NO_PARENT, 0, 0];
        let costs = SahCosts::KARRAS_AILA;
        let e = epo(Primitives::triangles(&tris), &nodes, &parents, &[0, 1], costs).unwrap();
        // The post's box (x 1..2, y 0..1, z 1..1) meets the ground in a
        // segment: no area. Its leaf holds nothing else: EPO 0.
        assert_eq!(e, 0.0);
        // A post leaning over the ground: its box now covers a unit square of it.
        let lean = tri([1.0, 0.0, 1.0], [2.0, 0.0, 1.0], [1.0, 1.0, 2.0]);
        let tris = [ground, lean];
        let nodes = [internal(b(&ground).union(&b(&lean)), 1, 2), leaf(b(&ground), 0, 1), leaf(b(&lean), 1, 1)];
        let e = epo(Primitives::triangles(&tris), &nodes, &parents, &[0, 1], costs).unwrap();
        let total = 8.0 + triangle_area(triangles_of(&lean)[0]);
        assert!((e - 1.0 * 1.0 / total).abs() < 1e-9, "{e}");
    }

    /// A triangle split into two leaves at x = 1: each leaf's box holds the
    /// other piece's part of nothing, so EPO stays 0; a tree that put the
    /// whole triangle's box in one leaf and also the other piece would not.
    #[test]
    fn a_split_triangles_own_pieces_are_no_overlap() {
        let t = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let left = Aabb::from_arrays([0.0, 0.0, 0.0], [1.0, 2.0, 0.0]);
        let right = Aabb::from_arrays([1.0, 0.0, 0.0], [2.0, 1.0, 0.0]);
        let nodes = [internal(left.union(&right), 1, 2), leaf(left, 0, 1), leaf(right, 1, 1)];
        let e = epo(Primitives::triangles(&[t]), &nodes, &[NO_PARENT, 0, 0], &[0, 0], SahCosts::KARRAS_AILA).unwrap();
        assert!(e.abs() < 1e-12, "{e}");
    }
}
