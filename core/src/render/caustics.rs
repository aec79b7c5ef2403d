//! Light paths for the caustics next-event estimation cannot find: light
//! focused by mirrors and glass onto diffuse surfaces (the glass ball's
//! bright spot on the floor). A camera path finds such light only where its
//! diffuse bounce happens to reach the lamp through the glass, and a shadow
//! ray cannot follow a refraction, so that spot stays noisy at any sample
//! count. Traced from the lamp the other way, the same light lands where
//! the glass sends it: light tracing (particle tracing; Veach 1997, 10.2;
//! the `s >= 1, t = 1` strategies of pbrt-v4's `bdpt`).
//!
//! The two estimators split path space instead of weighting each other:
//! from the lamp, one or more mirror or glass bounces, then one or more
//! diffuse points, the last seen by the camera, are the light paths'; camera
//! paths drop exactly those (see [`crate::render::integrator::Path`]). Each
//! part of the image then comes from one estimator, unbiased either way.
//! (Diffuse bounces after the caustic carry its light on: the room's walls
//! lit by the glass ball's spot, which camera paths find only by a diffuse
//! bounce that happens to reach the lamp through the glass.)
//!
//! One light path is traced per camera path (per pixel and sample), so that
//! the light paths' estimate, `1 / (width x height x spp)` of their sum,
//! adds to the pixel sums with the camera's weight `1 / spp`; a path lands
//! in the pixel its point projects to, weighted by the tent filter of its
//! sample's subpixel (as [`Camera::primary_ray`] draws it), so that each
//! sample of a pixel estimates the same filtered value either way.
//! Landings are added with atomics into a buffer of their own, which the
//! host adds to the sums it reads.
use glam::Vec3;

use crate::geometry::buffers::{Camera, DIFFUSE, MIRROR, RenderParams};
use crate::geometry::features::{self, has};
use crate::geometry::intersect::surface_offset;
use crate::geometry::prims::Origin;
use crate::gpu::atomics;
use crate::render::integrator::{MAX_BOUNCES, SceneRefs, glass_bounce, hit_normal_for, surface, trace};
use crate::render::lights::{Light, select_light};
use crate::render::sampler::BounceSamples;
use crate::render::sampling::{cosine_direction, sin_cos_turns};
use crate::trace::hit::{ClosestHit, Query};

/// Keeps light paths' random numbers apart from camera paths' (the same
/// pixel and sample numbers key both).
const LIGHT_STREAM: u32 = 0x6c69_6768;

/// Where light paths land: words of f32 bits, [`SPLAT_WORDS`] a pixel,
/// added to from any invocation. The GPU adds into its buffer with
/// atomics; the CPU runner's threads share atomics of their own.
pub trait Landings {
    fn add(&mut self, word: usize, value: f32);
}

impl Landings for [u32] {
    #[inline]
    fn add(&mut self, word: usize, value: f32) {
        atomics::add_f32_device(&mut self[word], value);
    }
}

/// Words of the landing buffer per pixel: red, green, blue and one unused,
/// as the pixel sums are laid out.
pub const SPLAT_WORDS: u32 = 4;

/// Kernel body (one invocation per pixel, as [`crate::render::integrator::render_pixel`]):
/// `params.samples` light paths, keyed by pixel `id` and sample, each
/// adding what it carries to the camera into `splats` (f32 bits,
/// [`SPLAT_WORDS`] a pixel). Nothing without [`features::CAUSTICS`] in
/// `F` (the host runs it on scenes with mirrors or glass), or without lights.
#[inline]
pub fn light_paths<T: ClosestHit, const F: u32, const S: usize, L: Landings + ?Sized>(
    id: u32,
    params: &RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
    splats: &mut L,
    stack: &mut [u32; S],
    lane: u32,
) {
    // A constant of the instance, not a call: rustc's collector then leaves
    // the light path out of every kernel without light paths (the shader
    // crate makes a light entry point for every variant), which saves the
    // shader build memory.
    if const { !has(F, features::CAUSTICS) } {
        return;
    }
    if params.light_count == 0 {
        return;
    }
    for s in 0..params.samples {
        light_path::<T, F, S, L>(id, params.first_sample + s, params, scene, lights, splats, stack, lane);
    }
}

/// One light path: from a point on a light chosen by power, a cosine-
/// weighted direction, through one or more mirror and glass bounces, then
/// diffuse bounces, each diffuse point linked to the camera; it ends at
/// the first diffuse point if it met no mirror or glass before (next-event
/// estimation finds that light), and at a mirror or glass after a diffuse
/// point (camera paths find those).
#[inline]
#[allow(clippy::too_many_arguments)]
fn light_path<T: ClosestHit, const F: u32, const S: usize, L: Landings + ?Sized>(
    id: u32,
    sample: u32,
    params: &RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
    splats: &mut L,
    stack: &mut [u32; S],
    lane: u32,
) {
    let seed = params.seed ^ LIGHT_STREAM;
    let rng = BounceSamples::new::<F>(params, seed, id, sample, 0);
    let light = lights[select_light(lights, params.light_count, rng.single(0)) as usize];
    let prims = &scene.prims;
    // A point uniformly on the emitter, and the normal it emits along. A
    // flat emitter lights both sides (as camera paths see it): one is drawn.
    let (y, n, area_over_pdf) = if prims.is_sphere::<F>(light.prim) {
        let s = prims.spheres[light.prim as usize];
        let (u1, u2) = rng.pair(1);
        let z = 1.0 - 2.0 * u1;
        let r = libm::sqrtf((1.0 - z * z).max(0.0));
        let (sp, cp) = sin_cos_turns(u2);
        let n = Vec3::new(r * cp, r * sp, z);
        let area = 4.0 * core::f32::consts::PI * s.radius * s.radius;
        (Vec3::from_array(s.center) + n * s.radius, n, area)
    } else {
        let t = prims.triangle(light.prim - prims.sphere_count);
        let (u1, u2) = rng.pair(1);
        let y = crate::geometry::flat::flat_point(&t, u1, u2, sin_cos_turns);
        let n = hit_normal_for::<F>(prims, light.prim, y, Vec3::Z);
        let n = if rng.single(3) < 0.5 { n } else { -n };
        (y, n, 2.0 * t.area())
    };
    // Emitted radiance times cos / (density of the point and direction):
    // the cosine-weighted direction's density cos/π leaves π.
    let emission = Vec3::from_array(scene.materials[light.prim as usize].emission);
    let mut power = emission * (core::f32::consts::PI * area_over_pdf / light.pmf);
    let (u4, u5) = rng.pair(4);
    let mut d = cosine_direction(n, u4, u5);
    let mut o = y + n * surface_offset(y);
    let outward = hit_normal_for::<F>(prims, light.prim, y, d);
    let mut from = Origin { prim: light.prim, into: d.dot(outward) < 0.0 };
    let mut bounces = 0;
    // Past the caustic's mirror and glass bounces, at a diffuse point.
    let mut diffuse = false;
    while bounces < MAX_BOUNCES {
        let hit = trace::<T, F, S>(o, d, from, Query::CLOSEST, scene, stack, lane);
        if !hit.is_hit() {
            return;
        }
        let x = o + d * hit.t;
        // A placed copy's triangle too (`crate::trace::with_instances`).
        let (m, n) = surface::<T, F>(scene, hit.prim, x, d);
        let nl = if n.dot(d) < 0.0 { n } else { -n };
        if m.kind == DIFFUSE && bounces == 0 {
            return; // Not a caustic: next-event estimation's.
        }
        if m.kind != DIFFUSE && diffuse {
            return; // A mirror or glass after the caustic: camera paths'.
        }
        bounces += 1;
        let rng = BounceSamples::new::<F>(params, seed, id, sample, bounces);
        let eps = surface_offset(x);
        if m.kind == DIFFUSE {
            // The caustic's light, and its diffuse bounces, seen by the camera.
            let albedo = Vec3::from_array(m.color);
            to_camera::<T, F, S, L>(x, n, nl, hit.prim, power * albedo * core::f32::consts::FRAC_1_PI, sample, params, scene, splats, stack, lane);
            diffuse = true;
            power *= albedo;
            let (u2, u3) = rng.pair(2);
            d = cosine_direction(nl, u2, u3);
            o = x + nl * eps;
        } else if has(F, features::MIRROR) && m.kind == MIRROR {
            power *= Vec3::from_array(m.color);
            d = d - n * 2.0 * n.dot(d);
            o = x + nl * eps;
        } else {
            power *= Vec3::from_array(m.color);
            let b = glass_bounce(d, n, nl, m.ior, rng.single(0));
            // Light crossing into a denser medium spreads its flux over
            // more solid angle: camera paths (smallpt's) carry radiance
            // unscaled through a refraction, so the light's flux takes the
            // adjoint's factor (eta_from / eta_to)² (Veach 1997, 5.2).
            power *= if b.refracted { b.weight * b.eta * b.eta } else { b.weight };
            d = b.d;
            o = if b.refracted { x - nl * eps } else { x + nl * eps };
        }
        from = Origin { prim: hit.prim, into: d.dot(n) < 0.0 };
        // Roulette on what is left of the light's power after a few
        // bounces (rays inside glass can bounce long).
        if bounces >= 3 {
            let p = power.max_element() / (emission.max_element() * core::f32::consts::PI * area_over_pdf / light.pmf);
            if p < 1.0 {
                if rng.single(1) < p {
                    power /= p;
                } else {
                    return;
                }
            }
        }
    }
}

/// Links diffuse point `x` (of primitive `prim`, outward normal `n`, `nl`
/// facing where the light came from), reflecting `radiance_factor` (the
/// light's power times the BRDF) towards the camera, to the pixel it
/// projects to, if the camera sees it.
#[inline]
#[allow(clippy::too_many_arguments)]
fn to_camera<T: ClosestHit, const F: u32, const S: usize, L: Landings + ?Sized>(
    x: Vec3,
    n: Vec3,
    nl: Vec3,
    prim: u32,
    radiance_factor: Vec3,
    sample: u32,
    params: &RenderParams,
    scene: &SceneRefs<T>,
    splats: &mut L,
    stack: &mut [u32; S],
    lane: u32,
) {
    let cam = &params.camera;
    let to = Vec3::from_array(cam.origin) - x;
    let d2 = to.length_squared();
    let dist = libm::sqrtf(d2);
    let wc = to / dist;
    let cos_x = nl.dot(wc);
    if !(cos_x > 0.0) {
        return; // The camera is on the other side.
    }
    let Some(land) = landing(cam, -wc, sample, params.width, params.height) else { return };
    // Camera rays start `near` along their unnormalized direction.
    let t_max = dist - cam.near / land.cos;
    if !(t_max > 0.0) {
        return;
    }
    let eps = surface_offset(x);
    let from = Origin { prim, into: wc.dot(n) < 0.0 };
    let query = if T::OCCLUSION_STOPS_EARLY { Query::occlusion(t_max, u32::MAX) } else { Query::CLOSEST };
    let hit = trace::<T, F, S>(x + nl * eps, wc, from, query, scene, stack, lane);
    if hit.is_hit() && hit.t <= t_max {
        return;
    }
    // Importance of a pinhole on the image plane at unit distance: a pixel's
    // solid angle per unit of its filter is cos³θ |cx| |cy| / (w h); the
    // w h cancels against the number of light paths (see the module).
    let (cx, cy) = (Vec3::from_array(cam.cx).length(), Vec3::from_array(cam.cy).length());
    let c3 = land.cos * land.cos * land.cos;
    let value = radiance_factor * (cos_x / d2 * land.weight / (c3 * cx * cy));
    let base = (land.pixel * SPLAT_WORDS) as usize;
    splats.add(base, value.x);
    splats.add(base + 1, value.y);
    splats.add(base + 2, value.z);
}

/// Where a direction `v` from the camera lands: the pixel (row-major from
/// the top row) whose subpixel filter for sample `sample` covers it, that
/// filter's weight there, and the cosine to the camera's axis.
#[derive(Clone, Copy, Debug)]
pub struct Landing {
    pub pixel: u32,
    pub weight: f32,
    pub cos: f32,
}

/// [`Landing`] of direction `v` (unit) for a `width x height` image, or
/// none outside it. The inverse of [`Camera::primary_ray`]: that draws
/// image-plane coordinates `x + 1/4 + sx/2 + dx/2` with `dx` from a tent on
/// (-1, 1), so pixel `x` of subpixel column `sx` covers one pixel width
/// centred there with density `2 (1 - 2 |v|)`.
#[inline]
pub fn landing(cam: &Camera, v: Vec3, sample: u32, width: u32, height: u32) -> Option<Landing> {
    let (dir, cx, cy) = (Vec3::from_array(cam.dir), Vec3::from_array(cam.cx), Vec3::from_array(cam.cy));
    let cos = v.dot(dir);
    if !(cos > 0.0) {
        return None;
    }
    let p = v / cos;
    let u = (p.dot(cx) / cx.length_squared() + 0.5) * width as f32;
    let w = (p.dot(cy) / cy.length_squared() + 0.5) * height as f32;
    let sub = sample % 4;
    let (cu, cw) = (0.25 + 0.5 * (sub % 2) as f32, 0.25 + 0.5 * (sub / 2) as f32);
    // The one pixel whose centre `x + c` is within half a pixel of `u`.
    let (fx, fy) = (libm::floorf(u - cu + 0.5), libm::floorf(w - cw + 0.5));
    if !(fx >= 0.0 && fx < width as f32 && fy >= 0.0 && fy < height as f32) {
        return None;
    }
    let tent = |v: f32| (2.0 * (1.0 - 2.0 * v.abs())).max(0.0);
    let weight = tent(u - fx - cu) * tent(w - fy - cw);
    let (x, y) = (fx as u32, fy as u32);
    Some(Landing { pixel: (height - 1 - y) * width + x, weight, cos })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::rng::BounceRng;

    /// A camera ray drawn for a pixel and sample lands back in that pixel,
    /// with a positive weight.
    #[test]
    fn camera_rays_land_in_their_own_pixel() {
        let (w, h) = (37u32, 23u32);
        let cam = Camera::look(Vec3::new(50.0, 52.0, 295.6), Vec3::new(0.0, -0.042612, -1.0), 140.0, 0.5135, w, h);
        for pixel in 0..w * h {
            for sample in 0..8 {
                let (x, y) = (pixel % w, h - 1 - pixel / w);
                let rng = BounceRng::new(3, pixel, sample, 0);
                let (_, d) = cam.primary_ray(x, y, sample % 4, w, h, (rng.uniform(0), rng.uniform(1)));
                let l = landing(&cam, d, sample, w, h).expect("lands");
                assert_eq!(l.pixel, pixel, "sample {sample}");
                assert!(l.weight > 0.0 && l.weight <= 4.0);
            }
        }
    }

    /// The filter weights of one subpixel integrate to one pixel: the
    /// mean weight over a pixel-sized grid of image-plane points is 1.
    #[test]
    fn landing_weights_integrate_to_one() {
        let (w, h) = (16u32, 12u32);
        let cam = Camera::look(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 0.0, 0.5, w, h);
        let (cx, cy, dir) = (Vec3::from_array(cam.cx), Vec3::from_array(cam.cy), Vec3::from_array(cam.dir));
        for sample in 0..4 {
            let mut sums = [0.0f64; 16 * 12];
            let k = 64;
            for i in 0..w * k {
                for j in 0..h * k {
                    let fx = (i as f32 + 0.5) / (w * k) as f32 - 0.5;
                    let fy = (j as f32 + 0.5) / (h * k) as f32 - 0.5;
                    let v = (dir + cx * fx + cy * fy).normalize();
                    if let Some(l) = landing(&cam, v, sample, w, h) {
                        sums[l.pixel as usize] += l.weight as f64 / (k * k) as f64;
                    }
                }
            }
            // Pixels away from the border (whose filters reach past it).
            for y in 1..h - 1 {
                for x in 1..w - 1 {
                    let s = sums[(y * w + x) as usize];
                    assert!((s - 1.0).abs() < 1e-2, "sample {sample}, pixel ({x}, {y}): {s}");
                }
            }
        }
    }
}
