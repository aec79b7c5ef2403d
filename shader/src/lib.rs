//! Compute entry points of Treelet. Each `<stage>_cs` reads its ids, maps its
//! bindings and calls one function of `treelet-core`, where the logic lives
//! (and where the CPU runner and the tests call it too).
//!
//! Binding 0 of every entry point is its parameter struct; the host's kernel
//! table (`treelet::runtime::kernels`) lists the rest in the same order.
#![cfg_attr(target_arch = "spirv", no_std)]

pub mod bounds;
pub mod bvh2;
pub mod cwbvh;
pub mod depth;
pub mod fill;
pub mod fit;
pub mod morton;
pub mod multisplit;
pub mod radix_tree;
pub mod render;
pub mod scan;
pub mod scene;
pub mod sort;
pub mod treelet;

// `#[spirv(compute(threads(256)))]` takes a literal: keep it in step.
const _: () = assert!(treelet_core::WORKGROUP_SIZE == 256);
