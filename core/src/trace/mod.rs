//! # Tracing
//!
//! One closest-hit function per traversal layout, each behind the
//! [`ClosestHit`](hit::ClosestHit) trait so the renderer and the ray casts
//! are generic over it:
//! - [`classic`]: the scan of every primitive, and the seed's 32-byte
//!   nodes with a stack;
//! - [`bvh2`]: two-box binary nodes, nearer child first (Aila & Laine 2009);
//! - [`cwbvh`]: compressed 8-wide nodes with node and primitive groups
//!   (Ylitie, Karras & Laine 2017).
//!
//! Every layout finds exactly the scan's closest hit: ties go to the lower
//! primitive index ([`hit::Hit::is_beaten_by`]).
pub mod bvh2;
pub mod classic;
pub mod cwbvh;
pub mod hit;
pub mod instances;
