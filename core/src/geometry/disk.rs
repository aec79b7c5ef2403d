//! Disks (and ellipses): a flat primitive stored as a [`Triangle`] of shape
//! [`SHAPE_DISK`], centre `v0` and semi-axes `e1 = v1 - v0`, `e2 = v2 - v0`,
//! the points `v0 + x e1 + y e2` with `x² + y² <= 1`. A disk-shaped lamp is
//! one primitive instead of a fan of triangles: one intersection, one box
//! in the tree, sampled uniformly by area as one light (as Mitsuba 3's
//! `disk` shape and pbrt-v4's `Disk` are). Its normal is the triangle's,
//! `e1 × e2`, so shading and light densities need no case of their own.
use glam::Vec3;

use crate::geometry::aabb::Aabb;
use crate::geometry::intersect::MISS;
use crate::geometry::triangle::{Triangle, SHAPE_DISK};

impl Triangle {
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

/// Box of the ellipse of centre `c` and semi-axes `e1`, `e2`: along each
/// axis it reaches `sqrt(e1ᵢ² + e2ᵢ²)` either side of the centre, widened
/// by a few ulps of the reach and the centre, as the rim's points and the
/// box's corners are both rounded.
#[inline]
pub fn disk_aabb(c: Vec3, e1: Vec3, e2: Vec3) -> Aabb {
    let reach = Vec3::new(
        libm::sqrtf(e1.x * e1.x + e2.x * e2.x),
        libm::sqrtf(e1.y * e1.y + e2.y * e2.y),
        libm::sqrtf(e1.z * e1.z + e2.z * e2.z),
    );
    let half = reach * (1.0 + 4.0 * f32::EPSILON) + c.abs() * (4.0 * f32::EPSILON);
    Aabb::new(c - half, c + half)
}

/// Distance along `d` (in units of its length) from `o` to disk `disk`,
/// beyond 0 and up to `t_max` (inclusive), or [`MISS`]; both faces are hit,
/// a ray in its plane never. The hit point is solved in the disk's own
/// frame (`p - c = x e1 + y e2`, as Möller–Trumbore solves a triangle's
/// barycentrics), then kept if `x² + y² <= 1`.
#[inline]
pub fn ray_disk(o: Vec3, d: Vec3, disk: &Triangle, t_max: f32) -> f32 {
    let (t, x, y) = ray_disk_coordinates(o, d, disk, t_max);
    if t == MISS || x * x + y * y > 1.0 {
        MISS
    } else {
        t
    }
}

/// The distance to the plane of `disk` along the ray (or [`MISS`]) and the
/// hit point's coordinates `(x, y)` along its semi-axes.
#[inline]
pub fn ray_disk_coordinates(o: Vec3, d: Vec3, disk: &Triangle, t_max: f32) -> (f32, f32, f32) {
    let c = Vec3::from_array(disk.v0);
    let (e1, e2) = (Vec3::from_array(disk.v1) - c, Vec3::from_array(disk.v2) - c);
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
    fn rays_hit_inside_the_rim_only() {
        let disk = Triangle::disk([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], 2.0);
        let o = Vec3::new(0.2, -0.1, 0.0);
        for i in 0..2000 {
            let r = BounceRng::new(3, i, 0, 1);
            let target = Vec3::new(r.uniform(0) * 6.0 - 3.0, r.uniform(1) * 6.0 - 3.0, 5.0);
            let d = target - o;
            let t = ray_disk(o, d, &disk, MISS);
            let inside = target.truncate().length() <= 2.0;
            if (target.truncate().length() - 2.0).abs() > 1e-4 {
                assert_eq!(t != MISS, inside, "{target:?}");
            }
            if t != MISS {
                assert!((t - 1.0).abs() < 1e-5, "{t}");
                assert_eq!(ray_disk(o, d, &disk, 0.99), MISS, "beyond t_max");
                assert_eq!(ray_disk(o, -d, &disk, MISS), MISS, "behind the origin");
            }
        }
        // In its plane: never.
        assert_eq!(ray_disk(Vec3::new(-5.0, 0.0, 5.0), Vec3::X, &disk, MISS), MISS);
    }
}
