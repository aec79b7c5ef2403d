//! One device's part of a render before its first sample: the tree built
//! and laid out, the scene and light table uploaded, the kernel chosen, and
//! the accumulation buffer of per-pixel sums that its dispatches add to.
use anyhow::{bail, Context, Result};
use treelet_core::geometry::buffers::RenderParams;
use treelet_core::gpu::workgroup::groups_for;
use treelet_core::render::integrator::tiled_invocations;
use treelet_core::render::lights::{light_power, Light};

use super::dispatch_size::DispatchSize;
use super::settings::{Integrator, MemoryEstimate, RenderSettings, Sampler};
use super::variant::{self, Plan, PILOT_MIN_SPP};
use crate::bvh::layout::{PrimBuffers, TracedTree};
use crate::bvh::lbvh;
use crate::bvh::layout::Layout;
use crate::bvh::tree::{binary_tree, traced_tree};
use crate::runtime::backend::DeviceClass;
use crate::runtime::backend::Backend;
use crate::runtime::kernels::Kernel;
use crate::runtime::memory::human;
use crate::scene::primitives::Primitives;
use crate::scene::Scene;

/// The light table of `prims` (spheres then triangles, one material each):
/// every emitter, chosen in proportion to its power
/// (`treelet_core::render::lights::light_power`), in primitive order. Empty
/// without emitters.
pub fn light_table(prims: Primitives, materials: &[treelet_core::geometry::buffers::Material]) -> Vec<Light> {
    let p = prims.as_core();
    let powers: Vec<(u32, f64)> = (0..p.count())
        .map(|i| (i, light_power(&p, materials, i) as f64))
        .filter(|&(_, w)| w > 0.0 && w.is_finite())
        .collect();
    let total: f64 = powers.iter().map(|&(_, w)| w).sum();
    let mut cumulative = 0.0;
    let mut table: Vec<Light> = powers
        .iter()
        .map(|&(prim, w)| {
            cumulative += w;
            Light { prim, pmf: (w / total) as f32, cdf: (cumulative / total) as f32, _pad: 0 }
        })
        .collect();
    if let Some(last) = table.last_mut() {
        last.cdf = 1.0; // Whatever rounding did, the last light takes the rest.
    }
    table
}

/// Everything a render needs on one device before its first sample: the
/// tree and buffers, the kernel, and an accumulation buffer of per-pixel
/// sums. A render is samples dispatched into it, in any ranges, on any
/// number of devices (see [`super::run`]).
pub struct Prepared<B: Backend> {
    tree: TracedTree<B>,
    buffers: PrimBuffers<B>,
    materials: B::Buffer,
    lights: B::Buffer,
    accum: B::Buffer,
    kernel: Kernel,
    /// With `--integrator caustics` on a scene with mirrors or glass and
    /// lights: the light paths' kernel and the buffer they land in (its
    /// sums are added to `accum`'s when read).
    light_paths: Option<(Kernel, B::Buffer)>,
    /// The scene's instances of meshes, if it has any (the kernel
    /// is then [`Kernel::RenderInstanced`]).
    instances: Option<super::instances::InstancesPart<B>>,
    /// Render parameters but for the samples of a dispatch.
    params: RenderParams,
    pixels: u64,
    pub build_ms: f64,
    pub plan: Plan,
}

/// The kernels a render of `plan` dispatches on `b`: its tree's and its
/// render kernel, for building their pipelines before the timed work
/// ([`Backend::prepare_kernels`]).
pub fn kernels<B: Backend>(b: &B, plan: &Plan) -> Vec<Kernel> {
    let mut k = crate::bvh::tree::kernels_of(b, plan.accel, plan.layout);
    k.push(render_kernel(plan));
    k
}

/// The render kernel of `plan`.
fn render_kernel(plan: &Plan) -> Kernel {
    match (plan.instanced, plan.light_paths()) {
        (true, true) => Kernel::RenderInstancedCaustics,
        (true, false) => Kernel::RenderInstanced,
        _ => Kernel::Render(plan.method(), plan.variant as u8),
    }
}

/// The light paths' kernel of a render following `plan`, if it traces any:
/// caustics asked for, and mirrors or glass, and lights (see
/// [`variant::plan`], which then picks a variant with
/// `treelet_core::geometry::features::CAUSTICS`).
fn light_kernel(plan: &Plan, lights: bool) -> Option<Kernel> {
    let kernel = if plan.instanced { Kernel::LightInstanced } else { Kernel::Light(plan.method(), plan.variant as u8) };
    (plan.light_paths() && lights).then_some(kernel)
}

/// Builds the pipelines of a render of `scene` with `settings` on `b`
/// before its timed work: a fresh machine's driver compiles each for
/// seconds, so all at once ([`Backend::prepare_kernels`]).
pub fn prepare_pipelines<B: Backend>(b: &mut B, scene: &Scene, settings: &RenderSettings) {
    let plan = variant::plan(scene, settings.paths(), settings.accel, settings.layout, settings.kernel, b.class(), settings.integrator == Integrator::Caustics, settings.sampler == Sampler::Independent);
    let mut kernels = kernels(b, &plan);
    let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
    let lights = scene.materials.len() == all.len() && !light_table(all, &scene.materials).is_empty();
    kernels.extend(light_kernel(&plan, lights));
    if pilots_layout(settings, &plan, b.class()) {
        for layout in PILOT_LAYOUTS {
            let other = Plan { layout, ..plan.clone() };
            kernels.extend(self::kernels(b, &other));
        }
    }
    b.prepare_kernels(&kernels);
}

/// The layouts a pilot times (see [`pilots_layout`]). Not `bvh4`: its
/// render kernels ran 7-9% slower than `bvh2`'s on the H200 (terrain and
/// the city in smallpt's room), and a pilot that timed it never kept it
/// (`docs/results/h200-bvh4-2026-12-01/`).
const PILOT_LAYOUTS: [Layout; 2] = [Layout::Bvh2, Layout::Cwbvh];


/// Whether a render with `settings` following `plan` on a device of
/// `class` times both layouts it pilots (`bvh2`, `cwbvh`) before it starts (see [`PILOT_MIN_SPP`]).
pub fn pilots_layout(settings: &RenderSettings, plan: &Plan, class: DeviceClass) -> bool {
    settings.layout == Layout::Auto
        && !plan.instanced
        && class != DeviceClass::CpuRunner
        && plan.accel != crate::bvh::tree::Accel::None
        && plan.method().specialized()
        && settings.spp >= PILOT_MIN_SPP
}

impl<B: Backend> Prepared<B> {
    /// Checks the settings and the scene, builds the tree on `b` and uploads
    /// the scene. `base`: per-pixel sums the accumulation starts from (a
    /// resumed render's part), else zeros.
    pub fn new(b: &mut B, scene: &Scene, settings: &RenderSettings, base: Option<&[[f32; 4]]>) -> Result<Self> {
        let RenderSettings { width, height, spp, seed, accel, layout, kernel, integrator, sampler, first_sample, .. } =
            *settings;
        if width == 0 || height == 0 || spp == 0 {
            bail!("image size {width}x{height} at {spp} samples per pixel: all three must be positive");
        }
        let pixels = width as u64 * height as u64;
        if pixels > u32::MAX as u64 / 2 {
            bail!("image size {width}x{height} is too large ({pixels} pixels)");
        }
        if first_sample.checked_add(spp).is_none() {
            bail!("samples {first_sample}.. plus {spp}: the sample index must stay below 2^32");
        }
        // Everything the render traces: spheres (the room included), then triangles.
        let all = Primitives { spheres: &scene.spheres, triangles: &scene.triangles };
        all.check()?;
        if scene.materials.len() != all.len() {
            bail!("{}: {} materials for {} primitives", scene.name, scene.materials.len(), all.len());
        }
        if let Some(memory) = b.device_memory_bytes() {
            let needed = MemoryEstimate::device_bytes(settings, scene.traced_primitives());
            if needed > memory {
                bail!(
                    "this render needs about {} of device memory ({width}x{height} image and trees of {} primitives), and `{}` has {}",
                    human(needed),
                    scene.traced_primitives(),
                    b.adapter(),
                    human(memory)
                );
            }
        }
        if let Some(sums) = base.filter(|sums| sums.len() as u64 != pixels) {
            bail!("the sums to resume from are of {} pixels, the image has {pixels}", sums.len());
        }
        let mut plan = variant::plan(scene, settings.paths(), accel, layout, kernel, b.class(), integrator == Integrator::Caustics, sampler == Sampler::Independent);
        let materials = b.upload("materials", &scene.materials)?;
        let table = light_table(all, &scene.materials);
        let lights = lbvh::upload_or_placeholder(b, "lights", &table)?;
        let params = RenderParams {
            width,
            height,
            seed,
            prims: scene.spheres.len() as u32,
            triangles: scene.triangles.len() as u32,
            camera: scene.camera.camera(width, height),
            environment: scene.environment,
            integrator: integrator.code(),
            light_count: table.len() as u32,
            sampler: sampler.code(),
            ..Default::default()
        };
        let (tree, buffers, mut build_ms) = if pilots_layout(settings, &plan, b.class()) {
            let scene_buffers = (&materials, &lights, &params);
            faster_layout(b, all, &mut plan, scene_buffers, pixels)?
        } else if plan.instanced && all.is_empty() {
            // No primitives of its own: placeholders the kernel never reads.
            traced_tree(b, all, crate::bvh::tree::Accel::None, plan.layout)?
        } else {
            traced_tree(b, all, plan.accel, plan.layout)?
        };
        let instances = match &scene.instances {
            Some(copies) => {
                if plan.layout != Layout::Bvh2 || (plan.accel == crate::bvh::tree::Accel::None && !all.is_empty()) {
                    bail!(
                        "{}: the scene keeps instances of meshes, and their kernel traces the scene's own primitives through a bvh2 tree (not --accel none, nor --layout {})",
                        scene.name,
                        plan.layout.name()
                    );
                }
                let quality = super::instances::mesh_quality(accel, settings.paths());
                let part = super::instances::InstancesPart::build(b, copies, all.len() as u32, quality)?;
                build_ms += part.build_ms;
                Some(part)
            }
            None => None,
        };
        // After the pilot, whose scratch sums (as large) are released by then.
        let accum = match base {
            Some(sums) => b.upload("accumulation", sums)?,
            None => b.zeroed("accumulation", pixels * 16)?,
        };
        if integrator == Integrator::Caustics && scene.camera.lens_radius > 0.0 {
            bail!("--integrator caustics links light paths to a pinhole camera; {}'s camera has a lens (lens_radius {}): use --integrator nee", scene.name, scene.camera.lens_radius);
        }
        if integrator == Integrator::Caustics && plan.method() == crate::runtime::kernels::Method::Classic {
            bail!("--integrator caustics traces light paths through the scan and the bvh2 and cwbvh layouts, not the seed's classic layout");
        }
        let light_paths = match light_kernel(&plan, !table.is_empty()) {
            Some(k) => Some((k, b.zeroed("light path landings", pixels * 16)?)),
            None => None,
        };
        Ok(Prepared {
            tree,
            buffers,
            materials,
            lights,
            accum,
            kernel: render_kernel(&plan),
            light_paths,
            params: instances.as_ref().map_or(params, |p| p.params(params)),
            instances,
            pixels,
            build_ms,
            plan,
        })
    }

    /// Dispatches samples `first .. first + count` of every pixel, adding
    /// to the accumulation (recorded, not waited for), in dispatches of at
    /// most `size`'s samples; gives the samples of the largest.
    pub fn dispatch_samples(&self, b: &mut B, first: u32, count: u32, size: &DispatchSize) -> Result<u32> {
        b.stage("render");
        let mut done = 0;
        let mut largest = 0;
        for samples in size.cuts(count) {
            largest = largest.max(samples);
            let params = RenderParams { samples, first_sample: first + done, ..self.params };
            let scene = (&self.materials, &self.lights, &params);
            if let Some(instances) = &self.instances {
                dispatch_instanced(b, self.kernel, &self.tree, &self.buffers, scene, instances, &self.accum)?;
                if let Some((kernel, landings)) = &self.light_paths {
                    dispatch_instanced(b, *kernel, &self.tree, &self.buffers, scene, instances, landings)?;
                }
                done += samples;
                continue;
            }
            dispatch_render(b, self.kernel, &self.tree, &self.buffers, scene, &self.accum)?;
            if let Some((kernel, landings)) = &self.light_paths {
                dispatch_render(b, *kernel, &self.tree, &self.buffers, scene, landings)?;
            }
            done += samples;
        }
        Ok(largest)
    }

    /// The layout this render traces (`auto` resolved, by a pilot or not).
    pub fn layout(&self) -> Layout {
        self.plan.layout
    }

    /// The per-pixel sums so far (waits for the dispatches).
    pub fn read_sums(&self, b: &mut B) -> Result<Vec<[f32; 4]>> {
        let mut sums: Vec<[f32; 4]> = b.read(&self.accum, self.pixels as usize)?;
        if let Some((_, landings)) = &self.light_paths {
            // The light paths' landings: colour only (the squared
            // luminance, for the noise estimate, is the camera paths').
            let landed: Vec<[f32; 4]> = b.read(landings, self.pixels as usize)?;
            for (s, l) in sums.iter_mut().zip(&landed) {
                for k in 0..3 {
                    s[k] += l[k];
                }
            }
        }
        Ok(sums)
    }
}

/// One dispatch of render kernel `kernel` with `params`' samples of every
/// pixel through `tree`, adding to `accum`.
fn dispatch_render<B: Backend>(
    b: &mut B,
    kernel: Kernel,
    tree: &TracedTree<B>,
    buffers: &PrimBuffers<B>,
    (materials, lights, params): (&B::Buffer, &B::Buffer, &RenderParams),
    accum: &B::Buffer,
) -> Result<()> {
    let p = b.upload("render params", &[*params])?;
    b.dispatch(
        kernel,
        &[&p, &buffers.spheres, materials, &tree.nodes, &tree.prims, accum, &buffers.triangles, lights],
        groups_for(tiled_invocations(params.width, params.height), kernel.workgroup_size()),
    );
    Ok(())
}

/// [`dispatch_render`] of [`Kernel::RenderInstanced`] (or its caustics
/// kernels): the scene's own bindings, then the copies'.
fn dispatch_instanced<B: Backend>(
    b: &mut B,
    kernel: Kernel,
    tree: &TracedTree<B>,
    buffers: &PrimBuffers<B>,
    (materials, lights, params): (&B::Buffer, &B::Buffer, &RenderParams),
    instances: &super::instances::InstancesPart<B>,
    accum: &B::Buffer,
) -> Result<()> {
    let p = b.upload("render params", &[*params])?;
    let [records, info, nodes, leaves, triangles, instance_materials] = instances.bindings();
    b.dispatch(
        kernel,
        &[
            &p,
            &buffers.spheres,
            materials,
            &tree.nodes,
            &tree.prims,
            accum,
            &buffers.triangles,
            lights,
            records,
            info,
            nodes,
            leaves,
            triangles,
            instance_materials,
        ],
        groups_for(tiled_invocations(params.width, params.height), kernel.workgroup_size()),
    );
    Ok(())
}

/// Builds `plan`'s tree once, lays it out in each of [`PILOT_LAYOUTS`],
/// renders one sample of every pixel through each into a scratch buffer
/// (GPU timestamps), and keeps the faster, saying so in `plan`.
fn faster_layout<B: Backend>(
    b: &mut B,
    all: Primitives,
    plan: &mut Plan,
    (materials, lights, params): (&B::Buffer, &B::Buffer, &RenderParams),
    pixels: u64,
) -> Result<(TracedTree<B>, PrimBuffers<B>, f64)> {
    let builder = plan.accel.builder()?.context("a layout pilot needs a tree")?;
    let built = binary_tree(b, all, builder)?;
    let buffers = built.prim_buffers(b, all)?;
    let scratch = b.zeroed("layout pilot accumulation", pixels * 16)?;
    let pilot = RenderParams { samples: 1, first_sample: 0, ..*params };
    let mut best: Option<(f64, f64, TracedTree<B>, Layout)> = None;
    let mut measured = Vec::new();
    for layout in PILOT_LAYOUTS {
        let (tree, layout_ms) = built.lay_out(b, layout, &buffers)?;
        b.take_times()?;
        b.stage("layout pilot");
        let kernel = Kernel::Render(layout.method(), plan.variant as u8);
        dispatch_render(b, kernel, &tree, &buffers, (materials, lights, &pilot), &scratch)?;
        let ms = b.take_times()?.get("layout pilot");
        measured.push(format!("{} {ms:.2} ms", layout.name()));
        if best.as_ref().is_none_or(|(fastest, ..)| ms < *fastest) {
            best = Some((ms, layout_ms, tree, layout));
        }
    }
    b.release(&[&scratch]);
    let (_, layout_ms, tree, layout) = best.context("the pilot timed no layout")?;
    plan.layout = layout;
    plan.layout_reason = format!(
        "the faster of one sample per pixel through each layout, timed before the render ({}; at {PILOT_MIN_SPP} spp or more, see `treelet::render::variant::PILOT_MIN_SPP`)",
        measured.join(", ")
    );
    Ok((tree, buffers, built.build_ms + layout_ms))
}
