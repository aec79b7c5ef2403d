//! # Traversal layouts
//!
//! Making the trees rays are traced through from a built binary tree:
//! - [`bvh2`]: two-box binary nodes (Aila & Laine 2009), made from the
//!   collapsed tree in depth-first order;
//! - [`bvh4`]: 4-wide nodes of full-precision boxes, made from `bvh2`'s;
//! - [`cwbvh`] (the node format) and [`cwbvh::build`]: compressed 8-wide
//!   nodes (Ylitie, Karras & Laine 2017), made bottom-up from the tree of
//!   one primitive per leaf.
//!
//! The seed's classic layout is the collapsed tree itself
//! ([`crate::construct::collapse`]). Their traversals are in [`crate::trace`].
pub mod bvh2;
pub mod bvh4;
pub mod depth;
pub mod cwbvh;
