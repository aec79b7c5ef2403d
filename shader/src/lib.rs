//! Compute entry points of Treelet. Each `<stage>_cs` reads its ids, maps its
//! bindings and calls one function of `treelet-core`, where the logic lives
//! (and where the CPU runner and the tests call it too).
//!
//! Binding 0 of every entry point is its parameter struct; the host's kernel
//! table (`treelet::runtime::kernels`) lists the rest in the same order.
#![cfg_attr(target_arch = "spirv", no_std)]
#![cfg_attr(not(feature = "kernels"), allow(unused_macros))]

/// Runs a phase function once per phase, a workgroup barrier after each,
/// with the phase numbers as literals (checked against the kernel's phase
/// count): the driver's compiler then keeps only each phase's own branch,
/// where a loop over phases pays for the whole function in every phase (on
/// the H100 the sort pass took 1.04 ms per 1M keys looped, 0.66 unrolled).
macro_rules! unrolled_phases {
    ($count:expr, [$($p:literal)*], |$phase:ident| $body:expr) => {{
        const _: () = assert!([$($p),*].len() as u32 == $count);
        $(
            {
                let $phase: u32 = $p;
                $body;
                treelet_core::gpu::workgroup::barrier();
            }
        )*
    }};
}

/// A binding's type in a registry's entry point (`treelet_core::registry`):
/// `read` a shared slice, `write` a mutable one.
macro_rules! slice {
    (read, $t:ty) => { &[$t] };
    (write, $t:ty) => { &mut [$t] };
}

/// A buffer a registry's entry point binds in two parts, as one view.
macro_rules! join {
    (read, $lo:ident, $hi:ident) => {
        let $lo = treelet_core::geometry::split::Split::new($lo, $hi);
    };
    (write, $lo:ident, $hi:ident) => {
        #[allow(unused_mut)]
        let mut $lo = treelet_core::geometry::split::SplitMut::new($lo, $hi);
    };
}

// The entry points come in groups, one per feature of this crate, so that
// the SPIR-V is built one group per rust-gpu run: its linker holds a whole
// run's kernels at once, and all of them in one run peaked at 22 GB
// (host/build.rs lists the groups).
#[cfg(feature = "kernels")]
pub mod agglomerate_subgroup;
#[cfg(feature = "kernels")]
pub mod hploc;
#[cfg(feature = "kernels")]
pub mod multisplit_rank;
#[cfg(feature = "kernels")]
pub mod per_invocation;
#[cfg(feature = "kernels")]
pub mod per_workgroup;
#[cfg(any(feature = "render-linear", feature = "render-bvh2", feature = "render-bvh2-light", feature = "render-bvh4", feature = "render-cwbvh"))]
pub mod render;
#[cfg(feature = "kernels")]
pub mod sort;
#[cfg(feature = "kernels")]
pub mod treelet;

// `#[spirv(compute(threads(256)))]` takes a literal: keep it in step
// (`threads(64)` for the ray kernels of `render`).
const _: () = assert!(treelet_core::WORKGROUP_SIZE == 256);
const _: () = assert!(treelet_core::gpu::workgroup::RAY_WORKGROUP_SIZE == 64);
