//! Stage order of the radix sort and of the prefix sum it uses, over any
//! [`Backend`]. The kernels are in `treelet_core::{sort, scan}`.
use anyhow::Result;
use treelet_core::layout::{ScanParams, SortParams};
use treelet_core::scan::SCAN_TILE;
use treelet_core::sort::{passes_for, RADIX, RADIX_BITS, SORT_TILE};
use treelet_core::workgroup::groups_for;

use crate::backend::Backend;
use crate::kernels::Kernel;

/// Exclusive prefix sum of the first `len` u32s of `data`, in place.
pub fn exclusive_scan<B: Backend>(b: &mut B, data: &B::Buffer, len: u32) -> Result<()> {
    let tiles = groups_for(len, SCAN_TILE);
    if tiles == 0 {
        return Ok(());
    }
    let params = b.upload("scan params", &[ScanParams { len, tiles, _pad0: [0; 2] }])?;
    let partials = b.scratch("scan partials", tiles as u64 * 4)?;
    b.dispatch(Kernel::ScanReduce, &[&params, data, &partials], tiles);
    b.dispatch(Kernel::ScanSpine, &[&params, &partials], 1);
    b.dispatch(Kernel::ScanDownsweep, &[&params, data, &partials], tiles);
    Ok(())
}

/// Sorts `n` `(key, value)` pairs by the low `key_bits` bits of the keys,
/// stably. Returns the buffers that hold the result (the inputs or the
/// scratch pair, depending on the number of passes).
pub fn radix_sort<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
) -> Result<(B::Buffer, B::Buffer)> {
    let blocks = groups_for(n, SORT_TILE);
    let mut src = (keys.clone(), values.clone());
    if n < 2 {
        return Ok(src);
    }
    let mut dst = (b.scratch("sort keys scratch", n as u64 * 8)?, b.scratch("sort values scratch", n as u64 * 4)?);
    let hist_len = RADIX * blocks;
    let hist = b.scratch("sort histogram", hist_len as u64 * 4)?;
    for pass in 0..passes_for(key_bits) {
        let params = b.upload("sort params", &[SortParams { n, shift: pass * RADIX_BITS, blocks, _pad0: 0 }])?;
        b.dispatch(Kernel::SortHistogram, &[&params, &src.0, &hist], blocks);
        exclusive_scan(b, &hist, hist_len)?;
        b.dispatch(Kernel::SortScatter, &[&params, &src.0, &src.1, &hist, &dst.0, &dst.1], blocks);
        std::mem::swap(&mut src, &mut dst);
    }
    Ok(src)
}
