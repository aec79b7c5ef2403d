//! Filling a `u32` buffer with one value: how reused buffers are zeroed
//! (the fit's arrival counters) inside the timed stream of dispatches; and
//! copying words between buffers in that stream (an instanced scene's
//! meshes gathered into one buffer).
use crate::geometry::buffers::{CopyParams, FillParams};

/// Kernel: `data[id] = params.value` for `id < params.len`.
#[inline]
pub fn fill_kernel(id: u32, params: &FillParams, data: &mut [u32]) {
    if id < params.len {
        data[id as usize] = params.value;
    }
}

/// Kernel: `dst[params.dst_offset + id] = src[params.src_offset + id]`
/// for `id < params.len` (offsets and length in words).
#[inline]
pub fn copy_words_kernel(id: u32, params: &CopyParams, src: &[u32], dst: &mut [u32]) {
    if id < params.len {
        dst[(params.dst_offset + id) as usize] = src[(params.src_offset + id) as usize];
    }
}
