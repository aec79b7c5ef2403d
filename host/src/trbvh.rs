//! Treelet restructuring of an LBVH on the device (Karras & Aila 2013),
//! round by round: a bottom-up pass computes each node's primitive count,
//! SAH cost and height, then one dispatch per height, from the leaves up,
//! restructures every treelet whose root has at least `gamma` primitives.
//! Nodes of one height never contain each other, so each dispatch works on
//! disjoint subtrees. (The paper instead restructures during one bottom-up
//! climb with atomic counters; per-height dispatches trade some launches
//! for visibility guarantees that need no device-scope atomics.)
use anyhow::Result;
use treelet_core::layout::TreeletParams;
use treelet_core::sah::SahCosts;
use treelet_core::workgroup::{groups_for, WORKGROUP_SIZE};
use treelet_core::{Aabb, Node};

use crate::backend::{Backend, StageTimes};
use crate::kernels::Kernel;
use crate::lbvh::DeviceBvh;

/// How the optimization runs; defaults after Karras & Aila 2013.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct TreeletConfig {
    /// Optimization rounds (the paper: 3).
    pub rounds: u32,
    /// Smallest subtree, in primitives, restructured in the first round;
    /// doubled each round (the paper: 7, i.e. one full treelet).
    pub gamma: u32,
}

impl Default for TreeletConfig {
    fn default() -> Self {
        Self { rounds: 3, gamma: 7 }
    }
}

/// Optimizes `bvh` in place. `root_box` (the tree's root box) scales areas so
/// that f32 costs cannot overflow. Stage times are named `round 1`, ...
pub fn optimize<B: Backend>(
    b: &mut B,
    bvh: &DeviceBvh<B>,
    root_box: &Aabb,
    config: &TreeletConfig,
) -> Result<StageTimes> {
    let n = bvh.n;
    if n < 3 {
        return b.take_times();
    }
    let node_count = 2 * n as u64 - 1;
    let extent = root_box.extent().max_element();
    let inv_extent = if extent > 0.0 { (1.0 / extent).min(f32::MAX) } else { 1.0 };
    let sah = SahCosts::KARRAS_AILA;
    let base =
        TreeletParams { n, node_cost: sah.node as f32, prim_cost: sah.prim as f32, inv_extent, ..Default::default() };
    let counts = b.scratch("treelet counts", node_count * 4)?;
    let costs = b.scratch("treelet costs", node_count * 4)?;
    let heights = b.scratch("treelet heights", node_count * 4)?;
    let init = if b.ordered_atomics_in_divergent_flow() { Kernel::TreeletInit } else { Kernel::TreeletInitRelaxed };
    const ROUND_NAMES: [&str; 8] =
        ["round 1", "round 2", "round 3", "round 4", "round 5", "round 6", "round 7", "round 8"];
    let mut gamma = config.gamma;
    for round in 0..config.rounds.min(ROUND_NAMES.len() as u32) {
        b.stage(ROUND_NAMES[round as usize]);
        let flags = b.zeroed("treelet flags", (n as u64 - 1) * 4)?;
        let p = b.upload("treelet params", &[TreeletParams { gamma, ..base }])?;
        b.dispatch(
            init,
            &[&p, &bvh.nodes, &bvh.parents, &flags, &counts, &costs, &heights],
            groups_for(n, WORKGROUP_SIZE),
        );
        let root_height = b.read::<u32>(&heights, 1)?[0];
        for level in 1..=root_height {
            let lp = b.upload("treelet params", &[TreeletParams { gamma, level, ..base }])?;
            b.dispatch(
                Kernel::TreeletLevel,
                &[&lp, &bvh.nodes, &bvh.parents, &counts, &costs, &heights],
                groups_for(n - 1, WORKGROUP_SIZE),
            );
        }
        gamma = gamma.saturating_mul(2);
    }
    b.take_times()
}

/// The root box of a device BVH (one node read back).
pub fn root_box<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>) -> Result<Aabb> {
    Ok(b.read::<Node>(&bvh.nodes, 1)?.first().map(|n| n.aabb()).unwrap_or(Aabb::EMPTY))
}
