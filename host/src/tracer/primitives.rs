//! A tree over one set of an engine's primitives: build, refit, trace.
use anyhow::Result;
use treelet_core::geometry::buffers::{RenderParams, Sphere};
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::groups_for;
use treelet_core::render::integrator::tiled_invocations;
use treelet_core::render::rays::{CAST_OCCLUDED, CAST_RAYS};

use super::engine_mesh::{gather, MeshBuffers};
use super::queries::{collect_hits, collect_occluded, ray_queries};
use super::rays::{batch_dims, Ray, RayHit};
use crate::bvh::choice::{cheaper_builder, Work};
use crate::bvh::layout::{Layout, PrimBuffers, TracedTree};
use crate::bvh::refit::{refit_bvh2, refit_uploaded};
use crate::bvh::tree::{binary_tree, binary_tree_uploaded, split_budget, Builder, BuiltTree};
use crate::runtime::backend::{Backend, DeviceClass};
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{Kernel, Method};

kernel_set! {
    /// The kernels casting an engine's rays through a tracer's `bvh2` tree.
    pub struct CastKernels for b {
        /// Every kind of primitive.
        any: Kernel::Cast(Method::Bvh2, false),
        /// Triangles alone (no spheres: a mesh).
        triangles: Kernel::Cast(Method::Bvh2, true),
    }
}

/// The kernels a tracer with trees of `builder` dispatches on `b`: its
/// build, the `bvh2` layout, refits and gathers from an engine's buffers,
/// and casts. A build prepares them all at once, so that a GPU's driver
/// compiles them side by side rather than one at a time as first used.
pub(crate) fn kernels<B: Backend>(b: &B, builder: Builder) -> Vec<Kernel> {
    let mut k = crate::bvh::tree::build_kernels(b, builder, split_budget(builder), &crate::bvh::trbvh::TreeletConfig::default());
    k.extend(crate::bvh::layout::kernels(b, Layout::Bvh2));
    k.extend(crate::bvh::refit::RefitBvh2Kernels::of(b).all());
    k.extend(super::engine_mesh::GatherKernels::of(b).all());
    k.extend(CastKernels::of(b).all());
    k
}
use crate::scene::primitives::Primitives;

/// How much build time to spend for faster rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// The LBVH (Karras 2012): the fastest build.
    Fast,
    /// The LBVH after treelet restructuring (Karras & Aila 2013): about ten
    /// times the build time, faster rays.
    High,
    /// H-PLOC (Benthin et al. 2024, `treelet_core::construct::hploc`):
    /// about three times the LBVH's build, rays close to `High`'s (H100,
    /// 940k-triangle bunny: 1.85 ms against 0.58 and 9.05 ms; 1.02 G
    /// diffuse rays/s as `High`). Needs subgroups of 4 lanes or more.
    Balanced,
    /// Whichever of the two gives the least build plus trace time when each
    /// build serves this many rays, by the trade-off measured on the
    /// device's class ([`crate::bvh::choice`]). An engine that builds every
    /// frame passes one frame's rays; one that builds once, all the rays it
    /// will trace. On the H100 the LBVH wins below about 8M rays a build
    /// for any mesh, and below about 50M for a mesh of 1M triangles.
    ForRays(u64),
}

impl Quality {
    /// The builder this quality stands for on a device of `class`, for
    /// `prims` primitives.
    pub fn builder(self, class: DeviceClass, prims: usize) -> Builder {
        match self {
            Quality::Fast => Builder::Lbvh,
            Quality::High => Builder::Trbvh,
            Quality::Balanced => Builder::Hploc,
            Quality::ForRays(rays) => cheaper_builder(class, prims, Work::Rays(rays)).0,
        }
    }
}

/// A tree over an engine's primitives on one device, laid out for tracing.
pub struct Tracer<B: Backend> {
    built: Option<BuiltTree<B>>,
    /// The primitives, the tree in the `bvh2` layout and the counts (spheres,
    /// triangles): what an instanced scene gathers of each mesh.
    pub(super) prims: PrimBuffers<B>,
    pub(super) tree: Option<TracedTree<B>>,
    pub(super) counts: (usize, usize),
    /// Device time of the last build or refit, layout included (ms).
    update_ms: f64,
    /// The `bvh2` refit's state (arrival counters, layout node indices, the
    /// leaf each primitive slot starts), kept from one refit to the next
    /// ([`refit_bvh2`]).
    refit_state: Option<B::Buffer>,
    /// The primitives of the update before the last, kept after a refit
    /// from an engine's buffers: the next such refit gathers into them and
    /// swaps, so that a mesh refit every frame takes no new memory (403 MB
    /// a frame at 8.4M triangles) and a failed gather leaves the tree's
    /// own primitives as they were.
    spare: Option<PrimBuffers<B>>,
}

impl<B: Backend> Tracer<B> {
    /// Builds the tree over `spheres` and `triangles` on `b` and lays it out
    /// for tracing. Rejects non-finite or degenerate input, naming it.
    pub fn build(b: &mut B, spheres: &[Sphere], triangles: &[Triangle], quality: Quality) -> crate::error::Result<Self> {
        crate::error::typed(|| {
            let all = Primitives { spheres, triangles };
            all.check()?;
            let builder = quality.builder(b.class(), all.len());
            b.prepare_kernels(&kernels(b, builder));
            let built = if all.len() == 0 { None } else { Some(binary_tree(b, all, builder)?) };
            let prims = match &built {
                Some(t) => t.prim_buffers(b, all)?,
                None => PrimBuffers::upload(b, all)?,
            };
            let mut tracer = Tracer {
                built,
                prims,
                tree: None,
                counts: (spheres.len(), triangles.len()),
                update_ms: 0.0,
                refit_state: None,
                spare: None,
            };
            let build_ms = tracer.built.as_ref().map_or(0.0, |t| t.build_ms);
            tracer.update_ms = build_ms + tracer.lay_out(b)?;
            tracer.keep_buffers(b);
            Ok(tracer)
        })
    }

    /// Builds the tree over an engine's mesh in its own buffers on `b`'s
    /// device ([`MeshBuffers`]: a vertex buffer, an optional index buffer),
    /// gathered into Treelet's triangles on the device: nothing goes
    /// through the host but the two-word check of what the buffers hold
    /// (indices past the vertices, coordinates that are not finite: an
    /// error names the first such triangle). Triangle `t` of the mesh is
    /// primitive `t` of the hits. Its kernels are submitted and waited for
    /// on `b`'s queue (the engine's, for a [`GpuContext::from_wgpu`](crate::runtime::gpu::GpuContext::from_wgpu)
    /// context): work the engine recorded into its own encoders is not
    /// seen unless submitted before.
    pub fn build_from_buffers(b: &mut B, mesh: &MeshBuffers<B>, quality: Quality) -> crate::error::Result<Self> {
        crate::error::typed(|| {
            let n = mesh.triangle_count as usize;
            let builder = match quality.builder(b.class(), n) {
                // The CPU builders take host primitives: the device's best instead.
                Builder::Sweep | Builder::Reference => Builder::Trbvh,
                builder => builder,
            };
            b.prepare_kernels(&kernels(b, builder));
            b.begin_build();
            let prims = gather(b, mesh, None)?;
            let n = prims.triangle_count as usize;
            let built = if n == 0 { None } else { Some(binary_tree_uploaded(b, &prims, builder, split_budget(builder))?) };
            let mut tracer = Tracer { built, prims, tree: None, counts: (0, n), update_ms: 0.0, refit_state: None, spare: None };
            let build_ms = tracer.built.as_ref().map_or(0.0, |t| t.build_ms);
            tracer.update_ms = build_ms + tracer.lay_out(b)?;
            tracer.keep_buffers(b);
            Ok(tracer)
        })
    }

    /// [`Tracer::refit`] from an engine's buffers: the mesh of
    /// [`Tracer::build_from_buffers`] moved (the same triangle count and
    /// vertex indices), gathered again on the device and the tree refit
    /// there.
    pub fn refit_from_buffers(&mut self, b: &mut B, mesh: &MeshBuffers<B>) -> crate::error::Result<()> {
        crate::error::typed(|| {
            if (0, mesh.triangle_count as usize) != self.counts {
                return Err(crate::error::input(format!("refit with {} triangles: the tree was built over {} spheres and {} triangles (build a new one)",
                    mesh.triangle_count,
                    self.counts.0,
                    self.counts.1)));
            }
            b.begin_build();
            // The device time of work queued before (the engine's last
            // trace) is not the refit's.
            b.take_times()?;
            let prims = gather(b, mesh, self.spare.as_ref())?;
            let last = std::mem::replace(&mut self.prims, prims.clone());
            self.spare = Some(last);
            self.refit_with(b, prims)
        })
    }

    /// Moves the primitives: the same counts, in the same order, at new
    /// places. The tree keeps its shape and gets new boxes bottom-up, written
    /// into its layout in place (its leaves' primitives too: see
    /// [`crate::bvh::refit::refit_bvh2`]). A refit tree stays
    /// correct however far things move, but its rays slow down as it drifts
    /// from what a new build would make: rebuild after large changes.
    pub fn refit(&mut self, b: &mut B, spheres: &[Sphere], triangles: &[Triangle]) -> crate::error::Result<()> {
        crate::error::typed(|| {
            if (spheres.len(), triangles.len()) != self.counts {
                return Err(crate::error::input(format!("refit with {} spheres and {} triangles: the tree was built over {} and {} (build a new one)",
                    spheres.len(),
                    triangles.len(),
                    self.counts.0,
                    self.counts.1)));
            }
            let all = Primitives { spheres, triangles };
            all.check()?;
            // The last update's temporaries go back to the pool (what this and
            // other tracers hold was kept out of it), so that a tracer refit
            // every frame does not make the pool grow.
            b.begin_build();
            b.take_times()?; // not the refit's (see refit_from_buffers)
            // Uploaded once, for the refit and for tracing.
            let prims = PrimBuffers::upload(b, all)?;
            self.refit_with(b, prims)
        })
    }

    /// The refit of the tree over `prims` (on the device, the same counts).
    fn refit_with(&mut self, b: &mut B, prims: PrimBuffers<B>) -> Result<()> {
        self.prims = prims;
        self.update_ms = match (&self.tree, &self.built) {
            // The layout's boxes and primitives rewritten in place.
            (Some(tree), _) if tree.collapsed.is_some() => refit_bvh2(b, tree, &self.prims, &mut self.refit_state)?.total(),
            (_, Some(built)) => refit_uploaded(b, &built.bvh, &self.prims)?.total() + self.lay_out(b)?,
            _ => 0.0,
        };
        self.keep_buffers(b);
        Ok(())
    }

    /// Takes this tracer's buffers out of `b`'s pool, so that no later build
    /// or refit on `b`, of this tracer or another, hands them out again.
    fn keep_buffers(&self, b: &mut B) {
        let mut kept = vec![&self.prims.spheres, &self.prims.triangles];
        if let Some(built) = &self.built {
            let bvh = &built.bvh;
            kept.extend([&bvh.nodes, &bvh.parents, &bvh.prim_indices, &bvh.sorted_keys]);
        }
        kept.extend(&self.refit_state);
        if let Some(spare) = &self.spare {
            kept.extend([&spare.spheres, &spare.triangles]);
        }
        if let Some(tree) = &self.tree {
            kept.extend([&tree.nodes, &tree.prims]);
            if let Some(c) = &tree.collapsed {
                kept.extend([&c.nodes, &c.parents, &c.prim_indices]);
            }
        }
        b.keep(&kept);
    }

    /// The box of the tree's primitives, read from its layout's root (one
    /// node, 64 bytes): what an instanced scene needs of a mesh that is in
    /// an engine's buffers. An empty box for a tracer without primitives.
    pub(super) fn layout_bounds(&self, b: &mut B) -> Result<[[f64; 3]; 2]> {
        let mut bounds = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
        let Some(tree) = &self.tree else { return Ok(bounds) };
        let root: treelet_core::Bvh2Node = b.read(&tree.nodes, 1)?[0];
        // A one-leaf tree's second child is an empty (inverted) box.
        let children = [(root.left_min, root.left_max), (root.right_min, root.right_max)];
        for (lo, hi) in children.into_iter().filter(|(lo, hi)| lo[0] <= hi[0]) {
            for k in 0..3 {
                bounds[0][k] = bounds[0][k].min(lo[k] as f64);
                bounds[1][k] = bounds[1][k].max(hi[k] as f64);
            }
        }
        Ok(bounds)
    }

    /// Device time of the last [`Tracer::build`] or [`Tracer::refit`], in
    /// ms: the tree's build or refit and its layout for tracing (GPU
    /// timestamps where the device has them; wall clock on the CPU runner).
    /// Uploads and the host's work are not in it.
    pub fn last_update_ms(&self) -> f64 {
        self.update_ms
    }

    /// The two-box binary layout: the fastest to trace in our measurements.
    /// Returns its device time (ms).
    fn lay_out(&mut self, b: &mut B) -> Result<f64> {
        let (tree, ms) = match &self.built {
            Some(built) => {
                let (tree, ms) = built.lay_out(b, Layout::Bvh2, &self.prims)?;
                (Some(tree), ms)
            }
            None => (None, 0.0),
        };
        self.tree = tree;
        // The refit's state names nodes of the tree it was made for.
        self.refit_state = None;
        Ok(ms)
    }

    /// The closest hit of each ray, with its hit record (see [`RayHit`]).
    /// Rays in another form than a slice: [`RayQueries::closest_hits_with`](crate::tracer::RayQueries::closest_hits_with).
    pub fn closest_hits(&self, b: &mut B, rays: &[Ray]) -> crate::error::Result<Vec<RayHit>> {
        collect_hits(self, b, rays)
    }

    /// Whether each ray hits anything up to its `t_max` (inclusive): an
    /// occlusion query, which stops at the first hit it finds (shadow and
    /// ambient-occlusion rays). Agrees with [`Tracer::closest_hits`]: a ray
    /// is occluded exactly when its closest hit is within `t_max`.
    pub fn occluded(&self, b: &mut B, rays: &[Ray]) -> crate::error::Result<Vec<bool>> {
        collect_occluded(self, b, rays)
    }

    /// Whether the tracer has no primitives (every ray misses).
    pub fn is_empty(&self) -> bool {
        self.tree.is_none()
    }

    /// Traces `count` rays that are already on the device (for callers that
    /// hold their rays in a GPU buffer, e.g. a `wgpu::Buffer` through
    /// [`GpuBackend`](crate::runtime::gpu::GpuBackend)), in place: ray `k` is
    /// `rays[2k]` = (origin, t_max) and `rays[2k + 1]` = (direction, 1), as
    /// four f32 each, and `rays[2k]` becomes (t, bits of the primitive, b1,
    /// b2): a triangle's barycentric coordinates of the hit as in [`RayHit`]
    /// (0 for a sphere), and `rays[2k + 1]` (the unit geometric normal, 0:
    /// the bits of instance 0); for a miss (inf, bits of `u32::MAX`, 0, 0)
    /// and (0, 0, 0, bits of `u32::MAX`). The buffer holds [`batch_slots`](crate::tracer::batch_slots)`(count)` such pairs; pairs past
    /// `count` must be zero. Recorded, not submitted: on a GPU, submitted at
    /// the backend's next flush ([`GpuBackend::submit`](crate::runtime::gpu::GpuBackend::submit), a read).
    pub fn closest_hits_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> crate::error::Result<()> {
        crate::error::typed(|| self.cast_on_device(b, rays, count, CAST_RAYS))
    }

    /// [`Tracer::occluded`] on rays already on the device, laid out as for
    /// [`Tracer::closest_hits_on_device`]: `rays[2k]` becomes (1 if
    /// occluded else 0, 0, 0, 0). Recorded, as [`Tracer::closest_hits_on_device`].
    pub fn occluded_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> crate::error::Result<()> {
        crate::error::typed(|| self.cast_on_device(b, rays, count, CAST_OCCLUDED))
    }

    fn cast_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize, cast_mode: u32) -> Result<()> {
        let (width, height) = batch_dims(count)?;
        let params = RenderParams {
            width,
            height,
            prims: self.prims.sphere_count,
            triangles: self.prims.triangle_count,
            cast_mode,
            ..Default::default()
        };
        let p = b.upload("trace params", &[params])?;
        let materials = b.upload("no materials", &[treelet_core::geometry::buffers::Material::default()])?;
        let Some(tree) = &self.tree else {
            return Err(crate::error::input(format!("this tracer has no primitives: there is nothing on the device to trace against (closest_hits answers misses)")));
        };
        let k = CastKernels::of(b);
        let kernel = if self.counts.0 == 0 { k.triangles } else { k.any };
        b.stage("trace");
        b.dispatch(
            kernel,
            &[&p, &self.prims.spheres, &materials, &tree.nodes, &tree.prims, rays, &self.prims.triangles],
            groups_for(tiled_invocations(width, height), kernel.workgroup_size()),
        );
        Ok(())
    }
}

ray_queries!(Tracer);
