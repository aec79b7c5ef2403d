//! Stage order of the radix sort and of the prefix sum it uses, over any
//! [`Backend`]. The kernels are in `treelet_core::{sort, scan}`.
use anyhow::Result;
use treelet_core::construct::sort::scan::SCAN_TILE;
use treelet_core::construct::sort::{MAX_KEYS, RADIX, SMALL_SORT_TILE, SORT_TILE, histogram_tile, passes_for, state};
use treelet_core::construct::sort::multisplit::{
    MEDIUM_MULTISPLIT_SORT_TILE, MIN_SUBGROUP_SIZE, MULTISPLIT_SORT_TILE, SMALL_MULTISPLIT_SORT_TILE,
};
use treelet_core::geometry::buffers::{ScanParams, SortParams};
use treelet_core::gpu::workgroup::{WORKGROUP_SIZE, groups_for};

use crate::runtime::backend::Backend;
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};

kernel_set! {
    /// The kernels of [`exclusive_scan`].
    pub struct ScanKernels for b {
        reduce: Kernel::ScanReduce,
        spine: Kernel::ScanSpine,
        downsweep: Kernel::ScanDownsweep,
    }
}

kernel_set! {
    /// The kernels of the sort with look-back, but its passes' (`pass_kernel`).
    pub struct LookBackKernels for b {
        histogram: Kernel::SortHistogram,
        offsets: Kernel::SortOffsets,
    }
}

kernel_set! {
    /// The kernels of the sort without look-back (each pass's digit counts
    /// scanned, then ranked in workgroup memory).
    pub struct ScannedSortKernels for b {
        tile_counts: Kernel::SortTileCounts,
        pass: Kernel::SortOnesweepScanned,
    }
}

kernel_set! {
    /// The kernel ending a sort by the high digits ([`radix_sort_high_first`]).
    pub struct SettleKernels for b {
        settle_ties: Kernel::SortSettleTies,
    }
}

/// The kernels [`radix_sort`] and [`exclusive_scan`] dispatch on `b`, for
/// building their pipelines ahead: the pass kernel of each size class as
/// `pass_kernel` picks it (so a new choice there is prepared too).
pub fn kernels<B: Backend>(b: &B) -> Vec<Kernel> {
    let mut k = [ScanKernels::of(b).all(), SettleKernels::of(b).all()].concat();
    if b.look_back_works() {
        k.extend(LookBackKernels::of(b).all());
        // One size from each class of `SortTiles::resolve`.
        let sizes = [1, SMALL_TILES_BESIDE_MULTISPLIT_UP_TO, SMALL_TILES_UP_TO, SMALL_MULTISPLIT_UP_TO, MEDIUM_MULTISPLIT_UP_TO];
        k.extend(sizes.iter().filter_map(|&n| pass_kernel(b, n.saturating_add(1), SortTiles::Auto).ok().map(|(pass, _)| pass)));
    } else {
        k.extend(ScannedSortKernels::of(b).all());
    }
    k.sort();
    k.dedup();
    k
}

/// Exclusive prefix sum of the first `len` u32s of `data`, in place.
pub fn exclusive_scan<B: Backend>(b: &mut B, data: &B::Buffer, len: u32) -> Result<()> {
    let tiles = groups_for(len, SCAN_TILE);
    if tiles == 0 {
        return Ok(());
    }
    let params = b.upload("scan params", &[ScanParams { len, tiles, _pad0: [0; 2] }])?;
    let partials = b.scratch("scan partials", tiles as u64 * 4)?;
    let k = ScanKernels::of(b);
    let (params, partials) = (&params, &partials);
    b.dispatch_with(k.reduce, bind::ScanReduce { params, data, partials }, tiles);
    b.dispatch_with(k.spine, bind::ScanSpine { params, partials }, 1);
    b.dispatch_with(k.downsweep, bind::ScanDownsweep { params, data, partials }, tiles);
    Ok(())
}

/// Which pass kernel and tiles the sort takes (with look-back; without it,
/// large tiles ranked in workgroup memory).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SortTiles {
    /// By size and device: `TREELET_SORT_TILES=small|large|multisplit|multisplit-medium|multisplit-small`
    /// overrides it (to measure).
    Auto,
    /// `treelet_core::construct::sort::SMALL_SORT_TILE` keys per workgroup.
    Small,
    /// `treelet_core::construct::sort::SORT_TILE` keys per workgroup.
    Large,
    /// Tiles ranked by subgroups
    /// (`treelet_core::construct::sort::multisplit`), on devices whose
    /// subgroups have at least `MIN_SUBGROUP_SIZE` lanes.
    Multisplit,
    /// The same with half the keys per lane (`SMALL_MULTISPLIT_SORT_TILE`).
    MultisplitSmall,
    /// The same with three quarters of the keys per lane (`MEDIUM_MULTISPLIT_SORT_TILE`).
    MultisplitMedium,
}

impl SortTiles {
    /// The tiles a sort of `n` keys takes (`multisplit`: whether large sorts
    /// take the pass ranked by subgroups, [`multisplit_by_default`]).
    ///
    /// Small tiles up to [`SMALL_TILES_BESIDE_MULTISPLIT_UP_TO`] keys where
    /// the device runs tiles ranked by subgroups ([`SMALL_TILES_UP_TO`]
    /// elsewhere), then those tiles, small ones up to
    /// [`SMALL_MULTISPLIT_UP_TO`], medium ones up to [`MEDIUM_MULTISPLIT_UP_TO`]: on the H100 (one machine, `bench build
    /// --per-kernel`, medians of 11 and 21, 2026-11-26) the 8 passes ranked
    /// by subgroups take 0.202 / 0.351 / 0.990 / 3.25 ms at 65 536 / 1M /
    /// 4M / 16M keys, small tiles 0.135 / 0.582 / 2.15 / 8.29 and large
    /// ones 0.224 / 0.480 / 1.79 / 6.55; with half the keys per lane
    /// 0.153 / 0.194 / 0.251 / 0.368 / 1.10 ms at 65 536 / 262 144 /
    /// 524 288 / 1M / 4M against 0.202 / 0.226 / 0.263 / 0.350 / 1.01
    /// (`docs/results/h100-sort-occupancy/log_4_keys_per_lane.txt`).
    fn resolve(self, n: u32, multisplit: bool) -> SortTiles {
        if self != SortTiles::Auto {
            return self;
        }
        use crate::tuning::SortTiles as Forced;
        match crate::tuning::Tuning::current().sort_tiles {
            Some(Forced::Small) => SortTiles::Small,
            Some(Forced::Large) => SortTiles::Large,
            Some(Forced::Multisplit) => SortTiles::Multisplit,
            Some(Forced::MultisplitSmall) => SortTiles::MultisplitSmall,
            Some(Forced::MultisplitMedium) => SortTiles::MultisplitMedium,
            _ if n <= if multisplit { SMALL_TILES_BESIDE_MULTISPLIT_UP_TO } else { SMALL_TILES_UP_TO } => {
                SortTiles::Small
            }
            _ if multisplit && n <= SMALL_MULTISPLIT_UP_TO => SortTiles::MultisplitSmall,
            _ if multisplit && n <= MEDIUM_MULTISPLIT_UP_TO => SortTiles::MultisplitMedium,
            _ if multisplit => SortTiles::Multisplit,
            _ => SortTiles::Large,
        }
    }
}

/// Whether `b` can run the pass ranked by subgroups: look-back, and
/// subgroups of `MIN_SUBGROUP_SIZE` lanes or more.
pub fn multisplit_runs_on<B: Backend>(b: &B) -> bool {
    b.look_back_works() && b.min_subgroup_size() >= MIN_SUBGROUP_SIZE
}

/// Whether large sorts on `b` take the tiles ranked by subgroups unless
/// asked otherwise: where `b` runs them, but not on the CPU runner, which
/// emulates each subgroup operation lane by lane (1M keys on two cores:
/// about 0.63 s against 0.58 with large tiles ranked in workgroup memory).
fn multisplit_by_default<B: Backend>(b: &B) -> bool {
    multisplit_runs_on(b) && !b.runs_on_cpu()
}

/// Largest sort that takes the small tiles ranked by subgroups by default
/// (where large sorts take tiles ranked by subgroups): on the H100 they
/// were 14% faster at 262 144 keys, 5% at 524 288, 1.6% slower at 750 000
/// (`docs/results/h100-sort-occupancy/log_small_multisplit.txt`).
const SMALL_MULTISPLIT_UP_TO: u32 = 600_000;

/// Largest sort that takes the medium tiles ranked by subgroups by default:
/// on the H100 they were 3% faster than the large ones at 1M and 2M keys,
/// 1% at 4M, 4% and 6% slower at 8M and 16M; the small ones were as fast
/// at 524 288 and faster below
/// (`docs/results/h100-agglomerate-subgroup/log_sort_tiles.txt`).
const MEDIUM_MULTISPLIT_UP_TO: u32 = 4_000_000;

/// Largest sort that takes small tiles by default where tiles ranked by
/// subgroups run: on the H100 (2026-11-27, the builds' sort of the high
/// digits, three or four passes) small tiles ranked by subgroups made the
/// LBVH faster at 65 536 / 100 000 / 131 072 / 200 000 primitives: 0.147 /
/// 0.174 / 0.184 / 0.217 ms against 0.149 / 0.177 / 0.191 / 0.224, and the
/// instanced top level of 10 000 took 0.143 against 0.142
/// (`docs/results/h100-lbvh-dispatches-2026-11-27/log_knobs.txt`).
const SMALL_TILES_BESIDE_MULTISPLIT_UP_TO: u32 = 50_000;

/// Largest sort that takes small tiles by default elsewhere: on the H100 small tiles
/// sorted 65 536 keys in 0.165 ms (large: 0.274) and 131 072 in 0.187 (0.279),
/// both the same at 262 144, large ones 1M in 0.58 ms (small: 0.72). With
/// their phases unrolled, small tiles take 0.137 ms at 65 536 and 0.578 at
/// 1M (large, looped: 0.583): the crossover is to be measured again.
const SMALL_TILES_UP_TO: u32 = 200_000;

/// Sorts `n` `(key, value)` pairs by the low `key_bits` bits of the keys,
/// stably: one digit histogram for all passes, then one sweep per pass
/// (see `treelet_core::construct::sort`). Returns the buffers that hold the result (the
/// inputs or the scratch pair, depending on the number of passes).
pub fn radix_sort<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
) -> Result<(B::Buffer, B::Buffer)> {
    radix_sort_tiled(b, keys, values, n, key_bits, SortTiles::Auto)
}

/// [`radix_sort`] with the given tiles.
pub fn radix_sort_tiled<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
    tile_size: SortTiles,
) -> Result<(B::Buffer, B::Buffer)> {
    anyhow::ensure!(key_bits <= 64, "{key_bits}-bit keys: the radix sort takes at most 64 bits");
    Ok(sort_passes(b, keys, values, n, 0..passes_for(key_bits), tile_size, None)?.0)
}

/// Sorts as [`radix_sort`] does, in about half the passes where few keys
/// agree in their high digits: a stable sort by the high digits (enough for
/// `log2(n)` and eight bits more), then each run of keys tied in those ordered by the low ones
/// (`treelet_core::construct::sort::ties`): the same result. Returns `None`
/// when a run of ties was too long to settle that way; the buffers then hold
/// the pairs sorted by the high digits only, and the caller sorts every
/// digit from its inputs again. One word is read back (the run flag).
pub fn radix_sort_high_first<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
) -> Result<Option<(B::Buffer, B::Buffer)>> {
    radix_sort_high_first_tiled(b, keys, values, n, key_bits, SortTiles::Auto)
}

/// The state of a sort's look-back, for a caller that zeroes it along with
/// work of its own (the LBVH's Morton kernel) rather than by a fill
/// dispatch: `zeroed_words` words of `buffer` must be zero.
pub struct SortState<Buf> {
    pub buffer: Buf,
    pub zeroed_words: u32,
    tiles: u32,
}

/// The state [`radix_sort_high_first_zeroed`] uses for `n` keys of
/// `key_bits` bits, where it uses one (with look-back).
pub fn high_first_state<B: Backend>(b: &mut B, n: u32, key_bits: u32) -> Result<Option<SortState<B::Buffer>>> {
    if n < 2 || !b.look_back_works() || passes_for(key_bits) == 0 {
        return Ok(None);
    }
    let first = high_first_digit(n, passes_for(key_bits));
    let tiles = groups_for(n, pass_kernel(b, n, SortTiles::Auto)?.1);
    let buffer = b.scratch("sort state", state::words(tiles) as u64 * 4)?;
    Ok(Some(SortState { buffer, zeroed_words: zeroed_words(first, tiles), tiles }))
}

/// [`radix_sort_high_first`] with the state of [`high_first_state`],
/// zeroed by the caller.
pub fn radix_sort_high_first_zeroed<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
    state: Option<SortState<B::Buffer>>,
) -> Result<Option<(B::Buffer, B::Buffer)>> {
    high_first(b, keys, values, n, key_bits, SortTiles::Auto, state)
}

/// The first digit the sort by high digits sorts (0: every digit).
fn high_first_digit(n: u32, passes: u32) -> u32 {
    if passes < 2 || n < 2 { 0 } else { treelet_core::construct::sort::ties::first_high_digit(n, passes) }
}

/// Words of a sort's state that must be zero before it, where its first
/// pass is `first`: a pass uses the status region of its parity and clears
/// the other for the next, so a first pass of odd parity finds its region
/// cleared too.
fn zeroed_words(first: u32, tiles: u32) -> u32 {
    if first % 2 == 0 { state::zeroed_words(tiles) } else { state::words(tiles) }
}

/// [`radix_sort_high_first`] with the given tiles.
pub fn radix_sort_high_first_tiled<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
    tile_size: SortTiles,
) -> Result<Option<(B::Buffer, B::Buffer)>> {
    high_first(b, keys, values, n, key_bits, tile_size, None)
}

fn high_first<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    key_bits: u32,
    tile_size: SortTiles,
    zeroed: Option<SortState<B::Buffer>>,
) -> Result<Option<(B::Buffer, B::Buffer)>> {
    anyhow::ensure!(key_bits <= 64, "{key_bits}-bit keys: the radix sort takes at most 64 bits");
    let passes = passes_for(key_bits);
    let first = high_first_digit(n, passes);
    if first == 0 {
        return Ok(Some(sort_passes(b, keys, values, n, 0..passes, tile_size, zeroed)?.0));
    }
    let (sorted, sort_state) = sort_passes(b, keys, values, n, first..passes, tile_size, zeroed)?;
    // The run flag: a word of the sort's state, zeroed with it (no fill of
    // its own); without look-back there is no state, and a word is zeroed.
    let flag_words = state::TIE_OVERFLOW + 1;
    let sort_state = match sort_state {
        Some(s) => s,
        None => b.zeroed("sort tie overflow", flag_words as u64 * 4)?,
    };
    let params = b.upload("sort params", &[SortParams { n, tiles: 0, pass: first, passes }])?;
    let settle = bind::SortSettleTies { params: &params, keys: &sorted.0, values: &sorted.1, sort_state: &sort_state };
    b.dispatch_with(SettleKernels::of(b).settle_ties, settle, groups_for(n, WORKGROUP_SIZE));
    let flags = b.read::<u32>(&sort_state, flag_words as usize)?;
    Ok((flags[state::TIE_OVERFLOW as usize] == 0).then_some(sorted))
}

/// Whether builds sort by the high digits first ([`radix_sort_high_first`]):
/// yes, unless `TREELET_SORT_HIGH_FIRST=0` (to measure against).
pub fn high_first_by_default() -> bool {
    crate::tuning::Tuning::current().sort_high_first
}

/// Stable sort of `n` pairs by the digits `passes` (a range of
/// `0..passes_for(key_bits)`): every digit for a full sort, the high ones
/// for [`radix_sort_high_first`]. Also returns the sort's state buffer,
/// where it has one (with look-back): `zeroed` where the caller zeroed it.
fn sort_passes<B: Backend>(
    b: &mut B,
    keys: &B::Buffer,
    values: &B::Buffer,
    n: u32,
    passes: std::ops::Range<u32>,
    tile_size: SortTiles,
    zeroed: Option<SortState<B::Buffer>>,
) -> Result<((B::Buffer, B::Buffer), Option<B::Buffer>)> {
    let mut src = (keys.clone(), values.clone());
    if n < 2 || passes.is_empty() {
        return Ok((src, None));
    }
    anyhow::ensure!(n <= MAX_KEYS, "{n} keys: the radix sort takes at most {MAX_KEYS}");
    let (first, passes) = (passes.start, passes.end);
    let (kernel, tile) = pass_kernel(b, n, tile_size)?;
    let tiles = groups_for(n, tile);
    let mut dst = (b.scratch("sort keys scratch", n as u64 * 8)?, b.scratch("sort values scratch", n as u64 * 4)?);
    let params = |pass| SortParams { n, tiles, pass, passes };
    if !b.look_back_works() {
        // Reduce, then scan, then the same pass kernel without look-back.
        let k = ScannedSortKernels::of(b);
        let tile_counts = b.scratch("sort tile counts", RADIX as u64 * tiles as u64 * 4)?;
        for pass in first..passes {
            let p = b.upload("sort params", &[params(pass)])?;
            b.dispatch_with(k.tile_counts, bind::SortTileCounts { params: &p, keys: &src.0, tile_counts: &tile_counts }, tiles);
            exclusive_scan(b, &tile_counts, RADIX * tiles)?;
            b.dispatch(k.pass, &[&p, &src.0, &src.1, &dst.0, &dst.1, &tile_counts], tiles);
            std::mem::swap(&mut src, &mut dst);
        }
        return Ok((src, None));
    }
    let sort_state = match zeroed {
        Some(s) => {
            anyhow::ensure!(
                s.tiles == tiles && s.zeroed_words >= zeroed_words(first, tiles),
                "internal: the sort's state was made for another sort"
            );
            s.buffer
        }
        None => {
            let s = b.scratch("sort state", state::words(tiles) as u64 * 4)?;
            b.zero_words(&s, zeroed_words(first, tiles))?;
            s
        }
    };
    // The histogram counts the digits of passes `first..` (its `pass`).
    let p = b.upload("sort params", &[params(first)])?;
    let k = LookBackKernels::of(b);
    b.dispatch_with(k.histogram, bind::SortHistogram { params: &p, keys: &src.0, sort_state: &sort_state }, groups_for(n, histogram_tile(n)));
    b.dispatch_with(k.offsets, bind::SortOffsets { params: &p, sort_state: &sort_state }, passes);
    for pass in first..passes {
        let p = b.upload("sort params", &[params(pass)])?;
        b.dispatch(kernel, &[&p, &src.0, &src.1, &dst.0, &dst.1, &sort_state], tiles);
        std::mem::swap(&mut src, &mut dst);
    }
    Ok((src, Some(sort_state)))
}

/// The pass kernel of a sort of `n` keys on `b` and its keys per tile.
fn pass_kernel<B: Backend>(b: &B, n: u32, tile_size: SortTiles) -> Result<(Kernel, u32)> {
    // Small tiles where large ones would leave the GPU idle (look-back only).
    let tile_size = if b.look_back_works() { tile_size.resolve(n, multisplit_by_default(b)) } else { SortTiles::Large };
    let multisplit = matches!(tile_size, SortTiles::Multisplit | SortTiles::MultisplitSmall | SortTiles::MultisplitMedium);
    if multisplit && !multisplit_runs_on(b) {
        anyhow::bail!(
            "the sort ranked by subgroups needs look-back and subgroups of at least {MIN_SUBGROUP_SIZE} lanes; `{}` has subgroups of {} or more lanes{}",
            b.adapter(),
            b.min_subgroup_size(),
            if b.look_back_works() { "" } else { " and runs the sort without look-back" }
        );
    }
    Ok(match tile_size {
        SortTiles::Small => (Kernel::SortOnesweepSmall, SMALL_SORT_TILE),
        SortTiles::Multisplit if b.subgroup_partitioned() => (Kernel::SortMultisplitPartitioned, MULTISPLIT_SORT_TILE),
        SortTiles::Multisplit => (Kernel::SortMultisplit, MULTISPLIT_SORT_TILE),
        SortTiles::MultisplitSmall if b.subgroup_partitioned() => {
            (Kernel::SortMultisplitSmallPartitioned, SMALL_MULTISPLIT_SORT_TILE)
        }
        SortTiles::MultisplitSmall => (Kernel::SortMultisplitSmall, SMALL_MULTISPLIT_SORT_TILE),
        SortTiles::MultisplitMedium if b.subgroup_partitioned() => {
            (Kernel::SortMultisplitMediumPartitioned, MEDIUM_MULTISPLIT_SORT_TILE)
        }
        SortTiles::MultisplitMedium => (Kernel::SortMultisplitMedium, MEDIUM_MULTISPLIT_SORT_TILE),
        _ => (Kernel::SortOnesweep, SORT_TILE),
    })
}
