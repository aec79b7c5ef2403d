//! # treelet
//!
//! The host side of Treelet, in the order of its pipeline; each folder
//! depends only on the ones above it:
//!
//! - [`runtime`]: where kernels run: the [`Backend`](runtime::backend::Backend)
//!   trait, the GPU through wgpu, and the CPU runner that calls the same
//!   kernel functions over every invocation id;
//! - [`scene`]: what is built and rendered: spheres and triangles, meshes,
//!   scene files, and the checks that reject bad input;
//! - [`bvh`]: the BVH builders (LBVH, treelet restructuring, full-sweep
//!   SAH), the traversal layouts and the independent validators;
//! - [`render`]: the path tracer's passes, the kernel variant a scene needs,
//!   images in and out;
//! - [`tracer`]: the engine API: a tree over your spheres and triangles on
//!   a device, refit after they move, closest hits for batches of rays;
//! - [`plot`]: charts for reports and benchmarks.
//!
//! The `treelet` command (`main.rs`, `bench/`) sits on top.
//!
//! ```no_run
//! use treelet::{bvh::lbvh, runtime::cpu_runner::CpuBackend, scene};
//! let spheres = scene::random_spheres(1000, 7);
//! let (bvh, times) = lbvh::build(&mut CpuBackend::new(), &spheres).unwrap();
//! assert_eq!(bvh.nodes.len(), 1999);
//! println!("{} ms", times.total());
//! ```
pub mod bvh;
pub mod plot;
pub mod render;
pub mod runtime;
pub mod scene;
pub mod tracer;
