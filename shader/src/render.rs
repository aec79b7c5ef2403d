// Built in groups (this crate's features, one rust-gpu run each; see
// host/build.rs): a group leaves the others' imports and macros unused.
#![cfg_attr(
    not(all(feature = "render-linear", feature = "render-bvh2", feature = "render-bvh2-light", feature = "render-bvh4", feature = "render-cwbvh")),
    allow(unused_imports, unused_macros)
)]
use spirv_std::glam::{UVec3, Vec4};
use spirv_std::spirv;
use treelet_core::geometry::buffers::{Material, Node, InstanceInfo, RenderParams, Sphere};
use treelet_core::geometry::prims::Prims;
use treelet_core::geometry::features::{ALL, CAUSTICS, INDEPENDENT_NUMBERS, INSTANCES};
use treelet_core::geometry::split::Split;
use treelet_core::geometry::triangle::Triangle;
use treelet_core::gpu::workgroup::{RAY_WORKGROUP_SIZE, linear_id, linear_id_in};
use treelet_core::render::caustics::light_paths;
use treelet_core::render::integrator::{SceneRefs, accumulate, render_pixel, tiled_pixel};
use treelet_core::render::lights::Light;
use treelet_core::trace::bvh2::{Bvh2Tree, Level};
use treelet_core::trace::bvh4::Bvh4Tree;
use treelet_core::trace::classic::{ClassicTree, Scan};
use treelet_core::trace::cwbvh::{WORKGROUP_STACK_WORDS, WideTree};
use treelet_core::trace::with_instances::SceneWithInstances;

/// What a pass of the render kernels adds to: the pixel sums (camera
/// paths), or the light paths' landings (f32 bits, added with atomics).
macro_rules! pass_target {
    (camera) => { [f32; 4] };
    (light) => { u32 };
}

/// A pass's work for one pixel: its camera paths, added to its sums, or
/// its light paths (`treelet_core::render::caustics`), landing anywhere.
macro_rules! pass_body {
    (camera, $pixel:ident, $params:ident, $scene:ident, $lights:ident, $accum:ident, $features:expr) => {
        let sums = render_pixel::<_, { $features }, 1>($pixel, $params, &$scene, $lights, &mut [0u32; 1], 0);
        accumulate(&mut $accum[$pixel as usize], sums);
    };
    (light, $pixel:ident, $params:ident, $scene:ident, $lights:ident, $accum:ident, $features:expr) => {
        light_paths::<_, { $features }, 1, [u32]>($pixel, $params, &$scene, $lights, $accum, &mut [0u32; 1], 0);
    };
}

/// One path-tracing entry point: `render_pixel` for one closest-hit method
/// (`$tree` made from bindings 3 and 4) and one feature set (see
/// `treelet_core::for_each_render_variant!`). The stack stays private.
/// The `bvh2` and `cwbvh` layouts' records are bound as 16-byte vectors, read one
/// vector per load (`treelet_core::geometry::records`).
macro_rules! render_kernel {
    // Trees in the `bvh2` layout: nodes, leaf primitives and triangles may
    // each pass one binding (`treelet_core::geometry::split`). The `cwbvh`
    // layout is not built past one binding yet, and its traversal lost 4%
    // of its diffuse rays/s to the split's branch (H100): it binds whole.
    ($pass:ident $name:ident, $node:ty, $prim:ty, $tree:path, $features:expr) => {
        #[spirv(compute(threads(64)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[$node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prims: &[$prim],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] accum: &mut [pass_target!($pass)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] lights: &[Light],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] triangles_hi: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] nodes_hi: &[$node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] prims_hi: &[$prim],
        ) {
            let pixel = tiled_pixel(linear_id_in(gid.x, gid.y, groups.x, RAY_WORKGROUP_SIZE), params.width, params.height);
            if pixel != u32::MAX {
                let tree = $tree(Split::new(nodes, nodes_hi), Split::new(prims, prims_hi));
                let scene = SceneRefs::new(params, spheres, Split::new(triangles, triangles_hi), materials, tree);
                pass_body!($pass, pixel, params, scene, lights, accum, $features);
            }
        }
    };
    // The scan, the seed's layout and `cwbvh`: their buffers in one
    // binding each, triangles still in one or two parts.
    ($pass:ident whole $name:ident, $node:ty, $prim:ty, $tree:path, $features:expr) => {
        #[spirv(compute(threads(64)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[$node],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prims: &[$prim],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] accum: &mut [pass_target!($pass)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] lights: &[Light],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] triangles_hi: &[Triangle],
        ) {
            let pixel = tiled_pixel(linear_id_in(gid.x, gid.y, groups.x, RAY_WORKGROUP_SIZE), params.width, params.height);
            if pixel != u32::MAX {
                let scene = SceneRefs::new(params, spheres, Split::new(triangles, triangles_hi), materials, $tree(nodes, prims));
                pass_body!($pass, pixel, params, scene, lights, accum, $features);
            }
        }
    };
}

/// The render entry points of every variant of
/// `treelet_core::for_each_render_variant!`: a module per variant
/// (`render::<variant>::`) with the scan and the two layouts `auto` picks.
macro_rules! render_entry_points {
    ([] $($i:literal $name:ident [$($f:path),*];)*) => {
        $(
            pub mod $name {
                use super::*;
                #[cfg(feature = "render-linear")]
                render_kernel!(camera whole linear_cs, Node, u32, Scan::new, 0 $(| $f)*);
                #[cfg(feature = "render-bvh2")]
                render_kernel!(camera bvh2_cs, Vec4, Vec4, Bvh2Tree::new, 0 $(| $f)*);
                #[cfg(feature = "render-bvh4")]
                render_kernel!(camera whole bvh4_cs, Vec4, Vec4, Bvh4Tree::new, 0 $(| $f)*);
                #[cfg(feature = "render-cwbvh")]
                render_kernel!(camera whole cwbvh_cs, Vec4, Vec4, WideTree::new, 0 $(| $f)*);
                #[cfg(feature = "render-linear")]
                render_kernel!(light whole light_linear_cs, Node, u32, Scan::new, 0 $(| $f)*);
                #[cfg(feature = "render-bvh2-light")]
                render_kernel!(light light_bvh2_cs, Vec4, Vec4, Bvh2Tree::new, 0 $(| $f)*);
                #[cfg(feature = "render-bvh4")]
                render_kernel!(light whole light_bvh4_cs, Vec4, Vec4, Bvh4Tree::new, 0 $(| $f)*);
                #[cfg(feature = "render-cwbvh")]
                render_kernel!(light whole light_cwbvh_cs, Vec4, Vec4, WideTree::new, 0 $(| $f)*);
            }
        )*
    };
}
treelet_core::for_each_render_variant!(render_entry_points);

// The seed's layout, kept for comparison: the general kernel only
// (`render::classic_cs`).
#[cfg(feature = "render-linear")]
render_kernel!(camera whole classic_cs, Node, u32, ClassicTree::new, ALL);

/// The binding element types of a layout's nodes and leaf primitives:
/// 16-byte vectors (`records`) or the seed's `Node`s and `u32`s (`classic`).
macro_rules! node_type {
    (records) => { Vec4 };
    (classic) => { Node };
}
macro_rules! prim_type {
    (records) => { Vec4 };
    (classic) => { u32 };
}

/// Ray-casting throughput: one primary or one diffuse ray per pixel,
/// through one layout (`$new` over bindings 3 and 4), its stack private,
/// testing the primitive kinds of `$features`.
macro_rules! cast_kernel {
    // As `render_kernel!`: the `bvh2` layout's buffers in one or two parts.
    (split $records:ident $name:ident, $new:path, $features:expr) => {
        #[spirv(compute(threads(64)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[node_type!($records)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prims: &[prim_type!($records)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] rays: &mut [[f32; 4]],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] triangles_hi: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] nodes_hi: &[node_type!($records)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] prims_hi: &[prim_type!($records)],
        ) {
            let id = linear_id_in(gid.x, gid.y, groups.x, RAY_WORKGROUP_SIZE);
            let tree = $new(Split::new(nodes, nodes_hi), Split::new(prims, prims_hi));
            let scene = SceneRefs::new(params, spheres, Split::new(triangles, triangles_hi), materials, tree);
            treelet_core::render::rays::cast_kernel::<_, { $features }, 1>(id, params, &scene, rays, &mut [0u32; 1], 0);
        }
    };
    (whole $records:ident $name:ident, $new:path, $features:expr) => {
        #[spirv(compute(threads(64)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[node_type!($records)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prims: &[prim_type!($records)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] rays: &mut [[f32; 4]],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] triangles_hi: &[Triangle],
        ) {
            let id = linear_id_in(gid.x, gid.y, groups.x, RAY_WORKGROUP_SIZE);
            let scene = SceneRefs::new(params, spheres, Split::new(triangles, triangles_hi), materials, $new(nodes, prims));
            treelet_core::render::rays::cast_kernel::<_, { $features }, 1>(id, params, &scene, rays, &mut [0u32; 1], 0);
        }
    };
}

/// The cast entry points of `treelet_core::for_each_cast_kernel!`, each in
/// its build group.
macro_rules! cast_entry_points {
    ([] $($method:ident $triangles:literal $group:literal $bound:ident $records:ident $name:ident $new:path, $features:path;)*) => {
        $(
            #[cfg(feature = $group)]
            cast_kernel!($bound $records $name, $new, $features);
        )*
    };
}
treelet_core::for_each_cast_kernel!(cast_entry_points);

/// As `cast_cwbvh_cs`, the top of each ray's stack in workgroup memory.
#[cfg(feature = "render-cwbvh")]
#[spirv(compute(threads(256)))]
pub fn cast_cwbvh_workgroup_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(local_invocation_index)] lane: u32,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prims: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] rays: &mut [[f32; 4]],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] triangles_hi: &[Triangle],
    #[spirv(workgroup)] stack: &mut [u32; WORKGROUP_STACK_WORDS],
) {
    let id = linear_id(gid.x, gid.y, groups.x);
    let tree = WideTree::new(nodes, prims);
    let scene = SceneRefs::new(params, spheres, Split::new(triangles, triangles_hi), materials, tree);
    treelet_core::render::rays::cast_kernel::<_, ALL, WORKGROUP_STACK_WORDS>(id, params, &scene, rays, stack, lane);
}

/// An engine's rays through an instanced scene: the top-level tree over
/// the instances, then each instance's mesh tree (bindings: see
/// `treelet_core::render::rays::cast_instances_kernel`).
#[cfg(feature = "render-bvh2")]
#[spirv(compute(threads(64)))]
pub fn cast_instances_cs(
    #[spirv(global_invocation_id)] gid: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] instances: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] nodes: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] leaves: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] spheres: &[Sphere],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] rays: &mut [[f32; 4]],
) {
    let id = linear_id_in(gid.x, gid.y, groups.x, RAY_WORKGROUP_SIZE);
    // Bound whole: the part past the split (the same slice) is never read.
    let prims = Prims { spheres, sphere_count: 0, triangles: Split::new(triangles, triangles), triangle_count: params.triangles };
    treelet_core::render::rays::cast_instances_kernel(
        id, params, instances, nodes, leaves, &prims, rays,
    );
}

/// The render of a scene with instances of meshes: its own primitives
/// through their `bvh2` tree, the copies through the instanced walk
/// (`treelet_core::trace::with_instances`); every feature, camera paths
/// (`render_instanced_cs`, and `render_instanced_caustics_cs` beside light paths)
/// and light paths for caustics (`light_instanced_cs`).
/// The own tree's bindings as `render::<variant>::bvh2_cs`'s, then the
/// copies': instance records, their `InstanceInfo`s, the top level and mesh
/// trees, their leaf primitives, every mesh's triangles, and the materials
/// of mesh triangles and copies.
macro_rules! instanced_kernel {
    ($pass:ident $name:ident, $features:expr) => {
        #[spirv(compute(threads(64)))]
        pub fn $name(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &RenderParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] spheres: &[Sphere],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] materials: &[Material],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] nodes: &[Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] prims: &[Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] accum: &mut [pass_target!($pass)],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] lights: &[Light],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 8)] instances: &[Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] info: &[InstanceInfo],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] instance_nodes: &[Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 11)] instance_leaves: &[Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 12)] instance_triangles: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 13)] instance_materials: &[Material],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 14)] triangles_hi: &[Triangle],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 15)] nodes_hi: &[Vec4],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 16)] prims_hi: &[Vec4],
        ) {
            let pixel = tiled_pixel(linear_id_in(gid.x, gid.y, groups.x, RAY_WORKGROUP_SIZE), params.width, params.height);
            if pixel != u32::MAX {
                let own = Bvh2Tree::new(Split::new(nodes, nodes_hi), Split::new(prims, prims_hi));
                // Bound whole: the part past the split (the same slice) is never read.
                let meshes = Prims {
                    spheres,
                    sphere_count: 0,
                    triangles: Split::new(instance_triangles, instance_triangles),
                    triangle_count: params.instance_triangles,
                };
                let tree = SceneWithInstances {
                    own,
                    instances,
                    info,
                    count: params.instances,
                    trees: Level { nodes: instance_nodes, leaves: instance_leaves },
                    meshes,
                    materials: instance_materials,
                };
                let scene = SceneRefs::new(params, spheres, Split::new(triangles, triangles_hi), materials, tree);
                pass_body!($pass, pixel, params, scene, lights, accum, $features);
            }
        }
    };
}
// Camera paths without the light paths' split of path space
// (`treelet_core::render::caustics`) where none are traced: compiled in,
// it made the placed render 1.7% slower with NEE (H100).
// Placed copies' kernels draw either sampler's numbers, as the render asks.
#[cfg(feature = "render-bvh2-light")]
instanced_kernel!(camera render_instanced_cs, ALL | INSTANCES | INDEPENDENT_NUMBERS);
#[cfg(feature = "render-bvh2-light")]
instanced_kernel!(camera render_instanced_caustics_cs, ALL | INSTANCES | CAUSTICS | INDEPENDENT_NUMBERS);
#[cfg(feature = "render-bvh2-light")]
instanced_kernel!(light light_instanced_cs, ALL | INSTANCES | CAUSTICS | INDEPENDENT_NUMBERS);
