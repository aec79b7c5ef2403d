//! # treelet-core
//!
//! The algorithms of Treelet, written once and compiled twice: to SPIR-V
//! compute kernels (through rust-gpu, see the `treelet-shader` crate) and to
//! ordinary host code, which the CPU runner, the tests and embedding engines
//! call. Nothing here allocates; every buffer is a slice owned by the caller.
//!
//! ## The folders, bottom to top
//!
//! Each folder is a stage of the pipeline and imports only the folders
//! below it (`tests/layering.rs` checks this):
//!
//! | folder | what | papers |
//! |---|---|---|
//! | [`gpu`] | atomics, workgroup phases, subgroup operations (and their CPU emulation), unchecked access, fills: the one GPU/CPU split | |
//! | [`geometry`] | buffer types, boxes, spheres, triangles, ray intersection, feature bits | Ize 2013; Woop, Benthin & Wald 2013 |
//! | [`construct`] | Morton codes, radix sort, radix tree, bottom-up fit, agglomerative build, treelet restructuring, leaf collapse, SAH | Karras 2012; Apetrei 2014; Karras & Aila 2013; Adinets & Merrill 2022 |
//! | [`layouts`] | two-box binary nodes and compressed 8-wide nodes, made from a built tree | Aila & Laine 2009; Ylitie, Karras & Laine 2017 |
//! | [`trace`] | one closest-hit traversal per layout | the same |
//! | [`render`] | the path tracer (smallpt's estimator, NEE with MIS), lights, sampling, ray casts | Veach 1997; pbrt-v4 |
//!
//! Every kernel is a plain function of its invocation id (or of its
//! workgroup, for kernels that share workgroup memory: see
//! [`gpu::workgroup`]). The shader crate's entry points only map ids and
//! bindings to these functions.
//!
//! ## Example: a sphere's box, and a closest hit by the scan
//! ```
//! use glam::Vec3;
//! use treelet_core::geometry::prims::{Origin, Prims};
//! use treelet_core::trace::classic::closest_hit_linear;
//! use treelet_core::{Node, Sphere};
//! let spheres = [Sphere::new([0.0, 0.0, 0.0], 1.0), Sphere::new([4.0, 0.0, 0.0], 1.0)];
//! assert_eq!(spheres[0].aabb().surface_area(), 24.0);
//! assert_eq!(core::mem::size_of::<Node>(), 32);
//! let hit = closest_hit_linear(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, Origin::NONE, &Prims::spheres(&spheres));
//! assert_eq!((hit.prim, hit.t), (0, 4.0));
//! ```
//! The host crate (`treelet`) runs these stages on a device: see its
//! `Tracer` for building a tree and finding closest hits from an engine.
#![cfg_attr(target_arch = "spirv", feature(asm_experimental_arch))]
#![no_std]

/// `$body` once for each of the eight values of `$i` (0 to 7), a constant
/// in each copy. For loops whose arrays must stay in registers (an array
/// indexed at run time lives in local memory on the H100) or whose loads
/// must all be in flight at once.
macro_rules! unrolled_8 {
    ($i:ident, $body:block) => {
        unrolled_8!(@each $i, $body, 0 1 2 3 4 5 6 7)
    };
    (@each $i:ident, $body:block, $($v:literal)*) => {
        $({
            let $i: usize = $v;
            $body
        })*
    };
}

pub mod construct;
pub mod geometry;
pub mod gpu;
pub mod layouts;
pub mod registry;
pub mod render;
pub mod trace;

pub use geometry::aabb::Aabb;
pub use geometry::buffers::{
    BuildParams, Bvh2Node, Bvh4Node, Camera, CopyParams, FillParams, GatherParams, InstanceRecord, LayoutParams, LeafPrim, Material, Node, RenderParams, ScanParams, SplitParams,
    SortParams, Sphere, WideNode, INVALID, LEAF_BIT,
};
pub use geometry::triangle::Triangle;
pub use gpu::workgroup::WORKGROUP_SIZE;
