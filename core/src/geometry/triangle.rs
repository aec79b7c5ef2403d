//! Watertight ray/triangle intersection: S. Woop, C. Benthin and I. Wald,
//! "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013.
//!
//! The ray is made the +z axis of a sheared frame (its largest direction
//! component becomes z, the other two are sheared away), so each edge test
//! is the 2D sign of a difference of two products of vertex coordinates. A
//! vertex shared by two triangles has the same sheared coordinates in both,
//! and each edge function here is evaluated with Kahan's difference of
//! products (one fused multiply-add), whose result is within 1.5 ulps of the
//! exact value: its sign is exact, so two triangles sharing an edge can never
//! both reject a ray through it. (The paper instead recomputes in f64 when an
//! edge function is zero; GPUs without f64 cannot.)
//!
//! ```
//! use glam::Vec3;
//! use treelet_core::geometry::triangle::{ray_triangle, Triangle, WatertightRay};
//! let tri = Triangle::new([0.0, 0.0, 5.0], [2.0, 0.0, 5.0], [0.0, 2.0, 5.0]);
//! // A ray through the vertex at the origin's corner still hits.
//! let ray = WatertightRay::new(Vec3::ZERO, Vec3::Z);
//! assert_eq!(ray_triangle(&ray, &tri, f32::MAX), 5.0);
//! ```
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::geometry::intersect::MISS;

/// A flat primitive spanned by three points: the triangle `v0 v1 v2`
/// ([`SHAPE_TRIANGLE`], what meshes are made of), or a disk or a
/// parallelogram on the same three points ([`SHAPE_DISK`],
/// [`SHAPE_PARALLELOGRAM`], see [`crate::geometry::flat`]). All share the
/// triangle's buffers, indices, normal `(v1 - v0) × (v2 - v0)` and frame,
/// so a scene's disk lamps and rectangular walls cost no binding of their
/// own. repr(C), Pod, 48 bytes (16-byte rows).
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Triangle {
    pub v0: [f32; 3],
    /// [`SHAPE_TRIANGLE`] (0, as [`Triangle::new`] sets it), [`SHAPE_DISK`]
    /// or [`SHAPE_PARALLELOGRAM`]. An engine that fills triangle buffers
    /// itself leaves this word 0 (the host's checks refuse other values).
    pub shape: u32,
    pub v1: [f32; 3],
    pub _pad1: u32,
    pub v2: [f32; 3],
    pub _pad2: u32,
}
const _: () = assert!(core::mem::size_of::<Triangle>() == 48);

/// [`Triangle::shape`] of a triangle.
pub const SHAPE_TRIANGLE: u32 = 0;
/// [`Triangle::shape`] of a disk (or ellipse): centre `v0`, semi-axes
/// `v1 - v0` and `v2 - v0`.
pub const SHAPE_DISK: u32 = 1;
/// [`Triangle::shape`] of a parallelogram: corner `v0`, edges `v1 - v0`
/// and `v2 - v0`.
pub const SHAPE_PARALLELOGRAM: u32 = 2;

impl Triangle {
    pub const fn new(v0: [f32; 3], v1: [f32; 3], v2: [f32; 3]) -> Self {
        Self { v0, shape: SHAPE_TRIANGLE, v1, _pad1: 0, v2, _pad2: 0 }
    }

    /// Whether this is a triangle (not another flat shape).
    #[inline]
    pub fn is_triangle(&self) -> bool {
        self.shape == SHAPE_TRIANGLE
    }

    // `aabb` and `area`, which depend on the shape, are with the shapes
    // (`crate::geometry::flat`).
}

/// `a * b - c * d` within 1.5 ulps (W. Kahan), so its sign is exact, and
/// exactly 0 when the two products are equal.
#[inline]
pub fn difference_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    let cd = c * d;
    let error = libm::fmaf(-c, d, cd);
    libm::fmaf(a, b, -cd) + error
}

/// The per-ray constants of the watertight test: the origin, the axes
/// permuted so that the largest direction component is the third, and the
/// shear that maps the direction to (0, 0, 1).
#[derive(Clone, Copy)]
pub struct WatertightRay {
    pub origin: [f32; 3],
    /// Axis indices (x, y, z) of the sheared frame, two bits each (one
    /// register instead of three, in kernels that keep it all along).
    pub axes: u32,
    /// Shear constants: `d[kx] / d[kz]`, `d[ky] / d[kz]`, `1 / d[kz]`.
    pub shear: [f32; 3],
}

impl WatertightRay {
    /// The constants for a ray from `origin` along `dir` (any length, not zero).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let d = dir.to_array();
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = if kz == 2 { 0 } else { kz + 1 };
        let mut ky = if kx == 2 { 0 } else { kx + 1 };
        // Keep the frame's winding when the ray points down its z axis.
        if pick(d, kz) < 0.0 {
            core::mem::swap(&mut kx, &mut ky);
        }
        let inv = 1.0 / pick(d, kz);
        let axes = (kx | ky << 2 | kz << 4) as u32;
        WatertightRay { origin: origin.to_array(), axes, shear: [pick(d, kx) * inv, pick(d, ky) * inv, inv] }
    }
}

/// `v[k]` by selects: a GPU keeps an array indexed at run time in slow
/// local memory.
#[inline]
fn pick(v: [f32; 3], k: usize) -> f32 {
    if k == 0 {
        v[0]
    } else if k == 1 {
        v[1]
    } else {
        v[2]
    }
}

/// Distance (in units of the ray direction's length) to the hit with `tri`
/// beyond 0 and up to `t_max` (inclusive, so that a tie with the closest
/// hit so far can go to the lower index), or [`MISS`]. Both faces are hit; a
/// triangle whose area seen from the ray computes to zero (degenerate, or
/// seen edge-on) is never hit.
#[inline]
pub fn ray_triangle(ray: &WatertightRay, tri: &Triangle, t_max: f32) -> f32 {
    ray_triangle_barycentrics(ray, tri, t_max).0
}

/// [`ray_triangle`] with the hit's barycentric coordinates: `(t, b1, b2)`,
/// the hit point being `(1 - b1 - b2) v0 + b1 v1 + b2 v2` (both 0 on a miss).
#[inline]
pub fn ray_triangle_barycentrics(ray: &WatertightRay, tri: &Triangle, t_max: f32) -> (f32, f32, f32) {
    let (kx, ky, kz) = ((ray.axes & 3) as usize, (ray.axes >> 2 & 3) as usize, (ray.axes >> 4) as usize);
    let [sx, sy, sz] = ray.shear;
    let o = ray.origin;
    // Vertices relative to the origin, sheared into the ray's frame.
    let a = [tri.v0[0] - o[0], tri.v0[1] - o[1], tri.v0[2] - o[2]];
    let b = [tri.v1[0] - o[0], tri.v1[1] - o[1], tri.v1[2] - o[2]];
    let c = [tri.v2[0] - o[0], tri.v2[1] - o[1], tri.v2[2] - o[2]];
    let (az, bz, cz) = (pick(a, kz), pick(b, kz), pick(c, kz));
    let (ax, ay) = (pick(a, kx) - sx * az, pick(a, ky) - sy * az);
    let (bx, by) = (pick(b, kx) - sx * bz, pick(b, ky) - sy * bz);
    let (cx, cy) = (pick(c, kx) - sx * cz, pick(c, ky) - sy * cz);
    // Scaled barycentrics (of v0, v1, v2): the signed areas seen from the ray.
    let u = difference_of_products(cx, by, cy, bx);
    let v = difference_of_products(ax, cy, ay, cx);
    let w = difference_of_products(bx, ay, by, ax);
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return (MISS, 0.0, 0.0);
    }
    let det = u + v + w;
    if det == 0.0 {
        return (MISS, 0.0, 0.0);
    }
    let t_scaled = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
    let t = t_scaled / det;
    if t > 0.0 && t <= t_max {
        (t, v / det, w / det)
    } else {
        (MISS, 0.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::gpu::rng::BounceRng;
    use std::vec::Vec;

    /// Reference hit distance in f64 (Möller–Trumbore) and the smallest
    /// barycentric coordinate, or None when the ray misses the plane.
    fn reference(o: [f64; 3], d: [f64; 3], t: &Triangle) -> Option<(f64, f64)> {
        let v = |p: [f32; 3]| [p[0] as f64, p[1] as f64, p[2] as f64];
        let (p0, p1, p2) = (v(t.v0), v(t.v1), v(t.v2));
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (e1, e2) = (sub(p1, p0), sub(p2, p0));
        let p = cross(d, e2);
        let det = dot(e1, p);
        // Grazing rays (under ~6 degrees to the plane) are ill-conditioned
        // for any method: the comparison is about precision, so skip them.
        let n = cross(e1, e2);
        if det == 0.0 || det.abs() < 0.1 * dot(n, n).sqrt() * dot(d, d).sqrt() {
            return None;
        }
        let s = sub(o, p0);
        let bu = dot(s, p) / det;
        let q = cross(s, e1);
        let bv = dot(d, q) / det;
        let t = dot(e2, q) / det;
        Some((t, bu.min(bv).min(1.0 - bu - bv)))
    }

    fn random_vec(r: &BounceRng, k: u32) -> Vec3 {
        Vec3::new(r.uniform(k), r.uniform(k + 1), r.uniform(k + 2)) * 2.0 - 1.0
    }

    /// Random triangles at `offset` scaled by `scale`, rays from a point near
    /// them aimed inside: worst relative hit-distance error against f64.
    fn worst_error(offset: f32, scale: f32, needle: bool) -> f64 {
        let mut worst = 0.0f64;
        let mut hits = 0;
        for i in 0..20_000u32 {
            let r = BounceRng::new(91, i, 0, 0);
            let base = Vec3::splat(offset);
            let mut p = [random_vec(&r, 0), random_vec(&r, 3), random_vec(&r, 6)];
            if needle {
                // Aspect ratio about 1e6: the third vertex almost on the first edge.
                p[2] = p[0] + (p[1] - p[0]) * 0.5 + random_vec(&r, 9) * 1e-6;
            }
            let tri = Triangle::new(
                (base + p[0] * scale).to_array(),
                (base + p[1] * scale).to_array(),
                (base + p[2] * scale).to_array(),
            );
            // Aim at a random interior point from 3 scale-lengths away.
            let (b0, b1) = (r.uniform(12), r.uniform(13));
            let (b0, b1) = if b0 + b1 > 1.0 { (1.0 - b0, 1.0 - b1) } else { (b0, b1) };
            let target = base + (p[0] + (p[1] - p[0]) * b0 + (p[2] - p[0]) * b1) * scale;
            let o = target + random_vec(&r, 14).normalize_or(Vec3::X) * 3.0 * scale;
            let d = (target - o).normalize();
            let f = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
            let Some((t_ref, margin)) = reference(f(o), f(d), &tri) else { continue };
            if margin < 1e-3 || t_ref <= 0.0 {
                continue; // too close to an edge for the comparison to be about precision
            }
            let t = ray_triangle(&WatertightRay::new(o, d), &tri, MISS);
            if needle && t == MISS {
                // A needle's interior is ~1e-6 wide: a point 1e-3 of it from
                // an edge is within f32 rounding of the edge, so a miss is fair.
                continue;
            }
            assert!(t != MISS, "offset {offset} scale {scale}: missed an interior hit (margin {margin})");
            worst = worst.max(((t as f64) - t_ref).abs() / t_ref);
            hits += 1;
        }
        assert!(hits > 1000, "only {hits} comparable hits");
        worst
    }

    #[test]
    fn hit_distance_matches_f64() {
        for (offset, scale, needle, bound) in [
            (0.0f32, 1.0f32, false, 1e-5),
            (1e6, 1.0, false, 1e-5),
            (0.0, 1e-4, false, 1e-5),
            (1e3, 1e-3, false, 1e-5),
            (0.0, 1.0, true, 1e-5),
        ] {
            let e = worst_error(offset, scale, needle);
            std::eprintln!("offset {offset:e}, scale {scale:e}, needles {needle}: worst relative hit-distance error {e:.2e}");
            assert!(e < bound, "offset {offset} scale {scale}: {e}");
        }
    }

    #[test]
    fn needles_and_degenerate_triangles_never_crash() {
        // Needles (aspect ~1e6): hits, when found, are finite and positive.
        for i in 0..2000u32 {
            let r = BounceRng::new(5, i, 0, 0);
            let (a, b) = (random_vec(&r, 0), random_vec(&r, 3));
            let tri = Triangle::new(a.to_array(), b.to_array(), (a + (b - a) * 0.5 + Vec3::Z * 1e-6).to_array());
            let o = random_vec(&r, 6) * 5.0;
            let t = ray_triangle(&WatertightRay::new(o, (a + b) * 0.5 - o), &tri, MISS);
            assert!(t == MISS || (t.is_finite() && t > 0.0));
        }
        // Zero area: a point, a segment, collinear vertices.
        let degenerate = [
            Triangle::new([1.0; 3], [1.0; 3], [1.0; 3]),
            Triangle::new([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, 1.0]),
            Triangle::new([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [2.0, 0.0, 1.0]),
        ];
        for tri in &degenerate {
            for d in [Vec3::Z, Vec3::new(0.5, 0.0, 1.0), Vec3::ONE] {
                assert_eq!(ray_triangle(&WatertightRay::new(Vec3::ZERO, d), tri, MISS), MISS);
            }
        }
    }

    /// A closed mesh: the surface of a cube, each face an n x n grid of
    /// quads split into two triangles, vertices shared exactly.
    fn cube_mesh(n: usize, center: Vec3, half: f32) -> Vec<Triangle> {
        let mut tris = Vec::new();
        for axis in 0..3 {
            for side in [-1.0f32, 1.0] {
                let point = |i: usize, j: usize| {
                    let (u, v) = (i as f32 / n as f32 * 2.0 - 1.0, j as f32 / n as f32 * 2.0 - 1.0);
                    let mut p = [0.0f32; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    (center + Vec3::from_array(p) * half).to_array()
                };
                for i in 0..n {
                    for j in 0..n {
                        let (a, b, c, d) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
                        tris.push(Triangle::new(a, b, c));
                        tris.push(Triangle::new(a, c, d));
                    }
                }
            }
        }
        tris
    }

    fn hits_any(o: Vec3, d: Vec3, tris: &[Triangle]) -> bool {
        let ray = WatertightRay::new(o, d);
        tris.iter().any(|t| ray_triangle(&ray, t, MISS) != MISS)
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_never_slip_through() {
        for (center, half) in [(Vec3::ZERO, 1.0f32), (Vec3::splat(1e5), 3.0), (Vec3::new(0.3, -7.0, 2.0), 1e-3)] {
            let mesh = cube_mesh(4, center, half);
            // Every vertex and every edge midpoint of the mesh, aimed at from
            // inside (the centre and an off-centre point) and from outside.
            let mut targets = Vec::new();
            for t in &mesh {
                let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
                targets.extend([a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
            }
            let origins = [center, center + Vec3::new(0.31, -0.17, 0.23) * half];
            let mut rays = 0;
            for &target in &targets {
                for &o in &origins {
                    assert!(hits_any(o, target - o, &mesh), "centre {center}: ray from {o} to {target} slipped through");
                    rays += 1;
                }
                // From outside, through the target and on into the cube.
                let o = center + (target - center) * 3.0 + Vec3::new(0.01, 0.02, -0.015) * half;
                assert!(hits_any(o, target - o, &mesh), "centre {center}: ray from outside to {target} slipped through");
            }
            assert!(rays > 1000);
        }
    }

    #[test]
    fn axis_aligned_rays_hit() {
        // Rays along each axis (two zero direction components) through a
        // grid's vertices, edges and cell centres.
        let mesh = cube_mesh(3, Vec3::ZERO, 1.0);
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut d = [0.0f32; 3];
                d[axis] = sign;
                for i in 0..=12 {
                    for j in 0..=12 {
                        let (u, v) = (i as f32 / 6.0 - 1.0, j as f32 / 6.0 - 1.0);
                        let mut o = [0.0f32; 3];
                        o[axis] = -5.0 * sign;
                        o[(axis + 1) % 3] = u;
                        o[(axis + 2) % 3] = v;
                        let o = Vec3::from_array(o);
                        assert!(hits_any(o, Vec3::from_array(d), &mesh), "axis ray from {o} along {d:?} missed");
                    }
                }
            }
        }
    }
}
