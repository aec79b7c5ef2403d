//! The quality reference (`--builder reference`, `--accel reference`): the
//! best tree of the peers crate's builders, `obvhs`'s PLOC with reinsertion
//! over every node (Meister & Bittner 2018's reinsertion, on the CPU),
//! converted to the LBVH's layout, so that Treelet's own SAH leaf collapse,
//! layouts, validator, SAH and EPO take it as they take the others. The
//! full-sweep tree ([`super::sweep`]) is no reference on scenes of mixed
//! triangle sizes: the TRBVH beats its SAH there.
//!
//! It needs the `peers` feature (`cargo build --release -p treelet
//! --features peers`), which the default build leaves out.
use anyhow::Result;
use treelet_core::Aabb;

use crate::bvh::lbvh::Bvh;

/// The reference tree over `boxes`, one primitive per leaf, in the LBVH's
/// layout (see [`super::sweep`]), and its CPU build time (ms).
pub fn build_boxes(boxes: &[Aabb]) -> Result<(Bvh, f64)> {
    #[cfg(feature = "peers")]
    {
        let peer = treelet_peers::obvhs_reference(boxes);
        Ok((lbvh_layout(&peer.nodes, &peer.prim_indices)?, peer.build_ms))
    }
    #[cfg(not(feature = "peers"))]
    {
        let _ = boxes;
        anyhow::bail!("the reference builder comes with the `peers` feature: cargo build --release -p treelet --features peers")
    }
}

/// A tree of one primitive per leaf (root 0, leaves `left` = slot into
/// `prim_indices`) in the LBVH's layout: internal nodes numbered from 0 in
/// depth-first order, the leaf of sorted position `j` at `n - 1 + j`, the
/// sorted positions in depth-first order of the leaves, parent links.
#[cfg_attr(not(feature = "peers"), allow(dead_code))]
fn lbvh_layout(nodes: &[treelet_core::Node], prim_indices: &[u32]) -> Result<Bvh> {
    use treelet_core::geometry::buffers::{INVALID, LEAF_BIT, Node};
    let n = prim_indices.len();
    if n == 0 {
        return Ok(Bvh::default());
    }
    let mut out = vec![Node::default(); 2 * n - 1];
    let mut parents = vec![INVALID; 2 * n - 1];
    let mut sorted = Vec::with_capacity(n);
    let (mut next_internal, mut next_leaf) = (0usize, 0usize);
    // (input node, its parent in the output)
    let mut stack = vec![(0usize, INVALID)];
    while let Some((i, parent)) = stack.pop() {
        let node = nodes[i];
        let id = if node.is_leaf() {
            if node.prim_count() != 1 {
                anyhow::bail!("internal: the reference tree has a leaf of {} primitives", node.prim_count());
            }
            sorted.push(prim_indices[node.left as usize]);
            next_leaf += 1;
            let id = n - 1 + next_leaf - 1;
            out[id] = Node { min: node.min, left: (next_leaf - 1) as u32, max: node.max, right: LEAF_BIT | 1 };
            id
        } else {
            let id = next_internal;
            next_internal += 1;
            out[id] = Node { min: node.min, left: u32::MAX, max: node.max, right: u32::MAX };
            // Right first on the stack, so the left subtree's leaves come first.
            stack.push((node.right as usize, id as u32));
            stack.push((node.left as usize, id as u32));
            id
        };
        parents[id] = parent;
        if parent != INVALID {
            let p = &mut out[parent as usize];
            if p.left == u32::MAX {
                p.left = id as u32;
            } else {
                p.right = id as u32;
            }
        }
    }
    if next_leaf != n || (n > 1 && next_internal != n - 1) {
        anyhow::bail!("internal: the reference tree has {next_leaf} leaves and {next_internal} internal nodes for {n} primitives");
    }
    Ok(Bvh { nodes: out, parents, prim_indices: sorted, sorted_keys: Vec::new(), centroid_bounds: Aabb::EMPTY })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::validate::validate;
    use treelet_core::construct::sah::{SahCosts, sah_cost};

    /// The conversion keeps the tree: the sweep's tree (root 0, leaves
    /// naming slots of its primitive order) comes out valid with the same
    /// SAH, its leaves renumbered in depth-first order.
    #[test]
    fn the_layout_conversion_keeps_the_tree() {
        let spheres = crate::scene::random_spheres(2000, 9);
        let boxes: Vec<Aabb> = spheres.iter().map(|s| s.aabb()).collect();
        let sweep = crate::bvh::sweep::build_boxes(&boxes);
        let tree = lbvh_layout(&sweep.nodes, &sweep.prim_indices).unwrap();
        let v = validate(&spheres, &tree.nodes, &tree.parents, &tree.prim_indices);
        assert!(v.is_valid(), "{:?}", v.errors);
        let (a, b) = (sah_cost(&tree.nodes, SahCosts::KARRAS_AILA), sah_cost(&sweep.nodes, SahCosts::KARRAS_AILA));
        assert!((a - b).abs() <= 1e-9 * b, "{a} against {b}");
        // A leaf of two primitives is refused, not split silently.
        let mut bad = sweep.nodes.clone();
        let leaf = bad.iter().position(|n| n.is_leaf()).unwrap();
        bad[leaf].right = treelet_core::geometry::buffers::LEAF_BIT | 2;
        assert!(lbvh_layout(&bad, &sweep.prim_indices).is_err());
    }

    /// The reference tree is a valid tree over the boxes, and no worse by
    /// SAH than the full-sweep tree on random boxes.
    #[cfg(feature = "peers")]
    #[test]
    fn the_reference_is_a_valid_tree_at_least_as_good_as_the_sweep() {
        let spheres = crate::scene::random_spheres(3000, 5);
        let boxes: Vec<Aabb> = spheres.iter().map(|s| s.aabb()).collect();
        let (tree, _) = build_boxes(&boxes).unwrap();
        let v = validate(&spheres, &tree.nodes, &tree.parents, &tree.prim_indices);
        assert!(v.is_valid(), "{:?}", v.errors);
        let sweep = crate::bvh::sweep::build_boxes(&boxes);
        let (a, b) = (sah_cost(&tree.nodes, SahCosts::KARRAS_AILA), sah_cost(&sweep.nodes, SahCosts::KARRAS_AILA));
        assert!(a <= b * 1.05, "reference SAH {a} against the sweep's {b}");
    }
}
