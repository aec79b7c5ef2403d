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

/// Kernel: the box of primitive `id`: sphere `id` below `spheres`, else
/// triangle `id - spheres`.
pub fn primitive_boxes_kernel(
    id: u32,
    n: u32,
    spheres: u32,
    sphere_data: &[Sphere],
    triangles: &[Triangle],
    boxes: &mut [Aabb],
) {
    if id < spheres {
        boxes[id as usize] = sphere_data[id as usize].aabb();
    } else if id < n {
        boxes[id as usize] = triangles[(id - spheres) as usize].aabb();
    }
}
