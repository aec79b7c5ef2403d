//! The one place where the GPU and CPU builds differ: atomics.
//!
//! On SPIR-V these are `OpAtomic*` instructions (rust-gpu's Vulkan memory
//! model; device-scope atomics need the `VulkanMemoryModelDeviceScope`
//! capability and therefore wgpu's SPIR-V passthrough). On the host they are
//! `core::sync::atomic` operations. The CPU runner executes invocations one
//! after another, so the host versions never race; they are atomics only so
//! that the code means the same thing on both sides.
#[cfg(target_arch = "spirv")]
use spirv_std::memory::{Scope, Semantics};

#[cfg(target_arch = "spirv")]
const DEVICE: u32 = Scope::Device as u32;
#[cfg(target_arch = "spirv")]
const WORKGROUP: u32 = Scope::Workgroup as u32;
/// Acquire-release on storage buffers.
#[cfg(target_arch = "spirv")]
const ACQ_REL_STORAGE: u32 = Semantics::ACQUIRE_RELEASE.bits() | Semantics::UNIFORM_MEMORY.bits();
#[cfg(target_arch = "spirv")]
const RELAXED: u32 = Semantics::NONE.bits();

/// `slot` as an atomic on the host: what the unstable `AtomicU32::from_mut`
/// does, on stable Rust (so that crates depending on Treelet build on any
/// toolchain).
#[cfg(not(target_arch = "spirv"))]
#[inline]
fn host_atomic(slot: &mut u32) -> &core::sync::atomic::AtomicU32 {
    use core::sync::atomic::AtomicU32;
    const _: () = assert!(core::mem::align_of::<AtomicU32>() == core::mem::align_of::<u32>());
    // SAFETY: `slot` is valid, aligned (asserted above) and exclusively
    // borrowed for the returned reference's lifetime, so no other access,
    // atomic or not, can overlap it.
    unsafe { AtomicU32::from_ptr(slot) }
}

/// Adds `value` to a storage-buffer counter with device scope, relaxed;
/// returns the previous value.
#[inline]
pub fn add_device(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_i_add::<u32, DEVICE, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        use core::sync::atomic::Ordering;
        host_atomic(slot).fetch_add(value, Ordering::Relaxed)
    }
}

/// Adds `value` to a storage-buffer counter with device scope and
/// acquire-release ordering on storage buffers; returns the previous value.
///
/// Mesa's lavapipe (22.3) mis-executes such atomics (and memory barriers) in
/// divergent control flow: kernels that need one there come in an ordered
/// and a relaxed variant, and the host picks the relaxed one on CPU
/// adapters, whose threads share coherent caches.
#[inline]
pub fn add_device_acq_rel(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_i_add::<u32, DEVICE, ACQ_REL_STORAGE>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        use core::sync::atomic::Ordering;
        host_atomic(slot).fetch_add(value, Ordering::AcqRel)
    }
}

/// Adds `value` to the f32 whose bits are in a storage-buffer word, with
/// device scope, relaxed: a compare-exchange loop (float atomics need an
/// extension not every device has).
#[inline]
pub fn add_f32_device(slot: &mut u32, value: f32) {
    #[cfg(target_arch = "spirv")]
    unsafe {
        let mut old = spirv_std::arch::atomic_load::<u32, DEVICE, RELAXED>(slot);
        loop {
            let new = (f32::from_bits(old) + value).to_bits();
            let seen = spirv_std::arch::atomic_compare_exchange::<u32, DEVICE, RELAXED, RELAXED>(slot, new, old);
            if seen == old {
                break;
            }
            old = seen;
        }
    }
    #[cfg(not(target_arch = "spirv"))]
    add_f32_host(host_atomic(slot), value);
}

/// [`add_f32_device`] on the host, for words that threads share (the CPU
/// runner's light paths): the same compare-exchange loop.
#[cfg(not(target_arch = "spirv"))]
#[inline]
pub fn add_f32_host(slot: &core::sync::atomic::AtomicU32, value: f32) {
    use core::sync::atomic::Ordering::Relaxed;
    let mut old = slot.load(Relaxed);
    while let Err(seen) = slot.compare_exchange_weak(old, (f32::from_bits(old) + value).to_bits(), Relaxed, Relaxed) {
        old = seen;
    }
}

/// Swaps `value` into a storage-buffer word with device scope, relaxed;
/// returns the previous value.
#[inline]
pub fn exchange_device(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_exchange::<u32, DEVICE, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        use core::sync::atomic::Ordering;
        host_atomic(slot).swap(value, Ordering::Relaxed)
    }
}

/// [`exchange_device`] with acquire-release ordering on storage buffers (see
/// [`add_device_acq_rel`] for the device that needs the relaxed one).
#[inline]
pub fn exchange_device_acq_rel(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_exchange::<u32, DEVICE, ACQ_REL_STORAGE>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        use core::sync::atomic::Ordering;
        host_atomic(slot).swap(value, Ordering::AcqRel)
    }
}

/// Raises a storage-buffer word to at least `value` with device scope,
/// relaxed; returns the previous value.
#[inline]
pub fn max_device(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_u_max::<u32, DEVICE, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        use core::sync::atomic::Ordering;
        host_atomic(slot).fetch_max(value, Ordering::Relaxed)
    }
}

/// Lowers a storage-buffer word to at most `value` with device scope,
/// relaxed; returns the previous value.
#[inline]
pub fn min_device(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_u_min::<u32, DEVICE, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        use core::sync::atomic::Ordering;
        host_atomic(slot).fetch_min(value, Ordering::Relaxed)
    }
}

/// Adds `value` to a workgroup-memory counter (relaxed: a barrier follows).
#[inline]
pub fn add_workgroup(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_i_add::<u32, WORKGROUP, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        let old = *slot;
        *slot = old.wrapping_add(value);
        old
    }
}

/// Ors `value` into a workgroup-memory word (relaxed: a barrier follows).
#[inline]
pub fn or_workgroup(slot: &mut u32, value: u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_or::<u32, WORKGROUP, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        let old = *slot;
        *slot = old | value;
        old
    }
}

/// Device-scope relaxed store of an `f32`, for data another invocation reads
/// after synchronizing through [`add_device`].
#[inline]
pub fn store_f32(slot: &mut f32, value: f32) {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_store::<f32, DEVICE, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        *slot = value;
    }
}

/// Device-scope relaxed load of an `f32` (see [`store_f32`]).
#[inline]
pub fn load_f32(slot: &f32) -> f32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_load::<f32, DEVICE, RELAXED>(slot)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        *slot
    }
}

/// Device-scope relaxed store of a `u32` (see [`store_f32`]).
#[inline]
pub fn store_u32(slot: &mut u32, value: u32) {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_store::<u32, DEVICE, RELAXED>(slot, value)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        *slot = value;
    }
}

/// Device-scope relaxed load of a `u32` (see [`store_f32`]).
#[inline]
pub fn load_u32(slot: &u32) -> u32 {
    #[cfg(target_arch = "spirv")]
    unsafe {
        spirv_std::arch::atomic_load::<u32, DEVICE, RELAXED>(slot)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        *slot
    }
}
