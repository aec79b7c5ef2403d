//! PLY meshes, ASCII and binary (the direct reader of the common layout, ply-rs for the rest).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    treelet_fuzz::on_file(data, "input.ply", treelet::scene::mesh::load);
});
