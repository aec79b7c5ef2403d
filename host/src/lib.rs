//! # treelet
//!
//! GPU-built bounding volume hierarchies and closest-hit queries for an
//! engine's own geometry, and the host side of Treelet's path tracer.
//!
//! ## For an engine
//!
//! Everything an engine needs is at the crate root: a [`Tracer`] builds a
//! tree over [`Sphere`]s and [`Triangle`]s on a device (a [`GpuBackend`] on
//! any Vulkan adapter, or the [`CpuBackend`], which runs the same kernels on
//! CPU cores), refits it after they move, and finds the closest hits
//! ([`RayHit`]) of batches of [`Ray`]s. [`Quality`] trades build time for
//! faster rays, or ([`Quality::ForRays`]) picks the builder that finishes a
//! given number of rays per build first, by costs measured per device class.
//! Rays and hits in an engine's own arrays (columns, say) need no slice of
//! [`Ray`]s: [`tracer::RayQueries::closest_hits_with`] asks for each ray
//! and hands back each hit, writing the rays straight into the device's
//! upload memory ([`tracer::RayQueries::closest_hits_batch`] hands the
//! whole batch's hits over at once, to be taken on every core). An [`InstancedTracer`] places meshes many times; [`scene::instanced::InstancedScene::load`]
//! reads a glTF or scene file's meshes once each, with their copies as
//! instances ([`InstancedTracer::build_scene`]).
//!
//! ```
//! use treelet::{CpuBackend, Quality, Ray, Tracer, Triangle};
//! let triangles = [Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])];
//! let b = &mut CpuBackend::new(); // or GpuBackend::new(GpuContext::new()?)
//! let mut tracer = Tracer::build(b, &[], &triangles, Quality::High)?;
//! let hits = tracer.closest_hits(b, &[Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 1.0])])?;
//! assert_eq!((hits[0].prim, hits[0].t), (0, 5.0));
//! let moved = [Triangle::new([0.0, 0.0, 7.0], [1.0, 0.0, 7.0], [0.0, 1.0, 7.0])];
//! tracer.refit(b, &[], &moved)?; // same shape, new boxes
//! let t = tracer.closest_hits(b, &[Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 1.0])])?[0].t;
//! assert!((t - 7.0).abs() < 1e-5, "{t}");
//! # anyhow::Ok(())
//! ```
//!
//! The engine API returns [`error::Error`]: its [`kind`](error::Error::kind)
//! says whether the input was at fault (a non-finite vertex, a mesh index
//! past the meshes: the message names which), the work is too large for the
//! device, or the device cannot run Treelet; its message tells the rest.
//!
//! An engine that has no use for the `treelet` command depends on the
//! crate with `default-features = false`: the feature `cli` (on by default)
//! brings in clap and the command line's parsing of the option types
//! ([`Accel`](bvh::tree::Accel), [`Layout`](bvh::layout::Layout) and the rest).
//!
//! ### On the engine's own GPU device
//!
//! An engine opens its wgpu device with the features and limits Treelet
//! needs, hands it over ([`GpuContext::from_wgpu`] names anything missing),
//! and keeps its mesh in its own buffers: the tree is built from them on
//! the device ([`tracer::MeshBuffers`], [`Tracer::build_from_buffers`]),
//! rays are traced in a buffer of its own, in place
//! ([`Tracer::closest_hits_on_device`]), and [`GpuBackend::submit`] puts
//! Treelet's recorded kernels on the shared queue before the engine's own
//! work that reads the hits. `examples/engine_frames.rs` is a whole frame
//! loop.
//!
//! ```no_run
//! use treelet::tracer::{IndexBuffer, IndexFormat, MeshBuffers};
//! use treelet::{wgpu, GpuBackend, GpuContext, Quality, Tracer};
//! # fn engine(adapter: &wgpu::Adapter, vertices: &wgpu::Buffer, indices: &wgpu::Buffer, rays: &wgpu::Buffer) -> anyhow::Result<()> {
//! let descriptor = wgpu::DeviceDescriptor {
//!     required_features: GpuContext::required_features(),
//!     required_limits: GpuContext::required_limits(adapter.limits()),
//!     // SAFETY: Treelet's kernels are SPIR-V passed through, validated by the driver.
//!     experimental_features: unsafe { wgpu::ExperimentalFeatures::enabled() },
//!     ..Default::default()
//! };
//! let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))?;
//! // ... the engine makes `vertices`, `indices` and `rays` on `device` (usage STORAGE) ...
//! let b = &mut GpuBackend::new(GpuContext::from_wgpu(adapter, device.clone(), queue.clone())?);
//! // 32-byte vertices with the position first; u32 indices.
//! let mesh = MeshBuffers::<GpuBackend> {
//!     vertices,
//!     vertex_offset: 0,
//!     vertex_stride: 32,
//!     vertex_count: 10_000,
//!     indices: Some(IndexBuffer { buffer: indices, offset: 0, format: IndexFormat::U32 }),
//!     triangle_count: 19_602,
//! };
//! let mut tracer = Tracer::build_from_buffers(b, &mesh, Quality::Fast)?;
//! // Each frame: the mesh moved in its buffers; rays written as `device_rays` lays them out.
//! tracer.refit_from_buffers(b, &mesh)?;
//! tracer.closest_hits_on_device(b, rays, 1920 * 1080)?;
//! b.submit()?;
//! // ... the engine's passes read the hits from `rays` ...
//! # Ok(()) }
//! ```
//!
//! ## The folders, bottom to top
//!
//! Each folder depends only on the ones above it in this list
//! (`tests/layering.rs` checks it):
//!
//! - [`runtime`]: where kernels run: the [`Backend`] trait, the GPU through
//!   wgpu, and the CPU runner that calls the same kernel functions over
//!   every invocation id; [`tuning`]: the developers' knobs, read once;
//!   [`internals`]: what the command uses that is not API (notes that
//!   never panic, files read within caps, plots);
//! - [`scene`]: what is built and rendered: spheres and triangles, meshes,
//!   scene files, and the checks that reject bad input;
//! - [`bvh`]: the BVH builders (LBVH, treelet restructuring, full-sweep
//!   SAH), refit, the traversal layouts, the tree a render or an engine asks
//!   for ([`bvh::tree`]), and the independent validators;
//! - [`render`]: the one render loop (one device or several, checkpoints,
//!   stops, resumes), the kernel variant a scene needs, images in and out,
//!   render parts;
//! - [`tracer`]: the engine API re-exported above.
//!
//! The `treelet` command (`cli/`: `main.rs`, `bench/`) sits on top. The kernels
//! themselves are in the `treelet-core` crate, which an engine may also use
//! directly (`no_std`): see its docs for the traversal functions.
/// Notes on standard error that never panic (see [`internals::console`]); defined
/// before the modules, so that theirs is this one.
macro_rules! eprintln {
    () => { $crate::internals::console::err(format_args!("")) };
    ($($t:tt)*) => { $crate::internals::console::err(format_args!($($t)*)) };
}

pub mod error;
pub mod internals;
pub mod bvh;
pub mod render;
pub mod runtime;
pub mod scene;
pub mod tracer;
pub mod tuning;

pub use runtime::backend::Backend;
pub use runtime::cpu_runner::CpuBackend;
pub use runtime::gpu::{GpuBackend, GpuContext};
pub use tracer::{Instance, InstancedTracer, Quality, Ray, RayHit, Tracer};
pub use treelet_core::{Sphere, Triangle};
/// The wgpu Treelet is built on: an engine that hands Treelet its device
/// ([`GpuContext::from_wgpu`]) uses this version.
pub use wgpu;

/// The README's Rust snippets, run as doc tests: what a newcomer copies
/// first compiles and passes.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
