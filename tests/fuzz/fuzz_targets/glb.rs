//! Binary glTF (GLB): its header, JSON and BIN chunks.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    treelet_fuzz::on_file(data, "scene.glb", treelet::scene::gltf::load);
});
