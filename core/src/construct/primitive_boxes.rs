//! Primitives: their boxes and centroids, the first stage of every build.

use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::Sphere;
use crate::geometry::triangle::Triangle;

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
