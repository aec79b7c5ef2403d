//! The tree a render or an engine asks for: which builder ([`Builder`]; a
//! render's [`Accel`] adds the scan and `auto`), the binary tree it builds
//! on the device ([`BuiltTree`]), and that tree laid out for tracing with
//! the primitives' buffers ([`traced_tree`]).
use anyhow::{bail, Result};
use serde::Serialize;
use treelet_core::geometry::buffers::Node;

use crate::bvh::layout::{lay_out, Layout, PrimBuffers, TracedTree};
use crate::bvh::lbvh;
use crate::bvh::trbvh::{self, TreeletConfig};
use crate::runtime::backend::{Backend, DeviceClass, StageTimes};
use crate::scene::primitives::Primitives;

/// Which BVH builder: the one type for `treelet build --builder`,
/// `treelet bench build --builder`, a render's `--accel` (through
/// [`Accel::builder`]) and the engine API's `Quality`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Builder {
    /// Karras 2012, on the chosen device.
    Lbvh,
    /// The LBVH, then treelet restructuring (Karras & Aila 2013), on the
    /// chosen device; on GPUs then two iterations of reinsertion (Meister &
    /// Bittner 2018).
    Trbvh,
    /// H-PLOC (Benthin et al. 2024): the LBVH's Morton order, nearest
    /// neighbours merged within subgroups as the climbs go up, on the
    /// chosen device (subgroups of 4 lanes or more).
    Hploc,
    /// Full-sweep SAH, top-down on the CPU (beaten by the TRBVH on scenes
    /// of mixed triangle sizes).
    Sweep,
    /// The quality reference, built on the CPU: PLOC with reinsertion over
    /// every node, from the obvhs crate (build with --features peers).
    Reference,
}

impl Builder {
    /// The word the command line takes (`--builder`).
    pub fn name(self) -> &'static str {
        match self {
            Builder::Lbvh => "lbvh",
            Builder::Trbvh => "trbvh",
            Builder::Hploc => "hploc",
            Builder::Sweep => "sweep",
            Builder::Reference => "reference",
        }
    }
}

/// How closest hits are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Accel {
    /// A linear scan for scenes below a measured size; above it lbvh,
    /// hploc (GPUs only) or trbvh, whichever measured costs say finishes the
    /// build and the render first (--explain shows the numbers).
    // (Plain words: this is `--accel auto`'s help. The code is
    // `render::variant::plan` and `bvh::choice::cheaper_builder`; a test in
    // main.rs holds them to this text.)
    Auto,
    /// Test every primitive.
    None,
    /// Traverse the LBVH (Karras 2012).
    Lbvh,
    /// Traverse the LBVH after treelet restructuring (Karras & Aila 2013;
    /// on GPUs then two iterations of reinsertion, Meister & Bittner 2018).
    Trbvh,
    /// Traverse the H-PLOC tree (Benthin et al. 2024).
    Hploc,
    /// Traverse the full-sweep SAH tree, built on the CPU.
    Sweep,
    /// Traverse the quality reference, built on the CPU: PLOC with
    /// reinsertion over every node, from the obvhs crate (build with
    /// --features peers).
    Reference,
}

impl Accel {
    /// The word the command line takes (`--accel`).
    pub fn name(self) -> &'static str {
        match self {
            Accel::Auto => "auto",
            Accel::None => "none",
            Accel::Lbvh => "lbvh",
            Accel::Trbvh => "trbvh",
            Accel::Hploc => "hploc",
            Accel::Sweep => "sweep",
            Accel::Reference => "reference",
        }
    }

    /// The builder of the tree this traces; `None` for the scan. `Auto`
    /// must have been resolved first (see `treelet::render::variant::plan`).
    pub fn builder(self) -> Result<Option<Builder>> {
        Ok(match self {
            Accel::Auto => bail!("internal: --accel auto reached the tree builder unresolved"),
            Accel::None => None,
            Accel::Lbvh => Some(Builder::Lbvh),
            Accel::Trbvh => Some(Builder::Trbvh),
            Accel::Hploc => Some(Builder::Hploc),
            Accel::Sweep => Some(Builder::Sweep),
            Accel::Reference => Some(Builder::Reference),
        })
    }
}

/// The tree `accel` traces for these primitives, on the device, laid out
/// as `layout`, with the primitives' buffers (uploaded after the build, as
/// the render and cast kernels bind them) and the build time (ms: device
/// stages, or the CPU build of the sweep plus its layout on the device). The
/// scan gets placeholders. `Accel::Auto` must have been resolved (see
/// `treelet::render::variant::plan`).
pub fn traced_tree<B: Backend>(
    b: &mut B,
    all: Primitives,
    accel: Accel,
    layout: Layout,
) -> Result<(TracedTree<B>, PrimBuffers<B>, f64)> {
    let budget = accel.builder()?.map_or(0.0, split_budget);
    traced_tree_split(b, all, accel, layout, budget)
}

/// [`traced_tree`] over pieces of the triangles (see [`binary_tree_split`]).
pub fn traced_tree_split<B: Backend>(
    b: &mut B,
    all: Primitives,
    accel: Accel,
    layout: Layout,
    budget: f32,
) -> Result<(TracedTree<B>, PrimBuffers<B>, f64)> {
    traced_tree_with(b, all, accel, layout, budget, &TreeletConfig::default())
}

/// [`traced_tree_split`] with the optimizing builders' settings given
/// (`config`'s reinsertion as set, else the device's default: the TRBVH
/// reinserts on GPUs, not on the CPU runner; so a CPU tree that is to equal
/// a GPU's sets it).
pub fn traced_tree_with<B: Backend>(
    b: &mut B,
    all: Primitives,
    accel: Accel,
    layout: Layout,
    budget: f32,
    config: &TreeletConfig,
) -> Result<(TracedTree<B>, PrimBuffers<B>, f64)> {
    let Some(builder) = accel.builder()? else {
        let buffers = PrimBuffers::upload(b, all)?;
        let tree = TracedTree {
            layout: Layout::Classic,
            nodes: b.upload("no nodes", &[Node::default()])?,
            prims: b.upload("no indices", &[0u32])?,
            node_count: 0,
            collapsed: None,
        };
        return Ok((tree, buffers, 0.0));
    };
    let built = binary_tree_with(b, all, builder, budget, config)?;
    let buffers = built.prim_buffers(b, all)?;
    let (tree, layout_ms) = built.lay_out(b, layout, &buffers)?;
    Ok((tree, buffers, built.build_ms + layout_ms))
}

/// The kernels [`traced_tree`] dispatches on `b` for `accel` in `layout`,
/// gathered from the modules that dispatch them, for building their
/// pipelines ahead and at once (`GpuContext::prepare`). A missing one would
/// only be built when first used; `tests/layouts.rs` checks that none is.
pub fn kernels_of<B: Backend>(b: &B, accel: Accel, layout: Layout) -> Vec<crate::runtime::kernels::Kernel> {
    let builder = match accel.builder() {
        Ok(Some(builder)) => builder,
        _ => return Vec::new(),
    };
    let mut k = build_kernels(b, builder, split_budget(builder), &TreeletConfig::default());
    k.extend(crate::bvh::layout::kernels(b, layout));
    k.sort();
    k.dedup();
    k
}

/// The kernels a device build of `builder` over pieces within `budget`,
/// optimized as `config` says, dispatches on `b` (as `optimize_built`
/// and `built_within_stack` choose them), before any layout.
pub fn build_kernels<B: Backend>(b: &B, builder: Builder, budget: f32, config: &TreeletConfig) -> Vec<crate::runtime::kernels::Kernel> {
    let config = settled(config, builder, b.class());
    let mut k = match builder {
        Builder::Lbvh => lbvh::kernels(b),
        Builder::Trbvh => [lbvh::kernels(b), trbvh::kernels(b, &config)].concat(),
        Builder::Hploc if config.reinsert_iterations() > 0 => {
            [lbvh::kernels_with(b, lbvh::Hierarchy::Hploc), trbvh::kernels(b, &TreeletConfig { rounds: 0, ..config })].concat()
        }
        Builder::Hploc => lbvh::kernels_with(b, lbvh::Hierarchy::Hploc),
        Builder::Sweep | Builder::Reference => return Vec::new(),
    };
    if budget > 0.0 {
        k.extend(lbvh::split_kernels(b));
    }
    if config.reinsert_iterations() > 0 {
        // The depth check after reinsertion.
        k.extend(crate::bvh::layout::DepthKernels::of(b).all());
    }
    k
}

/// A binary tree of one primitive per leaf, on the device, as a builder
/// left it: what every traversal layout is made from.
pub struct BuiltTree<B: Backend> {
    pub bvh: lbvh::DeviceBvh<B>,
    /// The largest leaf the binary layouts' SAH collapse makes (1: none).
    pub max_leaf: u32,
    /// Build time (ms): device stages, or the sweep's CPU build.
    pub build_ms: f64,
}

impl<B: Backend> BuiltTree<B> {
    /// The primitives `all` (those the tree was built over) on the device:
    /// the build's own upload where it made one (a 940k-triangle mesh is 45
    /// MB, uploaded once instead of twice), else a fresh upload.
    pub fn prim_buffers(&self, b: &mut B, all: Primitives) -> Result<PrimBuffers<B>> {
        Ok(match self.bvh.prims.clone() {
            Some((spheres, triangles)) => PrimBuffers {
                spheres,
                triangles,
                sphere_count: all.spheres.len() as u32,
                triangle_count: all.triangles.len() as u32,
            },
            None => PrimBuffers::upload(b, all)?,
        })
    }

    /// Lays the tree out (it stays usable for other layouts); returns the
    /// layout's device time (ms).
    pub fn lay_out(&self, b: &mut B, layout: Layout, prims: &PrimBuffers<B>) -> Result<(TracedTree<B>, f64)> {
        let (tree, times) = self.lay_out_timed(b, layout, prims)?;
        Ok((tree, times.total()))
    }

    /// [`BuiltTree::lay_out`] with the layout's stage times.
    pub fn lay_out_timed(&self, b: &mut B, layout: Layout, prims: &PrimBuffers<B>) -> Result<(TracedTree<B>, StageTimes)> {
        b.take_times()?;
        let tree = lay_out(b, self.bvh.clone(), layout, self.max_leaf, prims)?;
        Ok((tree, b.take_times()?))
    }
}

/// The binary tree `builder` makes, to be laid out for tracing: the LBVH
/// as built, the TRBVH's restructured tree (or the H-PLOC tree) before its leaf collapse, or the
/// full-sweep tree built on the CPU and uploaded. Starts a new build on `b`.
pub fn binary_tree<B: Backend>(b: &mut B, all: Primitives, builder: Builder) -> Result<BuiltTree<B>> {
    binary_tree_split(b, all, builder, split_budget(builder))
}

/// Extra references, as a fraction of the triangles, that the traced trees
/// of the optimizing builders (TRBVH, H-PLOC) split large triangles into
/// by default (`treelet_core::construct::presplit`). Measured on the H200
/// (`docs/results/h200-splits-2026-12-01/`): on interiors with large
/// walls and floors 0.3 gives 1.5x the diffuse rays from inside (the
/// breakfast room, the staircase) and the same elsewhere within a few
/// percent; on scans it splits almost nothing, since a triangle gets a
/// piece more only where its box wastes over three times the mean; 1.0
/// slows scans and terrain (longer builds, 6-13% fewer rays).
pub const DEFAULT_SPLITS: f32 = 0.3;

/// The split budget of `builder`'s traced trees: `TREELET_SPLITS` where
/// set ([`lbvh::split_override`]), else [`DEFAULT_SPLITS`] for the TRBVH and
/// H-PLOC and none for the LBVH (the fastest build, kept so) and the CPU
/// builders (which take whole primitives).
pub fn split_budget(builder: Builder) -> f32 {
    lbvh::split_override().unwrap_or(match builder {
        Builder::Trbvh | Builder::Hploc => DEFAULT_SPLITS,
        Builder::Lbvh | Builder::Sweep | Builder::Reference => 0.0,
    })
}

/// [`binary_tree`] over pieces of the triangles, `budget` times the
/// triangles more at most (0: none; see `treelet_core::construct::presplit`;
/// the sweep takes whole primitives).
pub fn binary_tree_split<B: Backend>(b: &mut B, all: Primitives, builder: Builder, budget: f32) -> Result<BuiltTree<B>> {
    binary_tree_with(b, all, builder, budget, &TreeletConfig::default())
}

/// [`binary_tree_split`] with the optimizing builders' settings given (see
/// [`traced_tree_with`]).
pub fn binary_tree_with<B: Backend>(b: &mut B, all: Primitives, builder: Builder, budget: f32, config: &TreeletConfig) -> Result<BuiltTree<B>> {
    Ok(match builder {
        Builder::Lbvh | Builder::Trbvh | Builder::Hploc => {
            let hierarchy = hierarchy_of(b, builder, all.len());
            built_within_stack(b, builder, config, |b| lbvh::build_primitives_split(b, all, hierarchy, budget))?
        }
        Builder::Sweep => {
            let build = std::time::Instant::now();
            let tree = crate::bvh::sweep::build_boxes(&all.boxes());
            let build_ms = build.elapsed().as_secs_f64() * 1e3;
            b.begin_build();
            BuiltTree { bvh: lbvh::DeviceBvh::upload(b, &tree)?, max_leaf: config.max_leaf, build_ms }
        }
        Builder::Reference => {
            let (tree, build_ms) = crate::bvh::reference::build_boxes(&all.boxes())?;
            b.begin_build();
            BuiltTree { bvh: lbvh::DeviceBvh::upload(b, &tree)?, max_leaf: config.max_leaf, build_ms }
        }
    })
}

/// [`binary_tree_split`] over primitives already on the device (an
/// engine's mesh gathered from its own buffers), after `b.begin_build()`:
/// the device's builders only (the sweep and the reference take the host's
/// primitives).
pub fn binary_tree_uploaded<B: Backend>(b: &mut B, prims: &PrimBuffers<B>, builder: Builder, budget: f32) -> Result<BuiltTree<B>> {
    match builder {
        Builder::Lbvh | Builder::Trbvh | Builder::Hploc => {
            let counts = (prims.sphere_count, prims.triangle_count);
            let hierarchy = hierarchy_of(b, builder, (counts.0 + counts.1) as usize);
            let build = |b: &mut B| lbvh::build_uploaded_split(b, (prims.spheres.clone(), prims.triangles.clone()), counts, hierarchy, budget);
            built_within_stack(b, builder, &TreeletConfig::default(), build)
        }
        Builder::Sweep | Builder::Reference => bail!("the {} builder runs on the CPU over the host's primitives", builder.name()),
    }
}

/// The hierarchy step of a device builder's LBVH.
fn hierarchy_of<B: Backend>(b: &B, builder: Builder, n: usize) -> lbvh::Hierarchy {
    if builder == Builder::Hploc { lbvh::Hierarchy::Hploc } else { lbvh::Hierarchy::for_device(b, n) }
}

/// A device builder's tree from its LBVH (or H-PLOC tree): the LBVH traced
/// as built; the TRBVH's treelet rounds (and reinsertion on GPUs); H-PLOC's
/// tree with reinsertion where configured.
fn optimize_built<B: Backend>(
    b: &mut B,
    builder: Builder,
    (mut bvh, times): (lbvh::DeviceBvh<B>, StageTimes),
    config: &TreeletConfig,
) -> Result<BuiltTree<B>> {
    let mut build_ms = times.total();
    Ok(match builder {
        Builder::Trbvh => {
            let root = trbvh::root_box(b, &bvh)?;
            let (restructured, times) = trbvh::restructure(b, bvh, &root, &settled(config, builder, b.class()))?;
            build_ms += times.total();
            BuiltTree { bvh: restructured, max_leaf: config.max_leaf, build_ms }
        }
        Builder::Hploc => {
            let config = settled(config, builder, b.class());
            if config.reinsert_iterations() > 0 {
                // Reinsertion over H-PLOC's tree, without treelet rounds.
                let root = trbvh::root_box(b, &bvh)?;
                let (reinserted, times) = trbvh::restructure(b, bvh, &root, &TreeletConfig { rounds: 0, ..config })?;
                bvh = reinserted;
                build_ms += times.total();
            }
            // Leaves collapsed by SAH when laid out, as the TRBVH's.
            BuiltTree { bvh, max_leaf: config.max_leaf, build_ms }
        }
        // The LBVH is traced as built (one primitive per leaf).
        _ => BuiltTree { bvh, max_leaf: 1, build_ms },
    })
}

/// `builder`'s tree from the LBVH (or H-PLOC tree) `build` makes, optimized
/// as `config` says, within the traversal stack: reinsertion can chain a
/// tree of coincident boxes (2 000 triangles of one box, `tests/layouts.rs`'s
/// stiff scenes) past it where the tree before it was shallow, so a
/// reinserted tree found too deep (on the device: one word read back) is
/// made again without reinsertion.
fn built_within_stack<B: Backend>(
    b: &mut B,
    builder: Builder,
    config: &TreeletConfig,
    mut build: impl FnMut(&mut B) -> Result<(lbvh::DeviceBvh<B>, StageTimes)>,
) -> Result<BuiltTree<B>> {
    let lbvh = build(b)?;
    let built = optimize_built(b, builder, lbvh, config)?;
    if settled(config, builder, b.class()).reinsert_iterations() == 0
        || crate::bvh::layout::tree_depth(b, &built.bvh)? as usize + 1 <= treelet_core::trace::hit::STACK_DEPTH
    {
        return Ok(built);
    }
    let lbvh = build(b)?;
    optimize_built(b, builder, lbvh, &TreeletConfig { reinsert: Some(0), ..*config })
}

/// `config` with its reinsertion settled for a tree of `builder` on
/// `class`: as set, else the TRBVH's default on the device
/// ([`trbvh::trbvh_reinsert`]), none for other builders.
pub fn settled(config: &TreeletConfig, builder: Builder, class: crate::runtime::backend::DeviceClass) -> TreeletConfig {
    config.with_default_reinsert(if builder == Builder::Trbvh { trbvh::trbvh_reinsert(class) } else { 0 })
}

/// The tree `builder` makes on the device with its leaves collapsed by SAH
/// as it is traced, and the stage times of the whole build (what `bench
/// build` and the pareto figure time): the LBVH as built; the LBVH, then
/// `config`'s treelet rounds and the collapse; H-PLOC's tree, then the
/// rounds (where `config` has any) and the collapse. Starts a new build.
pub fn collapsed_tree<B: Backend>(
    b: &mut B,
    all: Primitives,
    builder: Builder,
    config: &TreeletConfig,
) -> Result<(lbvh::DeviceBvh<B>, StageTimes)> {
    let (bvh, mut times) = match builder {
        Builder::Lbvh | Builder::Trbvh => {
            let hierarchy = lbvh::Hierarchy::for_device(b, all.len());
            lbvh::build_primitives_split(b, all, hierarchy, split_budget(builder))?
        }
        Builder::Hploc => lbvh::build_primitives_split(b, all, lbvh::Hierarchy::Hploc, split_budget(builder))?,
        Builder::Sweep | Builder::Reference => bail!("internal: the {} builder runs on the CPU", builder.name()),
    };
    let (bvh, more) = match builder {
        Builder::Trbvh | Builder::Hploc if builder == Builder::Trbvh || config.rounds > 0 || settled(&config, builder, b.class()).reinsert_iterations() > 0 => {
            let root = trbvh::root_box(b, &bvh)?;
            trbvh::optimize(b, bvh, &root, &settled(&config, builder, b.class()))?
        }
        Builder::Hploc => {
            b.take_times()?;
            b.stage("collapse");
            let collapsed = trbvh::collapse(b, bvh, config.max_leaf)?;
            (collapsed, b.take_times()?)
        }
        _ => (bvh, StageTimes::default()),
    };
    for s in &more.order {
        times.add(s, more.get(s));
    }
    Ok((bvh, times))
}

/// Host bytes a tree build takes per primitive where the device's memory is
/// the host's (the CPU runner, lavapipe): scene, Morton codes, the sort,
/// nodes, treelets (measured: 310 to 330 bytes with TRBVH at 1M primitives
/// on the CPU runner).
pub const CPU_TREE_BYTES_PER_PRIM: u64 = 384;
/// Host bytes per primitive with a GPU, whose tree is in its own memory:
/// the scene and its upload.
pub const GPU_HOST_BYTES_PER_PRIM: u64 = 128;

/// Host bytes that building a tree over `prims` primitives on a device of
/// `class` takes, estimated.
pub fn tree_host_bytes(prims: u64, class: DeviceClass) -> u64 {
    prims.saturating_mul(match class {
        DeviceClass::Gpu => GPU_HOST_BYTES_PER_PRIM,
        DeviceClass::CpuAdapter | DeviceClass::CpuRunner => CPU_TREE_BYTES_PER_PRIM,
    })
}

/// Refuses a build over `prims` primitives on a device of `class` whose
/// estimate is past the memory the machine has.
pub fn check_build_memory(prims: u64, class: DeviceClass) -> Result<()> {
    crate::runtime::memory::check_fits(
        &format!("a tree over {prims} primitives"),
        tree_host_bytes(prims, class),
        &format!("{} bytes a primitive on this device", tree_host_bytes(1, class)),
    )
}
