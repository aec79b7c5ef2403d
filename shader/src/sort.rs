use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::construct::sort;
use treelet_core::construct::sort::multisplit::{
    MultisplitPassLane, SUBGROUP_COUNTS, multisplit_pass_phase, multisplit_pass_phases, multisplit_pass_sync,
};
use treelet_core::gpu::subgroup::{Lane, apply_with};
use treelet_core::geometry::buffers::SortParams;
use treelet_core::gpu::workgroup::{WG, barrier, linear_group};

/// A sort pass's entry point; `$look_back` and `$items` as in
/// `treelet_core::construct::sort::onesweep_phase` (entry points cannot be
/// generic). The phases are unrolled, each with its number a constant
/// (`$phase`, all of `0..onesweep_phases($items)`), so that the driver's
/// compiler keeps only that phase's branch of the function: a loop over
/// phases pays for the whole function in every phase.
macro_rules! onesweep_kernel {
    ($name:ident, $look_back:literal, $items:expr, [$($phase:literal)*]) => {
        #[spirv(compute(threads(256)))]
        #[allow(clippy::too_many_arguments)]
        pub fn $name(
            #[spirv(local_invocation_index)] lid: u32,
            #[spirv(workgroup_id)] group: UVec3,
            #[spirv(num_workgroups)] groups: UVec3,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &SortParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys_in: &[u64],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] values_in: &[u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] keys_out: &mut [u64],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] values_out: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] sort_state: &mut [u32],
            #[spirv(workgroup)] ticket: &mut [u32; 1],
            #[spirv(workgroup)] running: &mut [u32; WG],
            #[spirv(workgroup)] digits: &mut [u32; WG],
            #[spirv(workgroup)] packed: &mut [u32; sort::PACKED_DIGITS],
            #[spirv(workgroup)] counts: &mut [u32; sort::CHUNK_COUNTS],
            #[spirv(workgroup)] totals: &mut [u32; WG],
            #[spirv(workgroup)] ranks: &mut [u32; ($items * treelet_core::WORKGROUP_SIZE) as usize],
            #[spirv(workgroup)] local_offsets: &mut [u32; WG],
            #[spirv(workgroup)] global_offsets: &mut [u32; WG],
            #[spirv(workgroup)] scan_sums: &mut [u32; 16],
        ) {
            // A private copy, kept in registers across the barriers instead of
            // read from the storage buffer again in each phase (H200: 1% off the sort).
            let params = &{ *params };
            let group = linear_group(group.x, group.y, groups.x);
            const _: () = assert!([$($phase),*].len() as u32 == sort::onesweep_phases($items));
            $(
                sort::onesweep_phase::<
                    $look_back,
                    { $items },
                    { ($items * treelet_core::WORKGROUP_SIZE) as usize },
                >(
                    $phase,
                    lid,
                    group,
                    params,
                    keys_in,
                    values_in,
                    keys_out,
                    values_out,
                    sort_state,
                    ticket,
                    running,
                    digits,
                    packed,
                    counts,
                    totals,
                    ranks,
                    local_offsets,
                    global_offsets,
                    scan_sums,
                );
                barrier();
            )*
        }
    };
}

/// A sort pass ranked by subgroups, `$items` keys per lane: each lane's
/// state stays in registers, and only the phases that need it end in a
/// workgroup barrier. The phases unrolled, each with its number a
/// constant, so that the driver's compiler keeps only that phase's branch
/// of the function (a loop over phases pays for the whole function in
/// every phase).
macro_rules! multisplit_kernel {
    ($name:ident, $items:expr, $partitioned:literal, [$($phase:literal)*]) => {
        #[spirv(compute(threads(256)))]
        #[allow(clippy::too_many_arguments)]
        pub fn $name(
            #[spirv(local_invocation_index)] lid: u32,
            #[spirv(subgroup_id)] subgroup: u32,
            #[spirv(subgroup_local_invocation_id)] lane: u32,
            #[spirv(subgroup_size)] size: u32,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &SortParams,
            #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys_in: &[u64],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] values_in: &[u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] keys_out: &mut [u64],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] values_out: &mut [u32],
            #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] sort_state: &mut [u32],
            #[spirv(workgroup)] ticket: &mut [u32; 1],
            #[spirv(workgroup)] counts: &mut [u32; SUBGROUP_COUNTS],
            #[spirv(workgroup)] running: &mut [u32; WG],
            #[spirv(workgroup)] local_offsets: &mut [u32; WG],
            #[spirv(workgroup)] global_offsets: &mut [u32; WG],
            #[spirv(workgroup)] scan_sums: &mut [u32; 16],
        ) {
            // A private copy, kept in registers across the barriers instead of
            // read from the storage buffer again in each phase (H200: 1% off the sort).
            let params = &{ *params };
            let mut me = MultisplitPassLane::default();
            let mut io = Lane::default();
            const _: () = assert!([$($phase),*].len() as u32 == multisplit_pass_phases($items));
            $(
                multisplit_pass_phase::<{ $items }>(
                    $phase,
                    lid,
                    subgroup,
                    lane,
                    size,
                    params,
                    keys_in,
                    values_in,
                    keys_out,
                    values_out,
                    sort_state,
                    ticket,
                    counts,
                    running,
                    local_offsets,
                    global_offsets,
                    scan_sums,
                    &mut me,
                    &mut io,
                );
                apply_with::<$partitioned>(multisplit_pass_sync($phase, $items, $partitioned), &mut io);
            )*
        }
    };
}

/// The sort pass entry points of `treelet_core::for_each_sort_pass!`.
macro_rules! sort_entry_points {
    ([] $($kernel:ident $kind:ident $name:ident $items:path, $flag:literal, $phases:tt;)*) => {
        $(sort_pass!($kind $name, $items, $flag, $phases);)*
    };
}
macro_rules! sort_pass {
    (onesweep $name:ident, $items:path, $look_back:literal, $phases:tt) => {
        onesweep_kernel!($name, $look_back, $items, $phases);
    };
    // With `$partitioned`, the byte match by NVIDIA's partition instruction,
    // for devices on which the host enabled `VK_NV_shader_subgroup_partitioned`.
    (multisplit $name:ident, $items:path, $partitioned:literal, $phases:tt) => {
        multisplit_kernel!($name, $items, $partitioned, $phases);
    };
}
treelet_core::for_each_sort_pass!(sort_entry_points);
