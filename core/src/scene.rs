//! Primitives: their boxes and centroids, the first stage of every build.
use glam::Vec3;

use crate::aabb::Aabb;
use crate::layout::Sphere;
use crate::triangle::Triangle;

impl Sphere {
    #[inline]
    pub fn center_vec(&self) -> Vec3 {
        Vec3::from_array(self.center)
    }
    /// Bounding box: centre ± radius.
    #[inline]
    pub fn aabb(&self) -> Aabb {
        let c = self.center_vec();
        let r = Vec3::splat(self.radius);
        Aabb::new(c - r, c + r)
    }
}

/// Kernel: the box of sphere `id`.
pub fn sphere_boxes_kernel(id: u32, n: u32, spheres: &[Sphere], boxes: &mut [Aabb]) {
    if id < n {
        boxes[id as usize] = spheres[id as usize].aabb();
    }
}

/// Kernel: the box of triangle `id`.
pub fn triangle_boxes_kernel(id: u32, n: u32, triangles: &[Triangle], boxes: &mut [Aabb]) {
    if id < n {
        boxes[id as usize] = triangles[id as usize].aabb();
    }
}
