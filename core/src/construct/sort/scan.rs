//! Exclusive prefix sum of a `u32` array in three kernels: a reduce of each
//! tile to one partial sum, a single-workgroup scan of the partial sums (the
//! "spine"), and a down-sweep that scans each tile from its partial.
//! (Reduce-then-scan, as in Merrill & Grimshaw, "Parallel Scan for Stream
//! Architectures", 2009; Treelet skips their decoupled look-back.)
//! The radix sort uses it on its digit-major histogram.
//!
//! Kernels are phase functions: see [`crate::gpu::workgroup`].
use crate::geometry::buffers::ScanParams;
use crate::gpu::workgroup::{SCAN_STEPS, WG, WG_LOG2, WORKGROUP_SIZE, hillis_steele_step, reduction_stride};

/// Elements each invocation sums serially.
pub const SCAN_ITEMS: u32 = 4;
/// Elements per workgroup of the reduce and down-sweep kernels.
pub const SCAN_TILE: u32 = WORKGROUP_SIZE * SCAN_ITEMS;

/// After a workgroup inclusive scan of `a`: the exclusive prefix for `lid`.
#[inline]
fn exclusive(a: &[u32; WG], lid: u32) -> u32 {
    if lid == 0 {
        0
    } else {
        a[lid as usize - 1]
    }
}

/// Sum of the `SCAN_ITEMS` elements invocation `lid` of tile `tile` owns.
#[inline]
fn thread_sum(data: &[u32], len: u32, tile: u32, lid: u32) -> u32 {
    let start = tile * SCAN_TILE + lid * SCAN_ITEMS;
    let mut sum = 0;
    for k in 0..SCAN_ITEMS {
        if start + k < len {
            sum += data[(start + k) as usize];
        }
    }
    sum
}

/// Phases of [`scan_reduce_phase`]: load, tree reduction, write.
pub const SCAN_REDUCE_PHASES: u32 = 2 + WG_LOG2;

/// Kernel: `partials[tile] = sum of data over the tile`.
pub fn scan_reduce_phase(
    phase: u32,
    lid: u32,
    tile: u32,
    params: &ScanParams,
    data: &[u32],
    partials: &mut [u32],
    sums: &mut [u32; WG],
) {
    if phase == 0 {
        sums[lid as usize] = thread_sum(data, params.len, tile, lid);
    } else if phase <= WG_LOG2 {
        let stride = reduction_stride(phase - 1);
        if lid < stride {
            sums[lid as usize] += sums[(lid + stride) as usize];
        }
    } else if lid == 0 && tile < params.tiles {
        partials[tile as usize] = sums[0];
    }
}

/// Phases of [`scan_spine_phase`] and [`scan_downsweep_phase`]:
/// per-invocation sums, workgroup scan, serial write-back.
pub const SCAN_SWEEP_PHASES: u32 = 2 + SCAN_STEPS;

/// Kernel (one workgroup): exclusive scan of `partials[..params.tiles]` in place.
/// Each invocation owns a contiguous chunk, so any number of tiles works.
pub fn scan_spine_phase(
    phase: u32,
    lid: u32,
    params: &ScanParams,
    partials: &mut [u32],
    a: &mut [u32; WG],
    b: &mut [u32; WG],
) {
    let chunk = params.tiles.div_ceil(WORKGROUP_SIZE);
    if phase == 0 {
        let mut sum = 0;
        for k in 0..chunk {
            let i = lid * chunk + k;
            if i < params.tiles {
                sum += partials[i as usize];
            }
        }
        a[lid as usize] = sum;
    } else if phase <= SCAN_STEPS {
        hillis_steele_step(phase - 1, lid, a, b);
    } else {
        let mut running = exclusive(a, lid);
        for k in 0..chunk {
            let i = lid * chunk + k;
            if i < params.tiles {
                let v = partials[i as usize];
                partials[i as usize] = running;
                running += v;
            }
        }
    }
}

/// Kernel: exclusive scan of one tile of `data` in place, offset by the
/// tile's scanned partial sum.
#[allow(clippy::too_many_arguments)]
pub fn scan_downsweep_phase(
    phase: u32,
    lid: u32,
    tile: u32,
    params: &ScanParams,
    data: &mut [u32],
    partials: &[u32],
    a: &mut [u32; WG],
    b: &mut [u32; WG],
) {
    if phase == 0 {
        a[lid as usize] = thread_sum(data, params.len, tile, lid);
    } else if phase <= SCAN_STEPS {
        hillis_steele_step(phase - 1, lid, a, b);
    } else if tile < params.tiles {
        let mut running = partials[tile as usize] + exclusive(a, lid);
        let start = tile * SCAN_TILE + lid * SCAN_ITEMS;
        for k in 0..SCAN_ITEMS {
            let i = start + k;
            if i < params.len {
                let v = data[i as usize];
                data[i as usize] = running;
                running += v;
            }
        }
    }
}
