//! # The kernel registry
//!
//! Kernels that run one core function once per invocation (invocation `id`
//! of a one-dimensional dispatch in workgroups of
//! [`WORKGROUP_SIZE`](crate::gpu::workgroup::WORKGROUP_SIZE), its parameter struct at
//! binding 0, then storage buffers) are declared once, in
//! [`per_invocation_kernels!`](crate::per_invocation_kernels); kernels that
//! run a core function phase by phase over each workgroup, with workgroup
//! memory and a barrier between phases, in
//! [`per_workgroup_kernels!`](crate::per_workgroup_kernels). From that
//! one declaration:
//!
//! - the shader crate makes each kernel's entry point (`treelet-shader`'s
//!   `per_invocation` and `per_workgroup` modules),
//! - the host makes its `Kernel` variant, entry-point name, binding
//!   accesses and split bindings, and a struct of its bindings by name
//!   that a dispatch fills (`treelet::runtime::kernels::bind`),
//! - the CPU runner makes its dispatch (`treelet::runtime::cpu_runner`).
//!
//! So the GPU and the CPU run the same call on the same bindings, and
//! adding such a kernel is one entry here. The families with compile-time
//! variants have lists of their own: the render kernels
//! ([`for_each_render_variant!`](crate::for_each_render_variant)), the sort
//! passes ([`for_each_sort_pass!`](crate::for_each_sort_pass)) and the
//! ray-casting kernels ([`for_each_cast_kernel!`](crate::for_each_cast_kernel)).
//! The few others with subgroup operations or teams within a workgroup
//! (H-PLOC, the treelet teams) are written out in the shader crate and the
//! CPU runner.
//!
//! An entry reads:
//!
//! ```text
//! /// What it does.
//! Name = entry_point_cs(Params) {
//!     1 input: read [T],
//!     2 output: write [U as CpuU],
//!     3 nodes: read [Node] | 5 nodes_hi,
//! } |id, params| $crate::path::to::kernel(id, params, input, output, &nodes);
//! ```
//!
//! - Each binding: its number (binding 0 is `params`), name, `read` or
//!   `write`, and element type. The numbers are written out because the
//!   shader's binding attributes take literals; the host checks them
//!   (`treelet::runtime::kernels`' tests).
//! - `as CpuU`: the CPU runner views the buffer as `CpuU` instead. Its
//!   buffers are 8-byte aligned, and glam's `Vec4` needs 16.
//! - `| n name_hi`: a buffer that may pass one binding's limit, bound in
//!   two parts (the second at binding `n`: `bindings + k` for the `k`-th
//!   such buffer). The call sees one `Split` (read) or `SplitMut` (write)
//!   view of both ([`crate::geometry::split`]); the CPU runner binds it
//!   whole.
//! - The call: what each invocation runs, with `id` and `params` (`&Params`)
//!   and the bindings by name.
//! - `Name / NameRelaxed = name_cs / name_relaxed_cs(...)`: two kernels of
//!   one declaration, whose call reads the constant `ORDERED`: `true` in the
//!   first (acquire-release atomics, for GPUs), `false` in the second
//!   (relaxed, for CPU adapters such as lavapipe: see
//!   [`crate::gpu::atomics`]).
//!
//! The macro hands the entries to a macro of the caller's (`$callback`),
//! which makes what its side needs of them; the second kernel of a pair
//! comes marked `#[relaxed_of(Name)]` (the host maps each kernel to its
//! relaxed twin from it).

/// The per-invocation kernels; see [`crate::registry`].
#[macro_export]
macro_rules! per_invocation_kernels {
    ($callback:ident) => {
        $crate::__kernel_pairs! { $callback []
            /// Fills a buffer's words with a value.
            Fill = fill_cs($crate::geometry::buffers::FillParams) {
                1 data: write [u32],
            } |id, params| $crate::construct::fill::fill_kernel(id, params, data);

            /// Words copied from one buffer into another.
            CopyWords = copy_words_cs($crate::geometry::buffers::CopyParams) {
                1 src: read [u32],
                2 dst: write [u32],
            } |id, params| $crate::construct::fill::copy_words_kernel(id, params, src, dst);

            /// An engine's mesh gathered from its vertex and index buffers into
            /// triangles (`treelet_core::geometry::gather`).
            GatherTriangles = gather_triangles_cs($crate::geometry::buffers::GatherParams) {
                1 vertices: read [u32],
                2 indices: read [u32],
                3 out: write [$crate::geometry::triangle::Triangle],
                4 flags: write [u32],
            } |id, params| $crate::geometry::gather::gather_triangles_kernel(id, params, vertices, indices, out, flags);

            /// Primitive boxes (spheres, then triangles).
            PrimitiveBoxes = primitive_boxes_cs($crate::geometry::buffers::BuildParams) {
                1 spheres: read [$crate::geometry::buffers::Sphere],
                2 triangles: read [$crate::geometry::triangle::Triangle] | 4 triangles_hi,
                3 boxes: write [$crate::geometry::records::Vec4 as $crate::geometry::aabb::Aabb],
            } |id, params| $crate::construct::primitive_boxes::primitive_boxes_kernel(id, params.n, params.spheres, spheres, &triangles, boxes);

            /// Morton codes of the primitives' centroids.
            Morton = morton_cs($crate::geometry::buffers::BuildParams) {
                1 boxes: read [$crate::geometry::aabb::Aabb],
                2 keys: write [u64],
                3 values: write [u32],
                4 slots: write [u32],
                5 zeroed: write [u32],
            } |id, params| $crate::construct::morton::morton_kernel(id, params, boxes, keys, values, slots, zeroed);

            /// Bottom-up fit of the radix tree's boxes: a climb from each leaf,
            /// the second to arrive at a node goes on (`construct::fit`).
            Fit / FitRelaxed = fit_cs / fit_relaxed_cs($crate::geometry::buffers::BuildParams) {
                1 sorted_prims: read [u32],
                2 prim_boxes: read [$crate::geometry::aabb::Aabb],
                3 nodes: write [$crate::geometry::buffers::Node] | 6 nodes_hi,
                4 parents: write [u32],
                5 flags: write [u32],
            } |id, params| $crate::construct::fit::fit_kernel::<ORDERED>(id, params.n, sorted_prims, prim_boxes, &mut nodes, parents, flags);

            /// Hierarchy and boxes in one bottom-up pass (Apetrei 2014).
            Agglomerate / AgglomerateRelaxed = agglomerate_cs / agglomerate_relaxed_cs($crate::geometry::buffers::BuildParams) {
                1 keys: read [u64],
                2 sorted_prims: read [u32],
                3 prim_boxes: read [$crate::geometry::aabb::Aabb],
                4 nodes: write [$crate::geometry::buffers::Node] | 7 nodes_hi,
                5 parents: write [u32],
                6 ends: write [u32],
            } |id, params| $crate::construct::agglomerate::agglomerate_kernel::<ORDERED>(id, params.n, keys, sorted_prims, prim_boxes, &mut nodes, parents, ends);

            /// The climbs of the clusters the subgroup agglomeration queued.
            ClimbQueued / ClimbQueuedRelaxed = climb_queued_cs / climb_queued_relaxed_cs($crate::geometry::buffers::BuildParams) {
                1 keys: read [u64],
                2 nodes: write [$crate::geometry::buffers::Node] | 7 nodes_hi,
                3 parents: write [u32],
                4 ends: write [u32],
                5 queue: read [u32],
                6 queued: read [u32],
            } |id, params| $crate::construct::agglomerate_subgroup::climb_queued_kernel::<ORDERED>(id, params.n, keys, &mut nodes, parents, ends, queue, queued);

            /// Triangle splitting: each primitive's pieces, boxes and primitive.
            SplitEmit = split_emit_cs($crate::geometry::buffers::SplitParams) {
                1 spheres: read [$crate::geometry::buffers::Sphere],
                2 triangles: read [$crate::geometry::triangle::Triangle] | 6 triangles_hi,
                3 offsets: read [u32],
                4 ref_boxes: write [$crate::geometry::records::Vec4 as $crate::geometry::aabb::Aabb],
                5 ref_prims: write [u32],
            } |id, params| $crate::construct::presplit::emit_kernel(id, params, spheres, triangles, offsets, ref_boxes, ref_prims);

            /// Triangle splitting: pieces per primitive.
            SplitCount = split_count_cs($crate::geometry::buffers::SplitParams) {
                1 priorities: read [f32],
                2 counts: write [u32],
            } |id, params| $crate::construct::presplit::count_kernel(id, params, priorities, counts);

            /// Triangle splitting: leaf slots name primitives instead of pieces.
            SplitRemap = split_remap_cs($crate::geometry::buffers::BuildParams) {
                1 ref_prims: read [u32],
                2 values: write [u32],
            } |id, params| $crate::construct::presplit::remap_kernel(id, params.n, ref_prims, values);

            /// Sort: runs of keys tied in their high digits ordered by their low ones.
            SortSettleTies = sort_settle_ties_cs($crate::geometry::buffers::SortParams) {
                1 keys: write [u64],
                2 values: write [u32],
                3 sort_state: write [u32],
            } |id, params| $crate::construct::sort::ties::settle_ties_kernel(id, params, keys, values, sort_state);

            /// The binary radix tree over sorted Morton codes (Karras 2012).
            RadixTree = radix_tree_cs($crate::geometry::buffers::BuildParams) {
                1 keys: read [u64],
                2 nodes: write [$crate::geometry::buffers::Node] | 4 nodes_hi,
                3 parents: write [u32],
            } |id, params| $crate::construct::radix_tree::radix_tree_kernel(id, params.n, keys, &mut nodes, parents);

            /// Reinsertion (Meister & Bittner 2018): each node's best move.
            ReinsertSearch = reinsert_search_cs($crate::geometry::buffers::ReinsertParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 4 nodes_hi,
                2 parents: read [u32],
                3 moves: write [$crate::geometry::buffers::Reinsertion],
            } |id, params| $crate::construct::reinsert::search_kernel(id, params, &nodes, parents, moves);

            /// Reinsertion: moves bid their gains on their nodes.
            ReinsertBid = reinsert_bid_cs($crate::geometry::buffers::ReinsertParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 5 nodes_hi,
                2 parents: read [u32],
                3 moves: read [$crate::geometry::buffers::Reinsertion],
                4 bids: write [u32],
            } |id, params| $crate::construct::reinsert::bid_kernel(id, params, &nodes, parents, moves, bids);

            /// Reinsertion: moves that won every bid claim their nodes.
            ReinsertClaim = reinsert_claim_cs($crate::geometry::buffers::ReinsertParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 6 nodes_hi,
                2 parents: read [u32],
                3 moves: read [$crate::geometry::buffers::Reinsertion],
                4 bids: read [u32],
                5 owners: write [u32],
            } |id, params| $crate::construct::reinsert::claim_kernel(id, params, &nodes, parents, moves, bids, owners);

            /// Reinsertion: the moves that hold all their nodes are made.
            ReinsertApply = reinsert_apply_cs($crate::geometry::buffers::ReinsertParams) {
                1 nodes: write [$crate::geometry::buffers::Node] | 7 nodes_hi,
                2 parents: write [u32],
                3 moves: read [$crate::geometry::buffers::Reinsertion],
                4 bids: read [u32],
                5 owners: read [u32],
                6 made: write [u32],
            } |id, params| $crate::construct::reinsert::apply_kernel(id, params, &mut nodes, parents, moves, bids, owners, made);

            /// Reinsertion: boxes refit from the leaves after the moves.
            ReinsertRefit / ReinsertRefitRelaxed = reinsert_refit_cs / reinsert_refit_relaxed_cs($crate::geometry::buffers::ReinsertParams) {
                1 nodes: write [$crate::geometry::buffers::Node] | 4 nodes_hi,
                2 parents: read [u32],
                3 flags: write [u32],
            } |id, params| $crate::construct::fit::refit_nodes_kernel::<ORDERED>(id, params.n, &mut nodes, parents, flags);

            /// Treelet optimization: per-node counts, costs, heights (bottom up).
            TreeletInit / TreeletInitRelaxed = treelet_init_cs / treelet_init_relaxed_cs($crate::geometry::buffers::TreeletParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 10 nodes_hi,
                2 parents: read [u32],
                3 flags: write [u32],
                4 counts: write [u32],
                5 costs: write [f32],
                6 heights: write [u32],
                7 tree_leaves: write [u32],
                8 queue: write [u32],
                9 queued: write [u32],
            } |id, params| $crate::construct::treelet::kernels::treelet_init_kernel::<ORDERED, _>(id, params, &nodes, parents, flags, (&mut *counts, &mut *costs, &mut *heights, &mut *tree_leaves), queue, queued);

            /// The climbs `TreeletInit` queued.
            TreeletInitClimb / TreeletInitClimbRelaxed = treelet_init_climb_cs / treelet_init_climb_relaxed_cs($crate::geometry::buffers::TreeletParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 10 nodes_hi,
                2 parents: read [u32],
                3 flags: write [u32],
                4 counts: write [u32],
                5 costs: write [f32],
                6 heights: write [u32],
                7 tree_leaves: write [u32],
                8 queue: read [u32],
                9 queued: read [u32],
            } |id, params| $crate::construct::treelet::kernels::treelet_init_climb_kernel::<ORDERED, _>(id, params, &nodes, parents, flags, (&mut *counts, &mut *costs, &mut *heights, &mut *tree_leaves), queue, queued);

            /// Restructures the treelets of one height, one invocation each
            /// (heights of many small treelets).
            TreeletRestructureSingle = treelet_restructure_single_cs($crate::geometry::buffers::TreeletParams) {
                1 roots: read [u32],
                2 nodes: write [$crate::geometry::buffers::Node] | 8 nodes_hi,
                3 parents: write [u32],
                4 counts: write [u32],
                5 costs: write [f32],
                6 heights: write [u32],
                7 marks: write [u32],
            } |id, params| $crate::construct::treelet::kernels::treelet_restructure_single(id, params, roots, &mut nodes, parents, counts, costs, heights, marks);

            /// SAH leaf collapse and depth-first compaction into fresh arrays.
            Collapse = collapse_cs($crate::geometry::buffers::TreeletParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 9 nodes_hi,
                2 parents: read [u32],
                3 counts: read [u32],
                4 tree_leaves: read [u32],
                5 prims: read [u32],
                6 out_nodes: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::Node] | 10 out_nodes_hi,
                7 out_parents: write [u32],
                8 out_prims: write [u32],
            } |id, params| $crate::construct::collapse::collapse_kernel(id, params.n, &nodes, parents, counts, tree_leaves, prims, &mut out_nodes, out_parents, out_prims);

            /// A `bvh2` layout's refit in place: its leaf primitives, and its boxes
            /// bottom-up over its collapsed tree.
            RefitLeaves / RefitLeavesRelaxed = refit_cs / refit_relaxed_cs($crate::geometry::buffers::LayoutParams) {
                1 prim_indices: read [u32],
                2 spheres: read [$crate::geometry::buffers::Sphere],
                3 triangles: read [$crate::geometry::triangle::Triangle] | 9 triangles_hi,
                4 nodes: read [$crate::geometry::buffers::Node] | 10 nodes_hi,
                5 parents: read [u32],
                6 state: write [u32],
                7 out_prims: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::LeafPrim] | 11 out_prims_hi,
                8 out_nodes: write [f32] | 12 out_nodes_hi,
            } |id, params| $crate::layouts::bvh2::refit_kernel::<ORDERED, _, _>(
                id, params.n, params.nodes,
                &$crate::geometry::prims::Prims { spheres, sphere_count: params.spheres, triangles, triangle_count: params.n - params.spheres },
                prim_indices, &nodes, parents, state, &mut out_prims, &mut out_nodes,
            );

            /// The two-box binary layout from a collapsed tree.
            Bvh2Nodes = bvh2_nodes_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 4 nodes_hi,
                2 parents: read [u32],
                3 out: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::Bvh2Node] | 5 out_hi,
            } |id, params| $crate::layouts::bvh2::bvh2_node_kernel(id, params.nodes, &nodes, parents, &mut out);

            /// Primitives in leaf order.
            LeafPrims = leaf_prims_cs($crate::geometry::buffers::LayoutParams) {
                1 prim_indices: read [u32],
                2 spheres: read [$crate::geometry::buffers::Sphere],
                3 triangles: read [$crate::geometry::triangle::Triangle] | 5 triangles_hi,
                4 out: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::LeafPrim] | 6 out_hi,
            } |id, params| $crate::layouts::bvh2::leaf_prims_kernel(id, params.n, params.spheres, prim_indices, spheres, triangles, &mut out);

            /// The state a `bvh2` layout's refit climbs on (counters, node indices,
            /// the leaf each primitive slot starts), made once per tree.
            RefitState = refit_state_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 4 nodes_hi,
                2 parents: read [u32],
                3 state: write [u32],
            } |id, params| $crate::layouts::bvh2::refit_state_kernel(id, params.nodes, &nodes, parents, state);

            /// An instanced scene's top level in the two-box layout, from its LBVH
            /// as built (leaves refer to instances).
            TopLevelNodes = top_level_nodes_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node],
                2 prim_indices: read [u32],
                3 out: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::Bvh2Node],
                4 parents: read [u32],
                5 deepest: write [u32],
            } |id, params| $crate::layouts::bvh2::top_level_kernel(id, params.n, nodes, parents, prim_indices, out, deepest);

            /// The 4-wide layout from the two-box one.
            Bvh4Nodes = bvh4_nodes_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::records::Vec4 as $crate::geometry::buffers::Bvh2Node],
                2 out: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::Bvh4Node],
            } |id, params| $crate::layouts::bvh4::bvh4_node_kernel(id, params.nodes, nodes, out);

            /// The depth of a tree (each leaf climbs; the deepest counts).
            TreeDepth = tree_depth_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node] | 4 nodes_hi,
                2 parents: read [u32],
                3 deepest: write [u32],
            } |id, params| $crate::layouts::depth::leaf_depth_kernel(id, params.nodes, &nodes, parents, deepest);

            /// The compressed wide BVH: SAH DP over the binary tree (bottom up).
            WideDp / WideDpRelaxed = wide_dp_cs / wide_dp_relaxed_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node],
                2 parents: read [u32],
                3 flags: write [u32],
                4 counts: write [u32],
                5 costs: write [f32],
                6 decisions: write [u32],
            } |id, params| $crate::layouts::cwbvh::build::wide_dp_kernel::<ORDERED>(id, params, nodes, parents, flags, counts, costs, decisions);

            /// The compressed wide BVH: which nodes are wide nodes, their children's counts.
            WideCount = wide_count_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node],
                2 parents: read [u32],
                3 counts: read [u32],
                4 decisions: read [u32],
                5 is_wide: write [u32],
                6 child_counts: write [u32],
                7 prim_counts: write [u32],
            } |id, params| $crate::layouts::cwbvh::build::wide_count_kernel(id, params, nodes, parents, counts, decisions, is_wide, child_counts, prim_counts);

            /// The compressed wide BVH: nodes and leaf primitives.
            WideEmit = wide_emit_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node],
                2 slots: read [u32],
                3 is_wide: read [u32],
                4 child_offsets: read [u32],
                5 prim_offsets: read [u32],
                6 positions: read [u32],
                7 prim_indices: read [u32],
                8 spheres: read [$crate::geometry::buffers::Sphere],
                9 triangles: read [$crate::geometry::triangle::Triangle] | 12 triangles_hi,
                10 out_nodes: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::WideNode],
                11 out_prims: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::LeafPrim],
            } |id, params| $crate::layouts::cwbvh::build::wide_emit_kernel(
                id, params, nodes, slots, is_wide, child_offsets, prim_offsets, positions, prim_indices, spheres, triangles, out_nodes, out_prims,
            );

            /// The compressed wide BVH: indices of wide nodes.
            WidePlace = wide_place_cs($crate::geometry::buffers::LayoutParams) {
                1 nodes: read [$crate::geometry::buffers::Node],
                2 decisions: read [u32],
                3 is_wide: read [u32],
                4 child_offsets: read [u32],
                5 positions: write [u32],
                6 slots: write [u32],
            } |id, params| $crate::layouts::cwbvh::build::wide_place_kernel(id, params, nodes, decisions, is_wide, child_offsets, positions, slots);
        }
    };
}

/// The kernels that run a core function phase by phase over each workgroup
/// (a barrier between phases; workgroup memory shared within the
/// workgroup); see [`crate::registry`]. An entry reads:
///
/// ```text
/// /// What it does.
/// Name = entry_point_cs(Params) phases(PHASES, [0 1 2]) shared { local: [u32; WG] } {
///     1 input: read [T],
///     2 output: write [U],
/// } |phase, lid, group, params| $crate::path::to::name_phase(phase, lid, group, params, input, output, local);
/// ```
///
/// - `phases`: the constant that counts them, and each phase's number
///   written out: the shader unrolls the phases, each with its number a
///   constant, so that the driver's compiler keeps only that phase's
///   branch of the function (a loop over phases pays for all of it in
///   every phase); the shader checks the two agree.
/// - `shared`: the workgroup arrays (uninitialized on the GPU: a phase
///   writes before another reads; zeroed on the CPU runner).
/// - The call sees the phase, the invocation's index in its workgroup
///   (`lid`), the workgroup's index (`group`), the parameters (a private
///   copy on the GPU, kept in registers across the barriers: 1% off the
///   H200's sort), the bindings as in [`per_invocation_kernels!`](crate::per_invocation_kernels)
///   and the shared arrays (`&mut [T; N]`).
///
/// Given `{ tokens }` after the callback, the callback gets them first
/// (so that one callback can take both registries' entries).
#[macro_export]
macro_rules! per_workgroup_kernels {
    ($callback:ident $({ $($carried:tt)* })?) => {
        $callback! {
            $({ $($carried)* })?

            /// Exclusive scan: each tile's sum.
            ScanReduce = scan_reduce_cs($crate::geometry::buffers::ScanParams)
                phases($crate::construct::sort::scan::SCAN_REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9])
                shared { sums: [u32; $crate::gpu::workgroup::WG] } {
                1 data: read [u32],
                2 partials: write [u32],
            } |phase, lid, group, params| $crate::construct::sort::scan::scan_reduce_phase(phase, lid, group, params, data, partials, sums);

            /// Exclusive scan: the tiles' sums scanned by one workgroup.
            ScanSpine = scan_spine_cs($crate::geometry::buffers::ScanParams)
                phases($crate::construct::sort::scan::SCAN_SWEEP_PHASES, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17])
                shared { a: [u32; $crate::gpu::workgroup::WG], b: [u32; $crate::gpu::workgroup::WG] } {
                1 partials: write [u32],
            } |phase, lid, group, params| $crate::construct::sort::scan::scan_spine_phase(phase, lid, params, partials, a, b);

            /// Exclusive scan: each tile scanned from its offset.
            ScanDownsweep = scan_downsweep_cs($crate::geometry::buffers::ScanParams)
                phases($crate::construct::sort::scan::SCAN_SWEEP_PHASES, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17])
                shared { a: [u32; $crate::gpu::workgroup::WG], b: [u32; $crate::gpu::workgroup::WG] } {
                1 data: write [u32],
                2 partials: read [u32],
            } |phase, lid, group, params| $crate::construct::sort::scan::scan_downsweep_phase(phase, lid, group, params, data, partials, a, b);

            /// Radix sort: digit counts of every pass.
            SortHistogram = sort_histogram_cs($crate::geometry::buffers::SortParams)
                phases($crate::construct::sort::HISTOGRAM_PHASES, [0 1 2])
                shared { counts: [u32; ($crate::construct::sort::MAX_PASSES * $crate::construct::sort::RADIX) as usize] } {
                1 keys: read [u64],
                2 sort_state: write [u32],
            } |phase, lid, group, params| $crate::construct::sort::histogram_phase(phase, lid, group, params, keys, sort_state, counts);

            /// Radix sort: where each digit starts, per pass (a workgroup a pass).
            SortOffsets = sort_offsets_cs($crate::geometry::buffers::SortParams)
                phases($crate::construct::sort::OFFSETS_PHASES, [0 1 2 3 4])
                shared { values: [u32; $crate::gpu::workgroup::WG], out: [u32; $crate::gpu::workgroup::WG], sums: [u32; 16] } {
                1 sort_state: write [u32],
            } |phase, lid, group, params| $crate::construct::sort::offsets_phase(phase, lid, group, params, sort_state, values, out, sums);

            /// Radix sort without look-back: each tile's digit counts.
            SortTileCounts = sort_tile_counts_cs($crate::geometry::buffers::SortParams)
                phases($crate::construct::sort::TILE_COUNTS_PHASES, [0 1 2])
                shared { counts: [u32; $crate::gpu::workgroup::WG] } {
                1 keys: read [u64],
                2 tile_counts: write [u32],
            } |phase, lid, group, params| $crate::construct::sort::tile_counts_phase(phase, lid, group, params, keys, tile_counts, counts);

            /// Counts treelet roots per height (a local histogram per workgroup first).
            TreeletHistogram = treelet_histogram_cs($crate::geometry::buffers::TreeletParams)
                phases($crate::construct::treelet::kernels::HISTOGRAM_PHASES, [0 1 2])
                shared { local: [u32; $crate::gpu::workgroup::WG] } {
                1 counts: read [u32],
                2 heights: read [u32],
                3 level_counts: write [u32],
            } |phase, lid, group, params| $crate::construct::treelet::kernels::treelet_histogram_phase(phase, lid, group, params, counts, heights, level_counts, local);

            /// Lists treelet roots by height (a range per workgroup and height).
            TreeletScatter = treelet_scatter_cs($crate::geometry::buffers::TreeletParams)
                phases($crate::construct::treelet::kernels::SCATTER_PHASES, [0 1 2 3])
                shared { local: [u32; $crate::gpu::workgroup::WG], ranks: [u32; $crate::gpu::workgroup::WG] } {
                1 counts: read [u32],
                2 heights: read [u32],
                3 cursors: write [u32],
                4 roots: write [u32],
            } |phase, lid, group, params| $crate::construct::treelet::kernels::treelet_scatter_phase(phase, lid, group, params, counts, heights, cursors, roots, local, ranks);

            /// The primitive boxes (spheres, then triangles), and their centroid bounds.
            PrimitiveBounds = primitive_bounds_cs($crate::geometry::buffers::BuildParams)
                phases($crate::construct::bounds::REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9])
                shared { shared: [$crate::geometry::aabb::Aabb; $crate::gpu::workgroup::WG] } {
                1 spheres: read [$crate::geometry::buffers::Sphere],
                2 triangles: read [$crate::geometry::triangle::Triangle] | 5 triangles_hi,
                3 boxes: write [$crate::geometry::records::Vec4 as $crate::geometry::aabb::Aabb],
                4 bounds: write [u32],
            } |phase, lid, group, params| {
                let mut source = $crate::construct::bounds::PrimitiveBoxes { spheres: params.spheres, sphere_data: spheres, triangles };
                $crate::construct::bounds::primitive_bounds_phase(phase, lid, group, params.n, &mut source, boxes, bounds, shared)
            };

            /// An instanced scene's top level: each instance's record and world
            /// box (`construct::instances`), and their centroid bounds.
            InstanceBounds = instance_bounds_cs($crate::geometry::buffers::BuildParams)
                phases($crate::construct::bounds::REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9])
                shared { shared: [$crate::geometry::aabb::Aabb; $crate::gpu::workgroup::WG] } {
                1 descs: read [$crate::geometry::records::Vec4 as $crate::geometry::buffers::InstanceDesc],
                2 meshes: read [$crate::geometry::records::Vec4 as $crate::geometry::buffers::MeshRecord],
                3 records: write [$crate::geometry::records::Vec4 as $crate::geometry::buffers::InstanceRecord],
                4 boxes: write [$crate::geometry::records::Vec4 as $crate::geometry::aabb::Aabb],
                5 bounds: write [u32],
            } |phase, lid, group, params| {
                let mut source = $crate::construct::instances::InstanceBoxes { descs, meshes, records: &mut *records };
                $crate::construct::bounds::primitive_bounds_phase(phase, lid, group, params.n, &mut source, boxes, bounds, shared)
            };

            /// Triangle splitting: each primitive's priority, and their sum per workgroup.
            SplitPriority = split_priority_cs($crate::geometry::buffers::SplitParams)
                phases($crate::construct::presplit::PRIORITY_PHASES, [0 1 2 3 4 5 6 7 8 9])
                shared { shared: [f32; $crate::gpu::workgroup::WG] } {
                1 triangles: read [$crate::geometry::triangle::Triangle] | 4 triangles_hi,
                2 priorities: write [f32],
                3 partials: write [f32],
            } |phase, lid, group, params| $crate::construct::presplit::priority_phase(phase, lid, group, params, triangles, priorities, partials, shared);

            /// Triangle splitting: the pieces' boxes as the build's, with their centroid bounds.
            SplitBounds = split_bounds_cs($crate::geometry::buffers::BuildParams)
                phases($crate::construct::bounds::REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9])
                shared { shared: [$crate::geometry::aabb::Aabb; $crate::gpu::workgroup::WG] } {
                1 ref_boxes: read [$crate::geometry::aabb::Aabb],
                2 boxes: write [$crate::geometry::records::Vec4 as $crate::geometry::aabb::Aabb],
                3 bounds: write [u32],
            } |phase, lid, group, params| {
                let mut source = $crate::construct::presplit::StoredBoxes { boxes: ref_boxes };
                $crate::construct::bounds::primitive_bounds_phase(phase, lid, group, params.n, &mut source, boxes, bounds, shared)
            };
        }
    };
}

/// Hands [`per_invocation_kernels!`](crate::per_invocation_kernels)' entries
/// to the callback, each ordered/relaxed pair made two entries (with
/// `ORDERED` defined for each call).
#[doc(hidden)]
#[macro_export]
macro_rules! __kernel_pairs {
    ($callback:ident [$($done:tt)*]) => {
        $callback! { $($done)* }
    };
    ($callback:ident [$($done:tt)*]
        $(#[doc = $doc:expr])*
        $name:ident / $relaxed:ident = $entry:ident / $relaxed_entry:ident($params:ty) { $($bindings:tt)* } |$id:ident, $p:ident| $call:expr;
        $($rest:tt)*
    ) => {
        $crate::__kernel_pairs! { $callback [$($done)*
            $(#[doc = $doc])*
            $name = $entry($params) { $($bindings)* } |$id, $p| { const ORDERED: bool = true; $call };
            #[doc = concat!("`", stringify!($name), "` with relaxed atomics, for CPU adapters (lavapipe).")]
            #[relaxed_of($name)]
            $relaxed = $relaxed_entry($params) { $($bindings)* } |$id, $p| { const ORDERED: bool = false; $call };
        ] $($rest)* }
    };
    ($callback:ident [$($done:tt)*]
        $(#[doc = $doc:expr])*
        $name:ident = $entry:ident($params:ty) { $($bindings:tt)* } |$id:ident, $p:ident| $call:expr;
        $($rest:tt)*
    ) => {
        $crate::__kernel_pairs! { $callback [$($done)* $(#[doc = $doc])* $name = $entry($params) { $($bindings)* } |$id, $p| $call;] $($rest)* }
    };
}
