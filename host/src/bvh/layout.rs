//! Traversal layouts: how a built binary tree is laid out for the kernels
//! that trace it (the kernels: `treelet_core::layouts::{bvh2, bvh4, cwbvh,
//! cwbvh::build}`). Every builder (LBVH, TRBVH, sweep) gives a tree of one
//! primitive per leaf; [`lay_out`] turns it into any layout, on the device.
use anyhow::{bail, Result};
use serde::Serialize;
use treelet_core::geometry::aabb::Aabb;
use treelet_core::geometry::buffers::{Bvh2Node, Bvh4Node, LayoutParams, LeafPrim, WideNode};
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};
use treelet_core::layouts::cwbvh::build::{WIDE_NODE_COST, WIDE_PRIM_COST};
use treelet_core::trace::hit::STACK_DEPTH;

use crate::bvh::lbvh::{upload_or_placeholder, DeviceBvh};
use crate::bvh::trbvh;
use crate::runtime::backend::{check_fits, Backend, DeviceClass};
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel, Method};
use crate::scene::primitives::Primitives;

/// How a tree is stored for traversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Layout {
    /// The fastest measured on the device: bvh2 on GPUs and on the CPU
    /// runner, cwbvh on CPU Vulkan adapters (lavapipe); a render of 256
    /// samples per pixel or more on a Vulkan device times both first and
    /// keeps the faster.
    // (Plain words: this is `--layout auto`'s help. The code is `resolve`
    // and `render::variant::PILOT_MIN_SPP`; a test in main.rs holds them
    // to this text.)
    Auto,
    /// The seed's: 32-byte nodes that hold their own box; leaves name their
    /// primitives through an index array.
    Classic,
    /// Binary nodes that hold both children's boxes (Aila & Laine 2009);
    /// primitives in leaf order.
    Bvh2,
    /// 4-wide nodes of full-precision boxes, made from bvh2's (a node's two
    /// children, then twice the internal child of largest area opened);
    /// primitives in leaf order.
    Bvh4,
    /// Compressed 8-wide nodes, child boxes quantized to bytes (Ylitie,
    /// Karras & Laine 2017); primitives in leaf order.
    Cwbvh,
}

impl Layout {
    /// The layouts a tree can be traced in, `auto` aside.
    pub const ALL: [Layout; 4] = [Layout::Classic, Layout::Bvh2, Layout::Bvh4, Layout::Cwbvh];

    /// What `auto` stands for on `device`: the layout that rendered fastest
    /// there (`treelet render --layout L --report F`, render-kernel time;
    /// TRBVH, 1024x768):
    /// * H100: bvh2 0.35 s, cwbvh 0.44 s, classic 0.84 s (a 940 544-triangle
    ///   mesh in smallpt's room, 64 spp); bvh2 also casts the most diffuse
    ///   rays (`treelet bench rays`, 0.95 G/s against 0.88);
    /// * lavapipe: cwbvh 0.58 s, bvh2 0.86 s (terrain:20000, 128x96, 8 spp);
    /// * the CPU runner: bvh2 0.20 s, cwbvh 0.24 s (the same).
    pub fn resolve(self, device: DeviceClass) -> Layout {
        match (self, device) {
            (Layout::Auto, DeviceClass::CpuAdapter) => Layout::Cwbvh,
            (Layout::Auto, _) => Layout::Bvh2,
            (other, _) => other,
        }
    }

    /// The name the command line takes.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Auto => "auto",
            Layout::Classic => "classic",
            Layout::Bvh2 => "bvh2",
            Layout::Bvh4 => "bvh4",
            Layout::Cwbvh => "cwbvh",
        }
    }

    /// The kernels' closest-hit method for this (resolved) layout.
    pub fn method(self) -> Method {
        match self {
            Layout::Classic => Method::Classic,
            Layout::Bvh2 => Method::Bvh2,
            Layout::Bvh4 => Method::Bvh4,
            Layout::Cwbvh => Method::Cwbvh,
            Layout::Auto => panic!("internal: a layout must be resolved for its device first"),
        }
    }
}

/// The scene's primitives on the device, as the layouts and the render and
/// cast kernels bind them.
pub struct PrimBuffers<B: Backend> {
    pub spheres: B::Buffer,
    pub triangles: B::Buffer,
    pub sphere_count: u32,
    pub triangle_count: u32,
}

// By hand: a derive would ask `B: Clone`; the buffers are handles.
impl<B: Backend> Clone for PrimBuffers<B> {
    fn clone(&self) -> Self {
        PrimBuffers { spheres: self.spheres.clone(), triangles: self.triangles.clone(), sphere_count: self.sphere_count, triangle_count: self.triangle_count }
    }
}

impl<B: Backend> PrimBuffers<B> {
    /// Uploads `prims` (call after any build: a build may hand out again
    /// buffers taken before it).
    pub fn upload(b: &mut B, prims: Primitives) -> Result<Self> {
        Ok(PrimBuffers {
            spheres: upload_or_placeholder(b, "spheres", prims.spheres)?,
            triangles: upload_or_placeholder(b, "triangles", prims.triangles)?,
            sphere_count: prims.spheres.len() as u32,
            triangle_count: prims.triangles.len() as u32,
        })
    }

    fn count(&self) -> u32 {
        self.sphere_count + self.triangle_count
    }
}

/// A tree in a traversal layout, on the device: what bindings 3 (nodes) and
/// 4 (primitive indices or leaf primitives) of the render and cast kernels
/// take.
pub struct TracedTree<B: Backend> {
    pub layout: Layout,
    pub nodes: B::Buffer,
    pub prims: B::Buffer,
    /// Nodes in the layout (an upper bound for cwbvh, whose buffer is sized
    /// before the count is known; see [`wide_node_count`]).
    pub node_count: u32,
    /// For `bvh2`: the collapsed tree it was made from, kept so that a refit
    /// ([`crate::bvh::refit::refit_bvh2`]) rewrites the layout's boxes and
    /// primitives without collapsing again.
    pub collapsed: Option<DeviceBvh<B>>,
}

/// Lays out `bvh`, a tree of one primitive per leaf in the LBVH layout (as
/// the builders leave it), for tracing: `max_leaf` bounds the leaves of the
/// binary layouts' SAH collapse (1: none, and `classic` then traces `bvh`
/// as it is). `layout` must be resolved ([`Layout::resolve`]). Checks that
/// the tree fits the traversal stack.
pub fn lay_out<B: Backend>(
    b: &mut B,
    bvh: DeviceBvh<B>,
    layout: Layout,
    max_leaf: u32,
    prims: &PrimBuffers<B>,
) -> Result<TracedTree<B>> {
    if layout == Layout::Auto {
        // Resolved once, where the choice is made (the render's plan, or the caller).
        bail!("internal: resolve the layout for the device (Layout::resolve) before laying out");
    }
    if bvh.n == 0 {
        bail!("no primitives to lay out");
    }
    // One leaf slot per primitive, or more where triangles were split into pieces.
    if bvh.n < prims.count() {
        bail!("internal: a tree over {} primitives laid out for {}", bvh.n, prims.count());
    }
    match layout {
        Layout::Cwbvh => {
            check_depth(b, &bvh)?;
            b.stage("layout");
            cwbvh(b, &bvh, prims)
        }
        _ if max_leaf <= 1 && layout == Layout::Classic => {
            check_depth(b, &bvh)?;
            Ok(TracedTree { layout, node_count: bvh.node_count, nodes: bvh.nodes, prims: bvh.prim_indices, collapsed: None })
        }
        _ => {
            b.stage("collapse");
            let collapsed = trbvh::collapse(b, bvh, max_leaf)?;
            check_depth(b, &collapsed)?;
            if layout == Layout::Classic {
                return Ok(TracedTree {
                    layout,
                    node_count: collapsed.node_count,
                    nodes: collapsed.nodes,
                    prims: collapsed.prim_indices,
                    collapsed: None,
                });
            }
            b.stage("layout");
            let two = bvh2(b, &collapsed, prims)?;
            if layout == Layout::Bvh4 {
                return bvh4(b, two);
            }
            Ok(two)
        }
    }
}

/// Refuses trees deeper than the traversal stack (a wide tree is never
/// deeper than the binary tree it is made from).
fn check_depth<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>) -> Result<()> {
    b.stage("depth");
    let deepest = tree_depth(b, bvh)?;
    if deepest as usize + 1 > STACK_DEPTH {
        bail!("the BVH is {deepest} or more levels deep; traversal supports {}", STACK_DEPTH - 1);
    }
    Ok(())
}

/// The depth of `bvh` (the root's is 0), up to
/// `treelet_core::layouts::depth::DEPTH_LIMIT` (one more than traversal
/// supports), found on the device: one word read back, not the tree.
pub fn tree_depth<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>) -> Result<u32> {
    let params = LayoutParams { n: bvh.n, nodes: bvh.node_count, ..Default::default() };
    let p = b.upload("depth params", &[params])?;
    let deepest = b.zeroed("tree depth", 4)?;
    let depth = bind::TreeDepth { params: &p, nodes: &bvh.nodes, parents: &bvh.parents, deepest: &deepest };
    b.dispatch_with(DepthKernels::of(b).depth, depth, groups_for(bvh.node_count, WORKGROUP_SIZE));
    Ok(b.read::<u32>(&deepest, 1)?[0])
}

/// The wide DP's cost model: the defaults, or for developers tuning it,
/// `TREELET_WIDE_COSTS=NODE,PRIM`.
fn wide_costs() -> (f32, f32) {
    crate::tuning::Tuning::current().wide_costs.unwrap_or((WIDE_NODE_COST, WIDE_PRIM_COST))
}

fn params<B: Backend>(bvh: &DeviceBvh<B>, prims: &PrimBuffers<B>, root: &Aabb) -> LayoutParams {
    let extent = root.extent().max_element();
    let (node_cost, prim_cost) = wide_costs();
    LayoutParams {
        n: bvh.n,
        nodes: bvh.node_count,
        spheres: prims.sphere_count,
        node_cost,
        prim_cost,
        inv_extent: if extent > 0.0 { (1.0 / extent).min(f32::MAX) } else { 1.0 },
        ..Default::default()
    }
}

kernel_set! {
    /// The kernel of [`tree_depth`], run before every layout.
    pub struct DepthKernels for b {
        depth: Kernel::TreeDepth,
    }
}

kernel_set! {
    /// The kernels of the two-box layout.
    pub struct Bvh2Kernels for b {
        nodes: Kernel::Bvh2Nodes,
        leaf_prims: Kernel::LeafPrims,
    }
}

kernel_set! {
    /// The kernel of the 4-wide layout, made from the two-box one.
    pub struct Bvh4Kernels for b {
        nodes: Kernel::Bvh4Nodes,
    }
}

kernel_set! {
    /// The kernels of the compressed wide layout (and the scans between
    /// them: `crate::bvh::sort::ScanKernels`).
    pub struct WideKernels for b {
        dp: b.atomics_for(Kernel::WideDp),
        count: Kernel::WideCount,
        place: Kernel::WidePlace,
        emit: Kernel::WideEmit,
    }
}

/// The kernels laying a tree out in `layout` dispatches on `b` (the same
/// question of `b` as it asks), for building their pipelines ahead.
pub fn kernels<B: Backend>(b: &B, layout: Layout) -> Vec<Kernel> {
    let depth = DepthKernels::of(b).all();
    match layout {
        Layout::Cwbvh => [depth, WideKernels::of(b).all(), crate::bvh::sort::ScanKernels::of(b).all()].concat(),
        // Classic and bvh2 collapse the tree's leaves first (classic only when it has leaves to collapse).
        Layout::Classic | Layout::Auto => [trbvh::collapse_kernels(b), depth].concat(),
        Layout::Bvh2 => [trbvh::collapse_kernels(b), depth, Bvh2Kernels::of(b).all()].concat(),
        Layout::Bvh4 => [trbvh::collapse_kernels(b), depth, Bvh2Kernels::of(b).all(), Bvh4Kernels::of(b).all()].concat(),
    }
}

/// The 4-wide layout made from a tree in the two-box one
/// (`treelet_core::layouts::bvh4`): a node for each of its nodes, the
/// same leaf primitives. The walk's stack holds what a tree of the depth
/// the two-box layout admits needs (`treelet_core::trace::bvh4::BVH4_STACK_ENTRIES`).
fn bvh4<B: Backend>(b: &mut B, two: TracedTree<B>) -> Result<TracedTree<B>> {
    let bytes = two.node_count as u64 * std::mem::size_of::<Bvh4Node>() as u64;
    check_fits(b, "4-wide nodes", bytes)?;
    let nodes = b.scratch("4-wide nodes", bytes)?;
    let p = b.upload("4-wide params", &[LayoutParams { nodes: two.node_count, ..Default::default() }])?;
    b.dispatch_with(Bvh4Kernels::of(b).nodes, bind::Bvh4Nodes { params: &p, nodes: &two.nodes, out: &nodes }, groups_for(two.node_count, WORKGROUP_SIZE));
    Ok(TracedTree { layout: Layout::Bvh4, nodes, prims: two.prims, node_count: two.node_count, collapsed: None })
}

/// The two-box binary layout of a collapsed tree (depth-first order).
fn bvh2<B: Backend>(b: &mut B, collapsed: &DeviceBvh<B>, prims: &PrimBuffers<B>) -> Result<TracedTree<B>> {
    let internal = (collapsed.node_count / 2).max(1); // 2 L - 1 nodes, L - 1 internal
    check_fits(b, "two-box nodes", internal as u64 * std::mem::size_of::<Bvh2Node>() as u64)?;
    check_fits(b, "leaf primitives", collapsed.n as u64 * std::mem::size_of::<LeafPrim>() as u64)?;
    let nodes = b.scratch("two-box nodes", internal as u64 * std::mem::size_of::<Bvh2Node>() as u64)?;
    let leaf_prims = b.scratch("leaf primitives", collapsed.n as u64 * std::mem::size_of::<LeafPrim>() as u64)?;
    write_bvh2(b, collapsed, prims, &nodes, &leaf_prims)?;
    Ok(TracedTree { layout: Layout::Bvh2, nodes, prims: leaf_prims, node_count: internal, collapsed: Some(collapsed.clone()) })
}

/// Writes the two-box nodes of `collapsed` into `nodes` and its primitives
/// in leaf order into `leaf_prims`.
fn write_bvh2<B: Backend>(
    b: &mut B,
    collapsed: &DeviceBvh<B>,
    prims: &PrimBuffers<B>,
    nodes: &B::Buffer,
    leaf_prims: &B::Buffer,
) -> Result<()> {
    let p = write_bvh2_nodes(b, collapsed, prims, nodes)?;
    let n = collapsed.n;
    b.dispatch_with(
        Bvh2Kernels::of(b).leaf_prims,
        bind::LeafPrims { params: &p, prim_indices: &collapsed.prim_indices, spheres: &prims.spheres, triangles: &prims.triangles, out: leaf_prims },
        groups_for(n, WORKGROUP_SIZE),
    );
    Ok(())
}

/// Writes the two-box nodes of `collapsed` into `nodes`; returns the
/// layout's parameters.
fn write_bvh2_nodes<B: Backend>(
    b: &mut B,
    collapsed: &DeviceBvh<B>,
    prims: &PrimBuffers<B>,
    nodes: &B::Buffer,
) -> Result<B::Buffer> {
    let p = b.upload("layout params", &[params(collapsed, prims, &Aabb::EMPTY)])?;
    b.dispatch_with(
        Bvh2Kernels::of(b).nodes,
        bind::Bvh2Nodes { params: &p, nodes: &collapsed.nodes, parents: &collapsed.parents, out: nodes },
        groups_for(collapsed.node_count, WORKGROUP_SIZE),
    );
    Ok(p)
}

/// The compressed wide BVH of a tree of one primitive per leaf (see
/// `treelet_core::layouts::cwbvh::build` for the steps).
fn cwbvh<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>, prims: &PrimBuffers<B>) -> Result<TracedTree<B>> {
    let n = bvh.n;
    if bvh.node_count != 2 * n - 1 {
        bail!("internal: the wide layout needs one primitive per leaf ({} nodes for {n} primitives)", bvh.node_count);
    }
    let nodes = bvh.node_count as u64;
    // Binary internal nodes (the root when the tree is one leaf): the wide
    // nodes are among them.
    let internal = (n - 1).max(1);
    check_fits(b, "wide DP costs", nodes * 32)?;
    check_fits(b, "wide node slots", internal as u64 * 32)?;
    check_fits(b, "wide nodes", internal as u64 * std::mem::size_of::<WideNode>() as u64)?;
    check_fits(b, "leaf primitives", n as u64 * std::mem::size_of::<LeafPrim>() as u64)?;
    let root = trbvh::root_box(b, bvh)?;
    let p = b.upload("layout params", &[params(bvh, prims, &root)])?;
    let flags = b.zeroed("wide DP flags", internal as u64 * 4)?;
    let counts = b.scratch("wide DP counts", nodes * 4)?;
    let costs = b.scratch("wide DP costs", nodes * 32)?;
    let decisions = b.scratch("wide DP decisions", nodes * 8)?;
    let k = WideKernels::of(b);
    // A stage per step, so that `bench rays` shows where the time goes.
    b.stage("wide dp");
    let (nodes, parents) = (&bvh.nodes, &bvh.parents);
    let dp = bind::WideDp { params: &p, nodes, parents, flags: &flags, counts: &counts, costs: &costs, decisions: &decisions };
    b.dispatch_with(k.dp, dp, groups_for(n, WORKGROUP_SIZE));

    let is_wide = b.scratch("wide node flags", internal as u64 * 4)?;
    let child_offsets = b.scratch("wide child offsets", internal as u64 * 4)?;
    let prim_offsets = b.scratch("wide primitive offsets", internal as u64 * 4)?;
    let groups = groups_for(internal, WORKGROUP_SIZE);
    b.stage("wide count");
    b.dispatch_with(
        k.count,
        // Counts, scanned into offsets in place below.
        bind::WideCount {
            params: &p,
            nodes,
            parents,
            counts: &counts,
            decisions: &decisions,
            is_wide: &is_wide,
            child_counts: &child_offsets,
            prim_counts: &prim_offsets,
        },
        groups,
    );
    b.stage("wide scans");
    crate::bvh::sort::exclusive_scan(b, &child_offsets, internal)?;
    crate::bvh::sort::exclusive_scan(b, &prim_offsets, internal)?;
    let positions = b.scratch("wide node positions", internal as u64 * 4)?;
    let slots = b.scratch("wide node slots", internal as u64 * 32)?;
    b.stage("wide place");
    let place = bind::WidePlace { params: &p, nodes, decisions: &decisions, is_wide: &is_wide, child_offsets: &child_offsets, positions: &positions, slots: &slots };
    b.dispatch_with(k.place, place, groups);
    let out_nodes = b.scratch("wide nodes", internal as u64 * std::mem::size_of::<WideNode>() as u64)?;
    let out_prims = b.scratch("leaf primitives", n as u64 * std::mem::size_of::<LeafPrim>() as u64)?;
    b.stage("wide emit");
    b.dispatch_with(
        k.emit,
        bind::WideEmit {
            params: &p,
            nodes,
            slots: &slots,
            is_wide: &is_wide,
            child_offsets: &child_offsets,
            prim_offsets: &prim_offsets,
            positions: &positions,
            prim_indices: &bvh.prim_indices,
            spheres: &prims.spheres,
            triangles: &prims.triangles,
            out_nodes: &out_nodes,
            out_prims: &out_prims,
        },
        groups,
    );
    Ok(TracedTree { layout: Layout::Cwbvh, nodes: out_nodes, prims: out_prims, node_count: internal, collapsed: None })
}

/// The nodes of a wide tree that are in use: those reachable from the root
/// (read back; for reports and tests).
pub fn wide_nodes<B: Backend>(b: &mut B, tree: &TracedTree<B>) -> Result<Vec<WideNode>> {
    let all = b.read::<WideNode>(&tree.nodes, tree.node_count as usize)?;
    let mut used = 0usize;
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        used = used.max(i + 1);
        let node = &all[i];
        let imask = node.exp_imask >> 24;
        for k in 0..imask.count_ones() as usize {
            stack.push(node.child_base as usize + k);
        }
    }
    Ok(all[..used].to_vec())
}

/// Nodes in use in a wide tree (see [`wide_nodes`]).
pub fn wide_node_count<B: Backend>(b: &mut B, tree: &TracedTree<B>) -> Result<usize> {
    Ok(wide_nodes(b, tree)?.len())
}
