//! The entry points of the registry's per-workgroup kernels
//! (`treelet_core::per_workgroup_kernels!`): each is made here from its
//! one declaration, which the host's kernel table and the CPU runner read
//! too.
use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::gpu::workgroup::linear_group;

macro_rules! entry_points {
    ($(
        $(#[doc = $doc:expr])*
        $name:ident = $entry:ident($params:ty) phases($count:expr, [$($phase:literal)*]) shared { $($s:ident : [$st:ty; $sn:expr]),* $(,)? } {
            $($binding:literal $b:ident : $access:ident [$t:ty $(as $cpu:ty)?] $(| $hi_binding:literal $hi:ident)?),* $(,)?
        } |$ph:ident, $lid:ident, $group:ident, $p:ident| $call:expr;
    )*) => {$(
        $(#[doc = $doc])*
        #[spirv(compute(threads(256)))]
        #[allow(clippy::too_many_arguments)]
        pub fn $entry(
            #[spirv(local_invocation_index)] $lid: u32,
            #[spirv(workgroup_id)] workgroup: UVec3,
            #[spirv(num_workgroups)] workgroups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] $p: &$params,
            $(#[spirv(storage_buffer, descriptor_set = 0, binding = $binding)] $b: slice!($access, $t),)*
            $($(#[spirv(storage_buffer, descriptor_set = 0, binding = $hi_binding)] $hi: slice!($access, $t),)?)*
            $(#[spirv(workgroup)] $s: &mut [$st; $sn],)*
        ) {
            // A private copy, kept in registers across the barriers instead
            // of read from the storage buffer again in each phase.
            let $p = &{ *$p };
            let $group = linear_group(workgroup.x, workgroup.y, workgroups.x);
            let _ = $group;
            $($(join!($access, $b, $hi);)?)*
            unrolled_phases!($count, [$($phase)*], |$ph| $call);
        }
    )*};
}

treelet_core::per_workgroup_kernels!(entry_points);

// `threads(256)` above is the workgroup size the host counts these in.
const _: () = assert!(treelet_core::WORKGROUP_SIZE == 256);
