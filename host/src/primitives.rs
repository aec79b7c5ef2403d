//! What a BVH is built over: spheres or triangles.
use anyhow::{bail, Result};
use treelet_core::triangle::Triangle;
use treelet_core::{Aabb, Sphere};

/// The primitives of one build (one kind per tree, for now).
#[derive(Clone, Copy, Debug)]
pub enum Primitives<'a> {
    Spheres(&'a [Sphere]),
    Triangles(&'a [Triangle]),
}

impl Primitives<'_> {
    pub fn len(&self) -> usize {
        match self {
            Primitives::Spheres(s) => s.len(),
            Primitives::Triangles(t) => t.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// (spheres, triangles): what a build report counts.
    pub fn counts(&self) -> (usize, usize) {
        match self {
            Primitives::Spheres(s) => (s.len(), 0),
            Primitives::Triangles(t) => (0, t.len()),
        }
    }

    /// Each primitive's box, on the host (the CPU reference builder's input).
    pub fn boxes(&self) -> Vec<Aabb> {
        match self {
            Primitives::Spheres(s) => s.iter().map(|s| s.aabb()).collect(),
            Primitives::Triangles(t) => t.iter().map(|t| t.aabb()).collect(),
        }
    }

    /// Rejects what no build can take: NaN or infinite coordinates, negative
    /// or overflowing radii, boxes whose extent overflows f32. Names the
    /// first bad primitive.
    pub fn check(&self) -> Result<()> {
        match self {
            Primitives::Spheres(s) => crate::scene::validate_spheres(s),
            Primitives::Triangles(tris) => {
                for (i, t) in tris.iter().enumerate() {
                    for (k, v) in [t.v0, t.v1, t.v2].iter().enumerate() {
                        if v.iter().any(|x| !x.is_finite()) {
                            bail!("triangle {i}: vertex {k} {v:?} is not finite");
                        }
                    }
                    if !t.aabb().extent().is_finite() {
                        bail!("triangle {i}: its extent overflows f32");
                    }
                }
                Ok(())
            }
        }
    }
}
