//! Ray-casting throughput: the two workloads a path tracer's speed is made
//! of, cast alone. Primary rays go from the camera to their first hit;
//! diffuse rays leave that hit in a cosine-distributed direction (incoherent,
//! the hard case for a BVH). Each pixel casts one of each, in three passes:
//! the camera rays, then the bounce rays made from their hits, then the
//! bounce rays cast. The first and the last are what is timed, as the
//! OptiX peer times its intersection launches alone.
use glam::Vec3;

use crate::geometry::buffers::{Bvh2Node, InstanceRecord, LeafPrim, RenderParams};
use crate::geometry::records::RecordLoad;
use crate::trace::instances::{trace_instances, InstanceHit};
use crate::geometry::intersect::{MISS, surface_offset};
use crate::geometry::prims::{Origin, Prims};
use crate::geometry::triangle::{WatertightRay, ray_triangle_barycentrics};
use crate::geometry::flat::ray_plane_coordinates;
use crate::gpu::rng::BounceRng;
use crate::render::integrator::{SceneRefs, closest_hit, hit_normal_for, tiled_pixel, trace};
use crate::render::sampling::cosine_direction;
use crate::trace::hit::{ClosestHit, Hit, Query};

/// [`RenderParams::cast_mode`]: camera rays; each pixel keeps its hit.
pub const CAST_PRIMARY: u32 = 0;
/// [`RenderParams::cast_mode`]: the diffuse rays the bounce pass made.
pub const CAST_DIFFUSE: u32 = 1;
/// [`RenderParams::cast_mode`]: a diffuse bounce ray from each camera hit
/// (no tracing).
pub const CAST_BOUNCE: u32 = 2;
/// [`RenderParams::cast_mode`]: the caller's own rays (an engine's batch):
/// `rays[2 id]` = (origin, farthest hit distance), `rays[2 id + 1]` =
/// (direction, 1 to trace or 0 to skip); the closest hit replaces the
/// first: (distance along the normalized direction, bits of the primitive,
/// b1, b2), the primitive `u32::MAX` for none; `b1`, `b2` are a triangle's
/// barycentric coordinates of the hit (of `v1` and `v2`: the point is
/// `(1 - b1 - b2) v0 + b1 v1 + b2 v2`), 0 for a sphere.
pub const CAST_RAYS: u32 = 3;
/// [`RenderParams::cast_mode`]: occlusion queries of the caller's rays, laid
/// out as for [`CAST_RAYS`]: whether anything is hit up to the farthest
/// distance replaces the first: (1 or 0, 0, 0, 0). The walk stops at the
/// first hit it finds.
pub const CAST_OCCLUDED: u32 = 4;
/// [`RenderParams::cast_mode`]: the diffuse rays the bounce pass made, as
/// occlusion queries at any distance (shadow rays toward an infinitely far
/// light): as [`CAST_DIFFUSE`], with the distance of the first hit found.
pub const CAST_DIFFUSE_OCCLUDED: u32 = 5;

/// Kernel (one invocation per pixel, in tiles: see
/// [`crate::render::integrator::tiled_pixel`]), for pixel `id` of invocation
/// `invocation`, by `params.cast_mode`:
/// * [`CAST_PRIMARY`]: casts the camera ray; `rays[2 id]` = (hit
///   distance, bits of the primitive hit or `u32::MAX`, 0, 0);
/// * [`CAST_BOUNCE`]: from that hit, `rays[2 id]` = (origin, 1 if a ray is
///   to be cast, else 0) and `rays[2 id + 1]` = (direction, bits of the
///   primitive it leaves);
/// * [`CAST_DIFFUSE`]: casts that ray and writes its hit distance (or -1)
///   into `rays[2 id][3]`; [`CAST_DIFFUSE_OCCLUDED`] as an occlusion query;
/// * [`CAST_RAYS`], [`CAST_OCCLUDED`]: the caller's rays (a closest hit
///   writes `(t, prim, b1, b2)` into `rays[2 id]` and the unit geometric
///   normal into `rays[2 id + 1]`).
///
/// `F` (see [`crate::geometry::features`]) may leave out the tests of primitive kinds
/// the scene lacks.
pub fn cast_kernel<T: ClosestHit, const F: u32, const S: usize>(
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
    if params.cast_mode == CAST_RAYS || params.cast_mode == CAST_OCCLUDED {
        let EngineRay { o, d, query, marked } = engine_ray(params, rays, id);
        if marked {
            let hit = if query.t_max >= 0.0 { trace::<T, F, S>(o, d, Origin::NONE, query, scene, stack, lane) } else { Hit::NONE };
            let found = hit.is_hit() && hit.t <= query.t_max;
            let record = if found {
                let (b1, b2) = barycentrics::<F>(&scene.prims, hit.prim, o, d);
                let n = geometric_normal::<F>(&scene.prims, hit.prim, o + d * hit.t);
                Some(([hit.t, f32::from_bits(hit.prim), b1, b2], [n.x, n.y, n.z, 0.0]))
            } else {
                None
            };
            write_engine_hit(params, rays, id, found, record);
        }
    } else if params.cast_mode == CAST_PRIMARY {
        let (o, d) = camera_ray(params, id);
        let hit = closest_hit::<T, F, S>(o, d, Origin::NONE, scene, stack, lane);
        rays[i] = [hit.t, f32::from_bits(hit.prim), 0.0, 0.0];
    } else if params.cast_mode == CAST_BOUNCE {
        let (t, prim) = (rays[i][0], rays[i][1].to_bits());
        if prim == u32::MAX {
            rays[i] = [0.0; 4];
            return;
        }
        let (o, d) = camera_ray(params, id);
        let x = o + d * t;
        let n = hit_normal_for::<F>(&scene.prims, prim, x, d);
        let nl = if n.dot(d) < 0.0 { n } else { -n };
        let bounce = BounceRng::new(params.seed, id, params.first_sample, 1);
        let d2 = cosine_direction(nl, bounce.uniform(1), bounce.uniform(2));
        let o2 = x + nl * surface_offset(x);
        rays[i] = [o2.x, o2.y, o2.z, 1.0];
        rays[j] = [d2.x, d2.y, d2.z, f32::from_bits(prim)];
    } else if rays[i][3] != 0.0 {
        let o = Vec3::new(rays[i][0], rays[i][1], rays[i][2]);
        let d = Vec3::new(rays[j][0], rays[j][1], rays[j][2]);
        let prim = rays[j][3].to_bits();
        // Leaving the surface outwards: it cannot be hit again.
        let query = if params.cast_mode == CAST_DIFFUSE_OCCLUDED { Query::occlusion(MISS, u32::MAX) } else { Query::CLOSEST };
        let hit = trace::<T, F, S>(o, d, Origin { prim, into: false }, query, scene, stack, lane);
        rays[i][3] = if hit.is_hit() { hit.t } else { -1.0 };
    }
}

/// Kernel (one invocation per ray, in tiles as [`cast_kernel`]): an
/// engine's rays ([`CAST_RAYS`], [`CAST_OCCLUDED`]) through an instanced
/// scene ([`crate::trace::instances`]: the top-level tree `top_nodes`,
/// `top_leaves` over `instances`; the meshes' trees `nodes`, `leaves`; their
/// triangles in `prims`, one mesh after another). A closest hit writes
/// `(t, primitive within its mesh, b1, b2)` and `(unit world normal, bits
/// of the instance)`, as [`cast_kernel`] does for one mesh.
#[allow(clippy::too_many_arguments)]
pub fn cast_instances_kernel(
    invocation: u32,
    params: &RenderParams,
    instances: &(impl RecordLoad<InstanceRecord> + ?Sized),
    nodes: &(impl RecordLoad<Bvh2Node> + ?Sized),
    leaves: &(impl RecordLoad<LeafPrim> + ?Sized),
    prims: &Prims,
    rays: &mut [[f32; 4]],
) {
    let id = tiled_pixel(invocation, params.width, params.height);
    if id == u32::MAX || (params.cast_mode != CAST_RAYS && params.cast_mode != CAST_OCCLUDED) {
        return;
    }
    let EngineRay { o, d, query, marked } = engine_ray(params, rays, id);
    if !marked {
        return;
    }
    let hit = if query.t_max >= 0.0 && params.instances > 0 {
        trace_instances(o, d, query, instances, nodes, leaves, prims)
    } else {
        InstanceHit { t: MISS, prim: u32::MAX, instance: u32::MAX }
    };
    let found = hit.is_hit() && hit.t <= query.t_max;
    let record = if found && params.cast_mode == CAST_RAYS {
        // The barycentrics by the traversal's own test, in the mesh's space;
        // the ray read again, so that it is not held through the walk.
        let EngineRay { o, d, .. } = engine_ray(params, rays, id);
        let instance = instances.load(hit.instance as usize);
        let tri = prims.triangle(instance.triangle_base + hit.prim);
        let (o2, d2) = instance.to_object(o, d);
        let (_, b1, b2) = ray_triangle_barycentrics(&WatertightRay::new(o2, d2), &tri, MISS);
        let (a, b, c) = (Vec3::from_array(tri.v0), Vec3::from_array(tri.v1), Vec3::from_array(tri.v2));
        let n = instance.normal_to_world((b - a).cross(c - a)).normalize_or_zero();
        Some(([hit.t, f32::from_bits(hit.prim), b1, b2], [n.x, n.y, n.z, f32::from_bits(hit.instance)]))
    } else {
        None
    };
    write_engine_hit(params, rays, id, found, record);
}

/// An engine's ray ([`CAST_RAYS`], [`CAST_OCCLUDED`]), read by [`engine_ray`].
#[derive(Clone, Copy)]
pub struct EngineRay {
    pub o: Vec3,
    /// Unit direction.
    pub d: Vec3,
    pub query: Query,
    /// The ray is marked to be traced (else its slots stay as they are).
    pub marked: bool,
}

/// An engine's ray `id`: origin, unit direction and the query to trace. A
/// ray with no direction or an invalid `t_max` gets a query with a
/// negative `t_max`: not to be traced, it finds nothing. (A struct, not an
/// `Option`: rust-gpu cannot make an `Option` of vectors.)
#[inline]
pub fn engine_ray(params: &RenderParams, rays: &[[f32; 4]], id: u32) -> EngineRay {
    let (i, j) = (2 * id as usize, 2 * id as usize + 1);
    let (o, d) = (Vec3::new(rays[i][0], rays[i][1], rays[i][2]), Vec3::new(rays[j][0], rays[j][1], rays[j][2]));
    let len = d.length();
    // An infinite `t_max` is no bound; a NaN one finds nothing.
    let mut t_max = rays[i][3];
    if !(len > 0.0 && len.is_finite() && t_max >= 0.0) {
        t_max = -1.0;
    }
    let query = if params.cast_mode == CAST_OCCLUDED { Query::occlusion(t_max, u32::MAX) } else { Query::closest_within(t_max) };
    EngineRay { o, d: d / len.max(f32::MIN_POSITIVE), query, marked: rays[j][3] != 0.0 }
}

/// Writes what ray `id` found: for an occlusion query whether it `found`
/// anything; for a closest hit its `record` (hit, and normal with the
/// instance), or a miss.
#[inline]
pub fn write_engine_hit(params: &RenderParams, rays: &mut [[f32; 4]], id: u32, found: bool, record: Option<([f32; 4], [f32; 4])>) {
    let (i, j) = (2 * id as usize, 2 * id as usize + 1);
    if params.cast_mode == CAST_OCCLUDED {
        rays[i] = [found as u32 as f32, 0.0, 0.0, 0.0];
    } else if let Some((hit, normal)) = record {
        rays[i] = hit;
        rays[j] = normal;
    } else {
        rays[i] = [f32::INFINITY, f32::from_bits(u32::MAX), 0.0, 0.0];
        rays[j] = [0.0, 0.0, 0.0, f32::from_bits(u32::MAX)];
    }
}

/// The unit geometric normal of primitive `prim` at `x`: a sphere's outward
/// one, a triangle's `(v1 - v0) x (v2 - v0)`; zero where it has none.
#[inline]
fn geometric_normal<const F: u32>(prims: &Prims, prim: u32, x: Vec3) -> Vec3 {
    if prims.is_sphere::<F>(prim) {
        (x - Vec3::from_array(prims.spheres[prim as usize].center)).normalize_or_zero()
    } else {
        let t = &prims.triangle(prim - prims.sphere_count);
        let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
        (b - a).cross(c - a).normalize_or_zero()
    }
}

/// The barycentric coordinates (of `v1`, `v2`) where the ray `o + t d` hits
/// primitive `prim`, by the traversal's own test; 0 for a sphere. For a
/// disk or parallelogram, its coordinates along its two edges: the hit is
/// `v0 + b1 (v1 - v0) + b2 (v2 - v0)` for every flat shape.
#[inline]
fn barycentrics<const F: u32>(prims: &Prims, prim: u32, o: Vec3, d: Vec3) -> (f32, f32) {
    if prims.is_sphere::<F>(prim) {
        return (0.0, 0.0);
    }
    let tri = &prims.triangle(prim - prims.sphere_count);
    if crate::geometry::prims::is_shape::<F>(tri) {
        let (_, x, y) = ray_plane_coordinates(o, d, tri, MISS);
        return (x, y);
    }
    let (_, b1, b2) = ray_triangle_barycentrics(&WatertightRay::new(o, d), tri, MISS);
    (b1, b2)
}

/// Pixel `id`'s camera ray (its first subpixel, sample `first_sample`).
#[inline]
fn camera_ray(params: &RenderParams, id: u32) -> (Vec3, Vec3) {
    let (w, h) = (params.width, params.height);
    let rng = BounceRng::new(params.seed, id, params.first_sample, 0);
    params.camera.primary_ray(id % w, h - 1 - id / w, 0, w, h, (rng.uniform(0), rng.uniform(1)))
}
