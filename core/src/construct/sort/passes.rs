//! The sort passes' kernels, listed once: Onesweep's passes
//! ([`crate::construct::sort`]) and the passes ranked by subgroups
//! ([`crate::construct::sort::multisplit`]).

/// Calls `$callback!` with the one list of sort pass kernels, as
/// `[extra args] Kernel kind entry_point items, flag, [phases];`: the host's
/// `Kernel` variant; `onesweep` ([`crate::construct::sort::onesweep_phase`], `flag`: decoupled
/// look-back, else the offsets scanned first) or `multisplit`
/// ([`crate::construct::sort::multisplit::multisplit_pass_phase`], `flag`: NVIDIA's partition
/// instruction); the entry point (in the shader crate's `sort` module);
/// keys per lane; and every phase's number, written out because the shader
/// unrolls them with each number a constant. The shader's entry points and
/// the host's kernel list and entry-point names expand from it.
#[macro_export]
macro_rules! for_each_sort_pass {
    ($callback:ident $(, $arg:tt)*) => {
        $callback! {
            [$($arg),*]
            SortOnesweep onesweep sort_onesweep_cs $crate::construct::sort::SORT_ITEMS, true, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23];
            SortOnesweepSmall onesweep sort_onesweep_small_cs $crate::construct::sort::SMALL_SORT_ITEMS, true, [0 1 2 3 4 5 6 7 8 9 10 11];
            SortOnesweepScanned onesweep sort_onesweep_scanned_cs $crate::construct::sort::SORT_ITEMS, false, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23];
            SortMultisplit multisplit sort_multisplit_cs $crate::construct::sort::multisplit::MULTISPLIT_SORT_ITEMS, false, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25];
            SortMultisplitSmall multisplit sort_multisplit_small_cs $crate::construct::sort::multisplit::SMALL_MULTISPLIT_SORT_ITEMS, false, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17];
            SortMultisplitMedium multisplit sort_multisplit_medium_cs $crate::construct::sort::multisplit::MEDIUM_MULTISPLIT_SORT_ITEMS, false, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21];
            SortMultisplitPartitioned multisplit sort_multisplit_partitioned_cs $crate::construct::sort::multisplit::MULTISPLIT_SORT_ITEMS, true, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25];
            SortMultisplitSmallPartitioned multisplit sort_multisplit_small_partitioned_cs $crate::construct::sort::multisplit::SMALL_MULTISPLIT_SORT_ITEMS, true, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17];
            SortMultisplitMediumPartitioned multisplit sort_multisplit_medium_partitioned_cs $crate::construct::sort::multisplit::MEDIUM_MULTISPLIT_SORT_ITEMS, true, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21];
        }
    };
}
