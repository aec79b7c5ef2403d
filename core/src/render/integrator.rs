//! The path tracer of smallpt (Kevin Beason, "smallpt: Global Illumination
//! in 99 lines of C++"), iterative so that it runs on a GPU:
//!
//! * 2x2 subpixels per pixel with a tent filter; with independent numbers
//!   sample `s` of a pixel falls in subpixel `s % 4`, with Sobol points
//!   ([`crate::render::sampler`], the default) each run of four samples
//!   covers the four; `spp` counts all samples of the pixel;
//! * diffuse (cosine-weighted), mirror, and glass with Schlick's Fresnel;
//! * Russian roulette after depth 5 with the surface's largest reflectance
//!   (smallpt's estimator; next-event estimation uses pbrt-v4's rule, see
//!   [`NEE_ROULETTE_DEPTH`]).
//!
//! Departures from smallpt, all keeping the estimate unbiased unless said:
//! smallpt splits glass paths into reflection and refraction below depth 3;
//! a loop cannot recurse, so glass always picks one with probability
//! `P = 1/4 + Re/2` and weights it (smallpt's own rule at depth 3 and more).
//! A ray leaving a sphere ignores that sphere, or only takes its far side
//! when it heads into it ([`Origin`]), instead of smallpt's fixed 1e-4
//! epsilon, which no f32 epsilon could replace near 1e5-radius walls; the
//! origin is still pushed off the surface by a distance scaled to the
//! point's magnitude ([`crate::geometry::intersect::surface_offset`]) for the benefit of other, touching
//! surfaces. Paths stop after [`MAX_BOUNCES`] (a bias no render
//! has shown: Russian roulette ends them long before).
//! A path also ends where its throughput becomes zero (a black surface such
//! as smallpt's lamp or front wall), which changes no pixel's value.
//! Random numbers are counter-based ([`crate::gpu::rng`]), or Owen-scrambled
//! Sobol points keyed the same way ([`crate::render::sampler`]):
//! [`RenderParams::sampler`].
//!
//! `RenderParams::integrator` selects smallpt's estimator or next-event
//! estimation with multiple importance sampling (see [`radiance`] and
//! [`crate::render::lights`]); both converge to the same image.
use glam::Vec3;

use crate::geometry::buffers::{CAUSTICS, Camera, DIFFUSE, MIRROR, Material, NEE, RenderParams, Sphere};
use crate::geometry::features::{self, has};
use crate::geometry::intersect::{MISS, surface_offset};
use crate::geometry::split::Split;
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::triangle::{Triangle, WatertightRay};
use crate::gpu::rng::BounceRng;
use crate::render::lights::{Light, light_pdf, light_pmf, power_heuristic, sample_light, select_light};
use crate::render::sampler::{BounceSamples, PathSampler, uses_sobol};
use crate::render::sampling::{cosine_direction, luminance, sin_cos_turns};
use crate::trace::hit::{ClosestHit, Hit, Query};

/// Hard cap on path length.
pub const MAX_BOUNCES: u32 = 512;
/// Field of view of smallpt: the full height of the image plane at unit
/// distance (its rays span `-fov/2..fov/2` up and down: 28.8 degrees).
pub const SMALLPT_FOV: f32 = 0.5135;

impl Camera {
    /// A camera at `origin` looking along `dir`, `fov` being the full height
    /// of the image plane at unit distance, `2 tan(vertical angle / 2)`
    /// (smallpt: 0.5135). "Up" is +y.
    pub fn look(origin: Vec3, dir: Vec3, near: f32, fov: f32, width: u32, height: u32) -> Camera {
        let dir = dir.normalize();
        let side = if dir.cross(Vec3::Y).length_squared() > 1e-12 { dir.cross(Vec3::Y) } else { Vec3::X };
        let cx = side.normalize() * (width as f32 * fov / height as f32);
        let cy = cx.cross(dir).normalize() * fov;
        Camera {
            origin: origin.to_array(),
            near,
            dir: dir.to_array(),
            cx: cx.to_array(),
            cy: cy.to_array(),
            ..Default::default()
        }
    }

    /// Ray through pixel (`x`, `y`; y up from the bottom row, as smallpt),
    /// subpixel `sub` (0..4), with the tent-filter offsets drawn from the
    /// uniform numbers `u`, from the pinhole at `origin` (the lens is
    /// [`Camera::lens_ray`]'s).
    #[inline]
    pub fn primary_ray(&self, x: u32, y: u32, sub: u32, width: u32, height: u32, u: (f32, f32)) -> (Vec3, Vec3) {
        let d = self.image_plane(x, y, sub, width, height, u);
        (Vec3::from_array(self.origin) + d * self.near, d.normalize())
    }

    /// [`Camera::primary_ray`] through the thin lens: from the point of the
    /// lens disk (radius `lens_radius`, across `cx` and `cy`) that the
    /// uniform numbers `lens` pick (Shirley and Chiu's concentric map), to
    /// where the pinhole's ray meets the plane in focus, `focus_distance`
    /// along `dir` (pbrt-v4's `PerspectiveCamera`). Points on that plane
    /// stay sharp; nearer and farther ones blur.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn lens_ray(&self, x: u32, y: u32, sub: u32, width: u32, height: u32, u: (f32, f32), lens: (f32, f32)) -> (Vec3, Vec3) {
        let d = self.image_plane(x, y, sub, width, height, u);
        let (lx, ly) = concentric_disk(lens.0, lens.1);
        let offset = (Vec3::from_array(self.cx).normalize() * lx + Vec3::from_array(self.cy).normalize() * ly) * self.lens_radius;
        // `d` has unit length along `dir` (`cx` and `cy` are across it): the
        // pinhole's ray meets the plane in focus at `focus_distance * d`,
        // and the lens's ray, scaled alike, starts on the near plane.
        let d = d - offset / self.focus_distance;
        (Vec3::from_array(self.origin) + offset + d * self.near, d.normalize())
    }

    /// The unnormalized direction of [`Camera::primary_ray`] (its component
    /// along `dir` is one).
    #[inline]
    fn image_plane(&self, x: u32, y: u32, sub: u32, width: u32, height: u32, u: (f32, f32)) -> Vec3 {
        let tent = |u: f32| {
            let r = 2.0 * u;
            if r < 1.0 {
                libm::sqrtf(r) - 1.0
            } else {
                1.0 - libm::sqrtf(2.0 - r)
            }
        };
        let (sx, sy) = ((sub % 2) as f32, (sub / 2) as f32);
        let (dx, dy) = (tent(u.0), tent(u.1));
        let fx = ((sx + 0.5 + dx) / 2.0 + x as f32) / width as f32 - 0.5;
        let fy = ((sy + 0.5 + dy) / 2.0 + y as f32) / height as f32 - 0.5;
        Vec3::from_array(self.cx) * fx + Vec3::from_array(self.cy) * fy + Vec3::from_array(self.dir)
    }
}

/// A point of the unit disk from two uniform numbers, by Shirley and Chiu's
/// concentric map (uniform in area, and neighbouring numbers stay
/// neighbours, which keeps Sobol points stratified on the lens). Its angle,
/// in turns, goes through [`sin_cos_turns`]: `libm`'s `sinf` and `cosf`
/// (a range reduction in f64) made every render kernel slower.
#[inline]
pub fn concentric_disk(u: f32, v: f32) -> (f32, f32) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    // pi/4 (b/a), or pi/2 - pi/4 (a/b), as turns of 2 pi.
    let (r, turns) = if a.abs() > b.abs() { (a, 0.125 * (b / a)) } else { (b, 0.25 - 0.125 * (a / b)) };
    let (sin, cos) = sin_cos_turns(turns);
    (r * cos, r * sin)
}


/// Scene buffers of a render, and the way closest hits are found in them
/// (the scan or a tree in one of the traversal layouts: see
/// [`ClosestHit`]).
pub struct SceneRefs<'a, T> {
    /// Spheres then triangles; one material per primitive, in that order.
    pub prims: Prims<'a>,
    pub materials: &'a [Material],
    pub tree: T,
}

impl<'a, T: ClosestHit> SceneRefs<'a, T> {
    /// The scene the render and cast kernels see: their bindings, with the
    /// primitive counts from `params` (buffers may be longer than their content).
    #[inline]
    pub fn new(
        params: &RenderParams,
        spheres: &'a [Sphere],
        triangles: Split<'a, Triangle>,
        materials: &'a [Material],
        tree: T,
    ) -> Self {
        let prims = Prims { spheres, sphere_count: params.prims, triangles, triangle_count: params.triangles };
        SceneRefs { prims, materials, tree }
    }
}

/// The closest hit, testing the primitive kinds of `F` (see [`crate::geometry::features`]).
#[inline]
pub fn closest_hit<T: ClosestHit, const F: u32, const S: usize>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    scene: &SceneRefs<T>,
    stack: &mut [u32; S],
    lane: u32,
) -> Hit {
    trace::<T, F, S>(o, d, from, Query::CLOSEST, scene, stack, lane)
}

/// What `query` asks of the ray through the scene's tree (see
/// [`ClosestHit::trace`]).
#[inline]
pub fn trace<T: ClosestHit, const F: u32, const S: usize>(
    o: Vec3,
    d: Vec3,
    from: Origin,
    query: Query,
    scene: &SceneRefs<T>,
    stack: &mut [u32; S],
    lane: u32,
) -> Hit {
    scene.tree.trace::<F, S>(o, d, from, query, &scene.prims, stack, lane)
}

/// One path in flight: what the loop of [`radiance`] carries from one
/// traced ray to the next. [`render_pixel`] steps a pixel's paths one ray at
/// a time and starts the next sample's path as soon as one ends (path
/// regeneration: the lanes of a subgroup then wait for each other once per
/// dispatch, not once per sample), which changes no pixel's value.
pub struct Path {
    /// The ray to trace next.
    o: Vec3,
    d: Vec3,
    from: Origin,
    /// Radiance gathered so far: the path's value once it has ended.
    pub result: Vec3,
    throughput: Vec3,
    depth: u32,
    sample: u32,
    /// Density of the last bounce's direction if it was diffuse (else 0: a
    /// hit emitter then counts in full), and where that bounce was.
    bsdf_pdf: f32,
    last_x: Vec3,
    /// A shadow ray is traced by the same call as the path's rays, in the
    /// step after its diffuse bounce: one traversal inlined in the kernel,
    /// not two (with two, NEE through the treelet BVH ran 6.7 times as long
    /// as smallpt's estimator on the H100; with one, 3 times; with pbrt-v4's
    /// roulette as well, 1.8 times). While one is pending, `(o, d, from)` is
    /// the shadow ray, `next_d` and [`NEXT_INTO`] the path's bounce (which
    /// leaves from the same point and primitive, so only its direction and
    /// side are kept: eight words of state fewer), and `shadow_value` what
    /// the light adds if the ray reaches `shadow_light` first: if an
    /// occlusion query finds nothing else up to `shadow_t`, where the ray
    /// meets the light (it stops at the first occluder, and the light is
    /// never its own); through a scan, if the light is its closest hit (see
    /// [`ClosestHit::OCCLUSION_STOPS_EARLY`]).
    shadow_light: u32,
    shadow_t: f32,
    shadow_value: Vec3,
    next_d: Vec3,
    /// [`ENDED`], and where the path stands among those light paths find
    /// instead ([`CAUSTICS`]): [`SEEN_DIFFUSE`] while every hit has been
    /// diffuse, [`THEN_SPECULAR`] after mirror or glass bounces since. One
    /// word: a register more made cornell's NEE kernel 3% slower (H100).
    flags: u32,
}

/// [`Path::flags`]: roulette ended the path; a pending shadow ray is still traced.
const ENDED: u32 = 1;
/// [`Path::flags`]: every hit so far was diffuse.
const SEEN_DIFFUSE: u32 = 2;
/// [`Path::flags`]: then only mirror and glass bounces: the emitter such a
/// path reaches is the light paths' to count (see `crate::render::caustics`).
const THEN_SPECULAR: u32 = 4;
/// [`Path::flags`]: the caustic states.
const CAUSTIC_STATE: u32 = SEEN_DIFFUSE | THEN_SPECULAR;
/// [`Path::flags`]: while a shadow ray is pending, the path's bounce heads
/// into the sphere it leaves (its [`Origin::into`]).
const NEXT_INTO: u32 = 8;

impl Path {
    /// A path starting with the ray `(o, d)`, as sample `sample` of its pixel.
    #[inline]
    pub fn new(o: Vec3, d: Vec3, sample: u32) -> Path {
        Path {
            o,
            d,
            from: Origin::NONE,
            result: Vec3::ZERO,
            throughput: Vec3::ONE,
            depth: 0,
            sample,
            bsdf_pdf: 0.0,
            last_x: o,
            shadow_light: NO_LIGHT,
            shadow_t: 0.0,
            shadow_value: Vec3::ZERO,
            next_d: d,
            flags: 0,
        }
    }

    /// The camera path of sample `sample` of pixel `pixel`, in a kernel of
    /// features `F` (see [`crate::render::sampler::uses_sobol`]).
    #[inline]
    pub fn camera<const F: u32>(params: &RenderParams, pixel: u32, sample: u32) -> Path {
        let (w, h) = (params.width, params.height);
        let (x, y) = (pixel % w, h - 1 - pixel / w);
        let (sub, u) = camera_sample::<F>(params, pixel, sample);
        let (o, d) = if has(F, features::LENS) && params.camera.lens_radius > 0.0 {
            params.camera.lens_ray(x, y, sub, w, h, u, lens_sample::<F>(params, pixel, sample))
        } else {
            params.camera.primary_ray(x, y, sub, w, h, u)
        };
        Path::new(o, d, sample)
    }

    /// Traces the path's next ray and follows what it hits (see
    /// [`radiance`]); false once the path has ended, its radiance then
    /// being `result`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn step<T: ClosestHit, const F: u32, const S: usize>(
        &mut self,
        params: &RenderParams,
        pixel: u32,
        scene: &SceneRefs<T>,
        lights: &[Light],
        stack: &mut [u32; S],
        lane: u32,
    ) -> bool {
        if (self.depth >= MAX_BOUNCES || self.flags & ENDED != 0) && self.shadow_light == NO_LIGHT {
            return false;
        }
        let nee = (params.integrator == NEE || params.integrator == CAUSTICS) && params.light_count > 0;
        let shadow = self.shadow_light != NO_LIGHT;
        let occlusion = shadow && T::OCCLUSION_STOPS_EARLY;
        let query = if occlusion { Query::occlusion(self.shadow_t, self.shadow_light) } else { Query::CLOSEST };
        let hit = trace::<T, F, S>(self.o, self.d, self.from, query, scene, stack, lane);
        if shadow {
            // Anything else first, glass too, occludes it: paths through
            // glass reach a light by their bounces, at full weight. (Through
            // a scan, the shadow ray is a closest hit: it reaches the light
            // if the light is what it hits.)
            let reached = if T::OCCLUSION_STOPS_EARLY { !hit.is_hit() } else { hit.prim == self.shadow_light };
            if reached {
                self.result += self.shadow_value;
            }
            self.shadow_light = NO_LIGHT;
            // The bounce leaves from where the shadow ray did.
            (self.d, self.from.into) = (self.next_d, self.flags & NEXT_INTO != 0);
            return true;
        }
        if !hit.is_hit() {
            // The environment, at full weight: next-event estimation never
            // samples it, so only this strategy finds it.
            if has(F, features::ENVIRONMENT) {
                self.result += self.throughput * Vec3::from_array(params.environment);
            }
            return false;
        }
        let x = self.o + self.d * hit.t;
        let (m, n) = surface::<T, F>(scene, hit.prim, x, self.d);
        let nl = if n.dot(self.d) < 0.0 { n } else { -n };
        let mut f = Vec3::from_array(m.color);
        let emission = Vec3::from_array(m.emission);
        // Diffuse hits, then mirror or glass, then the side of an emitter
        // that light paths leave from (any side of a flat one, the outside
        // of a sphere): those paths are the light paths'
        // (`crate::render::caustics`), not counted twice.
        let caustics = has(F, features::CAUSTICS) && params.integrator == CAUSTICS;
        let theirs = caustics
            && self.flags & THEN_SPECULAR != 0
            && (!scene.prims.is_sphere::<F>(hit.prim) || self.d.dot(n) < 0.0);
        if theirs {
        } else if nee && self.bsdf_pdf > 0.0 && emission != Vec3::ZERO {
            let light = light_pmf(lights, params.light_count, hit.prim)
                * light_pdf(&scene.prims, hit.prim, self.last_x, self.d, hit.t);
            self.result += self.throughput * emission * power_heuristic(self.bsdf_pdf, light);
        } else {
            self.result += self.throughput * emission;
        }
        self.bsdf_pdf = 0.0;
        self.depth += 1;
        // Bounce 0's dimensions 0 and 1 are the camera's tent filter.
        let rng = BounceSamples::new::<F>(params, params.seed, pixel, self.sample, self.depth);
        if self.depth > 5 && !nee {
            let p = f.max_element();
            if rng.single(0) < p {
                f /= p;
            } else {
                return false;
            }
        }
        self.throughput *= f;
        // A black surface (a lamp, smallpt's front wall) ends the path:
        // nothing after it can add light, and smallpt's way (on to Russian
        // roulette after depth 5) only spends rays. No pixel changes.
        if self.throughput == Vec3::ZERO {
            return false;
        }
        let eps = surface_offset(x);
        // The light sample's direction, where one is taken (a diffuse hit).
        let mut shadow_d = Vec3::Z;
        // Branches for materials outside `F` are not compiled (the host
        // never runs such a kernel on a scene that has them).
        if !has(F, features::MIRROR | features::GLASS) || m.kind == DIFFUSE {
            if caustics {
                let seen = self.depth == 1 || self.flags & SEEN_DIFFUSE != 0;
                self.flags = (self.flags & !CAUSTIC_STATE) | if seen { SEEN_DIFFUSE } else { 0 };
            }
            if nee {
                let s = sample_direct(x, nl, hit.prim, &rng, params, scene, lights);
                if s.light != NO_LIGHT && !T::OCCLUSION_STOPS_EARLY {
                    (self.shadow_light, shadow_d, self.shadow_value) = (s.light, s.dir, self.throughput * s.value);
                } else if s.light != NO_LIGHT {
                    // Where the shadow ray (as traced below) meets the light,
                    // by the test the traversal itself would make; a ray
                    // that grazes past it numerically carries nothing.
                    let (so, from) = (x + nl * eps, Origin { prim: hit.prim, into: s.dir.dot(n) < 0.0 });
                    let t = scene.prims.distance::<F>(so, s.dir, &WatertightRay::new(so, s.dir), from, s.light, MISS);
                    if t < MISS {
                        (self.shadow_light, shadow_d, self.shadow_value) = (s.light, s.dir, self.throughput * s.value);
                        self.shadow_t = t;
                    }
                }
            }
            let (u1, u2) = rng.pair(1);
            self.d = cosine_direction(nl, u1, u2);
            self.o = x + nl * eps;
            self.bsdf_pdf = nl.dot(self.d).max(0.0) * core::f32::consts::FRAC_1_PI;
            self.last_x = x;
        } else if !has(F, features::GLASS) || (has(F, features::MIRROR) && m.kind == MIRROR) {
            if caustics && self.flags & CAUSTIC_STATE != 0 {
                self.flags = (self.flags & !CAUSTIC_STATE) | THEN_SPECULAR;
            }
            self.d = self.d - n * 2.0 * n.dot(self.d);
            self.o = x + nl * eps;
        } else {
            if caustics && self.flags & CAUSTIC_STATE != 0 {
                self.flags = (self.flags & !CAUSTIC_STATE) | THEN_SPECULAR;
            }
            let b = glass_bounce(self.d, n, nl, m.ior, rng.single(3));
            self.throughput *= b.weight;
            self.d = b.d;
            self.o = if b.refracted { x - nl * eps } else { x + nl * eps };
        }
        // The next ray leaves this sphere: into it when it heads against the
        // outward normal.
        self.from = Origin { prim: hit.prim, into: self.d.dot(n) < 0.0 };
        // NEE's roulette on the path's throughput (see NEE_ROULETTE_DEPTH),
        // after this vertex's light sample, which it leaves to be traced.
        if nee && self.depth >= NEE_ROULETTE_DEPTH {
            let p = self.throughput.max_element();
            if p < 1.0 {
                if rng.single(0) < p {
                    self.throughput /= p;
                } else if self.shadow_light == NO_LIGHT {
                    return false;
                } else {
                    self.flags |= ENDED;
                }
            }
        }
        if self.shadow_light != NO_LIGHT {
            // The shadow ray first, from the same point (see above).
            // Only a diffuse bounce samples a light: its ray leaves from
            // `x + nl * eps` too, and from the same primitive.
            self.next_d = self.d;
            self.flags = (self.flags & !NEXT_INTO) | if self.from.into { NEXT_INTO } else { 0 };
            (self.d, self.from) = (shadow_d, Origin { prim: hit.prim, into: shadow_d.dot(n) < 0.0 });
        }
        true
    }
}

/// A bounce off smallpt's glass (Schlick's Fresnel): the new direction, the
/// factor the path's throughput takes (reflection and refraction are picked
/// with probability `P = 1/4 + Re/2` and weighted), and whether it
/// refracted, with `eta`, the ratio of the indices on the side the ray comes
/// from and the side it goes to. Camera paths and light paths
/// ([`crate::render::caustics`]) take the same bounce.
pub struct GlassBounce {
    pub d: Vec3,
    pub weight: f32,
    pub refracted: bool,
    pub eta: f32,
}

/// [`GlassBounce`] of a ray along `d` at a point of outward normal `n`
/// (`nl` facing the ray), index of refraction `ior`, with the uniform `u`.
#[inline]
pub fn glass_bounce(d: Vec3, n: Vec3, nl: Vec3, ior: f32, u: f32) -> GlassBounce {
    let reflected = d - n * 2.0 * n.dot(d);
    let into = n.dot(nl) > 0.0;
    let (nc, nt) = (1.0, ior);
    let nnt = if into { nc / nt } else { nt / nc };
    let ddn = d.dot(nl);
    let cos2t = 1.0 - nnt * nnt * (1.0 - ddn * ddn);
    if cos2t < 0.0 {
        // Total internal reflection.
        return GlassBounce { d: reflected, weight: 1.0, refracted: false, eta: 1.0 };
    }
    let sign = if into { 1.0 } else { -1.0 };
    let tdir = (d * nnt - n * (sign * (ddn * nnt + libm::sqrtf(cos2t)))).normalize();
    let (a, b) = (nt - nc, nt + nc);
    let r0 = a * a / (b * b);
    let c = 1.0 - if into { -ddn } else { tdir.dot(n) };
    let re = r0 + (1.0 - r0) * c * c * c * c * c;
    let tr = 1.0 - re;
    let p = 0.25 + 0.5 * re;
    if u < p {
        GlassBounce { d: reflected, weight: re / p, refracted: false, eta: 1.0 }
    } else {
        GlassBounce { d: tdir, weight: tr / (1.0 - p), refracted: true, eta: nnt }
    }
}

/// Radiance along one path (smallpt's `radiance`, as a loop), with the
/// code for the features `F` only (see [`crate::geometry::features`]).
///
/// With `params.integrator == NEE` and a light table, every diffuse bounce
/// also samples a light ([`crate::render::lights`]) and casts a shadow ray to it;
/// that sample and the emission a diffuse bounce's path hits next are both
/// weighted by the power heuristic. Camera rays and mirror and glass
/// bounces see emission at full weight, as the shadow ray cannot follow
/// them: a light behind glass is found only by paths through it.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn radiance<T: ClosestHit, const F: u32, const S: usize>(
    o: Vec3,
    d: Vec3,
    params: &RenderParams,
    pixel: u32,
    sample: u32,
    scene: &SceneRefs<T>,
    lights: &[Light],
    stack: &mut [u32; S],
    lane: u32,
) -> Vec3 {
    let mut path = Path::new(o, d, sample);
    while path.step::<T, F, S>(params, pixel, scene, lights, stack, lane) {}
    path.result
}

/// With next-event estimation, Russian roulette starts at the third hit
/// and keeps a path with probability equal to its throughput's largest
/// component (then divides the throughput by it), as pbrt-v4's path
/// integrator does, instead of smallpt's rule (from the sixth hit, with the
/// surface's reflectance, whatever light the path still carries). Measured
/// on the H100 (1024x768, 1024 spp): the disk-lit room's NEE render took
/// 4.87 s of kernels instead of 8.66 s, cornell's 0.95 s instead of 1.41 s,
/// for 1.3 to 1.5 times the variance at equal samples: 1.1 times less
/// RMSE at equal time on both (`docs/results/h100-roulette`). On the CPU
/// runner, starting at the second hit measured within noise of the third,
/// and at the sixth worse.
pub const NEE_ROULETTE_DEPTH: u32 = 3;

/// No light: no shadow ray pending.
const NO_LIGHT: u32 = u32::MAX;

/// The subpixel and tent-filter numbers of sample `sample` of `pixel`:
/// with [`SOBOL`](crate::geometry::buffers::SOBOL), one Owen-scrambled Sobol point over the pixel's 2x2
/// subpixels (its top bits pick the subpixel, so each run of four samples
/// covers all four; the rest are uniform within it); else sample `s` in
/// subpixel `s % 4` with two independent numbers, as smallpt.
#[inline]
pub fn camera_sample<const F: u32>(params: &RenderParams, pixel: u32, sample: u32) -> (u32, (f32, f32)) {
    if uses_sobol::<F>(params) {
        let (u, v) = PathSampler::new(params.seed, pixel, sample, 0).pair(0);
        let (sx, sy) = ((u >= 0.5) as u32, (v >= 0.5) as u32);
        (sx + 2 * sy, (2.0 * u - sx as f32, 2.0 * v - sy as f32))
    } else {
        let rng = BounceRng::new(params.seed, pixel, sample, 0);
        (sample % 4, (rng.uniform(0), rng.uniform(1)))
    }
}

/// The lens numbers of sample `sample` of `pixel` (see [`Camera::lens_ray`]):
/// the camera bounce's second pair (its first is [`camera_sample`]'s), a
/// Sobol point or two independent numbers as that one.
#[inline]
pub fn lens_sample<const F: u32>(params: &RenderParams, pixel: u32, sample: u32) -> (f32, f32) {
    if uses_sobol::<F>(params) {
        PathSampler::new(params.seed, pixel, sample, 0).pair(2)
    } else {
        let rng = BounceRng::new(params.seed, pixel, sample, 0);
        (rng.uniform(2), rng.uniform(3))
    }
}

/// A light sample at a diffuse point: the light, the shadow ray's
/// direction, and the radiance the light adds (per unit throughput) if that
/// ray reaches it first; `light == NO_LIGHT` where there is nothing to trace.
struct DirectSample {
    light: u32,
    dir: Vec3,
    value: Vec3,
}

/// Next-event estimation at a diffuse point `x` (`nl` facing the incoming
/// ray) of primitive `prim`: one light chosen by power, one direction to
/// it, weighted by the power heuristic against the cosine-weighted bounce.
/// The caller traces the shadow ray (see [`radiance`]).
#[inline]
fn sample_direct<T: ClosestHit>(
    x: Vec3,
    nl: Vec3,
    prim: u32,
    rng: &BounceSamples,
    params: &RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
) -> DirectSample {
    let none = DirectSample { light: NO_LIGHT, dir: Vec3::Z, value: Vec3::ZERO };
    let light = lights[select_light(lights, params.light_count, rng.single(4)) as usize];
    if light.prim == prim {
        return none; // A surface does not light itself.
    }
    let (u5, u6) = rng.pair(5);
    let s = sample_light(&scene.prims, light.prim, x, u5, u6);
    let cos = nl.dot(s.dir);
    if !(s.pdf > 0.0) || !(cos > 0.0) {
        return none;
    }
    let light_pdf = light.pmf * s.pdf;
    let bsdf_pdf = cos * core::f32::consts::FRAC_1_PI;
    let emission = Vec3::from_array(scene.materials[light.prim as usize].emission);
    let value = emission * (bsdf_pdf / light_pdf * power_heuristic(light_pdf, bsdf_pdf));
    DirectSample { light: light.prim, dir: s.dir, value }
}

/// The material and outward normal of primitive `prim` at its point `x`
/// (hit along `d`): the scene's own ([`hit_normal_for`]), or, where `F`
/// has [`features::INSTANCES`], a placed copy's past them
/// ([`ClosestHit::instance_surface`]).
#[inline]
pub(crate) fn surface<T: ClosestHit, const F: u32>(scene: &SceneRefs<T>, prim: u32, x: Vec3, d: Vec3) -> (Material, Vec3) {
    if has(F, features::INSTANCES) && prim >= scene.prims.count() {
        scene.tree.instance_surface(prim - scene.prims.count(), d)
    } else {
        (scene.materials[prim as usize], hit_normal_for::<F>(&scene.prims, prim, x, d))
    }
}

/// The outward normal of primitive `prim` at its point `x` (hit along `d`):
/// a sphere's radial direction, a triangle's geometric normal (its winding
/// decides "into" for glass).
#[inline]
pub fn hit_normal(prims: &Prims, prim: u32, x: Vec3, d: Vec3) -> Vec3 {
    hit_normal_for::<{ features::ALL }>(prims, prim, x, d)
}

/// [`hit_normal`] compiled for the primitive kinds of `F`.
#[inline]
pub fn hit_normal_for<const F: u32>(prims: &Prims, prim: u32, x: Vec3, d: Vec3) -> Vec3 {
    if prims.is_sphere::<F>(prim) {
        (x - Vec3::from_array(prims.spheres[prim as usize].center)).normalize()
    } else {
        let t = prims.triangle(prim - prims.sphere_count);
        let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
        (b - a).cross(c - a).normalize_or(-d)
    }
}

/// Pixels are given to invocations in tiles of `TILE_W x TILE_H` (a
/// subgroup of 32 on most GPUs), row-major within a tile: the rays of one
/// subgroup then start close together and go through the same nodes, so
/// they diverge less than a row of 32 pixels would.
pub const TILE_W: u32 = 8;
pub const TILE_H: u32 = 4;

/// Invocations a dispatch needs to cover a `width x height` image in tiles.
#[inline]
pub fn tiled_invocations(width: u32, height: u32) -> u32 {
    width.div_ceil(TILE_W) * TILE_W * height.div_ceil(TILE_H) * TILE_H
}

/// The pixel (row-major from the top row) of invocation `id`, or
/// `u32::MAX` for an invocation past the image (edge tiles, the last
/// workgroup).
#[inline]
pub fn tiled_pixel(id: u32, width: u32, height: u32) -> u32 {
    let tiles_x = width.div_ceil(TILE_W);
    let (tile, lane) = (id / (TILE_W * TILE_H), id % (TILE_W * TILE_H));
    let x = (tile % tiles_x) * TILE_W + lane % TILE_W;
    let y = (tile / tiles_x) * TILE_H + lane / TILE_W;
    if x < width && y < height {
        y * width + x
    } else {
        u32::MAX
    }
}

/// Kernel body (one invocation per pixel): `params.samples` camera paths
/// of pixel `id`, as sums of radiance and of squared luminance. `F`: the
/// features compiled in (see [`crate::geometry::features`]); the scene's must be
/// among them.
#[inline]
pub fn render_pixel<T: ClosestHit, const F: u32, const S: usize>(
    id: u32,
    params: &RenderParams,
    scene: &SceneRefs<T>,
    lights: &[Light],
    stack: &mut [u32; S],
    lane: u32,
) -> [f32; 4] {
    let mut sum = Vec3::ZERO;
    let mut sum_sq = 0.0;
    let mut s = 0;
    // One loop over every ray of the pixel's paths (see [`Path`]).
    let mut path = Path::camera::<F>(params, id, params.first_sample);
    while s < params.samples {
        if !path.step::<T, F, S>(params, id, scene, lights, stack, lane) {
            let l = path.result;
            sum += l;
            let lum = luminance(l);
            sum_sq += lum * lum;
            s += 1;
            if s < params.samples {
                path = Path::camera::<F>(params, id, params.first_sample + s);
            }
        }
    }
    [sum.x, sum.y, sum.z, sum_sq]
}

/// Adds one dispatch's [`render_pixel`] result to a pixel's running sums.
#[inline]
pub fn accumulate(acc: &mut [f32; 4], add: [f32; 4]) {
    for k in 0..4 {
        acc[k] += add[k];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::buffers::{INDEPENDENT, SOBOL};
    use crate::gpu::rng::BounceRng;
    use crate::render::sampling::sin_cos_turns;

    #[test]
    fn tiles_cover_every_pixel_once() {
        extern crate std;
        for (w, h) in [(1u32, 1u32), (8, 4), (9, 5), (1920, 1080), (33, 7)] {
            let mut seen = std::vec![0u8; (w * h) as usize];
            for id in 0..tiled_invocations(w, h) {
                let p = tiled_pixel(id, w, h);
                if p != u32::MAX {
                    seen[p as usize] += 1;
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "{w}x{h}");
        }
    }

    /// render_pixel's one loop over a pixel's paths (path regeneration) adds
    /// up the same paths as tracing each sample alone with `radiance`, in
    /// order, with both integrators: sample indices, restarts and sums kept.
    #[test]
    fn path_regeneration_sums_the_same_paths() {
        use crate::geometry::buffers::{GLASS, SMALLPT};
        use crate::trace::classic::Scan;
        // smallpt's room: walls (the front one black), a mirror ball, a
        // glass ball and the lamp through the ceiling.
        let spheres = [
            Sphere::new([1e5 + 1.0, 40.8, 81.6], 1e5),
            Sphere::new([-1e5 + 99.0, 40.8, 81.6], 1e5),
            Sphere::new([50.0, 40.8, 1e5], 1e5),
            Sphere::new([50.0, 40.8, -1e5 + 170.0], 1e5),
            Sphere::new([50.0, 1e5, 81.6], 1e5),
            Sphere::new([50.0, -1e5 + 81.6, 81.6], 1e5),
            Sphere::new([27.0, 16.5, 47.0], 16.5),
            Sphere::new([73.0, 16.5, 78.0], 16.5),
            Sphere::new([50.0, 681.6 - 0.27, 81.6], 600.0),
        ];
        let diffuse = |c: f32, k: f32| Material { kind: DIFFUSE, color: [c, k, k], ..Default::default() };
        let materials = [
            diffuse(0.75, 0.25),
            diffuse(0.25, 0.75),
            diffuse(0.75, 0.75),
            diffuse(0.0, 0.0),
            diffuse(0.75, 0.75),
            diffuse(0.75, 0.75),
            Material { kind: MIRROR, color: [0.999; 3], ..Default::default() },
            Material { kind: GLASS, color: [0.999; 3], ior: 1.5, ..Default::default() },
            Material { emission: [12.0; 3], ..diffuse(0.0, 0.0) },
        ];
        let lights = [Light { prim: 8, pmf: 1.0, cdf: 1.0, _pad: 0 }];
        let (w, h) = (8u32, 6u32);
        let camera = Camera::look(Vec3::new(50.0, 52.0, 295.6), Vec3::new(0.0, -0.042612, -1.0), 140.0, SMALLPT_FOV, w, h);
        let mut total = 0.0;
        // The general kernel with both samplers.
        const G: u32 = features::ALL | features::INDEPENDENT_NUMBERS;
        for (integrator, sampler) in [(SMALLPT, INDEPENDENT), (NEE, INDEPENDENT), (NEE, SOBOL)] {
            let params = RenderParams {
                width: w,
                height: h,
                samples: 9,
                first_sample: 5,
                seed: 3,
                prims: spheres.len() as u32,
                camera,
                integrator,
                light_count: 1,
                sampler,
                ..Default::default()
            };
            let scene = SceneRefs::new(&params, &spheres, Split::whole(&[]), &materials, Scan::new(&[], &[]));
            for pixel in 0..w * h {
                let got = render_pixel::<_, G, 1>(pixel, &params, &scene, &lights, &mut [0; 1], 0);
                let (x, y) = (pixel % w, h - 1 - pixel / w);
                let (mut sum, mut sum_sq) = (Vec3::ZERO, 0.0f32);
                for sample in params.first_sample..params.first_sample + params.samples {
                    let (sub, u) = camera_sample::<G>(&params, pixel, sample);
                    let (o, d) = camera.primary_ray(x, y, sub, w, h, u);
                    let l = radiance::<_, G, 1>(o, d, &params, pixel, sample, &scene, &lights, &mut [0; 1], 0);
                    sum += l;
                    sum_sq += luminance(l) * luminance(l);
                }
                assert_eq!(got, [sum.x, sum.y, sum.z, sum_sq], "integrator {integrator}, sampler {sampler}, pixel {pixel}");
                total += sum_sq;
            }
        }
        assert!(total > 0.0, "the room rendered black: the test compared nothing");
    }

    #[test]
    fn sin_cos_turns_is_accurate() {
        for i in 0..10_000 {
            let u = i as f32 / 10_000.0;
            let (s, c) = sin_cos_turns(u);
            let a = 2.0 * core::f64::consts::PI * u as f64;
            assert!((s as f64 - a.sin()).abs() < 3e-7 && (c as f64 - a.cos()).abs() < 3e-7, "u = {u}");
        }
    }

    /// Rays bouncing off smallpt's walls, floor and ceiling (radius 1e5) must
    /// never hit the surface they leave: f32 cannot resolve points within
    /// 0.004 of such a sphere, which is what the start-surface rule is for.
    #[test]
    fn no_self_hits_on_huge_walls() {
        use crate::geometry::buffers::Sphere;
        use crate::trace::classic::closest_hit_linear;
        let walls = [
            Sphere::new([1e5 + 1.0, 40.8, 81.6], 1e5),
            Sphere::new([-1e5 + 99.0, 40.8, 81.6], 1e5),
            Sphere::new([50.0, 40.8, 1e5], 1e5),
            Sphere::new([50.0, 1e5, 81.6], 1e5),
            Sphere::new([50.0, -1e5 + 81.6, 81.6], 1e5),
        ];
        for i in 0..20_000u32 {
            let r = BounceRng::new(1, i, 0, 1);
            let eye = Vec3::new(50.0, 40.0, 150.0);
            let aim = Vec3::new(1.0 + 98.0 * r.uniform(5), 81.6 * r.uniform(6), 170.0 * r.uniform(7));
            let d = (aim - eye).normalize();
            let hit = closest_hit_linear(eye, d, Origin::NONE, &Prims::spheres(&walls));
            assert!(hit.is_hit());
            let x = eye + d * hit.t;
            let n = (x - Vec3::from_array(walls[hit.prim as usize].center)).normalize();
            let nl = if n.dot(d) < 0.0 { n } else { -n };
            let d2 = cosine_direction(nl, r.uniform(1), r.uniform(2));
            let from = Origin { prim: hit.prim, into: d2.dot(n) < 0.0 };
            let next = closest_hit_linear(x + nl * surface_offset(x), d2, from, &Prims::spheres(&walls));
            // Hitting the same wall again is only possible at its far side.
            assert!(next.prim != hit.prim || next.t > 1e3, "bounce {i} hit its own wall {} away", next.t);
        }
    }

    #[test]
    fn cosine_directions_have_the_right_moments() {
        for w in [Vec3::Y, Vec3::new(0.3, -0.2, 0.9).normalize(), -Vec3::X] {
            let n = 100_000;
            let (mut mean_cos, mut mean_perp) = (0.0f64, Vec3::ZERO);
            for i in 0..n {
                let r = BounceRng::new(3, i, 0, 1);
                let d = cosine_direction(w, r.uniform(1), r.uniform(2));
                assert!((d.length() - 1.0).abs() < 1e-5);
                assert!(d.dot(w) >= -1e-6, "below the surface");
                mean_cos += d.dot(w) as f64;
                mean_perp += d - w * d.dot(w);
            }
            // E[cos θ] = 2/3 for a cosine-weighted hemisphere.
            assert!((mean_cos / n as f64 - 2.0 / 3.0).abs() < 0.005, "{}", mean_cos / n as f64);
            assert!((mean_perp / n as f32).length() < 0.01);
        }
    }
}
