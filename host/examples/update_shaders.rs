//! Rewrites the committed SPIR-V modules (`host/shaders/treelet_shaders.bin`,
//! one per entry point, packed) with this build's, compiled from `shader/`
//! by rust-gpu:
//!
//!     cargo run -p treelet --features rebuild-shaders --example update_shaders
//!
//! Run it after changing `shader/` or `core/` (the test
//! `committed_spirv_is_the_shader_sources_build` fails until then).
fn main() -> std::io::Result<()> {
    let path = treelet::runtime::gpu::COMMITTED_SHADERS_PATH;
    let fresh = treelet::runtime::gpu::SHADERS;
    if std::fs::read(path).is_ok_and(|old| old == fresh) {
        println!("{path} is current ({} bytes)", fresh.len());
        return Ok(());
    }
    std::fs::write(path, fresh)?;
    println!("wrote {path} ({} bytes)", fresh.len());
    Ok(())
}
