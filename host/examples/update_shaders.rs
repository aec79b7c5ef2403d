//! Rewrites the committed SPIR-V module (`host/shaders/treelet_shader.spv`)
//! with this build's, compiled from `shader/` by rust-gpu:
//!
//!     cargo run -p treelet --features rebuild-shaders --example update_shaders
//!
//! Run it after changing `shader/` or `core/` (the test
//! `committed_spirv_is_the_shader_sources_build` fails until then).
fn main() -> std::io::Result<()> {
    let path = env!("treelet_shader_committed.spv");
    let fresh = treelet::runtime::gpu::SHADER_SPV;
    if std::fs::read(path).is_ok_and(|old| old == fresh) {
        println!("{path} is current ({} bytes)", fresh.len());
        return Ok(());
    }
    std::fs::write(path, fresh)?;
    println!("wrote {path} ({} bytes)", fresh.len());
    Ok(())
}
