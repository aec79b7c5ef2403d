//! The table of kernels: one entry per compute entry point of the shader
//! crate, with its bindings. The GPU backend builds one pipeline per entry;
//! the CPU runner matches on the same enum to call the same core function.

/// How a kernel uses one storage binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Read,
    ReadWrite,
}
use treelet_core::render::variants::VARIANTS;
use Access::{Read, ReadWrite};

/// How a render or cast kernel finds closest hits: the scan, or a tree in
/// one of the traversal layouts (see [`crate::bvh::layout::Layout`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    Scan,
    Classic,
    Bvh2,
    Bvh4,
    Cwbvh,
}

impl Method {
    /// The name in entry points (`render::<variant>::<name>_cs`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Scan => "linear",
            Method::Classic => "classic",
            Method::Bvh2 => "bvh2",
            Method::Bvh4 => "bvh4",
            Method::Cwbvh => "cwbvh",
        }
    }

    /// Whether the shader compiles this method for every feature set
    /// (else only for the general one): the scan and the layouts `auto`
    /// picks do; the seed's layout, kept for comparison, has the general
    /// kernel.
    pub fn specialized(self) -> bool {
        !matches!(self, Method::Classic)
    }

    pub const ALL: [Method; 5] = [Method::Scan, Method::Classic, Method::Bvh2, Method::Bvh4, Method::Cwbvh];
}

/// Entry point of render kernel `(method, variant)`, as the shader crate
/// names the modules it makes from `treelet_core::for_each_render_variant!`:
/// `render::<variant>::<method>_cs`; the seed's layout has the general
/// kernel only, `render::classic_cs`.
pub fn render_entry_point_name(method: Method, variant: usize) -> String {
    match method {
        Method::Classic => "render::classic_cs".to_string(),
        _ => format!("render::{}::{}_cs", VARIANTS[variant].1, method.name()),
    }
}

/// The entry point of the light paths (`treelet_core::render::caustics`)
/// for `method` and `VARIANTS[variant]`: beside the camera paths' (no
/// seed layout).
pub fn light_entry_point_name(method: Method, variant: usize) -> String {
    format!("render::{}::light_{}_cs", VARIANTS[variant].1, method.name())
}

fn render_entry_point(method: Method, variant: u8, light: bool) -> &'static str {
    static NAMES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    let names = NAMES.get_or_init(|| {
        let name = |m: Method, v: usize, light: bool| if light { light_entry_point_name(m, v) } else { render_entry_point_name(m, v) };
        [false, true]
            .iter()
            .flat_map(|&l| Method::ALL.iter().flat_map(move |&m| (0..VARIANTS.len()).map(move |v| name(m, v, l))))
            .collect()
    });
    let m = Method::ALL.iter().position(|&x| x == method).unwrap();
    &names[(light as usize * Method::ALL.len() + m) * VARIANTS.len() + variant as usize]
}

/// Every compute kernel of Treelet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kernel {
    Fill,
    PrimitiveBoxes,
    /// [`Kernel::PrimitiveBoxes`] fused with the centroid bounds.
    PrimitiveBounds,
    Morton,
    /// Triangle splitting (`treelet_core::construct::presplit`): each
    /// primitive's priority and their sums per workgroup.
    SplitPriority,
    /// Triangle splitting: pieces per primitive.
    SplitCount,
    /// Triangle splitting: each primitive's pieces, boxes and primitive.
    SplitEmit,
    /// Triangle splitting: the pieces' boxes as the build's, with their centroid bounds.
    SplitBounds,
    /// Triangle splitting: leaf slots name primitives instead of pieces.
    SplitRemap,
    /// Radix sort: digit counts of every pass.
    SortHistogram,
    /// Radix sort: where each digit starts, per pass.
    SortOffsets,
    /// Sort: runs of keys tied in their high digits ordered by their low ones.
    SortSettleTies,
    /// Radix sort: one pass (one sweep with decoupled look-back).
    SortOnesweep,
    /// [`Kernel::SortOnesweep`] with small tiles (`treelet_core::construct::sort::SMALL_SORT_TILE`).
    SortOnesweepSmall,
    /// Radix sort: one pass ranked by subgroups (Onesweep's warp-level
    /// multisplit; `treelet_core::construct::sort_multisplit`).
    SortMultisplit,
    /// The same with half the keys per lane (small tiles).
    SortMultisplitSmall,
    /// The same with three quarters of the keys per lane (medium tiles).
    SortMultisplitMedium,
    /// [`Kernel::SortMultisplit`] matching digits by NVIDIA's partition
    /// instruction instead of ballots (devices with
    /// `VK_NV_shader_subgroup_partitioned`, see
    /// `Backend::subgroup_partitioned`).
    SortMultisplitPartitioned,
    /// [`Kernel::SortMultisplitSmall`] likewise.
    SortMultisplitSmallPartitioned,
    /// [`Kernel::SortMultisplitMedium`] likewise.
    SortMultisplitMediumPartitioned,
    /// Radix sort without look-back: this pass's digit counts per tile.
    SortTileCounts,
    /// Radix sort without look-back: one pass, offsets from the scanned tile counts.
    SortOnesweepScanned,
    /// Ranks keys by digit within their subgroup with ballots (Onesweep's
    /// warp-level multisplit; `treelet_core::construct::multisplit`).
    Multisplit,
    ScanReduce,
    ScanSpine,
    ScanDownsweep,
    RadixTree,
    Fit,
    /// [`Kernel::Fit`] with a relaxed counter, for CPU adapters.
    FitRelaxed,
    /// The state a `bvh2` layout's refit climbs on (counters, node indices,
    /// the leaf each primitive slot starts), made once per tree.
    RefitState,
    /// A `bvh2` layout's refit in place: its leaf primitives, and its boxes
    /// bottom-up over its collapsed tree.
    RefitLeaves,
    /// [`Kernel::RefitLeaves`] with relaxed counters, for CPU adapters.
    RefitLeavesRelaxed,
    /// Hierarchy and boxes in one bottom-up pass (Apetrei 2014).
    Agglomerate,
    /// [`Kernel::Agglomerate`] with relaxed exchanges, for CPU adapters.
    AgglomerateRelaxed,
    /// The agglomerative build's lowest levels merged within each subgroup,
    /// the rest queued for [`Kernel::ClimbQueued`].
    AgglomerateSubgroup,
    /// The climbs of the queued clusters, as [`Kernel::Agglomerate`]'s.
    ClimbQueued,
    /// [`Kernel::ClimbQueued`] with relaxed exchanges, for CPU adapters.
    ClimbQueuedRelaxed,
    /// H-PLOC (Benthin et al. 2024): nearest-neighbour clusters merged
    /// within subgroups as the climbs go up.
    Hploc,
    /// [`Kernel::Hploc`] with relaxed exchanges, for CPU adapters.
    HplocRelaxed,
    /// Treelet optimization: per-node counts, costs, heights (bottom up).
    TreeletInit,
    /// [`Kernel::TreeletInit`] with relaxed counters, for CPU adapters.
    TreeletInitRelaxed,
    /// The climbs [`Kernel::TreeletInit`] queued.
    TreeletInitClimb,
    /// [`Kernel::TreeletInitClimb`] with relaxed counters, for CPU adapters.
    TreeletInitClimbRelaxed,
    /// Treelet optimization: count treelet roots per height.
    TreeletHistogram,
    /// Treelet optimization: list treelet roots by height.
    TreeletScatter,
    /// Treelet optimization: restructure the treelets of one height, a team of lanes each.
    TreeletRestructure,
    /// Treelet optimization: restructure the treelets of one height, one invocation each.
    TreeletRestructureSingle,
    /// Reinsertion (Meister & Bittner 2018): each node's best move.
    ReinsertSearch,
    /// Reinsertion: moves bid their gains on their nodes.
    ReinsertBid,
    /// Reinsertion: moves that won every bid claim their nodes.
    ReinsertClaim,
    /// Reinsertion: the moves that hold all their nodes are made.
    ReinsertApply,
    /// Reinsertion: boxes refit from the leaves after the moves.
    ReinsertRefit,
    /// [`Kernel::ReinsertRefit`] with relaxed counters, for CPU adapters.
    ReinsertRefitRelaxed,
    /// SAH leaf collapse and depth-first compaction into fresh arrays.
    Collapse,
    /// The two-box binary layout from a collapsed tree.
    Bvh2Nodes,
    /// Primitives in leaf order.
    LeafPrims,
    /// The 4-wide layout from the two-box one.
    Bvh4Nodes,
    /// The depth of a tree (each leaf climbs; the deepest counts).
    TreeDepth,
    /// The compressed wide BVH: SAH DP over the binary tree (bottom up).
    WideDp,
    /// [`Kernel::WideDp`] with relaxed counters, for CPU adapters.
    WideDpRelaxed,
    /// The compressed wide BVH: which nodes are wide nodes, their children's counts.
    WideCount,
    /// The compressed wide BVH: indices of wide nodes.
    WidePlace,
    /// The compressed wide BVH: nodes and leaf primitives.
    WideEmit,
    /// Path tracing with a closest-hit method, compiled for the feature set
    /// `treelet_core::render::variants::VARIANTS[i]` (binary layouts: the general one only).
    Render(Method, u8),
    /// Path tracing of a scene with copies of meshes kept placed
    /// (`treelet_core::trace::placed`): its own primitives in `bvh2`, the
    /// copies through the instanced walk; every feature.
    RenderPlaced,
    /// [`Kernel::RenderPlaced`] beside light paths for caustics
    /// ([`Kernel::LightPlaced`]): camera paths leave theirs to them.
    RenderPlacedCaustics,
    /// The light paths of [`Kernel::RenderPlaced`]'s scenes, for caustics.
    LightPlaced,
    /// The light paths of [`Kernel::Render`]'s method and feature set, for
    /// caustics (`treelet_core::render::caustics`; not for the seed layout).
    Light(Method, u8),
    /// Ray-casting throughput (primary, bounce or diffuse passes) through a
    /// tree; `true`: compiled for triangles alone (meshes).
    Cast(Method, bool),
    /// [`Kernel::Cast`] through the wide BVH with the top of the stack in workgroup memory.
    CastWideWorkgroupStack,
    /// Words copied from one buffer into another.
    CopyWords,
    /// An engine's mesh gathered from its vertex and index buffers into
    /// triangles (`treelet_core::geometry::gather`).
    GatherTriangles,
    /// An engine's rays through an instanced scene (a top-level tree over
    /// instances of meshes, `bvh2` layout at both levels).
    CastInstances,
    /// An instanced scene's top level: each instance's record and world
    /// box, and the first pass of their centroid bounds.
    InstanceBounds,
    /// An instanced scene's top level in the two-box layout, from its LBVH
    /// as built (leaves refer to instances).
    TopLevelNodes,
}

impl Kernel {
    const FIXED: [Kernel; 76] = [
        Kernel::Fill,
        Kernel::CopyWords,
        Kernel::GatherTriangles,
        Kernel::CastInstances,
        Kernel::InstanceBounds,
        Kernel::TopLevelNodes,
        Kernel::PrimitiveBoxes,
        Kernel::PrimitiveBounds,
        Kernel::Morton,
        Kernel::SplitPriority,
        Kernel::SplitCount,
        Kernel::SplitEmit,
        Kernel::SplitBounds,
        Kernel::SplitRemap,
        Kernel::SortHistogram,
        Kernel::SortOffsets,
        Kernel::SortSettleTies,
        Kernel::SortOnesweep,
        Kernel::SortOnesweepSmall,
        Kernel::SortMultisplit,
        Kernel::SortMultisplitSmall,
        Kernel::SortMultisplitMedium,
        Kernel::SortMultisplitPartitioned,
        Kernel::SortMultisplitSmallPartitioned,
        Kernel::SortMultisplitMediumPartitioned,
        Kernel::SortTileCounts,
        Kernel::SortOnesweepScanned,
        Kernel::Multisplit,
        Kernel::ScanReduce,
        Kernel::ScanSpine,
        Kernel::ScanDownsweep,
        Kernel::RadixTree,
        Kernel::Fit,
        Kernel::FitRelaxed,
        Kernel::RefitState,
        Kernel::RefitLeaves,
        Kernel::RefitLeavesRelaxed,
        Kernel::Agglomerate,
        Kernel::AgglomerateRelaxed,
        Kernel::AgglomerateSubgroup,
        Kernel::ClimbQueued,
        Kernel::ClimbQueuedRelaxed,
        Kernel::Hploc,
        Kernel::HplocRelaxed,
        Kernel::TreeletInit,
        Kernel::TreeletInitRelaxed,
        Kernel::TreeletInitClimb,
        Kernel::TreeletInitClimbRelaxed,
        Kernel::TreeletHistogram,
        Kernel::TreeletScatter,
        Kernel::TreeletRestructure,
        Kernel::TreeletRestructureSingle,
        Kernel::ReinsertSearch,
        Kernel::ReinsertBid,
        Kernel::ReinsertClaim,
        Kernel::ReinsertApply,
        Kernel::ReinsertRefit,
        Kernel::ReinsertRefitRelaxed,
        Kernel::Collapse,
        Kernel::Bvh2Nodes,
        Kernel::LeafPrims,
        Kernel::Bvh4Nodes,
        Kernel::TreeDepth,
        Kernel::WideDp,
        Kernel::WideDpRelaxed,
        Kernel::WideCount,
        Kernel::WidePlace,
        Kernel::WideEmit,
        Kernel::Cast(Method::Classic, false),
        Kernel::Cast(Method::Bvh2, false),
        Kernel::Cast(Method::Bvh4, false),
        Kernel::Cast(Method::Cwbvh, false),
        Kernel::Cast(Method::Classic, true),
        Kernel::Cast(Method::Bvh2, true),
        Kernel::Cast(Method::Bvh4, true),
        Kernel::Cast(Method::Cwbvh, true),
    ];

    /// Every kernel: the fixed ones and each render kernel the shader has.
    pub fn all() -> Vec<Kernel> {
        let full = VARIANTS.iter().position(|(f, _)| *f == treelet_core::geometry::features::ALL).unwrap() as u8;
        let mut all = Self::FIXED.to_vec();
        all.push(Kernel::CastWideWorkgroupStack);
        all.push(Kernel::RenderPlaced);
        all.push(Kernel::RenderPlacedCaustics);
        all.push(Kernel::LightPlaced);
        for method in Method::ALL {
            for v in 0..VARIANTS.len() as u8 {
                if method.specialized() || v == full {
                    all.push(Kernel::Render(method, v));
                    // Every variant has one (the shader makes them all; only
                    // the caustics variants' trace anything).
                    if method != Method::Classic {
                        all.push(Kernel::Light(method, v));
                    }
                }
            }
        }
        all
    }

    /// Name of the entry point in the shader crate (`<module>::<name>`).
    pub fn entry_point(self) -> &'static str {
        match self {
            Kernel::Fill => "fill::fill_cs",
            Kernel::CopyWords => "fill::copy_words_cs",
            Kernel::GatherTriangles => "gather::gather_triangles_cs",
            Kernel::CastInstances => "render::cast_instances_cs",
            Kernel::InstanceBounds => "bounds::instance_bounds_cs",
            Kernel::TopLevelNodes => "bvh2::top_level_nodes_cs",
            Kernel::PrimitiveBoxes => "scene::primitive_boxes_cs",
            Kernel::PrimitiveBounds => "bounds::primitive_bounds_cs",
            Kernel::Morton => "morton::morton_cs",
            Kernel::SplitPriority => "presplit::split_priority_cs",
            Kernel::SplitCount => "presplit::split_count_cs",
            Kernel::SplitEmit => "presplit::split_emit_cs",
            Kernel::SplitBounds => "presplit::split_bounds_cs",
            Kernel::SplitRemap => "presplit::split_remap_cs",
            Kernel::SortHistogram => "sort::sort_histogram_cs",
            Kernel::SortOffsets => "sort::sort_offsets_cs",
            Kernel::SortSettleTies => "sort::sort_settle_ties_cs",
            Kernel::SortOnesweep => "sort::sort_onesweep_cs",
            Kernel::SortOnesweepSmall => "sort::sort_onesweep_small_cs",
            Kernel::SortMultisplit => "sort::sort_multisplit_cs",
            Kernel::SortMultisplitSmall => "sort::sort_multisplit_small_cs",
            Kernel::SortMultisplitMedium => "sort::sort_multisplit_medium_cs",
            Kernel::SortMultisplitPartitioned => "sort::sort_multisplit_partitioned_cs",
            Kernel::SortMultisplitSmallPartitioned => "sort::sort_multisplit_small_partitioned_cs",
            Kernel::SortMultisplitMediumPartitioned => "sort::sort_multisplit_medium_partitioned_cs",
            Kernel::SortTileCounts => "sort::sort_tile_counts_cs",
            Kernel::SortOnesweepScanned => "sort::sort_onesweep_scanned_cs",
            Kernel::Multisplit => "multisplit::multisplit_cs",
            Kernel::ScanReduce => "scan::scan_reduce_cs",
            Kernel::ScanSpine => "scan::scan_spine_cs",
            Kernel::ScanDownsweep => "scan::scan_downsweep_cs",
            Kernel::RadixTree => "radix_tree::radix_tree_cs",
            Kernel::Fit => "fit::fit_cs",
            Kernel::FitRelaxed => "fit::fit_relaxed_cs",
            Kernel::RefitState => "bvh2::refit_state_cs",
            Kernel::RefitLeaves => "bvh2::refit_cs",
            Kernel::RefitLeavesRelaxed => "bvh2::refit_relaxed_cs",
            Kernel::Agglomerate => "fit::agglomerate_cs",
            Kernel::AgglomerateRelaxed => "fit::agglomerate_relaxed_cs",
            Kernel::AgglomerateSubgroup => "fit::agglomerate_subgroup_cs",
            Kernel::ClimbQueued => "fit::climb_queued_cs",
            Kernel::ClimbQueuedRelaxed => "fit::climb_queued_relaxed_cs",
            Kernel::Hploc => "fit::hploc_cs",
            Kernel::HplocRelaxed => "fit::hploc_relaxed_cs",
            Kernel::TreeletInit => "treelet::treelet_init_cs",
            Kernel::TreeletInitRelaxed => "treelet::treelet_init_relaxed_cs",
            Kernel::TreeletInitClimb => "treelet::treelet_init_climb_cs",
            Kernel::TreeletInitClimbRelaxed => "treelet::treelet_init_climb_relaxed_cs",
            Kernel::TreeletHistogram => "treelet::treelet_histogram_cs",
            Kernel::TreeletScatter => "treelet::treelet_scatter_cs",
            Kernel::TreeletRestructure => "treelet::treelet_restructure_cs",
            Kernel::TreeletRestructureSingle => "treelet::treelet_restructure_single_cs",
            Kernel::ReinsertSearch => "reinsert::reinsert_search_cs",
            Kernel::ReinsertBid => "reinsert::reinsert_bid_cs",
            Kernel::ReinsertClaim => "reinsert::reinsert_claim_cs",
            Kernel::ReinsertApply => "reinsert::reinsert_apply_cs",
            Kernel::ReinsertRefit => "reinsert::reinsert_refit_cs",
            Kernel::ReinsertRefitRelaxed => "reinsert::reinsert_refit_relaxed_cs",
            Kernel::Collapse => "treelet::collapse_cs",
            Kernel::Bvh2Nodes => "bvh2::bvh2_nodes_cs",
            Kernel::LeafPrims => "bvh2::leaf_prims_cs",
            Kernel::Bvh4Nodes => "bvh4::bvh4_nodes_cs",
            Kernel::TreeDepth => "depth::tree_depth_cs",
            Kernel::WideDp => "cwbvh::wide_dp_cs",
            Kernel::WideDpRelaxed => "cwbvh::wide_dp_relaxed_cs",
            Kernel::WideCount => "cwbvh::wide_count_cs",
            Kernel::WidePlace => "cwbvh::wide_place_cs",
            Kernel::WideEmit => "cwbvh::wide_emit_cs",
            Kernel::Render(method, v) => render_entry_point(method, v, false),
            Kernel::RenderPlaced => "render::render_placed_cs",
            Kernel::RenderPlacedCaustics => "render::render_placed_caustics_cs",
            Kernel::LightPlaced => "render::light_placed_cs",
            Kernel::Light(Method::Classic, _) => panic!("no light paths through the seed's layout"),
            Kernel::Light(method, v) => render_entry_point(method, v, true),
            Kernel::Cast(Method::Classic, false) => "render::cast_classic_cs",
            Kernel::Cast(Method::Bvh2, false) => "render::cast_bvh2_cs",
            Kernel::Cast(Method::Bvh4, false) => "render::cast_bvh4_cs",
            Kernel::Cast(Method::Cwbvh, false) => "render::cast_cwbvh_cs",
            Kernel::Cast(Method::Classic, true) => "render::cast_classic_triangles_cs",
            Kernel::Cast(Method::Bvh2, true) => "render::cast_bvh2_triangles_cs",
            Kernel::Cast(Method::Bvh4, true) => "render::cast_bvh4_triangles_cs",
            Kernel::Cast(Method::Cwbvh, true) => "render::cast_cwbvh_triangles_cs",
            Kernel::Cast(Method::Scan, _) => panic!("no cast kernel scans"),
            Kernel::CastWideWorkgroupStack => "render::cast_cwbvh_workgroup_cs",
        }
    }

    /// The bindings (of [`Kernel::bindings`]) that may pass one binding's
    /// limit, in the order of their second parts: the shader declares the
    /// part from the split on (`treelet_core::geometry::split`) as binding
    /// `bindings().len() + k` for the `k`-th of them, with the same access.
    pub fn split_bindings(self) -> &'static [usize] {
        match self {
            Kernel::PrimitiveBoxes | Kernel::PrimitiveBounds | Kernel::RadixTree | Kernel::ClimbQueued | Kernel::ClimbQueuedRelaxed => &[2],
            Kernel::Fit | Kernel::FitRelaxed => &[3],
            Kernel::SplitPriority => &[1],
            Kernel::SplitEmit => &[2],
            Kernel::RefitState => &[1],
            Kernel::RefitLeaves | Kernel::RefitLeavesRelaxed => &[3, 4, 7, 8],
            Kernel::Agglomerate | Kernel::AgglomerateRelaxed | Kernel::AgglomerateSubgroup | Kernel::Hploc | Kernel::HplocRelaxed => &[4],
            Kernel::TreeletInit | Kernel::TreeletInitRelaxed | Kernel::TreeletInitClimb | Kernel::TreeletInitClimbRelaxed | Kernel::TreeDepth => &[1],
            Kernel::Collapse => &[1, 6],
            Kernel::ReinsertSearch
            | Kernel::ReinsertBid
            | Kernel::ReinsertClaim
            | Kernel::ReinsertApply
            | Kernel::ReinsertRefit
            | Kernel::ReinsertRefitRelaxed => &[1],
            Kernel::TreeletRestructure => &[3],
            Kernel::TreeletRestructureSingle => &[2],
            Kernel::Bvh2Nodes => &[1, 3],
            Kernel::LeafPrims => &[3, 4],
            Kernel::WideEmit => &[9],
            // Traversal: the `bvh2` layout's nodes and leaf primitives too.
            Kernel::Render(Method::Bvh2, _) | Kernel::Light(Method::Bvh2, _) | Kernel::Cast(Method::Bvh2, _) | Kernel::RenderPlaced | Kernel::RenderPlacedCaustics | Kernel::LightPlaced => &[6, 3, 4],
            Kernel::Render(..) | Kernel::Light(..) | Kernel::Cast(..) | Kernel::CastWideWorkgroupStack => &[6],
            _ => &[],
        }
    }

    /// Invocations per workgroup of the kernel's entry point (the number a
    /// dispatch's workgroups are counted in): the ray kernels' own size
    /// (`treelet_core::gpu::workgroup::RAY_WORKGROUP_SIZE`), else
    /// `WORKGROUP_SIZE`.
    pub fn workgroup_size(self) -> u32 {
        use treelet_core::gpu::workgroup::{RAY_WORKGROUP_SIZE, WORKGROUP_SIZE};
        match self {
            Kernel::Render(..)
            | Kernel::Light(..)
            | Kernel::RenderPlaced
            | Kernel::RenderPlacedCaustics
            | Kernel::LightPlaced
            | Kernel::Cast(..)
            | Kernel::CastInstances => RAY_WORKGROUP_SIZE,
            _ => WORKGROUP_SIZE,
        }
    }

    /// Bindings in order; binding 0 is always the parameter struct.
    pub fn bindings(self) -> &'static [Access] {
        match self {
            Kernel::Fill => &[Read, ReadWrite],
            Kernel::CopyWords => &[Read, Read, ReadWrite],
            Kernel::GatherTriangles => &[Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::CastInstances => &[Read, Read, Read, Read, Read, Read, ReadWrite],
            Kernel::InstanceBounds => &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::TopLevelNodes => &[Read, Read, Read, ReadWrite, Read, ReadWrite],
            Kernel::PrimitiveBoxes => &[Read, Read, Read, ReadWrite],
            Kernel::PrimitiveBounds => &[Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::Morton => &[Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite],
            Kernel::SplitPriority => &[Read, Read, ReadWrite, ReadWrite],
            Kernel::SplitCount => &[Read, Read, ReadWrite],
            Kernel::SplitEmit => &[Read, Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::SplitBounds => &[Read, Read, ReadWrite, ReadWrite],
            Kernel::SplitRemap => &[Read, Read, ReadWrite],
            Kernel::SortHistogram => &[Read, Read, ReadWrite],
            Kernel::ScanReduce => &[Read, Read, ReadWrite],
            Kernel::ScanSpine => &[Read, ReadWrite],
            Kernel::ScanDownsweep => &[Read, ReadWrite, Read],
            Kernel::SortOffsets => &[Read, ReadWrite],
            Kernel::SortSettleTies => &[Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::SortOnesweep
            | Kernel::SortOnesweepSmall
            | Kernel::SortOnesweepScanned
            | Kernel::SortMultisplit
            | Kernel::SortMultisplitSmall
            | Kernel::SortMultisplitMedium
            | Kernel::SortMultisplitPartitioned
            | Kernel::SortMultisplitSmallPartitioned
            | Kernel::SortMultisplitMediumPartitioned => &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::SortTileCounts => &[Read, Read, ReadWrite],
            Kernel::Multisplit => &[Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::RadixTree => &[Read, Read, ReadWrite, ReadWrite],
            Kernel::Fit | Kernel::FitRelaxed => &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::RefitState => &[Read, Read, Read, ReadWrite],
            Kernel::RefitLeaves | Kernel::RefitLeavesRelaxed => &[Read, Read, Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::Agglomerate | Kernel::AgglomerateRelaxed => {
                &[Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::AgglomerateSubgroup => &[Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite],
            Kernel::ClimbQueued | Kernel::ClimbQueuedRelaxed => &[Read, Read, ReadWrite, ReadWrite, ReadWrite, Read, Read],
            Kernel::Hploc | Kernel::HplocRelaxed => &[Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite],
            Kernel::TreeletInit | Kernel::TreeletInitRelaxed => {
                &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::TreeletInitClimb | Kernel::TreeletInitClimbRelaxed => {
                &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, Read, Read]
            }
            Kernel::TreeletHistogram => &[Read, Read, Read, ReadWrite],
            Kernel::TreeletScatter => &[Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::TreeletRestructure => {
                &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::TreeletRestructureSingle => {
                &[Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::ReinsertSearch => &[Read, Read, Read, ReadWrite],
            Kernel::ReinsertBid => &[Read, Read, Read, Read, ReadWrite],
            Kernel::ReinsertClaim => &[Read, Read, Read, Read, Read, ReadWrite],
            Kernel::ReinsertApply => &[Read, ReadWrite, ReadWrite, Read, Read, Read, ReadWrite],
            Kernel::ReinsertRefit | Kernel::ReinsertRefitRelaxed => &[Read, ReadWrite, Read, ReadWrite],
            Kernel::Collapse => &[Read, Read, Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::Bvh2Nodes => &[Read, Read, Read, ReadWrite],
            Kernel::Bvh4Nodes => &[Read, Read, ReadWrite],
            Kernel::LeafPrims => &[Read, Read, Read, Read, ReadWrite],
            Kernel::TreeDepth => &[Read, Read, Read, ReadWrite],
            Kernel::WideDp | Kernel::WideDpRelaxed => &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite],
            Kernel::WideCount => &[Read, Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::WidePlace => &[Read, Read, Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::WideEmit => &[Read, Read, Read, Read, Read, Read, Read, Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::Render(..) | Kernel::Light(..) => &[Read, Read, Read, Read, Read, ReadWrite, Read, Read],
            // The render's, then the copies' (`render::render_placed_cs`).
            Kernel::RenderPlaced | Kernel::RenderPlacedCaustics | Kernel::LightPlaced => &[Read, Read, Read, Read, Read, ReadWrite, Read, Read, Read, Read, Read, Read, Read, Read],
            Kernel::Cast(..) | Kernel::CastWideWorkgroupStack => &[Read, Read, Read, Read, Read, ReadWrite, Read],
        }
    }
}
