//! Treelet's JSON scene files (with their meshes, instances and cameras).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    treelet_fuzz::on_file(data, "scene.json", treelet::scene::file::load);
});
