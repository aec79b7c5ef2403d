//! Array reads and writes without bounds checks on the GPU.
//!
//! rust-gpu keeps every bounds check as a branch, and in the treelet DP's
//! inner loops those branches cost more than the work. The CPU build, which
//! runs the same kernels in the tests, keeps the checks: an index out of
//! range there fails a test instead of passing silently.

/// `a[i]`, unchecked on the GPU.
#[inline]
pub fn get<T: Copy, const N: usize>(a: &[T; N], i: usize) -> T {
    #[cfg(target_arch = "spirv")]
    {
        use spirv_std::arch::IndexUnchecked;
        // SAFETY: callers index within the arrays they size; the CPU build checks it.
        unsafe { *a.index_unchecked(i) }
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        a[i]
    }
}

/// `a[i] = v`, unchecked on the GPU.
#[inline]
pub fn set<T: Copy, const N: usize>(a: &mut [T; N], i: usize, v: T) {
    #[cfg(target_arch = "spirv")]
    {
        use spirv_std::arch::IndexUnchecked;
        // SAFETY: as in `get`.
        unsafe { *a.index_unchecked_mut(i) = v }
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        a[i] = v;
    }
}

/// `a[i]` of a slice (a storage buffer), unchecked on the GPU. Besides the
/// check itself, its branch splits the code into blocks, and GPU compilers
/// then do not start a load before the previous one's value is used.
#[inline]
pub fn at<T: Copy>(a: &[T], i: usize) -> T {
    #[cfg(target_arch = "spirv")]
    {
        use spirv_std::arch::IndexUnchecked;
        // SAFETY: as in `get`.
        unsafe { *a.index_unchecked(i) }
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        a[i]
    }
}

/// `a[i] = v` of a slice (a storage buffer), unchecked on the GPU.
#[inline]
pub fn put<T: Copy>(a: &mut [T], i: usize, v: T) {
    #[cfg(target_arch = "spirv")]
    {
        use spirv_std::arch::IndexUnchecked;
        // SAFETY: as in `get`.
        unsafe { *a.index_unchecked_mut(i) = v }
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        a[i] = v;
    }
}

/// A private array a kernel writes before it reads each element (a
/// traversal stack, a DP table): undefined on the GPU, zeros
/// (`T::default()`) on the CPU. Zero-filling it is not
/// free there: rust-gpu stores a constant of the whole array, which the
/// driver keeps as one store per word into local memory, for every ray
/// (a 128-word stack: 512 bytes a ray, before the walk reads a node).
#[inline]
pub fn scratch<T: Copy + Default, const N: usize>() -> [T; N] {
    #[cfg(target_arch = "spirv")]
    {
        // SAFETY: SPIR-V's undefined value (OpUndef) is some bit pattern, and
        // callers write each element before reading it; the CPU build, which
        // runs the same kernels in the tests, zero-fills.
        unsafe { core::mem::MaybeUninit::<[T; N]>::uninit().assume_init() }
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        [T::default(); N]
    }
}
