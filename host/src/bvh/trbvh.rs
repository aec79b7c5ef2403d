//! Treelet restructuring of an LBVH on the device (Karras & Aila 2013),
//! round by round (the kernels: `treelet_core::construct::treelet::kernels`): a
//! bottom-up pass computes each node's primitive count, SAH cost and height
//! once; each round lists the roots of its treelets (at least `gamma`
//! primitives) by height, then restructures them with one dispatch per
//! height, from the leaves up, a team of 32 lanes per treelet, skipping
//! treelets kept before under which nothing changed. Last, the SAH leaf collapse writes the tree anew in depth-first order
//! with leaves of up to `max_leaf` primitives.
//! Nodes of one height never contain each other, so each dispatch works on
//! disjoint subtrees. (The paper instead restructures during one bottom-up
//! climb with atomic counters; per-height dispatches trade some launches
//! for visibility guarantees that need no device-scope atomics.)
use anyhow::{bail, Result};
use treelet_core::construct::sah::SahCosts;
use treelet_core::construct::treelet::kernels::{MAX_LEVELS, TEAMS, subset_order};
use treelet_core::geometry::buffers::TreeletParams;
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};
use treelet_core::{Aabb, Node};

use crate::bvh::lbvh::DeviceBvh;
use crate::runtime::backend::{Backend, DeviceClass, StageTimes};
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};

kernel_set! {
    /// The kernels of the treelet rounds ([`optimize`]).
    pub struct TreeletKernels for b {
        histogram: Kernel::TreeletHistogram,
        scatter: Kernel::TreeletScatter,
        /// A team of lanes per treelet.
        team: Kernel::TreeletRestructure,
        /// A lane per treelet, for the lowest heights.
        single: Kernel::TreeletRestructureSingle,
    }
}

kernel_set! {
    /// The kernels of the bottom-up pass (counts, costs, heights) and the
    /// SAH leaf collapse (relaxed counters where the device needs them).
    pub struct CollapseKernels for b {
        init: b.atomics_for(Kernel::TreeletInit),
        climb: b.atomics_for(Kernel::TreeletInitClimb),
        collapse: Kernel::Collapse,
    }
}

/// How the optimization runs; defaults after Karras & Aila 2013.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct TreeletConfig {
    /// Optimization rounds (the paper: 3).
    pub rounds: u32,
    /// Smallest subtree, in primitives, restructured in the first round;
    /// doubled each round. The paper uses 7 (one full treelet); 3 also
    /// restructures the small subtrees near the leaves, which brings the SAH
    /// within 2.4% of the full-sweep builder's on 1M random spheres (7: 3.5%)
    /// for 1.7 times the time (1M spheres on the H100: 9.7 ms against 5.7).
    pub gamma: u32,
    /// Largest leaf the final SAH collapse makes (1: one primitive per leaf,
    /// no collapse). The paper sets no bound; a bound keeps the worst leaf
    /// a ray must test small.
    pub max_leaf: u32,
    /// Iterations of parallel reinsertion after the rounds (Meister &
    /// Bittner 2018, [`crate::bvh::reinsert`]); `None`: the builder's and
    /// device's default (see [`trbvh_reinsert`]).
    pub reinsert: Option<u32>,
    /// How many ancestors a reinsertion search climbs (0: to the root).
    pub reinsert_climb: u32,
    /// Skip treelets kept in an earlier round under which nothing has
    /// changed since (their DP would keep them again). Off: solve them all
    /// (the same tree, slower; for tests).
    #[serde(skip)]
    pub skip_kept: bool,
    /// After the rounds, climb the tree afresh and check that the counts,
    /// costs and heights the rounds kept current (instead of climbing each
    /// round) match; an error if not. For tests.
    #[serde(skip)]
    pub verify: bool,
    /// Treelets of subtrees this high or lower are restructured one
    /// invocation each, higher ones by a team of lanes each (the same tree
    /// either way; see [`SINGLE_INVOCATION_HEIGHTS`]).
    #[serde(skip, default = "single_invocation_heights")]
    pub single_heights: u32,
}

impl Default for TreeletConfig {
    /// The paper's three rounds, gamma 3 and leaves of at most 8,
    /// reinsertion as the builder and device call for (searches climbing
    /// [`REINSERT_CLIMB`] ancestors); for developers tuning them,
    /// `TREELET_TREELETS=ROUNDS,GAMMA,MAX_LEAF`, `TREELET_REINSERT=ITERATIONS`
    /// and `TREELET_REINSERT_CLIMB=ANCESTORS`.
    fn default() -> Self {
        let tuning = crate::tuning::Tuning::current();
        let (rounds, gamma, max_leaf) = tuning.treelets.unwrap_or((3, 3, 8));
        let (reinsert, reinsert_climb) = (tuning.reinsert, tuning.reinsert_climb.unwrap_or(REINSERT_CLIMB));
        Self {
            rounds,
            gamma,
            max_leaf,
            reinsert,
            reinsert_climb,
            skip_kept: true,
            verify: false,
            single_heights: single_invocation_heights(),
        }
    }
}

/// Reinsertion iterations the TRBVH gets on GPUs unless told otherwise.
/// On the H200 (splits 0.3, `docs/results/h200-reinsertion-2026-11-29/`),
/// two iterations whose searches climb at most 12 ancestors raised the
/// TRBVH's diffuse rays inside the real-scene suite by 2-8% (the breakfast
/// room's unchanged), primary rays from the city street by 35%, a scanned
/// bunny's and a terrain's diffuse rays by 2%, for 0.6-3.1 ms more build
/// (about 0.4 ms plus 2.5 ns a triangle). CPU devices run the searches too
/// slowly for it to pay (the CPU runner took 2.5 s for 8 iterations over
/// 262k triangles), and H-PLOC is the fast build: none there.
pub const GPU_TRBVH_REINSERT: u32 = 2;

/// Ancestors a reinsertion search climbs by default: 12 kept nearly all of
/// the unbounded search's gain for 10-40% less time (H200, same results).
pub const REINSERT_CLIMB: u32 = 12;

/// Reinsertion iterations the TRBVH gets on `class` unless told
/// otherwise: [`GPU_TRBVH_REINSERT`] on GPUs, none on CPU devices.
pub fn trbvh_reinsert(class: DeviceClass) -> u32 {
    if class == DeviceClass::Gpu { GPU_TRBVH_REINSERT } else { 0 }
}

impl TreeletConfig {
    /// This config with its reinsertion settled: as set, else `default`
    /// (`crate::bvh::tree` settles it per builder and device).
    pub fn with_default_reinsert(&self, default: u32) -> Self {
        Self { reinsert: Some(self.reinsert.unwrap_or(default)), ..*self }
    }

    /// Reinsertion iterations as set (0 where unset: see [`TreeletConfig::with_default_reinsert`]).
    pub fn reinsert_iterations(&self) -> u32 {
        self.reinsert.unwrap_or(0)
    }
}

/// [`SINGLE_INVOCATION_HEIGHTS`], or `TREELET_SINGLE_HEIGHTS` (to measure).
fn single_invocation_heights() -> u32 {
    crate::tuning::Tuning::current().single_heights.unwrap_or(SINGLE_INVOCATION_HEIGHTS)
}

/// Per-node scratch the passes share.
struct Scratch<B: Backend> {
    counts: B::Buffer,
    costs: B::Buffer,
    heights: B::Buffer,
    tree_leaves: B::Buffer,
}

/// Optimizes `bvh`: restructuring rounds in place, then the SAH leaf
/// collapse into a new, compacted tree (depth-first order), which it
/// returns. `root_box` (the tree's root box) scales areas so that f32 costs
/// cannot overflow. Stage times are named `round 1`, ..., `collapse`.
pub fn optimize<B: Backend>(
    b: &mut B,
    bvh: DeviceBvh<B>,
    root_box: &Aabb,
    config: &TreeletConfig,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    if bvh.n < 2 {
        return Ok((bvh, b.take_times()?));
    }
    let (bvh, scratch, base) = rounds(b, bvh, root_box, config)?;
    b.stage("collapse");
    let collapsed = collapse_pass(b, &bvh, &scratch, &base)?;
    Ok((collapsed, b.take_times()?))
}

/// The restructuring rounds of [`optimize`] alone: the tree keeps one
/// primitive per leaf and the LBVH layout, for layouts that collapse
/// leaves their own way ([`crate::bvh::layout::Layout::Cwbvh`]).
pub fn restructure<B: Backend>(
    b: &mut B,
    bvh: DeviceBvh<B>,
    root_box: &Aabb,
    config: &TreeletConfig,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    if bvh.n < 2 {
        return Ok((bvh, b.take_times()?));
    }
    let (bvh, _, _) = rounds(b, bvh, root_box, config)?;
    Ok((bvh, b.take_times()?))
}

/// Treelets of subtrees this high or lower are restructured one invocation
/// each (`treelet_core::construct::treelet::kernels::treelet_restructure_single`),
/// higher ones by a team of lanes each; `TREELET_SINGLE_HEIGHTS` overrides it
/// (to measure). Both give the same tree. On the H100 (1M random spheres,
/// gamma 3) the 225 526 treelets of height 2 took 0.497 ms one invocation
/// each against 0.823 by teams, but height 3 took 1.038 against 0.937 and
/// height 4 0.830 against 0.848: TRBVH 10.19 -> 9.87 ms with 2, 10.09 with
/// 3, 10.35 with 4 (`docs/results/h100-sort-occupancy/log_single_heights.txt`).
pub const SINGLE_INVOCATION_HEIGHTS: u32 = 2;

/// The rounds, in place; returns the tree, the per-node scratch and the
/// parameters the collapse goes on with.
fn rounds<B: Backend>(
    b: &mut B,
    bvh: DeviceBvh<B>,
    root_box: &Aabb,
    config: &TreeletConfig,
) -> Result<(DeviceBvh<B>, Scratch<B>, TreeletParams)> {
    let n = bvh.n;
    let base = base_params(n, root_box, config);
    let scratch = scratch(b, n)?;
    let subsets = b.upload("treelet subset order", &subset_order())?;
    let marks = b.zeroed("treelet marks", (2 * n as u64 - 1) * 4)?;
    const ROUND_NAMES: [&str; 8] =
        ["round 1", "round 2", "round 3", "round 4", "round 5", "round 6", "round 7", "round 8"];
    let mut gamma = config.gamma;
    // Developers' profiling switch: time each height as its own stage.
    let profile = crate::tuning::Tuning::current().profile_levels;
    let profile_levels = profile.is_some();
    // ... and with `empty`, an empty launch after each height.
    let profile_empty = profile == Some(crate::tuning::ProfileLevels::WithEmptyLaunches);
    let single_heights = config.single_heights;
    let k = TreeletKernels::of(b);
    for round in 0..config.rounds.min(ROUND_NAMES.len() as u32) {
        b.stage(ROUND_NAMES[round as usize]);
        if round == 0 {
            // Later rounds find counts, costs and heights kept current.
            init_pass(b, &bvh, &scratch, &base)?;
        }
        // Treelet roots (at least gamma primitives) listed by height...
        let p = b.upload("treelet params", &[TreeletParams { gamma, ..base }])?;
        let level_counts = b.zeroed("treelet level counts", MAX_LEVELS as u64 * 4)?;
        let (s, internal_groups) = (&scratch, groups_for(n - 1, WORKGROUP_SIZE));
        let histogram = bind::TreeletHistogram { params: &p, counts: &s.counts, heights: &s.heights, level_counts: &level_counts };
        b.dispatch_with(k.histogram, histogram, internal_groups);
        let per_level = b.read::<u32>(&level_counts, MAX_LEVELS)?;
        if per_level[MAX_LEVELS - 1] > 0 {
            bail!("the BVH is deeper than {} levels: treelet optimization refuses it", MAX_LEVELS - 2);
        }
        let offsets: Vec<u32> = per_level
            .iter()
            .scan(0u32, |sum, &c| {
                *sum += c;
                Some(*sum - c)
            })
            .collect();
        let total: u32 = per_level.iter().sum();
        gamma = gamma.saturating_mul(2);
        if total == 0 {
            continue;
        }
        let cursors = b.upload("treelet cursors", &offsets)?;
        let roots = b.scratch("treelet roots", total as u64 * 4)?;
        let scatter = bind::TreeletScatter { params: &p, counts: &s.counts, heights: &s.heights, cursors: &cursors, roots: &roots };
        b.dispatch_with(k.scatter, scatter, internal_groups);
        // ...then restructured height by height, bottom up: the treelets of
        // one height are disjoint, and each sees its subtrees finished.
        for (level, &count) in per_level.iter().enumerate().skip(1) {
            if count == 0 {
                continue;
            }
            let lp = TreeletParams {
                level_offset: offsets[level],
                level_count: count,
                round: round + 1,
                skip_kept: config.skip_kept as u32,
                ..base
            };
            let lp = b.upload("treelet params", &[lp])?;
            if profile_levels {
                // A stage per height (`round r h<height> n<treelets>`), for
                // `bench build`: what a height costs against its treelets.
                b.stage(Box::leak(format!("r{round} h{level:02} n{count}").into_boxed_str()));
            }
            let single = level as u32 <= single_heights;
            let restructure = |b: &mut B, p: &B::Buffer| {
                if single {
                    let (nodes, parents, counts, costs, heights) = (&bvh.nodes, &bvh.parents, &s.counts, &s.costs, &s.heights);
                    let single = bind::TreeletRestructureSingle { params: p, roots: &roots, nodes, parents, counts, costs, heights, marks: &marks };
                    b.dispatch_with(k.single, single, groups_for(count, WORKGROUP_SIZE));
                } else {
                    let buffers =
                        [p, &roots, &subsets, &bvh.nodes, &bvh.parents, &s.counts, &s.costs, &s.heights, &marks];
                    b.dispatch(k.team, &buffers, count.div_ceil(TEAMS));
                }
            };
            restructure(b, &lp);
            if profile_empty {
                // The same launch with no treelets: what a height costs
                // before any treelet work.
                let ep = b.upload("treelet params", &[TreeletParams { level_count: 0, ..base }])?;
                b.stage(Box::leak(format!("r{round} h{level:02} empty").into_boxed_str()));
                restructure(b, &ep);
            }
        }
    }
    if config.verify {
        verify_current(b, &bvh, &scratch, &base)?;
    }
    if config.reinsert_iterations() > 0 {
        // Moves nodes anywhere: the counts and costs above go stale (the
        // collapse climbs afresh).
        b.stage("reinsert");
        let iterations = config.reinsert_iterations();
        let made = crate::bvh::reinsert::reinsert(b, &bvh, root_box, iterations, config.reinsert_climb)?;
        if crate::tuning::Tuning::current().profile_reinsert {
            let made = crate::bvh::reinsert::moves_made(b, made.as_ref(), iterations)?;
            eprintln!("reinsertion: moves made per iteration {made:?}");
        }
    }
    Ok((bvh, scratch, base))
}

/// Only the SAH leaf collapse and compaction (what [`optimize`] ends with),
/// for trees built otherwise: `bvh` must have the LBVH layout (leaf `j` at
/// node `n - 1 + j`, one primitive each).
pub fn collapse<B: Backend>(b: &mut B, bvh: DeviceBvh<B>, max_leaf: u32) -> Result<DeviceBvh<B>> {
    if bvh.n < 2 {
        return Ok(bvh);
    }
    let root = root_box(b, &bvh)?;
    let base = base_params(bvh.n, &root, &TreeletConfig { max_leaf, ..Default::default() });
    let scratch = scratch(b, bvh.n)?;
    collapse_pass(b, &bvh, &scratch, &base)
}

fn base_params(n: u32, root_box: &Aabb, config: &TreeletConfig) -> TreeletParams {
    let extent = root_box.extent().max_element();
    let inv_extent = if extent > 0.0 { (1.0 / extent).min(f32::MAX) } else { 1.0 };
    let sah = SahCosts::KARRAS_AILA;
    TreeletParams {
        n,
        node_cost: sah.node as f32,
        prim_cost: sah.prim as f32,
        inv_extent,
        max_leaf: config.max_leaf.max(1),
        ..Default::default()
    }
}

fn scratch<B: Backend>(b: &mut B, n: u32) -> Result<Scratch<B>> {
    let node_count = 2 * n as u64 - 1;
    Ok(Scratch {
        counts: b.scratch("treelet counts", node_count * 4)?,
        costs: b.scratch("treelet costs", node_count * 4)?,
        heights: b.scratch("treelet heights", node_count * 4)?,
        tree_leaves: b.scratch("treelet tree leaves", node_count * 4)?,
    })
}

/// Every node's count, cost, height and output leaf count, bottom up.
fn init_pass<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>, s: &Scratch<B>, base: &TreeletParams) -> Result<()> {
    let n = bvh.n;
    let CollapseKernels { init, climb, .. } = CollapseKernels::of(b);
    let flags = b.zeroed("treelet flags", (n as u64 - 1) * 4)?;
    let p = b.upload("treelet params", &[*base])?;
    // The lowest levels, then the climbs that go on, from queues.
    let (queues, capacity) = treelet_core::construct::climb_queue::queue_shape(n);
    let stride = treelet_core::construct::climb_queue::QUEUE_COUNTER_STRIDE;
    let queue = b.scratch("treelet init queues", (queues * capacity) as u64 * 4)?;
    let queued = b.zeroed("treelet init queue counts", (queues * stride) as u64 * 4)?;
    let (nodes, parents, flags, counts, costs, heights, tree_leaves) = (&bvh.nodes, &bvh.parents, &flags, &s.counts, &s.costs, &s.heights, &s.tree_leaves);
    let (queue, queued) = (&queue, &queued);
    let all = bind::TreeletInit { params: &p, nodes, parents, flags, counts, costs, heights, tree_leaves, queue, queued };
    b.dispatch_with(init, all, groups_for(n, WORKGROUP_SIZE));
    let all = bind::TreeletInitClimb { params: &p, nodes, parents, flags, counts, costs, heights, tree_leaves, queue, queued };
    b.dispatch_with(climb, all, groups_for(queues * capacity, WORKGROUP_SIZE));
    Ok(())
}

/// Checks the counts, costs and heights in `s` against a fresh climb.
fn verify_current<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>, s: &Scratch<B>, base: &TreeletParams) -> Result<()> {
    let node_count = 2 * bvh.n as usize - 1;
    let kept = (b.read::<u32>(&s.counts, node_count)?, b.read::<f32>(&s.costs, node_count)?, b.read::<u32>(&s.heights, node_count)?);
    let fresh = scratch(b, bvh.n)?;
    init_pass(b, bvh, &fresh, base)?;
    let (counts, costs, heights) =
        (b.read::<u32>(&fresh.counts, node_count)?, b.read::<f32>(&fresh.costs, node_count)?, b.read::<u32>(&fresh.heights, node_count)?);
    for i in 0..node_count {
        if kept.0[i] != counts[i] || kept.2[i] != heights[i] {
            bail!("node {i}: kept count {} height {}, fresh {} {}", kept.0[i], kept.2[i], counts[i], heights[i]);
        }
        // Kept costs come from the DP's operations, fresh ones from the climb's.
        if (kept.1[i] - costs[i]).abs() > 1e-4 * costs[i].abs().max(f32::MIN_POSITIVE) {
            bail!("node {i}: kept cost {} fresh {}", kept.1[i], costs[i]);
        }
    }
    Ok(())
}

/// Fresh counts and costs, then the collapse into new arrays.
fn collapse_pass<B: Backend>(
    b: &mut B,
    bvh: &DeviceBvh<B>,
    s: &Scratch<B>,
    base: &TreeletParams,
) -> Result<DeviceBvh<B>> {
    let n = bvh.n;
    init_pass(b, bvh, s, base)?;
    let leaves = b.read::<u32>(&s.tree_leaves, 1)?[0];
    let node_count = 2 * leaves - 1;
    let nodes = b.scratch("collapsed nodes", node_count as u64 * std::mem::size_of::<Node>() as u64)?;
    let parents = b.scratch("collapsed parents", node_count as u64 * 4)?;
    let prims = b.scratch("collapsed primitive indices", n as u64 * 4)?;
    let p = b.upload("treelet params", &[*base])?;
    let (counts, tree_leaves) = (&s.counts, &s.tree_leaves);
    b.dispatch_with(
        CollapseKernels::of(b).collapse,
        bind::Collapse {
            params: &p,
            nodes: &bvh.nodes,
            parents: &bvh.parents,
            counts,
            tree_leaves,
            prims: &bvh.prim_indices,
            out_nodes: &nodes,
            out_parents: &parents,
            out_prims: &prims,
        },
        groups_for(n, WORKGROUP_SIZE),
    );
    Ok(DeviceBvh {
        n,
        node_count,
        nodes,
        parents,
        prim_indices: prims,
        sorted_keys: bvh.sorted_keys.clone(),
        centroid_bounds: bvh.centroid_bounds,
        prims: bvh.prims.clone(),
    })
}

/// The kernels [`restructure`] with `config` (reinsertion settled) and
/// [`collapse`] dispatch on `b`, for building their pipelines ahead.
pub fn kernels<B: Backend>(b: &B, config: &TreeletConfig) -> Vec<Kernel> {
    let mut k = collapse_kernels(b);
    if config.rounds > 0 {
        k.extend(TreeletKernels::of(b).all());
    }
    if config.reinsert_iterations() > 0 {
        k.extend(crate::bvh::reinsert::kernels(b));
    }
    k
}

/// The kernels [`collapse`] dispatches on `b` (its counts come from the
/// treelet pass's init kernel).
pub fn collapse_kernels<B: Backend>(b: &B) -> Vec<Kernel> {
    CollapseKernels::of(b).all()
}

/// The root box of a device BVH (one node read back).
pub fn root_box<B: Backend>(b: &mut B, bvh: &DeviceBvh<B>) -> Result<Aabb> {
    Ok(b.read::<Node>(&bvh.nodes, 1)?.first().map(|n| n.aabb()).unwrap_or(Aabb::EMPTY))
}
