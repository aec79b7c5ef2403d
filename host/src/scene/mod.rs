//! Scenes: what a build or render runs over, where it comes from, and the
//! checks that turn bad input into an error naming the problem.
//!
//! [`model`] is the scene itself and the built-in ones, [`city`] a
//! generated city of triangles of every size, [`primitives`] the
//! spheres-then-triangles view a build takes (and its checks), [`mesh`]
//! reads `.obj` / `.ply` ([`ply`] writes one), [`file`](mod@file) reads JSON scene files,
//! [`gltf`](mod@gltf) glTF 2.0 ones, [`instanced`] keeps their meshes placed by
//! reference (and flattens them), [`instances`] the meshes and
//! instances a render keeps, and [`spec`]
//! parses the names the command line takes ([`Scene::from_spec`]).
pub mod builtin;
pub mod city;
pub mod file;
pub mod gltf;
pub mod instanced;
pub mod instances;
pub mod json_keys;
pub mod mesh;
pub mod model;
pub mod ply;
mod obj_plain;
mod ply_binary;
pub mod primitives;
pub mod spec;

pub use model::*;
pub use primitives::{validate_spheres, Primitives};
