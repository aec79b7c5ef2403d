//! Ray-casting throughput: the two workloads a path tracer's speed is made
//! of, cast alone. Primary rays go from the camera to their first hit;
//! diffuse rays leave that hit in a cosine-distributed direction (incoherent,
//! the hard case for a BVH). Each pixel casts one of each, in two passes.
use glam::Vec3;

use crate::layout::RenderParams;
use crate::features;
use crate::render::{closest_hit, cosine_direction, hit_normal, surface_offset, tiled_pixel, SceneRefs};
use crate::rng::BounceRng;
use crate::traverse::{ClosestHit, Origin};

/// [`RenderParams::cast_mode`]: camera rays, which leave the diffuse rays.
pub const CAST_PRIMARY: u32 = 0;
/// [`RenderParams::cast_mode`]: the diffuse rays the primary pass left.
pub const CAST_DIFFUSE: u32 = 1;

/// Kernel (one invocation per pixel, in tiles: see
/// [`crate::render::tiled_pixel`]): casts the ray of invocation
/// `invocation`'s pixel `id` and writes
/// `rays[2 id]` = (origin, 1 if a ray is to be cast, else 0) and
/// `rays[2 id + 1]` = (direction, bits of the primitive it leaves) for the
/// diffuse pass; the diffuse pass writes its hit distance into the last.
pub fn cast_kernel<T: ClosestHit, const S: usize>(
    invocation: u32,
    params: &RenderParams,
    scene: &SceneRefs<T>,
    rays: &mut [[f32; 4]],
    stack: &mut [u32; S],
    lane: u32,
) {
    let (w, h) = (params.width, params.height);
    let id = tiled_pixel(invocation, w, h);
    if id == u32::MAX {
        return;
    }
    let (i, j) = (2 * id as usize, 2 * id as usize + 1);
    if params.cast_mode == CAST_PRIMARY {
        let rng = BounceRng::new(params.seed, id, params.first_sample, 0);
        let (o, d) = params.camera.primary_ray(id % w, h - 1 - id / w, 0, w, h, &rng);
        let hit = closest_hit::<T, { features::ALL }, S>(o, d, Origin::NONE, scene, stack, lane);
        if !hit.is_hit() {
            rays[i] = [0.0; 4];
            return;
        }
        let x = o + d * hit.t;
        let n = hit_normal(&scene.prims, hit.prim, x, d);
        let nl = if n.dot(d) < 0.0 { n } else { -n };
        let bounce = BounceRng::new(params.seed, id, params.first_sample, 1);
        let d2 = cosine_direction(nl, bounce.uniform(1), bounce.uniform(2));
        let o2 = x + nl * surface_offset(x);
        rays[i] = [o2.x, o2.y, o2.z, 1.0];
        rays[j] = [d2.x, d2.y, d2.z, f32::from_bits(hit.prim)];
    } else if rays[i][3] != 0.0 {
        let o = Vec3::new(rays[i][0], rays[i][1], rays[i][2]);
        let d = Vec3::new(rays[j][0], rays[j][1], rays[j][2]);
        let prim = rays[j][3].to_bits();
        // Leaving the surface outwards: it cannot be hit again.
        let hit = closest_hit::<T, { features::ALL }, S>(o, d, Origin { prim, into: false }, scene, stack, lane);
        rays[i][3] = if hit.is_hit() { hit.t } else { -1.0 };
    }
}
