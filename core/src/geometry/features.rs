//! What a scene uses, as bits of a `u32`: render kernels are compiled per
//! set of features (a const generic, monomorphized in the shader crate), so
//! a kernel for a scene without glass has no refraction code, one for
//! spheres only no triangle test, and so on. Code that is present costs
//! registers and occupancy on a GPU even when never taken.
//!
//! Diffuse surfaces and emission are always compiled: every scene has them
//! (the light, the walls). A kernel may only be run on a scene whose
//! features it contains: the host chooses (see `treelet::render::variant`).

/// The scene has spheres.
pub const SPHERES: u32 = 1;
/// The scene has triangles.
pub const TRIANGLES: u32 = 2;
/// The scene has mirror materials.
pub const MIRROR: u32 = 4;
/// The scene has glass (refraction).
pub const GLASS: u32 = 8;
/// The scene has disks or parallelograms (flat primitives stored as
/// triangles are, see [`crate::geometry::flat`]): without it a kernel tests
/// every flat primitive as a triangle, without [`TRIANGLES`] as a disk or
/// parallelogram.
pub const SHAPES: u32 = 16;
/// The scene has an environment: rays that leave it see a constant
/// radiance (`RenderParams::environment`) instead of black. Without it a
/// kernel has no code for that.
pub const ENVIRONMENT: u32 = 256;
/// The camera has a thin lens (`Camera::lens_radius` above 0): depth of
/// field. Without it a kernel's camera rays are a pinhole's, with no lens
/// code (on the H200 that code, in the loop that starts paths, cost the
/// specialized kernels 2-4%).
pub const LENS: u32 = 512;
/// Everything a scene can have: the general kernel.
pub const ALL: u32 = SPHERES | TRIANGLES | MIRROR | GLASS | SHAPES | ENVIRONMENT | LENS;
/// Not of the scene but of the render: camera paths that leave caustics to
/// light paths (`--integrator caustics`, [`crate::render::caustics`]), and
/// the light paths' kernel. Outside [`ALL`], so that the kernels of every
/// other render have none of that code (it cost cornell's NEE kernel 2%).
pub const CAUSTICS: u32 = 32;
/// Not of the primitives but of how they are held: instances of meshes
/// beyond the scene's own primitives ([`crate::trace::with_instances`]), traced
/// through the instanced walk. Outside [`ALL`]: only the kernel of scenes
/// with copies has that walk.
pub const INSTANCES: u32 = 64;
/// Not of the scene but of the render: `--sampler independent`'s numbers
/// ([`crate::render::sampler`]). Outside [`ALL`]: the other kernels draw
/// Sobol points only (carrying both behind a branch cost the H100's render
/// kernels 6 to 12% whichever ran, `docs/results/h100-sampler-2026-11-28`).
pub const INDEPENDENT_NUMBERS: u32 = 128;

/// Whether `features` includes `feature`.
#[inline]
pub const fn has(features: u32, feature: u32) -> bool {
    features & feature != 0
}
