//! OBJ meshes (the chunked reader of plain files, tobj for the rest).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    treelet_fuzz::on_file(data, "input.obj", treelet::scene::mesh::load);
});
