//! # treelet-core
//!
//! The algorithms of Treelet, written once and compiled twice: to SPIR-V
//! compute kernels (through rust-gpu, see the `treelet-shader` crate) and to
//! ordinary host code, which the CPU runner, the tests and embedding engines
//! call. Nothing here allocates; every buffer is a slice owned by the caller.
//!
//! ## The LBVH build (Karras 2012), stage by stage
//!
//! | stage | file | reads | writes |
//! |---|---|---|---|
//! | primitive boxes | [`scene`] | spheres | one [`Aabb`] per primitive |
//! | centroid bounds | [`bounds`] | boxes | one box per workgroup, reduced again until one remains |
//! | Morton codes | [`morton`] | boxes, centroid bounds | 63-bit keys, identity values |
//! | sort | [`sort`], [`scan`] | keys, values | keys, values sorted (stable LSD radix sort) |
//! | radix tree | [`radix_tree`] | sorted keys | internal nodes' children, parent links |
//! | fit | [`fit`] | tree, boxes | leaf and internal boxes, bottom-up with atomic flags |
//!
//! Treelet restructuring (Karras & Aila 2013) then rewrites the tree in
//! place, round by round ([`treelet`]), and [`collapse`] compacts it into
//! depth-first order with SAH-collapsed leaves of several primitives.
//!
//! Node layout: `n` leaves and `n - 1` internal nodes in one array of
//! `2n - 1` [`Node`]s. Internal node `i` sits at index `i` (so the root is 0),
//! leaf `j` (the `j`-th primitive in Morton order) at index `n - 1 + j`.
//!
//! Every kernel is a plain function of its invocation id (or of its workgroup,
//! for kernels that share workgroup memory: see [`workgroup`]). The shader
//! crate's entry points only map ids and bindings to these functions.
//!
//! ## Example: build a BVH over spheres on the CPU
//! ```
//! use treelet_core::{Sphere, Node};
//! // The host crate (`treelet`) wraps these stages; see `treelet::bvh::build_cpu`.
//! let s = Sphere::new([0.0, 0.0, 0.0], 1.0);
//! assert_eq!(s.aabb().surface_area(), 24.0);
//! assert_eq!(core::mem::size_of::<Node>(), 32);
//! ```
#![no_std]

pub mod aabb;
pub mod agglomerate;
pub mod atomics;
pub mod bounds;
pub mod bvh2;
pub mod collapse;
pub mod cwbvh;
pub mod cwbvh_build;
pub mod features;
pub mod fill;
pub mod fit;
pub mod intersect;
pub mod layout;
pub mod lights;
pub mod morton;
pub mod radix_tree;
pub mod rays;
pub mod render;
pub mod rng;
pub mod sah;
pub mod scan;
pub mod scene;
pub mod sort;
pub mod traverse;
pub mod treelet;
pub mod treelet_kernels;
pub mod triangle;
pub mod unchecked;
pub mod workgroup;

pub use aabb::Aabb;
pub use layout::{
    BuildParams, Bvh2Node, Camera, FillParams, LayoutParams, LeafPrim, Material, Node, RenderParams, ScanParams,
    SortParams, Sphere, WideNode, INVALID, LEAF_BIT,
};
pub use workgroup::WORKGROUP_SIZE;
