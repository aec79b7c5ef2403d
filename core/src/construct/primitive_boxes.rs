//! Primitives: their boxes and centroids, the first stage of every build.

use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::Sphere;
use crate::geometry::triangle::Triangle;
use crate::gpu::unchecked::at;
use crate::geometry::records::RecordStore;
use crate::geometry::split::Split;

/// Kernel: the box of primitive `id`: sphere `id` below `spheres`, else
/// triangle `id - spheres`. `boxes` as records or as vectors (see
/// [`crate::geometry::records`]).
pub fn primitive_boxes_kernel<B: RecordStore<Aabb> + ?Sized>(
    id: u32,
    n: u32,
    spheres: u32,
    sphere_data: &[Sphere],
    triangles: &Split<Triangle>,
    boxes: &mut B,
) {
    if id < n {
        boxes.store(id as usize, &primitive_box(id, spheres, sphere_data, triangles));
    }
}

/// The box of primitive `id` (of those there are): sphere `id` below
/// `spheres`, else triangle `id - spheres`.
#[inline]
pub fn primitive_box(id: u32, spheres: u32, sphere_data: &[Sphere], triangles: &Split<Triangle>) -> Aabb {
    if id < spheres { at(sphere_data, id as usize).aabb() } else { triangles.get((id - spheres) as usize).aabb() }
}
