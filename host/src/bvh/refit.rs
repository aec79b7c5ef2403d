//! Refit: new boxes for a tree whose primitives moved, its shape kept. The
//! primitives' boxes are made as a build makes them, then the build's own
//! bottom-up fit (`treelet_core::construct::fit`) runs over the tree's leaves and
//! parent links, so any binary tree of one primitive per leaf refits, the
//! treelet-restructured one included (Karras 2012, section 4, applied to an
//! existing hierarchy).
use anyhow::{bail, Result};
use treelet_core::geometry::buffers::{BuildParams, LayoutParams};
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};

use crate::bvh::layout::{PrimBuffers, TracedTree};
use crate::bvh::lbvh::DeviceBvh;
use crate::runtime::backend::{Backend, StageTimes};
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};

kernel_set! {
    /// The kernels of [`refit`]: the primitives' boxes, then the fit's climb.
    pub struct RefitKernels for b {
        boxes: Kernel::PrimitiveBoxes,
        fit: b.atomics_for(Kernel::Fit),
    }
}

kernel_set! {
    /// The kernels of [`refit_bvh2`]: its climb's state (once), then the climb.
    pub struct RefitBvh2Kernels for b {
        state: Kernel::RefitState,
        leaves: b.atomics_for(Kernel::RefitLeaves),
    }
}
use crate::scene::primitives::Primitives;

/// Rewrites the boxes of `bvh`'s nodes for `prims`, which must be the
/// primitives it was built over (same count and order), moved.
pub fn refit<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>, prims: Primitives) -> Result<StageTimes> {
    if prims.len() != bvh.n as usize {
        bail!("refit with {} primitives: the tree was built over {}", prims.len(), bvh.n);
    }
    let uploaded = PrimBuffers::upload(b, prims)?;
    refit_uploaded(b, bvh, &uploaded)
}

/// [`refit`] from primitives already on the device (an engine's tracer
/// uploads them once, for the refit and for tracing).
pub fn refit_uploaded<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>, prims: &PrimBuffers<B>) -> Result<StageTimes> {
    let n = bvh.n;
    if prims.sphere_count + prims.triangle_count != n {
        // Also a tree over pieces of triangles (more leaf slots than
        // primitives): its boxes come from the pieces, which this refit
        // does not make; its `bvh2` layout refits (`refit_bvh2`).
        bail!("refit with {} primitives: the tree was built over {n} (or over pieces of them: refit its bvh2 layout)", prims.sphere_count + prims.triangle_count);
    }
    if n == 0 {
        return Ok(StageTimes::default());
    }
    b.stage("bounds");
    let params = BuildParams { n, spheres: prims.sphere_count, ..Default::default() };
    let p = b.upload("refit params", &[params])?;
    let boxes = b.scratch("primitive boxes", n as u64 * 32)?;
    let prim_boxes = bind::PrimitiveBoxes { params: &p, spheres: &prims.spheres, triangles: &prims.triangles, boxes: &boxes };
    b.dispatch_with(RefitKernels::of(b).boxes, prim_boxes, groups_for(n, WORKGROUP_SIZE));
    b.stage("fit");
    let flags = b.zeroed("fit flags", (n as u64 - 1).max(1) * 4)?;
    let fit = bind::Fit { params: &p, sorted_prims: &bvh.prim_indices, prim_boxes: &boxes, nodes: &bvh.nodes, parents: &bvh.parents, flags: &flags };
    b.dispatch_with(RefitKernels::of(b).fit, fit, groups_for(n, WORKGROUP_SIZE));
    b.take_times()
}

/// Refits a tree laid out in `bvh2` in place, from the collapsed tree it was
/// made from ([`TracedTree::collapsed`]), for `prims`, the primitives it was
/// built over (same count and order), moved, in one dispatch: each primitive
/// slot is written again, and the boxes climb from the leaves as the
/// build's fit does, each written straight into the two-box node above it
/// (`treelet_core::layouts::bvh2::refit_kernel`). No collapse, no depth
/// check and no pass over the nodes: the shape is the one laid out.
///
/// `state`: what the climb needs besides the tree, two words per node of
/// the collapsed tree (its arrival counter, and where its node is in the
/// layout) and one per primitive slot (the leaf it starts, if any): made
/// when `None` (one more dispatch) and kept there for the next refit of the
/// same tree (a climb leaves the counters as it found them:
/// `treelet_core::construct::climb::second_arrival`), so that a refit every
/// frame makes it once.
pub fn refit_bvh2<B: Backend>(
    b: &mut B,
    tree: &TracedTree<B>,
    prims: &PrimBuffers<B>,
    state: &mut Option<B::Buffer>,
) -> Result<StageTimes> {
    let Some(collapsed) = &tree.collapsed else {
        bail!("internal: a {} tree keeps no collapsed tree to refit", tree.layout.name());
    };
    // Leaf slots: one a primitive, or more where triangles were split
    // before the build (`treelet_core::construct::presplit`). Each slot is
    // written from its whole primitive, so a split triangle's leaves get
    // its whole box: looser than the pieces', still correct. The caller
    // checks that the primitives are those the tree was built over.
    let n = collapsed.n;
    if prims.sphere_count + prims.triangle_count > n {
        bail!("refit with {} primitives: the tree has {n} leaf slots", prims.sphere_count + prims.triangle_count);
    }
    b.stage("fit");
    let nodes = collapsed.node_count;
    let lp = b.upload("refit params", &[LayoutParams { n, nodes, spheres: prims.sphere_count, ..Default::default() }])?;
    let climb = match state.take() {
        Some(kept) => kept,
        None => {
            let made = b.scratch("refit state", nodes as u64 * 8 + n as u64 * 4)?;
            let state = bind::RefitState { params: &lp, nodes: &collapsed.nodes, parents: &collapsed.parents, state: &made };
            b.dispatch_with(RefitBvh2Kernels::of(b).state, state, groups_for(nodes, WORKGROUP_SIZE));
            made
        }
    };
    b.dispatch_with(
        RefitBvh2Kernels::of(b).leaves,
        bind::RefitLeaves {
            params: &lp,
            prim_indices: &collapsed.prim_indices,
            spheres: &prims.spheres,
            triangles: &prims.triangles,
            nodes: &collapsed.nodes,
            parents: &collapsed.parents,
            state: &climb,
            out_prims: &tree.prims,
            out_nodes: &tree.nodes,
        },
        groups_for(n, WORKGROUP_SIZE),
    );
    *state = Some(climb);
    b.take_times()
}
