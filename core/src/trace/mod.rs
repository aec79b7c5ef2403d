//! # Tracing
//!
//! One closest-hit function per traversal layout, each behind the
//! [`ClosestHit`](hit::ClosestHit) trait so the renderer and the ray casts
//! are generic over it:
//! - [`classic`]: the scan of every primitive, and the seed's 32-byte
//!   nodes with a stack;
//! - [`bvh2`]: two-box binary nodes, nearer child first (Aila & Laine 2009);
//! - [`bvh4`]: the same tree as 4-wide nodes of full-precision boxes, half
//!   the steps;
//! - [`cwbvh`]: compressed 8-wide nodes with node and primitive groups
//!   (Ylitie, Karras & Laine 2017).
//!
//! Two more walk instances of meshes: [`instances`] (a top-level tree
//! over copies, each entered with the ray in its mesh's space: the engine
//! API's), and [`with_instances`] (a scene's own tree, then its copies: the
//! renderer's).
//!
//! Every layout finds exactly the scan's closest hit: ties go to the lower
//! primitive index ([`hit::Hit::is_beaten_by`]).
pub mod bvh2;
pub mod bvh4;
pub mod classic;
pub mod cwbvh;
pub mod hit;
pub mod instances;
pub mod with_instances;
