//! Filling a `u32` buffer with one value: how reused buffers are zeroed
//! (the fit's arrival counters) inside the timed stream of dispatches.
use crate::geometry::buffers::FillParams;

/// Kernel: `data[id] = params.value` for `id < params.len`.
#[inline]
pub fn fill_kernel(id: u32, params: &FillParams, data: &mut [u32]) {
    if id < params.len {
        data[id as usize] = params.value;
    }
}
