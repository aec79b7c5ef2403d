//! HDR images (`compare`'s references): OpenEXR and PFM, the first byte of
//! the input choosing which.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else { return };
    let name = if kind & 1 == 0 { "image.exr" } else { "image.pfm" };
    treelet_fuzz::on_file(bytes, name, treelet::render::image_io::read_hdr);
});
