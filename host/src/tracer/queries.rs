//! What [`Tracer`] and [`InstancedTracer`] share: ray queries on a built
//! scene, so that an engine's code can take either.
use crate::error::Result;

use super::instances::InstancedTracer;
use super::primitives::Tracer;
use super::rays::{Ray, RayHit};
use crate::runtime::backend::Backend;

/// Ray queries on a built scene of device `B`: closest hits and occlusion,
/// from host slices or on rays already on the device (see
/// [`Tracer::closest_hits_on_device`] for their layout), and the device
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
}

/// Both implement it by their own methods of the same names.
macro_rules! ray_queries {
    ($t:ident) => {
        impl<B: Backend> RayQueries<B> for $t<B> {
            fn closest_hits(&self, b: &mut B, rays: &[Ray]) -> Result<Vec<RayHit>> {
                $t::closest_hits(self, b, rays)
            }
            fn occluded(&self, b: &mut B, rays: &[Ray]) -> Result<Vec<bool>> {
                $t::occluded(self, b, rays)
            }
            fn closest_hits_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> Result<()> {
                $t::closest_hits_on_device(self, b, rays, count)
            }
            fn occluded_on_device(&self, b: &mut B, rays: &B::Buffer, count: usize) -> Result<()> {
                $t::occluded_on_device(self, b, rays, count)
            }
            fn last_update_ms(&self) -> f64 {
                $t::last_update_ms(self)
            }
        }
    };
}
ray_queries!(Tracer);
ray_queries!(InstancedTracer);
