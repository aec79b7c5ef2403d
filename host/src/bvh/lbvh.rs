//! The LBVH build of Karras 2012, stage by stage, over any [`Backend`]:
//! primitive boxes → centroid bounds → Morton codes → radix sort →
//! radix tree → bottom-up fit (or both at once, [`Hierarchy`]). The kernels
//! live in `treelet-core`.
use anyhow::Result;
use treelet_core::construct::bounds::{BOUNDS_START, BOUNDS_WORDS, REDUCE_TILE, bounds_from_words};
use treelet_core::construct::morton::{KEY_BITS, MortonFrame, SORTED_KEY_BITS};
use treelet_core::geometry::aabb::Aabb;
use treelet_core::geometry::buffers::{BuildParams, Node, Sphere};
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};

use crate::runtime::backend::{check_fits, Backend, StageTimes};
use crate::bvh::sort::ScanKernels;
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};
use crate::scene::primitives::Primitives;

/// The stages of a build, in order, as named in timings and reports.
pub const STAGES: [&str; 5] = ["bounds", "morton", "sort", "tree", "fit"];

kernel_set! {
    /// The kernels of a build's first stages: boxes with their centroid
    /// bounds, Morton codes (the sort's: `crate::bvh::sort`).
    pub struct LbvhKernels for b {
        bounds: Kernel::PrimitiveBounds,
        morton: Kernel::Morton,
    }
}

kernel_set! {
    /// The kernels [`Hierarchy::RadixTreeThenFit`] dispatches.
    pub struct RadixTreeKernels for b {
        tree: Kernel::RadixTree,
        fit: b.atomics_for(Kernel::Fit),
    }
}

kernel_set! {
    /// The kernel [`Hierarchy::Agglomerative`] dispatches.
    pub struct AgglomerateKernels for b {
        agglomerate: b.atomics_for(Kernel::Agglomerate),
    }
}

kernel_set! {
    /// The kernels [`Hierarchy::AgglomerativeSubgroup`] dispatches.
    pub struct AgglomerateSubgroupKernels for b {
        agglomerate: Kernel::AgglomerateSubgroup,
        climb: b.atomics_for(Kernel::ClimbQueued),
    }
}

kernel_set! {
    /// The kernel [`Hierarchy::Hploc`] dispatches.
    pub struct HplocKernels for b {
        hploc: b.atomics_for(Kernel::Hploc),
    }
}

kernel_set! {
    /// The kernels triangle splitting adds to a build (and the scan's:
    /// [`split_kernels`]).
    pub struct SplitKernels for b {
        bounds: Kernel::PrimitiveBounds,
        priority: Kernel::SplitPriority,
        count: Kernel::SplitCount,
        emit: Kernel::SplitEmit,
        piece_bounds: Kernel::SplitBounds,
        remap: Kernel::SplitRemap,
    }
}

/// A built BVH, read back from the device.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// `2n - 1` nodes (none for an empty scene; fewer after a leaf collapse); the root is node 0.
    pub nodes: Vec<Node>,
    /// Parent of each node; `INVALID` for the root.
    pub parents: Vec<u32>,
    /// Primitive index of each sorted position (leaves point into this).
    pub prim_indices: Vec<u32>,
    /// Sort keys (the top `SORTED_KEY_BITS` bits of each Morton code) in the LBVH's order.
    pub sorted_keys: Vec<u64>,
    /// Centroid bounds used for the Morton frame.
    pub centroid_bounds: Aabb,
}

/// A BVH still on the device, as a renderer uses it. Cloning clones the
/// buffer handles, not the data.
pub struct DeviceBvh<B: Backend> {
    /// Primitives.
    pub n: u32,
    /// Nodes: `2n - 1` after the build, `2 * leaves - 1` after a leaf collapse.
    pub node_count: u32,
    pub nodes: B::Buffer,
    pub parents: B::Buffer,
    pub prim_indices: B::Buffer,
    pub sorted_keys: B::Buffer,
    pub centroid_bounds: Aabb,
    /// The spheres and triangles the build read, as it uploaded them (valid
    /// until the next build on the backend), so that traversal need not
    /// upload them again; `None` for a tree built elsewhere.
    pub prims: Option<(B::Buffer, B::Buffer)>,
}

impl<B: Backend> Clone for DeviceBvh<B> {
    fn clone(&self) -> Self {
        DeviceBvh {
            n: self.n,
            node_count: self.node_count,
            nodes: self.nodes.clone(),
            parents: self.parents.clone(),
            prim_indices: self.prim_indices.clone(),
            sorted_keys: self.sorted_keys.clone(),
            centroid_bounds: self.centroid_bounds,
            prims: self.prims.clone(),
        }
    }
}

impl<B: Backend> DeviceBvh<B> {
    /// A host tree on the device (at least two primitives); a tree without
    /// Morton keys (the sweep's) gets zeros in their place.
    pub fn upload(b: &mut B, bvh: &Bvh) -> Result<Self> {
        let n = bvh.prim_indices.len();
        let keys = if bvh.sorted_keys.is_empty() { vec![0u64; n] } else { bvh.sorted_keys.clone() };
        Ok(DeviceBvh {
            n: n as u32,
            node_count: bvh.nodes.len() as u32,
            nodes: b.upload("nodes", &bvh.nodes)?,
            parents: b.upload("parents", &bvh.parents)?,
            prim_indices: b.upload("primitive indices", &bvh.prim_indices)?,
            sorted_keys: b.upload("keys", &keys)?,
            centroid_bounds: bvh.centroid_bounds,
            prims: None,
        })
    }

    /// Copies the tree back to the host.
    pub fn read(&self, b: &mut B) -> Result<Bvh> {
        if self.n == 0 {
            return Ok(Bvh::default());
        }
        let node_count = self.node_count as usize;
        Ok(Bvh {
            nodes: b.read(&self.nodes, node_count)?,
            parents: b.read(&self.parents, node_count)?,
            prim_indices: b.read(&self.prim_indices, self.n as usize)?,
            sorted_keys: b.read(&self.sorted_keys, self.n as usize)?,
            centroid_bounds: self.centroid_bounds,
        })
    }
}

/// Builds the LBVH of `spheres` on `b` and reads it back. Inputs must be
/// finite (see [`crate::scene::validate_spheres`]). Returns the tree and
/// stage times.
pub fn build<B: Backend>(b: &mut B, spheres: &[Sphere]) -> Result<(Bvh, StageTimes)> {
    let (device_bvh, times) = build_on_device(b, spheres)?;
    Ok((device_bvh.read(b)?, times))
}

/// Builds the LBVH of `spheres` on `b` and leaves it there.
pub fn build_on_device<B: Backend>(b: &mut B, spheres: &[Sphere]) -> Result<(DeviceBvh<B>, StageTimes)> {
    build_primitives_on_device(b, Primitives::spheres(spheres))
}

/// Builds the LBVH of spheres or triangles on `b` and leaves it there.
pub fn build_primitives_on_device<B: Backend>(b: &mut B, prims: Primitives) -> Result<(DeviceBvh<B>, StageTimes)> {
    let hierarchy = Hierarchy::for_device(b, prims.len());
    build_primitives_with(b, prims, hierarchy)
}

/// Builds the LBVH of `spheres` on `b` with the given way of making the
/// hierarchy, and reads it back (to compare the two).
pub fn build_with<B: Backend>(b: &mut B, spheres: &[Sphere], hierarchy: Hierarchy) -> Result<Bvh> {
    let (device_bvh, _) = build_primitives_with(b, Primitives::spheres(spheres), hierarchy)?;
    device_bvh.read(b)
}

/// The kernels [`build_primitives_on_device`] dispatches on `b`, for
/// building their pipelines ahead (the hierarchies as
/// [`Hierarchy::for_device`] picks them).
pub fn kernels<B: Backend>(b: &B) -> Vec<Kernel> {
    let mut k = LbvhKernels::of(b).all();
    if split_override().is_some_and(|b| b > 0.0) {
        k.extend(split_kernels(b));
    }
    k.extend(crate::bvh::sort::kernels(b));
    // Which hierarchy runs depends on the primitive count: one count from
    // each class of `Hierarchy::for_device`.
    for n in [1, SUBGROUP_HIERARCHY_MIN] {
        k.extend(Hierarchy::for_device(b, n).kernels(b));
    }
    k.sort();
    k.dedup();
    k
}

/// The kernels [`build_primitives_with`] dispatches on `b` for `hierarchy`.
pub fn kernels_with<B: Backend>(b: &B, hierarchy: Hierarchy) -> Vec<Kernel> {
    let mut k = LbvhKernels::of(b).all();
    if split_override().is_some_and(|b| b > 0.0) {
        k.extend(split_kernels(b));
    }
    k.extend(crate::bvh::sort::kernels(b));
    k.extend(hierarchy.kernels(b));
    k
}

/// [`build_primitives_on_device`] with the given way of making the hierarchy
/// (whole triangles, unless `TREELET_SPLITS` says otherwise: [`split_override`];
/// the traced trees' default is `crate::bvh::tree::split_budget`'s).
pub fn build_primitives_with<B: Backend>(
    b: &mut B,
    prims: Primitives,
    hierarchy: Hierarchy,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    build_primitives_split(b, prims, hierarchy, split_override().unwrap_or(0.0))
}

/// [`build_primitives_with`] over pieces of the triangles: at most
/// `budget` times as many more leaf slots as there are triangles (0: no
/// splitting; see `treelet_core::construct::presplit`).
pub fn build_primitives_split<B: Backend>(
    b: &mut B,
    prims: Primitives,
    hierarchy: Hierarchy,
    budget: f32,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    let n = u32::try_from(prims.len())
        .ok()
        .filter(|&n| n <= MAX_PRIMITIVES)
        .ok_or_else(|| anyhow::anyhow!("{} primitives: at most {MAX_PRIMITIVES} are supported", prims.len()))?;
    b.begin_build();
    if n == 0 {
        let empty = b.scratch("empty", 0)?;
        let bvh = DeviceBvh {
            n,
            node_count: 0,
            nodes: empty.clone(),
            parents: empty.clone(),
            prim_indices: empty.clone(),
            sorted_keys: empty,
            centroid_bounds: Aabb::EMPTY,
            prims: None,
        };
        return Ok((bvh, b.take_times()?));
    }
    let spheres = upload_or_placeholder(b, "spheres", prims.spheres)?;
    let triangles = upload_or_placeholder(b, "triangles", prims.triangles)?;
    build_uploaded_split(b, (spheres, triangles), (prims.spheres.len() as u32, prims.triangles.len() as u32), hierarchy, budget)
}

/// [`build_primitives_split`] over primitives already on the device
/// (`spheres`, `triangles`: buffers, counts; an engine's mesh gathered from
/// its own buffers), after `b.begin_build()` and with at least one
/// primitive. The tree keeps the buffers as its `prims`.
pub fn build_uploaded_split<B: Backend>(
    b: &mut B,
    (spheres, triangles): (B::Buffer, B::Buffer),
    (sphere_count, triangle_count): (u32, u32),
    hierarchy: Hierarchy,
    budget: f32,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    let n = sphere_count + triangle_count;
    anyhow::ensure!(n >= 1 && n <= MAX_PRIMITIVES, "{n} primitives: the build takes 1 to {MAX_PRIMITIVES}");
    let mut params = BuildParams { spheres: sphere_count, ..Default::default() };
    if budget > 0.0 && triangle_count > 0 && n > 1 {
        let (mut bvh, times) = build_split(b, (sphere_count, triangle_count), hierarchy, budget, &spheres, &triangles)?;
        bvh.prims = Some((spheres, triangles));
        return Ok((bvh, times));
    }
    // The boxes and their centroid bounds in one kernel.
    let first_pass = |b: &mut B, p: &B::Buffer, boxes: &B::Buffer, bounds: &B::Buffer, groups| {
        b.dispatch_with(LbvhKernels::of(b).bounds, bind::PrimitiveBounds { params: p, spheres: &spheres, triangles: &triangles, boxes, bounds }, groups);
        Ok(())
    };
    params.n = n;
    let (mut bvh, times) = build_from_first_pass(b, params, hierarchy, first_pass)?;
    bvh.prims = Some((spheres, triangles));
    Ok((bvh, times))
}

/// Extra references that triangle splitting may add, as a fraction of the
/// triangles (`treelet_core::construct::presplit`), where the process's
/// [`Tuning`](crate::tuning::Tuning) sets it (`TREELET_SPLITS` for the
/// command; 0: no splitting) for every build; `None` where it does not
/// (each builder's default then holds: `crate::bvh::tree::split_budget`).
pub fn split_override() -> Option<f32> {
    crate::tuning::Tuning::current().splits
}

/// The kernels splitting adds to a build on `b`.
pub fn split_kernels<B: Backend>(b: &B) -> Vec<Kernel> {
    [SplitKernels::of(b).all(), ScanKernels::of(b).all()].concat()
}

/// The build over pieces of the triangles (Karras & Aila 2013, section
/// 5.1; `treelet_core::construct::presplit`): at most `budget` times the
/// triangles more references, given to the triangles whose boxes waste
/// most space, then the usual build over the pieces' boxes, and the leaf
/// slots turned back into primitive indices. The tree's `n` is the number
/// of references (leaf slots), a primitive's index may appear in several.
fn build_split<B: Backend>(
    b: &mut B,
    (sphere_count, triangle_count): (u32, u32),
    hierarchy: Hierarchy,
    budget: f32,
    spheres: &B::Buffer,
    triangles: &B::Buffer,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    use treelet_core::construct::presplit::PRIORITY_TILE;
    use treelet_core::geometry::buffers::SplitParams;
    let n = sphere_count + triangle_count;
    let k = SplitKernels::of(b);
    b.stage("split");
    // The primitives' centroid bounds: the Morton grid the pieces follow.
    let params = BuildParams { n, spheres: sphere_count, ..Default::default() };
    let p = b.upload("build params", &[params])?;
    let prim_boxes = b.scratch("primitive boxes", n as u64 * 32)?;
    let bounds = b.upload("centroid bounds", &BOUNDS_START)?;
    b.dispatch_with(k.bounds, bind::PrimitiveBounds { params: &p, spheres, triangles, boxes: &prim_boxes, bounds: &bounds }, groups_for(n, REDUCE_TILE));
    let words: [u32; BOUNDS_WORDS] = b.read::<u32>(&bounds, BOUNDS_WORDS)?.try_into().expect("six words read");
    b.release(&[&prim_boxes]);
    let frame = MortonFrame::new(&bounds_from_words(&words));
    let mut split = SplitParams {
        n,
        spheres: params.spheres,
        scale: 0.0,
        reach: treelet_core::construct::presplit::reach(&frame),
        frame: Aabb::new(frame.offset, frame.scale),
    };
    // Priorities, and their sum (per workgroup on the device, added here in f64).
    let sp = b.upload("split params", &[split])?;
    let priorities = b.scratch("split priorities", n as u64 * 4)?;
    let tiles = groups_for(n, PRIORITY_TILE);
    let partials = b.scratch("split priority sums", tiles as u64 * 4)?;
    b.dispatch_with(k.priority, bind::SplitPriority { params: &sp, triangles, priorities: &priorities, partials: &partials }, tiles);
    let sum: f64 = b.read::<f32>(&partials, tiles as usize)?.iter().map(|&s| s as f64).sum();
    let extra = (budget as f64 * triangle_count as f64).min((MAX_PRIMITIVES - n) as f64);
    split.scale = if sum > 0.0 && sum.is_finite() { (extra / sum) as f32 } else { 0.0 };
    // Pieces per primitive, scanned into offsets; the total after the last.
    let sp = b.upload("split params", &[split])?;
    let offsets = b.scratch("split offsets", (n as u64 + 1) * 4)?;
    b.dispatch_with(k.count, bind::SplitCount { params: &sp, priorities: &priorities, counts: &offsets }, groups_for(n + 1, WORKGROUP_SIZE));
    crate::bvh::sort::exclusive_scan(b, &offsets, n + 1)?;
    let total = b.scratch("split total", 4)?;
    b.copy_words((&offsets, n), (&total, 0), 1)?;
    let refs = b.read::<u32>(&total, 1)?[0];
    anyhow::ensure!(
        refs >= n && refs <= MAX_PRIMITIVES,
        "internal: triangle splitting made {refs} references of {n} primitives"
    );
    b.release(&[&priorities, &partials]);
    let ref_boxes = b.scratch("split boxes", refs as u64 * 32)?;
    let ref_prims = b.scratch("split primitives", refs as u64 * 4)?;
    let emit = bind::SplitEmit { params: &sp, spheres, triangles, offsets: &offsets, ref_boxes: &ref_boxes, ref_prims: &ref_prims };
    b.dispatch_with(k.emit, emit, groups_for(n, WORKGROUP_SIZE));
    let build = BuildParams { n: refs, spheres: params.spheres, ..Default::default() };
    let first_pass = |b: &mut B, p: &B::Buffer, boxes: &B::Buffer, bounds: &B::Buffer, groups| {
        b.dispatch_with(k.piece_bounds, bind::SplitBounds { params: p, ref_boxes: &ref_boxes, boxes, bounds }, groups);
        Ok(())
    };
    let (bvh, mut times) = build_from_first_pass(b, build, hierarchy, first_pass)?;
    // Leaf slots name primitives from here on.
    b.stage("split");
    let p = b.upload("build params", &[build])?;
    b.dispatch_with(k.remap, bind::SplitRemap { params: &p, ref_prims: &ref_prims, values: &bvh.prim_indices }, groups_for(refs, WORKGROUP_SIZE));
    let more = b.take_times()?;
    for s in &more.order {
        times.add(s, more.get(s));
    }
    Ok((bvh, times))
}

/// The LBVH over `n` boxes that `first_pass` makes on the device (an
/// instanced scene's top level: the instances' world boxes), with the
/// default hierarchy for `n`; `first_pass(b, params, boxes, bounds,
/// groups)` dispatches a kernel that writes the `n` boxes (32 bytes each)
/// and merges their centroid bounds into `bounds` (one workgroup per
/// `REDUCE_TILE` boxes; see `treelet_core::construct::bounds`), as
/// [`Kernel::PrimitiveBounds`] does. Starts a new build
/// on `b`. The tree's `prims` is `None`.
pub fn build_over_boxes<B: Backend>(
    b: &mut B,
    n: u32,
    first_pass: impl FnOnce(&mut B, &B::Buffer, &B::Buffer, &B::Buffer, u32) -> Result<()>,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    anyhow::ensure!(n >= 1 && n <= MAX_PRIMITIVES, "{n} boxes: the LBVH takes 1 to {MAX_PRIMITIVES}");
    b.begin_build();
    let hierarchy = Hierarchy::for_device(b, n as usize);
    build_from_first_pass(b, BuildParams { n, ..Default::default() }, hierarchy, first_pass)
}

/// The build after its inputs are on the device: `first_pass` makes the
/// boxes and their centroid bounds, the rest is the same for every input.
fn build_from_first_pass<B: Backend>(
    b: &mut B,
    mut params: BuildParams,
    hierarchy: Hierarchy,
    first_pass: impl FnOnce(&mut B, &B::Buffer, &B::Buffer, &B::Buffer, u32) -> Result<()>,
) -> Result<(DeviceBvh<B>, StageTimes)> {
    let n = params.n;
    let node_count = 2 * n as u64 - 1;
    // Fail before any GPU work when the largest buffer does not fit.
    check_fits(b, "nodes", node_count * std::mem::size_of::<Node>() as u64)?;

    b.stage("bounds");
    // Dev knob, to measure other key lengths (sort passes) against tree quality.
    let key_bits = crate::tuning::Tuning::current().morton_key_bits.unwrap_or(SORTED_KEY_BITS).clamp(1, KEY_BITS);
    params.key_shift = KEY_BITS - key_bits;
    if hierarchy == Hierarchy::Hploc {
        (params.cluster_keep, params.cluster_radius) = hploc_settings();
    }
    // The subgroup hierarchy zeroes its slots itself, just before its climb.
    params.zero_slots = u32::from(hierarchy != Hierarchy::AgglomerativeSubgroup);
    let boxes = b.scratch("primitive boxes", n as u64 * 32)?;
    let p = b.upload("build params", &[params])?;
    // Merged by atomics into words that start as the empty box (uploaded
    // with the parameters, no dispatch).
    let bounds = b.upload("centroid bounds", &BOUNDS_START)?;
    first_pass(b, &p, &boxes, &bounds, groups_for(n, REDUCE_TILE))?;
    let words: [u32; BOUNDS_WORDS] = b.read::<u32>(&bounds, BOUNDS_WORDS)?.try_into().expect("six words read");
    let centroid_bounds = bounds_from_words(&words);

    b.stage("morton");
    MortonFrame::new(&centroid_bounds).to_params(&mut params);
    let keys = b.scratch("morton keys", n as u64 * 8)?;
    let values = b.scratch("primitive indices", n as u64 * 4)?;
    // The hierarchy's arrival slots (one per internal node): the climbs'
    // `ends`, the fit's flags (zeroed by the Morton kernel, see `zero_slots`).
    let slots = b.scratch("hierarchy slots", (n as u64 - 1).max(1) * 4)?;
    // The sort's state, also zeroed by the Morton kernel.
    let high_first = crate::bvh::sort::high_first_by_default();
    let sort_state = if high_first { crate::bvh::sort::high_first_state(b, n, key_bits)? } else { None };
    let zeroed = match &sort_state {
        Some(s) => {
            params.zero_words = s.zeroed_words;
            s.buffer.clone()
        }
        None => b.scratch("no words to zero", 4)?,
    };
    let p = b.upload("build params", &[params])?;
    let morton = bind::Morton { params: &p, boxes: &boxes, keys: &keys, values: &values, slots: &slots, zeroed: &zeroed };
    let morton_kernel = LbvhKernels::of(b).morton;
    b.dispatch_with(morton_kernel, morton, groups_for(n, WORKGROUP_SIZE));

    b.stage("sort");
    let sorted = if high_first {
        crate::bvh::sort::radix_sort_high_first_zeroed(b, &keys, &values, n, key_bits, sort_state)?
    } else {
        None
    };
    let (keys, values) = match sorted {
        Some(sorted) => sorted,
        None => {
            if high_first {
                // Ties too long to settle: codes again, and every digit sorted.
                b.dispatch_with(morton_kernel, morton, groups_for(n, WORKGROUP_SIZE));
            }
            crate::bvh::sort::radix_sort(b, &keys, &values, n, key_bits)?
        }
    };

    let nodes = b.scratch("nodes", node_count * 32)?;
    let parents = b.scratch("parents", node_count * 4)?;
    match hierarchy {
        Hierarchy::RadixTreeThenFit => {
            b.stage("tree");
            let k = RadixTreeKernels::of(b);
            b.dispatch_with(k.tree, bind::RadixTree { params: &p, keys: &keys, nodes: &nodes, parents: &parents }, groups_for(n - 1, WORKGROUP_SIZE));
            b.stage("fit");
            let fit = bind::Fit { params: &p, sorted_prims: &values, prim_boxes: &boxes, nodes: &nodes, parents: &parents, flags: &slots };
            b.dispatch_with(k.fit, fit, groups_for(n, WORKGROUP_SIZE));
        }
        Hierarchy::Agglomerative => {
            // One kernel makes both: its time is the fit's, the tree's is none.
            b.stage("fit");
            let agglomerate =
                bind::Agglomerate { params: &p, keys: &keys, sorted_prims: &values, prim_boxes: &boxes, nodes: &nodes, parents: &parents, ends: &slots };
            b.dispatch_with(AgglomerateKernels::of(b).agglomerate, agglomerate, groups_for(n, WORKGROUP_SIZE));
        }
        Hierarchy::Hploc => {
            b.stage("fit");
            let min = treelet_core::construct::hploc::MIN_SUBGROUP_SIZE;
            if b.min_subgroup_size() < min {
                anyhow::bail!(
                    "the hploc builder needs subgroups of at least {min} lanes, and this device may run {}: use --builder lbvh or trbvh",
                    b.min_subgroup_size()
                );
            }
            let words = treelet_core::construct::hploc::lists_words(n) as u64;
            let lists = b.scratch("hploc clusters", words * 4)?;
            b.dispatch(HplocKernels::of(b).hploc, &[&p, &keys, &values, &boxes, &nodes, &parents, &slots, &lists], groups_for(n, WORKGROUP_SIZE));
        }
        Hierarchy::AgglomerativeSubgroup => {
            b.stage("fit");
            // At most one cluster per leaf is left to climb (where no two
            // leaves of a subgroup are siblings): each queue has room for
            // its workgroups' leaves, the climb's dispatch covers every
            // place, and invocations past a queue's count return.
            let (queues, capacity) = treelet_core::construct::climb_queue::queue_shape(n);
            let places = queues * capacity;
            let queue = b.scratch("agglomerate queues", places as u64 * 8)?;
            let stride = treelet_core::construct::climb_queue::QUEUE_COUNTER_STRIDE;
            let queued = b.zeroed("agglomerate queue counts", (queues * stride) as u64 * 4)?;
            let all = [&p, &keys, &values, &boxes, &nodes, &parents, &slots, &queue, &queued];
            let k = AgglomerateSubgroupKernels::of(b);
            b.dispatch(k.agglomerate, &all, groups_for(n, WORKGROUP_SIZE));
            let climb = bind::ClimbQueued { params: &p, keys: &keys, nodes: &nodes, parents: &parents, ends: &slots, queue: &queue, queued: &queued };
            b.dispatch_with(k.climb, climb, groups_for(places, WORKGROUP_SIZE));
        }
    }

    let times = b.take_times()?;
    let node_count = node_count as u32;
    Ok((DeviceBvh { n, node_count, nodes, parents, prim_indices: values, sorted_keys: keys, centroid_bounds, prims: None }, times))
}

/// H-PLOC's most clusters a merged range keeps (the paper: half the
/// subgroup, 16 on NVIDIA) and how far apart two merged clusters may be
/// (0: any two of the range): [`HPLOC_KEEP`] and [`HPLOC_RADIUS`], or
/// `TREELET_HPLOC_KEEP` and `TREELET_HPLOC_RADIUS` (0: the most) to measure.
pub fn hploc_settings() -> (u32, u32) {
    let tuning = crate::tuning::Tuning::current();
    (tuning.hploc_keep.unwrap_or(HPLOC_KEEP), tuning.hploc_radius.unwrap_or(HPLOC_RADIUS))
}

/// Clusters a merged range keeps: 2, not the paper's 16. Measured on the
/// H100 (bunny4, 940 544 triangles, `bvh2`, 1920x1080; all four keeps
/// against all radii, `docs/results/h100-hploc/`): with 16 kept the
/// clusters left over at each level are merged late, into nodes that
/// overlap, and primary rays ran at 1.41 G/s against the LBVH's 2.11 and
/// the TRBVH's 2.13, although the SAH was lower than the LBVH's; with 2
/// kept, 2.09 G primary and 1.02 G diffuse rays/s (TRBVH: 2.13, 1.02) for
/// a build of 1.85 ms against the TRBVH's 9.05.
pub const HPLOC_KEEP: u32 = 2;
/// Any two clusters of a range may merge (radius 2 builds in 1.41 ms, with
/// diffuse rays 5% slower).
pub const HPLOC_RADIUS: u32 = 0;

/// Fewest primitives for which the default hierarchy is
/// [`Hierarchy::AgglomerativeSubgroup`]: below, its second dispatch costs
/// more than it saves (H100: 65 536 primitives 0.077 ms against 0.070 plain;
/// 1M 0.21 against 0.33).
pub const SUBGROUP_HIERARCHY_MIN: usize = 131_072;

/// How the hierarchy and its boxes are made from the sorted keys; all but
/// [`Hierarchy::Hploc`] give the same nodes, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hierarchy {
    /// Karras 2012: the radix tree (one invocation per internal node), then
    /// the bottom-up fit.
    RadixTreeThenFit,
    /// Apetrei 2014: both in one bottom-up pass.
    Agglomerative,
    /// [`Hierarchy::Agglomerative`] with the lowest levels merged within
    /// each subgroup (`treelet_core::construct::agglomerate_subgroup`).
    AgglomerativeSubgroup,
    /// H-PLOC (Benthin et al. 2024, `treelet_core::construct::hploc`): not
    /// the radix tree but a better one, whose nodes merge nearest
    /// neighbours; the hierarchy of `Builder::Hploc`, never a default.
    Hploc,
}

impl Hierarchy {
    /// The hierarchy for `n` primitives on `b`: `TREELET_HIERARCHY=radix|agglomerative|subgroup|hploc`
    /// (to measure; `hploc` gives the LBVH and TRBVH builders H-PLOC's tree), else agglomerative (faster than radix tree plus fit at
    /// every size measured on the H100: 0.070 ms against 0.020 + 0.076 at
    /// 65 536 primitives, 0.328 against 0.064 + 0.311 at 1M), merged within
    /// subgroups first on GPUs from [`SUBGROUP_HIERARCHY_MIN`] primitives up
    /// (not on CPU cores: lavapipe's subgroups are 8 lanes, and there the
    /// climb costs no more for being spread; 1M primitives on two cores
    /// took 130 to 167 ms either way).
    pub fn for_device<B: Backend>(b: &B, n: usize) -> Hierarchy {
        Hierarchy::from_env().unwrap_or(if n >= SUBGROUP_HIERARCHY_MIN && !b.runs_on_cpu() {
            Hierarchy::AgglomerativeSubgroup
        } else {
            Hierarchy::Agglomerative
        })
    }

    /// The hierarchy the process's [`Tuning`](crate::tuning::Tuning) asks
    /// for (`TREELET_HIERARCHY` for the command), if it does.
    pub fn from_env() -> Option<Hierarchy> {
        use crate::tuning::Hierarchy as Forced;
        crate::tuning::Tuning::current().hierarchy.map(|h| match h {
            Forced::Radix => Hierarchy::RadixTreeThenFit,
            Forced::Agglomerative => Hierarchy::Agglomerative,
            Forced::Subgroup => Hierarchy::AgglomerativeSubgroup,
            Forced::Hploc => Hierarchy::Hploc,
        })
    }

    /// The kernels of a hierarchy, as `b` runs them (relaxed atomics where
    /// it needs them: `Backend::atomics_for`).
    fn kernels<B: Backend>(self, b: &B) -> Vec<Kernel> {
        match self {
            Hierarchy::RadixTreeThenFit => RadixTreeKernels::of(b).all(),
            Hierarchy::Agglomerative => AgglomerateKernels::of(b).all(),
            Hierarchy::AgglomerativeSubgroup => AgglomerateSubgroupKernels::of(b).all(),
            Hierarchy::Hploc => HplocKernels::of(b).all(),
        }
    }
}

/// `data` on the device, or one zeroed element where it is empty (a
/// binding needs a buffer; the kernels never read past their counts).
pub fn upload_or_placeholder<B: Backend, T: bytemuck::Pod>(
    b: &mut B,
    label: &'static str,
    data: &[T],
) -> Result<B::Buffer> {
    if data.is_empty() {
        b.upload(label, &[T::zeroed()])
    } else {
        b.upload(label, data)
    }
}

pub use crate::scene::primitives::MAX_PRIMITIVES;
