//! glTF as JSON, buffers embedded as data URIs or in files beside it.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    treelet_fuzz::on_file(data, "scene.gltf", treelet::scene::gltf::load);
});
