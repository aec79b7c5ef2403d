//! The CPU runner: the same kernel functions of `treelet-core` the shaders
//! call, run over every invocation id (and, for workgroup kernels, every
//! workgroup phase by phase, each phase over all local ids: see
//! `treelet_core::gpu::workgroup`). Invocations run
//! one after another, so results are deterministic and equal the GPU's
//! wherever the kernels are (the sort is stable, the tree unique).
use std::cell::RefCell;
use std::rc::Rc;
use std::time::Instant;

use anyhow::Result;
use bytemuck::Pod;
use rayon::prelude::*;
use treelet_core::geometry::split::{Split, SplitMut};
use treelet_core::construct::sort::multisplit_rank::{multisplit_op, multisplit_phase, MultisplitLane, MULTISPLIT_PHASES};
use treelet_core::gpu::subgroup::{self, Lane};
use treelet_core::gpu::workgroup::{WG, WORKGROUP_SIZE, groups_for};
use treelet_core::render::integrator::{SceneRefs, accumulate, render_pixel};
use treelet_core::render::lights::Light;
use treelet_core::render::variants::VARIANTS;
use treelet_core::trace::bvh2::{Bvh2Tree, Level};
use treelet_core::trace::bvh4::Bvh4Tree;
use treelet_core::trace::with_instances::SceneWithInstances;
use treelet_core::trace::classic::{ClassicTree, Scan};
use treelet_core::trace::cwbvh::{WORKGROUP_STACK_WORDS, WideTree};
use treelet_core::trace::hit::ClosestHit;
use treelet_core::construct::sort;
use treelet_core::construct::treelet::kernels as treelet_kernels;

use crate::runtime::backend::{Backend, StageTimes};
use crate::runtime::kernels::{Kernel, Method};

/// A CPU buffer: 8-byte words, so that any Pod type of alignment ≤ 8 views it.
pub type CpuBuffer = Rc<RefCell<Vec<u64>>>;

pub struct CpuBackend {
    times: StageTimes,
    current: Option<(&'static str, Instant)>,
    /// Lanes of a subgroup in the emulation of subgroup operations
    /// (`treelet_core::gpu::subgroup`): set it to a GPU's to compare exactly.
    subgroup_size: u32,
    /// Every kernel dispatched so far (what a GPU would need pipelines for).
    dispatched: std::collections::BTreeSet<Kernel>,
    /// Every kernel listed to [`Backend::prepare_kernels`] so far, with the
    /// backend's own (what a GPU would have built ahead).
    prepared: std::collections::BTreeSet<Kernel>,
}

impl Default for CpuBackend {
    fn default() -> Self {
        CpuBackend {
            times: StageTimes::default(),
            current: None,
            subgroup_size: DEFAULT_SUBGROUP_SIZE,
            dispatched: Default::default(),
            prepared: Default::default(),
        }
    }
}

/// The CPU runner's subgroup size unless set: NVIDIA's.
pub const DEFAULT_SUBGROUP_SIZE: u32 = 32;

impl CpuBackend {
    pub fn new() -> Self {
        Self::default()
    }

    /// A CPU runner whose subgroups have `size` lanes (a power of two from
    /// 1 to 64, as Vulkan's are).
    pub fn with_subgroup_size(size: u32) -> Self {
        assert!(size.is_power_of_two() && size <= subgroup::MAX_SUBGROUP_SIZE, "subgroup size {size}");
        CpuBackend { subgroup_size: size, ..Self::default() }
    }

    pub fn subgroup_size(&self) -> u32 {
        self.subgroup_size
    }

    /// Every kernel dispatched on this backend so far.
    pub fn kernels_dispatched(&self) -> &std::collections::BTreeSet<Kernel> {
        &self.dispatched
    }

    /// The kernels dispatched so far that no call of
    /// [`Backend::prepare_kernels`] listed: on a GPU, pipelines built in the
    /// middle of timed work.
    pub fn kernels_not_prepared(&self) -> Vec<Kernel> {
        self.dispatched.difference(&self.prepared).copied().collect()
    }

    fn close_stage(&mut self) {
        if let Some((stage, start)) = self.current.take() {
            self.times.add(stage, start.elapsed().as_secs_f64() * 1e3);
        }
    }
}

/// The whole-element prefix of a word buffer, as `T`s.
fn view<T: Pod>(words: &mut [u64]) -> &mut [T] {
    let bytes: &mut [u8] = bytemuck::cast_slice_mut(words);
    let whole = bytes.len() / std::mem::size_of::<T>() * std::mem::size_of::<T>();
    bytemuck::cast_slice_mut(&mut bytes[..whole])
}

fn params<T: Pod>(words: &mut [u64]) -> T {
    view::<T>(words)[0]
}

/// Runs a phased kernel with subgroup operations
/// (`treelet_core::gpu::subgroup`): for each workgroup and phase,
/// `f(group, phase, local_id, lanes)` for every local id, then the phase's
/// operation `op(phase)` over each subgroup of `size` lanes of `lanes`.
fn subgroup_workgroups(groups: u32, phases: u32, size: u32, op: impl Fn(u32) -> u32, mut f: impl FnMut(u32, u32, u32, &mut [Lane; WG])) {
    let mut lanes = [Lane::default(); WG];
    for group in 0..groups {
        for phase in 0..phases {
            for lid in 0..WORKGROUP_SIZE {
                f(group, phase, lid, &mut lanes);
            }
            let op = op(phase) & subgroup::OP_MASK;
            if op != subgroup::OP_NONE {
                for chunk in lanes.chunks_mut(size as usize) {
                    subgroup::emulate(op, chunk);
                }
            }
        }
    }
}

/// Runs a phased workgroup kernel: for each workgroup, each phase, each local
/// id, `f(group, phase, local_id)`. Workgroup memory is the caller's, reused
/// across workgroups as on the GPU (where it starts undefined).
fn workgroups(groups: u32, phases: u32, f: impl FnMut(u32, u32, u32)) {
    workgroups_of(WORKGROUP_SIZE, groups, phases, f)
}

/// [`workgroups`] for a kernel of `size` invocations per workgroup.
fn workgroups_of(size: u32, groups: u32, phases: u32, mut f: impl FnMut(u32, u32, u32)) {
    for group in 0..groups {
        for phase in 0..phases {
            for lid in 0..size {
                f(group, phase, lid);
            }
        }
    }
}

/// `render_pixel` compiled for `VARIANTS[v]`, as the shader's entry points are.
fn render_variant<T: ClosestHit>(
    v: u8,
    id: u32,
    p: &treelet_core::RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
) -> [f32; 4] {
    let stack = &mut [0u32; 1];
    // One arm per variant of the one list (`for_each_render_variant!`).
    macro_rules! arms {
        ([$v:ident] $($i:literal $name:ident [$($f:path),*];)*) => {
            match $v {
                $($i => render_pixel::<T, { 0 $(| $f)* }, 1>(id, p, scene, lights, stack, 0),)*
                _ => panic!("render variant {} of {}", $v, VARIANTS.len()),
            }
        };
    }
    treelet_core::for_each_render_variant!(arms, v)
}

/// Every pixel of a render dispatch (pixels are independent: the one
/// kernel the CPU runs in parallel; the GPU's tiling of pixels, see
/// `treelet_core::render::integrator::tiled_pixel`, only orders them).
fn render_all<T: ClosestHit + Sync>(
    v: u8,
    p: &treelet_core::RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
    accum: &mut [[f32; 4]],
    groups: u32,
) {
    let pixels = ((p.width * p.height) as usize).min(accum.len()).min((groups * WORKGROUP_SIZE) as usize);
    accum[..pixels]
        .par_iter_mut()
        .enumerate()
        .for_each(|(id, acc)| accumulate(acc, render_variant(v, id as u32, p, scene, lights)));
}

/// Light paths' landings shared by the CPU runner's threads: each word an
/// atomic, added to by compare-exchange (as the GPU does).
struct SharedLandings<'a>(&'a [std::sync::atomic::AtomicU32]);

impl treelet_core::render::caustics::Landings for SharedLandings<'_> {
    fn add(&mut self, word: usize, value: f32) {
        treelet_core::gpu::atomics::add_f32_host(&self.0[word], value);
    }
}

/// The light paths of every pixel of a dispatch (`light_paths` compiled for
/// `VARIANTS[v]`), in parallel (see [`light_with`]).
fn light_all<T: ClosestHit + Sync>(
    v: u8,
    p: &treelet_core::RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
    splats: &mut [u32],
    groups: u32,
) {
    macro_rules! arms {
        ([$v:ident] $($i:literal $name:ident [$($f:path),*];)*) => {
            match $v {
                $($i => light_with::<T, { 0 $(| $f)* }>(p, scene, lights, splats, groups),)*
                _ => panic!("render variant {} of {}", $v, VARIANTS.len()),
            }
        };
    }
    treelet_core::for_each_render_variant!(arms, v)
}

/// The light paths of every pixel of a dispatch, compiled for features
/// `F`, in parallel: they land anywhere, so through atomics.
fn light_with<T: ClosestHit + Sync, const F: u32>(
    p: &treelet_core::RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
    splats: &mut [u32],
    groups: u32,
) {
    use treelet_core::render::caustics::light_paths;
    let pixels = (p.width * p.height).min(groups * WORKGROUP_SIZE);
    let shared: &[std::sync::atomic::AtomicU32] = {
        let words = splats.as_mut_ptr();
        // SAFETY: `splats` is exclusively borrowed for this call, u32 and
        // AtomicU32 have the same size and alignment, and every access below
        // is atomic.
        unsafe { std::slice::from_raw_parts(words as *const std::sync::atomic::AtomicU32, splats.len()) }
    };
    (0..pixels).into_par_iter().for_each(|id| {
        light_paths::<T, F, 1, _>(id, p, scene, lights, &mut SharedLandings(shared), &mut [0u32; 1], 0)
    });
}

/// The sort pass ranked by subgroups (`ITEMS` keys per lane), its
/// workgroups one after another, each subgroup's operations emulated.
fn multisplit_sort_pass<const ITEMS: u32>(
    p: &treelet_core::SortParams,
    (keys_in, values_in, keys_out, values_out, sort_state): (&[u64], &[u32], &mut [u64], &mut [u32], &mut [u32]),
    groups: u32,
    size: u32,
    partitioned: bool,
) {
    use treelet_core::construct::sort::multisplit::*;
    let mut ticket = [0u32; 1];
    let mut counts = [0u32; SUBGROUP_COUNTS];
    let (mut running, mut local_offsets, mut global_offsets, mut scan_sums) = ([0u32; WG], [0u32; WG], [0u32; WG], [0u32; 16]);
    let mut lanes = [MultisplitPassLane::default(); WG];
    let sync = |phase| multisplit_pass_sync(phase, ITEMS, partitioned);
    subgroup_workgroups(groups, multisplit_pass_phases(ITEMS), size, sync, |_, phase, lid, io| {
        multisplit_pass_phase::<ITEMS>(
            phase,
            lid,
            lid / size,
            lid % size,
            size,
            p,
            keys_in,
            values_in,
            keys_out,
            values_out,
            sort_state,
            &mut ticket,
            &mut counts,
            &mut running,
            &mut local_offsets,
            &mut global_offsets,
            &mut scan_sums,
            &mut lanes[lid as usize],
            &mut io[lid as usize],
        )
    });
}

/// A sort pass kernel's workgroups, one after another: every earlier
/// ticket's tile is done when a look-back reads it, so it never waits.
fn onesweep<const LOOK_BACK: bool, const ITEMS: u32, const TILE: usize>(
    p: &treelet_core::SortParams,
    (keys_in, values_in, keys_out, values_out, sort_state): (&[u64], &[u32], &mut [u64], &mut [u32], &mut [u32]),
    groups: u32,
) {
    let mut ticket = [0u32; 1];
    let (mut running, mut digits, mut totals) = ([0u32; WG], [0u32; WG], [0u32; WG]);
    let (mut local_offsets, mut global_offsets) = ([0u32; WG], [0u32; WG]);
    let mut packed = [0u32; sort::PACKED_DIGITS];
    let mut counts = [0u32; sort::CHUNK_COUNTS];
    let mut ranks = [0u32; TILE];
    let mut scan_sums = [0u32; 16];
    workgroups(groups, sort::onesweep_phases(ITEMS), |g, phase, lid| {
        sort::onesweep_phase::<LOOK_BACK, ITEMS, TILE>(
            phase,
            lid,
            g,
            p,
            keys_in,
            values_in,
            keys_out,
            values_out,
            sort_state,
            &mut ticket,
            &mut running,
            &mut digits,
            &mut packed,
            &mut counts,
            &mut totals,
            &mut ranks,
            &mut local_offsets,
            &mut global_offsets,
            &mut scan_sums,
        )
    });
}

/// Every invocation of a cast dispatch, `S` words of workgroup stack each
/// (one invocation at a time: each gets the whole array as its own).
fn cast_all<T: ClosestHit, const F: u32, const S: usize>(
    p: &treelet_core::RenderParams,
    scene: &SceneRefs<T>,
    rays: &mut [[f32; 4]],
    groups: u32,
) {
    let mut stack = vec![0u32; S];
    let stack: &mut [u32; S] = stack.as_mut_slice().try_into().unwrap();
    for id in ids(groups) {
        treelet_core::render::rays::cast_kernel::<T, F, S>(id, p, scene, rays, stack, id % WORKGROUP_SIZE);
    }
}

/// [`cast_all`] compiled for every primitive kind, or triangles alone.
fn cast_variant<T: ClosestHit>(
    triangles: bool,
    p: &treelet_core::RenderParams,
    scene: &SceneRefs<T>,
    rays: &mut [[f32; 4]],
    groups: u32,
) {
    use treelet_core::geometry::features::{ALL, TRIANGLES};
    if triangles {
        cast_all::<T, TRIANGLES, 1>(p, scene, rays, groups)
    } else {
        cast_all::<T, ALL, 1>(p, scene, rays, groups)
    }
}

/// Invocation ids of a dispatch of `groups` workgroups.
fn ids(groups: u32) -> std::ops::Range<u32> {
    0..groups * WORKGROUP_SIZE
}

impl Backend for CpuBackend {
    type Buffer = CpuBuffer;

    /// Builds nothing (the runner calls functions); notes the kernels, as
    /// a GPU's list, for [`CpuBackend::kernels_not_prepared`].
    fn prepare_kernels(&mut self, kernels: &[Kernel]) -> f64 {
        let own = crate::runtime::backend::BackendKernels::of(self).all();
        self.prepared.extend(kernels.iter().chain(&own));
        0.0
    }

    fn adapter(&self) -> String {
        "cpu".into()
    }
    fn buffer_bytes(&self, buffer: &CpuBuffer) -> u64 {
        buffer.borrow().len() as u64 * 8
    }
    fn same_buffer(&self, a: &CpuBuffer, b: &CpuBuffer) -> bool {
        Rc::ptr_eq(a, b)
    }
    fn device_kind(&self) -> &'static str {
        "cpu"
    }
    fn runs_on_cpu(&self) -> bool {
        true
    }
    fn min_subgroup_size(&self) -> u32 {
        self.subgroup_size
    }
    fn max_buffer_bytes(&self) -> u64 {
        u64::MAX
    }

    fn upload<T: Pod>(&mut self, label: &'static str, data: &[T]) -> Result<CpuBuffer> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let mut words = zeroed_words(bytes.len() as u64, label)?;
        bytemuck::cast_slice_mut::<u64, u8>(&mut words)[..bytes.len()].copy_from_slice(bytes);
        Ok(Rc::new(RefCell::new(words)))
    }

    fn upload_indexed<T: Pod + Send>(&mut self, label: &'static str, len: usize, item: impl Fn(usize) -> Result<T> + Sync) -> Result<CpuBuffer> {
        let bytes = (len as u64).checked_mul(std::mem::size_of::<T>() as u64).unwrap_or(u64::MAX);
        let mut words = zeroed_words(bytes, label)?;
        for (k, slot) in view::<T>(&mut words)[..len].iter_mut().enumerate() {
            *slot = item(k)?;
        }
        Ok(Rc::new(RefCell::new(words)))
    }

    fn scratch(&mut self, label: &'static str, bytes: u64) -> Result<CpuBuffer> {
        Ok(Rc::new(RefCell::new(zeroed_words(bytes, label)?)))
    }

    fn stage(&mut self, stage: &'static str) {
        self.close_stage();
        self.current = Some((stage, Instant::now()));
    }

    fn dispatch_listed(&mut self, kernel: Kernel, bindings: &[&CpuBuffer], groups: u32) {
        assert_eq!(bindings.len(), kernel.bindings().len(), "{kernel:?}: wrong number of bindings");
        let mut guards: Vec<_> = bindings.iter().map(|b| b.borrow_mut()).collect();
        let mut b: Vec<&mut [u64]> = guards.iter_mut().map(|g| g.as_mut_slice()).collect();
        // The runner counts invocations in workgroups of `WORKGROUP_SIZE`;
        // the ray kernels' smaller ones are rounded up to those (their
        // invocations past the last pixel return at once, as on the GPU).
        let groups = groups_for(groups * kernel.workgroup_size(), WORKGROUP_SIZE);
        run_kernel(kernel, &mut b, groups, self.subgroup_size);
        self.dispatched.insert(kernel);
    }

    fn read<T: Pod>(&mut self, buffer: &CpuBuffer, count: usize) -> Result<Vec<T>> {
        let mut words = buffer.borrow_mut();
        let mut out = crate::internals::input::room_for(count, "a buffer read back from the CPU runner")?;
        out.extend_from_slice(&view::<T>(&mut words)[..count]);
        Ok(out)
    }

    fn read_with<T: Pod, R>(&mut self, buffer: &CpuBuffer, count: usize, take: impl FnOnce(&[T]) -> R) -> Result<R> {
        Ok(take(&view::<T>(&mut buffer.borrow_mut())[..count]))
    }

    fn take_times(&mut self) -> Result<StageTimes> {
        self.close_stage();
        let mut times = std::mem::take(&mut self.times);
        times.source = "wall-clock";
        Ok(times)
    }
}

/// A runner buffer of at least `bytes` bytes, zeroed: its memory asked for
/// first, so that a buffer the machine cannot hold is an error naming it
/// (`buffer \`nodes\``), not an abort.
fn zeroed_words(bytes: u64, label: &str) -> Result<Vec<u64>> {
    let words = usize::try_from(bytes.div_ceil(8).max(1))
        .map_err(|_| crate::error::too_large(format!("buffer `{label}`: {bytes} bytes do not fit this machine's addresses")))?;
    crate::internals::input::zeroed_vec(words, &format!("buffer `{label}` on the CPU runner"))
}

/// A binding of a registered kernel as its call takes it: a shared or a
/// mutable view of the buffer's words.
macro_rules! cpu_view {
    (read, $b:ident, $t:ty) => {
        let $b: &[$t] = view($b);
    };
    (write, $b:ident, $t:ty) => {
        let $b: &mut [$t] = view($b);
    };
}

/// A buffer the GPU binds in two parts, bound whole.
macro_rules! cpu_whole {
    (read, $b:ident, $hi:ident) => {
        let $b = Split::whole($b);
    };
    (write, $b:ident, $hi:ident) => {
        #[allow(unused_mut)]
        let mut $b = SplitMut::whole($b);
    };
}

/// The element type the CPU views a binding as (`as` in the registry).
macro_rules! cpu_type {
    ($t:ty) => {
        $t
    };
    ($t:ty, $cpu:ty) => {
        $cpu
    };
}

/// A registered kernel's parameters (`$p`, a reference) and bindings (each
/// by its name) as its call takes them, from the dispatch's buffers `b`.
macro_rules! cpu_bindings {
    ($kernel:ident, $buffers:ident, $params:ty, $p:ident, $($access:ident $b:ident [$t:ty $(as $cpu:ty)?] $(| $hi:ident)?),*) => {
        let [params_words, $($b),*] = $buffers else { panic!("{:?}: wrong number of bindings", $kernel) };
        let params_value: $params = params(params_words);
        let $p = &params_value;
        $(cpu_view!($access, $b, cpu_type!($t $(, $cpu)?));)*
        $($(cpu_whole!($access, $b, $hi);)?)*
    };
}

// The registry's kernels (`treelet_core::registry`): each one's call, made
// from its one declaration, for every invocation.
macro_rules! run_registered {
    ($(
        $(#[doc = $doc:expr])*
        $(#[relaxed_of($ordered:ident)])?
        $name:ident = $entry:ident($params:ty) {
            $($binding:literal $b:ident : $access:ident [$t:ty $(as $cpu:ty)?] $(| $hi_binding:literal $hi:ident)?),* $(,)?
        } |$id:ident, $p:ident| $call:expr;
    )*) => {
        /// Runs `kernel` if it is one of the registry's (and says whether it was).
        fn run_registered(kernel: Kernel, b: &mut [&mut [u64]], groups: u32) -> bool {
            match kernel {
                $(Kernel::$name => {
                    cpu_bindings!(kernel, b, $params, $p, $($access $b [$t $(as $cpu)?] $(| $hi)?),*);
                    for $id in ids(groups) {
                        $call;
                    }
                    true
                })*
                _ => false,
            }
        }
    };
}
treelet_core::per_invocation_kernels!(run_registered);

// The per-workgroup registry's kernels: each one's call, made from its one
// declaration, for every invocation of each workgroup, phase by phase.
macro_rules! run_per_workgroup {
    ($(
        $(#[doc = $doc:expr])*
        $name:ident = $entry:ident($params:ty) phases($count:expr, [$($phase:literal)*]) shared { $($s:ident : [$st:ty; $sn:expr]),* $(,)? } {
            $($binding:literal $b:ident : $access:ident [$t:ty $(as $cpu:ty)?] $(| $hi_binding:literal $hi:ident)?),* $(,)?
        } |$ph:ident, $lid:ident, $group:ident, $p:ident| $call:expr;
    )*) => {
        /// Runs `kernel` if it is one of the per-workgroup registry's (and
        /// says whether it was).
        fn run_per_workgroup(kernel: Kernel, b: &mut [&mut [u64]], groups: u32) -> bool {
            match kernel {
                $(Kernel::$name => {
                    cpu_bindings!(kernel, b, $params, $p, $($access $b [$t $(as $cpu)?] $(| $hi)?),*);
                    $(let mut $s: [$st; $sn] = [bytemuck::Zeroable::zeroed(); $sn];)*
                    $(let $s = &mut $s;)*
                    workgroups(groups, $count, |$group, $ph, $lid| {
                        let _ = $group;
                        $call;
                    });
                    true
                })*
                _ => false,
            }
        }
    };
}
treelet_core::per_workgroup_kernels!(run_per_workgroup);

/// Calls the core function of `kernel` for every invocation of the dispatch.
fn run_kernel(kernel: Kernel, b: &mut [&mut [u64]], groups: u32, subgroup_size: u32) {
    if run_registered(kernel, b, groups) || run_per_workgroup(kernel, b, groups) {
        return;
    }
    match (kernel, b) {
        (Kernel::CastInstances, [p, instances, nodes, leaves, spheres, triangles, rays]) => {
            use treelet_core::{Bvh2Node, LeafPrim};
            let p: treelet_core::RenderParams = params(p);
            let prims = treelet_core::geometry::prims::Prims {
                spheres: view(spheres),
                sphere_count: 0,
                triangles: Split::whole(view(triangles)),
                triangle_count: p.triangles,
            };
            let (nodes, leaves): (&[Bvh2Node], &[LeafPrim]) = (view(nodes), view(leaves));
            let (instances, rays): (&[treelet_core::InstanceRecord], _) = (view(instances), view(rays));
            for id in ids(groups) {
                treelet_core::render::rays::cast_instances_kernel(id, &p, instances, nodes, leaves, &prims, rays);
            }
        }
        (Kernel::Multisplit, [p, keys, ranks, counts, sizes]) => {
            let p: treelet_core::SortParams = params(p);
            let (keys, ranks, counts, sizes) = (view(keys), view(ranks), view(counts), view(sizes));
            let mut states = [MultisplitLane::default(); WG];
            let size = subgroup_size;
            subgroup_workgroups(groups, MULTISPLIT_PHASES, size, multisplit_op, |g, phase, lid, lanes| {
                let (id, l) = (g * WORKGROUP_SIZE + lid, lid as usize);
                multisplit_phase(phase, id, g, lid % size, size, &p, keys, ranks, counts, sizes, &mut states[l], &mut lanes[l]);
            });
        }
        (
            Kernel::SortMultisplit | Kernel::SortMultisplitPartitioned,
            [p, keys_in, values_in, keys_out, values_out, sort_state],
        ) => {
            use treelet_core::construct::sort::multisplit::MULTISPLIT_SORT_ITEMS;
            let p: treelet_core::SortParams = params(p);
            let io = (&*view(keys_in), &*view(values_in), view(keys_out), view(values_out), view(sort_state));
            let partitioned = kernel == Kernel::SortMultisplitPartitioned;
            multisplit_sort_pass::<MULTISPLIT_SORT_ITEMS>(&p, io, groups, subgroup_size, partitioned);
        }
        (
            Kernel::SortMultisplitSmall | Kernel::SortMultisplitSmallPartitioned,
            [p, keys_in, values_in, keys_out, values_out, sort_state],
        ) => {
            use treelet_core::construct::sort::multisplit::SMALL_MULTISPLIT_SORT_ITEMS;
            let p: treelet_core::SortParams = params(p);
            let io = (&*view(keys_in), &*view(values_in), view(keys_out), view(values_out), view(sort_state));
            let partitioned = kernel == Kernel::SortMultisplitSmallPartitioned;
            multisplit_sort_pass::<SMALL_MULTISPLIT_SORT_ITEMS>(&p, io, groups, subgroup_size, partitioned);
        }
        (
            Kernel::SortMultisplitMedium | Kernel::SortMultisplitMediumPartitioned,
            [p, keys_in, values_in, keys_out, values_out, sort_state],
        ) => {
            use treelet_core::construct::sort::multisplit::MEDIUM_MULTISPLIT_SORT_ITEMS;
            let p: treelet_core::SortParams = params(p);
            let io = (&*view(keys_in), &*view(values_in), view(keys_out), view(values_out), view(sort_state));
            let partitioned = kernel == Kernel::SortMultisplitMediumPartitioned;
            multisplit_sort_pass::<MEDIUM_MULTISPLIT_SORT_ITEMS>(&p, io, groups, subgroup_size, partitioned);
        }
        (
            kernel @ (Kernel::SortOnesweep | Kernel::SortOnesweepSmall | Kernel::SortOnesweepScanned),
            [p, keys_in, values_in, keys_out, values_out, sort_state],
        ) => {
            let p: treelet_core::SortParams = params(p);
            let (keys_in, values_in, sort_state) = (view(keys_in), view(values_in), view(sort_state));
            let (keys_out, values_out) = (view(keys_out), view(values_out));
            let io = (&*keys_in, &*values_in, keys_out, values_out, sort_state);
            match kernel {
                Kernel::SortOnesweep => onesweep::<true, { sort::SORT_ITEMS }, { sort::SORT_TILE as usize }>(&p, io, groups),
                Kernel::SortOnesweepSmall => {
                    onesweep::<true, { sort::SMALL_SORT_ITEMS }, { sort::SMALL_SORT_TILE as usize }>(&p, io, groups)
                }
                _ => onesweep::<false, { sort::SORT_ITEMS }, { sort::SORT_TILE as usize }>(&p, io, groups),
            }
        }
        (Kernel::AgglomerateSubgroup, [p, keys, prims, boxes, nodes, parents, ends, queue, queued]) => {
            use treelet_core::construct::agglomerate_subgroup::*;
            let p: treelet_core::BuildParams = params(p);
            let (keys, prims, boxes, nodes) = (view(keys), view(prims), view(boxes), view::<treelet_core::Node>(nodes));
            let (parents, ends, queue, queued) = (view(parents), view(ends), view(queue), view(queued));
            let mut states = [AgglomerateLane::default(); WG];
            let size = subgroup_size;
            let op = |phase| agglomerate_subgroup_op(agglomerate_subgroup_step(phase));
            subgroup_workgroups(groups, AGGLOMERATE_SUBGROUP_PHASES, size, op, |g, phase, lid, lanes| {
                let (id, l) = (g * WORKGROUP_SIZE + lid, lid as usize);
                let step = agglomerate_subgroup_step(phase);
                let (me, io) = (&mut states[l], &mut lanes[l]);
                agglomerate_subgroup_phase(step, id, lid % size, size, p.n, keys, prims, boxes, nodes, parents, ends, queue, queued, me, io);
            });
        }
        (Kernel::Hploc | Kernel::HplocRelaxed, [p, keys, prims, boxes, nodes, parents, ends, lists]) => {
            use treelet_core::construct::hploc::{hploc_subgroup_on_cpu, SHARED_BOX_WORDS};
            let p: treelet_core::BuildParams = params(p);
            let (keys, prims, boxes, nodes) = (view(keys), view(prims), view(boxes), view::<treelet_core::Node>(nodes));
            let (parents, ends, lists) = (view(parents), view(ends), view(lists));
            let mut shared = ([0f32; SHARED_BOX_WORDS], [0u32; WG], [0u32; WG]);
            let settings = (p.n, p.cluster_keep, p.cluster_radius);
            for g in 0..groups {
                for base in (0..WORKGROUP_SIZE).step_by(subgroup_size as usize) {
                    let sh = (&mut shared.0, &mut shared.1, &mut shared.2);
                    let inputs = (&*keys, &*prims, &*boxes);
                    hploc_subgroup_on_cpu(g, base, subgroup_size, settings, inputs, &mut SplitMut::whole(nodes), parents, ends, lists, sh);
                }
            }
        }
        (Kernel::TreeletRestructure, [p, roots, subsets, nodes, parents, counts, costs, heights, marks]) => {
            let p: treelet_core::geometry::buffers::TreeletParams = params(p);
            let (roots, subsets, parents) = (view(roots), view(subsets), view(parents));
            let nodes = &mut SplitMut::whole(view(nodes));
            let (counts, costs, heights, marks) = (view(counts), view(costs), view(heights), view(marks));
            let mut stage = [0u32; treelet_kernels::TEAM_STAGE];
            let mut cost = [0f32; treelet_kernels::TEAM_COSTS];
            let mut parts = [0u32; treelet_kernels::TEAM_PARTS];
            let mut order = [0u32; treelet_core::construct::treelet::SUBSETS];
            let mut votes = [0u32; treelet_kernels::TEAM_VOTES];
            workgroups_of(treelet_kernels::RESTRUCTURE_THREADS, groups, treelet_kernels::RESTRUCTURE_PHASES, |group, phase, lid| {
                treelet_kernels::treelet_restructure_phase(
                    phase, lid, group, &p, roots, subsets, nodes, parents, counts, costs, heights, marks, &mut stage,
                    &mut cost, &mut parts, &mut order, &mut votes,
                );
            });
        }
        (Kernel::Cast(..) | Kernel::CastWideWorkgroupStack, [p, spheres, materials, nodes, prims, rays, triangles]) => {
            let p: treelet_core::RenderParams = params(p);
            let (spheres, triangles, materials) = (view(spheres), Split::whole(view(triangles)), view(materials));
            let rays: &mut [[f32; 4]] = view(rays);
            match kernel {
                Kernel::Cast(Method::Classic, tri) => {
                    let scene =
                        SceneRefs::new(&p, spheres, triangles, materials, ClassicTree::new(view(nodes), view(prims)));
                    cast_variant(tri, &p, &scene, rays, groups);
                }
                Kernel::Cast(Method::Bvh2, tri) => {
                    let scene =
                        SceneRefs::new(&p, spheres, triangles, materials, Bvh2Tree::new(view::<treelet_core::Bvh2Node>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]));
                    cast_variant(tri, &p, &scene, rays, groups);
                }
                Kernel::Cast(Method::Bvh4, tri) => {
                    let scene =
                        SceneRefs::new(&p, spheres, triangles, materials, Bvh4Tree::new(view::<treelet_core::Bvh4Node>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]));
                    cast_variant(tri, &p, &scene, rays, groups);
                }
                Kernel::Cast(Method::Cwbvh, tri) => {
                    let scene =
                        SceneRefs::new(&p, spheres, triangles, materials, WideTree::new(view::<treelet_core::WideNode>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]));
                    cast_variant(tri, &p, &scene, rays, groups);
                }
                Kernel::CastWideWorkgroupStack => {
                    let scene =
                        SceneRefs::new(&p, spheres, triangles, materials, WideTree::new(view::<treelet_core::WideNode>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]));
                    cast_all::<_, { treelet_core::geometry::features::ALL }, WORKGROUP_STACK_WORDS>(&p, &scene, rays, groups);
                }
                _ => panic!("{kernel:?}: no such cast kernel"),
            }
        }
        (Kernel::Render(method, v), [p, spheres, materials, nodes, prims, accum, triangles, lights]) => {
            let p: treelet_core::RenderParams = params(p);
            let lights: &[Light] = view(lights);
            let (spheres, triangles, materials) = (view(spheres), Split::whole(view(triangles)), view(materials));
            let accum: &mut [[f32; 4]] = view(accum);
            match method {
                Method::Scan => {
                    let tree = Scan::new(&[], &[]);
                    render_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, accum, groups)
                }
                Method::Classic => {
                    let tree = ClassicTree::new(view(nodes), view(prims));
                    render_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, accum, groups)
                }
                Method::Bvh2 => {
                    let tree = Bvh2Tree::new(view::<treelet_core::Bvh2Node>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]);
                    render_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, accum, groups)
                }
                Method::Bvh4 => {
                    let tree = Bvh4Tree::new(view::<treelet_core::Bvh4Node>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]);
                    render_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, accum, groups)
                }
                Method::Cwbvh => {
                    let tree = WideTree::new(view::<treelet_core::WideNode>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]);
                    render_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, accum, groups)
                }
            }
        }
        (
            Kernel::RenderInstanced | Kernel::RenderInstancedCaustics | Kernel::LightInstanced,
            [p, spheres, materials, nodes, prims, accum, triangles, lights, records, info, instance_nodes, instance_leaves, instance_triangles, instance_materials],
        ) => {
            use treelet_core::geometry::features::{ALL, INSTANCES};
            use treelet_core::{Bvh2Node, InstanceRecord, LeafPrim};
            let p: treelet_core::RenderParams = params(p);
            let lights: &[Light] = view(lights);
            let (spheres, triangles, materials) = (view(spheres), Split::whole(view(triangles)), view(materials));
            let own = Bvh2Tree::new(view::<Bvh2Node>(nodes) as &[_], view::<LeafPrim>(prims) as &[_]);
            let (instance_nodes, instance_leaves): (&[Bvh2Node], &[LeafPrim]) = (view(instance_nodes), view(instance_leaves));
            let meshes = treelet_core::geometry::prims::Prims {
                spheres: &[],
                sphere_count: 0,
                triangles: Split::whole(view(instance_triangles)),
                triangle_count: p.instance_triangles,
            };
            let tree = SceneWithInstances {
                own,
                instances: view::<InstanceRecord>(records) as &[_],
                info: view(info),
                count: p.instances,
                trees: Level { nodes: instance_nodes, leaves: instance_leaves },
                meshes,
                materials: view(instance_materials),
            };
            let scene = SceneRefs::new(&p, spheres, triangles, materials, tree);
            // As the shader's entry points: light paths' split of path space only beside them.
            const F: u32 = ALL | INSTANCES | treelet_core::geometry::features::INDEPENDENT_NUMBERS;
            const C: u32 = F | treelet_core::geometry::features::CAUSTICS;
            if kernel == Kernel::LightInstanced {
                light_with::<_, C>(&p, &scene, lights, view(accum), groups);
            } else {
                let accum: &mut [[f32; 4]] = view(accum);
                let pixels = ((p.width * p.height) as usize).min(accum.len()).min((groups * WORKGROUP_SIZE) as usize);
                let caustics = kernel == Kernel::RenderInstancedCaustics;
                accum[..pixels].par_iter_mut().enumerate().for_each(|(id, acc)| {
                    let sums = if caustics {
                        render_pixel::<_, C, 1>(id as u32, &p, &scene, lights, &mut [0u32; 1], 0)
                    } else {
                        render_pixel::<_, F, 1>(id as u32, &p, &scene, lights, &mut [0u32; 1], 0)
                    };
                    accumulate(acc, sums)
                });
            }
        }
        (Kernel::Light(method, v), [p, spheres, materials, nodes, prims, splats, triangles, lights]) => {
            let p: treelet_core::RenderParams = params(p);
            let lights: &[Light] = view(lights);
            let (spheres, triangles, materials) = (view(spheres), Split::whole(view(triangles)), view(materials));
            let splats: &mut [u32] = view(splats);
            match method {
                Method::Scan => {
                    let tree = Scan::new(&[], &[]);
                    light_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, splats, groups)
                }
                Method::Classic => panic!("no light paths through the seed's layout"),
                Method::Bvh2 => {
                    let tree = Bvh2Tree::new(view::<treelet_core::Bvh2Node>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]);
                    light_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, splats, groups)
                }
                Method::Bvh4 => {
                    let tree = Bvh4Tree::new(view::<treelet_core::Bvh4Node>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]);
                    light_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, splats, groups)
                }
                Method::Cwbvh => {
                    let tree = WideTree::new(view::<treelet_core::WideNode>(nodes) as &[_], view::<treelet_core::LeafPrim>(prims) as &[_]);
                    light_all(v, &p, &SceneRefs::new(&p, spheres, triangles, materials, tree), lights, splats, groups)
                }
            }
        }
        (kernel, b) => panic!("{kernel:?} dispatched with {} bindings", b.len()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::backend::Backend;

    #[test]
    fn a_buffer_past_the_memory_is_an_error_naming_it() {
        let mut b = CpuBackend::new();
        // 2^60 bytes: no machine holds it; the allocation must fail as an error, not abort.
        let e = b.scratch("nodes", 1 << 60).err().expect("an exabyte buffer was allocated");
        assert!(format!("{e:#}").contains("buffer `nodes`"), "{e:#}");
        let ok = b.scratch("small", 12).unwrap();
        assert_eq!(ok.borrow().len(), 2);
        let up = b.upload("data", &[1u32, 2, 3]).unwrap();
        assert_eq!(b.read::<u32>(&up, 3).unwrap(), [1, 2, 3]);
    }
}
