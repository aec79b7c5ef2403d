//! The render kernel variants: which feature sets the shader crate compiles
//! render kernels for.
use crate::geometry::features::{ALL, GLASS, MIRROR, SPHERES, TRIANGLES};

/// The feature sets the shader crate compiles render kernels for (each
/// with a linear scan and with a BVH), with the names of their entry points
/// (`render::render_{linear,bvh}_<name>_cs`). A scene runs the smallest
/// set that contains its features; [`ALL`] (the general kernel) is last.
pub const VARIANTS: [(u32, &str); 6] = [
    (SPHERES, "spheres_diffuse"),
    (SPHERES | MIRROR, "spheres_mirror"),
    (SPHERES | MIRROR | GLASS, "spheres"),
    (TRIANGLES, "triangles_diffuse"),
    (SPHERES | TRIANGLES, "mixed_diffuse"),
    (ALL, "full"),
];
