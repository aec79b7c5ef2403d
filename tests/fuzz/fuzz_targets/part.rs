//! Render parts (`--checkpoint`, `merge`, `--resume`): EXR with Treelet's header and checksum.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    treelet_fuzz::on_file(data, "part.exr", treelet::render::parts::read_part);
});
