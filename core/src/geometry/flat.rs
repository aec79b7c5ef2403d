//! Flat shapes beyond the triangle, stored as a [`Triangle`] is (three
//! points `v0`, `v1`, `v2`; `e1 = v1 - v0`, `e2 = v2 - v0`) with a
//! [`Triangle::shape`] tag: the points `v0 + x e1 + y e2` with
//! - `x² + y² <= 1` for a disk ([`SHAPE_DISK`]; an ellipse when the
//!   semi-axes `e1`, `e2` differ), as Mitsuba 3's `disk` and pbrt-v4's `Disk`;
//! - `0 <= x, y <= 1` for a parallelogram ([`SHAPE_PARALLELOGRAM`]; a
//!   rectangle when the edges are square to each other), as Mitsuba 3's
//!   `rectangle`.
//!
//! A disk lamp or a wall is then one primitive instead of a fan or a pair
//! of triangles: one intersection, one box in the tree, sampled uniformly
//! by area as one light. The normal is the triangle's, `e1 × e2`, so
//! shading and light densities need no case of their own; only the box,
//! the area, the test of the hit point and the sampled point depend on the
//! shape. Unlike meshes, these shapes share no edges, so they are not
//! watertight: scenes overlap walls at their corners.
use glam::Vec3;

use crate::geometry::aabb::Aabb;
use crate::geometry::intersect::MISS;
use crate::geometry::triangle::{Triangle, SHAPE_DISK, SHAPE_PARALLELOGRAM, SHAPE_TRIANGLE};

impl Triangle {
    /// The primitive's bounding box (a disk's or parallelogram's, not its
    /// three points').
    #[inline]
    pub fn aabb(&self) -> Aabb {
        flat_aabb(self)
    }

    /// The primitive's area.
    #[inline]
    pub fn area(&self) -> f32 {
        flat_area(self)
    }

    /// The parallelogram with corner `corner` and edges `edge1`, `edge2`
    /// (its normal `edge1 × edge2`).
    pub fn parallelogram(corner: [f32; 3], edge1: [f32; 3], edge2: [f32; 3]) -> Triangle {
        let c = Vec3::from_array(corner);
        Triangle {
            v0: corner,
            shape: SHAPE_PARALLELOGRAM,
            v1: (c + Vec3::from_array(edge1)).to_array(),
            _pad1: 0,
            v2: (c + Vec3::from_array(edge2)).to_array(),
            _pad2: 0,
        }
    }

    /// The disk of centre `center`, normal `normal` (need not be unit) and
    /// radius `radius`; its semi-axes are chosen so that `e1 × e2` points
    /// along `normal`.
    pub fn disk(center: [f32; 3], normal: [f32; 3], radius: f32) -> Triangle {
        let n = Vec3::from_array(normal).normalize();
        // Any unit vector across the normal (Duff et al. 2017's branchless basis).
        let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let u = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let v = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        let c = Vec3::from_array(center);
        Triangle {
            v0: center,
            shape: SHAPE_DISK,
            v1: (c + u * radius).to_array(),
            _pad1: 0,
            v2: (c + v * radius).to_array(),
            _pad2: 0,
        }
    }
}

/// Box of flat primitive `t`: a triangle's three points, a
/// parallelogram's four corners; an ellipse of centre `c` and semi-axes
/// `e1`, `e2` reaches `sqrt(e1ᵢ² + e2ᵢ²)` either side of its centre along
/// each axis, widened by a few ulps of the reach and the centre, as the
/// rim's points and the box's corners are both rounded.
#[inline]
pub fn flat_aabb(t: &Triangle) -> Aabb {
    let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
    if t.shape == SHAPE_DISK {
        let (e1, e2) = (b - a, c - a);
        let reach = Vec3::new(
            libm::sqrtf(e1.x * e1.x + e2.x * e2.x),
            libm::sqrtf(e1.y * e1.y + e2.y * e2.y),
            libm::sqrtf(e1.z * e1.z + e2.z * e2.z),
        );
        let half = reach * (1.0 + 4.0 * f32::EPSILON) + a.abs() * (4.0 * f32::EPSILON);
        return Aabb::new(a - half, a + half);
    }
    let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
    if t.shape == SHAPE_PARALLELOGRAM {
        let d = b + (c - a);
        return Aabb::new(lo.min(d), hi.max(d));
    }
    Aabb::new(lo, hi)
}

/// Area of flat primitive `t`: of the parallelogram of its two edges, half
/// of it for a triangle, π times it for a disk.
#[inline]
pub fn flat_area(t: &Triangle) -> f32 {
    let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
    (b - a).cross(c - a).length() * area_factor(t.shape)
}

/// A shape's area over its parallelogram's `|e1 × e2|`.
#[inline]
pub fn area_factor(shape: u32) -> f32 {
    match shape {
        SHAPE_TRIANGLE => 0.5,
        SHAPE_DISK => core::f32::consts::PI,
        _ => 1.0,
    }
}

/// The point of flat primitive `t` that `u1`, `u2` in `[0, 1)` pick,
/// uniformly by area: on a triangle by Turk's square-root
/// parametrization, on a disk at radius `sqrt(u1)` and angle `u2` turns
/// (`sin_cos` gives that angle's sine and cosine), on a parallelogram at
/// `(u1, u2)`.
#[inline]
pub fn flat_point(t: &Triangle, u1: f32, u2: f32, sin_cos: impl Fn(f32) -> (f32, f32)) -> Vec3 {
    let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
    if t.shape == SHAPE_DISK {
        let r = libm::sqrtf(u1);
        let (s, co) = sin_cos(u2);
        a + (b - a) * (r * co) + (c - a) * (r * s)
    } else if t.shape == SHAPE_PARALLELOGRAM {
        a + (b - a) * u1 + (c - a) * u2
    } else {
        let su = libm::sqrtf(u1);
        a * (1.0 - su) + b * (su * (1.0 - u2)) + c * (su * u2)
    }
}

/// Distance along `d` (in units of its length) from `o` to the disk or
/// parallelogram `shape`, beyond 0 and up to `t_max` (inclusive), or
/// [`MISS`]; both faces are hit, a ray in its plane never. The hit point is
/// solved in the shape's own frame (`p - v0 = x e1 + y e2`, as
/// Möller–Trumbore solves a triangle's barycentrics), then kept if it lies
/// inside (see the module's documentation). Triangles take the watertight
/// test instead ([`crate::geometry::triangle::ray_triangle`]).
#[inline]
pub fn ray_shape(o: Vec3, d: Vec3, shape: &Triangle, t_max: f32) -> f32 {
    let (t, x, y) = ray_plane_coordinates(o, d, shape, t_max);
    let inside = if shape.shape == SHAPE_DISK { x * x + y * y <= 1.0 } else { x >= 0.0 && x <= 1.0 && y >= 0.0 && y <= 1.0 };
    if t != MISS && inside {
        t
    } else {
        MISS
    }
}

/// The distance to the plane of `shape` along the ray (or [`MISS`]) and
/// the hit point's coordinates `(x, y)` along its edges.
#[inline]
pub fn ray_plane_coordinates(o: Vec3, d: Vec3, shape: &Triangle, t_max: f32) -> (f32, f32, f32) {
    let c = Vec3::from_array(shape.v0);
    let (e1, e2) = (Vec3::from_array(shape.v1) - c, Vec3::from_array(shape.v2) - c);
    let n = e1.cross(e2);
    let denom = d.dot(n);
    if denom == 0.0 {
        return (MISS, 0.0, 0.0);
    }
    let t = (c - o).dot(n) / denom;
    if !(t > 0.0 && t <= t_max) {
        return (MISS, 0.0, 0.0);
    }
    let p = o + d * t - c;
    let nn = n.dot(n);
    (t, p.cross(e2).dot(n) / nn, e1.cross(p).dot(n) / nn)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::rng::BounceRng;

    #[test]
    fn a_disk_is_round_flat_and_boxed() {
        let disk = Triangle::disk([1.0, 2.0, 3.0], [0.3, -1.0, 0.2], 2.5);
        let (c, n) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.3, -1.0, 0.2).normalize());
        let (e1, e2) = (Vec3::from_array(disk.v1) - c, Vec3::from_array(disk.v2) - c);
        assert!((e1.length() - 2.5).abs() < 1e-5 && (e2.length() - 2.5).abs() < 1e-5);
        assert!(e1.dot(e2).abs() < 1e-4 && (e1.cross(e2).normalize() - n).length() < 1e-5);
        assert!((disk.area() - core::f32::consts::PI * 6.25).abs() < 1e-3);
        let b = disk.aabb();
        let mut seen = Aabb::EMPTY;
        for i in 0..4096 {
            let a = i as f32 / 4096.0 * core::f32::consts::TAU;
            let p = c + e1 * libm::cosf(a) + e2 * libm::sinf(a);
            assert!(b.contains(&Aabb::point(p)), "{p:?} outside {b:?}");
            assert!((p - c).dot(n).abs() < 1e-4);
            seen = seen.union(&Aabb::point(p));
        }
        // The box is tight: the rim reaches it on every side.
        assert!((seen.lo() - b.lo()).abs().max_element() < 1e-5 && (seen.hi() - b.hi()).abs().max_element() < 1e-5);
    }

    #[test]
    fn a_parallelogram_is_boxed_by_its_corners() {
        let p = Triangle::parallelogram([1.0, 2.0, 3.0], [4.0, -1.0, 0.5], [-0.5, 2.0, 1.0]);
        assert!((p.area() - Vec3::new(4.0, -1.0, 0.5).cross(Vec3::new(-0.5, 2.0, 1.0)).length()).abs() < 1e-5);
        let b = p.aabb();
        assert_eq!(b, Aabb::new(Vec3::new(0.5, 1.0, 3.0), Vec3::new(5.0, 4.0, 4.5)));
    }

    /// Rays aimed at random points of a plane hit a disk or parallelogram
    /// exactly where the point is inside it, at the right distance.
    #[test]
    fn rays_hit_inside_the_shape_only() {
        let disk = Triangle::disk([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], 2.0);
        let quad = Triangle::parallelogram([-1.0, -2.0, 5.0], [3.0, 0.0, 0.0], [1.0, 2.5, 0.0]);
        // The parallelogram's coordinates of a point of its plane.
        let quad_xy = |p: Vec3| {
            let y = (p.y + 2.0) / 2.5;
            ((p.x + 1.0 - y) / 3.0, y)
        };
        let o = Vec3::new(0.2, -0.1, 0.0);
        for (shape, margin) in [(&disk, 1e-4f32), (&quad, 1e-4)] {
            let mut hits = 0;
            for i in 0..2000 {
                let r = BounceRng::new(3, i, 0, 1);
                let target = Vec3::new(r.uniform(0) * 6.0 - 3.0, r.uniform(1) * 6.0 - 3.0, 5.0);
                // Signed distance (in shape units) inside the boundary.
                let depth = if shape.shape == SHAPE_DISK {
                    2.0 - target.truncate().length()
                } else {
                    let (x, y) = quad_xy(target);
                    x.min(1.0 - x).min(y).min(1.0 - y)
                };
                let d = target - o;
                let t = ray_shape(o, d, shape, MISS);
                if depth.abs() > margin {
                    assert_eq!(t != MISS, depth > 0.0, "shape {} at {target:?}", shape.shape);
                }
                if t != MISS {
                    hits += 1;
                    assert!((t - 1.0).abs() < 1e-5, "{t}");
                    assert_eq!(ray_shape(o, d, shape, 0.99), MISS, "beyond t_max");
                    assert_eq!(ray_shape(o, -d, shape, MISS), MISS, "behind the origin");
                }
            }
            assert!(hits > 200, "shape {}: {hits} hits", shape.shape);
            // In its plane: never.
            assert_eq!(ray_shape(Vec3::new(-5.0, 0.0, 5.0), Vec3::X, shape, MISS), MISS);
        }
    }
}
