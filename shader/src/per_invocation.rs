//! The entry points of the registry's per-invocation kernels
//! (`treelet_core::registry`): each is made here from its one declaration,
//! which the host's kernel table and the CPU runner read too.
use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::gpu::workgroup::linear_id;

macro_rules! entry_points {
    ($(
        $(#[doc = $doc:expr])*
        $(#[relaxed_of($ordered:ident)])?
        $name:ident = $entry:ident($params:ty) {
            $($binding:literal $b:ident : $access:ident [$t:ty $(as $cpu:ty)?] $(| $hi_binding:literal $hi:ident)?),* $(,)?
        } |$id:ident, $p:ident| $call:expr;
    )*) => {$(
        $(#[doc = $doc])*
        #[spirv(compute(threads(256)))]
        pub fn $entry(
            #[spirv(global_invocation_id)] gid: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] $p: &$params,
            $(#[spirv(storage_buffer, descriptor_set = 0, binding = $binding)] $b: slice!($access, $t),)*
            $($(#[spirv(storage_buffer, descriptor_set = 0, binding = $hi_binding)] $hi: slice!($access, $t),)?)*
        ) {
            let $id = linear_id(gid.x, gid.y, groups.x);
            $($(join!($access, $b, $hi);)?)*
            $call;
        }
    )*};
}

treelet_core::per_invocation_kernels!(entry_points);

// `threads(256)` above is the workgroup size the host counts these in.
const _: () = assert!(treelet_core::WORKGROUP_SIZE == 256);
