use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::construct::scan;
use treelet_core::geometry::buffers::ScanParams;
use treelet_core::gpu::workgroup::{WG, barrier, linear_group};

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
    for phase in 0..scan::SCAN_REDUCE_PHASES {
        scan::scan_reduce_phase(phase, lid, tile, params, data, partials, sums);
        barrier();
    }
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
    for phase in 0..scan::SCAN_SWEEP_PHASES {
        scan::scan_spine_phase(phase, lid, params, partials, a, b);
        barrier();
    }
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
    for phase in 0..scan::SCAN_SWEEP_PHASES {
        scan::scan_downsweep_phase(phase, lid, tile, params, data, partials, a, b);
        barrier();
    }
}
