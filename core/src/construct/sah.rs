//! Surface area heuristic cost of a tree (MacDonald & Booth 1990), with the
//! constants of Karras & Aila 2013: `C_i = 1.2` per internal node visited,
//! `C_t = 1.0` per primitive tested:
//!
//! `SAH = (C_i Σ_internal A(n) + C_t Σ_leaves A(l) · |l|) / A(root)`
//!
//! Areas are taken in f64 so that scenes near the f32 range stay finite.
//! A tree whose root box has zero area (all primitives at one point) counts
//! every area as 1: every box is the same point.
use crate::geometry::buffers::Node;

/// The two constants of the heuristic.
#[derive(Clone, Copy, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct SahCosts {
    /// Cost of visiting an internal node (`C_i`).
    pub node: f64,
    /// Cost of intersecting one primitive (`C_t`).
    pub prim: f64,
}

impl SahCosts {
    /// Karras & Aila 2013, section 3.
    pub const KARRAS_AILA: SahCosts = SahCosts { node: 1.2, prim: 1.0 };
}

impl Default for SahCosts {
    fn default() -> Self {
        Self::KARRAS_AILA
    }
}

/// SAH cost of the tree in `nodes` rooted at index 0 (0 for an empty tree).
pub fn sah_cost(nodes: &[Node], costs: SahCosts) -> f64 {
    if nodes.is_empty() {
        return 0.0;
    }
    let root_area = nodes[0].aabb().half_area_f64();
    let mut total = 0.0;
    for node in nodes {
        let area = if root_area > 0.0 { node.aabb().half_area_f64() / root_area } else { 1.0 };
        total += if node.is_leaf() { costs.prim * node.prim_count() as f64 * area } else { costs.node * area };
    }
    total
}
