//! What a BVH is built over: spheres and triangles, in one index space
//! (spheres first, then triangles), as the kernels see them.
use anyhow::{bail, Result};
use treelet_core::geometry::triangle::Triangle;
use treelet_core::{Aabb, Sphere};

/// Largest scene a build accepts: node indices must stay below `LEAF_BIT`.
pub const MAX_PRIMITIVES: u32 = 1 << 30;

/// The primitives of one build: primitive `i` is sphere `i` below
/// `spheres.len()`, else triangle `i - spheres.len()`.
#[derive(Clone, Copy, Debug)]
pub struct Primitives<'a> {
    pub spheres: &'a [Sphere],
    pub triangles: &'a [Triangle],
}

impl<'a> Primitives<'a> {
    pub fn spheres(spheres: &'a [Sphere]) -> Self {
        Primitives { spheres, triangles: &[] }
    }

    pub fn triangles(triangles: &'a [Triangle]) -> Self {
        Primitives { spheres: &[], triangles }
    }

    /// The same primitives as the kernels' view of them.
    pub fn as_core(&self) -> treelet_core::geometry::prims::Prims<'a> {
        treelet_core::geometry::prims::Prims {
            spheres: self.spheres,
            sphere_count: self.spheres.len() as u32,
            triangles: self.triangles,
            triangle_count: self.triangles.len() as u32,
        }
    }

    pub fn len(&self) -> usize {
        self.spheres.len() + self.triangles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// (spheres, triangles): what a build report counts.
    pub fn counts(&self) -> (usize, usize) {
        (self.spheres.len(), self.triangles.len())
    }

    /// Each primitive's box, on the host (the CPU reference builder's input).
    pub fn boxes(&self) -> Vec<Aabb> {
        self.spheres.iter().map(|s| s.aabb()).chain(self.triangles.iter().map(|t| t.aabb())).collect()
    }

    /// Rejects what no build can take: NaN or infinite coordinates, negative
    /// or overflowing radii, boxes whose extent overflows f32. Names the
    /// first bad primitive.
    pub fn check(&self) -> Result<()> {
        validate_spheres(self.spheres)?;
        for (i, t) in self.triangles.iter().enumerate() {
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

/// Rejects spheres a build or render cannot use, naming the first bad one:
/// non-finite centre or radius, or a negative radius.
pub fn validate_spheres(spheres: &[Sphere]) -> Result<()> {
    for (i, s) in spheres.iter().enumerate() {
        if let Some(k) = s.center.iter().position(|c| !c.is_finite()) {
            bail!(
                "sphere {i}: centre coordinate {} is {} (every coordinate must be finite)",
                "xyz".as_bytes()[k] as char,
                s.center[k]
            );
        }
        if !s.radius.is_finite() || s.radius < 0.0 {
            bail!("sphere {i}: radius is {} (must be finite and non-negative)", s.radius);
        }
        // A box corner (centre ± radius) must stay finite too.
        if s.center.iter().any(|c| !(c.abs() + s.radius).is_finite()) {
            bail!("sphere {i}: its bounding box overflows f32 (centre {:?}, radius {})", s.center, s.radius);
        }
    }
    Ok(())
}
