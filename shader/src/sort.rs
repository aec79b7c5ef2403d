use spirv_std::glam::UVec3;
use spirv_std::spirv;
use treelet_core::layout::SortParams;
use treelet_core::sort;
use treelet_core::workgroup::{barrier, linear_group, WG};

#[spirv(compute(threads(256)))]
pub fn sort_histogram_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &SortParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] block_hist: &mut [u32],
    #[spirv(workgroup)] counts: &mut [u32; WG],
) {
    let tile = linear_group(group.x, group.y, groups.x);
    for phase in 0..sort::HISTOGRAM_PHASES {
        sort::histogram_phase(phase, lid, tile, params, keys, block_hist, counts);
        barrier();
    }
}

#[spirv(compute(threads(256)))]
pub fn sort_scatter_cs(
    #[spirv(local_invocation_index)] lid: u32,
    #[spirv(workgroup_id)] group: UVec3,
    #[spirv(num_workgroups)] groups: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] params: &SortParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] keys_in: &[u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] values_in: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] offsets: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] keys_out: &mut [u64],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] values_out: &mut [u32],
    #[spirv(workgroup)] running: &mut [u32; WG],
    #[spirv(workgroup)] digits: &mut [u32; WG],
    #[spirv(workgroup)] packed: &mut [u32; sort::PACKED_DIGITS],
    #[spirv(workgroup)] counts: &mut [u32; sort::CHUNK_COUNTS],
    #[spirv(workgroup)] totals: &mut [u32; WG],
) {
    let tile = linear_group(group.x, group.y, groups.x);
    for phase in 0..sort::SCATTER_PHASES {
        sort::scatter_phase(
            phase, lid, tile, params, keys_in, values_in, offsets, keys_out, values_out, running, digits, packed,
            counts, totals,
        );
        barrier();
    }
}
