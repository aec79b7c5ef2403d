//! BVH builders, each written once as a sequence of kernel dispatches on a
//! [`Backend`](crate::runtime::backend::Backend), so that the GPU and the CPU
//! runner run the same stages:
//!
//! - [`lbvh`]: Karras 2012 (Morton codes, [`sort`], radix tree or
//!   agglomerative hierarchy, bottom-up boxes);
//! - [`trbvh`]: Karras & Aila 2013 treelet restructuring and SAH leaf collapse;
//! - [`refit`]: new boxes for a tree whose primitives moved;
//! - [`sweep`]: the full-sweep SAH tree on the CPU;
//! - [`mod@reference`]: the quality reference, the peers crate's best tree (PLOC
//!   with full reinsertion, on the CPU; feature `peers`);
//! - [`layout`]: the traversal layouts (binary, classic, compressed wide);
//! - [`tree`]: the tree a render or an engine asks for: the builder's
//!   choice ([`tree::Accel`]), its binary tree, and that tree laid out;
//! - [`choice`]: which builder finishes a render's or a frame's work first;
//! - [`validate`], [`validate_layout`]: independent checks that share no
//!   code with the kernels;
//! - [`report`]: one build, timed and checked (the `treelet build` command),
//!   with its SAH and [`epo`] (end-point overlap; [`clip`] cuts triangles to boxes).
pub mod choice;
pub mod clip;
pub mod epo;
pub mod layout;
pub mod lbvh;
pub mod reference;
pub mod refit;
pub mod reinsert;
pub mod report;
pub mod sort;
pub mod sweep;
pub mod trbvh;
pub mod tree;
pub mod validate;
pub mod validate_layout;
