//! Peer BVH builders from crates.io, run over Treelet's own boxes and
//! converted to Treelet's node layout, so that the benchmark suite scores
//! them with the same SAH function and constants (`treelet_core::construct::sah`).
//! Only the suite uses this crate (`treelet` feature `peers`): the release
//! binary does not depend on them.
//!
//! - [`bvh_crate`]: `bvh` 0.13 (svenstaro), a top-down SAH builder with buckets,
//!   one primitive per leaf, single-threaded (`Bvh::build`).
//! - [`obvhs_ploc`]: `obvhs` 0.4 (DGriffin91), PLOC with reinsertion and SAH
//!   collapse (`BvhBuildParams::medium_build`, leaves of up to 8), single-threaded.
use std::time::Instant;

use treelet_core::Aabb;
use treelet_core::geometry::buffers::{LEAF_BIT, Node};

/// A peer's tree in Treelet's layout (root at 0) and its build time.
pub struct PeerTree {
    pub name: &'static str,
    pub nodes: Vec<Node>,
    pub prim_indices: Vec<u32>,
    /// Wall-clock build time (ms), conversion excluded.
    pub build_ms: f64,
}

fn internal(b: Aabb, left: u32, right: u32) -> Node {
    Node { min: b.min, left, max: b.max, right }
}

fn leaf(b: Aabb, first: u32, count: u32) -> Node {
    Node { min: b.min, left: first, max: b.max, right: LEAF_BIT | count }
}

/// `bvh` 0.13's SAH builder.
pub fn bvh_crate(boxes: &[Aabb]) -> PeerTree {
    use bvh::aabb::{Aabb as PAabb, Bounded};
    use bvh::bounding_hierarchy::BHShape;
    use bvh::bvh::{Bvh, BvhNode};
    use nalgebra::Point3;

    struct Shape {
        aabb: PAabb<f32, 3>,
        node: usize,
    }
    impl Bounded<f32, 3> for Shape {
        fn aabb(&self) -> PAabb<f32, 3> {
            self.aabb
        }
    }
    impl BHShape<f32, 3> for Shape {
        fn set_bh_node_index(&mut self, i: usize) {
            self.node = i;
        }
        fn bh_node_index(&self) -> usize {
            self.node
        }
    }
    let mut shapes: Vec<Shape> = boxes
        .iter()
        .map(|b| Shape {
            aabb: PAabb::with_bounds(Point3::from(b.min), Point3::from(b.max)),
            node: 0,
        })
        .collect();
    let start = Instant::now();
    let bvh = Bvh::build(&mut shapes);
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    // Its inner nodes hold their children's boxes; leaves hold a shape.
    let mut nodes = Vec::with_capacity(bvh.nodes.len());
    let mut prim_indices = Vec::with_capacity(boxes.len());
    if boxes.len() == 1 {
        return PeerTree { name: "bvh", nodes: vec![leaf(boxes[0], 0, 1)], prim_indices: vec![0], build_ms };
    }
    let to_aabb = |a: &PAabb<f32, 3>| Aabb::from_arrays([a.min.x, a.min.y, a.min.z], [a.max.x, a.max.y, a.max.z]);
    let root_box = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
    // (peer node, its box, our slot)
    let mut stack = vec![(0usize, root_box, 0usize)];
    nodes.push(Node::default());
    while let Some((i, b, slot)) = stack.pop() {
        match &bvh.nodes[i] {
            BvhNode::Leaf { shape_index, .. } => {
                nodes[slot] = leaf(b, prim_indices.len() as u32, 1);
                prim_indices.push(*shape_index as u32);
            }
            BvhNode::Node { child_l_index, child_l_aabb, child_r_index, child_r_aabb, .. } => {
                let (l, r) = (nodes.len(), nodes.len() + 1);
                nodes.push(Node::default());
                nodes.push(Node::default());
                nodes[slot] = internal(b, l as u32, r as u32);
                stack.push((*child_l_index, to_aabb(child_l_aabb), l));
                stack.push((*child_r_index, to_aabb(child_r_aabb), r));
            }
        }
    }
    PeerTree { name: "bvh", nodes, prim_indices, build_ms }
}

/// `obvhs` 0.4's PLOC builder (medium preset).
pub fn obvhs_ploc(boxes: &[Aabb]) -> PeerTree {
    use obvhs::BvhBuildParams;
    let prims: Vec<Prim> = boxes.iter().map(prim).collect();
    obvhs_with(&prims, BvhBuildParams::medium_build(), "obvhs")
}

/// `obvhs` 0.4's best tree over boxes, one primitive per leaf, for
/// Treelet's quality reference (`treelet build --builder reference`): PLOC
/// with its widest search, then reinsertion over every node
/// (`very_slow_build`'s ratio 1.0; its pre-splitting needs triangles, so
/// it is off here), no leaf collapse (Treelet's own SAH collapse runs
/// after, as for its other trees).
pub fn obvhs_reference(boxes: &[Aabb]) -> PeerTree {
    use obvhs::BvhBuildParams;
    use obvhs::ploc::PlocSearchDistance;
    let prims: Vec<Prim> = boxes.iter().map(prim).collect();
    let params = BvhBuildParams {
        pre_split: false,
        ploc_search_distance: PlocSearchDistance::High,
        search_depth_threshold: 0,
        reinsertion_batch_ratio: 1.0,
        post_collapse_reinsertion_batch_ratio_multiplier: 0.0,
        max_prims_per_leaf: 1,
        ..BvhBuildParams::very_slow_build()
    };
    obvhs_with(&prims, params, "obvhs reference")
}

struct Prim(obvhs::aabb::Aabb);

impl obvhs::Boundable for Prim {
    fn aabb(&self) -> obvhs::aabb::Aabb {
        self.0
    }
}

fn prim(b: &Aabb) -> Prim {
    Prim(obvhs::aabb::Aabb { min: glam::Vec3A::from_array(b.min), max: glam::Vec3A::from_array(b.max) })
}

fn obvhs_with(prims: &[Prim], params: obvhs::BvhBuildParams, name: &'static str) -> PeerTree {
    use obvhs::bvh2::builder::build_bvh2;
    let mut core = std::time::Duration::ZERO;
    let start = Instant::now();
    let bvh = build_bvh2(prims, params, &mut core);
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    // Inner nodes: children at first_index and first_index + 1.
    let mut nodes = Vec::with_capacity(bvh.nodes.len());
    let prim_indices: Vec<u32> = bvh.primitive_indices.clone();
    let mut stack = vec![(0usize, 0usize)];
    nodes.push(Node::default());
    while let Some((i, slot)) = stack.pop() {
        let n = &bvh.nodes[i];
        let b = Aabb::from_arrays(n.aabb.min.to_array(), n.aabb.max.to_array());
        if n.prim_count > 0 {
            nodes[slot] = leaf(b, n.first_index, n.prim_count);
        } else {
            let (l, r) = (nodes.len(), nodes.len() + 1);
            nodes.push(Node::default());
            nodes.push(Node::default());
            nodes[slot] = internal(b, l as u32, r as u32);
            stack.push((n.first_index as usize, l));
            stack.push((n.first_index as usize + 1, r));
        }
    }
    PeerTree { name, nodes, prim_indices, build_ms }
}

#[cfg(test)]
mod tests {
    use super::*;
    use treelet_core::construct::sah::{SahCosts, sah_cost};

    fn boxes(n: usize) -> Vec<Aabb> {
        let mut x = 12345u32;
        let mut r = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32
        };
        (0..n)
            .map(|_| {
                let c = [r() * 100.0, r() * 100.0, r() * 100.0];
                let h = 0.5 + r();
                Aabb::from_arrays(c.map(|v| v - h), c.map(|v| v + h))
            })
            .collect()
    }

    /// Every primitive in exactly one leaf, every box inside its parent's.
    fn check(t: &PeerTree, boxes: &[Aabb]) {
        let mut seen = vec![0u32; boxes.len()];
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = t.nodes[i];
            if n.is_leaf() {
                for k in 0..n.prim_count() {
                    let p = t.prim_indices[(n.left + k) as usize] as usize;
                    seen[p] += 1;
                    assert!(n.aabb().contains(&boxes[p]), "{}: leaf {i} misses its primitive {p}", t.name);
                }
            } else {
                for c in [n.left as usize, n.right as usize] {
                    assert!(n.aabb().contains(&t.nodes[c].aabb()), "{}: node {c} outside its parent {i}", t.name);
                    stack.push(c);
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "{}: a primitive is not in exactly one leaf", t.name);
    }

    #[test]
    fn peers_give_valid_trees_in_treelet_layout() {
        let b = boxes(5000);
        for t in [bvh_crate(&b), obvhs_ploc(&b)] {
            check(&t, &b);
            let sah = sah_cost(&t.nodes, SahCosts::KARRAS_AILA);
            assert!(sah.is_finite() && sah > 1.0, "{}: SAH {sah}", t.name);
        }
    }
}
