//! The engine API's rays and hits, and how a batch of them travels to the
//! device and back (shared by [`crate::tracer::Tracer`] and
//! [`crate::tracer::InstancedTracer`]).
use anyhow::Result;

use crate::runtime::backend::Backend;

/// A ray of a batch: from `origin` along `dir` (any length but zero), hits
/// from distance `t_min` (finite, at least 0) up to `t_max` (both along the
/// normalized direction). A ray that leaves a surface should start a little
/// off it, or set `t_min`: nothing else is excluded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    /// A ray with no limit on its hit distance.
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Ray {
        Ray { origin, dir, t_min: 0.0, t_max: f32::INFINITY }
    }
}

/// The closest hit of a ray: the primitive (spheres first, then triangles,
/// in the order given to [`Tracer::build`](crate::tracer::Tracer::build); in an instanced scene the
/// triangle's index within its mesh), the instance hit (0 for a
/// [`Tracer`](crate::tracer::Tracer), which is one), the distance along the normalized direction,
/// a triangle's barycentric coordinates of the hit (of `v1` and `v2`: the
/// point is `(1 - b1 - b2) v0 + b1 v1 + b2 v2`; 0 for a sphere), to
/// interpolate vertex normals and texture coordinates, and the geometric
/// normal in world space (unit; a triangle's `(v1 - v0) x (v2 - v0)`, a
/// sphere's outward). For no hit: `prim` and `instance` `u32::MAX`, `t`
/// infinite, the rest 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    pub t: f32,
    pub prim: u32,
    pub instance: u32,
    pub barycentrics: [f32; 2],
    pub normal: [f32; 3],
}

impl RayHit {
    /// No hit.
    pub const MISS: RayHit =
        RayHit { t: f32::INFINITY, prim: u32::MAX, instance: u32::MAX, barycentrics: [0.0; 2], normal: [0.0; 3] };

    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }
}

/// The hit of ray `r` from its device record `(t, prim, b1, b2)` and
/// `(n, bits of the instance)` (traced from `t_min` on: see [`device_rays`]).
pub(super) fn hit_record(r: &Ray, [[t, prim, b1, b2], [nx, ny, nz, instance]]: [[f32; 4]; 2]) -> RayHit {
    let prim = prim.to_bits();
    if prim == u32::MAX {
        return RayHit::MISS;
    }
    RayHit { t: t + r.t_min, prim, instance: instance.to_bits(), barycentrics: [b1, b2], normal: [nx, ny, nz] }
}

/// Uploads the rays `ray(k)`, `k < count` (made in parallel, written
/// straight into the device's upload memory), has `cast` trace them on the device in place,
/// and hands the rays' records (two a ray), read where they lie, to `take`.
pub(super) fn trace_batch<B: Backend, T>(
    b: &mut B,
    count: usize,
    ray: &(impl Fn(usize) -> Ray + Sync),
    cast: impl FnOnce(&mut B, &B::Buffer) -> Result<()>,
    take: impl FnOnce(&[[[f32; 4]; 2]]) -> T,
) -> Result<T> {
    let slots = batch_slots(count)?;
    let buffer = b.upload_indexed("rays", slots, |k| if k < count { device_pair(k, &ray(k)) } else { Ok([[0.0; 4]; 2]) })?;
    let traced = cast(b, &buffer).and_then(|()| b.read_with(&buffer, count, take));
    // Waited for: the buffer serves the next batch (without this, every
    // batch took a new one until the next build: 66 MB a 1080p frame).
    b.release(&[&buffer]);
    traced
}

/// The image a batch of `count` rays is cast as (the cast kernels walk one).
pub(super) fn batch_dims(count: usize) -> Result<(u32, u32)> {
    let slots = batch_slots(count)? as u32;
    Ok((BATCH_WIDTH.min(slots.max(1)), slots.div_ceil(BATCH_WIDTH).max(1)))
}

/// Rays a device batch holds per row (the cast kernels walk an image).
pub(super) const BATCH_WIDTH: u32 = 1024;

/// `rays` as [`Tracer::closest_hits_on_device`](crate::tracer::Tracer::closest_hits_on_device) reads them from a device
/// buffer: two `[f32; 4]` a ray, padded with zeros to [`batch_slots`] pairs.
/// The device layout has no `t_min`: a ray is moved `t_min` along its
/// direction and its `t_max` shortened by as much (hit distances then count
/// from there); engines that fill device buffers themselves do the same.
pub fn device_rays(rays: &[Ray]) -> crate::error::Result<Vec<[f32; 4]>> {
    crate::error::typed(|| {
        // Written once, in order (a zeroed vector written over cost a second
        // pass over 32 MB a million rays), its padding zeros last.
        let slots = 2 * batch_slots(rays.len())?;
        let mut data = crate::internals::input::room_for(slots, "a batch of rays")?;
        for (k, r) in rays.iter().enumerate() {
            data.extend_from_slice(&device_pair(k, r)?);
        }
        data.resize(slots, [0.0; 4]);
        Ok(data)
    })
}

/// Ray `k` as the device reads it (see [`device_rays`]); an error where its
/// `t_min` is not finite or below 0. (A direction of length 0 hits nothing,
/// and a NaN `t_max` is no bound that a hit is within, as `tests/tracer.rs`
/// holds the API to; the Python package refuses non-finite rays before they
/// get here.)
pub(super) fn device_pair(k: usize, r: &Ray) -> Result<[[f32; 4]; 2]> {
    if !(r.t_min >= 0.0 && r.t_min.is_finite()) {
        return Err(crate::error::input(format!("ray {k}: t_min {} must be finite and at least 0", r.t_min)));
    }
    let d = glam::Vec3::from(r.dir);
    let o = if r.t_min > 0.0 && d.length() > 0.0 { glam::Vec3::from(r.origin) + d.normalize() * r.t_min } else { r.origin.into() };
    Ok([[o.x, o.y, o.z, r.t_max - r.t_min], [r.dir[0], r.dir[1], r.dir[2], 1.0]])
}

/// Ray pairs a device batch of `count` rays holds (rows of whole width).
pub fn batch_slots(count: usize) -> crate::error::Result<usize> {
    crate::error::typed(|| {
        let width = BATCH_WIDTH as usize;
        let slots = if count <= width { count.max(1) } else { count.div_ceil(width) * width };
        if slots > u32::MAX as usize / 4 {
            return Err(crate::error::too_large(format!("{count} rays in one batch: at most {} are supported", u32::MAX / 4)));
        }
        Ok(slots)
    })
}
