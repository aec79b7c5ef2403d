//! Parallel reinsertion on the device (Meister & Bittner 2018; the kernels
//! and the reasoning: `treelet_core::construct::reinsert`): each iteration
//! every node finds its best move, the moves that share no node with a
//! better one are made, and the boxes are refit. It runs after the treelet
//! rounds (`trbvh`), on a tree of one primitive per leaf in the LBVH layout,
//! which it keeps.
use anyhow::Result;
use treelet_core::geometry::buffers::{FillParams, ReinsertParams};
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};
use treelet_core::Aabb;

use crate::bvh::lbvh::DeviceBvh;
use crate::runtime::backend::Backend;
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};

kernel_set! {
    /// The kernels [`reinsert`] dispatches (relaxed refit counters where the
    /// device needs them).
    pub struct ReinsertKernels for b {
        search: Kernel::ReinsertSearch,
        fill: Kernel::Fill,
        bid: Kernel::ReinsertBid,
        claim: Kernel::ReinsertClaim,
        apply: Kernel::ReinsertApply,
        refit: b.atomics_for(Kernel::ReinsertRefit),
    }
}

/// Runs `iterations` iterations over `bvh` in place, searches climbing at
/// most `max_climb` ancestors (0: to the root). Returns the buffer of the
/// moves made in each iteration (u32s), left on the device: reading it
/// back would wait for the build in its middle ([`moves_made`] does, to
/// measure).
pub fn reinsert<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>, root_box: &Aabb, iterations: u32, max_climb: u32) -> Result<Option<B::Buffer>> {
    let n = bvh.n;
    if n < 3 || iterations == 0 {
        return Ok(None);
    }
    let (node_count, movers) = (2 * n - 1, 2 * n - 2);
    let extent = root_box.extent().max_element();
    let inv_extent = if extent > 0.0 { (1.0 / extent).min(f32::MAX) } else { 1.0 };
    let moves = b.scratch("reinsertion moves", movers as u64 * 16)?;
    let bids = b.scratch("reinsertion bids", node_count as u64 * 4)?;
    let owners = b.scratch("reinsertion owners", node_count as u64 * 4)?;
    let flags = b.scratch("reinsertion refit flags", (n as u64 - 1) * 4)?;
    let made = b.zeroed("reinsertion moves made", iterations as u64 * 4)?;
    let unowned = b.upload("reinsertion owners fill", &[FillParams { len: node_count, value: u32::MAX, _pad0: [0; 2] }])?;
    let k = ReinsertKernels::of(b);
    // Developers' switch: `TREELET_REINSERT_LEAVES=0` moves internal nodes only (nodes
    // 1 to n - 2 in the LBVH layout: the first n - 2 moves), half the searches.
    let leaves = crate::tuning::Tuning::current().reinsert_leaves;
    let searched = if leaves { movers } else { n - 2 };
    let (move_groups, node_groups) = (groups_for(searched, WORKGROUP_SIZE), groups_for(node_count, WORKGROUP_SIZE));
    for iteration in 0..iterations {
        let p = b.upload("reinsertion params", &[ReinsertParams { n, iteration, inv_extent, max_climb }])?;
        let (nodes, parents) = (&bvh.nodes, &bvh.parents);
        b.dispatch_with(k.search, bind::ReinsertSearch { params: &p, nodes, parents, moves: &moves }, move_groups);
        b.zero_words(&bids, node_count)?;
        b.dispatch_with(k.fill, bind::Fill { params: &unowned, data: &owners }, node_groups);
        b.dispatch_with(k.bid, bind::ReinsertBid { params: &p, nodes, parents, moves: &moves, bids: &bids }, move_groups);
        let claim = bind::ReinsertClaim { params: &p, nodes, parents, moves: &moves, bids: &bids, owners: &owners };
        b.dispatch_with(k.claim, claim, move_groups);
        let apply = bind::ReinsertApply { params: &p, nodes, parents, moves: &moves, bids: &bids, owners: &owners, made: &made };
        b.dispatch_with(k.apply, apply, move_groups);
        b.zero_words(&flags, n - 1)?;
        b.dispatch_with(k.refit, bind::ReinsertRefit { params: &p, nodes, parents, flags: &flags }, groups_for(n, WORKGROUP_SIZE));
    }
    Ok(Some(made))
}

/// The moves made in each of `iterations` iterations, read back from what
/// [`reinsert`] returned (waits for the device).
pub fn moves_made<B: Backend>(b: &mut B, made: Option<&B::Buffer>, iterations: u32) -> Result<Vec<u32>> {
    made.map_or(Ok(Vec::new()), |m| b.read::<u32>(m, iterations as usize))
}

/// The kernels [`reinsert`] dispatches on `b`, for building their pipelines ahead.
pub fn kernels<B: Backend>(b: &B) -> Vec<Kernel> {
    ReinsertKernels::of(b).all()
}
