//! What a BVH is built over: spheres and triangles, in one index space
//! (spheres first, then triangles), as the kernels see them.
use anyhow::Result;
use treelet_core::geometry::triangle::{Triangle, SHAPE_DISK, SHAPE_PARALLELOGRAM, SHAPE_TRIANGLE};
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
            triangles: treelet_core::geometry::split::Split::whole(self.triangles),
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
        use rayon::prelude::*;
        validate_spheres(self.spheres)?;
        // On all cores, as an engine checks every frame's mesh (1M triangles
        // took 10 ms on one core of the H100's host); the first bad one is named.
        let known = |t: &Triangle| matches!(t.shape, SHAPE_TRIANGLE | SHAPE_DISK | SHAPE_PARALLELOGRAM);
        let bad = |t: &Triangle| {
            !known(t) || [t.v0, t.v1, t.v2].iter().flatten().any(|x| !x.is_finite()) || !t.aabb().extent().is_finite()
        };
        let Some(i) = self.triangles.par_iter().position_first(bad) else { return Ok(()) };
        let t = &self.triangles[i];
        if !known(t) {
            // Words an engine left in the padding (a w of 1.0, say) would
            // otherwise make a triangle another shape.
            return Err(crate::error::input(format!("triangle {i}: shape tag {:#x} is none of {SHAPE_TRIANGLE} (triangle), {SHAPE_DISK} (disk), {SHAPE_PARALLELOGRAM} (parallelogram); `Triangle::new` sets it",
                t.shape)));
        }
        for (k, v) in [t.v0, t.v1, t.v2].iter().enumerate() {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(crate::error::input(format!("triangle {i}: vertex {k} {v:?} is not finite")));
            }
        }
        Err(crate::error::input(format!("triangle {i}: its extent overflows f32")))
    }
}

/// Rejects spheres a build or render cannot use, naming the first bad one:
/// non-finite centre or radius, or a negative radius.
pub fn validate_spheres(spheres: &[Sphere]) -> Result<()> {
    for (i, s) in spheres.iter().enumerate() {
        if let Some(k) = s.center.iter().position(|c| !c.is_finite()) {
            return Err(crate::error::input(format!("sphere {i}: centre coordinate {} is {} (every coordinate must be finite)",
                "xyz".as_bytes()[k] as char,
                s.center[k])));
        }
        if !s.radius.is_finite() || s.radius < 0.0 {
            return Err(crate::error::input(format!("sphere {i}: radius is {} (must be finite and non-negative)", s.radius)));
        }
        // A box corner (centre ± radius) must stay finite too.
        if s.center.iter().any(|c| !(c.abs() + s.radius).is_finite()) {
            return Err(crate::error::input(format!("sphere {i}: its bounding box overflows f32 (centre {:?}, radius {})", s.center, s.radius)));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first bad triangle is named, however many there are (the check
    /// runs on all cores), with what is wrong with it.
    #[test]
    fn the_first_bad_triangle_is_named() {
        let good = Triangle::new([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let mut triangles = vec![good; 100_000];
        let all = |t: &[Triangle]| Primitives { spheres: &[], triangles: t }.check();
        assert!(all(&triangles).is_ok());
        triangles[70_000].v2[1] = f32::NAN;
        triangles[5_001].v1 = [f32::INFINITY, 0.0, 0.0];
        let e = format!("{:#}", all(&triangles).unwrap_err());
        assert!(e.contains("triangle 5001: vertex 1") && e.contains("not finite"), "{e}");
        triangles[5_001] = good;
        triangles[3].v0 = [-f32::MAX, 0.0, 0.0];
        triangles[3].v1 = [f32::MAX, 0.0, 0.0];
        let e = format!("{:#}", all(&triangles).unwrap_err());
        assert_eq!(e, "triangle 3: its extent overflows f32");
        triangles[3] = good;
        triangles[2].shape = 1.0f32.to_bits();
        let e = format!("{:#}", all(&triangles).unwrap_err());
        assert!(e.starts_with("triangle 2: shape tag 0x3f800000 is none of"), "{e}");
        triangles[2] = Triangle::disk([0.0; 3], [0.0, 0.0, 1.0], 1.0);
        triangles[70_000] = Triangle::parallelogram([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!(all(&triangles).is_ok());
    }
}
