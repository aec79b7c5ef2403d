//! Closest hits and occlusion queries for an engine's own geometry: build a
//! tree over its spheres and triangles on a device (the GPU, or the CPU
//! runner with the same kernels), refit the tree after they move, and trace
//! batches of rays, from host slices or from a buffer that stays on the
//! device.
//!
//! ```
//! use treelet::{CpuBackend, Quality, Ray, Tracer, Triangle};
//! let triangles = [Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])];
//! let b = &mut CpuBackend::new();
//! let tracer = Tracer::build(b, &[], &triangles, Quality::Fast)?;
//! let hits = tracer.closest_hits(b, &[Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 1.0])])?;
//! assert_eq!((hits[0].prim, hits[0].t), (0, 5.0));
//! // Shadow rays: is anything hit up to `t_max`?
//! let shadow = [Ray { t_max: 4.0, ..Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 1.0]) }, Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 1.0])];
//! assert_eq!(tracer.occluded(b, &shadow)?, vec![false, true]);
//! # anyhow::Ok(())
//! ```
//!
//! Meshes placed many times with transforms (instancing, a top-level tree
//! over bottom-level trees): [`InstancedTracer`]. An engine's mesh in its
//! own vertex and index buffers: [`Tracer::build_from_buffers`]. Files:
//! `primitives.rs` ([`Tracer`]), `engine_mesh.rs` ([`MeshBuffers`]),
//! `instances.rs`, `queries.rs` ([`RayQueries`], what both tracers
//! answer), `rays.rs` (rays, hits, device batches).
mod engine_mesh;
mod instances;
mod primitives;
mod queries;
mod rays;

pub use engine_mesh::{IndexBuffer, IndexFormat, MeshBuffers};
pub use instances::{Instance, InstancedTracer};
pub use primitives::{Quality, Tracer};
pub use queries::{BatchHits, BatchOccluded, RayQueries};
pub use rays::{batch_slots, device_rays, Ray, RayHit};
