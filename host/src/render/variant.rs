//! Leaving out what a scene does not need: from the scene's features, the
//! render kernel compiled without the rest (`treelet_core::geometry::features`), and
//! whether a BVH pays at all. The same choice on every backend, recorded
//! with its reasons for `treelet render --explain` and the report.
use serde::Serialize;
use treelet_core::geometry::buffers::{DIFFUSE, GLASS, MIRROR};
use treelet_core::geometry::features;
use treelet_core::render::variants::VARIANTS;

use crate::bvh::choice::{cheaper_builder, Work};
use crate::bvh::layout::Layout;
use crate::bvh::tree::{Accel, Builder};
use crate::runtime::backend::DeviceClass;
use crate::runtime::kernels::Method;
use crate::scene::Scene;

/// What a scene contains.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SceneFeatures {
    pub spheres: usize,
    /// Flat primitives: triangles, and the disks and parallelograms among
    /// them (`treelet_core::geometry::flat`).
    pub triangles: usize,
    pub disks: usize,
    pub parallelograms: usize,
    /// Primitives by material kind.
    pub diffuse: usize,
    pub mirror: usize,
    pub glass: usize,
    /// Primitives that emit light (of any kind).
    pub emissive: usize,
    /// Copies of meshes kept as instances (`Scene::instances`), and their triangles.
    pub copies: usize,
    pub copied_triangles: u64,
    /// Whether rays leaving the scene see a radiance (`Scene::environment`).
    pub environment: bool,
    /// Whether the camera has a thin lens (depth of field).
    pub lens: bool,
}

impl SceneFeatures {
    pub fn of(scene: &Scene) -> Self {
        use treelet_core::geometry::triangle::{SHAPE_DISK, SHAPE_PARALLELOGRAM};
        let count = |shape| scene.triangles.iter().filter(|t| t.shape == shape).count();
        let mut f = SceneFeatures {
            spheres: scene.spheres.len(),
            triangles: scene.triangles.len(),
            disks: count(SHAPE_DISK),
            parallelograms: count(SHAPE_PARALLELOGRAM),
            environment: scene.environment.iter().any(|&e| e > 0.0),
            lens: scene.camera.lens_radius > 0.0,
            ..Default::default()
        };
        let mut count_material = |m: &treelet_core::geometry::buffers::Material| {
            match m.kind {
                DIFFUSE => f.diffuse += 1,
                MIRROR => f.mirror += 1,
                GLASS => f.glass += 1,
                _ => {}
            }
            if m.emission.iter().any(|&e| e > 0.0) {
                f.emissive += 1;
            }
        };
        scene.materials.iter().for_each(&mut count_material);
        if let Some(copies) = &scene.instances {
            // A copy's triangles, each in its material (none emits).
            for instance in &copies.instances {
                let mesh = &copies.meshes[instance.mesh as usize];
                match &instance.material {
                    Some(m) => (0..mesh.triangles.len()).for_each(|_| count_material(m)),
                    None => mesh.materials.iter().for_each(&mut count_material),
                }
            }
            f.copies = copies.instances.len();
            f.copied_triangles = copies.triangles();
        }
        f
    }

    pub fn primitives(&self) -> usize {
        self.spheres + self.triangles
    }

    /// The scan's cost in spheres: a triangle counts [`TRIANGLE_SCAN_WEIGHT`].
    pub fn scan_cost(&self) -> usize {
        self.spheres + TRIANGLE_SCAN_WEIGHT * self.triangles
    }

    /// The kernel features (`treelet_core::geometry::features`) these need.
    pub fn bits(&self) -> u32 {
        let mut bits = 0;
        for (count, bit) in [
            (self.spheres, features::SPHERES),
            (self.triangles - self.disks - self.parallelograms, features::TRIANGLES),
            (self.mirror, features::MIRROR),
            (self.glass, features::GLASS),
            (self.disks + self.parallelograms, features::SHAPES),
            (self.environment as usize, features::ENVIRONMENT),
            (self.lens as usize, features::LENS),
        ] {
            if count > 0 {
                bits |= bit;
            }
        }
        bits
    }
}

/// Names of the optional features in `bits`, for messages.
fn optional(bits: u32) -> String {
    let names: Vec<&str> = [
        (features::SPHERES, "spheres"),
        (features::TRIANGLES, "triangles"),
        (features::MIRROR, "mirror"),
        (features::GLASS, "glass"),
        (features::SHAPES, "disks and parallelograms"),
        (features::ENVIRONMENT, "environment"),
        (features::LENS, "thin lens"),
        (features::CAUSTICS, "light paths for caustics"),
        (features::INDEPENDENT_NUMBERS, "independent numbers"),
    ]
    .iter()
    .filter(|(bit, _)| bits & bit != 0)
    .map(|&(_, name)| name)
    .collect();
    names.join(", ")
}

/// Names of everything `bits` compiles in (diffuse and emission always).
pub fn describe(bits: u32) -> String {
    match optional(bits) {
        o if o.is_empty() => "diffuse, emission".to_string(),
        o => format!("diffuse, emission, {o}"),
    }
}

/// Which render kernel to run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum KernelChoice {
    /// The smallest variant compiled for the scene's features.
    #[default]
    Auto,
    /// The general kernel (every feature compiled in), for comparison.
    Full,
}

/// The smallest compiled variant (index into `VARIANTS`) whose features
/// include `bits`; the general kernel always does.
pub fn smallest_variant(bits: u32) -> usize {
    VARIANTS
        .iter()
        .enumerate()
        .filter(|(_, (v, _))| v & bits == bits)
        .min_by_key(|(i, (v, _))| (v.count_ones(), *i))
        .map(|(i, _)| i)
        .expect("the general variant contains every feature")
}

/// Index of the general kernel in `VARIANTS`.
pub fn full_variant() -> usize {
    VARIANTS.iter().position(|(v, _)| *v == features::ALL).expect("VARIANTS has the general kernel")
}

/// Up to this many primitives a linear scan beats traversing a BVH on a
/// GPU. Measured with `treelet bench render --spp 4 --sizes
/// 0,8,16,32,64,128,256,1000 --accels none,lbvh,trbvh` (random:N: N spheres
/// in smallpt's 9-sphere room, 1024x768) on an H100: render-kernel time of
/// the scan 40.4 ms against 45.5 ms for the treelet-optimized BVH at 265
/// primitives, 158 ms against 66 ms at 1009.
pub const LINEAR_MAX_GPU: usize = 256;
/// What a triangle costs a linear scan, in spheres, against the crossovers
/// above. Measured on the H100 with terrain:N in smallpt's room (7 spheres;
/// 1024x768, 64 spp, each integrator): the scan is as fast as the
/// treelet-optimized BVH at 32 triangles (0.168 s against 0.164), half as
/// fast at 64 (0.333 against 0.166), faster at 16 (0.113 against 0.167).
/// CPU devices use the same weight (not measured there).
pub const TRIANGLE_SCAN_WEIGHT: usize = 8;
/// As [`LINEAR_MAX_GPU`] on CPU devices (lavapipe, 256x192): the scan wins
/// at 521 primitives (5.0 s against 7.5 s), loses at 1009 (11.7 s against
/// 4.5 s). The CPU runner uses it too (not measured separately).
pub const LINEAR_MAX_CPU: usize = 512;

/// Samples per pixel from which a render on a Vulkan device (a GPU or
/// lavapipe; not the CPU runner) with `--layout auto` lays its tree out
/// both ways and keeps the layout whose render kernel ran one sample of
/// every pixel faster (`super::prepared::pilots_layout`; the pilot's
/// samples are thrown away: two samples' work, under 1% of the render's). Which is faster depends on
/// the scene, not only on its size: on the H100 `cwbvh` renders
/// the disk-lit room with its lamp a fan of 64 triangles (before disks were
/// one primitive) 15% faster than `bvh2` and
/// `scenes/cornell_mesh.json` 10% faster, while `bvh2` is faster for
/// terrain in smallpt's room at every size from 256 to 1M triangles
/// (`docs/results/h100-caustics-2026-11-27`).
pub const PILOT_MIN_SPP: u32 = 256;

/// What the render will run, and why.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    pub features: SceneFeatures,
    pub accel: Accel,
    pub accel_reason: String,
    /// How the tree is laid out (meaningless for the scan).
    pub layout: Layout,
    pub layout_reason: String,
    /// Index into `VARIANTS`.
    #[serde(skip)]
    pub variant: usize,
    /// Name of the variant (entry points `render::<name>::<method>_cs`).
    pub kernel: &'static str,
    /// The scene keeps instances of meshes: the kernel is
    /// `render::render_instanced_cs` (every feature, and the copies' walk),
    /// over the scene's own primitives in `bvh2`.
    pub instanced: bool,
    pub kernel_features: String,
    pub kernel_reason: String,
}

/// Chooses the acceleration structure, its layout and the kernel variant
/// for rendering `paths` camera paths (pixels times samples) of `scene` on
/// a device of `class`. `Accel::Auto` picks the linear scan up to the
/// measured crossover, else the LBVH, the H-PLOC tree (on GPUs) or the
/// treelet-optimized BVH, whichever gives the least build plus render time
/// ([`cheaper_builder`]);
/// `Layout::Auto` the fastest measured layout.
/// `independent`: the render draws independent numbers (`--sampler
/// independent`), which only the general kernels have.
#[allow(clippy::too_many_arguments)]
pub fn plan(scene: &Scene, paths: u64, accel: Accel, layout: Layout, kernel: KernelChoice, class: DeviceClass, light_paths: bool, independent: bool) -> Plan {
    let features = SceneFeatures::of(scene);
    let (n, cost) = (features.primitives(), features.scan_cost());
    let runs_on_cpu = class != DeviceClass::Gpu;
    let (linear_max, device) = if runs_on_cpu { (LINEAR_MAX_CPU, "a CPU device") } else { (LINEAR_MAX_GPU, "a GPU") };
    let (accel, accel_reason) = match accel {
        Accel::Auto if cost <= linear_max => (
            Accel::None,
            format!(
                "{n} primitives, scan cost {cost} (a triangle counts {TRIANGLE_SCAN_WEIGHT} spheres): a linear scan is faster than a BVH up to {linear_max} on {device}"
            ),
        ),
        Accel::Auto => {
            let (builder, why) = cheaper_builder(class, n, Work::Paths(paths));
            let accel = match builder {
                Builder::Trbvh => Accel::Trbvh,
                Builder::Hploc => Accel::Hploc,
                Builder::Lbvh | Builder::Sweep | Builder::Reference => Accel::Lbvh,
            };
            (
                accel,
                format!(
                    "{n} primitives, scan cost {cost} (a triangle counts {TRIANGLE_SCAN_WEIGHT} spheres): above {linear_max} a BVH is faster on {device}; {}: {why}",
                    accel.name()
                ),
            )
        }
        other => (other, "as asked (--accel)".to_string()),
    };
    let (layout, layout_reason) = match layout {
        _ if accel == Accel::None => (Layout::Auto, "no tree".to_string()),
        Layout::Auto => {
            let chosen = Layout::Auto.resolve(class);
            let on = match class {
                DeviceClass::Gpu => "GPUs (H100)",
                DeviceClass::CpuAdapter => "CPU Vulkan adapters (lavapipe)",
                DeviceClass::CpuRunner => "the CPU runner",
            };
            let pilot = if class != DeviceClass::CpuRunner { format!("; renders of {} spp or more time both layouts first and keep the faster", PILOT_MIN_SPP) } else { String::new() };
            (chosen, format!("the layout that renders fastest on {on}, as measured (see `treelet::bvh::layout::Layout::resolve`){pilot}"))
        }
        other => (other, "as asked (--layout)".to_string()),
    };
    let method = if accel == Accel::None { crate::runtime::kernels::Method::Scan } else { layout.method() };
    // Light paths (`--integrator caustics`) where they can find caustics:
    // mirrors or glass, and lights.
    let caustics = light_paths && features.mirror + features.glass > 0 && features.emissive > 0;
    let render_bits = if caustics { features::CAUSTICS } else { 0 } | if independent { features::INDEPENDENT_NUMBERS } else { 0 };
    let bits = features.bits() | render_bits;
    let full = if render_bits != 0 { smallest_variant(features::ALL | render_bits) } else { full_variant() };
    let (variant, kernel_reason) = match kernel {
        KernelChoice::Full => (full, "as asked (--kernel full)".to_string()),
        KernelChoice::Auto if !method.specialized() => {
            (full, format!("the {} layout has the general kernel only", layout.name()))
        }
        KernelChoice::Auto => {
            let v = smallest_variant(bits);
            let left_out = features::ALL & !VARIANTS[v].0;
            let reason = if left_out == 0 {
                "no smaller variant covers the scene".to_string()
            } else {
                format!("the scene needs {}; left out: {}", describe(bits), optional(left_out))
            };
            (v, reason)
        }
    };
    let name = VARIANTS[variant].1;
    let plan = Plan {
        features,
        accel,
        accel_reason,
        layout,
        layout_reason,
        variant,
        kernel: name,
        instanced: false,
        kernel_features: describe(VARIANTS[variant].0),
        kernel_reason,
    };
    if features.copies > 0 { instanced_plan(plan) } else { plan }
}

/// [`plan`] for a scene with instances: one kernel traces them
/// (`render::render_instanced_cs`, or `render_instanced_caustics_cs` and `render::light_instanced_cs` for light
/// paths), with the scene's own primitives in a
/// `bvh2` tree (an LBVH where a scan would do: the room's few primitives
/// cost nothing to build). What was asked explicitly is kept, and refused
/// by the render if that kernel cannot run it.
fn instanced_plan(mut plan: Plan) -> Plan {
    let why = "the kernel of instances traces the scene's own primitives through a bvh2 tree";
    if plan.accel_reason.starts_with("as asked") {
    } else if plan.accel == Accel::None {
        plan.accel = Accel::Lbvh;
        plan.accel_reason = format!("{} primitives of the scene's own, besides its copies: {why}", plan.features.primitives());
    }
    if plan.layout_reason != "as asked (--layout)" {
        plan.layout = Layout::Bvh2;
        plan.layout_reason = why.to_string();
    }
    plan.instanced = true;
    // Light paths, where the plan has them, run through the copies too
    // (`render::light_instanced_cs`).
    let caustics = plan.light_paths();
    let bits = features::ALL | if caustics { features::CAUSTICS } else { 0 };
    plan.variant = if caustics { smallest_variant(bits) } else { full_variant() };
    plan.kernel = "instanced";
    plan.kernel_features = format!("{}, instances of meshes", describe(bits));
    plan.kernel_reason = format!(
        "{} instances of meshes ({} triangles), traced through their meshes' own trees",
        plan.features.copies, plan.features.copied_triangles
    );
    plan
}

impl Plan {
    /// The lines `--explain` prints, in the words the command line takes.
    pub fn explain(&self) -> String {
        let f = &self.features;
        let accel = serde_json::to_value(self.accel).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default();
        let layout = if self.accel == Accel::None { "-" } else { self.layout.name() };
        format!(
            "features   {} spheres, {} triangles{}; materials: {} diffuse, {} mirror, {} glass, {} emissive\n\
             accel      {accel}: {}\n\
             layout     {layout}: {}\n\
             kernel     {} ({}): {}",
            f.spheres,
            f.triangles - f.disks - f.parallelograms,
            [(f.disks, "disk"), (f.parallelograms, "parallelogram")]
                .iter()
                .filter(|(n, _)| *n > 0)
                .map(|(n, what)| format!(", {n} {what}{}", if *n == 1 { "" } else { "s" }))
                .chain((f.copies > 0).then(|| format!(", {} instances of meshes ({} triangles)", f.copies, f.copied_triangles)))
                .collect::<String>(),
            f.diffuse,
            f.mirror,
            f.glass,
            f.emissive,
            self.accel_reason,
            self.layout_reason,
            self.kernel,
            self.kernel_features,
            self.kernel_reason
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_feature_set_gets_a_variant_that_contains_it() {
        // Every subset of the scene's features (the render's own bits,
        // CAUSTICS and the like, lie between them and come with ALL).
        for bits in (0..=features::ALL).filter(|b| b & !features::ALL == 0) {
            let v = smallest_variant(bits);
            assert_eq!(VARIANTS[v].0 & bits, bits, "features {bits:#b} got {}", VARIANTS[v].1);
            // And no variant that contains them is smaller.
            for (other, _) in VARIANTS {
                if other & bits == bits {
                    assert!(other.count_ones() >= VARIANTS[v].0.count_ones());
                }
            }
        }
    }

    #[test]
    fn glass_never_runs_without_refraction() {
        for bits in (0..=features::ALL).filter(|b| b & !features::ALL == 0) {
            if bits & features::GLASS != 0 {
                assert!(VARIANTS[smallest_variant(bits)].0 & features::GLASS != 0);
            }
        }
    }
}

impl Plan {
    /// The closest-hit method of the render kernel.
    pub fn method(&self) -> Method {
        if self.accel == Accel::None {
            Method::Scan
        } else {
            self.layout.method()
        }
    }

    /// Whether the render kernel leaves caustics to light paths
    /// (`--integrator caustics` where the scene has mirrors or glass and
    /// lights): its variant has `features::CAUSTICS`.
    pub fn light_paths(&self) -> bool {
        VARIANTS[self.variant].0 & features::CAUSTICS != 0
    }
}
