//! Light sampling for next-event estimation (Veach 1997, chapter 9; the
//! design of pbrt-v4's path integrator): at a diffuse bounce a point is
//! chosen on an emitter, a shadow ray is cast to it through the same tree,
//! and the result is weighted against the BSDF-sampled path by the power
//! heuristic, so that each of the two strategies counts where it is good.
//!
//! Emitters are the primitives whose emission is not black, each chosen with
//! probability proportional to its power (luminance times area), from a
//! table the host builds once per scene ([`Light`], sorted by primitive).
//! Spheres are sampled by the solid angle of the cone they subtend, as
//! smallpt's "explicit" variant does; triangles, disks and parallelograms
//! uniformly by area (a disk lamp as one shape, not a fan of triangles). Either
//! way the density is expressed per unit solid angle at the shading point.
use glam::Vec3;

use crate::geometry::buffers::{Material, Sphere};
use crate::geometry::prims::Prims;
use crate::geometry::triangle::Triangle;
use crate::render::sampling::{luminance, sin_cos_turns};

/// One emitter of the light table. repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Light {
    /// The primitive (spheres first, then triangles, as in the scene).
    pub prim: u32,
    /// Probability of choosing this light.
    pub pmf: f32,
    /// Probability of choosing this light or one before it (the last is 1).
    pub cdf: f32,
    pub _pad: u32,
}
const _: () = assert!(core::mem::size_of::<Light>() == 16);

/// Power of primitive `prim` as a light (luminance of its emission times
/// its area; a sphere's whole surface emits), 0 for non-emitters. What the
/// host's light table is proportional to.
pub fn light_power(prims: &Prims, materials: &[Material], prim: u32) -> f32 {
    let e = luminance(Vec3::from_array(materials[prim as usize].emission));
    if !(e > 0.0) {
        return 0.0;
    }
    let area = if prim < prims.sphere_count {
        let r = prims.spheres[prim as usize].radius;
        4.0 * core::f32::consts::PI * r * r
    } else {
        prims.triangle(prim - prims.sphere_count).area()
    };
    e * area
}

/// Index of the light `u` in `[0, 1)` selects: the first whose `cdf`
/// exceeds `u` (binary search).
#[inline]
pub fn select_light(lights: &[Light], count: u32, u: f32) -> u32 {
    let (mut lo, mut hi) = (0u32, count - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if lights[mid as usize].cdf > u {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// Probability of choosing primitive `prim` as a light (0 if it is none).
#[inline]
pub fn light_pmf(lights: &[Light], count: u32, prim: u32) -> f32 {
    let (mut lo, mut hi) = (0u32, count);
    while lo < hi {
        let mid = (lo + hi) / 2;
        let p = lights[mid as usize].prim;
        if p == prim {
            return lights[mid as usize].pmf;
        } else if p < prim {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    0.0
}

/// A direction towards a light and its density per unit solid angle (before
/// the choice of the light); `pdf == 0` where none could be drawn.
#[derive(Clone, Copy)]
pub struct LightSample {
    pub dir: Vec3,
    pub pdf: f32,
}

/// `1 - cos θmax` of the cone sphere `s` subtends from `x`, computed as
/// `sin² / (1 + cos)` so that a small or far sphere keeps its precision; 0
/// when `x` is inside (or on) the sphere, where no cone exists.
#[inline]
fn cone_width(s: &Sphere, x: Vec3) -> f32 {
    let to = Vec3::from_array(s.center) - x;
    let d2 = to.length_squared();
    let r2 = s.radius * s.radius;
    if d2 <= r2 * 1.000_01 {
        return 0.0;
    }
    let sin2 = r2 / d2;
    let cos = libm::sqrtf((1.0 - sin2).max(0.0));
    sin2 / (1.0 + cos)
}

/// Samples a direction from `x` towards primitive `prim` with the two
/// uniforms `u1`, `u2`.
#[inline]
pub fn sample_light(prims: &Prims, prim: u32, x: Vec3, u1: f32, u2: f32) -> LightSample {
    if prim < prims.sphere_count {
        let s = &prims.spheres[prim as usize];
        let width = cone_width(s, x);
        if !(width > 0.0) {
            return LightSample { dir: Vec3::Z, pdf: 0.0 };
        }
        // cos θ uniform in [cos θmax, 1]: 1 - cos θ = u1 * (1 - cos θmax).
        let one_minus_cos = u1 * width;
        let cos = 1.0 - one_minus_cos;
        let sin = libm::sqrtf((one_minus_cos * (2.0 - one_minus_cos)).max(0.0));
        let (sp, cp) = sin_cos_turns(u2);
        let w = (Vec3::from_array(s.center) - x).normalize();
        let u = (if w.x.abs() > 0.1 { Vec3::Y } else { Vec3::X }).cross(w).normalize();
        let v = w.cross(u);
        let dir = (u * (cp * sin) + v * (sp * sin) + w * cos).normalize();
        LightSample { dir, pdf: 1.0 / (2.0 * core::f32::consts::PI * width) }
    } else {
        let t = &prims.triangle(prim - prims.sphere_count);
        let y = crate::geometry::flat::flat_point(t, u1, u2, sin_cos_turns);
        let to = y - x;
        let d2 = to.length_squared();
        if !(d2 > 0.0) {
            return LightSample { dir: Vec3::Z, pdf: 0.0 };
        }
        let dir = to / libm::sqrtf(d2);
        LightSample { dir, pdf: triangle_pdf(t, dir, d2) }
    }
}

/// Density per unit solid angle of reaching a point at squared distance
/// `d2` in direction `dir` on flat primitive `t` by uniform area sampling.
#[inline]
fn triangle_pdf(t: &Triangle, dir: Vec3, d2: f32) -> f32 {
    let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
    let n = (b - a).cross(c - a);
    let parallelogram = n.length();
    let cos = (n.dot(dir) / parallelogram).abs();
    if !(parallelogram > 0.0) || !(cos > 0.0) {
        return 0.0;
    }
    d2 / (parallelogram * crate::geometry::flat::area_factor(t.shape) * cos)
}

/// Density per unit solid angle with which [`sample_light`] from `x` would
/// have drawn the direction `dir` that hit primitive `prim` at distance `t`.
#[inline]
pub fn light_pdf(prims: &Prims, prim: u32, x: Vec3, dir: Vec3, t: f32) -> f32 {
    if prim < prims.sphere_count {
        let width = cone_width(&prims.spheres[prim as usize], x);
        if width > 0.0 {
            1.0 / (2.0 * core::f32::consts::PI * width)
        } else {
            0.0
        }
    } else {
        triangle_pdf(&prims.triangle(prim - prims.sphere_count), dir, t * t)
    }
}

/// Veach's power heuristic (β = 2): the weight of a sample drawn with
/// density `a` when `b` is the other strategy's density for it.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::rng::BounceRng;

    /// The mean of 1/pdf over samples is the solid angle the light
    /// subtends (each direction the cone or the triangle covers, once).
    #[test]
    fn inverse_pdf_integrates_to_the_solid_angle() {
        let spheres = [Sphere::new([0.0, 0.0, 10.0], 2.0)];
        // Behind the shading point, so that neither hides the other.
        let triangles = [
            Triangle::new([-1.0, -1.0, -5.0], [3.0, -1.0, -5.0], [-1.0, 2.0, -6.0]),
            Triangle::disk([4.0, 3.0, 1.0], [-1.0, -0.5, 0.3], 1.5),
            Triangle::parallelogram([-4.0, 2.0, 2.0], [0.5, 0.3, 2.0], [0.2, 1.5, -0.4]),
        ];
        let prims = Prims { spheres: &spheres, sphere_count: 1, triangles: crate::geometry::split::Split::whole(&triangles), triangle_count: 3 };
        let x = Vec3::new(0.3, -0.2, 0.0);
        // Sphere: 2π(1 - cos θmax).
        let d = Vec3::from_array(spheres[0].center) - x;
        let exact = 2.0 * core::f64::consts::PI * (1.0 - (1.0 - 4.0 / d.length_squared() as f64).sqrt());
        let n = 200_000;
        for prim in [0u32, 1, 2, 3] {
            let mut sum = 0.0f64;
            let mut hits = 0;
            for i in 0..n {
                let r = BounceRng::new(5, i, 0, 1);
                let s = sample_light(&prims, prim, x, r.uniform(4), r.uniform(5));
                assert!(s.pdf > 0.0 && (s.dir.length() - 1.0).abs() < 1e-5);
                sum += 1.0 / s.pdf as f64;
                // The direction reaches the light, and light_pdf agrees.
                let hit = crate::trace::classic::closest_hit_linear(x, s.dir, crate::geometry::prims::Origin::NONE, &prims);
                if hit.prim == prim {
                    hits += 1;
                    let p = light_pdf(&prims, prim, x, s.dir, hit.t);
                    assert!((p / s.pdf - 1.0).abs() < 2e-3, "prim {prim}: {p} against {}", s.pdf);
                }
            }
            assert!(hits as f64 > 0.99 * n as f64, "prim {prim}: {hits} of {n} samples reach it");
            let mean = sum / n as f64;
            if prim == 0 {
                assert!((mean / exact - 1.0).abs() < 1e-4, "sphere: {mean} against {exact}");
            } else if prim == 2 {
                // A solid angle by quadrature over the disk, in polar
                // coordinates (area element |e1 × e2| ρ dρ dφ).
                let t = &triangles[1];
                let (c, e1, e2) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1) - Vec3::from_array(t.v0), Vec3::from_array(t.v2) - Vec3::from_array(t.v0));
                let nrm = e1.cross(e2);
                let (mut omega, m) = (0.0f64, 400);
                for i in 0..m {
                    let rho = (i as f64 + 0.5) / m as f64;
                    for j in 0..4 * m {
                        let phi = (j as f64 + 0.5) / (4 * m) as f64 * core::f64::consts::TAU;
                        let y = c + e1 * (rho * libm::cos(phi)) as f32 + e2 * (rho * libm::sin(phi)) as f32;
                        let to = y - x;
                        let cos = (nrm.normalize().dot(to.normalize())).abs() as f64;
                        let da = nrm.length() as f64 * rho / m as f64 * core::f64::consts::TAU / (4 * m) as f64;
                        omega += da * cos / to.length_squared() as f64;
                    }
                }
                assert!((mean / omega - 1.0).abs() < 0.01, "disk: {mean} against {omega}");
            } else if prim == 3 {
                // A solid angle by the midpoint rule over the parallelogram.
                let t = &triangles[2];
                let (c, e1, e2) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1) - Vec3::from_array(t.v0), Vec3::from_array(t.v2) - Vec3::from_array(t.v0));
                let nrm = e1.cross(e2);
                let (mut omega, m) = (0.0f64, 400);
                let da = nrm.length() as f64 / (m * m) as f64;
                for i in 0..m {
                    for j in 0..m {
                        let y = c + e1 * ((i as f32 + 0.5) / m as f32) + e2 * ((j as f32 + 0.5) / m as f32);
                        let to = y - x;
                        omega += da * (nrm.normalize().dot(to.normalize())).abs() as f64 / to.length_squared() as f64;
                    }
                }
                assert!((mean / omega - 1.0).abs() < 0.01, "parallelogram: {mean} against {omega}");
            } else {
                // A solid angle by fine quadrature over the triangle.
                let t = &triangles[0];
                let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
                let (mut omega, m) = (0.0f64, 400);
                let nrm = (b - a).cross(c - a);
                let da = 0.5 * nrm.length() as f64 / (m * m) as f64;
                for i in 0..m {
                    for j in 0..m - i {
                        for (p, q) in [(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0), (i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0)] {
                            if p + q >= m as f64 {
                                continue;
                            }
                            let y = a + (b - a) * (p / m as f64) as f32 + (c - a) * (q / m as f64) as f32;
                            let to = y - x;
                            let cos = (nrm.normalize().dot(to.normalize())).abs() as f64;
                            omega += da * cos / to.length_squared() as f64;
                        }
                    }
                }
                assert!((mean / omega - 1.0).abs() < 0.01, "triangle: {mean} against {omega}");
            }
        }
    }

    #[test]
    fn selection_follows_the_table() {
        let lights = [
            Light { prim: 2, pmf: 0.25, cdf: 0.25, _pad: 0 },
            Light { prim: 7, pmf: 0.5, cdf: 0.75, _pad: 0 },
            Light { prim: 9, pmf: 0.25, cdf: 1.0, _pad: 0 },
        ];
        assert_eq!(select_light(&lights, 3, 0.0), 0);
        assert_eq!(select_light(&lights, 3, 0.2499), 0);
        assert_eq!(select_light(&lights, 3, 0.25), 1);
        assert_eq!(select_light(&lights, 3, 0.9999), 2);
        assert_eq!(light_pmf(&lights, 3, 7), 0.5);
        assert_eq!(light_pmf(&lights, 3, 9), 0.25);
        assert_eq!(light_pmf(&lights, 3, 3), 0.0);
        assert_eq!(power_heuristic(1.0, 0.0), 1.0);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert!((power_heuristic(1.0, 1.0) - 0.5).abs() < 1e-7);
    }
}
