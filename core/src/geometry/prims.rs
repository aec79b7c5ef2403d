//! The primitives rays are traced against: spheres then triangles in one
//! index space, the distance to one of them, and the surface a ray leaves.
use glam::Vec3;

use crate::geometry::buffers::{LeafPrim, Sphere};
use crate::geometry::flat::ray_shape;
use crate::geometry::features::{self, has};
use crate::geometry::intersect::{ray_sphere_mode, MISS};
use crate::geometry::split::Split;
use crate::geometry::triangle::{ray_triangle, Triangle, WatertightRay};

/// The primitives rays are traced against (counts given apart from the
/// slices, which on a GPU may be longer than their content). Triangles may
/// be bound in two parts ([`Split`]): a mesh's can pass 2 GiB.
pub struct Prims<'a> {
    pub spheres: &'a [Sphere],
    pub sphere_count: u32,
    pub triangles: Split<'a, Triangle>,
    pub triangle_count: u32,
}

impl<'a> Prims<'a> {
    /// Spheres, then triangles: all of both slices (host code; kernels
    /// take counts and triangles in parts from their bindings).
    #[cfg(not(target_arch = "spirv"))]
    pub fn new(spheres: &'a [Sphere], triangles: &'a [Triangle]) -> Self {
        let (sphere_count, triangle_count) = (spheres.len() as u32, triangles.len() as u32);
        Prims { spheres, sphere_count, triangles: Split::whole(triangles), triangle_count }
    }

    /// Spheres only.
    #[cfg(not(target_arch = "spirv"))]
    pub fn spheres(spheres: &'a [Sphere]) -> Self {
        Prims { spheres, sphere_count: spheres.len() as u32, triangles: Split::whole(&[]), triangle_count: 0 }
    }

    /// Triangle `k` (primitive `sphere_count + k`).
    #[inline]
    pub fn triangle(&self, k: u32) -> Triangle {
        self.triangles.get(k as usize)
    }

    #[inline]
    pub fn count(&self) -> u32 {
        self.sphere_count + self.triangle_count
    }

    /// Whether primitive `prim` is a sphere, decided at compile time when
    /// `F` (see [`crate::geometry::features`]) has only one primitive kind.
    #[inline]
    pub fn is_sphere<const F: u32>(&self, prim: u32) -> bool {
        if !has(F, features::TRIANGLES) && !has(F, features::SHAPES) {
            true
        } else if !has(F, features::SPHERES) {
            false
        } else {
            prim < self.sphere_count
        }
    }

    /// Distance to primitive `prim` along the ray (a triangle's only up to
    /// `t_max`, inclusive); `F` (see
    /// [`crate::geometry::features`]) leaves out the test of a kind the scene lacks.
    #[inline]
    pub fn distance<const F: u32>(
        &self,
        o: Vec3,
        d: Vec3,
        ray: &WatertightRay,
        from: Origin,
        prim: u32,
        t_max: f32,
    ) -> f32 {
        if self.is_sphere::<F>(prim) {
            from.distance(o, d, &self.spheres[prim as usize], prim)
        } else if prim == from.prim {
            MISS // a flat triangle cannot be hit again by a ray leaving it
        } else {
            flat_distance::<F>(o, d, ray, &self.triangle(prim - self.sphere_count), t_max)
        }
    }
}

/// Whether flat primitive `tri` is a disk or parallelogram (else a
/// triangle), decided at compile time when `F` has only one of the kinds.
#[inline]
pub fn is_shape<const F: u32>(tri: &Triangle) -> bool {
    has(F, features::SHAPES) && (!has(F, features::TRIANGLES) || !tri.is_triangle())
}

/// Distance to a flat primitive: the watertight triangle test, or the
/// disk's or parallelogram's where `F` has them and `tri` is one.
#[inline]
fn flat_distance<const F: u32>(o: Vec3, d: Vec3, ray: &WatertightRay, tri: &Triangle, t_max: f32) -> f32 {
    if is_shape::<F>(tri) {
        ray_shape(o, d, tri, t_max)
    } else {
        ray_triangle(ray, tri, t_max)
    }
}

impl Prims<'_> {
    /// Distance to a primitive stored in leaf order ([`LeafPrim`]), as
    /// [`Prims::distance`] finds it from the scene's own arrays: the same
    /// tests on the same numbers.
    #[inline]
    pub fn leaf_distance<const F: u32>(
        &self,
        o: Vec3,
        d: Vec3,
        ray: &WatertightRay,
        from: Origin,
        leaf: &LeafPrim,
        t_max: f32,
    ) -> f32 {
        let prim = leaf.prim;
        if self.is_sphere::<F>(prim) {
            from.distance(o, d, &Sphere::new(leaf.p0, leaf.p1[0]), prim)
        } else if prim == from.prim {
            MISS
        } else {
            let tri = Triangle { v0: leaf.p0, shape: leaf.shape, v1: leaf.p1, _pad1: 0, v2: leaf.p2, _pad2: 0 };
            flat_distance::<F>(o, d, ray, &tri, t_max)
        }
    }

    /// Primitive `prim` as its leaf stores it.
    #[inline]
    pub fn leaf_prim(&self, prim: u32) -> LeafPrim {
        if prim < self.sphere_count {
            let s = self.spheres[prim as usize];
            LeafPrim { p0: s.center, prim, p1: [s.radius, 0.0, 0.0], ..Default::default() }
        } else {
            let t = self.triangle(prim - self.sphere_count);
            LeafPrim { p0: t.v0, prim, p1: t.v1, shape: t.shape, p2: t.v2, ..Default::default() }
        }
    }
}

/// The surface a ray starts on, if any: a ray leaving sphere `prim` cannot
/// hit it again (`into == false`), or hits only its far side (`into`).
#[derive(Clone, Copy)]
pub struct Origin {
    pub prim: u32,
    pub into: bool,
}

impl Origin {
    /// A ray from no surface (a camera ray).
    pub const NONE: Origin = Origin { prim: u32::MAX, into: false };

    /// Distance to sphere `prim` along the ray, honouring the start surface.
    #[inline]
    pub fn distance(&self, o: Vec3, d: Vec3, s: &Sphere, prim: u32) -> f32 {
        if prim == self.prim {
            if !self.into {
                return MISS;
            }
            return ray_sphere_mode(o, d, Vec3::from_array(s.center), s.radius, 0.0, true);
        }
        ray_sphere_mode(o, d, Vec3::from_array(s.center), s.radius, 0.0, false)
    }
}
