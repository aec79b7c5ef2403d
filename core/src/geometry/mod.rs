//! # Geometry
//!
//! What every stage reads: the buffer types shared by both builds
//! ([`buffers`]: `#[repr(C)]`, `Pod`, sizes asserted), boxes ([`aabb`]),
//! spheres and triangles and their intersection with rays ([`intersect`],
//! after Ize 2013 for robust slabs; [`triangle`], after Woop, Benthin &
//! Wald 2013 for watertight triangles; [`flat`], disks and
//! parallelograms stored as triangles are), the primitive set a ray is traced
//! against ([`prims`]), and the feature bits that say which primitive kinds
//! and materials a scene has ([`features`]), and an engine's mesh read
//! from its own vertex and index buffers ([`gather`]).
pub mod aabb;
pub mod buffers;
pub mod flat;
pub mod features;
pub mod gather;
pub mod intersect;
pub mod prims;
pub mod records;
pub mod split;
pub mod triangle;
