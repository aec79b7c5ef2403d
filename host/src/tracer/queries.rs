//! What [`Tracer`] and [`InstancedTracer`] share: ray queries on a built
//! scene, so that an engine's code can take either. (Each implements it in
//! its own file, by [`ray_queries`]: this file names neither.)
//!
//! [`Tracer`]: crate::tracer::Tracer
//! [`InstancedTracer`]: crate::tracer::InstancedTracer
use crate::error::Result;

use rayon::prelude::*;

use super::rays::{device_pair, hit_record, trace_batch, Ray, RayHit};
use crate::runtime::backend::Backend;

/// Ray queries on a built scene of device `B`: closest hits and occlusion,
/// from host slices or on rays already on the device (see
/// [`Tracer::closest_hits_on_device`](crate::tracer::Tracer::closest_hits_on_device) for their layout), and the device
/// time of the last update.
///
/// ```
/// use treelet::tracer::RayQueries;
/// use treelet::{Backend, CpuBackend, Instance, InstancedTracer, Quality, Ray, Tracer, Triangle};
/// /// How many of `rays` hit something, through either kind of scene.
/// fn hits<B: Backend>(scene: &impl RayQueries<B>, b: &mut B, rays: &[Ray]) -> anyhow::Result<usize> {
///     Ok(scene.closest_hits(b, rays)?.iter().filter(|h| h.is_hit()).count())
/// }
/// let tri = [Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])];
/// let b = &mut CpuBackend::new();
/// let rays = [Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, 1.0]), Ray::new([0.2, 0.2, 0.0], [0.0, 0.0, -1.0])];
/// let one = Tracer::build(b, &[], &tri, Quality::Fast)?;
/// let placed = InstancedTracer::build(b, &[&tri], &[Instance::translated(0, [0.0, 0.0, 0.0])], Quality::Fast)?;
/// assert_eq!((hits(&one, b, &rays)?, hits(&placed, b, &rays)?), (1, 1));
/// # anyhow::Ok(())
/// ```
pub trait RayQueries<B: Backend> {
    /// The closest hit of each ray, with its hit record.
    fn closest_hits(&self, b: &mut B, rays: &[Ray]) -> Result<Vec<RayHit>>;
    /// Whether each ray hits anything up to its `t_max`.
    fn occluded(&self, b: &mut B, rays: &[Ray]) -> Result<Vec<bool>>;
    /// [`RayQueries::closest_hits`] on `count` rays in a device buffer, in place; recorded.
    fn closest_hits_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> Result<()>;
    /// [`RayQueries::occluded`] on `count` rays in a device buffer, in place; recorded.
    fn occluded_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> Result<()>;
    /// Device time of the last build or update, in ms.
    fn last_update_ms(&self) -> f64;
    /// Whether the scene holds nothing to hit: every ray misses, and
    /// nothing is traced.
    fn is_empty(&self) -> bool;

    /// [`RayQueries::closest_hits`] of `count` rays in the caller's own
    /// form: ray `k` is `ray(k)` (asked for in parallel, from several
    /// threads), and its hit is handed to `hit(k, ..)`, in order, on the
    /// caller's thread. On a GPU the rays are written straight into upload memory and
    /// the hits read where they land, both kept between calls: no vector of
    /// rays or hits in between (an engine's or a binding's arrays of
    /// origins, directions and distances; `ray` may be called twice for a
    /// ray). Not in a `dyn RayQueries`.
    ///
    /// ```
    /// use treelet::tracer::RayQueries;
    /// use treelet::{CpuBackend, Quality, Ray, Tracer, Triangle};
    /// let b = &mut CpuBackend::new();
    /// let tracer = Tracer::build(b, &[], &[Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])], Quality::Fast)?;
    /// // Rays as columns: a grid of x over the triangle's corner, looking along +z.
    /// let xs = [0.1f32, 0.5, 0.9, 1.5];
    /// let mut t = vec![0.0; xs.len()];
    /// tracer.closest_hits_with(b, xs.len(), |k| Ray::new([xs[k], 0.05, 0.0], [0.0, 0.0, 1.0]), |k, h| t[k] = h.t)?;
    /// assert_eq!(t, [5.0, 5.0, 5.0, f32::INFINITY]);
    /// # anyhow::Ok(())
    /// ```
    fn closest_hits_with(&self, b: &mut B, count: usize, ray: impl Fn(usize) -> Ray + Sync, mut hit: impl FnMut(usize, RayHit)) -> Result<()>
    where
        Self: Sized,
    {
        self.closest_hits_batch(b, count, ray, |hits| (0..hits.len()).for_each(|k| hit(k, hits.get(k))))
    }

    /// [`RayQueries::closest_hits_with`], the hits handed over all at once
    /// as a [`BatchHits`] (read where they lie in the device's read-back
    /// memory), so that the caller may take them on every core: on the
    /// H200's host, writing a million hits one by one took longer than
    /// tracing them. Returns what `take` returns.
    ///
    /// ```
    /// use rayon::prelude::*;
    /// use treelet::tracer::RayQueries;
    /// use treelet::{CpuBackend, Quality, Ray, Tracer, Triangle};
    /// let b = &mut CpuBackend::new();
    /// let tracer = Tracer::build(b, &[], &[Triangle::new([0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0])], Quality::Fast)?;
    /// let xs: Vec<f32> = (0..1000).map(|k| k as f32 / 500.0).collect();
    /// let ray = |k: usize| Ray::new([xs[k], 0.05, 0.0], [0.0, 0.0, 1.0]);
    /// // The distances, taken on every core.
    /// let t: Vec<f32> = tracer.closest_hits_batch(b, xs.len(), ray, |hits| (0..hits.len()).into_par_iter().map(|k| hits.get(k).t).collect())?;
    /// assert_eq!((t[0], t[999]), (5.0, f32::INFINITY));
    /// # anyhow::Ok(())
    /// ```
    fn closest_hits_batch<T, R: Fn(usize) -> Ray + Sync>(&self, b: &mut B, count: usize, ray: R, take: impl FnOnce(&BatchHits<'_, R>) -> T) -> Result<T>
    where
        Self: Sized,
    {
        crate::error::typed(|| {
            if self.is_empty() {
                check_rays(count, &ray)?;
                return Ok(take(&BatchHits { records: None, ray: &ray, count }));
            }
            trace_batch(b, count, &ray, |b, rays| Ok(self.closest_hits_on_device(b, rays, count)?), |records| {
                take(&BatchHits { records: Some(records), ray: &ray, count })
            })
        })
    }

    /// [`RayQueries::occluded`] of `count` rays in the caller's own form, as
    /// [`RayQueries::closest_hits_with`]: whether ray `ray(k)` hits anything
    /// up to its `t_max` is handed to `occluded(k, ..)`.
    fn occluded_with(&self, b: &mut B, count: usize, ray: impl Fn(usize) -> Ray + Sync, mut occluded: impl FnMut(usize, bool)) -> Result<()>
    where
        Self: Sized,
    {
        self.occluded_batch(b, count, ray, |answers| (0..answers.len()).for_each(|k| occluded(k, answers.get(k))))
    }

    /// [`RayQueries::occluded_with`], the answers handed over all at once
    /// (see [`RayQueries::closest_hits_batch`]).
    fn occluded_batch<T, R: Fn(usize) -> Ray + Sync>(&self, b: &mut B, count: usize, ray: R, take: impl FnOnce(&BatchOccluded<'_>) -> T) -> Result<T>
    where
        Self: Sized,
    {
        crate::error::typed(|| {
            if self.is_empty() {
                check_rays(count, &ray)?;
                return Ok(take(&BatchOccluded { records: None, count }));
            }
            trace_batch(b, count, &ray, |b, rays| Ok(self.occluded_on_device(b, rays, count)?), |records| {
                take(&BatchOccluded { records: Some(records), count })
            })
        })
    }
}

/// The closest hits of a batch ([`RayQueries::closest_hits_batch`]): the
/// device's records, read where they lie, made into [`RayHit`]s as asked
/// for, from any thread.
pub struct BatchHits<'a, R> {
    /// Two `[f32; 4]` a ray; `None` for a scene with nothing to hit.
    records: Option<&'a [[[f32; 4]; 2]]>,
    ray: &'a R,
    count: usize,
}

impl<R: Fn(usize) -> Ray + Sync> BatchHits<'_, R> {
    /// The number of rays.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the batch has no rays.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The hit of ray `k` (`k < len()`).
    pub fn get(&self, k: usize) -> RayHit {
        match self.records {
            Some(records) => hit_record(&(self.ray)(k), records[k]),
            None => RayHit::MISS,
        }
    }
}

/// The answers of an occlusion batch ([`RayQueries::occluded_batch`]).
pub struct BatchOccluded<'a> {
    records: Option<&'a [[[f32; 4]; 2]]>,
    count: usize,
}

impl BatchOccluded<'_> {
    /// The number of rays.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the batch has no rays.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Whether ray `k` hits anything up to its `t_max` (`k < len()`).
    pub fn get(&self, k: usize) -> bool {
        self.records.is_some_and(|records| records[k][0][0] != 0.0)
    }
}

/// The rays of a batch on a scene with nothing to hit, checked as a traced
/// batch checks them (each `t_min`).
fn check_rays(count: usize, ray: &impl Fn(usize) -> Ray) -> anyhow::Result<()> {
    for k in 0..count {
        device_pair(k, &ray(k))?;
    }
    Ok(())
}

/// [`RayQueries::closest_hits`] of a slice, through [`RayQueries::closest_hits_with`].
pub(super) fn collect_hits<B: Backend>(scene: &impl RayQueries<B>, b: &mut B, rays: &[Ray]) -> Result<Vec<RayHit>> {
    let mut out = crate::error::typed(|| crate::internals::input::room_to_fill(rays.len(), "hits of a batch"))?;
    scene.closest_hits_batch(b, rays.len(), |k| rays[k], |hits| (0..hits.len()).into_par_iter().map(|k| hits.get(k)).collect_into_vec(&mut out))?;
    Ok(out)
}

/// [`RayQueries::occluded`] of a slice, through [`RayQueries::occluded_with`].
pub(super) fn collect_occluded<B: Backend>(scene: &impl RayQueries<B>, b: &mut B, rays: &[Ray]) -> Result<Vec<bool>> {
    let mut out = crate::error::typed(|| crate::internals::input::room_to_fill(rays.len(), "answers of a batch"))?;
    scene.occluded_batch(b, rays.len(), |k| rays[k], |answers| (0..answers.len()).into_par_iter().map(|k| answers.get(k)).collect_into_vec(&mut out))?;
    Ok(out)
}

/// Both implement it by their own methods of the same names.
macro_rules! ray_queries {
    ($t:ident) => {
        impl<B: $crate::runtime::backend::Backend> $crate::tracer::queries::RayQueries<B> for $t<B> {
            fn closest_hits(&self, b: &mut B, rays: &[$crate::tracer::rays::Ray]) -> $crate::error::Result<Vec<$crate::tracer::rays::RayHit>> {
                $t::closest_hits(self, b, rays)
            }
            fn occluded(&self, b: &mut B, rays: &[$crate::tracer::rays::Ray]) -> $crate::error::Result<Vec<bool>> {
                $t::occluded(self, b, rays)
            }
            fn closest_hits_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> $crate::error::Result<()> {
                $t::closest_hits_on_device(self, b, rays, count)
            }
            fn occluded_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> $crate::error::Result<()> {
                $t::occluded_on_device(self, b, rays, count)
            }
            fn last_update_ms(&self) -> f64 {
                $t::last_update_ms(self)
            }
            fn is_empty(&self) -> bool {
                $t::is_empty(self)
            }
        }
    };
}
pub(super) use ray_queries;
