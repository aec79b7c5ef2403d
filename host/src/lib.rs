//! # treelet
//!
//! The host side of Treelet: a wgpu runtime for the SPIR-V kernels of
//! `treelet-shader`, a CPU runner for the same kernel functions, the stage
//! order of each build, scenes, an independent tree validator, and the
//! `treelet` command.
//!
//! ```no_run
//! use treelet::{backend::Backend, cpu_runner::CpuBackend, lbvh, scene};
//! let spheres = scene::random_spheres(1000, 7);
//! let (bvh, times) = lbvh::build(&mut CpuBackend::new(), &spheres).unwrap();
//! assert_eq!(bvh.nodes.len(), 1999);
//! println!("{} ms", times.total());
//! ```
pub mod backend;
pub mod cpu_runner;
pub mod gpu;
pub mod image_io;
pub mod kernels;
pub mod layout;
pub mod lbvh;
pub mod mesh;
pub mod primitives;
pub mod plot;
pub mod render;
pub mod report;
pub mod scene;
pub mod scene_file;
pub mod sort;
pub mod sweep;
pub mod trbvh;
pub mod validate;
pub mod validate_layout;
pub mod variant;
