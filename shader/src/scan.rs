use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::construct::sort::scan;
use treelet_core::geometry::buffers::ScanParams;
use treelet_core::gpu::workgroup::{WG, linear_group};

#[spirv(compute(threads(256)))]
pub fn scan_reduce_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ScanParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] data: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] partials: &mut [u32],
    #[spirv(workgroup)] sums: &mut [u32; WG],
) {
    // A private copy, kept in registers across the barriers instead of
    // read from the storage buffer again in each phase (H200: 1% off the sort).
    let params = &{ *params };
    let tile = linear_group(group.x, group.y, groups.x);
    unrolled_phases!(scan::SCAN_REDUCE_PHASES, [0 1 2 3 4 5 6 7 8 9], |phase| {
        scan::scan_reduce_phase(phase, lid, tile, params, data, partials, sums)
    });
}

#[spirv(compute(threads(256)))]
pub fn scan_spine_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ScanParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] partials: &mut [u32],
    #[spirv(workgroup)] a: &mut [u32; WG],
    #[spirv(workgroup)] b: &mut [u32; WG],
) {
    // A private copy, kept in registers across the barriers instead of
    // read from the storage buffer again in each phase (H200: 1% off the sort).
    let params = &{ *params };
    unrolled_phases!(scan::SCAN_SWEEP_PHASES, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17], |phase| {
        scan::scan_spine_phase(phase, lid, params, partials, a, b)
    });
}

#[spirv(compute(threads(256)))]
pub fn scan_downsweep_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &ScanParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] data: &mut [u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] partials: &[u32],
    #[spirv(workgroup)] a: &mut [u32; WG],
    #[spirv(workgroup)] b: &mut [u32; WG],
) {
    // A private copy, kept in registers across the barriers instead of
    // read from the storage buffer again in each phase (H200: 1% off the sort).
    let params = &{ *params };
    let tile = linear_group(group.x, group.y, groups.x);
    unrolled_phases!(scan::SCAN_SWEEP_PHASES, [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17], |phase| {
        scan::scan_downsweep_phase(phase, lid, tile, params, data, partials, a, b)
    });
}
